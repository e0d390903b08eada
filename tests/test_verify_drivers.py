"""Layer 4's drivers on the real engines (no mocks): the pan-tilt mobile robot converted, its
verification variant (sphere wheel proxies) driven by the seed's controllers in MuJoCo and in
PyBullet's child process, compared as verification.md §2.1/§6 measured them."""

from __future__ import annotations

import dataclasses
import time
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import modelkit
from modelkit.verify import bench as verify_bench
from modelkit.verify.drive import Command, Drive, Profile, Scenario, Trajectory, variant
from modelkit.verify.engines import mujoco as engine_mujoco
from modelkit.verify.engines import pybullet as engine_pybullet
from tests.drivers_support import DRIVE, PANTILT, TRACKS, profile

# The seed's drive built by hand (LeftWheel/RightWheel, r 0.076, b 0.145: these tests do not depend on
# vehicle.find_drive); verification.md §1's graded profiles with the pan and tilt joints moving.
PROFILES = (profile("straight", 0.5, 0.0), profile("spin", 0.0, 1.0), profile("arc", 0.3, 0.5))
SCENARIO = Scenario(profiles=PROFILES, controller="drive")


def _diff(a: Trajectory, b: Trajectory) -> dict[str, float]:
    assert np.array_equal(a.t, b.t)
    out = {"position": float(np.hypot(a.x - b.x, a.y - b.y).max()),
           "yaw": float(np.abs(a.yaw - b.yaw).max()),
           "wheel": float(np.abs(a.wheels - b.wheels).max())}
    for name in a.joints:
        out[name] = float(np.abs(a.joints[name] - b.joints[name]).max())
    return out


def _run_both(robot: Any, drive: Drive, scenario: Scenario, out: Path, proxy: str
              ) -> tuple[list[Trajectory], list[Trajectory], dict[str, Any]]:
    files, maps = variant.write_variant(robot, drive, scenario, out, proxy)  # type: ignore[arg-type]
    timing: dict[str, Any] = {}
    pb = engine_pybullet.driver(files["urdf"], maps["urdf"], drive=drive, scenario=scenario)
    try:
        start = time.perf_counter()
        pb.start(list(scenario.profiles), scenario, drive)  # PyBullet steps in its child meanwhile
        mj = engine_mujoco.driver(files["mjcf"], maps["mjcf"], drive=drive, scenario=scenario)
        mj_runs, mj_wall = [], []
        for profile in scenario.profiles:
            mj_runs.append(mj.run(profile, scenario, drive))
            mj_wall.append(mj.last_wall)
        pb_runs = pb.result()
        timing = {"mujoco": mj_wall, "pybullet": list(pb.last_wall), "total": time.perf_counter() - start,
                  "mujoco_warnings": list(mj.warnings), "mujoco_settings": mj.settings,
                  "pybullet_settings": pb.settings}
    finally:
        pb.close()
    return mj_runs, pb_runs, timing


@pytest.fixture(scope="module")
def pantilt() -> Any:
    return modelkit.load(PANTILT)


@pytest.fixture(scope="module")
def sphere_runs(pantilt: Any, tmp_path_factory: pytest.TempPathFactory) -> Any:
    return _run_both(pantilt, DRIVE, SCENARIO, tmp_path_factory.mktemp("sphere"), "sphere")


