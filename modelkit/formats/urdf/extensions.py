"""Extensions kept as data: ``<gazebo>``, ``<transmission>``, ``<ros2_control>``, ``<mujoco>``.

None of them changes the kinematic model, but writers and conversion reports need them:

* ``<gazebo reference="X">`` goes to link X, or joint X, or the robot (no reference) as a dict in
  ``extras["gazebo"]``: the reference, the block as canonical XML, its location, and the simple
  values libsdformat understands (``mu1``, ``mu2``, ``kp``, ``kd``, ``material``, ``selfCollide``...).
  A ``<sensor>`` inside becomes a :class:`Device` of that link.
* ``<transmission>`` → ``robot.extras["transmissions"]`` (name, type, joints, actuators, location).
* ``<ros2_control>`` and ``<mujoco>`` → ``robot.extras`` as canonical XML.
"""

from __future__ import annotations

import math
from typing import Any

from lxml import etree
from lxml.etree import _Element as Element

from modelkit import rot3
from modelkit.diagnostics import did_you_mean
from modelkit.formats.devices import sdf_sensor_canonical
from modelkit.formats.urdf.values import Context
from modelkit.model import Device, Joint, Link, Robot, SurfaceFriction
from modelkit.spatial import Pose
from modelkit.xmlsource import parse_number, parse_numbers

# Simple values of a <gazebo> block that libsdformat maps onto the model (peers.md §2.1).
GAZEBO_KEYS = (
    "material",
    "mu1",
    "mu2",
    "kp",
    "kd",
    "fdir1",
    "selfCollide",
    "static",
    "turnGravityOff",
    "gravity",
    "maxContacts",
    "minDepth",
    "maxVel",
    "dampingFactor",
    "laserRetro",
    "stopCfm",
    "stopErp",
    "fudgeFactor",
    "springReference",
    "springStiffness",
    "provideFeedback",
    "implicitSpringDamper",
    "preserveFixedJoint",
    "disableFixedJointLumping",
)


def canonical_xml(element: Element) -> str:
    """The element (without its tail text) as canonical XML."""
    copy = etree.fromstring(etree.tostring(element, with_tail=False))
    return etree.tostring(copy, method="c14n").decode("utf-8")


class _Pending:
    """The value of a :class:`KeptBlock`'s ``"xml"`` item before anyone asked for it."""

    __slots__ = ()


_PENDING = _Pending()


class KeptBlock(dict[str, Any]):
    """A kept extension block (``<gazebo>``, ``<transmission>`` ...) as a dict whose ``"xml"`` item, the
    block's canonical XML, is made the first time it is read.

    Only writers read it, and making it is most of the cost of reading a block (a large xacro expansion has
    thousands). The key is present from the start, in its place; every way of reading values (``[]``,
    ``get``, ``items``, ``values``, iteration as a mapping, ``==``, ``repr``, copies and pickles, which are
    plain dicts) sees the canonical XML, the same string the eager reader stored.
    """

    __slots__ = ("_element",)

    def __init__(self, element: Element, items: dict[str, Any]) -> None:
        super().__init__(items)
        self._element: Element | None = element

    def _fill(self) -> None:
        element = self._element
        if element is not None:
            self._element = None
            if dict.get(self, "xml") is _PENDING:
                dict.__setitem__(self, "xml", canonical_xml(element))

    def __getitem__(self, key: str) -> Any:
        self._fill()
        return dict.__getitem__(self, key)

    def get(self, key: str, default: Any = None) -> Any:
        self._fill()
        return dict.get(self, key, default)

    def __iter__(self) -> Any:  # overridden so that dict(block) and {**block} read values through []
        self._fill()
        return dict.__iter__(self)

    def items(self) -> Any:
        self._fill()
        return dict.items(self)

    def values(self) -> Any:
        self._fill()
        return dict.values(self)

    def pop(self, key: str, *default: Any) -> Any:
        self._fill()
        return dict.pop(self, key, *default)

    def popitem(self) -> tuple[str, Any]:
        self._fill()
        return dict.popitem(self)

    def setdefault(self, key: str, default: Any = None) -> Any:
        self._fill()
        return dict.setdefault(self, key, default)

    def copy(self) -> dict[str, Any]:
        self._fill()
        return dict(dict.items(self))

    def __eq__(self, other: object) -> bool:
        self._fill()
        if isinstance(other, KeptBlock):
            other._fill()
        return dict.__eq__(self, other)

    def __ne__(self, other: object) -> bool:
        return not self == other

    def __or__(self, other: Any) -> Any:
        self._fill()
        return dict.__or__(self, other)

    def __repr__(self) -> str:
        self._fill()
        return dict.__repr__(self)

    def __reduce_ex__(self, protocol: Any) -> Any:  # copies and pickles are plain dicts
        self._fill()
        return (dict, (dict(dict.items(self)),))



def _value(text: str | None) -> Any:
    """A simple value: a number when it is one, true/false words as bools, else the stripped text."""
    if text is None:
        return None
    stripped = text.strip()
    number = parse_number(stripped)
    if number is not None:
        return number
    if stripped.lower() in ("true", "false"):
        return stripped.lower() == "true"
    numbers = parse_numbers(stripped)
    if numbers:
        return numbers
    return stripped


def _gazebo_friction(link: Link, mu1: Any, mu2: Any) -> None:
    """A link block's ``mu1``/``mu2`` (what Gazebo puts on each of the link's collisions, SDF's
    ``<mu>``/``<mu2>``) as the collisions' own friction, unless PyBullet's ``<contact>`` gave one."""
    if not isinstance(mu1, float) and not isinstance(mu2, float):
        return
    if any(geom.friction is not None for geom in link.collisions):
        return
    first = mu1 if isinstance(mu1, float) and mu1 >= 0.0 else 1.0  # SDF's default
    second = mu2 if isinstance(mu2, float) and mu2 >= 0.0 else 1.0
    friction = SurfaceFriction(first, None, None, None if second == first else second)
    for geom in link.collisions:
        geom.friction = friction


