"""Load mesh files (STL, OBJ, COLLADA, VRML97, glTF, PLY) into triangles, the way Choreonoid reads them.

One entry point, :func:`load_mesh`, returns every triangle of a file (or of one named part of it) in
metres, in the file's root frame. The rules follow ``docs/body-format.md`` §3.6 / §4.9:

* **Units.** Meshes are metres. ``metadata.length_unit`` (millimeter ×0.001, inch ×0.0254) and
  ``metadata.upper_axis: Y`` (the cyclic permutation (x, y, z) → (z, x, y)) are honoured for STL, OBJ
  and COLLADA, **not** for VRML (as Choreonoid).
* **COLLADA.** The root ``<asset><unit meter>`` is applied; ``<up_axis>`` is **ignored** (Choreonoid,
  RViz and Gazebo all ignore it; trimesh ignores ``<unit>`` as well, so it is not used for DAE).
* **PLY** (binary or ASCII, as Blender and ManiSkill's SO-100 write it) is read with trimesh; metadata
  applies as for STL. No target but rviz and gz-sim (Assimp) reads it, so ``convert`` writes it as
  STL/OBJ for every target.
* **Fragments** (VRML ``DEF`` names, COLLADA node ``name`` attributes): the first node with that name in a
  depth-first search is *detached*: the translations of its ancestors and its own translation are
  dropped, the accumulated linear part (rotation, scale) is kept.

Third-party parsers (trimesh, pycollada) are imported lazily inside the loaders so that importing this
module stays cheap (the ``validate`` command must start fast).
"""

from __future__ import annotations

import io
import math
import re
import warnings
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from modelkit.geometry import mesh_cache
from modelkit.geometry.glbcheck import glb_verdict
from modelkit.geometry.objcheck import UNDECIDED, obj_verdict
from modelkit.model import TriangleMeshData
from modelkit.textio import DEFAULT_MAX_BYTES, UnreadableFile, read_regular

__all__ = [
    "SUPPORTED_EXTENSIONS",
    "LoadedMesh",
    "MeshLoadError",
    "MeshMetadata",
    "load_mesh",
]

SUPPORTED_EXTENSIONS: frozenset[str] = frozenset({".stl", ".obj", ".dae", ".wrl", ".glb", ".gltf", ".ply"})

#: Extensions Choreonoid reads through Assimp that modelkit does not read.
_ASSIMP_ONLY_EXTENSIONS = frozenset({".blend", ".x", ".dxf"})

#: Limits that keep hostile files (deep nesting, exponential DEF/USE or instance_node sharing) from
#: exhausting the stack, the memory or the time.
MAX_NESTING_DEPTH = 256
MAX_NODE_VISITS = 1_000_000
MAX_TRIANGLES = 5_000_000

_LENGTH_UNITS = {"millimeter": 0.001, "inch": 0.0254, "meter": 1.0}

