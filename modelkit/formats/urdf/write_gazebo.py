"""URDF writer, extensions: ``<gazebo>`` blocks (sensors, friction, kept blocks), transmissions and
the other kept extension elements.

URDF has no sensors; Gazebo (and libsdformat's URDF → SDF conversion) reads SDF ``<sensor>``
elements inside ``<gazebo reference="link">`` and copies them into the link. A device in the
shared vocabulary (:class:`modelkit.model.DeviceKind`) is written as such a sensor, its ``<pose>``
the device frame in the link frame (+X forward, as SDF). A device read from a URDF ``<gazebo>``
block (its SDF kept in ``params["xml"]``) is written back as it was. Lights and devices without a
meaning elsewhere are dropped (MK806).
"""

from __future__ import annotations

from typing import Any

from lxml import etree
from lxml.etree import _Element as Element

from modelkit.convert.context import WriteContext
from modelkit.convert.friction import floor_friction
from modelkit.convert.numbers import fmt, fmt_vec
from modelkit.diagnostics import SourceLocation
from modelkit.formats.urdf.write_names import NameTable
from modelkit.model import CAMERA_KINDS, Device, DeviceKind, Link, Robot
from modelkit.spatial import rpy_from_matrix

SENSOR_TYPES = {
    DeviceKind.CAMERA: "camera",
    DeviceKind.DEPTH_CAMERA: "depth_camera",
    DeviceKind.RGBD_CAMERA: "rgbd_camera",
    DeviceKind.LIDAR: "gpu_lidar",
    DeviceKind.IMU: "imu",
    DeviceKind.ACCELEROMETER: "imu",
    DeviceKind.GYRO: "imu",
    DeviceKind.FORCE_TORQUE: "force_torque",
    DeviceKind.CONTACT: "contact",
}


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


def _sub(parent: Element, tag: str, text: str | None = None) -> Element:
    el = etree.SubElement(parent, tag)
    if text is not None:
        el.text = text
    return el


def _number(params: dict[str, Any], key: str) -> str | None:
    value = params.get(key)
    if isinstance(value, bool) or not isinstance(value, int | float):
        return None
    return fmt(value)


def _noise(parent: Element, params: dict[str, Any]) -> None:
    stddev = _number(params, "noise_stddev")
    if stddev is not None:
        noise = _sub(parent, "noise")
        _sub(noise, "type", "gaussian")
        _sub(noise, "mean", "0")
        _sub(noise, "stddev", stddev)


def _camera(sensor: Element, params: dict[str, Any]) -> None:
    camera = _sub(sensor, "camera")
    fov = _number(params, "horizontal_fov")
    if fov is not None:
        _sub(camera, "horizontal_fov", fov)
    width, height = _number(params, "width"), _number(params, "height")
    if width is not None or height is not None:
        image = _sub(camera, "image")
        if width is not None:
            _sub(image, "width", width)
        if height is not None:
            _sub(image, "height", height)
    near, far = _number(params, "near"), _number(params, "far")
    if near is not None or far is not None:
        clip = _sub(camera, "clip")
        if near is not None:
            _sub(clip, "near", near)
        if far is not None:
            _sub(clip, "far", far)
    _noise(camera, params)


def _lidar(sensor: Element, params: dict[str, Any]) -> None:
    ray = _sub(sensor, "ray")
    scan = _sub(ray, "scan")
    for axis in ("horizontal", "vertical"):
        values = {k: _number(params, f"{axis}_{k}") for k in ("samples", "min_angle", "max_angle")}
        if all(v is None for v in values.values()):
            continue
        el = _sub(scan, axis)
        for key, value in values.items():
            if value is not None:
                _sub(el, key, value)
    rng = _sub(ray, "range")
    for key in ("min", "max", "resolution"):
        value = _number(params, f"range_{key}")
        if value is not None:
            _sub(rng, key, value)
    _noise(ray, params)


