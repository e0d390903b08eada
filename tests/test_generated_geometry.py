"""Acceptance checks for modelkit.geometry.generated (body-format.md §4.6–§4.8, §6.4, Appendix A).

Every expectation here is derived independently of the code under test: shoelace areas, closed-form
volumes, rotation matrices written out by hand, or the spec's own reference formula (Appendix A).
"""

from __future__ import annotations

import itertools
import math
from collections import Counter
from typing import Any

import numpy as np
import pytest
import yaml

from modelkit.geometry.generated import (
    GeometryError,
    elevation_grid,
    extrusion,
    flip_if_inward,
    indexed_face_set,
    signed_volume,
    triangle_mesh,
)
from modelkit.model import TriangleMeshData

from .conftest import CORPUS

TRACKS_BODY = CORPUS / "choreonoid_ros2_mobile_robot_tutorial/model/mobile_robot_tracks.body"

VRML_SQUARE = [1, 1, 1, -1, -1, -1, -1, 1, 1, 1]  # clockwise in (u, v)
REVERSED_SQUARE = [1, 1, -1, 1, -1, -1, 1, -1, 1, 1]  # counter-clockwise

# Choreonoid share/model/misc/Torus.body (choreonoid/choreonoid, MIT licence): the Extrusion data.
TORUS_CROSS_SECTION = [
    1.0000, 0.0000, 0.9808, 0.1951, 0.9239, 0.3827,
    0.8315, 0.5556, 0.7071, 0.7071, 0.5556, 0.8315,
    0.3827, 0.9239, 0.1951, 0.9808, 0.0000, 1.0000,
    -0.1951, 0.9808, -0.3827, 0.9239, -0.5556, 0.8315,
    -0.7071, 0.7071, -0.8315, 0.5556, -0.9239, 0.3827,
    -0.9808, 0.1951, -1.0000, 0.0000, -0.9808, -0.1951,
    -0.9239, -0.3827, -0.8315, -0.5556, -0.7071, -0.7071,
    -0.5556, -0.8315, -0.3827, -0.9239, -0.1951, -0.9808,
    0.0000, -1.0000, 0.1951, -0.9808, 0.3827, -0.9239,
    0.5556, -0.8315, 0.7071, -0.7071, 0.8315, -0.5556,
    0.9239, -0.3827, 0.9808, -0.1951, 1.0000, 0.0000,
]  # fmt: skip
TORUS_SPINE = [
    1.0000, 0.0000, 0, 0.9808, 0.1951, 0, 0.9239, 0.3827, 0,
    0.8315, 0.5556, 0, 0.7071, 0.7071, 0, 0.5556, 0.8315, 0,
    0.3827, 0.9239, 0, 0.1951, 0.9808, 0, 0.0000, 1.0000, 0,
    -0.1951, 0.9808, 0, -0.3827, 0.9239, 0, -0.5556, 0.8315, 0,
    -0.7071, 0.7071, 0, -0.8315, 0.5556, 0, -0.9239, 0.3827, 0,
    -0.9808, 0.1951, 0, -1.0000, 0.0000, 0, -0.9808, -0.1951, 0,
    -0.9239, -0.3827, 0, -0.8315, -0.5556, 0, -0.7071, -0.7071, 0,
    -0.5556, -0.8315, 0, -0.3827, -0.9239, 0, -0.1951, -0.9808, 0,
    0.0000, -1.0000, 0, 0.1951, -0.9808, 0, 0.3827, -0.9239, 0,
    0.5556, -0.8315, 0, 0.7071, -0.7071, 0, 0.8315, -0.5556, 0,
    0.9239, -0.3827, 0, 0.9808, -0.1951, 0, 1.0000, 0.0000, 0,
]  # fmt: skip


# ---- independent reference helpers ---------------------------------------------------------------


def shoelace(flat_uv: list[float]) -> float:
    """Signed area of a polygon given as a flat u, v list (closing repeat allowed)."""
    pts = [(flat_uv[i], flat_uv[i + 1]) for i in range(0, len(flat_uv) - 1, 2)]
    if pts[0] == pts[-1]:
        pts = pts[:-1]
    total = 0.0
    for k, (x0, y0) in enumerate(pts):
        x1, y1 = pts[(k + 1) % len(pts)]
        total += x0 * y1 - x1 * y0
    return total / 2.0


def reference_volume(mesh: TriangleMeshData) -> float:
    """Signed volume by tetrahedra to an off-origin apex, in plain Python (closed meshes only)."""
    apex = (0.123, -0.456, 0.789)
    total = 0.0
    verts = mesh.vertices.tolist()
    for i, j, k in mesh.faces.tolist():
        a = [verts[i][c] - apex[c] for c in range(3)]
        b = [verts[j][c] - apex[c] for c in range(3)]
        d = [verts[k][c] - apex[c] for c in range(3)]
        total += (
            a[0] * (b[1] * d[2] - b[2] * d[1])
            - a[1] * (b[0] * d[2] - b[2] * d[0])
            + a[2] * (b[0] * d[1] - b[1] * d[0])
        )
    return total / 6.0


def boundary_edges(faces: np.ndarray) -> list[tuple[int, int]]:
    """Directed edges without their reversed twin (empty for a closed, consistently wound mesh)."""
    edges = Counter()
    for a, b, c in faces.tolist():
        for e in ((a, b), (b, c), (c, a)):
            edges[e] += 1
    return [e for e in edges if edges[(e[1], e[0])] == 0]


