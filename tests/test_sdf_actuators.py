"""SDF actuators and self-collision (issue 17 items 2 and 4).

Actuators: gz-sim's joint-controller systems (JointPositionController, JointController, ApplyJointForce)
are read as canonical actuators and written back as those systems; every other format's actuators reach
SDF as them and come back as the same kinds. Self-collision: the SDF writer's ``<self_collide>`` flags
follow the MJCF writer's touching pairs. Oracles: libsdformat (the compiled checker of
``tests/test_sdf_reader.py``) accepts every written file, Drake parses it, MuJoCo finds the pairs.
"""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from modelkit.api import load
from modelkit.convert.api import write
from modelkit.convert.notes import ConversionNote, renames
from modelkit.convert.options import WriteOptions
from modelkit.model import ActuatorKind, Robot
from tests.conftest import PENDULUM_BODY, example_robot
from tests.test_actuators import MJCF, URDF
from tests.test_sdf_reader import oracle_has_errors, sdf_oracle  # noqa: F401 (the fixture)

LINK = """
    <link name="{name}">
      <pose relative_to="{joint}"/>
      <inertial><pose>0 0 0.15 0 0 0</pose><mass>1</mass>
        <inertia><ixx>0.01</ixx><iyy>0.01</iyy><izz>0.001</izz></inertia></inertial>
      <collision name="c"><pose>0 0 0.15 0 0 0</pose>
        <geometry><cylinder><radius>0.03</radius><length>0.3</length></cylinder></geometry></collision>
    </link>
    <joint name="{joint}" type="{type}">
      <pose relative_to="{parent}">0 0 {offset} 0 0 0</pose>
      <parent>{parent}</parent><child>{name}</child>
      <axis><xyz>{axis}</xyz><limit><lower>-2</lower><upper>2</upper>{effort}</limit></axis>
    </joint>"""

ARM = (
    """<?xml version="1.0"?>
<sdf version="1.9">
  <model name="arm">
    <self_collide>true</self_collide>
    <joint name="weld" type="fixed"><parent>world</parent><child>base</child></joint>
    <link name="base">
      <self_collide>false</self_collide>
      <inertial><mass>2</mass><inertia><ixx>0.01</ixx><iyy>0.01</iyy><izz>0.01</izz></inertia></inertial>
      <collision name="c"><geometry><box><size>0.2 0.2 0.1</size></box></geometry></collision>
    </link>"""
    + LINK.format(name="upper", joint="shoulder", type="revolute", parent="base", offset=0.05,
                  axis="0 1 0", effort="<effort>50</effort>")
    + LINK.format(name="fore", joint="elbow", type="revolute", parent="upper", offset=0.3,
                  axis="0 1 0", effort="")
    + LINK.format(name="hand", joint="spin", type="revolute", parent="fore", offset=0.3,
                  axis="0 0 1", effort="")
    + LINK.format(name="slider", joint="slide", type="prismatic", parent="hand", offset=0.3,
                  axis="1 0 0", effort="")
    + LINK.format(name="tip", joint="push", type="prismatic", parent="slider", offset=0.3,
                  axis="0 0 1", effort="")
    + """
    <plugin filename="gz-sim-joint-position-controller-system"
            name="gz::sim::systems::JointPositionController">
      <joint_name>shoulder</joint_name>
      <topic>/arm/shoulder</topic>
      <p_gain>300</p_gain>
      <i_gain>0.5</i_gain>
      <d_gain>20</d_gain>
      <cmd_max>40</cmd_max>
      <cmd_min>-40</cmd_min>
    </plugin>
    <plugin filename="ignition-gazebo-joint-position-controller-system"
            name="ignition::gazebo::systems::JointPositionController">
      <joint_name>elbow</joint_name>
      <p_gain>100</p_gain>
    </plugin>
    <plugin filename="gz-sim-joint-controller-system" name="gz::sim::systems::JointController">
      <joint_name>spin</joint_name>
    </plugin>
    <plugin filename="gz-sim-joint-controller-system" name="gz::sim::systems::JointController">
      <joint_name>slide</joint_name>
      <use_force_commands>true</use_force_commands>
      <p_gain>5</p_gain>
      <cmd_max>10</cmd_max>
      <cmd_min>-10</cmd_min>
    </plugin>
    <plugin filename="gz-sim-apply-joint-force-system" name="gz::sim::systems::ApplyJointForce">
      <joint_name>push</joint_name>
    </plugin>
    <plugin filename="gz-sim-joint-state-publisher-system" name="gz::sim::systems::JointStatePublisher"/>
  </model>
</sdf>
"""
)


