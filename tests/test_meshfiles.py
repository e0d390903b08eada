"""Mesh loading (modelkit.geometry.meshfiles / vrml) against real corpus files and hand-written inputs."""

from __future__ import annotations

import math
import os
import re
import struct
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from modelkit.geometry.meshfiles import (
    SUPPORTED_EXTENSIONS,
    LoadedMesh,
    MeshLoadError,
    MeshMetadata,
    load_mesh,
    triangulate_polygons,
)

from .conftest import CORPUS

MODEL = CORPUS / "choreonoid/share/model"
GR001_PARTS = sorted((MODEL / "GR001/parts").glob("*.stl"))
PA10_PARTS = sorted((MODEL / "PA10/parts").glob("*.wrl"))
DAE_FILES = [
    *sorted((MODEL / "Robotiq/parts").glob("*.dae")),
    CORPUS / "choreonoid_ros2_mobile_robot_tutorial/meshes/vmega_wheel.dae",
    *sorted((CORPUS / "urdf_tutorial/meshes").glob("*.dae")),
]

needs_corpus = pytest.mark.skipif(not MODEL.is_dir(), reason="shared corpus not available")


def bbox(m: LoadedMesh) -> tuple[np.ndarray, np.ndarray]:
    v = m.mesh.vertices
    return v.min(axis=0), v.max(axis=0)


def signed_volume(m: LoadedMesh) -> float:
    t = m.mesh.vertices[m.mesh.faces]
    return float(np.einsum("ij,ij->i", t[:, 0], np.cross(t[:, 1], t[:, 2])).sum() / 6.0)


def write(tmp_path: Path, name: str, content: str | bytes) -> Path:
    p = tmp_path / name
    if isinstance(content, str):
        p.write_text(content)
    else:
        p.write_bytes(content)
    return p


def assert_mesh_arrays(m: LoadedMesh) -> None:
    v, f = m.mesh.vertices, m.mesh.faces
    assert v.dtype == np.float64 and v.ndim == 2 and v.shape[1] == 3
    assert f.dtype == np.int64 and f.ndim == 2 and f.shape[1] == 3
    if len(f):
        assert f.min() >= 0 and f.max() < len(v)
    assert np.all(np.isfinite(v))


# ---- module surface ----------------------------------------------------------------------------


def test_import_does_not_load_parsers() -> None:
    code = (
        "import sys\n"
        "import modelkit.geometry.meshfiles, modelkit.geometry.vrml\n"
        "heavy = [m for m in ('trimesh', 'collada', 'lxml') if m in sys.modules]\n"
        "print(','.join(heavy))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == ""


def test_supported_extensions() -> None:
    assert frozenset({".stl", ".obj", ".dae", ".wrl", ".glb", ".gltf", ".ply"}) == SUPPORTED_EXTENSIONS


# ---- STL (GR001) -------------------------------------------------------------------------------


def read_binary_stl(path: Path) -> np.ndarray:
    """Independent reader: (n, 3, 3) triangle corners straight from the bytes."""
    data = path.read_bytes()
    (n,) = struct.unpack("<I", data[80:84])
    rec = np.dtype([("normal", "<f4", 3), ("v", "<f4", (3, 3)), ("attr", "<u2")])
    return np.frombuffer(data, dtype=rec, count=n, offset=84)["v"].astype(np.float64)


@needs_corpus
def test_gr001_waist_stl() -> None:
    path = MODEL / "GR001/parts/WAIST.stl"
    m = load_mesh(path)
    tri = read_binary_stl(path)
    assert m.source_format == "stl" and m.unit_scale == 1.0 and m.parts == [] and m.notes == []
    assert len(m.mesh.faces) == len(tri) == 2475
    assert_mesh_arrays(m)
    lo, hi = bbox(m)
    assert np.allclose(lo, tri.reshape(-1, 3).min(axis=0)) and np.allclose(hi, tri.reshape(-1, 3).max(axis=0))
    assert np.allclose(lo, [-0.030, -0.042, -0.0015], atol=1e-6)
    assert np.allclose(hi, [0.059, 0.042, 0.0485], atol=1e-6)
    # shared corners are merged, triangles are the same as in the file
    assert len(m.mesh.vertices) < 3 * len(tri)
    assert np.allclose(m.mesh.vertices[m.mesh.faces], tri)


@needs_corpus
@pytest.mark.parametrize("path", GR001_PARTS, ids=lambda p: p.name)
def test_gr001_all_parts(path: Path) -> None:
    m = load_mesh(path)
    assert_mesh_arrays(m)
    tri = read_binary_stl(path)
    assert len(m.mesh.faces) == len(tri) >= 12
    assert np.allclose(m.mesh.vertices[m.mesh.faces], tri)
    lo, hi = bbox(m)
    assert np.all(hi - lo > 0.005) and np.all(hi - lo < 0.2)  # a small humanoid: parts of a few cm, in metres


@needs_corpus
def test_stl_metadata_units_and_upper_axis() -> None:
    path = MODEL / "GR001/parts/WAIST.stl"
    base = load_mesh(path).mesh.vertices
    mm = load_mesh(path, metadata=MeshMetadata(length_unit="millimeter"))
    assert mm.unit_scale == 0.001 and np.allclose(mm.mesh.vertices, 0.001 * base)
    inch = load_mesh(path, metadata=MeshMetadata(length_unit="inch"))
    assert inch.unit_scale == 0.0254 and np.allclose(inch.mesh.vertices, 0.0254 * base)
    yup = load_mesh(path, metadata=MeshMetadata(upper_axis="Y"))
    assert np.allclose(yup.mesh.vertices, base[:, [2, 0, 1]])  # (x, y, z) -> (z, x, y)
    both = load_mesh(path, metadata=MeshMetadata("millimeter", "Y"))
    assert np.allclose(both.mesh.vertices, 0.001 * base[:, [2, 0, 1]])
    assert any("upper_axis Y" in n for n in both.notes)


def test_ascii_stl(tmp_path: Path) -> None:
    facet = "facet normal 0 0 1\n outer loop\n  vertex {}\n  vertex {}\n  vertex {}\n endloop\nendfacet\n"
    text = "solid demo\n" + facet.format("0 0 0", "1 0 0", "0 1 0") + facet.format("1 0 0", "1 1 0", "0 1 0")
    m = load_mesh(write(tmp_path, "a.stl", text + "endsolid demo\n"))
    assert len(m.mesh.faces) == 2 and len(m.mesh.vertices) == 4
    assert np.allclose(bbox(m)[1], [1, 1, 0])
    assert any("ASCII STL" in n for n in m.notes)


# ---- OBJ ---------------------------------------------------------------------------------------


OBJ_TEXT = """# a unit quad, an L-shaped hexagon and a triangle with negative indices
o quad
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
f 1 2 3 4
o hexagon
v 0 0 1
v 2 0 1
v 2 1 1
v 1 1 1
v 1 2 1
v 0 2 1
f 5 6 7 8 9 10
o tri
v 0 0 2
v 0.5 0 2
v 0 0.5 2
f -3 -2 -1
"""


def test_obj(tmp_path: Path) -> None:
    path = write(tmp_path, "m.obj", OBJ_TEXT)
    m = load_mesh(path)
    assert m.source_format == "obj" and m.parts == []
    assert_mesh_arrays(m)
    assert len(m.mesh.faces) == 2 + 4 + 1
    assert np.allclose(bbox(m)[0], [0, 0, 0]) and np.allclose(bbox(m)[1], [2, 2, 2])
    # total area = quad 1 + L-hexagon 3 + triangle 0.125 (no triangle outside the concave polygon)
    t = m.mesh.vertices[m.mesh.faces]
    area = 0.5 * np.linalg.norm(np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]), axis=1).sum()
    assert math.isclose(area, 4.125, rel_tol=1e-12)
    mm = load_mesh(path, metadata=MeshMetadata(length_unit="millimeter", upper_axis="Y"))
    assert np.allclose(mm.mesh.vertices, 0.001 * m.mesh.vertices[:, [2, 0, 1]])


