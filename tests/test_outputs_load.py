"""Issue 17 §8: every MJCF ``convert`` writes loads in MuJoCo, or ``convert`` exits 1 naming why.

Each case is a small generated robot in a tmp folder, converted with the CLI; the output is then
loaded with ``mujoco.MjModel.from_xml_path``.
"""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest
import trimesh
from click.testing import CliRunner

from modelkit.cli import main

BOX = trimesh.creation.box([0.1, 0.1, 0.1])
INERTIAL = ('<inertial><mass value="1"/>'
            '<inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>')


def _urdf(mesh: str, collision: bool) -> str:
    geometry = f'<geometry><mesh filename="{mesh}"/></geometry>'
    shapes = f"<visual>{geometry}</visual>" + (f"<collision>{geometry}</collision>" if collision else "")
    return f'<robot name="r"><link name="base">{INERTIAL}{shapes}</link></robot>'


def _ascii_stl() -> bytes:
    text = BOX.export(file_type="stl_ascii")
    return text.encode() if isinstance(text, str) else bytes(text)


def _binary_stl(vertices: np.ndarray, faces: np.ndarray) -> bytes:
    data = trimesh.Trimesh(vertices, faces, process=False).export(file_type="stl")
    return bytes(data)


def _nan_stl() -> bytes:
    vertices = np.array(BOX.vertices)
    vertices[0, 0] = np.nan
    return _binary_stl(vertices, np.asarray(BOX.faces))


def _flat_stl() -> bytes:
    return _binary_stl(np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]], dtype=float),
                       np.array([[0, 1, 2], [1, 3, 2]]))


def _huge_stl() -> bytes:
    sphere = trimesh.creation.icosphere(subdivisions=7)  # 327,680 faces
    return _binary_stl(np.asarray(sphere.vertices), np.asarray(sphere.faces))


def _tiny_stl() -> bytes:  # a closed cube of 10 µm: 1e-15 m³, "mesh volume is too small" for MuJoCo
    return _binary_stl(np.asarray(BOX.vertices) * 1e-4, np.asarray(BOX.faces))


MESHES = {
    "tiny": _tiny_stl,
    "ascii": _ascii_stl,
    "obj_text": lambda: str(BOX.export(file_type="obj")).encode(),
    "png": lambda: b"\x89PNG\r\n\x1a\n" + bytes(200),
    "empty": lambda: b"",
    "nan": _nan_stl,
    "flat": _flat_stl,
    "huge": _huge_stl,
}

# (mesh, collision: the mesh is the visual and the collision shape, else visual only)
#   → (exit code, a code the output must print, geoms MuJoCo loads)
CASES = {
    ("ascii", True): (0, "MK804", 2),  # converted to binary STL
    ("ascii", False): (0, "MK804", 1),
    ("obj_text", True): (0, "MK804", 2),  # read by its content, written as binary STL
    ("flat", False): (0, "MK876", 1),  # a visual plane: inertia="shell" on its asset
    ("tiny", True): (0, "MK876", 2),
    ("flat", True): (0, "MK881", 2),  # the collision a thin box in the plane: MuJoCo has no hull of a plane
    ("png", True): (1, "MK805", 0),
    ("empty", True): (1, "MK805", 0),
    ("nan", True): (1, "MK805", 0),
    ("huge", True): (0, "MK804", 2),  # 327,680 faces: over MuJoCo's STL bound, written as OBJ
    # check_urdf never opens meshes, so the reading's MK500 is a warning; the written robot has no
    # collision there (MK805), and convert exits 1
    ("missing", True): (1, "MK805", 0),
}


def _convert(source: Path, out: Path) -> tuple[int, str]:
    result = CliRunner().invoke(main, ["convert", str(source), "-o", str(out)])
    return result.exit_code, result.output  # stdout and stderr, each line once


