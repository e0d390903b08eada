"""MuJoCo's layer-4 driver with the seed's laws as MuJoCo actuators (``fast``, no Python per physics
step) against the same driver calling the controllers' ``output`` before every ``mj_step``: the same
physics to round-off (≤ 1e-9 m / rad over 10 s), on the real engine (no mocks); and layer 4's
results unchanged by it."""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any

import mujoco
import numpy as np
import pytest

import modelkit
from modelkit.verify.drive import Drive, Scenario, variant
from modelkit.verify.engines import mujoco as engine_mujoco
from tests.drivers_support import (
    DRIVE,
    PANTILT,
    PROFILES,
    ROUND_OFF,
    TRACKS,
    assert_same_layer4,
    run_difference,
)


def _pair(files: dict[str, Path], maps: dict[str, Any], drive: Drive, scenario: Scenario,
          factory: str | None = None) -> tuple[engine_mujoco.MujocoDriver, engine_mujoco.MujocoDriver]:
    fast = engine_mujoco.driver(files["mjcf"], maps["mjcf"], drive=drive, scenario=scenario, factory=factory)
    slow = engine_mujoco.driver(files["mjcf"], maps["mjcf"], drive=drive, scenario=scenario, factory=factory,
                                fast=False)
    return fast, slow


@pytest.fixture(scope="module")
def pantilt() -> Any:
    return modelkit.load(PANTILT)


@pytest.fixture(scope="module")
def pantilt_files(pantilt: Any, tmp_path_factory: pytest.TempPathFactory) -> Any:
    scenario = Scenario(profiles=PROFILES, controller="drive")
    return variant.write_variant(pantilt, DRIVE, scenario, tmp_path_factory.mktemp("fast"), "sphere")


@pytest.mark.parametrize("controller", ["drive", "drive-tester"])
def test_laws_as_actuators_equal_the_python_law_every_step(pantilt_files: Any, controller: str) -> None:
    """Straight, arc (pan and tilt moving) and, for the drive controller, the steps profile. The drive
    tester (1 N·m whatever the command) spins a slipping wheel to 334 rad on "steps", where the two
    paths end 1.2e-9 rad apart (4e-12 relative: the pan/tilt round-off grown by the slip): not a
    10 s profile the brief grades, so it runs the two graded ones."""
    files, maps = pantilt_files
    scenario = Scenario(profiles=PROFILES, controller=controller)  # type: ignore[arg-type]
    fast, slow = _pair(files, maps, DRIVE, scenario)
    assert "mujoco.pid" in fast.settings["control"] and "per step" in slow.settings["control"]
    kd = 0.5 if controller == "drive" else None
    expected = {"PanJoint": 0.1, "TiltJoint": 0.1, **({"LeftWheel": kd, "RightWheel": kd} if kd else {})}
    assert fast.settings["law_actuators"] == expected and slow.settings["law_actuators"] == {}
    assert slow.model.nu == 0 and fast.model.nu == len(expected)
    for profile in PROFILES if controller == "drive" else PROFILES[:2]:
        a, b = fast.run(profile, scenario, DRIVE), slow.run(profile, scenario, DRIVE)
        assert not a.warnings and not b.warnings
        largest = run_difference(a, b)
        print(controller, profile.name, f"{largest:.3g}", f"fast {fast.last_wall:.3f} s, per step "
              f"{slow.last_wall:.3f} s")
        assert largest <= ROUND_OFF, (profile.name, largest)
        # the run moved: the pan joint followed its command, the robot drove
        path = float(np.hypot(np.diff(a.x), np.diff(a.y)).sum())
        assert abs(a.joints["PanJoint"][300]) > 0.3 and path > 1.0
    # between runs the law actuators are inert (gear 0): nothing acts outside a profile
    assert np.all(fast.model.actuator_gear[:, 0] == 0.0)