def read_gazebo(
    ctx: Context,
    element: Element,
    robot: Robot,
    links: dict[str, Link] | None = None,
    joints: dict[str, Joint] | None = None,
) -> None:
    """File one ``<gazebo>`` block under its link, joint or the robot. ``links`` and ``joints`` index
    the robot's by name (the first of a name), so that a block per link stays linear in links."""
    reference = element.get("reference")
    entry = KeptBlock(element, {"reference": reference, "xml": _PENDING, "source": ctx.loc(element)})
    for child in element:
        tag = ctx.tag(child)
        if tag in GAZEBO_KEYS and len(child) == 0:
            entry[tag] = _value(child.text)
    if links is None or joints is None:
        link = robot.link(reference) if reference else None
        joint = next((j for j in robot.joints if j.name == reference), None) if reference else None
    else:
        link = links.get(reference) if reference else None
        joint = joints.get(reference) if reference else None
    collide = dict.get(entry, "selfCollide")  # not entry.get: that would make the block's XML now
    literal = element.find("self_collide")  # the SDF element itself: libsdformat copies it into the link
    if collide is None and literal is not None and len(literal) == 0 and (literal.text or "").strip():
        collide = (literal.text or "").strip().lower() in ("1", "true")
    if link is not None:
        link.extras.setdefault("gazebo", []).append(entry)
        if isinstance(collide, bool):
            link.self_collide = collide
        _gazebo_friction(link, dict.get(entry, "mu1"), dict.get(entry, "mu2"))
        for sensor in ctx.children(element, "sensor"):
            device = _sensor(ctx, sensor)
            if device is not None:
                link.devices.append(device)
    elif joint is not None:
        joint.extras.setdefault("gazebo", []).append(entry)
    else:
        robot.extras.setdefault("gazebo", []).append(entry)
        flag = element.find("self_collide")  # libsdformat's import reads a robot-level one
        if flag is not None:
            robot.self_collide = (flag.text or "").strip().lower() in ("1", "true")
        if reference:
            names = {lk.name for lk in robot.links} | {j.name for j in robot.joints}
            ctx.emit(
                "MK138",
                f'<gazebo reference="{reference}"> names neither a link nor a joint; libsdformat ignores '
                "the block",
                ctx.loc(element, "reference"),
                hint=did_you_mean(reference, names),
            )


def _sensor(ctx: Context, element: Element) -> Device | None:
    """A Gazebo ``<sensor name type>`` as a device; its SDF content is kept as raw XML."""
    name = element.get("name")
    kind = element.get("type")
    if not name or not kind:
        missing = " and ".join(k for k, v in (("name", name), ("type", kind)) if not v)
        ctx.emit(
            "MK620",
            f"<sensor> in a <gazebo> block has no {missing}; SDF needs both, so Gazebo refuses it",
            ctx.loc(element),
        )
        return None
    canonical, canonical_params = sdf_sensor_canonical(element)  # the same content as an SDF <sensor>
    device = Device(
        kind, name, source=ctx.loc(element), canonical=canonical, canonical_params=canonical_params
    )
    device.params["xml"] = canonical_xml(element)
    plugins = [
        {"name": child.get("name") or "", "filename": child.get("filename") or "",
         "owner": f'sensor "{name}"', "xml": canonical_xml(child)}
        for child in element if child.tag == "plugin"
    ]
    if plugins:  # as an SDF sensor's (modelkit/formats/sdf/sensors.py): other targets carry them
        device.params["plugins"] = plugins
    for key in ("update_rate", "always_on", "visualize", "topic"):
        child = ctx.first(element, key)
        if child is not None:
            device.params[key] = _value(child.text)
    pose_el = ctx.first(element, "pose")
    if pose_el is not None:
        values = parse_numbers(pose_el.text or "")
        if values is None or len(values) != 6 or not all(math.isfinite(v) for v in values):
            ctx.emit(
                "MK620",
                f'sensor "{name}": <pose> "{(pose_el.text or "").strip()}" is not six numbers '
                "(x y z roll pitch yaw); the sensor is placed at the link origin",
                ctx.text_loc(pose_el),
            )
        else:
            device.pose = Pose(rot3.from_rpy(*values[3:]), rot3.vec3(values[:3]))
    return device


def read_transmission(ctx: Context, element: Element, joint_names: set[str]) -> dict[str, Any]:
    """A ROS transmission: both the current form (``<type>`` element) and the old PR2 attribute."""
    type_el = ctx.first(element, "type")
    name = element.get("name")
    joints: list[str] = []
    actuators: list[str] = []
    entry = KeptBlock(element, {
        "name": name,
        "type": (type_el.text or "").strip() if type_el is not None else element.get("type"),
        "joints": joints,
        "actuators": actuators,
        "source": ctx.loc(element),
        "xml": _PENDING,
    })
    for joint_el in ctx.children(element, "joint"):
        joint = joint_el.get("name")
        if joint is None:
            continue
        joints.append(joint)
        if joint not in joint_names:
            ctx.emit(
                "MK139",
                f'transmission "{name}" drives joint "{joint}", which is not a joint of this robot',
                ctx.loc(joint_el, "name"),
                hint=did_you_mean(joint, joint_names),
            )
    for actuator in ctx.children(element, "actuator"):
        actuator_name = actuator.get("name")
        if actuator_name is not None:
            actuators.append(actuator_name)
    return entry
