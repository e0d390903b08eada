"""The layers: each compares what the engines report with the source model (names mapped through
the conversion's renames) and returns :class:`Check`s (the worst error per quantity and engine,
naming the source link or joint) and :class:`Skip`s.

* layer 1, static: link and joint sets, joint types, axes, limits, masses, COMs, inertia tensors;
* layer 2, kinematics: link poses relative to the root link at random configurations;
* layer 3a, dynamics: joint-space mass matrix and bias forces at random (q, dq) against Pinocchio.

Errors: positions and COMs in metres (absolute), rotations in radians (the angle of R_aᵀR_b), axes
as the largest component difference of the unit vectors, limits relative (max(1, |x|)), masses
relative to the source mass, inertia tensors and the mass matrix relative to their largest entry,
bias forces relative to max(1e-6, largest entry). An engine may raise a tolerance for a quantity
through ``settings["tolerances"]`` (PyBullet's float32 paths: 1e-6); the report shows which.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from modelkit.convert.compare import random_configuration
from modelkit.model import WORLD_LINK, Robot
from modelkit.spatial import Pose
from modelkit.verify.engines.protocol import Array, Check, EngineModel, Skip, StaticFacts
from modelkit.verify.layers import shapes

TOLERANCE = 1e-9
Renames = dict[str, dict[str, str]]


@dataclass
class Loaded:
    """One engine with one model loaded, and the renames of the file it read (source → written)."""

    label: str  # "mujoco", "pybullet", "drake-sdf", ...
    model: EngineModel
    renames: Renames = field(default_factory=dict)

    def link(self, source_name: str) -> str:
        return self.renames.get("link", {}).get(source_name, source_name)

    def joint(self, source_name: str) -> str:
        return self.renames.get("joint", {}).get(source_name, source_name)

    def tolerance(self, quantity: str) -> float:
        tolerances = self.model.settings.get("tolerances", {})
        return float(tolerances.get(quantity, TOLERANCE))


class Worst:
    """The worst error seen for one quantity, and where."""

    def __init__(self) -> None:
        self.error = 0.0
        self.where = ""
        self.detail = ""

    def beats(self, error: float) -> bool:
        return error > self.error or (math.isnan(error) and not math.isnan(self.error))

    def see(self, error: float, where: str, detail: str) -> None:
        self.error, self.where, self.detail = error, where, detail

    def check(self, layer: int, engine: str, quantity: str, tolerance: float, empty: str = "") -> Check:
        error = math.inf if math.isnan(self.error) else self.error
        return Check(layer, engine, quantity, self.where, error, tolerance, self.detail or empty)


def _limit_error(a: float, b: float) -> float:
    if math.isinf(a) or math.isinf(b):
        return 0.0 if a == b else math.inf
    return abs(a - b) / max(1.0, abs(a), abs(b))


def _vec(v: Array) -> str:
    return "[" + ", ".join(f"{x:.9g}" for x in np.asarray(v).ravel()) + "]"


def rotation_angle(a: Array, b: Array) -> float:
    """The angle of the rotation between two rotation matrices (radians, accurate near zero)."""
    r = np.asarray(a).T @ np.asarray(b)
    s = 0.5 * float(np.linalg.norm([r[2, 1] - r[1, 2], r[0, 2] - r[2, 0], r[1, 0] - r[0, 1]]))
    c = 0.5 * (float(np.trace(r)) - 1.0)
    return math.atan2(s, c)


# ---- layer 1 ------------------------------------------------------------------------------------


def layer1(source: StaticFacts, eng: Loaded) -> list[Check]:
    """Static equivalence of one engine's model with the source model."""
    facts: StaticFacts = eng.model.static()
    label = eng.label
    checks: list[Check] = []

    world = world_root(source)
    # The source's root "world" link is the engine's world: MuJoCo's world body and PyBullet's fixed
    # base report it (compared), Drake's world body and SDF's world frame are no link of the model.
    missing = [name for name in source.links if eng.link(name) not in facts.links and name != world]
    written = {eng.link(name) for name in source.links}
    extra = sorted(name for name in facts.links if name not in written)
    detail = f"missing {missing}, extra {extra}" if missing or extra else f"{len(source.links)} links"
    count = float(len(missing) + len(extra))
    checks.append(Check(1, label, "link-set", [*missing, *extra, ""][0], count, 0.0, detail))

    by_child = {jf.child: (name, jf) for name, jf in facts.joints.items()}
    jmissing = [name for name, jf in source.joints.items() if eng.link(jf.child) not in by_child]
    checks.append(Check(1, label, "joint-set", [*jmissing, ""][0], float(len(jmissing)), 0.0,
                        f"no joint moves the links of {jmissing}" if jmissing
                        else f"{len(source.joints)} joints (matched by child link)"))

    axes, limits = Worst(), Worst()
    mismatched: list[str] = []
    for name, sj in source.joints.items():
        found = by_child.get(eng.link(sj.child))
        if found is None:
            continue
        ej = found[1]
        if ej.type != sj.type:
            mismatched.append(f"{name}: {sj.type} became {ej.type}")
            continue
        if sj.type in ("revolute", "prismatic"):
            err = float(np.max(np.abs(np.asarray(sj.axis) - np.asarray(ej.axis))))
            if axes.beats(err):
                axes.see(err, name, f"axis {_vec(sj.axis)} read back as {_vec(ej.axis)}")
            err = max(_limit_error(sj.lower, ej.lower), _limit_error(sj.upper, ej.upper))
            if limits.beats(err):
                limits.see(err, name, f"limits [{sj.lower:.9g}, {sj.upper:.9g}] read back as "
                                      f"[{ej.lower:.9g}, {ej.upper:.9g}]")
    checks.append(Check(1, label, "joint-type", mismatched[0].split(":")[0] if mismatched else "",
                        float(len(mismatched)), 0.0, "; ".join(mismatched) or "all types equal"))
    checks.append(axes.check(1, label, "axis", eng.tolerance("axis")))
    checks.append(limits.check(1, label, "limits", eng.tolerance("limits")))

    mass, com, inertia = Worst(), Worst(), Worst()
    for name, sl in source.links.items():
        el = facts.links.get(eng.link(name))
        if el is None or sl.mass == 0.0 or name == world:
            continue  # massless links: see massless_skips; the world welded: its mass takes part in nothing
        err = abs(sl.mass - el.mass) / abs(sl.mass)
        if mass.beats(err):
            mass.see(err, name, f"mass {sl.mass:.12g} kg read back as {el.mass:.12g} kg")
        err = float(np.linalg.norm(np.asarray(sl.com) - np.asarray(el.com)))
        if com.beats(err):
            com.see(err, name, f"COM {_vec(sl.com)} m read back as {_vec(el.com)} m")
        ia, ib = np.asarray(sl.inertia), np.asarray(el.inertia)
        diff = float(np.max(np.abs(ia - ib)))
        err = diff / max(float(np.max(np.abs(ia))), 1e-300) if diff else 0.0
        if inertia.beats(err):
            inertia.see(err, name, f"inertia {_vec(ia)} kg·m² read back as {_vec(ib)}")
    checks.append(mass.check(1, label, "mass", eng.tolerance("mass")))
    checks.append(com.check(1, label, "com", eng.tolerance("com")))
    checks.append(inertia.check(1, label, "inertia", eng.tolerance("inertia")))
    checks.extend(shapes.compare(source, facts, eng))  # collision shapes (modelkit.verify.layers.shapes)
    return checks


