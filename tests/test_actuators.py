"""Actuators (issue 17 item 2): read from each format into ``Robot.actuators``, written to MJCF, and
held under MuJoCo.

The hold test is the acceptance check: an arm converted to MJCF with position actuators, reset to its
``home`` keyframe (which carries ``ctrl`` = the home positions), stays within 1 mm at every body
(the end effector included) for 2 s of MuJoCo; the actuator count equals the joints the source actuates.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any

import pytest

from modelkit.api import load, validate
from modelkit.convert.api import write
from modelkit.convert.options import WriteOptions
from modelkit.formats.common import ReadOptions
from modelkit.model import ActuatorKind, JointType, Robot
from tests.conftest import CORPUS, PENDULUM_BODY, example_robot, example_robot_data

mujoco = pytest.importorskip("mujoco")
np = pytest.importorskip("numpy")

HOLD_SECONDS = 2.0
HOLD_TOLERANCE = 1e-3  # m, at every body


def hold_error(path: Path) -> tuple[int, float]:
    """(actuator count, the largest distance in m any body moves from its home position in 2 s)."""
    m = mujoco.MjModel.from_xml_path(str(path))
    d = mujoco.MjData(m)
    key = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_KEY, "home")
    assert key >= 0, "no home keyframe"
    mujoco.mj_resetDataKeyframe(m, d, key)
    mujoco.mj_forward(m, d)
    start = d.xpos.copy()
    worst = 0.0
    for _ in range(round(HOLD_SECONDS / m.opt.timestep)):
        mujoco.mj_step(m, d)
        worst = max(worst, float(np.linalg.norm(d.xpos - start, axis=1).max()))
    return int(m.nu), worst


def convert(robot: Robot, folder: Path, actuators: str | None = None,
            source_actuators: str | None = None) -> tuple[Path, list]:
    """``robot`` written to MJCF in ``folder``, with ``--actuators`` and ``--source-actuators`` default
    unless given."""
    out = folder / f"{robot.name or 'model'}.xml"
    chosen = {"actuators": actuators, "source_actuators": source_actuators}
    options = WriteOptions(**{key: value for key, value in chosen.items() if value is not None})
    notes = write(robot, out, options=options, force=True)
    return out, notes


def actuator_elements(path: Path) -> list[ET.Element]:
    section = ET.parse(path).getroot().find("actuator")
    return [] if section is None else list(section)


def srdf_pose(srdf: Path, state: str) -> dict[str, float]:
    root = ET.parse(srdf).getroot()
    for group in root.iter("group_state"):
        if group.get("name") == state:
            return {j.get("name", ""): float(j.get("value", "0")) for j in group.iter("joint")}
    raise AssertionError(f"no group_state {state} in {srdf}")


def robots_dir() -> Path:
    found = example_robot_data()
    if found is None:
        pytest.skip("example-robot-data is not installed")
    return found


# -- reading -------------------------------------------------------------------------------------

MJCF = """<mujoco model="four">
  <worldbody><body name="b"><joint name="j1" axis="0 0 1" range="-1 1"/><geom size=".1" mass="1"/>
  <body name="c" pos="0 0 .3"><joint name="j2" axis="0 1 0"/><geom size=".1" mass="1"/>
  <body name="d" pos="0 0 .3"><joint name="j3" axis="0 1 0"/><geom size=".1" mass="1"/>
  <body name="e" pos="0 0 .3"><joint name="j4" axis="0 1 0"/><geom size=".1" mass="1"/>
  <body name="f" pos="0 0 .3"><joint name="j5" axis="0 1 0"/><geom size=".1" mass="1"/>
  </body></body></body></body></body></worldbody>
  <actuator>
    <position name="p" joint="j1" kp="100" kv="5" ctrlrange="-1 1" forcerange="-20 20"/>
    <velocity joint="j2" kv="3"/>
    <motor joint="j3" gear="2" ctrlrange="-1 1"/>
    <general joint="j4" gainprm="50" biastype="affine" biasprm="0 -50 -4"/>
    <intvelocity joint="j5" kp="10" actrange="-1 1"/>
  </actuator>
</mujoco>
"""


def test_mjcf_actuators_are_read_by_what_they_compute(tmp_path: Path) -> None:
    path = tmp_path / "four.xml"
    path.write_text(MJCF)
    robot = load(path)
    got = {a.joint: a for a in robot.actuators}
    assert set(got) == {"j1", "j2", "j3", "j4"}  # intvelocity has activation dynamics: not canonical
    p, v, motor, general = got["j1"], got["j2"], got["j3"], got["j4"]
    assert (p.kind, p.kp, p.kv, p.ctrl_range, p.force_range, p.name) == (
        ActuatorKind.POSITION, 100.0, 5.0, (-1.0, 1.0), (-20.0, 20.0), "p")
    assert (v.kind, v.kv) == (ActuatorKind.VELOCITY, 3.0)
    assert (motor.kind, motor.gear, motor.ctrl_range) == (ActuatorKind.EFFORT, 2.0, (-1.0, 1.0))
    assert (general.kind, general.kp, general.kv, general.source_kind) == (ActuatorKind.POSITION, 50.0, 4.0,
                                                                          "general")


def test_mjcf_actuators_survive_a_round_trip(tmp_path: Path) -> None:
    path = tmp_path / "four.xml"
    path.write_text(MJCF)
    out, notes = convert(load(path), tmp_path / "out")
    again = {a.joint: a for a in load(out).actuators}
    assert {j: (a.kind, a.kp, a.kv, a.gear) for j, a in again.items()} == {
        "j1": (ActuatorKind.POSITION, 100.0, 5.0, 1.0),
        "j2": (ActuatorKind.VELOCITY, None, 3.0, 1.0),
        "j3": (ActuatorKind.EFFORT, None, None, 2.0),
        "j4": (ActuatorKind.POSITION, 50.0, 4.0, 1.0),
    }
    assert again["j1"].force_range == (-20.0, 20.0)
    assert not [n for n in notes if n.code in ("MK840", "MK842")]  # every gain came from the source
    # the intvelocity (activation dynamics: not one of the model's) is written back as <general>, in
    # its place: the file compiles to the source's actuators, in the source's order
    a, b = mujoco.MjModel.from_xml_string(MJCF), mujoco.MjModel.from_xml_path(str(out))
    assert a.nu == b.nu == 5
    for field in ("trnid", "dyntype", "gaintype", "biastype", "dynprm", "gainprm", "biasprm", "gear",
                  "ctrlrange", "forcerange", "actrange", "actlimited", "ctrllimited", "forcelimited"):
        np.testing.assert_array_equal(getattr(b, f"actuator_{field}"), getattr(a, f"actuator_{field}"),
                                      err_msg=field)


URDF = """<robot name="two">
  <link name="base"/>
  <link name="a">INERTIAL</link>
  <link name="b">INERTIAL</link>
  <link name="c">INERTIAL</link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="a"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="10" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="a"/><child link="b"/><origin xyz="0 0 0.3"/>
    <axis xyz="0 1 0"/>
    <limit lower="-1" upper="1" effort="10" velocity="1"/></joint>
  <joint name="j3" type="revolute"><parent link="b"/><child link="c"/><origin xyz="0 0 0.3"/>
    <axis xyz="0 1 0"/>
    <limit lower="-1" upper="1" effort="10" velocity="1"/></joint>
  <transmission name="t1"><type>transmission_interface/SimpleTransmission</type>
    <joint name="j1">
      <hardwareInterface>hardware_interface/EffortJointInterface</hardwareInterface></joint>
    <actuator name="m1"><mechanicalReduction>50</mechanicalReduction></actuator></transmission>
  <transmission name="t2" type="pr2_mechanism_model/SimpleTransmission">
    <joint name="j2"/>
    <actuator name="m2"><hardwareInterface>VelocityJointInterface</hardwareInterface></actuator>
  </transmission>
  <ros2_control name="hw" type="system">
    <joint name="j3"><command_interface name="position"><param name="min">-0.5</param>
      <param name="max">0.5</param></command_interface><command_interface name="velocity"/>
      <state_interface name="position"/></joint>
  </ros2_control>
