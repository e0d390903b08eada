"""Small helpers of the MJCF writer: poses as ``pos``/``quat`` attributes, elements in order."""

from __future__ import annotations

import math
import re

import numpy as np
from lxml import etree

from modelkit.convert.numbers import (
    SNAP,
    ZERO,
    clean_rotation,
    fmt,
    fmt_position,
    fmt_rpy,
    fmt_vec,
    significant_digits,
)
from modelkit.spatial import Mat3, Pose, axis_angle, matrix_from_quat_wxyz, matrix_from_rpy

Element = etree._Element


def quat_wxyz(rotation: Mat3) -> np.ndarray:
    """The unit quaternion (w, x, y, z), first non-zero component > 0, of a rotation matrix
    (Shepperd's method); components within 1e-12 of 0, ±1, ±0.5 or ±√½ are that value
    (:func:`clean_rotation`)."""
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
    q = np.array([clean_rotation(x) for x in q / float(np.linalg.norm(q))])
    leading = next(x for x in q if x != 0.0)  # w ≥ 0; a half turn (w = 0) with its first axis ≥ 0
    return -q + 0.0 if leading < 0.0 else q


EULER_SEQUENCE = "XYZ"  # <compiler eulerseq>: fixed axes x, then y, then z = URDF's and SDF's rpy


def set_pose(el: Element, pose: Pose) -> None:
    """``pos`` and ``quat`` (or ``zaxis``, ``euler``) attributes, each left out when it is the identity.

    The rotation is written in the shortest of three texts that give the same matrix to 1e-12:
    ``quat``; ``zaxis`` when it is the shortest turn taking Z to a direction (``zaxis="0 1 0"``);
    ``euler``, URDF's roll-pitch-yaw (with ``<compiler eulerseq="XYZ">``, which the writer adds):
    ``rpy="1.57079 0 1.57079"`` stays ``euler="1.57079 0 1.57079"`` instead of a quaternion of
    four 15-digit numbers. A quaternion as a source writes one (:func:`short_quat`, at most
    :data:`SOURCE_DIGITS` digits) goes before them when they have a longer number: a source's
    ``quat="0.996179 0 -0.0873386 0"`` stays that, not ``euler="0 -0.174899984293942 0"``. A text
    with a tiny number (:func:`tiny_number`) is written only when every other one has one too."""
    position = fmt_position(pose.translation)
    if position != "0 0 0":
        el.set("pos", position)
    if not np.array_equal(np.asarray(pose.rotation, dtype=float), np.eye(3)):
        q = quat_wxyz(pose.rotation)
        if not (q[0] == 1.0 and not np.any(q[1:])):
            texts = {"quat": fmt_vec(q)}
            for key, text in (("zaxis", zaxis_text(pose.rotation)), ("euler", euler_text(pose.rotation))):
                if text is not None:
                    texts[key] = text
            # the shortest exact one (quat on a tie) among those without a tiny number, if any has none
            key = min(texts, key=lambda k: (tiny_number(texts[k]), len(texts[k])))
            if plainness(texts[key]) > SOURCE_DIGITS:
                written = short_quat(pose.rotation)
                if written is not None and (tiny_number(texts[key]) or not tiny_number(written)):
                    key, texts[key] = "quat", written
            el.set(key, texts[key])


_TINY = re.compile(r"\de-")


def tiny_number(text: str) -> bool:
    """Whether ``text`` holds a number written with a negative exponent (``8.95e-10``). Allegro's
    ``rpy="3.1415926518 0 0"`` is ``quat="8.95e-10 1 0 0"``, four characters shorter than its
    ``euler="3.1415926518 0 0"``, which is the source's own text and is written instead."""
    return _TINY.search(text) is not None


# A number of at most this many significant digits is one a source wrote (MuJoCo saves six, exporters
# up to nine); a longer one is arithmetic. Another form of a pose or an inertia replaces the writer's
# usual one only when that has a longer number and the other has none.
SOURCE_DIGITS = 9
# How far from unit length a rounded quaternion may be: six digits put it within 1e-6 (each component
# off by 5e-7 at most). A turn about Z by π/2 rounded to fewer digits (``0.7 0 0 0.7``, ``0.7071 0 0
# 0.7071``) normalises to the same rotation too, but reads as an approximation of it.
UNIT_QUAT = 2e-6


