"""Meshes for a writer: copy a source mesh file, convert it, or write triangles as a file.

Every mesh a written model references lives in the output folder's ``meshes/`` with a
deterministic, safe name, and is referenced by a path relative to the model file, so the folder
can be moved as a whole. What had to change on the way is a conversion note.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from modelkit.convert.notes import NoteSink
from modelkit.convert.options import WriteOptions
from modelkit.convert.output import OutputPlan, safe_file_name
from modelkit.diagnostics import Severity, SourceLocation
from modelkit.model import Capsule, Cone, Ellipsoid, Mesh, TriangleMeshData
from modelkit.spatial import Vec3

MESH_FOLDER = "meshes"
PRIMITIVE_SECTIONS = 32  # segments around the axis of a cone, capsule or ellipsoid written as a mesh


@dataclass(frozen=True)
class MeshRef:
    """What a writer puts in its mesh element: a reference and the scale to apply to it."""

    uri: str  # relative to the model file (or a kept package:// URI)
    scale: Vec3
    file_format: str  # "stl" | "obj" | "dae"
    hollow: bool = False  # encloses no volume: MuJoCo needs inertia="shell" on its asset
    plate: Plate | None = None  # a flat collision mesh for MuJoCo: write this box instead (MK881)


PLATE_THICKNESS = 1e-3
"""m: the thickness of the box a flat collision mesh is written as for MuJoCo (at most a tenth of the
plate's larger side): MuJoCo collides with a mesh's convex hull, and a plane has none."""


@dataclass(frozen=True)
class Plate:
    """A flat mesh as a thin box: its centre and axes (the columns of ``rotation``: the plane's two
    axes, then its normal) in the mesh's frame with the scale applied, and the box's full sizes."""

    centre: tuple[float, ...]
    rotation: tuple[tuple[float, ...], ...]
    size: tuple[float, ...]


def plate_of(corners: np.ndarray, scale: Vec3 | None = None) -> Plate:
    """The thin box of a flat mesh's corners: the smallest rectangle that holds the vertices in their
    plane (over the directions of the edges of their convex hull there, as the rotating calipers
    find it: a square marker gives its own square, whatever way its principal axes fall), and
    ``PLATE_THICKNESS`` across it. The plane is the one of the two largest principal axes."""
    points = corners.reshape(-1, 3) * (np.ones(3) if scale is None else np.asarray(scale, dtype=float))
    mean = points.mean(axis=0)
    _, _, vt = np.linalg.svd(points - mean)
    normal = vt[2] if vt[2][int(np.argmax(np.abs(vt[2])))] > 0 else -vt[2]
    base_u = vt[0]
    base_v = np.cross(normal, base_u)
    flat = np.column_stack([(points - mean) @ base_u, (points - mean) @ base_v])
    hull = _hull_2d(flat)
    best: tuple[float, np.ndarray] | None = None  # area, the rectangle's 2 × 2 axes
    for i in range(len(hull)):
        edge = hull[(i + 1) % len(hull)] - hull[i]
        length = float(np.hypot(edge[0], edge[1]))
        if length == 0.0:
            continue
        d = edge / length
        axes2 = np.array([[d[0], -d[1]], [d[1], d[0]]])  # columns: the edge and its normal in the plane
        local = hull @ axes2
        area = float(np.prod(local.max(axis=0) - local.min(axis=0)))
        if best is None or area < best[0] * (1.0 - 1e-12):
            best = (area, axes2)
    axes2 = np.eye(2) if best is None else best[1]
    u = axes2[0, 0] * base_u + axes2[1, 0] * base_v
    u = u if u[int(np.argmax(np.abs(u)))] > 0 else -u
    v = np.cross(normal, u)
    axes = np.column_stack([u, v, normal])
    local = (points - mean) @ axes
    low, high = local.min(axis=0), local.max(axis=0)
    centre = mean + axes @ (0.5 * (low + high))
    extent = high - low
    thickness = min(PLATE_THICKNESS, 0.1 * float(max(extent[0], extent[1])))
    if np.array_equal(corners, corners.astype(np.float32)):  # single-precision vertices (an STL):
        size = float(max(extent[0], extent[1]))  # no more digits than they hold
        centre = np.array([_single(x, size) for x in centre])
        extent = np.array([_single(x, size) for x in extent])
    return Plate(tuple(float(x) for x in centre), tuple(tuple(float(x) for x in row) for row in axes),
                 (float(extent[0]), float(extent[1]), thickness))


def _single(value: float, size: float) -> float:
    """A length computed from single-precision vertices, to their precision: the shortest decimal
    within a few of float32's ε of the plate's ``size`` (0 when that is 0): a side from -0.0300000012
    to 0.0299999993 is 0.06, a centre 9.3e-10 m off the plate's axis is 0."""
    tolerance = 4.0 * float(np.finfo(np.float32).eps) * size
    if abs(value) <= tolerance:
        return 0.0
    for digits in range(1, 10):
        short = float(f"{value:.{digits}g}")
        if abs(short - value) <= tolerance:
            return short
    return float(value)


def _hull_2d(points: np.ndarray) -> np.ndarray:
    """The convex hull of 2-D points, counter-clockwise (Andrew's monotone chain)."""
    ordered = sorted({(float(x), float(y)) for x, y in points})
    if len(ordered) < 3:
        return np.asarray(ordered, dtype=float).reshape(-1, 2)

    def cross(o: tuple[float, float], a: tuple[float, float], b: tuple[float, float]) -> float:
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    lower: list[tuple[float, float]] = []
    for point in ordered:
        while len(lower) >= 2 and cross(lower[-2], lower[-1], point) <= 0.0:
            lower.pop()
        lower.append(point)
    upper: list[tuple[float, float]] = []
    for point in reversed(ordered):
        while len(upper) >= 2 and cross(upper[-2], upper[-1], point) <= 0.0:
            upper.pop()
        upper.append(point)
    return np.asarray(lower[:-1] + upper[:-1], dtype=float)


MUJOCO_MAX_STL_FACES = 200_000  # MuJoCo's STL decoder: "number of faces should be between 1 and 200000"


@dataclass(frozen=True)
class Prepared:
    """A mesh file as MuJoCo will read it: the bytes, what was done to them, whether it is hollow."""

    data: bytes
    converted: str | None  # what the bytes were ("an ASCII STL"), None when copied as is
    hollow: bool
    # all vertices in a plane (MuJoCo cannot build the convex hull it collides with): the thin box a
    # collision shape is written as (:func:`plate_of`); None for a mesh with volume
    plate: Plate | None = None
    # an OBJ kept as OBJ but written without what MuJoCo's reader cannot take (:func:`obj_face_data`):
    # what was left out and why; None when the bytes are the file's own
    cleaned: str | None = None


def _prepared(data: bytes, converted: str | None, corners: np.ndarray, scale: Vec3 | None) -> Prepared:
    """``data`` with what MuJoCo will make of its ``corners``: hollow, or flat (its plate)."""
    plate = plate_of(corners, scale) if _flat(corners) else None
    return Prepared(data, converted, _hollow(corners, scale), plate)


class Unusable(Exception):
    """A mesh file MuJoCo cannot use, with the reason."""


class TooManyForStl(Unusable):
    """Triangles MuJoCo would read from an OBJ file but not from an STL (over its STL bound)."""

    def __init__(self, message: str, corners: np.ndarray) -> None:
        super().__init__(message)
        self.corners = corners


def for_mujoco(data: bytes, ext: str, scale: Vec3 | None = None) -> Prepared:
    """``data`` (a file named ``*.ext``) made readable by MuJoCo, read by its content.

    A binary STL is checked (faces between 1 and 200,000, finite corners); an ASCII STL or OBJ text
    becomes a binary STL (MuJoCo reads only binary STL; an OBJ named ``.stl`` is read as what it is).
    Raises :class:`Unusable` for an empty file, something that is not a mesh (a PNG...), non-finite
    coordinates or too many faces. ``scale`` is the one the model applies (for :func:`_hollow`).
    """
    if not data.strip():
        raise Unusable("the file is empty")
    if ext == "obj":
        return _obj_for_mujoco(data, scale)
    count = _binary_stl_faces(data)
    if count is not None:
        corners = _checked(_binary_stl_corners(data, count))
        return _prepared(data, None, corners, scale)
    text = _text(data)
    if text is None:
        kind = "a PNG image" if data.startswith(b"\x89PNG") else "binary data that is no STL"
        raise Unusable(f"the file is {kind}")
    words = text.split(None, 2)
    if words[:1] == ["solid"] and "facet" in text:
        kind, file_type = "an ASCII STL", "stl"
    elif any(line.startswith(("v ", "f ")) for line in text.splitlines()):
        kind, file_type = "OBJ text", "obj"
    else:
        raise Unusable("the file is text that is neither an ASCII STL nor OBJ")
    corners = _checked(_text_corners(data, file_type))
    faces = np.arange(len(corners) * 3, dtype=np.int64).reshape(-1, 3)
    mesh = TriangleMeshData(corners.reshape(-1, 3), faces)
    return _prepared(triangles_to_bytes(mesh, "stl"), kind, corners, scale)


def _loaded(path: Path, fragment: str | None, metadata: Any) -> Any:
    """:func:`modelkit.geometry.meshfiles.load_mesh`, remembered per file version within a process:
    ``verify`` writes the same robot up to seven times (its engines' files, layer 4's two sets), and
    loading the tutorial robot's two COLLADA meshes took 0.44 s of its 5.5 s."""
    from modelkit.geometry.meshfiles import load_mesh

    try:
        stat = path.stat()
    except OSError:
        return load_mesh(path, fragment, metadata)  # its MeshLoadError says what is wrong
    version = (stat.st_mtime_ns, stat.st_size, stat.st_ino)
    return _load_version(str(path.resolve()), version, fragment, metadata)


@functools.lru_cache(maxsize=32)
def _load_version(path: str, version: tuple[int, int, int], fragment: str | None, metadata: Any) -> Any:
    from modelkit.geometry.meshfiles import load_mesh

    del version  # part of the key only: a changed file is loaded again
    return load_mesh(Path(path), fragment, metadata)


def as_binary_stl(data: bytes) -> Prepared | None:
    """A ``.stl`` file that is text (an ASCII STL, or OBJ text named ``.stl``) as a binary STL, for
    every target; ``None`` for a binary STL or anything that is no mesh (then copied as is, and judged
    by the target's own checks)."""
    if _binary_stl_faces(data) is not None:
        return None
    try:
        ready = for_mujoco(data, "stl")
    except Unusable:
        return None
    return ready if ready.converted is not None else None


def obj_face_data(data: bytes) -> tuple[bytes, str | None]:
    """An OBJ file's bytes as MuJoCo's OBJ reader takes them, and what was left out (None: unchanged).

    MuJoCo needs a face's texture coordinate and normal on every corner of every face, or on none: a file
    with ``vt`` lines and a corner without one loads with a warning and no texture coordinates at all; a
    file with ``vn`` lines and a corner without one is refused ("mesh_facenormal normal index out of
    bounds", measured with MuJoCo 4.0 on pybullet_data's ``table_square/table.obj``). Such a file is
    written without the texture coordinates (MuJoCo would drop them) or without the normals (MuJoCo then
    computes its own); the vertices and faces are the file's."""
    has_vt = has_vn = vt_missing = vn_missing = False
    for line in data.splitlines():
        if line.startswith(b"vt "):
            has_vt = True
        elif line.startswith(b"vn "):
            has_vn = True
        elif line.startswith(b"f "):
            for corner in line.split()[1:]:
                parts = corner.split(b"/")
                vt_missing = vt_missing or len(parts) < 2 or not parts[1]
                vn_missing = vn_missing or len(parts) < 3 or not parts[2]
    drop_vt, drop_vn = has_vt and vt_missing, has_vn and vn_missing
    if not (drop_vt or drop_vn):
        return data, None
    out: list[bytes] = []
    for line in data.splitlines(keepends=True):
        if (drop_vt and line.startswith(b"vt ")) or (drop_vn and line.startswith(b"vn ")):
            continue
        if line.startswith(b"f "):
            corners = []
            for corner in line.split()[1:]:
                vertex, texture, normal = ([*corner.split(b"/"), b"", b""])[:3]
                texture = b"" if drop_vt else texture
                normal = b"" if drop_vn else normal
                corners.append(vertex + (b"/" + texture if texture or normal else b"")
                               + (b"/" + normal if normal else b""))
            line = b"f " + b" ".join(corners) + b"\n"
        out.append(line)
    left_out = []
    if drop_vt:
        left_out.append("its texture coordinates (some face corners have none: MuJoCo would drop them all, "
                        "with a warning)")
    if drop_vn:
        left_out.append("its normals (some face corners have none: MuJoCo refuses such a file; it computes "
                        "the normals itself)")
    return b"".join(out), " and ".join(left_out)


def _obj_for_mujoco(data: bytes, scale: Vec3 | None) -> Prepared:
    data, cleaned = obj_face_data(data)
    ready = _obj_whole_for_mujoco(data, scale)
    return replace(ready, cleaned=cleaned) if cleaned and ready.converted is None else ready


def _obj_whole_for_mujoco(data: bytes, scale: Vec3 | None) -> Prepared:
    """An OBJ file kept as is (with whether it is hollow or flat), unless MuJoCo's own OBJ reader reads
    fewer triangles than it holds (measured on files of several objects: example-robot-data's
    ``nub.obj`` gives 29 of 1,404, its laikago ``trunk.obj`` 5,368 of 22,246); then its triangles
    become a binary STL, read whole. Only
    files of two or more ``o``/``g`` groups are put to MuJoCo (:mod:`modelkit.formats.mjcf.meshprobe`,
    ~0.1 s for a 10,000-face file): every OBJ measured that MuJoCo reads short has them, and none of
    the single-group ones (84 files of example-robot-data and the corpus)."""
    triangles, groups = _obj_counts(data)
    if groups < 2:
        corners = _obj_corners(data)
        if corners is None or len(corners) == 0 or not np.all(np.isfinite(corners)):
            return Prepared(data, None, False)  # MuJoCo's own verdict comes with the model
        return _prepared(data, None, corners, scale)
    from modelkit.formats.mjcf.meshprobe import faces_mujoco_reads

    read = faces_mujoco_reads(data, "obj")
    if read is None or read >= triangles:
        return Prepared(data, None, False)
    corners = _checked(_text_corners(data, "obj"))
    faces = np.arange(len(corners) * 3, dtype=np.int64).reshape(-1, 3)
    mesh = TriangleMeshData(corners.reshape(-1, 3), faces)
    why = (f"an OBJ file of {groups} objects of which MuJoCo's OBJ reader keeps {read:,} of its "
           f"{triangles:,} triangles")
    return _prepared(triangles_to_bytes(mesh, "stl"), why, corners, scale)


def _obj_corners(data: bytes) -> np.ndarray | None:
    """The triangles (n × 3 × 3) of an OBJ file's faces, polygons fanned from their first corner, indices
    as OBJ counts them (from 1; negative from the last vertex so far); None when a line does not parse.
    Read without trimesh (0.5-0.8 s to import): only whether MuJoCo will find the mesh hollow or flat
    is asked (robosuite's Sawyer ``head_1.obj``, one flat group, was copied and MuJoCo refused the model:
    "mesh volume is too small")."""
    vertices: list[list[float]] = []
    triangles: list[tuple[int, int, int]] = []
    try:
        for line in data.splitlines():
            if line.startswith(b"v "):
                vertices.append([float(w) for w in line.split()[1:4]])
            elif line.startswith(b"f "):
                ids = [int(w.split(b"/", 1)[0]) for w in line.split()[1:]]
                ids = [i - 1 if i > 0 else len(vertices) + i for i in ids]
                triangles.extend((ids[0], ids[k], ids[k + 1]) for k in range(1, len(ids) - 1))
        if not triangles:
            return np.zeros((0, 3, 3))
        points = np.array(vertices, dtype=np.float64).reshape(-1, 3)
        index = np.array(triangles, dtype=np.int64)
    except ValueError:
        return None
    if index.min() < 0 or index.max() >= len(points):
        return None
    corners: np.ndarray = points[index]
    return corners


def _obj_counts(data: bytes) -> tuple[int, int]:
    """The triangles an OBJ file's faces make (a face of k corners makes k − 2) and its ``o``/``g``
    lines, counted without parsing the numbers."""
    triangles = groups = 0
    for line in data.splitlines():
        if line.startswith(b"f "):
            triangles += max(len(line.split()) - 3, 0)
        elif line.startswith((b"o ", b"g ")):
            groups += 1
    return triangles, groups


def _binary_stl_faces(data: bytes) -> int | None:
    """The face count of a binary STL (its size is 84 + 50 × the count it declares), else None."""
    count = int.from_bytes(data[80:84], "little") if len(data) >= 84 else -1
    return count if count >= 0 and len(data) == 84 + 50 * count else None


def _binary_stl_corners(data: bytes, count: int) -> np.ndarray:
    record = np.dtype([("normal", "<f4", 3), ("corners", "<f4", (3, 3)), ("attribute", "<u2")])
    return np.frombuffer(data, dtype=record, count=count, offset=84)["corners"].astype(np.float64)


def _text(data: bytes) -> str | None:
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        return None
    return None if "\x00" in text else text


def _text_corners(data: bytes, file_type: str) -> np.ndarray:
    import io

    import trimesh

    try:
        loaded = trimesh.load(io.BytesIO(data), file_type=file_type, force="mesh", process=False)
    except Exception as exc:
        raise Unusable(f"the file cannot be parsed ({exc})") from exc
    vertices = np.asarray(getattr(loaded, "vertices", np.zeros((0, 3))), dtype=np.float64)
    faces = np.asarray(getattr(loaded, "faces", np.zeros((0, 3))), dtype=np.int64)
    return vertices[faces] if len(faces) else np.zeros((0, 3, 3))


def _checked(corners: np.ndarray, stl: bool = True) -> np.ndarray:
    """``corners`` (n × 3 × 3) if MuJoCo reads them (as an STL when ``stl``), else :class:`Unusable`."""
    if len(corners) == 0:
        raise Unusable("the mesh has no faces")
    if not np.all(np.isfinite(corners)):
        raise Unusable("the mesh has coordinates that are not finite (NaN or infinite)")
    if stl and len(corners) > MUJOCO_MAX_STL_FACES:
        raise TooManyForStl(f"the mesh has {len(corners):,} faces, over MuJoCo's {MUJOCO_MAX_STL_FACES:,} "
                            "for an STL", corners)
    return corners


def _hollow(corners: np.ndarray, scale: Vec3 | None = None) -> bool:
    """Whether the triangles, scaled, enclose (almost) no volume: |V| below 1e-6 of their box's
    volume scale, or below 1e-12 m³ (MuJoCo refuses below 1e-15: "mesh volume is too small"). V is
    summed over tetrahedra from the vertices' centroid, as MuJoCo does: from the origin, an open
    surface has the volume of the cone it makes with the origin (robosuite's flat Sawyer ``head_1.obj``,
    2.75 mm off its origin: 3.9e-6 m³, while MuJoCo finds none)."""
    corners = corners * (np.ones(3) if scale is None else np.asarray(scale, dtype=float))
    corners = corners - corners.reshape(-1, 3).mean(axis=0)
    triple = np.einsum("ij,ij->i", corners[:, 0], np.cross(corners[:, 1], corners[:, 2]))
    volume = abs(float(triple.sum())) / 6.0
    extent = float(np.max(corners.reshape(-1, 3).max(axis=0) - corners.reshape(-1, 3).min(axis=0)))
    return volume <= max(1e-6 * extent ** 3, 1e-12)


def _flat(corners: np.ndarray) -> bool:
    """Whether every vertex lies in one plane (or line), to 1e-9 of the mesh's size."""
    points = corners.reshape(-1, 3)
    centred = points - points.mean(axis=0)
    singular = np.linalg.svd(centred, compute_uv=False)
    return bool(singular[-1] <= 1e-9 * max(float(singular[0]), 1e-300))


STL_HEADER = b"modelkit binary STL".ljust(80, b" ")


def triangles_to_bytes(mesh: TriangleMeshData, file_format: str) -> bytes:
    """Triangles as a binary STL or an OBJ file; deterministic bytes.

    Written with numpy rather than trimesh: both formats are a few lines of layout, and importing
    trimesh (and scipy under it) takes 0.5-0.8 s, more than a whole conversion. Facet normals are
    computed from the winding (STL readers recompute them; zero for a degenerate triangle).
    """
    vertices = np.asarray(mesh.vertices, dtype=np.float64)
    faces = np.asarray(mesh.faces, dtype=np.int64)
    if file_format == "obj":
        texts = _coordinate_texts(vertices)
        lines = ["# modelkit OBJ"]
        lines += [f"v {texts[i]} {texts[i + 1]} {texts[i + 2]}" for i in range(0, len(texts), 3)]
        lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in faces]
        return ("\n".join(lines) + "\n").encode("ascii")
    corners = vertices[faces] if len(faces) else np.zeros((0, 3, 3))
    normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    lengths = np.linalg.norm(normals, axis=1, keepdims=True)
    normals = np.divide(normals, lengths, out=np.zeros_like(normals), where=lengths > 0)
    record = np.dtype([("normal", "<f4", 3), ("corners", "<f4", (3, 3)), ("attribute", "<u2")])
    table = np.zeros(len(faces), dtype=record)
    table["normal"] = normals
    table["corners"] = corners
    return STL_HEADER + np.uint32(len(faces)).astype("<u4").tobytes() + table.tobytes()


