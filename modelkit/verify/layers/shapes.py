"""Layer 1's collision-shape checks: each link's collision shapes in an engine against the source.

Per link, the shapes are compared as a multiset: grouped by type, then paired greedily by the
smallest (position + rotation + relative size) difference. Three quantities, each the worst over
the links, naming the source link:

* ``shape-set``: how many shapes have no partner (a count; tolerance 0): a shape lost, added, or
  of another type;
* ``shape-size``: the largest size difference of a pair relative to the source's largest
  dimension (box full edges, sphere radius, cylinder/capsule radius and length, ellipsoid radii,
  a mesh's scale: its vertices are not compared);
* ``shape-pose``: the larger of the position error (m) and the rotation error (rad) of a pair, where
  the rotation error respects each shape's symmetry: none for a sphere, the angle between the axes
  up to sign for a cylinder or capsule (a turned cylinder is the classic Choreonoid Y-axis error),
  the smallest angle over the box's (ellipsoid's) half turns about its own axes, the full angle
  for a mesh.

A primitive the engine's file format cannot hold (a cone anywhere; capsule and ellipsoid in URDF)
is written as a mesh by every writer (with a note): it is expected as a mesh of scale 1 at the same
pose. A source mesh whose file is missing is left out (the writers drop it, MK805), and so is, for
MuJoCo, a primitive with a size that is not positive (validate's MK416: a sphere of radius 0, which
MuJoCo refuses and the MJCF writer leaves out, MK871; PyBullet collides with a point there, so it is
compared there). Engines that report no shapes (Pinocchio, yourdfpy, Drake) get a Skip saying so,
and so do the shapes left out.
"""

from __future__ import annotations

import math
from collections import Counter
from typing import TYPE_CHECKING

import numpy as np

from modelkit.verify.engines.protocol import Array, Check, ShapeFacts, Skip, StaticFacts

if TYPE_CHECKING:
    from modelkit.verify.layers.common import Loaded

# Source primitives each engine's input format cannot hold: the writers mesh them.
MESHED: dict[str, tuple[str, ...]] = {
    "mujoco": ("cone",),
    "pybullet": ("capsule", "cone", "ellipsoid"),
    "drake": ("cone",),
    "drake-urdf": ("capsule", "cone", "ellipsoid"),
}
DEFAULT_MESHED = ("capsule", "cone", "ellipsoid")
MISSING = "missing-mesh"  # a source mesh whose file is not there: no writer can write it (MK805)
# engines whose file cannot hold a primitive with a size that is not positive (the writer leaves it out)
REFUSE_DEGENERATE = ("mujoco",)
_BOX_TURNS = [np.diag(d) for d in ((1.0, 1.0, 1.0), (1.0, -1.0, -1.0), (-1.0, 1.0, -1.0), (-1.0, -1.0, 1.0))]


def _angle(a: Array, b: Array) -> float:
    """The angle of the rotation between two rotation matrices (radians, accurate near zero)."""
    r = np.asarray(a).T @ np.asarray(b)
    s = 0.5 * float(np.linalg.norm([r[2, 1] - r[1, 2], r[0, 2] - r[2, 0], r[1, 0] - r[0, 1]]))
    c = 0.5 * (float(np.trace(r)) - 1.0)
    return math.atan2(s, c)


def _axis_angle(a: Array, b: Array, signed: bool) -> float:
    """The angle between two unit vectors, up to sign unless ``signed`` (accurate near zero)."""
    dot = float(a @ b)
    cross = float(np.linalg.norm(np.cross(a, b)))
    return math.atan2(cross, dot if signed else abs(dot))


def rotation_error(kind: str, a: Array, b: Array) -> float:
    """The rotation error of two shapes of type ``kind``, modulo the shape's symmetry."""
    if kind == "sphere":
        return 0.0
    if kind in ("cylinder", "capsule", "cone"):
        return _axis_angle(np.asarray(a)[:, 2], np.asarray(b)[:, 2], signed=kind == "cone")
    if kind in ("box", "ellipsoid"):
        return min(_angle(np.asarray(a) @ d, b) for d in _BOX_TURNS)
    return _angle(a, b)


def size_error(a: Array, b: Array) -> float:
    x, y = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    if x.shape != y.shape:
        return math.inf
    diff = float(np.max(np.abs(x - y))) if x.size else 0.0
    return diff / max(float(np.max(np.abs(x))), 1e-300) if diff else 0.0


def expected(shape: ShapeFacts, meshed: tuple[str, ...]) -> ShapeFacts:
    """The source shape as the engine's file can hold it (a meshed primitive: a mesh of scale 1)."""
    if shape.type in meshed:
        return ShapeFacts("mesh", np.ones(3), shape.pose)
    return shape


def _degenerate(shape: ShapeFacts) -> bool:
    """A primitive with a size that is not positive (a sphere of radius 0: validate's MK416)."""
    size = np.asarray(shape.size, dtype=float)
    return shape.type not in ("mesh", MISSING) and size.size > 0 and bool(np.any(size <= 0.0))


def _refused(shape: ShapeFacts, engine: str) -> bool:
    return engine in REFUSE_DEGENERATE and _degenerate(shape)


