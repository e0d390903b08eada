"""xacro's ``load_yaml`` on hostile YAML: no hang, no run over 1 GiB, a coded located diagnostic.

Issue 18 §2: an alias bomb loaded by ``load_yaml`` and printed by an expression ran for minutes past
2 GB. Each case here is a real file in ``tmp_path``; the memory cases run ``modelkit validate`` in a
child process and read its peak resident size (``VmHWM``), under an address-space cap so that a
regression fails the test instead of swapping the machine. Values of a sound file are compared with
the xacro package's own ``process_file``, run in its own process.
"""

from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

import pytest

from modelkit.formats.xacro import expand_xacro

HEAD = '<?xml version="1.0"?>\n<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
GIB = 1 << 30

# Runs the CLI in a child process with 2 GiB of address space at most and prints, after the CLI's
# own output, one JSON line with the exit code and the peak resident size in bytes.
_CHILD = f"""
import json, resource, sys
sys.path.insert(0, {str(Path(__file__).resolve().parents[1])!r})
resource.setrlimit(resource.RLIMIT_AS, (2 << 30, 2 << 30))
from modelkit.cli import main
from tests.hostile.runner import own_peak_kib
try:
    main(sys.argv[1:], standalone_mode=False)
    code = 0
except SystemExit as exc:
    code = exc.code
print(json.dumps({{"exit": code, "peak": own_peak_kib() * 1024}}))
"""


def robot(folder: Path, expression: str, name: str = "m.urdf.xacro") -> Path:
    """A two-link robot whose joint offset is ``expression``, after ``v`` is loaded."""
    path = folder / name
    path.write_text(
        HEAD
        + "  <xacro:property name=\"v\" value=\"${xacro.load_yaml('values.yaml')}\"/>\n"
        + '  <link name="base"><inertial><mass value="1"/>'
        '<inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>\n'
        + '  <link name="tip"><inertial><mass value="1"/>'
        '<inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>\n'
        + '  <joint name="j" type="fixed"><parent link="base"/><child link="tip"/>'
        f'<origin xyz="{expression} 0 0"/></joint>\n</robot>\n'
    )
    return path


def validate_in_child(path: Path) -> tuple[int, int, list[dict[str, object]]]:
    """(exit code, peak resident bytes, diagnostics) of ``modelkit validate --format json``."""
    done = subprocess.run(
        [sys.executable, "-c", _CHILD, "validate", "--format", "json", str(path)],
        capture_output=True,
        text=True,
        timeout=120,  # a watchdog for a hang, not a timing assertion
    )
    assert "Traceback" not in done.stderr, done.stderr
    lines = done.stdout.strip().splitlines()
    status = json.loads(lines[-1])
    report = json.loads("\n".join(lines[:-1]))
    diagnostics = report["diagnostics"] if isinstance(report, dict) else report
    return int(status["exit"]), int(status["peak"]), diagnostics


def billion_laughs(levels: int = 9, width: int = 10) -> str:
    """Ten strings, then nine levels of ten aliases of the level below: 10**9 strings expanded."""
    lines = ["l0: &l0 [" + ", ".join(["lol"] * width) + "]"]
    for level in range(1, levels + 1):
        lines.append(f"l{level}: &l{level} [" + ", ".join([f"*l{level - 1}"] * width) + "]")
    return "\n".join(lines) + "\n"


def codes(diagnostics: list[dict[str, object]]) -> list[object]:
    return [d["code"] for d in diagnostics if d["severity"] == "error"]


def test_an_alias_bomb_is_refused_at_its_node_before_any_expression_expands_it(tmp_path: Path) -> None:
    (tmp_path / "values.yaml").write_text(billion_laughs())
    model = robot(tmp_path, "${len(str(v))}")
    exit_code, peak, found = validate_in_child(model)
    assert exit_code == 1
    assert codes(found) == ["MK015"]
    bomb = next(d for d in found if d["code"] == "MK015")
    assert bomb["file"] == str(tmp_path / "values.yaml") or str(bomb["file"]).endswith("values.yaml")
    assert isinstance(bomb["line"], int) and 2 <= bomb["line"] <= 10  # a level of the bomb, not line 0
    assert peak < GIB


def test_a_recursive_alias_is_refused(tmp_path: Path) -> None:
    (tmp_path / "values.yaml").write_text("a: &a [1, *a]\n")
    _, found = expand_xacro(robot(tmp_path, "${len(str(v))}"))
    refused = [d for d in found if d.code == "MK014"]
    assert refused and refused[0].location is not None and refused[0].location.line == 1


def test_a_yaml_of_almost_a_megabyte_loads_in_bounded_memory(tmp_path: Path) -> None:
    # 240,000 numbers (under --max-list-items): xacro's pure-Python loader takes seconds on them.
    (tmp_path / "values.yaml").write_text("v: [" + ", ".join(["1"] * 240_000) + "]\n")
    assert (tmp_path / "values.yaml").stat().st_size < 1_000_000
    exit_code, peak, found = validate_in_child(robot(tmp_path, "${len(v.v) / 240000}"))
    assert exit_code == 0, found
    assert peak < GIB