</robot>
"""


INERTIAL = ('<inertial><mass value="1"/>'
            '<inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>')
URDF = URDF.replace("INERTIAL", INERTIAL)


def test_urdf_transmissions_and_ros2_control_become_actuators(tmp_path: Path) -> None:
    path = tmp_path / "two.urdf"
    path.write_text(URDF)
    got = {a.joint: a for a in load(path).actuators}
    assert (got["j1"].kind, got["j1"].reduction, got["j1"].name) == (ActuatorKind.EFFORT, 50.0, "m1")
    assert got["j2"].kind is ActuatorKind.VELOCITY  # the old PR2 form: the interface in <actuator>
    assert (got["j3"].kind, got["j3"].ctrl_range) == (ActuatorKind.POSITION, (-0.5, 0.5))  # the first one
    out, notes = convert(load(path), tmp_path / "keep", source_actuators="keep")
    tags = {el.get("joint"): el.tag for el in actuator_elements(out)}
    assert tags == {"j1": "motor", "j2": "velocity", "j3": "position"}
    codes = sorted(n.code for n in notes if n.code.startswith("MK84"))
    assert codes == ["MK840", "MK840", "MK843"]  # j2's kv and j3's kp/kv made up; j1's reduction folded


def test_a_ros_effort_interface_on_a_ranged_joint_is_written_as_a_servo(tmp_path: Path) -> None:
    """By default (``--source-actuators auto``) j1's ``EffortJointInterface`` gets the ``--actuators``
    choice, a position servo on a joint with a range, bounded by the joint's effort limit, and MK864 says
    so; the velocity and position interfaces are written as they are."""
    path = tmp_path / "two.urdf"
    path.write_text(URDF)
    out, notes = convert(load(path), tmp_path / "auto")
    written = {el.get("joint"): el for el in actuator_elements(out)}
    assert {joint: el.tag for joint, el in written.items()} == {"j1": "position", "j2": "velocity",
                                                              "j3": "position"}
    assert written["j1"].get("forcerange") == "-10 10" and written["j1"].get("ctrlrange") == "-1 1"
    assert written["j3"].get("ctrlrange") == "-0.5 0.5"  # the source's own position interface, as it was
    (said,) = [n for n in notes if n.code == "MK864"]
    assert said.message.startswith("1 joint(s) (j1) whose source names ROS effort interfaces")
    assert "written as 1 <position> (--actuators auto)" in said.message
    # a ros2_control effort command interface is a ROS effort interface too: its min/max bound the servo
    path.write_text(URDF.replace('<command_interface name="position"><param name="min">-0.5</param>',
                                 '<command_interface name="effort"><param name="min">-7</param>')
                    .replace('<param name="max">0.5</param>', '<param name="max">7</param>'))
    out, notes = convert(load(path), tmp_path / "ros2_control")
    written = {el.get("joint"): el for el in actuator_elements(out)}
    assert written["j3"].tag == "position" and written["j3"].get("forcerange") == "-7 7"
    assert written["j3"].get("ctrlrange") == "-1 1"  # the joint's range: the servo's control is a position
    (said,) = [n for n in notes if n.code == "MK864"]
    assert said.message.startswith("2 joint(s) (j1, j3)")
    path.write_text(URDF)
    # --actuators motor is the source's kind: the source's motor is written, with its reduction
    out, notes = convert(load(path), tmp_path / "motor", actuators="motor")
    assert {el.get("joint"): el.tag for el in actuator_elements(out)}["j1"] == "motor"
    assert "MK864" not in {n.code for n in notes} and "MK843" in {n.code for n in notes}


def test_body_actuation_mode_becomes_an_actuator(tmp_path: Path) -> None:
    extra = "    actuation_mode: joint_displacement\n    rotor_inertia: 1.0e-4\n    gear_ratio: 100\n"
    text = PENDULUM_BODY.replace("    joint_id: 0\n", "    joint_id: 0\n" + extra)
    path = tmp_path / "pendulum.body"
    path.write_text(text)
    robot = load(path)
    (actuator,) = robot.actuators
    assert (actuator.joint, actuator.kind, actuator.reduction, actuator.rotor_inertia) == (
        "ARM", ActuatorKind.POSITION, 100.0, 1.0e-4)
    assert robot.joints[0].armature == pytest.approx(1.0)  # 100² · 1e-4: the reflected rotor inertia
    out, _ = convert(robot, tmp_path / "out")
    assert [el.tag for el in actuator_elements(out)] == ["position"]


# -- the --actuators choice where the source has none ------------------------------------------


@pytest.mark.parametrize(("choice", "tags"), [("motor", ["motor"]), ("velocity", ["velocity"]),
                                              ("position", ["position"]), ("none", []),
                                              ("auto", ["position"])])  # welded: every joint holds
def test_actuators_option_decides_for_a_source_without_any(tmp_path: Path, choice: str,
                                                           tags: list[str]) -> None:
    path = tmp_path / "pendulum.body"
    path.write_text(PENDULUM_BODY)
    robot = load(path)
    assert robot.actuators == []
    out, notes = convert(robot, tmp_path / "out", choice)
    assert [el.tag for el in actuator_elements(out)] == tags
    assert [n.code for n in notes if n.code == "MK841"] == ["MK841"]
    assert len([n for n in notes if n.code == "MK840"]) == (1 if choice in ("position", "velocity", "auto")
                                                           else 0)
    m = mujoco.MjModel.from_xml_path(str(out))
    assert m.nu == len(tags)


ARM_ON_WHEELS = """<robot name="arm_on_wheels">
  <link name="base"><inertial><mass value="5"/>
    <inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="wheel"><inertial><mass value="1"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="arm"><inertial><origin xyz="0 0 0.25"/><mass value="1"/>
    <inertia ixx="0.02" iyy="0.02" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="slider"><inertial><mass value="0.5"/>
    <inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="wheel_joint" type="continuous"><parent link="base"/><child link="wheel"/><axis xyz="0 1 0"/>
  </joint>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="arm"/><origin xyz="0 0 0.1"/>
    <axis xyz="0 1 0"/><limit lower="-1.5" upper="1.5" effort="50" velocity="2"/></joint>
  <joint name="lift" type="prismatic"><parent link="arm"/><child link="slider"/><origin xyz="0 0 0.5"/>
    <axis xyz="0 0 1"/><limit lower="0" upper="0.2" effort="100" velocity="0.5"/></joint>