def _pair_cost(a: ShapeFacts, b: ShapeFacts) -> tuple[float, float, float]:
    position = float(np.linalg.norm(a.pose.translation - b.pose.translation))
    rotation = rotation_error(a.type, a.pose.rotation, b.pose.rotation)
    return position, rotation, size_error(a.size, b.size)


def _vec(v: Array) -> str:
    return "[" + ", ".join(f"{x:.9g}" for x in np.asarray(v).ravel()) + "]"


def _census(shapes: list[ShapeFacts]) -> str:
    counts = Counter(s.type for s in shapes)
    return ", ".join(f"{n} {kind}" for kind, n in sorted(counts.items())) or "none"


def compare(source: StaticFacts, facts: StaticFacts, eng: Loaded) -> list[Check]:
    """The ``shape-set``, ``shape-size`` and ``shape-pose`` checks of one engine (none when the
    engine reports no shapes: see :func:`skips`)."""
    if not facts.shapes:
        return []
    label = eng.label
    meshed = MESHED.get(label, DEFAULT_MESHED)
    set_error, set_where, set_detail = 0, "", ""
    size_worst, size_where, size_detail = 0.0, "", ""
    pose_worst, pose_where, pose_detail = 0.0, "", ""
    compared = 0
    for link, source_shapes in source.shapes.items():
        got = facts.shapes.get(eng.link(link))
        if got is None:
            continue  # a missing link: the link-set check reports it
        want = [expected(s, meshed) for s in source_shapes if s.type != MISSING and not _refused(s, label)]
        unmatched = 0
        for kind in sorted({s.type for s in want} | {s.type for s in got}):
            a = [s for s in want if s.type == kind]
            b = [s for s in got if s.type == kind]
            unmatched += abs(len(a) - len(b))
            costs = sorted(((sum(_pair_cost(x, y)), i, j) for i, x in enumerate(a) for j, y in enumerate(b)),
                           key=lambda t: (t[0] if math.isfinite(t[0]) else math.inf, t[1], t[2]))
            used_a: set[int] = set()
            used_b: set[int] = set()
            for _, i, j in costs:
                if i in used_a or j in used_b:
                    continue
                used_a.add(i)
                used_b.add(j)
                compared += 1
                x, y = a[i], b[j]
                position, rotation, size = _pair_cost(x, y)
                if size > size_worst or math.isnan(size):
                    size_worst, size_where = size, link
                    what = "scale" if kind == "mesh" else "size"
                    size_detail = f"{kind} {what} {_vec(x.size)} read back as {_vec(y.size)}"
                worst = max(position, rotation)
                if worst > pose_worst or math.isnan(worst):
                    pose_worst, pose_where = worst, link
                    turned = "axis" if kind in ("cylinder", "capsule", "cone") else "frame"
                    axes = (f": axis {_vec(x.pose.rotation[:, 2])} read back as {_vec(y.pose.rotation[:, 2])}"
                            if turned == "axis" and rotation else "")
                    pose_detail = (f"{kind} at {_vec(x.pose.translation)} m read back at "
                                   f"{_vec(y.pose.translation)} m ({position:.3g} m away), its {turned} "
                                   f"turned by {rotation:.6g} rad{axes}")
        if unmatched > set_error:
            set_error, set_where = unmatched, link
            set_detail = f"collision shapes: source {_census(want)}, engine {_census(got)}"
    if not set_detail:
        set_detail = f"{compared} collision shapes, every link"
    checks = [
        Check(1, label, "shape-set", set_where, float(set_error), 0.0, set_detail),
        Check(1, label, "shape-size", size_where, math.inf if math.isnan(size_worst) else size_worst,
              eng.tolerance("shape-size"), size_detail or f"{compared} collision shapes"),
        Check(1, label, "shape-pose", pose_where, math.inf if math.isnan(pose_worst) else pose_worst,
              eng.tolerance("shape-pose"), pose_detail or f"{compared} collision shapes"),
    ]
    return checks


def skips(source: StaticFacts, eng: Loaded) -> list[Skip]:
    """What the shape checks of one engine left out, said rather than hidden: everything, for an
    engine that reports no shapes; source meshes whose file is missing (no writer can write them)."""
    if not eng.model.static().shapes:
        why = " (it is built from the source model itself)" if eng.label == "pinocchio" else ""
        return [Skip(1, eng.label, f"{eng.label} reports no collision shapes{why}: shape-set, shape-size and "
                                   "shape-pose not compared for it")]
    out = []
    missing = [link for link, shapes in source.shapes.items() for s in shapes if s.type == MISSING]
    if missing:
        out.append(Skip(1, eng.label, f"{len(missing)} collision mesh(es) of the source not compared: the "
                                      "file is missing, so no writer could write it (MK805); links: "
                                      f"{', '.join(sorted(set(missing)))}"))
    refused = [link for link, shapes in source.shapes.items() for s in shapes if _refused(s, eng.label)]
    if refused:
        links = ", ".join(sorted(set(refused)))
        out.append(Skip(1, eng.label, f"source finding MK416: {len(refused)} collision primitive(s) of the "
                                      f"source with a size that is not positive (links: {links}), which "
                                      f"{eng.label} refuses and the writer leaves out (MK871): not compared, "
                                      "not a conversion fault"))
    return out
