"""MJCF writer, actuators: the model's canonical actuators, or the ``--actuators`` choice without any.

* The source's actuators (``robot.actuators``), one element each on its joint's written hinge or slide:
  position → ``<position kp kv ctrlrange forcerange>``, velocity → ``<velocity kv forcerange>``,
  effort → ``<motor gear ctrlrange>``. ``ctrlrange``: the source's, else for a position servo the
  joint's range, for a motor ±effort/gear; ``forcerange``: the source's, else ±effort.
  Gains the source did not give come from :mod:`modelkit.convert.servo_gains` (MK840).
  An actuator on a joint that is not written as one hinge or slide (fixed, ball, planar, a mimic
  follower or a locked joint) is left out (MK842); a transmission reduction is folded into the joint
  (MK843). An MJCF source's other actuators (tendon and site transmissions, activation dynamics,
  other laws) are written back as ``<general>`` by :mod:`.write_transmissions`, in the source's order.
* ``--source-actuators``: ``auto`` (the default) writes the source's actuators but its ROS effort
  interfaces (URDF ``EffortJointInterface`` transmissions, ros2_control ``effort``), which get the
  ``--actuators`` choice where it gives a servo (MK864); ``keep`` writes them all; ``replace`` sets them
  all aside, as for a source without any (MK855).
* A source without actuators: every hinge and slide that is not a mimic follower or locked gets the
  ``--actuators`` kind, or none (MK841). ``auto`` (the default): a position servo on each joint with a
  range or in a leg (the model holds its ``home`` pose, as MuJoCo Menagerie's arms and legs do), a
  motor on each other joint without a range (wheels: gear 1, the control is the joint force,
  ``ctrlrange`` = ±effort; zero control leaves the joint free). The track approximation's roller
  servos do not count as the source's: a tracked robot's other joints get the choice too.

Position actuators make the ``home`` keyframe carry ``ctrl`` = the home positions (others 0), so that
a model reset to ``home`` holds it.
"""

from __future__ import annotations

import math

