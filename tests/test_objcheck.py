"""The fast OBJ verdict (modelkit.geometry.objcheck) against the full loader (meshfiles.load_mesh).

``mesh_problem`` answers ``validate``'s question "can this mesh file be used?" for plain OBJ files with
``obj_problem`` instead of trimesh; the answer must be the one ``load_mesh`` gives: None for a file that
loads, the same ``MK501`` message for one that does not. ``UNDECIDED`` (the caller then loads the file) is
allowed for hand-made hostile inputs, not for real files.
"""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap
import warnings
from pathlib import Path

import numpy as np
import pytest

from modelkit.geometry import meshfiles
from modelkit.geometry.meshfiles import MeshLoadError, MeshMetadata, load_mesh, mesh_problem
from modelkit.geometry.objcheck import UNDECIDED, obj_problem, obj_verdict

from .conftest import example_robot_data

PROJECT_ROOT = Path(__file__).resolve().parents[1]
CORPUS = PROJECT_ROOT.parent / "shared" / "corpus"
EXAMPLE_ROBOT_DATA = example_robot_data()


def reference(path: Path) -> str | None:
    """The verdict of the full loader, as mesh_problem gave it before the fast path."""
    return reference_and_corners(path)[0]


def reference_and_corners(path: Path) -> tuple[str | None, np.ndarray | None]:
    """The full loader's verdict and, for a file that loads, the corners of its vertices (low, high)."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            vertices = load_mesh(path).mesh.vertices
    except MeshLoadError as exc:
        return f"{exc.code}\t{exc}", None
    return None, np.array([vertices.min(axis=0), vertices.max(axis=0)])


def same_corners(fast: tuple[object, object] | None, full: np.ndarray | None) -> bool:
    """The fast check's corners are the full loader's, to the bit."""
    return fast is not None and full is not None and np.array_equal(np.array(fast), full)


def _pybullet_data() -> Path | None:
    try:
        import pybullet_data
    except ImportError:
        return None
    return Path(pybullet_data.getDataPath())


def _obj_files(root: Path | None) -> list[Path]:
    if root is None or not root.is_dir():
        return []
    return sorted(p for p in root.rglob("*") if p.suffix.lower() == ".obj" and p.is_file())


ROOTS = {
    "corpus": CORPUS,
    "pybullet_data": _pybullet_data(),
    "example-robot-data": EXAMPLE_ROBOT_DATA,
}


# ---- (a) real files: the same verdict, decided without loading -------------------------------


@pytest.mark.parametrize("root", list(ROOTS), ids=list(ROOTS))
def test_same_verdict_as_load_mesh_on_real_files(root: str) -> None:
    files = _obj_files(ROOTS[root])
    if not files:
        pytest.skip(f"no .obj files under {ROOTS[root]}")
    differ = []
    for path in files:
        fast, fast_corners = obj_verdict(path.read_bytes(), path.name)
        full, full_corners = reference_and_corners(path)
        if fast != full:  # UNDECIDED counts as a difference for real files
            differ.append(f"{path}: fast {fast!r}, load_mesh {full!r}")
        elif full is None and not same_corners(fast_corners, full_corners):  # real files: always corners
            differ.append(f"{path}: fast corners {fast_corners}, load_mesh {full_corners}")
    assert differ == [], f"{len(differ)} of {len(files)} files differ:\n" + "\n".join(differ[:20])


def test_pybullet_data_has_hundreds_of_obj_files() -> None:
    """The equivalence test above is only worth something with many real files."""
    if _pybullet_data() is None:
        pytest.skip("pybullet_data is not installed")
    assert len(_obj_files(_pybullet_data())) >= 200


# ---- (b) hand-made files ------------------------------------------------------------------------

V4 = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n"
VT = "vt 0 0\nvt 1 0\nvt 0 1\n"

# loaded by load_mesh: the fast check must accept them too
GOOD = {
    "triangle": V4 + "f 1 2 3\n",
    "quad": V4 + "f 1 2 4 3\n",
    "all_quads_and_polygon": V4 + "v 2 2 0\nf 1 2 5 4 3\n",
    "mixed_triangles_quads": V4 + "f 1 2 3\nf 1 2 4 3\n",
    "negative_relative": V4 + "f -1 -2 -3\n",
    "v_slash_vt": V4 + VT + "f 1/1 2/2 3/3\n",
    "v_slash_slash_vn": V4 + "vn 0 0 1\nf 1//1 2//1 3//1\n",
    "v_vt_vn": V4 + VT + "vn 0 0 1\nf 1/1/1 2/2/1 3/3/1 4/1/1\n",
    "nan_after_last_textured_vertex": V4 + "v nan 0 0\n" + VT + "f 1/1 2/2 3/3\n",
    "continuation": V4 + "f 1 2 \\\n 3\n",
    "crlf": (V4 + "f 1 2 3\n").replace("\n", "\r\n"),
    "comments_o_g_usemtl_s": "# made by hand\nmtllib m.mtl\no body\n" + V4
    + "g a\nusemtl red\ns 1\nf 1 2 3\n# f 9 9 9\nusemtl blue\ns off\nf 2 4 3\n",
    "vertex_colours_and_w": "v 0 0 0 1 0 0\nv 1 0 0 1 0 0\nv 0 1 0 1 0 0\nf 1 2 3\n",
    "exponents_and_signs": "v 1e5 1E-5 -.5e+3\nv +1. 0 0\nv 0 1 0\nf 1 2 3\n",
    "latin1_comment": "# caf\xe9\n" + V4 + "f 1 2 3\n",
    "no_final_newline": V4 + "f 1 2 3",
    # the shape-based paths and their fall-backs to reading every number
    "meshlab_interleaved_rows": "vn 0 0 1\nv 0 0 0\nvn 0 0 1\nv 1 0 0\nvn 0 0 1\nv 0 1 0\n"
    + "vt 0 0\nvt 1 0\nvt 0 1\nf 1/1/1 2/2/2 3/3/3\nvt 1 1\nvt 0 1\nvt 1 0\nf 3/4/3 2/5/2 1/6/1\n",
    "blanks_around_face_lines": V4 + "f 1 2 3 \nf  2 4 3\nf\t1 3 4\n",
    "comment_among_face_lines": V4 + "f 1 2 3\n# caf\xe9\nf 2 4 3\n",
    "leading_zeros_past_eighteen_digits": V4 + "f 0000000000000000000001 2 3\n",
    "long_mantissa": "v 0." + "0" * 120 + "1 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    "two_digit_exponents": "v 1e-05 2E+10 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
}

# refused by load_mesh: the fast check must refuse them with the same message
BAD = {
    "nul_bytes": V4 + "f 1 2 3\n\x00\x00",
    "face_past_last_vertex": V4 + "f 1 2 5\n",
    "negative_before_first_vertex": V4 + "f -1 -2 -5\n",
    "textured_face_past_last_vertex": V4 + VT + "f 1/1 2/2 9/3\n",
    "textured_negative_index": V4 + VT + "f 1/1 2/2 -1/3\n",
    "missing_vertex_in_second_material": V4 + "usemtl a\nf 1 2 3\nusemtl b\nf 2 3 9\n",
    "v_with_two_numbers": "v 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    "v_with_two_numbers_everywhere": "v 0 0\nv 1 0\nv 0 1\nf 1 2 3\n",
    "v_with_a_word": "v 0 0 x\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    "v_with_decimal_comma": "v 0,5 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    "v_with_trailing_comment": V4.replace("\n", " # c\n") + "f 1 2 3\n",
    "vt_with_words": V4 + "vt a b\nf 1 2 3\n",
    "nan_coordinate": V4 + "v nan 0 0\nf 1 2 3\n",
    "infinite_coordinate": "v -inf 0 0\n" + V4 + "f 1 2 3\n",
    "overflowing_coordinate": "v 1e999 0 0\n" + V4 + "f 1 2 3\n",
    "no_faces": V4,
    "only_comments": "# nothing here\n",
    "blank": "  \n\n",
    "faces_without_vertices": "f 1 2 3\n",
    "faces_with_two_vertices": V4 + "f 1 2\nf 2 3\n",
    "face_line_with_tab": V4 + "f\t1 2 3\n",
    "second_kind_malformed": V4 + "vn 0 0 1..\nf 1//1 2//1 3//1\n",
    "overflow_in_a_long_mantissa": "v 9" + "9" * 400 + " 0 0\n" + V4 + "f 1 2 3\n",
    "interleaved_face_past_last_vertex": "vn 0 0 1\nv 0 0 0\nvn 0 0 1\nv 1 0 0\nvn 0 0 1\nv 0 1 0\n"
    + "vt 0 0\nf 1/1/1 2/1/2 3/1/3\nvt 1 1\nf 3/2/3 2/2/2 4/2/1\n",
}

# the fast check leaves these to load_mesh
UNDECIDED_CASES = {
    "old_mac_line_ends": (V4 + "f 1 2 3\n").replace("\n", "\r"),
    "no_break_space": V4 + "f 1\xa02 3\n",
    "plus_sign_index": V4 + "f +1 2 3\n",
    "mixed_token_forms": V4 + VT + "f 1/1 2 3\n",
    "huge_index": V4 + "f 1 2 99999999999999999999\n",
    "non_ascii_in_face_line": V4 + "f 1 2 3 \xe9\n",
}


def _write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "m.obj"
    path.write_bytes(text.encode("utf-8"))
    return path


@pytest.mark.parametrize("text", list(GOOD.values()), ids=list(GOOD))
def test_accepts_what_load_mesh_loads(text: str, tmp_path: Path) -> None:
    """... with the corners of the vertices the loader keeps (not the NaN row past the last textured
    vertex, not the colour columns)."""
    path = _write(tmp_path, text)
    full, corners = reference_and_corners(path)
    assert full is None
    fast, fast_corners = obj_verdict(path.read_bytes(), path.name)
    assert fast is None and same_corners(fast_corners, corners), (fast_corners, corners)


def test_rows_of_different_lengths_give_no_corners(tmp_path: Path) -> None:
    """trimesh clips such rows to the shortest: the fast check gives the verdict, and no corners."""
    path = _write(tmp_path, "v 0 0 0\nv 1 0 0 1\nv 0 1 0\nf 1 2 3\n")
    assert reference(path) is None
    assert obj_verdict(path.read_bytes(), path.name) == (None, None)


def test_mesh_problem_keeps_the_corners_of_a_plain_obj(tmp_path: Path) -> None:
    path = _write(tmp_path, GOOD["vertex_colours_and_w"])
    meshfiles.clear_mesh_cache()
    assert mesh_problem(path) is None
    assert meshfiles.known_bounds(path) == ((0.0, 0.0, 0.0), (1.0, 1.0, 0.0))


@pytest.mark.parametrize("text", list(BAD.values()), ids=list(BAD))
def test_refuses_with_load_mesh_message(text: str, tmp_path: Path) -> None:
    path = _write(tmp_path, text)
    full = reference(path)
    assert full is not None and full.startswith("MK501\t")
    assert obj_problem(path.read_bytes(), path.name) == full


@pytest.mark.parametrize("text", list(UNDECIDED_CASES.values()), ids=list(UNDECIDED_CASES))
def test_undecided_falls_back_to_load_mesh(text: str, tmp_path: Path) -> None:
    path = _write(tmp_path, text)
    assert obj_problem(path.read_bytes(), path.name) == UNDECIDED
    meshfiles.clear_mesh_cache()
    assert mesh_problem(path) == reference(path)


# ---- mesh_problem uses the fast check only where it applies ----------------------------------------


def test_mesh_problem_takes_the_fast_path_for_plain_obj(tmp_path: Path,
                                                        monkeypatch: pytest.MonkeyPatch) -> None:
    def no_load(*args: object, **kwargs: object) -> None:
        raise AssertionError("load_mesh called")

    good = _write(tmp_path, GOOD["v_vt_vn"])
    bad = tmp_path / "bad.obj"
    bad.write_text(BAD["face_past_last_vertex"])
    expected_bad = reference(bad)
    meshfiles.clear_mesh_cache()
    monkeypatch.setattr(meshfiles, "load_mesh", no_load)
    assert mesh_problem(good) is None
    assert mesh_problem(bad) == expected_bad


def test_mesh_problem_fragment_metadata_and_read_errors_unchanged(tmp_path: Path) -> None:
    path = _write(tmp_path, GOOD["triangle"])
    meshfiles.clear_mesh_cache()
    assert mesh_problem(path, fragment="x") == (
        'MK502\tfragment "x" is not found in m.obj; OBJ files have no named parts')
    assert mesh_problem(path, metadata=MeshMetadata(length_unit="millimeter")) is None
    assert mesh_problem(path, max_bytes=8) == f"MK002\tcannot read m.obj: file is {path.stat().st_size} " \
        "bytes, over the limit of 8 bytes"
    assert mesh_problem(tmp_path / "missing.obj") == reference(tmp_path / "missing.obj")
    assert (mesh_problem(tmp_path / "missing.obj") or "").startswith("MK501\tcannot read missing.obj")
    (tmp_path / "dir.obj").mkdir()
    assert mesh_problem(tmp_path / "dir.obj") == reference(tmp_path / "dir.obj")


def test_mesh_problem_sees_a_changed_file(tmp_path: Path) -> None:
    path = _write(tmp_path, GOOD["triangle"])
    meshfiles.clear_mesh_cache()
    assert mesh_problem(path) is None
    path.write_text(BAD["face_past_last_vertex"] + "\n# longer")
    changed = mesh_problem(path)
    assert changed is not None and changed == reference(path)


# ---- (c) validate decides OBJ meshes without trimesh ------------------------------------------------

URDF = """\
<robot name="r">
  <link name="base">
    <inertial><mass value="1"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial>
    <visual><geometry><mesh filename="meshes/good.obj"/></geometry></visual>
    <collision><geometry><mesh filename="meshes/bad.obj"/></geometry></collision>
  </link>
