"""Axis-aligned bounding boxes of a link's shapes in the link frame, in plain floats (no numpy, no meshes).

A primitive's box is exact for its pose (a rotated box's box is the smallest axis-aligned box around it).
A mesh counts when its triangles are in memory (generated geometry) or when the reader has already
checked its file (:func:`modelkit.geometry.meshfiles.known_bounds`; the fast OBJ and glTF checks give the
corners too): validate never loads a mesh a second time for this, and a mesh it did not check (a file
with unit metadata) has no box.
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass

from modelkit import rot3
from modelkit.model import Box, Capsule, Cone, Cylinder, Ellipsoid, Geom, Mesh, Sphere
from modelkit.spatial import Pose


@dataclass(frozen=True)
class Aabb:
    """An axis-aligned box: centre and half extents, in the link frame."""

    centre: rot3.V3
    half: rot3.V3

    @property
    def low(self) -> rot3.V3:
        return rot3.sub(self.centre, self.half)

    @property
    def high(self) -> rot3.V3:
        return rot3.add(self.centre, self.half)

    @property
    def radius(self) -> float:
        """Half the box's diagonal."""
        return rot3.norm(self.half)

    def gap(self, other: Aabb) -> float:
        """Distance between the two boxes (0 when they touch or overlap)."""
        apart = [
            max(0.0, abs(self.centre[i] - other.centre[i]) - self.half[i] - other.half[i]) for i in range(3)
        ]
        return math.sqrt(sum(a * a for a in apart))

    def farthest(self, point: rot3.V3) -> float:
        """The largest distance from ``point`` to a point of the box."""
        return math.sqrt(sum((abs(point[i] - self.centre[i]) + self.half[i]) ** 2 for i in range(3)))


def local_box(geometry: object) -> Aabb | None:
    """The shape's box in its own frame (primitives along local Z); None for a mesh not in memory."""
    if isinstance(geometry, Box):
        sx, sy, sz = (abs(float(v)) for v in rot3.peek(geometry, "size"))
        return Aabb(rot3.ZERO3, (sx / 2, sy / 2, sz / 2))
    if isinstance(geometry, Sphere):
        r = abs(geometry.radius)
        return Aabb(rot3.ZERO3, (r, r, r))
    if isinstance(geometry, Capsule):
        r = abs(geometry.radius)
        return Aabb(rot3.ZERO3, (r, r, abs(geometry.length) / 2 + r))
    if isinstance(geometry, (Cylinder, Cone)):
        r = abs(geometry.radius)
        return Aabb(rot3.ZERO3, (r, r, abs(geometry.length) / 2))
    if isinstance(geometry, Ellipsoid):
        a, b, c = (abs(float(v)) for v in rot3.peek(geometry, "radii"))
        return Aabb(rot3.ZERO3, (a, b, c))
    if isinstance(geometry, Mesh):
        corners = _mesh_corners(geometry)
        if corners is None:
            return None
        scale = [float(v) for v in rot3.peek(geometry, "scale")]
        low = [corners[0][i] * scale[i] for i in range(3)]
        high = [corners[1][i] * scale[i] for i in range(3)]
        lo = [min(low[i], high[i]) for i in range(3)]
        hi = [max(low[i], high[i]) for i in range(3)]
        return Aabb(
            ((lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, (lo[2] + hi[2]) / 2),
            ((hi[0] - lo[0]) / 2, (hi[1] - lo[1]) / 2, (hi[2] - lo[2]) / 2),
        )
    return None


def _mesh_corners(mesh: Mesh) -> tuple[rot3.V3, rot3.V3] | None:
    """A mesh's lowest and highest corners in its file frame: from its triangles in memory, or from the
    mesh file the reader already loaded (its check of the file; nothing is loaded here, and a reader that
    loaded no mesh has not imported the mesh module)."""
    if mesh.data is not None:
        vertices = mesh.data.vertices
        if not len(vertices):
            return None
        low, high = vertices.min(axis=0), vertices.max(axis=0)
        return rot3.vec3(low), rot3.vec3(high)
    meshfiles = sys.modules.get("modelkit.geometry.meshfiles")
    if meshfiles is None or mesh.path is None or mesh.source_params.get("metadata"):
        return None
    found: tuple[rot3.V3, rot3.V3] | None = meshfiles.known_bounds(mesh.path, mesh.fragment)
    return found


def geom_box(geom: Geom, frame: Pose | None = None) -> Aabb | None:
    """The shape's box in the link frame, or in the frame where the link frame is at ``frame`` (None for a
    mesh that is only a file reference)."""
    local = local_box(geom.geometry)
    if local is None:
        return None
    (cx, cy, cz), (hx, hy, hz) = local.centre, local.half
    if not all(math.isfinite(v) for v in (cx, cy, cz, hx, hy, hz)):
        return None
    pose = geom.pose if frame is None or _is_identity(frame) else frame @ geom.pose
    (r0, r1, r2), (tx, ty, tz) = pose.rotation_tuple, pose.translation_tuple
    if r0 == (1.0, 0.0, 0.0) and r1 == (0.0, 1.0, 0.0) and r2 == (0.0, 0.0, 1.0):
        return Aabb((cx + tx, cy + ty, cz + tz), (hx, hy, hz))
    return Aabb(
        (r0[0] * cx + r0[1] * cy + r0[2] * cz + tx,
         r1[0] * cx + r1[1] * cy + r1[2] * cz + ty,
         r2[0] * cx + r2[1] * cy + r2[2] * cz + tz),
        (abs(r0[0]) * hx + abs(r0[1]) * hy + abs(r0[2]) * hz,
         abs(r1[0]) * hx + abs(r1[1]) * hy + abs(r1[2]) * hz,
         abs(r2[0]) * hx + abs(r2[1]) * hy + abs(r2[2]) * hz),
    )


def _is_identity(frame: Pose) -> bool:
    """Whether ``frame`` is exactly the identity (the pose of a body's own top link)."""
    return frame.translation_tuple == rot3.ZERO3 and frame.rotation_tuple == rot3.IDENTITY


def union(boxes: list[Aabb]) -> Aabb:
    """The box around several boxes (at least one)."""
    if len(boxes) == 1:
        return boxes[0]
    lows = [b.low for b in boxes]
    highs = [b.high for b in boxes]
    low = [min(b[i] for b in lows) for i in range(3)]
    high = [max(b[i] for b in highs) for i in range(3)]
    return Aabb(
        ((low[0] + high[0]) / 2, (low[1] + high[1]) / 2, (low[2] + high[2]) / 2),
        ((high[0] - low[0]) / 2, (high[1] - low[1]) / 2, (high[2] - low[2]) / 2),
    )


def shapes_box(geoms: list[Geom], frame: Pose | None = None) -> Aabb | None:
    """The box around all the shapes, or None when any of them has no box (a mesh file, a bad size)."""
    boxes = [geom_box(g, frame) for g in geoms]
    if not boxes or any(b is None for b in boxes):
        return None
    return union([b for b in boxes if b is not None])
