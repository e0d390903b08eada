"""A ball joint written to URDF is three continuous joints through two added links (MK813). Verify
compares the engines reading that URDF with the source holding the same chains, so a sound conversion
passes (dm_control's model_with_ball_joints.xml failed link-set and joint-type for PyBullet, yourdfpy
and drake-urdf), while a chain written wrong still fails. The added links carry the URDF writer's tiny
inertial: without one PyBullet gave each of them 1 kg, four times this robot's mass."""

from __future__ import annotations

from pathlib import Path

import pybullet
import pytest

from modelkit.convert.api import convert
from modelkit.verify.api import verify

BALLS = """<mujoco model="balls"><default><geom type="capsule" size=".01"/><joint type="ball" damping=".005"/>
  </default><worldbody><body name="body1"><geom fromto="0 0 0 0 0 .1"/>
  <body name="body2" pos="0 0 .1"><geom fromto="0 0 0 0 .1 .1"/><joint name="joint_1"/>
  <body name="body3" pos="0 .1 .1"><geom fromto="0 0 0 0 .1 0"/><joint name="joint_2"/>
  </body></body></body></worldbody></mujoco>"""

URDF_ENGINES = ("pybullet", "yourdfpy")


def _source(tmp_path: Path) -> Path:
    source = tmp_path / "balls.xml"
    source.write_text(BALLS)
    return source


def _layer1(report, engine: str) -> dict[str, object]:
    return {c.quantity: c for c in report.checks if c.layer == 1 and c.engine == engine}


def test_a_sound_ball_conversion_passes_layer_1_in_the_urdf_engines(tmp_path: Path) -> None:
    report = verify(_source(tmp_path), tmp_path / "out", ("mujoco", *URDF_ENGINES), configurations=2,
                    samples=1, replay=False, driven=False)
    for engine in URDF_ENGINES:
        checks = _layer1(report, engine)
        for quantity in ("link-set", "joint-set", "joint-type", "axis", "mass", "inertia"):
            assert checks[quantity].passed, (engine, checks[quantity].detail)
        said = [s.reason for s in report.skips if s.engine == engine and "ball joint(s)" in s.reason]
        chain = "joint_1 as joint_1_x, joint_1_y, joint_1_z through body2_ball_x, body2_ball_y"
        assert said and chain in said[0]
    assert not [s for s in report.skips if s.engine == "mujoco" and "ball joint(s)" in s.reason]
    # the balls' dynamics are compared (with Pinocchio, not loaded here: test_verify_ball_dynamics.py)
    layer3 = [s.reason for s in report.skips if s.layer == 3]
    assert layer3 and "needs Pinocchio" in layer3[0] and "nothing moves" not in layer3[0]


@pytest.mark.parametrize("engine", URDF_ENGINES)
@pytest.mark.parametrize(("fault", "quantity", "where"), [("axis:joint_1_y:flip", "axis", "joint_1_y"),
                                                         ("mass:body2_ball_x:50%", "mass", "body2_ball_x")])
def test_a_chain_written_wrong_fails(tmp_path: Path, engine: str, fault: str, quantity: str,
                                     where: str) -> None:
    report = verify(_source(tmp_path), tmp_path / "out", (engine,), inject=[fault], configurations=2,
                    samples=1, replay=False, driven=False)
    assert report.injected and report.injected[0].startswith(fault)
    check = _layer1(report, engine)[quantity]
    assert not check.passed and check.where == where, check.detail


def test_pybullet_holds_the_source_mass(tmp_path: Path) -> None:
    """The added links weigh 1e-6 kg each in PyBullet, not its 1 kg default for a link without mass."""
    urdf = tmp_path / "balls.urdf"
    convert([_source(tmp_path)], urdf)
    client = pybullet.connect(pybullet.DIRECT)
    try:
        body = pybullet.loadURDF(str(urdf), physicsClientId=client)
        masses = [pybullet.getDynamicsInfo(body, i, physicsClientId=client)[0]
                  for i in range(-1, pybullet.getNumJoints(body, physicsClientId=client))]
    finally:
        pybullet.disconnect(client)
    assert sum(masses) == pytest.approx(0.0356047167406843 * 2 + 0.0486176195863701 + 4e-6, rel=1e-6)


def test_layer2_turns_the_ball_joints_in_every_engine(tmp_path: Path) -> None:
    """Layer 2 held ball joints at zero. Now each configuration turns them by three angles about X, Y
    and Z (``NAME#x``...): MuJoCo and Drake turn their ball joint, the URDF engines the writer's chain."""
    import modelkit
    from modelkit.verify.layers.kinematics import configurations

    robot = modelkit.load(_source(tmp_path))
    configs = configurations(robot, 3, 0)
    assert {"joint_1#x", "joint_1#y", "joint_1#z", "joint_2#z"} <= set(configs[1])
    turned = robot.world_poses(configs[1])["body3"].rotation
    assert abs(turned - robot.world_poses()["body3"].rotation).max() > 0.1  # the reference moves it
    report = verify(_source(tmp_path), tmp_path / "out", ("mujoco", "drake", *URDF_ENGINES), configurations=5,
                    samples=1, replay=False, driven=False)
    layer2 = [c for c in report.checks if c.layer == 2]
    assert {c.engine for c in layer2} == {"mujoco", "drake", *URDF_ENGINES}
    assert all(c.passed and "held at zero" not in c.detail for c in layer2), layer2


