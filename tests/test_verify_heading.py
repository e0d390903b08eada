"""Layer 4 on a robot whose axle is its root's X (issue 16: turning graded for every driven robot), and
the drive law that is too stiff for a light robot.

REP-103 puts a mobile robot's X forward and its axle on Y, and layer 4 looked only there. A robot whose
root frame is turned (safety-gymnasium's car drives along its Y) was "not a differential drive".
Layer 4 now works in the drive frame, which is the root frame turned by ``Drive.heading``. The test
robot is the tutorial's primitive robot written as URDF under a massless root turned by 90°: the same
robot, so it must be graded as the plain one is.

The seed's drive law ``u = kd (dq* − dq)`` is applied once per control period. On a 20 g car the
wheel speeds overshoot at every period and the no-slip reference raised a ``math domain error`` (a
traceback). Layer 4 is now skipped with the kd that would work.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from modelkit.api import load
from modelkit.cli import main
from modelkit.verify.drive import scenario as scenarios
from modelkit.verify.drive.reference import law_too_stiff, planar_model
from modelkit.verify.drive.variant import planar
from modelkit.verify.drive.vehicle import find_drive

MODELS = Path(__file__).resolve().parents[1] / "samples" / "choreonoid_ros2_mobile_robot_tutorial" / "model"
TURN = """  <link name="base"/>
  <joint name="base_to_chassis" type="fixed">
    <parent link="base"/>
    <child link="Chassis"/>
    <origin xyz="0 0 0" rpy="0 0 1.5707963267948966"/>
  </joint>
"""


@pytest.fixture(scope="module")
def robots(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    folder = tmp_path_factory.mktemp("turned")
    plain = folder / "plain.urdf"
    source = MODELS / "mobile_robot_primitive.body"
    result = CliRunner().invoke(main, ["convert", str(source), "-o", str(plain)])
    assert result.exit_code == 0, result.output
    text = plain.read_text()
    assert text.count('<link name="Chassis">') == 1
    turned = folder / "turned.urdf"
    turned.write_text(text.replace('  <link name="Chassis">', TURN + '  <link name="Chassis">'))
    return {"plain": plain, "turned": turned}


def test_the_drive_is_found_in_the_turned_frame(robots: dict[str, Path]) -> None:
    default = scenarios.default_scenario()
    plain, turned = load(robots["plain"]), load(robots["turned"])
    a, b = find_drive(plain, default), find_drive(turned, default)
    assert a.heading == 0.0 and b.heading == pytest.approx(math.pi / 2)
    assert (b.left, b.right, b.signs) == (a.left, a.right, a.signs)
    assert b.radius == pytest.approx(a.radius) and b.half_axle == pytest.approx(a.half_axle)
    # the no-slip model is the same robot in the drive frame
    ma, mb = planar_model(plain, a), planar_model(turned, b)
    assert np.allclose(ma.com, mb.com, atol=1e-12) and np.allclose(ma.root_offset, mb.root_offset, atol=1e-12)
    assert mb.yaw_inertia == pytest.approx(ma.yaw_inertia, rel=1e-12)
    assert mb.spin == pytest.approx(ma.spin, rel=1e-12)


def test_an_engine_path_is_read_in_the_drive_frame() -> None:
    """A root frame turned by 90° moving along its own +Y is moving forward."""
    profile = scenarios.default_scenario().profiles[0]
    t = np.linspace(0.0, 1.0, 11)
    positions = np.column_stack([np.zeros_like(t), 0.3 * t, np.zeros_like(t)])  # world +Y
    rotations = np.repeat(np.eye(3)[None], len(t), axis=0)  # root frame = world: its +Y is forward
    joints = {"L": np.zeros_like(t), "R": np.zeros_like(t)}
    out = planar("x", profile, "", t, positions, rotations, joints, ("L", "R"), heading=math.pi / 2)
    assert out.x[-1] == pytest.approx(0.3) and abs(out.y[-1]) < 1e-15 and out.yaw[-1] == 0.0
    sideways = planar("x", profile, "", t, positions, rotations, joints, ("L", "R"))
    assert sideways.y[-1] == pytest.approx(0.3)  # heading 0: the same motion is to the left


def test_the_turned_robot_is_graded_as_the_plain_one(robots: dict[str, Path], tmp_path: Path) -> None:
    result = CliRunner().invoke(main, ["verify", str(robots["turned"]), "-o", str(tmp_path / "v"),
                                       "--engines", "mujoco,pybullet"])
    assert result.exit_code == 0, result.output
    report = json.loads((tmp_path / "v" / "report.json").read_text())
    assert report["drive"]["heading"] == pytest.approx(math.pi / 2)
    graded = {(c["engine"], c["quantity"], c["where"]) for c in report["checks"] if c["layer"] == 4}
    for profile in ("straight", "spin", "arc"):
        for engine in ("mujoco", "pybullet"):
            for quantity in ("noslip-position", "noslip-yaw"):
                assert (engine, quantity, profile) in graded
    assert "layer 4 graded arc, spin, straight" in result.output


LIGHT_CAR = """<mujoco model="light">
  <compiler angle="radian"/>
  <worldbody>
    <geom name="floor" type="plane" size="5 5 0.1"/>
    <body name="chassis" pos="0 0 0.1">
      <freejoint/>
      <geom type="box" size="0.1 0.1 0.05" density="5"/>
      <body name="left" pos="-0.1 0.1 -0.05">
        <joint name="left" axis="1 0 0"/>
        <geom type="cylinder" fromto="-0.055 0 0 -0.005 0 0" size="0.05" density="5"/>
      </body>
      <body name="right" pos="0.1 0.1 -0.05">
        <joint name="right" axis="1 0 0"/>
        <geom type="cylinder" fromto="0.005 0 0 0.055 0 0" size="0.05" density="5"/>
      </body>
      <body name="rear" pos="0 -0.1 -0.05">
        <joint name="rear" type="ball"/>
        <geom type="sphere" size="0.05" density="5"/>
      </body>
    </body>
  </worldbody>
</mujoco>
"""


def test_a_law_too_stiff_for_a_light_robot_is_a_skip(tmp_path: Path) -> None:
    """safety-gymnasium's car, in short: a chassis of density 5 kg/m³ on 5 cm wheels about its X."""
    source = tmp_path / "light.xml"
    source.write_text(LIGHT_CAR)
    robot = load(source)
    default = scenarios.default_scenario()
    drive = find_drive(robot, default)
    assert drive.heading == pytest.approx(math.pi / 2) and (drive.left, drive.right) == ("left", "right")
    why = law_too_stiff(planar_model(robot, drive), drive, default)
    assert why is not None and "give a scenario kd below" in why
    kd = float(why.rsplit(" ", 1)[1])
    assert 0.0 < kd < default.kd
    result = CliRunner().invoke(main, ["verify", str(source), "-o", str(tmp_path / "v"),
                                       "--engines", "mujoco", "--no-replay"])
    assert result.exit_code == 0, result.output
    assert "Traceback" not in result.output and "too stiff for this robot" in result.output


def test_the_tutorial_robot_is_far_from_too_stiff() -> None:
    robot = load(MODELS / "mobile_robot_pantilt.body")
    default = scenarios.default_scenario()
    drive = find_drive(robot, default)
    assert law_too_stiff(planar_model(robot, drive), drive, default) is None