</robot>
"""

CHILD = textwrap.dedent("""\
    import json
    import sys

    attempted = []


    class Recorder:
        @staticmethod
        def find_spec(fullname, path=None, target=None):
            if fullname.partition(".")[0] == "trimesh":
                attempted.append(fullname)
            return None


    sys.meta_path.insert(0, Recorder)

    from click.testing import CliRunner

    from modelkit.cli import main

    result = CliRunner().invoke(main, ["validate", sys.argv[1]], catch_exceptions=True)
    json.dump({"exit_code": result.exit_code, "output": result.output,
               "exception": None if result.exception is None or isinstance(result.exception, SystemExit)
               else repr(result.exception),
               "modules": sorted(sys.modules), "attempted": attempted}, sys.stdout)
""")


def test_validate_of_urdf_with_obj_meshes_does_not_import_trimesh(tmp_path: Path) -> None:
    (tmp_path / "meshes").mkdir()
    (tmp_path / "meshes" / "good.obj").write_text(GOOD["v_vt_vn"])
    (tmp_path / "meshes" / "bad.obj").write_text(BAD["face_past_last_vertex"])
    urdf = tmp_path / "r.urdf"
    urdf.write_text(URDF)
    done = subprocess.run([sys.executable, "-c", CHILD, str(urdf)], cwd=PROJECT_ROOT,
                          stdin=subprocess.DEVNULL, capture_output=True, text=True, check=False, timeout=300)
    assert done.returncode == 0, f"child failed:\n{done.stdout}\n{done.stderr}"
    report = json.loads(done.stdout)
    assert report["exception"] is None, report["exception"]
    # the meshes were judged: the broken one is reported, the good one is not
    assert "MK501" in report["output"] and "bad.obj: a face refers to a vertex that does not exist" in \
        report["output"], report["output"]
    assert "good.obj" not in report["output"], report["output"]
    assert "modelkit.geometry.objcheck" in report["modules"]
    assert [m for m in report["modules"] if m.partition(".")[0] == "trimesh"] == []
    assert report["attempted"] == []


def test_mixed_corner_counts_by_shape_equal_the_token_by_token_reading() -> None:
    """Face lines of different corner counts (triangles beside quads: gb-robot-models' gene01, 650,000
    corners, 1.6 s token by token) are judged by their shapes; the chunk is the one the token-by-token
    reading gives, on random blocks of plain, textured, normal, relative, empty-part and short lines."""
    import random

    from modelkit.geometry import objcheck as oc

    rng = random.Random(7)
    tokens = ["1", "2", "3", "12", "-1", "-2", "4/5", "6/7/8", "9//10", "3/-2", "-3/4/5", "2/", "5//", "7/8/",
              "0", "1/1/1", "--1", "1-2", "/3"]
    compared = refused = 0
    for _ in range(5000):
        lines = []
        for _ in range(rng.randint(1, 6)):
            corners = rng.choice([1, 2, 3, 3, 4, 4, 5, 6])
            separator = rng.choice([" ", "  ", "\t"])
            lead = " " if rng.random() < 0.2 else ""
            lines.append(lead + separator.join(rng.choice(tokens) for _ in range(corners)))
        block = "\n".join(lines).encode()
        shapes = oc._line_shapes(block)
        assert shapes is not None
        has_normals = rng.random() < 0.5
        try:
            expected = oc._per_line(block.split(b"\n"), has_normals)
        except oc._Undecided:
            with pytest.raises(oc._Undecided):
                oc._per_line_by_shape(block, shapes, has_normals)
            refused += 1
            continue
        got = oc._per_line_by_shape(block, shapes, has_normals)
        assert (got.width, got.masked_to_max, got.count, got.low, got.high) == (
            expected.width, expected.masked_to_max, expected.count, expected.low, expected.high), block
        assert got.faces == expected.faces
        compared += 1
    assert compared > 800 and refused > 800  # both outcomes exercised (1,006 and 3,994 with this seed)
