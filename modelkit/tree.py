"""The kinematic-tree report, byte for byte the layout of urdfdom's ``check_urdf``.

::

    robot name is: NAME
    ---------- Successfully Parsed XML ---------------
    root Link: ROOT has N child(ren)
        child(1):  CHILD
            child(1):  GRANDCHILD

Children are ordered by joint name (byte order), as check_urdf's ``std::map`` of joints orders
them; ``order="document"`` keeps the order of the source file instead.
"""

from __future__ import annotations

import json
from collections.abc import Iterator
from typing import Literal

from modelkit.model import Joint, Robot

Order = Literal["joint-name", "document"]


def _children(robot: Robot, order: Order) -> dict[str, list[Joint]]:
    out = robot.children_of()
    if order == "joint-name":
        for joints in out.values():
            joints.sort(key=lambda j: j.name.encode("utf-8"))
    return out


def tree_report(robot: Robot, order: Order = "joint-name") -> str:
    """The check_urdf report of ``robot`` (a str ending with a newline)."""
    root = robot.root or ""
    children = _children(robot, order)
    lines = [
        f"robot name is: {robot.name}",
        "---------- Successfully Parsed XML ---------------",
        f"root Link: {root} has {len(children.get(root, []))} child(ren)",
    ]
    # Iterative depth-first walk (a 10 000-link chain must not hit the recursion limit). A link
    # already on the current path is printed but not entered again, so no model can loop forever.
    Frame = tuple[Iterator[tuple[int, Joint]], int, str]
    stack: list[Frame] = [(iter(enumerate(children.get(root, []), 1)), 2, root)]
    on_path = {root}
    while stack:
        joints, level, link = stack[-1]
        item = next(joints, None)
        if item is None:
            stack.pop()
            on_path.discard(link)
            continue
        index, joint = item
        lines.append(f"{'  ' * level}child({index}):  {joint.child}")
        if joint.child not in on_path:
            on_path.add(joint.child)
            stack.append((iter(enumerate(children.get(joint.child, []), 1)), level + 2, joint.child))
    return "\n".join(lines) + "\n"


def tree_json(robot: Robot, order: Order = "joint-name") -> str:
    """The tree with joint types and origins, as JSON."""
    children = _children(robot, order)

    def node(name: str, path: frozenset[str]) -> dict[str, object]:
        kids = []
        for joint in children.get(name, []):
            entry: dict[str, object] = {
                "joint": joint.name,
                "type": joint.type.value,
                "origin": {
                    "xyz": [round(float(x), 12) for x in joint.origin.translation],
                    "rotation": [[round(float(x), 12) for x in row] for row in joint.origin.rotation],
                },
                "axis": [round(float(x), 12) for x in joint.axis],
            }
            if joint.child not in path:
                entry.update(node(joint.child, path | {joint.child}))
            else:
                entry["link"] = joint.child
            kids.append(entry)
        return {"link": name, "children": kids}

    root = robot.root or ""
    data = {
        "robot": robot.name,
        "root_joint": robot.root_joint.value if robot.root_joint else None,
        "tree": node(root, frozenset({root})),
    }
    return json.dumps(data, indent=2) + "\n"
