"""The fast ``.glb`` verdict (modelkit.geometry.glbcheck) against the full loader (meshfiles.load_mesh, which
reads glTF through trimesh).

``validate`` asks of a mesh whether it loads and where its triangles are. For a plain ``.glb`` the fast
check answers without trimesh: it may say None (loads) only when ``load_mesh`` loads the file, and its
corners must be those of the triangles ``load_mesh`` places. Anything else is ``UNDECIDED``, and the
caller loads the file. Files here are built byte by byte as exporters write them (Blender: nodes with
translation, rotation and scale, several primitives, materials with extensions), then broken on purpose
in the ways the check must leave to trimesh, and flipped at random.
"""

from __future__ import annotations

import copy
import json
import random
import struct
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from modelkit.geometry import glbcheck, meshfiles
from modelkit.geometry.glbcheck import UNDECIDED, glb_verdict
from modelkit.geometry.meshfiles import mesh_problem
from tests.test_objcheck import reference_and_corners as full_load

BOX = np.array([[x, y, z] for x in (-1.0, 1.0) for y in (-2.0, 2.0) for z in (-3.0, 3.0)], dtype="<f4") * 0.01
BOX_FACES = np.array([0, 1, 3, 0, 3, 2, 4, 6, 7, 4, 7, 5, 0, 4, 5, 0, 5, 1, 2, 3, 7, 2, 7, 6, 0, 2, 6,
                      0, 6, 4, 1, 5, 7, 1, 7, 3], dtype="<u2")


def _pad(data: bytes, fill: bytes) -> bytes:
    return data + fill * (-len(data) % 4)


def document() -> tuple[dict[str, Any], bytes]:
    """A glTF scene as Blender writes one: a parent node moved and turned, a child scaled holding a mesh of
    two primitives (indexed, and a plain triangle list read with a byte stride), a node without a mesh,
    and materials with extensions trimesh keeps but does not use."""
    normals = np.tile(np.array([[0.0, 0.0, 1.0]], dtype="<f4"), (8, 1))
    interleaved = np.hstack([BOX + np.float32(0.5), normals]).astype("<f4")  # stride 24: position, normal
    triangle = np.array([[0.0, 0.0, 0.0], [0.02, 0.0, 0.0], [0.0, 0.03, 0.0]], dtype="<f4")
    blobs = [BOX.tobytes(), normals.tobytes(), _pad(BOX_FACES.tobytes(), b"\0"), interleaved.tobytes(),
             triangle.tobytes()]
    views, offset = [], 0
    for blob in blobs:
        views.append({"buffer": 0, "byteOffset": offset, "byteLength": len(blob)})
        offset += len(blob)
    views[3]["byteStride"] = 24
    binary = b"".join(blobs)
    accessors = [
        {"bufferView": 0, "componentType": 5126, "count": 8, "type": "VEC3", "min": [-0.01, -0.02, -0.03],
         "max": [0.01, 0.02, 0.03]},
        {"bufferView": 1, "componentType": 5126, "count": 8, "type": "VEC3"},
        {"bufferView": 2, "componentType": 5123, "count": 36, "type": "SCALAR"},
        {"bufferView": 3, "componentType": 5126, "count": 8, "type": "VEC3"},
        {"bufferView": 3, "byteOffset": 12, "componentType": 5126, "count": 8, "type": "VEC3"},
        {"bufferView": 4, "componentType": 5126, "count": 3, "type": "VEC3"},
    ]
    header: dict[str, Any] = {
        "asset": {"version": "2.0", "generator": "hand"},
        "extensionsUsed": ["KHR_materials_clearcoat", "KHR_materials_ior"],
        "scene": 0,
        "scenes": [{"nodes": [0, 3]}],
        "nodes": [
            {"name": "base", "translation": [0.1, -0.2, 0.3], "rotation": [0.0, 0.0, 0.3826834, 0.9238795],
             "children": [1, 2]},
            {"name": "part", "mesh": 0, "scale": [2.0, 1.0, 0.5]},
            {"name": "empty", "matrix": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0.5, 0, 0, 1]},
            {"name": "loose", "mesh": 1, "matrix": [0, 1, 0, 0, -1, 0, 0, 0, 0, 0, 1, 0, 1.0, 2.0, 3.0, 1]},
        ],
        "meshes": [
            {"name": "body", "primitives": [
                {"attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 2, "material": 0},
                {"attributes": {"POSITION": 3, "NORMAL": 4}, "indices": 2, "material": 1}]},
            {"name": "flat", "primitives": [{"attributes": {"POSITION": 5}}]},
        ],
        "materials": [
            {"name": "paint", "doubleSided": True, "emissiveFactor": [0.0, 0.0, 0.0],
             "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.1, 0.1, 1.0], "metallicFactor": 0.0,
                                      "roughnessFactor": 0.5},
             "extensions": {"KHR_materials_clearcoat": {"clearcoatFactor": 1.0}}},
            {"name": "steel", "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1.0]},
             "extensions": {"KHR_materials_ior": {"ior": 1.45}}},
        ],
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"byteLength": len(binary)}],
    }
    return header, binary