@pytest.mark.parametrize(("mesh", "collision"), list(CASES))
def test_each_mesh_case_loads_in_mujoco_or_exits_1(mesh: str, collision: bool, tmp_path: Path) -> None:
    if mesh in MESHES:
        (tmp_path / f"{mesh}.stl").write_bytes(MESHES[mesh]())
    source = tmp_path / "robot.urdf"
    source.write_text(_urdf(f"{mesh}.stl", collision))
    out = tmp_path / "out" / "robot.xml"
    status, output = _convert(source, out)
    expected_status, code, geoms = CASES[(mesh, collision)]
    assert status == expected_status, output
    assert code in output, output
    if expected_status == 1:
        assert f"error {code}" in output and "error(s)" in output.splitlines()[-1], output
    model = mujoco.MjModel.from_xml_path(str(out))  # what is written always loads
    assert int(model.ngeom) == geoms, output
    if mesh in ("ascii", "obj_text"):
        written = next((out.parent / "meshes").glob("*.stl")).read_bytes()
        assert len(written) == 84 + 50 * int.from_bytes(written[80:84], "little")  # binary STL
    if (mesh, collision) == ("flat", True):  # the 1 m square as a 1 m × 1 m × 1 mm box over it
        box = [g for g in range(model.ngeom) if model.geom_type[g] == mujoco.mjtGeom.mjGEOM_BOX]
        assert len(box) == 1 and np.allclose(model.geom_size[box[0]], [0.5, 0.5, 0.0005]), output
        assert np.allclose(model.geom_pos[box[0]], [0.5, 0.5, 0.0]), output
    if mesh == "huge":
        assert [p.name for p in (out.parent / "meshes").glob("*")] == ["huge.obj"], output
        assert model.mesh_facenum[0] == 327_680


def test_panoramic_camera_is_clamped_with_a_note(tmp_path: Path) -> None:
    source = tmp_path / "pano.body"
    source.write_text("""\
format: ChoreonoidBody
format_version: 2.0
angle_unit: degree
name: pano
root_link: base
links:
  -
    name: base
    joint_type: free
    mass: 1.0
    center_of_mass: [ 0, 0, 0 ]
    inertia: [ 0.01, 0, 0, 0, 0.01, 0, 0, 0, 0.01 ]
    elements:
      - { type: Shape, geometry: { type: Box, size: [ 0.1, 0.1, 0.1 ] } }
      - { type: Camera, name: Panorama, format: COLOR, translation: [ 0.1, 0, 0 ], field_of_view: 180,
          width: 640, height: 480 }
""")
    out = tmp_path / "out" / "pano.xml"
    status, output = _convert(source, out)
    assert status == 0, output
    assert "MK875" in output
    model = mujoco.MjModel.from_xml_path(str(out))
    assert model.ncam == 1 and model.cam_fovy[0] == pytest.approx(179.0)


def test_summary_counts_every_warning_printed(tmp_path: Path) -> None:
    (tmp_path / "robot.urdf").write_text(
        '<robot name="r"><link name="base">' + INERTIAL
        + '<visual><geometry><mesh filename="gone.stl"/></geometry></visual>'
        + '<visual><geometry><box size="1 1 1"/></geometry><bogus/></visual></link></robot>')
    status, output = _convert(tmp_path / "robot.urdf", tmp_path / "out" / "robot.xml")
    printed = sum(" warning MK" in line for line in output.splitlines())
    assert printed >= 2
    assert f"notes: {printed} warning(s)" in output, output
    assert status == 0


def test_a_flat_generated_mesh_keeps_its_visual_and_its_collision_as_a_box(tmp_path: Path) -> None:
    """A `.body` TriangleMesh (written by the writer, not copied) gets the same checks."""
    source = tmp_path / "tri.body"
    source.write_text("""\
format: ChoreonoidBody
format_version: 2.0
angle_unit: degree
name: tri
root_link: base
links:
  -
    name: base
    joint_type: free
    mass: 1.0
    center_of_mass: [ 0, 0, 0 ]
    inertia: [ 0.01, 0, 0, 0, 0.01, 0, 0, 0, 0.01 ]
    elements:
      - type: Shape
        geometry: { type: TriangleMesh, vertices: [ 0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0 ],
                    faces: [ 0, 1, 2, 1, 3, 2 ] }
""")
    out = tmp_path / "out" / "tri.xml"
    status, output = _convert(source, out)
    assert status == 0, output
    assert "warning MK881" in output and "MK876" in output, output
    model = mujoco.MjModel.from_xml_path(str(out))
    assert model.ngeom == 2  # the visual plane and its collision as a thin box


