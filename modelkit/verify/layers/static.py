"""Layer 1, static: link and joint sets, joint types, axes, limits, masses, COMs, inertia tensors
(and the collision shapes, :mod:`modelkit.verify.layers.shapes`).

Like every layer (:mod:`.kinematics` layer 2, :mod:`.dynamics` layer 3a), it compares what the
engines report with the source model (names mapped through the conversion's renames) and returns
:class:`Check`s (the worst error per quantity and engine, naming the source link or joint) and
:class:`Skip`s.

Errors: positions and COMs in metres (absolute), rotations in radians (the angle of R_aᵀR_b), axes
as the largest component difference of the unit vectors, limits relative (max(1, |x|)), masses
relative to the source mass, inertia tensors and the mass matrix relative to their largest entry,
bias forces relative to max(1e-6, largest entry). An engine may raise a tolerance for a quantity
through ``settings["tolerances"]`` (PyBullet's float32 paths: 1e-6); the report shows which.
"""

from __future__ import annotations

import math

import numpy as np

from modelkit.model import WORLD_LINK
from modelkit.verify.engines.protocol import Check, Skip, StaticFacts
from modelkit.verify.layers import shapes
from modelkit.verify.layers.common import Loaded, Worst, vec, zero_inertia

NO_LIMIT = 1e16  # SDF's default limits, ±1e16, mean none: libsdformat's readers (Drake) report ±inf


def _limit_error(a: float, b: float) -> float:
    """Relative difference of two joint limits. Against an infinite limit, a finite one at or beyond
    ±1e16 (same sign) is no limit either (example-robot-data's iris rotors: URDF limits ±1e16, read
    back from the SDF by Drake as ±inf); two finite limits are compared as numbers (a URDF stand-in of
    ±1e16 must be held exactly)."""
    if math.isinf(a) != math.isinf(b):
        a = math.copysign(math.inf, a) if abs(a) >= NO_LIMIT else a
        b = math.copysign(math.inf, b) if abs(b) >= NO_LIMIT else b
    if math.isinf(a) or math.isinf(b):
        return 0.0 if a == b else math.inf
    return abs(a - b) / max(1.0, abs(a), abs(b))


# ---- layer 1 ------------------------------------------------------------------------------------


def layer1(source: StaticFacts, eng: Loaded) -> list[Check]:
    """Static equivalence of one engine's model with the source model."""
    facts: StaticFacts = eng.model.static()
    label = eng.label
    checks: list[Check] = []

    world = world_root(source)
    # The source's root "world" link is the engine's world: MuJoCo's world body and PyBullet's fixed
    # base report it (compared), Drake's world body and SDF's world frame are no link of the model.
    missing = [name for name in source.links
               if eng.link(name) not in facts.links and eng.link(name) not in facts.frames and name != world]
    written = {eng.link(name) for name in source.links}
    extra = sorted(name for name in facts.links if name not in written and name not in source.named_frames)
    detail = f"missing {missing}, extra {extra}" if missing or extra else f"{len(source.links)} links"
    count = float(len(missing) + len(extra))
    checks.append(Check(1, label, "link-set", [*missing, *extra, ""][0], count, 0.0, detail))

    by_child = {jf.child: (name, jf) for name, jf in [*facts.frames.items(), *facts.joints.items()]}
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
                axes.see(err, name, f"axis {vec(sj.axis)} read back as {vec(ej.axis)}")
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
            com.see(err, name, f"COM {vec(sl.com)} m read back as {vec(el.com)} m")
        ia, ib = np.asarray(sl.inertia), np.asarray(el.inertia)
        diff = float(np.max(np.abs(ia - ib)))
        # relative to the tensor; two tensors validate calls zero (every principal moment within
        # ZERO_MOMENT of 0, MK302: iCub's head gives ±2.4e-35, which the engines hold as 0) are equal
        if not diff or (zero_inertia(ia) and zero_inertia(ib)):
            err = 0.0
        else:
            err = diff / max(float(np.max(np.abs(ia))), 1e-300)
        if inertia.beats(err):
            inertia.see(err, name, f"inertia {vec(ia)} kg·m² read back as {vec(ib)}")
    checks.append(mass.check(1, label, "mass", eng.tolerance("mass")))
    checks.append(com.check(1, label, "com", eng.tolerance("com")))
    checks.append(inertia.check(1, label, "inertia", eng.tolerance("inertia")))
    checks.extend(shapes.compare(source, facts, eng))  # collision shapes (modelkit.verify.layers.shapes)
    return checks


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
