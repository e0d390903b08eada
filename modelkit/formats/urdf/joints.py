"""URDF ``<joint>`` elements: type, origin, parent/child, axis, limit, dynamics, mimic and the rest.

URDF's joint convention is the model's: ``origin`` is the child link frame in the parent link frame
and the axis is in the child (joint) frame, so nothing is converted. ``continuous`` becomes a
revolute joint without position limits (``extras["urdf_type"]`` keeps the word); ``<limit>`` lower
and upper are ignored on it, as urdfdom, libsdformat and MuJoCo ignore them.
"""

from __future__ import annotations

from lxml.etree import _Element as Element

from modelkit import rot3
from modelkit.diagnostics import did_you_mean
from modelkit.formats.urdf.values import Context, number, origin, vector
from modelkit.model import AXIS_UNIT_TOLERANCE, Joint, JointLimits, JointType, Mimic

JOINT_TYPES: dict[str, JointType] = {
    "revolute": JointType.REVOLUTE,
    "continuous": JointType.REVOLUTE,
    "prismatic": JointType.PRISMATIC,
    "fixed": JointType.FIXED,
    "floating": JointType.FLOATING,
    "planar": JointType.PLANAR,
}
NEEDS_LIMIT = ("revolute", "prismatic")
LIMIT_1_2 = ("acceleration", "deceleration", "jerk")


def read_joint(ctx: Context, element: Element) -> Joint:
    """A :class:`Joint`; every fault is reported and a usable joint still comes back."""
    name = element.get("name")
    if name is None:
        ctx.emit("MK120", "<joint> has no `name` attribute", ctx.loc(element))
    word = element.get("type")
    joint = Joint(name=name or "", type=JointType.FIXED, parent="", child="", source=ctx.loc(element))
    joint.axis = (1.0, 0.0, 0.0)
    joint.sources["name"] = ctx.loc(element, "name")
    joint.sources["type"] = ctx.loc(element, "type")
    label = f'joint "{joint.name}"'
    if word is None:
        ctx.emit("MK120", f"{label} has no `type` attribute", ctx.loc(element))
    elif word not in JOINT_TYPES:
        ctx.emit(
            "MK133",
            f'{label} has an unknown type "{word}" (URDF types: {", ".join(JOINT_TYPES)}); read as fixed',
            ctx.loc(element, "type"),
            hint=did_you_mean(word, tuple(JOINT_TYPES)),
        )
    else:
        joint.type = JOINT_TYPES[word]
    joint.extras["urdf_type"] = word if word in JOINT_TYPES else "fixed"
    _origin(ctx, element, joint, label)
    _links(ctx, element, joint)
    _axis(ctx, element, joint, label)
    _limit(ctx, element, joint, word, label)
    _dynamics(ctx, element, joint, label)
    _mimic(ctx, element, joint, label)
    _safety_and_calibration(ctx, element, joint, label)
    return joint


def _origin(ctx: Context, element: Element, joint: Joint, label: str) -> None:
    origin_el = ctx.first(element, "origin")
    if origin_el is None:
        return
    joint.sources["origin"] = ctx.loc(origin_el)
    pose = origin(ctx, origin_el, label)
    if pose is not None:
        joint.origin = pose


def _links(ctx: Context, element: Element, joint: Joint) -> None:
    """Parent and child names; a missing one stays "" (the tree rules and the reader report it)."""
    for role in ("parent", "child"):
        el = ctx.first(element, role)
        if el is None:
            continue
        value = el.get("link")
        joint.sources[role] = ctx.loc(el, "link")
        if value is not None:
            setattr(joint, role, value)


def _axis(ctx: Context, element: Element, joint: Joint, label: str) -> None:
    """The axis (default 1 0 0), normalised; urdfdom reads none for fixed and floating joints."""
    axis_el = ctx.first(element, "axis")
    if axis_el is None or joint.type in (JointType.FIXED, JointType.FLOATING):
        return
    joint.sources["axis"] = ctx.loc(axis_el, "xyz")
    if axis_el.get("xyz") is None:
        ctx.emit(
            "MK120", f"<axis> of {label} has no `xyz` attribute (urdfdom then uses 0 0 0)", ctx.loc(axis_el)
        )
        return
    values = vector(ctx, axis_el, "xyz", f"axis of {label}")
    if values is None:
        return
    norm = rot3.norm(values)
    if norm == 0.0:
        ctx.emit(
            "MK305",
            f'{label}: the axis "{axis_el.get("xyz")}" is the zero vector; the joint has no direction of '
            "motion and cannot be simulated (check_urdf and PyBullet load it; libsdformat and MuJoCo "
            "refuse it)",
            ctx.loc(axis_el, "xyz"),
        )
        return
    if abs(norm - 1.0) > AXIS_UNIT_TOLERANCE:
        ctx.emit(
            "MK306",
            f'{label}: the axis "{axis_el.get("xyz")}" has length {norm:.6g}, not 1; '
            f"{AXIS_NOT_UNIT_CONSUMERS}",
            ctx.loc(axis_el, "xyz"),
            hint="write a unit vector",
        )
    joint.axis = tuple(v / norm for v in values)


# What the consumers do with such an axis (measured: PyBullet 3.2.7, MuJoCo 4.0).
AXIS_NOT_UNIT_CONSUMERS = (
    "urdfdom and check_urdf keep it as written, PyBullet reports it as written (getJointInfo) but turns the "
    "joint by q about the normalised axis, MuJoCo and modelkit normalise it"
)


