"""Fixed-joint lumping: the mass of each rigid body, as simulators merge links joined by fixed joints."""

from __future__ import annotations

from modelkit import rot3
from modelkit.model import WORLD_LINK, Joint, JointType, Link, Robot
from modelkit.spatial import Pose


def subtree(children: dict[str, list[Joint]], start: str) -> list[str]:
    """``start`` and every link below it, each once, in depth-first pre-order."""
    order: list[str] = []
    stack = [start]
    seen: set[str] = set()
    while stack:
        name = stack.pop()
        if name in seen:
            continue
        seen.add(name)
        order.append(name)
        stack.extend(j.child for j in children.get(name, []))
    return order


def lumped_masses(robot: Robot, lump_into_world: bool = True, every_joint: bool = False) -> dict[str, float]:
    """Each link's mass after fixed-joint lumping, for the links reachable from the root.

    A link's value is its own mass (a negative mass counts as 0) plus the lumped masses of the
    links attached below it by fixed joints, so the top link of a rigid body holds the body's total.
    With ``lump_into_world`` False, fixed joints from the world link lump nothing (libsdformat keeps
    what is welded to the world as separate bodies). With ``every_joint`` the sum goes through every
    joint: each link's value is then the mass of its whole subtree.
    """
    children = robot.children_of()
    own = {link.name: (link.inertial.mass if link.inertial is not None else 0.0) for link in robot.links}
    order = subtree(children, robot.root) if robot.root else []
    total: dict[str, float] = {}
    for name in reversed(order):
        mass = max(own.get(name, 0.0), 0.0)
        if lump_into_world or name != WORLD_LINK:
            for joint in children.get(name, []):
                if every_joint or joint.type is JointType.FIXED:
                    mass += total.get(joint.child, 0.0)
        total[name] = mass
    return total


def welded_bodies(robot: Robot) -> dict[str, list[tuple[str, Pose]]]:
    """The rigid bodies engines simulate: links joined by fixed joints, keyed by the body's top link (the
    root, or the child of a joint that moves), each member with its pose in the top link's frame."""
    children = robot.children_of()
    bodies: dict[str, list[tuple[str, Pose]]] = {}
    heads = [robot.root] if robot.root else []
    seen: set[str] = set()
    while heads:
        head = heads.pop()
        if head in seen:
            continue
        members: list[tuple[str, Pose]] = []
        stack = [(head, Pose())]
        while stack:
            name, pose = stack.pop()
            if name in seen:
                continue
            seen.add(name)
            members.append((name, pose))
            for joint in children.get(name, []):
                if joint.type is JointType.FIXED:
                    stack.append((joint.child, pose @ joint.origin))
                else:
                    heads.append(joint.child)
        bodies[head] = members
    return bodies


def body_mass_properties(
    links: dict[str, Link], members: list[tuple[str, Pose]]
) -> tuple[float, rot3.V3, rot3.M3]:
    """Mass, centre of mass and inertia about it of one welded body, in its top link's frame (numpy-free)."""
    if len(members) == 1:  # a link on its own: its inertial as written, no arithmetic to round
        link = links.get(members[0][0])
        inertial = link.inertial if link is not None else None
        pose = members[0][1]
        if inertial is None or inertial.mass <= 0.0:
            return 0.0, rot3.ZERO3, rot3.ZERO33
        if pose.rotation_tuple == rot3.IDENTITY and pose.translation_tuple == rot3.ZERO3:
            return (inertial.mass, rot3.vec3(rot3.peek(inertial, "com")),
                    rot3.mat3(rot3.peek(inertial, "inertia")))
    parts = []
    for name, pose in members:
        link = links.get(name)
        inertial = link.inertial if link is not None else None
        if inertial is None or inertial.mass <= 0.0:
            continue
        rotation = pose.rotation_tuple
        com = rot3.add(rot3.matvec(rotation, rot3.vec3(rot3.peek(inertial, "com"))), pose.translation_tuple)
        inertia = rot3.rotate_inertia(rot3.mat3(rot3.peek(inertial, "inertia")), rotation)
        parts.append((inertial.mass, com, inertia))
    return rot3.combine_mass_properties(parts)