</robot>
"""


def test_auto_servos_ranged_joints_and_leaves_endless_ones_free(tmp_path: Path) -> None:
    """The default ``--actuators auto`` on a source without actuators: a position servo (with made-up
    gains, MK840) on each joint with a range, a motor on the endless wheel joint; MK841 says so."""
    path = tmp_path / "arm_on_wheels.urdf"
    path.write_text(ARM_ON_WHEELS)
    robot = load(path)
    assert robot.actuators == []
    out, notes = convert(robot, tmp_path / "out")
    tags = {el.get("joint"): el.tag for el in actuator_elements(out)}
    assert tags == {"wheel_joint": "motor", "shoulder": "position", "lift": "position"}
    (said,) = [n for n in notes if n.code == "MK841"]
    assert "2 <position> actuator(s) and 1 <motor> actuator(s)" in said.message
    assert "--actuators auto" in said.message
    assert len([n for n in notes if n.code == "MK840"]) == 2
    m = mujoco.MjModel.from_xml_path(str(out))
    assert m.opt.integrator == mujoco.mjtIntegrator.mjINT_IMPLICITFAST  # servos: MK825
    lift = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_ACTUATOR, "lift")
    assert tuple(m.actuator_ctrlrange[lift]) == (0.0, 0.2)  # the joint's range


def test_made_up_gains_follow_the_rule(tmp_path: Path) -> None:
    """The pendulum's arm: 1 kg, COM 0.5 m from the axis, Ixx 0.0835417 → I = 0.3335417 kg·m² about the
    joint; kp = I (2π·30)², kv = 2 I (2π·30), each rounded up to three significant digits."""
    path = tmp_path / "pendulum.body"
    path.write_text(PENDULUM_BODY)
    out, _ = convert(load(path), tmp_path / "out", "position")
    (el,) = actuator_elements(out)
    wn = 2 * np.pi * 30.0
    inertia = 0.0835417 + 1.0 * 0.5**2
    # the rule's numbers, rounded up to three significant digits: 11850.9 → 11900, 125.73 → 126
    assert (el.get("kp"), el.get("kv")) == ("11900", "126")
    assert inertia * wn**2 <= float(el.get("kp")) < inertia * wn**2 * 1.01
    assert 2 * inertia * wn <= float(el.get("kv")) < 2 * inertia * wn * 1.01
    m = mujoco.MjModel.from_xml_path(str(out))
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    assert m.opt.integrator == mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    # MuJoCo's own mass matrix at home agrees with the reflected inertia the rule used
    full = np.zeros((m.nv, m.nv))
    mujoco.mj_fullM(m, d, full)
    assert full[0, 0] == pytest.approx(inertia, rel=1e-6)


# -- holding a home pose (the acceptance check) --------------------------------------------------


def test_ur5_holds_home_under_its_own_position_actuators(tmp_path: Path) -> None:
    """UR5 (example-robot-data) names a PositionJointInterface transmission on each of its 6 joints; its
    home is q = 0, the arm stretched out horizontally (the most gravity torque it meets)."""
    robot = load(robots_dir() / "ur_description" / "urdf" / "ur5_robot.urdf")
    assert [a.kind for a in robot.actuators] == [ActuatorKind.POSITION] * 6
    out, _ = convert(robot, tmp_path)  # the default option: the source's own actuators decide
    count, error = hold_error(out)
    assert count == 6
    assert [el.tag for el in actuator_elements(out)] == ["position"] * 6
    assert error < HOLD_TOLERANCE, f"UR5 moved {error * 1e3:.3f} mm"


def test_a_kinematic_only_arm_holds_home_with_the_mass_it_is_written_with(tmp_path: Path) -> None:
    """An arm without one <inertial> (rtb-data's ABB IRB 140) is written with 1e-6 kg per moving body
    (MK816); its servos' gains are made for that mass, not for none (it hung 3.8 mm off home)."""
    source = tmp_path / "bare.urdf"
    reach_out = {2: 0.28, 5: 1.49}  # the forearm reaches out: gravity turns the shoulder and elbow
    joints = "".join(
        f'<joint name="j{i}" type="revolute"><parent link="l{i - 1}"/><child link="l{i}"/>'
        f'<origin xyz="{reach_out.get(i, 0)} 0 {1.4 if i in (2, 3) else 0.05}"/>'
        f'<axis xyz="0 {1 if i in (2, 3, 5) else 0} {0 if i in (2, 3, 5) else 1}"/>'
        '<limit lower="-2" upper="2" effort="100" velocity="2"/></joint>'
        for i in range(1, 7))
    links = "".join(f'<link name="l{i}"/>' for i in range(7))
    source.write_text(f'<robot name="bare">{links}{joints}</robot>')
    out, notes = convert(load(source), tmp_path)
    assert sum(n.code == "MK816" for n in notes) >= 6
    count, error = hold_error(out)
    assert count == 6
    assert error < HOLD_TOLERANCE, f"moved {error * 1e3:.3f} mm"


def test_panda_holds_its_reference_pose(tmp_path: Path) -> None:
    """Panda (example-robot-data) has no transmissions: the default ``--actuators auto`` gives one position
    servo per joint with a range (7 arm joints and finger 1; finger 2 mimics it); home = the SRDF's
    ``default`` state."""
    robots = robots_dir()
    robot = load(robots / "panda_description" / "urdf" / "panda.urdf")
    pose = srdf_pose(robots / "panda_description" / "srdf" / "panda.srdf", "default")
    by_name = {j.name: j for j in robot.joints}
    for joint in robot.joints:
        joint.initial_position = pose.get(joint.name, joint.initial_position)
    for joint in robot.joints:  # the SRDF gives finger 1 only: finger 2 where its mimic equality puts it
        if joint.mimic is not None:
            leader = by_name[joint.mimic.joint].initial_position
            joint.initial_position = joint.mimic.multiplier * leader + joint.mimic.offset
    out, _ = convert(robot, tmp_path)
    count, error = hold_error(out)
    actuated = [j for j in robot.joints if j.type.moves and j.mimic is None]
    assert count == len(actuated) == 8
    assert [el.tag for el in actuator_elements(out)] == ["position"] * 8
    assert error < HOLD_TOLERANCE, f"Panda moved {error * 1e3:.3f} mm"


def test_fr3_holds_the_pose_its_ros2_control_starts_in(tmp_path: Path) -> None:
    """Franka FR3 (corpus, xacro with ``ros2_control:=true``): its ros2_control names position, velocity
    and effort command interfaces on the 7 arm joints (position first: position servos) and the start
    pose as each joint's ``initial_value``; the hand's fingers are not actuated by it."""
    path = CORPUS / "franka_description" / "robots" / "fr3" / "fr3.urdf.xacro"
    if not path.is_file():
        pytest.skip("shared corpus not available")
    robot = load(path, ReadOptions(xacro_args={"ros2_control": "true", "use_fake_hardware": "true"}))
    assert [a.joint for a in robot.actuators] == [f"fr3_joint{i}" for i in range(1, 8)]
    assert {a.kind for a in robot.actuators} == {ActuatorKind.POSITION}
    joint4 = next(j for j in robot.joints if j.name == "fr3_joint4")
    assert joint4.initial_position == pytest.approx(-3 * np.pi / 4)
    out, _ = convert(robot, tmp_path)
    count, error = hold_error(out)
    assert count == 7
    assert error < HOLD_TOLERANCE, f"FR3 moved {error * 1e3:.3f} mm"


def test_pa10_holds_home(tmp_path: Path) -> None:
    """Choreonoid's PA10 (corpus): no actuation mode, so the default ``--actuators auto`` servos every
    joint (each has a range); rotor inertias are in
    the joints' armature, which the gain rule adds to the reflected inertia. Its zero pose stands
    upright (no gravity torque, nothing to hold), so home is bent: J2 30°, J4 60°, J6 30°."""
    path = CORPUS / "choreonoid" / "share" / "model" / "PA10" / "PA10.body"
    if not path.is_file():
        pytest.skip("shared corpus not available")
    robot = load(path)
    bent = {"J2": np.pi / 6, "J4": np.pi / 3, "J6": np.pi / 6}
    for joint in robot.joints:
        joint.initial_position = bent.get(joint.name, joint.initial_position)
    out, _ = convert(robot, tmp_path)
    count, error = hold_error(out)
    moving = [j for j in robot.joints if j.type.moves and j.mimic is None]
    assert count == len(moving)
    assert {el.tag for el in actuator_elements(out)} == {"position"}
    assert error < HOLD_TOLERANCE, f"PA10 moved {error * 1e3:.3f} mm"


# Every fixed-base arm of example-robot-data whose default MJCF is all position servos, with their count
# (the PR2 and Tiago carry continuous joints or wheels; Baxter names actuators for its grippers only;
# the Kinova arm's vertical joint 1 and wrist roll keep motors: its own test below).
KINOVA = "kinova_description/robots/kinova.urdf"  # Jaco: continuous joints 1, 4, 6; effort transmissions


SAGGING_KINOVA_JOINTS = ("j2s6s200_joint_2", "j2s6s200_joint_3", "j2s6s200_joint_4", "j2s6s200_joint_5")


@pytest.mark.parametrize("source_actuators", ["auto", "replace"])
def test_an_arm_with_effort_interfaces_holds_home_on_servos(tmp_path: Path, source_actuators: str) -> None:
    """example-robot-data's Kinova arm names ``EffortJointInterface`` transmissions. By default
    (``--source-actuators auto``) and with ``replace``, the ``--actuators auto`` choice gives a position
    servo to every joint, the base being welded: the continuous ones too, as Menagerie's Kinova Gen3 has
    them (joint 4: with a motor there the arm fell 257 mm; the vertical joint 1, a motor, turned 0.0136 rad
    while joint 2 moved 0.5 rad). The arm holds home within 1 mm; MK864 (auto) names the servoed joints."""
    robot = load(example_robot(KINOVA))
    out, notes = convert(robot, tmp_path, source_actuators=source_actuators)
    kinds = {el.get("joint"): el.tag for el in actuator_elements(out)}
    assert kinds == {f"j2s6s200_joint_{i}": "position" for i in range(1, 7)}
    assert "MK863" not in {n.code for n in notes}
    if source_actuators == "auto":
        (said,) = [n for n in notes if n.code == "MK864"]
        assert said.message.startswith("6 joint(s) (j2s6s200_joint_1, j2s6s200_joint_2, j2s6s200_joint_3, "
                                       "j2s6s200_joint_4 ...)")
    count, error = hold_error(out)
    assert count == 6 and error < HOLD_TOLERANCE, f"moved {error * 1e3:.3f} mm"


def test_an_arms_other_joints_hold_while_one_moves(tmp_path: Path) -> None:
    """The Kinova's joint 2 commanded 0.5 rad from home: its vertical joint 1 and wrist roll 6, servoed
    now, stay put (as motors, free at zero control, joint 1 turned 0.0136 rad under the reaction)."""
    out, _ = convert(load(example_robot(KINOVA)), tmp_path)
    m = mujoco.MjModel.from_xml_path(str(out))
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, 0)
    home = d.qpos.copy()
    d.ctrl[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_ACTUATOR, "j2s6s200_joint_2")] = home[1] + 0.5
    worst = 0.0
    for _ in range(3000):
        mujoco.mj_step(m, d)
        worst = max(worst, abs(d.qpos[0] - home[0]), abs(d.qpos[5] - home[5]))
    assert d.qpos[1] - home[1] == pytest.approx(0.5, abs=2e-3)
    assert worst < 1e-3, worst


