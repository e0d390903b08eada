"""Layer 4: the mobile robot driven through command profiles on a floor, in MuJoCo and PyBullet, with
the seed's controllers; the trajectories compared with each other and with engine-independent
references (verification.md §1, §2, §6).

What is graded (a :class:`~modelkit.verify.engines.protocol.Check`, layer 4), per graded profile:

* ``mujoco~pybullet``: ``path-position`` (the largest planar distance between the two root-frame
  paths over the run), ``path-yaw`` (the largest wrapped heading difference), ``wheel-angle`` (the
  largest wheel joint angle difference), ``pan-tilt-angle`` (the largest pan/tilt joint angle
  difference, at the wheel-angle tolerance); tolerances 1 cm, 10 mrad, 0.02 rad.
* each engine against the rigid **no-slip** reference built from the source model's own mass
  properties and driven by the same controllers (:mod:`modelkit.verify.drive.reference`):
  ``noslip-position``, ``noslip-yaw``; tolerances 1.5 cm, 15 mrad.

What is reported only (an :class:`~modelkit.verify.engines.protocol.Observation`): each engine's ``slip``
(distance between its path and its own wheel odometry) and ``effective-radius`` (the rolling radius
its own path implies for each wheel), the distance from the ideal ``unicycle`` (it differs from any
physical robot under this controller by v·τ plus the COM-offset yaw bias, §2.1), every comparison on
a report-only profile (``steps``: slip-dominated reversals), and the **native** wheel geometry run
(§2.2: MuJoCo and PyBullet model a cylinder on a plane differently, so that run has no meaningful
tolerance).

**Graded = written.** The graded runs load exactly the MJCF and URDF ``modelkit convert`` writes
with its default options (wheels: sphere collisions, MK826; the contact parameters, priority and
``<option>`` in the file, MK825), unmodified: MuJoCo gets a default plane added to the world,
PyBullet loads pybullet_data's ``plane.urdf`` as shipped (see the drivers for the engine settings).
``report.json`` names the files (``engines.layer4.files``).

Tracked robots are driven through the rollers ``convert`` writes, their velocity servos bounded
high enough to impose the belt speed (as Choreonoid does; ``variant.SERVO_FRICTION_SHARE``). A tracked
robot skids to turn, which no rigid no-slip model describes, so every profile of a tracked robot is
graded against the **skid-steer** reference instead (:mod:`modelkit.verify.drive.reference_skid`):
``skid-position``, ``skid-yaw`` for each engine, at the tolerance ``skid_tolerance`` derives per profile
(the spread of the skid path over the pressure distribution under the belt and μ × 0.5 … 2), and the
pair ``mujoco~pybullet`` at the same derived tolerance (docs/verify.md, "Tracked robots": the two
engines differ in how their rigid solvers split the weight among the rollers, which is the
pressure-distribution uncertainty again) and the roller angles at 0.02 rad.
"""

from __future__ import annotations

import copy
import importlib
import math
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from modelkit.model import WORLD_LINK, JointType, Robot
from modelkit.verify.drive import Array, Drive, Profile, Scenario, Trajectory, WheelProxy
from modelkit.verify.drive.reference import PlanarModel, noslip, odometry, planar_model, unicycle
from modelkit.verify.drive.reference_skid import (
    SkidModel,
    SkidTolerance,
    skid_model,
    skid_reference,
    skid_tolerance,
)
from modelkit.verify.engines.protocol import Check, Observation, Skip
from modelkit.verify.layers.common import Renames
from modelkit.verify.layers.stance import unloaded_wheel

