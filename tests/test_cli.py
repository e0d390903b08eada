"""The validate command as users and CI see it: output formats, exit codes, options."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from click.testing import CliRunner

from modelkit.cli import main

from .conftest import TUTORIAL

CLEAN = """format: ChoreonoidBody
format_version: 2.0
name: Pendulum
links:
  - name: base
  - name: arm
    parent: base
    joint_type: revolute
    joint_axis: Y
    mass: 1.0
    center_of_mass: [0, 0, -0.25]
    inertia: [0.02, 0, 0, 0.02, 0, 0.001]
"""


def run(*args: str) -> tuple[int, str, str]:
    result = CliRunner().invoke(main, list(args))
    assert result.exception is None or isinstance(result.exception, SystemExit), result.exception
    return result.exit_code, result.stdout, result.stderr


def test_clean_file_exits_0_with_summary(tmp_path: Path) -> None:
    body = tmp_path / "clean.body"
    body.write_text(CLEAN)
    code, out, err = run("validate", str(body))
    assert (code, out) == (0, "")
    assert "1 file(s) checked: 0 error(s), 0 warning(s)" in err


def test_error_line_format_and_exit_1(tmp_path: Path) -> None:
    body = tmp_path / "bad.body"
    body.write_text(CLEAN.replace("parent: base", "parent: bsae"))
    code, out, _ = run("validate", str(body))
    assert code == 1
    assert out == f'{body}:7:13: error MK202 parent link "bsae" of "arm" is not defined\n'


def test_warnings_pass_unless_strict_and_can_be_ignored(tmp_path: Path) -> None:
    body = tmp_path / "warn.body"
    body.write_text(CLEAN.replace("joint_axis: Y", "jointAxs: Y"))
    code, out, _ = run("validate", str(body))
    assert code == 0 and "warning MK103" in out and 'did you mean "jointAxis"' in out
    assert run("validate", "--strict", str(body))[0] == 1
    code, out, _ = run("validate", "--strict", "--ignore", "unknown-key", str(body))
    assert (code, out) == (0, "")


def test_json_output(tmp_path: Path) -> None:
    body = tmp_path / "bad.body"
    body.write_text(CLEAN.replace("mass: 1.0", "mass: -1.0"))
    code, out, _ = run("validate", "--format", "json", str(body))
    assert code == 1
    data = json.loads(out)
    assert data["summary"] == {"errors": 1, "warnings": 0, "infos": 0}
    (d,) = data["diagnostics"]
    assert (d["code"], d["name"], d["line"], d["column"], d["severity"]) == (
        "MK300",
        "mass-not-positive",
        10,
        11,
        "error",
    )


def test_github_annotations(tmp_path: Path) -> None:
    body = tmp_path / "bad.body"
    body.write_text(CLEAN.replace("mass: 1.0", "mass: -1.0"))
    _, out, _ = run("validate", "--format", "github", str(body))
    assert out.startswith(f"::error file={body},line=10,col=11,title=MK300::")


def test_missing_file_exits_2_and_others_still_checked(tmp_path: Path) -> None:
    body = tmp_path / "bad.body"
    body.write_text(CLEAN.replace("parent: base", "parent: bsae"))
    code, out, _ = run("validate", str(tmp_path / "nope.body"), str(body))
    assert code == 2
    assert "MK001" in out and "MK202" in out


def test_unknown_extension_is_a_diagnostic(tmp_path: Path) -> None:
    other = tmp_path / "robot.txt"
    other.write_text("x")
    code, out, _ = run("validate", str(other))
    assert code == 2 and "cannot tell the format" in out
    code, out, _ = run("validate", "--input-format", "body", str(other))
    assert code == 1 and "MK017" in out


def test_an_mjcf_include_fragment_is_named_as_one(tmp_path: Path) -> None:
    """gymnasium-robotics' adroit_model.xml is the <mujocoinclude> body of the scenes that include it."""
    fragment = tmp_path / "hand_model.xml"
    fragment.write_text('<mujocoinclude><body name="wrist"><geom size=".1"/></body></mujocoinclude>')
    code, out, _ = run("validate", str(fragment))
    assert code == 2 and "MK001" in out and "MJCF include fragment" in out
    assert f"{fragment}:" in out and "give that model's file instead" in out


def test_many_files_in_one_call() -> None:
    files = sorted(str(p) for p in TUTORIAL.glob("*.body"))
    code, out, err = run("validate", "--no-resources", *files)
    assert f"{len(files)} file(s) checked: 1 error(s)" in err
    # The one error: mobile_robot_mesh.body uses the absent chassis mesh as collision geometry.
    (error,) = [line for line in out.splitlines() if " error " in line]
    assert "mobile_robot_mesh.body:20:14: error MK500" in error
    assert code == 1


def test_materials_option(tmp_path: Path) -> None:
    table = tmp_path / "materials.yaml"
    table.write_text("materials:\n  - name: Rubber\n    roughness: 1.0\n    viscosity: 0.5\n")
    body = tmp_path / "m.body"
    body.write_text(CLEAN.replace("    joint_axis: Y\n", "    joint_axis: Y\n    material: Rubber\n"))
    code, out, _ = run("validate", str(body))
    assert code == 0 and "MK508" in out and '"Rubber"' in out
    assert run("validate", "--materials", str(table), str(body))[:2] == (0, "")