def glb(header: dict[str, Any], binary: bytes) -> bytes:
    text = _pad(json.dumps(header).encode(), b" ")
    binary = _pad(binary, b"\0")
    total = 12 + 8 + len(text) + 8 + len(binary)
    return (struct.pack("<III", 0x46546C67, 2, total) + struct.pack("<II", len(text), 0x4E4F534A) + text
            + struct.pack("<II", len(binary), 0x004E4942) + binary)


def agrees(path: Path) -> bool:
    """The fast verdict is UNDECIDED, or the full loader loads the file with the same corners. Returns
    whether the fast check decided."""
    fast = glb_verdict(path.read_bytes())
    if fast.problem == UNDECIDED:
        return False
    assert fast.problem is None and fast.corners is not None
    problem, corners = full_load(path)
    assert problem is None, f"the fast check says {path.name} loads; load_mesh: {problem}"
    np.testing.assert_allclose(np.array(fast.corners), corners, rtol=1e-12, atol=1e-12)
    return True


def test_an_exporters_glb_is_decided_with_the_full_loaders_corners(tmp_path: Path) -> None:
    path = tmp_path / "part.glb"
    path.write_bytes(glb(*document()))
    assert agrees(path)
    # the corners span the scaled, turned box and the loose triangle placed by its column-major matrix
    corners = np.array(glb_verdict(path.read_bytes()).corners)
    assert corners[1][2] == pytest.approx(3.0)  # the loose triangle at z = 3
    assert corners[0][1] < -0.19  # the box under the moved base


def _mutations() -> dict[str, Any]:
    """Files the fast check must leave to trimesh (each changes one thing of ``document()``)."""
    def header_change(change: Any) -> Any:
        def make() -> bytes:
            header, binary = document()
            change(header)
            return glb(header, binary)
        return make

    def prim(key: str, value: Any) -> Any:
        return header_change(lambda h: h["meshes"][0]["primitives"][0].__setitem__(key, value))

    def node(key: str, value: Any) -> Any:
        return header_change(lambda h: h["nodes"][1].__setitem__(key, value))

    def accessor(key: str, value: Any, index: int = 0) -> Any:
        return header_change(lambda h: h["accessors"][index].__setitem__(key, value))

    def material(key: str, value: Any) -> Any:
        return header_change(lambda h: h["materials"][0].__setitem__(key, value))

    def pbr(key: str, value: Any) -> Any:
        return header_change(lambda h: h["materials"][0]["pbrMetallicRoughness"].__setitem__(key, value))

    def binary_change(change: Any) -> Any:
        def make() -> bytes:
            header, binary = document()
            return glb(header, change(bytearray(binary)))
        return make

    def nan_vertex(b: bytearray) -> bytes:
        b[0:4] = struct.pack("<f", float("nan"))
        return bytes(b)

    def far_index(b: bytearray) -> bytes:
        start = len(BOX.tobytes()) * 2
        b[start:start + 2] = struct.pack("<H", 9)
        return bytes(b)

    whole = glb(*document())
    return {
        "truncated": lambda: whole[:-8],
        "wrong magic": lambda: b"gLTF" + whole[4:],
        "version 1": lambda: whole[:4] + struct.pack("<I", 1) + whole[8:],
        "trailing bytes": lambda: whole + b"\0" * 12,
        "no binary chunk": lambda: whole[:20 + struct.unpack_from("<I", whole, 12)[0]],
        "required extension": header_change(lambda h: h.__setitem__("extensionsRequired",
                                                                    ["KHR_draco_mesh_compression"])),
        "external buffer": header_change(lambda h: h["buffers"][0].__setitem__("uri", "part.bin")),
        "view past the buffer": header_change(lambda h: h["bufferViews"][0].__setitem__("byteLength", 10**6)),
        "accessor past its view": accessor("count", 9),
        "sparse accessor": accessor("sparse", {"count": 1}),
        "quantised positions": accessor("componentType", 5123),
        "unknown component type": accessor("componentType", 5124),
        "unknown accessor type": accessor("type", "VEC5"),
        "accessor without a view": header_change(lambda h: h["accessors"][0].pop("bufferView")),
        "lines": prim("mode", 1),
        "triangle strip": prim("mode", 5),
        "draco primitive": prim("extensions", {"KHR_draco_mesh_compression": {}}),
        "morph targets": prim("targets", [{"POSITION": 0}]),
        "skinned attribute": prim("attributes", {"POSITION": 0, "JOINTS_0": 2}),
        "custom attribute": prim("attributes", {"POSITION": 0, "_ID": 2}),
        "normals of another length": prim("attributes", {"POSITION": 0, "NORMAL": 5}),
        "missing material": prim("material", 7),
        "signed indices": accessor("componentType", 5122, index=2),
        "index past the vertices": binary_change(far_index),
        "non-finite vertex": binary_change(nan_vertex),
        "camera node": node("camera", 0),
        "skinned node": node("skin", 0),
        "missing mesh": node("mesh", 9),
        "node reached twice": header_change(lambda h: h["nodes"][0].__setitem__("children", [1, 1, 2])),
        "node cycle": header_change(lambda h: h["nodes"][1].__setitem__("children", [0])),
        "zero rotation": node("rotation", [0.0, 0.0, 0.0, 0.0]),
        "short matrix": node("matrix", [1, 0, 0]),
        "string scale": node("scale", ["2", 1, 1]),
        "no scenes": header_change(lambda h: h.pop("scenes")),
        "scene out of range": header_change(lambda h: h.__setitem__("scene", 4)),
        "bad alpha mode": material("alphaMode", "GLOWING"),
        "negative emission": material("emissiveFactor", [-1.0, 0.0, 0.0]),
        "colour above one": pbr("baseColorFactor", [2.0, 0.0, 0.0, 1.0]),
        "five colour channels": pbr("baseColorFactor", [0.1, 0.1, 0.1, 1.0, 1.0]),
        "handled material extension": material("extensions", {"KHR_materials_pbrSpecularGlossiness": {}}),
        "texture given as a number": material("normalTexture", 3),
        "empty mesh": header_change(lambda h: h["meshes"][1].__setitem__("primitives", [])),
        "nothing placed": header_change(lambda h: h["scenes"][0].__setitem__("nodes", [])),
        "json not an object": lambda: glb([], document()[1]),  # type: ignore[arg-type]
    }