LAYER = 4
DRIVERS = {
    "mujoco": "modelkit.verify.engines.mujoco:driver",
    "pybullet": "modelkit.verify.engines.pybullet:driver",
}
PAIR = "mujoco~pybullet"
NATIVE_WARNING = (
    "native wheel geometry, report-only: MuJoCo and PyBullet model a cylinder wheel on a plane differently "
    "(MuJoCo: two contacts, one on each rim edge, so a yawing wheel scrubs; PyBullet's implicit cylinder: "
    "one contact at whichever rim edge its support mapping picks, so the first acceleration yaws the robot); "
    "verification.md §2.2 measured up to 2.6 m and π rad between them on the arc. Choreonoid's own contact "
    "model (not run here) is a third meaning. This run reads what convert --wheel-collision cylinder writes; "
    "the graded runs read convert's default files (sphere wheels, MK826)."
)
TRACK_SKIP = (
    "tracks: graded against the skid-steer reference (modelkit.verify.drive.reference_skid: the planar rigid "
    "body on Coulomb friction under the rollers with the belt speeds imposed), not the no-slip one, at "
    "the tolerance derived per profile from the pressure distribution under the belt and μ (docs/verify.md, "
    "\"Tracked robots\"); the continuous tracks themselves are not simulated by either engine: both drive "
    "the cylinder rollers convert writes (MK809), each track's rollers coupled like its belt (MuJoCo: the "
    "file's mimic equality; PyBullet: a gear constraint), velocity-servoed with a torque bound of "
    "variant.SERVO_FRICTION_SHARE × what the weight lets friction pass (the belt speed is imposed and the "
    "belt slips, as in Choreonoid); MuJoCo with the file's <option>, PyBullet with the engine parameters "
    "the files' notes (MK809, MK825) ask a user to set"
)


@dataclass
class Layer4Result:
    checks: list[Check] = field(default_factory=list)
    observations: list[Observation] = field(default_factory=list)
    skips: list[Skip] = field(default_factory=list)
    trajectories: list[Trajectory] = field(default_factory=list)
    settings: dict[str, Any] = field(default_factory=dict)
    injected: list[str] = field(default_factory=list)
    timings: dict[str, float] = field(default_factory=dict)  # wall seconds (not for report.json)


def _resolve(target: str) -> Any:
    module, _, name = target.partition(":")
    return getattr(importlib.import_module(module), name)


def floating(source: Robot) -> Robot:
    """The source with a floating root (a URDF leaves it open); raises ValueError for a fixed root."""
    if source.root_joint is JointType.FLOATING:
        return source
    if source.root_joint is JointType.FIXED:
        raise ValueError(
            f"the root link {source.root!r} is fixed to the world: a driven robot needs a floating base"
        )
    out = copy.deepcopy(source)
    out.root_joint = JointType.FLOATING
    return out