def test_package_path_option(tmp_path: Path) -> None:
    pkg = tmp_path / "pkgdir"
    (pkg / "meshes").mkdir(parents=True)
    (pkg / "meshes" / "part.stl").write_text("solid x\nendsolid x\n")
    body = tmp_path / "p.body"
    body.write_text(
        CLEAN + "    elements:\n      - type: Visual\n        elements:\n          - type: Resource\n"
        "            uri: package://mypkg/meshes/part.stl\n"
    )
    code, out, _ = run("validate", "--no-resources", str(body))
    assert code == 0 and "MK504" in out and "--package-path mypkg=DIR" in out
    code, out, _ = run("validate", "--no-resources", "--package-path", f"mypkg={pkg}", str(body))
    assert "MK504" not in out and code == 0


def test_bad_option_value_is_usage_error() -> None:
    code, _, err = run("validate", "--package-path", "novalue", "x.body")
    assert code == 2 and "expected NAME=DIR" in err


def test_jobs_2_prints_the_same_bytes_as_jobs_1(corpus: Path) -> None:
    """`validate -j 2` checks files in two processes and prints exactly what `-j 1` prints, in
    input order (corpus files with and without findings, plus broken ones)."""
    here = Path(__file__).parent
    files = sorted(corpus.glob("choreonoid/share/model/*/*.body"))[:6]
    files += sorted(corpus.rglob("*.urdf"))[:3]
    files += sorted((here / "broken_urdf").glob("*.urdf"))[:2]
    files += sorted((here / "broken_body").glob("*.body"))[:2]
    assert len(files) >= 6
    words = [str(f) for f in files]
    for fmt in ("text", "json"):
        one = run("validate", "--show-info", "--format", fmt, "-j", "1", *words)
        two = run("validate", "--show-info", "--format", fmt, "-j", "2", *words)
        assert one == two
        assert one[1]  # there are findings to compare


def test_validate_leaves_the_callers_environment_as_it_was(monkeypatch: pytest.MonkeyPatch) -> None:
    """validate lets MuJoCo skip its OpenGL back end only for the command's own run: a program that
    runs the command in its process keeps MUJOCO_GL unset (verify's picture processes read it)."""
    import os

    monkeypatch.delenv("MUJOCO_GL", raising=False)
    pendulum = Path(__file__).parent / "mjcf" / "pendulum.xml"
    result = CliRunner().invoke(main, ["validate", str(pendulum)])
    assert result.exit_code == 0, result.output
    assert "MUJOCO_GL" not in os.environ


def test_materials_table_reaches_the_written_friction(tmp_path: Path) -> None:
    """`convert --materials TABLE` gives the links the friction of the user's table against Choreonoid's
    floor material (Ground), as validate reads the table; before, the converted friction always came from
    Choreonoid's own table (the reader never handed the path on), so the Rubber link got the Default rule."""
    table = tmp_path / "materials.yaml"
    table.write_text("materials:\n  - name: Default\n    roughness: 0.5\n    viscosity: 0.0\n"
                     "  - name: Ground\n    roughness: 0.5\n    viscosity: 0.0\n"
                     "  - name: Rubber\n    roughness: 1.0\n    viscosity: 0.5\n"
                     "contact_materials:\n  - materials: [ Rubber, Ground ]\n    friction: 0.37\n")
    body = tmp_path / "m.body"
    body.write_text(CLEAN.replace("    joint_axis: Y\n", "    joint_axis: Y\n    material: Rubber\n")
                    + "    elements:\n      - type: Shape\n"
                    "        geometry: { type: Box, size: [ 0.1, 0.1, 0.1 ] }\n")
    out = tmp_path / "out" / "m.xml"
    code, stdout, _ = run("convert", "--materials", str(table), str(body), "-o", str(out))
    assert code == 0, stdout
    assert 'friction="0.37 0.005 0.0001"' in out.read_text()


def test_an_undeclared_world_link_is_explained(tmp_path: Path) -> None:
    """Drake's URDFs (its acrobot) hang the robot from an undeclared "world", which Drake takes as its
    world body and urdfdom refuses: the root error names the link hanging from it, and the
    undefined-parent error says what to declare."""
    urdf = tmp_path / "welded.urdf"
    urdf.write_text('<robot name="w"><link name="base_link"/><link name="arm"/>'
                    '<joint name="weld" type="fixed"><parent link="world"/><child link="base_link"/></joint>'
                    '<joint name="j" type="continuous"><parent link="base_link"/><child link="arm"/>'
                    '<axis xyz="0 0 1"/></joint></robot>')
    code, out, _ = run("validate", str(urdf))
    assert code == 1
    root = next(line for line in out.splitlines() if "error MK200" in line)
    assert '"base_link" hangs from "world", which is not defined' in root
    parent = next(line for line in out.splitlines() if "error MK202" in line)
    assert 'declare <link name="world"/>' in parent and "Drake" in parent