def test_layer4_files_are_what_convert_writes(pantilt: Any, tmp_path: Path) -> None:
    """The graded files are byte for byte ``modelkit convert``'s default output (sphere wheels, MK826);
    the native run's are ``--wheel-collision cylinder``'s."""
    from modelkit.convert.api import write
    from modelkit.convert.options import WriteOptions
    from modelkit.model import Cylinder

    files, _ = variant.write_variant(pantilt, DRIVE, SCENARIO, tmp_path / "v", "sphere")
    native, _ = variant.write_variant(pantilt, DRIVE, SCENARIO, tmp_path / "v", "native")
    for fmt, suffix in (("mjcf", ".xml"), ("urdf", ".urdf")):
        write(pantilt, tmp_path / "c" / f"r{suffix}", fmt)
        write(pantilt, tmp_path / "k" / f"r{suffix}", fmt, options=WriteOptions(wheel_collision="cylinder"))
        assert files[fmt].read_bytes() == (tmp_path / "c" / f"r{suffix}").read_bytes()
        assert native[fmt].read_bytes() == (tmp_path / "k" / f"r{suffix}").read_bytes()
    assert files["mjcf"].read_text().count('type="sphere" size="0.076"') == 2
    assert native["mjcf"].read_text().count('type="cylinder" size="0.076 0.015"') == 2
    source_wheel = next(lk for lk in pantilt.links if lk.name == "LeftWheel")  # the source untouched
    assert isinstance(source_wheel.collisions[0].geometry, Cylinder)


def test_written_variant_is_floating_with_materials_friction(pantilt: Any, tmp_path: Path) -> None:
    files, maps = variant.write_variant(pantilt, DRIVE, SCENARIO, tmp_path, "sphere")
    xml = files["mjcf"].read_text()
    assert "<freejoint" in xml and xml.count('type="sphere" size="0.076"') == 2
    friction = engine_pybullet.urdf_friction(files["urdf"])
    assert friction == {"Chassis": 0.0, "LeftWheel": 3.0, "RightWheel": 3.0}
    assert maps["urdf"]["joint"] == {}  # URDF keeps the source joint names (MK846); the engines find them


def test_engines_agree_with_sphere_proxies(sphere_runs: Any) -> None:
    """verification.md §2.1 (D/F: recommended settings, Choreonoid's Ground/Tire mu 3): MuJoCo vs
    PyBullet ≤ 0.31 cm / 3.6 mrad / 0.004 rad measured; the pass thresholds are 1 cm / 10 mrad /
    0.02 rad, and the pan/tilt joints (the same controller in both) within 0.02 rad."""
    mj_runs, pb_runs, timing = sphere_runs
    assert not timing["mujoco_warnings"]
    for a, b in zip(mj_runs, pb_runs, strict=True):
        d = _diff(a, b)
        print(a.profile, {k: round(x, 5) for k, x in d.items()})
        assert d["position"] <= 0.01, (a.profile, d)
        assert d["yaw"] <= 0.010, (a.profile, d)
        assert d["wheel"] <= 0.02, (a.profile, d)
        assert d["PanJoint"] <= 0.02 and d["TiltJoint"] <= 0.02, (a.profile, d)
    print("wall s per profile", timing)


def test_trajectories_are_the_root_link_frame_from_zero(sphere_runs: Any) -> None:
    mj_runs, pb_runs, timing = sphere_runs
    for tr in [*mj_runs, *pb_runs]:
        assert tr.x[0] == 0.0 and tr.y[0] == 0.0 and tr.yaw[0] == 0.0
        assert np.all(tr.wheels[0] == 0.0) and all(q[0] == 0.0 for q in tr.joints.values())
        assert len(tr.t) == 1001 and tr.t[-1] == pytest.approx(10.0)
        assert set(tr.joints) == {"LeftWheel", "RightWheel", "PanJoint", "TiltJoint"}
    # the robot starts resting on the floor: wheel spheres and slider touch z = 0 at the root's z 0
    assert abs(timing["mujoco_settings"]["start_height"]) < 1e-9
    assert abs(timing["pybullet_settings"]["start_height"]) < 1e-9
    straight = mj_runs[0]
    assert straight.x[-1] == pytest.approx(4.95, abs=0.02)  # 0.5 m/s for 10 s minus the v·τ lag
    pan = mj_runs[0].joints["PanJoint"]
    assert pan[300] == pytest.approx(0.5 * 2.0, abs=0.05)  # pan at 0.5 rad/s from t = 1 to 3 s


