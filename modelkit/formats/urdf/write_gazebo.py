"""URDF writer, extensions: ``<gazebo>`` blocks (sensors, friction, kept blocks), transmissions and
the other kept extension elements.

URDF has no sensors; Gazebo (and libsdformat's URDF → SDF conversion) reads SDF ``<sensor>``
elements inside ``<gazebo reference="link">`` and copies them into the link. A device in the
shared vocabulary (:class:`modelkit.model.DeviceKind`) is written as such a sensor, on its own sensor
link (``write_frames``) or on its link with its ``<pose>`` the device frame in the link frame (+X
forward, as SDF). A device read from a URDF ``<gazebo>``
block (its SDF kept in ``params["xml"]``) is written back as it was. Lights and devices without a
meaning elsewhere are dropped (MK806).
"""

from __future__ import annotations

from typing import Any

from lxml import etree
from lxml.etree import _Element as Element

from modelkit.convert.context import WriteContext
from modelkit.convert.drive_plugin import planned_drive, plugin_elements
from modelkit.convert.friction import describe, floor_friction, link_surface
from modelkit.convert.gazebo import gazebo_family
from modelkit.convert.numbers import fmt
from modelkit.diagnostics import SourceLocation
from modelkit.formats.sdf.gazebo_blocks import joint_block, link_block, model_block, shape_data_kinds
from modelkit.formats.urdf.write_actuators import rename_motor, unique_motor, write_transmissions
from modelkit.formats.urdf.write_frames import SensorFrames
from modelkit.formats.urdf.write_names import NameTable
from modelkit.model import Device, DeviceKind, JointType, Link, Robot, SurfaceFriction
from modelkit.spatial import Pose

# Gazebo reads the SDF inside a URDF's <gazebo> blocks; sensors are written as SDF 1.6 describes them
# (`<ray>` for lidars), which Gazebo classic and Gazebo Sim both read.
GAZEBO_SDF_VERSION = (1, 6)


def parse_block(xml: str) -> Element | None:
    """A kept XML block, its layout whitespace removed (so that it is indented like the rest)."""
    try:
        element = etree.fromstring(
            xml.encode("utf-8"), etree.XMLParser(remove_blank_text=True, remove_comments=True)
        )
    except etree.XMLSyntaxError:
        return None
    for el in element.iter():
        if el.text is not None and not el.text.strip() and len(el):
            el.text = None
        if el.tail is not None and not el.tail.strip():
            el.tail = None
    return element


def sensor_element(
    device: Device, ctx: WriteContext, owner: str, pose: Pose | None = None, gazebo: str = "sim",
    frame: str | None = None,
) -> Element | None:
    """An SDF ``<sensor>`` for a device of the shared vocabulary at ``pose`` in the referenced link
    (default: the device pose) for Gazebo ``gazebo`` (classic or sim), written by the SDF writer's own
    device code (None: no sensor); ``frame``: the TF frame its data is stamped with."""
    from modelkit.formats.sdf.write_devices import CANONICAL_SENSOR, DeviceWriter

    if device.canonical not in CANONICAL_SENSOR:
        return None
    holder = etree.Element("gazebo")
    where = device.pose if pose is None else pose
    DeviceWriter(ctx, GAZEBO_SDF_VERSION, "urdf", gazebo).device(holder, device, where, None, owner, set(),
                                                                 frame)
    return holder[0] if len(holder) else None


def _gazebo(robot_el: Element, reference: str | None) -> Element:
    el = etree.SubElement(robot_el, "gazebo")
    if reference is not None:
        el.set("reference", reference)
    return el


def _sdf_block(robot_el: Element, reference: str | None, elements: list[Element]) -> None:
    """An SDF source's Gazebo data the URDF has no element for, in a ``<gazebo>`` block libsdformat
    copies back into the link, joint or model (:mod:`modelkit.formats.sdf.gazebo_blocks`)."""
    if elements:
        block = _gazebo(robot_el, reference)
        for element in elements:
            block.append(element)


