"""An SDF model's ``<frame>``s carried to every target (MK874): URDF and ``.body`` links on fixed joints,
MJCF sites, SDF frames again. Before, the URDF writer left them out with a note that printed a Python
dict and the MJCF and ``.body`` writers left them out without a word.

Oracles: ``check_urdf`` and yourdfpy forward kinematics (what robot_state_publisher publishes), MuJoCo's
own site positions, libsdformat's frame graph through modelkit's SDF reader, the source's poses worked
out by hand.
"""

from __future__ import annotations

import math
import subprocess
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from lxml import etree

from modelkit.api import validate
from modelkit.cli import main
from tests.conftest import require_tool

# l1 turns about Y at 0.5 m above the base; tool0 is 0.3 m along l1's Z, turned 90° about Y; tcp is
# 0.1 m along tool0's Z (a frame attached to a frame); "base" names a link too (renamed, MK800).
ARM = """<?xml version="1.0"?>
<sdf version="1.9">
  <model name="arm">
    <link name="base"><inertial><mass>1</mass>
      <inertia><ixx>0.01</ixx><iyy>0.01</iyy><izz>0.01</izz></inertia></inertial></link>
    <link name="l1"><pose>0 0 0.5 0 0 0</pose><inertial><mass>1</mass>
      <inertia><ixx>0.01</ixx><iyy>0.01</iyy><izz>0.01</izz></inertia></inertial></link>
    <joint name="j1" type="revolute"><parent>base</parent><child>l1</child>
      <axis><xyz>0 1 0</xyz><limit><lower>-1</lower><upper>1</upper></limit></axis></joint>
    <frame name="tool0" attached_to="l1"><pose>0 0 0.3 0 1.5707963267948966 0</pose></frame>
    <frame name="tcp" attached_to="tool0"><pose>0 0 0.1 0 0 0</pose></frame>
    <frame name="mount" attached_to="base"><pose>0.2 0 0 0 0 0</pose></frame>
    <joint name="world_fix" type="fixed"><parent>world</parent><child>base</child></joint>
  </model>
</sdf>
"""
# Positions in the model frame at q = 0: tool0 at (0, 0, 0.8); tcp 0.1 m along tool0's Z, which the
# 90° turn about Y points along the model's X: (0.1, 0, 0.8); mount at (0.2, 0, 0).
EXPECTED = {"tool0": (0.0, 0.0, 0.8), "tcp": (0.1, 0.0, 0.8), "mount": (0.2, 0.0, 0.0)}


@pytest.fixture()
def arm(tmp_path: Path) -> Path:
    path = tmp_path / "src" / "arm.sdf"
    path.parent.mkdir()
    path.write_text(ARM)
    return path


def _convert(source: Path, out: Path, *extra: str) -> str:
    result = CliRunner().invoke(main, ["convert", str(source), "-o", str(out), *extra])
    assert result.exit_code == 0, result.output
    return result.output


def test_urdf_gets_each_frame_as_a_link_that_ros_tools_see(arm: Path, tmp_path: Path) -> None:
    import yourdfpy

    out = tmp_path / "arm.urdf"
    said = _convert(arm, out)
    assert "MK874 3 SDF frame(s) written as massless links" in said
    assert "tool0 (on l1)" in said and "tcp (on l1)" in said and "mount (on base)" in said
    assert "sdf_frames" not in said  # no internal key or Python value in a note
    run = subprocess.run([require_tool("check_urdf"), str(out)], capture_output=True, text=True, timeout=30)
    assert run.returncode == 0, run.stderr
    tree = run.stdout.splitlines()
    expected = {"            child(1):  tcp", "            child(2):  tool0", "        child(2):  mount"}
    assert expected <= set(tree)
    urdf = yourdfpy.URDF.load(str(out), load_meshes=False, build_collision_scene_graph=False,
                              load_collision_meshes=False)
    for name, where in EXPECTED.items():
        pose = urdf.get_transform(name, "world")
        assert np.allclose(pose[:3, 3], where, atol=1e-12), (name, pose)
    tool = urdf.get_transform("tool0", "world")
    assert np.allclose(tool[:3, 2], (1.0, 0.0, 0.0), atol=1e-12)  # its Z along the model's X
    urdf.update_cfg({"j1": 0.5})
    tcp = urdf.get_transform("tcp", "world")
    # turned with l1 about Y through (0, 0, 0.5): the offset (0.1, 0, 0.3) rotated by 0.5 rad
    c, s = math.cos(0.5), math.sin(0.5)
    assert np.allclose(tcp[:3, 3], (0.1 * c + 0.3 * s, 0.0, 0.5 - 0.1 * s + 0.3 * c), atol=1e-12)