# ---- VRML (PA10) -------------------------------------------------------------------------------


def vrml_points(text: str) -> np.ndarray:
    """Independent reading of every ``point [ ... ]`` block of a VRML file."""
    text = re.sub(r"#[^\n]*", "", text)
    blocks = re.findall(r"point\s*\[([^\]]*)\]", text)
    nums = [float(x) for b in blocks for x in re.split(r"[\s,]+", b.strip()) if x]
    return np.array(nums).reshape(-1, 3)


@needs_corpus
@pytest.mark.parametrize("path", PA10_PARTS, ids=lambda p: p.name)
def test_pa10_parts_load(path: Path) -> None:
    m = load_mesh(path)
    assert m.source_format == "wrl" and m.unit_scale == 1.0
    assert_mesh_arrays(m)
    assert len(m.mesh.faces) > 0
    lo, hi = bbox(m)
    assert np.all(hi - lo > 0.005) and np.all(hi - lo < 0.5)
    # every file is one Transform rotated by 90 deg about X: all its points are used, and the
    # bounding box is the rotation of the points' bounding box
    pts = vrml_points(path.read_text())
    rx = np.array([[1, 0, 0], [0, 0, -1], [0, 1, 0]], dtype=float)
    moved = pts @ rx.T
    assert np.allclose(lo, moved.min(axis=0), atol=1e-9) and np.allclose(hi, moved.max(axis=0), atol=1e-9)


@needs_corpus
def test_pa10_base_bbox_from_file_text() -> None:
    path = MODEL / "PA10/parts/BASE.wrl"
    text = path.read_text()
    # the numbers, read from the text: a 24-point cylinder of radius 0.117, y in [0, 0.2], under
    # "rotation 1 0 0 1.570796326795" (the translation line is commented out)
    assert "rotation 1 0 0 1.570796326795" in text and "#translation" in text
    pts = vrml_points(text)
    assert pts.shape == (24, 3)
    assert pts[:, 1].min() == 0.0 and pts[:, 1].max() == 0.2
    assert np.isclose(np.abs(pts[:, 0]).max(), 0.117) and np.isclose(np.abs(pts[:, 2]).max(), 0.117)
    m = load_mesh(path)
    lo, hi = bbox(m)
    # Rx(+90 deg): (x, y, z) -> (x, -z, y)
    assert np.allclose(lo, [-0.117, -0.117, 0.0], atol=1e-6)
    assert np.allclose(hi, [0.117, 0.117, 0.2], atol=1e-6)
    assert len(m.mesh.faces) == 44  # 44 "-1"-terminated triangles in coordIndex
    coord_index = re.search(r"coordIndex\s*\[([^\]]*)\]", text)
    assert coord_index is not None and re.findall(r"-?\d+", coord_index.group(1)).count("-1") == 44