TWO_OBJECTS_OBJ = (
    "v 0 0 0\nv 0.1 0 0\nv 0 0.1 0\nv 0 0 0.1\nv 0.3 0 0\nv 0.4 0 0\nv 0.3 0.1 0\nv 0.3 0 0.1\n"
    "o first\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\no second\nf 5 7 6\nf 5 6 8\nf 5 8 7\nf 6 7 8\n"
)


def test_an_obj_of_several_objects_reaches_mujoco_whole(tmp_path: Path) -> None:
    """MuJoCo's OBJ reader keeps only a file's first object (4 of these 8 faces): the MJCF writer asks
    MuJoCo, converts such a file to a binary STL and says so (MK804); MuJoCo then reads all 8."""
    (tmp_path / "two.obj").write_text(TWO_OBJECTS_OBJ)
    direct = mujoco.MjModel.from_xml_string(
        f'<mujoco><asset><mesh name="m" file="{tmp_path / "two.obj"}" inertia="shell"/></asset>'
        "<worldbody/></mujoco>")
    assert direct.mesh_facenum[0] == 4  # the reader's behaviour this conversion exists for
    source = tmp_path / "robot.urdf"
    source.write_text(_urdf("two.obj", collision=True))
    out = tmp_path / "out" / "robot.xml"
    status, output = _convert(source, out)
    assert status == 0, output
    assert "MK804" in output and "keeps 4 of its 8 triangles" in output, output
    model = mujoco.MjModel.from_xml_path(str(out))
    assert model.nmesh == 1 and model.mesh_facenum[0] == 8


def _copied_as_is(obj: str, tmp_path: Path) -> None:
    """An OBJ MuJoCo reads whole and without complaint is copied byte for byte, without a note."""
    (tmp_path / "m.obj").write_text(obj)
    source = tmp_path / "robot.urdf"
    source.write_text(_urdf("m.obj", collision=True))
    out = tmp_path / "out" / "robot.xml"
    status, output = _convert(source, out)
    assert status == 0 and "MK804" not in output, output
    assert (out.parent / "meshes" / "m.obj").read_text() == obj


def test_an_obj_of_one_object_is_copied_as_is(tmp_path: Path) -> None:
    _copied_as_is(TWO_OBJECTS_OBJ.replace("o second\n", ""), tmp_path)


PYBULLET_SHAPES = """
import sys, pybullet as p
p.connect(p.DIRECT)
body = p.loadURDF(sys.argv[1])
print("SHAPES", [s[2] for s in p.getCollisionShapeData(body, -1)])
"""


@pytest.mark.parametrize("suffix", [".urdf", ".sdf", ".body"])
def test_an_ascii_stl_is_binary_in_every_target(suffix: str, tmp_path: Path) -> None:
    """PyBullet reads only binary STL: an ASCII one crashed it (segmentation fault, measured), and
    MuJoCo refuses it. Every writer converts it (MK804), keeping the file name."""
    (tmp_path / "box.stl").write_bytes(_ascii_stl())
    source = tmp_path / "robot.urdf"
    source.write_text(_urdf("box.stl", collision=True))
    out = tmp_path / "out" / f"robot{suffix}"
    status, output = _convert(source, out)
    assert status == 0 and "MK804" in output, output
    written = (out.parent / "meshes" / "box.stl").read_bytes()
    assert len(written) == 84 + 50 * int.from_bytes(written[80:84], "little") == 84 + 50 * 12
    if suffix == ".urdf":
        import subprocess
        import sys

        run = subprocess.run([sys.executable, "-c", PYBULLET_SHAPES, str(out)], capture_output=True,
                             text=True, timeout=120, check=False)
        assert run.returncode == 0, run.stderr
        assert "SHAPES [5]" in run.stdout  # GEOM_MESH


