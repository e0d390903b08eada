"""Small XML helpers of the SDF writer: elements with text, poses, colours, data back to elements."""

from __future__ import annotations

import math
from typing import Any

from lxml import etree
from lxml.etree import _Element as Element

from modelkit.convert.numbers import fmt, fmt_position, fmt_rpy, fmt_vec
from modelkit.spatial import Pose


def sub(parent: Element, tag: str, text: str | None = None, **attrib: str) -> Element:
    """A child element (attributes in the given order) with optional text."""
    el = etree.SubElement(parent, tag)
    for key, value in attrib.items():
        el.set(key, value)
    if text is not None:
        el.text = text
    return el


def child_or_sub(parent: Element, tag: str) -> Element:
    """The first child ``tag`` of ``parent``, made when there is none."""
    found = parent.find(tag)
    return found if found is not None else sub(parent, tag)


def num(parent: Element, tag: str, value: float) -> Element:
    return sub(parent, tag, fmt(value))


def pose_text(pose: Pose) -> str:
    return f"{fmt_position(pose.translation)} {fmt_rpy(pose.rotation)}"


def add_pose(parent: Element, pose: Pose, relative_to: str | None = None, always: bool = False) -> None:
    """A ``<pose>`` child; left out when it is the identity in the default frame (unless ``always``)."""
    if relative_to is None and not always and pose.is_identity(0.0):
        return
    el = sub(parent, "pose", pose_text(pose))
    if relative_to is not None:
        el.set("relative_to", relative_to)


FLOAT32_SMALLEST_NORMAL = 1.1754943508222875e-38


def rgba(values: Any, alpha: float = 1.0) -> str:
    """A colour's text. libsdformat reads colour components as 32-bit floats (``std::stof``), which
    refuses a value too small for one ("Out of range. Unable to set value [1e-300]"): such a component
    is written 0, the colour it stands for."""
    v = [float(x) for x in values]
    if len(v) == 3:
        v.append(alpha)
    return fmt_vec([0.0 if abs(x) < FLOAT32_SMALLEST_NORMAL else x for x in v])


def data_to_element(parent: Element, tag: str, data: Any) -> Element:
    """The inverse of the reader's ``element_data``: dicts are children (``@x`` attributes,
    ``#text`` text), lists are repeated children, numbers are printed with ``fmt``."""
    el = etree.SubElement(parent, tag)
    if isinstance(data, dict):
        for key, value in data.items():
            if key.startswith("@"):
                el.set(key[1:], str(value))
        text = data.get("#text")
        if text is not None:
            el.text = _scalar_text(text)
        for key, value in data.items():
            if key.startswith(("@", "#")):
                continue
            for item in value if isinstance(value, list) and _is_repeat(value) else [value]:
                data_to_element(el, key, item)
    else:
        el.text = _scalar_text(data)
    return el


def _is_repeat(value: list[Any]) -> bool:
    """A list of children (dicts or strings), not the numbers of one vector element."""
    return any(isinstance(v, dict | str) for v in value)


def _scalar_text(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int | float):
        return fmt(float(value)) if math.isfinite(float(value)) else str(value)
    if isinstance(value, list):
        return " ".join(_scalar_text(v) for v in value)
    return str(value)


def parse_fragment(xml: str) -> Element | None:
    """A verbatim element kept by a reader (a plugin), or None when it does not parse on its own."""
    try:
        return etree.fromstring(xml)
    except etree.XMLSyntaxError:
        return None


def data_element(tag: str, data: Any) -> Element:
    """The element the SDF reader's ``element_data`` made ``data`` of: ``@name`` keys are attributes,
    ``#text`` the text, other keys children (a list: repeated children), a scalar or a list of numbers
    the text."""
    el = etree.Element(tag)
    if isinstance(data, dict):
        for key, value in data.items():
            if key.startswith("@"):
                el.set(key[1:], str(value))
            elif key == "#text":
                el.text = _data_text(value)
            else:
                repeated = isinstance(value, list) and any(isinstance(v, dict) for v in value)
                for item in value if repeated else [value]:
                    el.append(data_element(key, item))
    else:
        el.text = _data_text(data)
    return el


def _data_text(value: Any) -> str:
    if isinstance(value, list):
        return " ".join(_data_text(v) for v in value)
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return fmt(value)
    return str(value)