@needs_corpus
def test_pa10_parts_and_fragments() -> None:
    j7 = MODEL / "PA10/parts/J7.wrl"
    whole = load_mesh(j7)
    assert whole.parts == ["HA", "HAND"]
    hand = load_mesh(j7, fragment="HAND")  # the root Transform: nothing to detach
    assert np.array_equal(hand.mesh.vertices, whole.mesh.vertices)
    ha = load_mesh(j7, fragment="HA")  # nested; keeps HAND's rotation
    assert 0 < len(ha.mesh.faces) < len(whole.mesh.faces)
    with pytest.raises(MeshLoadError) as e:
        load_mesh(j7, fragment="_16")  # a DEF on a geometry names the mesh, not a node
    assert e.value.code == "MK502" and e.value.parts == ["HA", "HAND"] and "HA, HAND" in e.value.message


DETACH_WRL = """#VRML V2.0 utf8
# an outer Transform with translation + rotation (90 deg about Z) holding a DEF'd child
Transform {
  translation 1 2 3
  rotation 0 0 1 1.5707963267948966
  children [
    DEF PART Transform {
      translation 0.5 0 0
      children [
        DEF BOX Shape { geometry Box { size 0.2 0.4 0.6 } }
      ]
    }
  ]
}
DEF SCALED Transform {
  translation 10 0 0
  scale 2 2 2
  children DEF INNER Transform { translation 1 1 1 children USE BOX }
}
"""


def test_vrml_fragment_detach_rule(tmp_path: Path) -> None:
    path = write(tmp_path, "detach.wrl", DETACH_WRL)
    whole = load_mesh(path)
    assert whole.parts == ["BOX", "INNER", "PART", "SCALED"]
    assert len(whole.mesh.faces) == 24  # the box, and its USE
    part = load_mesh(path, fragment="PART")
    lo, hi = bbox(part)
    # translations (1 2 3) and (0.5 0 0) dropped; the 90 deg rotation kept: x/y extents swapped
    assert np.allclose(lo, [-0.2, -0.1, -0.3]) and np.allclose(hi, [0.2, 0.1, 0.3])
    assert any("detached" in n and "(1, 2.5, 3)" in n for n in part.notes)
    # in the whole file the same box sits at T + R·(0.5, 0, 0) = (1, 2.5, 3)
    first = whole.mesh.vertices[: len(part.mesh.vertices)]
    assert np.allclose((first.min(axis=0) + first.max(axis=0)) / 2, [1.0, 2.5, 3.0])
    # a DEF'd Shape inside the rotated Transform: detached too, orientation kept
    box = load_mesh(path, fragment="BOX")
    assert np.allclose(bbox(box)[0], lo) and np.allclose(bbox(box)[1], hi)
    # ancestor scale is kept (it is part of the linear part), ancestor translations are not
    inner = load_mesh(path, fragment="INNER")
    assert np.allclose(bbox(inner)[0], [-0.2, -0.4, -0.6]) and np.allclose(bbox(inner)[1], [0.2, 0.4, 0.6])


def test_vrml_full_transform_formula(tmp_path: Path) -> None:
    text = """#VRML V2.0 utf8
Transform {
  translation 1 2 3  rotation 0 1 0 0.3  scale 2 3 4  scaleOrientation 1 0 0 0.7  center 0.5 -0.5 0.25
  children Shape {
    geometry IndexedFaceSet { coord Coordinate { point [ 1 0 0, 0 1 0, 0 0 1 ] } coordIndex [ 0 1 2 ] }
  }
}
"""
    m = load_mesh(write(tmp_path, "t.wrl", text))

    def rot(axis: list[float], a: float) -> np.ndarray:
        x, y, z = np.asarray(axis) / np.linalg.norm(axis)
        k = np.array([[0, -z, y], [z, 0, -x], [-y, x, 0]])
        return np.eye(3) + math.sin(a) * k + (1 - math.cos(a)) * k @ k

    r, sr, s = rot([0, 1, 0], 0.3), rot([1, 0, 0], 0.7), np.diag([2.0, 3.0, 4.0])
    t, c = np.array([1.0, 2.0, 3.0]), np.array([0.5, -0.5, 0.25])
    expected = [t + c + r @ sr @ s @ sr.T @ (p - c) for p in np.eye(3)]  # T·C·R·SR·S·SR⁻¹·C⁻¹
    assert np.allclose(m.mesh.vertices[m.mesh.faces[0]], expected)


def test_vrml_primitives_along_y(tmp_path: Path) -> None:
    text = """#VRML V2.0 utf8
DEF B Shape { geometry Box { size 1 2 3 } }
DEF S Shape { geometry Sphere { radius 0.5 } }
DEF C Shape { geometry Cylinder { radius 0.5 height 2 } }
DEF K Shape { geometry Cone { bottomRadius 0.5 height 2 } }
DEF D Shape { geometry Box { } }
"""
    path = write(tmp_path, "p.wrl", text)
    cases = {
        "B": ([0.5, 1.0, 1.5], 6.0, 12),
        "S": ([0.5, 0.5, 0.5], 4 / 3 * math.pi * 0.125, 360),
        "C": ([0.5, 1.0, 0.5], math.pi * 0.25 * 2, 80),
        "K": ([0.5, 1.0, 0.5], math.pi * 0.25 * 2 / 3, 40),
        "D": ([1.0, 1.0, 1.0], 8.0, 12),  # VRML default size 2 2 2
    }
    for name, (half, volume, n_tri) in cases.items():
        m = load_mesh(path, fragment=name)
        lo, hi = bbox(m)
        assert np.allclose(hi, half) and np.allclose(lo, -np.asarray(half)), name
        assert len(m.mesh.faces) == n_tri, name
        vol = signed_volume(m)
        assert 0 < vol <= volume * (1 + 1e-9) and vol > 0.9 * volume, name  # closed, outward, tessellated
    cone = load_mesh(path, fragment="K")
    apex = cone.mesh.vertices[np.argmax(cone.mesh.vertices[:, 1])]
    assert np.allclose(apex, [0, 1, 0])  # apex up (+Y), base at y = -h/2


