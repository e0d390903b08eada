"""glTF meshes (``.glb``, ``.gltf``): read where their nodes place them, refused with MK501 when broken
or when a ``.gltf`` names a file outside its folder, accepted by ``validate`` with the MK514 portability
warning (an error for ``--target pybullet`` and ``--target mjcf``, whose consumers refuse them), and
converted by ``convert`` into meshes every target's consumer loads: MuJoCo from the MJCF, PyBullet from
the URDF (both refuse the glTF itself, checked here too)."""

from __future__ import annotations

import json
from pathlib import Path

import mujoco
import numpy as np
import pybullet
import pytest
import trimesh
from click.testing import CliRunner

from modelkit.cli import main
from modelkit.geometry.meshfiles import MeshLoadError, load_mesh

# A node turned 90° about Z and moved: the box's triangles must be read where the node puts them.
NODE = trimesh.transformations.rotation_matrix(np.pi / 2, [0, 0, 1])
NODE[:3, 3] = [0.1, 0.2, 0.3]
BOX = (0.02, 0.04, 0.06)


def _scene() -> trimesh.Scene:
    scene = trimesh.Scene()
    scene.add_geometry(trimesh.creation.box(extents=BOX), node_name="part", geom_name="box", transform=NODE)
    return scene


def _glb(folder: Path, name: str = "part.glb") -> Path:
    path = folder / name
    path.write_bytes(_scene().export(file_type="glb"))
    return path


def _gltf(folder: Path, buffer_uri: str | None = None) -> Path:
    """A .gltf file and its buffer file beside it; ``buffer_uri`` replaces the buffer's URI."""
    files = _scene().export(file_type="gltf")
    for name, data in files.items():
        if name != "model.gltf":
            (folder / name).write_bytes(data)
    document = json.loads(files["model.gltf"])
    assert all(not b["uri"].startswith("data:") for b in document["buffers"])  # an external buffer
    if buffer_uri is not None:
        document["buffers"][0]["uri"] = buffer_uri
    path = folder / "part.gltf"
    path.write_text(json.dumps(document))
    return path


def _expected_corners() -> tuple[np.ndarray, np.ndarray]:
    half = np.asarray(BOX) / 2.0
    corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]) * half
    placed = corners @ NODE[:3, :3].T + NODE[:3, 3]
    return placed.min(axis=0), placed.max(axis=0)


def test_glb_triangles_are_where_the_nodes_put_them(tmp_path: Path) -> None:
    loaded = load_mesh(_glb(tmp_path))
    low, high = _expected_corners()
    np.testing.assert_allclose(loaded.mesh.vertices.min(axis=0), low, atol=1e-7)  # float32 in the file
    np.testing.assert_allclose(loaded.mesh.vertices.max(axis=0), high, atol=1e-7)
    assert len(loaded.mesh.faces) == 12 and loaded.source_format == "glb" and "part" in loaded.parts


def test_gltf_reads_its_buffer_beside_it(tmp_path: Path) -> None:
    loaded = load_mesh(_gltf(tmp_path))
    low, high = _expected_corners()
    np.testing.assert_allclose(loaded.mesh.vertices.min(axis=0), low, atol=1e-7)
    np.testing.assert_allclose(loaded.mesh.vertices.max(axis=0), high, atol=1e-7)


def test_gltf_buffer_outside_its_folder_is_refused_without_content(tmp_path: Path) -> None:
    secret = tmp_path / "secret.bin"
    secret.write_bytes(b"TOP SECRET " * 100)
    folder = tmp_path / "model"
    folder.mkdir()
    with pytest.raises(MeshLoadError) as caught:
        load_mesh(_gltf(folder, "../secret.bin"))
    assert caught.value.code == "MK501"
    assert '"../secret.bin", outside its own folder' in caught.value.message
    assert "SECRET" not in caught.value.message


BROKEN = [b"", b"glTF\x02\x00\x00\x00garbage", b"\x89PNG\r\n\x1a\n" + b"\x00" * 40]


@pytest.mark.parametrize("content", BROKEN)
def test_a_broken_glb_is_mk501(tmp_path: Path, content: bytes) -> None:
    path = tmp_path / "bad.glb"
    path.write_bytes(content)
    with pytest.raises(MeshLoadError) as caught:
        load_mesh(path)
    assert caught.value.code == "MK501"


URDF = """<robot name="g">
  <link name="base">
    <inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <visual><geometry><mesh filename="{mesh}"/></geometry></visual>
    <collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision>
  </link>
  <link name="arm">
    <inertial><mass value="0.5"/>
      <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><mesh filename="{mesh}"/></geometry></collision>
  </link>
  <joint name="j" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="10" velocity="1"/></joint>
</robot>
"""


@pytest.fixture()
def glb_urdf(tmp_path: Path) -> Path:
    _glb(tmp_path)
    path = tmp_path / "g.urdf"
    path.write_text(URDF.format(mesh="part.glb"))
    return path


