"""URDF → SDF writes a link's ``<gazebo reference>`` tags as the SDF elements libsdformat's own URDF
parser makes of them (:mod:`modelkit.formats.sdf.write_gazebo_tags`). Before, only ``mu1``/``mu2``,
``selfCollide`` and sensors were carried and the rest of the block was dropped ("not carried over").
Oracle: libsdformat 12's URDF to SDF conversion of the same file (``sdf_check --print``)."""

from __future__ import annotations

import contextlib
import subprocess
from pathlib import Path

from lxml import etree

from modelkit.convert.api import convert
from tests.test_sdf_reader import sdf_oracle  # noqa: F401 (the fixture)

URDF = """<?xml version="1.0"?>
<robot name="gz">
  <link name="base">
    <inertial><mass value="2"/><inertia ixx="0.02" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.02"/></inertial>
    <collision><geometry><box size="0.2 0.2 0.1"/></geometry></collision>
  </link>
  <link name="arm">
    <inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.001"/></inertial>
    <visual><geometry><cylinder radius="0.02" length="0.2"/></geometry></visual>
    <collision><geometry><cylinder radius="0.02" length="0.2"/></geometry></collision>
  </link>
  <joint name="j" type="revolute"><parent link="base"/><child link="arm"/><origin xyz="0 0 0.1"/>
    <axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="10" velocity="2"/></joint>
  <gazebo reference="arm"><mu1>0.5</mu1><mu2>0.5</mu2><kp>1e5</kp><kd>10</kd><maxVel>0.1</maxVel>
    <minDepth>0.001</minDepth><fdir1>1 0 0</fdir1><maxContacts>4</maxContacts><laserRetro>50</laserRetro>
    <material>Gazebo/Red</material><turnGravityOff>true</turnGravityOff><kinematic>1</kinematic>
    <dampingFactor>0.05</dampingFactor><plugin name="p" filename="libp.so"/></gazebo>
</robot>
"""
PATHS = ("gravity", "kinematic", "velocity_decay/linear", "velocity_decay/angular",
         "collision/max_contacts", "collision/laser_retro", "collision/surface/contact/ode/kp",
         "collision/surface/contact/ode/kd", "collision/surface/contact/ode/max_vel",
         "collision/surface/contact/ode/min_depth", "collision/surface/friction/ode/fdir1",
         "visual/material/script/name", "visual/material/script/uri")


FLAGS = frozenset({"gravity", "kinematic", "physics/provide_feedback", "physics/ode/provide_feedback",
                   "physics/ode/implicit_spring_damper", "physics/ode/cfm_damping"})


def _values(sdf: str, tag: str, name: str, paths: tuple[str, ...]) -> dict[str, str]:
    """The text at each path below the element ``tag`` named ``name``, normalised: a flag's true and 1
    are the same, as are the numbers 1e5 and 100000."""
    element = next(el for el in etree.fromstring(sdf.encode()).iter(tag) if el.get("name") == name)
    out = {}
    for path in paths:
        found = element.find(path)
        assert found is not None, path
        text = " ".join((found.text or "").split())
        if path in FLAGS:
            text = "true" if text in ("true", "1") else "false"
        else:
            with contextlib.suppress(ValueError):
                text = repr(float(text))
        out[path] = text
    return out


def _ours_and_libsdformats(tmp_path: Path, urdf: str, oracle: Path) -> tuple[list[str], str, str]:
    """The notes and SDF of ``convert`` for ``urdf``, and libsdformat's own conversion of it."""
    source = tmp_path / "gz.urdf"
    source.write_text(urdf)
    out = tmp_path / "out" / "gz.sdf"
    notes = [n.message for n in convert([source], out).notes if n.code == "MK808"]
    theirs = subprocess.run([str(oracle), "--print", source.name], cwd=tmp_path, capture_output=True,
                            text=True, timeout=60, check=True).stdout
    return notes, out.read_text(), theirs


def test_gazebo_link_tags_are_the_sdf_libsdformat_makes(tmp_path: Path, sdf_oracle: Path) -> None:  # noqa: F811
    notes, ours_text, theirs = _ours_and_libsdformats(tmp_path, URDF, sdf_oracle)
    ours = _values(ours_text, "link", "arm", PATHS)
    assert ours == _values(theirs, "link", "arm", PATHS)
    assert ours["gravity"] == "false" and ours["collision/max_contacts"] == "4.0"
    left = [n for n in notes if "<gazebo> extension" in n]
    assert len(left) == 1 and "<plugin> not carried over" in left[0], left


