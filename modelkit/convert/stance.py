"""A free robot that cannot stand at home on a floor (MK887).

Put on a plain floor at its home pose (the MJCF ``home`` keyframe, :mod:`modelkit.formats.mjcf.
write_home`; the spawn height of MK884), a robot stands only when its centre of mass lies over the
region its ground contacts span: the convex hull, seen from above, of the collision shapes it rests on
(a line for two wheels, a point for a ball). Off it by more than :data:`OUTSIDE`, the robot tips over in
any simulator before a controller can act. roboschool's Fetch has
no caster collision: its centre of mass lies 41 mm off its wheels' contact line, and in MuJoCo it
pitches 9° onto its chassis in the first half second.

The contacts are the links whose collision shapes come within :data:`GROUND_BAND` of the robot's
height of its lowest point (at least :data:`MIN_BAND`), as ``--base auto`` finds feet and wheels: a
foot at home a few millimetres above the other still stands. Each touches with its points within
:data:`CONTACT_BAND` of its own lowest (mesh vertices; box corners; a sphere's, capsule's or
ellipsoid's lowest point; a cylinder's and a cone's rims), seen from above: a wheel touches along a
line across its tread, not over the arc the band would take in. Judged on the model, for every target;
nothing is changed.
"""

from __future__ import annotations

import math

import numpy as np

from modelkit.convert.notes import NoteSink
from modelkit.convert.numbers import fmt
from modelkit.convert.servo_gains import home_position
from modelkit.geometry.extents import mesh_vertices
from modelkit.model import Box, Capsule, Cone, Cylinder, Ellipsoid, Geom, JointType, Mesh, Robot, Sphere
from modelkit.spatial import Pose

GROUND_BAND = 0.02  # of the robot's height: how far above its lowest point a shape still rests on the floor
MIN_BAND = 0.001  # m
CONTACT_BAND = 0.001  # m: a resting link touches the floor with its points this close to its own lowest
OUTSIDE = 0.005  # m: how far outside its support the centre of mass must lie to be said
RIM_POINTS = 24  # points on each rim of a cylinder (and on a cone's base)
_UP = np.array([0.0, 0.0, 1.0])


def note_tipping(robot: Robot, notes: NoteSink) -> None:
    """MK887 when a free robot (with a moving joint: not a prop) has its centre of mass at home more
    than :data:`OUTSIDE` from the support of its ground contacts (a region, or a line or a point: two
    wheels, a ball). Over a line or a point nothing is said: a robot balanced over its wheels' line
    stands until something pushes it."""
    if robot.root is None or robot.root_joint is not JointType.FLOATING:
        return
    if not any(joint.type.moves for joint in robot.joints):
        return  # a prop (pybullet_data's duck and teddy bear rock a degree or two on their curved bottoms)
    poses = robot.world_poses({joint.name: home_position(joint) for joint in robot.joints})
    clouds = _clouds(robot, poses)
    points, links = _resting(clouds)
    centre = _centre_of_mass(robot, poses)
    if points is None or centre is None:
        return
    hull = _hull(points)
    outside = _distance_outside(hull, centre)
    if outside <= OUTSIDE:  # over its support (a ball on its point, a robot over its feet)
        return
    away = f"{fmt(round(outside * 1000, 1))} mm"
    if len(hull) >= 3 and _area(hull) > OUTSIDE**2:
        what = f"its centre of mass at home lies {away} outside the region its ground contacts span"
    else:
        what = ("its ground contacts at home span only " + ("a line" if len(hull) == 2 else "a point")
                + f", {away} from below its centre of mass")
    shown = ", ".join(links[:4]) + (" ..." if len(links) > 4 else "")
    falls = "it tips over on a floor before a controller can act"
    if len(hull) == 2:
        caught = _caught(clouds, set(links), hull, centre)
        if caught is not None:
            angle, by = caught
            falls = (f"on a floor it pitches {fmt(round(math.degrees(angle), 1))}° about that line onto "
                     f"the collision shape of {by} before a controller can act")
    notes.note(
        "MK887",
        f"the robot cannot stand on its own: {what} (the collision shapes of {shown}, seen from above); "
        f"{falls}. A caster, a support or a foot the source lacks, or a home pose over the feet, is what "
        "it needs",
        robot.source,
        "model",
    )


