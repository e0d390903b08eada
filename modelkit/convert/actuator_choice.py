"""The ``--actuators`` choice: which actuator a joint gets when the source names none.

One rule for every target that writes actuators (MJCF ``<actuator>``, SDF gz-sim joint controllers), so
that a robot converted to either holds the same pose under the same kinds of actuators.

``auto``: a position servo on a joint with a finite range, in a leg (:mod:`modelkit.convert.legs`: a
URDF's ``continuous`` knee) or on a welded base (an arm's ``continuous`` joints: Menagerie's Kinova Gen3
servos its four), so the written model holds its home pose as MuJoCo Menagerie's arms and legs do; on a
free base, a motor on any other joint without one (wheels, casters, endless spindles), whose zero control
leaves it free as the source has it. A mobile robot's joints without a range are its wheels and casters
(the lecture's smartcar has its wheels' masses off their axes: still motors), except those of an arm
(:func:`mobile_arm_joints`: off the ground, so no wheel or caster, and turned by gravity at home),
which get a servo as a welded arm's do: roboschool's Fetch has three continuous roll joints in its
arm; as motors, its forearm roll turned 0.161 rad in 2 s. Before, a welded arm's
unranged joints that gravity does not turn (example-robot-data's Kinova: joint 1, vertical, and joint 6)
were motors: free at zero control, joint 1 turned 0.0136 rad while joint 2 moved 0.5 rad.
"""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Callable, Mapping, Set

import numpy as np

from modelkit.convert.legs import is_wheel, off_ground_joints
from modelkit.convert.servo_gains import JointLoad
from modelkit.model import Actuator, ActuatorKind, Joint, JointType, Link, Robot

CHOICES = {"motor": ActuatorKind.EFFORT, "position": ActuatorKind.POSITION, "velocity": ActuatorKind.VELOCITY}
CHOSEN = "--actuators"  # an Actuator's source_kind when the --actuators choice put it there
SERVOED = "ROS effort interface, servoed"  # source_kind of a servo --source-actuators auto put there
FILLED = "unactuated, load-bearing"  # source_kind of a servo on a joint the source left without (MK827)
GRAVITY_FLOOR = 1e-9  # N·m or N: a gravity load at home below this is rounding (a vertical axis)
ARM_LOAD = 1e-6  # of the robot's weight times its size: a smaller gravity load turns no arm joint
STANDARD_GRAVITY = 9.81  # m/s²
ORDER = (ActuatorKind.POSITION, ActuatorKind.VELOCITY, ActuatorKind.EFFORT)  # notes list kinds in this order


def chosen_kind(joint: Joint, robot: Robot, choice: str, legs: Set[str],
                arms: Set[str] = frozenset()) -> ActuatorKind | None:
    """The ``choice`` kind for a joint the source does not actuate (None: no actuator); ``legs`` are the
    joints of the robot's legs (:func:`modelkit.convert.legs.leg_joints`), ``arms`` the unranged joints
    of a mobile robot's arms (:func:`mobile_arm_joints`)."""
    if joint.type not in (JointType.REVOLUTE, JointType.PRISMATIC):
        return None
    if choice == "auto":
        welded = robot.root_joint is JointType.FIXED  # an arm; a mobile robot's are wheels, casters
        held = ranged(joint) or joint.name in legs or welded or joint.name in arms
        return ActuatorKind.POSITION if held else ActuatorKind.EFFORT
    return CHOICES.get(choice)


def ranged(joint: Joint) -> bool:
    """Whether the joint has a finite range of more than one value."""
    lower, upper = joint.limits.lower, joint.limits.upper
    return math.isfinite(lower) and math.isfinite(upper) and lower < upper