def _write_text(folder: Path, name: str, text: str) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / name
    path.write_text(text)
    return path


def _plugins(path: Path) -> list[ET.Element]:
    model = ET.parse(path).getroot().find("model")
    assert model is not None
    return list(model.iter("plugin"))


def _by_joint(path: Path) -> dict[str, ET.Element]:
    return {p.findtext("joint_name", ""): p for p in _plugins(path) if p.find("joint_name") is not None}


def _kinds(robot: Robot) -> dict[str, ActuatorKind]:
    return {a.joint: a.kind for a in robot.actuators}


def _codes(notes: list[ConversionNote], code: str) -> list[str]:
    return [n.message for n in notes if n.code == code]


def _drake_loads(path: Path) -> int:
    """Drake parses the file (it ignores <plugin> and <self_collide> with a warning): its joint count."""
    pytest.importorskip("pydrake")
    from pydrake.multibody.parsing import Parser
    from pydrake.multibody.plant import MultibodyPlant

    plant = MultibodyPlant(0.0)
    Parser(plant).AddModels(str(path))
    plant.Finalize()
    return int(plant.num_joints())


# -- reading -------------------------------------------------------------------------------------


def test_gz_sim_joint_controllers_are_read_as_actuators(tmp_path: Path) -> None:
    robot = load(_write_text(tmp_path, "arm.sdf", ARM))
    got = {a.joint: a for a in robot.actuators}
    assert list(got) == ["shoulder", "elbow", "spin", "slide", "push"]  # not the JointStatePublisher
    shoulder, elbow, spin, slide, push = got.values()
    # position PID: kp = p_gain, kv = d_gain (the error's rate is the joint velocity), force = the clamp
    assert (shoulder.kind, shoulder.kp, shoulder.kv, shoulder.force_range) == (
        ActuatorKind.POSITION, 300.0, 20.0, (-40.0, 40.0))
    # a gain the plugin leaves out is not gz-sim's default copied in: None (an ignition- file name too)
    assert (elbow.kind, elbow.kp, elbow.kv, elbow.force_range) == (ActuatorKind.POSITION, 100.0, None, None)
    assert (spin.kind, spin.kv, spin.source_kind) == (
        ActuatorKind.VELOCITY, None, "gz-sim JointController (velocity mode)")
    # force mode: a PID on the velocity error, kv = p_gain
    assert (slide.kind, slide.kv, slide.force_range) == (ActuatorKind.VELOCITY, 5.0, (-10.0, 10.0))
    assert push.kind is ActuatorKind.EFFORT
    assert robot.self_collide is True


def test_sdf_to_sdf_keeps_each_controller_whole(tmp_path: Path, sdf_oracle: Path) -> None:  # noqa: F811
    """Each written plugin has the source's file name, class and every parameter (topic, i_gain...),
    once; libsdformat accepts the file and the actuators read back equal."""
    source_path = _write_text(tmp_path, "arm.sdf", ARM)
    source = load(source_path)
    out = tmp_path / "out" / "arm.sdf"
    write(source, out)
    assert not oracle_has_errors(sdf_oracle, out)
    before, after = _by_joint(source_path), _by_joint(out)
    assert set(after) == set(before) == {"shoulder", "elbow", "spin", "slide", "push"}
    for joint, element in before.items():
        assert after[joint].attrib == element.attrib, joint
        assert [(c.tag, c.text) for c in after[joint]] == [(c.tag, c.text) for c in element], joint
    assert len(_plugins(out)) == 6  # the five and the JointStatePublisher, nothing twice
    again = {a.joint: (a.kind, a.kp, a.kv, a.force_range) for a in load(out).actuators}
    assert again == {a.joint: (a.kind, a.kp, a.kv, a.force_range) for a in source.actuators}
    assert _drake_loads(out) == 6  # the world weld and five joints


