"""How far a collision shape reaches in a direction, and whether it is round about an axis.

Shared by the conversion rules that look at shapes (tracks' extents, the base decision's ground
contact, wheels) and by ``verify``'s wheel finder, so that convert and verify call the same shape a
wheel. A mesh held only by its path is read from its file (Hello Robot's Stretch and the tutorial's
``mobile_robot_mesh.body`` keep their wheels as files); an unreadable mesh reaches nowhere (None).
"""

from __future__ import annotations

import math
import weakref
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from modelkit.model import Box, Capsule, Cone, Cylinder, Ellipsoid, Geom, Geometry, Mesh, Sphere
from modelkit.spatial import Vec3

ROUNDNESS = 0.02
"""A mesh is round about an axis when its reach across the axis, in every one of
:data:`ROUND_DIRECTIONS` directions, is within this fraction of the largest (a 16-sided prism is,
0.8 %; a square is not, 41 %)."""
ROUND_DIRECTIONS = 12
MICRON_DIGITS = 6
"""A round mesh's radius, centre and width are given to the micrometre: mesh files hold float32
vertices (7 digits), and the shape written from them (a wheel's sphere) is an approximation anyway."""


_READ: weakref.WeakKeyDictionary[Mesh, tuple[tuple[object, ...], np.ndarray | None]] = \
    weakref.WeakKeyDictionary()
"""A file mesh's vertices as read, per model object and what it was read from: the rules ask for the
same mesh's reach in several directions (``extent`` asks twice per direction), and each ask parsed the
file again."""


def mesh_vertices(mesh: Mesh) -> np.ndarray | None:
    """The mesh's vertices in its geom frame (scale applied), loading the file when needed."""
    if mesh.data is not None:
        vertices: np.ndarray | None = np.asarray(mesh.data.vertices, dtype=float)
    elif mesh.path:
        vertices = _file_vertices(mesh)
    else:
        return None
    if vertices is None or vertices.size == 0:
        return None
    return vertices.reshape(-1, 3) * np.asarray(mesh.scale, dtype=float)


def _file_vertices(mesh: Mesh) -> np.ndarray | None:
    """The vertices of the mesh's file (None when it does not load), read once per mesh object."""
    from modelkit.geometry.meshfiles import MeshLoadError, MeshMetadata, load_mesh

    meta = mesh.source_params.get("metadata")
    metadata = (MeshMetadata(meta.get("length_unit"), meta.get("upper_axis"))
                if isinstance(meta, dict) and meta else None)
    try:
        stat = Path(str(mesh.path)).stat()
    except OSError:
        return None
    # a rewritten file (another modification time or size) is read again
    key = (mesh.path, mesh.fragment, metadata, stat.st_mtime_ns, stat.st_size)
    kept = _READ.get(mesh)
    if kept is not None and kept[0] == key:
        return kept[1]
    try:
        vertices: np.ndarray | None = np.asarray(
            load_mesh(Path(str(mesh.path)), mesh.fragment, metadata).mesh.vertices, dtype=float)
    except (MeshLoadError, OSError):
        vertices = None
    _READ[mesh] = (key, vertices)
    return vertices


def support(geometry: Geometry, direction: Vec3) -> float | None:
    """max over the shape of ``direction · p`` (p in the geom frame); None for an unreadable mesh."""
    d = np.asarray(direction, dtype=float)
    lateral = math.hypot(float(d[0]), float(d[1]))
    if isinstance(geometry, Box):
        return float(np.abs(d) @ (0.5 * np.asarray(geometry.size, dtype=float)))
    if isinstance(geometry, Sphere):
        return float(geometry.radius * np.linalg.norm(d))
    if isinstance(geometry, Cylinder):
        return geometry.radius * lateral + 0.5 * geometry.length * abs(float(d[2]))
    if isinstance(geometry, Capsule):
        return 0.5 * geometry.length * abs(float(d[2])) + geometry.radius * float(np.linalg.norm(d))
    if isinstance(geometry, Cone):  # apex at +length/2, base circle at -length/2
        half = 0.5 * geometry.length
        return max(half * float(d[2]), -half * float(d[2]) + geometry.radius * lateral)
    if isinstance(geometry, Ellipsoid):
        return float(np.linalg.norm(np.asarray(geometry.radii, dtype=float) * d))
    vertices = mesh_vertices(geometry) if isinstance(geometry, Mesh) else None
    return None if vertices is None else float(np.max(vertices @ d))