@pytest.mark.parametrize("name", sorted(_mutations()))
def test_what_the_fast_check_cannot_settle_is_left_to_trimesh(tmp_path: Path, name: str) -> None:
    path = tmp_path / "part.glb"
    path.write_bytes(_mutations()[name]())
    assert glb_verdict(path.read_bytes()).problem == UNDECIDED
    # and mesh_problem, which then loads it, gives the full loader's verdict
    meshfiles.clear_mesh_cache()
    assert mesh_problem(path) == full_load(path)[0]


def test_random_flips_never_get_a_verdict_the_full_loader_does_not_give(tmp_path: Path) -> None:
    """A byte flipped anywhere in an exporter's file (300 seeds): the fast check is UNDECIDED, or the file
    loads with the corners the fast check gives."""
    whole = bytearray(glb(*document()))
    decided = 0
    path = tmp_path / "part.glb"
    for seed in range(300):
        rng = random.Random(seed)
        flipped = copy.copy(whole)
        for _ in range(rng.randint(1, 3)):
            flipped[rng.randrange(len(flipped))] = rng.randrange(256)
        path.write_bytes(bytes(flipped))
        decided += agrees(path)
    assert 0 < decided < 300  # some flips land in padding or values that change nothing; many do not


def test_mesh_problem_keeps_the_corners_of_a_decided_glb(tmp_path: Path) -> None:
    path = tmp_path / "part.glb"
    path.write_bytes(glb(*document()))
    meshfiles.clear_mesh_cache()
    assert mesh_problem(path) is None
    kept = meshfiles.known_bounds(path)
    assert kept is not None
    np.testing.assert_allclose(np.array(kept), full_load(path)[1], rtol=0.0, atol=1e-12)


def test_passive_material_extensions_have_no_trimesh_handler() -> None:
    """The extensions the fast check lets through must be ones trimesh keeps unused: a trimesh that starts
    to handle one (and so to change the material) fails this test."""
    from trimesh.exchange.gltf import extensions

    handled = set(extensions._handlers.get("material", {}))
    assert handled and not handled & glbcheck.PASSIVE_MATERIAL_EXTENSIONS


def test_validate_reads_a_glb_visual_without_trimesh(tmp_path: Path) -> None:
    (tmp_path / "part.glb").write_bytes(glb(*document()))
    robot = tmp_path / "robot.urdf"
    robot.write_text('<robot name="r"><link name="a"><visual><geometry><mesh filename="part.glb"/></geometry>'
                     '</visual></link></robot>')
    script = ("import sys; from modelkit.api import validate; "
              f"d = validate({str(robot)!r}).diagnostics; "
              "print(sorted({x.code for x in d}), 'trimesh' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, check=True,
                         env={"MODELKIT_CACHE_DIR": "off", "PATH": "/usr/bin:/bin"})
    assert out.stdout.strip().endswith("False"), out.stdout + out.stderr
    assert "MK501" not in out.stdout
