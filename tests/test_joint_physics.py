"""Joint physics kept across formats: damping, Coulomb friction, armature, springs, effort and velocity
limits, initial positions (MJCF's ``home`` keyframe)."""

from __future__ import annotations

import math
import textwrap
from pathlib import Path

import mujoco
import numpy as np
import pytest

from modelkit.api import validate
from modelkit.convert.api import write
from modelkit.convert.options import WriteOptions
from modelkit.model import Box, Geom, Inertial, Joint, JointLimits, JointType, Link, Robot
from modelkit.spatial import Pose


def _link(name: str) -> Link:
    shape = Geom(Box((0.1, 0.1, 0.1)))
    return Link(name, Inertial(1.0, np.zeros(3), np.diag([0.01, 0.01, 0.01])), [shape], [shape])


def _robot(root_joint: JointType = JointType.FLOATING) -> Robot:
    """A floating base with a hinge (every physics field set) and a slide (spring, no home offset)."""
    hinge = Joint("hinge", JointType.REVOLUTE, "base", "arm", Pose(np.eye(3), np.array([0.0, 0.0, 0.2])),
                  (0.0, 1.0, 0.0), JointLimits(-1.5, 1.5, 2.0, -2.0, 2.0, 30.0), armature=0.05,
                  damping=0.7, friction=0.3, initial_position=0.4)
    hinge.spring_stiffness, hinge.spring_reference = 12.0, 0.25
    slide = Joint("slide", JointType.PRISMATIC, "arm", "tip", Pose(np.eye(3), np.array([0.0, 0.0, 0.2])),
                  (0.0, 0.0, 1.0), JointLimits(0.0, 0.1, 0.5, -0.5, 0.5, 80.0), damping=2.0)
    slide.spring_stiffness, slide.spring_reference = 100.0, 0.05
    robot = Robot("physics", [_link("base"), _link("arm"), _link("tip")], [hinge, slide], root="base",
                  root_joint=root_joint, root_pose=Pose(np.eye(3), np.array([0.0, 0.0, 1.0])),
                  source_format="test")
    return robot


def _joint(robot: Robot, name: str) -> Joint:
    return next(j for j in robot.joints if j.name == name)


def test_mjcf_writes_every_field_and_reads_them_back(tmp_path: Path) -> None:
    out = tmp_path / "m.xml"
    notes = write(_robot(), out)
    model = mujoco.MjModel.from_xml_path(str(out))
    hinge = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, "hinge")
    slide = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, "slide")
    h, s = model.jnt_dofadr[hinge], model.jnt_dofadr[slide]
    assert (model.dof_damping[h], model.dof_frictionloss[h], model.dof_armature[h]) == (0.7, 0.3, 0.05)
    assert model.dof_damping[s] == 2.0
    assert model.jnt_stiffness[hinge] == 12.0 and model.qpos_spring[model.jnt_qposadr[hinge]] == 0.25
    assert model.jnt_stiffness[slide] == 100.0 and model.qpos_spring[model.jnt_qposadr[slide]] == 0.05
    assert list(model.jnt_actfrcrange[hinge]) == [-30.0, 30.0] and bool(model.jnt_actfrclimited[hinge])
    assert list(model.jnt_actfrcrange[slide]) == [-80.0, 80.0]
    key = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_KEY, "home")
    assert key >= 0
    qpos = model.key_qpos[key]
    assert qpos[model.jnt_qposadr[hinge]] == 0.4 and qpos[model.jnt_qposadr[slide]] == 0.0
    # the free base where its lowest collision shape (the base's box, 0.05 below its frame) rests on z = 0
    # (MK882); the body itself stays at the root's pose, 1 m up
    assert list(qpos[:7]) == [0.0, 0.0, 0.05, 1.0, 0.0, 0.0, 0.0]
    assert list(model.qpos0[:3]) == [0.0, 0.0, 1.0]
    assert not [n for n in notes if n.code == "MK820" and "initial position" in n.message]
    velocity = [n for n in notes if n.code == "MK820" and "velocity limit" in n.message]
    assert len(velocity) == 2  # MJCF joints have no velocity limit: said, not silently dropped
    back = validate(out).robot
    assert back is not None
    for name in ("hinge", "slide"):
        a, b = _joint(_robot(), name), _joint(back, name)
        assert (b.damping, b.friction, b.armature) == (a.damping, a.friction, a.armature)
        assert (b.spring_stiffness, b.spring_reference) == (a.spring_stiffness, a.spring_reference)
        assert b.limits.effort == a.limits.effort and b.initial_position == a.initial_position


def test_home_keyframe_puts_the_arm_at_its_initial_position(tmp_path: Path) -> None:
    out = tmp_path / "m.xml"
    write(_robot(JointType.FIXED), out)
    model = mujoco.MjModel.from_xml_path(str(out))
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_KEY, "home"))
    assert model.nq == 2 and list(data.qpos) == [0.4, 0.0]


def test_no_keyframe_without_initial_positions(tmp_path: Path) -> None:
    """Motors, q = 0 and a base resting on z = 0: nothing for a key to hold (position servos get one
    for their controls; a free base off the floor, one that stands it there)."""
    robot = _robot()
    _joint(robot, "hinge").initial_position = 0.0
    robot.root_pose = Pose(np.eye(3), np.array([0.0, 0.0, 0.05]))
    out = tmp_path / "m.xml"
    write(robot, out, options=WriteOptions(actuators="motor"))
    assert b"keyframe" not in out.read_bytes()


