"""PyBullet reports the joint states of a body of at most 127 joints, fixed ones included (its shared
memory's limit: on a serial chain 127 answer and 128 fail, "getJointState failed" for every joint).
The URDF writer says so (MK862), and verify's layer 4 reports PyBullet as not run on such a file
instead of failing it with the engine's error (example-robot-data's TIAGo dual written with its
sensor frames has 129 joints)."""

from __future__ import annotations

import copy
import dataclasses
from pathlib import Path

import pybullet
import pytest

import modelkit
from modelkit.convert.api import convert, write
from modelkit.formats.urdf.writer import PYBULLET_MAX_JOINTS
from modelkit.model import Joint, JointType, Link, Robot
from modelkit.spatial import Pose
from modelkit.verify.drive.scenario import default_scenario
from modelkit.verify.drive.vehicle import find_drive
from modelkit.verify.layers import layer4

from .conftest import TUTORIAL


def _with_frames(count: int) -> Robot:
    """The tutorial robot with ``count`` extra links on fixed joints to its chassis."""
    robot = copy.deepcopy(modelkit.load(TUTORIAL / "mobile_robot.body"))
    assert isinstance(robot, Robot) and robot.root is not None
    for i in range(count):
        robot.links.append(Link(f"frame_{i}"))
        robot.joints.append(Joint(f"frame_{i}_joint", JointType.FIXED, robot.root, f"frame_{i}",
                                  origin=Pose()))
    return robot


def _joint_state_answers(path: Path) -> bool:
    client = pybullet.connect(pybullet.DIRECT)
    try:
        body = pybullet.loadURDF(str(path), physicsClientId=client)
        try:
            pybullet.getJointState(body, 0, physicsClientId=client)
        except pybullet.error:
            return False
        return True
    finally:
        pybullet.disconnect(client)


@pytest.mark.parametrize("extra", [0, 1])
def test_the_urdf_writer_says_when_pybullet_cannot_report_the_joints(tmp_path: Path, extra: int) -> None:
    base = len(_with_frames(0).joints)
    robot = _with_frames(PYBULLET_MAX_JOINTS - base + extra)
    path = tmp_path / "r.urdf"
    notes = write(robot, path)
    joints = path.read_text().count("<joint ")
    assert joints == PYBULLET_MAX_JOINTS + extra
    said = [n.message for n in notes if n.code == "MK862"]
    assert _joint_state_answers(path) == (extra == 0)  # the limit, measured
    assert bool(said) is bool(extra), said
    if extra:
        assert f"the URDF has {joints} joints" in said[0]
    assert convert([TUTORIAL / "mobile_robot.body"], tmp_path / "plain" / "r.urdf").status == 0


def test_layer4_reports_pybullet_not_run_on_a_body_of_too_many_joints(tmp_path: Path) -> None:
    robot = _with_frames(PYBULLET_MAX_JOINTS)
    scenario = default_scenario()
    scenario = dataclasses.replace(scenario, native_report=False,
                                   profiles=tuple(p for p in scenario.profiles if p.name == "straight"))
    result = layer4.run(robot, find_drive(robot, scenario), scenario, tmp_path, engines=("pybullet",))
    assert [c for c in result.checks if c.engine == "pybullet"] == []
    said = [s.reason for s in result.skips if s.engine == "pybullet"]
    assert any("not driven" in s and "at most 127" in s for s in said), said