def test_layer2_finds_a_chain_axis_written_wrong(tmp_path: Path) -> None:
    """With the ball held at zero, a flipped chain axis changed no pose: only layer 1 saw it."""
    report = verify(_source(tmp_path), tmp_path / "out", ("pybullet",), configurations=5, samples=1,
                    replay=False, driven=False, inject=["axis:joint_1_y:flip"])
    assert not report.errors, report.errors
    failed = {(c.layer, c.engine, c.quantity) for c in report.checks if not c.passed}
    assert (2, "pybullet", "pose-rotation") in failed


def test_a_given_urdf_from_convert_is_graded_with_its_chains(tmp_path: Path) -> None:
    """``--urdf`` with the file ``convert`` wrote by default (a ``world`` link welds the root; each ball
    a chain): the chains are read from the conversion staged in memory, so layers 1 and 2 grade the file
    as they grade verify's own URDF, and a flipped chain axis in it still fails. Before, PyBullet and
    yourdfpy failed link-set and joint-type on the chain links and layer 2 held the balls at zero."""
    source = _source(tmp_path)
    given = tmp_path / "given" / "balls.urdf"
    convert([source], given)
    assert '<link name="world"' in given.read_text()
    report = verify(source, tmp_path / "out", ("mujoco", *URDF_ENGINES), urdf=given, configurations=5,
                    samples=1, replay=False, driven=False)
    assert not report.errors, report.errors
    assert [c for c in report.checks if not c.passed] == []
    layer2 = [c for c in report.checks if c.layer == 2 and c.engine in URDF_ENGINES]
    assert {c.engine for c in layer2} == set(URDF_ENGINES)
    assert all("held at zero" not in c.detail for c in layer2)
    faulty = verify(source, tmp_path / "out2", ("pybullet",), urdf=given, configurations=5, samples=1,
                    replay=False, driven=False, inject=["axis:joint_1_y:flip"])
    assert (2, "pybullet", "pose-rotation") in {(c.layer, c.engine, c.quantity) for c in faulty.failed}


MIXED = """<mujoco model="mixed"><default><geom type="capsule" size=".01"/></default><worldbody>
  <body name="body1"><geom fromto="0 0 0 0 0 .1"/>
  <body name="body2" pos="0 0 .1"><geom fromto="0 0 0 0 .1 .1"/>
    <joint name="joint_1" type="ball" damping=".005"/>
  <body name="body3" pos="0 .1 .1"><geom fromto="0 0 0 0 .1 0"/>
    <joint name="hinge" type="hinge" axis="1 0 0"/>
  </body></body></body></worldbody></mujoco>"""


def _mixed(tmp_path: Path) -> Path:
    source = tmp_path / "mixed.xml"
    source.write_text(MIXED)
    return source


def test_layer3_compares_a_model_with_a_ball_and_a_hinge(tmp_path: Path) -> None:
    """A ball joint above a hinge: the Pinocchio reference holds the ball as three revolute joints at
    each sampled orientation, at rest. MuJoCo and Drake (SDF) hold a ball and compare it in the chain's
    coordinates with the hinge (before, Drake compared the hinge's degree of freedom only); PyBullet and
    Drake's URDF hold the writer's chain and compare its three joints too. Before, the Pinocchio
    reference refused the ball, layer 3a was skipped for every engine, and the replay failed on a sound
    model (MuJoCo asked for the chain's links); then it was skipped."""
    engines = ("mujoco", "pybullet", "drake", "drake-urdf", "pinocchio")
    report = verify(_mixed(tmp_path), tmp_path / "out", engines, configurations=2, samples=3, driven=False)
    assert not report.errors, report.errors
    assert report.failed == [], [c.detail for c in report.failed]
    layer3 = {(c.engine, c.quantity): c for c in report.checks if c.layer == 3}
    for engine in ("mujoco", "pybullet", "drake", "drake-urdf"):
        for quantity in ("mass-matrix", "bias"):
            check = layer3[(engine, quantity)]
            assert check.passed and check.error < 1e-12, (engine, quantity, check.detail)
    # MuJoCo and Drake (SDF) compare the hinge and the ball's three angles (in the URDF chain's
    # coordinates): MuJoCo's ball velocity is ω in the child's frame, Drake's BallRpyJoint's ω in the parent's
    for engine in ("mujoco", "drake"):
        assert "4 dofs" in layer3[(engine, "mass-matrix")].detail
        assert "three angles" in layer3[(engine, "mass-matrix")].detail
    assert not [s.reason for s in report.skips if s.layer == 3 and s.engine == "drake"]
    # the replay drives the ball and the hinge, graded by the step ladder (test_verify_ball_dynamics.py)
    (replay,) = [c for c in report.checks if c.quantity == "replay"]
    assert replay.passed and "step ladder" in replay.detail
    assert "hinge" in replay.detail and "joint_1#x" in replay.detail


def test_layer3_with_a_ball_finds_a_mass_written_wrong(tmp_path: Path) -> None:
    report = verify(_mixed(tmp_path), tmp_path / "out", ("mujoco", "pybullet", "pinocchio"), configurations=2,
                    samples=3, driven=False, inject=["mass:body3:10%"])
    failed = {(c.layer, c.engine, c.quantity): c for c in report.failed}
    for engine in ("mujoco", "pybullet"):
        assert (3, engine, "mass-matrix") in failed, sorted(failed)
    assert failed[(3, "mujoco", "mass-matrix")].where in ("hinge", "joint_1#x", "joint_1#y", "joint_1#z")
    assert failed[(3, "pybullet", "mass-matrix")].where in ("hinge", "joint_1_x", "joint_1_y", "joint_1")
