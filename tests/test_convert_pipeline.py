"""The convert pipeline's own promises: numbers, output safety, atomic writes, reports, exit codes."""

from __future__ import annotations

import json
import math
import os
from pathlib import Path

import pytest
from click.testing import CliRunner
from hypothesis import given
from hypothesis import strategies as st

from modelkit.cli import main
from modelkit.convert.numbers import fmt, fmt_vec
from modelkit.convert.output import OutputPlan, safe_file_name

from .conftest import PENDULUM_BODY, TUTORIAL


def test_numbers_are_short_and_clean() -> None:
    assert fmt(1.0000000000000002) == "1"
    assert fmt(-0.0) == "0"
    assert fmt(0.1) == "0.1"
    assert fmt(100.0) == "100"
    assert fmt(1e-5) == "1e-5"
    assert fmt(-2.5e-12) == "-2.5e-12"
    assert fmt(123456789.125) == "123456789.125"
    assert fmt_vec([0.0, -0.0, 1.5]) == "0 0 1.5"
    with pytest.raises(ValueError):
        fmt(math.inf)


@given(st.floats(allow_nan=False, allow_infinity=False))
def test_numbers_round_trip_within_1e_12(x: float) -> None:
    """Issue 17 §5: a value within 1e-12 (relative) of a shorter decimal is written as that decimal;
    otherwise 15 significant digits (half an ulp of 15 digits: 5e-15)."""
    text = fmt(x)
    back = float(text)
    assert back == x or abs(back - x) <= 1e-12 * abs(x)
    if abs(back - x) > 5e-15 * abs(x):
        assert len(text.split("e")[0].replace("-", "").replace(".", "").strip("0")) < 15


@given(st.decimals(min_value=-1e6, max_value=1e6, places=6, allow_nan=False, allow_infinity=False))
def test_numbers_a_person_wrote_come_back_exactly(d: object) -> None:
    x = float(str(d))
    assert float(fmt(x)) == x


def test_safe_names_cannot_leave_the_folder() -> None:
    assert safe_file_name("../../etc/passwd") == "passwd"
    assert safe_file_name("..") == "file"
    assert safe_file_name("a b/c:d.stl") == "c_d.stl"
    assert safe_file_name(".hidden.stl") == "hidden.stl"


def test_plan_refuses_outside_inputs_and_existing(tmp_path: Path) -> None:
    source = tmp_path / "in.urdf"
    source.write_text("x")
    plan = OutputPlan(tmp_path, {source})
    plan.add("in.urdf", b"y", "model")
    plan.add("../escape.stl", b"z", "mesh")
    (tmp_path / "exists.sdf").write_text("old")
    plan.add("exists.sdf", b"new", "model")
    codes = sorted(d.code for d in plan.problems())
    assert codes == ["MK890", "MK891", "MK892"]
    assert source.read_text() == "x" and (tmp_path / "exists.sdf").read_text() == "old"


def test_plan_shares_identical_files_and_numbers_different_ones(tmp_path: Path) -> None:
    plan = OutputPlan(tmp_path)
    assert plan.add("meshes/a.stl", b"1", "mesh") == "meshes/a.stl"
    assert plan.add("meshes/a.stl", b"1", "mesh") == "meshes/a.stl"
    assert plan.add("meshes/b.stl", b"1", "mesh") == "meshes/a.stl"  # same bytes, one file
    assert plan.add("meshes/a.stl", b"2", "mesh") == "meshes/a_2.stl"
    plan.commit()
    assert sorted(os.listdir(tmp_path / "meshes")) == ["a.stl", "a_2.stl"]


def test_plan_keeps_an_identical_existing_mesh_without_force(tmp_path: Path) -> None:
    (tmp_path / "meshes").mkdir()
    (tmp_path / "meshes" / "a.stl").write_bytes(b"same")
    plan = OutputPlan(tmp_path)
    plan.add("meshes/a.stl", b"same", "mesh")
    assert plan.problems() == []


