"""URDF ``<transmission>`` and ``<ros2_control>`` as the model's canonical actuators.

* ``<transmission>``: each ``<joint>`` with a ``<hardwareInterface>`` (in the joint, or in the
  ``<actuator>`` as the old PR2 form writes it; the first of several that commands the joint, not
  ``JointStateInterface``) naming a position, velocity or effort interface
  (``hardware_interface/PositionJointInterface``, ``...VelocityJointInterface``,
  ``...EffortJointInterface``, or ROS 2's bare ``position``...) gets one actuator; the first
  ``<actuator>``'s ``<mechanicalReduction>`` is its reduction.
* ``<ros2_control>``: each ``<joint>``'s first ``<command_interface>`` (position, velocity or
  effort) gives the kind; its ``min``/``max`` parameters give the control range. A joint that a
  transmission also names keeps the transmission's reduction and takes ros2_control's kind. The
  ``initial_value`` of a joint's position ``<state_interface>`` is its initial position (the pose
  ``gz_ros2_control`` starts it in; URDF has no other), which writers keep as the home pose.

Neither gives gains: a writer that needs them makes them up and says so. The elements themselves stay
in ``extras`` (``transmissions``, ``ros2_control``) for the URDF writer.
"""

from __future__ import annotations

import math

from lxml.etree import _Element as Element

from modelkit.formats.urdf.values import Context
from modelkit.model import Actuator, ActuatorKind, Joint, Robot
from modelkit.xmlsource import parse_number

KINDS = (("position", ActuatorKind.POSITION), ("velocity", ActuatorKind.VELOCITY),
         ("effort", ActuatorKind.EFFORT))


def interface_kind(text: str | None) -> ActuatorKind | None:
    """``hardware_interface/PositionJointInterface`` or ``position`` → position; None when unknown."""
    word = (text or "").strip().rsplit("/", 1)[-1].lower()
    for prefix, kind in KINDS:
        if word.startswith(prefix):
            return kind
    return None


def read_actuators(ctx: Context, root: Element, robot: Robot) -> None:
    """Fill ``robot.actuators`` from the transmissions, then ros2_control, in document order."""
    joints = {j.name for j in robot.joints}
    found: dict[str, Actuator] = {}
    motors: dict[str, str] = {}  # actuator name → the joint of the first transmission naming it
    for element in ctx.children(root, "transmission"):
        _transmission(ctx, element, joints, found)
        _same_motor(ctx, element, motors)
    for element in ctx.children(root, "ros2_control"):
        _ros2_control(ctx, element, joints, found)
        _initial_values(ctx, element, robot)
    robot.actuators = list(found.values())


def _text(ctx: Context, element: Element | None, name: str) -> str | None:
    child = ctx.first(element, name) if element is not None else None
    return child.text if child is not None else None


def _transmission(ctx: Context, element: Element, joints: set[str], found: dict[str, Actuator]) -> None:
    actuators = ctx.children(element, "actuator")
    first = actuators[0] if actuators else None
    reduction = parse_number((_text(ctx, first, "mechanicalReduction") or "").strip())
    for joint_el in ctx.children(element, "joint"):
        name = joint_el.get("name")
        if name is None or name not in joints or name in found:
            continue
        written = _command_interface(ctx, joint_el) or _command_interface(ctx, first)
        kind = interface_kind(written)
        if kind is None:
            continue
        found[name] = Actuator(
            joint=name,
            kind=kind,
            name=first.get("name") if first is not None else None,
            reduction=reduction if reduction else 1.0,
            source_kind=(written or "").strip(),
            source=ctx.loc(joint_el),
            ros_interface=True,
        )


def _command_interface(ctx: Context, element: Element | None) -> str | None:
    """The first ``<hardwareInterface>`` of ``element`` that commands the joint (position, velocity,
    effort). A joint may list several; ``JointStateInterface`` only reports its state: PAL's TIAGo lists
    it first for its head and wrist joints, then ``PositionJointInterface``."""
    for child in ctx.children(element, "hardwareInterface") if element is not None else []:
        if interface_kind(child.text) is not None:
            return child.text
    return None


def _same_motor(ctx: Context, element: Element, motors: dict[str, str]) -> None:
    """MK242 when this transmission's actuator is already another transmission's (for another joint)."""
    joint_names = [str(j.get("name")) for j in ctx.children(element, "joint") if j.get("name")]
    for actuator in ctx.children(element, "actuator"):
        name = actuator.get("name")
        if not name or not joint_names:
            continue
        first = motors.setdefault(name, joint_names[0])
        if first not in joint_names:
            ctx.emit("MK242", f'actuator "{name}" of the transmission of joint "{joint_names[0]}" is also '
                     f'the actuator of joint "{first}": Drake refuses the file (joint actuator names must '
                     "be unique within a model); check_urdf, PyBullet and MuJoCo load it",
                     ctx.loc(actuator, "name"))


def _initial_values(ctx: Context, element: Element, robot: Robot) -> None:
    by_name: dict[str, Joint] = {}
    for each in robot.joints:
        by_name.setdefault(each.name, each)
    for joint_el in ctx.children(element, "joint"):
        joint = by_name.get(joint_el.get("name") or "")
        if joint is None:
            continue
        for state in ctx.children(joint_el, "state_interface"):
            if state.get("name") != "position":
                continue
            for param in ctx.children(state, "param"):
                if param.get("name") != "initial_value":
                    continue
                value = parse_number((param.text or "").strip())
                if value is not None and math.isfinite(value):
                    joint.initial_position = value
                    joint.sources["initial_position"] = ctx.loc(param)


def _ros2_control(ctx: Context, element: Element, joints: set[str], found: dict[str, Actuator]) -> None:
    for joint_el in ctx.children(element, "joint"):
        name = joint_el.get("name")
        if name is None or name not in joints:
            continue
        for command in ctx.children(joint_el, "command_interface"):
            kind = interface_kind(command.get("name"))
            if kind is None:
                continue
            actuator: Actuator = found.get(name) or Actuator(joint=name)
            actuator.kind = kind
            actuator.source_kind = f"ros2_control {kind.value}"
            actuator.ros_interface = True
            actuator.source = ctx.loc(command)
            params = {p.get("name"): parse_number((p.text or "").strip())
                      for p in ctx.children(command, "param")}
            low, high = params.get("min"), params.get("max")
            if low is not None and high is not None and low < high:
                actuator.ctrl_range = (low, high)
            found[name] = actuator
            break