def test_a_plugin_for_several_joints_is_one_actuator_each(tmp_path: Path) -> None:
    """gz-sim's JointPositionController takes several <joint_name>s ("identical joints"): one actuator
    each, written back as one plugin each with the plugin's other parameters."""
    text = ARM.replace("<joint_name>elbow</joint_name>",
                       "<joint_name>elbow</joint_name><joint_name>nowhere</joint_name>"
                       "<joint_name>spin</joint_name><topic>/both</topic>")
    robot = load(_write_text(tmp_path, "arm.sdf", text))
    got = {a.joint: a for a in robot.actuators}
    assert (got["elbow"].kind, got["spin"].kind) == (ActuatorKind.POSITION, ActuatorKind.POSITION)
    assert got["spin"].kp == 100.0  # the first plugin naming a joint wins (the JointController comes later)
    out = tmp_path / "out" / "arm.sdf"
    write(robot, out)
    spin = [p for p in _plugins(out) if p.findtext("joint_name") == "spin"]
    # the source's own JointController on spin is copied as it was (both act in gz-sim, as in the source)
    assert [p.get("filename") for p in spin] == ["ignition-gazebo-joint-position-controller-system",
                                                 "gz-sim-joint-controller-system"]
    kept = [(c.tag, c.text) for c in spin[0]]
    assert kept == [("joint_name", "spin"), ("topic", "/both"), ("p_gain", "100")]  # the source's order


# -- other formats to SDF and back ---------------------------------------------------------------


def test_urdf_actuators_become_gz_sim_systems(tmp_path: Path, sdf_oracle: Path) -> None:  # noqa: F811
    """URDF transmissions and ros2_control → SDF: effort → ApplyJointForce, velocity → JointController
    in force mode, position → JointPositionController; gains made up by the MJCF writer's rule (MK840),
    clamps = the effort limits; read back as the same kinds; libsdformat and Drake load it. With
    ``--source-actuators keep``: the default makes the ROS effort interface a servo (the next test)."""
    source = load(_write_text(tmp_path, "two.urdf", URDF))
    out = tmp_path / "out" / "two.sdf"
    notes = write(source, out, options=WriteOptions(source_actuators="keep"))
    assert not oracle_has_errors(sdf_oracle, out)
    plugins = _by_joint(out)
    assert {j: p.get("name") for j, p in plugins.items()} == {
        "j1": "gz::sim::systems::ApplyJointForce",
        "j2": "gz::sim::systems::JointController",
        "j3": "gz::sim::systems::JointPositionController",
    }
    assert plugins["j2"].findtext("use_force_commands") == "true"
    j3 = plugins["j3"]
    assert (j3.findtext("i_gain"), j3.findtext("cmd_max"), j3.findtext("cmd_min")) == ("0", "10", "-10")
    made_up = _codes(notes, "MK840")
    assert len(made_up) == 1 and "j2 kv" in made_up[0] and "j3 kp" in made_up[0]
    back = load(out)
    assert _kinds(back) == _kinds(source)
    got = {a.joint: a for a in back.actuators}
    assert float(j3.findtext("p_gain") or 0) == got["j3"].kp > 0.0
    assert got["j3"].force_range == (-10.0, 10.0)
    assert _drake_loads(out) == 4  # --base auto welds the arm: the world joint and three
    transmissions = [m for m in _codes(notes, "MK808") if "<transmission>" in m]
    assert transmissions and all("written as gz-sim joint controllers" in m for m in transmissions)


def test_ros_effort_interfaces_become_position_controllers(tmp_path: Path) -> None:
    """``--source-actuators auto`` (the default), as in MJCF (MK864): a URDF's ROS effort interface on a
    joint the ``--actuators`` choice servos is written as a JointPositionController, keeping the effort
    limit as its clamp. example-robot-data's Kinova (6 EffortJointInterface transmissions) held by
    nothing in gz-sim before (ApplyJointForce at zero force); a servo each now."""
    source = load(_write_text(tmp_path, "two.urdf", URDF))
    out = tmp_path / "out" / "two.sdf"
    notes = write(source, out)
    plugins = _by_joint(out)
    assert plugins["j1"].get("name") == "gz::sim::systems::JointPositionController"
    (said,) = _codes(notes, "MK864")
    assert "1 joint(s) (j1)" in said and "1 JointPositionController" in said
    kinova = load(example_robot("kinova_description/robots/kinova.urdf"))
    out = tmp_path / "kinova" / "kinova.sdf"
    write(kinova, out)
    assert {p.get("name") for p in _by_joint(out).values()} == {"gz::sim::systems::JointPositionController"}
    assert len(_by_joint(out)) == 6
    kept = tmp_path / "kept" / "kinova.sdf"
    write(kinova, kept, options=WriteOptions(source_actuators="keep"))
    assert {p.get("name") for p in _by_joint(kept).values()} == {"gz::sim::systems::ApplyJointForce"}