def test_an_arm_whose_effort_interfaces_are_kept_as_motors_says_it_sags(tmp_path: Path) -> None:
    """``--source-actuators keep``: the Kinova's effort interfaces written as the source's motors, it
    falls at zero control (255 mm in 2 s), and MK863 says so with the joints gravity turns."""
    robot = load(example_robot(KINOVA))
    out, notes = convert(robot, tmp_path, source_actuators="keep")
    (sags,) = [n for n in notes if n.code == "MK863"]
    assert sags.message.startswith("4 joint(s) with the source's effort actuators")
    assert all(joint in sags.message for joint in SAGGING_KINOVA_JOINTS)
    assert {el.tag for el in actuator_elements(out)} == {"motor"}
    count, error = hold_error(out)
    assert count == 6 and error > 0.1  # the source's motors: the arm falls


EXAMPLE_ARMS = {
    "ur_description/urdf/ur3_robot.urdf": 6,
    "ur_description/urdf/ur10_robot.urdf": 6,
    "so_arm_description/urdf/so100.urdf": 6,
    "so_arm_description/urdf/so101.urdf": 6,
    "xarm_description/urdf/xarm7.urdf": 7,
    "panda_description/urdf/panda.urdf": 8,
    "talos_data/robots/talos_left_arm.urdf": 7,
    "finger_edu_description/robots/finger_edu.urdf": 3,
    "z1_description/urdf/z1.urdf": 6,  # effort transmissions, servoed by --source-actuators auto (MK864)
}


@pytest.mark.parametrize("relative", sorted(EXAMPLE_ARMS))
def test_every_example_arm_holds_home(tmp_path: Path, relative: str) -> None:
    """The user's next step on an arm nobody here modelled: ``convert`` with the default options, load
    the MJCF, reset to ``home`` (q = 0, put into range where it is not: MK845) and let it be. Position
    servos on every ranged joint (``--actuators auto``), welded base (``--base auto``): within 1 mm."""
    robot = load(example_robot(relative))
    out, notes = convert(robot, tmp_path)
    count, error = hold_error(out)
    assert count == EXAMPLE_ARMS[relative]
    assert {el.tag for el in actuator_elements(out)} == {"position"}
    assert error < HOLD_TOLERANCE, f"{relative} moved {error * 1e3:.3f} mm"
    if relative.endswith("panda.urdf"):  # joint 4's range [-3.07, -0.07] excludes q = 0
        (moved,) = [n for n in notes if n.code == "MK845"]
        assert moved.message.startswith("joint panda_joint4: home position 0 is outside its range")


# -- other targets -----------------------------------------------------------------------------


def test_mjcf_actuators_reach_urdf_and_body_as_their_kinds(tmp_path: Path) -> None:
    """MJCF → URDF writes one ``<transmission>`` per canonical actuator (MK844 lists the gains it cannot
    hold) and MJCF → .body an ``actuation_mode``; both read back as the same kinds."""
    path = tmp_path / "four.xml"
    path.write_text(MJCF)
    robot = load(path)
    kinds = {a.joint: a.kind for a in robot.actuators}
    urdf = tmp_path / "urdf" / "four.urdf"
    notes = write(robot, urdf, force=True)
    assert {a.joint: a.kind for a in load(urdf).actuators} == kinds
    (lost,) = [n for n in notes if n.code == "MK844"]
    assert "j1 (kp 100, kv 5" in lost.message
    assert "1 MJCF actuators" in " ".join(n.message for n in notes if n.code == "MK808")  # the intvelocity
    body = tmp_path / "body" / "four.body"
    write(robot, body, force=True)
    assert {a.joint: a.kind for a in load(body).actuators} == kinds


def test_reflected_inertias_equal_mujocos_mass_matrix(tmp_path: Path) -> None:
    """The gain rule's inertia of every Panda joint (summed once per subtree, bottom up, with a
    parallel-axis shift) is the diagonal of MuJoCo's own joint-space mass matrix at home, less the
    armature the file gives the fingers' mimic coupling (MK835; the source has none)."""
    from modelkit.convert.servo_gains import joint_loads

    robot = load(example_robot("panda_description/urdf/panda.urdf"))
    loads = joint_loads(robot)
    out, _ = convert(robot, tmp_path, "motor")
    m = mujoco.MjModel.from_xml_path(str(out))
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_KEY, "home"))
    mujoco.mj_forward(m, d)
    full = np.zeros((m.nv, m.nv))
    mujoco.mj_fullM(m, d, full)
    for j in range(m.njnt):
        name = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_JOINT, j)
        dof = m.jnt_dofadr[j]
        assert loads[name].inertia == pytest.approx(full[dof, dof] - m.dof_armature[dof], rel=1e-9), name
    assert {mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_JOINT, j) for j in range(m.njnt)
            if m.dof_armature[m.jnt_dofadr[j]]} == {"panda_finger_joint1", "panda_finger_joint2"}


