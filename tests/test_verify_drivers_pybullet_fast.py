"""PyBullet's layer-4 driver with the seed's affine laws applied by Bullet (``fast``: ``−gain·q̇`` as the
law joints' ``jointDamping``, the offset torque re-sent every step, velocity targets at command changes,
states read at samples only) against the same driver calling the controllers' ``output`` before every
``stepSimulation``: the same physics to round-off (≤ 1e-9 m / rad over 10 s), on the real engine in
its child process (no mocks); and layer 4's results unchanged by it."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import modelkit
from modelkit.verify.drive import Command, Drive, Scenario, controllers, variant
from modelkit.verify.engines import pybullet as engine_pybullet
from tests.drivers_support import (
    DRIVE,
    PANTILT,
    PROFILES,
    ROUND_OFF,
    TRACKS,
    assert_same_layer4,
    run_difference,
)

# The floor of these comparisons: an analytic plane, not layer 4's plane.urdf, whose box–sphere contact
# amplifies a one-ulp torque difference to 1e-5 m over 10 s (engine_pybullet.ANALYTIC_FLOOR); what is
# compared here is the control path, the same on either floor.
ANALYTIC = engine_pybullet.ANALYTIC_FLOOR

# where the child process finds this module (for the factories below): "tests.x" or "x"
HERE = [str(Path(__file__).resolve().parents[__name__.count(".")])]


def _pair(files: dict[str, Path], maps: dict[str, Any], drive: Drive, scenario: Scenario, **kw: Any
          ) -> tuple[engine_pybullet.PyBulletDriver, engine_pybullet.PyBulletDriver]:
    fast = engine_pybullet.driver(files["urdf"], maps["urdf"], drive=drive, scenario=scenario,
                                  floor=ANALYTIC, **kw)
    try:
        slow = engine_pybullet.driver(files["urdf"], maps["urdf"], drive=drive, scenario=scenario,
                                      floor=ANALYTIC, fast=False,
                                      **kw)
    except BaseException:
        fast.close()
        raise
    return fast, slow


@pytest.fixture(scope="module")
def pantilt() -> Any:
    return modelkit.load(PANTILT)


@pytest.fixture(scope="module")
def pantilt_files(pantilt: Any, tmp_path_factory: pytest.TempPathFactory) -> Any:
    scenario = Scenario(profiles=PROFILES, controller="drive")
    return variant.write_variant(pantilt, DRIVE, scenario, tmp_path_factory.mktemp("pbfast"), "sphere")


def test_drive_law_as_joint_damping_equals_the_python_law_every_step(pantilt_files: Any) -> None:
    """The drive and pan-tilt controllers: straight, arc (pan and tilt moving) and steps (a command
    change between two samples). Measured 1.4e-13 / 1.1e-13 / 6.8e-14: Bullet's joint damping is the
    explicit ``−d·q̇`` from the step's starting velocity, the same torque the per-step law sends."""
    files, maps = pantilt_files
    scenario = Scenario(profiles=PROFILES, controller="drive")
    fast, slow = _pair(files, maps, DRIVE, scenario)
    try:
        assert "jointDamping" in fast.settings["control"] and "per step" in slow.settings["control"]
        assert "controller's gain" in fast.settings["damping"] and "gain" not in slow.settings["damping"]
        for profile in PROFILES:
            a, b = fast.run(profile, scenario, DRIVE), slow.run(profile, scenario, DRIVE)
            assert fast.last_law == ["bullet"] and slow.last_law == ["per-step"]
            largest = run_difference(a, b)
            print(profile.name, f"{largest:.3g}",
                  f"fast {fast.last_wall[0]:.3f} s, per step {slow.last_wall[0]:.3f} s")
            assert largest <= ROUND_OFF, (profile.name, largest)
            # the run moved: the pan joint followed its command, the robot drove
            path = float(np.hypot(np.diff(a.x), np.diff(a.y)).sum())
            assert abs(a.joints["PanJoint"][300]) > 0.3 and path > 1.0
    finally:
        fast.close()
        slow.close()


