"""Mimic joints in MuJoCo (issue 17): a mimic is rigid in URDF; MuJoCo's joint equality is a soft
constraint whose default 20 ms time constant lets a light follower lag its servoed leader. The MJCF
writer gives the equalities it makes of mimics a 5 ms time constant (MK869), as MuJoCo Menagerie's
Robotiq 2F-85 couples its drivers.

Measured on pybullet_data's xArm 6 with its gripper (a leader and five mimic followers), converted with
default options and commanded as a user does: hold home 2 s, then the gripper to mid-range for 2 s.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from modelkit.cli import main

pybullet_data = pytest.importorskip("pybullet_data")
mujoco = pytest.importorskip("mujoco")
XARM = Path(pybullet_data.getDataPath()) / "xarm" / "xarm6_with_gripper.urdf"


def _worst_violation(xml: Path, gripper: str, target: float) -> float:
    """The largest |q_follower − (offset + multiplier q_leader)| over the file's joint equalities, held
    at home 2 s, then with the gripper's servo at ``target`` for 2 s."""
    m = mujoco.MjModel.from_xml_path(str(xml))
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, 0)
    pairs = [(int(m.jnt_qposadr[m.eq_obj1id[e]]), int(m.jnt_qposadr[m.eq_obj2id[e]]), m.eq_data[e][:2].copy())
             for e in range(m.neq) if m.eq_type[e] == mujoco.mjtEq.mjEQ_JOINT]
    assert pairs
    worst = 0.0
    steps = int(2.0 / m.opt.timestep)
    for phase in range(2):
        if phase:
            d.ctrl[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_ACTUATOR, gripper)] = target
        for _ in range(steps):
            mujoco.mj_step(m, d)
            for follower, leader, (offset, multiplier) in pairs:
                worst = max(worst, abs(d.qpos[follower] - offset - multiplier * d.qpos[leader]))
    assert np.all(np.isfinite(d.qpos))
    return worst


def test_a_gripper_follows_its_leader_when_commanded(tmp_path: Path) -> None:
    target = tmp_path / "xarm.xml"
    result = CliRunner().invoke(main, ["convert", str(XARM), "-o", str(target)])
    assert result.exit_code == 0, result.output
    assert 'info MK869 5 mimic joint(s) written as joint equalities with solref="0.005 1"' in result.output
    xml = target.read_text()
    assert xml.count('solref="0.005 1"') == 5
    worst = _worst_violation(target, "drive_joint_motor", 0.425)
    assert worst < 0.1, worst
    # the same file with MuJoCo's default coupling: the follower lags by 0.28 rad
    default = tmp_path / "default.xml"
    default.write_text(re.sub(r' solref="0\.005 1"', "", xml))
    assert _worst_violation(default, "drive_joint_motor", 0.425) > 0.2


def test_an_mjcf_source_keeps_its_own_equalities(tmp_path: Path) -> None:
    source = tmp_path / "coupled.xml"
    source.write_text("""<mujoco>
  <worldbody><body name="a"><joint name="j1" axis="1 0 0"/><geom size="0.1"/>
    <body name="b" pos="0 0 0.3"><joint name="j2" axis="1 0 0"/><geom size="0.1"/></body></body></worldbody>
  <equality><joint joint1="j2" joint2="j1" polycoef="0 2 0 0 0"/></equality>
</mujoco>""")
    result = CliRunner().invoke(main, ["convert", str(source), "-o", str(tmp_path / "out.xml")])
    assert result.exit_code == 0, result.output
    assert "solref" not in (tmp_path / "out.xml").read_text() and "MK869" not in result.output
    result = CliRunner().invoke(main, ["convert", str(source), "-o", str(tmp_path / "out.urdf")])
    assert result.exit_code == 0, result.output
    back = tmp_path / "back.xml"
    result = CliRunner().invoke(main, ["convert", str(tmp_path / "out.urdf"), "-o", str(back)])
    assert result.exit_code == 0, result.output
    assert 'polycoef="0 2 0 0 0" solref="0.005 1"' in back.read_text()  # a URDF mimic