def test_vrml_syntax_subset(tmp_path: Path) -> None:
    text = """#VRML V2.0 utf8
# comments, commas, PROTO / EXTERNPROTO / ROUTE / Script / unknown nodes are skipped
PROTO Joint [ field SFVec3f translation 0 0 0  exposedField MFNode children [] ] {
  Transform { translation IS translation children IS children }
}
EXTERNPROTO Other [ field SFFloat x ] "other.wrl#Other"
DEF TS TimeSensor { cycleInterval 2 loop TRUE }
Joint { translation 1 0 0 children [ Shape { geometry Box {} } ] }
Script { field SFFloat x 1 eventIn SFTime go url "javascript: function go() {}" }
Viewpoint { position 0 0 10 description "front { not a brace }" }
DEF G Group {
  children [
    Shape {
      appearance Appearance { material Material { diffuseColor 1 0 0 } }
      geometry DEF QUAD IndexedFaceSet {
      coord DEF PTS Coordinate { point [ 0 0 0, 1 0 0, 1 1 0, 0 1 0 ] }
      coordIndex [ 0, 1, 2, 3 ]   # the last polygon need not end with -1
      }
    }
    Shape { geometry IndexedFaceSet { coord USE PTS coordIndex [ 0 1 2 -1 ] ccw FALSE } }
    Switch { whichChoice 0 choice [ Shape { geometry Box { size 0.1 0.1 0.1 } } ] }
  ]
}
ROUTE TS.fraction_changed TO G.set_children
"""
    m = load_mesh(write(tmp_path, "s.wrl", text), metadata=MeshMetadata(length_unit="millimeter"))
    assert m.parts == ["G"]  # TS is not a scene node; the Joint instance was skipped
    assert len(m.mesh.faces) == 2 + 1 + 12
    assert m.unit_scale == 1.0 and any("ignored for VRML" in n for n in m.notes)
    notes = "\n".join(m.notes)
    for word in ("PROTO", "EXTERNPROTO", "ROUTE", "Script", "Joint", "Switch"):
        assert word in notes, word
    # ccw FALSE reverses the triangle: (0 1 2) -> (2 1 0)
    tri = m.mesh.vertices[m.mesh.faces[2]]
    assert np.allclose(tri, [[1, 1, 0], [1, 0, 0], [0, 0, 0]])


def test_vrml_number_lists_slow_and_fast_paths_agree(tmp_path: Path) -> None:
    plain = "Shape { geometry IndexedFaceSet { coord Coordinate { point [ 0 0 0, 1 0 0, 0 2 0, 0 0 3 ] }\n"
    plain += "coordIndex [ 0 1 2 -1 0 2 3 -1 ] } }\n"
    # a comment inside the list and hexadecimal indices force the token-by-token path
    tricky = plain.replace("1 0 0,", "1 0 0, # second point ] not the end\n")
    tricky = tricky.replace("0 2 3 -1", "0x0 0x2 0x3 -1")
    a = load_mesh(write(tmp_path, "plain.wrl", plain))
    b = load_mesh(write(tmp_path, "tricky.wrl", tricky))
    assert np.array_equal(a.mesh.vertices, b.mesh.vertices) and np.array_equal(a.mesh.faces, b.mesh.faces)
    assert len(a.mesh.faces) == 2


def test_vrml_elevation_grid(tmp_path: Path) -> None:
    text = """#VRML V2.0 utf8
DEF UP Shape { geometry ElevationGrid { xDimension 3 zDimension 2 xSpacing 0.5 zSpacing 2
                                        height [ 0 1 0, 0 2 0 ] } }
DEF DOWN Shape { geometry ElevationGrid { xDimension 2 zDimension 2 height [ 0 0 0 0 ] ccw FALSE } }
"""
    path = write(tmp_path, "eg.wrl", text)
    up = load_mesh(path, fragment="UP")
    assert len(up.mesh.faces) == 4
    assert np.allclose(bbox(up)[0], [0, 0, 0]) and np.allclose(bbox(up)[1], [1, 2, 2])
    t = up.mesh.vertices[up.mesh.faces]
    assert np.all(np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])[:, 1] > 0)  # ccw: facing +Y
    down = load_mesh(path, fragment="DOWN")
    t = down.mesh.vertices[down.mesh.faces]
    assert np.all(np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])[:, 1] < 0)


def test_vrml_duplicate_def_keeps_first(tmp_path: Path) -> None:
    text = """#VRML V2.0 utf8
DEF A Shape { geometry Box { size 1 1 1 } }
DEF A Shape { geometry Box { size 4 4 4 } }
Transform { translation 10 0 0 children USE A }
"""
    m = load_mesh(write(tmp_path, "d.wrl", text))
    used = m.mesh.vertices[-8:]
    assert np.allclose(used.max(axis=0) - used.min(axis=0), [1, 1, 1])  # as Choreonoid: the first DEF
    assert any('DEF "A" defined again' in n for n in m.notes)


