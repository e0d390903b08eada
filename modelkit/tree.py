"""The kinematic-tree report, byte for byte the layout of urdfdom's ``check_urdf``.

::

    robot name is: NAME
    ---------- Successfully Parsed XML ---------------
    root Link: ROOT has N child(ren)
        child(1):  CHILD
            child(1):  GRANDCHILD

Children are ordered by joint name (byte order), as check_urdf's ``std::map`` of joints orders
them; ``order="document"`` keeps the order of the source file instead.

check_urdf prints a link once per path from the root: a link with several parents (MK220) is
printed under each of them, with its whole subtree. On a ladder-shaped model the report doubles
with every rung (30 rungs: about 400 GB, hours of output). Both renderers here stop with
:class:`TreeTooLarge` before the report passes ``max_lines`` lines (or JSON entries); below that,
the output is check_urdf's, byte for byte. Both walks are iterative, so no chain is too deep, and
both come as chunks (:func:`report_chunks`, :func:`json_chunks`) that the CLI streams: a 20,000-link
chain's report is 800 MB (check_urdf indents 4 spaces per level), never held in memory at once.

The JSON is ``json.dumps(data, indent=2)``'s layout, except that the indentation stops growing
after :data:`JSON_INDENT_LEVELS` levels (JSON ignores that whitespace): indenting every level of a
20,000-link chain would make 20 GB of spaces.
"""

from __future__ import annotations

import json
from collections.abc import Iterable, Iterator
from typing import Literal

from modelkit.model import Joint, Robot
from modelkit.rot3 import peek

Order = Literal["joint-name", "document"]

# At most this many lines in a report (one per link and path from the root): about 60 MB of text.
MAX_REPORT_LINES = 1_000_000
# The JSON indentation grows for this many nesting levels (two per tree level), then stays.
JSON_INDENT_LEVELS = 64
_BATCH = 4096  # lines (or JSON pieces) per streamed chunk
_BATCH_CHARS = 1 << 20  # and at most about this many characters (deep lines are long)


class TreeTooLarge(ValueError):
    """The report would be longer than ``limit`` lines (links printed once per path from the root)."""

    def __init__(self, limit: int, link: str) -> None:
        super().__init__(f"the tree report would pass {limit} lines")
        self.limit = limit
        self.link = link


def _children(robot: Robot, order: Order) -> dict[str, list[Joint]]:
    out = robot.children_of()
    if order == "joint-name":
        for joints in out.values():
            joints.sort(key=lambda j: j.name.encode("utf-8"))
    return out


def _walk(
    root: str, children: dict[str, list[Joint]], max_lines: int
) -> Iterator[tuple[int, int, Joint, bool]]:
    """Depth-first over the report's lines: (depth from 1, index among siblings from 1, joint, entered).

    A link already on the current path is yielded but not entered again (``entered`` False), so no
    model can loop forever; raises :class:`TreeTooLarge` before line ``max_lines + 1``.
    """
    stack: list[tuple[Iterator[tuple[int, Joint]], str]] = [
        (iter(enumerate(children.get(root, []), 1)), root)
    ]
    on_path = {root}
    count = 0
    while stack:
        joints, link = stack[-1]
        item = next(joints, None)
        if item is None:
            stack.pop()
            on_path.discard(link)
            continue
        index, joint = item
        count += 1
        if count > max_lines:
            raise TreeTooLarge(max_lines, joint.child)
        enter = joint.child not in on_path
        yield len(stack), index, joint, enter
        if enter:
            on_path.add(joint.child)
            stack.append((iter(enumerate(children.get(joint.child, []), 1)), joint.child))


def report_chunks(
    robot: Robot, order: Order = "joint-name", max_lines: int = MAX_REPORT_LINES
) -> Iterator[str]:
    """The check_urdf report of ``robot`` in chunks; raises :class:`TreeTooLarge` here, before any chunk."""
    root = robot.root or ""
    children = _children(robot, order)
    for _ in _walk(root, children, max_lines):  # count first: nothing is printed of a report refused
        pass
    head = [
        f"robot name is: {robot.name}",
        "---------- Successfully Parsed XML ---------------",
        f"root Link: {root} has {len(children.get(root, []))} child(ren)",
    ]
    lines = (
        f"{'    ' * depth}child({index}):  {joint.child}"
        for depth, index, joint, _ in _walk(root, children, max_lines)
    )
    return _batched(head, lines)