def run(
    source: Robot,
    drive: Drive,
    scenario: Scenario,
    out_dir: Path,
    engines: Sequence[str] = ("mujoco", "pybullet"),
    inject: Sequence[str] = (),
    prepared: Robot | None = None,
    given: Mapping[str, tuple[Path, Renames]] | None = None,
) -> Layer4Result:
    """Run every profile of ``scenario`` in every engine, compute the references, compare.

    ``source``: the model as read (its root free, not welded); ``prepared``: the model with its track
    approximation (``convert``'s prepare), needed for tracked robots (computed when None).
    ``inject``: fault specs (:mod:`modelkit.verify.layers.inject`) applied to the verification variant's
    files, as ``verify --inject`` applies them to the converted files. ``given``: "mjcf"/"urdf" → a file
    the user gave (``verify --mjcf/--urdf``) and its renames, which the graded runs drive instead of
    the written one (as it is: ``inject`` is not applied to it again). Never raises for a model
    problem: an engine failing is a failed check."""
    result = Layer4Result()
    t0 = time.perf_counter()
    try:
        robot = floating(source)
    except ValueError as exc:
        result.skips.append(Skip(LAYER, "all", f"layer 4 not run: {exc}"))
        return result
    if drive.kind == "tracks" and prepared is None:
        from modelkit.verify.drive.vehicle import prepare_tracks

        prepared = prepare_tracks(robot)
    model = planar_model(
        prepared if drive.kind == "tracks" and prepared is not None else robot, drive, scenario.friction
    )
    result.settings["reference"] = {"noslip": model.as_dict(), "unicycle": "exact, from the commanded (v, w)"}
    skid: Skid | None = None
    if drive.kind == "tracks" and prepared is not None:
        skid = Skid(prepared, skid_model(prepared, drive, scenario.friction))
        result.settings["reference"]["skid"] = skid.model.as_dict()
    wanted = [e for e in engines if e in DRIVERS]
    if scenario.friction is not None and wanted:
        result.skips.append(Skip(LAYER, "all", (
            f"the scenario's friction {scenario.friction:g} is used by the no-slip reference only: the "
            "engines drive the files convert wrote, unmodified, whose friction is the contact materials' "
            "against the floor (MK817)")))
    for e in engines:
        if e not in DRIVERS:
            result.skips.append(Skip(LAYER, e, "layer 4 runs MuJoCo and PyBullet only"))
    proxies: list[WheelProxy] = [scenario.wheel_proxy]
    if scenario.native_report and scenario.wheel_proxy == "sphere" and wanted:
        proxies.append("native")
    out_dir = Path(out_dir)
    jobs = []
    try:
        for proxy in proxies:
            profiles = list(scenario.profiles) if proxy == scenario.wheel_proxy else native_profiles(scenario)
            jobs.append(_Job(proxy, profiles))
            _setup(jobs[-1], robot, drive, scenario, out_dir, wanted, inject, result, given or {})
        t1 = time.perf_counter()
        for job in jobs:  # MuJoCo here while PyBullet's children step their batches
            job.run_here(scenario, drive, result)
        references = {p.name: _references(model, p, scenario, drive, skid) for p in scenario.profiles}
        t2 = time.perf_counter()
        for job in jobs:
            job.collect(result)
    finally:
        for job in jobs:
            job.close(result)
    t3 = time.perf_counter()
    if drive.kind == "tracks":
        result.skips.append(Skip(LAYER, "all", TRACK_SKIP))
    for profile in scenario.profiles:
        ref = references[profile.name]
        result.trajectories.extend(ref.values())
        for job in jobs:
            runs = {e: got[profile.name] for e, got in sorted(job.runs.items()) if profile.name in got}
            if not runs:
                continue
            result.trajectories.extend(runs.values())
            graded = profile.graded and job.proxy == scenario.wheel_proxy
            unloaded = unloaded_wheel(runs, drive, job.link_names) if graded else None
            if unloaded is not None:
                skip = Skip(LAYER, unloaded.engine, unloaded.reason())
                if skip not in result.skips:
                    result.skips.append(skip)
            _compare(profile, job.proxy, graded, runs, ref, model, drive, scenario, result,
                     skid.tolerances.get(profile.name) if skid is not None else None,
                     frozenset({unloaded.engine}) if unloaded is not None else frozenset())
    if skid is not None:
        result.settings["reference"]["skid_tolerances"] = {
            k: v.as_dict() for k, v in sorted(skid.tolerances.items())}
    t4 = time.perf_counter()
    result.timings.update(
        {
            "layer 4 setup": t1 - t0,
            "layer 4 mujoco and references": t2 - t1,
            "layer 4 pybullet wait": t3 - t2,
            "layer 4 compare": t4 - t3,
            "layer 4": t4 - t0,
        }
    )
    return result


NATIVE_PROFILES = ("arc",)
"""The profiles the report-only native-wheel run drives (the arc shows the cylinder-contact disagreement
most, verification.md §2.2); the first graded profile when the scenario has none of them."""


def native_profiles(scenario: Scenario) -> list[Profile]:
    chosen = [p for p in scenario.profiles if p.name in NATIVE_PROFILES]
    if not chosen:
        chosen = [p for p in scenario.profiles if p.graded][:1] or list(scenario.profiles[:1])
    return chosen


# ----------------------------------------------------------------------------------------------------
# running the engines