#: ``metadata.upper_axis: Y``: mesh (x, y, z) → (z, x, y), §3.6 (a cyclic permutation, not Rx(90°)).
UPPER_AXIS_Y_ROTATION: NDArray[np.float64] = np.array(
    [[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], dtype=np.float64
)

Mesh = tuple[NDArray[np.float64], NDArray[np.int64]]  # (vertices (n,3), faces (m,3))
Rgba = tuple[float, float, float, float]


# ---- public types ---------------------------------------------------------------------------


class MeshLoadError(Exception):
    """A mesh file cannot be used.

    ``code`` is a diagnostic code: ``MK501`` cannot parse/load, ``MK502`` fragment not found, ``MK506``
    unsupported extension. ``line`` is the 1-based line in the mesh file when known (text formats);
    ``parts`` lists the named parts of the file (for "did you mean" hints on MK502).
    """

    def __init__(self, code: str, message: str, *, line: int | None = None,
                 parts: Sequence[str] = ()) -> None:
        super().__init__(message)
        self.code = code
        self.message = message
        self.line = line
        self.parts = list(parts)


@dataclass(frozen=True)
class MeshMetadata:
    """The ``metadata`` of a Choreonoid ``Resource`` node (§3.6)."""

    length_unit: str | None = None  # "millimeter" | "inch" | None
    upper_axis: str | None = None  # "Y" | None


@dataclass
class LoadedMesh:
    mesh: TriangleMeshData  # all triangles of the file (or fragment), metres, file root frame
    parts: list[str]  # named nodes found (VRML DEF names / COLLADA node names), sorted
    unit_scale: float  # scale applied (COLLADA <unit meter> × metadata length unit)
    source_format: str  # "stl" | "obj" | "dae" | "wrl" | "glb" | "gltf" | "ply"
    notes: list[str] = field(default_factory=list)  # facts worth telling a user
    # The file's own colours (COLLADA, glTF): per face an index into ``palette`` (RGBA 0..1, None for a
    # face without a colour of its own); None when the file gives none
    face_colours: NDArray[np.int64] | None = None
    palette: list[Rgba | None] = field(default_factory=list)


# ---- entry point ----------------------------------------------------------------------------


def load_mesh(
    path: Path,
    fragment: str | None = None,
    metadata: MeshMetadata | None = None,
    max_bytes: int = DEFAULT_MAX_BYTES,
) -> LoadedMesh:
    """Load the triangles of a mesh file as Choreonoid would (§3.6).

    Raises :class:`MeshLoadError` (and nothing else) for any input that cannot be used: an unsupported
    extension (MK506), a file that cannot be read or parsed (MK501), an unknown ``fragment`` (MK502).
    """
    path = Path(path)
    ext = path.suffix.lower()
    if ext not in SUPPORTED_EXTENSIONS:
        shown = ext or "(no extension)"
        extra = " (Choreonoid reads it through Assimp)" if ext in _ASSIMP_ONLY_EXTENSIONS else ""
        raise MeshLoadError(
            "MK506",
            f"mesh file type {shown}{extra} is not supported; supported: "
            + ", ".join(sorted(SUPPORTED_EXTENSIONS)),
        )
    data = _read_mesh_bytes(path, max_bytes)
    if not data.strip():
        raise MeshLoadError("MK501", f"{path.name} is empty")
    try:
        return _load_data(path, ext, data, fragment, metadata)
    except MeshLoadError as e:
        withheld = _withheld(path, ext, data)
        if withheld is None or e.code != "MK501":
            raise
        raise MeshLoadError("MK501", withheld) from None


def _withheld(path: Path, ext: str, data: bytes) -> str | None:
    """The message that replaces a parser's own (which may quote the file) when the file is not one to
    quote: reached through a symbolic link out of its folder (``x.wrl`` → ``/etc/passwd``), or a VRML
    file without the ``#VRML`` header. None when the parser's message may be shown."""
    try:
        real = path.resolve(strict=True)
        folder = path.absolute().parent.resolve(strict=True)
    except (OSError, RuntimeError):
        return None
    if not real.is_relative_to(folder) and path.is_symlink():
        return (f"{path.name} is a symbolic link out of its folder (to {real}) and cannot be loaded as a "
                f"{ext[1:].upper()} mesh; nothing of its content is shown")
    if ext == ".wrl" and not _VRML_START.match(data):
        return (f"{path.name} is not a VRML file (no '#VRML' header and it does not begin with a node); "
                "nothing of its content is shown")
    return None


# The start of a VRML file: its header, or (headerless) a first node "[DEF name] Type {" after comments.
_VRML_START = re.compile(
    rb"^(?:\xef\xbb\xbf)?\s*(?:#VRML|(?:#[^\n]*\n\s*)*(?:DEF\s+[^\s{}\[\]]+\s+)?[A-Za-z_][A-Za-z0-9_]*\s*\{)"
)


def _load_data(
    path: Path, ext: str, data: bytes, fragment: str | None, metadata: MeshMetadata | None
) -> LoadedMesh:
    """:func:`load_mesh` once the bytes are read: :class:`MeshLoadError` for anything that fails."""
    try:
        # overflow/invalid values in hostile files end up as non-finite vertices, reported below; the
        # parser libraries' own warnings (trimesh's texture statistics on an OBJ whose UVs are all NaN:
        # pybullet's Panda as genesis-world ships it) are neither a finding nor something for stderr
        with np.errstate(all="ignore"), warnings.catch_warnings():
            warnings.simplefilter("ignore")
            if ext == ".stl":
                return _finish(_load_stl(data, path.name), path.name, fragment, metadata)
            if ext == ".obj":
                return _finish(_load_obj(data, path.name), path.name, fragment, metadata)
            if ext == ".ply":
                return _finish(_load_ply(data, path.name), path.name, fragment, metadata)
            if ext == ".dae":
                return _load_dae(data, path.name, fragment, metadata)
            if ext in (".glb", ".gltf"):
                return _load_gltf(data, path, fragment, metadata)
            return _load_wrl(data, path.name, fragment, metadata)
    except MeshLoadError:
        raise
    except RecursionError as e:
        raise MeshLoadError("MK501", f"cannot load {path.name}: nesting too deep") from e
    except MemoryError as e:
        raise MeshLoadError("MK501", f"cannot load {path.name}: out of memory") from e
    except Exception as e:  # a parser library failed in a way we did not foresee
        raise MeshLoadError("MK501", f"cannot load {path.name}: {type(e).__name__}: {e}") from e


def _read_mesh_bytes(path: Path, max_bytes: int) -> bytes:
    """The bytes of a mesh file, read with the checks every input gets; :class:`MeshLoadError` if it
    cannot be read (MK501) or is over ``max_bytes`` (MK002)."""
    try:
        return read_regular(path, max_bytes)
    except UnreadableFile as e:  # a FIFO, a device, a directory, a loop (MK501); too large (MK002)
        code = "MK002" if e.code == "MK002" else "MK501"
        reason = e.message.removeprefix("cannot read file: ")
        raise MeshLoadError(code, f"cannot read {path.name}: {reason}") from e


# ---- per-run outcome cache --------------------------------------------------------------------

# (resolved path, mtime_ns, size, fragment, metadata, max_bytes, name as given) -> None (loads) or
# "CODE\tmessage". Validating many files that share meshes loads each once per process (one CLI run).
_OUTCOMES: dict[tuple[str, int, int, str | None, MeshMetadata | None, int, str], str | None] = {}


def mesh_problem(
    path: Path,
    fragment: str | None = None,
    metadata: MeshMetadata | None = None,
    max_bytes: int = DEFAULT_MAX_BYTES,
) -> str | None:
    """None when :func:`load_mesh` loads ``path`` (``fragment``), else ``"CODE\tmessage"`` of its
    :class:`MeshLoadError`. Outcomes for regular files are kept for the process, keyed by the resolved
    path, modification time, size, fragment and metadata, so a changed file is loaded again; without
    metadata also on disk between runs (:mod:`modelkit.geometry.mesh_cache`)."""
    import os
    import stat

    key = None
    try:
        info = os.stat(path)
        if stat.S_ISREG(info.st_mode):
            resolved = str(Path(path).resolve())
            # the name as given too: the suffix picks the parser and messages name the file (two links
            # to one file, a.dae and b.stl, are two meshes)
            key = (resolved, info.st_mtime_ns, info.st_size, fragment, metadata, max_bytes, Path(path).name)
    except (OSError, RuntimeError, ValueError):  # missing, a loop: load_mesh reports it
        key = None
    if key is not None and key in _OUTCOMES:
        return _OUTCOMES[key]
    kept = key is not None and metadata is None  # kept on disk too
    if kept and key is not None:
        found, outcome, corners = mesh_cache.lookup(key)
        if found:
            _OUTCOMES[key] = outcome
            if corners is not None:
                _BOUNDS[(str(path), fragment)] = (key[1], key[2], corners)
            return outcome
    corners = None
    try:
        outcome, fast_corners = _fast_problem(Path(path), fragment, metadata, max_bytes)
        if fast_corners is not None and kept and key is not None:
            corners = fast_corners
            _BOUNDS[(str(path), fragment)] = (key[1], key[2], corners)
        if outcome == UNDECIDED:
            # the mesh libraries' own warnings (trimesh's texture statistics on an all-transparent image)
            # are neither a finding nor something to print on stderr
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                loaded = load_mesh(path, fragment, metadata, max_bytes)
            outcome = None
            if kept and key is not None:
                corners = _keep_bounds(str(path), key[1], key[2], fragment, loaded.mesh.vertices)
    except MeshLoadError as exc:
        outcome = f"{exc.code}\t{exc}"
    if key is not None:
        _OUTCOMES[key] = outcome
    if kept and key is not None:
        mesh_cache.store(key, outcome, corners)
    return outcome


def _fast_problem(path: Path, fragment: str | None, metadata: MeshMetadata | None,
                  max_bytes: int) -> tuple[str | None, Corners | None]:
    """:func:`mesh_problem`'s verdict on a plain OBJ or ``.glb`` file (no fragment, no metadata) without
    trimesh (``objcheck``, ``glbcheck``), with the corners of the triangles when the check gives them; the
    ``UNDECIDED`` sentinel for anything else or when the fast check cannot tell."""
    suffix = path.suffix.lower()
    if fragment is not None or metadata is not None or suffix not in (".obj", ".glb"):
        return UNDECIDED, None
    data = _read_mesh_bytes(path, max_bytes)
    if suffix == ".obj":
        return obj_verdict(data, path.name)
    verdict = glb_verdict(data)
    return (UNDECIDED, None) if verdict.problem is not None else (None, verdict.corners)


def clear_mesh_cache() -> None:
    """Forget every outcome kept by :func:`mesh_problem` (benchmarks, long-running processes)."""
    _OUTCOMES.clear()
    _BOUNDS.clear()


Corners = tuple[tuple[float, float, float], tuple[float, float, float]]
# (path as given, fragment) -> (mtime_ns, size, the lowest and highest corner of the triangles) of a mesh that
# :func:`mesh_problem` loaded, or judged with ``objcheck``/``glbcheck``, without metadata: the validation
# rules use a mesh's extent without loading it again.
_BOUNDS: dict[tuple[str, str | None], tuple[int, int, Corners]] = {}


def _keep_bounds(path: str, mtime: int, size: int, fragment: str | None,
                 vertices: NDArray[np.float64]) -> Corners | None:
    """Keep the corners of ``vertices`` for the process; returns them (None for no vertex)."""
    if not len(vertices):
        return None
    low, high = vertices.min(axis=0), vertices.max(axis=0)
    corners = ((float(low[0]), float(low[1]), float(low[2])),
               (float(high[0]), float(high[1]), float(high[2])))
    _BOUNDS[(path, fragment)] = (mtime, size, corners)
    return corners


def known_bounds(path: str | Path, fragment: str | None = None) -> Corners | None:
    """The corners of a mesh :func:`mesh_problem` has loaded in this process under the same path (None if
    it has not, or if the file has changed since)."""
    import os

    kept = _BOUNDS.get((str(path), fragment))
    if kept is None:
        return None
    try:
        info = os.stat(path)
    except (OSError, ValueError):
        return None
    return kept[2] if (info.st_mtime_ns, info.st_size) == kept[:2] else None


# ---- shared scene graph ---------------------------------------------------------------------


@dataclass(eq=False)
class MeshSceneNode:
    """A node of a loaded scene: a local 4×4 transform, meshes in the node frame, child nodes.

    Children may be shared (VRML ``USE``, COLLADA ``instance_node``), so the graph is a DAG.
    """

    name: str | None = None
    matrix: NDArray[np.float64] = field(default_factory=lambda: np.eye(4))
    meshes: list[Mesh] = field(default_factory=list)
    children: list[MeshSceneNode] = field(default_factory=list)
    colours: list[Rgba | None] = field(default_factory=list)  # per mesh, when the file gives colours


@dataclass
class _Flattened:
    vertices: NDArray[np.float64]
    faces: NDArray[np.int64]
    parts: list[str]
    notes: list[str]
    face_colours: NDArray[np.int64] | None = None
    palette: list[Rgba | None] = field(default_factory=list)


def _scene_names(roots: Sequence[MeshSceneNode]) -> list[str]:
    """All node names, each node visited once (shared nodes are not expanded)."""
    seen: set[int] = set()
    names: set[str] = set()
    stack = list(roots)
    while stack:
        node = stack.pop()
        if id(node) in seen:
            continue
        seen.add(id(node))
        if node.name:
            names.add(node.name)
        stack.extend(node.children)
    return sorted(names)


def _count_visit(visits: int, file_name: str) -> int:
    """One more scene-node visit; refuse scene graphs that explode through shared instances."""
    if visits >= MAX_NODE_VISITS:
        raise MeshLoadError(
            "MK501", f"{file_name}: scene graph too large (more than {MAX_NODE_VISITS} node visits)"
        )
    return visits + 1


def _find_fragment(
    roots: Sequence[MeshSceneNode], name: str, file_name: str
) -> tuple[MeshSceneNode, NDArray[np.float64]] | None:
    """First node called ``name`` in depth-first pre-order, with its accumulated transform
    (ancestors × own)."""
    stack: list[tuple[MeshSceneNode, NDArray[np.float64]]] = [(r, r.matrix) for r in reversed(roots)]
    visits = 0
    while stack:
        node, acc = stack.pop()
        visits = _count_visit(visits, file_name)
        if node.name == name:
            return node, acc
        for child in reversed(node.children):
            stack.append((child, acc @ child.matrix))
    return None


def flatten_scene(roots: Sequence[MeshSceneNode], fragment: str | None, file_name: str) -> _Flattened:
    """Bake every mesh instance of the scene (or of the fragment, detached per §3.6) into one
    triangle list. Triangles under a mirroring transform (negative determinant) have their winding
    reversed so that outward faces stay outward."""
    parts = _scene_names(roots)
    notes: list[str] = []
    starts: list[tuple[MeshSceneNode, NDArray[np.float64]]]
    if fragment is not None:
        found = _find_fragment(roots, fragment, file_name)
        if found is None:
            hint = ("; named parts: " + ", ".join(parts)) if parts else "; the file has no named parts"
            message = f'fragment "{fragment}" is not found in {file_name}{hint}'
            raise MeshLoadError("MK502", message, parts=parts)
        node, acc = found
        detached = np.eye(4)
        detached[:3, :3] = acc[:3, :3]  # keep the accumulated linear part, drop every translation
        starts = [(node, detached)]
        if np.any(np.abs(acc[:3, 3]) > 0.0):
            t = acc[:3, 3]
            notes.append(
                f'fragment "{fragment}" detached: its accumulated translation '
                f"({t[0]:.6g}, {t[1]:.6g}, {t[2]:.6g}) is dropped, its orientation is kept (as Choreonoid)"
            )
    else:
        starts = [(r, r.matrix) for r in roots]

    instances: list[tuple[Mesh, NDArray[np.float64], Rgba | None]] = []
    n_tri = 0
    visits = 0
    stack = list(reversed(starts))
    while stack:
        node, acc = stack.pop()
        visits = _count_visit(visits, file_name)
        for k, mesh in enumerate(node.meshes):
            n_tri += len(mesh[1])
            if n_tri > MAX_TRIANGLES:
                raise MeshLoadError("MK501", f"{file_name} expands to more than {MAX_TRIANGLES} triangles")
            instances.append((mesh, acc, node.colours[k] if k < len(node.colours) else None))
        for child in reversed(node.children):
            stack.append((child, acc @ child.matrix))

    verts: list[NDArray[np.float64]] = []
    faces: list[NDArray[np.int64]] = []
    palette: list[Rgba | None] = []
    colour_runs: list[NDArray[np.int64]] = []
    offset = 0
    mirrored = 0
    for (v, f), acc, colour in instances:
        if len(f) == 0:
            continue
        if colour not in palette:
            palette.append(colour)
        colour_runs.append(np.full(len(f), palette.index(colour), dtype=np.int64))
        lin = acc[:3, :3]
        verts.append(v @ lin.T + acc[:3, 3])
        ff = f + offset
        if np.linalg.det(lin) < 0.0:
            ff = ff[:, [0, 2, 1]]
            mirrored += 1
        faces.append(ff)
        offset += len(v)
    if mirrored:
        notes.append(f"{mirrored} mesh instance(s) under a mirroring transform: triangle winding reversed")
    if verts:
        coloured = any(c is not None for c in palette)
        return _Flattened(np.concatenate(verts), np.concatenate(faces).astype(np.int64), parts, notes,
                          np.concatenate(colour_runs) if coloured else None, palette if coloured else [])
    return _Flattened(np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64), parts, notes)