JOINT_URDF = URDF.replace("<dampingFactor>0.05</dampingFactor>", "").replace(
    "</robot>", """  <gazebo reference="j"><provideFeedback>true</provideFeedback>
    <implicitSpringDamper>1</implicitSpringDamper><stopCfm>0.01</stopCfm><stopErp>0.3</stopErp><fudgeFactor>0.5</fudgeFactor><cfmDamping>true</cfmDamping>
    <springStiffness>5</springStiffness><springReference>0.2</springReference><other>1</other></gazebo>
</robot>""")
JOINT_PATHS = ("physics/provide_feedback", "physics/ode/implicit_spring_damper", "physics/ode/cfm_damping",
               "physics/ode/fudge_factor",
               "physics/ode/limit/cfm", "physics/ode/limit/erp", "axis/dynamics/spring_stiffness",
               "axis/dynamics/spring_reference")


def test_gazebo_joint_tags_are_the_sdf_libsdformat_makes(tmp_path: Path, sdf_oracle: Path) -> None:  # noqa: F811
    notes, ours, theirs = _ours_and_libsdformats(tmp_path, JOINT_URDF, sdf_oracle)
    assert _values(ours, "joint", "j", JOINT_PATHS) == _values(theirs, "joint", "j", JOINT_PATHS)
    # libsdformat also writes <physics><ode><provide_feedback>, which SDFormat 1.9 does not define and
    # Drake refuses: ours leaves it out, and Drake loads the file
    assert _values(theirs, "joint", "j", ("physics/ode/provide_feedback",)) == {
        "physics/ode/provide_feedback": "true"}
    joint = next(el for el in etree.fromstring(ours.encode()).iter("joint") if el.get("name") == "j")
    assert joint.find("physics/ode/provide_feedback") is None
    from pydrake.multibody.parsing import Parser
    from pydrake.multibody.plant import MultibodyPlant

    plant = MultibodyPlant(time_step=0.0)
    assert Parser(plant).AddModels(file_name=str(tmp_path / "out" / "gz.sdf"))
    said = [n for n in notes if "joint" in n and "<gazebo>" in n]
    assert said == ['<gazebo> extension of joint "j": <other> not carried over'], said


BLOB_URDF = """<?xml version="1.0"?>
<robot name="blobs">
  <material name="blue"><color rgba="0 0 1 1"/></material>
  <link name="base">
    <inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
    <visual><geometry><box size="0.1 0.1 0.1"/></geometry><material name="blue"/></visual>
    <visual><origin xyz="0 0 0.1"/><geometry><sphere radius="0.05"/></geometry></visual>
    <collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision>
    <collision><origin xyz="0 0 0.1"/><geometry><sphere radius="0.05"/></geometry></collision>
  </link>
  <gazebo reference="base">
    <visual>
      <material><ambient>1 0 0 1</ambient><diffuse>1 0 0 1</diffuse>
        <specular>0.5 0.5 0.5 1</specular></material>
      <transparency>0.3</transparency>
    </visual>
    <collision><surface><bounce><restitution_coefficient>0.5</restitution_coefficient></bounce></surface></collision>
    <mu1>0.7</mu1><kp>1000</kp><material>Gazebo/Red</material>
    <light name="lamp" type="point"><diffuse>1 1 1 1</diffuse></light>
    <enable_wind>true</enable_wind>
    <plugin name="p" filename="libp.so"/><implicitSpringDamper>1</implicitSpringDamper>
  </gazebo>
  <gazebo reference="base"><visual><cast_shadows>false</cast_shadows></visual></gazebo>
</robot>
"""


def _leaves(element: etree._Element, skip: tuple[str, ...] = ("pose", "geometry")) -> list[tuple[str, str]]:
    """Every element below ``element`` that holds a text, as (path, text), sorted; numbers normalised;
    the shape's own pose and geometry left out (they are the URDF's, compared elsewhere)."""
    out = []
    for leaf in element.iter():
        path = element.getroottree().getpath(leaf)[len(element.getroottree().getpath(element)) + 1:]
        path = "/".join(part.split("[")[0] for part in path.split("/"))
        text = " ".join((leaf.text or "").split())
        if not text or len(leaf) or path.split("/")[0] in skip:
            continue
        with contextlib.suppress(ValueError):
            text = " ".join(repr(float(v)) for v in text.split())
        out.append((path, text))
    return sorted(out)


def test_gazebo_visual_collision_and_link_blobs_are_where_libsdformat_puts_them(
    tmp_path: Path, sdf_oracle: Path  # noqa: F811
) -> None:
    notes, ours_text, theirs_text = _ours_and_libsdformats(tmp_path, BLOB_URDF, sdf_oracle)
    ours, theirs = (next(el for el in etree.fromstring(text.encode()).iter("link")
                         if el.get("name") == "base") for text in (ours_text, theirs_text))
    for kind in ("visual", "collision"):
        mine, libs = ours.findall(kind), theirs.findall(kind)
        assert len(mine) == len(libs) == 2
        for a, b in zip(mine, libs, strict=True):
            assert _leaves(a) == _leaves(b), kind
    visual = _leaves(ours.find("visual"))
    assert ("material/diffuse", "1.0 0.0 0.0 1.0") in visual and ("transparency", "0.3") in visual
    assert ("cast_shadows", "false") in visual and ("material/script/name", "Gazebo/Red") in visual
    collision = _leaves(ours.find("collision"))
    assert ("surface/bounce/restitution_coefficient", "0.5") in collision
    assert ("surface/friction/ode/mu", "0.7") in collision  # re-applied after the blob's surface
    assert ours.findtext("enable_wind") == theirs.findtext("enable_wind") == "true"
    light = _leaves(ours.find("light"), ())
    assert light == [("diffuse", "1.0 1.0 1.0 1.0")] and set(light) <= set(_leaves(theirs.find("light"), ()))
    assert ours.find("plugin") is None  # libsdformat copies it into the link, where Gazebo ignores it
    said = [n for n in notes if "<gazebo> extension" in n]
    assert len(said) == 1 and "<plugin>, <implicitSpringDamper> not carried over" in said[0], said
    assert "no link plugins" in said[0] and "<implicitSpringDamper> is a joint's tag" in said[0], said


