"""MK865: a welded arm whose home pose reaches below its base is said at conversion, with the depth.

On a table or floor the base stands on, such a pose starts inside it and MuJoCo pushes the arm out at
the first step. The test arms are a base box (its bottom at z = 0) and one link on a hinge whose
capsule hangs down or stands up at q = 0. The Kinova arm of example-robot-data, which has the fault
in its zero pose and not in its SRDF's ``arm_up``, is in ``tests/test_srdf_home.py``.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from modelkit.api import load
from modelkit.convert.api import write
from modelkit.convert.options import WriteOptions
from tests.conftest import example_robot

INERTIAL = ('<inertial><mass value="1"/>'
            '<inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>')
LIGHT = ('<inertial><mass value="0.01"/>'
         '<inertia ixx="1e-5" iyy="1e-5" izz="1e-5" ixy="0" ixz="0" iyz="0"/></inertial>')

ARM = f"""<robot name="arm">
  <link name="base">{INERTIAL}
    <collision><origin xyz="0 0 0.05"/><geometry><box size="0.2 0.2 0.1"/></geometry></collision></link>
  <link name="upper">{INERTIAL}
    <collision><origin xyz="0.2 0 OFFSET"/><geometry><cylinder radius="0.03" length="0.3"/></geometry>
    </collision></link>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/>
    <origin xyz="0 0 0.1"/><axis xyz="0 1 0"/>
    <limit lower="-2" upper="2" effort="100" velocity="1"/></joint>
  <link name="fore">{LIGHT}</link>
  <joint name="elbow" type="revolute"><parent link="upper"/><child link="fore"/>
    <origin xyz="0.4 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-2" upper="2" effort="100" velocity="1"/></joint>
  <link name="hand">{LIGHT}</link>
  <joint name="wrist" type="revolute"><parent link="fore"/><child link="hand"/>
    <origin xyz="0.1 0 0"/><axis xyz="1 0 0"/>
    <limit lower="-2" upper="2" effort="100" velocity="1"/></joint>
FINGERS</robot>
"""
FINGER = """  <link name="finger{i}">{LIGHT}</link>
  <joint name="finger{i}" type="revolute"><parent link="PARENT"/><child link="finger{i}"/>
    <origin xyz="0.05 0 0"/><axis xyz="0 1 0"/><limit lower="0" upper="1" effort="1" velocity="1"/></joint>
"""


def _notes(tmp_path: Path, offset: float, base: str = "auto", fingers: str = "") -> list:
    path = tmp_path / "arm.urdf"
    path.write_text(ARM.replace("OFFSET", str(offset)).replace("FINGERS", fingers))
    return write(load(path), tmp_path / "out" / "arm.xml", options=WriteOptions(base=base), force=True)


def test_a_link_hanging_below_the_base_is_said_with_its_depth(tmp_path: Path) -> None:
    # the upper link's cylinder (axis along z, half length 0.15) centred 0.2 below the shoulder, which is
    # 0.1 above the base's bottom: its lowest point is 0.1 - 0.2 - 0.15 = -0.25 m, 250 mm below the base
    (said,) = [n for n in _notes(tmp_path, -0.2) if n.code == "MK865"]
    assert said.severity == "warning"
    assert "1 moving bod(ies)" in said.message and "upper 250 mm" in said.message
    assert "--srdf" in said.message


def test_a_link_above_the_base_or_just_touching_its_plane_is_not_said(tmp_path: Path) -> None:
    assert not [n for n in _notes(tmp_path, 0.3) if n.code == "MK865"]
    # centred 0.0495 above the shoulder: its lowest point 0.1 + 0.0495 - 0.15 is 0.5 mm below the base's
    # bottom, within the 1 mm a mesh's or a rounding's slack may take
    assert not [n for n in _notes(tmp_path, 0.0495) if n.code == "MK865"]


def test_a_robot_hanging_from_its_base_is_not_judged(tmp_path: Path) -> None:
    """The moving link's mass at the cylinder's centre, 0.1 m below the base's bottom: the robot hangs
    from its base (a finger under its frame, an arm on a shoulder), so no floor is under it."""
    path = tmp_path / "arm.urdf"
    hanging = ARM.replace("OFFSET", "-0.2").replace("FINGERS", "").replace(
        f'<link name="upper">{INERTIAL}',
        '<link name="upper">' + INERTIAL.replace("<inertial>", '<inertial><origin xyz="0.2 0 -0.2"/>'))
    path.write_text(hanging)
    notes = write(load(path), tmp_path / "out" / "arm.xml", force=True)
    assert not [n for n in notes if n.code == "MK865"]


def test_a_floating_robot_is_not_judged(tmp_path: Path) -> None:
    assert not [n for n in _notes(tmp_path, -0.2, base="floating") if n.code == "MK865"]


def _fingers(parent: str, count: int) -> str:
    return "".join(FINGER.format(i=i, LIGHT=LIGHT).replace("PARENT", parent) for i in range(count))


def test_a_gripper_at_the_arms_end_is_still_a_standing_arm(tmp_path: Path) -> None:
    """Two fingers on the hand: the chain of three joints from the base is longer than any branch."""
    (said,) = [n for n in _notes(tmp_path, -0.2, fingers=_fingers("hand", 2)) if n.code == "MK865"]
    assert "upper 250 mm" in said.message


def test_branches_as_long_as_the_chain_before_them_are_not_a_standing_arm(tmp_path: Path) -> None:
    """A waist of three joints under two arms of three (Alex's upper body), a short chain under long
    fingers (a hand): a torso or a wrist holds such a robot, not a table; nothing is said. Nor for a
    chain of fewer than three joints (a one-motor test rig, pybullet_data's Minitaur motor)."""
    arms = _fingers("hand", 2)
    second = "".join(
        FINGER.format(i=f"{i}b", LIGHT=LIGHT).replace("PARENT", f"finger{i}")
        + FINGER.format(i=f"{i}c", LIGHT=LIGHT).replace("PARENT", f"finger{i}b") for i in range(2))
    assert not [n for n in _notes(tmp_path, -0.2, fingers=arms + second) if n.code == "MK865"]
    rig = ARM.replace("OFFSET", "-0.2").replace("FINGERS", "")
    rig = rig[:rig.index('  <link name="fore">')] + "</robot>\n"
    path = tmp_path / "rig.urdf"
    path.write_text(rig)
    notes = write(load(path), tmp_path / "rig" / "rig.xml", force=True)
    assert not [n for n in notes if n.code == "MK865"]


@pytest.mark.parametrize(
    ("relative", "said"),
    [
        ("ur_description/urdf/ur5_robot.urdf", True),  # its wrist 41-45 mm through the table at q = 0
        ("allegro_hand_description/urdf/allegro_right_hand.urdf", False),  # a thumb tip, 3 mm past the mount
        ("alex_description/urdf/alex_nub_hands.urdf", False),  # arms beside the pelvis, under a waist
    ],
)
def test_real_robots(tmp_path: Path, relative: str, said: bool) -> None:
    """example-robot-data: a standing arm is said, a hand and an upper body are not (they were, before
    the rule judged standing arms only: 15 files of example-robot-data, pybullet_data and the corpus got
    MK865, 7 now, all of them standing arms)."""
    notes = write(load(example_robot(relative)), tmp_path / "out" / "robot.xml", force=True)
    assert bool([n for n in notes if n.code == "MK865"]) is said