# robosuite's Sawyer head_1.obj, reduced: one flat object 2.75 mm above its origin (a disc). MuJoCo
# finds no volume ("mesh volume is too small"); from the origin the surface and the origin make a cone
# of 3.9e-6 m³, so the writer thought it solid and copied it without inertia="shell" (Sawyer refused).
FLAT_DISC_OBJ = "".join(f"v {0.037 * np.cos(a):.6f} {0.037 * np.sin(a):.6f} 0.00275\n"
                        for a in np.linspace(0.0, 2.0 * np.pi, 12, endpoint=False)) + \
    "".join(f"f 1 {i} {i + 1}\n" for i in range(2, 12))


@pytest.mark.parametrize(("collision", "status", "code", "geoms"),
                         [(False, 0, "MK876", 1), (True, 0, "MK881", 2)])
def test_a_flat_obj_of_one_object_loads(collision: bool, status: int, code: str, geoms: int,
                                                   tmp_path: Path) -> None:
    (tmp_path / "disc.obj").write_text(FLAT_DISC_OBJ)
    source = tmp_path / "robot.urdf"
    source.write_text(_urdf("disc.obj", collision))
    out = tmp_path / "out" / "robot.xml"
    got, output = _convert(source, out)
    assert got == status and code in output, output
    model = mujoco.MjModel.from_xml_path(str(out))  # refused before: "mesh volume is too small: disc"
    assert int(model.ngeom) == geoms
    assert (out.parent / "meshes" / "disc.obj").read_text() == FLAT_DISC_OBJ  # still the file as it was