def test_a_literal_self_collide_tag_is_the_links_flag_as_in_libsdformat(
    tmp_path: Path, sdf_oracle: Path  # noqa: F811
) -> None:
    """TIAGo Pro writes ``<self_collide>0</self_collide>`` (the SDF element, not ``selfCollide``) in a link's
    block: libsdformat copies it into the link. It was noted as "not carried over" and the link got the
    computed policy's flag (true) instead."""
    urdf = URDF.replace('<gazebo reference="arm">', '<gazebo reference="base"><self_collide>0</self_collide>'
                        '</gazebo>\n  <gazebo reference="arm">')
    notes, ours, theirs = _ours_and_libsdformats(tmp_path, urdf, sdf_oracle)
    flag = {text: next(el.findtext("self_collide") for el in etree.fromstring(text.encode()).iter("link")
                       if el.get("name") == "base") for text in (ours, theirs)}
    assert flag[ours] == "false" and flag[theirs] == "0"
    assert not [n for n in notes if "self_collide" in n], notes


MODEL_URDF = URDF.replace("</robot>", """  <ros2_control name="sys" type="system">
    <hardware><plugin>gz_ros2_control/GazeboSimSystem</plugin></hardware>
    <joint name="j"><command_interface name="position"/><state_interface name="position"/></joint>
  </ros2_control>
  <gazebo>
    <plugin filename="gz_ros2_control-system" name="gz_ros2_control::GazeboSimROS2ControlPlugin">
      <parameters>/tmp/controllers.yaml</parameters>
    </plugin>
    <plugin filename="libgazebo_ros_p3d.so" name="p3d"><body_name>base</body_name></plugin>
    <enable_wind>true</enable_wind>
    <weird>1</weird>
  </gazebo>
</robot>""")


def _model_children(sdf: str) -> dict[str, list[list[tuple[str, str]]]]:
    model = etree.fromstring(sdf.encode()).find("model")
    out: dict[str, list[list[tuple[str, str]]]] = {}
    for child in model:
        if child.tag in ("plugin", "enable_wind", "weird"):
            out.setdefault(child.tag, []).append(sorted(child.attrib.items()) + _leaves(child, ()))
    return out


def test_robot_level_gazebo_blocks_go_into_the_model_as_in_libsdformat(
    tmp_path: Path, sdf_oracle: Path  # noqa: F811
) -> None:
    """libsdformat copies a robot-level block's children into the model. A ros2_control plugin written
    this way drives the joints itself: no gz-sim joint controller beside it (MK878). A plugin of the
    other Gazebo (here a classic one, the file being written for Gazebo Sim) is named (MK848); an element
    an SDF model cannot hold is named (MK808)."""
    source = tmp_path / "gz.urdf"
    source.write_text(MODEL_URDF)
    out = tmp_path / "out" / "gz.sdf"
    notes = convert([source], out).notes
    theirs = subprocess.run([str(sdf_oracle), "--print", source.name], cwd=tmp_path, capture_output=True,
                            text=True, timeout=60, check=True).stdout
    ours, libs = _model_children(out.read_text()), _model_children(theirs)
    assert ours["plugin"] == [libs["plugin"][0]] and ours["enable_wind"] == libs["enable_wind"]
    assert "weird" not in ours and "weird" in libs
    said = {n.code: n.message for n in notes}
    assert "gz_ros2_control-system" in said["MK878"] and '"p3d" (libgazebo_ros_p3d.so)' in said["MK848"], said
    assert any(n.code == "MK808" and "<weird>" in n.message for n in notes)
    assert "JointPositionController" not in out.read_text()
    without = tmp_path / "plain.urdf"  # the same robot without the plugin: its actuator is a gz-sim servo
    without.write_text(MODEL_URDF.replace("gz_ros2_control-system", "libother.so").replace(
        "gz_ros2_control::GazeboSimROS2ControlPlugin", "other"))
    plain = tmp_path / "out2" / "plain.sdf"
    assert "MK878" not in {n.code for n in convert([without], plain).notes}
    assert "JointPositionController" in plain.read_text()