def test_failed_commit_leaves_nothing(tmp_path: Path) -> None:
    plan = OutputPlan(tmp_path)
    plan.add("a.urdf", b"1", "model")
    plan.add("sub/b.stl", b"2", "mesh")
    (tmp_path / "sub").write_text("a file where a folder must go")
    with pytest.raises(OSError):
        plan.commit()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["sub"]


def _pendulum(tmp_path: Path) -> Path:
    path = tmp_path / "pendulum.body"
    path.write_text(PENDULUM_BODY)
    return path


def test_cli_converts_and_reports(tmp_path: Path) -> None:
    source = _pendulum(tmp_path)
    out = tmp_path / "out" / "pendulum.urdf"
    report = tmp_path / "notes.json"
    result = CliRunner().invoke(main, ["convert", str(source), "-o", str(out), "--report", str(report)])
    assert result.exit_code == 0, result.output
    assert out.is_file() and "<robot" in out.read_text()
    data = json.loads(report.read_text())
    assert data["outputs"] == [str(out)] and data["status"] == 0
    assert all(n["code"].startswith("MK8") for n in data["notes"])
    # the same again is refused (exit 2, file untouched), then replaced with --force
    before = out.read_bytes()
    again = CliRunner().invoke(main, ["convert", str(source), "-o", str(out)])
    assert again.exit_code == 2 and "MK890" in again.output
    forced = CliRunner().invoke(main, ["convert", str(source), "-o", str(out), "--force"])
    assert forced.exit_code == 0 and out.read_bytes() == before


def test_cli_never_overwrites_its_input(tmp_path: Path) -> None:
    source = tmp_path / "robot.urdf"
    CliRunner().invoke(main, ["convert", str(_pendulum(tmp_path)), "-o", str(source)])
    text = source.read_text()
    result = CliRunner().invoke(main, ["convert", str(source), "-o", str(source), "--force"])
    assert result.exit_code == 2 and "MK891" in result.output
    assert source.read_text() == text


def test_cli_bad_input_writes_nothing(tmp_path: Path) -> None:
    bad = tmp_path / "bad.body"
    bad.write_text("format: ChoreonoidBody\nformat_version: 2.0\nlinks: [ {name: A, mass: x} ]\n")
    out = tmp_path / "out"
    result = CliRunner().invoke(main, ["convert", str(bad), "-o", str(out / "bad.urdf")])
    assert result.exit_code == 1, result.output
    assert "Traceback" not in result.output
    assert not out.exists()
    missing = CliRunner().invoke(main, ["convert", str(tmp_path / "nope.body"), "-o", str(out / "x.urdf")])
    assert missing.exit_code == 2 and "MK001" in missing.output


def test_cli_needs_a_target(tmp_path: Path) -> None:
    result = CliRunner().invoke(main, ["convert", str(_pendulum(tmp_path)), "-o", str(tmp_path / "out")])
    assert result.exit_code == 2 and "--to" in result.output


def test_cli_many_inputs_into_one_folder(tmp_path: Path) -> None:
    source = _pendulum(tmp_path)
    sensors = TUTORIAL / "mobile_robot_sensors.body"
    out = tmp_path / "out"
    result = CliRunner().invoke(main, ["convert", str(source), str(sensors), "--to", "urdf", "-o", str(out)])
    assert result.exit_code == 0, result.output
    assert sorted(p.name for p in out.glob("*.urdf")) == ["mobile_robot_sensors.urdf", "pendulum.urdf"]


def test_cli_strict_fails_on_warnings(tmp_path: Path) -> None:
    sensors = TUTORIAL / "mobile_robot_sensors.body"  # its chassis mesh is missing: MK805 warning
    out = tmp_path / "r.urdf"
    result = CliRunner().invoke(main, ["convert", str(sensors), "-o", str(out), "--strict"])
    assert result.exit_code == 1, result.output
    assert out.is_file()  # written all the same: --strict judges, it does not withhold