# Legged robots of example-robot-data whose URDF names no actuators: each gets a free base and a position
# servo per joint, and its home keyframe (q = 0, put into range: MK845) is a standing pose. The A1's home
# puts all four feet 0.16 m behind their hips: with gains for its legs' own weight alone it sagged and
# tipped over nose first; with each leg's share of the robot's weight in the rule it stands. Left out:
# Go1, B1 and HyQ, whose URDFs name effort interfaces (motors at zero control: the source's answer, MK857).
EXAMPLE_LEGGED = (
    "a1_description/urdf/a1.urdf",
    "anymal_b_simple_description/robots/anymal.urdf",
    "anymal_c_simple_description/urdf/anymal.urdf",
    "go2_description/urdf/go2.urdf",
    "laikago_description/urdf/laikago.urdf",
    "solo_description/robots/solo12.urdf",
)
STAND_SECONDS, STAND_SAG, STAND_TILT = 3.0, 0.015, 0.05  # s, m, rad



def _home_on_a_plain_floor(path: Path) -> tuple[Any, Any]:
    """The written MJCF as a user loads it: a default plane added and reset to the ``home`` keyframe,
    nothing else. The key stands the robot on z = 0 (MK882): no contact with the floor deeper than 1 µm."""
    spec = mujoco.MjSpec.from_file(str(path))
    spec.worldbody.add_geom(name="floor", type=mujoco.mjtGeom.mjGEOM_PLANE, size=[0.0, 0.0, 1.0])
    m = spec.compile()
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_KEY, "home"))
    mujoco.mj_forward(m, d)
    floor = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, "floor")
    depth = min([c.dist for c in d.contact[:d.ncon] if floor in tuple(c.geom)] or [0.0])
    assert depth >= -1e-6, f"{path.name}: at home the robot starts {-depth * 1e3:.3f} mm inside the floor"
    return m, d


def stand_on_a_plain_floor(path: Path) -> tuple[float, float]:
    """The written MJCF with only a default-contact plane added, reset to ``home``, lowered onto the
    floor and left alone: (how far the base sank in m, how far it tilted in rad)."""
    m, d = _home_on_a_plain_floor(path)
    assert m.jnt_type[0] == mujoco.mjtJoint.mjJNT_FREE, "a legged robot is free"
    start = float(d.qpos[2])
    for _ in range(round(STAND_SECONDS / m.opt.timestep)):
        mujoco.mj_step(m, d)
    w = min(1.0, abs(float(d.qpos[3])))
    return start - float(d.qpos[2]), 2.0 * math.acos(w)


@pytest.mark.parametrize("relative", EXAMPLE_LEGGED)
def test_example_legged_robots_stand_at_home(tmp_path: Path, relative: str) -> None:
    """The user's next step on a legged robot: ``convert`` with the default options, a floor added, reset
    to ``home``: it floats and stands on its own servos (base within 15 mm and 0.05 rad after 3 s)."""
    robot = load(example_robot(relative))
    out, _ = convert(robot, tmp_path)
    assert {el.tag for el in actuator_elements(out)} == {"position"}
    sag, tilt = stand_on_a_plain_floor(out)
    assert sag < STAND_SAG and tilt < STAND_TILT, f"{relative}: sank {sag * 1e3:.1f} mm, tilted {tilt:.3f}"



def test_a_biped_whose_arms_hang_from_a_waist_stands(tmp_path: Path) -> None:
    """example-robot-data's Unitree G1: two legs and a waist from its pelvis, its arms on the torso, so
    fewer than four limbs start at the root and it was not taken for legged (leg_joints): its ankles got
    gains for the foot's own inertia (30 Hz), softer than the robot tipping over them, and it fell on
    its back (the base 0.70 m down in 3 s). Now its legs are its two limbs on the ground, their servos
    hold at least TIPPING_MARGIN times the tipping stiffness of their share of the robot, and it stands."""
    from modelkit.convert.legs import leg_joints
    from modelkit.convert.servo_gains import TIPPING_MARGIN, joint_loads

    robot = load(example_robot("g1_description/urdf/g1_29dof_rev_1_0.urdf"))
    out, _ = convert(robot, tmp_path)
    free = load(example_robot("g1_description/urdf/g1_29dof_rev_1_0.urdf"))
    free.root_joint = JointType.FLOATING
    legs = leg_joints(free)
    assert {"left_ankle_pitch_joint", "right_knee_joint", "left_hip_roll_joint"} <= legs
    assert not any("shoulder" in name or "waist" in name for name in legs)
    loads = joint_loads(free)
    m = mujoco.MjModel.from_xml_path(str(out))
    ankle = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_ACTUATOR, "left_ankle_pitch_joint")
    tipping = loads["left_ankle_pitch_joint"].tipping
    assert tipping > 50.0 and m.actuator_gainprm[ankle][0] >= TIPPING_MARGIN * tipping * (1 - 1e-9)
    sag, tilt = stand_on_a_plain_floor(out)
    assert sag < STAND_SAG and tilt < STAND_TILT, f"sank {sag * 1e3:.1f} mm, tilted {tilt:.3f}"

# pybullet_data's quadrupeds whose URDFs declare leg joints ``continuous`` (no range) and name no
# actuators: Laikago (toes, Z up) all twelve, Aliengo its four thighs. ``--actuators auto`` used to give
# each such joint a motor (as for a wheel), and at zero control the robot folded to the floor (Laikago
# 396 mm, Aliengo 350 mm in 2 s); a joint in a leg now gets a position servo (convert.legs).
PYBULLET_LEGGED_CONTINUOUS = ("laikago/laikago_toes_zup.urdf", "aliengo/aliengo.urdf")


@pytest.mark.parametrize("relative", PYBULLET_LEGGED_CONTINUOUS)
def test_continuous_leg_joints_are_servoed_so_the_robot_stands(tmp_path: Path, relative: str) -> None:
    pybullet_data = pytest.importorskip("pybullet_data")
    robot = load(Path(pybullet_data.getDataPath()) / relative)
    assert any(not math.isfinite(j.limits.upper) for j in robot.joints if j.type.moves), "a continuous joint"
    out, notes = convert(robot, tmp_path)
    sag, tilt = stand_on_a_plain_floor(out)
    assert sag < STAND_SAG and tilt < STAND_TILT, f"{relative}: sank {sag * 1e3:.1f} mm, tilted {tilt:.3f}"
    assert [el.tag for el in actuator_elements(out)] == ["position"] * 12
    (said,) = [n for n in notes if n.code == "MK841"]
    assert "in a leg or" in said.message


FOUR_CASTERS = """<robot name="cart">
  <link name="base"><inertial><mass value="10"/>
    <inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.6 0.4 0.1"/></geometry></collision></link>
""" + "".join(f"""
  <link name="fork{i}"><inertial><mass value="0.2"/>
    <inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="-0.02 0 -0.03"/><geometry><box size="0.02 0.04 0.06"/></geometry>
    </collision></link>
  <link name="wheel{i}"><inertial><mass value="0.3"/>
    <inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin rpy="1.5707963 0 0"/><geometry><cylinder radius="0.05" length="0.03"/></geometry>
    </collision></link>
  <joint name="swivel{i}" type="continuous"><parent link="base"/><child link="fork{i}"/>
    <origin xyz="{x} {y} -0.1"/><axis xyz="0 0 1"/></joint>
  <joint name="spin{i}" type="continuous"><parent link="fork{i}"/><child link="wheel{i}"/>
    <origin xyz="-0.04 0 -0.06"/><axis xyz="0 1 0"/></joint>""" for i, (x, y) in enumerate(
    [(0.25, 0.15), (0.25, -0.15), (-0.25, 0.15), (-0.25, -0.15)])) + "\n</robot>\n"


