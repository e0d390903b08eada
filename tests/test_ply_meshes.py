"""PLY meshes (ManiSkill 3.0's SO-100 collides its jaws with five Blender PLY files).

rviz and gz-sim read PLY through Assimp; MuJoCo has no decoder for it and PyBullet refuses the whole
URDF. modelkit used to refuse the files itself (MK506 "not supported"), so `convert` left the jaws
without collision and exited 1. Now PLY is read (trimesh's reader, binary and ASCII, quads fanned),
`validate` says which consumers cannot read it (MK515, an error under `--target mjcf|pybullet`), and
`convert` writes the meshes as STL/OBJ, which every target reads.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from modelkit.api import load, validate
from modelkit.convert.api import write
from modelkit.formats.meshref import MESH_FILE_EXTENSIONS
from modelkit.geometry.meshfiles import SUPPORTED_EXTENSIONS, MeshLoadError, load_mesh

trimesh = pytest.importorskip("trimesh")

ASCII_QUAD = b"""ply
format ascii 1.0
comment a unit square in z = 0, one quad
element vertex 4
property float x
property float y
property float z
element face 1
property list uchar int vertex_indices
end_header
0 0 0
1 0 0
1 1 0
0 1 0
4 0 1 2 3
"""


def _box_ply(path: Path, encoding: str = "binary") -> Path:
    box = trimesh.creation.box(extents=(0.1, 0.2, 0.3))
    path.write_bytes(box.export(file_type="ply", encoding=encoding))
    return path


def test_the_suffix_lists_agree() -> None:
    assert MESH_FILE_EXTENSIONS == SUPPORTED_EXTENSIONS and ".ply" in SUPPORTED_EXTENSIONS


@pytest.mark.parametrize("encoding", ["binary", "ascii"])
def test_a_ply_file_is_read_as_trimesh_reads_it(tmp_path: Path, encoding: str) -> None:
    path = _box_ply(tmp_path / "box.ply", encoding)
    loaded = load_mesh(path)
    reference = trimesh.load(str(path), process=False, force="mesh")
    assert loaded.source_format == "ply" and loaded.mesh.faces.shape == (12, 3)
    ours = np.sort(loaded.mesh.vertices[loaded.mesh.faces].reshape(-1, 9), axis=0)
    theirs = np.sort(reference.vertices[reference.faces].reshape(-1, 9), axis=0)
    assert np.allclose(ours, theirs, rtol=0.0, atol=1e-7)


def test_a_quad_becomes_two_triangles(tmp_path: Path) -> None:
    path = tmp_path / "quad.ply"
    path.write_bytes(ASCII_QUAD)
    loaded = load_mesh(path)
    assert loaded.mesh.faces.shape == (2, 3)
    assert sorted(set(loaded.mesh.faces.ravel().tolist())) == [0, 1, 2, 3]


@pytest.mark.parametrize(
    ("data", "said"),
    [
        (ASCII_QUAD.replace(b"element face 1", b"element face 0").replace(b"4 0 1 2 3\n", b""),
         "contains no triangles"),  # a point cloud
        (ASCII_QUAD.replace(b"4 0 1 2 3", b"4 0 1 2 9"), "a vertex the file does not have"),
        (b"solid cube\nendsolid\n", "is not a PLY file"),
    ],
    ids=["point cloud", "index past the vertices", "not PLY"],
)
def test_a_ply_file_that_holds_no_usable_mesh_is_refused(tmp_path: Path, data: bytes, said: str) -> None:
    path = tmp_path / "bad.ply"
    path.write_bytes(data)
    with pytest.raises(MeshLoadError) as caught:
        load_mesh(path)
    assert caught.value.code == "MK501" and said in str(caught.value)


def _urdf_with_ply(tmp_path: Path) -> Path:
    _box_ply(tmp_path / "jaw.ply")
    path = tmp_path / "gripper.urdf"
    path.write_text("""<robot name="gripper">
  <link name="base"><inertial><mass value="1"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.2 0.2 0.05"/></geometry></collision></link>
  <link name="jaw"><inertial><mass value="0.1"/>
    <inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial>
    <visual><geometry><mesh filename="jaw.ply"/></geometry></visual>
    <collision><geometry><mesh filename="jaw.ply"/></geometry></collision></link>
  <joint name="slide" type="prismatic"><parent link="base"/><child link="jaw"/><origin xyz="0 0 0.2"/>
    <axis xyz="1 0 0"/><limit lower="0" upper="0.05" effort="10" velocity="1"/></joint>
</robot>
""")
    return path


def test_validate_names_the_consumers_that_cannot_read_ply(tmp_path: Path) -> None:
    path = _urdf_with_ply(tmp_path)
    v = validate(path)
    assert v.errors == [] and "MK506" not in {d.code for d in v.diagnostics}
    (said,) = [d for d in v.diagnostics if d.code == "MK515"]  # once per file, at its first use
    assert said.message.startswith('visual mesh "jaw.ply" is PLY')
    assert "PyBullet refuses the whole URDF" in said.message
    for target in ("mjcf", "pybullet"):
        assert {d.code for d in validate(path, target=target).errors} == {"MK515"}
    assert validate(path, target="urdf").errors == []


@pytest.mark.parametrize("suffix", ["xml", "urdf"])
def test_convert_writes_the_ply_mesh_so_the_target_loads_it(tmp_path: Path, suffix: str) -> None:
    source = _urdf_with_ply(tmp_path)
    out = tmp_path / "out" / f"gripper.{suffix}"
    notes = write(load(source), out, force=True)
    assert not [n for n in notes if n.code == "MK805"]
    assert any(n.code == "MK804" and "jaw.ply (ply) converted" in n.message for n in notes)
    written = out.read_text()
    assert ".ply" not in written
    if suffix == "xml":
        mujoco = pytest.importorskip("mujoco")
        m = mujoco.MjModel.from_xml_path(str(out))
        jaw = m.body("jaw").id
        meshes = [g for g in range(m.ngeom) if m.geom_bodyid[g] == jaw and m.geom_type[g] == 7]
        assert meshes and m.mesh_vertnum.sum() >= 8
    else:
        pybullet = pytest.importorskip("pybullet")
        client = pybullet.connect(pybullet.DIRECT)
        try:
            robot = pybullet.loadURDF(str(out), physicsClientId=client)
            names = [pybullet.getJointInfo(robot, j, physicsClientId=client)[12].decode()
                     for j in range(pybullet.getNumJoints(robot, physicsClientId=client))]
            shapes = pybullet.getCollisionShapeData(robot, names.index("jaw"), physicsClientId=client)
            assert shapes and shapes[0][2] == pybullet.GEOM_MESH
        finally:
            pybullet.disconnect(client)