def test_pybullet_base_pose_is_the_link_frame_not_the_com(sphere_runs: Any) -> None:
    """§2.8's pitfall: getBasePositionAndOrientation is the COM frame (here 8 cm behind the root link
    frame and 8 cm up). Spinning in place, the COM circles the link frame: reading it as the root
    pose would put PyBullet's path centimetres away from MuJoCo's; corrected, they agree."""
    mj_runs, pb_runs, _ = sphere_runs
    mj, pb = mj_runs[1], pb_runs[1]  # spin
    com = np.array([-0.08, 0.0])  # the chassis COM in the root link frame (x, y)
    cos, sin = np.cos(pb.yaw), np.sin(pb.yaw)
    com_x = pb.x + cos * com[0] - sin * com[1] - com[0]
    com_y = pb.y + sin * com[0] + cos * com[1] - com[1]
    wrong = float(np.hypot(com_x - mj.x, com_y - mj.y).max())
    right = float(np.hypot(pb.x - mj.x, pb.y - mj.y).max())
    assert wrong > 0.15 and right < 0.005, (wrong, right)


def test_runs_are_deterministic(pantilt: Any, tmp_path: Path) -> None:
    profile = Profile("short", 2.0, (Command(0.0, 0.4, 0.3, 0.2, 0.1),), settle=0.2)
    scenario = Scenario(profiles=(profile,), controller="drive")
    files, maps = variant.write_variant(pantilt, DRIVE, scenario, tmp_path, "sphere")
    mj = engine_mujoco.driver(files["mjcf"], maps["mjcf"], drive=DRIVE, scenario=scenario)
    pb = engine_pybullet.driver(files["urdf"], maps["urdf"], drive=DRIVE, scenario=scenario)
    try:
        for drv in (mj, pb):
            a, b = drv.run(profile, scenario, DRIVE), drv.run(profile, scenario, DRIVE)
            for field in ("x", "y", "yaw", "wheels"):
                assert np.array_equal(getattr(a, field), getattr(b, field)), (drv.engine, field)
            assert a.x[-1] > 0.5
    finally:
        pb.close()


def test_native_cylinder_wheels_disagree(pantilt: Any, tmp_path: Path) -> None:
    """Report-only physics (§2.2): MuJoCo's two rim contacts scrub, PyBullet's implicit cylinder
    touches one rim edge; with the converted cylinder wheels the engines part by decimetres to
    metres where the sphere proxies agree to millimetres."""
    scenario = Scenario(profiles=(PROFILES[0], PROFILES[2]), controller="drive")
    mj_runs, pb_runs, _ = _run_both(pantilt, DRIVE, scenario, tmp_path, "native")
    straight, arc = _diff(mj_runs[0], pb_runs[0]), _diff(mj_runs[1], pb_runs[1])
    print("native straight", straight, "arc", arc)
    assert straight["position"] > 0.05  # measured 16 cm (verification.md: 17 cm)
    assert arc["position"] > 0.5  # measured 3.4 m (verification.md: 2.6 m at mu 1, default softness)


def test_engines_keep_the_files_friction(pantilt: Any, tmp_path: Path) -> None:
    """The drivers edit no friction: the contact materials' (wheels 3, the caster 0) win against the
    default floor through the MJCF's priority and the URDF's <contact>, even when a scenario names a
    friction (which layer 4 then says it does not apply to the engines)."""
    scenario = dataclasses.replace(SCENARIO, friction=1.0)
    files, maps = variant.write_variant(pantilt, DRIVE, scenario, tmp_path, "sphere")
    mj = engine_mujoco.driver(files["mjcf"], maps["mjcf"], drive=DRIVE, scenario=scenario)
    pb = engine_pybullet.driver(files["urdf"], maps["urdf"], drive=DRIVE, scenario=scenario)
    try:
        assert mj.settings["friction"]["LeftWheel"] == 3.0 and mj.settings["friction"]["Chassis"] == 0.0
        assert pb.settings["friction"]["LeftWheel"] == 3.0 and pb.settings["friction"]["Chassis"] == 0.0
    finally:
        pb.close()


