"""A mimic joint with an offset is at its offset when its leader is at 0 (q = multiplier · q_leader +
offset). Layer 2's first configuration, q = 0, held it at 0 in the source while yourdfpy, which applies
<mimic>, put it at the offset: dexmate's F5D6 hands (thumb offset 0.00765 rad) failed layer 2 in
yourdfpy on a sound conversion, 7.65e-3 rad at ``L_th_l2``."""

from __future__ import annotations

from pathlib import Path

import modelkit
from modelkit.verify.api import verify
from modelkit.verify.layers.kinematics import configurations

PINCH = """<robot name="pinch">
  <link name="base"><inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0"
    izz="0.01"/></inertial></link>
  <link name="finger_a"><inertial><origin xyz="0 0 0.05"/><mass value="0.1"/>
    <inertia ixx="1e-4" ixy="0" ixz="0" iyy="1e-4" iyz="0" izz="1e-5"/></inertial></link>
  <link name="finger_b"><inertial><origin xyz="0 0 0.05"/><mass value="0.1"/>
    <inertia ixx="1e-4" ixy="0" ixz="0" iyy="1e-4" iyz="0" izz="1e-5"/></inertial></link>
  <joint name="a" type="revolute"><parent link="base"/><child link="finger_a"/><origin xyz="0.02 0 0.1"/>
    <axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="5" velocity="2"/></joint>
  <joint name="b" type="revolute"><parent link="base"/><child link="finger_b"/><origin xyz="-0.02 0 0.1"/>
    <axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="5" velocity="2"/>
    <mimic joint="a" multiplier="-1.2" offset="0.05"/></joint>
</robot>"""


def _source(tmp_path: Path) -> Path:
    source = tmp_path / "pinch.urdf"
    source.write_text(PINCH)
    return source


def test_every_configuration_puts_the_mimic_joint_where_its_leader_says(tmp_path: Path) -> None:
    robot = modelkit.load(_source(tmp_path))
    configs = configurations(robot, 4, 0)
    assert configs[0] == {"b": 0.05}  # q = 0: the leader at 0, the mimic joint at its offset
    for q in configs[1:]:
        assert q["b"] == -1.2 * q["a"] + 0.05


def test_yourdfpy_agrees_at_q_0(tmp_path: Path) -> None:
    report = verify(_source(tmp_path), tmp_path / "out", ("mujoco", "pybullet", "yourdfpy", "pinocchio"),
                    configurations=3, samples=1, driven=False)
    assert report.failed == [], [c.detail for c in report.failed]
    layer2 = [c for c in report.checks if c.layer == 2 and c.engine == "yourdfpy"]
    assert layer2 and all(c.passed for c in layer2)
