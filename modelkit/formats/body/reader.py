"""The Choreonoid `.body` reader: YAML → schema check → robot model, with diagnostics.

It never stops at the first fault: every problem becomes a diagnostic with a file, line and
column, and the model is built from whatever can be read. ``body-format.md`` (in the project's
shared docs) is the specification; section numbers below refer to it.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path

from modelkit import rot3
from modelkit.diagnostics import DiagnosticSink, SourceLocation, sorted_diagnostics
from modelkit.formats.body import values as v
from modelkit.formats.body.elements import Collected, WalkContext, inertia_matrix, walk
from modelkit.formats.body.materials import MaterialTable, load_materials
from modelkit.formats.body.values import IDENTITY_AFFINE
from modelkit.formats.common import ReadOptions, ReadResult
from modelkit.limits import too_many_links
from modelkit.model import (
    Actuator,
    ActuatorKind,
    Inertial,
    Joint,
    JointLimits,
    JointType,
    Link,
    LoopConstraint,
    Robot,
)
from modelkit.spatial import Pose
from modelkit.textio import real_path
from modelkit.yamltree import (
    YMap,
    YNode,
    YScalar,
    YSeq,
    parse_yaml,
    read_text,
)

JOINT_TYPES: dict[str, JointType] = {
    "revolute": JointType.REVOLUTE,
    "prismatic": JointType.PRISMATIC,
    "slide": JointType.PRISMATIC,
    "free": JointType.FLOATING,
    "fixed": JointType.FIXED,
    "pseudo_continuous_track": JointType.PSEUDO_CONTINUOUS_TRACK,
    "pseudoContinuousTrack": JointType.PSEUDO_CONTINUOUS_TRACK,
}
AXIS_SYMBOLS = {"x": (1.0, 0.0, 0.0), "y": (0.0, 1.0, 0.0), "z": (0.0, 0.0, 1.0)}
ACTUATION_MODES = {
    "joint_effort": "effort",
    "jointEffort": "effort",
    "jointTorque": "effort",
    "jointForce": "effort",
    "joint_displacement": "displacement",
    "jointDisplacement": "displacement",
    "jointAngle": "displacement",
    "joint_velocity": "velocity",
    "jointVelocity": "velocity",
    "link_position": "link_position",
    "linkPosition": "link_position",
    "jointSurfaceVelocity": "velocity",
}
BODY_ACTUATOR_KINDS = {
    "effort": ActuatorKind.EFFORT,
    "displacement": ActuatorKind.POSITION,
    "velocity": ActuatorKind.VELOCITY,
}
# Keys that limit a joint's motion: meaningless on a fixed joint.
LIMIT_KEYS = (
    "joint_range",
    "jointRange",
    "max_joint_velocity",
    "maxJointVelocity",
    "joint_velocity_range",
    "jointVelocityRange",
)
MASS_KEYS = ("mass", "center_of_mass", "centerOfMass", "inertia")


# The .body reader takes the shared reading options; the old name stays for callers.
BodyOptions = ReadOptions


@dataclass
class _LinkRecord:
    link: Link
    joint: Joint
    parent: str | None
    parent_loc: SourceLocation | None
    joint_type_word: str | None
    pose: Pose


def read_body(path: Path, options: BodyOptions | None = None, display: str | None = None) -> ReadResult:
    """Read a `.body` file into a :class:`Robot`; the robot is None when nothing usable was read."""
    options = options or BodyOptions()
    sink = DiagnosticSink()
    with v.trailing_text_noted() as noted:
        robot = _BodyReader(path, options, sink, display or str(path), stack=()).read()
    for node in noted:  # the sink keeps one record per place: a value read twice is reported once
        sink.emit("MK181", trailing_text_message(node.value), node.loc, hint=TRAILING_TEXT_HINT)
    return ReadResult(robot, sorted_diagnostics(sink.items))


# MK181: what Choreonoid does with a number followed by text ("0.001f", "0.5m") where it reads the value
# with a "to" accessor (list elements, mass): C strtod reads the leading number and the rest is dropped.
TRAILING_TEXT_HINT = "write the number alone (no C-style suffix such as f, no unit)"


def trailing_text_message(text: str) -> str:
    number = v.leading_number_text(text) or text
    value = v.parse_float(number)
    shown = number if value is None else f"{value:g}"
    rest = text.strip()[len(number):]
    what = f'"{text}" is a number followed by text'
    return f'{what}: Choreonoid reads {shown} and ignores "{rest}" (so does modelkit)'



# SubBody loads one read may make, each inclusion counted (MK009): a body included twice by each of 20
# nested bodies is 2^20 loads (it ran for minutes); real models load a handful. ~3 ms a load.
MAX_SUBBODY_LOADS = 2_000

# What Choreonoid does with a SubBody it cannot load (MK216): the robot loses that whole subtree.
SUBBODY_DROPPED = (
    "Choreonoid prints \"cannot be loaded\" and loads the robot without that subtree (its links, masses and "
    "collision shapes), which cannot be simulated as the robot it describes"
)

class _BodyReader:
    def __init__(
        self, path: Path, options: BodyOptions, sink: DiagnosticSink, display: str, stack: tuple[str, ...],
        loads: list[int] | None = None,
    ) -> None:
        self.loads = loads if loads is not None else [0]  # SubBody loads of this whole read (MK009)
        self.path = path
        self.options = options
        self.sink = sink
        self.display = display
        self.stack = (*stack, str(real_path(path)))
        self.angle_scale = math.pi / 180.0
        self.materials: MaterialTable | None = None
        self.drives: dict[int, tuple[float, float]] = {}  # id(joint) → (rotor inertia, gear ratio)

    # -- top level ---------------------------------------------------------------------------

    def read(self) -> Robot | None:
        text = read_text(self.path, self.sink, self.options.max_bytes, self.display)
        if text is None:
            return None
        doc = parse_yaml(
            text,
            self.display,
            self.sink,
            self.options.expansion_limit,
            self.options.max_list_items,
            {"links": self.options.max_links},
        )
        if doc.root is None:
            return None
        root = doc.root
        if not isinstance(root, YMap):
            self.sink.emit("MK017", "the top-level node must be a mapping", root.loc)
            return None
        links_list = root.get("links")
        count = len(links_list.items) if isinstance(links_list, YSeq) else 0
        if too_many_links(self.sink, root.loc, count, count, self.options.max_links):
            return None
        self._check_schema(root)
        if not self._header(root):
            return None
        links_node = root.get("links")
        if links_node is None:
            self.sink.emit("MK114", 'there is no "links" value defining the links of the body', root.loc)
            return None
        name = v.get_text(root, "name") or self.path.stem
        robot = Robot(name=name, source_format="body", source=root.loc,
                      materials_file=self.options.materials_path)
        ctx = WalkContext(
            self.path,
            self.display,
            self.angle_scale,
            self.sink,
            self.options.resolver,
            self.options.check_resources,
            self.options.faithful_extrusion,
            doc.anchors,
        )
        records = self._links(links_node, ctx)
        if records is None:
            return None
        self._assemble(robot, root, records)
        self._extra_joints(robot, root)
        self._actuators(robot)
        return robot

    def _actuators(self, robot: Robot) -> None:
        """One actuator per moving joint with an ``actuation_mode`` (effort, displacement → position,
        velocity), with its ``gear_ratio`` as reduction and ``rotor_inertia`` (the joint's armature
        is already gear_ratio² · rotor_inertia). Choreonoid gives no gains."""
        for joint in robot.joints:
            kind = BODY_ACTUATOR_KINDS.get(joint.actuation_mode or "")
            if kind is None or joint.type not in (JointType.REVOLUTE, JointType.PRISMATIC):
                continue
            rotor, gear = self.drives.get(id(joint), (0.0, 1.0))
            effort = joint.limits.effort
            robot.actuators.append(
                Actuator(
                    joint=joint.name,
                    kind=kind,
                    reduction=gear,
                    rotor_inertia=rotor,
                    force_range=(-effort, effort) if math.isfinite(effort) and effort > 0 else None,
                    source_kind=f"actuation_mode {joint.actuation_mode}",
                    source=joint.loc("actuation_mode"),
                )
            )

    def _check_schema(self, root: YMap) -> None:
        from modelkit.formats.body.finite import non_finite
        from modelkit.formats.body.schema import check_schema

        try:
            self.sink.extend(check_schema(root, self.display))
            self.sink.extend(non_finite(root))
        except RecursionError:
            self.sink.emit("MK104", "the document is nested too deeply to check against the schema", root.loc)

    def _header(self, root: YMap) -> bool:
        fmt = root.get("format")
        if fmt is None:
            model_file = root.get("model_file", "modelFile")
            if model_file is not None:
                self.sink.emit(
                    "MK115",
                    "this file has no `format` key: it is a wrapper around "
                    f'"{v.scalar_text(model_file)}", which modelkit does not follow yet',
                    model_file.loc,
                )
            else:
                self.sink.emit(
                    "MK110",
                    "neither `format: ChoreonoidBody` nor `model_file` is specified",
                    root.loc,
                    hint="add `format: ChoreonoidBody` at the top",
                )
            return False
        if v.scalar_text(fmt) != "ChoreonoidBody":
            self.sink.emit(
                "MK110",
                f'`format` is "{v.scalar_text(fmt)}", not "ChoreonoidBody": the file cannot be '
                "loaded as a Choreonoid body model",
                fmt.loc,
            )
            return False
        version_node = root.get("format_version", "formatVersion")
        version = v.number(version_node)
        if version_node is None:
            self.sink.emit(
                "MK111",
                "the version of the Choreonoid body format is not specified",
                root.loc,
                hint="add `format_version: 2.0`",
            )
            version = 1.0
        elif version is not None and version >= 2.1:
            self.sink.emit(
                "MK112",
                f"version {v.scalar_text(version_node)} of the Choreonoid body format is not "
                "supported (2.0 is the latest)",
                version_node.loc,
            )
        unit_node = root.get("angle_unit", "angleUnit")
        unit = v.scalar_text(unit_node)
        if unit == "radian":
            self.angle_scale = 1.0
            if version is not None and version >= 2.0 and unit_node is not None:
                self.sink.emit(
                    "MK113",
                    "`angle_unit: radian` is not supported in format version 2.0; write angles in degrees",
                    unit_node.loc,
                )
        return True

    # -- links -------------------------------------------------------------------------------

    def _links(self, links_node: YNode, ctx: WalkContext) -> list[_LinkRecord] | None:
        if isinstance(links_node, YSeq):
            items: list[tuple[str, YMap]] = []
            for item in links_node.items:
                if isinstance(item, YMap):
                    items.append((v.get_text(item, "type") or "Link", item))
            if not links_node.items:
                self.sink.emit("MK114", 'no link is contained in the "links" list', links_node.loc)
                return None
        elif isinstance(links_node, YMap):
            items = [(k, n) for k, n in sorted(links_node.items()) if isinstance(n, YMap)]
        else:
            return None  # a scalar: reported by the schema check
        records: list[_LinkRecord] = []
        for node_type, node in items:
            if node_type == "Skip":
                continue
            if node_type in ("Link", ""):
                records.append(self._link(node, ctx))
            elif node_type == "SubBody":
                records.extend(self._sub_body(node, ctx))
            elif node_type == "ContinuousTrack":
                records.extend(self._continuous_track(node, ctx))
            else:
                self.sink.emit(
                    "MK212", f"a {node_type} node cannot be specified in links", node.key_loc("type")
                )
        if not records:
            self.sink.emit("MK114", "there is no link defined", links_node.loc)
            return None
        return records

    def _link(self, node: YMap, ctx: WalkContext, name_override: str | None = None) -> _LinkRecord:
        sink = self.sink
        name_node = node.get("name")
        name = name_override if name_override is not None else (v.scalar_text(name_node) or "")
        link = Link(name=name, source=node.loc)
        link.sources["name"] = name_node.loc if name_node is not None else node.loc
        offset = Pose()
        t = v.translation(node.get("translation"), sink)
        r = v.rotation(node.get("rotation"), self.angle_scale, sink)
        if t is not None:
            offset.translation = t
        if r is not None:
            offset.rotation = r
        joint_type_node = node.get("joint_type", "jointType")
        word = v.scalar_text(joint_type_node)
        joint_type = JOINT_TYPES.get(word or "fixed", JointType.FIXED)
        mode_node = node.get("actuation_mode", "actuationMode")
        mode_word = v.scalar_text(mode_node)
        if mode_word == "jointSurfaceVelocity" and mode_node is not None:
            sink.emit(
                "MK219",
                "`actuation_mode: jointSurfaceVelocity` is deprecated; it forces a pseudo continuous track",
                mode_node.loc,
                hint="use joint_type: pseudo_continuous_track",
            )
            joint_type = JointType.PSEUDO_CONTINUOUS_TRACK
        joint_name_node = node.get("joint_name")
        joint = Joint(
            name=v.scalar_text(joint_name_node) or name,
            type=joint_type,
            parent="",
            child=name,
            origin=offset,
            source=node.loc,
        )
        joint.sources["name"] = (joint_name_node or name_node or node).loc
        if joint_name_node is None:
            joint.implicit_name = True
        if joint_type_node is not None:
            joint.sources["type"] = joint_type_node.loc
        joint.actuation_mode = ACTUATION_MODES.get(mode_word or "")
        if mode_node is not None:
            joint.sources["actuation_mode"] = mode_node.loc
        self._joint_details(node, joint, word)
        parent_node = node.get("parent")
        parent = v.scalar_text(parent_node)
        if parent_node is not None:
            joint.sources["parent"] = parent_node.loc
        material_node = node.get("material")
        link.contact_material = v.scalar_text(material_node)
        if material_node is not None:
            link.sources["material"] = material_node.loc
            self._check_material(link.contact_material, material_node.loc)
        collected = Collected()
        walk(node.get("elements"), IDENTITY_AFFINE, "both", collected, ctx)
        link.visuals, link.collisions, link.devices = (
            collected.visuals,
            collected.collisions,
            collected.devices,
        )
        link.inertial = self._mass_properties(node, collected)
        return _LinkRecord(
            link, joint, parent, parent_node.loc if parent_node is not None else None, word, offset
        )

    def _check_material(self, name: str | None, loc: SourceLocation) -> None:
        if name is None:
            return
        if self.materials is None:
            self.materials = load_materials(self.options.materials_path, self.sink)
        if not self.materials.knows(name):
            self.sink.emit(
                "MK508",
                f'contact material "{name}" is not in {Path(self.materials.path).name}; '
                "Choreonoid gives it the Default material's parameters",
                loc,
            )

    def _joint_details(self, node: YMap, joint: Joint, word: str | None) -> None:
        sink = self.sink
        revolute = joint.type is JointType.REVOLUTE
        scale = self.angle_scale if revolute else 1.0
        axis_node = node.get("joint_axis", "jointAxis")
        if axis_node is not None:
            joint.sources["axis"] = axis_node.loc
            axis = self._axis(axis_node)
            if axis is not None:
                norm = rot3.norm(axis)
                if norm == 0.0:
                    sink.emit("MK305", f'joint "{joint.name}": the axis is the zero vector', axis_node.loc)
                else:
                    if abs(norm - 1.0) > 1e-6:
                        sink.emit(
                            "MK306",
                            f'joint "{joint.name}": the axis {list(axis)} has length {norm:.6g}; '
                            "Choreonoid uses it unnormalised (modelkit normalises it)",
                            axis_node.loc,
                        )
                    joint.axis = (axis[0] / norm, axis[1] / norm, axis[2] / norm)
        limits = JointLimits()
        range_node = node.get("joint_range", "jointRange")
        if range_node is not None:
            joint.sources["range"] = range_node.loc
            lo_hi = self._range(range_node)
            if lo_hi is not None:
                limits.lower = lo_hi[0] * scale if math.isfinite(lo_hi[0]) else lo_hi[0]
                limits.upper = lo_hi[1] * scale if math.isfinite(lo_hi[1]) else lo_hi[1]
        max_velocity = v.finite_or_unlimited(node.get("max_joint_velocity", "maxJointVelocity"))
        if max_velocity is not None:
            max_velocity = abs(max_velocity)
            limits.velocity_lower, limits.velocity_upper = -max_velocity * scale, max_velocity * scale
        else:
            vr_node = node.get("joint_velocity_range", "jointVelocityRange")
            vr = self._range(vr_node) if vr_node is not None else None
            if vr is not None and vr_node is not None:
                limits.velocity_lower, limits.velocity_upper = vr[0] * scale, vr[1] * scale
                joint.sources["velocity_range"] = vr_node.loc
        if limits.velocity_lower == -limits.velocity_upper:
            limits.velocity = limits.velocity_upper
        effort = v.finite_or_unlimited(node.get("max_joint_effort"))
        if effort is not None:
            limits.effort = abs(effort)
        joint.limits = limits
        armature = v.number(node.get("joint_axis_inertia"))
        if armature is None:
            rotor = v.get_number(node, "rotor_inertia", "rotorInertia", default=0.0) or 0.0
            gear = v.get_number(node, "gear_ratio", "gearRatio", default=1.0)
            armature = (gear if gear is not None else 1.0) ** 2 * rotor
            self.drives[id(joint)] = (rotor, gear if gear is not None else 1.0)
        joint.armature = armature
        displacement = v.number(node.get("joint_displacement", "jointDisplacement"))
        angle_node = node.get("joint_angle", "jointAngle")
        angle = v.number(angle_node)
        if displacement is not None:
            joint.initial_position = displacement * scale
        elif angle is not None and angle_node is not None:
            joint.initial_position = angle * self.angle_scale
            if joint.type is JointType.PRISMATIC:
                sink.emit(
                    "MK310",
                    f'joint "{joint.name}" is prismatic but `joint_angle` is converted as an '
                    "angle by Choreonoid",
                    node.key_loc("joint_angle" if "joint_angle" in node else "jointAngle"),
                    hint="use joint_displacement",
                )
        id_node = node.get("joint_id", "jointId")
        joint_id = v.integer(id_node)
        if joint_id is not None and id_node is not None and joint_id >= 0:
            joint.joint_id = joint_id
            joint.sources["id"] = id_node.loc
        if not joint.type.moves and word in JOINT_TYPES:
            present = [k for k in LIMIT_KEYS if k in node]
            if present and joint.type is JointType.FIXED:
                sink.emit(
                    "MK311",
                    f'joint "{joint.name}" is fixed; `{present[0]}` has no effect',
                    node.key_loc(present[0]),
                )

    def _axis(self, node: YNode) -> rot3.V3 | None:
        if isinstance(node, YScalar):
            word = node.value.strip().lower()
            sign = -1.0 if word.startswith("-") else 1.0
            base = AXIS_SYMBOLS.get(word.lstrip("+-"))
            return None if base is None else rot3.scale(sign, base)
        return v.vector3(node)

    def _range(self, node: YNode) -> tuple[float, float] | None:
        if isinstance(node, YScalar):
            value = v.finite_or_unlimited(node)
            return None if value is None else (-abs(value), abs(value))
        if isinstance(node, YSeq) and len(node.items) == 2:
            lo = v.finite_or_unlimited(node.items[0])
            hi = v.finite_or_unlimited(node.items[1])
            if lo is None or hi is None:
                return None
            return (-math.inf if lo == math.inf else lo, hi)
        return None

    def _mass_properties(self, node: YMap, collected: Collected) -> Inertial:
        present = [k for k in MASS_KEYS if k in node]
        has_rigid = bool(collected.rigid_bodies)
        if not present and not has_rigid:
            return Inertial(1.0, rot3.ZERO3, rot3.IDENTITY, defaulted=True, source=node.loc)
        parts = [(m, c, i) for m, c, i, _ in collected.rigid_bodies]
        inertial = Inertial(1.0, source=node.loc)
        if present:
            mass_node = node.get("mass")
            com_node = node.get("center_of_mass", "centerOfMass")
            inertia_node = node.get("inertia")
            default_mass, default_inertia = (0.0, rot3.ZERO33) if has_rigid else (1.0, rot3.IDENTITY)
            mass = v.number_prefix(mass_node)
            com = v.vector3(com_node)
            inertia = inertia_matrix(inertia_node)
            if isinstance(inertia_node, YSeq) and v.numbers(inertia_node) is not None and inertia is None:
                self.sink.emit(
                    "MK314",
                    f"an inertia must have six or nine numbers, not {len(inertia_node.items)}",
                    inertia_node.loc,
                )
            if inertia_node is None and not has_rigid:
                inertial.defaulted = True  # only mass/COM given: identity inertia
            parts.append(
                (
                    default_mass if mass is None else mass,
                    rot3.ZERO3 if com is None else com,
                    default_inertia if inertia is None else inertia,
                )
            )
            for key, n in (("mass", mass_node), ("com", com_node), ("inertia", inertia_node)):
                if n is not None:
                    inertial.sources[key] = n.loc
        if len(parts) == 1:
            inertial.mass, inertial.com, inertial.inertia = parts[0][0], parts[0][1], parts[0][2]
        else:
            inertial.mass, inertial.com, inertial.inertia = rot3.combine_mass_properties(parts)
        return inertial

    # -- SubBody and ContinuousTrack -------------------------------------------------------------

    def _sub_body(self, node: YMap, ctx: WalkContext) -> list[_LinkRecord]:
        uri_node = node.get("uri")
        uri = v.scalar_text(uri_node)
        if uri is None or uri_node is None:
            self.sink.emit("MK216", "a SubBody needs `uri`", node.loc)
            return []
        path = real_path(self.path.parent / uri)
        if str(path) in self.stack:
            self.sink.emit(
                "MK216",
                f'SubBody "{uri}" includes a body that is already being loaded (recursive sub-body)',
                uri_node.loc,
            )
            return []
        if not os.path.exists(path):  # False for a name too long to look up, as for a missing file
            self.sink.emit(
                "MK216",
                f'SubBody "{uri}" cannot be loaded: not found at {path}; {SUBBODY_DROPPED}',
                uri_node.loc,
            )
            return []
        self.loads[0] += 1
        if self.loads[0] > MAX_SUBBODY_LOADS:
            self.sink.emit(
                "MK009",
                f'SubBody "{uri}" is not read: this file has loaded {MAX_SUBBODY_LOADS:,} SubBodies (each '
                "inclusion counted), as a body included twice by each of many nested bodies does",
                uri_node.loc,
            )
            return []
        sub_sink = DiagnosticSink()
        sub_reader = _BodyReader(path, self.options, sub_sink, str(path), self.stack, self.loads)
        sub = sub_reader.read()
        for d in sub_sink.items:
            self.sink.add(d)
        if sub is None or sub.root is None:
            self.sink.emit("MK216", f'SubBody "{uri}" cannot be loaded; {SUBBODY_DROPPED}', uri_node.loc)
            return []
        prefix = v.get_text(node, "prefix") or ""
        suffix = v.get_text(node, "suffix") or ""
        device_prefix = v.get_text(node, "device_prefix", "devicePrefix")
        device_prefix = prefix if device_prefix is None else device_prefix
        offset = v.integer(node.get("joint_id_offset", "jointIdOffset")) or 0
        records: list[_LinkRecord] = []
        override = self._link(node, ctx, name_override="")
        for link in sub.links:
            old = link.name
            link.name = prefix + old + suffix
            for device in link.devices:
                device.name = device_prefix + device.name
            if old == sub.root:
                joint = override.joint
                joint.child = link.name
                joint.name = v.scalar_text(node.get("joint_name")) or link.name
                link.visuals += override.link.visuals
                link.collisions += override.link.collisions
                link.devices += override.link.devices
                if override.link.contact_material:
                    link.contact_material = override.link.contact_material
                records.append(
                    _LinkRecord(
                        link,
                        joint,
                        override.parent,
                        override.parent_loc,
                        override.joint_type_word,
                        joint.origin,
                    )
                )
                continue
            parent_joint = next(j for j in sub.joints if j.child == old)
            parent_joint.child = link.name
            parent_joint.parent = prefix + parent_joint.parent + suffix
            parent_joint.name = prefix + parent_joint.name + suffix
            if parent_joint.joint_id is not None:
                parent_joint.joint_id += offset
            records.append(
                _LinkRecord(
                    link,
                    parent_joint,
                    parent_joint.parent,
                    parent_joint.loc("parent"),
                    parent_joint.type.value,
                    parent_joint.origin,
                )
            )
        return records

    def _continuous_track(self, node: YMap, ctx: WalkContext) -> list[_LinkRecord]:
        name = v.get_text(node, "name") or ""
        missing = [
            k
            for k, present in (
                ("parent", "parent" in node),
                ("numJoints", "numJoints" in node),
                ("jointOffset", "joint_offset" in node or "jointOffset" in node),
            )
            if not present
        ]
        if missing:
            self.sink.emit("MK217", f'ContinuousTrack "{name}": {missing[0]} must be specified', node.loc)
            return []
        count = v.integer(node.get("numJoints")) or 0
        if count < 3:
            self.sink.emit(
                "MK217",
                f'ContinuousTrack "{name}": numJoints must be more than 2',
                (node.get("numJoints") or node).loc,
            )
            return []
        joint_offset = v.vector3(node.get("joint_offset", "jointOffset"))
        angles = v.numbers(node.get("initialJointAngles")) or []
        records: list[_LinkRecord] = []
        first = self._link(node, ctx, name_override=f"{name}0")
        first.joint.type = JointType.FLOATING
        first.link.extras["is_continuous_track"] = True
        records.append(first)
        for i in range(1, count):
            rec = self._link(node, ctx, name_override=f"{name}{i}")
            rec.joint.type = JointType.REVOLUTE
            rec.joint.name = f"{name}{i}"
            rec.parent = f"{name}{i - 1}"
            rec.joint.origin = Pose(
                rec.joint.origin.rotation_tuple, rot3.ZERO3 if joint_offset is None else joint_offset
            )
            if i - 1 < len(angles):
                rec.joint.initial_position = angles[i - 1] * self.angle_scale
            records.append(rec)
        return records

    # -- assembling the tree ----------------------------------------------------------------------

    def _assemble(self, robot: Robot, root: YMap, records: list[_LinkRecord]) -> None:
        root_node = root.get("root_link", "rootLink")
        root_name = v.scalar_text(root_node)
        names = {r.link.name for r in records}
        if root_name is not None and root_node is not None and root_name not in names:
            self.sink.emit(
                "MK208", f'link "{root_name}" specified in `root_link` is not defined', root_node.loc
            )
            root_name = None
        if root_name is None:
            root_name = records[0].link.name
        robot.root = root_name
        for record in records:
            link, joint = record.link, record.joint
            robot.links.append(link)
            if not link.name and record.link.source is not None:
                self.sink.emit("MK210", "a link without a name cannot be referenced as a parent", link.source)
            if link.name == root_name and robot.root_joint is None:
                if record.parent and record.parent_loc is not None:
                    self.sink.emit(
                        "MK209",
                        f'the root link "{link.name}" has a parent "{record.parent}", which is ignored',
                        record.parent_loc,
                    )
                robot.root_joint = JointType.FLOATING if joint.type is JointType.FLOATING else JointType.FIXED
                robot.root_pose = record.pose
                robot.root_joint_source = joint.loc("type")
                continue
            if not record.parent:  # Choreonoid: an empty parent (`parent:`, an alias of one) is none
                self.sink.emit(
                    "MK218",
                    f'the parent of "{link.name}" is not specified'
                    + (" (its `parent` value is empty)" if record.parent == "" else ""),
                    link.source,
                    hint=f"add `parent:` or make it the root with `root_link: {link.name}`",
                )
                continue
            joint.parent = record.parent
            robot.joints.append(joint)

    def _extra_joints(self, robot: Robot, root: YMap) -> None:
        node = root.get("extra_joints", "extraJoints")
        if not isinstance(node, YSeq):
            return
        names = {link.name for link in robot.links}
        for i, item in enumerate(node.items):
            if not isinstance(item, YMap):
                continue
            link1 = v.get_text(item, "link1_name", "link1Name")
            link2 = v.get_text(item, "link2_name", "link2Name")
            kind = v.get_text(item, "joint_type", "jointType")
            problem = None
            if link1 is None or link2 is None or kind is None:
                problem = "link1_name, link2_name and joint_type must all be specified"
            elif link1 not in names or link2 not in names:
                missing = link1 if link1 not in names else link2
                key = "link1_name" if link1 not in names else "link2_name"
                where = item.get(key, key.replace("_name", "Name"))
                self.sink.emit(
                    "MK215", f'the link "{missing}" of extra joint {i} is not found', (where or item).loc
                )
                continue
            if problem:
                self.sink.emit("MK215", f"extra joint {i}: {problem}", item.loc)
                continue
            assert link1 is not None and link2 is not None and kind is not None
            if link1 == link2:  # constrains nothing; libsdformat and Drake refuse such a joint in the SDF
                where = item.get("link2_name", "link2Name")
                self.sink.emit(
                    "MK215",
                    f'extra joint {i} joins link "{link1}" to itself: an extra joint closes a loop between '
                    "two links",
                    (where or item).loc,
                )
                continue
            axis = v.vector3(item.get("axis", "jointAxis"))
            loop = LoopConstraint(
                name=v.get_text(item, "name") or f"extra_joint_{i}",
                type=kind,
                link1=link1,
                link2=link2,
                source=item.loc,
            )
            if axis is not None and rot3.norm(axis) > 0:
                length = rot3.norm(axis)
                loop.axis = (axis[0] / length, axis[1] / length, axis[2] / length)
            for which, t_keys, r_key in (
                (1, ("translation_in_link1", "link1LocalPos"), "rotation_in_link1"),
                (2, ("translation_in_link2", "link2LocalPos"), "rotation_in_link2"),
            ):
                t = v.vector3(item.get(*t_keys))
                r = v.rotation(item.get(r_key), self.angle_scale, self.sink)
                pose = Pose(rot3.IDENTITY if r is None else r, rot3.ZERO3 if t is None else t)
                if which == 1:
                    loop.pose_in_link1 = pose
                else:
                    loop.pose_in_link2 = pose
            robot.loops.append(loop)
