"""The SDF reader: corpus trees and poses, frame semantics, re-framing at joints, worlds, includes,
devices, the unicycle sample, robustness, and libsdformat as an oracle when it is installed.

Expected trees and poses are written out by hand from the SDF files (not produced by modelkit).
"""

from __future__ import annotations

import hashlib
import math
import os
import re
import shutil
import subprocess
import tempfile
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from lxml import etree

from modelkit.api import validate
from modelkit.cli import main
from modelkit.formats import read_model
from modelkit.formats.common import ReadOptions, ReadResult
from modelkit.model import Box, Cylinder, JointType, Mesh, Robot, Sphere
from modelkit.resources import Resolver
from modelkit.spatial import Pose, axis_angle
from modelkit.tree import tree_report

from .conftest import CORPUS, REPO

SDF_MODELS = CORPUS / "sdformat_urdf" / "sdformat_test_files" / "models"
UNICYCLE = REPO / "samples" / "gazebo_unicycle" / "unicycle.sdf"
BROKEN = REPO / "tests" / "broken_sdf"
HEADER = "---------- Successfully Parsed XML ---------------\n"


def tree_text(name: str, root: str, lines: list[str]) -> str:
    children = sum(1 for line in lines if line.startswith("    child(") and not line.startswith("     "))
    return f"robot name is: {name}\n{HEADER}root Link: {root} has {children} child(ren)\n" + "".join(
        line + "\n" for line in lines
    )


def single(name: str) -> str:
    return tree_text(name, "link", [])


def one_joint(name: str) -> str:
    return tree_text(name, "link_1", ["    child(1):  link_2"])


# Written from the files: links, and joints with their parent and child.
CORPUS_TREES = {
    "geometry_box": single("geometry_box"),
    "geometry_cylinder": single("geometry_cylinder"),
    "geometry_mesh_collada": single("geometry_mesh_collada"),
    "geometry_mesh_obj": single("geometry_mesh_obj"),
    "geometry_mesh_scaled": single("geometry_mesh_scaled"),
    "geometry_mesh_stl": single("geometry_mesh_stl"),
    "geometry_sphere": single("geometry_sphere"),
    "link_inertia": single("link_inertia"),
    "link_multiple_collisions": single("link_multiple_collisions"),
    "link_multiple_visuals": single("link_multiple_visuals"),
    "graph_chain": tree_text("graph_chain", "link_1", ["    child(1):  link_2", "        child(1):  link_3"]),
    # joint_1: link_1 -> link_2, joint_2: link_1 -> link_3, joint_3: link_2 -> link_4,
    # joint_4: link_3 -> link_5, joint_5: link_3 -> link_6
    "graph_tree": tree_text(
        "graph_tree",
        "link_1",
        [
            "    child(1):  link_2",
            "        child(1):  link_4",
            "    child(2):  link_3",
            "        child(1):  link_5",
            "        child(2):  link_6",
        ],
    ),
    "joint_continuous": one_joint("joint_continuous"),
    "joint_fixed": one_joint("joint_fixed"),
    "joint_prismatic": one_joint("joint_prismatic"),
    "joint_revolute": one_joint("joint_revolute"),
    "joint_revolute_axis": one_joint("joint_revolute_axis"),
}


def corpus_files() -> list[Path]:
    return sorted(SDF_MODELS.glob("*/*.sdf")) if SDF_MODELS.is_dir() else []


def read_text(
    tmp_path: Path, text: str, name: str = "model.sdf", options: ReadOptions | None = None
) -> ReadResult:
    path = tmp_path / name
    path.write_text(text)
    return read_model(path, options or ReadOptions())


def codes(result: ReadResult) -> list[str]:
    return [d.code for d in result.diagnostics]


def robot_of(result: ReadResult) -> Robot:
    assert result.robot is not None, [str(d) for d in result.diagnostics]
    return result.robot


def assert_pose(pose: Pose, xyz: list[float], rotation: np.ndarray | None = None) -> None:
    assert np.allclose(pose.translation, xyz, atol=1e-9), pose
    if rotation is not None:
        assert np.allclose(pose.rotation, rotation, atol=1e-9), pose


def rpy(roll: float, pitch: float, yaw: float) -> np.ndarray:
    """Independent of the reader: Rz(yaw)·Ry(pitch)·Rx(roll) by products of axis rotations."""
    return (
        axis_angle([0.0, 0.0, 1.0], yaw)
        @ axis_angle([0.0, 1.0, 0.0], pitch)
        @ axis_angle([1.0, 0.0, 0.0], roll)
    )


# ---- the sdformat_urdf corpus ------------------------------------------------------------------


def test_corpus_is_complete(corpus: Path) -> None:
    assert sorted(p.stem for p in corpus_files()) == sorted(CORPUS_TREES)


# The only warning on the sdformat_urdf corpus: a converter test whose revolute axis "0.1 1.23 4.567" is not a
# unit vector (length 4.73; MK306 at its <xyz> line).
CORPUS_WARNINGS = {"joint_revolute_axis": [("MK306", 64)]}


@pytest.mark.parametrize("name", sorted(CORPUS_TREES))
def test_corpus_tree(name: str, corpus: Path) -> None:
    path = SDF_MODELS / name / f"{name}.sdf"
    result = validate(path)
    expected = CORPUS_WARNINGS.get(name, [])
    assert [(d.code, d.location.line if d.location else None)
            for d in result.diagnostics if d.severity.value != "info"] == expected
    assert {d.code for d in result.diagnostics} <= {"MK532"} | {code for code, _ in expected}
    robot = robot_of(result)
    assert robot.source_format == "sdf" and robot.name == name
    assert robot.root_joint is JointType.FLOATING
    assert tree_report(robot) == CORPUS_TREES[name]
    out = CliRunner().invoke(main, ["tree", str(path)])
    assert (out.exit_code, out.stdout) == (0, CORPUS_TREES[name])