def rodrigues(axis: list[float], angle: float) -> np.ndarray:
    """cosθ·E + (1−cosθ)·aaᵀ + sinθ·[a]× with the axis exactly as given."""
    a = np.array(axis, dtype=float)
    k = np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])
    return math.cos(angle) * np.eye(3) + (1 - math.cos(angle)) * np.outer(a, a) + math.sin(angle) * k


def scp_straight(y_unit: np.ndarray) -> np.ndarray:
    """Spec Appendix A: what Choreonoid computes for a straight spine."""
    a = np.array([y_unit[2], 0.0, -y_unit[0]])
    th = math.acos(float(np.clip(y_unit[1], -1, 1)))
    k = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return math.cos(th) * np.eye(3) + (1 - math.cos(th)) * np.outer(a, a) + math.sin(th) * k


def face_normals(mesh: TriangleMeshData) -> np.ndarray:
    v, f = mesh.vertices, mesh.faces
    return np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])


def ring(mesh: TriangleMeshData, i: int, m: int) -> np.ndarray:
    return mesh.vertices[i * m : (i + 1) * m]


def cs_points(flat_uv: list[float]) -> np.ndarray:
    return np.array(flat_uv, dtype=float).reshape(-1, 2)


def torus_data(n: int, m: int, big_r: float, small_r: float) -> tuple[list[float], list[float]]:
    """A closed circular spine (n segments, XY plane) and a closed unit-circle cross-section (m)."""
    spine: list[float] = []
    cross: list[float] = []
    for k in range(n):
        a = 2 * math.pi * k / n
        spine += [big_r * math.cos(a), big_r * math.sin(a), 0.0]
    spine += spine[:3]
    for k in range(m):
        a = 2 * math.pi * k / m
        cross += [math.cos(a), math.sin(a)]
    cross += cross[:2]
    return spine, cross


def polygonal_torus_volume(n: int, m: int, big_r: float, small_r: float) -> float:
    """Exact volume of the faceted torus: n wedges of sin(2π/n)·R·A (A = regular m-gon area)."""
    area = 0.5 * m * small_r**2 * math.sin(2 * math.pi / m)
    return n * math.sin(2 * math.pi / n) * big_r * area


# ---- Extrusion: winding and the straight-spine frame ---------------------------------------------


def test_vrml_square_is_inward_minus_four() -> None:
    mesh, report = extrusion(VRML_SQUARE, [0, 0, 0, 0, 1, 0])
    assert shoelace(VRML_SQUARE) == -4.0  # clockwise
    assert signed_volume(mesh) == pytest.approx(-4.0, abs=1e-12)
    assert reference_volume(mesh) == pytest.approx(-4.0, abs=1e-12)
    assert len(mesh.faces) == 4 * 2 + 2 + 2
    assert boundary_edges(mesh.faces) == []
    assert report.straight and not report.mirrored and not report.oblique_straight
    # spine along +Y: S = identity, so (u, v) ↦ (u, y, v)
    uv = cs_points(VRML_SQUARE)[:4]
    np.testing.assert_allclose(ring(mesh, 1, 4), np.column_stack([uv[:, 0], np.ones(4), uv[:, 1]]))


def test_reversed_square_is_outward_plus_four() -> None:
    mesh, _ = extrusion(REVERSED_SQUARE, [0, 0, 0, 0, 1, 0])
    assert shoelace(REVERSED_SQUARE) == 4.0
    assert signed_volume(mesh) == pytest.approx(4.0, abs=1e-12)
    assert reference_volume(mesh) == pytest.approx(4.0, abs=1e-12)


def test_minus_y_spine_is_a_point_reflection() -> None:
    spine = [0, 1, 0, 0, 0, 0]
    mesh, report = extrusion(VRML_SQUARE, spine)
    assert report.mirrored and report.straight and not report.oblique_straight
    uv = cs_points(VRML_SQUARE)[:4]
    # S = −E: (u, v) ↦ (−u, 0, −v) + spine point
    np.testing.assert_allclose(
        ring(mesh, 0, 4), np.column_stack([-uv[:, 0], np.ones(4), -uv[:, 1]]), atol=1e-15
    )
    np.testing.assert_allclose(
        ring(mesh, 1, 4), np.column_stack([-uv[:, 0], np.zeros(4), -uv[:, 1]]), atol=1e-15
    )
    # spec: the reflection reverses the winding, so the clockwise square now faces outward: +4
    assert signed_volume(mesh) == pytest.approx(4.0, abs=1e-12)
    assert reference_volume(mesh) == pytest.approx(4.0, abs=1e-12)
    centre = np.array([0.0, 0.5, 0.0])
    v, f = mesh.vertices, mesh.faces
    centroids = v[f].mean(axis=1)
    assert np.all(np.einsum("ij,ij->i", face_normals(mesh), centroids - centre) > 0)  # every triangle outward

    # VRML-intended: the proper rotation Rx(π), (u, v) ↦ (u, 0, −v); the clockwise square is inward again.
    vrml, vrml_report = extrusion(VRML_SQUARE, spine, faithful=False)
    np.testing.assert_allclose(
        ring(vrml, 0, 4), np.column_stack([uv[:, 0], np.ones(4), -uv[:, 1]]), atol=1e-15
    )
    assert signed_volume(vrml) == pytest.approx(-4.0, abs=1e-12)
    assert vrml_report.mirrored  # the report describes Choreonoid, whatever faithful says


def find_extrusion(node: Any) -> dict[str, Any] | None:
    if isinstance(node, dict):
        if node.get("type") == "Extrusion":
            return node
        children = list(node.values())
    elif isinstance(node, list):
        children = node
    else:
        return None
    for child in children:
        found = find_extrusion(child)
        if found is not None:
            return found
    return None