# ---- polygon triangulation ------------------------------------------------------------------


def _polygon_normal(p: NDArray[np.float64]) -> NDArray[np.float64]:
    """Newell's normal of a (possibly non-planar) polygon, not normalised."""
    q = np.roll(p, -1, axis=0)
    return np.array(
        [
            np.sum((p[:, 1] - q[:, 1]) * (p[:, 2] + q[:, 2])),
            np.sum((p[:, 2] - q[:, 2]) * (p[:, 0] + q[:, 0])),
            np.sum((p[:, 0] - q[:, 0]) * (p[:, 1] + q[:, 1])),
        ]
    )


def _ear_clip(points: NDArray[np.float64]) -> list[tuple[int, int, int]]:
    """Triangulate one simple polygon (k ≥ 3 points, 3-D, roughly planar) by ear clipping.

    Returns index triples into ``points`` with the polygon's orientation. Falls back to a fan for the
    remaining vertices if no ear can be found (self-intersecting or degenerate input).
    """
    k = len(points)
    if k == 3:
        return [(0, 1, 2)]
    n = _polygon_normal(points)
    norm = float(np.linalg.norm(n))
    if norm <= 0.0 or not math.isfinite(norm):
        return [(0, i, i + 1) for i in range(1, k - 1)]
    n = n / norm
    # 2-D coordinates in the polygon plane, oriented so that the polygon is counter-clockwise
    ref = np.array([1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    u = np.cross(n, ref)
    u /= np.linalg.norm(u)
    w = np.cross(n, u)
    xy = np.stack([points @ u, points @ w], axis=1)
    idx = list(range(k))
    tris: list[tuple[int, int, int]] = []

    def cross2(o: int, p: int, q: int) -> float:
        ox, oy = xy[o]
        return float((xy[p, 0] - ox) * (xy[q, 1] - oy) - (xy[p, 1] - oy) * (xy[q, 0] - ox))

    def is_ear(a: int, b: int, c: int) -> bool:
        if cross2(a, b, c) <= 0.0:  # reflex or degenerate corner
            return False
        return not any(
            j not in (a, b, c)
            and cross2(a, b, j) >= 0.0
            and cross2(b, c, j) >= 0.0
            and cross2(c, a, j) >= 0.0
            for j in idx
        )

    i = 0
    fails = 0
    while len(idx) > 3 and fails < len(idx):
        m = len(idx)
        i0, i1, i2 = idx[(i - 1) % m], idx[i % m], idx[(i + 1) % m]
        if is_ear(i0, i1, i2):
            tris.append((i0, i1, i2))
            del idx[i % m]
            i %= len(idx)
            fails = 0
        else:
            i = (i + 1) % m
            fails += 1
    if len(idx) >= 3:  # three left, or ear search failed: fan the rest
        tris.extend((idx[0], idx[j], idx[j + 1]) for j in range(1, len(idx) - 1))
    return tris


def triangulate_polygons(
    vertices: NDArray[np.float64], counts: NDArray[np.int64], flat: NDArray[np.int64]
) -> tuple[NDArray[np.int64], int]:
    """Triangulate polygons given as vertex counts and a flat index list, keeping their orientation.

    Triangles pass through; quads are split at a concave corner if there is one; larger polygons are
    ear-clipped. Polygons with fewer than 3 vertices or with an index outside ``vertices`` are skipped;
    their number is returned with the (m, 3) faces, in polygon order.
    """
    counts = np.asarray(counts, dtype=np.int64)
    flat = np.asarray(flat, dtype=np.int64)
    nv = len(vertices)
    if len(counts) == 0:
        return np.zeros((0, 3), dtype=np.int64), 0
    if np.any(counts < 0) or int(counts.sum()) != len(flat):
        raise MeshLoadError("MK501", "polygon vertex counts do not match the index list")
    starts = np.concatenate([[0], np.cumsum(counts)[:-1]])
    bad_index = (flat < 0) | (flat >= nv)
    cum_bad = np.concatenate([[0], np.cumsum(bad_index)])
    bad_poly = (cum_bad[starts + counts] - cum_bad[starts] > 0) | (counts < 3)
    skipped = int(np.count_nonzero(bad_poly))

    out_faces: list[NDArray[np.int64]] = []
    out_poly: list[NDArray[np.int64]] = []
    poly_ids = np.arange(len(counts))

    tri = (counts == 3) & ~bad_poly
    if np.any(tri):
        s = starts[tri]
        out_faces.append(flat[s[:, None] + np.arange(3)])
        out_poly.append(poly_ids[tri])

    quad = (counts == 4) & ~bad_poly
    if np.any(quad):
        s = starts[quad]
        q = flat[s[:, None] + np.arange(4)]  # (k, 4)
        p = vertices[q]  # (k, 4, 3)
        nrm = np.cross(p[:, 2] - p[:, 0], p[:, 3] - p[:, 1])  # quad normal (diagonal cross product)
        prev = np.roll(p, 1, axis=1)
        nxt = np.roll(p, -1, axis=1)
        turn = np.einsum("kij,kj->ki", np.cross(p - prev, nxt - p), nrm)  # < 0 at a concave corner
        start = np.where(np.any(turn < 0, axis=1), np.argmin(turn, axis=1), 0)
        order = (start[:, None] + np.arange(4)) % 4
        qq = np.take_along_axis(q, order, axis=1)
        t1 = qq[:, [0, 1, 2]]
        t2 = qq[:, [0, 2, 3]]
        out_faces.append(np.stack([t1, t2], axis=1).reshape(-1, 3))
        out_poly.append(np.repeat(poly_ids[quad], 2))

    big = np.nonzero((counts > 4) & ~bad_poly)[0]
    for pi in big:
        s = int(starts[pi])
        ids = flat[s : s + int(counts[pi])]
        local = _ear_clip(np.asarray(vertices[ids], dtype=np.float64))
        if local:
            out_faces.append(ids[np.array(local, dtype=np.int64)])
            out_poly.append(np.full(len(local), pi, dtype=np.int64))

    if not out_faces:
        return np.zeros((0, 3), dtype=np.int64), skipped
    faces = np.concatenate(out_faces)
    order_idx = np.argsort(np.concatenate(out_poly), kind="stable")
    return faces[order_idx].astype(np.int64), skipped


def compact_mesh(vertices: NDArray[np.float64], faces: NDArray[np.int64]) -> Mesh:
    """Drop vertices no face refers to (keeps the order of the others)."""
    if len(faces) == 0:
        return np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64)
    if faces.min() >= 0 and faces.max() < len(vertices):
        mark = np.zeros(len(vertices), dtype=bool)
        mark[faces.ravel()] = True  # one pass, where np.unique sorts every index: the same sorted result
        used = np.flatnonzero(mark)
    else:  # out-of-range indices fail (or wrap) exactly as they always did
        used = np.unique(faces)
    if len(used) == len(vertices):
        return np.asarray(vertices, dtype=np.float64), faces.astype(np.int64)
    remap = np.full(len(vertices), -1, dtype=np.int64)
    remap[used] = np.arange(len(used))
    return np.asarray(vertices[used], dtype=np.float64), remap[faces]


def merge_identical_vertices(vertices: NDArray[np.float64], faces: NDArray[np.int64]) -> Mesh:
    """Merge exactly equal vertices (STL is a triangle soup), keeping first-occurrence order.

    Rows are grouped by a stable ``lexsort`` of the three coordinates (equal as floats: -0.0 is 0.0,
    a NaN equals nothing), which gives the groups and first occurrences of ``np.unique(axis=0)``
    at a tenth of its cost: that sorts the rows as structured items, compared field by field through
    a generic function (2.5 s of so101.urdf's 13 STL files)."""
    count = len(vertices)
    if count == 0:
        return vertices, faces
    rows = np.asarray(vertices, dtype=np.float64).reshape(count, -1)
    order = np.lexsort(rows.T[::-1])  # by x, then y, then z; stable, so a group's first is its first
    ranked = rows[order]
    starts = np.empty(count, dtype=bool)
    starts[0] = True
    np.any(ranked[1:] != ranked[:-1], axis=1, out=starts[1:])
    group = np.cumsum(starts) - 1  # the group of each sorted row
    first = order[starts]  # each group's first occurrence in the file
    by_first = np.argsort(first, kind="stable")
    rank = np.empty_like(by_first)
    rank[by_first] = np.arange(len(by_first))  # groups numbered in order of first occurrence
    inverse = np.empty(count, dtype=np.int64)
    inverse[order] = rank[group]
    return np.asarray(vertices[np.sort(first)], dtype=np.float64), inverse[faces]


# ---- STL / OBJ (trimesh) ----------------------------------------------------------------------


@dataclass
class _Raw:
    """Triangles of a file before metadata is applied."""

    fmt: str
    vertices: NDArray[np.float64]
    faces: NDArray[np.int64]
    notes: list[str] = field(default_factory=list)


# One binary STL triangle: normal, three vertices, attribute bytes (little-endian, 50 bytes).
_STL_RECORD = np.dtype([("normals", "<f4", (3,)), ("vertices", "<f4", (9,)), ("attributes", "<u2")])


def _load_stl(data: bytes, name: str) -> _Raw:
    """STL, binary or ASCII. Like Choreonoid the kind is decided by the size: a file of exactly
    84 + 50·n bytes (n = the header's triangle count) is binary, anything else must be ASCII.

    Both kinds are read here, without importing trimesh (0.5–0.8 s: example-robot-data's
    simple_humanoid, one ASCII STL cube of 8 KB, took 0.96 s to validate): a binary STL as the same
    arrays as trimesh's ``load_stl_binary``, an ASCII STL by :func:`ascii_stl_solids`."""
    header_count = int.from_bytes(data[80:84], "little") if len(data) >= 84 else -1
    if header_count >= 0 and len(data) == 84 + 50 * header_count:
        blob = np.frombuffer(data, dtype=_STL_RECORD, offset=84)
        triangles = blob["vertices"].reshape((-1, 3))
        faces_in_order = np.arange(len(triangles)).reshape((-1, 3))
        kwargs: list[dict[str, Any]] = [{"vertices": triangles, "faces": faces_in_order}]
        kind = "binary"
    else:
        text = data.decode("latin-1")
        if not text.lstrip().lower().startswith("solid") and _looks_like_obj(text):
            raw = _load_obj(data, name)
            raw.notes.append("OBJ text in a file named .stl (read by its content; tools that go by the "
                             "suffix, e.g. MuJoCo, refuse it)")
            return raw
        if not text.lstrip().lower().startswith("solid"):
            expected = f"; its header announces {header_count} triangles = {84 + 50 * header_count} bytes" \
                if header_count >= 0 else ""
            raise MeshLoadError(
                "MK501",
                f"{name} is neither a binary STL (size {len(data)} bytes{expected}) "
                "nor an ASCII STL (it does not start with 'solid'); truncated or not an STL file",
            )
        if "\x00" in text:
            raise MeshLoadError("MK501", f"{name}: ASCII STL contains NUL bytes (truncated binary STL?)")
        try:
            solids = ascii_stl_solids(text)
            kwargs = [{"vertices": v, "faces": np.arange(len(v)).reshape((-1, 3))} for v in solids]
        except ValueError as e:
            raise MeshLoadError("MK501", f"{name}: malformed ASCII STL ({e})") from e
        n_facets = len(re.findall(r"\bendfacet\b", text.lower()))
        n_parsed = sum(len(k["faces"]) for k in kwargs)
        if n_parsed != n_facets:
            raise MeshLoadError(
                "MK501", f"{name}: malformed ASCII STL ({n_facets} facets but {n_parsed} vertex triples read)"
            )
        kind = "ASCII"
    verts = [np.asarray(k["vertices"], dtype=np.float64).reshape(-1, 3) for k in kwargs]
    faces = [np.asarray(k["faces"], dtype=np.int64).reshape(-1, 3) for k in kwargs]
    offsets = np.cumsum([0] + [len(v) for v in verts])
    v_all = np.concatenate(verts) if verts else np.zeros((0, 3))
    f_all = (np.concatenate([f + o for f, o in zip(faces, offsets, strict=False)])
             if faces else np.zeros((0, 3), dtype=np.int64))
    v_all, f_all = merge_identical_vertices(v_all, f_all)
    return _Raw("stl", v_all, f_all, ["ASCII STL (some tools, e.g. MuJoCo, read only binary STL)"]
                if kind == "ASCII" else [])


_ASCII_STL_VERTEX = re.compile(r"\bvertex[ \t]+(\S+)[ \t]+(\S+)[ \t]+(\S+)[ \t]*(?=[\r\n]|$)")


def ascii_stl_solids(text: str) -> list[NDArray[np.float64]]:
    """The vertices of each ``solid`` … ``endsolid`` block of an ASCII STL (keywords in any case), three
    per facet in file order; a block with no vertex is left out, and text outside the blocks is not
    read. Raises ``ValueError`` for a coordinate that is not a number or a vertex count that is not a
    multiple of three."""
    lower = text.lower()
    solids: list[NDArray[np.float64]] = []
    start = lower.find("solid")
    while start >= 0:
        end = lower.find("endsolid", start)
        if end < 0:
            break
        rows = _ASCII_STL_VERTEX.findall(lower, start, end)
        if len(rows) % 3:
            raise ValueError(f"{len(rows)} vertices in a solid, not three per facet")
        if rows:
            solids.append(np.array(rows, dtype=np.float64).reshape(-1, 3))
        start = lower.find("solid", end + len("endsolid"))
    return solids


def _looks_like_obj(text: str) -> bool:
    """Wavefront OBJ text: no NUL byte, and vertex and face lines."""
    if "\x00" in text:
        return False
    lines = text.splitlines()
    return any(line.startswith("v ") for line in lines) and any(line.startswith("f ") for line in lines)


def _load_obj(data: bytes, name: str) -> _Raw:
    """Wavefront OBJ through trimesh (materials are not read; only the triangles matter)."""
    from trimesh.exchange.obj import load_obj

    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        text = data.decode("latin-1")
    if "\x00" in text:
        raise MeshLoadError("MK501", f"{name} contains NUL bytes: not a text OBJ file")
    try:
        loaded = load_obj(io.StringIO(text), group_material=False, skip_materials=True, maintain_order=True)
    except IndexError as e:
        raise MeshLoadError("MK501", f"{name}: a face refers to a vertex that does not exist") from e
    except ValueError as e:
        raise MeshLoadError("MK501", f"{name}: malformed OBJ ({e})") from e
    kwargs: list[dict[str, Any]] = list(loaded["geometry"].values()) if "geometry" in loaded else [loaded]
    verts: list[NDArray[np.float64]] = []
    faces: list[NDArray[np.int64]] = []
    offset = 0
    for k in kwargs:
        if "vertices" not in k or "faces" not in k:
            continue
        v = np.asarray(k["vertices"], dtype=np.float64).reshape(-1, 3)
        f = np.asarray(k["faces"], dtype=np.int64)
        if f.ndim != 2 or len(f) == 0:
            continue
        if f.shape[1] != 3:  # trimesh keeps all-quad (or all-k-gon) objects as polygons
            f, _ = triangulate_polygons(v, np.full(len(f), f.shape[1], dtype=np.int64), f.reshape(-1))
        verts.append(v)
        faces.append(f + offset)
        offset += len(v)
    if not faces:
        raise MeshLoadError("MK501", f"{name} contains no faces: not a usable OBJ file")
    v_all = np.concatenate(verts)
    f_all = np.concatenate(faces)
    if np.any(f_all < 0) or np.any(f_all >= len(v_all)):
        raise MeshLoadError("MK501", f"{name}: face index out of range")
    return _Raw("obj", v_all, f_all, [])


def _metadata_transform(metadata: MeshMetadata | None, notes: list[str]) -> tuple[float, NDArray[np.float64]]:
    """(length scale, rotation) requested by a Resource's ``metadata``."""
    scale = 1.0
    rot = np.eye(3)
    if metadata is None:
        return scale, rot
    if metadata.length_unit is not None:
        unit = metadata.length_unit.strip().lower()
        if unit in _LENGTH_UNITS:
            scale = _LENGTH_UNITS[unit]
        else:
            notes.append(
                f'metadata length_unit "{metadata.length_unit}" is not known (millimeter, inch); ignored'
            )
    if metadata.upper_axis is not None:
        axis = metadata.upper_axis.strip().upper()
        if axis == "Y":
            rot = UPPER_AXIS_Y_ROTATION.copy()
            notes.append("metadata upper_axis Y applied: mesh (x, y, z) -> (z, x, y)")
        elif axis != "Z":
            notes.append(f'metadata upper_axis "{metadata.upper_axis}" is not known (Y); ignored')
    return scale, rot


def _load_ply(data: bytes, name: str) -> _Raw:
    """PLY, binary or ASCII, with trimesh's reader (imported here: only a PLY file pays for it). A file
    of points without faces (a point cloud) holds no triangles; a face index past the vertices is
    refused, as trimesh's own mesh would fail on it later."""
    from trimesh.exchange.ply import load_ply
    from trimesh.geometry import triangulate_quads

    if not data.startswith(b"ply"):
        raise MeshLoadError("MK501", f"{name} is not a PLY file (it does not start with 'ply')")
    loaded = load_ply(io.BytesIO(data), fix_texture=False, prefer_color=None, skip_materials=True)
    vertices = np.asarray(loaded.get("vertices", np.zeros((0, 3))), dtype=np.float64).reshape(-1, 3)
    polygons = loaded.get("faces")
    if polygons is None or len(polygons) == 0:
        return _Raw("ply", vertices, np.zeros((0, 3), dtype=np.int64))
    faces = np.asarray(triangulate_quads(polygons), dtype=np.int64).reshape(-1, 3)  # quads, polygons fanned
    if faces.size and (int(faces.min()) < 0 or int(faces.max()) >= len(vertices)):
        raise MeshLoadError("MK501", f"{name}: a face names a vertex the file does not have")
    return _Raw("ply", vertices, faces)


def _finish(raw: _Raw, name: str, fragment: str | None, metadata: MeshMetadata | None) -> LoadedMesh:
    """STL/OBJ/PLY: no named parts; apply metadata; check the numbers."""
    if fragment is not None:
        raise MeshLoadError(
            "MK502",
            f'fragment "{fragment}" is not found in {name}; {raw.fmt.upper()} files have no named parts',
        )
    if len(raw.faces) == 0:
        raise MeshLoadError("MK501", f"{name} contains no triangles")
    notes = list(raw.notes)
    scale, rot = _metadata_transform(metadata, notes)
    verts = raw.vertices @ (scale * rot).T
    _check_finite(verts, name)
    return LoadedMesh(TriangleMeshData(verts, raw.faces.astype(np.int64)), [], scale, raw.fmt, notes)


def _check_finite(vertices: NDArray[np.float64], name: str) -> None:
    """Reject NaN/infinite coordinates; turn -0.0 into 0.0 (in place) so output files stay clean."""
    if not np.all(np.isfinite(vertices)):
        raise MeshLoadError("MK501", f"{name} has non-finite vertex coordinates (NaN or infinity)")
    vertices += 0.0


# ---- COLLADA (pycollada) ----------------------------------------------------------------------


def _local(tag: object) -> str:
    return str(tag).rsplit("}", 1)[-1]


def _axis_angle4(axis: NDArray[np.float64], angle: float) -> NDArray[np.float64]:
    m = np.eye(4)
    n = float(np.linalg.norm(axis))
    if n == 0.0:
        return m
    a = axis / n
    c, s = math.cos(angle), math.sin(angle)
    k = np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])
    m[:3, :3] = c * np.eye(3) + (1.0 - c) * np.outer(a, a) + s * k
    return m