@dataclass
class _Job:
    """One verification variant (sphere or native) in every engine."""

    proxy: WheelProxy
    profiles: list[Profile]
    drivers: dict[str, Any] = field(default_factory=dict)
    pending: list[str] = field(default_factory=list)
    runs: dict[str, dict[str, Trajectory]] = field(default_factory=dict)  # engine → profile → trajectory
    link_names: dict[str, dict[str, str]] = field(default_factory=dict)  # engine → source link → its file's

    def run_here(self, scenario: Scenario, drive: Drive, result: Layer4Result) -> None:
        for e, d in self.drivers.items():
            if e in self.pending:
                continue
            got = _guard(
                lambda d=d: [d.run(p, scenario, drive) for p in self.profiles], e, self.proxy, result
            )
            self._keep(e, got)

    def collect(self, result: Layer4Result) -> None:
        for e in self.pending:
            self._keep(e, _guard(lambda e=e: self.drivers[e].result(), e, self.proxy, result))
        self.pending = []

    def _keep(self, engine: str, got: list[Trajectory] | None) -> None:
        if got is None:
            return
        for trajectory in got:
            trajectory.variant = self.proxy
        self.runs[engine] = {p.name: t for p, t in zip(self.profiles, got, strict=True)}

    def close(self, result: Layer4Result) -> None:
        for e, d in self.drivers.items():
            result.settings.setdefault("engines", {}).setdefault(e, {})[self.proxy] = dict(d.settings)
            warnings = list(getattr(d, "warnings", []))
            if warnings:
                _warnings(e, self.proxy, warnings, result)
            d.close()
        self.drivers = {}


def _setup(
    job: _Job,
    robot: Robot,
    drive: Drive,
    scenario: Scenario,
    out_dir: Path,
    engines: list[str],
    inject: Sequence[str],
    result: Layer4Result,
    given: Mapping[str, tuple[Path, Renames]],
) -> None:
    """Write the variant (the graded one: but the files the user gave), apply the injected faults to
    what was written, load every engine and start the engines that run in a child process (PyBullet)
    on the job's profiles."""
    from modelkit.verify.drive.variant import write_variant

    proxy = job.proxy
    try:
        graded = proxy == scenario.wheel_proxy
        files, maps = write_variant(robot, drive, scenario, out_dir, proxy,
                                    tuple(k for k in ("mjcf", "urdf") if not (graded and k in given)))
    except Exception as exc:  # a conversion defect: every engine's layer 4 fails
        for e in engines:
            result.checks.append(
                Check(
                    LAYER,
                    e,
                    "variant",
                    proxy,
                    math.inf,
                    0.0,
                    f"the {proxy} verification variant could not be written: {type(exc).__name__}: {exc}",
                )
            )
        return
    written = dict(files)
    if graded:  # the graded run: the files convert writes by default, as they are, or the user's
        for kind, (path, renamed) in sorted(given.items()):
            files[kind], maps[kind] = Path(path), renamed
        result.settings["files"] = {k: (str(p) if k in given else p.name) for k, p in sorted(files.items())}
        result.settings["given"] = sorted(given)
    result.settings.setdefault("variant", {})[proxy] = {k: p.name for k, p in sorted(files.items())}
    for spec in inject if written else ():
        apply = _resolve("modelkit.verify.layers.inject:apply")
        try:
            result.injected.append(f"layer 4 {proxy} variant: {apply(spec, written, maps)}")
        except ValueError as exc:  # e.g. cylinder-y on a variant whose wheels are sphere proxies
            reason = str(exc).splitlines()[0]
            result.injected.append(f"layer 4 {proxy} variant: {spec}: not applicable ({reason})")
    kinds = {"mujoco": "mjcf", "pybullet": "urdf"}
    for e in engines:
        if graded and kinds[e] in given and _welds_the_base(files[kinds[e]], kinds[e]):
            result.skips.append(Skip(LAYER, e, (
                f"not run: the given {kinds[e].upper()} {files[kinds[e]].name} welds the robot's base to "
                "the world (convert --base fixed), and layer 4 drives the robot on a floor")))
            continue
        try:
            make = _resolve(DRIVERS[e])
        except ImportError as exc:
            result.skips.append(Skip(LAYER, e, f"not installed ({exc})"))
            continue
        job.link_names[e] = dict(maps[kinds[e]].get("link", {}))
        try:
            job.drivers[e] = make(files[kinds[e]], maps[kinds[e]], drive=drive, scenario=scenario)
        except Exception as exc:
            if getattr(type(exc), "engine_limit", False):  # PyBullet's 127 joints: the engine's limit
                result.skips.append(Skip(LAYER, e, f"{proxy} variant not driven: {exc}"))
                continue
            result.checks.append(
                Check(
                    LAYER,
                    e,
                    "load",
                    proxy,
                    math.inf,
                    0.0,
                    f"{e} could not load the {proxy} verification variant "
                    f"{files[kinds[e]].name}: {type(exc).__name__}: {exc}",
                )
            )
    for e, d in job.drivers.items():
        if hasattr(d, "start") and _guard(
            lambda d=d: d.start(job.profiles, scenario, drive) or True, e, proxy, result
        ):
            job.pending.append(e)


