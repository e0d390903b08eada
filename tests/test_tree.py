"""The tree report: byte-identical to Debian's check_urdf (run as an oracle), for .body too."""

from __future__ import annotations

import subprocess
from pathlib import Path

import pytest
from click.testing import CliRunner

from modelkit.cli import main
from modelkit.model import Joint, JointType, Link, Robot
from modelkit.tree import tree_json, tree_report

from .conftest import TUTORIAL, require_tool


def robot_from_edges(name: str, links: list[str], edges: list[tuple[str, str, str]]) -> Robot:
    robot = Robot(name=name, root=links[0])
    robot.links = [Link(n) for n in links]
    robot.joints = [Joint(j, JointType.FIXED, parent, child) for j, parent, child in edges]
    return robot


def urdf_of(robot: Robot) -> str:
    parts = [f'<robot name="{robot.name}">']
    parts += [f'  <link name="{link.name}"/>' for link in robot.links]
    for j in robot.joints:
        parts.append(
            f'  <joint name="{j.name}" type="fixed"><parent link="{j.parent}"/>'
            f'<child link="{j.child}"/></joint>'
        )
    parts.append("</robot>")
    return "\n".join(parts) + "\n"


CASES = {
    "ordered_by_joint_name": robot_from_edges(
        "order",
        ["base", "zeta", "mid", "alpha"],
        [("b_joint", "base", "zeta"), ("a_joint", "base", "mid"), ("c_joint", "base", "alpha")],
    ),
    "deep_and_wide": robot_from_edges(
        "test_robot",
        ["base_link", "link1", "link2", "link3", "link4", "link5"],
        [
            ("j1", "base_link", "link1"),
            ("j2", "link1", "link2"),
            ("j3", "base_link", "link3"),
            ("j4", "link2", "link4"),
            ("J0", "link1", "link5"),
        ],
    ),
    "single_link": robot_from_edges("only", ["only"], []),
    "byte_order_names": robot_from_edges(
        "bytes",
        ["root", "x1", "x2", "x3", "x4"],
        [("B", "root", "x1"), ("a", "root", "x2"), ("_", "root", "x3"), ("A10", "root", "x4")],
    ),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_tree_matches_check_urdf_bytes(case: str, tmp_path: Path) -> None:
    check_urdf = require_tool("check_urdf")
    robot = CASES[case]
    urdf = tmp_path / f"{case}.urdf"
    urdf.write_text(urdf_of(robot))
    expected = subprocess.run([check_urdf, str(urdf)], capture_output=True, check=True).stdout
    assert tree_report(robot).encode() == expected


def test_long_chain_matches_check_urdf(tmp_path: Path) -> None:
    check_urdf = require_tool("check_urdf")
    names = [f"l{i}" for i in range(300)]
    robot = robot_from_edges("chain", names, [(f"j{i}", names[i - 1], names[i]) for i in range(1, 300)])
    urdf = tmp_path / "chain.urdf"
    urdf.write_text(urdf_of(robot))
    expected = subprocess.run([check_urdf, str(urdf)], capture_output=True, check=True).stdout
    assert tree_report(robot).encode() == expected


def test_three_thousand_link_chain_does_not_recurse() -> None:
    names = [f"l{i}" for i in range(3000)]
    robot = robot_from_edges("chain", names, [(f"j{i:05d}", names[i - 1], names[i]) for i in range(1, 3000)])
    text = tree_report(robot)
    assert text.count("\n") == 3 + 2999
    assert text.splitlines()[-1] == " " * (4 * 2999) + "child(1):  l2999"


def test_cycle_is_printed_once_not_forever() -> None:
    robot = robot_from_edges("loop", ["a", "b", "c"], [("j1", "a", "b"), ("j2", "b", "c"), ("j3", "c", "b")])
    lines = tree_report(robot).splitlines()
    assert lines[3:] == ["    child(1):  b", "        child(1):  c", "            child(1):  b"]


SENSORS_TREE = """robot name is: MobileRobot
---------- Successfully Parsed XML ---------------
root Link: Chassis has 3 child(ren)
    child(1):  LeftWheel
    child(2):  PanLink
        child(1):  TiltLink
    child(3):  RightWheel
"""


def test_body_tree_cli_and_document_order() -> None:
    runner = CliRunner()
    result = runner.invoke(main, ["tree", str(TUTORIAL / "mobile_robot_sensors.body")])
    assert result.exit_code == 0, result.output
    assert result.stdout == SENSORS_TREE
    doc = runner.invoke(main, ["tree", "--order", "document", str(TUTORIAL / "mobile_robot_sensors.body")])
    assert doc.stdout.splitlines()[3:] == [
        "    child(1):  LeftWheel",
        "    child(2):  RightWheel",
        "    child(3):  PanLink",
        "        child(1):  TiltLink",
    ]


def test_body_tree_matches_the_packages_own_urdf_shape() -> None:
    """The tutorial's hand-written URDF of the same robot gives the same tree under check_urdf,
    apart from the two sensor frames that only the URDF has as links."""
    check_urdf = require_tool("check_urdf")
    expected = subprocess.run(
        [check_urdf, str(TUTORIAL / "mobile_robot_sensors.urdf")], capture_output=True, check=True, text=True
    ).stdout
    without_sensor_links = "".join(
        line for line in expected.splitlines(keepends=True) if "LiDAR" not in line and "RealSense" not in line
    )
    assert without_sensor_links == SENSORS_TREE


def test_tree_json_has_types_and_origins() -> None:
    runner = CliRunner()
    result = runner.invoke(main, ["tree", "--format", "json", str(TUTORIAL / "mobile_robot_sensors.body")])
    assert result.exit_code == 0
    import json

    data = json.loads(result.stdout)
    assert data["root_joint"] == "floating"
    pan = next(c for c in data["tree"]["children"] if c["joint"] == "PanJoint")
    assert pan["type"] == "revolute" and pan["origin"]["xyz"] == [-0.02, 0.0, 0.165]
    assert pan["children"][0]["link"] == "TiltLink"
    assert tree_json(CASES["single_link"]).count('"children": []') == 1


def test_tree_on_broken_file_exits_1_with_message(tmp_path: Path) -> None:
    body = tmp_path / "b.body"
    body.write_text(
        "format: ChoreonoidBody\nformat_version: 2.0\nlinks:\n  - name: a\n  - name: b\n    parent: nope\n"
    )
    result = CliRunner().invoke(main, ["tree", str(body)])
    assert result.exit_code == 1
    assert "MK202" in result.stderr and "ERROR: the kinematic tree cannot be built" in result.stderr