def _dae_transform(t: Any) -> NDArray[np.float64]:
    """One COLLADA transform element as a float64 4×4 matrix (pycollada's own are float32)."""
    node = getattr(t, "xmlnode", None)
    tag = _local(node.tag) if node is not None else ""
    try:
        vals = np.array((node.text or "").split(), dtype=np.float64) if node is not None else np.zeros(0)
    except ValueError:
        vals = np.zeros(0)
    m = np.eye(4)
    if tag == "translate" and len(vals) == 3:
        m[:3, 3] = vals
    elif tag == "rotate" and len(vals) == 4:
        m = _axis_angle4(vals[:3], math.radians(vals[3]))
    elif tag == "scale" and len(vals) == 3:
        m[0, 0], m[1, 1], m[2, 2] = vals
    elif tag == "matrix" and len(vals) == 16:
        m = vals.reshape(4, 4)
    else:
        m = np.asarray(t.matrix, dtype=np.float64).reshape(4, 4)
    return m


def _bound_colours(instance: Any) -> dict[str, Rgba]:
    """Material symbol → the diffuse RGBA of the material an ``<instance_geometry>`` (or controller)
    binds to it; a textured or colourless material has none."""
    out: dict[str, Rgba] = {}
    for bound in getattr(instance, "materials", None) or []:
        effect = getattr(getattr(bound, "target", None), "effect", None)
        diffuse = getattr(effect, "diffuse", None)
        if isinstance(diffuse, tuple) and len(diffuse) >= 3:
            try:
                rgba = tuple(min(max(float(x), 0.0), 1.0) for x in (*diffuse[:3], *(diffuse[3:4] or (1.0,))))
            except (TypeError, ValueError):
                continue
            if all(math.isfinite(x) for x in rgba):
                out[str(bound.symbol)] = (rgba[0], rgba[1], rgba[2], rgba[3])
    return out