def _coordinate_texts(vertices: np.ndarray) -> list[str]:
    """Each coordinate as text: when all are single-precision values (an STL's), the shortest text of
    each as a float32 (``0.05``, not ``0.0500000007450581``), exact for every reader (MuJoCo reads single
    precision anyway); otherwise 15 significant digits, as many as :func:`fmt` writes at most. Both
    are formatted in C: :func:`fmt`'s search for the shortest decimal of each took 16 s of the conversion
    of a 294,002-face mesh (dexmate's gripper base); this takes under 1 s."""
    flat = np.ascontiguousarray(vertices, dtype=np.float64).ravel() + 0.0  # -0.0 → 0.0
    single = flat.astype(np.float32)
    if np.array_equal(single.astype(np.float64), flat):
        return [text[:-2] if text.endswith(".0") else text for text in map(str, single)]
    return list(map("{:.15g}".format, flat.tolist()))


def primitive_triangles(geometry: Cone | Capsule | Ellipsoid) -> TriangleMeshData:
    """A closed, outward-wound triangle mesh of a primitive in the model's convention (axis Z,
    cone apex at +length/2)."""
    import trimesh

    if isinstance(geometry, Cone):
        tm = trimesh.creation.cone(radius=geometry.radius, height=geometry.length,
                                   sections=PRIMITIVE_SECTIONS)
        tm.apply_translation([0.0, 0.0, -geometry.length / 2.0])  # trimesh: base at z=0, apex at +h
    elif isinstance(geometry, Capsule):
        tm = trimesh.creation.capsule(height=geometry.length, radius=geometry.radius,
                                      count=[PRIMITIVE_SECTIONS, PRIMITIVE_SECTIONS])
    else:
        tm = trimesh.creation.icosphere(subdivisions=3, radius=1.0)
        tm.apply_scale(np.asarray(geometry.radii, dtype=float))
    return TriangleMeshData(np.asarray(tm.vertices, dtype=float), np.asarray(tm.faces, dtype=np.int64))