def _clouds(robot: Robot, poses: dict[str, Pose]) -> list[tuple[str, np.ndarray]]:
    """Each collision shape's points that include its lowest ones, in the world, with its link."""
    clouds: list[tuple[str, np.ndarray]] = []
    for link in robot.links:
        pose = poses.get(link.name)
        if pose is None:
            continue
        rotation = np.asarray(pose.rotation, dtype=float)
        for geom in link.collisions:
            cloud = _points(geom, rotation.T @ -_UP)
            if cloud is not None and len(cloud):
                clouds.append((link.name, cloud @ rotation.T + np.asarray(pose.translation, dtype=float)))
    return clouds


def _resting(clouds: list[tuple[str, np.ndarray]]) -> tuple[np.ndarray | None, list[str]]:
    """The horizontal positions of the collision points within the ground band, and their links."""
    if not clouds:
        return None, []
    every = np.concatenate([cloud for _, cloud in clouds])
    floor, top = float(every[:, 2].min()), float(every[:, 2].max())
    band = max(GROUND_BAND * (top - floor), MIN_BAND)
    by_link: dict[str, list[np.ndarray]] = {}
    for name, cloud in clouds:
        by_link.setdefault(name, []).append(cloud)
    resting: list[np.ndarray] = []
    names: list[str] = []
    for name, parts in by_link.items():
        cloud = np.concatenate(parts)
        low = float(cloud[:, 2].min())
        if low <= floor + band:  # the link rests on the floor: its own lowest points touch it
            resting.append(cloud[cloud[:, 2] <= low + CONTACT_BAND, :2])
            names.append(name)
    return np.concatenate(resting), names


def _caught(clouds: list[tuple[str, np.ndarray]], resting: set[str], line: np.ndarray,
            centre: np.ndarray) -> tuple[float, str] | None:
    """When the robot rests on a line (two wheels) with its centre of mass to one side: the angle it
    turns about that line, towards its centre of mass, before another link's collision shape meets
    the floor, and that link (None when none lies on that side). A point at height h above the floor
    and s out from the line on that side meets it after atan2(h, s). The resting links turn about
    their own joints (wheels roll) and are left out. roboschool's Fetch: its chassis, 9.7 mm above the
    floor, catches it after a few degrees."""
    a, b = np.asarray(line[0], dtype=float), np.asarray(line[1], dtype=float)
    along = (b - a) / float(np.linalg.norm(b - a))
    offset = np.asarray(centre[:2], dtype=float) - a
    side = offset - float(offset @ along) * along
    if not float(np.linalg.norm(side)) > 0.0:
        return None
    side = side / float(np.linalg.norm(side))
    floor = min(float(cloud[:, 2].min()) for name, cloud in clouds if name in resting)
    best: tuple[float, str] | None = None
    for name, cloud in clouds:
        if name in resting:
            continue
        out = (cloud[:, :2] - a) @ side
        ahead = out > 0.0
        if not ahead.any():
            continue
        angles = np.arctan2(np.maximum(cloud[ahead, 2] - floor, 0.0), out[ahead])
        angle = float(angles.min())
        if best is None or angle < best[0]:
            best = (angle, name)
    return best


def _points(geom: Geom, down: np.ndarray) -> np.ndarray | None:
    """Points of the shape, in its link's frame, that include its lowest ones (``down``: the world's
    −Z in the link frame): a mesh's vertices, a box's corners, a cylinder's and a cone's rims, the
    lowest point of a sphere, capsule or ellipsoid (their support towards ``down``)."""
    g = geom.geometry
    rotation = np.asarray(geom.pose.rotation, dtype=float)
    offset = np.asarray(geom.pose.translation, dtype=float)
    d = rotation.T @ down  # in the shape's frame
    angles = np.linspace(0.0, 2.0 * math.pi, RIM_POINTS, endpoint=False)
    circle = np.stack([np.cos(angles), np.sin(angles), np.zeros_like(angles)], axis=1)
    local: np.ndarray | None
    if isinstance(g, Mesh):
        local = mesh_vertices(g)
    elif isinstance(g, Box):
        half = np.asarray(g.size, dtype=float) / 2.0
        local = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]) * half
    elif isinstance(g, Sphere):
        local = np.array([float(g.radius) * d])
    elif isinstance(g, Capsule):  # both ends' lowest points: the band keeps one, or both lying flat
        end = float(g.length) / 2.0
        local = np.array([[0.0, 0.0, -end], [0.0, 0.0, end]]) + float(g.radius) * d
    elif isinstance(g, Ellipsoid):
        radii = np.asarray(g.radii, dtype=float)
        scaled = float(np.linalg.norm(radii * d))
        local = np.array([radii**2 * d / scaled]) if scaled > 0.0 else None
    elif isinstance(g, Cylinder):
        end, radius = float(g.length) / 2.0, float(g.radius)
        local = np.concatenate([circle * radius + [0.0, 0.0, -end], circle * radius + [0.0, 0.0, end]])
    elif isinstance(g, Cone):
        local = np.concatenate([circle * float(g.radius) + [0.0, 0.0, -float(g.length) / 2.0],
                                [[0.0, 0.0, float(g.length) / 2.0]]])
    else:
        local = None
    if local is None or not len(local):
        return None
    return np.asarray(local, dtype=float) @ rotation.T + offset