def test_load_bearing_joints_the_source_leaves_unactuated_get_controllers(tmp_path: Path) -> None:
    """example-robot-data's ANYmal-Kinova names the arm's 6 transmissions only: as in MJCF (MK827), its
    12 leg joints get JointPositionControllers in SDF (they had none: the robot folded onto the floor),
    and the arm's effort interfaces are servos too (MK864)."""
    source = load(example_robot("anymal_b_simple_description/robots/anymal-kinova.urdf"))
    out = tmp_path / "out" / "anymal-kinova.sdf"
    notes = write(source, out)
    plugins = _by_joint(out)
    assert {p.get("name") for p in plugins.values()} == {"gz::sim::systems::JointPositionController"}
    legs = {f"{leg}_{joint}" for leg in ("LF", "RF", "LH", "RH") for joint in ("HAA", "HFE", "KFE")}
    assert legs < set(plugins) and len(plugins) == 18
    (filled,) = _codes(notes, "MK827")
    assert "12 joint(s)" in filled and "12 in legs" in filled and "JointPositionController" in filled
    kept = tmp_path / "kept" / "anymal-kinova.sdf"
    write(source, kept, options=WriteOptions(source_actuators="keep"))
    assert not legs & set(_by_joint(kept))


def test_replace_sets_the_sources_controllers_aside(tmp_path: Path) -> None:
    """``--source-actuators replace``: the SDF arm's five controllers are set aside (MK855) and every
    joint gets the ``--actuators`` choice: on the welded arm, position controllers with the rule's
    gains, none of the source's topics or gains kept."""
    source = load(_write_text(tmp_path, "arm.sdf", ARM))
    out = tmp_path / "out" / "arm.sdf"
    notes = write(source, out, options=WriteOptions(source_actuators="replace"))
    plugins = _by_joint(out)
    assert {p.get("name") for p in plugins.values()} == {"gz::sim::systems::JointPositionController"}
    assert sorted(plugins) == ["elbow", "push", "shoulder", "slide", "spin"]
    assert plugins["shoulder"].findtext("topic") is None and plugins["shoulder"].findtext("p_gain") != "300"
    assert len(_codes(notes, "MK855")) == 1 and "actuators set aside" in _codes(notes, "MK841")[0]


def test_body_actuation_mode_reaches_sdf(tmp_path: Path) -> None:
    extra = "    actuation_mode: joint_displacement\n"
    source = load(_write_text(tmp_path, "pendulum.body",
                              PENDULUM_BODY.replace("    joint_id: 0\n", "    joint_id: 0\n" + extra)))
    out = tmp_path / "out" / "pendulum.sdf"
    notes = write(source, out)
    joint = renames(notes, "joint").get("ARM")  # SDF forbids the joint the name of its link ARM
    assert joint == "ARM_joint"
    assert _kinds(load(out)) == {joint: ActuatorKind.POSITION}
    body = tmp_path / "back" / "pendulum.body"
    write(load(out), body)
    assert _kinds(load(body)) == {joint: ActuatorKind.POSITION}


def test_mjcf_actuators_through_sdf_keep_gains_and_say_what_is_lost(tmp_path: Path) -> None:
    """MJCF → SDF → MJCF: position kp/kv/forcerange and velocity kv survive; a motor's gear and the
    ctrlranges have no gz-sim parameter (MK844 names them)."""
    source = load(_write_text(tmp_path, "four.xml", MJCF))
    out = tmp_path / "sdf" / "four.sdf"
    notes = write(source, out)
    (lost,) = _codes(notes, "MK844")
    assert "j3 (gear 2, ctrlrange -1 1)" in lost and "j1 (ctrlrange -1 1)" in lost
    middle = {a.joint: (a.kind, a.kp, a.kv, a.force_range) for a in load(out).actuators}
    assert middle == {
        "j1": (ActuatorKind.POSITION, 100.0, 5.0, (-20.0, 20.0)),
        "j2": (ActuatorKind.VELOCITY, None, 3.0, None),
        "j3": (ActuatorKind.EFFORT, None, None, None),
        "j4": (ActuatorKind.POSITION, 50.0, 4.0, None),
    }
    back = tmp_path / "mjcf" / "four.xml"
    write(load(out), back)
    section = ET.parse(back).getroot().find("actuator")
    assert section is not None
    assert {el.get("joint"): el.tag for el in section} == {
        "j1": "position", "j2": "velocity", "j3": "motor", "j4": "position"}


def test_gazebo_classic_leaves_the_systems_out(tmp_path: Path) -> None:
    source = load(_write_text(tmp_path, "two.urdf", URDF))
    out = tmp_path / "out" / "two.sdf"
    notes = write(source, out, options=WriteOptions(gazebo="classic"))
    assert _plugins(out) == []
    assert any("3 actuator(s)" in m and "Gazebo classic" in m for m in _codes(notes, "MK808"))


