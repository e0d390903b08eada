"""SDF writer, actuators: the model's canonical actuators as gz-sim joint-controller systems.

SDF has no actuator element; Gazebo Sim drives a joint through a model ``<plugin>`` (the systems and
their parameters: :mod:`modelkit.formats.sdf.actuators`). One plugin per actuator on a written
revolute or prismatic joint:

* position → ``JointPositionController``: ``p_gain`` = kp, ``d_gain`` = kv, ``i_gain`` 0 (gz-sim's
  default integral gain is 0.1), ``cmd_max``/``cmd_min`` = the force range, else ±the joint's effort
  limit (gz-sim's own default clamp is ±1000);
* velocity → ``JointController`` with ``use_force_commands`` (a PID on the velocity error, the canonical
  velocity servo): ``p_gain`` = kv, ``i_gain``/``d_gain`` 0, the force range as for position; an
  actuator read from a JointController in velocity mode is written back in velocity mode;
* effort → ``ApplyJointForce``: the command is the joint force (gear, control and force ranges have no
  parameter there: MK844).

Gains the source did not give come from :mod:`modelkit.convert.servo_gains` (MK840), as for MJCF,
except for an actuator read from an SDF plugin: a gain it left out stays out (gz-sim's default). An
actuator read from an SDF plugin gets that plugin's other parameters back (``topic``, ``i_gain``,
``initial_position``...) and its ``filename``/``name`` (``ignition-gazebo-...`` stays). Written for
Gazebo classic (``--gazebo classic``), which has no such systems, actuators are left out (MK808).
"""

from __future__ import annotations

import math
from collections import Counter
from typing import Any

from lxml.etree import _Element as Element

from modelkit.convert.actuator_choice import (
    chosen_actuators,
    constrained_joints,
    counted,
    filled_message,
    load_bearing_unactuated,
    mobile_arm_joints,
    sags_at_home,
    servoed_interfaces,
    servoed_message,
)
from modelkit.convert.context import WriteContext
from modelkit.convert.drive_plugin import find_drive
from modelkit.convert.legs import leg_joints
from modelkit.convert.numbers import fmt
from modelkit.convert.servo_gains import (
    SERVO_BANDWIDTH_HZ,
    JointLoad,
    home_position,
    joint_loads,
    position_gains,
    velocity_gain,
)
from modelkit.formats.sdf.actuators import system_of
from modelkit.formats.sdf.write_xml import num, parse_fragment, sub
from modelkit.model import Actuator, ActuatorKind, Joint, Robot

SYSTEM_FILES = {
    "JointPositionController": "gz-sim-joint-position-controller-system",
    "JointController": "gz-sim-joint-controller-system",
    "ApplyJointForce": "gz-sim-apply-joint-force-system",
}
SYSTEM_FOR = {
    ActuatorKind.POSITION: "JointPositionController",
    ActuatorKind.VELOCITY: "JointController",
    ActuatorKind.EFFORT: "ApplyJointForce",
}
NOT_COPIED = frozenset({"joint_name"})  # the source plugin's children the writer always writes itself


def from_sdf_plugin(actuator: Actuator) -> bool:
    return actuator.source_kind.startswith("gz-sim ")


def source_plugins(robot: Robot) -> dict[str, dict[str, Any]]:
    """Joint name → the source's plugin dict that became its actuator (SDF sources)."""
    out: dict[str, dict[str, Any]] = {}
    for plugin in robot.extras.get("sdf_plugins") or []:
        if isinstance(plugin, dict):
            for joint in plugin.get("actuates") or []:
                out.setdefault(str(joint), plugin)
    return out


def _system(plugin: Element) -> str | None:
    return system_of(plugin.get("filename") or "", plugin.get("name") or "")