# ---- COLLADA -----------------------------------------------------------------------------------


@needs_corpus
@pytest.mark.parametrize("path", DAE_FILES, ids=lambda p: p.name)
def test_corpus_dae_loads(path: Path) -> None:
    m = load_mesh(path)
    assert m.source_format == "dae" and m.unit_scale == 1.0  # all declare <unit meter="1"/>
    assert_mesh_arrays(m)
    assert len(m.mesh.faces) > 500
    lo, hi = bbox(m)
    assert np.all(hi - lo > 0.005) and np.all(hi - lo < 0.5)
    assert "Camera" not in m.parts and "Lamp" not in m.parts  # nodes without meshes are not parts
    # cross-check against trimesh's own COLLADA loader (same file, unit 1, so units do not matter)
    import trimesh

    scene = trimesh.load(str(path), force="scene")
    ref = scene.to_geometry() if hasattr(scene, "to_geometry") else scene.dump(concatenate=True)
    assert len(ref.faces) == len(m.mesh.faces)
    assert np.allclose(ref.bounds, np.stack([lo, hi]), atol=1e-7)


@needs_corpus
def test_vmega_wheel_dae() -> None:
    m = load_mesh(CORPUS / "choreonoid_ros2_mobile_robot_tutorial/meshes/vmega_wheel.dae")
    assert len(m.mesh.faces) == 8480
    assert m.parts == ["Megarover_002"]
    lo, hi = bbox(m)
    assert np.allclose(lo, [-0.076, -0.0345, -0.076], atol=5e-4)
    assert np.allclose(hi, [0.076, 0.023, 0.076], atol=5e-4)
    assert not any("up_axis" in n for n in m.notes)  # Z_UP: nothing to say


@needs_corpus
def test_urdf_tutorial_dae_is_y_up_but_not_rotated() -> None:
    m = load_mesh(CORPUS / "urdf_tutorial/meshes/l_finger.dae")
    assert any("up_axis Y_UP ignored" in n for n in m.notes)
    assert m.parts == ["finger_M2K_mod"]


def dae_document(unit: str, up: str, nodes: str) -> str:
    return f"""<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit name="millimeter" meter="{unit}"/><up_axis>{up}</up_axis></asset>
  <library_geometries>
    <geometry id="tri-mesh" name="tri">
      <mesh>
        <source id="tri-pos">
          <float_array id="tri-pos-array" count="12">0 0 0 10 0 0 0 20 0 0 0 30</float_array>
          <technique_common>
            <accessor source="#tri-pos-array" count="4" stride="3">
              <param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/>
            </accessor>
          </technique_common>
        </source>
        <vertices id="tri-vtx"><input semantic="POSITION" source="#tri-pos"/></vertices>
        <triangles count="1"><input semantic="VERTEX" source="#tri-vtx" offset="0"/><p>0 1 2</p></triangles>
        <polylist count="1"><input semantic="VERTEX" source="#tri-vtx" offset="0"/>
          <vcount>4</vcount><p>0 1 2 3</p></polylist>
      </mesh>
    </geometry>
  </library_geometries>
  <library_visual_scenes>
    <visual_scene id="Scene" name="Scene">{nodes}</visual_scene>
  </library_visual_scenes>
  <scene><instance_visual_scene url="#Scene"/></scene>
</COLLADA>
"""


PLAIN_NODE = '<node id="n1" name="Body"><instance_geometry url="#tri-mesh"/></node>'


def test_dae_unit_applied_and_up_axis_ignored(tmp_path: Path) -> None:
    m = load_mesh(write(tmp_path, "mm.dae", dae_document("0.001", "Y_UP", PLAIN_NODE)))
    assert m.unit_scale == 0.001
    assert len(m.mesh.faces) == 3  # 1 triangle + a quad split in 2
    raw = np.array([[0, 0, 0], [10, 0, 0], [0, 20, 0], [0, 0, 30]], dtype=float)
    assert np.allclose(m.mesh.vertices, 0.001 * raw)  # scaled, and NOT rotated for Y_UP
    assert any("up_axis Y_UP ignored" in n for n in m.notes)
    assert any('unit meter="0.001"' in n for n in m.notes)
    both = load_mesh(tmp_path / "mm.dae", metadata=MeshMetadata(length_unit="inch", upper_axis="Y"))
    assert math.isclose(both.unit_scale, 0.001 * 0.0254)
    assert np.allclose(both.mesh.vertices, 0.001 * 0.0254 * raw[:, [2, 0, 1]])


def test_dae_node_transforms_and_fragment(tmp_path: Path) -> None:
    nodes = """
      <node id="outer" name="Outer">
        <translate>1 2 3</translate>
        <rotate>0 0 1 90</rotate>
        <node id="inner-id" name="Inner">
          <matrix>1 0 0 0.5  0 1 0 0  0 0 1 0  0 0 0 1</matrix>
          <instance_geometry url="#tri-mesh"/>
        </node>
      </node>
      <node id="empty" name="Camera"/>"""
    path = write(tmp_path, "frag.dae", dae_document("1", "Z_UP", nodes))
    whole = load_mesh(path)
    assert whole.parts == ["Inner", "Outer"]
    # vertex (10, 0, 0): + (0.5, 0, 0) -> (10.5, 0, 0); Rz(90) -> (0, 10.5, 0); + (1, 2, 3)
    assert np.allclose(whole.mesh.vertices[1], [1.0, 12.5, 3.0])
    part = load_mesh(path, fragment="Inner")
    # translations dropped (ancestors' and its own), rotation kept
    assert np.allclose(part.mesh.vertices[1], [0.0, 10.0, 0.0])
    assert np.allclose(part.mesh.vertices[3], [0.0, 0.0, 30.0])
    with pytest.raises(MeshLoadError) as e:
        load_mesh(path, fragment="inner-id")  # ids are not names
    assert e.value.code == "MK502" and e.value.parts == ["Inner", "Outer"]
    assert "Inner, Outer" in e.value.message


