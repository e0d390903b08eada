"""Faults of a wheeled robot's source that stop it rolling in any simulator (MK885, MK886).

No loader refuses them, and every simulator shows them once the robot drives:

* **A wheel that is not round** (MK885). The joint turns without end about a horizontal axis, its
  link's collision shapes reach the ground and its visual is round about the axis (so it is drawn as
  a wheel), but the collision shapes' reach from the axis changes as the wheel turns.
  Hello Robot's Stretch (every version of ``hello-robot-stretch-urdf``) collides its drive wheels as a
  box of 101.6 mm around a round 50.8 mm visual: the reach runs from 50.8 to 71.8 mm, so the wheel
  lifts the robot 21 mm four times a turn (measured in MuJoCo: the base rose 21.2 mm while it drove).
  The reach is the collision shapes' support, taken every 5° across the axis through the joint, so
  an off-centre disc is caught too; more than :data:`OUT_OF_ROUND` of the largest reach is said
  (a box is 41 %, a hexagonal prism 13 %; an octagon, 7.6 %, and finer polygons are not). A link
  whose collision and visual are both not round is not taken for a wheel: pybullet_data's y-up
  Laikago lies with its lower legs, on joints without a range, on the ground.
* **A chassis on the ground** (MK886). The root link's own collision shapes, other than those that
  roll (a ball caster; a cylinder or capsule on its side, as the tutorial's caster), reach the level
  the wheels stand on: on a floor the chassis rests on it beside
  them and drags. Stretch's ``base_link_collision.STL`` reaches z = 0 exactly, with the wheels and the
  caster.

Both are judged at q = 0 on a free robot (the base decision, :mod:`modelkit.convert.base`), with the
source's shapes (before any wheel approximation), and said as warnings; nothing is changed.
"""

from __future__ import annotations

import math

import numpy as np

from modelkit.convert.notes import NoteSink
from modelkit.model import Capsule, Cylinder, Geom, JointType, Link, Robot, Sphere
from modelkit.spatial import Pose

OUT_OF_ROUND = 0.10
"""MK885: a wheel whose reach from its axis varies by more than this fraction of the largest reach."""
STEPS = 72  # directions across the axis (every 5°)
TILT = 0.05  # |world axis · z| below this: a horizontal axis (about 3°)


def note_rolling_faults(robot: Robot, notes: NoteSink) -> None:
    """MK885 for each wheel that is not round, MK886 for a chassis on the wheels' ground."""
    from modelkit.convert.wheels import GROUND_LEVEL, endless_axles, link_lows

    if robot.root is None or robot.root_joint is not JointType.FLOATING:
        return
    poses = robot.world_poses()
    lows = link_lows(robot, poses)
    if not lows:
        return
    floor = min(lows.values())
    links = {link.name: link for link in robot.links}
    wheels: list[str] = []
    for joint, link, _, axis in endless_axles(robot, poses, TILT):
        if link.name not in lows or lows[link.name] - floor > GROUND_LEVEL:
            continue  # off the ground
        collided = _reach(link.collisions, axis)
        drawn = _reach(link.visuals, axis)
        if not (_round(collided) or _round(drawn)):
            continue  # a leg on a joint without a range (pybullet_data's y-up Laikago), not a wheel
        wheels.append(link.name)
        if collided is None or _round(collided):
            continue
        low, high = collided
        radius = drawn[1] * 1000.0 if drawn is not None else 0.0
        notes.note(
            "MK885",
            f"wheel {link.name} (joint {joint.name}, turning without end on a horizontal axis, on the "
            f"ground, its visual round: radius {radius:.1f} mm) does not collide as a round shape: the "
            f"reach of its collision shapes from the axis runs from {low * 1000.0:.1f} to "
            f"{high * 1000.0:.1f} mm as it turns, so rolling lifts the robot {(high - low) * 1000.0:.1f} mm "
            "and drops it again, in every simulator; a collision shaped like the visual rolls",
            link.source or robot.source,
            f"link[{link.name}]/collision",
        )
    if wheels:
        _chassis(robot, links, poses, floor, wheels, notes)


def _reach(geoms: list[Geom], axis: np.ndarray) -> tuple[float, float] | None:
    """(least, largest) reach of the shapes from the axis line through the link's origin, over
    :data:`STEPS` directions across it; None without shapes or when one's extent is unknown."""
    from modelkit.geometry.extents import across, extent

    if not geoms:
        return None
    u, w = across(axis)
    reaches: list[float] = []
    for k in range(STEPS):
        angle = 2.0 * math.pi * k / STEPS
        found = extent(geoms, math.cos(angle) * u + math.sin(angle) * w)
        if found is None:
            return None
        reaches.append(found[1])
    return min(reaches), max(reaches)


def _round(reach: tuple[float, float] | None) -> bool:
    """The shapes' reach from the axis is the same all round, within :data:`OUT_OF_ROUND`."""
    return reach is not None and reach[1] > 0.0 and reach[1] - reach[0] <= OUT_OF_ROUND * reach[1]


def _rolls(geom: Geom, link_pose: Pose) -> bool:
    """A shape that rolls on a floor: a sphere (a ball caster), or a cylinder or capsule lying with its
    axis horizontal (the tutorial's caster, a 20 mm disc on its side)."""
    if isinstance(geom.geometry, Sphere):
        return True
    if not isinstance(geom.geometry, (Cylinder, Capsule)):
        return False
    along = link_pose.rotation @ geom.pose.rotation @ np.array([0.0, 0.0, 1.0])
    return abs(float(along[2])) <= TILT


def _chassis(robot: Robot, links: dict[str, Link], poses: dict[str, Pose], floor: float,
             wheels: list[str], notes: NoteSink) -> None:
    from modelkit.convert.wheels import GROUND_LEVEL
    from modelkit.geometry.extents import extent

    root = links.get(robot.root or "")
    pose = poses.get(robot.root or "")
    if root is None or pose is None:
        return
    flat = [g for g in root.collisions if not _rolls(g, pose)]  # a caster of the chassis rolls
    found = extent(flat, pose.rotation.T @ np.array([0.0, 0.0, 1.0])) if flat else None
    if found is None:
        return
    low = float(pose.translation[2]) + found[0]
    if low - floor > GROUND_LEVEL:
        return
    notes.note(
        "MK886",
        f"the chassis {root.name} reaches the ground its wheels ({', '.join(wheels)}) stand on: its "
        f"collision shapes' lowest point at q = 0 is {(low - floor) * 1000.0:.1f} mm above theirs, so on a "
        "floor it rests there beside them and drags as they turn, in every simulator",
        root.source or robot.source,
        f"link[{root.name}]/collision",
    )
