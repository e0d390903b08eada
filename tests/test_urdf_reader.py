"""The URDF reader: what it puts in the model, where it says things are, and what it reports.

yourdfpy is the independent oracle for the kinematics of the corpus files; inertia rotation is
checked against a hand computation; the Choreonoid tutorial's URDF pins the link/joint name
collisions (MK211) by line and column.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from modelkit.api import validate
from modelkit.codes import CODES
from modelkit.diagnostics import DiagnosticSink, Severity, SourceLocation
from modelkit.formats import read_model
from modelkit.formats.common import ReadOptions
from modelkit.formats.urdf.reader import read_urdf, read_urdf_document
from modelkit.model import Box, Capsule, Cylinder, JointType, Mesh, Robot, Sphere
from modelkit.xmlsource import parse_xml_bytes

from .conftest import CORPUS

TUTORIAL_URDF = CORPUS / "choreonoid_ros2_mobile_robot_tutorial" / "model" / "mobile_robot_sensors.urdf"
CORPUS_URDFS = [*sorted((CORPUS / "urdf_tutorial" / "urdf").glob("0[1-7]*.urdf")), TUTORIAL_URDF]
CLEAN = Path(__file__).resolve().parent / "broken_urdf" / "support" / "clean.urdf"


def read(tmp_path: Path, text: str, name: str = "robot.urdf") -> tuple[Robot | None, list[str]]:
    """Read URDF text; the robot and the diagnostics as "CODE line:col message" strings."""
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    result = read_urdf(path, ReadOptions(check_resources=False), str(path))
    return result.robot, [
        f"{d.code} {d.location.line}:{d.location.col} {d.message}"
        for d in result.diagnostics
        if d.location is not None
    ]


def codes_of(path: Path) -> list[tuple[str, int, int, str]]:
    v = validate(path)
    return [
        (d.code, d.location.line if d.location else 0, d.location.col if d.location else 0, d.severity.value)
        for d in v.diagnostics
    ]


def robot_of(text: str) -> str:
    return f'<?xml version="1.0"?>\n<robot name="r">\n{text}\n</robot>\n'


MASS = '<inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>'


# ---- the corpus, against yourdfpy ------------------------------------------------------------


@pytest.mark.parametrize("path", CORPUS_URDFS, ids=[p.name for p in CORPUS_URDFS])
def test_corpus_against_yourdfpy(path: Path, corpus: Path) -> None:
    yourdfpy = pytest.importorskip("yourdfpy")
    result = read_model(path, ReadOptions(check_resources=False))
    robot = result.robot
    assert robot is not None and robot.root is not None
    assert not [d for d in result.diagnostics if d.severity is Severity.ERROR and d.code != "MK500"]
    oracle = yourdfpy.URDF.load(str(path), load_meshes=False, build_scene_graph=True)
    assert robot.root == oracle.base_link
    assert sorted(link.name for link in robot.links) == sorted(oracle.link_map)
    assert sorted(j.name for j in robot.joints) == sorted(oracle.joint_map)
    for theirs in oracle.robot.joints:
        ours = next(j for j in robot.joints if j.name == theirs.name)
        assert (ours.parent, ours.child) == (theirs.parent, theirs.child)
        assert ours.extras["urdf_type"] == theirs.type
        want = {
            "continuous": JointType.REVOLUTE,
            "revolute": JointType.REVOLUTE,
            "prismatic": JointType.PRISMATIC,
            "fixed": JointType.FIXED,
        }[theirs.type]
        assert ours.type is want
        origin = np.eye(4) if theirs.origin is None else theirs.origin
        np.testing.assert_allclose(ours.origin.rotation, origin[:3, :3], atol=1e-12)
        np.testing.assert_allclose(ours.origin.translation, origin[:3, 3], atol=1e-12)
        if theirs.type != "fixed":
            axis = np.asarray(theirs.axis, dtype=float)
            np.testing.assert_allclose(ours.axis, axis / np.linalg.norm(axis), atol=1e-12)
    rng = np.random.default_rng(7)
    for _ in range(4):
        cfg = {}
        for name in oracle.actuated_joint_names:
            joint = oracle.joint_map[name]
            low, high = (-math.pi, math.pi)
            if joint.limit is not None and joint.type != "continuous":
                low, high = joint.limit.lower, joint.limit.upper
            cfg[name] = float(rng.uniform(low, high))
        oracle.update_cfg(cfg)
        poses = robot.world_poses(cfg)
        assert set(poses) == set(oracle.link_map)
        for link, pose in poses.items():
            theirs = oracle.get_transform(link, oracle.base_link)
            np.testing.assert_allclose(pose.rotation, theirs[:3, :3], atol=1e-9, err_msg=link)
            np.testing.assert_allclose(pose.translation, theirs[:3, 3], atol=1e-9, err_msg=link)


def test_corpus_physics_values(corpus: Path) -> None:
    robot = read_model(CORPUS / "urdf_tutorial" / "urdf" / "07-physics.urdf", ReadOptions()).robot
    assert robot is not None
    base = robot.link("base_link")
    assert base is not None and base.inertial is not None
    assert base.inertial.mass == 10.0
    np.testing.assert_allclose(base.inertial.inertia, np.eye(3) * 1e-3)
    assert isinstance(base.visuals[0].geometry, Cylinder) and base.visuals[0].geometry.length == 0.6
    assert base.visuals[0].material is not None and base.visuals[0].material.name == "blue"
    np.testing.assert_allclose(base.visuals[0].material.diffuse, [0, 0, 0.8])
    gripper = next(j for j in robot.joints if j.name == "gripper_extension")
    assert gripper.type is JointType.PRISMATIC
    assert (gripper.limits.lower, gripper.limits.upper) == (-0.38, 0.0)
    assert (gripper.limits.effort, gripper.limits.velocity) == (1000.0, 0.5)
    wheel = next(j for j in robot.joints if j.name == "right_front_wheel_joint")
    assert wheel.type is JointType.REVOLUTE and wheel.extras["urdf_type"] == "continuous"
    assert not wheel.limits.position_limited
    finger = robot.link("left_gripper")
    assert finger is not None and isinstance(finger.visuals[0].geometry, Mesh)
    mesh = finger.visuals[0].geometry
    assert mesh.uri == "package://urdf_tutorial/meshes/l_finger.dae"
    assert mesh.path is not None and Path(mesh.path).is_file()


def test_choreonoid_tutorial_name_collisions_are_warnings_naming_the_consumer(corpus: Path) -> None:
    """check_urdf passes it, but joints RightWheel and LeftWheel are named like links: legal URDF, fatal
    only for libsdformat's URDF conversion (SDFormat 1.7+), so a warning that says so; an error when the
    file is judged for SDF (``--target sdf``)."""
    assert CODES["MK211"].severity == "error"  # the default: SDFormat 1.7+ files
    found = [(c, line, col, sev) for c, line, col, sev in codes_of(TUTORIAL_URDF) if c == "MK211"]
    # <joint name="RightWheel" ...> on line 103, <joint name="LeftWheel" ...> on line 110, both at the
    # name attribute (column 10)
    assert found == [("MK211", 103, 10, "warning"), ("MK211", 110, 10, "warning")]
    messages = [d.message for d in validate(TUTORIAL_URDF).diagnostics if d.code == "MK211"]
    assert all("libsdformat's URDF conversion" in m for m in messages)
    for_sdf = [d for d in validate(TUTORIAL_URDF, target="sdf").diagnostics if d.code == "MK211"]
    assert [d.severity.value for d in for_sdf] == ["error", "error"]
    lines = TUTORIAL_URDF.read_text().splitlines()
    assert lines[102][9:].startswith('name="RightWheel"') and lines[109][9:].startswith('name="LeftWheel"')


def test_choreonoid_tutorial_model(corpus: Path) -> None:
    robot = read_model(TUTORIAL_URDF, ReadOptions(check_resources=False)).robot
    assert robot is not None and robot.name == "MobileRobot" and robot.root == "Chassis"
    pan = robot.link("PanLink")
    assert pan is not None and len(pan.visuals) == 3
    # "gray" is defined inline in the first visual and reused by name in the next ones
    assert [g.material.name if g.material else None for g in pan.visuals] == ["gray"] * 3
    assert pan.visuals[1].material is pan.visuals[0].material
    chassis = robot.link("Chassis")
    assert chassis is not None and chassis.inertial is not None
    np.testing.assert_allclose(chassis.inertial.com, [-0.08, 0, 0.08])
    assert chassis.inertial.sources["mass"] == SourceLocation(str(TUTORIAL_URDF), 8, 13)
    assert chassis.loc("name") == SourceLocation(str(TUTORIAL_URDF), 5, 9)


# ---- joints -------------------------------------------------------------------------------------


JOINTS = robot_of(f"""
  <link name="a">{MASS}</link>
  <link name="b">{MASS}</link>
  <link name="c">{MASS}</link>
  <link name="d">{MASS}</link>
  <link name="e">{MASS}</link>
  <link name="f">{MASS}</link>
  <joint name="rev" type="revolute">
    <parent link="a"/><child link="b"/>
    <origin xyz="1 2 3" rpy="0.1 0.2 0.3"/>
    <axis xyz="0 0 2"/>
    <limit lower="-1" upper="2" effort="30" velocity="4" acceleration="5" deceleration="6" jerk="7"/>
    <dynamics damping="0.5" friction="0.25"/>
    <safety_controller soft_lower_limit="-0.9" soft_upper_limit="1.9" k_position="10" k_velocity="3"/>
    <calibration rising="0.1"/>
  </joint>
  <joint name="cont" type="continuous">
    <parent link="b"/><child link="c"/>
    <limit lower="-1" upper="1" effort="2" velocity="3"/>
    <mimic joint="rev" multiplier="-2" offset="0.5"/>
  </joint>
  <joint name="pris" type="prismatic">
    <parent link="c"/><child link="d"/>
    <limit effort="1" velocity="1"/>
  </joint>
  <joint name="float" type="floating"><parent link="a"/><child link="e"/></joint>
  <joint name="plane" type="planar"><parent link="a"/><child link="f"/><axis xyz="0 0 1"/></joint>