def test_graph_tree_world_poses(corpus: Path) -> None:
    robot = robot_of(read_model(SDF_MODELS / "graph_tree" / "graph_tree.sdf"))
    expected = {
        "link_1": [0, 0.3, 0.4],
        "link_2": [0, 0.1, 0.2],
        "link_3": [0, 0.4, 0.2],
        "link_4": [0, 0, 0],
        "link_5": [0, 0.3, 0],
        "link_6": [0, 0.5, 0],
    }
    poses = robot.world_poses()
    assert sorted(poses) == sorted(expected)
    for link, xyz in expected.items():
        assert_pose(poses[link], xyz, np.eye(3))
    joint_3 = next(j for j in robot.joints if j.name == "joint_3")
    assert_pose(joint_3.origin, [0, -0.1, -0.2])  # link_4 in link_2's frame
    assert np.allclose(joint_3.axis, [1, 0, 0])
    # q = 0.5 on joint_1 rotates link_2 and link_4 about x through link_2's origin
    moved = robot.world_poses({"joint_1": 0.5})
    assert_pose(moved["link_2"], [0, 0.1, 0.2], rpy(0.5, 0, 0))
    offset = rpy(0.5, 0, 0) @ np.array([0, -0.1, -0.2])
    assert_pose(moved["link_4"], (np.array([0, 0.1, 0.2]) + offset).tolist())


def test_graph_chain_world_poses(corpus: Path) -> None:
    poses = robot_of(read_model(SDF_MODELS / "graph_chain" / "graph_chain.sdf")).world_poses()
    for link, z in (("link_1", 0.0), ("link_2", 0.2), ("link_3", 0.4)):
        assert_pose(poses[link], [0, 0, z], np.eye(3))


def test_joint_revolute_axis_is_normalised_and_moves_link(corpus: Path) -> None:
    robot = robot_of(read_model(SDF_MODELS / "joint_revolute_axis" / "joint_revolute_axis.sdf"))
    (joint,) = robot.joints
    raw = np.array([0.1, 1.23, 4.567])
    assert np.allclose(joint.axis, raw / np.linalg.norm(raw))
    assert (joint.type, joint.limits.lower, joint.limits.upper) == (JointType.REVOLUTE, -1.5, 1.5)
    assert_pose(joint.origin, [0.1, 0, 0.1], np.eye(3))
    moved = robot.world_poses({"joint_revolute": 0.7})
    assert_pose(moved["link_2"], [0.1, 0, 0.1], axis_angle(raw, 0.7))


def test_joint_kinds_and_limits(corpus: Path) -> None:
    def joint(name: str) -> tuple[JointType, float, float, np.ndarray]:
        robot = robot_of(read_model(SDF_MODELS / name / f"{name}.sdf"))
        (j,) = robot.joints
        return j.type, j.limits.lower, j.limits.upper, j.axis

    kind, lower, upper, axis = joint("joint_continuous")
    assert (kind, lower, upper) == (JointType.REVOLUTE, -math.inf, math.inf) and np.allclose(axis, [1, 0, 0])
    kind, lower, upper, axis = joint("joint_prismatic")
    assert (kind, lower, upper) == (JointType.PRISMATIC, -0.2, 0.2) and np.allclose(axis, [0, 1, 0])
    assert joint("joint_fixed")[0] is JointType.FIXED
    robot = robot_of(read_model(SDF_MODELS / "joint_prismatic" / "joint_prismatic.sdf"))
    assert_pose(robot.world_poses({"joint_prismatic": 0.1})["link_2"], [0.1, 0.1, 0.1])


def test_link_inertia_full_tensor(corpus: Path) -> None:
    robot = robot_of(read_model(SDF_MODELS / "link_inertia" / "link_inertia.sdf"))
    inertial = robot.links[0].inertial
    assert inertial is not None and inertial.mass == 116.0 and not inertial.defaulted
    expected = np.array(
        [
            [5.652232699207, -0.009719934438, 1.293988226423],
            [-0.009719934438, 5.669473158652, -0.007379583694],
            [1.293988226423, -0.007379583694, 3.683196351726],
        ]
    )
    assert np.allclose(inertial.inertia, expected)
    assert inertial.sources["mass"].line == 20


def test_corpus_geometry(corpus: Path) -> None:
    def geoms(name: str) -> tuple[list[object], list[object]]:
        link = robot_of(read_model(SDF_MODELS / name / f"{name}.sdf")).links[0]
        return [g.geometry for g in link.visuals], [g.geometry for g in link.collisions]

    (box,), _ = geoms("geometry_box")
    assert isinstance(box, Box) and np.allclose(box.size, [0.1, 0.2, 0.4])
    (cyl,), _ = geoms("geometry_cylinder")
    assert isinstance(cyl, Cylinder) and (cyl.radius, cyl.length) == (0.125, 0.2)
    _, (ball,) = geoms("geometry_sphere")
    assert isinstance(ball, Sphere) and ball.radius == 0.125
    (mesh,), _ = geoms("geometry_mesh_scaled")
    assert isinstance(mesh, Mesh) and mesh.uri == "model://geometry_mesh_scaled/torus.stl"
    assert (
        np.allclose(mesh.scale, [0.1, 0.2, 0.4]) and mesh.path is not None and mesh.path.endswith("torus.stl")
    )
    visuals, collisions = geoms("link_multiple_collisions")
    assert len(visuals) == 1 and len(collisions) == 2


def test_model_uri_on_the_resource_path_needs_no_note(corpus: Path) -> None:
    resolver = Resolver(environ={"GZ_SIM_RESOURCE_PATH": str(SDF_MODELS)})
    result = read_model(
        SDF_MODELS / "geometry_mesh_stl" / "geometry_mesh_stl.sdf", ReadOptions(resolver=resolver)
    )
    assert result.diagnostics == []


# ---- the unicycle sample -------------------------------------------------------------------------

UNICYCLE_TREE = tree_text("unicycle", "base", ["    child(1):  top", "        child(1):  camera_link"])


def test_unicycle_tree_and_validation() -> None:
    out = CliRunner().invoke(main, ["tree", str(UNICYCLE)])
    assert (out.exit_code, out.stdout) == (0, UNICYCLE_TREE)
    strict = CliRunner().invoke(main, ["validate", "--strict", str(UNICYCLE)])
    assert (strict.exit_code, strict.stdout) == (0, "")


