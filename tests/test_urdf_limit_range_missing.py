"""MK125: a revolute or prismatic joint whose ``<limit>`` gives neither ``lower`` nor ``upper``. urdfdom
reads 0 and 0 (a locked joint for ROS and MoveIt), while MuJoCo's, PyBullet's and Drake's own URDF
import leave the joint free: the engines themselves are the oracle here, and modelkit reads it as they
do. The URDF writer writes such a limit back as it was; the MJCF's hinge is free, not locked by an
equality (it was: Genesis's ANYmal C, whose twelve leg joints all have such a limit, got locked legs
and no actuator; example-robot-data's Centauro and quadruped have four each)."""

from __future__ import annotations

from pathlib import Path

import pytest

from modelkit.api import validate

JOINT = """<robot name="r">
  <link name="a"><inertial><mass value="1"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/>
  </inertial></link>
  <link name="b"><inertial><origin xyz="0.3 0 0"/><mass value="1"/>
    <inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
  <joint name="j" type="{kind}"><parent link="a"/><child link="b"/><axis xyz="0 1 0"/>{limit}</joint>
</robot>
"""
BARE = '<limit effort="80" velocity="20"/>'


def _file(tmp_path: Path, kind: str = "revolute", limit: str = BARE) -> Path:
    path = tmp_path / f"{kind}.urdf"
    path.write_text(JOINT.format(kind=kind, limit=limit))
    return path


def test_a_limit_without_a_range_is_said(tmp_path: Path) -> None:
    found = [d for d in validate(_file(tmp_path)).diagnostics if d.code == "MK125"]
    assert len(found) == 1 and found[0].location is not None and found[0].location.line == 6
    robot = validate(_file(tmp_path)).robots[0]
    assert not robot.joints[0].limits.position_limited  # the simulators' reading, not urdfdom's 0 and 0
    assert [d for d in validate(_file(tmp_path, "prismatic")).diagnostics if d.code == "MK125"]


@pytest.mark.parametrize("limit", ['<limit lower="-1" upper="1" effort="80" velocity="20"/>',
                                   '<limit lower="0" upper="0" effort="80" velocity="20"/>'])
def test_a_given_range_or_a_continuous_joint_is_not(tmp_path: Path, limit: str) -> None:
    assert not [d for d in validate(_file(tmp_path, limit=limit)).diagnostics if d.code == "MK125"]
    assert not [d for d in validate(_file(tmp_path, "continuous")).diagnostics if d.code == "MK125"]


def test_the_engines_leave_such_a_joint_free(tmp_path: Path) -> None:
    """What the message says of MuJoCo and PyBullet, measured: gravity swings the joint in both."""
    mujoco = pytest.importorskip("mujoco")
    pybullet = pytest.importorskip("pybullet")
    path = _file(tmp_path)
    m = mujoco.MjModel.from_xml_path(str(path))
    d = mujoco.MjData(m)
    assert not m.jnt_limited[0]
    for _ in range(200):
        mujoco.mj_step(m, d)
    assert abs(d.qpos[0]) > 0.1
    client = pybullet.connect(pybullet.DIRECT)
    try:
        pybullet.setGravity(0, 0, -9.81, physicsClientId=client)
        body = pybullet.loadURDF(str(path), useFixedBase=True, physicsClientId=client)
        pybullet.setJointMotorControl2(body, 0, pybullet.VELOCITY_CONTROL, force=0, physicsClientId=client)
        for _ in range(240):
            pybullet.stepSimulation(physicsClientId=client)
        assert abs(pybullet.getJointState(body, 0, physicsClientId=client)[0]) > 0.1
    finally:
        pybullet.disconnect(physicsClientId=client)


def test_written_back_as_it_was_and_free_in_the_mjcf(tmp_path: Path) -> None:
    from click.testing import CliRunner
    from lxml import etree

    from modelkit.cli import main

    source = _file(tmp_path)
    for suffix in ("urdf", "xml"):
        out = tmp_path / "out" / f"r.{suffix}"
        result = CliRunner().invoke(main, ["convert", str(source), "-o", str(out)])
        assert result.exit_code == 0, result.output
    joint = etree.parse(str(tmp_path / "out" / "r.urdf")).find("joint")
    assert joint is not None and joint.get("type") == "revolute"
    limit = joint.find("limit")
    assert limit is not None and limit.get("lower") is None and limit.get("upper") is None
    mjcf = etree.parse(str(tmp_path / "out" / "r.xml"))
    hinge = mjcf.find(".//joint[@name='j']")
    assert hinge is not None and hinge.get("range") is None
    assert mjcf.find("equality") is None  # not held by a joint equality


def test_verify_passes_in_every_engine(tmp_path: Path) -> None:
    """MuJoCo, PyBullet, Drake (URDF and SDF) and yourdfpy (no bound given: none) all agree with the
    model's reading."""
    from modelkit.verify.api import verify

    report = verify(_file(tmp_path), tmp_path / "out", replay=False, driven=False)
    assert not report.errors, report.errors
    assert [c for c in report.checks if not c.passed] == []
    assert {c.engine for c in report.checks if c.quantity == "limits"} >= {"mujoco", "pybullet", "yourdfpy"}