def _batched(head: list[str], lines: Iterable[str]) -> Iterator[str]:
    batch = list(head)
    size = 0
    for line in lines:
        batch.append(line)
        size += len(line)
        if len(batch) >= _BATCH or size >= _BATCH_CHARS:
            yield "\n".join(batch) + "\n"
            batch = []
            size = 0
    if batch:
        yield "\n".join(batch) + "\n"


def tree_report(robot: Robot, order: Order = "joint-name", max_lines: int = MAX_REPORT_LINES) -> str:
    """The check_urdf report of ``robot`` (a str ending with a newline)."""
    return "".join(report_chunks(robot, order, max_lines))


def json_chunks(
    robot: Robot, order: Order = "joint-name", max_lines: int = MAX_REPORT_LINES
) -> Iterator[str]:
    """The tree with joint types and origins, as JSON, in chunks; raises :class:`TreeTooLarge` here."""
    root = robot.root or ""
    children = _children(robot, order)
    for _ in _walk(root, children, max_lines):  # count first: no entry is built for a tree refused
        pass
    top: dict[str, object] = {"link": root, "children": []}
    path: list[list[object]] = [top["children"]]  # type: ignore[list-item]
    for depth, _, joint, enter in _walk(root, children, max_lines):
        del path[depth:]
        entry: dict[str, object] = {
            "joint": joint.name,
            "type": joint.type.value,
            "origin": {
                "xyz": [round(float(x), 12) for x in joint.origin.translation_tuple],
                "rotation": [[round(float(x), 12) for x in row] for row in joint.origin.rotation_tuple],
            },
            "axis": [round(float(x), 12) for x in peek(joint, "axis")],
            "link": joint.child,
        }
        path[-1].append(entry)
        if enter:
            kids: list[object] = []
            entry["children"] = kids
            path.append(kids)
    data = {
        "robot": robot.name,
        "root_joint": robot.root_joint.value if robot.root_joint else None,
        "tree": top,
    }
    return _json_pieces(data)


def tree_json(robot: Robot, order: Order = "joint-name", max_lines: int = MAX_REPORT_LINES) -> str:
    """The tree with joint types and origins, as JSON (a str ending with a newline)."""
    return "".join(json_chunks(robot, order, max_lines))


def dumps_indented(data: object) -> str:
    """``json.dumps(data, indent=2)`` without recursion (its pure-Python encoder recurses per level),
    the indentation capped at :data:`JSON_INDENT_LEVELS` levels; no trailing newline."""
    return "".join(_json_pieces(data))[:-1]


def _json_pieces(data: object) -> Iterator[str]:
    out: list[str] = []
    # Frames: the items still to write, the indent level of those items, the closing bracket.
    stack: list[tuple[Iterator[tuple[str | None, object]], int, str]] = []
    first: list[bool] = []

    def indent(level: int) -> str:
        return "  " * min(level, JSON_INDENT_LEVELS)

    def begin(value: object, level: int) -> None:
        if isinstance(value, dict) and value:
            out.append("{")
            stack.append((iter(value.items()), level + 1, "}"))
            first.append(True)
        elif isinstance(value, list) and value:
            out.append("[")
            stack.append((((None, v) for v in value), level + 1, "]"))
            first.append(True)
        else:
            out.append(json.dumps(value))

    begin(data, 0)
    while stack:
        if len(out) >= _BATCH:
            yield "".join(out)
            out.clear()
        items, level, closer = stack[-1]
        item = next(items, None)
        if item is None:
            stack.pop()
            first.pop()
            out.append("\n" + indent(level - 1) + closer)
            continue
        key, value = item
        out.append(("\n" if first[-1] else ",\n") + indent(level))
        first[-1] = False
        if key is not None:
            out.append(json.dumps(key) + ": ")
        begin(value, level)
    out.append("\n")
    yield "".join(out)