class _DaeConverter:
    """pycollada scene → :class:`MeshSceneNode` graph (node names, float64 transforms)."""

    def __init__(self, name: str) -> None:
        self.name = name
        self.notes: list[str] = []
        self._nodes: dict[int, MeshSceneNode | None] = {}
        self._geoms: dict[tuple[int, tuple[tuple[str, Rgba], ...]], list[tuple[Mesh, Rgba | None]]] = {}
        self._skipped_polys = 0
        self._line_prims = 0
        self._other: set[str] = set()

    def geometry(self, geom: Any, colours: dict[str, Rgba] | None = None) -> list[tuple[Mesh, Rgba | None]]:
        """The triangles of a ``<geometry>``, one mesh per vertex source and material, each with the
        diffuse colour its ``<bind_material>`` (``colours``: symbol → RGBA) gives it (None: none)."""
        binding = tuple(sorted((colours or {}).items()))
        key = (id(geom), binding)
        if key in self._geoms:
            return self._geoms[key]
        from collada.lineset import LineSet
        from collada.polylist import Polylist
        from collada.triangleset import TriangleSet

        groups: dict[tuple[int, Rgba | None], tuple[NDArray[np.float64], list[NDArray[np.int64]]]] = {}
        for prim in geom.primitives:
            if isinstance(prim, LineSet):
                self._line_prims += 1
                continue
            vsrc = prim.vertex
            vidx = prim.vertex_index
            if vsrc is None or vidx is None or len(vidx) == 0:
                continue
            verts = np.asarray(vsrc, dtype=np.float64).reshape(-1, 3)
            if isinstance(prim, TriangleSet):
                faces = np.asarray(vidx, dtype=np.int64).reshape(-1, 3)
                bad = np.any((faces < 0) | (faces >= len(verts)), axis=1)
                if np.any(bad):
                    self._skipped_polys += int(bad.sum())
                    faces = faces[~bad]
            elif isinstance(prim, Polylist):  # also <polygons> (a Polylist subclass)
                counts = np.asarray(prim.vcounts)
                faces, skipped = triangulate_polygons(verts, counts, np.asarray(vidx).reshape(-1))
                self._skipped_polys += skipped
            else:
                self._other.add(type(prim).__name__)
                continue
            colour = (colours or {}).get(str(getattr(prim, "material", None) or ""))
            entry = groups.setdefault((id(vsrc), colour), (verts, []))
            entry[1].append(faces)
        meshes = [(compact_mesh(v, np.concatenate(fs)), group[1]) for group, (v, fs) in groups.items()]
        meshes = [(m, c) for m, c in meshes if len(m[1])]
        self._geoms[key] = meshes
        return meshes

    def node(self, node: Any, depth: int) -> MeshSceneNode | None:
        """Convert a <node>; None when nothing below it has a mesh (Choreonoid drops such nodes, so
        camera and light nodes are not selectable parts)."""
        from collada.scene import ControllerNode, GeometryNode, Node, NodeNode

        if depth > MAX_NESTING_DEPTH:
            raise MeshLoadError("MK501", f"{self.name}: node nesting deeper than {MAX_NESTING_DEPTH} "
                                         "(or a cyclic <instance_node>)")
        if isinstance(node, NodeNode):
            node = node.node
        key = id(node)
        if key in self._nodes:
            return self._nodes[key]
        out = MeshSceneNode(name=node.xmlnode.get("name") or None)
        mat = np.eye(4)
        for t in node.transforms:
            mat = mat @ _dae_transform(t)
        out.matrix = mat
        real: list[Any] = []
        instanced: list[Any] = []
        for child in node.children:
            if isinstance(child, NodeNode):
                instanced.append(child)
            elif isinstance(child, Node):
                real.append(child)
            elif isinstance(child, GeometryNode):
                for mesh, colour in self.geometry(child.geometry, _bound_colours(child)):
                    out.meshes.append(mesh)
                    out.colours.append(colour)
            elif isinstance(child, ControllerNode):
                self._controller(child, out)
        # Assimp lists a node's own <node> children before its <instance_node>s
        for c in real + instanced:  # a plain loop: one stack frame per level
            converted = self.node(c, depth + 1)
            if converted is not None:
                out.children.append(converted)
        result = out if (out.meshes or out.children) else None
        self._nodes[key] = result
        return result

    def _controller(self, child: Any, out: MeshSceneNode) -> None:
        ctrl = child.controller
        geom = getattr(ctrl, "geometry", None)
        bind = getattr(ctrl, "bind_shape_matrix", None)
        if geom is None or bind is None:
            self._other.add(type(ctrl).__name__)
            return
        b = np.asarray(bind, dtype=np.float64).reshape(4, 4)
        for (v, f), colour in self.geometry(geom, _bound_colours(child)):
            out.meshes.append((v @ b[:3, :3].T + b[:3, 3], f))
            out.colours.append(colour)
        self.notes.append("skinned mesh (<instance_controller>) taken in its bind pose")

    def finish_notes(self) -> list[str]:
        notes = list(self.notes)
        if self._skipped_polys:
            notes.append(
                f"{self._skipped_polys} polygon(s) with fewer than 3 vertices or bad indices skipped"
            )
        if self._line_prims:
            notes.append(f"{self._line_prims} <lines> primitive(s) ignored (no triangles)")
        for kind in sorted(self._other):
            notes.append(f"{kind} not supported; skipped")
        return notes


