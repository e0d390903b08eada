"""Rules for faults no loader finds: a file every reference accepts, whose shapes or inertia are wrong.

Each rule compares two things the file says about one link (its collision and its visual, its inertia and
its shapes) and warns only where they disagree by a wide margin; the thresholds are measured on real model
collections (docs/validate.md, "Plausibility warnings"). Shapes count through their bounding boxes
(:mod:`modelkit.checks.bounds`): a mesh counts when the reader has loaded it to check it; a mesh it did not
load (a plain OBJ, an unresolved file) leaves its link unjudged.
"""

from __future__ import annotations

import math
from collections.abc import Iterator

from modelkit import rot3
from modelkit.checks.bounds import Aabb, geom_box, shapes_box, union
from modelkit.checks.masses import body_mass_properties, welded_bodies
from modelkit.checks.registry import rule
from modelkit.diagnostics import Diagnostic, SourceLocation, diag
from modelkit.model import Capsule, Cone, Cylinder, Geom, Joint, Link, Mesh, Robot
from modelkit.spatial import Pose

# MK418: a collision is "far" from the visuals when the gap between their boxes exceeds this fraction of the
# larger of the two shapes' half-diagonals (boxes that touch or overlap have gap 0). At 0.5 a sound file
# fires: the Go1's hip collision, the thigh motor drawn by the thigh's mesh, is 0.53 of a size away.
FAR_FRACTION = 1.0
# MK419: one visual, one collision. Shapes of one axial kind (cylinder, capsule, cone) whose axes differ by
# more than AXIS_TOLERANCE_DEG; or boxes whose extent along some link axis differs by more than
# SIZE_FACTOR times and by more than SIZE_FRACTION of the larger shape's half-diagonal.
AXIS_TOLERANCE_DEG = 1.0
SIZE_FACTOR = 2.0
SIZE_FRACTION = 0.25
# MK419 leaves out a pair where one shape is this small beside the other: a placeholder (Baxter's 1 mm spheres
# for "no collision" beside a 17 cm visual), not a mistaken size.
PLACEHOLDER_FRACTION = 0.05
# MK316: the radius of gyration about the principal axis of largest moment, sqrt(I_max / m), may not exceed
# the largest distance from the centre of mass to the link's shapes (a mass inside the shapes cannot) by
# more than this factor.
GYRATION_FACTOR = 3.0
# MK316 does not judge a body whose shapes cannot hold its mass even at the density of osmium, the densest
# element (kg/m³), over their whole bounding box: such shapes are markers (Tiago's 1 mm spheres on 50 g finger
# links, Cassie's 1 cm box on a 0.27 kg link), not the body's extent.
DENSEST = 22_590.0

AXIAL = (Cylinder, Capsule, Cone)


def _fmt(v: rot3.V3) -> str:
    return " ".join(f"{x:.4g}" for x in v)


def _parent_joints(robot: Robot) -> dict[str, Joint]:
    out: dict[str, Joint] = {}
    for joint in robot.joints:
        out.setdefault(joint.child, joint)
    return out


def _judged(link: Link) -> bool:
    return not link.synthesised


def _repeats_joint_origin(offset: rot3.V3, joint: Joint | None, size: float) -> str:
    """A note when the collision's offset from the visual is the link's joint origin written a second time."""
    if joint is None:
        return ""
    origin = joint.origin.translation_tuple
    if rot3.norm(origin) == 0.0 or rot3.norm(rot3.sub(offset, origin)) > 0.1 * size:
        return ""
    return (f'; the offset repeats the origin of joint "{joint.name}" ({_fmt(origin)}), which already places '
            "the link frame")


@rule("collision-far-from-visual", "MK418")
def collision_far_from_visual(robot: Robot) -> Iterator[Diagnostic]:
    """A collision shape lies apart from the link's visual shapes (boxes apart by more than their size)."""
    parents = _parent_joints(robot)
    for link in robot.links:
        if not (_judged(link) and link.visuals and link.collisions):
            continue
        visuals = shapes_box(link.visuals)
        if visuals is None:
            continue
        for geom in link.collisions:
            box = geom_box(geom)
            if box is None:
                continue
            size = max(box.radius, visuals.radius)
            gap = box.gap(visuals)
            if size <= 0.0 or gap <= FAR_FRACTION * size:
                continue
            offset = rot3.sub(box.centre, visuals.centre)
            name = f' "{geom.name}"' if geom.name else ""
            yield diag(
                "MK418",
                f'link "{link.name}": collision{name} is {gap:.4g} m away from the link\'s visual shapes '
                f"(it is centred at {_fmt(box.centre)}, the visuals at {_fmt(visuals.centre)}; sizes "
                f"(half-diagonals) {box.radius:.4g} and {visuals.radius:.4g} m)"
                + _repeats_joint_origin(offset, parents.get(link.name), size),
                geom.source or link.loc("name"),
                hint="collisions and visuals are both placed in the link frame: give them the same origin",
            )