def _welds_the_base(path: Path, kind: str) -> bool:
    """Whether a given file holds the robot welded: an MJCF whose top bodies have no free joint, a URDF
    with a ``world`` link (what ``convert --base fixed`` writes)."""
    from lxml import etree

    try:
        root = etree.parse(str(path), etree.XMLParser(resolve_entities=False, no_network=True)).getroot()
    except (OSError, etree.XMLSyntaxError):
        return False  # the driver's own loading says what is wrong
    if kind == "urdf":
        return any(link.get("name") == WORLD_LINK for link in root.iterchildren("link"))
    tops = [body for world in root.iter("worldbody") for body in world.iterchildren("body")]
    return bool(tops) and not any(
        body.find("freejoint") is not None
        or any(j.get("type") == "free" for j in body.iterchildren("joint"))
        for body in tops)


def _guard(call: Any, engine: str, proxy: str, result: Layer4Result) -> Any:
    try:
        return call()
    except Exception as exc:
        result.checks.append(
            Check(
                LAYER,
                engine,
                "engine-error",
                proxy,
                math.inf,
                0.0,
                f"{engine} failed while driving the {proxy} variant: {type(exc).__name__}: {exc}",
            )
        )
        return None


def _warnings(engine: str, proxy: str, messages: list[str], result: Layer4Result) -> None:
    unique = list(dict.fromkeys(messages))
    result.settings.setdefault("engines", {}).setdefault(engine, {})[f"{proxy}_warnings"] = unique
    if engine != "mujoco":
        return
    from modelkit.verify.engines.mujoco import unstable

    bad = unstable(unique)
    if bad:
        result.checks.append(
            Check(
                LAYER,
                engine,
                "stability",
                proxy,
                float(len(bad)),
                0.0,
                f"{engine} warned while driving the {proxy} variant that the simulation is "
                "unstable: " + "; ".join(bad[:3]),
            )
        )


# ----------------------------------------------------------------------------------------------------
# references and comparisons


@dataclass
class Skid:
    """A tracked robot's skid-steer reference: its model and the tolerance derived per graded profile."""

    prepared: Robot
    model: SkidModel
    tolerances: dict[str, SkidTolerance] = field(default_factory=dict)


def _references(
    model: PlanarModel, profile: Profile, scenario: Scenario, drive: Drive, skid: Skid | None = None
) -> dict[str, Trajectory]:
    out = {
        "noslip": noslip(model, profile, scenario, drive),
        "unicycle": unicycle(model, profile, scenario, drive),
    }
    if skid is not None:
        out["skid"] = skid_reference(skid.model, profile, scenario, drive)
        if profile.graded:
            skid.tolerances[profile.name] = skid_tolerance(
                skid.model, profile, scenario, drive, skid.prepared, out["skid"]
            )
    return out


def wrap(angle: Array) -> Array:
    return (angle + math.pi) % (2.0 * math.pi) - math.pi


def _on(t: Array, other: Trajectory, values: Array) -> Array:
    """``values`` (sampled at ``other.t``) at the times ``t`` (identical grids: no interpolation)."""
    if len(other.t) == len(t) and np.array_equal(other.t, t):
        return values
    return np.interp(t, other.t, values)


@dataclass(frozen=True)
class Difference:
    position: float
    position_t: float
    yaw: float
    yaw_t: float
    final: float


def difference(a: Trajectory, b: Trajectory) -> Difference:
    """The largest planar position and wrapped yaw differences between two trajectories (and when)."""
    bx, by, byaw = _on(a.t, b, b.x), _on(a.t, b, b.y), _on(a.t, b, b.yaw)
    distance = np.hypot(a.x - bx, a.y - by)
    yaw = np.abs(wrap(a.yaw - byaw))
    i, k = int(np.argmax(distance)), int(np.argmax(yaw))
    return Difference(float(distance[i]), float(a.t[i]), float(yaw[k]), float(a.t[k]), float(distance[-1]))


