"""Numbers a ``.body`` file spells as infinity or not-a-number, refused where they stand (MK100).

Choreonoid reads numbers with C's ``strtod``, which takes ``nan``, ``inf`` and ``1e400`` (infinity)
as numbers, so the schema lets them through as numbers; a mass, pose, axis or size made of them is
no model at all. A joint limit may be infinite (it reads as ``unlimited``), never not-a-number.
YAML's own ``.nan``/``.inf`` are not numbers to ``strtod``: the schema reports those. Text values
(names, parents, types, file names) are not numbers and are left alone.
"""

from __future__ import annotations

import math
from collections.abc import Iterator

from modelkit.diagnostics import Diagnostic, diag
from modelkit.formats.body.values import parse_float
from modelkit.yamltree import YMap, YNode, YNumbers, YScalar, YSeq

# Keys whose values are words, never numbers (a link may be called "nan").
_TEXT_KEYS = frozenset(
    "name parent type jointType joint_type jointName joint_name uri file url format root_link rootLink "
    "link link1 link2 joint material texture sensor title description id".split()
)

# Limits where infinity means what ``unlimited`` means (Choreonoid's strtod reads it so): allowed there.
_LIMIT_KEYS = frozenset(
    "joint_range jointRange max_joint_velocity maxJointVelocity joint_velocity_range jointVelocityRange "
    "max_joint_effort maxJointEffort".split()
)


def non_finite(root: YNode) -> list[Diagnostic]:
    """One MK100 per number that reads as infinity or not-a-number, in document order."""
    return list(_walk(root))


def _walk(root: YNode) -> Iterator[Diagnostic]:
    seen: set[int] = set()
    stack: list[tuple[YNode, str]] = [(root, "")]
    found: list[Diagnostic] = []
    while stack:
        node, key = stack.pop()
        if id(node) in seen:  # an alias is judged where its anchor stands
            continue
        seen.add(id(node))
        if isinstance(node, YScalar):
            value = parse_float(node.value)
            if value is not None and _refused(value, key):
                found.append(_error(key, node.value, node))
        elif isinstance(node, YNumbers):
            for index, value in enumerate(node.values):
                if _refused(value, key):
                    item = node.items[index]
                    found.append(_error(key, item.value if isinstance(item, YScalar) else "", item))
        elif isinstance(node, YSeq):
            stack.extend((item, key) for item in reversed(node.items))
        elif isinstance(node, YMap):
            stack.extend((value, name) for name, (_, value) in reversed(node.entries.items()))
    yield from sorted(found, key=lambda d: (d.location.line, d.location.col) if d.location else (0, 0))


def _refused(value: float, key: str) -> bool:
    if math.isfinite(value) or key in _TEXT_KEYS:
        return False
    return math.isnan(value) or key not in _LIMIT_KEYS


def _error(key: str, text: str, node: YNode) -> Diagnostic:
    where = f'"{key}"' if key else "a value"
    return diag("MK100", f"{where}: {text.strip()!r} is not a finite number (infinity or not-a-number)",
                node.loc, hint="give a finite number")