# -- a source without actuators: the --actuators choice, as for MJCF ----------------------------------

BARE_ARM = """<?xml version="1.0"?>
<robot name="bare">
  <link name="base"><inertial><mass value="2"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="upper"><inertial><origin xyz="0 0 0.15"/><mass value="1"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="fore"><inertial><origin xyz="0 0 0.15"/><mass value="1"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="finger"><inertial><mass value="0.1"/>
    <inertia ixx="1e-4" iyy="1e-4" izz="1e-4" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="twin"><inertial><mass value="0.1"/>
    <inertia ixx="1e-4" iyy="1e-4" izz="1e-4" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/>
    <origin xyz="0 0 0.05"/><axis xyz="0 1 0"/><limit lower="-2" upper="2" effort="50" velocity="1"/></joint>
  <joint name="elbow" type="revolute"><parent link="upper"/><child link="fore"/>
    <origin xyz="0 0 0.3"/><axis xyz="0 1 0"/><limit lower="0.5" upper="2" effort="30" velocity="1"/></joint>
  <joint name="grip" type="prismatic"><parent link="fore"/><child link="finger"/>
    <origin xyz="0 0 0.3"/><axis xyz="1 0 0"/><limit lower="0" upper="0.04" effort="20" velocity="1"/></joint>
  <joint name="grip_twin" type="prismatic"><parent link="fore"/><child link="twin"/>
    <origin xyz="0 0 0.3"/><axis xyz="-1 0 0"/><limit lower="0" upper="0.04" effort="20" velocity="1"/>
    <mimic joint="grip"/></joint>
</robot>
"""


def test_a_source_without_actuators_gets_the_choice_as_gz_sim_systems(tmp_path: Path,
                                                                     sdf_oracle: Path) -> None:  # noqa: F811
    """A URDF arm without transmissions → SDF: --actuators auto puts a JointPositionController on every
    joint of the welded arm but the mimic follower, with the MJCF rule's gains and, where the home pose
    is not 0 (the elbow's range starts at 0.5), gz-sim's ``initial_position``; libsdformat accepts the
    file, and it reads back as position actuators on the same joints. The gains are the ones the MJCF
    output gets for the same joints (but for a mimic's leader, whose MJCF servo also moves the coupling
    armature MuJoCo needs, MK835)."""
    source = load(_write_text(tmp_path, "bare.urdf", BARE_ARM))
    out = tmp_path / "out" / "bare.sdf"
    notes = write(source, out)
    assert not oracle_has_errors(sdf_oracle, out)
    plugins = _by_joint(out)
    assert {j: p.get("name") for j, p in plugins.items()} == {
        name: "gz::sim::systems::JointPositionController" for name in ("shoulder", "elbow", "grip")}
    assert plugins["elbow"].findtext("initial_position") == "0.5"
    assert plugins["shoulder"].findtext("initial_position") is None  # home 0: gz-sim's default
    assert (plugins["elbow"].findtext("cmd_max"), plugins["elbow"].findtext("cmd_min")) == ("30", "-30")
    (chosen,) = _codes(notes, "MK841")
    assert "3 JointPositionController system(s)" in chosen and "--actuators auto" in chosen
    assert len(_codes(notes, "MK840")) == 1
    assert _kinds(load(out)) == {name: ActuatorKind.POSITION for name in ("shoulder", "elbow", "grip")}
    mjcf = tmp_path / "mjcf" / "bare.xml"
    write(source, mjcf)
    servos = {el.get("joint"): el for el in ET.parse(mjcf).getroot().iter("position")}
    for name in ("shoulder", "elbow"):  # grip leads a mimic: MuJoCo's coupling armature raises its gains
        got = float(plugins[name].findtext("p_gain") or 0)
        assert got == pytest.approx(float(servos[name].get("kp") or 0), rel=1e-6), name


@pytest.mark.parametrize(("choice", "system"), [("motor", "ApplyJointForce"), ("velocity", "JointController"),
                                                ("none", None)])
def test_the_actuators_option_chooses_the_systems(tmp_path: Path, choice: str, system: str | None) -> None:
    source = load(_write_text(tmp_path, "bare.urdf", BARE_ARM))
    out = tmp_path / "out" / "bare.sdf"
    notes = write(source, out, options=WriteOptions(actuators=choice))
    plugins = _by_joint(out)
    if system is None:
        assert plugins == {} and _codes(notes, "MK841") == []
        return
    assert {p.get("name") for p in plugins.values()} == {f"gz::sim::systems::{system}"}
    assert sorted(plugins) == ["elbow", "grip", "shoulder"]


