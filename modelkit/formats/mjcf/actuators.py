"""MJCF actuators as the model's canonical :class:`~modelkit.model.Actuator` (read from ``MjModel``).

MuJoCo compiles every shortcut to one general actuator: force = gear · (gain · ctrl + bias), gain =
``gainprm[0]`` (fixed), bias = ``biasprm[0] + biasprm[1]·length + biasprm[2]·velocity`` (affine), where
length = gear · q. The canonical kinds are recognised from those numbers, whichever element wrote them
(``<motor>``, ``<position>``, ``<velocity>``, or a ``<general>`` saying the same, as Menagerie's arms do):

* gain fixed, no bias → ``effort``, gear = gear · gain;
* gain kp, bias (0, −kp, −kv) → ``position`` with kp, kv;
* gain kv, bias (0, 0, −kv) → ``velocity`` with kv.

Actuators with activation dynamics (``dyntype`` not none: filtered servos, muscles, ``intvelocity``),
other gain or bias laws, or a transmission other than one hinge or slide joint are not canonical: they
stay in ``extras["mjcf_actuators"]`` only.
"""

from __future__ import annotations

from typing import Any, NamedTuple

from modelkit.model import Actuator, ActuatorKind, Joint

_REL = 1e-9


def _same(a: float, b: float) -> bool:
    return abs(a - b) <= _REL * max(1.0, abs(a), abs(b))


Classified = tuple[ActuatorKind, float | None, float | None]


def classify(gain: float, bias: tuple[float, float, float]) -> Classified | None:
    """(kind, kp, kv) of a fixed-gain actuator with bias (b0, b1, b2), or None when not canonical."""
    b0, b1, b2 = bias
    if b0 == 0.0 and b1 == 0.0 and b2 == 0.0:
        return ActuatorKind.EFFORT, None, None
    if b0 != 0.0 or gain <= 0.0:
        return None
    if _same(b1, -gain) and b2 <= 0.0:
        return ActuatorKind.POSITION, gain, -b2
    if b1 == 0.0 and _same(b2, -gain):
        return ActuatorKind.VELOCITY, None, gain
    return None


def read_actuators(mj: Any, m: Any, joints: dict[int, Joint]) -> list[tuple[int, int, Actuator]]:
    """(MuJoCo actuator index, joint index, actuator) for each canonical actuator, in model order."""
    out: list[tuple[int, int, Actuator]] = []
    hinge_slide = (int(mj.mjtJoint.mjJNT_HINGE), int(mj.mjtJoint.mjJNT_SLIDE))
    for a in range(int(m.nu)):
        if int(m.actuator_trntype[a]) != int(mj.mjtTrn.mjTRN_JOINT):
            continue
        j = int(m.actuator_trnid[a][0])
        joint = joints.get(j)
        if joint is None or int(m.jnt_type[j]) not in hinge_slide:
            continue
        if int(m.actuator_dyntype[a]) != int(mj.mjtDyn.mjDYN_NONE):
            continue
        if int(m.actuator_gaintype[a]) != int(mj.mjtGain.mjGAIN_FIXED):
            continue
        gain = float(m.actuator_gainprm[a][0])
        biastype = int(m.actuator_biastype[a])
        if biastype == int(mj.mjtBias.mjBIAS_NONE):
            bias = (0.0, 0.0, 0.0)
        elif biastype == int(mj.mjtBias.mjBIAS_AFFINE):
            row = m.actuator_biasprm[a]
            bias = (float(row[0]), float(row[1]), float(row[2]))
        else:
            continue
        found = classify(gain, bias)
        if found is None:
            continue
        kind, kp, kv = found
        gear = float(m.actuator_gear[a][0])
        element = "motor" if kind is ActuatorKind.EFFORT else kind.value
        name = mj.mj_id2name(m, mj.mjtObj.mjOBJ_ACTUATOR, a)
        actuator = Actuator(
            joint=joint.name,
            kind=kind,
            name=str(name) if name else None,
            gear=gear * gain if kind is ActuatorKind.EFFORT else gear,
            kp=kp,
            kv=kv,
            source_kind=element,
        )
        if bool(m.actuator_ctrllimited[a]):
            lo, hi = (float(x) for x in m.actuator_ctrlrange[a])
            actuator.ctrl_range = (lo, hi)
        if bool(m.actuator_forcelimited[a]):
            lo, hi = (float(x) for x in m.actuator_forcerange[a])
            actuator.force_range = (lo, hi)
        out.append((a, j, actuator))
    return out


TENDON_SOURCE = "general on a fixed tendon"
"""``Actuator.source_kind`` of an actuator read from one on a fixed tendon (:func:`tendon_actuators`):
the MJCF writer writes the source's own element back instead (:mod:`.write_transmissions`)."""


class OnJoint(NamedTuple):
    """An MJCF actuator on a fixed tendon read as one on the joint its joints follow."""

    actuator_id: int  # the MuJoCo actuator
    actuator: Actuator
    tendon: str
    scale: float  # the control u drives the joint's target as scale·u + offset (position, velocity)
    offset: float


