"""Wheel collisions: which links are wheels, and the collision shape a target gets for them.

A **wheel** is the child link of a revolute joint (unlimited, not a mimic follower, not a track
roller ``convert.tracks`` wrote) that has a cylinder collision coaxial with the joint axis (or a
sphere centred on it: the wheels of this module's own URDF and MJCF outputs), the axis
horizontal at q = 0 (perpendicular to the root's Z), and the cylinder's lowest point on the lowest
level of the robot's collision shapes (within :data:`GROUND_LEVEL` of it). A tilt head, a roller of a
track or a wheel of a robot welded to the world (fixed root) is not a wheel.

Why the shape matters (measured, docs/convert.md): MuJoCo and PyBullet give a cylinder lying on a
plane different meanings. MuJoCo's cylinder–plane collision makes contacts on both rim edges, so a
yawing wheel scrubs; PyBullet's implicit cylinder makes one contact at whichever rim edge its
support mapping picks, so the first acceleration yaws the robot. Dropped on a default floor and
driven by the tutorial's controller, the tutorial's pan-tilt robot with cylinder wheels spun 0.06 rad
(MuJoCo) and 0.0 rad (PyBullet) of the commanded 5 rad. A sphere of the wheel radius at the wheel
centre touches a flat floor at one point under the hub in both engines; it differs from the cylinder
only when the wheel meets something sideways. ``--wheel-collision``:

* ``auto`` (default): a sphere for MJCF and URDF (the formats MuJoCo and PyBullet load), the
  cylinder kept for SDF and ``.body`` (Gazebo's and Choreonoid's cylinder contacts roll);
* ``cylinder``: the source's cylinder, every target;
* ``sphere``: a sphere of the wheel radius at the cylinder's centre;
* ``ellipsoid``: an ellipsoid of radii (r, r, half width) in the cylinder's frame (round in the
  rolling plane, as thin as the wheel across it).

Every replaced shape gets an MK826 note; the wheels found are recorded in
``robot.extras["wheels"]`` (link → joint) for the writers' simulator options (MK825).
"""

from __future__ import annotations

import numpy as np

from modelkit.convert.choices import WHEEL_COLLISIONS
from modelkit.convert.notes import NoteSink
from modelkit.convert.registry import TARGETS
from modelkit.model import Cylinder, Ellipsoid, Geom, JointType, Robot, Sphere
from modelkit.spatial import Pose

WHEELS_KEY = "wheels"
"""``Robot.extras`` key: wheel link → its joint, for the writers."""
GROUND_LEVEL = 1e-3
"""m: a wheel's lowest point lies within this of the robot's lowest collision point."""
HORIZONTAL = 1e-6
"""|axis · z| below this: a joint axis is horizontal."""
PARALLEL = 1e-6
ON_AXIS = 1e-6
"""m: a sphere wheel's centre lies within this of the joint axis."""
SPHERE_TARGETS = frozenset(t.name for t in TARGETS if t.auto_wheel == "sphere")
"""Targets whose ``auto`` wheel collision is a sphere (the formats MuJoCo and PyBullet load), as each
format declares it (``auto_wheel`` in its ``declare.py``)."""


def resolve(choice: str, target: str) -> str:
    """The wheel collision ``choice`` means for ``target`` (``auto`` resolved)."""
    if choice not in WHEEL_COLLISIONS:
        raise ValueError(f"wheel collision must be one of {', '.join(WHEEL_COLLISIONS)}, not {choice!r}")
    if choice != "auto":
        return choice
    return "sphere" if target in SPHERE_TARGETS else "cylinder"


def link_lows(robot: Robot, poses: dict[str, Pose]) -> dict[str, float]:
    """Link → the lowest world z of its collision shapes at ``poses`` (links without any left out)."""
    from modelkit.convert.tracks import extent

    lows: dict[str, float] = {}
    for link in robot.links:
        pose = poses.get(link.name)
        if pose is None or not link.collisions:
            continue
        found = extent(link.collisions, pose.rotation.T @ np.array([0.0, 0.0, 1.0]))
        if found is not None:
            lows[link.name] = float(pose.translation[2]) + found[0]
    return lows


def _lowest(robot: Robot, poses: dict[str, Pose]) -> float | None:
    """The lowest world z of the robot's collision shapes at q = 0 (None without any)."""
    lows = link_lows(robot, poses)
    return min(lows.values()) if lows else None