def test_consumers_refuse_the_glb_urdf_itself(glb_urdf: Path) -> None:
    """What MK514 says, measured: PyBullet refuses the whole file, MuJoCo has no decoder."""
    client = pybullet.connect(pybullet.DIRECT)
    try:
        with pytest.raises(pybullet.error):
            pybullet.loadURDF(str(glb_urdf), physicsClientId=client)
    finally:
        pybullet.disconnect(client)
    with pytest.raises(ValueError, match="no decoder"):
        mujoco.MjModel.from_xml_path(str(glb_urdf))


def test_validate_accepts_glb_with_mk514(glb_urdf: Path) -> None:
    result = CliRunner().invoke(main, ["validate", str(glb_urdf)])
    assert result.exit_code == 0, result.output
    assert "MK506" not in result.output and "MK501" not in result.output
    assert result.output.count("warning MK514") == 1  # one per file: the visual and collision share it
    for target in ("pybullet", "mjcf"):
        refused = CliRunner().invoke(main, ["validate", "--target", target, str(glb_urdf)])
        assert refused.exit_code == 1 and "error MK514" in refused.output, refused.output
    sdf_ok = CliRunner().invoke(main, ["validate", "--target", "sdf", str(glb_urdf)])
    assert sdf_ok.exit_code == 0 and "warning MK514" in sdf_ok.output


def test_validate_reports_a_broken_glb(tmp_path: Path) -> None:
    (tmp_path / "part.glb").write_bytes(b"glTF\x02\x00\x00\x00garbage")
    path = tmp_path / "g.urdf"
    path.write_text(URDF.format(mesh="part.glb"))
    result = CliRunner().invoke(main, ["validate", str(path)])
    assert "MK501" in result.output and result.exit_code == 1, result.output


def test_converted_outputs_load_in_their_consumers(glb_urdf: Path, tmp_path: Path) -> None:
    low, high = _expected_corners()
    mjcf = tmp_path / "out" / "g.xml"
    result = CliRunner().invoke(main, ["convert", str(glb_urdf), "-o", str(mjcf)])
    assert result.exit_code == 0, result.output
    assert "MK804 mesh part.glb (glb) converted to STL; glTF" in result.output
    model = mujoco.MjModel.from_xml_path(str(mjcf))
    assert model.nmesh == 1 and model.ngeom >= 3  # the visual and the arm's collision share the mesh
    vertices = model.mesh_vert.copy()
    # MuJoCo moves a mesh to its centre of mass and principal axes; the geom's pose puts it back
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    geom = next(g for g in range(model.ngeom) if model.geom_type[g] == mujoco.mjtGeom.mjGEOM_MESH)
    placed = vertices @ data.geom_xmat[geom].reshape(3, 3).T + data.geom_xpos[geom]
    np.testing.assert_allclose(placed.min(axis=0), low, atol=1e-6)
    np.testing.assert_allclose(placed.max(axis=0), high, atol=1e-6)

    urdf = tmp_path / "out2" / "g.urdf"
    result = CliRunner().invoke(main, ["convert", str(glb_urdf), "-o", str(urdf)])
    assert result.exit_code == 0, result.output
    assert ".glb" not in urdf.read_text()
    client = pybullet.connect(pybullet.DIRECT)
    try:
        body = pybullet.loadURDF(str(urdf), physicsClientId=client)
        arm = next(i for i in range(pybullet.getNumJoints(body, physicsClientId=client))
                   if pybullet.getJointInfo(body, i, physicsClientId=client)[12] == b"arm")
        shapes = pybullet.getCollisionShapeData(body, arm, physicsClientId=client)
        assert shapes and shapes[0][2] == pybullet.GEOM_MESH
    finally:
        pybullet.disconnect(client)


def test_a_mesh_over_mujocos_stl_bound_is_written_as_obj(tmp_path: Path) -> None:
    """MuJoCo reads at most 200,000 triangles from an STL (dexmate's gripper base has 294,002): such a
    converted mesh becomes an OBJ file, which MuJoCo reads whole."""
    count = 200_001
    t = np.linspace(0.0, 40.0 * np.pi, count + 2)
    vertices = np.stack([np.cos(t), np.sin(t), t / 100.0], axis=1) * 0.05  # a helix strip: not flat
    faces = np.stack([np.arange(count), np.arange(1, count + 1), np.arange(2, count + 2)], axis=1)
    helix = trimesh.Trimesh(vertices, faces, process=False)
    (tmp_path / "part.glb").write_bytes(helix.export(file_type="glb"))
    source = tmp_path / "g.urdf"
    source.write_text(URDF.format(mesh="part.glb").replace(
        '<collision><geometry><mesh filename="part.glb"/></geometry></collision>',
        '<collision><geometry><sphere radius="0.05"/></geometry></collision>'))
    mjcf = tmp_path / "out" / "g.xml"
    result = CliRunner().invoke(main, ["convert", str(source), "-o", str(mjcf)])
    assert result.exit_code == 0, result.output
    assert "converted to OBJ (200,001 triangles: MuJoCo reads at most 200,000 from an STL)" in result.output
    assert 'file="part_glb.obj"' in mjcf.read_text()
    model = mujoco.MjModel.from_xml_path(str(mjcf))
    assert model.mesh_facenum[0] == count

