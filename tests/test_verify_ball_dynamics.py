"""Layer 3 on a model with ball joints.

3a: MuJoCo gives its mass matrix and bias in the coordinates of the URDF writer's chain (Tᵀ·M·T, T the
chain's Jacobian at the sampled orientation, the ball at rest), so a model whose only moving joints
are balls is compared with the Pinocchio reference; before, its layer 3 was skipped.

3b: MuJoCo integrates a ball as a quaternion, PyBullet the URDF writer's chain of three joints (MK813)
by their angles, so the same robot parts by O(dt) between the engines. The replay runs the step
ladder (dt, dt/2, dt/4, dt/8) and grades the difference extrapolated to dt → 0: a sound conversion
passes near round-off, a mass 0.01 % off in one file fails. Before, the replay was skipped for any
model with a ball joint."""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import jsonschema
import numpy as np
import pytest

import modelkit
from modelkit.convert.api import convert
from modelkit.verify.api import verify
from modelkit.verify.engines import ball_law
from modelkit.verify.engines.protocol import Check
from modelkit.verify.layers.replay import TOLERANCE, default_law, richardson
from modelkit.verify.report import VerifyReport, report_json
from modelkit.verify.report.html import render_html

BALLS = """<mujoco model="balls"><default><geom type="capsule" size=".01"/><joint type="ball" damping=".005"/>
  </default><worldbody><body name="body1"><geom fromto="0 0 0 0 0 .1"/>
  <body name="body2" pos="0 0 .1"><geom fromto="0 0 0 0 .1 .1"/><joint name="joint_1"/>
  <body name="body3" pos="0 .1 .1"><geom fromto="0 0 0 0 .1 0"/><joint name="joint_2"/>
  </body></body></body></worldbody></mujoco>"""
SCHEMA = json.loads((Path(__file__).parents[1] / "schemas" / "verify-report.schema.json").read_text())


def _source(tmp_path: Path) -> Path:
    source = tmp_path / "balls.xml"
    source.write_text(BALLS)
    return source


def _replay(report: VerifyReport) -> Check:
    (check,) = [c for c in report.checks if c.quantity == "replay"]
    return check


@pytest.fixture(scope="module")
def sound(tmp_path_factory: pytest.TempPathFactory) -> VerifyReport:
    tmp = tmp_path_factory.mktemp("balls")
    return verify(_source(tmp), tmp / "out", ("mujoco", "pybullet", "pinocchio"), configurations=1, samples=1,
                  driven=False)


def test_a_sound_two_ball_chain_passes_the_step_ladder(sound: VerifyReport) -> None:
    assert sound.failed == [], [c.detail for c in sound.failed]
    check = _replay(sound)
    record = sound.replay["pybullet"]
    assert check.passed and check.engine == "pybullet" and "step ladder" in check.detail
    # at one time step the two schemes part far beyond round-off: a strict 1e-8 there would fail it
    assert record["difference_at_dt"] > 1e-5, record
    # extrapolated to dt → 0 the same robot agrees to near round-off, within the floor of 1e-8
    assert record["largest_error"] < 1e-9 and check.tolerance == TOLERANCE, record
    assert record["time_steps"] == [1e-3, 5e-4, 2.5e-4, 1.25e-4]
    assert check.where.startswith(("joint_1#", "joint_2#"))
    said = [s.reason for s in sound.skips if s.layer == 3 and "PyBullet's chains (MK813)" in s.reason]
    assert said and "zeroed in PyBullet" in said[0]
    assert not [s for s in sound.skips if "layer 3b (replay) not run" in s.reason]
    data = json.loads(report_json(sound))
    jsonschema.validate(data, SCHEMA)
    assert data["replay"]["pybullet"]["method"] == "step ladder"
    assert "the step ladder" in render_html(sound)


def test_layer3a_compares_the_balls_in_the_chain_coordinates(sound: VerifyReport) -> None:
    layer3 = {(c.engine, c.quantity): c for c in sound.checks if c.layer == 3 and c.quantity != "replay"}
    for engine in ("mujoco", "pybullet"):
        for quantity in ("mass-matrix", "bias"):
            check = layer3[(engine, quantity)]
            assert check.passed and check.error < 1e-12, (engine, quantity, check.detail)
    mujoco = layer3[("mujoco", "mass-matrix")]
    assert "6 dofs" in mujoco.detail and "three angles" in mujoco.detail
    assert mujoco.where.startswith(("joint_1#", "joint_2#"))


