"""Typing of `.body` scalars and vectors the way Choreonoid's ValueTree does it.

Every YAML scalar is a string; these helpers turn Y-nodes into floats, ints, booleans, vectors,
rotations and translations. Type and shape mistakes are the schema's to report
(:mod:`modelkit.formats.body.schema`); the helpers here return ``None`` for them and report only the
semantic faults the schema cannot see (a zero rotation axis, an empty vector).

Vectors are tuples and rotations tuples of three rows (:mod:`modelkit.rot3`): reading a `.body` file
imports no numpy. A node's transform is an :data:`Affine` ``(linear 3×3, translation)``.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterator
from contextlib import contextmanager
from contextvars import ContextVar

from modelkit import rot3
from modelkit.diagnostics import DiagnosticSink
from modelkit.yamltree import YMap, YNode, YNumbers, YScalar, YSeq

Affine = tuple[rot3.M3, rot3.V3]
"""A 3-D affine map ``p ↦ linear·p + translation`` (Choreonoid's Trans·Rot·Scale of a node)."""
IDENTITY_AFFINE: Affine = (rot3.IDENTITY, rot3.ZERO3)

# C strtod's syntax: decimal with optional exponent, hex floats, inf/infinity, nan.
_FLOAT_RE = re.compile(
    r"^\s*[+-]?(?:(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?|0[xX](?:[0-9a-fA-F]+\.?[0-9a-fA-F]*|\.[0-9a-fA-F]+)"
    r"(?:[pP][+-]?\d+)?|(?i:inf(?:inity)?|nan))\s*$"
)
# The leading number that C strtod consumes (Choreonoid's "to" accessors: list elements, mass,
# joint_id) when text follows it: "0.5m" -> 0.5, "0.t" -> 0.
_FLOAT_PREFIX_RE = re.compile(
    r"^\s*[+-]?(?:0[xX](?:[0-9a-fA-F]+\.?[0-9a-fA-F]*|\.[0-9a-fA-F]+)(?:[pP][+-]?\d+)?"
    r"|(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?|(?i:inf(?:inity)?|nan))"
)
_INT_RE = re.compile(r"^\s*[+-]?\d+\s*$")
TRUE_WORDS = frozenset("y Y yes Yes YES true True TRUE on On ON".split())
FALSE_WORDS = frozenset("n N no No NO false False FALSE off Off OFF".split())
UNLIMITED = "unlimited"


def parse_float(text: str) -> float | None:
    """A number as Choreonoid's "read" accessors accept it (the whole string, blanks allowed)."""
    if not _FLOAT_RE.match(text):
        return None
    s = text.strip()
    body = s.lstrip("+-")
    if body[:2] in ("0x", "0X"):
        value = float.fromhex(body)
        return -value if s.startswith("-") else value
    return float(s)


def parse_float_prefix(text: str) -> float | None:
    """The number a "to" accessor reads: the whole text if it is a number, else its leading number."""
    whole = parse_float(text)
    if whole is not None:
        return whole
    match = _FLOAT_PREFIX_RE.match(text)
    return None if match is None else parse_float(match.group(0))


def parse_int(text: str) -> int | None:
    return int(text.strip()) if _INT_RE.match(text) else None


def parse_bool(text: str) -> bool | None:
    if text in TRUE_WORDS:
        return True
    if text in FALSE_WORDS:
        return False
    return None


def scalar_text(node: YNode | None) -> str | None:
    return node.value if isinstance(node, YScalar) else None


def number(node: YNode | None) -> float | None:
    text = scalar_text(node)
    return None if text is None else parse_float(text)


# Scalars read by their leading number while text follows it ("0.001f"), gathered while a file is read so
# that the reader reports each once (MK181): Choreonoid reads the number and drops the rest, silently.
_TRAILING_TEXT: ContextVar[list[YScalar] | None] = ContextVar("body_trailing_text", default=None)


@contextmanager
def trailing_text_noted() -> Iterator[list[YScalar]]:
    """Gather the scalars :func:`number_prefix` reads by their leading number only, within the block."""
    noted: list[YScalar] = []
    token = _TRAILING_TEXT.set(noted)
    try:
        yield noted
    finally:
        _TRAILING_TEXT.reset(token)


def number_prefix(node: YNode | None) -> float | None:
    """A number as Choreonoid's "to" accessors read it: its leading number (trailing text is noted)."""
    text = scalar_text(node)
    if text is None:
        return None
    whole = parse_float(text)
    if whole is not None:
        return whole
    value = parse_float_prefix(text)
    noted = _TRAILING_TEXT.get()
    if value is not None and noted is not None and isinstance(node, YScalar):
        noted.append(node)
    return value


def leading_number_text(text: str) -> str | None:
    """The leading number of a text that is not a number as a whole (``"0.001f"`` → ``"0.001"``), or None."""
    if parse_float(text) is not None:
        return None
    match = _FLOAT_PREFIX_RE.match(text)
    return None if match is None else match.group(0).strip()


def integer(node: YNode | None) -> int | None:
    text = scalar_text(node)
    return None if text is None else parse_int(text)


def boolean(node: YNode | None) -> bool | None:
    text = scalar_text(node)
    return None if text is None else parse_bool(text)


def get_number(m: YMap, *keys: str, default: float | None = None) -> float | None:
    value = number(m.get(*keys))
    return default if value is None else value


def get_angle(m: YMap, angle_scale: float, *keys: str, default: float | None = None) -> float | None:
    value = number(m.get(*keys))
    return default if value is None else value * angle_scale


def get_bool(m: YMap, *keys: str, default: bool) -> bool:
    value = boolean(m.get(*keys))
    return default if value is None else value


def get_text(m: YMap, *keys: str) -> str | None:
    return scalar_text(m.get(*keys))


def numbers(node: YNode | None) -> list[float] | None:
    """A flat list of numbers, or None when it is not one."""
    if isinstance(node, YNumbers):  # a long list of plain decimals, read once by the YAML reader
        return node.values.tolist()
    if not isinstance(node, YSeq):
        return None
    out: list[float] = []
    for item in node.items:
        value = number_prefix(item)  # list elements are read with strtod's prefix rule
        if value is None:
            return None
        out.append(value)
    return out


def vector(node: YNode | None, size: int) -> tuple[float, ...] | None:
    """``size`` numbers as a tuple of floats, or None."""
    values = numbers(node)
    if values is None or len(values) != size:
        return None
    return tuple(float(x) for x in values)


def vector3(node: YNode | None) -> rot3.V3 | None:
    """Three numbers as a 3-vector, or None."""
    values = numbers(node)
    if values is None or len(values) != 3:
        return None
    return rot3.vec3(values)


def compose(a: Affine, b: Affine) -> Affine:
    """The affine map ``a ∘ b`` (b applied first)."""
    return rot3.matmul(a[0], b[0]), rot3.add(rot3.matvec(a[0], b[1]), a[1])


def translation(node: YNode | None, sink: DiagnosticSink) -> rot3.V3 | None:
    """``[x, y, z]`` or a list of such vectors (summed), as links and Transforms accept it."""
    if node is None:
        return None
    if isinstance(node, YSeq) and not node.items:
        sink.emit("MK309", "`translation: []` is empty (undefined behaviour in Choreonoid)", node.loc)
        return None
    if isinstance(node, YSeq) and node.items and all(isinstance(i, YSeq) for i in node.items):
        total = rot3.ZERO3
        for item in node.items:
            v = vector3(item)
            if v is None:
                return None
            total = rot3.add(total, v)
        return total
    return vector3(node)


def rotation(node: YNode | None, angle_scale: float, sink: DiagnosticSink) -> rot3.M3 | None:
    """``[ax, ay, az, angle]`` or a list of them composed left to right (R1·R2·…)."""
    if node is None:
        return None
    if isinstance(node, YSeq) and not node.items:
        sink.emit("MK309", "`rotation: []` is empty (undefined behaviour in Choreonoid)", node.loc)
        return None
    parts = node.items if isinstance(node, YSeq) and all(isinstance(i, YSeq) for i in node.items) else [node]
    result = rot3.IDENTITY
    for part in parts:
        aa = vector(part, 4)
        if aa is None:
            return None
        if not all(math.isfinite(x) for x in aa):  # 1e400 reads as infinity: no rotation from it
            sink.emit("MK100", "a rotation holds a number that is not finite", part.loc)
            return None
        axis = (aa[0], aa[1], aa[2])
        if rot3.norm(rot3.scale(0.5, axis)) < 0.5e-6:  # halved: |axis| of 1e308s overflows
            sink.emit("MK308", "rotation axis is the zero vector", part.loc)
            return None
        biggest = max(abs(x) for x in axis)
        axis = (axis[0] / biggest, axis[1] / biggest, axis[2] / biggest)  # a norm that cannot overflow
        result = rot3.matmul(result, rot3.axis_angle(axis, aa[3] * angle_scale))
    return result


def scale3(node: YNode | None, sink: DiagnosticSink) -> rot3.V3 | None:
    if node is None:
        return None
    if isinstance(node, YScalar):
        sink.emit(
            "MK413",
            f"a scalar `scale: {node.value}` is ignored by Choreonoid",
            node.loc,
            hint=f"write scale: [{node.value}, {node.value}, {node.value}]",
        )
        return None
    return vector3(node)


def finite_or_unlimited(node: YNode | None) -> float | None:
    """A number, +inf for ``unlimited`` or -inf for ``-unlimited`` (as Choreonoid reads range values)."""
    text = scalar_text(node)
    if text is None:
        return None
    if text.strip() == UNLIMITED:
        return math.inf
    if text.strip() == "-" + UNLIMITED:
        return -math.inf
    return parse_float(text)


def node_transform(m: YMap, angle_scale: float, sink: DiagnosticSink) -> Affine:
    """The affine Trans(p)·Rot(R)·Scale(s) of a node with translation/rotation/scale keys."""
    t = translation(m.get("translation"), sink)
    r = rotation(m.get("rotation"), angle_scale, sink)
    s = scale3(m.get("scale"), sink)
    linear = rot3.IDENTITY if r is None else r
    if s is not None:  # R·diag(s): column j scaled by s[j]
        linear = tuple((row[0] * s[0], row[1] * s[1], row[2] * s[2]) for row in linear)  # type: ignore[assignment]
    return linear, rot3.ZERO3 if t is None else t