def tendon_actuators(mj: Any, m: Any, joints: dict[int, Joint]) -> list[OnJoint]:
    """Actuators on a fixed tendon whose joints all follow one joint, read as one on that joint.

    A fixed tendon's length is L = Σ cᵢ qᵢ; where every qᵢ is the leader's q or a mimic of it (qᵢ = mᵢ q
    + oᵢ, as the reader made of the file's joint equalities: MuJoCo Menagerie's Panda gripper), L = k q +
    c₀ with k = Σ cᵢ mᵢ and c₀ = Σ cᵢ oᵢ, and an actuator with gear g on the tendon (length ℓ = g L) acts
    on q through the moment g k. Its force F = G u + b₁ ℓ + b₂ ℓ̇ (a fixed gain G, an affine bias without
    a constant) is then, at the joint, τ = g k F:

    * no bias: an effort actuator of gear g k G;
    * b₁ < 0: a position servo kp = −b₁ (g k)², kv = −b₂ (g k)², whose target q* = G u / (−b₁ g k) − c₀ / k;
    * b₁ = 0, b₂ < 0: a velocity servo kv = −b₂ (g k)², target q̇* = G u / (−b₂ g k).

    The model's position and velocity actuators take the target as their control, so the control range
    is mapped through it (``scale``, ``offset``); the force range is F's times g k. Activation dynamics,
    spatial tendons and tendons whose joints do not follow one joint are not read."""
    out: list[OnJoint] = []
    for a in range(int(m.nu)):
        if int(m.actuator_trntype[a]) != int(mj.mjtTrn.mjTRN_TENDON):
            continue
        if int(m.actuator_dyntype[a]) != int(mj.mjtDyn.mjDYN_NONE) or \
                int(m.actuator_gaintype[a]) != int(mj.mjtGain.mjGAIN_FIXED):
            continue
        biastype = int(m.actuator_biastype[a])
        if biastype == int(mj.mjtBias.mjBIAS_NONE):
            b0 = b1 = b2 = 0.0
        elif biastype == int(mj.mjtBias.mjBIAS_AFFINE):
            b0, b1, b2 = (float(x) for x in m.actuator_biasprm[a][:3])
        else:
            continue
        t = int(m.actuator_trnid[a][0])
        coupling = _follows_one(mj, m, t, joints)
        if coupling is None or b0 != 0.0:
            continue
        leader, k, c0 = coupling
        gain, moment = float(m.actuator_gainprm[a][0]), float(m.actuator_gear[a][0]) * k
        name = mj.mj_id2name(m, mj.mjtObj.mjOBJ_ACTUATOR, a)
        tendon = str(mj.mj_id2name(m, mj.mjtObj.mjOBJ_TENDON, t) or f"tendon {t}")
        actuator = Actuator(joint=leader, name=str(name) if name else None, source_kind=TENDON_SOURCE)
        scale, offset = 1.0, 0.0
        if b1 == 0.0 and b2 == 0.0:
            actuator.kind, actuator.gear = ActuatorKind.EFFORT, moment * gain
        elif b1 < 0.0 and b2 <= 0.0 and gain > 0.0:
            actuator.kind, actuator.kp, actuator.kv = ActuatorKind.POSITION, -b1 * moment**2, -b2 * moment**2
            scale, offset = gain / (-b1 * moment), -c0 / k
        elif b1 == 0.0 and b2 < 0.0 and gain > 0.0:
            actuator.kind, actuator.kv = ActuatorKind.VELOCITY, -b2 * moment**2
            scale = gain / (-b2 * moment)
        else:
            continue
        if bool(m.actuator_ctrllimited[a]):
            lo, hi = (scale * float(x) + offset for x in m.actuator_ctrlrange[a])
            actuator.ctrl_range = (min(lo, hi), max(lo, hi))
        if bool(m.actuator_forcelimited[a]):
            lo, hi = (moment * float(x) for x in m.actuator_forcerange[a])
            actuator.force_range = (min(lo, hi), max(lo, hi))
        out.append(OnJoint(a, actuator, tendon, scale, offset))
    return out


def _follows_one(mj: Any, m: Any, t: int, joints: dict[int, Joint]) -> tuple[str, float, float] | None:
    """(the joint, k, c₀) when fixed tendon ``t``'s joints all follow one joint (module docstring)."""
    start, count = int(m.tendon_adr[t]), int(m.tendon_num[t])
    by_name = {joint.name: joint for joint in joints.values()}
    leader: str | None = None
    k = c0 = 0.0
    for w in range(start, start + count):
        if int(m.wrap_type[w]) != int(mj.mjtWrap.mjWRAP_JOINT):
            return None
        joint = joints.get(int(m.wrap_objid[w]))
        if joint is None:
            return None
        coef = float(m.wrap_prm[w])
        mimic = joint.mimic
        name, multiplier, shift = (joint.name, 1.0, 0.0) if mimic is None else \
            (mimic.joint, mimic.multiplier, mimic.offset)
        if by_name.get(name) is None or by_name[name].mimic is not None or leader not in (None, name):
            return None
        leader = name
        k += coef * multiplier
        c0 += coef * shift
    if leader is None or abs(k) < 1e-12:
        return None
    return leader, k, c0
