"""A URDF revolute joint whose limits are equal (``lower="0" upper="0"``: example-robot-data's
double pendulums and Centauro's wheels) is locked; MuJoCo's ``range`` cannot say so (its autolimits
read ``0 0`` as no limit), so the MJCF writer holds the joint with a joint equality. verify reads that
equality back as the limits [0, 0]; before, layer 1 failed a sound conversion with "limits [0, 0]
read back as [-inf, inf]"."""

from __future__ import annotations

from pathlib import Path

from modelkit.verify.api import verify

PENDULUM = """<?xml version="1.0"?>
<robot name="pendulum">
  <link name="base">
    <inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="joint1" type="revolute"><origin xyz="0 0 0.5"/><parent link="base"/><child link="arm"/>
    <axis xyz="1 0 0"/><limit lower="0.2" upper="0.2" effort="10" velocity="5"/></joint>
  <link name="arm">
    <inertial><origin xyz="0 0 0.2"/><mass value="0.5"/>
      <inertia ixx="0.007" iyy="0.007" izz="0.0005" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="joint2" type="revolute"><origin xyz="0 0 0.4"/><parent link="arm"/><child link="tip"/>
    <axis xyz="1 0 0"/><limit lower="-1" upper="1" effort="10" velocity="5"/></joint>
  <link name="tip">
    <inertial><origin xyz="0 0 0.1"/><mass value="0.2"/>
      <inertia ixx="0.001" iyy="0.001" izz="0.0001" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
</robot>
"""


def test_a_joint_locked_by_equal_limits_keeps_them_in_mujoco(tmp_path: Path) -> None:
    path = tmp_path / "pendulum.urdf"
    path.write_text(PENDULUM)
    report = verify(path, out_dir=tmp_path / "out", engines=("mujoco", "pybullet", "pinocchio"),
                    configurations=3, samples=3, driven=False)
    limits = [c for c in report.checks if c.quantity == "limits"]  # one check per engine, its worst joint
    assert {c.engine for c in limits} >= {"mujoco", "pybullet"}
    assert all(c.passed for c in limits), [c.detail for c in limits if not c.passed]
    assert 'polycoef="0.2 0 0 0 0"' in (tmp_path / "out" / "pendulum.xml").read_text()