def test_bench_reports_harness_overhead(pantilt: Any, tmp_path: Path) -> None:
    profile = Profile("straight", 3.0, (Command(0.0, 0.5),), settle=0.5)
    scenario = Scenario(profiles=(profile,), controller="drive")
    figures = verify_bench.bench(pantilt, DRIVE, scenario, tmp_path)
    print({k: round(v, 3) for k, v in figures.items()})
    for engine in ("mujoco", "pybullet"):
        assert figures[f"{engine}_harness_s"] > 0 and figures[f"{engine}_bare_s"] > 0
        assert figures[f"{engine}_realtime"] > 10  # measured ≈ 100× (MuJoCo), ≈ 55× (PyBullet)


@pytest.mark.xfail(strict=True, reason="the wheeled robot's 1 cm pair bound does not hold for tracks since "
                   "their servos impose the belt speed (bound 3 x the friction limit): the start is "
                   "friction-limited, MuJoCo's soft friction lags, and the engines' straight paths are "
                   "1.18 cm apart; layer 4 grades a tracked robot at the skid tolerance (1.5 cm on the "
                   "straight) and passes, tests/test_verify_tracks.py")
def test_tracked_robot_rollers_velocity_servoed(tmp_path: Path) -> None:
    """The tracked robot through convert's roller approximation (the written cylinder rollers),
    roller 0 of each track velocity-servoed by the seed's track controller, the other rollers given
    the same target (PyBullet has no mimic). Straight driving agrees like the wheeled robot; turning a
    skid-steer vehicle is all lateral sliding (slip-dominated, verification.md §2.1/§6: no pass/fail),
    so it is only run here, and its disagreement is reported by layer 4, not graded."""
    robot = modelkit.load(TRACKS)
    rollers: dict[str, tuple[str, ...]] = {
               "LeftTracks": ("LeftTracks_roller0_joint", "LeftTracks_roller1_joint"),
               "RightTracks": ("RightTracks_roller0_joint", "RightTracks_roller1_joint")}
    drive = Drive("tracks", "LeftTracks", "RightTracks", 0.06, 0.155, ("LeftTracks", "RightTracks"),
                  pan="PanJoint", tilt="TiltJoint", rollers=rollers, roller_radius=0.06, track_offset_y=0.155)
    straight = Profile("straight", 10.0, (Command(0.0, 0.5), Command(1.0, 0.5, pan=0.5, tilt=0.3)))
    spin = Profile("spin", 10.0, (Command(0.0, 0.0, 1.0),))
    scenario = Scenario(profiles=(straight, spin), controller="track")
    mj_runs, pb_runs, timing = _run_both(robot, drive, scenario, tmp_path, "sphere")
    assert not timing["mujoco_warnings"]
    assert "velocity actuator" in timing["mujoco_settings"]["velocity_servo"]
    assert "VELOCITY_CONTROL" in timing["pybullet_settings"]["velocity_servo"]
    d = _diff(mj_runs[0], pb_runs[0])
    print("tracks straight", d, "spin", _diff(mj_runs[1], pb_runs[1]))
    assert d["position"] <= 0.01 and d["yaw"] <= 0.010, d  # measured 0.30 cm / 0.6 mrad
    for tr in (mj_runs[0], pb_runs[0]):
        assert tr.x[-1] == pytest.approx(5.0, abs=0.03)  # 0.5 m/s, rollers of the track's radius
        # the servo's torque-bounded start (½·m·g·μ·r per roller: a ≈ 4.80 m/s², 0.104 s) costs half
        # the ramp time of roller rotation (tests/test_verify_tracks.py)
        force = 4 * variant.servo_torque_limit(17.6, 1.0, 0.06, 4) / 0.06
        ramp = 0.5 / (force / (17.6 + 4 * 0.00036 / 0.06**2))
        assert tr.wheels[-1, 0] == pytest.approx(0.5 / 0.06 * (10.0 - ramp / 2), rel=0.001)