def _limit(ctx: Context, element: Element, joint: Joint, word: str | None, label: str) -> None:
    limit_el = ctx.first(element, "limit")
    if limit_el is None:
        if word in NEEDS_LIMIT:
            ctx.emit(
                "MK134",
                f"{label} is {word} but has no <limit> (URDF requires one, with effort and velocity)",
                ctx.loc(element),
                hint='add <limit lower="..." upper="..." effort="..." velocity="..."/>, or use "continuous"',
            )
        return
    joint.sources["limit"] = ctx.loc(limit_el)
    joint.sources["range"] = ctx.loc(limit_el, "lower" if limit_el.get("lower") is not None else "upper")
    what = f"limit of {label}"
    range_unset = word in NEEDS_LIMIT and limit_el.get("lower") is None and limit_el.get("upper") is None
    if range_unset:
        ctx.emit(
            "MK125",
            f"<limit> of {label} gives neither `lower` nor `upper`: urdfdom reads 0 and 0, a locked joint "
            "for urdfdom's users (ROS, MoveIt), while MuJoCo's, PyBullet's and Drake's URDF import leave it "
            "free, as modelkit reads it",
            ctx.loc(limit_el),
            hint='give lower="..." upper="...", or make the joint "continuous" if it turns without end',
        )
        joint.extras["urdf_range_unset"] = True  # written back the same way (write_joints)
    lower = number(ctx, limit_el, "lower", what, default=0.0)
    upper = number(ctx, limit_el, "upper", what, default=0.0)
    missing = [k for k in ("effort", "velocity") if limit_el.get(k) is None]
    if missing:
        ctx.emit(
            "MK120",
            f"<limit> of {label} has no `{'` and `'.join(missing)}` (urdfdom requires both)",
            ctx.loc(limit_el),
        )
    effort = number(ctx, limit_el, "effort", what)
    velocity = number(ctx, limit_el, "velocity", what)
    limits = JointLimits()
    if word in NEEDS_LIMIT and not range_unset:  # else unlimited, as the simulators read it (MK125)
        limits.lower = lower if lower is not None else 0.0
        limits.upper = upper if upper is not None else 0.0
    for key, value in (("effort", effort), ("velocity", velocity)):
        if value is not None and value < 0.0:
            ctx.emit(
                "MK323",
                f"{what}: `{key}` is negative ({value:g}); it is a magnitude (Choreonoid refuses it)",
                ctx.loc(limit_el, key),
            )
    if effort is not None:
        limits.effort = abs(effort)
    if velocity is not None:
        limits.velocity = abs(velocity)
        limits.velocity_lower, limits.velocity_upper = -abs(velocity), abs(velocity)
    joint.limits = limits
    extra = {}
    for key in LIMIT_1_2:
        if limit_el.get(key) is not None:
            ctx.uses_feature(f"`{key}` in <limit>", "1.2", ctx.loc(limit_el, key))
            value = number(ctx, limit_el, key, what)
            if value is not None:
                extra[key] = value
    if extra:
        joint.extras["limit"] = extra


def _dynamics(ctx: Context, element: Element, joint: Joint, label: str) -> None:
    dynamics = ctx.first(element, "dynamics")
    if dynamics is None:
        return
    joint.sources["dynamics"] = ctx.loc(dynamics)
    if dynamics.get("damping") is None and dynamics.get("friction") is None:
        ctx.emit(
            "MK120",
            f"<dynamics> of {label} has neither `damping` nor `friction` (urdfdom refuses it)",
            ctx.loc(dynamics),
        )
        return
    damping = number(ctx, dynamics, "damping", f"dynamics of {label}", default=0.0)
    friction = number(ctx, dynamics, "friction", f"dynamics of {label}", default=0.0)
    joint.damping = damping if damping is not None else 0.0
    joint.friction = friction if friction is not None else 0.0


def _mimic(ctx: Context, element: Element, joint: Joint, label: str) -> None:
    mimic = ctx.first(element, "mimic")
    if mimic is None:
        return
    joint.sources["mimic"] = ctx.loc(mimic)
    leader = mimic.get("joint")
    if leader is None:
        ctx.emit("MK120", f"<mimic> of {label} has no `joint` attribute", ctx.loc(mimic))
        return
    multiplier = number(ctx, mimic, "multiplier", f"mimic of {label}", default=1.0)
    offset = number(ctx, mimic, "offset", f"mimic of {label}", default=0.0)
    joint.mimic = Mimic(
        joint=leader,
        multiplier=1.0 if multiplier is None else multiplier,
        offset=0.0 if offset is None else offset,
        source=ctx.loc(mimic, "joint"),
    )


def _safety_and_calibration(ctx: Context, element: Element, joint: Joint, label: str) -> None:
    """``<safety_controller>`` and ``<calibration>``: kept as numbers in ``joint.extras``."""
    safety = ctx.first(element, "safety_controller")
    if safety is not None:
        joint.sources["safety_controller"] = ctx.loc(safety)
        if safety.get("k_velocity") is None:
            ctx.emit(
                "MK120", f"<safety_controller> of {label} has no `k_velocity` attribute", ctx.loc(safety)
            )
        values: dict[str, float] = {}
        for key in ("soft_lower_limit", "soft_upper_limit", "k_position", "k_velocity"):
            value = number(ctx, safety, key, f"safety controller of {label}")
            if value is not None:
                values[key] = value
        joint.extras["safety_controller"] = values
    calibration = ctx.first(element, "calibration")
    if calibration is not None:
        joint.sources["calibration"] = ctx.loc(calibration)
        found: dict[str, float] = {}
        for key in ("rising", "falling", "reference_position"):
            value = number(ctx, calibration, key, f"calibration of {label}")
            if value is not None:
                found[key] = value
        joint.extras["calibration"] = found