# Why a mesh of this kind is converted, and what of it is not carried (said in its MK804 note).
_GLTF_WHY = ("; glTF, which MuJoCo has no decoder for, PyBullet refuses a whole URDF for, and Choreonoid "
             "does not read")
_GLTF_LOST = "; its materials and textures are not carried"
CONVERTED_WHY = {"glb": _GLTF_WHY, "gltf": _GLTF_WHY}
NOT_CARRIED = {"glb": _GLTF_LOST, "gltf": _GLTF_LOST}  # said when the file is converted whole
COLOURED_FORMATS = frozenset({"dae", "glb", "gltf"})  # mesh files whose materials give colours
Rgba = tuple[float, float, float, float]


def _written_as(ref: MeshRef, asked: str, triangles: int) -> str:
    """Why a mesh for MuJoCo is an OBJ file when ``asked`` was STL (empty otherwise)."""
    if ref.file_format == asked:
        return ""
    return f" ({triangles:,} triangles: MuJoCo reads at most {MUJOCO_MAX_STL_FACES:,} from an STL)"


def converted_stem(stem: str, source_ext: str, written_ext: str) -> str:
    """The file stem of a mesh converted from ``source_ext`` to ``written_ext``: the source's suffix
    kept in it (``base.dae`` → ``base_dae.stl``), so that it never takes the name of a mesh copied as
    it is (UR5's ``base.stl`` beside ``base.dae``). Names then follow from the files, not from the order
    in which a writer meets them: the MJCF writer met UR5's collision first and the URDF writer its
    visual, so the two gave ``base.stl`` and ``base_2.stl`` the other way round, and the two outputs
    could not share a folder (with ``--force`` one replaced the other's meshes)."""
    return stem if source_ext == written_ext else f"{stem}_{source_ext}"