def test_unicycle_frames_devices_and_reframing() -> None:
    robot = robot_of(read_model(UNICYCLE))
    assert robot.root == "base" and robot.root_joint is JointType.FLOATING
    # SDF 1.5: each joint pose is in its child link frame. joint: top (z 0.06) - 0.036785;
    # camera_joint: camera_link (z 0.085) - 0.03. Links are re-framed at their joints.
    poses = robot.world_poses()
    assert_pose(poses["base"], [0, 0, 0.02])
    assert_pose(poses["top"], [0, 0, 0.06 - 0.036785])
    assert_pose(poses["camera_link"], [0, 0, 0.085 - 0.03])
    top = robot.link("top")
    assert top is not None
    assert_pose(top.extras["sdf_link_pose"], [0, 0, 0.036785])
    assert_pose(top.visuals[0].pose, [0, 0, 0.036785])
    assert top.inertial is not None and np.allclose(top.inertial.com, [0, 0, 0.036785])
    joint = next(j for j in robot.joints if j.name == "joint")
    assert (joint.type, joint.limits.lower, joint.limits.upper) == (JointType.REVOLUTE, -math.inf, math.inf)
    kinds = {(link.name, d.kind, d.name) for link in robot.links for d in link.devices}
    assert kinds == {
        ("base", "ray", "sensor"),
        ("top", "ray", "sensor"),
        ("camera_link", "camera", "camera1"),
    }
    (ray,) = top.devices
    assert_pose(ray.pose, [0, 0, 0.036785 - 0.004645])
    assert ray.params["horizontal_samples"] == 2 and ray.params["horizontal_max_angle"] == 1.5707
    assert (ray.params["range_min"], ray.params["range_max"], ray.params["update_rate"]) == (0.05, 70.0, 30.0)
    assert ray.params["plugins"][0]["filename"] == "libgazebo_ros_velodyne_laser.so"
    camera_link = robot.link("camera_link")
    assert camera_link is not None
    (camera,) = camera_link.devices
    assert {k: camera.params[k] for k in ("width", "height", "format", "near", "far")} == {
        "width": 800,
        "height": 800,
        "format": "R8G8B8",
        "near": 0.02,
        "far": 300.0,
    }


# ---- frames, poses and re-framing ------------------------------------------------------------------

LINK = """<link name="{name}"><pose{rel}>{pose}</pose>
  <inertial><mass>1</mass><inertia><ixx>0.1</ixx><iyy>0.1</iyy><izz>0.1</izz></inertia></inertial></link>"""


def model(version: str, body: str, name: str = "m") -> str:
    return (
        f'<?xml version="1.0"?>\n<sdf version="{version}">\n<model name="{name}">\n{body}\n</model>\n</sdf>\n'
    )


def test_child_link_is_reframed_at_its_joint(tmp_path: Path) -> None:
    body = """
    <link name="a"><inertial><mass>1</mass></inertial></link>
    <link name="b">
      <pose>1 0 0 0 0 1.5707963267948966</pose>
      <inertial><pose>0.1 0 0 0 0 0</pose><mass>2</mass>
        <inertia><ixx>1</ixx><iyy>2</iyy><izz>3</izz></inertia></inertial>
      <visual name="v"><pose>0 0 0.5 0 0 0</pose>
        <geometry><sphere><radius>0.1</radius></sphere></geometry></visual>
    </link>
    <joint name="j" type="revolute">
      <pose>0 0 1 0 0 0</pose>
      <parent>a</parent><child>b</child>
      <axis><xyz expressed_in="__model__">1 0 0</xyz></axis>
    </joint>"""
    robot = robot_of(read_text(tmp_path, model("1.7", body)))
    (joint,) = robot.joints
    yaw = rpy(0, 0, math.pi / 2)
    # joint frame = link b frame (x = 1, yaw 90°) moved by (0, 0, 1) in it
    assert_pose(joint.origin, [1, 0, 1], yaw)
    # the model x axis in the joint frame (yawed 90°) is -y
    assert np.allclose(joint.axis, [0, -1, 0])
    b = robot.link("b")
    assert b is not None
    assert_pose(b.extras["sdf_link_pose"], [0, 0, -1], np.eye(3))
    assert_pose(b.visuals[0].pose, [0, 0, -0.5])
    assert b.inertial is not None
    assert np.allclose(b.inertial.com, [0.1, 0, -1]) and np.allclose(b.inertial.inertia, np.diag([1, 2, 3]))
    # the visual stays where SDF puts it in the world
    world = robot.world_poses()["b"] @ b.visuals[0].pose
    assert_pose(world, [1, 0, 0.5])


def test_inertial_pose_rotates_the_inertia(tmp_path: Path) -> None:
    body = """<link name="a"><inertial><pose>0 0 0 0 0 1.5707963267948966</pose><mass>1</mass>
      <inertia><ixx>1</ixx><iyy>2</iyy><izz>3</izz></inertia></inertial></link>"""
    inertial = robot_of(read_text(tmp_path, model("1.7", body))).links[0].inertial
    assert inertial is not None and np.allclose(inertial.inertia, np.diag([2, 1, 3]))


@pytest.mark.parametrize(
    ("version", "axis_extra", "expected"),
    [
        ("1.4", "", [0, -1, 0]),  # SDF 1.4: axes are in the model frame
        ("1.5", "", [1, 0, 0]),  # SDF 1.5/1.6: the joint frame ...
        ("1.6", "<use_parent_model_frame>true</use_parent_model_frame>", [0, -1, 0]),  # ... or the model
        ("1.7", "", [1, 0, 0]),
    ],
)
def test_axis_frame_by_version(tmp_path: Path, version: str, axis_extra: str, expected: list[float]) -> None:
    body = (
        LINK.format(name="a", rel="", pose="0 0 0 0 0 0")
        + LINK.format(name="b", rel="", pose="0 0 1 0 0 1.5707963267948966")
        + f"""<joint name="j" type="revolute"><parent>a</parent><child>b</child>
        <axis><xyz>1 0 0</xyz>{axis_extra}</axis></joint>"""
    )
    result = read_text(tmp_path, model(version, body))
    (joint,) = robot_of(result).joints
    assert np.allclose(joint.axis, expected)
    assert [d for d in result.diagnostics if d.severity.value != "info"] == []


