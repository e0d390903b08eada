"""The joints of a legged robot's legs, for the writers that must not take a leg joint for a wheel.

A URDF may declare a leg's joints ``continuous`` (pybullet_data's Laikago: all twelve; Aliengo: its
four thighs). ``--actuators auto`` gives a joint without a range a motor, as wheels, casters and
spindles want (zero control leaves them free); on a leg that motor lets the robot fold to the floor.

A leg here is a limb as :mod:`modelkit.convert.base` counts them for ``--base auto`` (a first moving
joint below the root's rigid body with two or more moving joints in a row below it, not pointing up at
q = 0), in a robot with four or more such limbs whose root floats (as settled for the output: a welded
test rig of 30 chains has no legs), that carries no wheel: no hinge in it without a range
whose child's shapes are round about its axis (a wheeled leg's wheel, a caster's wheel; a cart with
four casters has four limbs of two joints, and its swivels stay free). When four or more of those
limbs reach the ground at q = 0 (as ``--base auto`` finds feet), only they are legs: the Z1 arm folded
on a B1's back and the Kinova arm on an ANYmal carry none of the robot's weight. With fewer (a model
whose front legs point forward at q = 0, pybullet_data's Y-up Laikago) every such limb stays a leg.

:func:`resting_on` says what a legged robot rests on at its home pose: the links whose shapes reach
the lowest level (within 2 % of the robot's height, at least 1 mm, as ``--base auto`` judges it) that
hang from the root through fewer than two moving joints (the body, a hip): pybullet_data's Spirit40
at q = 0 has its legs folded flat beside its body, Vision60 its legs sideways. The MJCF writer says so
(MK856): its servos then hold a pose that lies on the floor.

:func:`carried_loads` is what each leg joint carries of the robot standing at home, for the servo gain
rule (:mod:`modelkit.convert.servo_gains`): the robot's weight shared equally by its legs, standing on
each leg's foot (the leg's lowest link frame at home), as a torque about the joint (a force along a
slide) with the distance from the joint to that foot as its lever.
"""

from __future__ import annotations

import math

import numpy as np

from modelkit.convert.base import (
    LIMBS,
    _below_root,
    _feet,
    _limbs,
    _raised,
    _round_about,
    touching_ground,
    vertical_spans,
)
from modelkit.convert.moving_paths import MovingPaths
from modelkit.model import Joint, JointType, Link, Robot
from modelkit.spatial import Pose

BIPED = 2  # limbs standing on the ground that make a free-base robot legged when it has fewer than LIMBS


def leg_joints(robot: Robot) -> frozenset[str]:
    """The names of the hinges and slides in the legs of a legged robot (empty for any other robot)."""
    return _joints_of(robot, leg_starts(robot))


def _joints_of(robot: Robot, firsts: list[str]) -> frozenset[str]:
    """The hinges and slides of the legs starting at ``firsts``, but a limb holding a wheel."""
    if not firsts:
        return frozenset()
    children = robot.children_of()
    by_name = {joint.name: joint for joint in robot.joints}
    links = {link.name: link for link in robot.links}
    out: set[str] = set()
    for first in firsts:
        below = _below(children, by_name[first])
        if any(is_wheel(joint, links) for joint in below):
            continue
        out.update(j.name for j in below if j.type in (JointType.REVOLUTE, JointType.PRISMATIC))
    return frozenset(out)


def leg_starts(robot: Robot) -> list[str]:
    """The first joints of a legged robot's legs (empty for any other robot), on a free base:

    * :data:`LIMBS` limbs or more from the root's body (the base decision's), those on the ground when
      that leaves :data:`LIMBS` (an arm folded on a quadruped's back is not a leg);
    * else :data:`BIPED` limbs from the root's body on the ground (a humanoid whose arms hang from a
      waist: Fourier's GR1T1);
    * else the feet ``--base auto`` finds below a waist (a humanoid rooted at its torso: Fourier's
      Qinglong), each leg starting at the first moving joint its foot shares with no other foot."""
    if robot.root_joint is not JointType.FLOATING:
        return []
    poses = robot.world_poses()
    limbs = _limbs(robot)
    raised = _raised(robot, poses, limbs)
    legs = [name for name in limbs if name not in raised]
    children = robot.children_of()
    by_name = {joint.name: joint for joint in robot.joints}
    grounded = _grounded(robot, poses, children, [by_name[first] for first in legs])
    if len(grounded) >= LIMBS:
        return grounded
    if len(legs) >= LIMBS:
        return legs
    if len(grounded) >= BIPED:
        return grounded
    return _legs_from_a_waist(robot, poses)


def _legs_from_a_waist(robot: Robot, poses: dict[str, Pose]) -> list[str]:
    """The legs' first joints below a waist, from the feet ``--base auto`` finds (:func:`base._feet`)."""
    lows = vertical_spans(robot, poses)
    if robot.root not in poses or not lows:
        return []
    paths = MovingPaths(robot)
    feet = _feet(paths, sorted(touching_ground(lows)), _below_root(robot, poses))
    if len(feet) < BIPED:
        return []
    firsts = []
    for foot in feet:
        shared = max(paths.shared(foot, other) for other in feet if other != foot)
        if shared < paths.length(foot):
            firsts.append(paths.at(foot, shared))
    return sorted(set(firsts))


def off_ground_joints(robot: Robot) -> frozenset[str]:
    """On a free base, the names of the joints with nothing below them that reaches the ground at q = 0
    (as ``--base auto`` finds feet and wheels): a mobile manipulator's arm, head and hands, which carry
    none of the robot's weight. A passive suspension, a caster and a leg have a link on the ground below
    them. Empty on a welded base (nothing of it stands on a floor)."""
    if robot.root_joint is not JointType.FLOATING:
        return frozenset()
    parent = {joint.child: joint.parent for joint in robot.joints}
    grounded: set[str] = set()  # links with a link on the ground at or below them
    for touching in touching_ground(vertical_spans(robot, robot.world_poses())):
        link: str | None = touching
        while link is not None and link not in grounded:  # each link is marked once: linear in the tree
            grounded.add(link)
            link = parent.get(link)
    return frozenset(joint.name for joint in robot.joints if joint.child not in grounded)


