"""MJCF writer, actuators: the model's canonical actuators, or the ``--actuators`` choice without any.

* The source's actuators (``robot.actuators``), one element each on its joint's written hinge or slide:
  position → ``<position kp kv ctrlrange forcerange>``, velocity → ``<velocity kv forcerange>``,
  effort → ``<motor gear ctrlrange>``. ``ctrlrange``: the source's, else for a position servo the
  joint's range, for a motor ±effort/gear; ``forcerange``: the source's, else ±effort.
  Gains the source did not give come from :mod:`modelkit.convert.servo_gains` (MK840).
  An actuator on a joint that is not written as one hinge or slide (fixed, ball, planar, a mimic
  follower or a locked joint) is left out (MK842); a transmission reduction is folded into the joint
  (MK843).
* A source without actuators: every hinge and slide that is not a mimic follower or locked gets the
  ``--actuators`` kind (``motor`` by default: gear 1, the control is the joint force, ``ctrlrange`` =
  ±effort; zero control applies no force, so the passive model is unchanged), or none (MK841).

Position actuators make the ``home`` keyframe carry ``ctrl`` = the home positions (others 0), so that
a model reset to ``home`` holds it.
"""

from __future__ import annotations

import math

from modelkit.convert.context import WriteContext
from modelkit.convert.numbers import fmt, fmt_vec
from modelkit.convert.servo_gains import SERVO_BANDWIDTH_HZ, position_gains, reflected_inertias, velocity_gain
from modelkit.formats.mjcf.write_names import NameTable
from modelkit.formats.mjcf.write_xml import Element, sub
from modelkit.model import Actuator, ActuatorKind, Joint, JointType, Robot

ELEMENTS = {ActuatorKind.EFFORT: "motor", ActuatorKind.POSITION: "position",
            ActuatorKind.VELOCITY: "velocity"}
CHOICES = {"motor": ActuatorKind.EFFORT, "position": ActuatorKind.POSITION, "velocity": ActuatorKind.VELOCITY}


