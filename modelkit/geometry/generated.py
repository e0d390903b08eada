"""Triangle meshes for Choreonoid's generated geometry: Extrusion, ElevationGrid, IndexedFaceSet,
TriangleMesh.

The behaviour follows the ``.body`` format specification (``body-format.md`` §4.6–§4.8, §6.4),
i.e. what Choreonoid's ``MeshGenerator`` / ``PolygonMeshTriangulator`` produce, with their quirks:

* Extrusion: the straight-spine cross-section frame is Rodrigues' formula evaluated with an
  *unnormalised* axis (shear for oblique spines, point reflection for a −Y spine), orientation
  axes are used as given, flat lists with a length that is not a multiple of the tuple size lose
  their trailing numbers. ``faithful=False`` gives the shape VRML97 intends instead.
* IndexedFaceSet: polygons are separated by −1; a trailing polygon without its −1 is dropped.
* TriangleMesh: Choreonoid does not check indices; we do.

Inputs on which Choreonoid would crash, refuse or run into undefined behaviour raise
:class:`GeometryError` carrying the modelkit diagnostic code. Everything here is deterministic:
the same input always gives identical arrays. Angles are radians (the caller converts degrees).
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from modelkit.model import TriangleMeshData
from modelkit.spatial import axis_angle

__all__ = [
    "UNIT_AXIS_TOLERANCE",
    "ExtrusionReport",
    "GeometryError",
    "elevation_grid",
    "extrusion",
    "flip_if_inward",
    "indexed_face_set",
    "signed_volume",
    "triangle_mesh",
]

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

#: An Extrusion orientation axis whose length differs from 1 by more than this is reported
#: (``ExtrusionReport.non_unit_orientation_axis``). Axes written with four significant digits
#: (0.7071, 0.7071, 0) stay below it.
UNIT_AXIS_TOLERANCE = 1e-4

#: A straight-spine cross-section frame counts as sheared (``oblique_straight``) when SᵀS differs
#: from the identity by more than this in some entry.
_ORTHOGONALITY_TOLERANCE = 1e-9

#: Containment tests of the ear clipper switch from a Python loop to numpy above this many candidates.
_VECTORISE_ABOVE = 24


class GeometryError(Exception):
    """Input on which Choreonoid would crash or refuse; ``code`` is a modelkit diagnostic code."""

    def __init__(self, code: str, message: str, key: str | None = None, index: int | None = None) -> None:
        super().__init__(f"{code}: {message}")
        self.code = code
        self.message = message
        # The input at fault ("spine", "cross_section", "scale", "orientation", "height", "faces").
        self.key = key
        self.index = index  # the element of that input at fault, when one is


@dataclass(frozen=True)
class ExtrusionReport:
    """Facts about an Extrusion that a validator warns about (none of them stops generation).

    The flags describe what *Choreonoid* does with the data, whatever ``faithful`` was.

    * ``straight``: the spine counts as straight (2 points, or every spine Z axis is zero).
    * ``oblique_straight`` (MK403): straight, and some cross-section frame is not orthogonal, i.e.
      the spine is neither along ±Y nor perpendicular to Y, so Choreonoid shears the cross-section.
    * ``mirrored`` (MK404): straight, and some cross-section frame has a negative determinant. This
      is the point reflection −E of a spine along −Y; it also covers steep downward oblique spines,
      whose sheared frame reverses orientation too. Triangle winding is reversed.
    * ``open_cross_section_with_caps`` (MK406): the cross-section is not closed and a cap is
      actually generated (caps are never generated for a closed spine).
    * ``non_unit_orientation_axis`` (MK415): some orientation that is used (the single one, or one
      of the first n) has an axis whose length differs from 1 by more than
      :data:`UNIT_AXIS_TOLERANCE` and a non-zero angle (with a zero angle the axis has no effect).
    * ``dropped_numbers``: for each of ``"cross_section"``, ``"spine"``, ``"orientation"``,
      ``"scale"`` whose flat length is not a multiple of its tuple size, how many trailing numbers
      were ignored. Keys with nothing dropped are absent.
    """

    straight: bool
    oblique_straight: bool
    mirrored: bool
    open_cross_section_with_caps: bool
    non_unit_orientation_axis: bool
    dropped_numbers: dict[str, int]


# ---- small helpers ------------------------------------------------------------------------------


def _tuples(values: Sequence[float], size: int, key: str, dropped: dict[str, int]) -> FloatArray:
    """Cut a flat list into rows of ``size`` numbers, ignoring (and recording) a trailing remainder."""
    flat = np.asarray(values, dtype=np.float64).reshape(-1)
    count = len(flat) // size
    extra = len(flat) - count * size
    if extra:
        dropped[key] = extra
    return flat[: count * size].reshape(count, size)


def _distinct_rows(rows: FloatArray) -> int:
    # +0.0 folds -0.0 into 0.0, so that distinctness agrees with the == comparisons Choreonoid uses.
    return len({tuple(float(x) + 0.0 for x in row) for row in rows})


def _normalized_rows(v: FloatArray) -> FloatArray:
    """Row-wise normalisation that leaves zero rows unchanged (as Eigen's ``normalized()``)."""
    norms = np.sqrt(np.einsum("ij,ij->i", v, v))
    out = v.copy()
    nonzero = norms > 0.0
    out[nonzero] = v[nonzero] / norms[nonzero, None]
    return out


def _vertex_rows(values: Sequence[float]) -> FloatArray:
    """Flat x, y, z list → (n, 3); a trailing partial triple is ignored."""
    flat = np.asarray(values, dtype=np.float64).reshape(-1)
    return flat[: len(flat) // 3 * 3].reshape(-1, 3)


def _empty_faces() -> IntArray:
    return np.zeros((0, 3), dtype=np.int64)


# ---- Extrusion -----------------------------------------------------------------------------------


def _spine_axes(s: FloatArray, closed: bool) -> tuple[FloatArray, FloatArray | None]:
    """Per-spine-point Y axes and (after zero replacement) raw Z axes, §4.6 step 2.

    Returns ``(Y, Z)`` with ``Z`` None when the spine counts as straight. ``Z`` rows before the
    first non-zero one ("definedZ") are already replaced by it.
    """
    n = len(s)
    if n == 2:
        y = np.repeat((s[1] - s[0])[None, :], 2, axis=0)
        return y, None
    if closed:
        prev = np.roll(s, 1, axis=0)
        nxt = np.roll(s, -1, axis=0)
        y = nxt - prev
        z = np.cross(nxt - s, prev - s)
    else:
        y = np.empty_like(s)
        z = np.empty_like(s)
        y[1:-1] = s[2:] - s[:-2]
        z[1:-1] = np.cross(s[2:] - s[1:-1], s[:-2] - s[1:-1])
        y[0] = s[1] - s[0]
        z[0] = z[1]  # the Z of point 1
        y[-1] = s[-1] - s[-2]
        z[-1] = z[-2]  # the Z of point n-2
    # A zero Z takes the last non-zero raw Z seen before it; leading zeros take the first non-zero.
    defined = -1
    previous = np.zeros(3)
    for i in range(n):
        if math.sqrt(float(z[i] @ z[i])) == 0.0:
            if defined != -1:
                z[i] = previous
        else:
            if defined == -1:
                defined = i
            previous = z[i].copy()
    if defined == -1:
        return y, None
    z[:defined] = z[defined]
    return y, z


def _straight_frames_faithful(y_axes: FloatArray) -> FloatArray:
    """Choreonoid's straight-spine frames: AA(acos(y_y), (y_z, 0, −y_x)) with the axis unnormalised."""
    y = _normalized_rows(y_axes)
    frames = np.empty((len(y), 3, 3))
    for i, (yx, yy, yz) in enumerate(y):
        theta = math.acos(min(1.0, max(-1.0, float(yy))))
        frames[i] = axis_angle([float(yz), 0.0, -float(yx)], theta, normalise=False)
    return frames


def _straight_frames_vrml(y_axes: FloatArray) -> FloatArray:
    """The rotation VRML97 intends: the proper rotation taking +Y to the spine direction.

    A spine along −Y gets Rx(π) (rotation of π about X), the limit of the rotations for spines
    tilted from −Y towards +Z. A zero Y axis (coincident spine points) borrows the nearest
    non-zero one, preferring earlier points; with none at all the frame is the identity.
    """
    y = _normalized_rows(y_axes)
    nonzero = [i for i in range(len(y)) if np.any(y[i] != 0.0)]
    frames = np.empty((len(y), 3, 3))
    for i in range(len(y)):
        if not nonzero:
            frames[i] = np.eye(3)
            continue
        earlier = [k for k in nonzero if k <= i]
        yx, yy, yz = (float(c) for c in y[earlier[-1] if earlier else nonzero[0]])
        a = np.array([yz, 0.0, -yx])
        if float(np.linalg.norm(a)) > 0.0:
            frames[i] = axis_angle(a, math.acos(min(1.0, max(-1.0, yy))))
        elif yy < 0.0:
            frames[i] = np.diag([1.0, -1.0, -1.0])  # Rx(π)
        else:
            frames[i] = np.eye(3)
    return frames


def _curved_frames(y_axes: FloatArray, z_axes: FloatArray) -> FloatArray:
    """Frames [x | y | z] of a curved spine, flipping Z sequentially to keep neighbours consistent."""
    z = z_axes.copy()
    for i in range(1, len(z)):
        if float(z[i] @ z[i - 1]) < 0.0:
            z[i] = -z[i]
    y = _normalized_rows(y_axes)
    zn = _normalized_rows(z)
    x = np.cross(y, zn)
    return np.stack([x, y, zn], axis=2)


def _orientation_matrices(ori: FloatArray, n: int, faithful: bool) -> FloatArray:
    if len(ori) == 0:
        return np.repeat(np.eye(3)[None], n, axis=0)
    rows = np.repeat(ori[:1], n, axis=0) if len(ori) == 1 else ori[:n]
    out = np.empty((n, 3, 3))
    for i, (ax, ay, az, angle) in enumerate(rows):
        axis = [float(ax), float(ay), float(az)]
        if faithful:
            out[i] = axis_angle(axis, float(angle), normalise=False)
        elif ax == 0.0 and ay == 0.0 and az == 0.0:
            out[i] = np.eye(3)  # no axis, no rotation
        else:
            out[i] = axis_angle(axis, float(angle))
    return out


def extrusion(
    cross_section: Sequence[float],
    spine: Sequence[float],
    *,
    orientation: Sequence[float] = (),
    scale: Sequence[float] = (),
    begin_cap: bool = True,
    end_cap: bool = True,
    faithful: bool = True,
) -> tuple[TriangleMeshData, ExtrusionReport]:
    """Mesh of an Extrusion exactly as Choreonoid's ``MeshGenerator::generateExtrusion`` builds it.

    ``cross_section`` (u0, v0, u1, v1, …), ``spine`` (x0, y0, z0, …), ``orientation`` (axis–angle
    quadruples, radians) and ``scale`` (su, sv pairs) are the flat lists of the file. A spine whose
    last point equals its first exactly is closed (no caps); a cross-section likewise. Vertex
    ``i·m + j`` is cross-section point j at spine point i: ``S_i · O_i · (u·su, 0, v·sv) + s_i``.
    Side triangles come first, then the begin cap, then the end cap (reverse winding).

    ``faithful=True`` reproduces Choreonoid: for a straight spine the cross-section frame is
    Rodrigues' formula with the unnormalised axis (y_z, 0, −y_x) — a shear for oblique spines and
    the point reflection −E for a spine along −Y — and orientation axes are used unnormalised.
    ``faithful=False`` gives the VRML97-intended shape: the proper rotation taking +Y to the spine
    direction (for a spine along −Y: a rotation of π about **X**, (u, v) ↦ (u, 0, −v)) and
    normalised orientation axes (a zero axis means no rotation). Curved spines are the same both ways.

    Raises GeometryError MK401 with fewer than 2 distinct spine or cross-section points (after the
    closing point is removed) and MK402 when ``scale`` or ``orientation`` has k tuples with
    1 < k < n (n = spine points without the closing one), which Choreonoid reads out of range.
    """
    dropped: dict[str, int] = {}
    cs = _tuples(cross_section, 2, "cross_section", dropped)
    sp = _tuples(spine, 3, "spine", dropped)
    ori = _tuples(orientation, 4, "orientation", dropped)
    sc = _tuples(scale, 2, "scale", dropped)

    spine_closed = len(sp) >= 2 and bool(np.array_equal(sp[0], sp[-1]))
    if spine_closed:
        sp = sp[:-1]
    cs_closed = len(cs) >= 2 and bool(np.array_equal(cs[0], cs[-1]))
    if cs_closed:
        cs = cs[:-1]
    if _distinct_rows(sp) < 2:
        raise GeometryError(
            "MK401",
            f"An Extrusion needs at least 2 distinct spine points; it has {_distinct_rows(sp)}"
            + (" (after removing the closing point)" if spine_closed else "")
            + ".",
            key="spine",
        )
    if _distinct_rows(cs) < 2:
        raise GeometryError(
            "MK401",
            f"An Extrusion needs at least 2 distinct cross-section points; it has {_distinct_rows(cs)}"
            + (" (after removing the closing point)" if cs_closed else "")
            + ".",
            key="cross_section",
        )
    n, m = len(sp), len(cs)
    for key, rows in (("scale", sc), ("orientation", ori)):
        if 1 < len(rows) < n:
            raise GeometryError(
                "MK402",
                f"Extrusion {key} has {len(rows)} entries; it needs 0, 1 or at least {n} "
                f"(one per spine point{' without the closing one' if spine_closed else ''}).",
                key=key,
            )

    # Cross-section plane frames.
    y_axes, z_axes = _spine_axes(sp, spine_closed)
    straight = z_axes is None
    if z_axes is None:
        frames_choreonoid = _straight_frames_faithful(y_axes)
        frames = frames_choreonoid if faithful else _straight_frames_vrml(y_axes)
        gram = np.einsum("nki,nkj->nij", frames_choreonoid, frames_choreonoid)
        oblique = bool(np.any(np.abs(gram - np.eye(3)) > _ORTHOGONALITY_TOLERANCE))
        mirrored = bool(np.any(np.linalg.det(frames_choreonoid) < 0.0))
    else:
        frames = _curved_frames(y_axes, z_axes)
        oblique = mirrored = False

    # Per-point scale and orientation.
    if len(sc) == 0:
        scales = np.ones((n, 2))
    elif len(sc) == 1:
        scales = np.repeat(sc, n, axis=0)
    else:
        scales = sc[:n]
    used_ori = ori[:1] if len(ori) == 1 else ori[:n]
    axis_len = np.linalg.norm(used_ori[:, :3], axis=1)
    non_unit = bool(np.any((np.abs(axis_len - 1.0) > UNIT_AXIS_TOLERANCE) & (used_ori[:, 3] != 0.0)))
    rotations = np.einsum("nij,njk->nik", frames, _orientation_matrices(ori, n, faithful))

    # Vertices: P[i·m + j] = (S_i O_i) (u·su, 0, v·sv) + s_i.
    u = cs[None, :, 0] * scales[:, 0, None]  # (n, m)
    v = cs[None, :, 1] * scales[:, 1, None]
    points = (
        u[:, :, None] * rotations[:, None, :, 0] + v[:, :, None] * rotations[:, None, :, 2] + sp[:, None, :]
    )
    vertices = points.reshape(n * m, 3)

    # Side triangles.
    rings = n if spine_closed else n - 1
    columns = m if cs_closed else m - 1
    i = np.arange(rings)[:, None]
    j = np.arange(columns)[None, :]
    a = i * m
    b = ((i + 1) % n) * m
    j2 = (j + 1) % m
    sides = np.stack(
        [
            np.stack([a + j, b + j, b + j2], axis=-1),
            np.stack([a + j, b + j2, a + j2], axis=-1),
        ],
        axis=2,
    ).reshape(-1, 3)
    parts: list[IntArray] = [sides.astype(np.int64)]

    # Caps (never for a closed spine).
    if not spine_closed:
        if begin_cap:
            parts.append(_triangulate_polygon(vertices[:m]))
        if end_cap:
            base = (n - 1) * m
            parts.append(_triangulate_polygon(vertices[base : base + m])[:, [0, 2, 1]] + base)
    faces = np.concatenate(parts, axis=0).astype(np.int64)

    report = ExtrusionReport(
        straight=straight,
        oblique_straight=straight and oblique,
        mirrored=straight and mirrored,
        open_cross_section_with_caps=(not cs_closed) and (not spine_closed) and (begin_cap or end_cap),
        non_unit_orientation_axis=non_unit,
        dropped_numbers=dropped,
    )
    return TriangleMeshData(vertices=np.ascontiguousarray(vertices), faces=faces), report


# ---- ElevationGrid -------------------------------------------------------------------------------


def elevation_grid(
    x_dimension: int,
    z_dimension: int,
    x_spacing: float,
    z_spacing: float,
    height: Sequence[float],
    *,
    ccw: bool = True,
) -> TriangleMeshData:
    """Mesh of an ElevationGrid (§4.7): vertex (x, z) = (x·x_spacing, height[z·x_dim + x], z·z_spacing).

    Per cell (p_xz): ``ccw`` → (p00, p01, p11), (p00, p11, p10), facing +Y for a flat grid;
    ``ccw=False`` reverses both. Raises GeometryError MK407 when a dimension is below 2 or
    ``height`` does not have exactly x_dimension·z_dimension entries.
    """
    xd, zd = int(x_dimension), int(z_dimension)
    h = np.asarray(height, dtype=np.float64).reshape(-1)
    if xd < 2 or zd < 2:
        raise GeometryError(
            "MK407",
            f"An ElevationGrid needs xDimension and zDimension of at least 2 (got {xd} × {zd}).",
            key="x_dimension",
        )
    if len(h) != xd * zd:
        raise GeometryError(
            "MK407",
            f"ElevationGrid height has {len(h)} values; xDimension·zDimension = {xd}·{zd} = {xd * zd}.",
            key="height",
        )
    zz, xx = np.meshgrid(np.arange(zd), np.arange(xd), indexing="ij")
    vertices = np.stack([xx.reshape(-1) * float(x_spacing), h, zz.reshape(-1) * float(z_spacing)], axis=1)
    z0, x0 = np.meshgrid(np.arange(zd - 1), np.arange(xd - 1), indexing="ij")
    p00 = (z0 * xd + x0).reshape(-1)
    p10 = p00 + 1
    p01 = p00 + xd
    p11 = p01 + 1
    if ccw:
        cells = np.stack([np.stack([p00, p01, p11], 1), np.stack([p00, p11, p10], 1)], axis=1)
    else:
        cells = np.stack([np.stack([p00, p11, p01], 1), np.stack([p00, p10, p11], 1)], axis=1)
    return TriangleMeshData(vertices=vertices, faces=cells.reshape(-1, 3).astype(np.int64))


# ---- IndexedFaceSet and TriangleMesh -------------------------------------------------------------


def _indices(values: Sequence[int], what: str) -> IntArray:
    raw = np.asarray(values).reshape(-1)
    if raw.size == 0:
        return np.zeros(0, dtype=np.int64)
    if raw.dtype.kind == "f":
        if not np.all(np.isfinite(raw)) or np.any(raw != np.floor(raw)):
            bad = raw[~np.isfinite(raw) | (raw != np.floor(raw))][0]
            raise GeometryError("MK408", f"{what} index {bad} is not an integer.")
    elif raw.dtype.kind not in "iub":
        raise GeometryError("MK408", f"{what} indices must be integers.")
    return raw.astype(np.int64)


def _out_of_range_message(bad: IntArray, n_vertices: int, allow_separator: bool) -> str:
    first = int(bad[0])
    if first >= n_vertices:
        text = f"Vertex index {first} is over the number of vertices ({n_vertices})."
    else:
        extra = " (only -1 separates polygons)" if allow_separator else ""
        text = f"Vertex index {first} is negative{extra}; there are {n_vertices} vertices."
    if len(bad) > 1:
        text += f" There are {len(bad)} invalid vertex indices."
    return text


def indexed_face_set(vertices: Sequence[float], coord_index: Sequence[int]) -> tuple[TriangleMeshData, int]:
    """Triangulate an IndexedFaceSet (§4.8).

    Polygons are separated by −1 and ear-clipped keeping their orientation (a 3-vertex polygon is
    taken as is; polygons of fewer than 3 vertices give nothing). Returns the mesh (all vertices
    kept, indices unchanged) and the number of indices in a trailing polygon that lacked its −1
    terminator (that polygon is dropped, as Choreonoid does; the caller warns MK409). A trailing
    partial vertex triple is ignored.

    Raises GeometryError MK408 for an index ≥ the vertex count or negative other than −1 (all
    indices are checked, including those of an unterminated trailing polygon), MK410 when no
    triangle results.
    """
    verts = _vertex_rows(vertices)
    nv = len(verts)
    idx = _indices(coord_index, "Vertex")
    mask = (idx >= nv) | (idx < -1)
    bad = idx[mask]
    if len(bad):
        raise GeometryError(
            "MK408",
            _out_of_range_message(bad, nv, allow_separator=True),
            key="faces",
            index=int(np.flatnonzero(mask)[0]),
        )

    separators = np.flatnonzero(idx == -1)
    trailing = len(idx) - (int(separators[-1]) + 1 if len(separators) else 0)
    starts = np.concatenate([[0], separators[:-1] + 1]).astype(np.int64) if len(separators) else separators
    lengths = separators - starts

    keys: list[IntArray] = []
    parts: list[IntArray] = []
    tri_polygons = np.flatnonzero(lengths == 3)
    if len(tri_polygons):
        first = starts[tri_polygons]
        parts.append(np.stack([idx[first], idx[first + 1], idx[first + 2]], axis=1))
        keys.append(tri_polygons.astype(np.int64))
    quads = np.flatnonzero(lengths == 4)
    if len(quads):
        corners = idx[starts[quads][:, None] + np.arange(4)[None, :]]  # (q, 4)
        convex = _strictly_convex_quads(verts[corners])
        if np.any(convex):
            # What the ear clipper gives for a strictly convex quad: (3, 0, 1), (2, 3, 1).
            c = corners[convex]
            parts.append(np.stack([c[:, [3, 0, 1]], c[:, [2, 3, 1]]], axis=1).reshape(-1, 3))
            keys.append(np.repeat(quads[convex], 2).astype(np.int64))
        general = np.concatenate([quads[~convex], np.flatnonzero(lengths > 4)])
    else:
        general = np.flatnonzero(lengths > 4)
    for p in np.sort(general):
        polygon = idx[starts[p] : starts[p] + lengths[p]]
        local = _triangulate_polygon(verts[polygon])
        if len(local):
            parts.append(polygon[local])
            keys.append(np.full(len(local), p, dtype=np.int64))
    if not parts:
        raise GeometryError("MK410", "There is no valid polygon to triangulate.", key="faces")
    faces = np.concatenate(parts, axis=0)
    order = np.argsort(np.concatenate(keys), kind="stable")  # polygon order, as Choreonoid emits
    return TriangleMeshData(vertices=verts, faces=faces[order].astype(np.int64)), trailing


def triangle_mesh(vertices: Sequence[float], triangles: Sequence[int]) -> TriangleMeshData:
    """A TriangleMesh: flat vertex list and flat index triples (a trailing partial triple is ignored;
    the caller can warn from ``len(triangles) % 3``).

    Choreonoid does not check the indices (out of range is undefined behaviour), so we raise
    GeometryError MK408 for any index outside 0 … vertex count − 1.
    """
    verts = _vertex_rows(vertices)
    idx = _indices(triangles, "Vertex")
    idx = idx[: len(idx) // 3 * 3]
    mask = (idx >= len(verts)) | (idx < 0)
    bad = idx[mask]
    if len(bad):
        raise GeometryError(
            "MK408",
            _out_of_range_message(bad, len(verts), allow_separator=False),
            key="faces",
            index=int(np.flatnonzero(mask)[0]),
        )
    return TriangleMeshData(vertices=verts, faces=idx.reshape(-1, 3))


# ---- volume and winding --------------------------------------------------------------------------


def signed_volume(mesh: TriangleMeshData) -> float:
    """Σ v0·(v1 × v2) / 6 over the triangles: the enclosed volume of a closed mesh, positive when the
    triangles face outward (counter-clockwise seen from outside). Origin-dependent for open meshes."""
    faces = np.asarray(mesh.faces, dtype=np.int64).reshape(-1, 3)
    if len(faces) == 0:
        return 0.0
    v = np.asarray(mesh.vertices, dtype=np.float64)
    a, b, c = v[faces[:, 0]], v[faces[:, 1]], v[faces[:, 2]]
    return float(np.einsum("ij,ij->", a, np.cross(b, c)) / 6.0)


def flip_if_inward(mesh: TriangleMeshData) -> TriangleMeshData:
    """For a closed mesh: a copy with every triangle reversed if its signed volume is negative,
    otherwise the mesh itself. (The caller decides whether the mesh is closed; for an open one
    the sign of the signed volume has no meaning.)"""
    if signed_volume(mesh) >= 0.0:
        return mesh
    faces = np.asarray(mesh.faces, dtype=np.int64).reshape(-1, 3)
    return TriangleMeshData(
        vertices=np.array(mesh.vertices, dtype=np.float64), faces=faces[:, [0, 2, 1]].copy()
    )


# ---- polygon triangulation -----------------------------------------------------------------------


def _strictly_convex_quads(quads: FloatArray) -> NDArray[np.bool_]:
    """For (q, 4, 3) quads: True where every corner turns the same way as the Newell normal by a
    clear margin, so that the ear clipper would cut the first corner off and keep the rest; such
    quads are triangulated in bulk. Anything else (concave, collinear, degenerate) goes the slow way.
    """
    nxt = np.roll(quads, -1, axis=1)
    prv = np.roll(quads, 1, axis=1)
    normal = np.cross(quads, nxt).sum(axis=1)
    length = np.linalg.norm(normal, axis=1)
    extent = np.max(np.ptp(quads, axis=1), axis=1)
    safe = np.where(length > 0.0, length, 1.0)
    turns = np.einsum("qij,qj->qi", np.cross(quads - prv, nxt - quads), normal / safe[:, None])
    return (length > 0.0) & np.all(turns > 1e-9 * (extent * extent)[:, None], axis=1)


def _project_polygon(points: FloatArray) -> FloatArray | None:
    """2-D coordinates of a (possibly non-planar) polygon in the plane of its Newell normal, in a
    basis chosen so that the polygon is counter-clockwise; None if it has no area."""
    centred = points - points.mean(axis=0)
    normal = np.cross(centred, np.roll(centred, -1, axis=0)).sum(axis=0)
    length = float(np.linalg.norm(normal))
    extent = float(np.max(np.ptp(centred, axis=0)))
    if extent == 0.0 or length <= 1e-12 * extent * extent:
        return None
    nz = normal / length
    helper = np.zeros(3)
    helper[int(np.argmin(np.abs(nz)))] = 1.0
    e1 = np.cross(helper, nz)
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(nz, e1)  # e1 × e2 = n: the polygon winds counter-clockwise in (e1, e2)
    return np.stack([centred @ e1, centred @ e2], axis=1)


def _triangulate_polygon(points: FloatArray) -> IntArray:
    """Ear-clip one polygon given by its vertices in order ((k, 3) array).

    Returns local index triples; every triangle (prev, ear, next) follows the polygon's own order,
    so it keeps the polygon's orientation. 3 vertices are returned as they are (as Choreonoid
    does); polygons without area give nothing; collinear vertices are dropped without a triangle.
    """
    k = len(points)
    if k < 3:
        return _empty_faces()
    if k == 3:
        return np.array([[0, 1, 2]], dtype=np.int64)
    xy = _project_polygon(points)
    if xy is None:
        return _empty_faces()
    triangles = _ear_clip_ccw(xy)
    if not triangles:
        return _empty_faces()
    return np.array(triangles, dtype=np.int64)


def _ear_clip_ccw(xy: FloatArray) -> list[tuple[int, int, int]]:
    """Ear clipping of a counter-clockwise simple polygon in O(n·r) (r = reflex vertices).

    Each vertex keeps its turn (cross product of its two edges). Only non-convex vertices can lie
    inside a candidate ear, so containment is tested against them alone (vectorised when there are
    many); after a clip only the two neighbours change, and only they are queued again. A vertex
    on an ear's boundary blocks it. If a whole pass finds no ear (the polygon is not simple, e.g. a
    warped face projected onto a plane), the most convex vertex is clipped anyway so that the face
    is still covered; when no convex vertex is left the rest is dropped.
    """
    k = len(xy)
    xs: list[float] = xy[:, 0].tolist()
    ys: list[float] = xy[:, 1].tolist()
    xs_arr, ys_arr = xy[:, 0].copy(), xy[:, 1].copy()
    extent = max(float(np.ptp(xy[:, 0])), float(np.ptp(xy[:, 1])))
    tol = 1e-12 * extent * extent
    prv = [k - 1, *range(k - 1)]
    nxt = [*range(1, k), 0]
    alive = [True] * k

    def turn(i: int) -> float:
        p, q = prv[i], nxt[i]
        return (xs[i] - xs[p]) * (ys[q] - ys[i]) - (ys[i] - ys[p]) * (xs[q] - xs[i])

    turns = [turn(i) for i in range(k)]
    nonconvex = {i for i in range(k) if turns[i] <= tol}

    def blocked(v: int) -> bool:
        a, c = prv[v], nxt[v]
        ax, ay, bx, by, cx, cy = xs[a], ys[a], xs[v], ys[v], xs[c], ys[c]
        candidates = nonconvex - {a, v, c}
        if not candidates:
            return False
        if len(candidates) <= _VECTORISE_ABOVE:
            for w in candidates:
                px, py = xs[w], ys[w]
                if (
                    (bx - ax) * (py - ay) - (by - ay) * (px - ax) >= -tol
                    and (cx - bx) * (py - by) - (cy - by) * (px - bx) >= -tol
                    and (ax - cx) * (py - cy) - (ay - cy) * (px - cx) >= -tol
                ):
                    return True
            return False
        w_idx = np.fromiter(candidates, dtype=np.int64, count=len(candidates))
        qx, qy = xs_arr[w_idx], ys_arr[w_idx]
        inside = (
            ((bx - ax) * (qy - ay) - (by - ay) * (qx - ax) >= -tol)
            & ((cx - bx) * (qy - by) - (cy - by) * (qx - bx) >= -tol)
            & ((ax - cx) * (qy - cy) - (ay - cy) * (qx - cx) >= -tol)
        )
        return bool(inside.any())

    triangles: list[tuple[int, int, int]] = []
    queue: deque[int] = deque(range(k))
    remaining = k
    head = 0
    stalled = False

    def remove(v: int) -> None:
        nonlocal remaining, head, stalled
        p, q = prv[v], nxt[v]
        nxt[p], prv[q] = q, p
        alive[v] = False
        nonconvex.discard(v)
        remaining -= 1
        head = p
        stalled = False
        for w in (p, q):
            turns[w] = turn(w)
            if turns[w] <= tol:
                nonconvex.add(w)
            else:
                nonconvex.discard(w)
            queue.append(w)

    while remaining > 3:
        if not queue:
            if stalled:
                # No ear in a whole pass: not a simple polygon. Clip the most convex vertex.
                live = [i for i in range(k) if alive[i]]
                best = max(live, key=lambda i: (turns[i], -i))
                if turns[best] <= tol:
                    return triangles
                triangles.append((prv[best], best, nxt[best]))
                remove(best)
                continue
            stalled = True
            queue.extend(i for i in range(k) if alive[i])
            continue
        v = queue.popleft()
        if not alive[v]:
            continue
        t = turns[v]
        if abs(t) <= tol:
            remove(v)  # collinear (or a zero-width spike): no area to cover
        elif t > 0.0 and not blocked(v):
            triangles.append((prv[v], v, nxt[v]))
            remove(v)
    if remaining == 3 and turns[head] > tol:
        triangles.append((prv[head], head, nxt[head]))
    return triangles