def wheel_difference(a: Trajectory, b: Trajectory) -> tuple[float, float, int]:
    """(largest |Δ wheel angle|, when, which wheel: 0 left, 1 right)."""
    diff = np.abs(a.wheels - np.column_stack([_on(a.t, b, b.wheels[:, 0]), _on(a.t, b, b.wheels[:, 1])]))
    i, side = np.unravel_index(int(np.argmax(diff)), diff.shape)
    return float(diff[i, side]), float(a.t[i]), int(side)


def effective_radius(trajectory: Trajectory, model: PlanarModel, drive: Drive) -> tuple[float, float]:
    """The rolling radius each wheel's own motion implies: the forward ground distance its centre
    travelled divided by its (sign-corrected) rotation, over the run. Negative: the joint's positive
    rotation moved that side backwards (a flipped axis, or left and right swapped)."""
    th = trajectory.yaw
    c, s = np.cos(th), np.sin(th)
    ox, oy = model.root_offset
    px = trajectory.x - (c * ox - s * oy) + ox  # the axle midpoint P, start frame
    py = trajectory.y - (s * ox + c * oy) + oy
    out = []
    for side, (sign, lateral) in enumerate(
        ((drive.signs[0], model.half_axle), (drive.signs[1], -model.half_axle))
    ):
        wx, wy = px - s * lateral, py + c * lateral
        mid = th[:-1] + 0.5 * np.diff(th)
        forward = np.diff(wx) * np.cos(mid) + np.diff(wy) * np.sin(mid)
        turn = sign * np.diff(trajectory.wheels[:, side])
        rotation = float(np.sum(np.abs(turn)))
        out.append(float(np.sum(forward * np.sign(turn))) / rotation if rotation > 1e-9 else math.nan)
    return out[0], out[1]


