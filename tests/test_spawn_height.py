"""MK884: the height at which a free robot written to URDF, SDF or ``.body`` stands on the ground.

MJCF's ``home`` key stands a free robot on z = 0 itself (MK882). A URDF has no root pose: Gazebo and
PyBullet spawn the root frame at the height the user passes, and example-robot-data's ANYmal spawned at
0 starts with its feet 579 mm in the ground. The note gives the height; the check here is the user's
step in PyBullet: ``loadURDF`` at that height next to ``plane.urdf``, and PyBullet's own closest points.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from modelkit.api import load
from modelkit.convert.api import write
from tests.conftest import TUTORIAL, example_robot

ANYMAL = "anymal_b_simple_description/robots/anymal.urdf"


def notes_of(source: Path, out: Path, code: str) -> list[str]:
    return [n.message for n in write(load(source), out, force=True) if n.code == code]


def spawn_height(message: str) -> float:
    found = re.search(r"with its root frame at z = ([0-9.e-]+) m", message)
    assert found, message
    return float(found.group(1))


def ground_distance(urdf: Path, height: float) -> float:
    """PyBullet's smallest signed distance between the robot spawned with its base at ``height`` and
    pybullet_data's plane (negative: inside it)."""
    pybullet = pytest.importorskip("pybullet")
    pybullet_data = pytest.importorskip("pybullet_data")
    client = pybullet.connect(pybullet.DIRECT)
    try:
        plane_file = Path(pybullet_data.getDataPath()) / "plane.urdf"
        plane = pybullet.loadURDF(str(plane_file), physicsClientId=client)
        robot = pybullet.loadURDF(str(urdf), basePosition=[0.0, 0.0, height], physicsClientId=client)
        pybullet.performCollisionDetection(physicsClientId=client)
        points = pybullet.getClosestPoints(robot, plane, 1.0, physicsClientId=client)
        return min(float(p[8]) for p in points)
    finally:
        pybullet.disconnect(client)


def test_urdf_spawn_height_stands_the_robot_on_the_ground(tmp_path: Path) -> None:
    out = tmp_path / "anymal.urdf"
    (said,) = notes_of(example_robot(ANYMAL), out, "MK884")
    height = spawn_height(said)
    assert "LF_FOOT" in said and "579 mm inside the ground when spawned at z = 0" in said
    assert "`loadURDF(..., basePosition=[0, 0, 0.579])` (PyBullet)" in said and "`create -z 0.579`" in said
    assert ground_distance(out, 0.0) < -0.5  # the user's spawn without the note: feet in the ground
    assert -1e-6 <= ground_distance(out, height) <= 2e-6


@pytest.mark.parametrize("suffix", ["sdf", "body"])
def test_files_that_place_the_root_are_told_the_same_height(tmp_path: Path, suffix: str) -> None:
    (said,) = notes_of(example_robot(ANYMAL), tmp_path / f"anymal.{suffix}", "MK884")
    assert spawn_height(said) == pytest.approx(0.579, abs=1e-3)
    assert "where the file puts its root (z = 0 m)" in said


@pytest.mark.parametrize("suffix", ["urdf", "sdf", "body", "xml"])
def test_a_robot_on_the_ground_and_mjcf_are_not_told(tmp_path: Path, suffix: str) -> None:
    # the tutorial's rover rests on z = 0 at its root pose; MJCF has its home key instead (MK882)
    assert not notes_of(TUTORIAL / "mobile_robot_pantilt.body", tmp_path / f"r.{suffix}", "MK884")
    assert suffix != "xml" or not notes_of(example_robot(ANYMAL), tmp_path / "a.xml", "MK884")


def test_a_welded_robot_is_not_told(tmp_path: Path) -> None:
    assert not notes_of(example_robot("ur_description/urdf/ur5_robot.urdf"), tmp_path / "ur5.urdf", "MK884")