from modelkit.convert.actuator_choice import (
    CHOSEN,
    FILLED,
    GRAVITY_FLOOR,
    SERVOED,
    chosen_actuators,
    chosen_kind,
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
from modelkit.convert.legs import is_wheel, leg_joints, resting_on
from modelkit.convert.numbers import fmt, fmt_vec
from modelkit.convert.servo_gains import (
    SERVO_BANDWIDTH_HZ,
    JointLoad,
    home_position,
    joint_loads,
    natural_frequency,
    natural_frequency_for,
    position_gains,
    velocity_gain,
)
from modelkit.convert.tracks import TRACK_ROLLER
from modelkit.formats.mjcf.actuators import TENDON_SOURCE
from modelkit.formats.mjcf.write_names import NameTable
from modelkit.formats.mjcf.write_xml import Element, sub
from modelkit.mimics import MIMIC_RANGE_SLACK, followers_by_leader, leader_range_within
from modelkit.model import Actuator, ActuatorKind, Joint, JointType, Link, Robot

ELEMENTS = {ActuatorKind.EFFORT: "motor", ActuatorKind.POSITION: "position",
            ActuatorKind.VELOCITY: "velocity"}


class ActuatorWriter:
    def __init__(self, robot: Robot, ctx: WriteContext, names: NameTable, section: Element,
                 joint_names: dict[str, list[str]], as_written: Robot | None = None) -> None:
        self.robot = robot
        # the robot with the masses the file holds (a massless link's MIN_MASS, MK816): the gains' model
        self.as_written = as_written or robot
        self.ctx = ctx
        self.names = names
        self.section = section
        self.joint_names = joint_names
        self.ctrl: list[float] = []  # the home keyframe's ctrl, one per written actuator
        self.elements: list[tuple[Actuator, Element]] = []  # the written actuators, as ``ctrl``
        self.set_aside = False  # --source-actuators replace set the source's actuators aside
        self.made_up = False  # the actuators are the --actuators choice, not the source's
        self.any_position = False
        self.servos = 0  # position and velocity actuators written
        # joint → (servo damping kv·gear², the joint's reflected inertia at home): what decides whether
        # MuJoCo's explicit Euler integrator can take the servo's damping (:meth:`euler_rate`)
        self.damping: dict[str, tuple[float, float]] = {}
        self._loads: dict[str, JointLoad] | None = None
        self._arms: frozenset[str] | None = None
        self._legs: frozenset[str] | None = None  # the joints in a legged robot's legs, found once
        self._links: dict[str, Link] | None = None
        self._holding: dict[str, float] = {}  # joint → the most its position servo gives it (N·m or N)
        self._followers: dict[str, list[Joint]] | None = None  # leader → its mimic followers, found once

    def write(self, home: dict[str, float]) -> None:
        by_name: dict[str, Joint] = {}
        for each in self.robot.joints:
            by_name.setdefault(each.name, each)
        replaced = self.set_aside = self._replaced()
        servoed = {} if replaced else self._servoed_interfaces()
        # an MJCF source's actuator on a fixed tendon, also read as one on the joint the tendon's joints
        # follow, is written back as it was (write_transmissions), not on the joint
        planned: list[tuple[Actuator, Joint | None]] = [
            (servoed.get(id(a), a), by_name.get(a.joint)) for a in self.robot.actuators
            if not (replaced and a.source_kind != TRACK_ROLLER) and a.source_kind != TENDON_SOURCE
        ]
        # The track approximation's roller servos are the writer's, not the source's: the rest of a
        # tracked robot is as silent as any other source (convert.tracks). An MJCF source's actuators
        # the model does not hold are its own too: they are written back (write_transmissions).
        made_up = self.made_up = replaced or not (
            any(a.source_kind != TRACK_ROLLER for a in self.robot.actuators)
            or self.robot.extras.get("mjcf_actuators"))
        taken = {a.joint for a, _ in planned}
        if made_up:
            chosen = chosen_actuators(self.robot, self.ctx.options.actuators, self._leg_joints(), taken,
                                      self._arm_joints())
            planned += [(a, by_name.get(a.joint)) for a in chosen]
        else:
            filled = self._load_bearing_unactuated(taken)
            planned += [(a, by_name.get(a.joint)) for a in filled]
        skipped = self._constrained()
        written: dict[ActuatorKind, int] = {}
        on_joint: dict[str, Actuator] = {}  # source joint name → the actuator written on it
        for actuator, joint in planned:
            target = self.joint_names.get(actuator.joint)
            reason = self._unwritable(joint, target, skipped)
            if reason is not None:
                if actuator.source_kind not in (CHOSEN, FILLED):
                    self.ctx.note("MK842", f"actuator on joint {actuator.joint} left out: {reason}",
                                  actuator.source, "actuator")
                continue
            assert joint is not None and target is not None
            self._one(actuator, joint, target[0], home.get(target[0], 0.0))
            on_joint.setdefault(joint.name, actuator)
            if actuator.source_kind == CHOSEN:
                written[actuator.kind] = written.get(actuator.kind, 0) + 1
        movable = any(j.type in (JointType.REVOLUTE, JointType.PRISMATIC) for j in self.robot.joints)
        if replaced:
            self._said_replaced(written)
        elif made_up and movable:
            self._said_choice(written)
        if servoed:
            self._said_servoed(list(servoed.values()))
        self._said_legs(on_joint)
        self._said_sagging(on_joint, by_name)
        self._said_overloaded(by_name)

    def _load_bearing_unactuated(self, taken: set[str]) -> list[Actuator]:
        """:func:`modelkit.convert.actuator_choice.load_bearing_unactuated` (MK827); not for an MJCF source,
        whose actuators the model may not all hold."""
        if self.ctx.options.source_actuators != "auto" or self.robot.source_format == "mjcf":
            return []
        choice = self.ctx.options.actuators
        out = load_bearing_unactuated(self.robot, taken, choice, self._leg_joints(), self.sags,
                                      self._arm_joints())
        if out:
            message = filled_message(out, self._leg_joints(), choice, f"<{ELEMENTS[out[0].kind]}>",
                                     "its home keyframe")
            self.ctx.note("MK827", message, self.robot.source, "actuator")
        return out

    def _replaced(self) -> bool:
        """Whether ``--source-actuators replace`` sets the source's own actuators aside (it has some)."""
        own = any(a.source_kind != TRACK_ROLLER for a in self.robot.actuators)
        return self.ctx.options.source_actuators == "replace" and (
            own or bool(self.robot.extras.get("mjcf_actuators")))

    def _servoed_interfaces(self) -> dict[int, Actuator]:
        """:func:`modelkit.convert.actuator_choice.servoed_interfaces` (MK864)."""
        return servoed_interfaces(self.robot, self.ctx.options.actuators, self.ctx.options.source_actuators,
                                  self._leg_joints(), self._arm_joints())

    def _said_servoed(self, servoed: list[Actuator]) -> None:
        """MK864: the source's ROS effort interfaces written as the ``--actuators`` choice."""
        message = servoed_message(servoed, self.ctx.options.actuators, lambda kind: f"<{ELEMENTS[kind]}>",
                                  "<motor>s", "at zero control a <motor> leaves the robot sagging until one "
                                  "drives it", "the <motor>s")
        self.ctx.note("MK864", message, self.robot.source, "actuator")

    def _said_replaced(self, written: dict[ActuatorKind, int]) -> None:
        """MK855: the source's actuators set aside by ``--source-actuators replace``, and what was written."""
        own = [a for a in self.robot.actuators if a.source_kind != TRACK_ROLLER]
        kinds: dict[str, int] = {}
        for actuator in own:
            kinds[actuator.kind.value] = kinds.get(actuator.kind.value, 0) + 1
        unheld = len(self.robot.extras.get("mjcf_actuators") or []) - len(own)
        parts = [f"{count} {kind}" for kind, count in sorted(kinds.items())]
        if unheld > 0:
            parts.append(f"{unheld} other MJCF")
        what = counted(written, lambda kind: f"<{ELEMENTS[kind]}>") or "none"
        self.ctx.note("MK855", f"the source's {len(own) + max(unheld, 0)} actuator(s) ({', '.join(parts)}) "
                      f"set aside (--source-actuators replace); written instead: {what} "
                      f"(--actuators {self.ctx.options.actuators})", self.robot.source, "actuator")

    def _said_sagging(self, on_joint: dict[str, Actuator], by_name: dict[str, Joint]) -> None:
        """MK863: joints outside legs (MK857) that the source's effort actuators drive and gravity turns
        at home (an arm's shoulder and elbow under URDF ``EffortJointInterface`` transmissions): at zero
        control the robot sags until a controller drives them."""
        sagging = [(name, self.load(by_name[name]).gravity) for name, actuator in on_joint.items()
                   if actuator.kind is ActuatorKind.EFFORT and actuator.source_kind not in (CHOSEN,
                                                                                             TRACK_ROLLER)
                   and name not in self._leg_joints() and name in by_name and self.sags(by_name[name])]
        if not sagging:
            return
        shown = ", ".join(f"{name} {load:.3g}" for name, load in sagging[:4]) + (" ..." if len(sagging) > 4
                                                                                 else "")
        self.ctx.note("MK863", f"{len(sagging)} joint(s) with the source's effort actuators, written as "
                      f"<motor>, carry a gravity load at home ({shown}; N·m, N for a slide): at zero control "
                      "the robot sags until a controller drives them (--source-actuators replace gives them "
                      "the --actuators choice: auto, position servos that hold the home keyframe; the "
                      "default --source-actuators auto does so for ROS effort interfaces)",
                      self.robot.source, "actuator")

    def _said_overloaded(self, by_name: dict[str, Joint]) -> None:
        """MK868: position servos whose force limit (the source's effort limit, or its actuator's force
        range) is below the gravity load they hold at home (a leg's with its share of the robot's
        weight), less the joint's Coulomb friction: the servo saturates and the robot sags off its home
        pose, whatever the gains (the PR2's shoulders: 52 N·m against 30; the real arm has a counterbalance
        spring its URDF does not describe)."""
        if self._links is None:
            self._links = {link.name: link for link in self.robot.links}
        over: list[tuple[str, float, float]] = []
        for name, most in self._holding.items():
            joint = by_name[name]
            if is_wheel(joint, self._links):
                continue  # a wheel's load is the robot's, which the floor carries
            gravity = self.load(joint).gravity
            if gravity > GRAVITY_FLOOR and gravity - joint.friction > most * (1.0 + 1e-9):
                over.append((name, gravity, most))
        if not over:
            return
        over.sort(key=lambda each: each[2] - each[1])
        shown = ", ".join(f"{name} {need:.3g} > {most:.3g}" for name, need, most in over[:4])
        legs = sum(1 for name, _, _ in over if name in self._leg_joints())
        share = f"; {legs} in legs, with the leg's share of the robot's weight standing" if legs else ""
        where = by_name[over[0][0]].source or self.robot.source
        self.ctx.note("MK868", f"{len(over)} joint(s) whose position servo's force limit is below the "
                      f"gravity load it holds at home ({shown}; N·m, N for a slide{share}): the servo "
                      "saturates and the robot sags off its home pose in any engine that applies the "
                      "limit; a counterbalance the source does not describe, a larger effort limit or "
                      "MuJoCo's body gravcomp holds it", where, "actuator")

    def _said_legs(self, on_joint: dict[str, Actuator]) -> None:
        """MK857: the source's motors leave a legged robot's legs limp; MK856: its home pose, which the
        servos hold, lies on the body, not the feet (convert.legs)."""
        legs = sorted(self._leg_joints())
        if not legs:
            return
        limp = [name for name in legs if name in on_joint and on_joint[name].kind is ActuatorKind.EFFORT
                and on_joint[name].source_kind != CHOSEN]
        if limp:
            shown = ", ".join(limp[:4]) + (" ..." if len(limp) > 4 else "")
            self.ctx.note("MK857", f"{len(limp)} of the {len(legs)} leg joints ({shown}) have the source's "
                          "effort actuators, written as <motor>: at zero control those legs are limp and the "
                          "robot lies down on a floor until a controller drives them (--source-actuators "
                          "replace gives them the --actuators choice: auto, position servos; the default "
                          "--source-actuators auto does so for ROS effort interfaces)",
                          self.robot.source, "actuator")
        held = [name for name in legs if name in on_joint and on_joint[name].kind is ActuatorKind.POSITION]
        if not held:
            return
        home = {j.name: home_position(j) for j in self.robot.joints}
        resting = resting_on(self.robot, home)
        if resting:
            shown = ", ".join(resting[:4]) + (" ..." if len(resting) > 4 else "")
            self.ctx.note("MK856", f"the home keyframe is not a standing pose: at home the robot rests on "
                          f"{shown}, not on its feet (the source gives no initial positions of a stance; a "
                          "URDF can give them as ros2_control initial_value), so on a floor its servos hold "
                          "it lying down", self.robot.source, "keyframe")

    def _leg_joints(self) -> frozenset[str]:
        """The joints of the robot's legs (:func:`modelkit.convert.legs.leg_joints`), found once."""
        if self._legs is None:
            self._legs = leg_joints(self.robot)
        return self._legs

    def _arm_joints(self) -> frozenset[str]:
        """The unranged joints of a mobile robot's arms (:func:`modelkit.convert.actuator_choice.
        mobile_arm_joints`), found once."""
        if self._arms is None:
            self._arms = mobile_arm_joints(self.robot, self.load)
        return self._arms

    def _chosen_kind(self, joint: Joint) -> ActuatorKind | None:
        """The ``--actuators`` kind of a joint the source does not actuate (None: no actuator):
        :func:`modelkit.convert.actuator_choice.chosen_kind`."""
        return chosen_kind(joint, self.robot, self.ctx.options.actuators, self._leg_joints(),
                           self._arm_joints())

    def sags(self, joint: Joint) -> bool:
        """Whether gravity turns the joint at home: its gravity load there exceeds its Coulomb friction
        (a wheel's, whose mass sits on its axis, and a vertical axis's are nil). A wheel never sags:
        its load is the robot's, which the floor carries."""
        if self._links is None:
            self._links = {link.name: link for link in self.robot.links}
        return sags_at_home(joint, self.load(joint), self._links)

    def _said_choice(self, written: dict[ActuatorKind, int]) -> None:
        """MK841: the source names no actuators, what ``--actuators`` wrote instead."""
        choice = self.ctx.options.actuators
        if choice == "none":
            what = "no actuators"
        elif not written:
            what = "no actuators (no hinge or slide that is free to drive)"
        else:
            what = counted(written, lambda kind: f"<{ELEMENTS[kind]}> actuator(s)")
        why = ""
        if choice == "auto":
            why = ("; auto puts a position servo on each joint with a range, in a leg or on a welded base "
                   "(the home keyframe holds) and a motor on each other joint "
                   "without a range (zero control leaves it free)")
        self.ctx.note("MK841", f"the source names no actuators: {what} written (--actuators {choice}{why})",
                      self.robot.source, "actuator")

    def _constrained(self) -> set[str]:
        return constrained_joints(self.robot)

    @staticmethod
    def _unwritable(joint: Joint | None, target: list[str] | None, skipped: set[str]) -> str | None:
        if joint is None or target is None:
            return "the joint is not written"
        if joint.type not in (JointType.REVOLUTE, JointType.PRISMATIC) or len(target) != 1:
            return f"a {joint.type.value} joint is not one hinge or slide"
        if joint.name in skipped:
            return "the joint follows another (mimic) or is locked"
        return None

    def euler_rate(self) -> tuple[str, float, float, float] | None:
        """The written servo whose damping Euler takes worst: (joint, damping, inertia, damping/inertia
        in 1/s). Euler integrates a servo's damping explicitly, and it diverges when damping/inertia × the
        timestep passes 2. None without damped servos or when a joint carries no inertia."""
        rates = [(name, d, i, d / i) for name, (d, i) in self.damping.items() if i > 0.0]
        return max(rates, key=lambda item: item[3]) if rates else None

    def load(self, joint: Joint) -> JointLoad:
        if self._loads is None:
            self._loads = joint_loads(self.as_written)
        return self._loads.get(joint.name, JointLoad(0.0))

    def _one(self, actuator: Actuator, joint: Joint, target: str, home_q: float) -> None:
        kind = actuator.kind
        name = actuator.name or target
        where = actuator.source or joint.source
        el = sub(self.section, ELEMENTS[kind],
                 name=self.names.claim("actuator", name, where, f"actuator[{name}]"), joint=target)
        self.elements.append((actuator, el))
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
                ctrl = self._kept_by_followers(joint, (joint.limits.lower, joint.limits.upper), name)
            if ctrl is not None:
                el.set("ctrlrange", fmt_vec(list(ctrl)))
            self.ctrl.append(home_q if kind is ActuatorKind.POSITION else 0.0)
            self.any_position = self.any_position or kind is ActuatorKind.POSITION
            self.servos += 1
            kv = float(el.get("kv") or 0.0)
            if kv > 0.0:
                self.damping[joint.name] = (kv * actuator.gear ** 2, self.load(joint).inertia)
        force = actuator.force_range
        if force is None and limited and kind is not ActuatorKind.EFFORT:
            force = (-effort, effort)
        if force is not None:
            el.set("forcerange", fmt_vec(list(force)))
        if kind is ActuatorKind.POSITION and (force is not None or limited):
            # the joint gets gear × the actuator's force, clamped by its actuatorfrcrange (±effort)
            most = max(abs(force[0]), abs(force[1])) * abs(actuator.gear) if force is not None else math.inf
            self._holding[joint.name] = min(most, effort if limited else math.inf)
        if actuator.reduction != 1.0:
            self.ctx.note(
                "MK843",
                f"actuator on joint {joint.name}: reduction {fmt(actuator.reduction)} folded into the joint "
                f"(the actuator acts at the joint; rotor inertia {fmt(actuator.rotor_inertia)} kg·m² × "
                "reduction² is in the joint's armature where the source gave it)",
                actuator.source or joint.source,
                f"actuator[{name}]",
            )

    def _kept_by_followers(self, joint: Joint, ctrl: tuple[float, float], name: str) -> tuple[float, float]:
        """A leader's servo range narrowed to the positions that keep every follower inside its own range
        (MK828): commanded past them, the follower's limit and the coupling fight (validate's MK326).
        A follower no position keeps in range (the source's fault, MK326's hint) narrows nothing, nor
        does one kept at a single position."""
        if self._followers is None:
            self._followers = followers_by_leader(self.robot)
        narrowed, by = ctrl, []
        for follower in self._followers.get(joint.name, []):
            mimic, own = follower.mimic, (follower.limits.lower, follower.limits.upper)
            if mimic is None or not (math.isfinite(own[0]) and math.isfinite(own[1]) and own[0] <= own[1]):
                continue
            alone = leader_range_within(mimic.multiplier, mimic.offset, ctrl, own)
            kept = leader_range_within(mimic.multiplier, mimic.offset, narrowed, own)
            if alone is None or kept is None or kept[1] - kept[0] <= MIMIC_RANGE_SLACK:
                continue
            if alone[0] - ctrl[0] > MIMIC_RANGE_SLACK or ctrl[1] - alone[1] > MIMIC_RANGE_SLACK:
                by.append(follower.name)
            narrowed = kept
        if narrowed[0] - ctrl[0] > MIMIC_RANGE_SLACK or ctrl[1] - narrowed[1] > MIMIC_RANGE_SLACK:
            self.ctx.note(
                "MK828",
                f"actuator on joint {joint.name}: ctrlrange {fmt_vec(list(narrowed))}, not the joint's range "
                f"{fmt_vec(list(ctrl))}: its mimic follower(s) {', '.join(by)} leave their own ranges beyond "
                "it, where their limits would fight the coupling (the joint's range is kept)",
                joint.source,
                f"actuator[{name}]",
            )
            return narrowed
        return ctrl

    def _gains(self, el: Element, actuator: Actuator, joint: Joint, target: str) -> None:
        kp, kv = actuator.kp, actuator.kv
        if actuator.kind is ActuatorKind.POSITION:
            if kp is None:
                load = self.load(joint)
                kp, rule_kv = position_gains(load)
                kv = rule_kv if kv is None else kv
                self._made_up(actuator, joint, target, load, f"kp {fmt(kp)}, kv {fmt(kv)}",
                              natural_frequency_for(load))
            el.set("kp", fmt(kp))
            if kv:
                el.set("kv", fmt(kv))
        else:
            if kv is None:
                load = self.load(joint)
                kv = velocity_gain(load)
                self._made_up(actuator, joint, target, load, f"kv {fmt(kv)}", natural_frequency())
            el.set("kv", fmt(kv))

    @staticmethod
    def _whose(actuator: Actuator) -> str:
        """What the gains were missing from, as MK840 says it."""
        if actuator.source_kind == SERVOED:
            return "the source's effort interface"
        if actuator.source_kind == FILLED:
            return "the source, which names no actuator for this joint,"
        return f"the source{' ' + actuator.source_kind if actuator.source_kind else ''}"

    def _made_up(self, actuator: Actuator, joint: Joint, target: str, load: JointLoad, gains: str,
                 wn: float) -> None:
        unit = "kg" if joint.type is JointType.PRISMATIC else "kg·m²"
        hz = wn / (2.0 * math.pi)
        why = f"a {fmt(SERVO_BANDWIDTH_HZ)} Hz critically damped servo"
        if hz > SERVO_BANDWIDTH_HZ * (1.0 + 1e-9):
            force = "N" if joint.type is JointType.PRISMATIC else "N·m"
            in_leg = joint.name in self._leg_joints()
            share = " (with its leg's share of the robot's weight)" if in_leg else ""
            why = (f"a critically damped servo raised to {hz:.1f} Hz against the gravity load "
                   f"{load.gravity:.3g} {force}{share} at home (docs/convert.md)")
        self.ctx.note(
            "MK840",
            f"{actuator.kind.value} actuator on joint {joint.name}: {gains} from its reflected inertia "
            f"{fmt(load.inertia)} {unit} at home"
            + (f" (with {fmt(load.pushed)} {unit}, its share of the robot it pushes as a drive wheel)"
               if load.pushed else "")
            + f" and {why} ({self._whose(actuator)} gives no gains)",
            actuator.source or joint.source,
            f"actuator[{target}]",
        )

