"""Wheel collisions: which links are wheels, and the collision shape a target gets for them.

A **wheel** is the child link of a revolute joint (unlimited, not a mimic follower, not a track
roller ``convert.tracks`` wrote) that has a cylinder collision coaxial with the joint axis, a
collision mesh round about it (``geometry.extents.round_about``: the tutorial's
``mobile_robot_mesh.body``, Hello Robot's Stretch), or a sphere centred on it (the wheels of this
module's own URDF and MJCF outputs), the axis
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
* ``sphere``: a sphere of the wheel radius at the cylinder's (mesh's) centre;
* ``ellipsoid``: an ellipsoid of radii (r, r, half width) in the cylinder's frame (for a mesh, a
  frame whose z is the joint axis): round in the rolling plane, as thin as the wheel across it.

A mesh wheel's radius is half its mean reach across the axis and its width its reach along it; its
visual stays the mesh. MuJoCo and PyBullet collide with a mesh's convex hull, a polygonal cylinder
with the cylinder's edge contacts.

Every replaced shape gets an MK826 note; the wheels found are recorded in
``robot.extras["wheels"]`` (link → joint) for the writers' simulator options (MK825).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from modelkit.convert.choices import WHEEL_COLLISIONS
from modelkit.convert.notes import NoteSink
from modelkit.convert.registry import TARGETS
from modelkit.convert.tracks import roller_names
from modelkit.geometry.extents import ROUNDNESS, Round, across, extent, round_about
from modelkit.model import Cylinder, Ellipsoid, Geom, Joint, JointType, Link, Mesh, Robot, Sphere
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


@dataclass(frozen=True)
class Wheel:
    """A wheel found: its joint, which of its link's collisions rolls, and that shape's roundness
    about the joint axis (link frame)."""

    joint: str
    index: int  # the largest collision that rolls
    round: Round
    axis: np.ndarray  # unit, link frame
    rolling: tuple[tuple[int, Round], ...] = ()
    """Every collision of the link that rolls on the floor (index, its roundness), the largest
    included: each gets the wheel's collision shape (a tyre given twice, a twin tyre)."""


def endless_axles(robot: Robot, poses: dict[str, Pose], tilt: float
                  ) -> Iterator[tuple[Joint, Link, Pose, np.ndarray]]:
    """(joint, child link, its pose, unit axis in the link frame) of each joint that could carry a wheel:
    a revolute joint without a range, not a mimic follower, not a track roller ``convert.tracks``
    wrote, its axis within ``tilt`` (|axis · z|) of horizontal at ``poses``. The wheel rules here and
    :mod:`modelkit.convert.rolling` judge the shapes on them."""
    rollers = roller_names(robot, "roller_links")
    links = {link.name: link for link in robot.links}
    z = np.array([0.0, 0.0, 1.0])
    for joint in robot.joints:
        link = links.get(joint.child)
        pose = poses.get(joint.child)
        if (joint.type is not JointType.REVOLUTE or not joint.limits.endless or joint.mimic is not None
                or link is None or pose is None or link.name in rollers):
            continue
        norm = float(np.linalg.norm(np.asarray(joint.axis, dtype=float)))
        if norm == 0.0:
            continue
        axis = np.asarray(joint.axis, dtype=float) / norm
        if abs(float((pose.rotation @ axis) @ z)) <= tilt:
            yield joint, link, pose, axis


def find_wheels(robot: Robot) -> dict[str, Wheel]:
    """Wheel link → its :class:`Wheel`."""
    if robot.root is None or robot.root_joint is JointType.FIXED:
        return {}
    poses = robot.world_poses()
    floor = _lowest(robot, poses)
    if floor is None:
        return {}
    z = np.array([0.0, 0.0, 1.0])
    out: dict[str, Wheel] = {}
    for joint, link, pose, axis in endless_axles(robot, poses, HORIZONTAL):
        best: Wheel | None = None
        rolling: list[tuple[int, Round]] = []
        for i, geom in enumerate(link.collisions):
            shape = round_about(geom, axis, PARALLEL)
            if shape is None or shape.radius <= 0.0:
                continue
            off_axis = shape.centre - float(shape.centre @ axis) * axis
            if not isinstance(geom.geometry, Cylinder) and float(np.linalg.norm(off_axis)) > max(
                    ON_AXIS, ROUNDNESS * shape.radius):
                continue  # a sphere or mesh wheel turns about its centre
            reach = extent([geom], pose.rotation.T @ z)
            if reach is None or abs(float(pose.translation[2]) + reach[0] - floor) > GROUND_LEVEL:
                continue
            rolling.append((i, shape))
            if best is None or shape.radius > best.round.radius:
                best = Wheel(joint.name, i, shape, axis)
        if best is not None:
            out[link.name] = dataclasses.replace(best, rolling=tuple(rolling))
    return out


