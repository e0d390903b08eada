"""A massless link on a moving joint gets a tiny explicit inertial in URDF (MK816). An MJCF body with
several joints is read as a chain of massless links, one per joint but the last. Written without
``<inertial>``, PyBullet gave each 1 kg and a unit inertia (dm_control's humanoid: 9 kg added to a
40 kg robot) and libsdformat's URDF import, Gazebo's, drops such a link with everything below it
(validate's MK322)."""

from __future__ import annotations

from pathlib import Path

import pybullet
import pytest

from modelkit.api import validate
from modelkit.convert.api import convert
from modelkit.convert.numbers import fmt
from modelkit.formats.urdf.write_links import TINY_INERTIA, TINY_MASS

from .conftest import CORPUS

HUMANOID = CORPUS / "dm_control_suite" / "dm_control" / "suite" / "humanoid.xml"


def _pybullet_mass(path: Path) -> tuple[float, int]:
    client = pybullet.connect(pybullet.DIRECT)
    try:
        body = pybullet.loadURDF(str(path), flags=pybullet.URDF_USE_INERTIA_FROM_FILE, physicsClientId=client)
        n = pybullet.getNumJoints(body, physicsClientId=client)
        masses = [pybullet.getDynamicsInfo(body, link, physicsClientId=client)[0] for link in range(-1, n)]
    finally:
        pybullet.disconnect(client)
    return sum(masses), sum(1 for m in masses if m == 1.0)


def test_the_humanoids_joint_links_weigh_nothing_in_pybullet_and_stay_in_gazebo(tmp_path: Path) -> None:
    assert HUMANOID.is_file(), f"the corpus file {HUMANOID} is missing"
    source = validate(HUMANOID).robots[0]
    total = sum(link.inertial.mass for link in source.links if link.inertial is not None)
    synthesised = [link.name for link in source.links if (link.inertial is None or link.inertial.mass == 0.0)
                   and any(j.child == link.name and j.type.value != "fixed" for j in source.joints)]
    assert len(synthesised) >= 8
    out = tmp_path / "h" / "humanoid.urdf"
    result = convert([HUMANOID], out)
    said = [n for n in result.notes if n.code == "MK816" and "no mass but moves" in n.message]
    assert len(said) == len(synthesised)
    mass, unit = _pybullet_mass(out)
    assert unit == 0  # no link holds PyBullet's 1 kg default
    assert mass == pytest.approx(total, abs=1e-4)  # 1e-6 kg per tiny inertial (sensor frames too)
    back = validate(out)
    assert not [d for d in back.diagnostics if d.code == "MK322"]  # libsdformat keeps every link
    text = out.read_text()
    assert text.count(f'<mass value="{fmt(TINY_MASS)}"/>') >= len(synthesised)
    assert f'ixx="{fmt(TINY_INERTIA)}"' in text


def test_massless_frames_and_root_weigh_nothing_in_pybullet(tmp_path: Path) -> None:
    """A massless link on a fixed joint (an MJCF site, an SDF frame, a URDF tool frame) and a massless
    root are written with the tiny inertial: PyBullet, loaded with no flags, then weighs the robot as
    its source (the root's 1 kg·m² made TIAGo turn short), and both read back as massless frames."""
    path = tmp_path / "r.urdf"
    path.write_text(
        '<robot name="r"><link name="base_footprint"/>'
        '<link name="a"><inertial><mass value="2"/>'
        '<inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>'
        '<link name="tool"/><joint name="f" type="fixed"><parent link="a"/><child link="tool"/></joint>'
        '<joint name="b" type="fixed"><parent link="base_footprint"/><child link="a"/></joint>'
        "</robot>")
    out = tmp_path / "o" / "r.urdf"
    result = convert([path], out)
    assert result.status == 0
    text = out.read_text()
    assert text.count(f'<mass value="{fmt(TINY_MASS)}"/>') == 2
    said = [n.message for n in result.notes if n.code == "MK816"]
    assert said and '"tool"' in said[0] and 'on the root "base_footprint"' in said[0], said
    client = pybullet.connect(pybullet.DIRECT)
    try:
        body = pybullet.loadURDF(str(out), physicsClientId=client)  # as a user loads it: no flags
        masses = {pybullet.getJointInfo(body, i, physicsClientId=client)[12].decode():
                  pybullet.getDynamicsInfo(body, i, physicsClientId=client)[0]
                  for i in range(pybullet.getNumJoints(body, physicsClientId=client))}
        base_mass, _, base_inertia = pybullet.getDynamicsInfo(body, -1, physicsClientId=client)[:3]
    finally:
        pybullet.disconnect(client)
    assert masses == {"a": 2.0, "tool": TINY_MASS}
    assert base_mass == TINY_MASS and max(base_inertia) < 1e-9  # not 1 kg and 1 kg·m²
    back = validate(out).robots[0]
    for name in ("tool", "base_footprint"):
        frame = back.link(name)
        assert frame is not None and frame.inertial is None, name
    assert not [n for n in result.notes if n.code == "MK816" and "no mass but moves" in n.message]