def short_quat(rotation: Mat3, most: int = SOURCE_DIGITS) -> str | None:
    """The rotation as a quaternion a source would write: the unit quaternion with every component
    rounded to the fewest significant digits (the same count for all four, at most ``most``) that
    give back the matrix to 1e-12 once MuJoCo has normalised them, and leave it within
    :data:`UNIT_QUAT` of unit length; None when no count does. A quaternion a source printed to six
    digits is not of unit length (``0.996179 0 -0.0873386 0``: 1 + 2e-7), so its normalised
    components have 16 digits; rounded to six they are the source's text again."""
    r = np.asarray(rotation, dtype=float)
    q = [float(x) for x in quat_wxyz(r)]
    for digits in range(1, most + 1):
        rounded = [float(f"{x:.{digits}g}") for x in q]
        norm = math.hypot(*rounded)
        if abs(norm - 1.0) > UNIT_QUAT:
            continue
        # a quaternion within SNAP/8 gives a matrix within SNAP (each entry is quadratic in it)
        if max(abs(a / norm - b) for a, b in zip(rounded, q, strict=True)) > SNAP / 8.0:
            continue
        if float(np.max(np.abs(matrix_from_quat_wxyz(rounded) - r))) <= SNAP:
            return fmt_vec(rounded)
    return None


def plainness(text: str) -> int:
    """The significant digits of the longest number in a text of numbers."""
    return max(significant_digits(number) for number in text.split())


ROTATION_KEYS = ("quat", "zaxis", "euler")


def use_fromto(el: Element, pose: Pose, half_length: float) -> None:
    """A capsule or cylinder ``el`` (``size="r h"`` and its pose already set) as MuJoCo's ``fromto``,
    the two ends of its axis, when ``pos``, the rotation and the half-length have a number longer
    than a source writes (:data:`SOURCE_DIGITS`) and the ends have none: a source's
    ``fromto="0 0 -0.03 -0.06 0 -0.17"`` comes back so, not as ``size="0.055 0.0761577310586391"
    pos="-0.03 0 -0.1" euler="0 0.404891786285083 0"``. Only when MuJoCo's reading of the ends (their
    middle, half their distance, the shortest turn taking Z towards the first) gives the shape back:
    the rotation to 1e-12, the centre and length to what a written position may differ by
    (:data:`ZERO` of the metre)."""
    rotation = np.asarray(pose.rotation, dtype=float)
    centre = np.asarray(pose.translation, dtype=float)
    axis = rotation[:, 2]
    # MuJoCo turns the shape's Z towards the first end: from = centre + h·Z, to = centre − h·Z
    ends = f"{fmt_position(centre + half_length * axis)} {fmt_position(centre - half_length * axis)}"
    radius, half_text = el.get("size", "").split()
    written = [el.get("pos", "0"), half_text, *(el.get(key) or "0" for key in ROTATION_KEYS)]
    if max(plainness(text) for text in written) <= SOURCE_DIGITS or plainness(ends) > SOURCE_DIGITS:
        return
    values = np.array([float(v) for v in ends.split()])
    start, end = values[:3], values[3:]
    length = float(np.linalg.norm(end - start))
    tolerance = ZERO * max(1.0, float(np.max(np.abs(values))))
    if (length == 0.0 or abs(length / 2.0 - half_length) > tolerance
            or float(np.max(np.abs((start + end) / 2.0 - centre))) > tolerance
            or float(np.max(np.abs(z_turn([float(v) for v in start - end]) - rotation))) > SNAP):
        return
    for key in ("pos", *ROTATION_KEYS):
        if key in el.attrib:
            del el.attrib[key]
    el.set("size", radius)
    el.set("fromto", ends)


def zaxis_text(rotation: Mat3) -> str | None:
    """The rotation as MuJoCo's ``zaxis`` (the shortest turn taking Z to it), or None when that is
    not this rotation to 1e-12 (a turn about the new Z as well)."""
    r = np.asarray(rotation, dtype=float)
    text = fmt_vec([clean_rotation(v) for v in r[:, 2]])
    if float(np.max(np.abs(z_turn([float(v) for v in text.split()]) - r))) > SNAP:
        return None
    return text


def z_turn(z: list[float]) -> np.ndarray:
    """The rotation MuJoCo makes of ``zaxis="z"``: about Z × z, by the angle between them (about X by
    π when z is −Z)."""
    v = np.asarray(z, dtype=float) / float(np.linalg.norm(z))
    cross = np.cross([0.0, 0.0, 1.0], v)
    sine = float(np.linalg.norm(cross))
    if sine < 1e-15:
        return np.eye(3) if v[2] > 0.0 else axis_angle([1.0, 0.0, 0.0], math.pi)
    return axis_angle(cross / sine, math.atan2(sine, float(v[2])))


def euler_text(rotation: Mat3) -> str | None:
    """The rotation as fixed-axis x-y-z angles (``eulerseq="XYZ"``, :func:`fmt_rpy`: the shorter of its
    two triples), or None when the printed angles do not give back the matrix to 1e-12."""
    text = fmt_rpy(np.asarray(rotation, dtype=float))
    back = matrix_from_rpy(*(float(v) for v in text.split()))
    if float(np.max(np.abs(back - np.asarray(rotation, dtype=float)))) > SNAP:
        return None
    return text


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