def test_wheels_the_drive_system_drives_get_no_controller(tmp_path: Path) -> None:
    """The tutorial's pan-tilt robot → SDF: its wheels are the DiffDrive system's (MK858); the pan and
    tilt joints, without a range on a free base, get ApplyJointForce (zero force leaves them free), as
    the MJCF gets <motor>s; Gazebo classic gets none."""
    tutorial = Path(__file__).resolve().parents[1] / "samples" / "choreonoid_ros2_mobile_robot_tutorial"
    source = load(tutorial / "model" / "mobile_robot_pantilt.body")
    out = tmp_path / "sim" / "robot.sdf"
    notes = write(source, out)
    plugins = _by_joint(out)
    assert {j: p.get("name") for j, p in plugins.items()} == {
        "PanJoint": "gz::sim::systems::ApplyJointForce", "TiltJoint": "gz::sim::systems::ApplyJointForce"}
    assert any(p.get("name") == "gz::sim::systems::DiffDrive" for p in _plugins(out))
    (chosen,) = _codes(notes, "MK841")
    assert "the wheels LeftWheel, RightWheel are the DiffDrive system's" in chosen
    classic = tmp_path / "classic" / "robot.sdf"
    write(source, classic, options=WriteOptions(gazebo="classic"))
    assert _by_joint(classic) == {}


# -- self-collision --------------------------------------------------------------------------------


def _flags(path: Path) -> tuple[str | None, dict[str, str]]:
    model = ET.parse(path).getroot().find("model")
    assert model is not None
    links = {link.get("name", ""): link.findtext("self_collide", "") for link in model.findall("link")}
    return model.findtext("self_collide"), {k: v for k, v in links.items() if v}


def test_panda_self_collision_follows_the_mjcf_excludes(tmp_path: Path, sdf_oracle: Path) -> None:  # noqa: F811
    """Panda touches itself at rest in 3 pairs (MuJoCo, MK832). SDF cannot exclude a pair: the links of
    those pairs are left unflagged, every other link with collision shapes gets <self_collide>, and the
    model flag stays off. libsdformat accepts it, Drake loads it."""
    panda = load(example_robot("panda_description/urdf/panda.urdf"))
    mjcf = tmp_path / "mjcf" / "panda.xml"
    write(panda, mjcf)
    contact = ET.parse(mjcf).getroot().find("contact")
    assert contact is not None
    excluded = {(e.get("body1"), e.get("body2")) for e in contact.iter("exclude")}
    assert len(excluded) == 3
    out = tmp_path / "sdf" / "panda.sdf"
    notes = write(panda, out)
    assert not oracle_has_errors(sdf_oracle, out)
    model_flag, links = _flags(out)
    assert model_flag is None
    touching = {name for pair in excluded for name in pair}
    shaped = {link.name for link in panda.links if link.collisions}
    assert links == dict.fromkeys(shaped - touching, "true")
    assert len(links) == 6
    (note,) = _codes(notes, "MK834")
    assert note.startswith("3 link pair(s) touch at rest") and "gz-sim reads only the model's flag" in note
    assert _drake_loads(out) > 0


def test_arm_that_touches_nothing_gets_the_model_flag(tmp_path: Path) -> None:
    """UR5 flags its links itself (``<gazebo><selfCollide>``): kept. Without them, nothing touches at
    rest and the model flag says it all."""
    ur5 = load(example_robot("ur_description/urdf/ur5_robot.urdf"))
    out = tmp_path / "own" / "ur5.sdf"
    notes = write(ur5, out)
    own = {"shoulder_link", "upper_arm_link", "forearm_link", "wrist_1_link", "wrist_2_link", "wrist_3_link",
           "ee_link"}
    assert _flags(out) == (None, dict.fromkeys(own, "true"))
    assert _codes(notes, "MK834") == []
    assert not [m for m in _codes(notes, "MK808") if "extension of link" in m]  # selfCollide is all they say
    for link in ur5.links:
        link.extras.pop("gazebo", None)
        link.self_collide = None  # the flag the reader took from the block
    out = tmp_path / "policy" / "ur5.sdf"
    notes = write(ur5, out)
    assert _flags(out) == ("true", {})
    assert any("no two links touch at rest" in m for m in _codes(notes, "MK834"))


