"""A ``<joint>``: type, parent and child, axis, limits, dynamics, mimic and joint sensors.

Types: revolute, continuous (a revolute joint without limits), prismatic, fixed and ball map to the
model. universal, revolute2, screw and gearbox have more than one degree of freedom or couple two
motions: the model cannot hold them, so they are kept as FIXED placeholders that remember their SDF
type (``extras["sdf_type"]``) and reported as warnings (MK340): the file is valid SDF, only the
model is poorer. An unknown type is an error (MK121), as in libsdformat.

Limits: SDF writes "no limit" as ±1e16 (the default before SDFormat 1.11) and as negative effort
and velocity; those become infinities. The axis is read here as written; :mod:`assemble` expresses
it in the joint frame.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from lxml.etree import _Element as Element

from modelkit import rot3
from modelkit.diagnostics import Severity, SourceLocation, did_you_mean
from modelkit.formats.sdf.collect import MODEL_FRAME, Item
from modelkit.formats.sdf.context import Context
from modelkit.formats.sdf.kept import JOINT_KEY, JOINT_TAGS, LIMIT_KEY, LIMIT_TAGS, keep
from modelkit.formats.sdf.poses import FrameGraph
from modelkit.formats.sdf.sensors import sensor_device
from modelkit.formats.sdf.values import child, children
from modelkit.model import AXIS_UNIT_TOLERANCE, WORLD_LINK, Device, Joint, JointLimits, JointType, Mimic
from modelkit.spatial import Pose

TYPES = {
    "revolute": JointType.REVOLUTE,
    "continuous": JointType.REVOLUTE,
    "prismatic": JointType.PRISMATIC,
    "fixed": JointType.FIXED,
    "ball": JointType.BALL,
}
UNSUPPORTED = ("universal", "revolute2", "screw", "gearbox")
UNLIMITED = 1e16


@dataclass
class AxisSpec:
    """An axis as written: the vector and the frame it is expressed in (a vertex name; "" = joint)."""

    xyz: tuple[float, ...]
    frame: str
    loc: SourceLocation | None


@dataclass
class JointData:
    item: Item
    joint: Joint
    word: str
    parent_link: str | None = None  # resolved link, or "world"
    child_link: str | None = None
    axis: AxisSpec | None = None
    axis2: AxisSpec | None = None
    sensors: list[tuple[Device, Pose]] = field(default_factory=list)  # pose in the model frame

    @property
    def valid(self) -> bool:
        return self.parent_link is not None and self.child_link is not None


def read_joint(ctx: Context, graph: FrameGraph, item: Item) -> JointData:
    src = item.src
    values = src.values
    el = item.element
    word = (el.get("type") or "").strip()
    joint = Joint(name=item.name, type=JointType.FIXED, parent="", child="", source=values.loc(el))
    joint.sources["name"] = values.loc(el, "name")
    data = JointData(item, joint, word)
    what = f'joint "{item.local}"'
    if el.get("type") is None:
        ctx.sink.emit("MK120", f"{what} has no type attribute", values.loc(el))
    else:
        joint.sources["type"] = values.loc(el, "type")
        _type(ctx, data, what)
    _ends(ctx, graph, data, what)
    axis_el = child(el, "axis")
    if axis_el is not None:
        data.axis = _axis(ctx, graph, data, axis_el)
        _axis_details(ctx, data, axis_el)
    axis2_el = child(el, "axis2")
    if axis2_el is not None:
        data.axis2 = _axis(ctx, graph, data, axis2_el)
    keep(joint.extras, JOINT_KEY, el, JOINT_TAGS, "joint")  # <physics>
    if data.word in ("universal", "revolute2", "gearbox", "screw"):
        _keep_unsupported(data)
    for sensor_el in children(el, "sensor"):
        device = sensor_device(ctx, src, sensor_el, what)
        if device is None:
            continue
        device.params["sdf_joint"] = item.name
        pose = graph.element_pose(
            src, child(sensor_el, "pose"), item.scope, item.name, f'sensor "{device.name}"'
        )
        data.sensors.append((device, pose))
    return data


def _type(ctx: Context, data: JointData, what: str) -> None:
    joint, word = data.joint, data.word
    loc = joint.sources["type"]
    if word in TYPES:
        joint.type = TYPES[word]
        if word == "continuous":
            joint.extras["sdf_type"] = word
        return
    joint.extras["sdf_type"] = word
    if word in UNSUPPORTED:
        ctx.sink.emit(
            "MK340",
            f"{what} is a {word} joint, which the robot model cannot hold; it is kept as a fixed "
            "joint placeholder (the tree is right, its motion is lost)",
            loc,
        )
        return
    known = [*TYPES, *UNSUPPORTED]
    ctx.sink.emit(
        "MK121",
        f'{what} has type "{word}", which is not an SDFormat joint type',
        loc,
        hint=did_you_mean(word, known) or "types: " + ", ".join(known),
    )


def _ends(ctx: Context, graph: FrameGraph, data: JointData, what: str) -> None:
    item, joint = data.item, data.joint
    values = item.src.values
    names: dict[str, str] = {}
    for end in ("parent", "child"):
        el = child(item.element, end)
        text = values.text(el)
        if el is None or not text:
            ctx.sink.emit("MK122", f"{what} has no <{end}>", values.loc(item.element if el is None else el))
            continue
        loc = values.text_loc(el)
        joint.sources[end] = loc
        names[end] = text
        if text == WORLD_LINK:
            if end == "child":
                ctx.sink.emit("MK234", f'the child of {what} is "world"; a child must be a link', loc)
                continue
            data.parent_link = WORLD_LINK
            joint.parent = WORLD_LINK
            continue
        if text == MODEL_FRAME:  # current libsdformat resolves it to the canonical link, 12 refuses it
            canonical = graph.link_of(graph.lookup(item.scope, text) or "")
            resolved = f' "{canonical}"' if canonical else ""
            ctx.sink.emit(
                "MK156",
                f'the {end} of {what} is the model frame "{MODEL_FRAME}": libsdformat 13 and later resolve '
                f"it to the canonical link{resolved} (as modelkit does), libsdformat 12 (Gazebo Fortress) "
                f'refuses it ("{end} frame with name[{MODEL_FRAME}] ... not found in model")',
                loc,
                hint="name the link the joint is meant to join, which every libsdformat reads",
            )
        vertex = graph.lookup(item.scope, text)
        link = graph.link_of(vertex) if vertex is not None else None
        if vertex is None:
            ctx.sink.emit(
                "MK234",
                f'the {end} "{text}" of {what} names no link or frame of model "{item.scope.path}"',
                loc,
                hint=graph.suggest(item.scope, text, ("link", "frame")),
            )
            continue
        if link is None:
            continue  # the frame's attachment is broken: reported by the frame graph
        if end == "parent":
            data.parent_link, joint.parent = link, link
        else:
            data.child_link, joint.child = link, link
    if "parent" in names and names.get("parent") == names.get("child"):
        ctx.sink.emit(
            "MK235",
            f'{what} has "{names["child"]}" as both parent and child',
            joint.sources.get("child"),
        )
        data.child_link = None
    elif data.child_link is not None and data.child_link == data.parent_link:
        # libsdformat 12 checks the resolved links of the top model's joints only (error 21); a nested
        # model's joint is loaded as it is (gz-sim's nested_models/model.sdf)
        top = item.scope.parent is None
        ctx.sink.emit(
            "MK235",
            f'the parent "{names["parent"]}" and child "{names["child"]}" of {what} are both attached to '
            f'link "{data.child_link}": the joint would join that link to itself and move nothing; '
            + ("libsdformat refuses it" if top else "libsdformat checks this only in the top model"),
            joint.sources.get("child"),
            severity=None if top else Severity.WARNING,
        )
        if top:
            data.child_link = None
        data.child_link = None


def _axis(ctx: Context, graph: FrameGraph, data: JointData, axis_el: Element) -> AxisSpec:
    item = data.item
    src = item.src
    values = src.values
    xyz_el = child(axis_el, "xyz")
    xyz = values.vector(xyz_el, 3) if xyz_el is not None else None
    loc = values.text_loc(xyz_el) if xyz_el is not None else values.loc(axis_el)
    if xyz is None:
        xyz = (0.0, 0.0, 1.0)
    frame = ""
    if src.at_least(1, 7):
        written = (xyz_el.get("expressed_in") or "").strip() if xyz_el is not None else ""
        if written and xyz_el is not None:
            found = graph.lookup(item.scope, written)
            if found is None:
                ctx.sink.emit(
                    "MK239",
                    f'expressed_in "{written}" of the axis of joint "{item.local}" names no frame of model '
                    f'"{item.scope.path}"',
                    values.loc(xyz_el, "expressed_in"),
                    hint=graph.suggest(item.scope, written),
                )
            else:
                frame = found
    elif not src.at_least(1, 5):
        frame = item.scope.frame  # SDF 1.4: axes are expressed in the model frame
    elif values.boolean(child(axis_el, "use_parent_model_frame")):
        frame = item.scope.frame
    norm = rot3.norm(xyz)
    if norm == 0.0 and data.joint.type.moves:
        ctx.sink.emit("MK305", f'joint "{item.local}": the axis is the zero vector', loc)
    elif abs(norm - 1.0) > AXIS_UNIT_TOLERANCE and data.joint.type.moves:
        ctx.sink.emit(
            "MK306",
            f'joint "{item.local}": the axis "{_fmt_axis(xyz)}" has length {norm:.6g}, not 1; modelkit and '
            "MuJoCo (after conversion) normalise it",
            loc,
            hint="write a unit vector",
        )
    return AxisSpec(xyz, frame, loc)


def _fmt_axis(xyz: tuple[float, ...]) -> str:
    return " ".join(f"{v:g}" for v in xyz)


def _axis_details(ctx: Context, data: JointData, axis_el: Element) -> None:
    item, joint = data.item, data.joint
    values = item.src.values
    if data.axis is not None:
        joint.sources["axis"] = data.axis.loc or values.loc(axis_el)
    limit = child(axis_el, "limit")
    limits = JointLimits()
    if limit is not None:
        joint.sources["range"] = values.loc(limit)
        keep(joint.extras, LIMIT_KEY, limit, LIMIT_TAGS, "limit")  # the stop's <stiffness>, <dissipation>
        if joint.type in (JointType.REVOLUTE, JointType.PRISMATIC) and data.word != "continuous":
            limits.lower = _bound(values.child_number(limit, "lower", -math.inf, allow_inf=True))
            limits.upper = _bound(values.child_number(limit, "upper", math.inf, allow_inf=True))
        effort = values.child_number(limit, "effort", -1.0, allow_inf=True)
        velocity = values.child_number(limit, "velocity", -1.0, allow_inf=True)
        limits.effort = _rate(effort)
        limits.velocity = _rate(velocity)
        limits.velocity_lower, limits.velocity_upper = -limits.velocity, limits.velocity
    joint.limits = limits
    dynamics = child(axis_el, "dynamics")
    if dynamics is not None:
        joint.damping = values.child_number(dynamics, "damping", 0.0) or 0.0
        joint.friction = values.child_number(dynamics, "friction", 0.0) or 0.0
        stiffness = values.child_number(dynamics, "spring_stiffness", 0.0) or 0.0
        reference = values.child_number(dynamics, "spring_reference", 0.0) or 0.0
        joint.spring_stiffness, joint.spring_reference = stiffness, reference
    initial = child(axis_el, "initial_position")
    if initial is not None:
        joint.initial_position = values.number(initial, 0.0) or 0.0
    mimic = child(axis_el, "mimic")
    if mimic is not None:
        leader = (mimic.get("joint") or "").strip()
        multiplier = values.child_number(mimic, "multiplier", 1.0)
        offset = values.child_number(mimic, "offset", 0.0) or 0.0
        reference = values.child_number(mimic, "reference", 0.0) or 0.0
        multiplier = 1.0 if multiplier is None else multiplier
        joint.mimic = Mimic(
            joint=item.scope.scoped(leader) if leader else "",
            multiplier=multiplier,
            offset=offset - multiplier * reference,
            source=values.loc(mimic, "joint"),
        )
        if mimic.get("axis", "axis") != "axis":
            joint.extras["sdf_mimic_axis"] = mimic.get("axis")


def _bound(value: float | None) -> float:
    if value is None:
        return math.nan
    if value >= UNLIMITED:
        return math.inf
    if value <= -UNLIMITED:
        return -math.inf
    return value


def _rate(value: float | None) -> float:
    if value is None or value < 0.0 or value >= UNLIMITED:
        return math.inf
    return value


def _keep_unsupported(data: JointData) -> None:
    joint = data.joint
    for key, spec in (("sdf_axis", data.axis), ("sdf_axis2", data.axis2)):
        if spec is not None:
            joint.extras[key] = {"xyz": list(spec.xyz), "expressed_in": spec.frame}
    values = data.item.src.values
    for key in ("gearbox_ratio", "gearbox_reference_body", "thread_pitch", "screw_thread_pitch"):
        el = child(data.item.element, key)
        if el is not None:
            joint.extras[f"sdf_{key}"] = values.text(el)
