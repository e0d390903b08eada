"""URDF writer, joints: type, origin, axis, limits, dynamics, mimic.

URDF requires ``effort`` and ``velocity`` on every ``<limit>`` and a ``<limit>`` on revolute and
prismatic joints. Where the model has no finite value a documented one is written (MK819):

* effort :data:`SYNTHESISED_EFFORT` = 1e6 (N·m or N) and velocity :data:`SYNTHESISED_VELOCITY`
  = 1e6 (rad/s or m/s): "no limit", far beyond any real actuator;
* a position bound of an unlimited prismatic joint (or the open side of a one-sided range):
  ±:data:`SYNTHESISED_POSITION` = ±1e16, the value libsdformat itself writes for an unlimited axis.

An unlimited revolute joint is ``continuous``. A ball joint (URDF has none) becomes three
``continuous`` joints about the child's X, Y and Z axes through two links that carry nothing but a
tiny explicit inertial (MK813, MK816: without one PyBullet gives each 1 kg): the same motion, though
the read-back model has two more links and three joints instead of one.
"""

from __future__ import annotations

import math
import re

import numpy as np
from lxml import etree
from lxml.etree import _Element as Element

from modelkit.convert.context import WriteContext
from modelkit.convert.joint_springs import note_spring_dropped
from modelkit.convert.numbers import fmt, fmt_direction
from modelkit.formats.urdf.write_links import origin_element
from modelkit.formats.urdf.write_names import NameTable
from modelkit.model import Joint, JointLimits, JointType, Link
from modelkit.spatial import Pose

SYNTHESISED_EFFORT = 1e6
SYNTHESISED_VELOCITY = 1e6
SYNTHESISED_POSITION = 1e16

URDF_TYPE = {
    JointType.FIXED: "fixed",
    JointType.PSEUDO_CONTINUOUS_TRACK: "fixed",
    JointType.PRISMATIC: "prismatic",
    JointType.FLOATING: "floating",
    JointType.PLANAR: "planar",
}
BALL_AXES = (("x", (1.0, 0.0, 0.0)), ("y", (0.0, 1.0, 0.0)), ("z", (0.0, 0.0, 1.0)))
# The MK813 note of a ball joint, as :func:`_ball` writes it: the source joint, the three written
# joints, the child as written and the two added links (verify reads the chain back from it).
BALL_NOTE = re.compile(r'joint "(?P<joint>.+)" is a ball joint, which URDF lacks; written as three '
                       r'continuous joints \((?P<x>[^,]+), (?P<y>[^,]+), (?P<z>[^)]+)\) '
                       r'about the X, Y and Z axes of '
                       r'"(?P<child>.+)" through the links "(?P<link_x>.+)" and "(?P<link_y>.+)", which')


def _velocity(limits: JointLimits) -> tuple[float, bool]:
    """The symmetric velocity bound URDF holds (the tightest given), and whether the model's velocity
    range is asymmetric (then it is narrowed to that bound)."""
    lo, hi = limits.velocity_lower, limits.velocity_upper
    value = min([limits.velocity] + [abs(v) for v in (lo, hi) if math.isfinite(v)])
    return value, lo != -hi