def _kept_blocks(
    robot_el: Element, entries: Any, reference: str | None, ctx: WriteContext, what: str
) -> set[str]:
    """Kept ``<gazebo>`` blocks written back verbatim (reference renamed); the sensor names inside."""
    sensors: set[str] = set()
    for entry in entries if isinstance(entries, list) else []:
        source = entry.get("source") if isinstance(entry, dict) else None
        block = (
            parse_block(entry["xml"])
            if isinstance(entry, dict) and isinstance(entry.get("xml"), str)
            else None
        )
        if block is None:
            ctx.note(
                "MK808",
                f"a <gazebo> block of {what} could not be carried over",
                source if isinstance(source, SourceLocation) else None,
                "gazebo",
            )
            continue
        if reference is not None:
            block.set("reference", reference)
        sensors |= {s.get("name", "") for s in block.iter("sensor")}
        robot_el.append(block)
    return sensors


def _device(
    robot_el: Element,
    link: Link,
    name: str,
    device: Device,
    ctx: WriteContext,
    place: tuple[str, Pose],
    gazebo: str,
    frame: str | None,
) -> None:
    """One device: its kept block on its link, or a sensor on ``place`` (its frame link and pose), its
    data stamped with ``frame``."""
    xml = device.params.get("xml")
    if isinstance(xml, str):
        block = parse_block(xml)
        if block is not None and block.tag == "sensor":
            _gazebo(robot_el, name).append(block)
            return
    reference, pose = place
    sensor = sensor_element(device, ctx, f"gazebo[{reference}]", pose, gazebo, frame)
    if sensor is None:
        what = device.canonical.value if device.canonical is not DeviceKind.OTHER else device.kind
        ctx.note(
            "MK806",
            f'{what} "{device.name}" of link "{link.name}" has no URDF or Gazebo sensor '
            "equivalent; it is left out",
            device.source,
            f"link[{name}]",
        )
        return
    _gazebo(robot_el, reference).append(sensor)


def write_extensions(
    robot_el: Element, robot: Robot, names: NameTable, frames: SensorFrames, ctx: WriteContext
) -> None:
    """Every ``<gazebo>`` block (per link, per joint, robot level), then the other kept extensions."""
    friction = floor_friction(robot)
    gazebo = gazebo_family(robot, ctx.options.gazebo)
    framed: list[tuple[Link, str, Device, tuple[str, Pose], str | None]] = []
    for index, link in enumerate(robot.links):
        name = names.links[index]
        written = _kept_blocks(robot_el, link.extras.get("gazebo"), name, ctx, f'link "{link.name}"')
        _sdf_block(robot_el, name, link_block(link))
        surface, _ = link_surface(link)
        pair = friction.get(link.name)
        if surface is not None and robot.source_format != "urdf" and not _has_mu(link):
            _surface_block(_gazebo(robot_el, name), link, surface, name, robot, ctx)
        elif surface is None and pair is not None:
            friction_block = _gazebo(robot_el, name)
            etree.SubElement(friction_block, "mu1").text = fmt(pair.dynamic)
            etree.SubElement(friction_block, "mu2").text = fmt(pair.dynamic)
            how = "from the material table" if pair.from_table else "by Choreonoid's √(roughness) rule"
            ctx.note(
                "MK817",
                f'link "{link.name}": contact material "{pair.material}" against the floor '
                f'material "{pair.against}" ({how}) is written as Gazebo mu1 = mu2 = {fmt(pair.dynamic)} '
                f"(dynamic friction; static {fmt(pair.static)}, restitution {fmt(pair.restitution)} left "
                "out), and as PyBullet's <contact> lateral_friction (rolling and spinning 0); Gazebo/ODE "
                "uses the smaller of the two shapes' values and PyBullet multiplies them (pybullet_data's "
                "plane.urdf has 1), so contacts with other materials differ",
                link.loc("material"),
                f"gazebo[{name}]",
            )
        for device_index, device in enumerate(link.devices):
            if device.name in written and isinstance(device.params.get("xml"), str):
                continue
            place = frames.place(index, device_index, name, device)
            frame = frames.data_frames.get((index, device_index))
            if place[0] != name:  # on its sensor link, which comes after the model's links
                framed.append((link, name, device, place, frame))
                continue
            _device(robot_el, link, name, device, ctx, place, gazebo, frame)
    for link, name, device, place, frame in framed:
        _device(robot_el, link, name, device, ctx, place, gazebo, frame)
    for index, joint in enumerate(robot.joints):
        _kept_blocks(robot_el, joint.extras.get("gazebo"), names.joints[index], ctx, f'joint "{joint.name}"')
        _sdf_block(robot_el, names.joints[index], joint_block(joint))
    _sdf_block(robot_el, None, model_block(robot))
    for entry in robot.extras.get("gazebo", []) or []:
        reference = entry.get("reference") if isinstance(entry, dict) else None
        written_ref = names.link(reference) if reference in names.link_map else reference
        _kept_blocks(robot_el, [entry], written_ref, ctx, "the robot")
    _model_plugins(robot_el, robot, gazebo, ctx)
    if ctx.options.drive_plugin:
        _drive_plugin(robot_el, robot, gazebo, names, ctx)
    _transmissions(robot_el, robot, names, ctx)
    write_transmissions(robot_el, robot, names.joint_map, ctx)
    for key in ("ros2_control", "mujoco", "sensor"):
        for entry in robot.extras.get(key, []) or []:
            block = parse_block(entry.get("xml", "")) if isinstance(entry, dict) else None
            if block is None:
                ctx.note("MK808", f"a <{key}> block could not be carried over", None, key)
                continue
            for joint_el in block.iter("joint"):
                if joint_el.get("name") in names.joint_map:
                    joint_el.set("name", names.joint(joint_el.get("name", "")))
            robot_el.append(block)