""")


def test_joint_fields(tmp_path: Path) -> None:
    robot, diags = read(tmp_path, JOINTS)
    assert robot is not None
    # the findings besides the URDF 1.2 attributes: the axis "0 0 2" is not a unit vector, and the slide's
    # <limit> gives no range (MK125: urdfdom reads 0 and 0; MuJoCo, PyBullet and Drake leave it free)
    assert [d.split(" ", 2)[:2] for d in diags if not d.startswith("MK142")] == [["MK306", "13:11"],
                                                                                  ["MK125", "26:5"]]
    joints = {j.name: j for j in robot.joints}
    rev = joints["rev"]
    assert rev.type is JointType.REVOLUTE and (rev.parent, rev.child) == ("a", "b")
    np.testing.assert_allclose(rev.origin.translation, [1, 2, 3])
    from modelkit.spatial import rpy_from_matrix

    np.testing.assert_allclose(rpy_from_matrix(rev.origin.rotation), [0.1, 0.2, 0.3], atol=1e-12)
    np.testing.assert_allclose(rev.axis, [0, 0, 1])
    limits = rev.limits
    assert (limits.lower, limits.upper, limits.effort, limits.velocity) == (-1.0, 2.0, 30.0, 4.0)
    assert (limits.velocity_lower, limits.velocity_upper) == (-4.0, 4.0)
    assert rev.extras["limit"] == {"acceleration": 5.0, "deceleration": 6.0, "jerk": 7.0}
    assert (rev.damping, rev.friction) == (0.5, 0.25)
    assert rev.extras["safety_controller"]["k_velocity"] == 3.0
    assert rev.extras["calibration"] == {"rising": 0.1}
    cont = joints["cont"]
    assert cont.type is JointType.REVOLUTE and cont.extras["urdf_type"] == "continuous"
    assert not cont.limits.position_limited and cont.limits.effort == 2.0
    np.testing.assert_allclose(cont.axis, [1, 0, 0])  # URDF's default axis
    assert cont.mimic is not None and (cont.mimic.joint, cont.mimic.multiplier, cont.mimic.offset) == (
        "rev",
        -2.0,
        0.5,
    )
    pris = joints["pris"]
    # its <limit> gives no range: unlimited, as MuJoCo, PyBullet and Drake read it (urdfdom: 0 and 0; MK125)
    assert pris.type is JointType.PRISMATIC and not pris.limits.position_limited
    assert joints["float"].type is JointType.FLOATING and joints["plane"].type is JointType.PLANAR
    assert robot.root == "a" and robot.root_joint is None


def test_joint_locations(tmp_path: Path) -> None:
    robot, _ = read(tmp_path, JOINTS)
    assert robot is not None
    rev = robot.joints[0]
    line = JOINTS.splitlines().index('  <joint name="rev" type="revolute">') + 1
    assert rev.source is not None and (rev.source.line, rev.source.col) == (line, 3)
    assert (rev.loc("name").line, rev.loc("name").col) == (line, 10)  # type: ignore[union-attr]
    assert (rev.loc("type").line, rev.loc("type").col) == (line, 21)  # type: ignore[union-attr]
    assert (rev.loc("parent").line, rev.loc("parent").col) == (line + 1, 13)  # type: ignore[union-attr]
    assert (rev.loc("child").line, rev.loc("child").col) == (line + 1, 30)  # type: ignore[union-attr]
    assert rev.loc("origin").line == line + 2  # type: ignore[union-attr]
    assert rev.loc("axis").line == line + 3  # type: ignore[union-attr]
    assert rev.loc("limit").line == line + 4  # type: ignore[union-attr]


def test_version_1_2_declared_quietly(tmp_path: Path) -> None:
    text = JOINTS.replace('<robot name="r">', '<robot name="r" version="1.2">')
    robot, diags = read(tmp_path, text)
    assert robot is not None and robot.extras["urdf_version"] == "1.2"
    # the axis "0 0 2" and the slide's limit without a range (MK125), no MK142
    assert [d.split(" ", 2)[:2] for d in diags] == [["MK306", "13:11"], ["MK125", "26:5"]]


def test_newer_feature_without_version_is_reported_once_each(tmp_path: Path) -> None:
    _, diags = read(tmp_path, JOINTS)
    assert sorted(d.split(" ", 2)[2].split(" is ")[0] for d in diags if d.startswith("MK142")) == [
        "`acceleration` in <limit>",
        "`deceleration` in <limit>",
        "`jerk` in <limit>",
    ]


def test_quat_xyzw_and_capsule(tmp_path: Path) -> None:
    text = robot_of(f"""
  <link name="a">{MASS}
    <visual><origin xyz="0 0 1" quat_xyzw="0 0 0.7071067811865476 0.7071067811865476"/>
      <geometry><capsule radius="0.1" length="0.5"/></geometry></visual>
  </link>""").replace('<robot name="r">', '<robot name="r" version="1.1">')
    robot, diags = read(tmp_path, text)
    assert robot is not None and diags == []
    geom = robot.links[0].visuals[0]
    assert isinstance(geom.geometry, Capsule) and (geom.geometry.radius, geom.geometry.length) == (0.1, 0.5)
    np.testing.assert_allclose(geom.pose.rotation, [[0, -1, 0], [1, 0, 0], [0, 0, 1]], atol=1e-12)


# ---- links, inertials, geometry, materials ---------------------------------------------------------


def test_inertia_is_rotated_into_link_axes(tmp_path: Path) -> None:
    """I_link = R · I_origin · Rᵀ, checked by hand: Rz(45°) turns diag(1, 3, 5) into [[2, -1], [-1, 2]]."""
    text = robot_of("""
  <link name="a">
    <inertial>
      <origin xyz="0.1 0.2 0.3" rpy="0 0 0.7853981633974483"/>
      <mass value="2"/>
      <inertia ixx="1" ixy="0" ixz="0" iyy="3" iyz="0" izz="5"/>
    </inertial>
  </link>
  <link name="b">
    <inertial>
      <origin rpy="1.5707963267948966 0 0"/>
      <mass value="1"/>
      <inertia ixx="1" ixy="0" ixz="0" iyy="2" iyz="0" izz="3"/>
    </inertial>
  </link>
  <joint name="j" type="fixed"><parent link="a"/><child link="b"/></joint>""")
    robot, diags = read(tmp_path, text)
    assert robot is not None and diags == []
    a, b = robot.links
    assert a.inertial is not None and b.inertial is not None
    np.testing.assert_allclose(a.inertial.com, [0.1, 0.2, 0.3])
    np.testing.assert_allclose(a.inertial.inertia, [[2, -1, 0], [-1, 2, 0], [0, 0, 5]], atol=1e-12)
    # a quarter turn about x swaps the y and z moments
    np.testing.assert_allclose(b.inertial.inertia, np.diag([1.0, 3.0, 2.0]), atol=1e-12)


def test_geometry_and_materials(tmp_path: Path) -> None:
    text = robot_of(f"""
  <material name="red"><color rgba="1 0 0 0.25"/></material>
  <material name="skin"><texture filename="skin.png"/></material>
  <link name="a">{MASS}
    <visual name="v1"><geometry><box size="1 2 3"/></geometry><material name="red"/></visual>
    <visual><geometry><sphere radius="0.5"/></geometry><material name="skin"/></visual>
    <visual><geometry><mesh filename="m.stl" scale="2 3 4"/></geometry>
      <material name="blue"><color rgba="0 0 1 1"/></material></visual>
    <collision name="c1"><origin xyz="0 0 1"/>
      <geometry><cylinder radius="0.1" length="2"/></geometry></collision>
  </link>""")
    robot, diags = read(tmp_path, text)
    assert robot is not None
    link = robot.links[0]
    box, sphere, mesh = (g.geometry for g in link.visuals)
    assert isinstance(box, Box) and box.size.tolist() == [1, 2, 3] and link.visuals[0].name == "v1"
    assert isinstance(sphere, Sphere) and sphere.radius == 0.5
    assert isinstance(mesh, Mesh) and mesh.scale.tolist() == [2, 3, 4] and mesh.uri == "m.stl"
    red = link.visuals[0].material
    assert red is not None and red.rgba == (1.0, 0.0, 0.0, 0.25)
    assert link.visuals[1].material is not None and link.visuals[1].material.texture == "skin.png"
    assert link.visuals[2].material is not None and link.visuals[2].material.name == "blue"
    assert set(robot.extras["materials"]) == {"red", "skin", "blue"}
    collision = link.collisions[0]
    assert isinstance(collision.geometry, Cylinder) and collision.name == "c1"
    np.testing.assert_allclose(collision.pose.translation, [0, 0, 1])
    lines = text.splitlines()
    assert collision.source is not None
    assert collision.source.line == lines.index('    <collision name="c1"><origin xyz="0 0 1"/>') + 1
    # the mesh file does not exist: a visual-only problem is a warning
    assert any(d.startswith("MK500") for d in diags)
    result = read_urdf(tmp_path / "robot.urdf", ReadOptions(), "robot.urdf")
    assert [d.severity for d in result.diagnostics if d.code == "MK500"] == [Severity.WARNING]


def test_material_referenced_before_its_inline_definition(tmp_path: Path) -> None:
    """urdfdom learns inline materials in document order: a reference before the definition is undefined."""
    text = robot_of(f"""
  <link name="a">{MASS}<visual><geometry><box size="1 1 1"/></geometry><material name="m"/></visual></link>
  <link name="b">{MASS}<visual><geometry><box size="1 1 1"/></geometry>
    <material name="m"><color rgba="0 1 0 1"/></material></visual></link>
  <joint name="j" type="fixed"><parent link="a"/><child link="b"/></joint>""")
    _, diags = read(tmp_path, text)
    col = text.splitlines()[3].index('name="m"') + 1
    assert [d.split(" ")[0:2] for d in diags] == [["MK135", f"4:{col}"]]


def test_broken_parts_are_left_out_and_the_rest_is_read(tmp_path: Path) -> None:
    text = robot_of("""
  <link name="a">
    <inertial><mass value="abc"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>
    <visual><geometry><box/></geometry></visual>
    <visual><geometry><sphere radius="1"/></geometry></visual>
    <collision><geometry/></collision>
    <collision><geometry><box size="1 1 1"/></geometry></collision>
  </link>""")
    robot, diags = read(tmp_path, text)
    assert robot is not None
    link = robot.links[0]
    assert link.inertial is None
    assert [type(g.geometry) for g in link.visuals] == [Sphere]
    assert [type(g.geometry) for g in link.collisions] == [Box]
    assert [d.split(" ")[0] for d in diags] == ["MK127", "MK143", "MK122"]


def test_gazebo_blocks_sensors_and_transmissions(tmp_path: Path) -> None:
    text = robot_of(f"""
  <link name="a">{MASS}</link>
  <link name="b">{MASS}</link>
  <joint name="j" type="continuous"><parent link="a"/><child link="b"/></joint>
  <gazebo><static>false</static></gazebo>
  <gazebo reference="b">
    <mu1>0.9</mu1><kp>1e6</kp><material>Gazebo/Red</material><selfCollide>true</selfCollide>
    <sensor name="cam" type="camera"><pose>0.1 0 0.2 0 0 1.5707963267948966</pose>
      <update_rate>30</update_rate><camera><horizontal_fov>1.0</horizontal_fov></camera></sensor>
  </gazebo>
  <gazebo reference="j"><provideFeedback>true</provideFeedback></gazebo>
  <gazebo reference="nothing"><mu1>1</mu1></gazebo>
  <transmission name="t"><type>SimpleTransmission</type>
    <joint name="j"><hardwareInterface>EffortJointInterface</hardwareInterface></joint>
    <actuator name="m"><mechanicalReduction>50</mechanicalReduction></actuator></transmission>
  <mujoco><compiler discardvisual="false"/></mujoco>
  <ros2_control name="sys" type="system"><hardware><plugin>mock</plugin></hardware></ros2_control>""")
    robot, diags = read(tmp_path, text)
    assert robot is not None
    assert [d.split(" ")[0] for d in diags] == ["MK138"]
    b = robot.link("b")
    assert b is not None
    (block,) = b.extras["gazebo"]
    assert block["reference"] == "b" and block["mu1"] == 0.9 and block["kp"] == 1e6
    assert block["material"] == "Gazebo/Red" and block["selfCollide"] is True
    assert block["xml"].startswith('<gazebo reference="b">') and block["source"].line == 8
    (camera,) = b.devices
    assert (camera.kind, camera.name, camera.params["update_rate"]) == ("camera", "cam", 30.0)
    np.testing.assert_allclose(camera.pose.translation, [0.1, 0, 0.2])
    np.testing.assert_allclose(camera.pose.rotation, [[0, -1, 0], [1, 0, 0], [0, 0, 1]], atol=1e-12)
    assert "<horizontal_fov>1.0</horizontal_fov>" in camera.params["xml"]
    assert robot.joints[0].extras["gazebo"][0]["provideFeedback"] is True
    assert [g["reference"] for g in robot.extras["gazebo"]] == [None, "nothing"]
    (transmission,) = robot.extras["transmissions"]
    assert (transmission["name"], transmission["type"]) == ("t", "SimpleTransmission")
    assert (transmission["joints"], transmission["actuators"]) == (["j"], ["m"])
    assert "discardvisual" in robot.extras["mujoco"][0]["xml"]
    assert robot.extras["ros2_control"][0]["name"] == "sys"


def test_unknown_elements_and_attributes_with_hints(tmp_path: Path) -> None:
    text = robot_of(f"""
  <link name="a" colour="red">{MASS}
    <visual><geometry><box size="1 1 1"/></geometry></visual>
    <colision><geometry><box size="1 1 1"/></geometry></colision>
    <collision><geometry><box size="1 1 1"/></geometry><material name="x"/></collision>
  </link>
  <drake:joint xmlns:drake="http://drake.mit.edu" name="x" type="ball"/>
  <frame name="f"/>""")
    _, diags = read(tmp_path, text)
    lines = text.splitlines()
    material = lines[6].index("<material") + 1
    assert [d.split(" ")[0:2] for d in diags] == [
        ["MK123", "4:18"],
        ["MK123", "6:5"],
        ["MK123", f"7:{material}"],
        ["MK123", "10:3"],
    ]
    assert "misplaced" in diags[2] and "only in <visual>" in diags[2]
    result = read_urdf(tmp_path / "robot.urdf", ReadOptions(check_resources=False), "x")
    hints = [d.hint for d in result.diagnostics]
    assert hints[1] == 'did you mean "collision"?'


def test_world_root_is_fixed_to_the_world(tmp_path: Path) -> None:
    text = robot_of(f"""<link name="world"/><link name="base">{MASS}</link>
  <joint name="weld" type="fixed"><parent link="world"/><child link="base"/></joint>""")
    robot, _ = read(tmp_path, text)
    assert robot is not None and robot.root == "world" and robot.root_joint is JointType.FIXED
    assert "world_link" not in robot.extras  # the root says it: no copy of it in extras


def test_two_parents_keep_both_joints(tmp_path: Path) -> None:
    text = robot_of(f"""<link name="a">{MASS}</link><link name="b">{MASS}</link><link name="c">{MASS}</link>
  <joint name="j1" type="fixed"><parent link="a"/><child link="b"/></joint>
  <joint name="j2" type="fixed"><parent link="a"/><child link="c"/></joint>
  <joint name="j3" type="fixed"><parent link="b"/><child link="c"/></joint>""")
    robot, _ = read(tmp_path, text)
    assert robot is not None and [j.name for j in robot.joints] == ["j1", "j2", "j3"]
    assert robot.root == "a"


def test_duplicates_are_kept_and_reported_once(tmp_path: Path) -> None:
    text = robot_of(f"""<link name="a">{MASS}</link><link name="b">{MASS}</link>