def _tester_nudged(drive: dict[str, Any], scenario: dict[str, Any]) -> list[Any]:
    """The seed's controllers with the drive tester's torque one ulp above the scenario's."""
    torque = math.nextafter(float(scenario.get("tester_torque", 1.0)), math.inf)
    return controllers.make_controllers(drive, {**scenario, "tester_torque": torque})


def test_drive_tester_equal_until_its_wheels_spin_out(pantilt_files: Any) -> None:
    """The drive tester (1 N·m on each wheel whatever the command, pan/tilt law as damping). The two
    paths stay within 1e-13 until the wheels spin out (≈ 2.1 s: a wheel reaches PyBullet's 100 rad/s
    joint speed clamp and the robot whirls, yaw −37 rad after 10 s); from there on the motion is
    chaotic: the per-step path with the tester torque one ulp (2.2e-16) larger departs from the
    per-step path by more than the fast path does (largest position/yaw/angle difference over 10 s:
    measured 0.32 against 0.19; asserted: not more than twice the one-ulp departure). So the fast path
    is round-off here too; this profile is not one layer 4 grades."""
    files, maps = pantilt_files
    scenario = Scenario(profiles=PROFILES[:1], controller="drive-tester")
    fast, slow = _pair(files, maps, DRIVE, scenario)
    nudged = engine_pybullet.driver(files["urdf"], maps["urdf"], drive=DRIVE, scenario=scenario,
                                    floor=ANALYTIC, fast=False,
                                    factory=f"{__name__}:_tester_nudged",
                                    sys_path=HERE)
    try:
        profile = PROFILES[0]
        a, b, c = (d.run(profile, scenario, DRIVE) for d in (fast, slow, nudged))
        assert fast.last_law == ["bullet"]
        early = run_difference(a, b, until=201)  # samples up to 2.0 s
        print("tester to 2 s", early, "10 s: fast", run_difference(a, b), "one ulp", run_difference(c, b))
        assert early <= ROUND_OFF
        assert 0.0 < run_difference(a, b) <= 2.0 * run_difference(c, b)
    finally:
        for d in (fast, slow, nudged):
            d.close()


def test_tracks_velocity_targets_at_command_changes(tmp_path: Path) -> None:
    """The tracked robot (track controller in velocity mode, pan-tilt law as damping, belts as gear
    constraints): with pan and tilt still the velocity motor is set once per command and nothing is
    sent per step: bit-identical to re-sending the same target every step. With them moving, straight
    (the tracked robot's graded profile) within round-off."""
    from modelkit.verify.drive import vehicle
    from modelkit.verify.drive.scenario import default_scenario

    robot = modelkit.load(TRACKS)
    drive = vehicle.find_drive(robot, default_scenario("tracks", True))
    scenario = dataclasses.replace(default_scenario("tracks", drive.pan is not None), controller="track")
    files, maps = variant.write_variant(robot, drive, scenario, tmp_path, "sphere")
    fast, slow = _pair(files, maps, drive, scenario)
    try:
        for profile in scenario.profiles:
            still = dataclasses.replace(profile, commands=tuple(dataclasses.replace(c, pan=0.0, tilt=0.0)
                                                                for c in profile.commands))
            exact = run_difference(fast.run(still, scenario, drive), slow.run(still, scenario, drive))
            assert fast.last_law == ["bullet"]
            print("tracks still", profile.name, exact, fast.last_wall, slow.last_wall)
            assert exact == 0.0, (profile.name, exact)
            if profile.name == "straight":
                largest = run_difference(fast.run(profile, scenario, drive),
                                         slow.run(profile, scenario, drive))
                print("tracks", profile.name, largest)
                assert largest <= ROUND_OFF, (profile.name, largest)
    finally:
        fast.close()
        slow.close()