def test_a_loaded_value_turned_into_text_again_and_again_stops(tmp_path: Path) -> None:
    # 1.4 million nodes (under the alias limit), printed 100 times: 2 GB of text without a bound.
    lines = ["a0: &a0 [xxxxxxxxxx, xxxxxxxxxx, xxxxxxxxxx, xxxxxxxxxx]"]
    lines += [f"a{i}: &a{i} [*a{i - 1}, *a{i - 1}, *a{i - 1}, *a{i - 1}]" for i in range(1, 10)]
    (tmp_path / "values.yaml").write_text("\n".join(lines) + "\n")
    model = robot(tmp_path, "${len([str(v) for i in python.range(100)])}")
    exit_code, peak, found = validate_in_child(model)
    assert exit_code == 1
    assert codes(found) == ["MK709"]
    assert peak < GIB


def test_a_yaml_file_loaded_in_a_loop_counts_as_includes(tmp_path: Path) -> None:
    (tmp_path / "values.yaml").write_text("v: " + "x" * 100_000 + "\n")
    model = robot(tmp_path, "${len([xacro.load_yaml('values.yaml') for i in python.range(5000)])}")
    _, found = expand_xacro(model)
    assert [d.code for d in found if d.severity.value == "error"] == ["MK008"]


def test_a_python_tag_is_refused_where_it_is_and_never_run(tmp_path: Path) -> None:
    marker = tmp_path / "ran"
    (tmp_path / "values.yaml").write_text(
        f"name: base\nv: !!python/object/apply:os.system ['touch {marker}']\n"
    )
    _, found = expand_xacro(robot(tmp_path, "${len(str(v))}"))
    refused = [d for d in found if d.code == "MK700"]
    assert refused, found
    where = refused[0].location
    assert where is not None and where.file.endswith("values.yaml") and where.line == 2
    assert "python/object/apply" in refused[0].message
    assert not marker.exists()


def test_a_missing_yaml_file_is_mk705_on_the_line_that_loads_it(tmp_path: Path) -> None:
    _, found = expand_xacro(robot(tmp_path, "${len(str(v))}"))
    missing = [d for d in found if d.code == "MK705"]
    assert missing and "values.yaml" in missing[0].message
    assert missing[0].location is not None and missing[0].location.line == 3


def test_a_symlink_to_a_system_file_is_refused_unread(tmp_path: Path) -> None:
    (tmp_path / "values.yaml").symlink_to("/etc/passwd")
    text, found = expand_xacro(robot(tmp_path, "${len(str(v))}"))
    assert text is None
    assert [d.code for d in found if d.severity.value == "error"] == ["MK711"]
    assert all("root:" not in d.message for d in found)


def test_a_loaded_file_is_protected_from_convert(tmp_path: Path) -> None:
    # The YAML file is named like a URDF output: --force must still not replace an input.
    (tmp_path / "values.urdf").write_text("x: 0.25\n")
    model = robot(tmp_path, "${v.x}")
    model.write_text(model.read_text().replace("values.yaml", "values.urdf"))
    done = subprocess.run(
        [sys.executable, "-m", "modelkit.cli", "convert", str(model), "-o", str(tmp_path / "values.urdf"),
         "--force"],
        capture_output=True, text=True, timeout=120,
    )
    assert done.returncode == 2, done.stderr
    assert "MK891" in done.stderr
    assert (tmp_path / "values.urdf").read_text() == "x: 0.25\n"


SOUND_YAML = """\
arm:
  length: 0.25
  angle: !degrees 90
  offsets: &off [0.1, -0.2, 3.0e-1]
  again: *off
  name: upper
"""


def test_values_are_the_ones_xacro_itself_loads(tmp_path: Path) -> None:
    (tmp_path / "values.yaml").write_text(SOUND_YAML)
    expression = "${v.arm.length + v.arm.angle + v.arm.offsets[1] + v.arm.again[2] + len(v.arm.name)}"
    model = robot(tmp_path, expression)
    ours, found = expand_xacro(model)
    assert ours is not None, found
    oracle = "import sys, xacro; print(xacro.process_file(sys.argv[1]).toxml())"
    reference = subprocess.run(
        [sys.executable, "-c", oracle, str(model)],
        capture_output=True, text=True, timeout=120, cwd=tmp_path,
    )
    assert reference.returncode == 0, reference.stderr
    pattern = re.compile(r'<origin xyz="([^"]+)"')
    theirs_match, ours_match = pattern.search(reference.stdout), pattern.search(ours)
    assert theirs_match and ours_match
    assert ours_match.group(1) == theirs_match.group(1)
    assert float(ours_match.group(1).split()[0]) == pytest.approx(0.25 + 1.5707963267948966 - 0.2 + 0.3 + 5)
