"""Self-contact at rest (issue 17 item 4): body pairs whose collision shapes MuJoCo finds touching at
the reference configuration, and that MuJoCo does not already exclude (parent and child, welded
bodies), get ``<contact><exclude>`` in the written MJCF, with an MK832 note each; MK833 when the
written file cannot be compiled to look.

Panda (example-robot-data) is the issue's case: at q = 0 its hand overlaps link 5, link 7 overlaps
link 5 and the two fingers overlap, three contacts MuJoCo would act on at the first step.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from lxml import etree

from modelkit.convert.api import convert

from .conftest import example_robot_data

mujoco = pytest.importorskip("mujoco")

ERD = example_robot_data()
PANDA_PAIRS = [("panda_link5", "panda_link7"), ("panda_link5", "panda_hand"),
               ("panda_leftfinger", "panda_rightfinger")]


def _panda(folder: Path) -> tuple[Path, list[str], list[str]]:
    if ERD is None:
        pytest.skip("example-robot-data is not installed")
    out = folder / "panda.xml"
    result = convert([ERD / "panda_description" / "urdf" / "panda.urdf"], out)
    assert result.outputs == [str(out)]
    return out, [n.message for n in result.notes if n.code == "MK832"], \
        [n.code for n in result.notes if n.code == "MK833"]


def touching(model: object) -> list[tuple[str, str]]:
    """The body pairs in contact at q = 0."""
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)

    def name(g: int) -> str:
        return str(mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, int(model.geom_bodyid[g])))

    return sorted({tuple(sorted((name(c.geom[0]), name(c.geom[1])))) for c in data.contact[:data.ncon]})


def test_panda_touches_nothing_at_rest_once_its_touching_pairs_are_excluded(tmp_path: Path) -> None:
    out, notes, unchecked = _panda(tmp_path)
    root = etree.parse(str(out)).getroot()
    excludes = [(e.get("body1"), e.get("body2")) for e in root.iterfind("contact/exclude")]
    assert excludes == PANDA_PAIRS and unchecked == []
    assert len(notes) == 3 and "panda_link5 and panda_hand" in notes[1] and "mm" in notes[1]
    assert touching(mujoco.MjModel.from_xml_path(str(out))) == []
    # the excludes are what makes it so: without them MuJoCo finds the same three pairs touching
    contact = root.find("contact")
    assert contact is not None
    root.remove(contact)
    bare = tmp_path / "bare.xml"
    bare.write_bytes(etree.tostring(root))
    assert touching(mujoco.MjModel.from_xml_path(str(bare))) == sorted(tuple(sorted(p)) for p in PANDA_PAIRS)


def test_the_excludes_are_deterministic(tmp_path: Path) -> None:
    first, _, _ = _panda(tmp_path / "a")
    second, _, _ = _panda(tmp_path / "b")
    assert first.read_bytes() == second.read_bytes()


def _chain_urdf(links: int) -> str:
    """A serial chain whose every link has a collision box; links i and i + 2 overlap."""
    out = ['<robot name="chain">']
    for i in range(links):
        out.append(f'<link name="l{i}"><inertial><mass value="0.5"/><inertia ixx="0.001" ixy="0" ixz="0" '
                   'iyy="0.001" iyz="0" izz="0.001"/></inertial><collision><geometry>'
                   '<box size="0.1 0.1 0.5"/>'
                   '</geometry></collision></link>')
    for i in range(1, links):
        out.append(f'<joint name="j{i}" type="revolute"><parent link="l{i - 1}"/><child link="l{i}"/>'
                   '<origin xyz="0 0 0.1"/><axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="1" '
                   'velocity="1"/></joint>')
    return "\n".join([*out, "</robot>"])


def test_grandparent_overlaps_are_found_and_mujoco_refusal_is_noted(tmp_path: Path) -> None:
    """Links 0.5 m long, 0.1 m apart: each overlaps the next three. MuJoCo excludes parent and child,
    except a child of a body welded to the world (l0 and l1 do collide there).
    A chain deeper than MuJoCo's XML parser reads (MK872) cannot be checked: MK833 says so."""
    small = tmp_path / "small.urdf"
    small.write_text(_chain_urdf(4))
    result = convert([small], tmp_path / "small.xml")
    pairs = [(e.get("body1"), e.get("body2"))
             for e in etree.parse(str(tmp_path / "small.xml")).getroot().iterfind("contact/exclude")]
    assert pairs == [("l0", "l1"), ("l0", "l2"), ("l0", "l3"), ("l1", "l3")]
    assert [n.code for n in result.notes].count("MK832") == 4
    assert touching(mujoco.MjModel.from_xml_path(str(tmp_path / "small.xml"))) == []
    deep = tmp_path / "deep.urdf"
    deep.write_text(_chain_urdf(500))
    result = convert([deep], tmp_path / "deep.xml")
    unchecked = [n for n in result.notes if n.code == "MK833"]
    assert len(unchecked) == 1 and "did not compile" in unchecked[0].message
    assert "<contact>" not in (tmp_path / "deep.xml").read_text()


SLIDER = """<robot name="slider">
<link name="base"><inertial><mass value="1"/>
<inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
<collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision></link>
<link name="cart"><inertial><mass value="1"/>
<inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
<collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision></link>
<joint name="x" type="prismatic"><parent link="base"/><child link="cart"/><axis xyz="1 0 0"/>
<limit lower="-2" upper="2" effort="10" velocity="1"/></joint>
</robot>
"""


def test_the_home_pose_is_the_reference_when_there_is_one(tmp_path: Path) -> None:
    """A cart on a slide overlaps its base at q = 0 (the base is welded to the world, so MuJoCo does not
    filter the pair); started 1 m away (its initial position, the ``home`` keyframe) it touches nothing,
    and nothing is excluded."""
    from modelkit.api import validate
    from modelkit.convert.api import write

    source = tmp_path / "slider.urdf"
    source.write_text(SLIDER)
    robot = validate(source).robot
    assert robot is not None
    at_zero = [n for n in write(robot, tmp_path / "zero" / "s.xml") if n.code == "MK832"]
    assert len(at_zero) == 1 and "base and cart" in at_zero[0].message and "q = 0" in at_zero[0].message
    next(j for j in robot.joints if j.name == "x").initial_position = 1.0
    notes = write(robot, tmp_path / "home" / "s.xml")
    assert [n for n in notes if n.code in ("MK832", "MK833")] == []
    text = (tmp_path / "home" / "s.xml").read_text()
    # the default --actuators auto gives the slide a position servo holding the home position
    assert "<contact>" not in text and '<key name="home" qpos="1" ctrl="1"/>' in text