def test_casters_are_not_legs(tmp_path: Path) -> None:
    """A cart on four casters has four limbs of two joints, as a quadruped has; its limbs carry wheels
    (an endless hinge whose child is round about its axis), so swivels and wheels keep their motors."""
    from modelkit.convert.base import decide
    from modelkit.convert.legs import leg_joints

    path = tmp_path / "cart.urdf"
    path.write_text(FOUR_CASTERS)
    robot = load(path)
    robot.root_joint = decide(robot).kind  # as --base auto settles it: floating, on wheels
    assert robot.root_joint is JointType.FLOATING
    assert leg_joints(robot) == frozenset()
    out, _ = convert(robot, tmp_path / "out")
    assert [el.tag for el in actuator_elements(out)] == ["motor"] * 8


# -- what a legged robot's source cannot give, said at conversion (MK856, MK857) --------------------

STANDING_LEGGED = EXAMPLE_LEGGED


def test_a_home_that_lies_on_the_body_is_said(tmp_path: Path) -> None:
    """pybullet_data's Spirit40 at q = 0 (its home: the URDF gives no initial positions) has its legs
    folded flat beside its body: MK856 says the home keyframe is not a stance, and MuJoCo agrees: on a
    plain floor its hips, not its toes, carry it."""
    pybullet_data = pytest.importorskip("pybullet_data")
    robot = load(Path(pybullet_data.getDataPath()) / "quadruped" / "spirit40.urdf")
    out, notes = convert(robot, tmp_path)
    (said,) = [n for n in notes if n.code == "MK856"]
    assert "hip0, hip1, hip2, hip3" in said.message and said.severity == "warning"
    spec = mujoco.MjSpec.from_file(str(out))
    spec.worldbody.add_geom(type=mujoco.mjtGeom.mjGEOM_PLANE, size=[0.0, 0.0, 1.0])
    m = spec.compile()
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_KEY, "home"))
    for _ in range(round(1.0 / m.opt.timestep)):
        mujoco.mj_step(m, d)
    touching = {mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, int(m.geom_bodyid[g]))
                for c in d.contact[:d.ncon] for g in (c.geom1, c.geom2)} - {"world"}
    assert {"hip0", "hip1", "hip2", "hip3"} <= touching and not touching & {"toe0", "toe1", "toe2", "toe3"}


def test_source_motors_on_legs_are_said(tmp_path: Path) -> None:
    """HyQ's URDF names an EffortJointInterface on each of its 12 leg joints: under
    ``--source-actuators keep`` written as motors (the source's kind), so MK857 says the legs are limp at
    zero control."""
    robot = load(example_robot("hyq_description/robots/hyq_no_sensors.urdf"))
    out, notes = convert(robot, tmp_path, source_actuators="keep")
    assert {el.tag for el in actuator_elements(out)} == {"motor"}
    (said,) = [n for n in notes if n.code == "MK857"]
    assert said.message.startswith("12 of the 12 leg joints")
    assert not [n for n in notes if n.code == "MK856"]


# Legged robots whose URDFs name an EffortJointInterface on every leg joint (MK857 above): by default
# (``--source-actuators auto``: ROS effort interfaces get the ``--actuators`` choice, MK864) and with
# ``--source-actuators replace`` they get ``--actuators auto``'s position servos and stand in MuJoCo.
# Measured: Go1 sank 6.4 mm and tilted 0.016 rad in 3 s, B1 4.8 mm and 0.006, HyQ 9.2 mm and 0.004; with
# the source's motors (``--source-actuators keep``) each lies down.
EFFORT_LEGGED = ("go1_description/urdf/go1.urdf", "b1_description/urdf/b1.urdf",
                 "hyq_description/robots/hyq_no_sensors.urdf")


def _convert_cli(source: Path, target: Path, *options: str) -> str:
    from click.testing import CliRunner

    from modelkit.cli import main

    result = CliRunner().invoke(main, ["convert", str(source), "-o", str(target), *options],
                                env={"ROS_PACKAGE_PATH": str(robots_dir())})
    assert result.exit_code == 0, result.output
    return result.output


@pytest.mark.parametrize("relative", EFFORT_LEGGED)
def test_source_motors_replaced_by_servos_stand(tmp_path: Path, relative: str) -> None:
    """``convert go1.urdf -o go1.xml --source-actuators replace``: the source's 12 effort transmissions
    are set aside (MK855 counts them), each leg joint gets a position servo, MK857 is not said, and the
    written file stands at home on a plain floor."""
    out = tmp_path / "m.xml"
    said = _convert_cli(example_robot(relative), out, "--source-actuators", "replace")
    assert [el.tag for el in actuator_elements(out)] == ["position"] * 12
    assert "MK855 the source's 12 actuator(s) (12 effort) set aside" in said
    assert "written instead: 12 <position> (--actuators auto)" in said and "MK857" not in said
    sag, tilt = stand_on_a_plain_floor(out)
    assert sag < STAND_SAG and tilt < STAND_TILT, f"{relative}: sank {sag * 1e3:.1f} mm, tilted {tilt:.3f}"


@pytest.mark.parametrize("relative", EFFORT_LEGGED)
def test_ros_effort_legs_are_servoed_by_default_and_stand(tmp_path: Path, relative: str) -> None:
    """``convert go1.urdf -o go1.xml`` with the default options: the source's 12 ROS effort interfaces
    get position servos (MK864 says so), MK857 is not said, and the written file stands at home on a
    plain floor."""
    out = tmp_path / "m.xml"
    said = _convert_cli(example_robot(relative), out)
    assert [el.tag for el in actuator_elements(out)] == ["position"] * 12
    assert "MK864 12 joint(s)" in said and "written as 12 <position> (--actuators auto)" in said
    assert "MK857" not in said and "MK855" not in said
    sag, tilt = stand_on_a_plain_floor(out)
    assert sag < STAND_SAG and tilt < STAND_TILT, f"{relative}: sank {sag * 1e3:.1f} mm, tilted {tilt:.3f}"


def test_source_motors_kept_leave_the_legs_limp(tmp_path: Path) -> None:
    """The contrast: ``--source-actuators keep`` writes HyQ's motors (MK857), and at zero control it does
    not stand."""
    out = tmp_path / "m.xml"
    said = _convert_cli(example_robot(EFFORT_LEGGED[2]), out, "--source-actuators", "keep")
    assert {el.tag for el in actuator_elements(out)} == {"motor"} and "MK857" in said
    assert "--source-actuators replace" in said
    sag, tilt = stand_on_a_plain_floor(out)
    assert sag > STAND_SAG or tilt > STAND_TILT


def test_replace_sets_aside_every_mjcf_actuator(tmp_path: Path) -> None:
    """An MJCF source's five actuators (four the model holds, an intvelocity it does not) are all set
    aside by ``--source-actuators replace --actuators velocity``: five velocity servos, no MK842."""
    path = tmp_path / "four.xml"
    path.write_text(MJCF)
    out = tmp_path / "out" / "four.xml"
    said = _convert_cli(path, out, "--source-actuators", "replace", "--actuators", "velocity")
    assert [(el.tag, el.get("joint")) for el in actuator_elements(out)] == [
        ("velocity", f"j{i}") for i in range(1, 6)]
    assert ("the source's 5 actuator(s) (1 effort, 2 position, 1 velocity, 1 other MJCF) set aside" in said)
    assert "MK842" not in said and "MK841" not in said
    m = mujoco.MjModel.from_xml_path(str(out))
    assert m.nu == 5 and {int(b) for b in m.actuator_biastype} == {int(mujoco.mjtBias.mjBIAS_AFFINE)}


