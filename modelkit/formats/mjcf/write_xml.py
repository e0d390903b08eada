"""Small helpers of the MJCF writer: poses as ``pos``/``quat`` attributes, elements in order."""

from __future__ import annotations

import math

import numpy as np
from lxml import etree

from modelkit.convert.numbers import clean, fmt, fmt_vec
from modelkit.spatial import Mat3, Pose

Element = etree._Element


def quat_wxyz(rotation: Mat3) -> np.ndarray:
    """The unit quaternion (w, x, y, z), w ≥ 0, of a rotation matrix (Shepperd's method)."""
    r = np.asarray(rotation, dtype=float)
    trace = r[0, 0] + r[1, 1] + r[2, 2]
    if trace > 0.0:
        s = 2.0 * math.sqrt(1.0 + trace)
        q = np.array([0.25 * s, (r[2, 1] - r[1, 2]) / s, (r[0, 2] - r[2, 0]) / s, (r[1, 0] - r[0, 1]) / s])
    elif r[0, 0] > r[1, 1] and r[0, 0] > r[2, 2]:
        s = 2.0 * math.sqrt(1.0 + r[0, 0] - r[1, 1] - r[2, 2])
        q = np.array([(r[2, 1] - r[1, 2]) / s, 0.25 * s, (r[0, 1] + r[1, 0]) / s, (r[0, 2] + r[2, 0]) / s])
    elif r[1, 1] > r[2, 2]:
        s = 2.0 * math.sqrt(1.0 + r[1, 1] - r[0, 0] - r[2, 2])
        q = np.array([(r[0, 2] - r[2, 0]) / s, (r[0, 1] + r[1, 0]) / s, 0.25 * s, (r[1, 2] + r[2, 1]) / s])
    else:
        s = 2.0 * math.sqrt(1.0 + r[2, 2] - r[0, 0] - r[1, 1])
        q = np.array([(r[1, 0] - r[0, 1]) / s, (r[0, 2] + r[2, 0]) / s, (r[1, 2] + r[2, 1]) / s, 0.25 * s])
    q = q / float(np.linalg.norm(q))
    if q[0] < 0.0:
        q = -q
    return np.array([clean(x) for x in q])


def set_pose(el: Element, pose: Pose) -> None:
    """``pos`` and ``quat`` attributes, each left out when it is the identity (MuJoCo's default)."""
    t = np.asarray(pose.translation, dtype=float)
    if np.any(t != 0.0):
        el.set("pos", fmt_vec(t))
    if not np.array_equal(np.asarray(pose.rotation, dtype=float), np.eye(3)):
        q = quat_wxyz(pose.rotation)
        if not (q[0] == 1.0 and not np.any(q[1:])):
            el.set("quat", fmt_vec(q))


def sub(parent: Element, tag: str, **attributes: str) -> Element:
    """A child element with attributes in the given order (lxml keeps insertion order)."""
    el = etree.SubElement(parent, tag)
    for key, value in attributes.items():
        el.set(key, value)
    return el


# Indentation stops growing at this depth: a chain of 10,000 bodies written with ever deeper
# indentation is quadratic in size (500 MB of spaces); every real model nests far less.
MAX_INDENT_LEVEL = 100


def indent(root: Element, space: str = "  ", max_level: int = MAX_INDENT_LEVEL) -> None:
    """``etree.indent(root, space)`` without a walk that recurses per level, and with the indentation
    of elements deeper than ``max_level`` held at that level: identical output for shallower trees,
    linear size for deep ones. Whitespace-only text and tails are replaced, other text kept."""
    stack: list[tuple[Element, int]] = [(root, 1)]
    while stack:
        el, level = stack.pop()
        if len(el) == 0:
            continue
        inner = "\n" + space * min(level, max_level)
        if not (el.text and el.text.strip()):
            el.text = inner
        for child in el:
            if not (child.tail and child.tail.strip()):
                child.tail = inner
            if len(child):
                stack.append((child, level + 1))
        last = el[-1]
        if not (last.tail and last.tail.strip()):
            last.tail = "\n" + space * min(level - 1, max_level)


def section(root: Element, tag: str) -> Element:
    """The top-level section ``tag`` of ``<mujoco>``, created on first use."""
    found = root.find(tag)
    return found if found is not None else etree.SubElement(root, tag)


def num(x: float) -> str:
    return fmt(x)
