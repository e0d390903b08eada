"""Layer 4 on the tracked tutorial robot (``mobile_robot_tracks.body``), real MuJoCo and PyBullet.

What is checked: the no-slip reference models the bounded velocity servo and its start-up ramp;
MuJoCo's servo gain is below the explicit-stability limit of a clamped actuator (a stiffer one runs
fast); spin and arc are graded against the skid-steer reference and the written files pass them in
both engines, each engine and the pair within the derived skid tolerance (issue 16 item 3).
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

import modelkit
from modelkit.verify.drive import Command, Profile, variant, vehicle
from modelkit.verify.drive.reference import noslip, planar_model
from modelkit.verify.drive.scenario import default_scenario
from modelkit.verify.layers import layer4

pytest.importorskip("mujoco")
pytest.importorskip("pybullet")

TRACKS = (
    Path(__file__).resolve().parent.parent
    / "samples/choreonoid_ros2_mobile_robot_tutorial/model/mobile_robot_tracks.body"
)


@pytest.fixture(scope="module")
def robot():  # type: ignore[no-untyped-def]
    source = layer4.floating(modelkit.load(TRACKS))
    prepared = vehicle.prepare_tracks(source)
    scenario = default_scenario("tracks", True)
    drive = vehicle.find_drive(source, scenario, prepared)
    return source, prepared, scenario, drive


def _straight(scenario, seconds: float = 2.0) -> Profile:  # type: ignore[no-untyped-def]
    base = next(p for p in scenario.profiles if p.name == "straight")
    return dataclasses.replace(base, duration=seconds)


def test_reference_models_the_servo_start_up(robot) -> None:  # type: ignore[no-untyped-def]
    """The torque-saturated start: acceleration n·τ_max/(r·M_eff), then the target held exactly."""
    _, prepared, scenario, drive = robot
    model = planar_model(prepared, drive)
    assert model.servo_rollers == (2, 2)
    mass = model.mass
    assert model.servo_limit == pytest.approx(
        variant.SERVO_FRICTION_SHARE * mass * 9.81 * 1.0 * 0.06 / 4, rel=1e-12)
    ref = noslip(model, _straight(scenario), scenario, drive)
    accel = 4 * model.servo_limit / model.radius / model.m_eff
    t_ramp = 0.5 / accel
    v = np.diff(ref.x) / np.diff(ref.t)
    early = ref.t[1:] < 0.8 * t_ramp
    assert np.allclose(np.diff(v[early]) / 0.01, accel, rtol=1e-3)
    assert np.allclose(v[ref.t[1:] > t_ramp + 0.02], 0.5, atol=1e-9)
    # the lag behind the ideal servo is v·t_ramp/2 (0.43 cm at the bound of 3 × the friction limit)
    lag = 0.5 * ref.t[-1] - ref.x[-1]
    assert lag == pytest.approx(0.5 * t_ramp / 2, rel=2e-2)


def test_servo_gain_below_the_clamped_stability_limit() -> None:
    kv = variant.servo_gain(17.6, 0.06, 4, 1e-3)
    assert kv == pytest.approx(15.84)
    # explicit velocity loop on J = m r^2 / n: stable for kv·dt/J < 2, here 1
    assert kv * 1e-3 / (17.6 * 0.06**2 / 4) == pytest.approx(1.0)


def _engines(robot, tmp_path: Path, profile: Profile, kv: float | None = None):  # type: ignore[no-untyped-def]
    from modelkit.verify.engines.mujoco import driver as mujoco_driver
    from modelkit.verify.engines.pybullet import driver as pybullet_driver

    source, _, scenario, drive = robot
    files, maps = variant.write_variant(source, drive, scenario, tmp_path, "sphere")
    mj = mujoco_driver(files["mjcf"], maps["mjcf"], drive=drive, scenario=scenario)
    if kv is not None:  # undo the fix: a stiffer servo than J/dt
        servos = [a for a in range(mj.model.nu) if mj.model.actuator_forcelimited[a]
                  and mj.model.actuator_biasprm[a, 2] < 0]
        mj.model.actuator_gainprm[servos, 0] = kv
        mj.model.actuator_biasprm[servos, 2] = -kv
    try:
        got_mj = mj.run(profile, scenario, drive)
    finally:
        mj.close()
    pb = pybullet_driver(files["urdf"], maps["urdf"], drive=drive, scenario=scenario)
    try:
        got_pb = pb.run(profile, scenario, drive)
    finally:
        pb.close()
    return got_mj, got_pb



@pytest.mark.xfail(strict=True, reason="superseded for tracks: the roller servos now impose the belt speed "
                   "(bound 3 x the friction limit, variant.SERVO_FRICTION_SHARE), so a start is "
                   "friction-limited and the belts slip, and the path is not the rollers' odometry; "
                   "layer 4 grades a tracked robot against the skid-steer reference instead (test below)")
def test_straight_engines_match_the_servo_reference(robot, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    _, prepared, scenario, drive = robot
    profile = _straight(scenario, 3.0)
    ref = noslip(planar_model(prepared, drive), profile, scenario, drive)
    mj, pb = _engines(robot, tmp_path, profile)
    tol = scenario.tolerances
    for got in (mj, pb):
        d = layer4.difference(got, ref)
        assert d.position < 0.2 * tol.noslip_position  # measured 0.4 mm (10 s)
        assert d.yaw < 0.1 * tol.noslip_yaw
        # no slip: the path is the rollers' own odometry
        assert abs(got.x[-1] - 0.06 * got.wheels[-1, 0]) < 1e-3
    pair = layer4.difference(mj, pb)
    assert pair.position < 0.2 * tol.engines_position
    assert layer4.wheel_difference(mj, pb)[0] < 0.25 * tol.engines_wheel
    # the start is the servo's ramp in both engines, not a step
    for got in (mj, pb):
        v = np.diff(got.x[:4]) / 0.01
        assert np.all(v < 0.25)


def test_stiff_mujoco_servo_chatters(robot, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    """kv 100 (the former gain, above 2·J/dt): the clamped servo chatters, the robot runs fast."""
    _, prepared, scenario, drive = robot
    profile = _straight(scenario, 3.0)
    ref = noslip(planar_model(prepared, drive), profile, scenario, drive)
    mj, _ = _engines(robot, tmp_path, profile, kv=100.0)
    excess = mj.x[-1] - ref.x[-1]
    assert excess > 2e-3  # measured 2.3 cm ahead over 3 s


def test_turning_is_graded_against_the_skid_reference(robot, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    """A tracked robot's spin is graded (each engine against the skid-steer reference, and the pair)
    at the derived skid tolerance, and the verdict's skip says so."""
    source, prepared, scenario, drive = robot
    spin = Profile("spin", 2.0, (Command(0.0, 0.0, 1.0),))
    result = layer4.run(
        source, drive, dataclasses.replace(scenario, profiles=(spin,), native_report=False), tmp_path,
        prepared=prepared,
    )
    graded = {(c.engine, c.quantity) for c in result.checks}
    for engine in ("mujoco", "pybullet"):
        assert {(engine, "skid-position"), (engine, "skid-yaw")} <= graded
    assert ("mujoco~pybullet", "path-yaw") in graded
    tolerance = result.settings["reference"]["skid_tolerances"]["spin"]
    yaw = next(c for c in result.checks if c.engine == "mujoco" and c.quantity == "skid-yaw")
    assert yaw.tolerance == tolerance["yaw"] > 0.1  # the pressure-distribution spread, not the 15 mrad floor
    # both engines turn the robot (the servo bound lets the belts slip): more than half the reference
    turned = {t.source: t.yaw[-1] for t in result.trajectories if t.profile == "spin"}
    for engine in ("mujoco", "pybullet"):
        assert turned[engine] > 0.5 * turned["skid:rollers"]
    assert any("graded against the skid-steer reference" in s.reason for s in result.skips)