def mobile_arm_joints(robot: Robot, load: Callable[[Joint], JointLoad]) -> frozenset[str]:
    """On a free base, the hinges and slides without a range that belong to an arm: off the ground
    (:func:`modelkit.convert.legs.off_ground_joints`: nothing below them reaches the floor, so no wheel
    or caster) and turned by gravity at home: a gravity ``load`` above the joint's Coulomb friction and
    above :data:`ARM_LOAD` of the robot's weight times its size (a massless sensor frame that a writer
    gives a milligram turns nothing: the tutorial's tilt joint, 6e-7 N·m, stays a motor). Those
    ``auto`` servos, as on a welded base; a pan joint about a vertical axis and a spindle with its mass
    on its axis stay motors. A link round about its roll axis is no wheel here: Fetch's forearm is a
    cylinder about its own. Empty on a welded base."""
    if robot.root_joint is not JointType.FLOATING:
        return frozenset()
    candidates = [joint for joint in robot.joints
                  if joint.type in (JointType.REVOLUTE, JointType.PRISMATIC) and not ranged(joint)]
    if not candidates:
        return frozenset()
    off_ground = off_ground_joints(robot)
    poses = robot.world_poses()
    corners = [np.asarray(pose.translation, dtype=float) for pose in poses.values()]
    size = float(np.linalg.norm(np.ptp(np.array(corners), axis=0))) if corners else 0.0
    masses = [link.inertial.mass for link in robot.links if link.inertial is not None]
    mass = sum(m for m in masses if math.isfinite(m) and m > 0.0)
    least = ARM_LOAD * mass * STANDARD_GRAVITY * size
    return frozenset(joint.name for joint in candidates if joint.name in off_ground
                     and load(joint).gravity > max(joint.friction, GRAVITY_FLOOR, least))


def chosen_actuators(robot: Robot, choice: str, legs: Set[str], skip: Set[str],
                     arms: Set[str] = frozenset()) -> list[Actuator]:
    """The ``choice`` actuator (:func:`chosen_kind`) of every joint not in ``skip`` that gets one."""
    out: list[Actuator] = []
    for joint in robot.joints:
        kind = None if joint.name in skip else chosen_kind(joint, robot, choice, legs, arms)
        if kind is not None:
            out.append(Actuator(joint=joint.name, kind=kind, source_kind=CHOSEN, source=joint.source))
    return out


def constrained_joints(robot: Robot) -> set[str]:
    """The joints that carry no actuator of their own: mimic followers (their leader's drives them) and
    locked joints (a range of one value)."""
    followers = {j.name for j in robot.joints if j.mimic is not None}
    return followers | {j.name for j in robot.joints if j.limits.lower == j.limits.upper}


def servoed_interfaces(robot: Robot, choice: str, source_actuators: str,
                       legs: Set[str], arms: Set[str] = frozenset()) -> dict[int, Actuator]:
    """``--source-actuators auto``: the source's ROS effort interfaces (URDF ``EffortJointInterface``
    transmissions, ros2_control ``effort`` command interfaces) on joints to which the ``--actuators``
    choice gives a servo, keyed by the id of the source's actuator they replace.

    A ROS effort interface says how a controller commands the joint (ros2_control's trajectory and
    position controllers close a PID over it), not that the joint is free at zero control; as motors
    the arm sags and the legs are limp until the user writes that controller. The servo keeps what the
    source says of the joint: the effort limit, or the interface's own ``min``/``max``, as its force
    range."""
    if source_actuators != "auto":
        return {}
    by_name: dict[str, Joint] = {}
    for each in robot.joints:
        by_name.setdefault(each.name, each)
    out: dict[int, Actuator] = {}
    constrained = constrained_joints(robot)  # a mimic follower or a locked joint carries no actuator
    for actuator in robot.actuators:
        joint = by_name.get(actuator.joint)
        if not actuator.ros_interface or actuator.kind is not ActuatorKind.EFFORT or joint is None \
                or joint.name in constrained:
            continue
        kind = chosen_kind(joint, robot, choice, legs, arms)
        if kind is None or kind is ActuatorKind.EFFORT:
            continue  # --actuators motor or none, a wheel, or not a hinge or slide: the source's motor
        force = actuator.force_range
        if force is None and actuator.ctrl_range is not None:
            low, high = actuator.ctrl_range
            force = (low * abs(actuator.gear), high * abs(actuator.gear))
        out[id(actuator)] = Actuator(joint=joint.name, kind=kind, force_range=force,
                                     source_kind=SERVOED, source=actuator.source)
    return out


