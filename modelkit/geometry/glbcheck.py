"""A fast verdict on a binary glTF (``.glb``) file: would :func:`modelkit.geometry.meshfiles.load_mesh` load
it, and where are its triangles?

``modelkit validate`` needs two things from a mesh: whether it loads, and the corners of its triangles
(the shape rules compare a collision's extent with its visual's). Loading a ``.glb`` through trimesh
costs the import of trimesh and scipy (about a second on a cold start) and the building of a scene; this
module reads the file's JSON and its binary chunk with the standard library and numpy only.

It decides only the plain, common case, the one exporters such as Blender write: one JSON chunk and one
binary chunk filling the file, every accessor in its buffer view, triangle lists (mode 4) with
``POSITION`` as float ``VEC3`` and unsigned indices inside the vertices, node transforms given as a
matrix or as translation, rotation and scale, a tree of nodes, materials whose values trimesh's
material accepts. In that case trimesh (``modelkit.geometry.gltf``) reads the file, and the triangles
are where the nodes place them: the verdict is None (the file loads) and the corners are those of the
placed vertices, as :func:`meshfiles.flatten_scene` computes them.

Anything else (a ``.gltf`` with its buffers named by URI, sparse or quantised accessors, Draco or other
required extensions, skins and morph targets, cameras, lines and points, an index past the vertices, a
non-finite number, a value trimesh's material setters refuse) gives :data:`UNDECIDED`: the caller then
loads the file with trimesh, which gives the verdict and its message.
"""

from __future__ import annotations

import json
import math
import struct
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from modelkit.rot3 import from_quat_wxyz

__all__ = ["UNDECIDED", "GlbVerdict", "glb_verdict"]

UNDECIDED = "UNDECIDED\tthe fast glTF check cannot decide; load the file"

_MAGIC, _JSON, _BIN = 0x46546C67, 0x4E4F534A, 0x004E4942
_COMPONENTS: dict[int, np.dtype[Any]] = {
    5120: np.dtype("<i1"), 5121: np.dtype("<u1"), 5122: np.dtype("<i2"), 5123: np.dtype("<u2"),
    5125: np.dtype("<u4"), 5126: np.dtype("<f4"),
}
_UNSIGNED = (5121, 5123, 5125)
_WIDTHS = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT2": 4, "MAT3": 9, "MAT4": 16}
_TRIANGLES = 4
# vertex attributes trimesh reads with checks of its own (COLOR_0, inside a try) or not at all
_IGNORED_ATTRIBUTES = ("COLOR_0", "TANGENT")
# material extensions trimesh 5.x has no handler for (they are kept as unused keys): a handled one
# (KHR_materials_pbrSpecularGlossiness) rewrites the material's values, so it is left to trimesh
PASSIVE_MATERIAL_EXTENSIONS = frozenset({
    "KHR_materials_anisotropy", "KHR_materials_clearcoat", "KHR_materials_dispersion",
    "KHR_materials_emissive_strength", "KHR_materials_ior", "KHR_materials_iridescence",
    "KHR_materials_sheen", "KHR_materials_specular", "KHR_materials_transmission", "KHR_materials_unlit",
    "KHR_materials_volume",
})
_ALPHA_MODES = ("OPAQUE", "MASK", "BLEND")
# meshfiles.MAX_TRIANGLES and a bound under its MAX_NODE_VISITS: larger scenes are for the full loader
MAX_TRIANGLES, MAX_NODES = 5_000_000, 100_000

Corners = tuple[tuple[float, float, float], tuple[float, float, float]]


class _Undecided(Exception):
    """Only the full loader can tell."""


@dataclass(frozen=True)
class GlbVerdict:
    """The file loads (``problem`` None) with its triangles within ``corners``, or :data:`UNDECIDED`."""

    problem: str | None
    corners: Corners | None = None


def glb_verdict(data: bytes) -> GlbVerdict:
    """None and the corners of the placed triangles when ``load_mesh`` surely loads these ``.glb`` bytes
    (no fragment, no metadata); :data:`UNDECIDED` otherwise."""
    try:
        with np.errstate(all="ignore"):
            return GlbVerdict(None, _corners(data))
    except (_Undecided, ValueError, TypeError, KeyError, IndexError, OverflowError, RecursionError):
        return GlbVerdict(UNDECIDED)


def _need(condition: bool) -> None:
    if not condition:
        raise _Undecided


def _int(value: object, low: int = 0) -> int:
    _need(type(value) is int and value >= low)
    return value  # type: ignore[return-value]


def _numbers(value: object, count: int) -> list[float]:
    """``count`` finite JSON numbers (not booleans)."""
    if not isinstance(value, list) or len(value) != count:
        raise _Undecided
    _need(all(type(v) in (int, float) for v in value))
    numbers = [float(v) for v in value]
    _need(all(map(math.isfinite, numbers)))
    return numbers


