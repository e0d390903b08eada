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
from tests.conftest import assert_pybullet_refuses
from tests.test_sdf_reader import oracle_has_errors, sdf_oracle  # noqa: F401 (the fixture)

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
    assert_pybullet_refuses(glb_urdf)
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
    # check_urdf never opens meshes: a warning that says who refuses the file, an error for them
    result = CliRunner().invoke(main, ["validate", str(path)])
    assert "warning MK501" in result.output and result.exit_code == 0, result.output
    result = CliRunner().invoke(main, ["validate", "--target", "mjcf", str(path)])
    assert "error MK501" in result.output and result.exit_code == 1, result.output


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



# ---- colours: MuJoCo reads none from a mesh file, so a coloured visual becomes one geom per colour ----


def _two_colour_glb(folder: Path) -> Path:
    """Two boxes, red and half-transparent blue, in one .glb."""
    scene = trimesh.Scene()
    for offset, colour in (((0.0, 0.0, 0.0), [255, 0, 0, 255]), ((0.1, 0.0, 0.0), [0, 0, 255, 128])):
        box = trimesh.creation.box(extents=BOX)
        box.apply_translation(offset)
        box.visual = trimesh.visual.TextureVisuals(material=trimesh.visual.material.PBRMaterial(
            baseColorFactor=colour))
        scene.add_geometry(box)
    path = folder / "part.glb"
    path.write_bytes(scene.export(file_type="glb"))
    return path


def test_glb_colours_are_read_per_face(tmp_path: Path) -> None:
    loaded = load_mesh(_two_colour_glb(tmp_path))
    assert loaded.face_colours is not None
    assert sorted(loaded.palette) == [(0.0, 0.0, 1.0, 128 / 255), (1.0, 0.0, 0.0, 1.0)]
    assert sorted(np.bincount(loaded.face_colours).tolist()) == [12, 12]


def test_collada_colours_are_read_per_face() -> None:
    from tests.conftest import example_robot

    loaded = load_mesh(example_robot("ur_description/meshes/ur5/visual/base.dae"))
    assert loaded.face_colours is not None
    by_colour = dict(zip(loaded.palette, np.bincount(loaded.face_colours).tolist(), strict=True))
    # the file's two <effect> diffuse colours and the triangles bound to each
    assert by_colour == {(0.5248, 0.5248, 0.5248, 1.0): 1795, (0.064, 0.064, 0.064, 1.0): 137}


def _rgba(model: mujoco.MjModel, geom: int) -> tuple[float, ...]:
    return tuple(round(float(x), 4) for x in model.geom_rgba[geom])  # MuJoCo keeps float32


def _mesh_geoms(model: mujoco.MjModel) -> list[int]:
    return [g for g in range(model.ngeom) if model.geom_type[g] == mujoco.mjtGeom.mjGEOM_MESH]


def _converted_two_colours(tmp_path: Path, suffix: str) -> Path:
    """The two-colour .glb robot converted by the CLI to ``suffix``; the split is said."""
    _two_colour_glb(tmp_path)
    source = tmp_path / "g.urdf"
    source.write_text(URDF.format(mesh="part.glb"))
    out = tmp_path / "out" / f"g.{suffix}"
    result = CliRunner().invoke(main, ["convert", str(source), "-o", str(out)])
    assert result.exit_code == 0, result.output
    assert "converted to 2 files, one per colour" in result.output
    return out


def test_a_coloured_visual_is_one_geom_per_colour(tmp_path: Path) -> None:
    mjcf = _converted_two_colours(tmp_path, "xml")
    model = mujoco.MjModel.from_xml_path(str(mjcf))
    visuals = [g for g in _mesh_geoms(model) if model.geom_group[g] == 1]
    colours = sorted(_rgba(model, g) for g in visuals)
    assert colours == [(0.0, 0.0, 1.0, round(128 / 255, 4)), (1.0, 0.0, 0.0, 1.0)]
    assert sum(int(model.mesh_facenum[model.geom_dataid[g]]) for g in visuals) == 24
    collisions = [g for g in _mesh_geoms(model) if model.geom_group[g] == 3]
    assert len(collisions) == 1 and model.mesh_facenum[model.geom_dataid[collisions[0]]] == 24  # whole