def wheel_proxy(geom: Geom, wheel: Wheel, shape: str, roundness: Round | None = None) -> tuple[Geom, str]:
    """The ``shape`` ("sphere" or "ellipsoid") written for a wheel's collision cylinder or round mesh
    ``geom`` (``roundness``: that collision's, one of ``wheel.rolling``; the largest's by default), and
    its words."""
    shaped = wheel.round if roundness is None else roundness
    radius, centre = shaped.radius, shaped.centre
    if shape == "sphere":
        new = Geom(Sphere(radius), Pose(translation=np.array(centre, dtype=float)),
                   name=geom.name, material=geom.material, source=geom.source)
        where = "the cylinder's centre" if isinstance(geom.geometry, Cylinder) else "the mesh's centre"
        return new, f"a sphere of radius {radius:g} m at {where}"
    radii = (radius, radius, 0.5 * shaped.width)
    if isinstance(geom.geometry, Cylinder):
        frame, words = geom.pose, "the cylinder's frame"
    else:  # the ellipsoid's z along the wheel's axis, at the mesh's centre
        u, w = across(wheel.axis)
        frame = Pose(np.column_stack([u, w, wheel.axis]), np.array(centre, dtype=float))
        words = "a frame whose z is the wheel's axis, at the mesh's centre"
    new = Geom(Ellipsoid(radii), frame, name=geom.name, material=geom.material, source=geom.source)
    return new, f"an ellipsoid of radii ({radii[0]:g}, {radii[1]:g}, {radii[2]:g}) m in {words}"


def approximate_wheels(robot: Robot, choice: str, target: str, notes: NoteSink) -> None:
    """Find the wheels, record them, and give each the wheel collision ``choice`` means for ``target``
    (in place; an MK826 note per replaced shape)."""
    wheels = find_wheels(robot)
    if not wheels:
        return
    robot.extras[WHEELS_KEY] = {link: wheel.joint for link, wheel in sorted(wheels.items())}
    shape = resolve(choice, target)
    if shape == "cylinder":
        return
    links = {link.name: link for link in robot.links}
    for name, wheel, index, roundness in rolling_shapes(wheels):
        link = links[name]
        geom = link.collisions[index]
        g = geom.geometry
        if isinstance(g, Cylinder):
            was = f"its collision cylinder (radius {g.radius:g} m, width {g.length:g} m)"
        elif isinstance(g, Mesh):
            was = (f"its collision mesh {mesh_name(g)} (round about the joint axis: radius "
                   f"{roundness.radius:.6g} m, width {roundness.width:.6g} m)")
        else:  # already a sphere: nothing to replace
            continue
        if len(wheel.rolling) > 1:
            was = f"{was}, collision {index} of the {len(wheel.rolling)} that roll on the floor,"
        link.collisions[index], what = wheel_proxy(geom, wheel, shape, roundness)
        notes.note(
            "MK826",
            f"wheel {name} (joint {wheel.joint}): {was} "
            f"is written as {what} (--wheel-collision {choice}"
            + (f", {shape} for this target" if choice == "auto" else "")
            + "): MuJoCo and PyBullet give a cylinder or a mesh's convex hull rolling on a plane different "
            "contacts, a sphere touches the floor at one point under the hub in both; --wheel-collision "
            "cylinder keeps the source's shape",
            geom.source or link.source,
            f"link[{name}]/collision[{index}]",
        )


def rolling_shapes(wheels: dict[str, Wheel]) -> Iterator[tuple[str, Wheel, int, Round]]:
    """(link, wheel, collision index, roundness) of every collision that rolls, wheels by name."""
    for name, wheel in sorted(wheels.items()):
        for index, roundness in wheel.rolling or ((wheel.index, wheel.round),):
            yield name, wheel, index, roundness


def mesh_name(mesh: Mesh) -> str:
    """The mesh's file name (with its fragment), or "(inline)" for a mesh held only in memory."""
    if not mesh.path:
        return "(inline)"
    name = Path(mesh.path).name
    return f"{name}#{mesh.fragment}" if mesh.fragment else name
