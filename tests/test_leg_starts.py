"""Which limbs are legs (convert.legs.leg_starts), on hand-made humanoids: rooted at the pelvis with a
waist, and rooted at the torso with the legs below a waist (as Fourier's Qinglong is)."""

from __future__ import annotations

from pathlib import Path

from modelkit.api import load
from modelkit.convert.legs import leg_joints, leg_starts
from modelkit.model import JointType

INERTIA = '<inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/>'


def _link(name: str, size: str = "0.1 0.1 0.1") -> str:
    return (f'<link name="{name}"><inertial><mass value="2"/>{INERTIA}</inertial>'
            f'<collision><geometry><box size="{size}"/></geometry></collision></link>')


def _joint(name: str, parent: str, child: str, xyz: str) -> str:
    return (f'<joint name="{name}" type="revolute"><parent link="{parent}"/><child link="{child}"/>'
            f'<origin xyz="{xyz}"/><axis xyz="0 1 0"/>'
            '<limit lower="-1" upper="1" effort="100" velocity="2"/></joint>')


def _humanoid(torso_rooted: bool) -> str:
    """Two legs (hip, knee, ankle) from a pelvis, a waist up to a torso with two arms (shoulder,
    elbow) hanging beside it; the root is the pelvis or the torso."""
    parts = [_link(n) for n in ("pelvis", "torso", "l_thigh", "l_shank", "r_thigh", "r_shank",
                                "l_upper", "l_lower", "r_upper", "r_lower")]
    parts += [_link("l_foot", "0.2 0.1 0.02"), _link("r_foot", "0.2 0.1 0.02")]
    legs = [_joint(f"{s}_hip", "pelvis", f"{s}_thigh", f"0 {y} -0.1")
            + _joint(f"{s}_knee", f"{s}_thigh", f"{s}_shank", "0 0 -0.4")
            + _joint(f"{s}_ankle", f"{s}_shank", f"{s}_foot", "0 0 -0.4")
            for s, y in (("l", 0.1), ("r", -0.1))]
    arms = [_joint(f"{s}_shoulder", "torso", f"{s}_upper", f"0 {y} 0.2")
            + _joint(f"{s}_elbow", f"{s}_upper", f"{s}_lower", "0 0 -0.25")
            for s, y in (("l", 0.25), ("r", -0.25))]
    if torso_rooted:
        waist = ('<joint name="waist" type="revolute"><parent link="torso"/><child link="pelvis"/>'
                 '<origin xyz="0 0 -0.3"/><axis xyz="0 0 1"/>'
                 '<limit lower="-1" upper="1" effort="100" velocity="2"/></joint>')
    else:
        waist = _joint("waist", "pelvis", "torso", "0 0 0.3")
    return '<robot name="h">' + "".join(parts + legs + arms) + waist + "</robot>"


def test_a_torso_rooted_humanoid_stands_on_the_legs_below_its_waist(tmp_path: Path) -> None:
    for torso_rooted in (False, True):
        path = tmp_path / f"h{int(torso_rooted)}.urdf"
        path.write_text(_humanoid(torso_rooted))
        robot = load(path)
        robot.root_joint = JointType.FLOATING
        assert leg_starts(robot) == ["l_hip", "r_hip"], torso_rooted
        assert leg_joints(robot) == {"l_hip", "l_knee", "l_ankle", "r_hip", "r_knee", "r_ankle"}
        robot.root_joint = JointType.FIXED
        assert leg_starts(robot) == [] and leg_joints(robot) == frozenset()