@pytest.mark.skipif(not TRACKS_BODY.exists(), reason="tutorial corpus not available")
def test_tutorial_track_cross_section_volume() -> None:
    node = find_extrusion(yaml.safe_load(TRACKS_BODY.read_text()))
    assert node is not None
    cross = [float(x) for x in node["crossSection"]]
    spine = [float(x) for x in node["spine"]]
    assert spine == [0, -0.03, 0, 0, 0.03, 0]
    area = shoelace(cross)
    expected = area * 0.06  # spine length
    mesh, report = extrusion(cross, spine)
    assert area > 0
    assert signed_volume(mesh) == pytest.approx(expected, rel=1e-12)
    assert reference_volume(mesh) == pytest.approx(expected, rel=1e-9)
    assert signed_volume(mesh) == pytest.approx(0.00223, abs=5e-6)
    assert boundary_edges(mesh.faces) == []
    assert not report.mirrored and not report.oblique_straight and not report.open_cross_section_with_caps


# ---- Extrusion: closed spines -------------------------------------------------------------------


def test_torus_body_volume_and_bounds() -> None:
    mesh, report = extrusion(TORUS_CROSS_SECTION, TORUS_SPINE, scale=[0.3, 0.3])
    assert not report.straight
    assert len(mesh.vertices) == 32 * 32  # closing points of both lists removed
    assert len(mesh.faces) == 32 * 32 * 2  # sides only: a closed spine has no caps
    assert boundary_edges(mesh.faces) == []
    volume = signed_volume(mesh)
    assert reference_volume(mesh) == pytest.approx(volume, rel=1e-9)
    # the file's 4-digit circle is a regular 32-gon to ~1e-4
    assert volume == pytest.approx(polygonal_torus_volume(32, 32, 1.0, 0.3), rel=1e-3)
    assert volume == pytest.approx(1.754, abs=1e-3)
    analytic = 2 * math.pi**2 * 1.0 * 0.3**2
    assert analytic == pytest.approx(1.777, abs=1e-3)
    assert abs(volume - analytic) / analytic < 0.015
    np.testing.assert_allclose(mesh.vertices.min(axis=0), [-1.3, -1.3, -0.3], atol=1e-4)
    np.testing.assert_allclose(mesh.vertices.max(axis=0), [1.3, 1.3, 0.3], atol=1e-4)


def test_torus_volume_converges_to_analytic() -> None:
    big_r, small_r = 2.0, 0.5
    analytic = 2 * math.pi**2 * big_r * small_r**2
    errors = []
    for n in (8, 16, 32, 64, 128):
        spine, cross = torus_data(n, n, big_r, small_r)
        mesh, report = extrusion(cross, spine, scale=[small_r, small_r])
        assert not report.straight and not report.open_cross_section_with_caps
        assert len(mesh.faces) == n * n * 2
        volume = signed_volume(mesh)
        assert volume == pytest.approx(polygonal_torus_volume(n, n, big_r, small_r), rel=1e-9)
        errors.append(abs(volume - analytic) / analytic)
        np.testing.assert_allclose(
            mesh.vertices.max(axis=0), [big_r + small_r, big_r + small_r, small_r], atol=1e-9
        )
    assert all(later < earlier for earlier, later in itertools.pairwise(errors))
    assert errors[-1] < 1e-3


def test_closed_spine_never_gets_caps() -> None:
    square_loop = [0, 0, 0, 2, 0, 0, 2, 0, 2, 0, 0, 2, 0, 0, 0]  # closed, in the X–Z plane
    open_cs = [0.1, 0.1, 0.1, -0.1, -0.1, -0.1]  # three points, not closed
    mesh, report = extrusion(open_cs, square_loop)
    assert len(mesh.faces) == 4 * 2 * 2  # 4 spine segments × 2 cross-section segments × 2
    assert not report.open_cross_section_with_caps


# ---- Extrusion: oblique, horizontal and +Z spines ------------------------------------------------


def scp_columns(spine: list[float], faithful: bool) -> np.ndarray:
    """Recover S at the first spine point from vertices: (1,0) ↦ S·e_x, (0,1) ↦ S·e_z, and with the
    orientation Rx(−π/2), which takes e_z to e_y, (0,1) ↦ S·e_y."""
    cross = [1, 0, 0, 1, 0, 0]
    origin = np.array(spine[:3], dtype=float)
    plain, _ = extrusion(cross, spine, faithful=faithful)
    turned, _ = extrusion(cross, spine, orientation=[1, 0, 0, -math.pi / 2], faithful=faithful)
    sx = plain.vertices[0] - origin
    sz = plain.vertices[1] - origin
    sy = turned.vertices[1] - origin
    return np.column_stack([sx, sy, sz])