def test_written_files_spin_and_arc_within_the_skid_tolerance(robot, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    """Layer 4 on the files convert writes (unmodified, on a default plane / plane.urdf): the default
    scenario's spin and arc, in both engines, each within the derived skid tolerance of the skid-steer
    reference, the pair within it too, and the roller angles within 0.02 rad (issue 16 item 3)."""
    source, prepared, scenario, drive = robot
    turning = tuple(p for p in scenario.profiles if p.name in ("spin", "arc"))
    result = layer4.run(source, drive, dataclasses.replace(scenario, profiles=turning, native_report=False),
                        tmp_path, prepared=prepared)
    checks = {(c.engine, c.quantity, c.where): c for c in result.checks}
    for where in ("spin", "arc"):
        tolerance = result.settings["reference"]["skid_tolerances"][where]
        for engine in ("mujoco", "pybullet"):
            position, yaw = checks[(engine, "skid-position", where)], checks[(engine, "skid-yaw", where)]
            assert position.tolerance == tolerance["position"] and yaw.tolerance == tolerance["yaw"]
            assert position.passed and yaw.passed, (position.detail, yaw.detail)
        for quantity in ("path-position", "path-yaw", "wheel-angle"):
            pair = checks[("mujoco~pybullet", quantity, where)]
            assert pair.passed, pair.detail
    # measured (docs/verify.md): spin MuJoCo 3.5 cm / 36 mrad, PyBullet 7.2 cm / 899 mrad of
    # 11.2 cm / 1769 mrad; arc MuJoCo 1.8 cm / 27 mrad, PyBullet 33 cm / 419 mrad of 90.4 cm / 870 mrad
    assert not [c.detail for c in result.checks if not c.passed]
