"""Deep models (issue 18 §2): a 10,000-link serial chain is read, checked, printed and written to every
format without a RecursionError, and the MJCF written for it stays linear in size.

The chains are generated in ``tmp_path`` (:mod:`tests.chain_support`); a chain is as deep as a tree
gets, ten times Python's default recursion limit.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from lxml import etree

from modelkit.api import validate
from modelkit.convert.api import write
from modelkit.formats.mjcf.write_xml import indent
from modelkit.formats.mjcf.writer import MUJOCO_MAX_BODY_DEPTH
from modelkit.tree import tree_json, tree_report
from modelkit.verify.engines.reference import dof_joints
from tests import chain_support

LINKS = 10_000
TARGETS = {"urdf": ".urdf", "sdf": ".sdf", "mjcf": ".xml", "body": ".body"}


@pytest.mark.parametrize("fmt", ["urdf", "xacro", "sdf", "body"])
def test_a_10000_link_chain_is_read_and_printed(tmp_path: Path, fmt: str) -> None:
    source = chain_support.write(tmp_path, fmt, LINKS)
    checked = validate(source)
    assert not checked.errors, checked.errors[:3]
    robot = checked.robot
    assert robot is not None and len(robot.links) == LINKS
    text = tree_report(robot, max_lines=10 * LINKS)
    assert text.rstrip().endswith(f"link{LINKS - 1}")
    data = tree_json(robot, max_lines=10 * LINKS)  # json.loads itself recurses per level: not used here
    assert data.count('"joint":') == LINKS - 1 and data.rstrip().endswith("}")
    assert len(dof_joints(robot)) == LINKS - 1


# The .body writer emits through PyYAML's pure-Python emitter, about 3 ms a link (30 s at 10,000 links,
# linear: bench/bench_chain.py); three times Python's recursion limit proves its walks iterative.
WRITTEN_LINKS = {"urdf": LINKS, "sdf": LINKS, "mjcf": LINKS, "body": 3000}


def test_a_10000_link_chain_is_written_to_every_format(tmp_path: Path) -> None:
    """Every writer walks the whole chain (the readers of what they write are the test above's)."""
    sizes = set(WRITTEN_LINKS.values())
    robots = {n: validate(chain_support.write(tmp_path, "urdf", n)).robot for n in sizes}
    for target, suffix in TARGETS.items():
        links = WRITTEN_LINKS[target]
        robot = robots[links]
        assert robot is not None
        out = tmp_path / target / f"chain{suffix}"
        notes = write(robot, out, target)
        codes = {n.code for n in notes}
        assert ("MK872" in codes) == (target == "mjcf"), codes
        text = out.read_text()
        assert f"link{links - 1}" in text and f"joint{links - 1}" in text, target


def test_the_mjcf_of_a_deep_chain_says_mujoco_refuses_it_and_stays_linear(tmp_path: Path) -> None:
    """MuJoCo reads at most 496 nested bodies (its XML parser stops at 500 levels): the writer writes
    the chain, says so (MK872), and holds the indentation of deeper bodies, so the file grows with
    the links, not with their square (it was 500 MB for 10,000 links)."""
    sizes = {}
    for links in (MUJOCO_MAX_BODY_DEPTH, MUJOCO_MAX_BODY_DEPTH + 1, 4000):
        robot = validate(chain_support.write(tmp_path, "urdf", links)).robot
        assert robot is not None
        out = tmp_path / f"c{links}.xml"
        notes = [n for n in write(robot, out, "mjcf") if n.code == "MK872"]
        assert len(notes) == (links > MUJOCO_MAX_BODY_DEPTH), notes
        sizes[links] = out.stat().st_size
    if notes:
        assert f"nest {4000} deep" in notes[0].message and "link3999" in notes[0].message
    per_link = sizes[4000] / 4000
    assert per_link < 2 * sizes[MUJOCO_MAX_BODY_DEPTH] / MUJOCO_MAX_BODY_DEPTH, sizes


def test_the_indentation_is_lxmls_up_to_its_cap() -> None:
    def nested(depth: int) -> etree._Element:
        root = etree.Element("a")
        el = root
        for i in range(depth):
            el = etree.SubElement(el, "b", n=str(i))
            etree.SubElement(el, "c")
            etree.SubElement(el, "d").text = "kept"
        el.append(etree.Comment("note"))
        return root

    ours, theirs = nested(20), nested(20)
    indent(ours, max_level=100)
    etree.indent(theirs, space="  ")
    assert etree.tostring(ours) == etree.tostring(theirs)
    deep = nested(300)
    indent(deep, max_level=100)
    longest = max(len(line) - len(line.lstrip(b" ")) for line in etree.tostring(deep).split(b"\n"))
    assert longest == 200


def test_mujoco_reads_exactly_the_depth_the_writer_allows(tmp_path: Path) -> None:
    mujoco = pytest.importorskip("mujoco")
    for links, loads in ((MUJOCO_MAX_BODY_DEPTH, True), (MUJOCO_MAX_BODY_DEPTH + 1, False)):
        robot = validate(chain_support.write(tmp_path, "urdf", links)).robot
        assert robot is not None
        out = tmp_path / f"c{links}.xml"
        write(robot, out, "mjcf")
        if loads:
            assert mujoco.MjModel.from_xml_path(str(out)).nbody == links + 1
        else:
            with pytest.raises(ValueError, match="XML_ELEMENT_DEPTH_EXCEEDED"):
                mujoco.MjModel.from_xml_path(str(out))