def test_a_visual_with_its_own_colour_keeps_it_whole(tmp_path: Path) -> None:
    _two_colour_glb(tmp_path)
    source = tmp_path / "g.urdf"
    source.write_text(URDF.format(mesh="part.glb").replace(
        '<visual><geometry><mesh filename="part.glb"/></geometry></visual>',
        '<visual><geometry><mesh filename="part.glb"/></geometry>'
        '<material name="green"><color rgba="0 1 0 1"/></material></visual>'))
    mjcf = tmp_path / "out" / "g.xml"
    result = CliRunner().invoke(main, ["convert", str(source), "-o", str(mjcf)])
    assert result.exit_code == 0, result.output
    model = mujoco.MjModel.from_xml_path(str(mjcf))
    visuals = [g for g in _mesh_geoms(model) if model.geom_group[g] == 1]
    assert len(visuals) == 1 and tuple(model.geom_rgba[visuals[0]]) == (0.0, 1.0, 0.0, 1.0)


def test_ur5_visuals_keep_their_colours(tmp_path: Path) -> None:
    """example-robot-data's UR5: each COLLADA visual becomes a geom per material colour, together every
    triangle of the file, where before each was one grey geom."""
    from tests.conftest import example_robot, example_robot_data

    source = example_robot("ur_description/urdf/ur5_robot.urdf")
    robots = example_robot_data()
    assert robots is not None
    mjcf = tmp_path / "out" / "ur5.xml"
    result = CliRunner().invoke(main, ["convert", str(source), "-o", str(mjcf), "--package-path",
                                       f"example-robot-data={robots.parent}"])
    assert result.exit_code == 0, result.output
    model = mujoco.MjModel.from_xml_path(str(mjcf))
    base = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "base_link")
    visuals = [g for g in _mesh_geoms(model) if model.geom_group[g] == 1 and model.geom_bodyid[g] == base]
    assert len(visuals) == 2
    assert sum(int(model.mesh_facenum[model.geom_dataid[g]]) for g in visuals) == 1795 + 137
    assert {_rgba(model, g) for g in visuals} == {(0.5248, 0.5248, 0.5248, 1.0),
                                                                        (0.064, 0.064, 0.064, 1.0)}


def test_urdf_and_sdf_visuals_keep_the_colours_too(tmp_path: Path, sdf_oracle: Path) -> None:  # noqa: F811
    """The STL a glTF (or a converted COLLADA) file becomes holds no colour in any format: the URDF
    gets a <visual> per colour with its <material> (PyBullet shows it), the SDF a <visual> per colour
    with its <material> and, below alpha 1, <transparency> (libsdformat loads it)."""
    _two_colour_glb(tmp_path)
    source = tmp_path / "g.urdf"
    source.write_text(URDF.format(mesh="part.glb"))
    urdf, sdf = tmp_path / "out" / "g.urdf", tmp_path / "out" / "g.sdf"
    for target in (urdf, sdf):
        result = CliRunner().invoke(main, ["convert", str(source), "-o", str(target)])
        assert result.exit_code == 0, result.output
        assert "converted to 2 files, one per colour" in result.output
    client = pybullet.connect(pybullet.DIRECT)
    try:
        body = pybullet.loadURDF(str(urdf), physicsClientId=client)
        base = next(i for i in range(pybullet.getNumJoints(body, physicsClientId=client))
                    if pybullet.getJointInfo(body, i, physicsClientId=client)[12] == b"base")
        shapes = pybullet.getVisualShapeData(body, physicsClientId=client)
        colours = sorted(tuple(round(c, 4) for c in shape[7]) for shape in shapes if shape[1] == base)
    finally:
        pybullet.disconnect(client)
    assert colours == [(0.0, 0.0, 1.0, round(128 / 255, 4)), (1.0, 0.0, 0.0, 1.0)]
    written = sdf.read_text()
    assert written.count("<visual ") == 2 and "<diffuse>1 0 0 1</diffuse>" in written
    assert "<transparency>" in written
    assert not oracle_has_errors(sdf_oracle, sdf)


def test_body_visuals_keep_the_colours_too(tmp_path: Path) -> None:
    """The `.body` writer: a Shape per colour in the link's Visual, each with its material; read back
    (Choreonoid's rules), the link has the two coloured visuals and the whole collision mesh."""
    from modelkit import load

    loaded = load(_converted_two_colours(tmp_path, "body"))
    robot = loaded[0] if isinstance(loaded, list) else loaded
    base = next(link for link in robot.links if link.name == "base")
    looks = [v.material for v in base.visuals if v.material is not None]
    colours = sorted((tuple(round(float(c), 4) for c in m.diffuse), round(m.transparency, 4)) for m in looks)
    assert colours == [((0.0, 0.0, 1.0), round(1 - 128 / 255, 4)), ((1.0, 0.0, 0.0), 0.0)]
    arm = next(link for link in robot.links if link.name == "arm")
    assert len(arm.collisions) == 1
