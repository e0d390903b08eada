"""Layer 4 on a robot that stands on swivel casters (issue 16: "TIAGo dual layer 4").

TIAGo's four caster wheels are round, turn without end about Y at q = 0 and touch the floor, like its
two drive wheels: layer 4 found six wheels and was not run. Caster wheels hang from a joint that turns
without end about the vertical (the swivel); drive wheels hang from the root's body or a suspension's
slide (TIAGo's ±5 mm). The casters are left out of the drive, and the no-slip reference, which has no
casters, stands for the robot only where the casters' contact has no sliding friction: TIAGo dual's
source gives them 0.1, and their drag while they swivel put MuJoCo's heading 55 mrad from the
reference after the 5 rad spin (0.45 mrad with the friction set to 0).
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

import modelkit
from modelkit.model import Robot
from modelkit.verify.drive.scenario import default_scenario
from modelkit.verify.drive.vehicle import caster_drag, find_drive
from tests.conftest import example_robot

CASTERS = {f"caster_{end}_{side}_2_joint" for end in ("front", "back") for side in ("left", "right")}


def prepared(path: Path) -> Robot:
    """The robot as layer 4 finds its drive in: after convert's wheel approximation (each round
    collision a sphere on its wheel's axis, MK826)."""
    from modelkit.convert.api import prepare
    from modelkit.convert.notes import NoteSink
    from modelkit.convert.options import WriteOptions
    from modelkit.convert.registry import target_info

    robot = modelkit.load(path)
    assert isinstance(robot, Robot)
    return prepare(robot, target_info("mjcf"), WriteOptions(), NoteSink())


def frictionless_copy(tmp_path: Path) -> Path:
    """TIAGo dual with its casters' Gazebo friction set to 0, beside the original (its package:// meshes
    resolve the same way)."""
    source = example_robot("tiago_description/robots/tiago_dual.urdf")
    text = re.sub(r'(<gazebo reference="caster_[a-z_]+_2_link">.*?<mu1>)0\.1(</mu1>\s*<mu2>)0\.1',
                  r"\g<1>0.0\g<2>0.0", source.read_text(), flags=re.S)
    assert text.count("<mu1>0.0</mu1>") == 4
    copy = tmp_path / "tiago_dual_frictionless_casters.urdf"
    copy.write_text(text.replace("package://example-robot-data/robots/", f"{source.parents[2]}/"))
    return copy


def test_the_drive_wheels_are_found_beside_four_casters() -> None:
    robot = prepared(example_robot("tiago_description/robots/tiago_dual.urdf"))
    drive = find_drive(robot, default_scenario())
    assert (drive.left, drive.right) == ("wheel_left_joint", "wheel_right_joint")
    assert set(drive.casters) == CASTERS
    why = caster_drag(robot, drive)
    assert why is not None and "4 swivel caster(s)" in why and "caster_front_left_2_joint (0.1)" in why


def test_frictionless_casters_are_driven(tmp_path: Path) -> None:
    robot = prepared(frictionless_copy(tmp_path))
    drive = find_drive(robot, default_scenario())
    assert set(drive.casters) == CASTERS and caster_drag(robot, drive) is None


def test_a_wheel_on_a_steering_joint_is_still_refused() -> None:
    """A suspension's slide is allowed above a drive wheel; a turning joint is not (a steered wheel)."""
    robot = prepared(example_robot("tiago_description/robots/tiago_dual.urdf"))
    joints = {j.name: j for j in robot.joints}
    for side in ("left", "right"):  # TIAGo's suspension slides become steering joints about Z
        suspension = joints[f"suspension_{side}_joint"]
        suspension.type = type(suspension.type).REVOLUTE
    with pytest.raises(ValueError, match="hang from a turning joint"):
        find_drive(robot, default_scenario())