class ActuatorWriter:
    def __init__(self, robot: Robot, ctx: WriteContext, names: NameTable, section: Element,
                 joint_names: dict[str, list[str]]) -> None:
        self.robot = robot
        self.ctx = ctx
        self.names = names
        self.section = section
        self.joint_names = joint_names
        self.ctrl: list[float] = []  # the home keyframe's ctrl, one per written actuator
        self.any_position = False
        self.servos = 0  # position and velocity actuators written
        self._inertias: dict[str, float] | None = None

    def write(self, home: dict[str, float]) -> None:
        by_name: dict[str, Joint] = {}
        for each in self.robot.joints:
            by_name.setdefault(each.name, each)
        if self.robot.actuators:
            planned: list[tuple[Actuator, Joint | None]] = [
                (a, by_name.get(a.joint)) for a in self.robot.actuators
            ]
            made_up = False
        else:
            kind = CHOICES.get(self.ctx.options.actuators)
            planned = [] if kind is None else [
                (Actuator(joint=j.name, kind=kind, source_kind="--actuators", source=j.source), j)
                for j in self.robot.joints if j.type in (JointType.REVOLUTE, JointType.PRISMATIC)
            ]
            made_up = True
        skipped = self._constrained()
        written = 0
        for actuator, joint in planned:
            target = self.joint_names.get(actuator.joint)
            reason = self._unwritable(joint, target, skipped)
            if reason is not None:
                if not made_up:
                    self.ctx.note("MK842", f"actuator on joint {actuator.joint} left out: {reason}",
                                  actuator.source, "actuator")
                continue
            assert joint is not None and target is not None
            self._one(actuator, joint, target[0], home.get(target[0], 0.0))
            written += 1
        self._uncanonical()
        movable = any(j.type in (JointType.REVOLUTE, JointType.PRISMATIC) for j in self.robot.joints)
        if made_up and movable:
            choice = self.ctx.options.actuators
            element = ELEMENTS.get(CHOICES.get(choice, ActuatorKind.EFFORT))
            what = "no actuators" if choice == "none" else f"{written} <{element}> actuator(s)"
            self.ctx.note("MK841", f"the source names no actuators: {what} written (--actuators {choice})",
                          self.robot.source, "actuator")

    def _uncanonical(self) -> None:
        """MK842 for an MJCF source's actuators that the model could not hold (activation dynamics,
        tendon or site transmissions, other gain and bias laws): they are not written."""
        kept = self.robot.extras.get("mjcf_actuators") or []
        canonical = sum(1 for a in self.robot.actuators if a.source_kind != "track roller")
        left = len(kept) - canonical
        if left > 0:
            self.ctx.note(
                "MK842",
                f"{left} MJCF actuator(s) of the source left out: not a motor, position or velocity law on "
                "one hinge or slide (activation dynamics, tendon or site transmission, another law)",
                self.robot.source,
                "actuator",
            )

    def _constrained(self) -> set[str]:
        followers = {j.name for j in self.robot.joints if j.mimic is not None}
        return followers | {j.name for j in self.robot.joints if j.limits.lower == j.limits.upper}

    @staticmethod
    def _unwritable(joint: Joint | None, target: list[str] | None, skipped: set[str]) -> str | None:
        if joint is None or target is None:
            return "the joint is not written"
        if joint.type not in (JointType.REVOLUTE, JointType.PRISMATIC) or len(target) != 1:
            return f"a {joint.type.value} joint is not one hinge or slide"
        if joint.name in skipped:
            return "the joint follows another (mimic) or is locked"
        return None

    def inertia(self, joint: Joint) -> float:
        if self._inertias is None:
            self._inertias = reflected_inertias(self.robot)
        return self._inertias.get(joint.name, 0.0)

    def _one(self, actuator: Actuator, joint: Joint, target: str, home_q: float) -> None:
        kind = actuator.kind
        name = actuator.name or target
        where = actuator.source or joint.source
        el = sub(self.section, ELEMENTS[kind],
                 name=self.names.claim("actuator", name, where, f"actuator[{name}]"), joint=target)
        effort = joint.limits.effort
        limited = math.isfinite(effort) and effort > 0.0
        if actuator.gear != 1.0:
            el.set("gear", fmt(actuator.gear))
        if kind is ActuatorKind.EFFORT:
            ctrl = actuator.ctrl_range
            if ctrl is None and limited:
                bound = effort / abs(actuator.gear) if actuator.gear else effort
                ctrl = (-bound, bound)
            if ctrl is not None:
                el.set("ctrlrange", fmt_vec(list(ctrl)))
            self.ctrl.append(0.0)
        else:
            self._gains(el, actuator, joint, target)
            ctrl = actuator.ctrl_range
            if ctrl is None and kind is ActuatorKind.POSITION and joint.limits.lower < joint.limits.upper \
                    and math.isfinite(joint.limits.lower) and math.isfinite(joint.limits.upper):
                ctrl = (joint.limits.lower, joint.limits.upper)
            if ctrl is not None:
                el.set("ctrlrange", fmt_vec(list(ctrl)))
            self.ctrl.append(home_q if kind is ActuatorKind.POSITION else 0.0)
            self.any_position = self.any_position or kind is ActuatorKind.POSITION
            self.servos += 1
        force = actuator.force_range
        if force is None and limited and kind is not ActuatorKind.EFFORT:
            force = (-effort, effort)
        if force is not None:
            el.set("forcerange", fmt_vec(list(force)))
        if actuator.reduction != 1.0:
            self.ctx.note(
                "MK843",
                f"actuator on joint {joint.name}: reduction {fmt(actuator.reduction)} folded into the joint "
                f"(the actuator acts at the joint; rotor inertia {fmt(actuator.rotor_inertia)} kg·m² × "
                "reduction² is in the joint's armature where the source gave it)",
                actuator.source or joint.source,
                f"actuator[{name}]",
            )

    def _gains(self, el: Element, actuator: Actuator, joint: Joint, target: str) -> None:
        kp, kv = actuator.kp, actuator.kv
        if actuator.kind is ActuatorKind.POSITION:
            if kp is None:
                inertia = self.inertia(joint)
                kp, rule_kv = position_gains(inertia)
                kv = rule_kv if kv is None else kv
                self._made_up(actuator, joint, target, inertia, f"kp {fmt(kp)}, kv {fmt(kv)}")
            el.set("kp", fmt(kp))
            if kv:
                el.set("kv", fmt(kv))
        else:
            if kv is None:
                inertia = self.inertia(joint)
                kv = velocity_gain(inertia)
                self._made_up(actuator, joint, target, inertia, f"kv {fmt(kv)}")
            el.set("kv", fmt(kv))

    def _made_up(self, actuator: Actuator, joint: Joint, target: str, inertia: float, gains: str) -> None:
        unit = "kg" if joint.type is JointType.PRISMATIC else "kg·m²"
        self.ctx.note(
            "MK840",
            f"{actuator.kind.value} actuator on joint {joint.name}: {gains} from its reflected inertia "
            f"{fmt(inertia)} {unit} at home and a {fmt(SERVO_BANDWIDTH_HZ)} Hz critically damped servo "
            f"(the source{' ' + actuator.source_kind if actuator.source_kind else ''} gives no gains)",
            actuator.source or joint.source,
            f"actuator[{target}]",
        )
