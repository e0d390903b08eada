"""A URDF that welds its robot to an empty ``world`` link (Unitree's Z1 and UFactory's xArm in
example-robot-data do) is verified like any welded arm: convert absorbs the weld (the written files'
base is the robot's first link), and verify's reference must absorb it the same way. Before, every
URDF engine refused the written file ("PyBullet's base link is 'link00', not the root 'world'",
yourdfpy "No path from world->link00") and the verdict was FAIL on a sound robot."""

from __future__ import annotations

from pathlib import Path

from modelkit.verify.api import verify

WELDED_ARM = """<?xml version="1.0"?>
<robot name="welded_arm">
  <link name="world"/>
  <joint name="base_static_joint" type="fixed">
    <origin xyz="0 0 0.1"/><parent link="world"/><child link="link00"/>
  </joint>
  <link name="link00">
    <collision><geometry><cylinder radius="0.03" length="0.05"/></geometry></collision>
    <inertial><mass value="0.5"/>
      <inertia ixx="4e-4" iyy="4e-4" izz="5e-4" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="joint1" type="revolute"><origin xyz="0 0 0.06"/><parent link="link00"/><child link="link01"/>
    <axis xyz="0 0 1"/><limit lower="-2.6" upper="2.6" effort="30" velocity="3"/></joint>
  <link name="link01">
    <collision><origin xyz="0 0 0.1"/><geometry><box size="0.04 0.04 0.2"/></geometry></collision>
    <inertial><origin xyz="0.01 0 0.1"/><mass value="0.7"/>
      <inertia ixx="3e-3" iyy="3e-3" izz="4e-4" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="joint2" type="revolute"><origin xyz="0 0 0.2"/><parent link="link01"/><child link="link02"/>
    <axis xyz="0 1 0"/><limit lower="-1.5" upper="1.5" effort="30" velocity="3"/></joint>
  <link name="link02">
    <collision><origin xyz="0 0 0.1"/><geometry><box size="0.03 0.03 0.2"/></geometry></collision>
    <inertial><origin xyz="0 0.01 0.1"/><mass value="0.4"/>
      <inertia ixx="2e-3" iyy="2e-3" izz="2e-4" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
</robot>
"""


def test_a_urdf_world_weld_verifies_in_every_urdf_engine(tmp_path: Path) -> None:
    path = tmp_path / "welded_arm.urdf"
    path.write_text(WELDED_ARM)
    report = verify(path, out_dir=tmp_path / "out", engines=("mujoco", "pybullet", "pinocchio", "yourdfpy"),
                    configurations=3, samples=3, driven=False)
    assert not report.errors, report.errors
    failed = [c for c in report.checks if not c.passed]
    assert failed == [], failed
    graded = {c.engine for c in report.checks}
    assert {"pybullet", "yourdfpy", "mujoco"} <= graded  # each loaded the written files and was graded
    assert "'link00'" in report.base  # the reference's root is the robot's first link, as written
