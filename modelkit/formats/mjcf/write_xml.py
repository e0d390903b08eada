"""Small helpers of the MJCF writer: poses as ``pos``/``quat`` attributes, elements in order."""

from __future__ import annotations

import math

import numpy as np
from lxml import etree

from modelkit.convert.numbers import SNAP, clean_rotation, fmt, fmt_position, fmt_rpy, fmt_vec
from modelkit.spatial import Mat3, Pose, axis_angle, matrix_from_rpy

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
    four 15-digit numbers."""
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
            key = min(texts, key=lambda k: len(texts[k]))  # the shortest exact one; quat on a tie
            el.set(key, texts[key])


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