def _body3_heavier(source: Path, given: Path, factor: float) -> Path:
    """``convert``'s file ``given`` (its suffix picks the format) with body3's mass times ``factor``."""
    convert([source], given)
    text = given.read_text()
    start = text.index('<body name="body3"' if given.suffix == ".xml" else '<link name="body3"')
    found = re.compile(r'mass(?:="| value=")([^"]+)"').search(text, start)
    assert found is not None
    heavier = found[0].replace(found[1], repr(float(found[1]) * factor))
    given.write_text(text[:found.start()] + heavier + text[found.end():])
    return given


def test_layer3a_finds_a_ball_link_mass_written_wrong_in_the_mjcf(tmp_path: Path) -> None:
    """body3's mass 10 % heavier in the MJCF MuJoCo reads: its ball rows of the mass matrix differ."""
    source = _source(tmp_path)
    given = _body3_heavier(source, tmp_path / "given" / "balls.xml", 1.1)
    report = verify(source, tmp_path / "out", ("mujoco", "pinocchio"), mjcf=given, configurations=1,
                    samples=2, replay=False, driven=False)
    failed = {(c.layer, c.engine, c.quantity): c for c in report.failed}
    assert (3, "mujoco", "mass-matrix") in failed, sorted(failed)
    assert failed[(3, "mujoco", "mass-matrix")].where.startswith(("joint_1#", "joint_2#"))


def test_a_mass_off_in_the_urdf_alone_fails_the_ladder(tmp_path: Path) -> None:
    """body3's mass 0.01 % heavier in the URDF PyBullet reads (MuJoCo's file sound)."""
    source = _source(tmp_path)
    given = _body3_heavier(source, tmp_path / "given" / "balls.urdf", 1.0001)
    report = verify(source, tmp_path / "out", ("mujoco", "pybullet", "pinocchio"), urdf=given,
                    configurations=1, samples=1, driven=False)
    check = _replay(report)
    assert not check.passed, check.detail
    assert check.error > 100 * check.tolerance, check.detail
    assert check.where.startswith(("joint_1#", "joint_2#"))


def test_the_law_drives_each_ball_about_its_three_axes(tmp_path: Path) -> None:
    law = default_law(modelkit.load(_source(tmp_path)))
    assert law.balls == ("joint_1", "joint_2")
    assert law.joints == ("joint_1#x", "joint_1#y", "joint_1#z", "joint_2#x", "joint_2#y", "joint_2#z")
    assert law.ball_columns() == [("joint_1", 0), ("joint_2", 3)]
    assert all(k > 0.0 for k in law.kp) and all(d > 0.0 for d in law.kd)
    assert set(law.phase) == {0.0}  # the target starts at the rest orientation: no step at t = 0
    assert len(set(law.frequency)) == 6


def test_richardson_removes_the_powers_of_dt_and_keeps_a_model_difference() -> None:
    def difference(h: float, offset: float) -> np.ndarray:
        return np.array([[offset + 3.0 * h + 40.0 * h * h - 500.0 * h**3]])

    steps = [1e-3 / 2**k for k in range(4)]
    same, correction = richardson([difference(h, 0.0) for h in steps])
    assert abs(float(same[0, 0])) < 1e-15
    # the last correction removed the dt³ term left at the finest steps: the extrapolation's uncertainty
    assert 1e-10 < abs(float(correction[0, 0])) < 500.0 * steps[1] ** 3
    model, _ = richardson([difference(h, 2e-6) for h in steps])
    assert float(model[0, 0]) == pytest.approx(2e-6, rel=1e-9)


def _matrix(flat: tuple[float, ...]) -> np.ndarray:
    return np.array(flat, dtype=float).reshape(3, 3)


@pytest.mark.parametrize("vector", [(0.3, -0.2, 0.5), (1e-9, 0.0, -2e-9), (0.0, 0.0, 0.0),
                                    (2.0, 1.0, -1.5), (math.pi - 1e-6, 0.0, 0.0), (0.0, 3.1415, 0.0)])
def test_rotation_vector_and_matrix_are_inverse(vector: tuple[float, float, float]) -> None:
    rotation = _matrix(ball_law.rotation_exp(vector))
    assert np.allclose(rotation @ rotation.T, np.eye(3), atol=1e-14)
    assert np.linalg.det(rotation) == pytest.approx(1.0)
    assert np.allclose(ball_law.rotation_log(tuple(rotation.ravel())), vector, atol=1e-8)


