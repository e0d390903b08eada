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
    assert worst < 0.05, worst  # 0.036 rad (0.078 before the coupled joints' armature, MK835)
    # the same file with MuJoCo's default coupling: the follower lags by 0.14 rad (0.28 without armature)
    default = tmp_path / "default.xml"
    default.write_text(re.sub(r' solref="0\.005 1"', "", xml))
    assert _worst_violation(default, "drive_joint_motor", 0.425) > 0.1


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


THUMB = """<robot name="thumb">
  <link name="palm"><inertial><mass value="0.1"/>
    <inertia ixx="1e-4" ixy="0" ixz="0" iyy="1e-4" iyz="0" izz="1e-4"/></inertial></link>
  <link name="proximal"><inertial><origin xyz="0.01 0 0"/><mass value="0.0066"/>
    <inertia ixx="3e-7" ixy="0" ixz="0" iyy="8e-7" iyz="0" izz="8e-7"/></inertial>
    <collision><origin xyz="0.01 0 0"/><geometry><box size="0.02 0.01 0.01"/></geometry></collision></link>
  <link name="intermediate"><inertial><origin xyz="0.008 0 0"/><mass value="0.0038"/>
    <inertia ixx="1e-7" ixy="0" ixz="0" iyy="2e-7" iyz="0" izz="2e-7"/></inertial>
    <collision><origin xyz="0.008 0 0"/><geometry><box size="0.014 0.008 0.008"/></geometry>
    </collision></link>
  <link name="distal"><inertial><origin xyz="0.006 0 0"/><mass value="0.0033"/>
    <inertia ixx="5e-8" ixy="0" ixz="0" iyy="1e-7" iyz="0" izz="1e-7"/></inertial>
    <collision><origin xyz="0.006 0 0"/><geometry><box size="0.01 0.007 0.007"/></geometry></collision></link>
  <joint name="pitch" type="revolute"><parent link="palm"/><child link="proximal"/><axis xyz="0 0 1"/>
    <limit lower="-0.1" upper="0.6" effort="1" velocity="2"/></joint>
  <joint name="middle" type="revolute"><parent link="proximal"/><child link="intermediate"/>
    <origin xyz="0.02 0 0"/><axis xyz="0 0 1"/><limit lower="0" upper="0.8" effort="1" velocity="2"/>
    <mimic joint="pitch" multiplier="1.6"/></joint>
  <joint name="tip" type="revolute"><parent link="intermediate"/><child link="distal"/>
    <origin xyz="0.016 0 0"/><axis xyz="0 0 1"/><limit lower="0" upper="1.2" effort="1" velocity="2"/>
    <mimic joint="pitch" multiplier="2.4"/></joint>
</robot>
"""
"""Fourier's Inspire hand's thumb, as its numbers go: a leader and two followers at ×1.6 and ×2.4, hung
from one another, a few grams each; the leader's range [-0.1, 0.6] carries the followers past theirs."""


def _thumb_after(xml: Path, command: float) -> tuple[float, float]:
    """The worst mimic violation and the worst follower beyond its range, from 1 s to 3 s after the
    thumb's servo is commanded to ``command`` from home."""
    m = mujoco.MjModel.from_xml_path(str(xml))
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, 0)
    d.ctrl[0] = command

    def q(name: str) -> float:
        return float(d.qpos[m.jnt_qposadr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, name)]])

    violation = beyond = 0.0
    for step in range(int(3.0 / m.opt.timestep)):
        mujoco.mj_step(m, d)
        if step * m.opt.timestep >= 1.0:
            violation = max(violation, abs(q("middle") - 1.6 * q("pitch")), abs(q("tip") - 2.4 * q("pitch")))
            beyond = max(beyond, q("middle") - 0.8, q("tip") - 1.2, -q("middle"), -q("tip"))
    return violation, beyond


def test_a_light_thumb_settles_on_its_mimics(tmp_path: Path) -> None:
    """MK835: the joints a mimic couples get their own inertia at home as armature. Without it the thumb
    commanded to mid-range swung about its mimics for as long as the command held (4.5 rad here, 1.0 rad
    on the Inspire hand itself). MK828: the servo's ctrlrange is [0, 0.5], where both followers stay in
    their ranges, not the joint's [-0.1, 0.6]."""
    (tmp_path / "thumb.urdf").write_text(THUMB)
    out = tmp_path / "out" / "thumb.xml"
    result = CliRunner().invoke(main, ["convert", str(tmp_path / "thumb.urdf"), "-o", str(out)])
    assert result.exit_code == 0, result.output
    assert "info MK835 3 joint(s) coupled by a mimic get an armature" in result.output
    assert ("info MK828 actuator on joint pitch: ctrlrange 0 0.5, not the joint's range -0.1 0.6"
            in result.output)
    assert "middle, tip leave their own ranges" in result.output
    m = mujoco.MjModel.from_xml_path(str(out))
    assert list(m.actuator_ctrlrange[0]) == [0.0, 0.5]
    assert list(m.jnt_range[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, "pitch")]) == [-0.1, 0.6]
    # each coupled joint's armature is its own inertia at home: MuJoCo's diagonal with the armature zeroed
    bare = mujoco.MjModel.from_xml_path(str(out))
    bare.dof_armature[:] = 0.0
    data = mujoco.MjData(bare)
    mujoco.mj_forward(bare, data)
    full = np.zeros((bare.nv, bare.nv))
    mujoco.mj_fullM(bare, data, full)
    assert np.allclose(m.dof_armature, np.diag(full), rtol=1e-9, atol=0.0)
    for command in (0.0, 0.25, 0.5):  # home, mid-range, the end of the narrowed range
        violation, beyond = _thumb_after(out, command)
        assert violation < 1e-3 and beyond < 1e-3, (command, violation, beyond)
    # the same file without the armature: the coupling never settles
    spec = mujoco.MjSpec.from_file(str(out))
    for joint in spec.joints:
        joint.armature = 0.0
    (tmp_path / "out" / "bare.xml").write_text(spec.to_xml())
    assert _thumb_after(tmp_path / "out" / "bare.xml", 0.25)[0] > 0.1


def test_verify_checks_the_coupled_armature_against_pinocchio(tmp_path: Path) -> None:
    """verify compares MuJoCo with the source holding the MJCF's coupled armature (read from the file),
    checks each value against Pinocchio's inertia at home, and replays MuJoCo without it against PyBullet
    (whose URDF holds none): before, the thumb's mass matrix and replay failed."""
    import json

    (tmp_path / "thumb.urdf").write_text(THUMB)
    result = CliRunner().invoke(main, ["verify", str(tmp_path / "thumb.urdf"), "-o", str(tmp_path / "v")])
    assert result.exit_code == 0, result.output
    checks = json.loads((tmp_path / "v" / "report.json").read_text())["checks"]
    rule = [c for c in checks if c["quantity"] == "coupled-armature"]
    assert sorted(c["where"] for c in rule) == ["middle", "pitch", "tip"]
    failed = [c for c in checks if c["error"] > c["tolerance"]]
    assert not failed, failed
    assert any(c["quantity"] == "mass-matrix" and c["engine"] == "mujoco" for c in checks)
    assert any(c["quantity"] == "replay" for c in checks)