def _limit_element(
    parent: Element, joint: Joint, name: str, ctx: WriteContext, positions: bool, dropped: list[str]
) -> None:
    limits = joint.limits
    target = f"joint[{name}]/limit"
    velocity, narrowed = _velocity(limits)
    if narrowed:
        dropped.append(
            f"velocity range [{fmt(limits.velocity_lower)}, {fmt(limits.velocity_upper)}] "
            f"(written as ±{fmt(velocity)})"
        )
    effort = limits.effort
    synthesised = []
    if not math.isfinite(effort):
        effort = SYNTHESISED_EFFORT
        synthesised.append(f"effort {fmt(SYNTHESISED_EFFORT)}")
    if not math.isfinite(velocity):
        velocity = SYNTHESISED_VELOCITY
        synthesised.append(f"velocity {fmt(SYNTHESISED_VELOCITY)}")
    el = etree.SubElement(parent, "limit")
    if positions:
        lower, upper = limits.lower, limits.upper
        if not math.isfinite(lower) or not math.isfinite(upper):
            lower = lower if math.isfinite(lower) else -SYNTHESISED_POSITION
            upper = upper if math.isfinite(upper) else SYNTHESISED_POSITION
            ctx.note(
                "MK819",
                f'joint "{name}" has no position limit on one side or both; URDF requires both, '
                f"written: lower {fmt(lower)}, upper {fmt(upper)}",
                joint.loc("range"),
                target,
            )
        el.set("lower", fmt(lower))
        el.set("upper", fmt(upper))
    el.set("effort", fmt(effort))
    el.set("velocity", fmt(velocity))
    if synthesised:
        ctx.note(
            "MK819",
            f'joint "{name}" has no finite {" or ".join(s.split()[0] for s in synthesised)} '
            f"limit; URDF requires one, written: {', '.join(synthesised)} (no limit)",
            joint.loc("limit"),
            target,
        )


def _dynamics(parent: Element, damping: float, friction: float) -> None:
    if damping != 0.0 or friction != 0.0:
        etree.SubElement(parent, "dynamics", damping=fmt(damping), friction=fmt(friction))


def _dropped_values(joint: Joint, dropped: list[str]) -> None:
    if joint.armature != 0.0:
        dropped.append(f"armature {fmt(joint.armature)}")
    if joint.initial_position != 0.0:
        dropped.append(f"initial position {fmt(joint.initial_position)}")
    if joint.joint_id is not None:
        dropped.append(f"joint id {joint.joint_id}")
    if joint.actuation_mode:
        dropped.append(f"actuation mode {joint.actuation_mode}")
    if "limit" in joint.extras:
        dropped.append("URDF 1.2 acceleration/deceleration/jerk limits")


def _extras(parent: Element, joint: Joint) -> None:
    """URDF's ``<calibration>`` and ``<safety_controller>``, kept by the URDF reader."""
    calibration = joint.extras.get("calibration")
    if isinstance(calibration, dict) and calibration:
        etree.SubElement(parent, "calibration", {k: fmt(v) for k, v in calibration.items()})
    safety = joint.extras.get("safety_controller")
    if isinstance(safety, dict) and "k_velocity" in safety:
        etree.SubElement(parent, "safety_controller", {k: fmt(v) for k, v in safety.items()})


def _axis(joint: Joint) -> str:
    axis = np.asarray(joint.axis, dtype=float)
    norm = float(np.linalg.norm(axis))
    return fmt_direction(axis / norm if norm > 0.0 else axis)