# ---- the file: header, JSON chunk, binary chunk ------------------------------------------------


def _chunks(data: bytes) -> tuple[dict[str, Any], bytes]:
    _need(len(data) >= 28)
    magic, version, length = struct.unpack_from("<III", data, 0)
    _need(magic == _MAGIC and version == 2 and length == len(data))
    json_length, json_type = struct.unpack_from("<II", data, 12)
    json_end = 20 + json_length
    _need(json_type == _JSON and json_end + 8 <= len(data))
    bin_length, bin_type = struct.unpack_from("<II", data, json_end)
    _need(bin_type == _BIN and json_end + 8 + bin_length == len(data))
    header = json.loads(data[20:json_end].decode("utf-8"))
    _need(isinstance(header, dict))
    _need("extensionsRequired" not in header)
    return header, data[json_end + 8:]


def _list(header: dict[str, Any], key: str) -> list[Any]:
    value = header.get(key, [])
    _need(isinstance(value, list) and all(isinstance(item, dict) for item in value))
    return value


def _views(header: dict[str, Any], binary: bytes) -> list[tuple[int, int, int | None]]:
    """Each buffer view's (start, length, stride) in the binary chunk."""
    buffers = _list(header, "buffers")
    _need(len(buffers) == 1 and "uri" not in buffers[0])
    _need(_int(buffers[0].get("byteLength")) <= len(binary))
    views = []
    for view in _list(header, "bufferViews"):
        _need(_int(view.get("buffer")) == 0)
        start, length = _int(view.get("byteOffset", 0)), _int(view.get("byteLength"), 1)
        _need(start + length <= len(binary))
        stride = _int(view["byteStride"], 1) if "byteStride" in view else None
        views.append((start, length, stride))
    return views


def _accessors(header: dict[str, Any], binary: bytes,
               views: list[tuple[int, int, int | None]]) -> list[tuple[int, str, NDArray[Any]]]:
    """Every accessor as (componentType, type, its values (count, width)); trimesh reads all of them."""
    out = []
    for accessor in _list(header, "accessors"):
        _need("sparse" not in accessor and not accessor.get("normalized", False))
        component, kind = accessor.get("componentType"), accessor.get("type")
        _need(component in _COMPONENTS and kind in _WIDTHS)
        dtype, width = _COMPONENTS[component], _WIDTHS[kind]
        count = _int(accessor.get("count"), 1)
        view_start, view_length, stride = views[_int(accessor.get("bufferView"))]
        offset = _int(accessor.get("byteOffset", 0))
        row = dtype.itemsize * width
        step = row if stride is None else stride
        _need(offset + (count - 1) * step + row <= view_length)
        size = (count - 1) * step + row
        raw = np.frombuffer(binary, dtype=np.uint8, count=size, offset=view_start + offset)
        rows = np.lib.stride_tricks.as_strided(raw, (count, row), (step, 1))
        out.append((component, kind, rows.view(dtype)))  # a view of the bytes: (count, width), no copy
    return out


# ---- materials, meshes, nodes --------------------------------------------------------------------


def _check_materials(header: dict[str, Any]) -> int:
    """The number of materials, each one trimesh's ``PBRMaterial`` takes as it is."""
    materials = _list(header, "materials")
    for material in materials:
        _need(isinstance(material.get("name", ""), str))
        _need(isinstance(material.get("doubleSided", False), bool))
        _need(material.get("alphaMode", "OPAQUE") in _ALPHA_MODES)
        if "alphaCutoff" in material:
            _numbers([material["alphaCutoff"]], 1)
        if "emissiveFactor" in material:
            _need(min(_numbers(material["emissiveFactor"], 3)) >= 0.0)
        pbr = material.get("pbrMetallicRoughness", {})
        _need(isinstance(pbr, dict))
        if "baseColorFactor" in pbr:
            factor = pbr["baseColorFactor"]
            _need(isinstance(factor, list) and len(factor) in (3, 4))
            _need(all(0.0 <= v <= 1.0 for v in _numbers(factor, len(factor))))
        for key in ("metallicFactor", "roughnessFactor"):
            if key in pbr:
                _numbers([pbr[key]], 1)
        for key, value in (*material.items(), *pbr.items()):
            if key.endswith("Texture"):
                _need(isinstance(value, dict))
        extensions = material.get("extensions", {})
        _need(isinstance(extensions, dict) and set(extensions) <= PASSIVE_MATERIAL_EXTENSIONS)
    for image in _list(header, "images"):  # trimesh reads each image's view outside its own try
        if "bufferView" in image:
            _need(_int(image["bufferView"]) < len(_list(header, "bufferViews")))
    return len(materials)


Triangles = tuple[NDArray[np.float64], int]  # (vertices (n, 3), triangles)