def test_an_implicit_damping_term_would_not_be_round_off(pantilt_files: Any) -> None:
    """Why a plugin actuator and not a ``general`` one with bias ``-kd·q̇`` (or joint damping): under
    ``implicitfast`` MuJoCo integrates those velocity terms implicitly, a different discretisation from
    the seed's explicit law. The same -kd·q̇ as ``dof_damping`` (integrated like an actuator's kv)
    lands far above round-off from the per-step law, so the agreement above is the plugin's doing."""
    files, maps = pantilt_files
    scenario = Scenario(profiles=PROFILES[:1], controller="drive")
    reference = engine_mujoco.driver(files["mjcf"], maps["mjcf"], drive=DRIVE, scenario=scenario,
                                     fast=False).run(PROFILES[0], scenario, DRIVE)
    implicit = engine_mujoco.driver(files["mjcf"], maps["mjcf"], drive=DRIVE, scenario=scenario)
    m = implicit.model
    assert all(int(m.actuator_plugin[a]) >= 0 for a in implicit._law_actuators)
    for name, gain in implicit.settings["law_actuators"].items():
        m.dof_damping[m.jnt_dofadr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, name)]] = gain
    implicit._law_actuators = np.zeros(0, dtype=int)  # plugins left at gear 0: damping carries -kd·q̇
    largest = run_difference(implicit.run(PROFILES[0], scenario, DRIVE), reference)
    print("implicit damping vs the explicit law", largest)
    assert largest > 1e3 * ROUND_OFF


def test_a_controller_without_an_affine_law_runs_per_step(pantilt_files: Any) -> None:
    files, maps = pantilt_files
    scenario = Scenario(profiles=PROFILES[1:2], controller="drive")
    fast, slow = _pair(files, maps, DRIVE, scenario)
    wrapped = engine_mujoco.driver(files["mjcf"], maps["mjcf"], drive=DRIVE, scenario=scenario,
                                   factory="tests.drivers_support:no_affine_law")
    assert "per step" in wrapped.settings["control"] and wrapped.model.nu == 0
    a = wrapped.run(PROFILES[1], scenario, DRIVE)
    assert run_difference(a, slow.run(PROFILES[1], scenario, DRIVE)) == 0.0  # the very same computation
    assert run_difference(a, fast.run(PROFILES[1], scenario, DRIVE)) <= ROUND_OFF


def test_track_controller_servo_targets_set_at_command_changes(tmp_path: Path) -> None:
    """The tracked robot (it has pan and tilt too): velocity targets into the rollers' servos at
    command changes only, the pan-tilt law as actuators; the servo force bound is the per-roller one
    (the law actuators do not count as rollers) and only the servos are force-limited.

    With pan and tilt still, every default profile is bit-identical (the servo targets are the same
    numbers, and -kd·q̇ lands in the same sum). With them moving, straight (the tracked robot's graded
    profile) is within round-off; the turning ones skid (layer 4 reports them, no pass/fail) and grow
    the pan/tilt rounding to 1e-11..4e-9 over 10 s depending on the servo settings: printed only."""
    from modelkit.verify.drive import vehicle
    from modelkit.verify.drive.scenario import default_scenario

    robot = modelkit.load(TRACKS)
    drive = vehicle.find_drive(robot, default_scenario("tracks", True))
    scenario = dataclasses.replace(default_scenario("tracks", drive.pan is not None), controller="track")
    files, maps = variant.write_variant(robot, drive, scenario, tmp_path, "sphere")
    fast, slow = _pair(files, maps, drive, scenario)
    assert fast.settings["law_actuators"] == {"PanJoint": 0.1, "TiltJoint": 0.1}
    assert "mujoco.pid" in fast.settings["control"]
    assert fast.servo_limit == slow.servo_limit and fast.model.nu == slow.model.nu + 2
    assert list(fast.model.actuator_forcelimited) == [*slow.model.actuator_forcelimited, 0, 0]
    for profile in scenario.profiles:
        still = dataclasses.replace(profile, commands=tuple(dataclasses.replace(c, pan=0.0, tilt=0.0)
                                                            for c in profile.commands))
        exact = run_difference(fast.run(still, scenario, drive), slow.run(still, scenario, drive))
        assert exact == 0.0, (profile.name, exact)
        largest = run_difference(fast.run(profile, scenario, drive), slow.run(profile, scenario, drive))
        print("tracks", profile.name, largest)
        if profile.name == "straight":
            assert largest <= ROUND_OFF, (profile.name, largest)


def per_step_driver(model: Path, renames: Any, *, drive: Drive, scenario: Scenario) -> Any:
    """Layer 4's MuJoCo driver with every controller called every step (for the comparison below)."""
    return engine_mujoco.driver(model, renames, drive=drive, scenario=scenario, fast=False)


def test_layer4_results_unchanged(pantilt: Any, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Layer 4 (MuJoCo, default scenario of the pan-tilt robot, sphere and native variants): every
    check and observation the same to round-off, the same pass/fail, with the fast driver as with the
    per-step one."""
    runs = assert_same_layer4(pantilt, "mujoco", f"{__name__}:per_step_driver", tmp_path, monkeypatch)
    assert runs