def sensor_element(device: Device, link_name: str, ctx: WriteContext, target: str) -> Element | None:
    """An SDF ``<sensor>`` for a device of the shared vocabulary (None: the kind has no sensor)."""
    kind = SENSOR_TYPES.get(device.canonical)
    if kind is None:
        return None
    params = device.canonical_params
    sensor = etree.Element("sensor", name=device.name, type=kind)
    pose = device.pose
    _sub(sensor, "pose", f"{fmt_vec(pose.translation)} {fmt_vec(rpy_from_matrix(pose.rotation))}")
    rate = _number(params, "update_rate")
    if rate is not None:
        _sub(sensor, "update_rate", rate)
    if device.canonical in CAMERA_KINDS:
        _camera(sensor, params)
    elif device.canonical is DeviceKind.LIDAR:
        _lidar(sensor, params)
    elif device.canonical in (DeviceKind.ACCELEROMETER, DeviceKind.GYRO):
        ctx.note(
            "MK807",
            f'{device.canonical.value} "{device.name}" is written as a Gazebo imu sensor (which '
            "measures both rates and accelerations)",
            device.source,
            target,
        )
    elif device.canonical is DeviceKind.FORCE_TORQUE:
        ctx.note(
            "MK807",
            f'force sensor "{device.name}" is written as a Gazebo force_torque sensor, which '
            "measures at the link's parent joint, not at the sensor's own frame",
            device.source,
            target,
        )
    elif device.canonical is DeviceKind.CONTACT:
        contact = _sub(sensor, "contact")
        _sub(contact, "collision", f"{link_name}_collision")
    return sensor


def _gazebo(robot_el: Element, reference: str | None) -> Element:
    el = etree.SubElement(robot_el, "gazebo")
    if reference is not None:
        el.set("reference", reference)
    return el


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


def _device(robot_el: Element, link: Link, name: str, device: Device, ctx: WriteContext) -> None:
    target = f"gazebo[{name}]/sensor[{device.name}]"
    xml = device.params.get("xml")
    if isinstance(xml, str):
        block = parse_block(xml)
        if block is not None and block.tag == "sensor":
            _gazebo(robot_el, name).append(block)
            return
    sensor = sensor_element(device, name, ctx, target)
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
    _gazebo(robot_el, name).append(sensor)


def write_extensions(robot_el: Element, robot: Robot, names: NameTable, ctx: WriteContext) -> None:
    """Every ``<gazebo>`` block (per link, per joint, robot level), then the other kept extensions."""
    friction = floor_friction(robot)
    for index, link in enumerate(robot.links):
        name = names.links[index]
        written = _kept_blocks(robot_el, link.extras.get("gazebo"), name, ctx, f'link "{link.name}"')
        pair = friction.get(link.name)
        if pair is not None:
            friction_block = _gazebo(robot_el, name)
            _sub(friction_block, "mu1", fmt(pair.dynamic))
            _sub(friction_block, "mu2", fmt(pair.dynamic))
            how = "from the material table" if pair.from_table else "by Choreonoid's √(roughness) rule"
            ctx.note(
                "MK817",
                f'link "{link.name}": contact material "{pair.material}" against the floor '
                f'material "{pair.against}" ({how}) is written as Gazebo mu1 = mu2 = {fmt(pair.dynamic)} '
                f"(dynamic friction; static {fmt(pair.static)}, restitution {fmt(pair.restitution)} left "
                "out); Gazebo/ODE uses the smaller of the two shapes' values and PyBullet multiplies "
                "them, so contacts with other materials differ",
                link.loc("material"),
                f"gazebo[{name}]",
            )
        for device in link.devices:
            if device.name in written and isinstance(device.params.get("xml"), str):
                continue
            _device(robot_el, link, name, device, ctx)
    for index, joint in enumerate(robot.joints):
        _kept_blocks(robot_el, joint.extras.get("gazebo"), names.joints[index], ctx, f'joint "{joint.name}"')
    for entry in robot.extras.get("gazebo", []) or []:
        reference = entry.get("reference") if isinstance(entry, dict) else None
        written_ref = names.link(reference) if reference in names.link_map else reference
        _kept_blocks(robot_el, [entry], written_ref, ctx, "the robot")
    _transmissions(robot_el, robot, names, ctx)
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


def _transmissions(robot_el: Element, robot: Robot, names: NameTable, ctx: WriteContext) -> None:
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
        for joint_el in block.iter("joint"):
            if joint_el.get("name") in names.joint_map:
                joint_el.set("name", names.joint(joint_el.get("name", "")))
        robot_el.append(block)
