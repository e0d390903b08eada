"""A free robot's ``home`` keyframe stands it on z = 0 (issue 17: "a legged robot is free", MK882).

A URDF's root is at the origin, so a quadruped's feet and a rover's wheels reach below z = 0. Before,
the key kept that pose: on a user's floor ``mj_resetDataKeyframe`` started the robot inside it (58 cm
deep for example-robot-data's ANYmal-Kinova), and MuJoCo threw it 3.1 m up in 0.5 s. The user's step
here is the whole check: the written file, a default plane added (nothing else), reset to ``home``. The
distance from each collision geom to the plane is MuJoCo's own (``mj_geomDistance``), not the writer's
arithmetic.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from modelkit.api import load
from modelkit.convert.api import write
from modelkit.convert.options import WriteOptions
from modelkit.model import JointType
from tests.conftest import TUTORIAL, example_robot

mujoco = pytest.importorskip("mujoco")
np = pytest.importorskip("numpy")

STEP = 1e-6  # m: the writer rounds the key's height up to this


def robot_file(relative: str) -> Path:
    """An example-robot-data file, or ``pybullet_data:NAME`` from pybullet's data package."""
    if relative.startswith("pybullet_data:"):
        pybullet_data = pytest.importorskip("pybullet_data")
        return Path(pybullet_data.getDataPath()) / relative.split(":", 1)[1]
    return example_robot(relative)


def floor_gap(path: Path) -> tuple[float, float]:
    """(the smallest distance from the robot's collision geoms to a default plane at the home key, how
    far the base rose in the first 0.5 s after that reset)."""
    spec = mujoco.MjSpec.from_file(str(path))
    spec.worldbody.add_geom(name="floor", type=mujoco.mjtGeom.mjGEOM_PLANE, size=[0.0, 0.0, 1.0])
    m = spec.compile()
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, m.key("home").id)
    mujoco.mj_forward(m, d)
    floor = m.geom("floor").id
    colliding = [g for g in range(m.ngeom) if g != floor and (m.geom_contype[g] or m.geom_conaffinity[g])]
    gap = min(mujoco.mj_geomDistance(m, d, g, floor, 1.0, None) for g in colliding)
    start, highest = float(d.qpos[2]), float(d.qpos[2])
    for _ in range(round(0.5 / m.opt.timestep)):
        mujoco.mj_step(m, d)
        highest = max(highest, float(d.qpos[2]))
    return gap, highest - start


@pytest.mark.parametrize(
    "relative",
    [
        "anymal_b_simple_description/robots/anymal-kinova.urdf",  # 579 mm deep, thrown 3.1 m up before
        "go1_description/urdf/go1.urdf",  # a crouched home pose from its SRDF
        "solo_description/robots/solo12.urdf",
        "pybullet_data:r2d2.urdf",  # wheels 47 cm below its root
    ],
)
def test_the_home_key_stands_a_free_robot_on_the_floor(tmp_path: Path, relative: str) -> None:
    out = tmp_path / "robot.xml"
    notes = write(load(robot_file(relative)), out, force=True)
    gap, rise = floor_gap(out)
    assert -1e-12 <= gap <= STEP + 1e-9, f"{relative}: {gap * 1e3:.4f} mm from the floor at home"
    assert rise < 1e-3, f"{relative}: the floor pushed the base {rise * 1e3:.1f} mm up"
    (said,) = [n for n in notes if n.code == "MK882"]
    assert "mm below it" in said.message
    root = ET.parse(out).getroot().find("worldbody/body")
    assert root is not None and root.find("freejoint") is not None
    assert root.get("pos") is None, "the body keeps the source's root pose (a URDF's: the origin)"


def test_a_free_robot_without_a_key_gets_one_to_rest_on(tmp_path: Path) -> None:
    """Motors give a key no ``ctrl``, and a robot at q = 0 has no initial positions: the key is written
    for the base's height alone, its joints at 0."""
    robot = load(example_robot("solo_description/robots/solo12.urdf"))
    out = tmp_path / "solo.xml"
    write(robot, out, options=WriteOptions(actuators="motor", source_actuators="replace"), force=True)
    (key,) = ET.parse(out).getroot().iter("key")
    assert key.get("ctrl") is None
    values = [float(v) for v in (key.get("qpos") or "").split()]
    assert values[2] > 0.3 and values[3:7] == [1.0, 0.0, 0.0, 0.0] and not any(values[7:])
    gap, _ = floor_gap(out)
    assert -1e-12 <= gap <= STEP + 1e-9


@pytest.mark.parametrize("name", ["mobile_robot_pantilt.body", "mobile_robot_tracks.body"])
def test_a_robot_already_on_the_floor_keeps_its_file(tmp_path: Path, name: str) -> None:
    """The tutorial's robots rest on z = 0 in their source: no key, no note."""
    out = tmp_path / "robot.xml"
    notes = write(load(TUTORIAL / name), out, force=True)
    assert ET.parse(out).getroot().find("keyframe") is None
    assert "MK882" not in {n.code for n in notes}


def test_a_key_already_on_the_floor_is_not_moved(tmp_path: Path) -> None:
    """example-robot-data's TIAGo stands on its wheels and casters at its root's z = 0: its key (for its
    servos) keeps the base at 0, without a note."""
    out = tmp_path / "tiago.xml"
    notes = write(load(example_robot("tiago_description/robots/tiago.urdf")), out, force=True)
    (key,) = ET.parse(out).getroot().iter("key")
    assert (key.get("qpos") or "").startswith("0 0 0 1 0 0 0 ")
    assert "MK882" not in {n.code for n in notes}
    gap, _ = floor_gap(out)
    assert -1e-12 <= gap <= STEP


def test_reading_the_file_back_gives_the_source_root_pose(tmp_path: Path) -> None:
    """The key's height is the user's start, not the model: the MJCF read back has its root floating at
    the source's pose (the origin), and its joints at the key's positions."""
    source = load(example_robot("go1_description/urdf/go1.urdf"))
    out = tmp_path / "go1.xml"
    write(source, out, force=True)
    back = load(out)
    assert back.root_joint is JointType.FLOATING and back.root_pose.is_identity()
    homes = {j.name: j.initial_position for j in back.joints if j.initial_position}
    assert homes and all(value == pytest.approx(-0.888) for value in homes.values())


def test_a_welded_arm_key_is_not_moved(tmp_path: Path) -> None:
    """Only a free root rests on the floor: a welded arm's key keeps its joints and has no base."""
    robot = load(example_robot("ur_description/urdf/ur5_robot.urdf"))
    robot.root_joint = JointType.FIXED
    out = tmp_path / "ur5.xml"
    notes = write(robot, out, force=True)
    assert ET.parse(out).getroot().find("worldbody/body/freejoint") is None
    assert "MK882" not in {n.code for n in notes}