def _compare(
    profile: Profile,
    proxy: str,
    graded: bool,
    runs: dict[str, Trajectory],
    ref: dict[str, Trajectory],
    model: PlanarModel,
    drive: Drive,
    scenario: Scenario,
    result: Layer4Result,
    skid_tol: SkidTolerance | None = None,
    ungraded: frozenset[str] = frozenset(),
) -> None:
    """The profile's comparisons: checks when ``graded``, else observations; an engine in ``ungraded``
    (and the pair with it) is reported only (:mod:`modelkit.verify.layers.stance`)."""
    tol = scenario.tolerances
    where = profile.name if proxy == "sphere" else f"{profile.name} ({proxy} wheels)"
    native = proxy == "native"
    prefix = "native-" if native and not graded else ""
    note = (
        (NATIVE_WARNING + " ")
        if native
        else ("report-only profile: " + profile.description + ". " if not profile.graded else "")
    )
    pair_graded = graded
    # tracks: the pair's paths at the skid tolerance (docs/verify.md, "Tracked robots")
    pair_position, pair_yaw = (
        (skid_tol.position, skid_tol.yaw) if skid_tol is not None else (tol.engines_position, tol.engines_yaw)
    )

    def record(
        engine: str,
        quantity: str,
        value: float,
        tolerance: float,
        detail: str,
        unit: str = "m",
        grade: bool = True,
    ) -> None:
        stance = engine in ungraded or (engine == PAIR and bool(ungraded))
        if grade and not stance:
            result.checks.append(Check(LAYER, engine, quantity, where, value, tolerance, detail))
        else:
            why = (f"not graded: {', '.join(sorted(ungraded))} leaves a drive wheel unloaded (see the skip). "
                   if stance and grade else "")
            result.observations.append(
                Observation(LAYER, engine, prefix + quantity, where, value, unit, why + note + detail)
            )

    mj, pb = runs.get("mujoco"), runs.get("pybullet")
    if mj is not None and pb is not None:
        d = difference(mj, pb)
        record(
            PAIR,
            "path-position",
            d.position,
            pair_position,
            f"MuJoCo's and PyBullet's root paths differ by up to {_cm(d.position)} "
            f"(t = {d.position_t:.2f} s; "
            f"{_cm(d.final)} at the end; tolerance {_cm(pair_position)}"
            + (", the skid tolerance" if skid_tol is not None else "") + ")",
            grade=pair_graded,
        )
        record(
            PAIR,
            "path-yaw",
            d.yaw,
            pair_yaw,
            f"MuJoCo's and PyBullet's headings differ by up to {_mrad(d.yaw)} (t = {d.yaw_t:.2f} s; "
            f"tolerance {_mrad(pair_yaw)}" + (", the skid tolerance" if skid_tol is not None else "") + ")",
            "rad",
            grade=pair_graded,
        )
        w, wt, side = wheel_difference(mj, pb)
        joint = (
            (drive.left, drive.right)[side]
            if drive.kind == "wheels"
            else f"{(drive.left, drive.right)[side]} roller 0"
        )
        record(
            PAIR,
            "wheel-angle",
            w,
            tol.engines_wheel,
            f"wheel joint angles differ by up to {w:.4f} rad ({joint}, t = {wt:.2f} s; tolerance "
            f"{tol.engines_wheel:g} rad)",
            "rad",
            grade=pair_graded,
        )
        shared = [j for j in (drive.pan, drive.tilt) if j and j in mj.joints and j in pb.joints]
        if shared:
            worst = max(
                shared, key=lambda j: float(np.max(np.abs(mj.joints[j] - _on(mj.t, pb, pb.joints[j]))))
            )
            value = float(np.max(np.abs(mj.joints[worst] - _on(mj.t, pb, pb.joints[worst]))))
            record(
                PAIR,
                "pan-tilt-angle",
                value,
                tol.engines_wheel,
                f"pan/tilt joint angles differ by up to {value:.2e} rad ({worst}; tolerance "
                f"{tol.engines_wheel:g} rad, the wheel-angle tolerance)",
                "rad",
                grade=pair_graded,
            )
    reference = ref["noslip"]
    for engine, trajectory in sorted(runs.items()):
        name = {"mujoco": "MuJoCo", "pybullet": "PyBullet"}.get(engine, engine)
        radii = effective_radius(trajectory, model, drive)
        radius_text = (
            f"effective rolling radius from its own path: left {_mm(radii[0])}, right {_mm(radii[1])} "
            f"(model {_mm(model.radius)})" + _radius_hint(radii, model.radius, drive)
        )
        if "skid" in ref:
            _skid_checks(engine, name, trajectory, ref["skid"], skid_tol if graded else None, record)
        else:
            d = difference(trajectory, reference)
            record(
                engine,
                "noslip-position",
                d.position,
                tol.noslip_position,
                f"{name}'s path is up to {_cm(d.position)} from the rigid no-slip reference built from the "
                f"source's mass properties (t = {d.position_t:.2f} s; tolerance {_cm(tol.noslip_position)}); "
                + radius_text,
                grade=graded,
            )
            record(
                engine,
                "noslip-yaw",
                d.yaw,
                tol.noslip_yaw,
                f"{name}'s heading is up to {_mrad(d.yaw)} from the rigid no-slip reference (t = "
                f"{d.yaw_t:.2f} s; tolerance {_mrad(tol.noslip_yaw)}); " + radius_text,
                "rad",
                grade=graded,
            )
        if native:
            continue
        odo = odometry(trajectory, model, drive)
        result.trajectories.append(odo)
        slip = difference(trajectory, odo)
        result.observations.append(
            Observation(
                LAYER,
                engine,
                "slip",
                where,
                slip.position,
                "m",
                note + f"largest distance between {name}'s path and its own wheel odometry "
                f"(r {_mm(model.radius)}, "
                f"b {_mm(model.half_axle)}): slip and effective-radius effects; heading {_mrad(slip.yaw)}",
            )
        )
        for label, value in zip(("left", "right"), radii, strict=True):
            result.observations.append(
                Observation(
                    LAYER,
                    engine,
                    f"effective-radius-{label}",
                    where,
                    value,
                    "m",
                    note + f"the rolling radius {name}'s own path implies for the {label} "
                    f"{'wheel' if drive.kind == 'wheels' else 'track roller 0'} (model {_mm(model.radius)}); "
                    "negative: a positive joint rotation moved that side backwards",
                )
            )
        u = difference(trajectory, ref["unicycle"])
        result.observations.append(
            Observation(
                LAYER,
                engine,
                "unicycle-position",
                where,
                u.position,
                "m",
                note + f"{name} vs the ideal unicycle of the commanded (v, w) "
                "(advisory, verification.md §2.1: the "
                f"controller's lag v·τ and the COM-offset yaw bias; heading {_mrad(u.yaw)})",
            )
        )
        result.observations.append(
            Observation(
                LAYER,
                engine,
                "unicycle-yaw",
                where,
                u.yaw,
                "rad",
                note + f"{name}'s heading vs the ideal unicycle (advisory)",
            )
        )