def test_frames_relative_to_and_attached_to(tmp_path: Path) -> None:
    body = """
    <frame name="f0"><pose>0 0 1 0 0 0</pose></frame>
    <frame name="f1" attached_to="a"><pose relative_to="f0">1 0 0 0 0 0</pose></frame>
    <link name="a"><pose relative_to="f0">0 2 0 0 0 0</pose><inertial><mass>1</mass></inertial></link>
    <link name="b"><pose relative_to="f1">0 0 0 0 0 0</pose><inertial><mass>1</mass></inertial></link>
    <joint name="j" type="fixed"><parent>f1</parent><child>b</child></joint>"""
    result = read_text(tmp_path, model("1.8", body))
    robot = robot_of(result)
    assert [d.code for d in result.diagnostics if d.severity.value != "info"] == []
    poses = robot.world_poses()
    assert_pose(poses["a"], [0, 2, 1])
    assert_pose(poses["b"], [1, 0, 1])
    (joint,) = robot.joints
    assert (joint.parent, joint.child) == ("a", "b")  # the joint's parent frame f1 is attached to a
    a = robot.link("a")
    assert a is not None
    assert_pose(a.extras["sdf_frames"]["f1"], [1, -2, 0])
    assert_pose(a.extras["sdf_frames"]["f0"], [0, -2, 0])  # f0 hangs on the model frame, i.e. on a


def test_pose_formats_of_sdf_1_9(tmp_path: Path) -> None:
    body = """
    <link name="a"><pose degrees="true">0 0 0 90 0 0</pose><inertial><mass>1</mass></inertial></link>
    <link name="b"><pose rotation_format="quat_xyzw">1 2 3 0 0 0.7071067811865476 0.7071067811865476</pose>
      <inertial><mass>1</mass></inertial></link>
    <joint name="j" type="fixed"><parent>a</parent><child>b</child></joint>"""
    robot = robot_of(read_text(tmp_path, model("1.9", body)))
    poses = robot.world_poses()
    assert_pose(poses["a"], [0, 0, 0], rpy(math.pi / 2, 0, 0))
    assert_pose(poses["b"], [1, 2, 3], rpy(0, 0, math.pi / 2))


def test_model_pose_places_the_root(tmp_path: Path) -> None:
    body = "<pose>1 2 3 0 0 0</pose>" + LINK.format(name="a", rel="", pose="0 0 1 0 0 0")
    robot = robot_of(read_text(tmp_path, model("1.7", body)))
    assert robot.root_joint is JointType.FLOATING
    assert_pose(robot.root_pose, [1, 2, 4])
    assert_pose(robot.extras["sdf_model_pose"], [1, 2, 3])


def test_nested_models_are_flattened_with_scoped_names(tmp_path: Path) -> None:
    body = (
        LINK.format(name="base", rel="", pose="0 0 0 0 0 0")
        + '<model name="arm"><pose>0 0 1 0 0 0</pose>'
        + LINK.format(name="link", rel="", pose="0 0 0.5 0 0 0")
        + "</model>"
        + '<joint name="mount" type="fixed"><parent>base</parent><child>arm::link</child></joint>'
    )
    result = read_text(tmp_path, model("1.8", body))
    robot = robot_of(result)
    assert [link.name for link in robot.links] == ["base", "arm::link"]
    assert_pose(robot.world_poses()["arm::link"], [0, 0, 1.5])
    assert tree_report(robot) == tree_text("m", "base", ["    child(1):  arm::link"])


def test_static_model_and_world_joints(tmp_path: Path) -> None:
    two = LINK.format(name="a", rel="", pose="0 0 1 0 0 0") + LINK.format(
        name="b", rel="", pose="0 0 2 0 0 0"
    )
    hinge = '<joint name="h" type="revolute"><parent>a</parent><child>b</child></joint>'
    static = robot_of(read_text(tmp_path, model("1.7", "<static>true</static>" + two + hinge)))
    assert static.root_joint is JointType.FIXED and static.root == "a"
    fixed = '<joint name="w" type="fixed"><parent>world</parent><child>a</child></joint>'
    welded = robot_of(read_text(tmp_path, model("1.7", two + fixed + hinge)))
    assert (welded.root, welded.root_joint) == ("a", JointType.FIXED)
    assert_pose(welded.root_pose, [0, 0, 1])
    moving = '<joint name="w" type="revolute"><parent>world</parent><child>a</child></joint>'
    pendulum = robot_of(read_text(tmp_path, model("1.7", two + moving + hinge)))
    assert (pendulum.root, pendulum.root_joint) == ("world", JointType.FIXED)
    w = next(j for j in pendulum.joints if j.name == "w")
    assert (w.parent, w.child, w.type) == ("world", "a", JointType.REVOLUTE)
    assert_pose(pendulum.world_poses()["b"], [0, 0, 2])


def test_free_links_and_loops_are_reported(tmp_path: Path) -> None:
    links = "".join(LINK.format(name=n, rel="", pose="0 0 0 0 0 0") for n in ("a", "b", "c", "d"))
    joints = (
        '<joint name="j1" type="revolute"><parent>a</parent><child>b</child></joint>'
        '<joint name="j2" type="revolute"><parent>b</parent><child>c</child></joint>'
        '<joint name="j3" type="revolute"><parent>a</parent><child>c</child></joint>'
    )
    result = read_text(tmp_path, model("1.7", links + joints))
    robot = robot_of(result)
    assert sorted((d.code, d.severity.value) for d in result.diagnostics) == [
        ("MK201", "warning"),
        ("MK241", "warning"),
    ]
    assert [loop.name for loop in robot.loops] == ["j3"] and robot.loops[0].type == "hinge"
    assert [j.name for j in robot.joints] == ["j1", "j2"]
    assert "d" in robot.free_link_poses