TEXTURE_FOLDER = "textures"
PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


class MeshExporter:
    """Turns the model's mesh geometry into files in the output plan, once each."""

    def __init__(self, plan: OutputPlan, model_relpath: str, options: WriteOptions, notes: NoteSink) -> None:
        self.plan = plan
        self.options = options
        self.notes = notes
        depth = model_relpath.count("/")
        self.prefix = "../" * depth  # from the model file's folder back to the output folder

    def _stage(self, data: bytes, name: str) -> str:
        relpath = self.plan.add(f"{MESH_FOLDER}/{name}", data, "mesh")
        return self.prefix + relpath

    def texture(self, uri: str, base: Path | None, target: str, source: SourceLocation | None,
                png_only: bool = False) -> str | None:
        """The image ``uri`` (a path, relative to ``base``, or a package:// or file:// URI) copied into the
        output's ``textures/`` folder: its reference from the model file, or None with an MK818 note
        (unreadable; not a PNG where the target reads PNG only, as MuJoCo does)."""
        from modelkit.resources import Resolver

        path = Path(uri)
        if not path.is_absolute():
            where = base if base is not None else Path.cwd()
            resolution = Resolver().resolve(uri, where, None)
            path = resolution.path if resolution.path is not None else where / uri
        try:
            data = path.read_bytes()
            self.plan.protect(path)
        except OSError:
            self.notes.note("MK818", f'texture "{uri}" cannot be read; the visual keeps its colour only',
                            source, target)
            return None
        if png_only and not data.startswith(PNG_SIGNATURE):
            self.notes.note("MK818", f'texture "{uri}" is not a PNG image, the only kind MuJoCo reads; the '
                            "visual keeps its colour only", source, target)
            return None
        relpath = self.plan.add(f"{TEXTURE_FOLDER}/{safe_file_name(path.name, 'texture')}", data, "texture")
        return self.prefix + relpath

    def triangles(self, mesh: TriangleMeshData, name: str, scale: Vec3 | None = None,
                  file_format: str | None = None) -> MeshRef:
        ext = file_format or self.options.mesh_format
        uri = self._stage(triangles_to_bytes(mesh, ext), f"{safe_file_name(name, 'mesh')}.{ext}")
        return MeshRef(uri, np.ones(3) if scale is None else np.asarray(scale, dtype=float), ext)

    def primitive(self, geometry: Cone | Capsule | Ellipsoid, name: str, target: str,
                  source: SourceLocation | None) -> MeshRef:
        kind = type(geometry).__name__.lower()
        self.notes.note("MK802", f"the target has no {kind}; written as a triangle mesh "
                        f"({PRIMITIVE_SECTIONS} segments around the axis)", source, target)
        return self.triangles(primitive_triangles(geometry), name)

    def mesh(self, geometry: Mesh, name: str, target: str, source: SourceLocation | None,
             readable: tuple[str, ...], mujoco: bool = False, collision: bool = False) -> MeshRef | None:
        """A reference for ``geometry`` that the target reads (``readable``: "stl", "obj", "dae").

        Returns None (with an MK805 note) when the mesh is missing or unreadable; the note is an error
        (``convert`` exits 1) for a ``collision`` shape. With ``mujoco``, a file copied as is is made
        readable by MuJoCo first (:func:`for_mujoco`).
        """
        ref, missing = self._mesh(geometry, name, target, source, readable, mujoco, collision)
        if ref is not None and ref.plate is not None:
            size = " × ".join(f"{x:.6g}" for x in ref.plate.size)
            what = geometry.uri or name
            self.notes.note("MK881", f"collision mesh {what} is flat (all its vertices in one plane), and "
                            "MuJoCo cannot build the convex hull it collides with: written as a box of "
                            f"{size} m in that plane", source, target)
        if ref is None:
            role = "collision shape" if collision else "shape"
            self.notes.note("MK805", f"{missing}; the {role} is left out", source, target,
                            severity=Severity.ERROR if collision else None)
        return ref

    def _mesh(self, geometry: Mesh, name: str, target: str, source: SourceLocation | None,
              readable: tuple[str, ...], mujoco: bool, collision: bool) -> tuple[MeshRef | None, str]:
        """The reference, or None and why the mesh is left out."""
        scale = np.asarray(geometry.scale, dtype=float)
        if geometry.data is not None and (geometry.path is None or geometry.generator):
            kind = geometry.generator or "in-memory mesh"
            self.notes.note("MK803", f"{kind} written as a mesh file", source, target)
            if mujoco:
                ref, why = self._mujoco_triangles(geometry.data, name, scale, kind, collision)
                if ref is not None and ref.file_format != self.options.mesh_format:
                    self.notes.note("MK804", f"{kind} written as OBJ"
                                    f"{_written_as(ref, self.options.mesh_format, len(geometry.data.faces))}",
                                    source, target)
                return ref, why
            return self.triangles(geometry.data, name, scale), ""
        uri = geometry.uri or ""
        if (self.options.keep_package_uris and uri.startswith(("package://", "model://"))
                and not geometry.fragment):
            ext = Path(uri).suffix.lower().lstrip(".")
            if ext in readable:
                return MeshRef(uri, scale, ext), ""
        if geometry.path is None:
            return None, f"mesh {uri or '(no uri)'} was not found"
        from modelkit.geometry.meshfiles import MeshLoadError, MeshMetadata

        meta = geometry.source_params.get("metadata")
        metadata = (MeshMetadata(meta.get("length_unit"), meta.get("upper_axis"))
                    if isinstance(meta, dict) and meta else None)
        path = Path(geometry.path)
        ext = path.suffix.lower().lstrip(".")
        as_is = ext in readable and not geometry.fragment and metadata is None
        if as_is and (ext != "dae" or self.options.keep_collada):
            try:
                data = path.read_bytes()
                self.plan.protect(path)
            except OSError as exc:
                return None, f"mesh {uri} cannot be read ({exc.strerror})"
            if not mujoco:
                binary = as_binary_stl(data) if ext == "stl" else None
                if binary is not None:
                    data = binary.data
                    why = "PyBullet reads only binary STL (an ASCII one crashed it, measured)"
                    self.notes.note("MK804", f"mesh {path.name} ({binary.converted}) converted to binary "
                                    f"STL: {why}, and every consumer reads it", source, target)
                return MeshRef(self._stage(data, safe_file_name(path.name, "mesh")), scale, ext), ""
            try:
                ready = for_mujoco(data, ext, scale)
            except TooManyForStl as exc:
                from modelkit.geometry.meshfiles import merge_identical_vertices

                faces = np.arange(exc.corners.size // 3, dtype=np.int64).reshape(-1, 3)
                mesh = TriangleMeshData(*merge_identical_vertices(exc.corners.reshape(-1, 3), faces))
                ref, why = self._mujoco_triangles(mesh, path.stem, scale, f"mesh {uri}", collision)
                if ref is not None:
                    self.notes.note("MK804", f"mesh {path.name} converted to {ref.file_format.upper()}"
                                    f"{_written_as(ref, 'stl', len(faces))}", source, target)
                return ref, why
            except Unusable as exc:
                return None, f"mesh {uri} cannot be read by MuJoCo ({exc})"
            if ready.plate is not None and collision:
                return MeshRef("", scale, "box", plate=ready.plate), ""
            file_name = safe_file_name(path.name, "mesh")
            if ready.cleaned is not None:
                self.notes.note("MK804", f"mesh {path.name} written for MuJoCo without {ready.cleaned}",
                                source, target)
            if ready.converted is not None:
                file_name = f"{safe_file_name(converted_stem(path.stem, ext, 'stl'), 'mesh')}.stl"
                why = "the only STL MuJoCo reads" if ext == "stl" else "which MuJoCo reads whole"
                self.notes.note("MK804", f"mesh {path.name} ({ready.converted}) converted to binary STL, "
                                f"{why}", source, target)
            return MeshRef(self._stage(ready.data, file_name), scale, "stl" if ready.converted else ext,
                           ready.hollow), ""
        try:
            loaded = _loaded(path, geometry.fragment, metadata)
        except MeshLoadError as exc:
            return None, f"mesh {uri} cannot be loaded ({exc.message})"
        part = f"#{geometry.fragment}" if geometry.fragment else ""
        unit = f", unit scale {loaded.unit_scale:g} applied" if loaded.unit_scale != 1.0 else ""
        written = "stl" if mujoco else self.options.mesh_format
        part_stem = path.stem + (f"_{geometry.fragment}" if geometry.fragment else "")
        stem = converted_stem(part_stem, ext, written)
        if mujoco:
            ref, why = self._mujoco_triangles(loaded.mesh, stem, scale, f"mesh {uri}", collision)
        elif not len(loaded.mesh.faces):  # an empty STL or OBJ: PyBullet says so, RViz shows nothing
            return None, f"mesh {uri}{part} holds no triangles"
        else:
            ref, why = self.triangles(loaded.mesh, stem, scale), ""
        if ref is not None:
            obj_why = _written_as(ref, self.options.mesh_format, len(loaded.mesh.faces))
            self.notes.note("MK804", f"mesh {path.name}{part} ({loaded.source_format}) converted to "
                            f"{ref.file_format.upper()}{unit}{obj_why}{CONVERTED_WHY.get(ext, '')}"
                            f"{NOT_CARRIED.get(ext, '')}",
                            source, target)
        return ref, why

    def coloured_parts(self, geometry: Mesh, target: str, source: SourceLocation | None,
                       readable: tuple[str, ...], mujoco: bool = False
                       ) -> list[tuple[MeshRef, Rgba | None]] | None:
        """A visual COLLADA or glTF file whose materials give colours, and which the target converts (it
        does not read it, ``readable``), as one mesh per colour, each with its colour (RGBA; None for
        faces without one): the STL or OBJ it becomes holds no colour, so the writer gives each part's
        shape its colour, as MuJoCo Menagerie splits its visual meshes by material. None when the file
        is copied as it is, gives no colour or cannot be read (:meth:`mesh` then writes it whole, or
        says why not)."""
        from modelkit.geometry.meshfiles import MeshLoadError, MeshMetadata, compact_mesh

        if geometry.path is None or geometry.generator or geometry.data is not None:
            return None
        path = Path(geometry.path)
        ext = path.suffix.lower().lstrip(".")
        if ext not in COLOURED_FORMATS:
            return None
        meta = geometry.source_params.get("metadata")
        metadata = (MeshMetadata(meta.get("length_unit"), meta.get("upper_axis"))
                    if isinstance(meta, dict) and meta else None)
        copied = ext in readable and not geometry.fragment and metadata is None
        if copied and (ext != "dae" or self.options.keep_collada):
            return None  # the file keeps its own colours
        try:
            loaded = _loaded(path, geometry.fragment, metadata)
        except MeshLoadError:
            return None
        if loaded.face_colours is None:
            return None
        self.plan.protect(path)
        scale = np.asarray(geometry.scale, dtype=float)
        part = f"#{geometry.fragment}" if geometry.fragment else ""
        written = "stl" if mujoco else self.options.mesh_format
        fragment = f"_{geometry.fragment}" if geometry.fragment else ""
        stem = converted_stem(path.stem + fragment, ext, written)
        used = [k for k in range(len(loaded.palette)) if np.any(loaded.face_colours == k)]
        parts: list[tuple[MeshRef, Rgba | None]] = []
        for k in used:
            vertices, faces = compact_mesh(loaded.mesh.vertices, loaded.mesh.faces[loaded.face_colours == k])
            part_name = stem if len(used) == 1 else f"{stem}_{len(parts)}"
            mesh = TriangleMeshData(vertices, faces)
            if mujoco:
                ref, _ = self._mujoco_triangles(mesh, part_name, scale, f"mesh {geometry.uri}", False)
            else:
                ref = self.triangles(mesh, part_name, scale)
            if ref is None:
                return None
            parts.append((ref, loaded.palette[k]))
        unit = f", unit scale {loaded.unit_scale:g} applied" if loaded.unit_scale != 1.0 else ""
        files = "one file" if len(parts) == 1 else f"{len(parts)} files, one per colour"
        kinds = sorted({ref.file_format.upper() for ref, _ in parts})
        self.notes.note("MK804", f"mesh {path.name}{part} ({loaded.source_format}) converted to {files} "
                        f"({'/'.join(kinds)}, which hold no colour: each part's shape has its material's "
                        f"colour){unit}{CONVERTED_WHY.get(ext, '')}", source, target)
        return parts

    def _mujoco_triangles(self, mesh: TriangleMeshData, name: str, scale: Vec3, what: str,
                          collision: bool) -> tuple[MeshRef | None, str]:
        """Triangles written for MuJoCo: the checks of :func:`for_mujoco`, applied before staging; as OBJ
        when an STL would hold more triangles than MuJoCo reads from one."""
        vertices = np.asarray(mesh.vertices, dtype=np.float64)
        faces = np.asarray(mesh.faces, dtype=np.int64)
        try:
            corners = _checked(vertices[faces] if len(faces) else np.zeros((0, 3, 3)), stl=False)
        except Unusable as exc:
            return None, f"{what} cannot be read by MuJoCo ({exc})"
        if collision and _flat(corners):
            return MeshRef("", scale, "box", plate=plate_of(corners, scale)), ""
        file_format = self.options.mesh_format
        if file_format == "stl" and len(corners) > MUJOCO_MAX_STL_FACES:
            file_format = "obj"  # MuJoCo's OBJ reader has no such bound (dexmate's gripper base: 294,002)
        ref = self.triangles(mesh, name, scale, file_format)
        return MeshRef(ref.uri, ref.scale, ref.file_format, _hollow(corners, scale)), ""
