"""Typed values of SDFormat text: numbers, vectors, booleans, colours and poses, with diagnostics.

A :class:`Values` is bound to one document (an included file has its own) so that every fault is
reported at its exact line and column. Invalid text is reported once (MK121) and the caller gets
``None`` (or the SDF default it asked for), never an exception.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

from lxml.etree import _Element as Element

from modelkit import rot3
from modelkit.diagnostics import DiagnosticSink, SourceLocation
from modelkit.spatial import Pose
from modelkit.xmlsource import XmlDocument, parse_number

_INF = re.compile(r"[+-]?inf(inity)?", re.IGNORECASE)
TRUE_WORDS = frozenset({"true", "1"})
FALSE_WORDS = frozenset({"false", "0"})
POSE_COUNTS = {"euler_rpy": 6, "quat_xyzw": 7}


def _finite(value: float | None) -> float | None:
    return value if value is not None and math.isfinite(value) else None


def local_name(element: Element) -> str:
    """The tag of an element without a namespace ("" for comments and processing instructions)."""
    tag = element.tag
    if not isinstance(tag, str):
        return ""
    return tag.rsplit("}", 1)[-1]


def is_custom(element: Element) -> bool:
    """A namespaced element (``<gz:...>``, ``<ignition:...>``): legal custom content in SDF."""
    tag = element.tag
    return isinstance(tag, str) and tag.startswith("{")


def children(element: Element, name: str) -> list[Element]:
    return [c for c in element if isinstance(c.tag, str) and c.tag == name]


def child(element: Element, name: str) -> Element | None:
    for c in element:
        if isinstance(c.tag, str) and c.tag == name:
            return c
    return None


@dataclass
class Values:
    """Value parsing for one document; faults go to ``sink`` at the document's positions."""

    doc: XmlDocument
    sink: DiagnosticSink

    def loc(self, element: Element, attribute: str | None = None) -> SourceLocation:
        return self.doc.loc(element, attribute)

    def text_loc(self, element: Element) -> SourceLocation:
        return self.doc.text_loc(element)

    def invalid(self, element: Element, message: str, hint: str | None = None) -> None:
        self.sink.emit("MK121", message, self.text_loc(element), hint=hint)

    @staticmethod
    def text(element: Element | None) -> str | None:
        if element is None:
            return None
        return (element.text or "").strip()

    def number(
        self, element: Element | None, default: float | None = None, allow_inf: bool = False
    ) -> float | None:
        """The number written in ``element`` (``default`` when absent or empty; reported when invalid).

        An empty value is libsdformat's default; where its description requires a value, the element
        check (:func:`modelkit.formats.sdf.spec.check_elements`) reports it, for every value kind.
        """
        if element is None:
            return default
        text = (element.text or "").strip()
        if not text:
            return default
        value = parse_number(text)
        if value is None and allow_inf and _INF.fullmatch(text):
            value = -math.inf if text.startswith("-") else math.inf
        elif value is not None and not allow_inf and not math.isfinite(value):
            value = None  # 1e400
        if value is None:
            self.invalid(element, f'<{element.tag}> must be a number, not "{text}"')
            return default
        return value

    def child_number(
        self, parent: Element | None, name: str, default: float | None = None, allow_inf: bool = False
    ) -> float | None:
        return self.number(None if parent is None else child(parent, name), default, allow_inf)

    def vector(
        self, element: Element | None, count: int, what: str | None = None
    ) -> tuple[float, ...] | None:
        """``count`` blank-separated numbers, or None (reported) when the text is not that."""
        if element is None:
            return None
        text = (element.text or "").strip()
        if not text:
            return None  # libsdformat's default; the element check reports it where a value is required
        items = text.split()
        values = [_finite(parse_number(t)) for t in items]
        if len(items) != count or any(v is None for v in values):
            shown = what or f"<{element.tag}>"
            self.invalid(element, f'{shown} must be {count} numbers, not "{text}"')
            return None
        return tuple(float(v) for v in values if v is not None)

    def boolean(self, element: Element | None, default: bool = False) -> bool:
        if element is None:
            return default
        text = (element.text or "").strip().lower()
        if not text:
            return default  # libsdformat's default; the element check reports it where a value is required
        if text in TRUE_WORDS:
            return True
        if text in FALSE_WORDS:
            return False
        self.invalid(element, f'<{element.tag}> must be true or false, not "{(element.text or "").strip()}"')
        return default

    def attribute_bool(self, element: Element, name: str, default: bool = False) -> bool:
        raw = element.get(name)
        if raw is None:
            return default
        text = raw.strip().lower()
        if text in TRUE_WORDS:
            return True
        if text in FALSE_WORDS:
            return False
        self.sink.emit(
            "MK121", f'attribute {name} must be true or false, not "{raw}"', self.loc(element, name)
        )
        return default

    def color(self, element: Element | None) -> tuple[float, float, float, float] | None:
        """An RGBA colour (three numbers mean opaque), each 0..1."""
        if element is None:
            return None
        text = (element.text or "").strip()
        if not text:
            return None
        values = [_finite(parse_number(t)) for t in text.split()]
        if len(values) not in (3, 4) or any(v is None for v in values):
            self.invalid(element, f'<{element.tag}> must be a colour of 3 or 4 numbers, not "{text}"')
            return None
        rgba = [float(v) for v in values if v is not None] + ([1.0] if len(values) == 3 else [])
        if any(v < 0.0 or v > 1.0 for v in rgba):
            self.invalid(element, f"<{element.tag}> colour components must be between 0 and 1: {text}")
            rgba = [min(1.0, max(0.0, v)) for v in rgba]
        return (rgba[0], rgba[1], rgba[2], rgba[3])

    def pose(self, element: Element | None) -> Pose | None:
        """The transform written in a ``<pose>`` element (identity when absent or empty).

        Handles ``rotation_format="quat_xyzw"`` and ``degrees="true"`` (SDFormat 1.9). Returns
        None, after reporting, when the text is not a valid pose.
        """
        if element is None:
            return Pose()
        fmt = (element.get("rotation_format") or "euler_rpy").strip()
        if fmt not in POSE_COUNTS:
            self.sink.emit(
                "MK121",
                f'rotation_format "{fmt}" is not euler_rpy or quat_xyzw',
                self.loc(element, "rotation_format"),
            )
            return None
        degrees = self.attribute_bool(element, "degrees")
        text = (element.text or "").strip()
        if not text:
            return Pose()
        items = text.split()
        values = [_finite(parse_number(t)) for t in items]
        count = POSE_COUNTS[fmt]
        if len(items) != count or any(v is None for v in values):
            layout = "x y z roll pitch yaw" if fmt == "euler_rpy" else "x y z qx qy qz qw"
            bad = [t for t, v in zip(items, values, strict=True) if v is None]
            why = f'"{bad[0]}" is not a finite number' if bad else f"found {len(items)}"
            self.invalid(element, f'<pose> must be {count} numbers ({layout}); {why}: "{text}"')
            return None
        nums = [float(v) for v in values if v is not None]
        translation = rot3.vec3(nums[:3])
        if fmt == "quat_xyzw":
            if degrees:
                self.sink.emit(
                    "MK121", 'degrees="true" applies only to euler_rpy poses', self.loc(element, "degrees")
                )
            if math.sqrt(sum(q * q for q in nums[3:])) == 0.0:
                self.invalid(element, "<pose> quaternion is zero")
                return None
            x, y, z, w = nums[3:]
            return Pose(rot3.from_quat_wxyz((w, x, y, z)), translation)
        angles = [math.radians(a) for a in nums[3:]] if degrees else nums[3:]
        return Pose(rot3.from_rpy(*angles), translation)