def test_a_written_file_mujoco_refuses_is_an_error(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The safety net under every MJCF rule: when MuJoCo's compiler refuses the written file for a reason
    no note explains (here the writer's hollow-mesh rule is switched off, as it was wrong for the Sawyer
    head before), MK877 quotes MuJoCo and convert exits 1; before, only an info note (MK833) said so."""
    import modelkit.convert.meshes as meshes

    monkeypatch.setattr(meshes, "_hollow", lambda corners, scale=None: False)
    (tmp_path / "disc.obj").write_text(FLAT_DISC_OBJ)
    source = tmp_path / "robot.urdf"
    source.write_text(_urdf("disc.obj", collision=False).replace(
        "</link>", '<collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link>'))
    out = tmp_path / "out" / "robot.xml"
    status, output = _convert(source, out)
    assert status == 1, output
    assert "error MK877" in output and "mesh volume is too small" in output, output
    with pytest.raises(ValueError, match="mesh volume is too small"):
        mujoco.MjModel.from_xml_path(str(out))



def _star_of_boxes(links: int) -> str:
    """A root with ``links - 1`` children, every one a 0.05 m box at the same place."""
    box = '<collision><geometry><box size="0.05 0.05 0.1"/></geometry></collision>'
    inertial = ('<inertial><mass value="0.5"/><inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" '
                'izz="0.0005"/></inertial>')
    out = ['<robot name="star">']
    out += [f'<link name="l{i}">{inertial}{box}</link>' for i in range(links)]
    out += [f'<joint name="j{i}" type="revolute"><parent link="l0"/><child link="l{i}"/>'
            '<origin xyz="0 0 0.1"/><axis xyz="0 1 0"/>'
            '<limit lower="-1" upper="1" effort="10" velocity="2"/></joint>'
            for i in range(1, links)]
    return "\n".join([*out, "</robot>"])


def test_a_written_file_mujoco_cannot_step_is_an_error(tmp_path: Path) -> None:
    """400 boxes at one place: 80,000 pairs in contact overflow MuJoCo's memory at the first step.
    Finding the contacts at rest raised mujoco.FatalError out of convert (a traceback); now MK877
    says what a user of the file meets, and convert exits 1."""
    source = tmp_path / "star.urdf"
    source.write_text(_star_of_boxes(400))
    out = tmp_path / "out" / "star.xml"
    status, output = _convert(source, out)
    assert status == 1, output
    assert "Traceback" not in output and "error MK877" in output and "out of memory" in output, output
    model = mujoco.MjModel.from_xml_path(str(out))
    with pytest.raises(mujoco.FatalError, match="out of memory"):  # what the note tells the user
        mujoco.mj_step(model, mujoco.MjData(model))

TETRA_VERTICES = "v 0 0 0\nv 0.1 0 0\nv 0 0.1 0\nv 0 0 0.1\nvt 0 0\nvt 1 0\nvt 0 1\nvn 0 0 1\n"
TETRA_FACES = ((1, 3, 2), (1, 2, 4), (1, 4, 3), (2, 3, 4))
# How the corners of the first face and of the other three are written (v / vt / vn).
FACE_ATTRIBUTE_CASES = {
    "texture coordinates on some corners": ("{v}/1/1", "{v}//1", "texture coordinates", "warns"),
    "normals on some corners": ("{v}/1/1", "{v}/1", "normals", "refuses"),
}


def _tetra_obj(first: str, rest: str) -> str:
    lines = [" ".join(("f", *((first if i == 0 else rest).format(v=v) for v in face)))
             for i, face in enumerate(TETRA_FACES)]
    return TETRA_VERTICES + "\n".join(lines) + "\n"


def _mujoco_load(path: Path) -> tuple[str, str]:
    """MuJoCo's verdict on a model file, in a child process: its error, and what it printed (its
    OBJ reader's warnings go to the process's stderr, not to Python)."""
    import subprocess
    import sys

    code = ("import sys, mujoco\ntry:\n    mujoco.MjModel.from_xml_path(sys.argv[1])\n"
            "except ValueError as e:\n    print('REFUSED', e)\n")
    done = subprocess.run([sys.executable, "-c", code, str(path)], capture_output=True, text=True, timeout=60)
    return done.stdout, done.stderr


@pytest.mark.parametrize("case", list(FACE_ATTRIBUTE_CASES))
def test_an_obj_whose_faces_mix_attributes_loads_without_a_warning(case: str, tmp_path: Path) -> None:
    """pybullet_data's table_square/table.obj gives normals to some face corners and not to others, and
    MuJoCo refuses it; a file that does the same with texture coordinates loads with a warning and no
    texture coordinates. The MJCF writer writes the OBJ without what MuJoCo cannot take (MK804)."""
    first, rest, left_out, verdict = FACE_ATTRIBUTE_CASES[case]
    obj = _tetra_obj(first, rest)
    (tmp_path / "m.obj").write_text(obj)
    direct = tmp_path / "direct.xml"
    direct.write_text(f'<mujoco><asset><mesh name="m" file="{tmp_path / "m.obj"}"/></asset>'
                      '<worldbody><geom type="mesh" mesh="m"/></worldbody></mujoco>')
    printed, warned = _mujoco_load(direct)  # the reader's behaviour this cleaning exists for
    assert ("REFUSED" in printed) if verdict == "refuses" else ("WARNING" in warned and not printed)
    source = tmp_path / "robot.urdf"
    source.write_text(_urdf("m.obj", collision=True))
    out = tmp_path / "out" / "robot.xml"
    status, output = _convert(source, out)
    assert status == 0, output
    assert "MK804" in output and f"without its {left_out}" in output, output
    assert _mujoco_load(out) == ("", "")  # loads, and prints nothing
    written = (out.parent / "meshes" / "m.obj").read_text()
    faces = [line for line in written.splitlines() if line.startswith("f ")]
    assert len(faces) == 4 and [line.split()[1].split("/")[0] for line in faces] == ["1", "1", "1", "2"]
    model = mujoco.MjModel.from_xml_path(str(out))
    assert model.nmesh == 1 and model.mesh_facenum[0] == 4 and model.mesh_vertnum[0] == 4


def test_an_obj_with_consistent_faces_keeps_its_normals_and_texture_coordinates(tmp_path: Path) -> None:
    _copied_as_is(_tetra_obj("{v}/1/1", "{v}/2/1"), tmp_path)
