"""Leftovers of the hostile-input work: trees that are very deep, trees whose check_urdf report
explodes (links with several parents), XML nested without bound."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest
from click.testing import CliRunner

from modelkit.api import validate
from modelkit.cli import main
from modelkit.tree import JSON_INDENT_LEVELS, TreeTooLarge, dumps_indented, tree_json, tree_report
from modelkit.xmlsource import MAX_XML_DEPTH

from .conftest import require_tool
from .test_tree import robot_from_edges


def chain_urdf(links: int) -> str:
    parts = ['<robot name="chain">'] + [f'  <link name="l{i}"/>' for i in range(links)]
    parts += [
        f'  <joint name="j{i:05d}" type="fixed"><parent link="l{i - 1}"/><child link="l{i}"/></joint>'
        for i in range(1, links)
    ]
    return "\n".join([*parts, "</robot>"]) + "\n"


def ladder_urdf(rungs: int) -> str:
    """Two rails; each rung's two links are children of both links of the rung before, so the paths
    from the root (and check_urdf's report) double with every rung."""
    parts = ['<robot name="ladder">', '<link name="base"/>', '<link name="a0"/>', '<link name="b0"/>']
    parts += [
        f'<joint name="j{c}0" type="fixed"><parent link="base"/><child link="{c}0"/></joint>' for c in "ab"
    ]
    for k in range(1, rungs + 1):
        parts += [f'<link name="a{k}"/>', f'<link name="b{k}"/>']
        parts += [
            f'<joint name="j{c}{k:03d}{p}" type="fixed"><parent link="{p}{k - 1}"/>'
            f'<child link="{c}{k}"/></joint>'
            for c in "ab"
            for p in "ab"
        ]
    return "\n".join([*parts, "</robot>"]) + "\n"


def test_tree_json_of_a_20000_link_chain(tmp_path: Path) -> None:
    urdf = tmp_path / "chain.urdf"
    urdf.write_text(chain_urdf(20_000))
    out = tmp_path / "tree.json"
    with out.open("wb") as stdout:
        done = subprocess.run(
            [
                sys.executable,
                "-m",
                "modelkit.cli",
                "tree",
                "--format",
                "json",
                "--max-links",
                "30000",
                str(urdf),
            ],
            stdout=stdout,
            stderr=subprocess.PIPE,
            check=False,
        )
    assert done.returncode == 0, done.stderr[-2000:]
    text = out.read_text()
    assert text.count('"joint": ') == 19_999 and '"link": "l19999",' in text
    assert text.endswith("}\n") and text.count("{") == text.count("}") and text.count("[") == text.count("]")
    widest = max(len(line) - len(line.lstrip(" ")) for line in text.splitlines())
    assert widest == 2 * JSON_INDENT_LEVELS  # the indentation stops growing: output linear in links


def test_tree_json_is_json_dumps_layout_below_the_indent_cap() -> None:
    names = [f"l{i}" for i in range(20)]
    robot = robot_from_edges("chain", names, [(f"j{i}", names[i - 1], names[i]) for i in range(1, 20)])
    text = tree_json(robot)
    assert text == json.dumps(json.loads(text), indent=2) + "\n"
    data = {"a": [1.5, None, "é", {"b": {}}, []], "c": {"d": [[1, 2], [3]]}, "e": float("inf")}
    assert dumps_indented(data) == json.dumps(data, indent=2)


@pytest.mark.parametrize("rungs", [3, 8])
def test_ladder_report_is_check_urdfs(rungs: int, tmp_path: Path) -> None:
    """check_urdf prints a link once per parent path; where it terminates, ours is the same bytes."""
    check_urdf = require_tool("check_urdf")
    urdf = tmp_path / "ladder.urdf"
    urdf.write_text(ladder_urdf(rungs))
    expected = subprocess.run([check_urdf, str(urdf)], capture_output=True, check=True).stdout
    result = CliRunner().invoke(main, ["tree", str(urdf)])
    assert result.exit_code == 1 and "MK220" in result.stderr  # printed, but two-parent links are errors
    assert result.stdout_bytes == expected
    assert len(expected.splitlines()) == 3 + 2 ** (rungs + 2) - 2


def test_ladder_of_30_rungs_is_refused_with_a_code(tmp_path: Path) -> None:
    """check_urdf would print 2**32 lines (about 400 GB; it ran 1.25 GB in 20 s): ours stops at once."""
    urdf = tmp_path / "ladder.urdf"
    urdf.write_text(ladder_urdf(30))
    for extra in ([], ["--format", "json"]):
        result = CliRunner().invoke(main, ["tree", *extra, str(urdf)])
        assert result.exit_code == 1
        assert result.stdout == ""
        assert "error MK223" in result.stderr
    robot = validate(urdf).robot
    assert robot is not None
    with pytest.raises(TreeTooLarge):
        tree_report(robot, max_lines=1000)


def nested(depth: int) -> str:
    """A URDF whose elements nest ``depth`` levels (the <robot> element is level 1)."""
    return '<robot name="r"><link name="a"/>' + "<x>" * (depth - 1) + "</x>" * (depth - 1) + "</robot>\n"


@pytest.mark.parametrize("depth", [MAX_XML_DEPTH + 1, 257, 100_000])
def test_xml_deeper_than_our_limit_is_refused(depth: int, tmp_path: Path) -> None:
    urdf = tmp_path / "deep.urdf"
    urdf.write_text(nested(depth))
    codes = [d.code for d in validate(urdf).errors]
    assert codes == ["MK023"]
    result = CliRunner().invoke(main, ["tree", str(urdf)])
    assert result.exit_code == 1 and "error MK023" in result.stderr


def test_xml_at_our_depth_limit_is_read(tmp_path: Path) -> None:
    urdf = tmp_path / "deep.urdf"
    urdf.write_text(nested(MAX_XML_DEPTH))
    assert "MK023" not in {d.code for d in validate(urdf).diagnostics}