def test_dae_instance_node_and_mirror(tmp_path: Path) -> None:
    doc = dae_document("1", "Z_UP", """
      <node id="a" name="A"><instance_node url="#lib"/></node>
      <node id="b" name="B"><scale>-1 1 1</scale><instance_node url="#lib"/></node>""")
    doc = doc.replace(
        "<library_visual_scenes>",
        '<library_nodes><node id="lib" name="Lib"><instance_geometry url="#tri-mesh"/></node>'
        "</library_nodes>\n  <library_visual_scenes>",
    )
    m = load_mesh(write(tmp_path, "inst.dae", doc))
    assert m.parts == ["A", "B", "Lib"]
    assert len(m.mesh.faces) == 6
    assert any("mirroring" in n for n in m.notes)
    t = m.mesh.vertices[m.mesh.faces]
    normals = np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])
    assert np.allclose(normals[0], normals[3] * [-1, 1, 1])  # the mirrored copy keeps its facing


# ---- polygons ----------------------------------------------------------------------------------


def test_triangulate_polygons() -> None:
    v = np.array([[0, 0, 0], [2, 0, 0], [2, 2, 0], [1, 0.5, 0], [0, 2, 0], [3, 3, 0]], dtype=float)
    counts = np.array([5, 4, 2, 3])
    flat = np.array([0, 1, 2, 3, 4, 0, 1, 2, 3, 0, 1, 0, 1, 9])  # concave pentagon, concave quad, bad, bad
    faces, skipped = triangulate_polygons(v, counts, flat)
    assert skipped == 2
    assert len(faces) == 3 + 2
    t = v[faces]
    cross_z = np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])[:, 2]
    assert np.all(cross_z > 0)  # orientation kept, no flipped (outside) triangle
    assert math.isclose(0.5 * cross_z[:3].sum(), 2.5) and math.isclose(0.5 * cross_z[3:].sum(), 1.5)


# ---- determinism -------------------------------------------------------------------------------


@needs_corpus
@pytest.mark.parametrize(
    "path",
    [
        MODEL / "GR001/parts/WAIST.stl",
        MODEL / "PA10/parts/J6.wrl",
        MODEL / "Robotiq/parts/robotiq_85_base_link.dae",
    ],
    ids=lambda p: p.suffix,
)
def test_deterministic(path: Path) -> None:
    a, b = load_mesh(path), load_mesh(path)
    assert np.array_equal(a.mesh.vertices, b.mesh.vertices) and np.array_equal(a.mesh.faces, b.mesh.faces)
    assert a.parts == b.parts and a.notes == b.notes


# ---- bad input: always MeshLoadError, with the right code --------------------------------------