def test_joint_details(tmp_path: Path) -> None:
    links = "".join(LINK.format(name=n, rel="", pose="0 0 0 0 0 0") for n in ("a", "b", "c", "d"))
    body = (
        links
        + """<joint name="lead" type="revolute"><parent>a</parent><child>b</child>
        <axis><xyz>0 0 2</xyz><limit><lower>-1e16</lower><upper>1e16</upper><effort>-1</effort>
        <velocity>3</velocity></limit>
        <dynamics><damping>0.5</damping><friction>0.2</friction><spring_stiffness>4</spring_stiffness>
        </dynamics></axis>
        <sensor name="ft" type="force_torque"><update_rate>100</update_rate>
          <force_torque><frame>child</frame></force_torque></sensor></joint>
      <joint name="follow" type="prismatic"><parent>b</parent><child>c</child>
        <axis><xyz>1 0 0</xyz><mimic joint="lead"><multiplier>2</multiplier><offset>0.1</offset>
        <reference>0.5</reference></mimic></axis></joint>
      <joint name="ball" type="ball"><parent>c</parent><child>d</child></joint>"""
    )
    result = read_text(tmp_path, model("1.11", body))
    robot = robot_of(result)
    # the one warning: the axis "0 0 2" of "lead" is not a unit vector (the model holds it normalised)
    assert [(d.code, d.location.line if d.location else None)
            for d in result.diagnostics if d.severity.value != "info"] == [("MK306", 9)]
    lead, follow, ball = robot.joints
    assert np.allclose(lead.axis, [0, 0, 1])
    assert (lead.limits.lower, lead.limits.upper, lead.limits.effort, lead.limits.velocity) == (
        -math.inf,
        math.inf,
        math.inf,
        3.0,
    )
    assert (lead.damping, lead.friction, lead.spring_stiffness) == (0.5, 0.2, 4.0)
    assert follow.mimic is not None and follow.mimic.joint == "lead"
    assert (follow.mimic.multiplier, follow.mimic.offset) == (2.0, pytest.approx(0.1 - 2 * 0.5))
    assert ball.type is JointType.BALL
    b = robot.link("b")
    assert b is not None and [(d.kind, d.name, d.params["sdf_joint"]) for d in b.devices] == [
        ("force_torque", "ft", "lead")
    ]


def test_auto_inertial_from_collision_primitives(tmp_path: Path) -> None:
    body = """<link name="a"><inertial auto="true"><density>500</density></inertial>
      <collision name="c"><pose>0 0 1 0 0 0</pose>
        <geometry><box><size>1 2 3</size></box></geometry></collision>
    </link>"""
    result = read_text(tmp_path, model("1.11", body))
    inertial = robot_of(result).links[0].inertial
    assert inertial is not None
    mass = 500 * 6.0
    assert inertial.mass == pytest.approx(mass) and np.allclose(inertial.com, [0, 0, 1])
    assert np.allclose(inertial.inertia, np.diag([mass * 13 / 12, mass * 10 / 12, mass * 5 / 12]))
    assert "MK342" in codes(result)


def test_materials_and_unmodelled_geometry(tmp_path: Path) -> None:
    body = """<link name="a"><inertial><mass>1</mass></inertial>
      <visual name="v"><geometry><box><size>1 1 1</size></box></geometry>
        <material><ambient>0.25 0 0 1</ambient><diffuse>0.5 0 0 0.8</diffuse>
        <specular>0.1 0.1 0.1 1</specular>
        </material></visual>
      <visual name="floor"><geometry><plane><normal>0 0 1</normal><size>5 5</size></plane></geometry></visual>
    </link>"""
    result = read_text(tmp_path, model("1.7", body))
    link = robot_of(result).links[0]
    material = link.visuals[0].material
    assert material is not None and material.rgba == pytest.approx((0.5, 0, 0, 0.8))
    assert material.ambient == pytest.approx(0.5)
    assert link.extras["sdf_geometry"][0]["kind"] == "plane"
    assert codes(result) == ["MK430"]


def test_pbr_albedo_map_is_checked_once_per_uri(tmp_path: Path) -> None:
    pbr = "<material><pbr><metal><albedo_map>{}</albedo_map></metal></pbr></material>"
    visual = '<visual name="{}"><geometry><box><size>1 1 1</size></box></geometry>{}</visual>'
    body = (
        '<link name="a"><inertial><mass>1</mass></inertial>'
        + visual.format("v1", pbr.format("textures/missing.png"))
        + visual.format("v2", pbr.format("textures/missing.png"))
        + visual.format("v3", pbr.format("textures/here.png"))
        + "</link>"
    )
    (tmp_path / "textures").mkdir()
    (tmp_path / "textures" / "here.png").write_bytes(b"")
    result = read_text(tmp_path, model("1.7", body))
    link = robot_of(result).links[0]
    assert [g.material.texture for g in link.visuals if g.material] == [
        "textures/missing.png",
        "textures/missing.png",
        "textures/here.png",
    ]
    found = [d for d in result.diagnostics if d.code == "MK507"]
    assert len(found) == 1 and '"textures/missing.png"' in found[0].message
    assert found[0].location is not None and found[0].location.line == 4


def test_namespaced_custom_elements_are_legal(tmp_path: Path) -> None:
    body = """<link name="a"><inertial><mass>1</mass></inertial><gz:extra value="1"/>
      <visual name="v" gz:flag="x"><geometry><box><size>1 1 1</size></box></geometry></visual></link>
      <ignition:meta><ignition:thing>1</ignition:thing></ignition:meta>"""
    result = read_text(tmp_path, model("1.9", body))
    assert result.diagnostics == [] and robot_of(result).links[0].visuals


def test_unknown_attribute_and_repeated_element(tmp_path: Path) -> None:
    body = '<link name="a" nmae="x"><pose>0 0 0 0 0 0</pose><pose>1 0 0 0 0 0</pose></link>'
    result = read_text(tmp_path, model("1.7", body))
    found = {(d.code, d.hint) for d in result.diagnostics}
    assert ("MK123", 'did you mean "name"?') in found and ("MK124", None) in found


# ---- worlds and includes ------------------------------------------------------------------------


def write_model_folder(root: Path, name: str, versions: dict[str, str]) -> None:
    folder = root / name
    folder.mkdir(parents=True)
    entries = "".join(f'<sdf version="{v}">{f}</sdf>' for v, f in versions.items())
    (folder / "model.config").write_text(f"<?xml version='1.0'?><model><name>{name}</name>{entries}</model>")
    for version, file in versions.items():
        body = LINK.format(name=f"link_{version.replace('.', '_')}", rel="", pose="0 0 0 0 0 0")
        (folder / file).write_text(model(version, body, name=name))