def extent(geoms: list[Geom], direction: Vec3) -> tuple[float, float] | None:
    """(min, max) of ``direction · p`` over the shapes, p in the link frame; None without any."""
    lows: list[float] = []
    highs: list[float] = []
    for geom in geoms:
        rotation, offset = geom.pose.rotation, geom.pose.translation
        hi = support(geom.geometry, rotation.T @ direction)
        lo = support(geom.geometry, rotation.T @ -direction)
        if hi is None or lo is None:
            continue
        base = float(direction @ offset)
        highs.append(base + hi)
        lows.append(base - lo)
    if not highs:
        return None
    return min(lows), max(highs)


@dataclass(frozen=True)
class Round:
    """A shape round about an axis: its radius, centre (link frame) and width along the axis."""

    radius: float
    centre: np.ndarray
    width: float


def across(axis: Vec3) -> tuple[np.ndarray, np.ndarray]:
    """Two unit directions perpendicular to the unit ``axis`` and to each other."""
    helper = np.array([1.0, 0.0, 0.0]) if abs(float(axis[0])) < 0.9 else np.array([0.0, 0.0, 1.0])
    u = np.cross(axis, helper)
    u /= np.linalg.norm(u)
    return u, np.cross(axis, u)


def round_about(geom: Geom, axis: Vec3, parallel: float = 1e-6) -> Round | None:
    """The shape's roundness about the unit ``axis`` (link frame), or None when it is not round: a
    sphere; a cylinder whose own axis is parallel to ``axis`` (``|1 − |cos||`` below ``parallel``);
    a mesh whose reach across ``axis`` is the same in every direction (:data:`ROUNDNESS`), its radius
    the mean half reach and its centre the middle of its extents along ``axis`` and across it
    (:data:`MICRON_DIGITS`)."""
    g = geom.geometry
    offset = np.asarray(geom.pose.translation, dtype=float)
    axis = np.asarray(axis, dtype=float)
    if isinstance(g, Sphere):
        return Round(float(g.radius), offset, 2.0 * float(g.radius))
    if isinstance(g, Cylinder):
        along = geom.pose.rotation @ np.array([0.0, 0.0, 1.0])
        if abs(1.0 - abs(float(along @ axis))) >= parallel:
            return None
        return Round(float(g.radius), offset, float(g.length))
    if not isinstance(g, Mesh):
        return None
    vertices = mesh_vertices(g)
    if vertices is None or not len(vertices):
        return None
    points = (geom.pose.rotation @ vertices.T).T + offset
    u, w = across(axis)
    angles = np.linspace(0.0, math.pi, ROUND_DIRECTIONS, endpoint=False)
    directions = np.outer(np.cos(angles), u) + np.outer(np.sin(angles), w)
    spans = np.ptp(points @ directions.T, axis=0)
    widest = float(spans.max())
    if widest <= 0.0 or float(spans.min()) < (1.0 - ROUNDNESS) * widest:
        return None
    centre = np.zeros(3)
    for direction in (u, w, axis):
        reach = points @ direction
        centre += 0.5 * float(reach.max() + reach.min()) * direction
    return Round(_micron(0.5 * float(spans.mean())), np.round(centre, MICRON_DIGITS) + 0.0,
                 _micron(float(np.ptp(points @ axis))))


def _micron(value: float) -> float:
    return round(value, MICRON_DIGITS) + 0.0  # + 0.0: no "-0"