def _meshes(header: dict[str, Any], accessors: list[tuple[int, str, NDArray[Any]]],
            materials: int) -> list[list[Triangles]]:
    """Each mesh's primitives as (vertices, triangle count), read as trimesh reads them."""
    out = []
    for mesh in _list(header, "meshes"):
        _need(isinstance(mesh.get("name", ""), str) and "extensions" not in mesh)
        primitives = mesh.get("primitives")
        _need(isinstance(primitives, list) and len(primitives) > 0)
        out.append([_primitive(p, accessors, materials) for p in primitives])
    return out


def _primitive(primitive: object, accessors: list[tuple[int, str, NDArray[Any]]],
               materials: int) -> Triangles:
    if not isinstance(primitive, dict):
        raise _Undecided
    _need(primitive.get("mode", _TRIANGLES) == _TRIANGLES)
    _need(not ({"extensions", "targets"} & set(primitive)))
    attributes = primitive.get("attributes")
    if not isinstance(attributes, dict):
        raise _Undecided
    component, kind, positions = accessors[_int(attributes.get("POSITION"))]
    _need(component == 5126 and kind == "VEC3")
    count = len(positions)
    for name, index in attributes.items():
        if name == "POSITION" or name in _IGNORED_ATTRIBUTES:
            continue
        component, kind, values = accessors[_int(index)]
        wanted = {"NORMAL": "VEC3", "TEXCOORD_0": "VEC2"}.get(name)
        _need(wanted is not None and kind == wanted and component == 5126 and len(values) == count)
    if "material" in primitive:
        _need(_int(primitive["material"]) < materials)
    if "indices" in primitive:
        component, kind, indices = accessors[_int(primitive["indices"])]
        _need(component in _UNSIGNED and kind == "SCALAR" and len(indices) % 3 == 0)
        _need(int(indices.max()) < count)
        triangles = len(indices) // 3
    else:
        _need(count % 3 == 0)
        triangles = count // 3
    vertices = positions.astype(np.float64)
    _need(bool(np.all(np.isfinite(vertices))))
    return vertices, triangles


def _node_matrix(node: dict[str, Any]) -> NDArray[np.float64]:
    """The node's transform in its parent: its matrix (column-major), then T·R·S."""
    _need(not ({"camera", "skin", "weights", "extensions"} & set(node)))
    matrix = np.eye(4)
    if "matrix" in node:
        matrix = np.asarray(_numbers(node["matrix"], 16)).reshape(4, 4).T
    if "translation" in node:
        moved = np.eye(4)
        moved[:3, 3] = _numbers(node["translation"], 3)
        matrix = matrix @ moved
    if "rotation" in node:
        x, y, z, w = _numbers(node["rotation"], 4)
        _need(w * w + x * x + y * y + z * z > 1e-12)
        turned = np.eye(4)
        turned[:3, :3] = from_quat_wxyz((w, x, y, z))
        matrix = matrix @ turned
    if "scale" in node:
        matrix = matrix @ np.diag([*_numbers(node["scale"], 3), 1.0])
    return matrix


def _placed(header: dict[str, Any], meshes: list[list[Triangles]]) -> Iterator[Triangles]:
    """Every primitive the default scene places: its vertices where its nodes place them, its triangles."""
    nodes = _list(header, "nodes")
    scenes = _list(header, "scenes")
    _need(len(scenes) > 0 and len(nodes) <= MAX_NODES)
    roots = scenes[_int(header.get("scene", 0))].get("nodes", [])
    _need(isinstance(roots, list))
    stack = [(_int(root), np.eye(4)) for root in roots]
    seen: set[int] = set()
    while stack:
        index, parent = stack.pop()
        _need(index < len(nodes) and index not in seen)  # a tree: no node reached twice
        seen.add(index)
        node = nodes[index]
        _need(isinstance(node.get("name", ""), str))
        placed = parent @ _node_matrix(node)
        if "mesh" in node:
            for vertices, triangles in meshes[_int(node["mesh"])]:
                yield vertices @ placed[:3, :3].T + placed[:3, 3], triangles
        children = node.get("children", [])
        _need(isinstance(children, list))
        stack.extend((_int(child), placed) for child in children)


def _corners(data: bytes) -> Corners:
    header, binary = _chunks(data)
    accessors = _accessors(header, binary, _views(header, binary))
    meshes = _meshes(header, accessors, _check_materials(header))
    low, high = np.full(3, np.inf), np.full(3, -np.inf)
    triangles = 0
    for placed, count in _placed(header, meshes):
        _need(bool(np.all(np.isfinite(placed))))
        low, high = np.minimum(low, placed.min(axis=0)), np.maximum(high, placed.max(axis=0))
        triangles += count
        _need(triangles <= MAX_TRIANGLES)
    _need(triangles > 0)
    return ((float(low[0]), float(low[1]), float(low[2])), (float(high[0]), float(high[1]), float(high[2])))
