"""Servo gains where the source gives none: a stated bandwidth on each joint's reflected inertia, raised
where gravity at home would make the servo sag.

The rule (docs/convert.md, "Actuators"): joint i's reflected inertia ``I_i`` is the diagonal entry of
the joint-space mass matrix at the home configuration (every joint at its initial position, clamped
into its range, the root welded), plus the joint's armature. For a hinge that is the inertia of the
whole subtree below the joint about the joint axis (``Σ aᵀ I_c a + m·d⊥²`` over its links); for a slide
the subtree's mass. Then, for a natural frequency ``ωn = 2π·SERVO_BANDWIDTH_HZ`` and damping ratio
``ζ = 1`` (critically damped):

* position servo: ``kp = I ωn²``, ``kv = 2 ζ √(kp I)``;
* velocity servo: ``kv = I ωn`` (a first-order loop with time constant 1/ωn).

Held against gravity a PD servo sags by ``τ_g / kp``, which moves the subtree's farthest point by
``τ_g · R / kp`` (``R`` its distance from the joint). Where that exceeds :data:`SAG_PER_JOINT`, kp is
raised to ``τ_g · R / SAG_PER_JOINT``: small arms with long light links (the SO-101: 1.4 mm off home
after 2 s at 30 Hz alone) hold as well as big ones. The raised servo's frequency stays at most
``2π·MAX_BANDWIDTH_HZ`` (``ωn·dt`` ≤ 1 at MuJoCo's 2 ms step; the explicit limit is 2). ``τ_g`` is
taken with gravity along the root's −Z (an arm standing upright on its base, as fixed bases are).
A subtree without mass gets ``MIN_INERTIA`` so that every gain is positive.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from modelkit.model import Joint, JointType, Link, Robot
from modelkit.spatial import Pose

SERVO_BANDWIDTH_HZ = 30.0
MAX_BANDWIDTH_HZ = 80.0  # the ceiling of a servo raised against gravity (ωn·dt = 1 at a 2 ms step)
SAG_PER_JOINT = 1e-4  # m: the largest move of a subtree's farthest point a servo's gravity sag may cause
DAMPING_RATIO = 1.0
MIN_INERTIA = 1e-6  # kg·m² or kg: the floor of a massless subtree's reflected inertia
GRAVITY = np.array([0.0, 0.0, -9.81])  # m/s², in the root's frame


@dataclass(frozen=True)
class JointLoad:
    """What a servo on a joint carries at home: the reflected inertia (kg·m² or kg), the gravity torque
    or force about the joint (N·m or N), and the distance from the joint to the farthest COM it moves."""

    inertia: float
    gravity: float = 0.0
    reach: float = 0.0


def home_position(joint: Joint) -> float:
    """The joint's initial position, clamped into its range when it has one (the MJCF ``home``)."""
    lower, upper, home = joint.limits.lower, joint.limits.upper, joint.initial_position
    if math.isfinite(lower) and math.isfinite(upper) and lower < upper:
        return min(max(home, lower), upper)
    return home


def natural_frequency() -> float:
    return 2.0 * math.pi * SERVO_BANDWIDTH_HZ


def joint_loads(robot: Robot) -> dict[str, JointLoad]:
    """Joint name → :class:`JointLoad` at home, hinges and slides (armature in the inertia)."""
    home = {j.name: home_position(j) for j in robot.joints}
    poses = robot.world_poses(home)
    children = robot.children_of()
    links: dict[str, Link] = {}
    for link in robot.links:
        links.setdefault(link.name, link)
    out: dict[str, JointLoad] = {}
    for joint in robot.joints:
        if joint.type not in (JointType.REVOLUTE, JointType.PRISMATIC) or joint.child not in poses:
            continue
        load = _subtree_load(links, joint, poses, children)
        out[joint.name] = JointLoad(load.inertia + joint.armature, load.gravity, load.reach)
    return out


def _subtree_load(
    links: dict[str, Link], joint: Joint, poses: dict[str, Pose], children: dict[str, list[Joint]]
) -> JointLoad:
    frame = poses[joint.child]
    rotation = np.asarray(frame.rotation, dtype=float)
    axis = rotation @ np.asarray(joint.axis, dtype=float)
    norm = float(np.linalg.norm(axis))
    if norm == 0.0:
        return JointLoad(0.0)
    axis /= norm
    anchor = np.asarray(frame.translation, dtype=float)
    inertia_sum, weight, reach = 0.0, np.zeros(3), 0.0
    stack, seen = [joint.child], set()
    while stack:
        name = stack.pop()
        if name in seen:
            continue
        seen.add(name)
        stack.extend(j.child for j in children.get(name, []))
        link = links.get(name)
        if link is None or link.inertial is None or name not in poses:
            continue
        mass = float(link.inertial.mass)
        pose = poses[name]
        r = np.asarray(pose.rotation, dtype=float)
        com = r @ np.asarray(link.inertial.com, dtype=float) + np.asarray(pose.translation, dtype=float)
        offset = com - anchor
        if joint.type is JointType.PRISMATIC:
            inertia_sum += mass
            weight += mass * GRAVITY
            continue
        if mass > 0.0:
            reach = max(reach, float(np.linalg.norm(offset)))
            weight += np.cross(offset, mass * GRAVITY)
        inertia = r @ np.asarray(link.inertial.inertia, dtype=float) @ r.T
        perpendicular = offset - float(offset @ axis) * axis
        inertia_sum += float(axis @ inertia @ axis) + mass * float(perpendicular @ perpendicular)
    gravity = abs(float(weight @ axis))
    if joint.type is JointType.PRISMATIC:
        reach = 1.0  # a slide's sag is its own displacement
    return JointLoad(inertia_sum, gravity, reach)


def natural_frequency_for(load: JointLoad) -> float:
    """The position servo's ωn: the stated bandwidth, raised (up to the ceiling) until the gravity sag
    moves the subtree's farthest COM at most :data:`SAG_PER_JOINT`."""
    i = max(load.inertia, MIN_INERTIA)
    wn = natural_frequency()
    if load.gravity > 0.0 and load.reach > 0.0:
        needed = math.sqrt(load.gravity * load.reach / SAG_PER_JOINT / i)
        wn = min(max(wn, needed), 2.0 * math.pi * MAX_BANDWIDTH_HZ)
    return wn


def position_gains(load: JointLoad) -> tuple[float, float]:
    """(kp, kv) of a critically damped position servo (module docstring)."""
    i = max(load.inertia, MIN_INERTIA)
    wn = natural_frequency_for(load)
    return i * wn * wn, 2.0 * DAMPING_RATIO * i * wn


def velocity_gain(load: JointLoad) -> float:
    """kv of a velocity servo at the stated bandwidth."""
    return max(load.inertia, MIN_INERTIA) * natural_frequency()
