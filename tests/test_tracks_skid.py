"""The skid-steer reference (modelkit.verify.drive.reference_skid) and the converted tracked robot driven
on a plain floor in real MuJoCo and PyBullet (tests/tracks_support.py: the files `convert` writes).

What is checked: the reference's physics (the steady spin rate of point contacts is the geometric
ratio b²/(a² + b²) whatever μ; a straight run follows the belts after a friction-limited start; the
static loads carry the weight at the COM), the tolerance's derivation, the straight profile of the
written files in both engines against the reference and each other, and the written files turning
as the reference says: MuJoCo through the MJCF's ``<option impratio>``, PyBullet with cone friction
off and 400 solver iterations as MK809 asks, and neither with its own default (the cause, undone).
PyBullet's 0.5 rad/s spin path (its yaw passes) is a strict xfail; layer 4's grading of the default
scenario's spin and arc is tested in tests/test_verify_tracks.py.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import modelkit
from modelkit.verify.drive import Command, Drive, Profile, vehicle
from modelkit.verify.drive.reference_skid import (
    FLOOR_POSITION,
    FLOOR_YAW,
    SkidModel,
    path_difference,
    skid_model,
    skid_reference,
    skid_tolerance,
    static_loads,
)
from modelkit.verify.drive.scenario import default_scenario
from modelkit.verify.layers import layer4
from tests import tracks_support as support

SCENARIO = default_scenario("tracks", True)
A, B = 0.11, 0.155  # the tutorial's roller half-spacing and track half-spacing


def _box_drive() -> Drive:
    return Drive("tracks", "L", "R", 0.06, B, ("L", "R"), rollers={"L": ("l0",), "R": ("r0",)},
                 roller_radius=0.06, track_offset_y=B)


def _four_points(mu: float = 1.0) -> SkidModel:
    points = np.array([(-A, B), (A, B), (-A, -B), (A, -B)])
    mass = 17.6
    return SkidModel(mass, 0.28, (0.0, 0.0), points, np.array([0, 0, 1, 1]),
                     static_loads(points, mass, np.zeros(2)), mu, 0.06)


def _profile(name: str, v: float, w: float, seconds: float = 10.0) -> Profile:
    return Profile(name, seconds, (Command(0.0, v, w),))


def test_point_contacts_spin_at_the_geometric_ratio() -> None:
    """Moment balance of four sliding points: ω (a² + b²) = b·u, so ω = ω_cmd·b² / (a² + b²)."""
    ref = skid_reference(_four_points(), _profile("spin", 0.0, 0.5, 4.0), SCENARIO, _box_drive())
    rate = (ref.yaw[-1] - ref.yaw[-101]) / (ref.t[-1] - ref.t[-101])
    assert rate == pytest.approx(0.5 * B * B / (A * A + B * B), rel=5e-3)
    assert np.hypot(ref.x[-1], ref.y[-1]) < 1e-9  # symmetric: spins on the spot


def test_steady_spin_does_not_depend_on_mu() -> None:
    low = skid_reference(_four_points(0.5), _profile("spin", 0.0, 0.5), SCENARIO, _box_drive())
    high = skid_reference(_four_points(1.0), _profile("spin", 0.0, 0.5), SCENARIO, _box_drive())
    assert abs(low.yaw[-1] - high.yaw[-1]) < 0.01  # only the start differs (μg-limited)
    assert low.yaw[-1] < high.yaw[-1]


def test_straight_follows_the_belts_after_a_friction_limited_start() -> None:
    v, mu = 0.3, 1.0
    ref = skid_reference(_four_points(mu), _profile("straight", v, 0.0), SCENARIO, _box_drive())
    lag = v * v / (2.0 * mu * 9.81)  # accelerating at μg to v
    assert ref.x[-1] == pytest.approx(v * 10.0 - lag, abs=2e-4)
    assert abs(ref.y[-1]) < 1e-12 and abs(ref.yaw[-1]) < 1e-12


def test_static_loads_carry_the_weight_at_the_com() -> None:
    points = np.array([(-0.19, 0.155), (0.03, 0.155), (-0.19, -0.155), (0.03, -0.155)])
    loads = static_loads(points, 10.0, np.array([-0.07, 0.01]))
    assert loads.sum() == pytest.approx(98.1)
    assert loads @ points[:, 0] == pytest.approx(98.1 * -0.07)
    assert loads @ points[:, 1] == pytest.approx(98.1 * 0.01)


@pytest.fixture(scope="module")
def tutorial():  # type: ignore[no-untyped-def]
    source = layer4.floating(modelkit.load(support.TRACKS))
    prepared = vehicle.prepare_tracks(source)
    drive = vehicle.find_drive(source, SCENARIO, prepared)
    return prepared, drive


def test_tutorial_model_and_tolerances(tutorial) -> None:  # type: ignore[no-untyped-def]
    prepared, drive = tutorial
    model = skid_model(prepared, drive)
    assert model.mass == pytest.approx(17.6)
    assert model.loads.sum() == pytest.approx(17.6 * 9.81)
    assert model.mu == 1.0  # Ground–TankTracks
    straight = skid_tolerance(model, _profile("straight", 0.3, 0.0), SCENARIO, drive, prepared)
    assert (straight.position, straight.yaw) == (FLOOR_POSITION, FLOOR_YAW)
    spin = skid_tolerance(model, _profile("spin", 0.0, 0.5), SCENARIO, drive, prepared)
    # the pressure distribution decides the spin: uniform belt 4.14 rad, load at the ends 3.25 rad
    assert spin.parts["layout uniform"][1] == pytest.approx(0.884, abs=0.01)
    assert spin.yaw == spin.parts["layout uniform"][1]


@pytest.fixture(scope="module")
def written(tmp_path_factory):  # type: ignore[no-untyped-def]
    pytest.importorskip("mujoco")
    pytest.importorskip("pybullet")
    files = support.convert(Path(tmp_path_factory.mktemp("tracks")))
    return files, support.track_info()


def _engines(written, profile: support.Profile):  # type: ignore[no-untyped-def]
    files, tracks = written
    return (support.run_mujoco(files["mjcf"], tracks, profile),
            support.run_pybullet(files["urdf"], tracks, profile))


def _as_reference(tutorial, profile: support.Profile):  # type: ignore[no-untyped-def]
    prepared, drive = tutorial
    model = skid_model(prepared, drive)
    p = _profile(profile.name, profile.v, profile.w, profile.duration)
    return skid_reference(model, p, SCENARIO, drive), skid_tolerance(model, p, SCENARIO, drive, prepared)


def _gap(path: support.Path2D, ref) -> tuple[float, float]:  # type: ignore[no-untyped-def]
    n = min(len(path.t), len(ref.t))
    return (float(np.hypot(path.x[:n] - ref.x[:n], path.y[:n] - ref.y[:n]).max()),
            float(np.abs(path.yaw[:n] - ref.yaw[:n]).max()))


def test_written_files_drive_straight_as_the_reference(written, tutorial) -> None:  # type: ignore[no-untyped-def]
    profile = support.PROFILES[0]
    ref, tol = _as_reference(tutorial, profile)
    mj, pb = _engines(written, profile)
    for path in (mj, pb):
        position, yaw = _gap(path, ref)
        assert position < tol.position and yaw < tol.yaw  # measured MuJoCo 1.0 cm, PyBullet 0.05 cm
    # the pair within the same derived tolerance: measured 1.004 cm at t = 0.11 s (MuJoCo's start
    # accelerates above μg), 0.32 cm at the end
    n = min(len(mj.t), len(pb.t))
    assert float(np.hypot(mj.x[:n] - pb.x[:n], mj.y[:n] - pb.y[:n]).max()) < tol.position


def test_written_mjcf_turns_as_the_skid_reference(written, tutorial) -> None:  # type: ignore[no-untyped-def]
    """The MJCF's <option impratio> (MK809) makes MuJoCo's roller friction follow the slip."""
    files, tracks = written
    assert 'impratio="0.03"' in files["mjcf"].read_text()
    for profile in support.PROFILES[1:]:
        ref, tol = _as_reference(tutorial, profile)
        position, yaw = _gap(support.run_mujoco(files["mjcf"], tracks, profile), ref)
        assert position < tol.position and yaw < tol.yaw  # measured: see docs/verify.md


def test_mujoco_without_soft_friction_hardly_turns(written, tutorial) -> None:  # type: ignore[no-untyped-def]
    """impratio 1 (MuJoCo's default): the end rollers' sideways friction holds, 0.93 rad of 3.25."""
    files, tracks = written
    spin = support.PROFILES[1]
    ref, tol = _as_reference(tutorial, spin)
    got = support.run_mujoco(files["mjcf"], tracks, spin, impratio=1.0)
    assert ref.yaw[-1] - got.yaw[-1] > tol.yaw


def test_pybullet_turns_as_the_skid_reference_without_cone_friction(  # type: ignore[no-untyped-def]
        written, tutorial) -> None:
    files, tracks = written
    arc = support.PROFILES[2]
    ref, tol = _as_reference(tutorial, arc)
    position, yaw = _gap(support.run_pybullet(files["urdf"], tracks, arc), ref)
    assert position < tol.position and yaw < tol.yaw  # measured 5.8 cm / 180 mrad (72 cm / 524 mrad)
    spin = support.PROFILES[1]
    ref, tol = _as_reference(tutorial, spin)
    got = support.run_pybullet(files["urdf"], tracks, spin)
    assert abs(got.yaw[-1] - ref.yaw[-1]) < tol.yaw  # measured 3.60 rad against 3.25 (± 0.88)
    # with PyBullet's default cone friction it hardly turns: 1.42 rad
    cone = support.run_pybullet(files["urdf"], tracks, spin, cone_friction=True)
    assert ref.yaw[-1] - cone.yaw[-1] > tol.yaw


@pytest.mark.xfail(strict=True, reason="open: PyBullet's box friction drifts differently on the spot: at "
                   "0.5 rad/s its spin path is up to 6.4 cm from the reference's (tolerance 5.4 cm; 12.2 cm "
                   "at 50 solver iterations), yaw within tolerance; layer 4's default 1 rad/s spin passes")
def test_pybullet_spin_path_as_the_skid_reference(written, tutorial) -> None:  # type: ignore[no-untyped-def]
    files, tracks = written
    spin = support.PROFILES[1]
    ref, tol = _as_reference(tutorial, spin)
    position, yaw = _gap(support.run_pybullet(files["urdf"], tracks, spin), ref)
    assert position < tol.position and yaw < tol.yaw


def test_engines_agree_on_the_arc(written, tutorial) -> None:  # type: ignore[no-untyped-def]
    arc = support.PROFILES[2]
    _, tol = _as_reference(tutorial, arc)
    mj, pb = _engines(written, arc)
    n = min(len(mj.t), len(pb.t))
    assert float(np.hypot(mj.x[:n] - pb.x[:n], mj.y[:n] - pb.y[:n]).max()) < tol.position
    assert float(np.abs(mj.yaw[:n] - pb.yaw[:n]).max()) < tol.yaw


def test_path_difference_is_the_largest_gap() -> None:
    a = skid_reference(_four_points(), _profile("arc", 0.3, 0.3, 2.0), SCENARIO, _box_drive())
    assert path_difference(a, a) == (0.0, 0.0)
    assert math.isfinite(path_difference(a, skid_reference(_four_points(0.5), _profile("arc", 0.3, 0.3, 2.0),
                                                           SCENARIO, _box_drive()))[0])


def test_only_a_tracked_robot_gets_the_soft_impratio(tmp_path: Path) -> None:
    """A wheeled robot gets the wheels' <option> (impratio 10, MK825), not the tracks' 0.03."""
    wheeled = support.TRACKS.with_name("mobile_robot_pantilt.body")
    files = support.convert(tmp_path, wheeled)
    assert 'impratio="10"' in files["mjcf"].read_text() and 'impratio="0.03"' not in files["mjcf"].read_text()