def test_oblique_straight_spine_is_sheared() -> None:
    d = np.array([0.22, 0.27, -0.13])
    spine = [0, 0, 0, *d.tolist()]
    y = d / np.linalg.norm(d)
    c = y[1]
    s2 = 1 - c * c
    expected_det = (c + (1 - c) * s2) * (c * c + s2 * s2)  # eigen-decomposition of the formula
    assert expected_det == pytest.approx(0.6424, abs=1e-4)

    faithful = scp_columns(spine, faithful=True)
    np.testing.assert_allclose(faithful, scp_straight(y), atol=1e-12)
    assert np.linalg.det(faithful) == pytest.approx(expected_det, rel=1e-9)
    assert round(float(np.linalg.det(faithful)), 2) == 0.64
    assert np.all(np.linalg.norm(faithful, axis=0) < 0.95)  # columns shrunk

    intended = scp_columns(spine, faithful=False)
    np.testing.assert_allclose(intended.T @ intended, np.eye(3), atol=1e-12)
    assert np.linalg.det(intended) == pytest.approx(1.0, abs=1e-12)
    np.testing.assert_allclose(intended[:, 1], y, atol=1e-12)  # takes +Y to the spine direction

    mesh_f, report = extrusion(VRML_SQUARE, spine)
    mesh_v, _ = extrusion(VRML_SQUARE, spine, faithful=False)
    assert report.oblique_straight and report.straight and not report.mirrored
    assert np.max(np.abs(mesh_f.vertices - mesh_v.vertices)) > 0.1
    # prism volume: A_uv · det[S·e_x, d, S·e_z]
    sf = scp_straight(y)
    assert signed_volume(mesh_f) == pytest.approx(
        -4.0 * np.linalg.det(np.column_stack([sf[:, 0], d, sf[:, 2]]))
    )
    assert signed_volume(mesh_v) == pytest.approx(-4.0 * float(np.linalg.norm(d)))


def test_spine_along_plus_z_is_rx_plus_90() -> None:
    cross = [0.5, 0.25, -0.3, 0.1, 0.2, -0.4]
    spine = [1, 2, 3, 1, 2, 5]
    mesh, report = extrusion(cross, spine)
    uv = cs_points(cross)
    for i, point in enumerate((np.array([1, 2, 3.0]), np.array([1, 2, 5.0]))):
        expected = np.column_stack([uv[:, 0], -uv[:, 1], np.zeros(3)]) + point  # (u, v) ↦ (u, −v, 0)
        np.testing.assert_allclose(ring(mesh, i, 3), expected, atol=1e-15)
    assert not report.oblique_straight and not report.mirrored


def test_horizontal_oblique_spine_is_a_proper_rotation() -> None:
    d = np.array([0.6, 0.0, 0.8])
    columns = scp_columns([0, 0, 0, *d.tolist()], faithful=True)
    np.testing.assert_allclose(columns.T @ columns, np.eye(3), atol=1e-12)
    np.testing.assert_allclose(columns[:, 1], d, atol=1e-12)
    _, report = extrusion(VRML_SQUARE, [0, 0, 0, *d.tolist()])
    assert not report.oblique_straight and not report.mirrored


def test_steep_downward_spine_is_sheared_and_orientation_reversing() -> None:
    d = np.array([0.3, -1.0, 0.0])
    y = d / np.linalg.norm(d)
    c, s2 = y[1], 1 - y[1] ** 2
    expected_det = (c + (1 - c) * s2) * (c * c + s2 * s2)
    assert expected_det < 0
    columns = scp_columns([0, 0, 0, *d.tolist()], faithful=True)
    assert np.linalg.det(columns) == pytest.approx(expected_det, rel=1e-9)
    _, report = extrusion(VRML_SQUARE, [0, 0, 0, *d.tolist()])
    assert report.oblique_straight and report.mirrored


# ---- Extrusion: curved spines --------------------------------------------------------------------


def test_bent_spine_frames() -> None:
    cross = [0.1, 0.2, -0.3, 0.05, 0.0, -0.2]
    uv = cs_points(cross)
    mesh, report = extrusion(cross, [0, 0, 0, 0, 1, 0, 1, 1, 0])
    assert not report.straight
    # point 1: Y = s2 − s0 = (1,1,0)/√2, Z = (s2−s1)×(s0−s1) = (0,0,−1), X = Y×Z = (−1,1,0)/√2
    x1 = np.array([-1, 1, 0]) / math.sqrt(2)
    z1 = np.array([0, 0, -1.0])
    np.testing.assert_allclose(ring(mesh, 1, 3), uv[:, :1] * x1 + uv[:, 1:] * z1 + [0, 1, 0], atol=1e-15)
    # point 0 (open end): Y = s1 − s0 = +Y, Z of point 1, X = (−1,0,0): (u, v) ↦ (−u, 0, −v)
    np.testing.assert_allclose(
        ring(mesh, 0, 3), np.column_stack([-uv[:, 0], np.zeros(3), -uv[:, 1]]), atol=1e-15
    )
    same, _ = extrusion(cross, [0, 0, 0, 0, 1, 0, 1, 1, 0], faithful=False)  # curved: no difference
    np.testing.assert_array_equal(same.vertices, mesh.vertices)


def test_collinear_start_takes_first_defined_z() -> None:
    cross = [0.1, 0.2, -0.3, 0.05, 0.0, -0.2]
    uv = cs_points(cross)
    mesh, report = extrusion(cross, [0, 0, 0, 0, 1, 0, 0, 2, 0, 1, 2, 0])
    assert not report.straight
    # Z0 = Z1 = 0 take Z2 = (s3−s2)×(s1−s2) = (0,0,−1); Y1 = (0,2,0): ring 1 is (−u, 1, −v)
    np.testing.assert_allclose(
        ring(mesh, 1, 3), np.column_stack([-uv[:, 0], np.ones(3), -uv[:, 1]]), atol=1e-15
    )