# ---- layer 2 ------------------------------------------------------------------------------------


def configurations(robot: Robot, count: int, seed: int) -> list[dict[str, float]]:
    """q = 0, then ``count`` random configurations inside the limits (±π / ±0.5 m where unlimited),
    mimic joints set from their leaders."""
    rng = np.random.default_rng(seed)
    out: list[dict[str, float]] = [{}]
    for _ in range(count):
        q = random_configuration(robot, rng)
        for joint in robot.joints:  # a mimic joint follows its leader (yourdfpy and URDF readers apply it)
            if joint.mimic is not None and joint.name in q and joint.mimic.joint in q:
                q[joint.name] = joint.mimic.multiplier * q[joint.mimic.joint] + joint.mimic.offset
        out.append(q)
    return out


def engine_q(q: dict[str, float], eng: Loaded) -> dict[str, float]:
    return {eng.joint(name): value for name, value in q.items()}


def layer2(reference: EngineModel, eng: Loaded, configs: list[dict[str, float]]) -> list[Check]:
    """Link poses relative to the root link, source FK vs the engine, over every configuration."""
    position, rotation = Worst(), Worst()
    for i, q in enumerate(configs):
        ref = reference.link_poses(q)
        got: dict[str, Pose] = eng.model.link_poses(engine_q(q, eng))
        for name, pa in ref.items():
            pb = got.get(eng.link(name))
            if pb is None:
                continue
            dp = float(np.linalg.norm(pa.translation - pb.translation))
            if position.beats(dp):
                position.see(dp, name, f"configuration {i}: origin {_vec(pa.translation)} m, "
                                       f"engine {_vec(pb.translation)} m")
            da = rotation_angle(pa.rotation, pb.rotation)
            if rotation.beats(da):
                rotation.see(da, name, f"configuration {i}: orientation differs by {da:.3g} rad")
    n = f"{len(configs)} configurations, every link"
    return [position.check(2, eng.label, "pose-position", eng.tolerance("pose"), n),
            rotation.check(2, eng.label, "pose-rotation", eng.tolerance("pose"), n)]


# ---- layer 3a -----------------------------------------------------------------------------------


State = tuple[dict[str, float], dict[str, float]]