def test_track_rollers_keep_mujocos_default_coupling(tmp_path: Path) -> None:
    """The track approximation's rollers mimic roller 0; its skid-steer tolerances (docs/verify.md)
    were measured with MuJoCo's default coupling, which they keep."""
    from tests.conftest import TUTORIAL

    target = tmp_path / "tracks.xml"
    source = TUTORIAL / "mobile_robot_tracks.body"
    result = CliRunner().invoke(main, ["convert", str(source), "-o", str(target)])
    assert result.exit_code == 0, result.output
    xml = target.read_text()
    assert "<equality>" in xml and "_mimic" in xml and "solref=\"0.005 1\"" not in xml
    assert "MK869" not in result.output


GRIPPER_STARTED_OPEN = """<robot name="gripper">
  <link name="palm"/>
  <link name="driver"><inertial><origin xyz="0 0 0.03"/><mass value="0.05"/>
    <inertia ixx="1e-5" iyy="1e-5" izz="1e-5" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="mirror"><inertial><origin xyz="0 0 0.03"/><mass value="0.05"/>
    <inertia ixx="1e-5" iyy="1e-5" izz="1e-5" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="tip"><inertial><origin xyz="0 0 0.02"/><mass value="0.02"/>
    <inertia ixx="1e-6" iyy="1e-6" izz="1e-6" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="finger" type="revolute"><parent link="palm"/><child link="driver"/><axis xyz="1 0 0"/>
    <limit lower="0" upper="0.8" effort="5" velocity="2"/></joint>
  <joint name="finger_mirror" type="revolute"><parent link="palm"/><child link="mirror"/>
    <origin xyz="0 0.05 0"/><axis xyz="1 0 0"/><limit lower="-0.8" upper="0" effort="5" velocity="2"/>
    <mimic joint="finger" multiplier="-1"/></joint>
  <joint name="finger_tip" type="revolute"><parent link="driver"/><child link="tip"/>
    <origin xyz="0 0 0.06"/><axis xyz="1 0 0"/><limit lower="0" upper="1" effort="5" velocity="2"/>
    <mimic joint="finger_mirror" multiplier="-0.5" offset="0.1"/></joint>
  <ros2_control name="hw" type="system">
    <joint name="finger"><command_interface name="position"/>
      <state_interface name="position"><param name="initial_value">0.4</param></state_interface></joint>
  </ros2_control>
</robot>
"""


def test_the_home_keyframe_puts_followers_where_their_mimics_do(tmp_path: Path) -> None:
    """A source that starts a gripper's leader open (ros2_control's ``initial_value``, as TIAGo Pro's does)
    and names no position for its followers: the ``home`` keyframe puts each follower, through a chain of
    two mimics, at its leader's image, so nothing snaps at the first step (before: the followers sat at 0
    and jumped to the leader's 0.15–0.19 rad on TIAGo Pro)."""
    source = tmp_path / "gripper.urdf"
    source.write_text(GRIPPER_STARTED_OPEN)
    out = tmp_path / "gripper.xml"
    result = CliRunner().invoke(main, ["convert", str(source), "-o", str(out)])
    assert result.exit_code == 0, result.output
    m = mujoco.MjModel.from_xml_path(str(out))
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_KEY, "home"))
    names = ("finger", "finger_mirror", "finger_tip")
    home = {name: float(d.qpos[m.joint(name).qposadr[0]]) for name in names}
    assert home == pytest.approx({"finger": 0.4, "finger_mirror": -0.4, "finger_tip": 0.3}, abs=1e-12)
    mujoco.mj_forward(m, d)
    assert float(np.max(np.abs(d.efc_pos[d.efc_type == mujoco.mjtConstraint.mjCNSTR_EQUALITY]))) < 1e-12
    for _ in range(round(0.2 / m.opt.timestep)):
        mujoco.mj_step(m, d)
    moved = {name: abs(float(d.qpos[m.joint(name).qposadr[0]]) - home[name]) for name in home}
    assert max(moved.values()) < 0.01, moved