def test_zigzag_spine_flips_z() -> None:
    cross = [0.1, 0.2, -0.3, 0.05, 0.0, -0.2]
    uv = cs_points(cross)
    spine = [0, 0, 0, 0, 1, 0, 1, 2, 0, 1, 3, 0]
    mesh, _ = extrusion(cross, spine)
    # Z1 = (0,0,−1); raw Z2 = (s3−s2)×(s1−s2) = (0,0,+1) points against it and is flipped to (0,0,−1)
    y2 = np.array([1.0, 2.0, 0.0]) / math.sqrt(5)  # s3 − s1
    z2 = np.array([0.0, 0.0, -1.0])
    x2 = np.cross(y2, z2)
    np.testing.assert_allclose(ring(mesh, 2, 3), uv[:, :1] * x2 + uv[:, 1:] * z2 + [1, 2, 0], atol=1e-15)


# ---- Extrusion: scale and orientation ------------------------------------------------------------


def test_per_point_scale() -> None:
    cross = [1, 0, 0, 1, -1, -1]
    uv = cs_points(cross)
    spine = [0, 0, 0, 0, 1, 0, 0, 3, 0]
    scales = [(1.0, 1.0), (2.0, 0.5), (0.25, 3.0)]
    mesh, _ = extrusion(cross, spine, scale=[x for pair in scales for x in pair])
    for i, ((su, sv), y) in enumerate(zip(scales, (0.0, 1.0, 3.0), strict=True)):
        expected = np.column_stack([uv[:, 0] * su, np.full(3, y), uv[:, 1] * sv])
        np.testing.assert_allclose(ring(mesh, i, 3), expected, atol=1e-15)
    single, _ = extrusion(cross, spine, scale=[2.0, 0.5])
    for i, y in enumerate((0.0, 1.0, 3.0)):
        np.testing.assert_allclose(
            ring(single, i, 3), np.column_stack([uv[:, 0] * 2, np.full(3, y), uv[:, 1] * 0.5])
        )
    more, _ = extrusion(cross, spine, scale=[1, 1, 2, 0.5, 0.25, 3, 9, 9])  # extra pairs ignored
    np.testing.assert_allclose(more.vertices, mesh.vertices)


def test_per_point_orientation() -> None:
    cross = [1, 0, 0, 1, -1, -1]
    uv = cs_points(cross)
    spine = [0, 0, 0, 0, 1, 0, 0, 2, 0]
    angles = [0.0, math.pi / 6, -math.pi / 2]
    mesh, report = extrusion(cross, spine, orientation=[x for a in angles for x in (0, 1, 0, a)])
    assert not report.non_unit_orientation_axis
    for i, a in enumerate(angles):
        # Ry(a)·(u, 0, v) = (u cos a + v sin a, 0, −u sin a + v cos a)
        expected = np.column_stack(
            [
                uv[:, 0] * math.cos(a) + uv[:, 1] * math.sin(a),
                np.full(3, float(i)),
                -uv[:, 0] * math.sin(a) + uv[:, 1] * math.cos(a),
            ]
        )
        np.testing.assert_allclose(ring(mesh, i, 3), expected, atol=1e-15)


def test_non_unit_orientation_axis() -> None:
    cross = [1, 0, 0, 1, -1, -1]
    uv = cs_points(cross)
    spine = [0, 0, 0, 0, 1, 0]
    a = 0.4
    faithful, report = extrusion(cross, spine, orientation=[0, 2, 0, a])
    assert report.non_unit_orientation_axis
    # Rodrigues with a = (0,2,0): cos·w + 2·sin·(a × w)/… → (u cos + 2 v sin, 0, v cos − 2 u sin)
    expected_f = np.column_stack(
        [
            uv[:, 0] * math.cos(a) + 2 * uv[:, 1] * math.sin(a),
            np.zeros(3),
            uv[:, 1] * math.cos(a) - 2 * uv[:, 0] * math.sin(a),
        ]
    )
    np.testing.assert_allclose(ring(faithful, 0, 3), expected_f, atol=1e-15)
    local = np.column_stack([uv[:, 0], np.zeros(3), uv[:, 1]])
    np.testing.assert_allclose(ring(faithful, 0, 3), local @ rodrigues([0, 2, 0], a).T, atol=1e-15)
    intended, _ = extrusion(cross, spine, orientation=[0, 2, 0, a], faithful=False)
    expected_v = np.column_stack(
        [
            uv[:, 0] * math.cos(a) + uv[:, 1] * math.sin(a),
            np.zeros(3),
            uv[:, 1] * math.cos(a) - uv[:, 0] * math.sin(a),
        ]
    )
    np.testing.assert_allclose(ring(intended, 0, 3), expected_v, atol=1e-15)
    _, zero_angle = extrusion(cross, spine, orientation=[0, 0, 0, 0])
    assert not zero_angle.non_unit_orientation_axis  # no rotation, the axis does not matter
    _, written = extrusion(cross, spine, orientation=[0.7071, 0, 0.7071, 1.0])
    assert not written.non_unit_orientation_axis  # four significant digits are unit enough


# ---- Extrusion: cross-section closure and caps ---------------------------------------------------


@pytest.mark.parametrize(
    ("begin", "end", "faces"), [(True, True, 12), (False, True, 10), (True, False, 10), (False, False, 8)]
)
def test_cap_face_counts(begin: bool, end: bool, faces: int) -> None:
    mesh, report = extrusion(REVERSED_SQUARE, [0, 0, 0, 0, 1, 0], begin_cap=begin, end_cap=end)
    assert len(mesh.vertices) == 2 * 4  # the closing point is not a vertex
    assert len(mesh.faces) == faces
    assert len(boundary_edges(mesh.faces)) == (0 if begin else 4) + (0 if end else 4)
    assert not report.open_cross_section_with_caps


