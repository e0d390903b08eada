"""Fixed-joint lumping: the mass of each rigid body, as simulators merge links joined by fixed joints."""

from __future__ import annotations

from modelkit.model import WORLD_LINK, Joint, JointType, Robot


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


def lumped_masses(robot: Robot, lump_into_world: bool = True) -> dict[str, float]:
    """Each link's mass after fixed-joint lumping, for the links reachable from the root.

    A link's value is its own mass (a negative mass counts as 0) plus the lumped masses of the
    links attached below it by fixed joints, so the top link of a rigid body holds the body's total.
    With ``lump_into_world`` False, fixed joints from the world link lump nothing (libsdformat keeps
    what is welded to the world as separate bodies).
    """
    children = robot.children_of()
    own = {link.name: (link.inertial.mass if link.inertial is not None else 0.0) for link in robot.links}
    order = subtree(children, robot.root) if robot.root else []
    total: dict[str, float] = {}
    for name in reversed(order):
        mass = max(own.get(name, 0.0), 0.0)
        if lump_into_world or name != WORLD_LINK:
            for joint in children.get(name, []):
                if joint.type is JointType.FIXED:
                    mass += total.get(joint.child, 0.0)
        total[name] = mass
    return total
