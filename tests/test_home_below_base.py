"""MK865: a welded arm whose home pose reaches below its base is said at conversion, with the depth.

On a table or floor the base stands on, such a pose starts inside it and MuJoCo pushes the arm out at
the first step. The test arms are a base box (its bottom at z = 0) and one link on a hinge whose
capsule hangs down or stands up at q = 0. The Kinova arm of example-robot-data, which has the fault
in its zero pose and not in its SRDF's ``arm_up``, is in ``tests/test_srdf_home.py``.
"""

from __future__ import annotations

from pathlib import Path

from modelkit.api import load
from modelkit.convert.api import write
from modelkit.convert.options import WriteOptions

INERTIAL = ('<inertial><mass value="1"/>'
            '<inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>')

ARM = f"""<robot name="arm">
  <link name="base">{INERTIAL}
    <collision><origin xyz="0 0 0.05"/><geometry><box size="0.2 0.2 0.1"/></geometry></collision></link>
  <link name="upper">{INERTIAL}
    <collision><origin xyz="0.2 0 OFFSET"/><geometry><cylinder radius="0.03" length="0.3"/></geometry>
    </collision></link>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/>
    <origin xyz="0 0 0.1"/><axis xyz="0 1 0"/>
    <limit lower="-2" upper="2" effort="100" velocity="1"/></joint>
</robot>
"""


def _notes(tmp_path: Path, offset: float, base: str = "auto") -> list:
    path = tmp_path / "arm.urdf"
    path.write_text(ARM.replace("OFFSET", str(offset)))
    return write(load(path), tmp_path / "out" / "arm.xml", options=WriteOptions(base=base), force=True)


def test_a_link_hanging_below_the_base_is_said_with_its_depth(tmp_path: Path) -> None:
    # the upper link's cylinder (axis along z, half length 0.15) centred 0.2 below the shoulder, which is
    # 0.1 above the base's bottom: its lowest point is 0.1 - 0.2 - 0.15 = -0.25 m, 250 mm below the base
    (said,) = [n for n in _notes(tmp_path, -0.2) if n.code == "MK865"]
    assert said.severity == "warning"
    assert "1 moving bod(ies)" in said.message and "upper 250 mm" in said.message
    assert "--srdf" in said.message


def test_a_link_above_the_base_or_just_touching_its_plane_is_not_said(tmp_path: Path) -> None:
    assert not [n for n in _notes(tmp_path, 0.3) if n.code == "MK865"]
    # centred 0.0495 above the shoulder: its lowest point 0.1 + 0.0495 - 0.15 is 0.5 mm below the base's
    # bottom, within the 1 mm a mesh's or a rounding's slack may take
    assert not [n for n in _notes(tmp_path, 0.0495) if n.code == "MK865"]


def test_a_robot_hanging_from_its_base_is_not_judged(tmp_path: Path) -> None:
    """The moving link's mass at the cylinder's centre, 0.1 m below the base's bottom: the robot hangs
    from its base (a finger under its frame, an arm on a shoulder), so no floor is under it."""
    path = tmp_path / "arm.urdf"
    hanging = ARM.replace("OFFSET", "-0.2").replace(
        f'<link name="upper">{INERTIAL}',
        '<link name="upper">' + INERTIAL.replace("<inertial>", '<inertial><origin xyz="0.2 0 -0.2"/>'))
    path.write_text(hanging)
    notes = write(load(path), tmp_path / "out" / "arm.xml", force=True)
    assert not [n for n in notes if n.code == "MK865"]


def test_a_floating_robot_is_not_judged(tmp_path: Path) -> None:
    assert not [n for n in _notes(tmp_path, -0.2, base="floating") if n.code == "MK865"]