def test_an_sdf_sources_own_flags_are_kept(tmp_path: Path) -> None:
    source = load(_write_text(tmp_path, "arm.sdf", ARM))
    out = tmp_path / "out" / "arm.sdf"
    notes = write(source, out)
    assert _flags(out) == ("true", {"base": "false"})
    assert _codes(notes, "MK834") == []


# -- self-collision in URDF: what libsdformat's URDF import (Gazebo's reader) makes of it ----------

FLAGS_SOURCE = r"""
#include <iostream>
#include <sdf/sdf.hh>
// Prints the self_collide flags libsdformat gives the model and each link of a file (a URDF is
// converted as Gazebo converts it).
int main(int argc, char **argv) {
  sdf::Root root;
  sdf::Errors errors = root.Load(argv[1]);
  if (!errors.empty() || root.Model() == nullptr) { std::cout << "error\n"; return 1; }
  const sdf::Model *model = root.Model();
  std::cout << "model " << model->SelfCollide() << "\n";
  for (uint64_t i = 0; i < model->LinkCount(); ++i) {
    const sdf::Link *link = model->LinkByIndex(i);
    std::cout << link->Name() << " " << link->Element()->Get<bool>("self_collide") << "\n";
  }
  return 0;
}
"""


@pytest.fixture(scope="module")
def sdf_flags(sdf_oracle: Path) -> Path:  # noqa: F811 (libsdformat present: the oracle compiled)
    import hashlib
    import subprocess

    flags = subprocess.run(["pkg-config", "--cflags", "--libs", "sdformat12"], capture_output=True,
                           text=True, check=True).stdout.split()
    digest = hashlib.sha256((FLAGS_SOURCE + " ".join(flags)).encode()).hexdigest()[:16]
    binary = sdf_oracle.parent / f"sdf_flags-{digest}"
    if not binary.exists():
        source = binary.with_suffix(".cc")
        source.write_text(FLAGS_SOURCE)
        partial = binary.with_name(f"{binary.name}.{os.getpid()}")
        subprocess.run(["g++", "-O0", "-o", str(partial), str(source), *flags], check=True)
        partial.replace(binary)
    return binary


def _libsdformat_flags(binary: Path, path: Path) -> tuple[bool, set[str]]:
    """(the model's flag, the links flagged) as libsdformat converts the file."""
    import subprocess

    run = subprocess.run([str(binary), path.name], cwd=path.parent, capture_output=True, text=True,
                         timeout=60)
    assert run.returncode == 0, run.stdout + run.stderr
    lines = [line.rsplit(" ", 1) for line in run.stdout.splitlines()]
    model = dict(lines)["model"] == "1"
    return model, {name for name, value in lines if name != "model" and value == "1"}


def test_urdf_self_collision_reaches_gazebo_through_libsdformat(tmp_path: Path, sdf_flags: Path) -> None:
    """Panda → URDF: libsdformat's URDF import (Gazebo's) flags the 6 links that touch nothing and not
    the model; UR5 → URDF: the model flag. The MK834 note tells PyBullet users the flag and the pairs."""
    panda = load(example_robot("panda_description/urdf/panda.urdf"))
    panda.source_format = "mjcf"  # a URDF source keeps its own <gazebo> blocks: judge the policy itself
    out = tmp_path / "panda" / "panda.urdf"
    notes = write(panda, out)
    model, links = _libsdformat_flags(sdf_flags, out)
    touching = {"panda_link5", "panda_link7", "panda_hand", "panda_leftfinger", "panda_rightfinger"}
    assert not model
    assert links == {link.name for link in panda.links if link.collisions} - touching
    (note,) = _codes(notes, "MK834")
    assert "URDF_USE_SELF_COLLISION" in note and "panda_leftfinger/panda_rightfinger" in note
    ur5 = load(example_robot("ur_description/urdf/ur5_robot.urdf"))
    out = tmp_path / "ur5" / "ur5.urdf"
    write(ur5, out)  # ur_description flags its 7 links itself: kept as they are
    own = {"shoulder_link", "upper_arm_link", "forearm_link", "wrist_1_link", "wrist_2_link", "wrist_3_link",
           "ee_link"}
    assert _libsdformat_flags(sdf_flags, out) == (False, own - {"ee_link"})  # lumped into wrist_3_link
    ur5.source_format = "mjcf"
    for link in ur5.links:
        link.extras.pop("gazebo", None)
        link.self_collide = None  # the flag the reader took from the block
    out = tmp_path / "ur5_policy" / "ur5.urdf"
    write(ur5, out)  # the policy: nothing touches at rest, so the model's flag
    assert _libsdformat_flags(sdf_flags, out) == (True, set())