def counted(counts: Mapping[ActuatorKind, int], label: Callable[[ActuatorKind], str]) -> str:
    """Actuators counted by kind for a note, in :data:`ORDER`: ``"3 <position> and 1 <motor>"``
    (``label`` names a kind as the target writes it)."""
    return " and ".join(f"{counts[kind]} {label(kind)}" for kind in ORDER if counts.get(kind))


def servoed_message(servoed: list[Actuator], choice: str, label: Callable[[ActuatorKind], str], motors: str,
                    at_zero: str, kept: str) -> str:
    """MK864's text: the source's ROS effort interfaces written as servos, in a target's words (``motors``
    what they are not written as, ``at_zero`` what such a motor does at zero command, ``kept`` what
    ``--source-actuators keep`` writes)."""
    names = [a.joint for a in servoed]
    shown = ", ".join(names[:4]) + (" ..." if len(names) > 4 else "")
    what = counted(Counter(a.kind for a in servoed), label)
    return (f"{len(servoed)} joint(s) ({shown}) whose source names ROS effort interfaces (URDF "
            f"transmissions, ros2_control) written as {what} (--actuators {choice}), not {motors}: a ROS "
            f"controller closes its own loop over an effort interface, and {at_zero} (--source-actuators "
            f"keep writes {kept})")


def load_bearing_unactuated(robot: Robot, taken: Set[str], choice: str, legs: Set[str],
                            sags: Callable[[Joint], bool], arms: Set[str] = frozenset()) -> list[Actuator]:
    """``--source-actuators auto``: the ``--actuators`` choice, where it gives a servo, on the joints
    that a source naming actuators for others leaves without one (not in ``taken``) and that carry the
    robot: a leg's joints, and the joints gravity turns at home (``sags``) on a welded base or, on a free
    base, off the ground (MK827). example-robot-data's ANYmal-Kinova names the arm's transmissions only:
    its twelve leg joints had no actuator and the robot folded onto the floor (451 mm in 2 s); its TIAGo
    names none for the 27 joints of its hand's coupled fingers, which drooped 0.1 rad in 2 s. Other
    unactuated joints (a free wheel, a passive suspension or linkage with the ground below it, a vertical
    axis) stay passive, as the source has them."""
    welded = robot.root_joint is JointType.FIXED
    off_ground = off_ground_joints(robot)
    constrained = constrained_joints(robot)
    out: list[Actuator] = []
    for joint in robot.joints:
        if joint.name in taken or joint.name in constrained or \
                joint.type not in (JointType.REVOLUTE, JointType.PRISMATIC):
            continue
        held = welded or joint.name in off_ground
        if joint.name not in legs and joint.name not in arms and not (held and sags(joint)):
            continue
        kind = chosen_kind(joint, robot, choice, legs, arms)
        if kind is ActuatorKind.POSITION or kind is ActuatorKind.VELOCITY:
            out.append(Actuator(joint=joint.name, kind=kind, source_kind=FILLED, source=joint.source))
    return out


def filled_message(filled: list[Actuator], legs: Set[str], choice: str, written_as: str, holds: str) -> str:
    """MK827's text: the servos :func:`load_bearing_unactuated` adds, in a target's words (``written_as``
    the element or system, ``holds`` what the robot then holds)."""
    names = [a.joint for a in filled]
    shown = ", ".join(names[:4]) + (" ..." if len(names) > 4 else "")
    in_legs = sum(1 for name in names if name in legs)
    what = f"{in_legs} in legs" if in_legs == len(names) else (
        f"{in_legs} in legs, {len(names) - in_legs} that gravity turns at home" if in_legs else
        "that gravity turns at home")
    return (f"{len(filled)} joint(s) ({shown}; {what}) that the source leaves without an actuator while it "
            f"names others get the --actuators choice ({choice}: {written_as}), so that the robot holds "
            f"{holds} (unactuated, they fold at zero control); --source-actuators keep leaves them without")


def sags_at_home(joint: Joint, load: JointLoad, links: dict[str, Link]) -> bool:
    """Whether gravity turns the joint at home: its gravity load there (``load``) exceeds its Coulomb
    friction (a wheel's, whose mass sits on its axis, and a vertical axis's are nil). A wheel never
    sags: its load is the robot's, which the floor carries."""
    if is_wheel(joint, links):
        return False
    return load.gravity > max(joint.friction, GRAVITY_FLOOR)