def _skid_checks(
    engine: str,
    name: str,
    trajectory: Trajectory,
    reference: Trajectory,
    tol: SkidTolerance | None,
    record: Any,
) -> None:
    """A tracked robot's path against the skid-steer reference (``tol`` None: not graded, reported)."""
    d = difference(trajectory, reference)
    position, yaw = (tol.position, tol.yaw) if tol is not None else (math.inf, math.inf)
    spread = (
        "; ".join(f"{k}: {_cm(p)} / {_mrad(q)}" for k, (p, q) in sorted(tol.parts.items()))
        if tol is not None
        else "not derived for a report-only profile"
    )
    record(
        engine,
        "skid-position",
        d.position,
        position,
        f"{name}'s path is up to {_cm(d.position)} from the skid-steer reference (t = {d.position_t:.2f} s; "
        f"{_cm(d.final)} at the end; tolerance {_cm(position)}, the largest spread of the reference: "
        f"{spread})",
        grade=tol is not None,
    )
    record(
        engine,
        "skid-yaw",
        d.yaw,
        yaw,
        f"{name}'s heading is up to {_mrad(d.yaw)} from the skid-steer reference (t = {d.yaw_t:.2f} s; "
        f"tolerance {_mrad(yaw)})",
        "rad",
        grade=tol is not None,
    )


RADIUS_HINT = 0.02  # an effective radius this far (relative) from the model's is pointed out


def _radius_hint(radii: tuple[float, float], radius: float, drive: Drive) -> str:
    """What an effective rolling radius far from the model's suggests (a wheel-radius, axis or
    left/right fault), for a failing check's detail."""
    what = "wheel" if drive.kind == "wheels" else "track roller"
    hints = []
    for side, value in zip(("left", "right"), radii, strict=True):
        if not math.isfinite(value):
            continue
        if value < 0:
            hints.append(
                f"the {side} {what} moves its side backwards for a positive rotation (a flipped joint "
                "axis, or left and right swapped?)"
            )
        elif abs(value - radius) > RADIUS_HINT * radius:
            hints.append(
                f"the {side} {what}'s effective radius is {100 * (value / radius - 1):+.1f} % off the "
                "model's (a wrong wheel radius, or left and right swapped?)"
            )
    return ": " + "; ".join(hints) if hints else ""


def _cm(x: float) -> str:
    return f"{x * 100:.3g} cm" if math.isfinite(x) else str(x)


def _mm(x: float) -> str:
    return f"{x * 1000:.4g} mm" if math.isfinite(x) else "n/a"


def _mrad(x: float) -> str:
    return f"{x * 1000:.3g} mrad" if math.isfinite(x) else str(x)


def profile_summary(result: Layer4Result) -> list[str]:
    """One line per check and observation (for logs and the benchmark)."""
    lines = []
    for c in result.checks:
        lines.append(
            f"{'PASS' if c.passed else 'FAIL'} {c.engine:16s} {c.quantity:16s} {c.where:20s} "
            f"{c.error:.3e} / {c.tolerance:.3e}"
        )
    for o in result.observations:
        lines.append(f"obs  {o.engine:16s} {o.quantity:26s} {o.where:28s} {o.value:.3e} {o.unit}")
    return lines


__all__ = ["Layer4Result", "difference", "effective_radius", "floating", "run"]