def test_a_controller_without_an_affine_law_runs_per_step(pantilt_files: Any) -> None:
    files, maps = pantilt_files
    scenario = Scenario(profiles=PROFILES[1:2], controller="drive")
    wrapped = engine_pybullet.driver(files["urdf"], maps["urdf"], drive=DRIVE, scenario=scenario,
                                     floor=ANALYTIC,
                                     factory="tests.drivers_support:no_affine_law",
                                     sys_path=HERE)
    slow = engine_pybullet.driver(files["urdf"], maps["urdf"], drive=DRIVE, scenario=scenario,
                                  floor=ANALYTIC, fast=False)
    try:
        a = wrapped.run(PROFILES[1], scenario, DRIVE)
        assert wrapped.last_law == ["per-step"] and "per step" in a.settings["control"]
        assert run_difference(a, slow.run(PROFILES[1], scenario, DRIVE)) == 0.0  # the very same computation
    finally:
        wrapped.close()
        slow.close()


def _offsets_only(drive: dict[str, Any], scenario: dict[str, Any]) -> list[Any]:
    """The seed's controllers claiming the law ``output = offset`` (gain 0): the fast path then sends
    the offsets and leaves every joint's damping at 0."""

    class OffsetOnly:
        def __init__(self, inner: Any) -> None:
            self.inner, self.name, self.joints, self.mode = inner, inner.name, inner.joints, inner.mode

        def output(self, t: float, command: Command, q: Any, dq: Any) -> Any:
            return self.inner.output(t, command, q, dq)

        def affine_law(self, command: Command) -> tuple[Any, Any]:
            offset, gain = self.inner.affine_law(command)
            return offset, np.zeros_like(gain)

    return [OffsetOnly(c) for c in controllers.make_controllers(drive, scenario)]


def test_the_damping_half_of_the_law_matters(pantilt_files: Any) -> None:
    """Sharpness: the fast path with the offsets alone (no joint damping) lands far from the per-step
    law, so the agreement above is the joint damping's doing (measured: the robot runs off, metres)."""
    files, maps = pantilt_files
    scenario = Scenario(profiles=PROFILES[:1], controller="drive")
    offsets = engine_pybullet.driver(files["urdf"], maps["urdf"], drive=DRIVE, scenario=scenario,
                                     floor=ANALYTIC,
                                     factory=f"{__name__}:_offsets_only",
                                     sys_path=HERE)
    slow = engine_pybullet.driver(files["urdf"], maps["urdf"], drive=DRIVE, scenario=scenario,
                                  floor=ANALYTIC, fast=False)
    try:
        a, b = offsets.run(PROFILES[0], scenario, DRIVE), slow.run(PROFILES[0], scenario, DRIVE)
        assert offsets.last_law == ["bullet"]
        print("offsets only vs the law", run_difference(a, b))
        assert run_difference(a, b) > 0.1
    finally:
        offsets.close()
        slow.close()


def per_step_driver(model: Path, renames: Any, *, drive: Drive, scenario: Scenario) -> Any:
    """Layer 4's PyBullet driver with every controller called every step (for the comparison below)."""
    return engine_pybullet.driver(model, renames, drive=drive, scenario=scenario, floor=ANALYTIC, fast=False)


def fast_driver(model: Path, renames: Any, *, drive: Drive, scenario: Scenario) -> Any:
    """Layer 4's PyBullet driver (fast path) on the analytic floor (see ANALYTIC)."""
    return engine_pybullet.driver(model, renames, drive=drive, scenario=scenario, floor=ANALYTIC)


def test_layer4_results_unchanged(pantilt: Any, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Layer 4 (PyBullet, default scenario of the pan-tilt robot, sphere and native variants): every
    check and observation the same to round-off, the same pass/fail, with the fast driver as with the
    per-step one."""
    from modelkit.verify.layers import layer4

    monkeypatch.setitem(layer4.DRIVERS, "pybullet", f"{__name__}:fast_driver")
    runs = assert_same_layer4(pantilt, "pybullet", f"{__name__}:per_step_driver", tmp_path, monkeypatch)
    assert all("jointDamping" in a.settings["control"] for a, _ in runs)
