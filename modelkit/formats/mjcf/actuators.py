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

from typing import Any

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