def test_mjcf_gets_each_frame_as_a_site_where_the_sdf_puts_it(arm: Path, tmp_path: Path) -> None:
    import mujoco

    out = tmp_path / "arm.xml"
    _convert(arm, out)
    model = mujoco.MjModel.from_xml_path(str(out))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    for name, where in EXPECTED.items():
        site = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, name)
        assert site >= 0, name
        assert np.allclose(data.site_xpos[site], where, atol=1e-12), (name, data.site_xpos[site])
    assert model.nbody == 3  # world, base, l1: the frames are no bodies


def test_body_gets_each_frame_as_a_link_and_sdf_keeps_frames(arm: Path, tmp_path: Path) -> None:
    body = tmp_path / "arm.body"
    _convert(arm, body)
    back = validate(body).robot
    assert back is not None
    poses = back.world_poses()
    for name, where in EXPECTED.items():
        assert np.allclose(poses[name].translation, where, atol=1e-12), name
    sdf = tmp_path / "arm.sdf"
    said = _convert(arm, sdf)
    assert "MK874" not in said
    frames = {el.get("name"): el.get("attached_to") for el in etree.parse(str(sdf)).iter("frame")}
    assert frames == {"tool0": "l1", "tcp": "l1", "mount": "base"}


def test_frames_come_back_as_frames_through_urdf_and_mjcf(arm: Path, tmp_path: Path) -> None:
    for middle in ("arm.urdf", "arm.xml"):
        first = tmp_path / middle
        _convert(arm, first)
        again = tmp_path / f"again_{first.suffix[1:]}.sdf"
        _convert(first, again)
        frames = {el.get("name") for el in etree.parse(str(again)).iter("frame")}
        assert set(EXPECTED) <= frames, (middle, frames)
        links = {el.get("name") for el in etree.parse(str(again)).iter("link")}
        assert not links & set(EXPECTED), (middle, links)


def test_a_frame_whose_joint_name_is_taken_gets_another(tmp_path: Path) -> None:
    """SDF names links, joints and frames apart (MK237 otherwise), but the frame's joint is made up: a
    source joint may already be called ``tool0_joint``."""
    source = tmp_path / "taken.sdf"
    source.write_text(ARM.replace('name="j1"', 'name="tool0_joint"'))
    out = tmp_path / "taken.urdf"
    _convert(source, out)
    joints = {el.get("name"): el.find("child").get("link") for el in etree.parse(str(out)).iter("joint")}
    assert joints["tool0_joint"] == "l1" and joints["tool0_joint_2"] == "tool0"


def test_frame_bodies_writes_the_frames_as_bodies_in_mjcf(arm: Path, tmp_path: Path) -> None:
    """``--frame-bodies`` is about how MJCF writes frame links (bodies instead of sites); URDF and .body
    hold the frames as links either way."""
    import mujoco

    out = tmp_path / "arm.xml"
    _convert(arm, out, "--frame-bodies")
    model = mujoco.MjModel.from_xml_path(str(out))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    assert model.nsite == 0
    for name, where in EXPECTED.items():
        body = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, name)
        assert body >= 0 and model.body_mass[body] == 0.0, name
        assert np.allclose(data.xpos[body], where, atol=1e-12), name
    for suffix in ("urdf", "body"):
        frames = tmp_path / f"fb.{suffix}"
        _convert(arm, frames, "--frame-bodies")
        assert "tool0_joint" in frames.read_text()


def test_verify_grades_where_each_engine_puts_a_frame(arm: Path, tmp_path: Path) -> None:
    """verify's reference holds the frames as links (MK874), so layer 2 compares each frame's pose in
    every engine; a URDF whose frame is 1 mm off fails there, naming the frame."""
    from modelkit.verify.api import verify

    report = verify(arm, tmp_path / "ok", engines=("mujoco", "pybullet", "drake"), configurations=5,
                    samples=3, replay=False, driven=False)
    assert not report.errors and all(c.passed for c in report.checks), [c for c in report.checks
                                                                         if not c.passed]
    assert {c.detail for c in report.checks if c.quantity == "link-set"} == {"5 links"}
    moved = tmp_path / "moved.urdf"
    _convert(arm, moved)
    text = moved.read_text()
    assert '<origin xyz="0 0 0.3" rpy="0 1.5707963267949 0"/>' in text
    moved.write_text(text.replace('<origin xyz="0 0 0.3" rpy="0 1.5707963267949 0"/>',
                                  '<origin xyz="0 0 0.301" rpy="0 1.5707963267949 0"/>'))
    report = verify(arm, tmp_path / "bad", engines=("pybullet",), urdf=moved, configurations=5,
                    samples=3, replay=False, driven=False)
    failed = [c for c in report.checks if not c.passed]
    assert failed and {c.quantity for c in failed} == {"pose-position"}, failed
    assert {c.where for c in failed} <= {"tool0", "tcp"} and abs(failed[0].error - 1e-3) < 1e-9