@pytest.mark.parametrize("relative", STANDING_LEGGED)
def test_no_leg_notes_on_robots_whose_home_stands(tmp_path: Path, relative: str) -> None:
    """Legged robots whose home puts their feet on the floor and whose joints get servos: neither note."""
    robot = load(example_robot(relative))
    _, notes = convert(robot, tmp_path)
    assert not [n for n in notes if n.code in ("MK856", "MK857")]


def test_no_leg_notes_on_the_tutorial_robots(tmp_path: Path) -> None:
    """The samples (the tutorial's wheeled, tracked and pan-tilt robots, the smartcar, the unicycle)."""
    samples = Path(__file__).resolve().parents[1] / "samples"
    paths = sorted(samples.glob("choreonoid_ros2_mobile_robot_tutorial/model/*.body"))
    paths += [samples / "smartcar" / "urdf" / "myrobot.urdf.xacro",
              samples / "gazebo_unicycle" / "unicycle.sdf"]
    assert len(paths) >= 5
    for path in paths:
        robot = validate(path).robot  # mobile_robot_mesh.body has an error (its missing chassis mesh)
        assert robot is not None
        _, notes = convert(robot, tmp_path / path.stem)
        assert not [n for n in notes if n.code in ("MK856", "MK857")], path.name


def test_spirit40_given_a_stance_holds_it_with_its_legs_share_of_the_weight(tmp_path: Path) -> None:
    """pybullet_data's Spirit40 has 75 g lower legs: with gains for a leg's own weight alone its knees
    got kp 44 N·m/rad and, given a stance (hips 0.8, knees 1.6 rad) on a plain floor, sagged 0.18 rad
    (the base 26 mm) while carrying the 11.5 kg robot; with each leg's share of the weight in the rule,
    every joint is back within 0.05 rad of the stance after 3 s and the base within 15 mm.

    Its toes carry the source's PyBullet friction (lateral 3, spinning 0.3: MJCF friction "3 0.3",
    condim 4), so they stick where they land: the legs take the touchdown without sliding, a transient
    of 0.09 rad at 0.1 s that the servos then work off (0.003 rad at 3 s). Measured with the rule
    before (gains for a leg's own weight): 0.23 rad transient, 0.10 rad at 3 s, 26.6 mm sag."""
    pybullet_data = pytest.importorskip("pybullet_data")
    robot = load(Path(pybullet_data.getDataPath()) / "quadruped" / "spirit40.urdf")
    for joint in robot.joints:
        joint.initial_position = {"0": 0.8, "2": 0.8, "4": 0.8, "6": 0.8,
                                  "1": 1.6, "3": 1.6, "5": 1.6, "7": 1.6}.get(joint.name, 0.0)
    out, notes = convert(robot, tmp_path)
    assert not [n for n in notes if n.code == "MK856"], "a stance: its toes carry it"
    m, d = _home_on_a_plain_floor(out)
    toes = [g for g in range(m.ngeom) if m.geom_condim[g] == 4]
    assert len(toes) == 4 and all(float(m.geom_friction[g][0]) == 3.0 for g in toes)  # the source's
    home, start = d.qpos[7:].copy(), float(d.qpos[2])
    worst = 0.0
    for _ in range(round(STAND_SECONDS / m.opt.timestep)):
        mujoco.mj_step(m, d)
        worst = max(worst, float(np.abs(d.qpos[7:] - home).max()))
    sag, held = start - float(d.qpos[2]), float(np.abs(d.qpos[7:] - home).max())
    assert held < 0.05 and worst < 0.15 and sag < STAND_SAG, (
        f"joints {held:.3f} rad off at the end ({worst:.3f} at worst), base sank {sag * 1e3:.1f} mm"
    )


def test_a_sources_unactuated_legs_get_servos_so_the_robot_stands(tmp_path: Path) -> None:
    """example-robot-data's ANYmal-Kinova names transmissions for the arm only. Its twelve leg joints had
    no actuator, and on a plain floor the robot folded (451 mm in 2 s): by default they now get the
    ``--actuators`` choice, position servos (MK827), and it stands; ``keep`` leaves them without."""
    robot = load(example_robot("anymal_b_simple_description/robots/anymal-kinova.urdf"))
    out, notes = convert(robot, tmp_path / "auto")
    (said,) = [n for n in notes if n.code == "MK827"]
    assert said.message.startswith("12 joint(s) (LF_HAA, LF_HFE, LF_KFE, RF_HAA ...; 12 in legs)")
    kinds = {el.get("joint"): el.tag for el in actuator_elements(out)}
    assert all(kinds.get(f"{leg}_{part}") == "position" for leg in ("LF", "RF", "LH", "RH")
               for part in ("HAA", "HFE", "KFE"))
    sag, tilt = stand_on_a_plain_floor(out)
    assert sag < STAND_SAG and tilt < STAND_TILT, f"sank {sag * 1e3:.1f} mm, tilted {tilt:.3f}"
    kept, notes = convert(robot, tmp_path / "keep", source_actuators="keep")
    assert "MK827" not in {n.code for n in notes}
    assert not any(el.get("joint", "").endswith("_KFE") for el in actuator_elements(kept))


# -- a free base's unactuated joints off the ground (MK827) and ROS interfaces listed after a state one ----

def test_a_joint_state_interface_listed_first_does_not_hide_the_command_interface(tmp_path: Path) -> None:
    """PAL's TIAGo lists ``JointStateInterface`` before ``PositionJointInterface`` for its head and wrist
    joints. The first interface that commands the joint gives the actuator; before, those joints had
    none and the head nodded 0.115 rad in 2 s."""
    path = tmp_path / "two.urdf"
    path.write_text(URDF.replace(
        "<hardwareInterface>hardware_interface/EffortJointInterface</hardwareInterface>",
        "<hardwareInterface>hardware_interface/JointStateInterface</hardwareInterface>"
        "<hardwareInterface>hardware_interface/PositionJointInterface</hardwareInterface>"
        "<hardwareInterface>hardware_interface/EffortJointInterface</hardwareInterface>"))
    got = {a.joint: a for a in load(path).actuators}
    assert got["j1"].kind is ActuatorKind.POSITION
    assert got["j1"].source_kind == "hardware_interface/PositionJointInterface"
    path.write_text(URDF.replace("hardware_interface/EffortJointInterface",
                                 "hardware_interface/JointStateInterface"))
    assert "j1" not in {a.joint for a in load(path).actuators}  # a state interface alone commands nothing


CART_WITH_ARM = FOUR_CASTERS.replace('''<joint name="swivel0" type="continuous"><parent link="base"/>''',
                                     '''<link name="strut"><inertial><mass value="0.2"/>
    <inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="suspension" type="prismatic"><parent link="base"/><child link="strut"/>
    <origin xyz="0.25 0.15 -0.1"/><axis xyz="0 0 1"/><limit lower="-0.02" upper="0.02" effort="500"
    velocity="1"/></joint>
  <joint name="swivel0" type="continuous"><parent link="strut"/>''').replace(
    '<origin xyz="0.25 0.15 -0.1"/><axis xyz="0 0 1"/></joint>',
    '<origin xyz="0 0 0"/><axis xyz="0 0 1"/></joint>', 1).replace("</robot>", '''
  <link name="upper_arm"><inertial><origin xyz="0.2 0 0"/><mass value="2"/>
    <inertia ixx="0.002" iyy="0.03" izz="0.03" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="0.2 0 0"/><geometry><box size="0.4 0.05 0.05"/></geometry></collision></link>
  <link name="head"><inertial><mass value="1"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper_arm"/>
    <origin xyz="0 0 0.3"/><axis xyz="0 1 0"/><limit lower="-1.5" upper="1.5" effort="40" velocity="2"/>
  </joint>
  <joint name="head_pan" type="revolute"><parent link="base"/><child link="head"/>
    <origin xyz="0 0 0.5"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="5" velocity="2"/></joint>
  <transmission name="drive"><type>transmission_interface/SimpleTransmission</type>
    <joint name="spin1"><hardwareInterface>hardware_interface/VelocityJointInterface</hardwareInterface>
    </joint><actuator name="drive_motor"/></transmission>
</robot>''')


