"""Layer 4 on the tracked tutorial robot (``mobile_robot_tracks.body``), real MuJoCo and PyBullet.

What is checked: the graded straight profile passes at verification.md's tolerances for the reasons
the modules state (the no-slip reference models the bounded velocity servo and its start-up ramp;
MuJoCo's servo gain is below the explicit-stability limit of a clamped actuator; PyBullet couples
each track's rollers like the belt), and each of those causes, undone, is measurably what broke it.
"""

from __future__ import annotations

import dataclasses
import math
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
    assert model.servo_limit == pytest.approx(0.5 * mass * 9.81 * 1.0 * 0.06 / 4, rel=1e-12)
    ref = noslip(model, _straight(scenario), scenario, drive)
    accel = 4 * model.servo_limit / model.radius / model.m_eff
    t_ramp = 0.5 / accel
    v = np.diff(ref.x) / np.diff(ref.t)
    early = ref.t[1:] < 0.8 * t_ramp
    assert np.allclose(np.diff(v[early]) / 0.01, accel, rtol=1e-3)
    assert np.allclose(v[ref.t[1:] > t_ramp + 0.02], 0.5, atol=1e-9)
    # the lag behind the ideal servo is v·t_ramp/2 (2.6 cm here: more than the 1.5 cm tolerance)
    lag = 0.5 * ref.t[-1] - ref.x[-1]
    assert lag == pytest.approx(0.5 * t_ramp / 2, rel=2e-2)
    assert lag > scenario.tolerances.noslip_position


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


TRACKS_OPEN = ("open (issue 16 item 3, tracks): layer 4 now drives the written cylinder rollers with "
               "MuJoCo's default contact and the file's impratio 0.03 instead of sphere proxies on a stiff "
               "floor")


@pytest.mark.xfail(strict=True, reason=TRACKS_OPEN + "; measured: the path is 6.0 mm from the rollers' own "
                   "odometry after 3 s (bound 1 mm; the graded noslip-position is 0.85 mm of 15)")
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


@pytest.mark.xfail(strict=True, reason=TRACKS_OPEN + "; measured: kv 100 now ends 2.5 mm behind the "
                   "reference (was 2+ mm ahead): the soft contact's smaller rolling radius masks the chatter")
def test_stiff_mujoco_servo_chatters(robot, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    """kv 100 (the former gain, above 2·J/dt): the clamped servo chatters, the robot runs fast."""
    _, prepared, scenario, drive = robot
    profile = _straight(scenario, 3.0)
    ref = noslip(planar_model(prepared, drive), profile, scenario, drive)
    mj, _ = _engines(robot, tmp_path, profile, kv=100.0)
    excess = mj.x[-1] - ref.x[-1]
    assert excess > 2e-3  # 0.24 % fast: 1.2 cm over 10 s


def test_turning_is_report_only_and_said(robot, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    source, prepared, scenario, drive = robot
    spin = Profile("spin", 2.0, (Command(0.0, 0.0, 1.0),))
    result = layer4.run(
        source, drive, dataclasses.replace(scenario, profiles=(spin,), native_report=False), tmp_path,
        prepared=prepared,
    )
    assert not result.checks  # turning tracked profiles are not graded (yet) ...
    said = "turning profiles (spin, arc) are NOT graded"
    assert any(said in s.reason for s in result.skips)  # ... and said
    pair = [o for o in result.observations if o.engine == "mujoco~pybullet" and o.quantity == "path-yaw"]
    assert pair and math.isfinite(pair[0].value)  # reported