def states(robot: Robot, dofs: list[str], count: int, seed: int) -> list[State]:
    """Random (q, dq): q inside the limits, dq uniform in ±2 rad/s (±0.5 m/s on prismatic joints)."""
    rng = np.random.default_rng(seed + 1)
    out = []
    for _ in range(count):
        q = random_configuration(robot, rng)
        dq = {name: float(rng.uniform(-2.0, 2.0)) for name in dofs}
        out.append((q, dq))
    return out


def layer3a(reference: EngineModel, eng: Loaded,
            samples: list[State]) -> list[Check]:
    """Mass matrix and bias forces of the engine against the reference, in the reference's dof order."""
    eng.model.mass_matrix({})  # NotImplementedError: an engine without dynamics (the caller skips it)
    ref_dofs = reference.dof_names()
    eng_dofs = eng.model.dof_names()
    where = {name: i for i, name in enumerate(eng_dofs)}
    order = [where.get(eng.joint(name), -1) for name in ref_dofs]
    label = eng.label
    if -1 in order or len(eng_dofs) != len(ref_dofs):
        lost = [name for name, i in zip(ref_dofs, order, strict=True) if i < 0]
        detail = f"degrees of freedom differ: source {ref_dofs}, engine {eng_dofs}; not found {lost}"
        first = [*lost, ""][0]
        return [Check(3, label, "mass-matrix", first, math.inf, eng.tolerance("mass-matrix"), detail),
                Check(3, label, "bias", first, math.inf, eng.tolerance("bias"), detail)]
    idx = np.asarray(order, dtype=int)
    mm, bias = Worst(), Worst()
    for k, (q, dq) in enumerate(samples):
        ma = reference.mass_matrix(q)
        mb = eng.model.mass_matrix(engine_q(q, eng))[np.ix_(idx, idx)]
        diff = np.abs(ma - mb)
        scale = max(float(np.max(np.abs(ma))) if ma.size else 0.0, 1e-300)
        if diff.size:
            i, j = (int(x) for x in np.unravel_index(int(np.argmax(diff)), diff.shape))
            err = float(diff[i, j]) / scale
            if mm.beats(err):
                mm.see(err, ref_dofs[i] if i == j else f"{ref_dofs[i]}/{ref_dofs[j]}",
                       f"sample {k}: M[{i},{j}] {ma[i, j]:.12g}, engine {mb[i, j]:.12g} "
                       f"(relative to max |M| = {scale:.6g})")
        ba = reference.bias(q, dq)
        bb = eng.model.bias(engine_q(q, eng), engine_q(dq, eng))[idx]
        bdiff = np.abs(ba - bb)
        if bdiff.size:
            n = int(np.argmax(bdiff))
            bscale = max(1e-6, float(np.max(np.abs(ba))))
            err = float(bdiff[n]) / bscale
            if bias.beats(err):
                bias.see(err, ref_dofs[n], f"sample {k}: bias {ba[n]:.12g}, engine {bb[n]:.12g} "
                                           f"(relative to max(1e-6, max |b|) = {bscale:.6g})")
    what = f"{len(samples)} random (q, dq), {len(ref_dofs)} dofs"
    return [mm.check(3, label, "mass-matrix", eng.tolerance("mass-matrix"), what),
            bias.check(3, label, "bias", eng.tolerance("bias"), what)]


def no_dynamics(eng: Loaded) -> Skip:
    return Skip(3, eng.label, f"{eng.label} computes kinematics only: no mass matrix or bias forces")



def massless_skips(source: StaticFacts, eng: Loaded) -> list[Skip]:
    """Links without mass in the source are frames: their mass, COM and inertia are not compared, and
    the Skip says what the engine made of them (writers give 1e-6 kg or nothing, MK816; PyBullet
    gives a URDF link without ``<inertial>`` 1 kg)."""
    facts = eng.model.static()
    got = {name: facts.links[eng.link(name)].mass for name, sl in source.links.items()
           if sl.mass == 0.0 and eng.link(name) in facts.links}
    if not got:
        return []
    shown = ", ".join(f"{n} {m:.3g} kg" for n, m in list(got.items())[:6]) + (" ..." if len(got) > 6 else "")
    return [Skip(1, eng.label, f"{len(got)} link(s) massless in the source (frames): mass, COM and inertia "
                               f"not compared; the engine has {shown} (MK816)")]


def world_root(source: StaticFacts) -> str | None:
    """The source's root link when it is the world itself (``world``, URDF's convention, and the MJCF
    reader's synthesised link for top-level bodies that hang from the world by their joints)."""
    children = {jf.child for jf in source.joints.values()}
    return WORLD_LINK if WORLD_LINK in source.links and WORLD_LINK not in children else None


def kinematic_only(robot: Robot) -> bool:
    """True when no link the joints move has mass: a kinematic model, no dynamics to verify."""
    moved = {j.child for j in robot.joints}
    return not any(link.inertial is not None and link.inertial.mass > 0 for link in robot.links
                   if link.name in moved)
