"""xacro macro libraries (files included by others, with no robot of their own) are not robots."""

from __future__ import annotations

import json
from pathlib import Path

from click.testing import CliRunner

from modelkit.cli import main

LIBRARY = """<?xml version="1.0"?>
<robot xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:property name="wheel_radius" value="0.1"/>
  <xacro:macro name="wheel" params="name">
    <link name="${name}"/>
  </xacro:macro>
</robot>
"""


def _validate(path: Path, *args: str) -> tuple[int, list[dict[str, object]]]:
    result = CliRunner().invoke(main, ["validate", "--format", "json", *args, str(path)])
    return result.exit_code, json.loads(result.stdout)["diagnostics"]


def test_macro_library_is_reported_as_info_not_as_a_broken_robot(tmp_path: Path) -> None:
    library = tmp_path / "wheel.xacro"
    library.write_text(LIBRARY, encoding="utf-8")
    code, diagnostics = _validate(library, "--strict")
    assert code == 0
    assert diagnostics == []  # info is hidden without --show-info
    code, diagnostics = _validate(library, "--show-info")
    assert code == 0
    assert [(d["code"], d["line"]) for d in diagnostics] == [("MK710", 2)]


def test_library_errors_are_still_reported(tmp_path: Path) -> None:
    library = tmp_path / "broken.xacro"
    include = '<xacro:include filename="missing.xacro"/>\n  '
    broken = LIBRARY.replace("<xacro:property", include + "<xacro:property")
    library.write_text(broken, encoding="utf-8")
    code, diagnostics = _validate(library)
    assert code == 1
    assert any(d["severity"] == "error" for d in diagnostics)


def test_tree_of_a_library_says_why_it_has_none(tmp_path: Path) -> None:
    library = tmp_path / "wheel.xacro"
    library.write_text(LIBRARY, encoding="utf-8")
    result = CliRunner().invoke(main, ["tree", str(library)])
    assert result.exit_code == 0  # as validate: no robot is not an error (issue 9: tree and validate agree)
    assert result.stdout == ""
    assert "info MK710" in result.stderr and "info MK222" in result.stderr