class ActuatorWriter:
    """Writes the plugins into ``model``; ``joints`` maps source joint names to written revolute or
    prismatic joints (anything else cannot carry one of these systems)."""

    def __init__(self, robot: Robot, ctx: WriteContext, family: str, joints: dict[str, str],
                 as_written: Robot | None = None) -> None:
        self.robot = robot
        # the robot with the masses the file holds (a massless link's tiny one, MK816): the gains' model
        self.as_written = as_written or robot
        self.ctx = ctx
        self.family = family
        self.joints = joints
        self.sources = source_plugins(robot)
        self._loads: dict[str, JointLoad] | None = None
        self._legs: frozenset[str] | None = None  # the joints in a legged robot's legs, found once
        self._arms: frozenset[str] | None = None  # the unranged joints of a mobile robot's arms

    def write(self, model: Element) -> int:
        robot = self.robot
        by_name: dict[str, Joint] = {}
        for each in robot.joints:
            by_name.setdefault(each.name, each)
        if not robot.actuators:
            return self._chosen(model, by_name)
        if self.family == "classic":
            self.ctx.note(
                "MK808",
                f"{len(robot.actuators)} actuator(s) of the source are left out: Gazebo classic has no "
                "per-joint controller plugin (its robots are driven by gazebo_ros_control from URDF "
                "transmissions); --gazebo sim writes them as gz-sim joint controllers",
                robot.source,
                "model",
            )
            return 0
        if self.ctx.options.source_actuators == "replace":
            self.ctx.note("MK855", f"the source's {len(robot.actuators)} actuator(s) set aside "
                          "(--source-actuators replace); the --actuators choice is written instead",
                          robot.source, "model/plugin")
            return self._chosen(model, by_name)
        written = 0
        made_up: list[str] = []
        lost: list[str] = []
        servoed = self._servoed()
        for source_actuator in robot.actuators:
            actuator = servoed.get(id(source_actuator), source_actuator)
            target = self.joints.get(actuator.joint)
            joint = by_name.get(actuator.joint)
            if target is None or joint is None:
                self.ctx.note("MK842", f"actuator on joint {actuator.joint} left out: the joint is not "
                              "written as a revolute or prismatic joint", actuator.source, "model/plugin")
                continue
            self._one(model, actuator, joint, target, made_up, lost)
            written += 1
        for actuator in self._load_bearing_unactuated():
            joint = by_name[actuator.joint]
            target = self.joints.get(joint.name)
            if target is not None:
                self._one(model, actuator, joint, target, made_up, lost)
                written += 1
        self._said_servoed(list(servoed.values()))
        self._said(made_up, lost)
        return written

    def _load_bearing_unactuated(self) -> list[Actuator]:
        """``--source-actuators auto``: servos on the load-bearing joints a source naming actuators for
        others leaves without one, as in MJCF (MK827, :func:`modelkit.convert.actuator_choice.
        load_bearing_unactuated`); not for an MJCF source, whose actuators the model may not all hold."""
        robot, options = self.robot, self.ctx.options
        if options.source_actuators != "auto" or robot.source_format == "mjcf":
            return []
        legs = self._leg_joints()
        links = {link.name: link for link in robot.links}
        taken = {a.joint for a in robot.actuators}
        out = load_bearing_unactuated(robot, taken, options.actuators, legs,
                                      lambda joint: sags_at_home(joint, self._load(joint.name), links),
                                      self._arm_joints())
        if out:
            message = filled_message(out, legs, options.actuators, SYSTEM_FOR[out[0].kind], "its home pose")
            self.ctx.note("MK827", message, robot.source, "model/plugin")
        return out

    def _servoed(self) -> dict[int, Actuator]:
        """``--source-actuators auto``: the source's ROS effort interfaces that the ``--actuators`` choice
        makes servos, as in MJCF (:func:`modelkit.convert.actuator_choice.servoed_interfaces`)."""
        robot, options = self.robot, self.ctx.options
        if not any(a.ros_interface and a.kind is ActuatorKind.EFFORT for a in robot.actuators):
            return {}
        return servoed_interfaces(robot, options.actuators, options.source_actuators, self._leg_joints(),
                                  self._arm_joints())

    def _leg_joints(self) -> frozenset[str]:
        """The joints of the robot's legs (:func:`modelkit.convert.legs.leg_joints`), found once."""
        if self._legs is None:
            self._legs = leg_joints(self.robot)
        return self._legs

    def _arm_joints(self) -> frozenset[str]:
        """The unranged joints of a mobile robot's arms (:func:`modelkit.convert.actuator_choice.
        mobile_arm_joints`), found once."""
        if self._arms is None:
            self._arms = mobile_arm_joints(self.robot, lambda joint: self._load(joint.name))
        return self._arms

    def _said_servoed(self, servoed: list[Actuator]) -> None:
        """MK864: the source's ROS effort interfaces written as position or velocity controllers."""
        if not servoed:
            return
        message = servoed_message(servoed, self.ctx.options.actuators, SYSTEM_FOR.__getitem__,
                                  "ApplyJointForce", "at zero force the robot sags until one drives it",
                                  "ApplyJointForce")
        self.ctx.note("MK864", message, self.robot.source, "model/plugin")

    def _said(self, made_up: list[str], lost: list[str]) -> None:
        """MK840: the gains the rule gave; MK844: what the systems cannot hold."""
        if made_up:
            self.ctx.note(
                "MK840",
                f"{len(made_up)} servo(s) without gains in the source get gains for a "
                f"{fmt(SERVO_BANDWIDTH_HZ)} Hz critically damped loop on each joint's reflected inertia at "
                "home, raised where gravity at home would make it sag (docs/convert.md): "
                + "; ".join(made_up),
                self.robot.source,
                "model/plugin",
            )
        if lost:
            self.ctx.note(
                "MK844",
                f"{len(lost)} actuator(s) written as gz-sim systems without what those systems cannot hold: "
                + "; ".join(lost),
                self.robot.source,
                "model/plugin",
            )

    def _chosen(self, model: Element, by_name: dict[str, Joint]) -> int:
        """The source names no actuators, or ``--source-actuators replace`` set them aside: the
        ``--actuators`` choice (:mod:`modelkit.convert.actuator_choice`, the MJCF writer's rule) on every
        hinge and slide written as a revolute or prismatic joint that is not a mimic follower, locked, or a
        wheel the differential-drive system drives (MK858); a position controller starts at the joint's
        home position (``initial_position``). Gazebo classic has no such systems: nothing is written
        there."""
        choice = self.ctx.options.actuators
        if self.family == "classic" or choice == "none":
            return 0
        robot = self.robot
        driven: set[str] = set()
        if self.ctx.options.drive_plugin:
            drive, _ = find_drive(robot, "sdf", self.family)
            driven = set(drive.left + drive.right) if drive is not None else set()
        made_up: list[str] = []
        lost: list[str] = []
        written: Counter[ActuatorKind] = Counter()
        skipped = constrained_joints(robot) | driven
        for actuator in chosen_actuators(robot, choice, self._leg_joints(), skipped, self._arm_joints()):
            joint, target = by_name[actuator.joint], self.joints.get(actuator.joint)
            if target is None:
                continue  # not written as a revolute or prismatic joint
            plugin = self._one(model, actuator, joint, target, made_up, lost)
            home = home_position(joint)
            if actuator.kind is ActuatorKind.POSITION and home != 0.0:
                num(plugin, "initial_position", home)
            written[actuator.kind] += 1
        if not written:
            return 0
        what = counted(written, SYSTEM_FOR.__getitem__)
        why = ("; auto puts a position controller on each joint with a range, in a leg or on a welded base "
               "(the home pose holds) and a force system on each other joint without a range (zero force "
               "leaves it free)") if choice == "auto" else ""
        wheels = f"; the wheels {', '.join(sorted(driven))} are the DiffDrive system's" if driven else ""
        whose = "the source's actuators set aside" if robot.actuators else "the source names no actuators"
        self.ctx.note("MK841", f"{whose}: {what} system(s) written (--actuators "
                      f"{choice}{why}{wheels}; --actuators none leaves them out)", robot.source,
                      "model/plugin")
        self._said(made_up, lost)
        return sum(written.values())

    # -- one actuator -------------------------------------------------------------------------------

    def _one(self, model: Element, actuator: Actuator, joint: Joint, target: str, made_up: list[str],
             lost: list[str]) -> Element:
        source = self.sources.get(actuator.joint) if from_sdf_plugin(actuator) else None
        verbatim = parse_fragment(str(source.get("xml", ""))) if source is not None else None
        system = SYSTEM_FOR[actuator.kind]
        if verbatim is not None and _system(verbatim) != system:
            verbatim = None  # the actuator's kind changed since it was read: written from the model
        filename = verbatim.get("filename") if verbatim is not None else None
        cls = verbatim.get("name") if verbatim is not None else None
        el = sub(model, "plugin", filename=filename or SYSTEM_FILES[system],
                 name=cls or f"gz::sim::systems::{system}")
        sub(el, "joint_name", target)
        written: set[str] = {"joint_name"}
        if verbatim is None:
            written |= self._parameters(el, actuator, joint, target, made_up)
            self._losses(actuator, target, lost)
        for extra in verbatim if verbatim is not None else []:
            if isinstance(extra.tag, str) and extra.tag not in written:
                extra.tail = None
                el.append(extra)
        return el

    def _parameters(self, el: Element, actuator: Actuator, joint: Joint, target: str,
                    made_up: list[str]) -> set[str]:
        kind = actuator.kind
        if kind is ActuatorKind.EFFORT:
            return set()
        if kind is ActuatorKind.VELOCITY:
            sub(el, "use_force_commands", "true")
        kp, kv = actuator.kp, actuator.kv
        load = self._load(joint.name)
        inertia = load.inertia
        if kind is ActuatorKind.POSITION and (kp is None or kv is None):
            rule_kp, rule_kv = position_gains(load)
            kp = rule_kp if kp is None else kp
            kv = rule_kv if kv is None else kv
            made_up.append(f"{target} kp {fmt(kp)} kv {fmt(kv)} (inertia {fmt(inertia)})")
        elif kind is ActuatorKind.VELOCITY and kv is None:
            kv = velocity_gain(load)
            made_up.append(f"{target} kv {fmt(kv)} (inertia {fmt(inertia)})")
        gains = (kp, 0.0, kv) if kind is ActuatorKind.POSITION else (kv, 0.0, 0.0)
        for tag, value in zip(("p_gain", "i_gain", "d_gain"), gains, strict=True):
            num(el, tag, float(value or 0.0))
        force = actuator.force_range
        effort = joint.limits.effort
        if force is None and math.isfinite(effort) and effort > 0.0:
            force = (-effort, effort)
        if force is not None:
            num(el, "cmd_max", force[1])
            num(el, "cmd_min", force[0])
        return {"use_force_commands", "p_gain", "i_gain", "d_gain", "cmd_max", "cmd_min"}

    def _losses(self, actuator: Actuator, target: str, lost: list[str]) -> None:
        dropped: list[str] = []
        if actuator.gear != 1.0:
            dropped.append(f"gear {fmt(actuator.gear)}")
        if actuator.ctrl_range is not None:
            dropped.append(f"ctrlrange {fmt(actuator.ctrl_range[0])} {fmt(actuator.ctrl_range[1])}")
        if actuator.kind is ActuatorKind.EFFORT and actuator.force_range is not None:
            dropped.append(f"forcerange {fmt(actuator.force_range[0])} {fmt(actuator.force_range[1])}")
        if dropped:
            lost.append(f"{target} ({', '.join(dropped)})")

    def _load(self, joint: str) -> JointLoad:
        if self._loads is None:
            self._loads = joint_loads(self.as_written)
        return self._loads.get(joint, JointLoad(0.0))