def test_sdf_flags_reach_urdf_and_come_back(tmp_path: Path, sdf_flags: Path) -> None:
    source = load(_write_text(tmp_path, "arm.sdf", ARM))
    out = tmp_path / "out" / "arm.urdf"
    notes = write(source, out)
    assert _libsdformat_flags(sdf_flags, out) == (True, set())  # base's explicit false is the default
    assert not [m for m in _codes(notes, "MK808") if "self_collide" in m]
    back = tmp_path / "back" / "arm.urdf"
    again = write(load(out), back)
    assert _libsdformat_flags(sdf_flags, back) == (True, set())  # a URDF's own blocks are kept as such
    assert _codes(again, "MK834") == []


def test_pybullet_with_its_flag_excludes_parent_and_child(tmp_path: Path) -> None:
    """What the MK834 note tells PyBullet users, measured: loaded with URDF_USE_SELF_COLLISION, a link
    overlapping its parent makes no contact, one overlapping its grandparent does (MuJoCo's rule)."""
    pybullet = pytest.importorskip("pybullet")
    box = '<box size="0.2 0.2 0.2"/>'
    inertial = ('<inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" '
                'iyz="0"/></inertial>')
    links = "".join(f'<link name="{n}">{inertial}<collision><origin xyz="0 0 {z}"/><geometry>{box}</geometry>'
                    "</collision></link>" for n, z in (("a", 0), ("b", 0), ("c", -0.1)))
    joints = "".join(f'<joint name="{j}" type="revolute"><parent link="{p}"/><child link="{c}"/>'
                     f'<origin xyz="0 0 {z}"/><axis xyz="0 0 1"/>'
                     '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint>'
                     for j, p, c, z in (("j", "a", "b", 0.1), ("k", "b", "c", 0.0)))
    path = _write_text(tmp_path, "chain.urdf", f'<robot name="chain">{links}{joints}</robot>')
    client = pybullet.connect(pybullet.DIRECT)
    try:
        found = {}
        for label, flags in (("off", 0), ("on", pybullet.URDF_USE_SELF_COLLISION)):
            body = pybullet.loadURDF(str(path), useFixedBase=1, flags=flags, physicsClientId=client)
            pybullet.performCollisionDetection(physicsClientId=client)
            contacts = pybullet.getContactPoints(body, body, physicsClientId=client)
            found[label] = {(c[3], c[4]) for c in contacts}
            pybullet.removeBody(body, physicsClientId=client)
    finally:
        pybullet.disconnect(client)
    assert found == {"off": set(), "on": {(1, -1)}}  # c (link 1) with a (the base), never b with a or c


def test_gains_are_made_for_the_masses_the_sdf_holds(tmp_path: Path) -> None:
    """A kinematic-only arm is written with 1e-6 kg per massless link (MK816); its joint controllers'
    gains are made for that mass, as the MJCF's are, not for none (the massless floor, 1e-6 kg·m²)."""
    links = "".join(f'<link name="l{i}"/>' for i in range(4))
    joints = "".join(
        f'<joint name="j{i}" type="revolute"><parent link="l{i - 1}"/><child link="l{i}"/>'
        f'<origin xyz="{0.5 if i > 1 else 0} 0 0.1"/><axis xyz="0 1 0"/>'
        '<limit lower="-2" upper="2" effort="10" velocity="2"/></joint>' for i in range(1, 4))
    transmissions = "".join(
        f'<transmission name="t{i}"><type>transmission_interface/SimpleTransmission</type>'
        f'<joint name="j{i}"><hardwareInterface>hardware_interface/PositionJointInterface</hardwareInterface>'
        '</joint></transmission>' for i in range(1, 4))
    text = f'<robot name="bare">{links}{joints}{transmissions}</robot>'
    source = load(_write_text(tmp_path, "bare.urdf", text))
    out = tmp_path / "out" / "bare.sdf"
    write(source, out)
    shoulder = float(_by_joint(out)["j1"].findtext("p_gain") or 0)
    # j1 carries two 1e-6 kg links 0.5 m and 1 m out: 1.5e-5 N·m of gravity at 1 m reach, held within
    # SAG_PER_JOINT (1e-4 m) by kp ≥ τ·R / 1e-4 = 0.147 (or the 80 Hz ceiling on 1.25e-6 kg·m²: 0.316)
    assert 0.145 < shoulder <= 0.317, shoulder  # without the written masses: the floor's 0.0355