_ENTITY_RE = re.compile(rb"<!ENTITY", re.IGNORECASE)


def _float_or_nan(text: str) -> float:
    try:
        return float(text)
    except ValueError:
        return float("nan")


def _load_dae(data: bytes, name: str, fragment: str | None, metadata: MeshMetadata | None) -> LoadedMesh:
    root_at = data.find(b"<COLLADA")
    prolog = data if root_at < 0 else data[:root_at]
    if _ENTITY_RE.search(prolog):
        raise MeshLoadError("MK501", f"{name}: XML entity declarations are not accepted in COLLADA files")

    import collada
    from collada.common import DaeBrokenRefError, DaeError, DaeUnsupportedError

    from modelkit.geometry.dae_sources import materials_optional, positions_only

    unbound: list[str] = []
    try:
        # normals and texture coordinates are not decoded (nothing reads them); a geometry bound to a
        # material the file lacks is kept without a colour, as Assimp keeps it
        with positions_only(), materials_optional(unbound):
            dae = collada.Collada(io.BytesIO(data), ignore=[DaeUnsupportedError, DaeBrokenRefError])
    except DaeError as e:
        msg = str(getattr(e, "msg", "") or e)
        at = re.search(r"line (\d+), column", msg)
        line = int(at.group(1)) if at else None
        raise MeshLoadError("MK501", f"{name}: not a readable COLLADA file: {msg}", line=line) from e
    except (ValueError, TypeError, KeyError, IndexError, AttributeError) as e:
        raise MeshLoadError("MK501", f"{name}: inconsistent COLLADA content ({type(e).__name__}: {e})") from e
    root = dae.xmlnode.getroot()
    if _local(root.tag) != "COLLADA":
        raise MeshLoadError("MK501", f"{name}: root element is <{_local(root.tag)}>, not <COLLADA>")

    notes: list[str] = []
    # units: only the document's <asset> counts (Assimp reads no nested <asset>)
    unit = 1.0
    asset = dae.assetInfo
    if asset is not None and getattr(asset, "unitmeter", None) is not None:
        unit = float(asset.unitmeter)
    if not math.isfinite(unit) or unit <= 0.0:
        raise MeshLoadError("MK501", f"{name}: invalid <unit meter> value {unit}")
    if unit != 1.0:
        notes.append(f"COLLADA <unit meter=\"{unit:g}\"> applied (x{unit:g})")
    up: str | None = None
    for asset_el in root.iter("{*}asset"):
        owner = asset_el.getparent()
        for child in asset_el:
            tag = _local(child.tag)
            if owner is root and tag == "up_axis":
                up = (child.text or "").strip().upper() or None
            elif owner is not root and tag == "unit" and _float_or_nan(child.get("meter", "1")) != unit:
                notes.append(
                    f'nested <unit meter="{child.get("meter")}"> in <{_local(owner.tag)}> not applied '
                    "(Assimp/Choreonoid use only the document unit)"
                )
    if up != "Z_UP":
        shown = up if up else "absent (COLLADA default Y_UP)"
        notes.append(
            f"COLLADA up_axis {shown} ignored, as Choreonoid does (RViz and Gazebo also ignore it; "
            "viewers that honour it show this mesh rotated)"
        )
    if unbound:
        shown = ", ".join(sorted(set(unbound))[:3]) + (" ..." if len(set(unbound)) > 3 else "")
        notes.append(f"material(s) {shown} not in the file: the triangles bound to them are kept without "
                     "a colour, as Assimp (RViz, Gazebo, Choreonoid) keeps them")
    if dae.errors:
        shown_errors = "; ".join(str(getattr(e, "msg", e)) for e in dae.errors[:3])
        more = f" (+{len(dae.errors) - 3} more)" if len(dae.errors) > 3 else ""
        notes.append(f"COLLADA content ignored: {shown_errors}{more}")

    scene = dae.scene
    if scene is None and len(dae.scenes):
        scene = dae.scenes[0]
        notes.append("no <scene><instance_visual_scene>: the first visual scene is used")
    conv = _DaeConverter(name)
    roots: list[MeshSceneNode] = []
    for top in scene.nodes if scene is not None else []:
        converted = conv.node(top, 1)
        if converted is not None:
            roots.append(converted)
    if scene is None:
        notes.append("no visual scene: no geometry is instanced")
    notes.extend(conv.finish_notes())

    flat = flatten_scene(roots, fragment, name)
    notes.extend(flat.notes)
    mscale, rot = _metadata_transform(metadata, notes)
    total = unit * mscale
    verts = flat.vertices @ (total * rot).T
    _check_finite(verts, name)
    if len(flat.faces) == 0:
        notes.append("no triangles")
    return LoadedMesh(TriangleMeshData(verts, flat.faces), flat.parts, total, "dae", notes,
                      flat.face_colours, flat.palette)