def _grounded(robot: Robot, poses: dict[str, Pose], children: dict[str, list[Joint]],
              firsts: list[Joint]) -> list[str]:
    """The limbs (by first joint) with a link that touches the ground at q = 0, as ``--base auto`` finds
    feet: within 2 % of the robot's height (at least 1 mm) of its lowest shape."""
    touching = touching_ground(vertical_spans(robot, poses))
    return [first.name for first in firsts if any(j.child in touching for j in _below(children, first))]


def _below(children: dict[str, list[Joint]], first: Joint) -> list[Joint]:
    """``first`` and every joint below it."""
    out: list[Joint] = [first]
    stack, seen = [first.child], {first.child}
    while stack:
        for joint in children.get(stack.pop(), []):
            out.append(joint)
            if joint.child not in seen:
                seen.add(joint.child)
                stack.append(joint.child)
    return out


def is_wheel(joint: Joint, links: dict[str, Link]) -> bool:
    """A hinge without a range whose child's collision shapes (its visuals without any) are round
    about its axis."""
    if joint.type is not JointType.REVOLUTE:
        return False
    lower, upper = joint.limits.lower, joint.limits.upper
    if math.isfinite(lower) and math.isfinite(upper) and lower < upper:
        return False
    link = links.get(joint.child)
    axis = np.asarray(joint.axis, dtype=float)
    norm = float(np.linalg.norm(axis))
    if link is None or norm == 0.0:
        return False
    geoms = link.collisions or link.visuals
    return any(_round_about(geom, axis / norm) for geom in geoms)


def carried_loads(robot: Robot, home: dict[str, float]) -> dict[str, tuple[float, float, float]]:
    """Leg joint name → (the torque, or force, that the robot's weight shared by its legs puts on it at
    ``home`` through the leg's foot; the distance from the joint to the foot; the tipping stiffness of
    that share about the joint, N·m/rad). Empty without legs.

    The tipping stiffness: a hinge that tilts by δ carries the robot's centre of mass, a height ``h``
    above it, sideways by ``h δ``, so gravity turns it further by ``(M / n) g h δ`` (an inverted
    pendulum on the leg's share ``M / n``), times ``1 − (a·z)²`` for an axis ``a`` off the horizontal
    (a yaw joint tips nothing). A servo softer than that lets the robot fall: Fourier's GR1T1 (53 kg,
    centre of mass 0.79 m above its ankles) needs 205 N·m/rad at each ankle and its ankles got 228 from
    the bandwidth rule alone; it tipped over backwards in 2 s."""
    starts = leg_starts(robot)
    legs = _joints_of(robot, starts)
    firsts = [name for name in starts if name in legs]  # not a wheel's limb
    if not firsts:
        return {}
    poses = robot.world_poses(home)
    children = robot.children_of()
    by_name = {joint.name: joint for joint in robot.joints}
    mass = robot.total_mass()
    share = np.array([0.0, 0.0, mass * 9.81 / len(firsts)])  # the floor's push on each foot
    height = _centre_of_mass_height(robot, poses)
    out: dict[str, tuple[float, float, float]] = {}
    for first in firsts:
        below = [j for j in _below(children, by_name[first]) if j.child in poses]
        if not below:
            continue
        lowest = min((poses[j.child] for j in below), key=lambda pose: float(pose.translation[2]))
        foot = np.asarray(lowest.translation, dtype=float)
        for joint in below:
            if joint.name not in legs:
                continue
            frame = poses[joint.child]
            axis = np.asarray(frame.rotation, dtype=float) @ np.asarray(joint.axis, dtype=float)
            norm = float(np.linalg.norm(axis))
            if norm == 0.0:
                continue
            axis /= norm
            lever = foot - np.asarray(frame.translation, dtype=float)
            if joint.type is JointType.PRISMATIC:
                out[joint.name] = (abs(float(axis @ share)), 1.0, 0.0)
            else:
                above = max(0.0, height - float(frame.translation[2]))
                tipping = float(share[2]) * above * (1.0 - float(axis[2]) ** 2)
                out[joint.name] = (abs(float(axis @ np.cross(lever, share))), float(np.linalg.norm(lever)),
                                   tipping)
    return out


def _centre_of_mass_height(robot: Robot, poses: dict[str, Pose]) -> float:
    """The height of the robot's centre of mass in the pose ``poses`` (0 without mass)."""
    mass = moment = 0.0
    for link in robot.links:
        inertial = link.inertial
        if inertial is None or inertial.mass <= 0.0 or link.name not in poses:
            continue
        pose = poses[link.name]
        com = np.asarray(pose.rotation, dtype=float) @ np.asarray(inertial.com, dtype=float)
        mass += float(inertial.mass)
        moment += float(inertial.mass) * float(com[2] + pose.translation[2])
    return moment / mass if mass > 0.0 else 0.0


def resting_on(robot: Robot, home: dict[str, float]) -> list[str]:
    """The links a legged robot at ``home`` (joint name → position) rests on other than its feet: those
    reaching the lowest level through fewer than two moving joints from the root (sorted; empty when
    it stands on its feet, or has no legs)."""
    if not leg_joints(robot):
        return []
    poses = robot.world_poses(home)
    paths = MovingPaths(robot)
    return sorted(name for name in touching_ground(vertical_spans(robot, poses)) if paths.length(name) < 2)