def truncated_stl() -> bytes:
    waist = MODEL / "GR001/parts/WAIST.stl"
    data = waist.read_bytes() if waist.is_file() else b"x" * 80 + struct.pack("<I", 9) + b"\0" * 450
    return data[: len(data) // 2]


BAD_INPUTS: list[tuple[str, bytes | str, str, str]] = [
    ("garbage.stl", os.urandom(4096), "MK501", "neither a binary STL"),
    ("truncated.stl", truncated_stl(), "MK501", "truncated"),
    ("empty.stl", b"", "MK501", "empty"),
    ("bad.stl", "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 zero\nendloop\nendfacet\nendsolid x\n",
     "MK501", "malformed ASCII STL"),
    ("garbage.obj", os.urandom(4096), "MK501", ""),
    ("noface.obj", "v 0 0 0\nv 1 0 0\n", "MK501", "no faces"),
    ("badindex.obj", "v 0 0 0\nf 1 2 3\n", "MK501", "does not exist"),
    ("malformed.dae", "<COLLADA><asset><unit meter='0.001'/></asset><library_geometries><geometry",
     "MK501", "not a readable COLLADA"),
    ("garbage.dae", os.urandom(4096), "MK501", ""),
    ("html.dae", "<html><body/></html>", "MK501", "not <COLLADA>"),
    ("entities.dae", '<?xml version="1.0"?><!DOCTYPE x [<!ENTITY a "aaaa">]><COLLADA>&a;</COLLADA>',
     "MK501", "entity"),
    ("unbalanced.wrl", "#VRML V2.0 utf8\nTransform { children [ Shape { geometry Box { } }\n", "MK501",
     "not closed"),
    ("extra_brace.wrl", "#VRML V2.0 utf8\nGroup { children [ ] } }\n", "MK501", "extra closing brace"),
    ("deep.wrl", "#VRML V2.0 utf8\n" + "Transform { children [\n" * 10000 + "] }\n" * 10000, "MK501",
     "nesting deeper"),
    ("deep_sf.wrl", "Group { children " * 10000 + "}" * 10000, "MK501", "nesting deeper"),
    ("garbage.wrl", os.urandom(4096), "MK501", ""),
    ("vrml1.wrl", "#VRML V1.0 ascii\nSeparator { }\n", "MK501", "VRML97"),
    ("use.wrl", "Group { children [ USE NOPE ] }", "MK501", "USE"),
    ("zero_axis.wrl", "Transform { rotation 0 0 0 1 children [] }", "MK501", "zero vector"),
    ("string.wrl", 'WorldInfo { title "never closed }', "MK501", "string"),
    ("bad_point.wrl", "Shape { geometry IndexedFaceSet { coord Coordinate { point [ 0 0 ] }\n"
     "coordIndex [0] } }", "MK501", "multiple of 3"),
    ("model.blend", b"BLENDER", "MK506", ".blend"),
    ("noext", b"solid", "MK506", "no extension"),
    ("model.3ds", b"", "MK506", ".3ds"),
]


@pytest.mark.parametrize(("name", "content", "code", "words"), BAD_INPUTS, ids=[b[0] for b in BAD_INPUTS])
def test_bad_inputs(tmp_path: Path, name: str, content: bytes | str, code: str, words: str) -> None:
    path = write(tmp_path, name, content)
    with pytest.raises(MeshLoadError) as e:
        load_mesh(path)
    assert e.value.code == code
    assert words in e.value.message


def test_vrml_error_line_numbers(tmp_path: Path) -> None:
    text = "#VRML V2.0 utf8\nGroup {\n  children [\n    Shape { geometry Box { size 1 1 } }\n  ]\n}\n"
    with pytest.raises(MeshLoadError) as e:
        load_mesh(write(tmp_path, "l.wrl", text))
    assert e.value.code == "MK501" and e.value.line == 4 and "needs 3 numbers" in e.value.message
    deep = "#VRML V2.0 utf8\n" + "Transform { children [\n" * 10000
    with pytest.raises(MeshLoadError) as e:
        load_mesh(write(tmp_path, "deep.wrl", deep))
    assert e.value.line is not None and 50 < e.value.line < 200


@pytest.mark.parametrize("name", ["a.stl", "a.dae", "a.wrl"])
def test_unknown_fragment(tmp_path: Path, name: str) -> None:
    if name == "a.stl":
        path = write(tmp_path, name, "solid a\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n"
                                     "vertex 0 1 0\nendloop\nendfacet\nendsolid a\n")
        parts: list[str] = []
    elif name == "a.dae":
        path = write(tmp_path, name, dae_document("1", "Z_UP", PLAIN_NODE))
        parts = ["Body"]
    else:
        text = "DEF LEFT Shape { geometry Box {} } DEF RIGHT Group { children USE LEFT }"
        path = write(tmp_path, name, text)
        parts = ["LEFT", "RIGHT"]
    with pytest.raises(MeshLoadError) as e:
        load_mesh(path, fragment="MISSING")
    assert e.value.code == "MK502" and e.value.parts == parts
    assert '"MISSING"' in e.value.message
    for p in parts:
        assert p in e.value.message


def test_directory_is_wrapped(tmp_path: Path) -> None:
    d = tmp_path / "dir.stl"
    d.mkdir()
    with pytest.raises(MeshLoadError) as e:
        load_mesh(d)
    assert e.value.code == "MK501"


def test_mesh_outcome_is_kept_per_file_version(tmp_path: Path) -> None:
    """`mesh_problem` loads a file once per (path, mtime, size, fragment) and again once it changes."""
    from modelkit.geometry.meshfiles import clear_mesh_cache, mesh_problem

    clear_mesh_cache()
    mesh = tmp_path / "m.stl"
    header = b"x".ljust(80, b" ") + struct.pack("<I", 1)
    mesh.write_bytes(header + struct.pack("<12fH", 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0))
    assert mesh_problem(mesh) is None
    assert mesh_problem(tmp_path / "." / "m.stl") is None  # same resolved path: the kept outcome
    mesh.write_text("solid broken\nfacet normal 0 0 1\n")  # another size: loaded again
    problem = mesh_problem(mesh)
    assert problem is not None and problem.startswith("MK501\t")
    assert mesh_problem(tmp_path / "missing.stl", None) is not None  # not a regular file: not kept
    clear_mesh_cache()


def _binary_stl_files() -> list[Path]:
    """Every binary STL with triangles in the corpus and pybullet's data."""
    roots = [CORPUS]
    try:
        import pybullet_data

        roots.append(Path(pybullet_data.getDataPath()))
    except ImportError:  # pragma: no cover - pybullet is in the test environment
        pass
    found = []
    for root in roots:
        for path in sorted(root.rglob("*")) if root.is_dir() else []:
            if path.suffix.lower() == ".stl" and path.is_file():
                head = path.read_bytes()[:84]
                count = int.from_bytes(head[80:84], "little") if len(head) == 84 else -1
                if count > 0 and path.stat().st_size == 84 + 50 * count:
                    found.append(path)
    return found


def test_binary_stl_reads_as_trimesh_reads_it(corpus: Path) -> None:
    """The binary STL reader (no trimesh import) gives trimesh's arrays, through the same merging."""
    import io

    from trimesh.exchange import stl as trimesh_stl

    from modelkit.geometry.meshfiles import _load_stl, merge_identical_vertices

    files = _binary_stl_files()
    assert len(files) >= 100
    for path in files:
        data = path.read_bytes()
        theirs = trimesh_stl.load_stl_binary(io.BytesIO(data))
        vertices = np.asarray(theirs["vertices"], dtype=np.float64).reshape(-1, 3)
        faces = np.asarray(theirs["faces"], dtype=np.int64).reshape(-1, 3)
        expected_vertices, expected_faces = merge_identical_vertices(vertices, faces)
        ours = _load_stl(data, path.name)
        assert np.array_equal(ours.vertices, expected_vertices), path
        assert np.array_equal(ours.faces, expected_faces), path


def test_binary_stl_without_triangles_is_refused(tmp_path: Path) -> None:
    path = tmp_path / "empty.stl"
    path.write_bytes(b"\0" * 80 + struct.pack("<I", 0))
    with pytest.raises(MeshLoadError) as caught:
        load_mesh(path)
    assert caught.value.code == "MK501" and "no triangles" in str(caught.value)


def test_binary_stl_does_not_import_trimesh(tmp_path: Path) -> None:
    path = tmp_path / "t.stl"
    triangle = struct.pack("<12fH", 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0)
    path.write_bytes(b"\0" * 80 + struct.pack("<I", 1) + triangle)
    child = (
        "import sys; from modelkit.geometry.meshfiles import load_mesh; "
        f"m = load_mesh({str(path)!r}); print(len(m.mesh.faces), 'trimesh' in sys.modules)"
    )
    done = subprocess.run([sys.executable, "-c", child], capture_output=True, text=True, check=True,
                          timeout=120)
    assert done.stdout.split() == ["1", "False"]


def test_a_changed_mesh_file_is_loaded_again_by_the_next_write(tmp_path: Path) -> None:
    """convert remembers loaded mesh files within a process (verify writes a robot up to seven
    times); a file changed between two writes must be read again, not served from memory."""
    import trimesh

    from modelkit.convert.api import convert

    wrl = tmp_path / "part.wrl"
    source = tmp_path / "robot.urdf"
    source.write_text('<robot name="r"><link name="base"><visual><geometry><mesh filename="part.wrl"/>'
                      "</geometry></visual></link></robot>")
    sizes = []
    for size in ("0.2 0.4 0.6", "1 2 3"):
        wrl.write_text(f"#VRML V2.0 utf8\nShape {{ geometry Box {{ size {size} }} }}\n")
        out = tmp_path / size.replace(" ", "_") / "robot.urdf"
        assert convert([source], out).status == 0
        (mesh,) = (out.parent / "meshes").iterdir()
        sizes.append(float(np.ptp(trimesh.load(mesh, force="mesh").vertices[:, 2])))
    assert sizes == pytest.approx([0.6, 3.0])


def test_compact_mesh_drops_unused_vertices_keeping_the_order_of_the_rest() -> None:
    # compact_mesh marks used vertices in one pass; the result must be the one of the sorted
    # np.unique of the face indices (used vertices in file order, faces renumbered).
    from modelkit.geometry.meshfiles import compact_mesh

    rng = np.random.default_rng(7)
    vertices = rng.normal(size=(500, 3))
    faces = rng.integers(0, 500, size=(300, 3)) // 2 * 2  # only even vertices are used
    kept, renumbered = compact_mesh(vertices, faces)
    used = np.unique(faces)
    assert np.array_equal(kept, vertices[used])
    assert np.array_equal(kept[renumbered], vertices[faces])
    assert len(kept) == len(used) < 500
    whole, same = compact_mesh(vertices[:3], np.array([[0, 1, 2]]))
    assert np.array_equal(whole, vertices[:3]) and np.array_equal(same, [[0, 1, 2]])


def _merged_by_unique(vertices: np.ndarray, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The former merge of identical STL vertices, by ``np.unique(axis=0)``: the reference."""
    _, first, inverse = np.unique(vertices, axis=0, return_index=True, return_inverse=True)
    order = np.argsort(first, kind="stable")
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    return vertices[np.sort(first)], rank[inverse.reshape(-1)][faces]


def test_identical_vertices_merge_as_np_unique_merges_them() -> None:
    # Small integer grids so that rows repeat; -0.0 against 0.0 and NaN rows included.
    from modelkit.geometry.meshfiles import merge_identical_vertices

    rng = np.random.default_rng(11)
    merges = 0
    for trial in range(300):
        vertices = rng.integers(-2, 3, size=(int(rng.integers(1, 80)), 3)).astype(float)
        vertices[rng.random(vertices.shape) < 0.1] = -0.0
        if trial % 3 == 0:
            vertices[rng.random(vertices.shape) < 0.05] = np.nan
        faces = rng.integers(0, len(vertices), size=(30, 3))
        merged, renumbered = merge_identical_vertices(vertices, faces)
        expected, expected_faces = _merged_by_unique(vertices, faces)
        assert np.array_equal(merged, expected, equal_nan=True), trial
        assert np.array_equal(renumbered, expected_faces), trial
        merges += len(merged) < len(vertices)
    assert merges > 200  # the grids do repeat rows: the comparison is not of untouched inputs


def test_a_parser_librarys_warning_is_not_printed(tmp_path: Path) -> None:
    """An OBJ with texture coordinates and a vertex no face uses: trimesh's loader warns "All-NaN slice
    encountered" on stderr (pybullet's Panda meshes as genesis-world 1.4.5 ships them printed it in the
    middle of `convert` and `verify`). The mesh loads; no warning leaves the loader."""
    import warnings

    path = tmp_path / "holes.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nvt 0 0\nvt 1 0\nvt 0 1\nvt 1 1\nf 1/1 2/2 4/4\n")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        loaded = load_mesh(path)
    assert loaded.mesh.faces.tolist() == [[0, 1, 3]]
    assert [str(w.message) for w in caught] == []