def test_world_with_models_and_includes(tmp_path: Path) -> None:
    write_model_folder(
        tmp_path / "models", "wheel", {"1.6": "wheel_16.sdf", "1.9": "wheel.sdf", "1.13": "future.sdf"}
    )
    (tmp_path / "local.sdf").write_text(
        model("1.7", LINK.format(name="body", rel="", pose="0 0 0 0 0 0"), "local")
    )
    world = (
        """<?xml version="1.0"?><sdf version="1.9"><world name="w">
      <frame name="spot"><pose>5 0 0 0 0 0</pose></frame>
      <light name="sun" type="directional"><direction>0 0 -1</direction></light>
      <model name="first">"""
        + LINK.format(name="a", rel="", pose="0 0 0 0 0 0")
        + """</model>
      <include><uri>model://wheel</uri><name>front_wheel</name><pose relative_to="spot">0 1 0 0 0 0</pose>
        <static>true</static></include>
      <include><uri>local.sdf</uri><pose relative_to="first">0 0 2 0 0 0</pose></include>
    </world></sdf>"""
    )
    resolver = Resolver(environ={"GZ_SIM_RESOURCE_PATH": str(tmp_path / "models")})
    result = read_text(tmp_path, world, "scene.world", ReadOptions(resolver=resolver))
    assert [d.code for d in result.diagnostics if d.severity.value != "info"] == []
    names = [r.name for r in result.robots]
    assert names == ["first", "front_wheel", "local"]
    wheel = result.robots[1]
    assert [link.name for link in wheel.links] == ["link_1_9"]  # model.config: highest version <= 1.12
    assert wheel.root_joint is JointType.FIXED
    assert_pose(wheel.root_pose, [5, 1, 0])
    assert_pose(result.robots[2].root_pose, [0, 0, 2])
    world_info = result.robots[0].extras["sdf_world"]
    assert world_info["name"] == "w" and [d.kind for d in world_info["lights"]] == ["light:directional"]
    out = CliRunner().invoke(
        main, ["tree", str(tmp_path / "scene.world")], env={"GZ_SIM_RESOURCE_PATH": str(tmp_path / "models")}
    )
    assert out.exit_code == 0
    assert out.stdout == (
        tree_text("first", "a", [])
        + tree_text("front_wheel", "link_1_9", [])
        + tree_text("local", "body", [])
    )


def test_nested_include_with_merge_and_cycle(tmp_path: Path) -> None:
    (tmp_path / "part.sdf").write_text(
        model("1.9", LINK.format(name="p", rel="", pose="0 0 1 0 0 0"), "part")
    )
    body = (
        LINK.format(name="base", rel="", pose="0 0 0 0 0 0")
        + "<include><uri>part.sdf</uri><name>left</name><pose>0 1 0 0 0 0</pose></include>"
        + '<include merge="true"><uri>part.sdf</uri><name>merged</name></include>'
        + '<joint name="j1" type="fixed"><parent>base</parent><child>left::p</child></joint>'
        + '<joint name="j2" type="fixed"><parent>base</parent><child>p</child></joint>'
    )
    robot = robot_of(read_text(tmp_path, model("1.9", body)))
    assert [link.name for link in robot.links] == ["base", "left::p", "p"]
    poses = robot.world_poses()
    assert_pose(poses["left::p"], [0, 1, 1]) and assert_pose(poses["p"], [0, 0, 1])  # type: ignore[func-returns-value]
    (tmp_path / "self.sdf").write_text(
        model(
            "1.9",
            LINK.format(name="x", rel="", pose="0 0 0 0 0 0") + "<include><uri>self.sdf</uri></include>",
        )
    )
    result = read_model(tmp_path / "self.sdf")
    assert codes(result).count("MK531") == 1


# ---- robustness ------------------------------------------------------------------------------------


def test_no_traceback_when_any_element_is_removed() -> None:
    """Remove each element of the clean base in turn: the reader reports, never raises."""
    text = (BROKEN / "support" / "clean.sdf").read_text()
    root = etree.fromstring(text.encode())
    count = sum(1 for _ in root.iter())
    with tempfile.TemporaryDirectory() as folder:
        for index in range(1, count):
            copy = etree.fromstring(text.encode())
            victim = list(copy.iter())[index]
            parent = victim.getparent()
            if parent is None or not isinstance(victim.tag, str):
                continue
            parent.remove(victim)
            path = Path(folder) / f"cut{index}.sdf"
            path.write_bytes(etree.tostring(copy))
            result = validate(path)
            assert result.robots or result.errors or result.diagnostics