def test_a_free_bases_unactuated_joints_off_the_ground_get_servos(tmp_path: Path) -> None:
    """A cart whose source actuates one wheel: the arm's shoulder, which gravity turns and below which
    nothing reaches the ground, gets the ``--actuators`` choice (MK827) and holds; the sprung strut above
    a caster (gravity turns it too, but its wheel is on the ground), the vertical head pan, the swivels
    and the other wheels stay passive, as the source has them."""
    from modelkit.convert.base import decide

    path = tmp_path / "cart.urdf"
    path.write_text(CART_WITH_ARM)
    robot = load(path)
    robot.root_joint = decide(robot).kind
    assert robot.root_joint is JointType.FLOATING
    out, notes = convert(robot, tmp_path / "auto")
    tags = {el.get("joint"): el.tag for el in actuator_elements(out)}
    assert tags == {"spin1": "velocity", "shoulder": "position"}
    (said,) = [n for n in notes if n.code == "MK827"]
    assert said.message.startswith("1 joint(s) (shoulder; that gravity turns at home)")
    m, d = _home_on_a_plain_floor(out)
    shoulder = m.jnt_qposadr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, "shoulder")]
    for _ in range(round(HOLD_SECONDS / m.opt.timestep)):
        mujoco.mj_step(m, d)
    assert abs(float(d.qpos[shoulder])) < 0.01, f"the shoulder turned {float(d.qpos[shoulder]):.3f} rad"
    kept, notes = convert(robot, tmp_path / "keep", source_actuators="keep")
    assert {el.get("joint") for el in actuator_elements(kept)} == {"spin1"}
    assert "MK827" not in {n.code for n in notes}


TIAGO = "tiago_description/robots/tiago.urdf"


def test_tiago_holds_its_head_and_hand_on_a_plain_floor(tmp_path: Path) -> None:
    """example-robot-data's TIAGo (a free base on wheels and casters): its head and wrist transmissions
    list ``JointStateInterface`` first, and its hand's 27 coupled finger joints have no transmission.
    Converted with the defaults and dropped on a plain floor, no hinge or slide turns 0.02 rad in 2 s
    (before: the head's tilt 0.115 rad, the fingers 0.1)."""
    robot = load(example_robot(TIAGO))
    out, notes = convert(robot, tmp_path / "tiago")
    acted = {el.get("joint") for el in actuator_elements(out)}
    assert {"head_1_joint", "head_2_joint", "arm_5_joint"} <= acted
    (said,) = [n for n in notes if n.code == "MK827"]
    assert said.message.startswith("27 joint(s) (hand_thumb_abd_joint")
    m, d = _home_on_a_plain_floor(out)
    start = d.qpos.copy()
    for _ in range(round(HOLD_SECONDS / m.opt.timestep)):
        mujoco.mj_step(m, d)
    one_dof = (int(mujoco.mjtJoint.mjJNT_HINGE), int(mujoco.mjtJoint.mjJNT_SLIDE))
    turned = {m.joint(j).name: abs(float(d.qpos[m.jnt_qposadr[j]] - start[m.jnt_qposadr[j]]))
              for j in range(m.njnt) if int(m.jnt_type[j]) in one_dof
              and not m.joint(j).name.startswith(("wheel", "caster"))}
    worst = max(turned, key=turned.__getitem__)
    assert turned[worst] < 0.02, f"{worst} turned {turned[worst]:.3f} rad"


def test_made_up_gains_are_rounded_up_to_three_digits() -> None:
    """A made-up gain is written as a person writes it, and never below the rule's value (the sag and
    tipping bounds are lower bounds)."""
    from modelkit.convert.servo_gains import rounded_up

    assert rounded_up(155503.604519839) == 156000.0
    assert rounded_up(6.46029817704328) == 6.47
    assert rounded_up(6.47) == 6.47  # already three digits: itself, not 6.48
    assert rounded_up(999.5) == 1000.0
    assert rounded_up(0.00123456) == 0.00124
    for value in (1e-7 / 3, 1.0 / 3, 12345.678, 9.999e5):
        assert value <= rounded_up(value) < value * 1.01
        assert len(f"{rounded_up(value):g}".replace(".", "").rstrip("0").lstrip("0").split("e")[0]) <= 3


# A leg as robotblockset's Unitree B2 robot file has it: position servos kp 4000, kv 200 on light links,
# MuJoCo's default Euler integrator and 2 ms step (its scene file sets implicitfast and 1 ms).
LIGHT_LEG = """<mujoco model="leg">
  <worldbody>
    <body name="thigh" pos="0 0 1">
      <joint name="hip" axis="0 1 0" range="-1 1"/>
      <geom type="capsule" fromto="0 0 0 0 0 -0.3" size="0.03" mass="{mass}"/>
      <body name="calf" pos="0 0 -0.3">
        <joint name="knee" axis="0 1 0" range="-2 0"/>
        <geom type="capsule" fromto="0 0 0 0 0 -0.3" size="0.02" mass="{mass}"/>
      </body>
    </body>
  </worldbody>
  <actuator>
    <general joint="hip" biastype="affine" gainprm="4000" biasprm="0 -4000 -200"/>
    <general joint="knee" biastype="affine" gainprm="4000" biasprm="0 -4000 -200"/>
  </actuator>
  <keyframe><key name="home" qpos="0.3 -0.6" ctrl="0.3 -0.6"/></keyframe>
</mujoco>
"""


@pytest.mark.parametrize(("mass", "diverges"), [(0.3, True), (40.0, False)])
def test_an_mjcf_source_s_servos_that_euler_cannot_take_get_implicitfast(tmp_path: Path, mass: float,
                                                                          diverges: bool) -> None:
    """An MJCF source's servos keep the integrator its author chose, unless Euler cannot take their
    damping at the file's step (damping/inertia × dt over 2): the file alone then goes NaN in
    milliseconds (the B2 robot file: 14 ms), and the written file gets implicitfast with MK825. A leg
    heavy enough for Euler keeps MuJoCo's default."""
    import mujoco
    import numpy as np

    source = tmp_path / "leg.xml"
    source.write_text(LIGHT_LEG.format(mass=mass))

    def hold(m: Any) -> tuple[bool, float]:
        d = mujoco.MjData(m)
        mujoco.mj_resetDataKeyframe(m, d, 0)
        while d.time < 1.0 and not np.isnan(d.qpos).any():
            mujoco.mj_step(m, d)
        return bool(np.isnan(d.qpos).any() or d.warning[mujoco.mjtWarning.mjWARN_BADQACC].number), \
            float(np.max(np.abs(d.qpos - m.key_qpos[0])))

    assert hold(mujoco.MjModel.from_xml_path(str(source)))[0] is diverges  # the source itself
    out = tmp_path / "out.xml"
    notes = write(load(source), out, options=WriteOptions(), force=True)
    said = [n.message for n in notes if n.code == "MK825"]
    m = mujoco.MjModel.from_xml_path(str(out))
    if diverges:
        (message,) = said
        assert "diverge under MuJoCo's default Euler integrator at its 0.002 s step" in message
        assert m.opt.integrator == mujoco.mjtIntegrator.mjINT_IMPLICITFAST
        bad, off = hold(m)
        assert not bad and off < 1e-2, off
    else:
        assert said == [] and m.opt.integrator == mujoco.mjtIntegrator.mjINT_EULER