# ---- glTF 2.0 (trimesh) --------------------------------------------------------------------------


def _load_gltf(data: bytes, path: Path, fragment: str | None, metadata: MeshMetadata | None) -> LoadedMesh:
    """A ``.glb``/``.gltf`` file's triangles where its nodes place them (:mod:`modelkit.geometry.gltf`);
    fragments are node names, as for COLLADA."""
    from modelkit.geometry.gltf import GltfRefused, gltf_root

    binary = path.suffix.lower() == ".glb"
    try:
        root = gltf_root(data, binary, path.parent)
    except GltfRefused as exc:
        raise MeshLoadError("MK501", f"{path.name}: {exc}") from exc
    flat = flatten_scene([root], fragment, path.name)
    notes = list(flat.notes)
    scale, rot = _metadata_transform(metadata, notes)
    verts = flat.vertices @ (scale * rot).T
    _check_finite(verts, path.name)
    if len(flat.faces) == 0:
        raise MeshLoadError("MK501", f"{path.name} contains no triangles")
    return LoadedMesh(TriangleMeshData(verts, flat.faces), flat.parts, scale, path.suffix.lower()[1:], notes,
                      flat.face_colours, flat.palette)


# ---- VRML97 ---------------------------------------------------------------------------------


def _load_wrl(data: bytes, name: str, fragment: str | None, metadata: MeshMetadata | None) -> LoadedMesh:
    from modelkit.geometry.vrml import VrmlError, read_vrml

    try:
        scene = read_vrml(data)
    except VrmlError as e:
        where = f" (line {e.line})" if e.line else ""
        raise MeshLoadError("MK501", f"{name}{where}: {e.message}", line=e.line) from e
    notes = list(scene.notes)
    if metadata is not None and (metadata.length_unit or metadata.upper_axis):
        notes.append("metadata length_unit/upper_axis ignored for VRML, as Choreonoid does")
    flat = flatten_scene(scene.roots, fragment, name)
    notes.extend(flat.notes)
    _check_finite(flat.vertices, name)
    if len(flat.faces) == 0:
        notes.append("no triangles")
    return LoadedMesh(TriangleMeshData(flat.vertices, flat.faces), flat.parts, 1.0, "wrl", notes)