def test_caps_face_outward_for_ccw_cross_section() -> None:
    mesh, _ = extrusion(REVERSED_SQUARE, [0, 0, 0, 0, 1, 0])
    normals = face_normals(mesh)
    begin, end = normals[8:10], normals[10:12]
    assert np.all(begin[:, 1] < 0) and np.all(end[:, 1] > 0)


def test_open_cross_section_leaves_a_gap() -> None:
    open_square = REVERSED_SQUARE[:-2]  # four points, last ≠ first
    mesh, report = extrusion(open_square, [0, 0, 0, 0, 1, 0])
    assert report.open_cross_section_with_caps
    assert len(mesh.vertices) == 8
    assert len(mesh.faces) == 3 * 2 + 2 + 2  # no side quad between point 3 and point 0
    gap = {frozenset(e) for e in boundary_edges(mesh.faces)}
    assert gap == {frozenset((3, 0)), frozenset((7, 4)), frozenset((0, 4)), frozenset((3, 7))}
    _, uncapped = extrusion(open_square, [0, 0, 0, 0, 1, 0], begin_cap=False, end_cap=False)
    assert not uncapped.open_cross_section_with_caps


def test_concave_cross_section_caps() -> None:
    ell = [0, 0, 2, 0, 2, 1, 1, 1, 1, 2, 0, 2, 0, 0]  # counter-clockwise L, area 3
    assert shoelace(ell) == 3.0
    mesh, _ = extrusion(ell, [0, 0, 0, 0, 2, 0])
    assert len(mesh.faces) == 6 * 2 + 4 + 4  # each cap: 6 − 2 triangles
    assert boundary_edges(mesh.faces) == []
    assert signed_volume(mesh) == pytest.approx(6.0, abs=1e-12)
    assert reference_volume(mesh) == pytest.approx(6.0, abs=1e-12)


# ---- Extrusion: errors and dropped numbers -------------------------------------------------------


@pytest.mark.parametrize(
    ("cross", "spine"),
    [
        (REVERSED_SQUARE, [0, 0, 0]),  # one spine point
        (REVERSED_SQUARE, [0, 1, 0, 0, 1, 0]),  # closed spine of one point
        (REVERSED_SQUARE, [0, 0, 0, 0, 0, 0, 0, 0, 0]),  # closed, 2 points left, not distinct
        (REVERSED_SQUARE, []),
        ([1, 1], [0, 0, 0, 0, 1, 0]),  # one cross-section point
        ([1, 1, 1, 1], [0, 0, 0, 0, 1, 0]),  # closed cross-section of one point
        ([1, 1, 1, 1, 1, 1], [0, 0, 0, 0, 1, 0]),  # closed, 2 points left, not distinct
        ([], [0, 0, 0, 0, 1, 0]),
    ],
)
def test_too_few_points_mk401(cross: list[float], spine: list[float]) -> None:
    with pytest.raises(GeometryError) as info:
        extrusion(cross, spine)
    assert info.value.code == "MK401"


def test_two_distinct_points_suffice() -> None:
    mesh, _ = extrusion([1, 1, -1, -1], [0, 0, 0, 0, 1, 0, 0, 0, 0])  # closed spine, 2 points left
    assert len(mesh.vertices) == 4


@pytest.mark.parametrize("key", ["scale", "orientation"])
def test_count_mismatch_mk402(key: str) -> None:
    spine = [0, 0, 0, 0, 1, 0, 0, 2, 0]  # 3 points
    values = [1.0, 1.0, 1.0, 1.0] if key == "scale" else [0, 1, 0, 0.1, 0, 1, 0, 0.2]  # 2 entries
    with pytest.raises(GeometryError) as info:
        extrusion(REVERSED_SQUARE, spine, **{key: values})
    assert info.value.code == "MK402"


def test_count_is_against_spine_without_closing_point() -> None:
    loop = [0, 0, 0, 1, 0, 0, 1, 0, 1, 0, 0, 0]  # 4 points, closed → 3
    mesh, _ = extrusion([0.1, 0, 0, 0.1, -0.1, -0.1], loop, scale=[1, 1, 1, 1, 1, 1])
    assert len(mesh.vertices) == 3 * 3
    with pytest.raises(GeometryError) as info:
        extrusion([0.1, 0, 0, 0.1, -0.1, -0.1], loop, scale=[1, 1, 1, 1])
    assert info.value.code == "MK402"


def test_dropped_numbers() -> None:
    mesh, report = extrusion(
        [*REVERSED_SQUARE, 7.0],  # one extra number
        [0, 0, 0, 0, 1, 0, 5.0],  # one extra
        orientation=[0, 1, 0, 0.0, 9.0, 9.0],  # two extra (one quadruple used)
        scale=[1.0, 1.0, 3.0],  # one extra (TankBody.body style)
    )
    assert report.dropped_numbers == {"cross_section": 1, "spine": 1, "orientation": 2, "scale": 1}
    assert signed_volume(mesh) == pytest.approx(4.0, abs=1e-12)
    _, clean = extrusion(REVERSED_SQUARE, [0, 0, 0, 0, 1, 0])
    assert clean.dropped_numbers == {}


def test_deterministic() -> None:
    args = (TORUS_CROSS_SECTION, TORUS_SPINE)
    first, _ = extrusion(*args, scale=[0.3, 0.3])
    second, _ = extrusion(*args, scale=[0.3, 0.3])
    assert np.array_equal(first.vertices, second.vertices) and np.array_equal(first.faces, second.faces)
    assert first.vertices.dtype == np.float64 and first.faces.dtype == np.int64