def test_no_traceback_on_truncated_files() -> None:
    """Every truncation of the lecture's unicycle is refused with a coded error at a position in the file."""
    text = UNICYCLE.read_text()
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "cut.sdf"
        for cut in range(0, len(text), max(1, len(text) // 60)):
            path.write_text(text[:cut])
            result = validate(path)
            errors = [d for d in result.diagnostics if d.severity.value == "error"]
            assert errors, f"a file cut at {cut} of {len(text)} characters was accepted"
            for error in errors:
                assert re.fullmatch(r"MK\d{3}", error.code), error
                assert error.location is not None and error.location.file == str(path), error
            if cut:  # a non-empty cut is malformed XML: the error points into the text
                assert any(e.location is not None and e.location.line >= 1 for e in errors), errors


def test_bad_values_are_reported_not_raised(tmp_path: Path) -> None:
    body = """<link name="a"><pose>0 0 x 0 0 0</pose>
      <inertial><mass>heavy</mass><inertia><ixx>1e</ixx></inertia></inertial>
      <visual name="v"><geometry><box><size>1 1</size></box></geometry>
        <material><diffuse>red</diffuse></material></visual>
      <collision name="c"><geometry><cylinder><radius>-1</radius></cylinder></geometry></collision>
      <sensor name="s" type="camera"><camera><image><width>wide</width></image></camera></sensor></link>
      <joint name="j" type="revolute"><parent>a</parent><child>a</child><axis><xyz>0 0 0</xyz>
      <limit><lower>low</lower></limit></axis></joint>"""
    result = read_text(tmp_path, model("1.7", body))
    found = codes(result)
    assert found.count("MK121") >= 6 and "MK416" in found and "MK235" in found
    (negative,) = [d for d in result.diagnostics if d.code == "MK416"]
    assert negative.severity.value == "error" and "negative" in negative.message  # radius -1


# ---- libsdformat as an oracle ----------------------------------------------------------------------

ORACLE_SOURCE = r"""
#include <iostream>
#include <sdf/sdf.hh>
// modelkit's SDF oracle: sdf::Root::Load plus the checks of `gz sdf -k` (graphs, names).
// `gz sdf -k`'s recursiveSameTypeUniqueNames, with the exception current libsdformat makes
// (Element::NameUniquenessExceptions: <plugin> names may repeat; Gazebo loads such worlds).
static bool sameTypeUniqueNames(sdf::ElementPtr elem) {
  if (elem->GetName() == "plugin" || elem->GetName().find(':') != std::string::npos) return true;
  bool ok = true;
  for (const std::string &type : elem->GetElementTypeNames()) {
    if (type != "plugin" && !elem->HasUniqueChildNames(type)) {
      std::cout << "Error: Non-unique names detected in type " << type << " in <" << elem->GetName() << ">\n";
      ok = false;
    }
  }
  for (sdf::ElementPtr c = elem->GetFirstElement(); c; c = c->GetNextElement())
    ok = sameTypeUniqueNames(c) && ok;
  return ok;
}
// With --print FILE it prints the SDF libsdformat made of the file instead (a URDF: its URDF to SDF
// conversion, what Gazebo spawns), errors on stderr.
int main(int argc, char **argv) {
  const bool print = argc == 3 && std::string(argv[1]) == "--print";
  if (argc != 2 && !print) { std::cerr << "usage: sdf_check [--print] FILE\n"; return 2; }
  sdf::Root root;
  sdf::Errors errors = root.Load(argv[argc - 1]);
  for (const auto &e : errors)
    (print ? std::cerr : std::cout) << "Error Code " << static_cast<int>(e.Code()) << ": " << e.Message()
                                    << "\n";
  if (!errors.empty()) return 1;
  if (print) { std::cout << root.Element()->ToString(""); return 0; }
  if (!sdf::checkCanonicalLinkNames(&root)) { std::cout << "invalid canonical link name\n"; return 1; }
  if (!sdf::checkJointParentChildLinkNames(&root)) { std::cout << "invalid parent or child\n"; return 1; }
  if (!sdf::checkFrameAttachedToGraph(&root)) { std::cout << "invalid attached_to graph\n"; return 1; }
  if (!sdf::checkFrameAttachedToNames(&root)) { std::cout << "invalid attached_to name\n"; return 1; }
  if (!sdf::checkPoseRelativeToGraph(&root)) { std::cout << "invalid relative_to graph\n"; return 1; }
  if (!sameTypeUniqueNames(root.Element())) { std::cout << "non-unique names\n"; return 1; }
  std::cout << "Valid.\n";
  return 0;
}
"""
ORACLE_PACKAGES = "apt-get install -y g++ pkg-config libsdformat-dev"
# Cases where libsdformat 12 (SDFormat <= 1.9, Debian bookworm) has no opinion or a known gap.
NO_ORACLE_OPINION = {
    "mimic_undefined.sdf": "SDFormat 1.11, newer than libsdformat 12 reads",
    "include_cycle.sdf": "libsdformat 12 recurses without end on include cycles",
    "expressed_in_undefined.sdf": "libsdformat 12 resolves expressed_in only when asked (Root::Load passes)",
    "joint_parent_model_frame.sdf": "libsdformat 12 refuses __model__ as a joint end; 13 and later accept it",
    "joint_child_model_frame.sdf": "libsdformat 12 refuses __model__ as a joint end; 13 and later accept it",
}


@pytest.fixture(scope="session")
def sdf_oracle() -> Path:
    """The oracle program, compiled once per source version under the temp folder."""
    compiler, pkg_config = shutil.which("g++"), shutil.which("pkg-config")
    flags = None
    if compiler and pkg_config:
        probe = subprocess.run(
            [pkg_config, "--cflags", "--libs", "sdformat12"], capture_output=True, text=True
        )
        flags = probe.stdout.split() if probe.returncode == 0 else None
    if compiler is None or flags is None:
        if os.environ.get("MODELKIT_REQUIRE_ORACLES"):
            pytest.fail(f"libsdformat is required in CI (MODELKIT_REQUIRE_ORACLES is set): {ORACLE_PACKAGES}")
        pytest.skip(f"libsdformat not installed ({ORACLE_PACKAGES})")
    digest = hashlib.sha256((ORACLE_SOURCE + " ".join(flags)).encode()).hexdigest()[:16]
    folder = Path(tempfile.gettempdir()) / "modelkit-oracles"
    binary = folder / f"sdf_check-{digest}"
    if not binary.exists():
        folder.mkdir(parents=True, exist_ok=True)
        source = folder / f"sdf_check-{digest}.cc"
        source.write_text(ORACLE_SOURCE)
        partial = folder / f"sdf_check-{digest}.{os.getpid()}"
        subprocess.run([compiler, "-O0", "-o", str(partial), str(source), *flags], check=True)
        partial.replace(binary)
    return binary


def oracle_has_errors(binary: Path, path: Path) -> bool:
    """libsdformat's verdict: errors from Root::Load or the graph checks, or errors it only prints
    (a version it cannot convert)."""
    run = subprocess.run(
        [str(binary), path.name], cwd=path.parent, capture_output=True, text=True, timeout=60
    )
    printed = re.search(r"Error \[|Error:", run.stdout + run.stderr) is not None
    return run.returncode != 0 or printed


def oracle_files() -> list[Path]:
    cases = sorted(
        p for p in BROKEN.iterdir() if p.suffix in (".sdf", ".world") and p.name not in NO_ORACLE_OPINION
    )
    return [*corpus_files(), UNICYCLE, BROKEN / "support" / "clean.sdf", *cases]


@pytest.mark.parametrize("path", oracle_files(), ids=lambda p: f"{p.parent.name}/{p.name}")
def test_validate_agrees_with_libsdformat(path: Path, sdf_oracle: Path) -> None:
    ours = bool(validate(path).errors)
    theirs = oracle_has_errors(sdf_oracle, path)
    assert ours == theirs, (
        f"modelkit says {'errors' if ours else 'valid'}, libsdformat {'errors' if theirs else 'valid'}"
    )


def test_oracle_exclusions_are_real_case_files() -> None:
    for name in NO_ORACLE_OPINION:
        assert (BROKEN / name).is_file(), name


def test_model_uri_include_without_model_config_is_refused_like_libsdformat(
    tmp_path: Path, sdf_oracle: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """MK535 (issue 18 item 3): a model:// folder on the resource path with model.sdf but no model.config
    is refused by libsdformat (error code 13); with a model.config both accept it."""
    models = tmp_path / "models"
    for name in ("bare", "configured"):
        (models / name).mkdir(parents=True)
        (models / name / "model.sdf").write_text((BROKEN / "support" / "clean.sdf").read_text())
    (models / "configured" / "model.config").write_text(
        '<?xml version="1.0"?>\n<model><name>configured</name><sdf version="1.9">model.sdf</sdf></model>\n'
    )
    monkeypatch.setenv("SDF_PATH", str(models))
    monkeypatch.setenv("GZ_SIM_RESOURCE_PATH", str(models))
    for name, refused in (("bare", True), ("configured", False)):
        world = tmp_path / f"{name}.world"
        world.write_text(
            f'<?xml version="1.0"?>\n<sdf version="1.9"><world name="w"><include><uri>model://{name}</uri>'
            "</include></world></sdf>\n"
        )
        assert oracle_has_errors(sdf_oracle, world) is refused, name
        errors = [d.code for d in validate(world).errors]
        assert errors == (["MK535"] if refused else []), name


_NESTED_STATIC = """
    <model name="fixture">
      <static>true</static>
      <pose>1 0 0 0 0 0</pose>
      <link name="post">
        <collision name="post_collision"><geometry><box><size>0.1 0.1 0.5</size></box></geometry></collision>
      </link>
    </model>
  </model>
</sdf>"""


def test_nested_static_model_is_accepted_like_libsdformat(tmp_path: Path, sdf_oracle: Path) -> None:
    """MK155 (issue 18 item 3): a static model nested in a moving one is valid SDF; its links stay fixed in
    the world. No error, and the message no longer claims the model is skipped or that its links float."""
    clean = (BROKEN / "support" / "clean.sdf").read_text()
    path = tmp_path / "nested_static.sdf"
    path.write_text(clean.replace("  </model>\n</sdf>", _NESTED_STATIC))
    assert not oracle_has_errors(sdf_oracle, path)
    v = validate(path)
    assert v.errors == []
    (note,) = [d for d in v.diagnostics if d.code == "MK155"]
    assert note.severity.value == "warning" and "libsdformat accepts it" in note.message
    assert "skipped" not in note.message
    (detached,) = [d for d in v.diagnostics if d.code == "MK201"]
    assert detached.severity.value == "info" and 'nested model "fixture" is static' in detached.message
    assert "floats freely" not in detached.message


def test_include_placement_frame_with_pose_is_accepted(tmp_path: Path, sdf_oracle: Path) -> None:
    """The counterpart of broken_sdf/include_placement_without_pose.world (MK157): with a <pose>,
    libsdformat and modelkit accept it."""
    (tmp_path / "clean.sdf").write_text((BROKEN / "support" / "clean.sdf").read_text())
    world = tmp_path / "w.world"
    world.write_text(
        '<?xml version="1.0"?>\n<sdf version="1.9"><world name="w"><include><uri>clean.sdf</uri>'
        "<pose>0 0 1 0 0 0</pose><placement_frame>upper</placement_frame></include></world></sdf>\n"
    )
    assert not oracle_has_errors(sdf_oracle, world)
    assert validate(world).errors == []


@pytest.mark.parametrize("layout", ["model-root", "sdf-subfolder"])
def test_mesh_uri_relative_to_an_included_model_is_found_in_its_folder(
    tmp_path: Path, sdf_oracle: Path, layout: str
) -> None:
    """Issue 18 item 3: a mesh URI written relative to an included model's own file is resolved from that
    file's folder (as Gazebo does), not from the including file's: both layouts validate without a
    finding, libsdformat accepts them, and convert copies the mesh, which MuJoCo then loads."""
    kr16 = CORPUS / "kuka_experimental" / "kuka_kr16_support" / "meshes" / "kr16_2" / "collision"
    kr16 = kr16 / "link_1.stl"
    folder = tmp_path / "models" / "part"
    model_file, uri = ("model.sdf", "meshes/part.stl") if layout == "model-root" else (
        "sdf/model.sdf", "../meshes/part.stl")
    (folder / "meshes").mkdir(parents=True)
    (folder / "meshes" / "part.stl").write_bytes(kr16.read_bytes())
    (folder / model_file).parent.mkdir(parents=True, exist_ok=True)
    (folder / "model.config").write_text(
        f'<?xml version="1.0"?>\n<model><name>part</name><sdf version="1.9">{model_file}</sdf></model>\n')
    geometry = f"<geometry><mesh><uri>{uri}</uri></mesh></geometry>"
    (folder / model_file).write_text(model("1.9", (
        '<link name="base"><inertial><mass>1</mass><inertia><ixx>0.1</ixx><iyy>0.1</iyy><izz>0.1</izz>'
        f'</inertia></inertial><collision name="c">{geometry}</collision><visual name="v">{geometry}</visual>'
        "</link>"), name="part"))
    top = tmp_path / "scene" / "top.sdf"
    top.parent.mkdir()
    top.write_text(model("1.9", (
        '<link name="root"><inertial><mass>1</mass></inertial></link>'
        "<include><uri>model://part</uri><name>p</name></include>"
        '<joint name="j" type="fixed"><parent>root</parent><child>p::base</child></joint>'), name="top"))
    env = {"GZ_SIM_RESOURCE_PATH": str(tmp_path / "models")}
    result = CliRunner().invoke(main, ["validate", str(top)], env=env)
    assert result.exit_code == 0 and "0 error(s), 0 warning(s)" in result.output, result.output
    run = subprocess.run([str(sdf_oracle), top.name], cwd=top.parent, capture_output=True, text=True,
                         timeout=60, env={**os.environ, **env, "SDF_PATH": env["GZ_SIM_RESOURCE_PATH"]})
    assert run.returncode == 0 and "Error" not in run.stdout + run.stderr, run.stdout + run.stderr
    out = tmp_path / "out" / "top.xml"
    result = CliRunner().invoke(main, ["convert", str(top), "-o", str(out)], env=env)
    assert result.exit_code == 0, result.output
    import mujoco

    written = mujoco.MjModel.from_xml_path(str(out))
    assert written.nmesh == 1 and written.mesh_vertnum[0] > 0