def _axis(geom: Geom) -> rot3.V3:
    r = geom.pose.rotation_tuple
    return (r[0][2], r[1][2], r[2][2])


def _kind(geom: Geom) -> str:
    return type(geom.geometry).__name__.lower()


def _shape_mismatch(visual: Geom, collision: Geom, vbox: Aabb, cbox: Aabb) -> str | None:
    """Why the collision is not the visual's shape, or None when they agree closely enough."""
    if type(visual.geometry) is type(collision.geometry) and isinstance(visual.geometry, AXIAL):
        va, ca = _axis(visual), _axis(collision)
        cosine = min(1.0, abs(rot3.dot(va, ca)) / (rot3.norm(va) * rot3.norm(ca)))
        angle = math.degrees(math.acos(cosine))
        if angle > AXIS_TOLERANCE_DEG:
            return (f"both are {_kind(visual)}s, but the collision's axis ({_fmt(ca)}) is {angle:.3g}° "
                    f"from the visual's ({_fmt(va)}) in the link frame")
        return None
    size = max(vbox.radius, cbox.radius)
    for i, axis in enumerate("xyz"):
        big, small = max(vbox.half[i], cbox.half[i]), min(vbox.half[i], cbox.half[i])
        if big > SIZE_FACTOR * small and big - small > SIZE_FRACTION * size:
            return (f"along the link's {axis} axis the {_kind(collision)} collision is "
                    f"{2 * cbox.half[i]:.4g} m long and the {_kind(visual)} visual {2 * vbox.half[i]:.4g} m "
                    "(a factor "
                    f"{big / small if small > 0 else math.inf:.3g})")
    return None


@rule("collision-shape-differs", "MK419")
def collision_shape_differs(robot: Robot) -> Iterator[Diagnostic]:
    """A link's one collision is not its one visual's shape: another axis, or sizes a large factor apart."""
    for link in robot.links:
        if not (_judged(link) and len(link.visuals) == 1 and len(link.collisions) == 1):
            continue
        visual, collision = link.visuals[0], link.collisions[0]
        if isinstance(visual.geometry, Mesh) or isinstance(collision.geometry, Mesh):
            continue  # a simpler collision around a mesh is the usual practice (a 10 cm box for a 5 cm laser)
        vbox, cbox = geom_box(visual), geom_box(collision)
        if vbox is None or cbox is None:
            continue
        if min(vbox.radius, cbox.radius) <= PLACEHOLDER_FRACTION * max(vbox.radius, cbox.radius):
            continue  # a dot standing for "no visual" or "no collision" (zero sizes are MK416/MK417)
        why = _shape_mismatch(visual, collision, vbox, cbox)
        if why is not None:
            yield diag(
                "MK419",
                f'link "{link.name}": the collision does not match the visual: {why}',
                collision.source or link.loc("name"),
                hint="a collision shape normally follows its visual; check its origin rpy and its size",
            )


def _shape_key(geom: Geom) -> tuple[object, ...]:
    """What makes two shapes the same, triangles in memory compared by content. Read from the stored
    values (:func:`_plain`): an array field's getter would import numpy, which validate does not."""
    g = geom.geometry
    if not isinstance(g, Mesh):
        return (type(g).__name__, *(_plain(value) for _, value in sorted(vars(g).items())))
    data = None if g.data is None else (g.data.vertices.tobytes(), g.data.faces.tobytes())
    return ("mesh", g.uri, g.path, g.fragment, _plain(rot3.peek(g, "scale")), g.generator, data)


def _plain(value: object) -> object:
    """A stored number, vector or matrix as nested tuples of floats (a numpy array by its ``tolist``)."""
    listed = value.tolist() if hasattr(value, "tolist") else value
    if isinstance(listed, (list, tuple)):
        return tuple(_plain(item) for item in listed)
    return float(listed) if isinstance(listed, (int, float)) else repr(listed)