def test_sdf_keeps_damping_friction_springs_and_limits(tmp_path: Path) -> None:
    out = tmp_path / "m.sdf"
    notes = write(_robot(), out)
    back = validate(out).robot
    assert back is not None
    for name in ("hinge", "slide"):
        a, b = _joint(_robot(), name), _joint(back, name)
        assert (b.damping, b.friction) == (a.damping, a.friction)
        assert (b.spring_stiffness, b.spring_reference) == (a.spring_stiffness, a.spring_reference)
        assert (b.limits.effort, b.limits.velocity) == (a.limits.effort, a.limits.velocity)
    said = " ".join(n.message for n in notes)
    assert "armature 0.05" in said and "initial position 0.4" in said  # SDF has no field for them


def test_urdf_keeps_damping_friction_limits_and_says_what_it_drops(tmp_path: Path) -> None:
    out = tmp_path / "m.urdf"
    notes = write(_robot(), out)
    back = validate(out).robot
    assert back is not None
    for name in ("hinge", "slide"):
        a, b = _joint(_robot(), name), _joint(back, name)
        assert (b.damping, b.friction, b.limits.effort, b.limits.velocity) == (
            a.damping, a.friction, a.limits.effort, a.limits.velocity)
    text = " ".join(n.message for n in notes if "hinge" in n.message)
    assert "armature" in text and "initial position" in text and "spring" in text


def test_body_keeps_armature_initial_position_and_limits(tmp_path: Path) -> None:
    out = tmp_path / "m.body"
    notes = write(_robot(), out)
    back = validate(out).robot
    assert back is not None
    a, b = _joint(_robot(), "hinge"), _joint(back, "hinge")
    assert math.isclose(b.armature, a.armature, rel_tol=1e-12)
    assert math.isclose(b.initial_position, a.initial_position, rel_tol=1e-12)
    assert math.isclose(b.limits.effort, a.limits.effort)
    assert math.isclose(b.limits.velocity, a.limits.velocity)
    said = " ".join(n.message for n in notes if n.code == "MK820")
    assert "damping" in said  # Choreonoid's body format has none
    springs = " ".join(n.message for n in notes if n.code == "MK854")  # nor springs (a warning)
    assert "stiffness 12, reference 0.25" in springs and "stiffness 100, reference 0.05" in springs


def test_choreonoid_rotor_inertia_becomes_mjcf_armature(tmp_path: Path) -> None:
    source = tmp_path / "r.body"
    source.write_text(textwrap.dedent("""\
        format: ChoreonoidBody
        format_version: 2.0
        name: r
        root_link: base
        links:
          - name: base
            joint_type: fixed
            mass: 1
            inertia: [ 0.01, 0, 0, 0, 0.01, 0, 0, 0, 0.01 ]
          - name: arm
            parent: base
            joint_type: revolute
            joint_axis: [ 0, 1, 0 ]
            joint_id: 0
            joint_range: [ -90, 90 ]
            rotor_inertia: 2.0e-5
            gear_ratio: 100
            joint_displacement: 30
            mass: 1
            inertia: [ 0.01, 0, 0, 0, 0.01, 0, 0, 0, 0.01 ]
        """))
    out = tmp_path / "out" / "r.xml"
    write(validate(source).robot, out)  # type: ignore[arg-type]
    model = mujoco.MjModel.from_xml_path(str(out))
    assert model.dof_armature[0] == pytest.approx(2.0e-5 * 100**2, rel=1e-12)
    assert model.key_qpos[0][0] == pytest.approx(math.radians(30), rel=1e-12)


def test_urdf_dynamics_reach_mjcf_and_come_back(tmp_path: Path) -> None:
    source = tmp_path / "r.urdf"
    source.write_text(textwrap.dedent("""\
        <robot name="r">
          <link name="base"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01"
            ixy="0" ixz="0" iyz="0"/></inertial></link>
          <link name="arm"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01"
            ixy="0" ixz="0" iyz="0"/></inertial></link>
          <joint name="j" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 1 0"/>
            <limit lower="-1" upper="1" effort="12" velocity="3"/>
            <dynamics damping="0.4" friction="0.15"/></joint>
        </robot>
        """))
    mjcf = tmp_path / "mj" / "r.xml"
    write(validate(source).robot, mjcf)  # type: ignore[arg-type]
    model = mujoco.MjModel.from_xml_path(str(mjcf))
    assert (model.dof_damping[-1], model.dof_frictionloss[-1]) == (0.4, 0.15)
    assert list(model.jnt_actfrcrange[-1]) == [-12.0, 12.0]
    again = tmp_path / "again" / "r.urdf"
    write(validate(mjcf).robot, again)  # type: ignore[arg-type]
    back = validate(again).robot
    assert back is not None
    j = _joint(back, "j")
    assert (j.damping, j.friction, j.limits.effort) == (0.4, 0.15, 12.0)


def test_sdf_springs_round_trip_through_mjcf(tmp_path: Path) -> None:
    sdf = tmp_path / "a" / "m.sdf"
    write(_robot(), sdf)
    mjcf = tmp_path / "b" / "m.xml"
    write(validate(sdf).robot, mjcf)  # type: ignore[arg-type]
    sdf2 = tmp_path / "c" / "m.sdf"
    write(validate(mjcf).robot, sdf2)  # type: ignore[arg-type]
    back = validate(sdf2).robot
    assert back is not None
    for name in ("hinge", "slide"):
        a, b = _joint(_robot(), name), _joint(back, name)
        assert (b.damping, b.friction, b.spring_stiffness, b.spring_reference, b.limits.effort) == (
            a.damping, a.friction, a.spring_stiffness, a.spring_reference, a.limits.effort)