def _model_plugins(robot_el: Element, robot: Robot, gazebo: str, ctx: WriteContext) -> None:
    """An SDF source's model plugins as robot-level ``<gazebo>`` blocks (libsdformat's URDF import
    copies them into the model), those of the other Gazebo left out with an MK848 note."""
    from modelkit.convert.gazebo import plugin_family

    for entry in robot.extras.get("sdf_plugins") or []:
        if not isinstance(entry, dict):
            continue
        name, filename = entry.get("name", ""), str(entry.get("filename", ""))
        family = plugin_family(filename)
        block = parse_block(str(entry.get("xml", "")))
        if family not in (None, gazebo) or block is None:
            why = (
                f"is Gazebo {family} code and this file is written for Gazebo {gazebo} "
                f"(--gazebo {family} keeps it)"
                if block is not None
                else "cannot be copied on its own"
            )
            ctx.note("MK848" if block is not None else "MK808", f'model plugin "{name}" ({filename}) {why}; '
                     "left out", robot.source, "gazebo")
            continue
        _gazebo(robot_el, None).append(block)


def _drive_plugin(robot_el: Element, robot: Robot, gazebo: str, names: NameTable, ctx: WriteContext) -> None:
    """Gazebo's differential drive, in a robot-level ``<gazebo>`` block (libsdformat's URDF import puts
    it in the model), for a robot on wheels without a controller (convert.drive_plugin)."""
    drive = planned_drive(robot, "urdf", gazebo, robot.name or "robot", ctx.notes)
    if drive is None:
        return
    joints = {name: names.joint(name) for name in (*drive.left, *drive.right)}
    filename, name, children = plugin_elements(drive, gazebo, joints, names.link(drive.base))
    plugin = etree.SubElement(_gazebo(robot_el, None), "plugin", filename=filename, name=name)
    for tag, text in children:
        etree.SubElement(plugin, tag).text = text


# The joints a transmission can drive: one coordinate each (a planar, floating or ball joint has more)
ONE_COORDINATE = frozenset({JointType.REVOLUTE, JointType.PRISMATIC})