def joint_elements(
    joint: Joint, index: int, names: NameTable, ctx: WriteContext, extra_links: list[Link]
) -> list[Element]:
    """The ``<joint>`` element(s) for one model joint; ``extra_links`` receives the links to add (each
    massless and moving: the writer gives it a tiny inertial)."""
    name = names.joints[index]
    parent, child = names.link(joint.parent), names.link(joint.child)
    if joint.type is JointType.BALL:
        return _ball(joint, name, parent, child, names, ctx, extra_links)
    el = etree.Element("joint", name=name)
    dropped: list[str] = []
    limited = joint.limits.position_limited
    # a URDF source's <limit> without lower and upper (MK125) is written the same way: free in the
    # simulators that read it so, locked at 0 where urdfdom's reading rules, as the source is
    range_unset = bool(joint.extras.get("urdf_range_unset")) and not limited
    if joint.type is JointType.REVOLUTE:
        word = "revolute" if limited or range_unset else "continuous"
    else:
        word = URDF_TYPE[joint.type]
    el.set("type", word)
    origin_element(el, joint.origin)
    etree.SubElement(el, "parent", link=parent)
    etree.SubElement(el, "child", link=child)
    if word in ("revolute", "continuous", "prismatic", "planar"):
        etree.SubElement(el, "axis", xyz=_axis(joint))
    if word in ("revolute", "prismatic"):
        _limit_element(el, joint, name, ctx, not range_unset, dropped)
    elif word == "continuous" and (
        math.isfinite(joint.limits.effort)
        or math.isfinite(joint.limits.velocity)
        or math.isfinite(joint.limits.velocity_upper)
    ):
        _limit_element(el, joint, name, ctx, False, dropped)
    elif word == "continuous":
        _, narrowed = _velocity(joint.limits)
        if narrowed:
            dropped.append("velocity range")
    _extras(el, joint)
    if word == "planar" and (joint.damping != 0.0 or joint.friction != 0.0):
        # a planar joint's <dynamics>: urdfdom reads one damping number and refuses three; Drake's parser
        # wants three (x, y, θ) and refuses one or none ("Expected 3 values for attribute damping got 1")
        dropped.append(f"damping {fmt(joint.damping)} and friction {fmt(joint.friction)} of a planar joint "
                       "(its <dynamics>: urdfdom reads one damping number, Drake's parser three; no form "
                       "loads in both)")
    else:
        _dynamics(el, joint.damping, joint.friction)
    if joint.mimic is not None and joint.mimic.joint not in names.joint_map:
        ctx.note(
            "MK812",
            f'joint "{name}" mimics "{joint.mimic.joint}", which is not a joint of this robot; '
            "the mimic is left out",
            joint.mimic.source or joint.source,
            f"joint[{name}]",
        )
    elif joint.mimic is not None:
        etree.SubElement(
            el,
            "mimic",
            joint=names.joint(joint.mimic.joint),
            multiplier=fmt(joint.mimic.multiplier),
            offset=fmt(joint.mimic.offset),
        )
    if joint.type is JointType.PSEUDO_CONTINUOUS_TRACK:
        ctx.note(
            "MK813",
            f'joint "{name}" is a pseudo continuous track; written as fixed',
            joint.source,
            f"joint[{name}]",
        )
    _dropped_values(joint, dropped)
    if dropped:
        ctx.note(
            "MK820",
            f'joint "{name}": URDF has no field for ' + "; ".join(dropped) + ", left out",
            joint.source,
            f"joint[{name}]",
        )
    note_spring_dropped(ctx, joint, "URDF has no joint spring", f"joint[{name}]")
    return [el]


def _ball(
    joint: Joint,
    name: str,
    parent: str,
    child: str,
    names: NameTable,
    ctx: WriteContext,
    extra_links: list[Link],
) -> list[Element]:
    """Three continuous joints (X, Y, Z of the child frame) through two links without mass of their
    own, named in the MK813 note (:data:`BALL_NOTE` reads it back)."""
    links = [parent, names.fresh(f"{child}_ball_x"), names.fresh(f"{child}_ball_y"), child]
    out = []
    for i, (suffix, axis) in enumerate(BALL_AXES):
        el = etree.Element("joint", name=names.fresh(f"{name}_{suffix}"))
        el.set("type", "continuous")
        origin_element(el, joint.origin if i == 0 else Pose())
        etree.SubElement(el, "parent", link=links[i])
        etree.SubElement(el, "child", link=links[i + 1])
        etree.SubElement(el, "axis", xyz=fmt_direction(axis))
        _dynamics(el, joint.damping, joint.friction)
        out.append(el)
    extra_links.extend(Link(link, source=joint.source) for link in links[1:3])
    ctx.note(
        "MK813",
        f'joint "{joint.name}" is a ball joint, which URDF lacks; written as three continuous '
        f'joints ({", ".join(e.get("name", "") for e in out)}) about the X, Y and Z axes of "{child}" '
        f'through the links "{links[1]}" and "{links[2]}", which carry only a tiny inertial (MK816)',
        joint.source,
        f"joint[{out[0].get('name', '')}]",
    )
    if joint.armature != 0.0:
        ctx.note(
            "MK820",
            f'joint "{joint.name}": URDF has no field for armature {fmt(joint.armature)}, left out',
            joint.source,
            f"joint[{out[0].get('name', '')}]",
        )
    note_spring_dropped(ctx, joint, "URDF has no joint spring", f"joint[{out[0].get('name', '')}]")
    return out