def find_wheels(robot: Robot) -> dict[str, tuple[str, int]]:
    """Wheel link → (its joint, the index of its wheel cylinder among the link's collisions)."""
    if robot.root is None or robot.root_joint is JointType.FIXED:
        return {}
    poses = robot.world_poses()
    floor = _lowest(robot, poses)
    if floor is None:
        return {}
    rollers: set[str] = set()
    tracks = robot.extras.get("tracks")
    if isinstance(tracks, dict):
        for record in tracks.values():
            if isinstance(record, dict):
                rollers.update(record.get("roller_links", []))
    links = {link.name: link for link in robot.links}
    z = np.array([0.0, 0.0, 1.0])
    out: dict[str, tuple[str, int]] = {}
    for joint in robot.joints:
        link = links.get(joint.child)
        pose = poses.get(joint.child)
        if (joint.type is not JointType.REVOLUTE or joint.limits.position_limited or joint.mimic is not None
                or link is None or pose is None or link.name in rollers):
            continue
        axis = np.asarray(joint.axis, dtype=float)
        if float(np.linalg.norm(axis)) == 0.0:
            continue
        axis = axis / float(np.linalg.norm(axis))
        if abs(float((pose.rotation @ axis) @ z)) > HORIZONTAL:
            continue
        best: tuple[float, int] | None = None
        for i, geom in enumerate(link.collisions):
            g = geom.geometry
            if not isinstance(g, Cylinder | Sphere) or g.radius <= 0.0:
                continue
            if isinstance(g, Cylinder):
                along = geom.pose.rotation @ z
                if abs(1.0 - abs(float(along @ axis))) > PARALLEL:
                    continue
            else:  # a sphere wheel (our own URDF and MJCF outputs): its centre on the axis
                centre_local = np.asarray(geom.pose.translation, dtype=float)
                off_axis = centre_local - float(centre_local @ axis) * axis
                if float(np.linalg.norm(off_axis)) > ON_AXIS:
                    continue
            centre = pose.rotation @ geom.pose.translation + pose.translation
            bottom = float(centre[2]) - g.radius
            if abs(bottom - floor) > GROUND_LEVEL:
                continue
            if best is None or g.radius > best[0]:
                best = (g.radius, i)
        if best is not None:
            out[link.name] = (joint.name, best[1])
    return out


def wheel_proxy(geom: Geom, cylinder: Cylinder, shape: str) -> tuple[Geom, str]:
    """The ``shape`` ("sphere" or "ellipsoid") written for a wheel's collision cylinder, and its words."""
    if shape == "sphere":
        new = Geom(Sphere(cylinder.radius), Pose(translation=geom.pose.translation.copy()),
                   name=geom.name, material=geom.material, source=geom.source)
        return new, f"a sphere of radius {cylinder.radius:g} m at the cylinder's centre"
    radii = (cylinder.radius, cylinder.radius, 0.5 * cylinder.length)
    new = Geom(Ellipsoid(radii), geom.pose, name=geom.name, material=geom.material, source=geom.source)
    return new, f"an ellipsoid of radii ({radii[0]:g}, {radii[1]:g}, {radii[2]:g}) m in the cylinder's frame"


def approximate_wheels(robot: Robot, choice: str, target: str, notes: NoteSink) -> None:
    """Find the wheels, record them, and give each the wheel collision ``choice`` means for ``target``
    (in place; an MK826 note per replaced shape)."""
    wheels = find_wheels(robot)
    if not wheels:
        return
    robot.extras[WHEELS_KEY] = {link: joint for link, (joint, _) in sorted(wheels.items())}
    shape = resolve(choice, target)
    if shape == "cylinder":
        return
    links = {link.name: link for link in robot.links}
    for name, (joint, index) in sorted(wheels.items()):
        link = links[name]
        geom = link.collisions[index]
        g = geom.geometry
        if not isinstance(g, Cylinder):  # already a sphere: nothing to replace
            continue
        link.collisions[index], what = wheel_proxy(geom, g, shape)
        notes.note(
            "MK826",
            f"wheel {name} (joint {joint}): its collision cylinder (radius {g.radius:g} m, width "
            f"{g.length:g} m) "
            f"is written as {what} (--wheel-collision {choice}"
            + (f", {shape} for this target" if choice == "auto" else "")
            + "): MuJoCo and PyBullet give a cylinder rolling on a plane different contacts, a sphere "
            "touches the floor at one point under the hub in both; --wheel-collision cylinder keeps it",
            geom.source or link.source,
            f"link[{name}]/collision[{index}]",
        )