def _centre_of_mass(robot: Robot, poses: dict[str, Pose]) -> np.ndarray | None:
    """The robot's centre of mass in the world (None without mass)."""
    mass, moment = 0.0, np.zeros(3)
    for link in robot.links:
        pose, inertial = poses.get(link.name), link.inertial
        if pose is None or inertial is None or not inertial.mass > 0.0 or not math.isfinite(inertial.mass):
            continue
        com = np.asarray(pose.rotation, dtype=float) @ np.asarray(inertial.com, dtype=float)
        moment += inertial.mass * (com + np.asarray(pose.translation, dtype=float))
        mass += inertial.mass
    return moment / mass if mass > 0.0 else None


def _hull(points: np.ndarray) -> np.ndarray:
    """The convex hull of 2-D points, counter-clockwise (Andrew's monotone chain); 1 or 2 points when
    they are all one point or on one line (to a micrometre)."""
    unique = np.unique(np.round(points, 6), axis=0)
    if len(unique) <= 2:
        return unique
    unique = _outer(unique)
    ordered = sorted(map(tuple, unique))

    def cross(o: tuple[float, ...], a: tuple[float, ...], b: tuple[float, ...]) -> float:
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    lower: list[tuple[float, ...]] = []
    for p in ordered:
        while len(lower) >= 2 and cross(lower[-2], lower[-1], p) <= 1e-12:
            lower.pop()
        lower.append(p)
    upper: list[tuple[float, ...]] = []
    for p in reversed(ordered):
        while len(upper) >= 2 and cross(upper[-2], upper[-1], p) <= 1e-12:
            upper.pop()
        upper.append(p)
    hull = lower[:-1] + upper[:-1]
    if len(hull) < 3:  # collinear: the two ends
        return np.array([ordered[0], ordered[-1]])
    return np.array(hull)


def _outer(points: np.ndarray) -> np.ndarray:
    """The points not strictly inside the octagon of the farthest points in eight directions (Akl and
    Toussaint's filter): the hull's corners are among them. The monotone chain is plain Python, and a
    flat-bottomed mesh puts every vertex of its sole on the floor."""
    angles = np.arange(8) * (math.pi / 4.0)
    reach = points @ np.stack([np.cos(angles), np.sin(angles)])
    corners = points[np.argmax(reach, axis=0)]  # counter-clockwise, as their directions turn
    keep = np.zeros(len(points), dtype=bool)
    for a, b in zip(corners, np.roll(corners, -1, axis=0), strict=True):
        if np.array_equal(a, b):
            continue
        keep |= (b[0] - a[0]) * (points[:, 1] - a[1]) - (b[1] - a[1]) * (points[:, 0] - a[0]) <= 0.0
    return points[keep] if keep.any() else points


def _area(hull: np.ndarray) -> float:
    x, y = hull[:, 0], hull[:, 1]
    return 0.5 * abs(float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))))


def _distance_outside(hull: np.ndarray, centre: np.ndarray) -> float:
    """How far the centre's horizontal position lies outside the hull (0 inside; for a segment or a
    point, its distance from it)."""
    c = np.asarray(centre[:2], dtype=float)
    if len(hull) == 1:
        return float(np.linalg.norm(c - hull[0]))
    if len(hull) == 2:
        return _to_segment(c, hull[0], hull[1])
    inside = all(
        (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]) >= 0.0
        for a, b in zip(hull, np.roll(hull, -1, axis=0), strict=True)
    )
    if inside:
        return 0.0
    return min(_to_segment(c, a, b) for a, b in zip(hull, np.roll(hull, -1, axis=0), strict=True))


def _to_segment(c: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
    ab = b - a
    length = float(ab @ ab)
    t = 0.0 if length == 0.0 else min(1.0, max(0.0, float((c - a) @ ab) / length))
    return float(np.linalg.norm(c - (a + t * ab)))