# ---- ElevationGrid -------------------------------------------------------------------------------


def test_elevation_grid_layout_and_winding() -> None:
    heights = [0.0, 0.1, 0.2, 0.3, 0.4, 0.5]  # x fastest: 3 × 2
    mesh = elevation_grid(3, 2, 0.5, 2.0, heights)
    assert mesh.vertices.shape == (6, 3) and mesh.faces.shape == (2 * 2, 3)
    np.testing.assert_allclose(mesh.vertices[4], [0.5, 0.4, 2.0])  # x = 1, z = 1
    np.testing.assert_allclose(mesh.vertices[2], [1.0, 0.2, 0.0])  # x = 2, z = 0
    assert np.all(face_normals(mesh)[:, 1] > 0)  # ccw faces +Y
    # first cell (p00, p01, p11), (p00, p11, p10) with p_xz = z·3 + x
    assert mesh.faces[:2].tolist() == [[0, 3, 4], [0, 4, 1]]
    flipped = elevation_grid(3, 2, 0.5, 2.0, heights, ccw=False)
    assert np.all(face_normals(flipped)[:, 1] < 0)
    flat = elevation_grid(4, 3, 0.5, 2.0, [0.0] * 12)
    projected = 0.5 * np.abs(face_normals(flat)[:, 1]).sum()
    assert projected == pytest.approx(3 * 0.5 * 2 * 2.0)  # area of the grid


@pytest.mark.parametrize(("xd", "zd", "n"), [(3, 2, 5), (3, 2, 7), (1, 4, 4), (0, 0, 0)])
def test_elevation_grid_count_mk407(xd: int, zd: int, n: int) -> None:
    with pytest.raises(GeometryError) as info:
        elevation_grid(xd, zd, 1.0, 1.0, [0.0] * n)
    assert info.value.code == "MK407"


# ---- IndexedFaceSet and TriangleMesh -------------------------------------------------------------

ELL_XY = [(0, 0), (2, 0), (2, 1), (1, 1), (1, 2), (0, 2)]  # concave, counter-clockwise, area 3


def xy_area_and_signs(mesh: TriangleMeshData) -> tuple[float, np.ndarray]:
    z = face_normals(mesh)[:, 2]
    return float(z.sum() / 2.0), np.sign(z)


def test_concave_l_polygon() -> None:
    verts = [c for x, y in ELL_XY for c in (x, y, 0.0)]
    mesh, trailing = indexed_face_set(verts, [0, 1, 2, 3, 4, 5, -1])
    assert trailing == 0
    area, signs = xy_area_and_signs(mesh)
    assert len(mesh.faces) == 4
    assert area == pytest.approx(3.0)
    assert np.all(signs > 0)  # orientation kept
    reverse, _ = indexed_face_set(verts, [5, 4, 3, 2, 1, 0, -1])
    area, signs = xy_area_and_signs(reverse)
    assert area == pytest.approx(-3.0) and np.all(signs < 0)
    # start the polygon at the reflex corner (index 3)
    rotated, _ = indexed_face_set(verts, [3, 4, 5, 0, 1, 2, -1])
    area, signs = xy_area_and_signs(rotated)
    assert area == pytest.approx(3.0) and np.all(signs > 0)


def test_collinear_vertices_give_no_degenerate_triangles() -> None:
    square = [(0, 0), (1, 0), (2, 0), (2, 1), (2, 2), (1, 2), (0, 2), (0, 1)]  # midpoints on every side
    verts = [c for x, y in square for c in (x, y, 0.0)]
    mesh, _ = indexed_face_set(verts, [*range(8), -1])
    area, signs = xy_area_and_signs(mesh)
    assert area == pytest.approx(4.0)
    assert np.all(signs > 0)  # no zero-area triangle, none reversed
    assert len(mesh.faces) <= 8 - 2


def test_large_concave_star() -> None:
    k = 2000
    ang = 2 * np.pi * np.arange(k) / k
    rad = np.where(np.arange(k) % 2 == 0, 1.0, 0.6)
    pts = np.column_stack([rad * np.cos(ang), rad * np.sin(ang), np.zeros(k)])
    expected = shoelace(pts[:, :2].reshape(-1).tolist())
    mesh, _ = indexed_face_set(pts.reshape(-1).tolist(), [*range(k), -1])
    area, signs = xy_area_and_signs(mesh)
    assert len(mesh.faces) == k - 2
    assert area == pytest.approx(expected, rel=1e-12)
    assert np.all(signs > 0)


def test_comb_polygon_with_many_reflex_vertices() -> None:
    teeth = 300
    outline = [(0.0, 0.0), (2.0 * teeth - 1, 0.0)]
    for t in reversed(range(teeth)):
        outline += [(2.0 * t + 1, 1.0), (2.0 * t + 1, 5.0), (2.0 * t, 5.0), (2.0 * t, 1.0)]
    outline = outline[:-1]  # the last tooth goes straight down to (0, 0)
    expected = shoelace([c for p in outline for c in p])
    assert expected == pytest.approx((2 * teeth - 1) * 1.0 + teeth * 4.0)
    mesh, _ = indexed_face_set([c for x, y in outline for c in (x, y, 0.0)], [*range(len(outline)), -1])
    area, signs = xy_area_and_signs(mesh)
    assert area == pytest.approx(expected, rel=1e-12)
    assert np.all(signs > 0)


