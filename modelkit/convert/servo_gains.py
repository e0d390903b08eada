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
A joint in a leg of a legged robot also carries its share of the robot's weight through its foot
(:func:`modelkit.convert.legs.carried_loads`): that torque is added to ``τ_g``, and ``R`` is at least
the distance to the foot, so a leg's servos hold the robot standing at home as an arm's hold the arm;
and its kp is at least :data:`TIPPING_MARGIN` times the stiffness with which the robot's share above it
tips over it (an inverted pendulum: ``(M / n) g h``), so a biped's ankles hold it upright.
A drive wheel also carries its share of the robot it pushes, ``(M / n) r²`` about its axis
(:mod:`modelkit.convert.wheel_loads`), so a wheel's velocity servo tracks with the robot on it.
A subtree without mass gets ``MIN_INERTIA`` so that every gain is positive.

Every gain is then rounded up to :data:`GAIN_DIGITS` significant digits (:func:`rounded_up`): a made-up
number is written as a person would write it (``kp="156000"``, not ``"155503.604519839"``), and
rounding up keeps every lower bound above (the sag, the tipping margin, a wheel's share) while moving
the servo's frequency by at most 0.5 %.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from decimal import ROUND_CEILING, Decimal

import numpy as np

from modelkit.convert.legs import carried_loads
from modelkit.convert.wheel_loads import carried_inertias
from modelkit.model import Inertial, Joint, JointType, Link, Robot
from modelkit.spatial import Pose

SERVO_BANDWIDTH_HZ = 30.0
MAX_BANDWIDTH_HZ = 80.0  # the ceiling of a servo raised against gravity (ωn·dt = 1 at a 2 ms step)
SAG_PER_JOINT = 1e-4  # m: the largest move of a subtree's farthest point a servo's gravity sag may cause
DAMPING_RATIO = 1.0
MIN_INERTIA = 1e-6  # kg·m² or kg: the floor of a massless subtree's reflected inertia
TIPPING_MARGIN = 4.0  # a leg servo's kp over the tipping stiffness it holds (legs.carried_loads)
TIPPING_BANDWIDTH_HZ = 150.0  # its ceiling: ωn·dt = 1.9 at a 2 ms step, under the explicit limit of 2
GAIN_DIGITS = 3  # significant digits of a made-up gain (rounded up: rounded_up)
GRAVITY = np.array([0.0, 0.0, -9.81])  # m/s², in the root's frame


@dataclass(frozen=True)
class JointLoad:
    """What a servo on a joint carries at home: the reflected inertia (kg·m² or kg), the gravity torque
    or force about the joint (N·m or N), and the distance from the joint to the farthest COM it moves."""

    inertia: float
    gravity: float = 0.0
    reach: float = 0.0
    pushed: float = 0.0  # of ``inertia``: a drive wheel's share of the robot it pushes (wheel_loads)
    tipping: float = 0.0  # N·m/rad: a leg joint's share of the robot tipping over it (legs.carried_loads)


def with_written_masses(robot: Robot, lifted: frozenset[str], mass: float, inertia: float) -> Robot:
    """``robot`` with the mass a writer gives each massless link of ``lifted`` (``mass`` kg at the link
    origin, ``inertia`` kg·m² per axis: MK816), so that gains are made for the file's masses: a
    kinematic-only arm (rtb-data's ABB IRB 140) held its home 3.8 mm off under gains made for no mass.
    ``robot`` itself when nothing was lifted."""
    if not lifted:
        return robot
    links = []
    for link in robot.links:
        if link.name in lifted:
            before = link.inertial
            had = before is not None and before.mass > 0.0
            com = before.com if before is not None and had else (0.0, 0.0, 0.0)
            tensor = np.asarray(before.inertia, dtype=float) if before is not None else np.zeros((3, 3))
            total = (before.mass if before is not None and had else 0.0) + mass
            link = dataclasses.replace(link, inertial=Inertial(total, com, tensor + inertia * np.eye(3)))
        links.append(link)
    return dataclasses.replace(robot, links=links)


def home_position(joint: Joint) -> float:
    """The joint's initial position, clamped into its range when it has one (the MJCF ``home``)."""
    lower, upper, home = joint.limits.lower, joint.limits.upper, joint.initial_position
    if math.isfinite(lower) and math.isfinite(upper) and lower < upper:
        return min(max(home, lower), upper)
    return home


def natural_frequency() -> float:
    return 2.0 * math.pi * SERVO_BANDWIDTH_HZ


def joint_loads(robot: Robot) -> dict[str, JointLoad]:
    """Joint name → :class:`JointLoad` at home, hinges and slides (armature in the inertia).

    Linear in the number of links (a 10,000-link chain is written in seconds): each link's subtree is
    summed once, bottom up, as its mass ``M``, first moment ``S = Σ m c`` and second moment about the
    world origin ``J = Σ R I Rᵀ + m (|c|² 1 − c cᵀ)``; a joint at ``a`` then reads its subtree's
    inertia about ``a`` by the parallel-axis shift ``J − (2 a·S − M |a|²) 1 + S aᵀ + a Sᵀ − M a aᵀ``.
    The reach is the farthest corner of the box around the subtree's centres of mass (at most √3
    times the farthest centre itself)."""
    home = {j.name: home_position(j) for j in robot.joints}
    poses = robot.world_poses(home)
    sums = _subtree_sums(robot, poses)
    out: dict[str, JointLoad] = {}
    for joint in robot.joints:
        if joint.type not in (JointType.REVOLUTE, JointType.PRISMATIC) or joint.child not in poses:
            continue
        total = sums.get(joint.child)
        load = JointLoad(0.0) if total is None else _load_about(joint, poses[joint.child], total)
        out[joint.name] = JointLoad(load.inertia + joint.armature, load.gravity, load.reach)
    for name, (torque, lever, tipping) in carried_loads(robot, home).items():
        if name in out:
            own = out[name]
            out[name] = dataclasses.replace(own, gravity=own.gravity + torque, reach=max(own.reach, lever),
                                            tipping=tipping)
    for name, inertia in carried_inertias(robot).items():
        if name in out:
            own = out[name]
            out[name] = dataclasses.replace(own, inertia=own.inertia + inertia, pushed=inertia)
    return out


@dataclass
class _Sums:
    """A subtree's mass, first moment and second moment about the world origin, and the box around
    its centres of mass (empty: ``low`` > ``high``)."""

    mass: float = 0.0
    first: np.ndarray = field(default_factory=lambda: np.zeros(3))
    second: np.ndarray = field(default_factory=lambda: np.zeros((3, 3)))
    low: np.ndarray = field(default_factory=lambda: np.full(3, np.inf))
    high: np.ndarray = field(default_factory=lambda: np.full(3, -np.inf))

    def add(self, other: _Sums) -> None:
        self.mass += other.mass
        self.first += other.first
        self.second += other.second
        self.low = np.minimum(self.low, other.low)
        self.high = np.maximum(self.high, other.high)


def _own_sums(link: Link | None, pose: Pose | None) -> _Sums:
    sums = _Sums()
    if link is None or link.inertial is None or pose is None:
        return sums
    mass = float(link.inertial.mass)
    r = np.asarray(pose.rotation, dtype=float)
    com = r @ np.asarray(link.inertial.com, dtype=float) + np.asarray(pose.translation, dtype=float)
    inertia = r @ np.asarray(link.inertial.inertia, dtype=float) @ r.T
    sums.mass = mass
    sums.first = mass * com
    sums.second = inertia + mass * (float(com @ com) * np.eye(3) - np.outer(com, com))
    if mass > 0.0:
        sums.low, sums.high = com.copy(), com.copy()
    return sums


def _subtree_sums(robot: Robot, poses: dict[str, Pose]) -> dict[str, _Sums]:
    """Every link's :class:`_Sums` over its subtree, by one iterative post-order walk of the tree."""
    children = robot.children_of()
    links: dict[str, Link] = {}
    for link in robot.links:
        links.setdefault(link.name, link)
    sums: dict[str, _Sums] = {}
    for start in links:
        if start in sums:
            continue
        stack: list[tuple[str, bool]] = [(start, False)]
        while stack:
            name, done = stack.pop()
            if done:
                total = _own_sums(links.get(name), poses.get(name))
                for joint in children.get(name, []):
                    below = sums.get(joint.child)
                    if below is not None and joint.child != name:
                        total.add(below)
                sums[name] = total
                continue
            if name in sums:
                continue
            sums[name] = _Sums()  # a placeholder: a cycle back to here adds nothing
            stack.append((name, True))
            stack.extend((j.child, False) for j in children.get(name, []) if j.child not in sums)
    return sums


def _load_about(joint: Joint, frame: Pose, sums: _Sums) -> JointLoad:
    axis = np.asarray(frame.rotation, dtype=float) @ np.asarray(joint.axis, dtype=float)
    norm = float(np.linalg.norm(axis))
    if norm == 0.0:
        return JointLoad(0.0)
    axis /= norm
    anchor = np.asarray(frame.translation, dtype=float)
    if joint.type is JointType.PRISMATIC:  # a slide's sag is its own displacement
        return JointLoad(sums.mass, abs(float(axis @ (sums.mass * GRAVITY))), 1.0)
    shift = ((2.0 * float(anchor @ sums.first) - sums.mass * float(anchor @ anchor)) * np.eye(3)
             - np.outer(sums.first, anchor) - np.outer(anchor, sums.first)
             + sums.mass * np.outer(anchor, anchor))
    inertia = float(axis @ (sums.second - shift) @ axis)
    gravity = abs(float(axis @ np.cross(sums.first - sums.mass * anchor, GRAVITY)))
    reach = 0.0
    if np.all(sums.low <= sums.high):
        corners = np.maximum(np.abs(sums.low - anchor), np.abs(sums.high - anchor))
        reach = float(np.linalg.norm(corners))
    return JointLoad(max(inertia, 0.0), gravity, reach)


def natural_frequency_for(load: JointLoad) -> float:
    """The position servo's ωn: the stated bandwidth, raised (up to the ceiling) until the gravity sag
    moves the subtree's farthest COM at most :data:`SAG_PER_JOINT`."""
    i = max(load.inertia, MIN_INERTIA)
    wn = natural_frequency()
    if load.gravity > 0.0 and load.reach > 0.0:
        needed = math.sqrt(load.gravity * load.reach / SAG_PER_JOINT / i)
        wn = min(max(wn, needed), 2.0 * math.pi * MAX_BANDWIDTH_HZ)
    if load.tipping > 0.0:  # a leg's servo holds the robot up: kp at least TIPPING_MARGIN × its tipping
        needed = math.sqrt(TIPPING_MARGIN * load.tipping / i)
        wn = max(wn, min(needed, 2.0 * math.pi * TIPPING_BANDWIDTH_HZ))
    return wn


def rounded_up(value: float, digits: int = GAIN_DIGITS) -> float:
    """``value`` (positive, finite) rounded up to ``digits`` significant digits: 155503.6 → 156000,
    6.4603 → 6.47; a value that already has no more digits is itself. Others are returned as given."""
    if not (math.isfinite(value) and value > 0.0):
        return value
    exact = Decimal(repr(value))
    step = Decimal(1).scaleb(exact.adjusted() - digits + 1)
    return float(exact.quantize(step, rounding=ROUND_CEILING))


def position_gains(load: JointLoad) -> tuple[float, float]:
    """(kp, kv) of a critically damped position servo (module docstring), each rounded up to
    :data:`GAIN_DIGITS` significant digits."""
    i = max(load.inertia, MIN_INERTIA)
    wn = natural_frequency_for(load)
    return rounded_up(i * wn * wn), rounded_up(2.0 * DAMPING_RATIO * i * wn)


def velocity_gain(load: JointLoad) -> float:
    """kv of a velocity servo at the stated bandwidth, rounded up to :data:`GAIN_DIGITS` significant
    digits."""
    return rounded_up(max(load.inertia, MIN_INERTIA) * natural_frequency())