<link name="b">{MASS}</link>
  <joint name="j" type="fixed"><parent link="a"/><child link="b"/></joint>
  <joint name="j" type="fixed"><parent link="a"/><child link="b"/></joint>""")
    path = tmp_path / "dup.urdf"
    path.write_text(text)
    found = [
        (d.code, d.location.line if d.location else 0, d.message)
        for d in validate(path).diagnostics
        if d.severity is Severity.ERROR
    ]
    assert found == [
        ("MK204", 4, 'duplicated link name "b" (first at line 3)'),
        ("MK205", 6, 'duplicated joint name "j" (first at line 5)'),
    ]


def test_default_namespace_is_urdf(tmp_path: Path) -> None:
    text = robot_of(f'<link name="a">{MASS}</link>').replace(
        '<robot name="r">', '<robot name="r" xmlns="http://www.ros.org">'
    )
    robot, diags = read(tmp_path, text)
    assert robot is not None and [link.name for link in robot.links] == ["a"] and diags == []
    assert robot.links[0].inertial is not None


def test_read_urdf_document_uses_the_document_origins(tmp_path: Path) -> None:
    """xacro output maps elements back to the .xacro source; every location must go through doc.loc."""
    sink = DiagnosticSink()
    text = robot_of(
        '<link name="a"/><joint name="j" type="hinge"><parent link="a"/><child link="a"/></joint>'
    )
    doc = parse_xml_bytes(text.encode(), "generated.urdf", sink)
    assert doc is not None
    source = SourceLocation("robot.urdf.xacro", 42, 7)
    for element in doc.root.iter():
        doc.origins[element] = source
    robot = read_urdf_document(doc, ReadOptions(), sink, tmp_path, None)
    assert robot is not None
    assert robot.links[0].loc("name") == source and robot.joints[0].loc("type") == source
    assert [(d.code, d.location) for d in sink.items] == [("MK133", source)]


def test_not_a_urdf(tmp_path: Path) -> None:
    robot, diags = read(tmp_path, '<?xml version="1.0"?>\n<sdf version="1.9"><model name="m"/></sdf>\n')
    assert robot is None
    assert diags == ["MK022 2:1 the top element is <sdf>, not <robot>: this is not a URDF document"]


def clean_variants() -> list[str]:
    """The clean base of the broken-URDF corpus with each attribute, and each element, removed in turn."""
    from lxml import etree

    text = CLEAN.read_text().split("-->\n", 1)[1]
    out = []
    root = etree.fromstring(text.encode())
    elements = list(root.iter())
    for i, element in enumerate(elements):
        for name in list(element.attrib):
            copy = etree.fromstring(text.encode())
            target = list(copy.iter())[i]
            del target.attrib[name]
            out.append(etree.tostring(copy).decode())
        if i:
            copy = etree.fromstring(text.encode())
            target = list(copy.iter())[i]
            parent = target.getparent()
            if parent is not None:
                parent.remove(target)
                out.append(etree.tostring(copy).decode())
    return out


def test_never_a_traceback_on_damaged_input(tmp_path: Path) -> None:
    """The clean base with each attribute or element removed reads and validates without raising."""
    variants = clean_variants()
    assert len(variants) > 100
    for i, variant in enumerate(variants):
        path = tmp_path / f"v{i}.urdf"
        path.write_text(variant)
        v = validate(path, ReadOptions(check_resources=False))
        assert v.robot is not None or any(d.code in ("MK022", "MK020") for d in v.diagnostics)


def test_unexpanded_xacro_is_reported_once(tmp_path: Path) -> None:
    text = robot_of(f"""<xacro:property name="w" value="1"/>
<xacro:macro name="m"><link name="x"/></xacro:macro>
  <link name="a">{MASS}</link>""").replace(
        '<robot name="r">', '<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">'
    )
    robot, diags = read(tmp_path, text)
    assert robot is not None and [link.name for link in robot.links] == ["a"]
    assert [d.split(" ")[0:2] for d in diags] == [["MK123", "3:1"]] and "expanded by xacro" in diags[0]