def _transmissions(robot_el: Element, robot: Robot, names: NameTable, ctx: WriteContext) -> None:
    motors: set[str] = set()
    for entry in robot.extras.get("transmissions", []) or []:
        block = parse_block(entry.get("xml", "")) if isinstance(entry, dict) else None
        if block is None:
            source = entry.get("source") if isinstance(entry, dict) else None
            ctx.note(
                "MK808",
                "a <transmission> could not be carried over",
                source if isinstance(source, SourceLocation) else None,
                "transmission",
            )
            continue
        missing = [str(joint.get("name", "")) for joint in block.iter("joint")
                   if joint.get("name") not in names.joint_map]
        if missing:  # the source's own fault (validate's MK139); Drake refuses the whole file over it
            source = entry.get("source")
            ctx.note(
                "MK808",
                f'<transmission> "{block.get("name", "")}" left out: it drives joint(s) '
                f'{", ".join(repr(m) for m in missing)}, which the robot does not have (validate: MK139); '
                "Drake refuses a URDF whose transmission names no joint",
                source if isinstance(source, SourceLocation) else None,
                "transmission",
            )
            continue
        types = {joint.name: joint.type for joint in robot.joints}
        driven = [str(joint.get("name", "")) for joint in block.iter("joint")]
        several = [f"{name!r} ({types[name].value})" for name in driven if types[name] not in ONE_COORDINATE]
        if several:  # Drake refuses the file: "only supports actuators for single degree-of-freedom joints"
            source = entry.get("source")
            ctx.note(
                "MK808",
                f'<transmission> "{block.get("name", "")}" left out: it drives joint(s) '
                f"{', '.join(several)}, which have more than one coordinate; a transmission drives one, "
                "and Drake refuses a URDF whose transmission names such a joint",
                source if isinstance(source, SourceLocation) else None,
                "transmission",
            )
            continue
        joints = []
        for joint_el in block.iter("joint"):
            joint_el.set("name", names.joint(joint_el.get("name", "")))
            joints.append(joint_el.get("name", ""))
        for motor in block.iter("actuator"):
            wanted = motor.get("name")
            if wanted and joints:
                written = unique_motor(wanted, joints[0], motors)
                if written != wanted:
                    motor.set("name", written)
                    rename_motor(ctx, wanted, written, joints[0])
        robot_el.append(block)


def unnamed_shapes(link: Link, robot: Robot, pairs: dict[str, Any]) -> set[str]:
    """The kinds of shape (``visual``, ``collision``) of ``link`` written without names: those its
    written ``<gazebo>`` blocks give data to (an SDF source's friction, material script, shadows...).

    libsdformat's URDF import applies a link block's ``<visual>``, ``<collision>``, ``<material>``,
    ``mu1``, ``kp``... only to a visual or collision the URDF leaves unnamed (it renames a named one and
    then fails its own name test, sdformat issue 333): Gazebo would drop them all on named shapes. A
    URDF source's own shapes and blocks are written as they were. ``pairs``: the robot's
    :func:`~modelkit.convert.friction.floor_friction`."""
    if robot.source_format == "urdf":
        return set()
    kinds = shape_data_kinds(link)
    surface, _ = link_surface(link)
    if link.collisions and (surface is not None or pairs.get(link.name) is not None):
        kinds.add("collision")
    return kinds


def _has_mu(link: Link) -> bool:
    """The link's kept ``<gazebo>`` blocks already set its friction."""
    blocks = link.extras.get("gazebo")
    return isinstance(blocks, list) and any(
        isinstance(b, dict) and (dict.get(b, "mu1") is not None or dict.get(b, "mu2") is not None)
        for b in blocks
    )


def _surface_block(block: Element, link: Link, surface: SurfaceFriction, name: str, robot: Robot,
                   ctx: WriteContext) -> None:
    """Gazebo's ``mu1``/``mu2`` of a link from its shapes' own friction (MJCF, SDF sources)."""
    etree.SubElement(block, "mu1").text = fmt(surface.sliding)
    etree.SubElement(block, "mu2").text = fmt(
        surface.sliding if surface.sliding2 is None else surface.sliding2
    )
    lost = [f"{what} {fmt(value)} m" for what, value in (("torsional", surface.torsional),
                                                          ("rolling", surface.rolling)) if value]
    ctx.note(
        "MK852",
        f"link {link.name}: the source's friction of its collisions ({describe(surface)}) is written as "
        "PyBullet's <contact> (lateral, spinning, rolling) and as Gazebo's mu1/mu2"
        + (f" ({', '.join(lost)} only in <contact>: Gazebo's URDF block has no field for it)" if lost else "")
        + "; PyBullet multiplies two shapes' values and Gazebo/ODE takes the smaller",
        link.loc("collision"),
        f"gazebo[{name}]",
    )