@rule("collision-repeated", "MK411")
def collision_repeated(robot: Robot) -> Iterator[Diagnostic]:
    """A link's collision repeats another of the link exactly: the same geometry at the same pose."""
    for link in robot.links:
        seen: dict[tuple[object, ...], int] = {}
        for index, geom in enumerate(link.collisions):
            key = (_shape_key(geom), geom.pose.translation_tuple, geom.pose.rotation_tuple)
            first = seen.setdefault(key, index)
            if first != index:
                yield diag(
                    "MK411",
                    f'link "{link.name}": collision {index} repeats collision {first} (the same '
                    f"{_kind(geom)} at the same pose); engines make a contact for each, so the contact there "
                    "is stiffer than one shape's",
                    geom.source or link.loc("name"),
                    hint="give the shape once",
                )


@rule("inertia-implausible", "MK316")
def inertia_implausible(robot: Robot) -> Iterator[Diagnostic]:
    """A rigid body's radius of gyration is far larger than its shapes: no mass inside them has that inertia.

    A mass m inside a sphere of radius R about its centre of mass has every moment at most m·R², so
    sqrt(I_max / m) ≤ R; the rule allows a factor GYRATION_FACTOR for mass the shapes do not show. Links
    joined by fixed joints are judged as the one body engines merge them into: a placeholder inertia on a
    1 g sensor frame welded to a 10 kg trunk changes nothing.
    """
    if robot.masses_unknown:
        return
    links = {link.name: link for link in robot.links}
    for head, members in welded_bodies(robot).items():
        found = _implausible_body(links, members)
        if found is None:
            continue
        mass, moment, gyration, reach, where = found
        names = [name for name, _ in members if links.get(name) is not None and links[name].inertial]
        what = (f'link "{head}"' if len(names) <= 1 else f'the rigid body of link "{head}" (links '
                + ", ".join(f'"{n}"' for n in names) + " joined by fixed joints, merged as engines do)")
        yield diag(
            "MK316",
            f"{what}: mass {mass:g} kg with a largest principal moment of {moment:.4g} kg·m² has a radius "
            f"of gyration of {gyration:.4g} m, {gyration / reach:.3g} times the {reach:.4g} m from its "
            "centre of mass to the farthest point of its shapes (a mass inside its shapes cannot exceed 1 "
            "time)",
            where,
            hint=f"a solid of this size and mass has moments of order m·r²/3 ≈ {mass * reach**2 / 3:.3g} "
            "kg·m²",
        )


def _implausible_body(
    links: dict[str, Link], members: list[tuple[str, Pose]]
) -> tuple[float, float, float, float, SourceLocation | None] | None:
    """(mass, largest moment, radius of gyration, reach, where) of a body whose inertia is implausible."""
    geoms: list[Aabb] = []
    judged: list[Link] = []
    for name, pose in members:
        link = links.get(name)
        if link is None or link.synthesised:
            continue
        inertial = link.inertial
        if inertial is not None and (inertial.defaulted or not math.isfinite(inertial.mass)):
            return None  # defaults are MK304's, non-finite numbers MK302's
        if inertial is not None and not rot3.all_finite(rot3.peek(inertial, "inertia")):
            return None
        shapes = [*link.visuals, *link.collisions]
        if shapes:
            box = shapes_box(shapes, pose)
            if box is None:
                return None  # a mesh file: its extent is not known here
            geoms.append(box)
        if inertial is not None and inertial.mass > 0.0:
            judged.append(link)
    if not geoms or not judged:
        return None
    mass, com, tensor = body_mass_properties(links, members)
    if not mass > 0.0:
        return None
    box = union(geoms)
    if mass > DENSEST * 8.0 * box.half[0] * box.half[1] * box.half[2]:
        return None  # the shapes are markers: they cannot hold the mass
    moment = rot3.symmetric_eigenvalues(tensor)[2]
    reach = box.farthest(com)
    if not (moment > 0.0 and reach > 0.0):
        return None
    gyration = math.sqrt(moment / mass)
    if gyration <= GYRATION_FACTOR * reach:
        return None
    # Point at the inertia written largest: where the wrong number most likely is.
    culprit = max(judged, key=lambda link: _largest_moment(link))
    inertial = culprit.inertial
    where = inertial.sources.get("inertia", inertial.source) if inertial else None
    return mass, moment, gyration, reach, where or culprit.loc("name")


def _largest_moment(link: Link) -> float:
    inertial = link.inertial
    return rot3.symmetric_eigenvalues(rot3.mat3(rot3.peek(inertial, "inertia")))[2] if inertial else 0.0