def test_the_chain_matches_the_three_joints_and_their_jacobian() -> None:
    a, b, c = 0.4, -0.7, 1.1

    def axis_angle(axis: int, angle: float) -> np.ndarray:
        v = [0.0, 0.0, 0.0]
        v[axis] = angle
        return _matrix(ball_law.rotation_exp(v))

    chain = _matrix(ball_law.chain_matrix(a, b, c))
    assert np.allclose(chain, axis_angle(0, a) @ axis_angle(1, b) @ axis_angle(2, c), atol=1e-15)
    rates = np.array([0.3, -1.2, 0.8])
    h = 1e-7
    moved = _matrix(ball_law.chain_matrix(*(np.array([a, b, c]) + h * rates)))
    spin = chain.T @ (moved - chain) / h
    omega = np.array([spin[2, 1], spin[0, 2], spin[1, 0]])
    jacobian = _matrix(ball_law.chain_jacobian(b, c))
    assert np.allclose(jacobian @ rates, omega, atol=1e-6)
    # the chain's generalised forces are Jᵀ·τ of the ball's torque at the same state
    args = ([0.5, 0.2, 0.1], [0.01, 0.02, 0.03], [0.4, 0.3, 0.2], [0.3, 0.47, 0.64], [0.0, 0.0, 0.0])
    tau = ball_law.ball_torque(ball_law.chain_matrix(a, b, c), jacobian @ rates, 0.37, *args)
    forces = ball_law.chain_torques((a, b, c), tuple(rates), 0.37, *args)
    assert np.allclose(forces, jacobian.T @ np.array(tau), atol=1e-15)


def test_a_quaternion_gives_its_rotation() -> None:
    half = 0.35
    axis = np.array([1.0, -2.0, 0.5]) / np.linalg.norm([1.0, -2.0, 0.5])
    w, (x, y, z) = math.cos(half), math.sin(half) * axis
    rotation = _matrix(ball_law.quaternion_matrix(w, x, y, z))
    assert np.allclose(ball_law.rotation_log(tuple(rotation.ravel())), 2.0 * half * axis, atol=1e-14)


def test_a_ball_s_armature_is_compared_in_the_chain_coordinates(tmp_path: Path) -> None:
    """MuJoCo's ball armature is a rotor inertia per axis of the child's angular velocity: in the
    chain's coordinates it adds a·JᵀJ, not a on the diagonal. MuJoCo's own test model (a ball wheel of
    armature 0.1) failed layer 3a by exactly that (0.0838 against 0.1838) when the reference held none."""
    source = tmp_path / "armature.xml"
    source.write_text(BALLS.replace('<joint type="ball" damping=".005"/>',
                                    '<joint type="ball" damping=".005" armature=".1"/>'))
    report = verify(source, None, ("mujoco", "pinocchio"), configurations=1, samples=3, replay=False,
                    driven=False)
    layer3 = {c.quantity: c for c in report.checks if c.layer == 3 and c.engine == "mujoco"}
    for quantity in ("mass-matrix", "bias"):
        assert layer3[quantity].passed and layer3[quantity].error < 1e-12, layer3[quantity].detail


def test_a_ball_s_armature_is_left_out_of_the_reference_for_urdf_and_sdf(tmp_path: Path) -> None:
    """URDF and SDF cannot hold armature (MK820), so the engines reading them are compared with the
    reference without it: a ball's a·JᵀJ included. It was kept for balls, and robotblockset's TIAGo base
    (casters on balls of armature 5) failed Drake's layer 3a by 5 (M 1.2e-5 against 5.00001)."""
    source = tmp_path / "armature.xml"
    source.write_text(BALLS.replace('<joint type="ball" damping=".005"/>',
                                    '<joint type="ball" damping=".005" armature="5"/>'))
    report = verify(source, tmp_path / "out", ("mujoco", "pybullet", "drake", "pinocchio"), configurations=1,
                    samples=3, replay=False, driven=False)
    for engine in ("mujoco", "pybullet", "drake"):
        (check,) = [c for c in report.checks if c.layer == 3 and c.engine == engine
                    and c.quantity == "mass-matrix"]
        assert check.passed and check.error < 1e-9, (engine, check.detail)
