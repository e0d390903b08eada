"""MK885 (a wheel that is not round) and MK886 (a chassis on the wheels' ground): faults of a source no
loader refuses, which stop the converted robot rolling in every simulator.

Hello Robot's Stretch collides its drive wheels as boxes around round visuals, and its chassis mesh
reaches z = 0 beside them; converted to MJCF and driven on a default floor, its base rose 21.2 mm as
the boxes turned. The rover here is built to have each fault alone; the check of MK885's premise is
the user's step: the written MJCF, rolled on a plane, lifts its axle by what the note says.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from modelkit.api import load
from modelkit.convert.api import write
from tests.conftest import TUTORIAL, example_robot

mujoco = pytest.importorskip("mujoco")

ROVER = """<robot name="rover">
  <link name="chassis">
    <inertial><mass value="10"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="0 0 {chassis_z}"/><geometry><box size="0.4 0.3 0.1"/></geometry></collision>
    <collision><origin xyz="-0.15 0 0.03"/><geometry><sphere radius="0.03"/></geometry></collision>
  </link>
{wheels}
</robot>
"""
WHEEL = """  <joint name="{side}_joint" type="continuous">
    <parent link="chassis"/><child link="{side}_wheel"/>
    <origin xyz="0.1 {y} 0.05" rpy="-1.5707963267948966 0 0"/>
    <axis xyz="0 0 1"/>
  </joint>
  <link name="{side}_wheel">
    <inertial><mass value="0.5"/>
      <inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial>
    <visual><geometry><cylinder radius="0.05" length="0.04"/></geometry></visual>
    <collision><geometry>{shape}</geometry></collision>
  </link>
"""
ROUND = '<cylinder radius="0.05" length="0.04"/>'
SQUARE = '<box size="0.1 0.1 0.04"/>'


def rover(tmp_path: Path, shape: str, chassis_z: float) -> Path:
    wheels = "".join(WHEEL.format(side=side, y=y, shape=shape)
                     for side, y in (("left", 0.17), ("right", -0.17)))
    path = tmp_path / f"rover_{'box' if shape == SQUARE else 'round'}_{chassis_z:g}.urdf"
    path.write_text(ROVER.format(chassis_z=chassis_z, wheels=wheels))
    return path


def said(source: Path, out: Path) -> dict[str, list[str]]:
    notes = write(load(source), out, force=True)
    return {code: [n.message for n in notes if n.code == code] for code in ("MK885", "MK886")}


def test_square_wheels_are_said(tmp_path: Path) -> None:
    found = said(rover(tmp_path, SQUARE, 0.1), tmp_path / "sq" / "r.urdf")
    assert len(found["MK885"]) == 2 and not found["MK886"]
    assert "runs from 50.0 to 70.7 mm as it turns, so rolling lifts the robot 20.7 mm" in found["MK885"][0]
    assert "its visual round: radius 50.0 mm) does not collide as a round shape" in found["MK885"][0]


def test_round_wheels_and_a_raised_chassis_are_not_said(tmp_path: Path) -> None:
    assert said(rover(tmp_path, ROUND, 0.1), tmp_path / "ok" / "r.urdf") == {"MK885": [], "MK886": []}


def test_a_chassis_on_the_ground_is_said_and_a_ball_caster_is_not(tmp_path: Path) -> None:
    found = said(rover(tmp_path, ROUND, 0.05), tmp_path / "low" / "r.urdf")  # box bottom at z = 0
    assert not found["MK885"]
    (message,) = found["MK886"]
    assert "the chassis chassis reaches the ground its wheels (left_wheel, right_wheel)" in message


def axle_heights(path: Path) -> tuple[float, float]:
    """The lowest and highest height of the left wheel's axle while the written MJCF, on a default
    plane, rolls half a turn in 2 s: its wheels' motors replaced by stiff position servos (a user's
    controller), so that the wheels turn slowly whatever their shape."""
    import math

    spec = mujoco.MjSpec.from_file(str(path))
    spec.worldbody.add_geom(type=mujoco.mjtGeom.mjGEOM_PLANE, size=[0.0, 0.0, 1.0])
    for actuator in list(spec.actuators):
        spec.delete(actuator)
    for joint in ("left_joint", "right_joint"):
        servo = spec.add_actuator()
        servo.target, servo.trntype = joint, mujoco.mjtTrn.mjTRN_JOINT
        servo.set_to_position(kp=200.0, kv=5.0)
    m = spec.compile()
    d = mujoco.MjData(m)
    wheel = m.body("left_wheel").id
    heights: list[float] = []
    while d.time < 3.0:
        d.ctrl[:] = -min(d.time / 2.0, 1.0) * math.pi
        mujoco.mj_step(m, d)
        if d.time > 0.1:
            heights.append(float(d.xpos[wheel][2]))
    assert abs(float(d.qpos[0])) > 0.1  # it rolled
    return min(heights), max(heights)


def test_the_square_wheel_lifts_the_written_robot(tmp_path: Path) -> None:
    """The user's step: the MJCF ``convert`` writes with its default options (the square wheels are no
    wheels to it and keep their boxes; the round ones become spheres, MK826), rolled on a plane: the
    square wheels lift the axle by what MK885 says (20.7 mm; measured 20.9), the round ones by
    nothing."""
    from click.testing import CliRunner

    from modelkit.cli import main

    lifts = {}
    for shape in (SQUARE, ROUND):
        out = tmp_path / ("box" if shape == SQUARE else "round") / "r.xml"
        result = CliRunner().invoke(main, ["convert", str(rover(tmp_path, shape, 0.1)), "-o", str(out)])
        assert result.exit_code == 0, result.output
        low, high = axle_heights(out)
        lifts[shape] = high - low
    assert abs(lifts[SQUARE] - 0.0207) < 0.002 and lifts[ROUND] < 0.001, lifts


@pytest.mark.parametrize("source", ["mobile_robot_pantilt.body", "mobile_robot_tracks.body"])
def test_the_tutorial_rovers_are_not_said(tmp_path: Path, source: str) -> None:
    assert said(TUTORIAL / source, tmp_path / "r.urdf") == {"MK885": [], "MK886": []}


def test_tiago_is_not_said(tmp_path: Path) -> None:
    found = said(example_robot("tiago_description/robots/tiago.urdf"), tmp_path / "t.urdf")
    assert found == {"MK885": [], "MK886": []}