def test_quad_grid_and_mixed_polygons_keep_order_and_area() -> None:
    n = 21
    xs, ys = np.meshgrid(np.arange(n, dtype=float), np.arange(n, dtype=float))
    zs = 0.05 * np.sin(xs)  # gently warped (non-planar quads)
    verts = np.column_stack([xs.ravel(), ys.ravel(), zs.ravel()]).reshape(-1).tolist()
    index: list[int] = []
    for i in range(n - 1):
        for j in range(n - 1):
            a = i * n + j
            index += (
                [a, a + 1, a + 1 + n, a + n, -1]
                if (i + j) % 3
                else [a, a + 1, a + 1 + n, -1, a, a + 1 + n, a + n, -1]
            )
    mesh, _ = indexed_face_set(verts, index)
    area, signs = xy_area_and_signs(mesh)
    assert area == pytest.approx((n - 1) ** 2)
    assert np.all(signs > 0)
    assert len(mesh.faces) == 2 * (n - 1) ** 2
    first_corner = mesh.faces.min(axis=1)
    assert np.all(np.diff(first_corner) >= 0)  # triangles come in polygon order


def test_non_planar_pentagon() -> None:
    pts = [(0, 0, 0.0), (3, 0, 0.2), (3, 2, -0.1), (1.5, 0.8, 0.3), (0, 2, 0.0)]  # concave at index 3
    mesh, _ = indexed_face_set([c for p in pts for c in p], [0, 1, 2, 3, 4, -1])
    area, signs = xy_area_and_signs(mesh)
    assert len(mesh.faces) == 3
    assert area == pytest.approx(shoelace([c for p in pts for c in p[:2]]))
    assert np.all(signs > 0)


def test_unterminated_polygon_is_dropped_and_counted() -> None:
    verts = [0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0]
    mesh, trailing = indexed_face_set(verts, [0, 1, 2, -1, 0, 2, 3])
    assert trailing == 3
    assert mesh.faces.tolist() == [[0, 1, 2]]
    _, none = indexed_face_set(verts, [0, 1, 2, -1, 0, 2, 3, -1])
    assert none == 0
    with pytest.raises(GeometryError) as info:
        indexed_face_set(verts, [0, 1, 2, 3])  # the only polygon is unterminated
    assert info.value.code == "MK410"


@pytest.mark.parametrize(
    ("index", "bad"), [([0, 1, 4, -1], 4), ([0, 1, 2, -1, 0, 2, 9], 9), ([0, -2, 1, 2, -1], -2)]
)
def test_ifs_index_out_of_range_mk408(index: list[int], bad: int) -> None:
    verts = [0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0]
    with pytest.raises(GeometryError) as info:
        indexed_face_set(verts, index)
    assert info.value.code == "MK408"
    assert str(bad) in info.value.message and "4" in info.value.message
    if bad >= 4:
        assert info.value.message.startswith(f"Vertex index {bad} is over the number of vertices (4).")


@pytest.mark.parametrize("index", [[], [-1, -1], [0, 1, -1], [0, 1, -1, 2, -1]])
def test_ifs_without_valid_polygon_mk410(index: list[int]) -> None:
    with pytest.raises(GeometryError) as info:
        indexed_face_set([0, 0, 0, 1, 0, 0, 1, 1, 0], index)
    assert info.value.code == "MK410"


def test_degenerate_polygon_gives_nothing() -> None:
    verts = [0, 0, 0, 1, 0, 0, 2, 0, 0, 3, 0, 0, 0, 0, 0, 1, 0, 0, 0, 1, 0]
    mesh, _ = indexed_face_set(verts, [0, 1, 2, 3, -1, 4, 5, 6, -1])  # a collinear quad, then a triangle
    assert mesh.faces.tolist() == [[4, 5, 6]]


def test_triangle_mesh() -> None:
    verts = [0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1]
    mesh = triangle_mesh(verts, [0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3])
    assert mesh.faces.shape == (4, 3)
    assert signed_volume(mesh) == pytest.approx(1 / 6)  # unit corner tetrahedron, outward
    assert reference_volume(mesh) == pytest.approx(1 / 6)
    partial = triangle_mesh(verts, [0, 2, 1, 0, 1])
    assert partial.faces.tolist() == [[0, 2, 1]]


@pytest.mark.parametrize(("tris", "bad"), [([0, 1, 4], 4), ([0, 1, 2, 3, -1, 2], -1)])
def test_triangle_mesh_out_of_range_mk408(tris: list[int], bad: int) -> None:
    with pytest.raises(GeometryError) as info:
        triangle_mesh([0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1], tris)
    assert info.value.code == "MK408"
    message = info.value.message
    assert str(bad) in message
    assert "(4)" in message or "4 vertices" in message


# ---- volume and winding --------------------------------------------------------------------------


def test_flip_if_inward() -> None:
    inward, _ = extrusion(VRML_SQUARE, [0, 0, 0, 0, 1, 0])
    flipped = flip_if_inward(inward)
    assert signed_volume(flipped) == pytest.approx(4.0, abs=1e-12)
    assert reference_volume(flipped) == pytest.approx(4.0, abs=1e-12)
    assert boundary_edges(flipped.faces) == []
    assert sorted(map(sorted, flipped.faces.tolist())) == sorted(map(sorted, inward.faces.tolist()))
    outward, _ = extrusion(REVERSED_SQUARE, [0, 0, 0, 0, 1, 0])
    assert flip_if_inward(outward) is outward


def test_signed_volume_of_empty_mesh() -> None:
    assert signed_volume(TriangleMeshData(np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64))) == 0.0
