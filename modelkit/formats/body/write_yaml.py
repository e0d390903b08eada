"""YAML output for the `.body` writer: PyYAML's emitter, our number printing, a fixed layout.

Numbers are :class:`Num` values holding the text :func:`modelkit.convert.numbers.fmt` printed; the
dumper writes them as plain scalars. Strings that YAML would read as numbers, booleans or nulls are
quoted (Choreonoid keeps every scalar as a string, so quoting never changes a value). Short lists
of numbers are :class:`Flow` lists (``[ 0, 0, 0.1 ]`` style, on one line); mappings keep the order
the writer built them in; no anchors or aliases are written.

Angles: ``format_version: 2.0`` forbids ``angle_unit: radian`` (body-format.md §1.3, MK113), so the
writer keeps the default degree unit and converts every angle with :func:`deg`.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

import numpy as np
import yaml

from modelkit.convert.numbers import (
    ZERO,
    clean_angle,
    clean_inertia,
    clean_length,
    fmt,
    fmt_inertia,
    fmt_length,
)
from modelkit.spatial import Mat3

NUM_TAG = "tag:modelkit,2024:number"
_NUMBER_TEXT = re.compile(r"^-?(?:\d+(?:\.\d*)?|\.\d+)(?:e-?\d+)?$|^-?inf$")


@dataclass(frozen=True)
class Num:
    """A number as it is printed."""

    text: str


class Flow(list[Any]):
    """A list written in flow style on one line: ``[ 1, 2, 3 ]``."""


def num(value: float) -> Num:
    """A finite number through ``fmt``; infinities as ``inf`` (C strtod reads them)."""
    x = float(value)
    if math.isinf(x):
        return Num("inf" if x > 0 else "-inf")
    return Num(fmt(x))


def nums(values: Iterable[float] | np.ndarray, tidy: bool = False) -> Flow:
    """A flow list of numbers; ``tidy`` (a direction: an axis) sets each component within 1e-10
    (:data:`~modelkit.convert.numbers.ZERO`) of the vector's length to 0, as the other writers do
    (``1.84768450970784e-13, -1, 1.84768450970784e-13`` → ``0, -1, 0``)."""
    flat = np.asarray(list(values) if not isinstance(values, np.ndarray) else values, dtype=float).ravel()
    if tidy:
        length = float(np.linalg.norm(flat)) if np.all(np.isfinite(flat)) else 0.0
        flat = np.where(np.abs(flat) <= ZERO * length, 0.0, flat)
    return Flow(num(float(x)) for x in flat)


def lengths(values: Iterable[float] | np.ndarray) -> Flow:
    """A flow list of lengths in metres: dust below 1e-10 of the model's size set to 0
    (``clean_length``: a CAD export's ``3.08087e-14``), each written by ``fmt_length`` (a shorter
    decimal within 1e-12 of the model's size, where the rest is arithmetic dust)."""
    flat = np.asarray(list(values) if not isinstance(values, np.ndarray) else values, dtype=float).ravel()
    return Flow(Num(fmt_length(clean_length(float(x)))) if math.isfinite(x) else num(x) for x in flat)


def tensor(values: np.ndarray, mass: float) -> Flow:
    """The 9 entries of the inertia tensor of a link of ``mass``, cleaned by ``clean_inertia`` (a product
    of 1e-17 beside moments of 0.1 kg·m² is 0) and each written by ``fmt_inertia`` (dust relative to
    the tensor's largest entry)."""
    t = np.asarray(values, dtype=float)
    if np.all(np.isfinite(t)):
        t = clean_inertia(t, mass)
    return Flow(Num(fmt_inertia(float(x), t)) if math.isfinite(x) else num(x) for x in t.ravel())


def deg(radians: float) -> Num:
    return num(math.degrees(radians))


def axis_angle_of(rotation: Mat3) -> tuple[np.ndarray, float] | None:
    """The (unit axis, angle in radians, 0 ≤ angle ≤ π) of a rotation matrix; None for the identity.

    Through the quaternion (Shepperd's method), which is well conditioned at every angle.
    """
    r = np.asarray(rotation, dtype=float)
    trace = r[0, 0] + r[1, 1] + r[2, 2]
    if trace > 0.0:
        s = math.sqrt(trace + 1.0) * 2.0
        w, x, y, z = 0.25 * s, (r[2, 1] - r[1, 2]) / s, (r[0, 2] - r[2, 0]) / s, (r[1, 0] - r[0, 1]) / s
    elif r[0, 0] > r[1, 1] and r[0, 0] > r[2, 2]:
        s = math.sqrt(1.0 + r[0, 0] - r[1, 1] - r[2, 2]) * 2.0
        w, x, y, z = (r[2, 1] - r[1, 2]) / s, 0.25 * s, (r[0, 1] + r[1, 0]) / s, (r[0, 2] + r[2, 0]) / s
    elif r[1, 1] > r[2, 2]:
        s = math.sqrt(1.0 + r[1, 1] - r[0, 0] - r[2, 2]) * 2.0
        w, x, y, z = (r[0, 2] - r[2, 0]) / s, (r[0, 1] + r[1, 0]) / s, 0.25 * s, (r[1, 2] + r[2, 1]) / s
    else:
        s = math.sqrt(1.0 + r[2, 2] - r[0, 0] - r[1, 1]) * 2.0
        w, x, y, z = (r[1, 0] - r[0, 1]) / s, (r[0, 2] + r[2, 0]) / s, (r[1, 2] + r[2, 1]) / s, 0.25 * s
    if w < 0.0:
        w, x, y, z = -w, -x, -y, -z
    vector = np.array([x, y, z])
    norm = float(np.linalg.norm(vector))
    angle = 2.0 * math.atan2(norm, w)
    if norm == 0.0 or abs(angle) < 1e-15:
        return None
    return vector / norm, angle


def rotation_value(rotation: Mat3) -> Flow | None:
    """``rotation: [ x, y, z, degrees ]`` of a matrix; None for the identity (the key is omitted)."""
    found = axis_angle_of(rotation)
    if found is None:
        return None
    axis, angle = found
    value = nums(axis, tidy=True)
    value.append(deg(clean_angle(angle)))
    return value


def put_pose(node: dict[str, Any], rotation: Mat3, translation: np.ndarray) -> None:
    """``translation`` / ``rotation`` keys of a node, each omitted when it is the identity."""
    t = np.asarray([clean_length(float(x)) for x in np.asarray(translation, dtype=float).ravel()])
    if np.any(t != 0.0):
        node["translation"] = lengths(t)
    r = rotation_value(rotation)
    if r is not None:
        node["rotation"] = r


class _Dumper(yaml.SafeDumper):
    def ignore_aliases(self, data: Any) -> bool:
        return True

    def increase_indent(self, flow: bool = False, indentless: bool = False) -> None:
        super().increase_indent(flow, False)  # block lists indented under their key

    def write_indicator(self, indicator: str, need_whitespace: bool, whitespace: bool = False,
                        indention: bool = False) -> None:
        # Flow lists as Choreonoid's own files space them: [ a, b ].
        super().write_indicator(indicator, need_whitespace or indicator == "]", whitespace, indention)
        if indicator == "[":
            self.whitespace = False

    def resolve(self, kind: Any, value: Any, implicit: Any) -> Any:
        if kind is yaml.ScalarNode and implicit[0] and isinstance(value, str) and _NUMBER_TEXT.match(value):
            return NUM_TAG  # number text: a plain Num, a quoted string
        return super().resolve(kind, value, implicit)


def _represent_num(dumper: yaml.SafeDumper, data: Num) -> yaml.ScalarNode:
    return dumper.represent_scalar(NUM_TAG, data.text)


def _represent_flow(dumper: yaml.SafeDumper, data: Flow) -> yaml.SequenceNode:
    return dumper.represent_sequence("tag:yaml.org,2002:seq", list(data), flow_style=True)


_Dumper.add_representer(Num, _represent_num)
_Dumper.add_representer(Flow, _represent_flow)


def dump(document: dict[str, Any]) -> bytes:
    text = yaml.dump(
        document,
        Dumper=_Dumper,
        sort_keys=False,
        default_flow_style=False,
        allow_unicode=True,
        width=100,
        indent=2,
    )
    return text.encode("utf-8")
