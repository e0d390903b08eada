"""The URDF writer against real tools: every sample and corpus model converts, Debian's check_urdf and
PyBullet (in a child process) accept the output, modelkit's URDF reader reads back the same robot
(compare_robots at 1e-9), the output is deterministic and idempotent; plus unit cases."""

from __future__ import annotations

import copy
import math
import subprocess
import sys
import textwrap
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest
from lxml import etree

from modelkit.api import validate
from modelkit.convert.api import CONVERTIBLE_ERRORS, prepare, render_model
from modelkit.convert.compare import Difference, compare_robots
from modelkit.convert.names import unique_name
from modelkit.convert.notes import ConversionNote, NoteSink
from modelkit.convert.options import WriteOptions
from modelkit.convert.output import OutputPlan
from modelkit.convert.registry import target_info
from modelkit.formats.urdf.write_joints import SYNTHESISED_EFFORT, SYNTHESISED_POSITION, SYNTHESISED_VELOCITY
from modelkit.formats.urdf.writer import urdf_renames
from modelkit.model import (
    CAMERA_KINDS,
    Box,
    Capsule,
    Device,
    DeviceKind,
    Geom,
    Inertial,
    Joint,
    JointLimits,
    JointType,
    Link,
    Mesh,
    Mimic,
    Robot,
)
from modelkit.spatial import Pose, matrix_from_rpy, rpy_from_matrix
from tests.conftest import CORPUS, SAMPLES, TUTORIAL, require_tool

SUFFIXES = (".body", ".urdf", ".xacro", ".sdf", ".world", ".xml")


def model_files() -> list[Path]:
    roots = [SAMPLES] + ([CORPUS] if CORPUS.is_dir() else [])
    return sorted(
        p for root in roots for p in root.rglob("*") if p.is_file() and p.name.lower().endswith(SUFFIXES)
    )


def write_to(
    robot: Robot, folder: Path, options: WriteOptions | None = None, relpath: str = "robot.urdf"
) -> tuple[bytes, list[ConversionNote]]:
    plan = OutputPlan(folder)
    notes = render_model(robot, "urdf", plan, relpath, options or WriteOptions())
    assert not plan.problems()
    plan.commit()
    return (folder / relpath).read_bytes(), notes


def read_back(path: Path) -> Robot:
    checked = validate(path)
    assert checked.robot is not None, [str(d) for d in checked.diagnostics]
    return checked.robot


@dataclass
class Converted:
    source: Path
    index: int
    prepared: Robot  # the model the writer got (tracks approximated)
    notes: list[ConversionNote]
    path: Path

    @property
    def label(self) -> str:
        return f"{self.source.relative_to(self.source.parents[2])}#{self.index}"

    def codes(self) -> set[str]:
        return {n.code for n in self.notes}


@pytest.fixture(scope="module")
def converted(tmp_path_factory: pytest.TempPathFactory) -> list[Converted]:
    """Every readable model of samples/ and the corpus, written as URDF (a traceback fails here)."""
    out = tmp_path_factory.mktemp("urdf")
    done: list[Converted] = []
    for n, source in enumerate(model_files()):
        checked = validate(source)
        if any(d.code not in CONVERTIBLE_ERRORS for d in checked.errors):
            continue
        for index, robot in enumerate(r for r in checked.robots if r.root is not None):
            folder = out / f"{n:03d}_{index}"
            _, notes = write_to(robot, folder)
            prepared = prepare(robot, target_info("urdf"), WriteOptions(), NoteSink())
            done.append(Converted(source, index, prepared, notes, folder / "robot.urdf"))
    return done


def test_every_model_converts(converted: list[Converted]) -> None:
    assert len(converted) >= 16  # the tutorial robots and the smartcar alone
    if CORPUS.is_dir():
        assert len(converted) >= 180, len(converted)  # measured: 187 robots from 123 files
    kinds = {c.source.suffix for c in converted}
    assert {".body", ".xacro"} <= kinds


def test_check_urdf_accepts_every_output(converted: list[Converted]) -> None:
    tool = require_tool("check_urdf")
    refused = []
    for item in converted:
        run = subprocess.run([tool, str(item.path)], capture_output=True, text=True, timeout=30)
        if run.returncode != 0 or "Successfully Parsed XML" not in run.stdout:
            refused.append(f"{item.label}: {run.stderr.strip()[:300]}")
    assert not refused, refused


PYBULLET_CHILD = textwrap.dedent("""
    import sys
    import pybullet as p
    p.connect(p.DIRECT)
    for path in sys.argv[1:]:
        try:
            body = p.loadURDF(path, flags=p.URDF_USE_INERTIA_FROM_FILE)
            ok = body >= 0
        except Exception:
            ok = False
        sys.stderr.write(("LOADED " if ok else "REFUSED ") + path + "\\n")
        sys.stderr.flush()
""")


def pybullet_load(paths: list[Path]) -> dict[str, bool]:
    """Which files PyBullet loads, in one child process (a crash leaves the rest unreported)."""
    pytest.importorskip("pybullet")
    run = subprocess.run(
        [sys.executable, "-c", PYBULLET_CHILD, *map(str, paths)], capture_output=True, text=True, timeout=300
    )
    found = {}
    for line in run.stderr.splitlines():
        word, _, path = line.partition(" ")
        if word in ("LOADED", "REFUSED"):
            found[path] = word == "LOADED"
    return found


def test_pybullet_loads_every_output(converted: list[Converted]) -> None:
    results = pybullet_load([c.path for c in converted])
    failed = [c.label for c in converted if not results.get(str(c.path))]
    assert not failed, failed


def expected_after_urdf(robot: Robot) -> Robot:
    """The model with the writer's documented substitutions: URDF needs both position bounds of a
    prismatic joint (and of a revolute joint limited on one side only), ±1e16 where there is none;
    a welded root hangs from a `world` link by a fixed joint at the robot's placement; a camera, LiDAR
    or IMU is a massless frame link on a fixed joint at its pose, a camera's optical frame one more
    (MK847: the tiny inertial a frame is written with reads back as none); a massless link on a moving
    joint has a tiny inertial (MK816)."""
    from modelkit.formats.urdf.write_frames import FRAMED_KINDS
    from modelkit.formats.urdf.write_links import TINY_INERTIA, TINY_MASS

    out = copy.deepcopy(robot)
    taken = {lk.name for lk in out.links} | {j.name for j in out.joints}
    for link in list(out.links):
        for device in link.devices:
            if device.canonical not in FRAMED_KINDS or device.name == link.name or "xml" in device.params:
                continue
            frame = unique_name(device.name, taken)
            out.links.append(Link(frame))
            out.joints.append(Joint(unique_name(f"{frame}_joint", taken), JointType.FIXED, link.name, frame,
                                    origin=device.pose))
            if device.canonical in CAMERA_KINDS:  # REP-103: z forward, x right, y down
                optical = unique_name(f"{frame}_optical", taken)
                rep103 = Pose(matrix_from_rpy(-math.pi / 2, 0.0, -math.pi / 2), np.zeros(3))
                out.links.append(Link(optical))
                out.joints.append(Joint(unique_name(f"{optical}_joint", taken), JointType.FIXED, frame,
                                        optical, origin=rep103))
    # a link of a fixed joint with exactly the tiny inertial reads back as a massless frame
    # (dm_control's manipulator gives its "pinch site" body that inertial)
    fixed = {joint.child for joint in out.joints if joint.type is JointType.FIXED}
    for link in out.links:
        inertial = link.inertial
        if (link.name in fixed and inertial is not None and inertial.mass == TINY_MASS
                and np.array_equal(inertial.com, np.zeros(3))
                and np.array_equal(inertial.inertia, np.eye(3) * TINY_INERTIA)):
            link.inertial = None
    # a massless link on a moving joint gets a tiny explicit inertial (MK816)
    moving = {joint.child for joint in out.joints if joint.type is not JointType.FIXED}
    for link in out.links:
        if link.name in moving and (link.inertial is None or link.inertial.mass <= 0.0):
            link.inertial = Inertial(TINY_MASS, (0.0, 0.0, 0.0), np.eye(3) * TINY_INERTIA)
    if out.root_joint is JointType.FIXED and out.root not in (None, "world"):
        root = str(out.root)
        out.links.insert(0, Link("world"))
        name = str(out.root_joint_name or f"world_to_{root}")
        out.joints.append(Joint(name, JointType.FIXED, "world", root, origin=out.root_pose))
        out.root, out.root_pose = "world", Pose()
    for joint in out.joints:
        limits = joint.limits
        if joint.type is JointType.PRISMATIC or (
            joint.type is JointType.REVOLUTE and limits.position_limited
        ):
            if not math.isfinite(limits.lower):
                limits.lower = -SYNTHESISED_POSITION
            if not math.isfinite(limits.upper):
                limits.upper = SYNTHESISED_POSITION
    return out


def ball_differences_only(diffs: list[Difference], item: Converted) -> bool:
    """A ball joint written as three continuous joints through two massless links (MK813)."""
    balls = {j.name for j in item.prepared.joints if j.type is JointType.BALL}
    for d in diffs:
        if d.quantity == "link-set" and "_ball_" in d.where:
            continue
        if d.quantity in ("joint-type", "joint-parent") and d.where in balls:
            continue
        return False
    return bool(balls)


def test_round_trip_reads_back_the_same_robot(converted: list[Converted]) -> None:
    clean, balls, failed = 0, 0, []
    for item in converted:
        back = read_back(item.path)
        diffs = compare_robots(expected_after_urdf(item.prepared), back, urdf_renames(item.notes))
        if not diffs:
            clean += 1
        elif ball_differences_only(diffs, item):
            balls += 1
        else:
            failed.append(f"{item.label}: {[str(d) for d in diffs[:4]]}")
    assert not failed, failed
    assert clean >= len(converted) - 4  # measured: all but the 4 robots with a ball joint


def test_urdf_to_urdf_is_idempotent_and_deterministic(converted: list[Converted], tmp_path: Path) -> None:
    sources = [c for c in converted if c.source.suffix in (".urdf", ".xacro")]
    assert sources
    for n, item in enumerate(sources):
        first = item.path.read_bytes()
        second, _ = write_to(read_back(item.path), tmp_path / f"again{n}")
        assert second == first, item.label
    for n, item in enumerate(c for c in converted if c.source.suffix == ".body"):
        again, _ = write_to(read_back_source(item), tmp_path / f"twice{n}")
        assert again == item.path.read_bytes(), item.label
        for mesh in sorted((item.path.parent / "meshes").glob("*")):
            assert (tmp_path / f"twice{n}" / "meshes" / mesh.name).read_bytes() == mesh.read_bytes()


def read_back_source(item: Converted) -> Robot:
    robots = [r for r in validate(item.source).robots if r.root is not None]
    return robots[item.index]


def test_tutorial_body_matches_the_hand_written_urdf(tmp_path: Path) -> None:
    """mobile_robot_sensors.body against the tutorial's own mobile_robot_sensors.urdf.

    Both model the LiDAR and the RealSense as links on fixed joints from TiltLink at the same places
    and name the wheel joints like their links. Known differences: the hand-written RealSense link is
    itself the optical frame (rpy -1.57 0 -1.57, Z forward) where ours is the sensor frame (+X forward,
    as the Gazebo sensor on it) with a child RealSense_optical at rpy -π/2 0 -π/2; its sensor links
    carry the visuals (here they stay on TiltLink, as in the .body) and its LeftWheel joint is at
    y = 0.146 where the .body says 0.145.
    """
    body = read_back(TUTORIAL / "mobile_robot_sensors.body")
    data, notes = write_to(body, tmp_path)
    ours = read_back(tmp_path / "robot.urdf")
    hand = read_back(TUTORIAL / "mobile_robot_sensors.urdf")
    assert {lk.name for lk in ours.links} == {lk.name for lk in hand.links} | {"RealSense_optical"}
    assert urdf_renames(notes) == {}
    ours_joints = {j.child: j for j in ours.joints}
    hand_joints = {j.child: j for j in hand.joints}
    for child, joint in ours_joints.items():
        if child == "RealSense_optical":
            continue
        other = hand_joints[child]
        assert joint.parent == other.parent and joint.type is other.type
        expected = other.origin.translation.copy()
        if child == "LeftWheel":
            assert expected[1] == 0.146
            expected[1] = 0.145
        assert np.allclose(joint.origin.translation, expected, atol=1e-12), child
        if child != "RealSense":
            assert np.allclose(joint.origin.rotation, other.origin.rotation, atol=1e-12)
        assert np.allclose(joint.axis, other.axis)
    ours_poses, hand_poses = ours.world_poses(), hand.world_poses()
    optical, hand_camera = ours_poses["RealSense_optical"], hand_poses["RealSense"]
    assert np.allclose(optical.translation, hand_camera.translation, atol=1e-12)
    assert np.allclose(optical.rotation, hand_camera.rotation, atol=1e-3)  # 1.57 against π/2
    assert {j.name for j in ours.joints} >= {"LeftWheel", "RightWheel", "PanJoint", "TiltJoint"}
    for link in ours.links:
        other_link = hand.link(link.name)
        if link.name in ("LiDAR", "RealSense", "RealSense_optical"):  # TF frames (tiny inertial: massless)
            assert link.inertial is None
            assert not link.visuals and not link.collisions
            continue
        assert other_link is not None and link.inertial is not None and other_link.inertial is not None
        assert link.inertial.mass == other_link.inertial.mass
        assert np.allclose(link.inertial.com, other_link.inertial.com, atol=1e-12)
        assert np.allclose(link.inertial.inertia, other_link.inertial.inertia, atol=1e-12)
    sensors = {s.get("name"): s for s in etree.fromstring(data).iter("sensor")}
    assert sensors["LiDAR"].get("type") == "gpu_lidar" and sensors["RealSense"].get("type") == "rgbd_camera"
    for name in ("LiDAR", "RealSense"):
        holder = sensors[name].getparent()
        assert holder is not None and holder.get("reference") == name
        assert sensors[name].find("pose") is None


# ---- unit cases ---------------------------------------------------------------------------------------


def _inertial(mass: float = 1.0) -> Inertial:
    return Inertial(
        mass,
        np.array([0.01, 0.02, 0.03]),
        np.array([[0.1, 0.01, -0.02], [0.01, 0.2, 0.003], [-0.02, 0.003, 0.3]]),
    )


def _robot(*joints: Joint, root_joint: JointType | None = JointType.FLOATING) -> Robot:
    robot = Robot("unit", root="base", root_joint=root_joint, source_format="body")
    robot.links = [Link("base", _inertial(2.0))] + [Link(j.child, _inertial()) for j in joints]
    robot.joints = list(joints)
    return robot


def _child(el: etree._Element, path: str) -> etree._Element:
    found = el.find(path)
    assert found is not None, path
    return found


def _joint_el(data: bytes, name: str) -> etree._Element:
    found = [j for j in etree.fromstring(data).iter("joint") if j.get("name") == name]
    assert len(found) == 1, name
    return found[0]


def test_revolute_limited_unlimited_and_prismatic(tmp_path: Path) -> None:
    origin = Pose(matrix_from_rpy(0.3, -0.2, 1.1), np.array([0.1, -0.2, 0.3]))
    limited = Joint(
        "hinge",
        JointType.REVOLUTE,
        "base",
        "a",
        origin=origin,
        axis=np.array([0.0, 0.6, 0.8]),
        limits=JointLimits(-1.0, 2.0, velocity=3.0, velocity_lower=-3.0, velocity_upper=3.0, effort=40.0),
    )
    free = Joint("wheel", JointType.REVOLUTE, "base", "b", damping=0.5)
    slider = Joint("slide", JointType.PRISMATIC, "base", "c", limits=JointLimits(effort=5.0), armature=0.1)
    robot = _robot(limited, free, slider)
    data, notes = write_to(robot, tmp_path)
    hinge = _joint_el(data, "hinge")
    assert hinge.get("type") == "revolute"
    assert _child(hinge, "limit").attrib == {"lower": "-1", "upper": "2", "effort": "40", "velocity": "3"}
    wheel = _joint_el(data, "wheel")
    assert wheel.get("type") == "continuous" and wheel.find("limit") is None
    assert _child(wheel, "dynamics").attrib == {"damping": "0.5", "friction": "0"}
    limit = _child(_joint_el(data, "slide"), "limit")
    assert limit.attrib == {"lower": "-1e16", "upper": "1e16", "effort": "5", "velocity": "1000000"}
    assert float(limit.get("velocity", "")) == SYNTHESISED_VELOCITY and SYNTHESISED_EFFORT == 1e6
    codes = [n.code for n in notes]
    assert codes.count("MK819") == 2 and "MK820" in codes
    back = read_back(tmp_path / "robot.urdf")
    assert compare_robots(expected_after_urdf(robot), back) == []
    assert math.isinf(back.joints[1].limits.upper)
    rpy = [float(v) for v in _child(hinge, "origin").get("rpy", "").split()]
    assert np.allclose(matrix_from_rpy(*rpy), origin.rotation, atol=1e-15)


def test_rpy_round_trips_at_gimbal_lock() -> None:
    for rpy in (
        (0.3, math.pi / 2, -0.4),
        (1.0, -math.pi / 2, 0.2),
        (math.pi, 0.0, -math.pi),
        (0.1, 0.2, 0.3),
    ):
        r = matrix_from_rpy(*rpy)
        assert np.allclose(matrix_from_rpy(*rpy_from_matrix(r)), r, atol=1e-14)


def test_world_link_option_and_root_notes(tmp_path: Path) -> None:
    arm = Joint("j", JointType.REVOLUTE, "base", "arm")
    robot = _robot(arm, root_joint=JointType.FIXED)
    robot.root_pose = Pose(matrix_from_rpy(0, 0, 0.5), np.array([1.0, 2.0, 0.0]))
    data, notes = write_to(robot, tmp_path / "plain")  # a welded root always hangs from `world`
    assert "MK823" not in {n.code for n in notes}
    assert _joint_el(data, "world_to_base").get("type") == "fixed"
    robot.root_joint = JointType.FLOATING
    data, notes = write_to(robot, tmp_path / "free")  # a floating root only with the option
    assert "MK823" in {n.code for n in notes} and b'"world"' not in data
    robot.root_joint = JointType.FIXED
    data, notes = write_to(robot, tmp_path / "world", WriteOptions(urdf_world_link=True))
    assert "MK823" not in {n.code for n in notes}
    root = etree.fromstring(data)
    assert _child(root, "link").get("name") == "world"
    weld = _joint_el(data, "world_to_base")
    assert weld.get("type") == "fixed" and _child(weld, "parent").get("link") == "world"
    assert _child(weld, "origin").attrib == {"xyz": "1 2 0", "rpy": "0 0 0.5"}
    back = read_back(tmp_path / "world" / "robot.urdf")
    assert back.root == "world" and back.root_joint is JointType.FIXED
    robot.root_joint = JointType.FLOATING
    data, _ = write_to(robot, tmp_path / "floating", WriteOptions(urdf_world_link=True))
    assert _joint_el(data, "world_to_base").get("type") == "floating"


def test_link_joint_name_clash_is_kept_or_renamed_on_request_and_mimic_follows(tmp_path: Path) -> None:
    """URDF allows a joint named like a link and ROS finds joints by name: the name is kept (MK846);
    option urdf_distinct_names renames the joint <name>_joint (MK800) and the mimic follows."""
    leader = Joint(
        "finger", JointType.REVOLUTE, "base", "finger", limits=JointLimits(0.0, 1.0, 2.0, -2.0, 2.0, 3.0)
    )
    follower = Joint(
        "other",
        JointType.REVOLUTE,
        "base",
        "b",
        limits=JointLimits(-1.0, 0.0, 2.0, -2.0, 2.0, 3.0),
        mimic=Mimic("finger", -1.0, 0.25),
    )
    robot = _robot(leader, follower)
    data, notes = write_to(robot, tmp_path / "kept")
    assert not [n for n in notes if n.code == "MK800"]
    kept = [n for n in notes if n.code == "MK846"]
    assert len(kept) == 1 and '"finger"' in kept[0].message
    assert _child(_joint_el(data, "finger"), "child").get("link") == "finger"
    assert _child(_joint_el(data, "other"), "mimic").get("joint") == "finger"
    assert compare_robots(robot, read_back(tmp_path / "kept" / "robot.urdf")) == []
    run_check_urdf(tmp_path / "kept" / "robot.urdf")

    data, notes = write_to(robot, tmp_path, WriteOptions(urdf_distinct_names=True))
    renamed = [n for n in notes if n.code == "MK800"]
    assert len(renamed) == 1 and '"finger"' in renamed[0].message and '"finger_joint"' in renamed[0].message
    assert "MK846" not in {n.code for n in notes}
    assert urdf_renames(notes) == {}  # links keep their names
    mimic = _child(_joint_el(data, "other"), "mimic")
    assert mimic.attrib == {"joint": "finger_joint", "multiplier": "-1", "offset": "0.25"}
    back = read_back(tmp_path / "robot.urdf")
    assert back.joints[1].mimic is not None and back.joints[1].mimic.joint == "finger_joint"
    assert compare_robots(robot, back) == []
    run_check_urdf(tmp_path / "robot.urdf")
    follower.mimic = Mimic("nowhere")
    data, notes = write_to(robot, tmp_path / "lost")
    assert _joint_el(data, "other").find("mimic") is None and "MK812" in {n.code for n in notes}


def run_check_urdf(path: Path) -> None:
    tool = require_tool("check_urdf")
    run = subprocess.run([tool, str(path)], capture_output=True, text=True, timeout=30)
    assert run.returncode == 0, run.stderr


def test_duplicate_and_empty_names(tmp_path: Path) -> None:
    robot = _robot(
        Joint("j", JointType.FIXED, "base", "a"),
        Joint("j", JointType.FIXED, "base", "b"),
        Joint("", JointType.FIXED, "base", "c"),
    )
    data, notes = write_to(robot, tmp_path)
    names = [j.get("name") for j in etree.fromstring(data).iter("joint")]
    assert names == ["j", "j_2", "c_joint"]
    assert sum(n.code == "MK800" for n in notes) == 2
    run_check_urdf(tmp_path / "robot.urdf")


def test_meshes_are_copied_and_referenced_relatively(tmp_path: Path) -> None:
    trimesh = pytest.importorskip("trimesh")
    source = tmp_path / "src"
    source.mkdir()
    trimesh.creation.box(extents=[0.1, 0.2, 0.3]).export(source / "part.stl")
    robot = _robot(Joint("j", JointType.FIXED, "base", "arm"))
    mesh = Mesh(uri="part.stl", path=str(source / "part.stl"), scale=np.array([2.0, 2.0, 2.0]))
    robot.links[0].visuals.append(Geom(mesh, Pose(np.eye(3), np.array([0.0, 0.0, 0.5]))))
    robot.links[1].collisions.append(Geom(Capsule(0.05, 0.2)))
    robot.links[1].collisions.append(Geom(Mesh(uri="gone.stl", path=None)))
    out = tmp_path / "out"
    data, notes = write_to(robot, out, relpath="urdf/robot.urdf")
    meshes = [{str(k): str(v) for k, v in m.attrib.items()} for m in etree.fromstring(data).iter("mesh")]
    assert meshes[0] == {"filename": "../meshes/part.stl", "scale": "2 2 2"}
    assert meshes[1]["filename"].startswith("../meshes/arm_collision0") and "scale" not in meshes[1]
    assert len(meshes) == 2  # the missing mesh is left out
    assert (out / "meshes" / "part.stl").read_bytes() == (source / "part.stl").read_bytes()
    assert (out / "urdf" / meshes[1]["filename"]).is_file()
    assert {"MK802", "MK805"} <= {n.code for n in notes}
    assert str(tmp_path) not in data.decode()
    run_check_urdf(out / "urdf" / "robot.urdf")
    assert pybullet_load([out / "urdf" / "robot.urdf"]) == {str(out / "urdf" / "robot.urdf"): True}


def test_ball_joint_becomes_three_continuous_joints(tmp_path: Path) -> None:
    ball = Joint("ball", JointType.BALL, "base", "arm", origin=Pose(np.eye(3), np.array([0.0, 0.0, 0.4])))
    robot = _robot(ball)
    data, notes = write_to(robot, tmp_path)
    joints = list(etree.fromstring(data).iter("joint"))
    assert [(j.get("name"), j.get("type"), _child(j, "axis").get("xyz")) for j in joints] == [
        ("ball_x", "continuous", "1 0 0"),
        ("ball_y", "continuous", "0 1 0"),
        ("ball_z", "continuous", "0 0 1"),
    ]
    assert "MK813" in {n.code for n in notes}
    back = read_back(tmp_path / "robot.urdf")
    poses = back.world_poses({"ball_x": 0.3, "ball_y": -0.2, "ball_z": 0.5})
    expected = Pose(matrix_from_rpy(0.0, 0.0, 0.0), np.array([0.0, 0.0, 0.4]))
    r = np.eye(3) @ _rx(0.3) @ _ry(-0.2) @ _rz(0.5)
    assert np.allclose(poses["arm"].translation, expected.translation)
    assert np.allclose(poses["arm"].rotation, r, atol=1e-12)


def _rx(a: float) -> np.ndarray:
    return matrix_from_rpy(a, 0.0, 0.0)


def _ry(a: float) -> np.ndarray:
    return matrix_from_rpy(0.0, a, 0.0)


def _rz(a: float) -> np.ndarray:
    return matrix_from_rpy(0.0, 0.0, a)


def test_devices_materials_and_loops(tmp_path: Path) -> None:
    from modelkit.model import LoopConstraint, VisualMaterial

    robot = _robot(Joint("j", JointType.REVOLUTE, "base", "arm"), root_joint=JointType.FLOATING)
    camera = Device(
        "Camera",
        "cam",
        Pose(np.eye(3), np.array([0.1, 0.0, 0.2])),
        canonical=DeviceKind.CAMERA,
        canonical_params={"width": 640, "height": 480, "horizontal_fov": 1.0, "near": 0.1, "far": 50.0},
    )
    light = Device("SpotLight", "lamp", canonical=DeviceKind.SPOT_LIGHT)
    kept = Device(
        "gps", "g", params={"xml": '<sensor name="g" type="gps"><update_rate>5</update_rate></sensor>'}
    )
    robot.links[1].devices += [camera, light, kept]
    red = VisualMaterial(diffuse=np.array([1.0, 0.0, 0.0]), specular=np.array([0.5, 0.5, 0.5]))
    robot.links[0].visuals += [
        Geom(Box(np.array([1.0, 1.0, 1.0])), material=red),
        Geom(Box(np.array([0.5, 0.5, 0.5])), material=red),
    ]
    robot.loops.append(LoopConstraint("loop", "hinge", "base", "arm"))
    data, notes = write_to(robot, tmp_path)
    root = etree.fromstring(data)
    assert [m.get("name") for m in root.findall("material")] == ["base_visual0"]
    sensors = {s.get("name"): s for s in root.iter("sensor")}
    assert set(sensors) == {"cam", "g"}
    assert sensors["cam"].get("type") == "camera" and sensors["cam"].findtext("camera/image/width") == "640"
    # the camera is its own link at the device pose (MK847); the kept block stays on its link
    assert sensors["cam"].findtext("pose") is None and sensors["cam"].getparent().get("reference") == "cam"
    assert _child(_joint_el(data, "cam_joint"), "origin").get("xyz") == "0.1 0 0.2"
    assert _child(_joint_el(data, "cam_optical_joint"), "parent").get("link") == "cam"
    assert sensors["g"].findtext("update_rate") == "5" and sensors["g"].getparent().get("reference") == "arm"
    codes = {n.code for n in notes}
    assert {"MK806", "MK810", "MK818", "MK847"} <= codes
    back = read_back(tmp_path / "robot.urdf")
    assert [d.name for d in back.links[1].devices] == ["g"]
    assert [d.name for d in next(lk for lk in back.links if lk.name == "cam").devices] == ["cam"]
    # The floating root reads back open (URDF's convention); --base auto would weld this shape resting on
    # its base, so the second write asks for the floating root the first one had.
    again, _ = write_to(back, tmp_path / "again", WriteOptions(base="floating"))
    assert again == data
    run_check_urdf(tmp_path / "robot.urdf")


def test_convert_api_writes_the_file(tmp_path: Path) -> None:
    from modelkit.convert.api import convert

    result = convert([TUTORIAL / "mobile_robot.body"], tmp_path / "out" / "robot.urdf")
    assert result.status == 0 and result.outputs
    assert (tmp_path / "out" / "robot.urdf").read_bytes().startswith(b'<?xml version="1.0"?>\n<robot name=')


def test_texture_copied_or_noted(tmp_path: Path) -> None:
    from modelkit.model import VisualMaterial

    (tmp_path / "wood.png").write_bytes(b"\x89PNG not really")
    robot = _robot(Joint("j", JointType.FIXED, "base", "arm"))
    white = VisualMaterial(name="wood", diffuse=np.ones(3), texture=str(tmp_path / "wood.png"))
    lost = VisualMaterial(name="wood", diffuse=np.array([1.0, 0.0, 1.0]), texture=str(tmp_path / "gone.png"))
    robot.links[1].visuals += [Geom(Box(np.ones(3)), material=white), Geom(Box(np.ones(3)), material=lost)]
    data, notes = write_to(robot, tmp_path / "out")
    materials = etree.fromstring(data).findall("material")
    assert [m.get("name") for m in materials] == ["wood", "wood_2"]
    assert _child(materials[0], "texture").get("filename") == "textures/wood.png"
    assert materials[1].find("texture") is None
    assert (tmp_path / "out" / "textures" / "wood.png").read_bytes() == (tmp_path / "wood.png").read_bytes()
    assert [n.code for n in notes if n.code == "MK818"] == ["MK818"]
    run_check_urdf(tmp_path / "out" / "robot.urdf")


def test_mjcf_cameras_on_links_are_written_not_reported_as_dropped(tmp_path: Path) -> None:
    """An MJCF camera on a body is a device (a Gazebo camera sensor in URDF); only what hangs on the
    world body is left out, and the note counts only that."""
    path = tmp_path / "cam.xml"
    path.write_text(
        '<mujoco model="m"><worldbody><light name="sun" pos="0 0 3"/><body name="b">'
        '<inertial pos="0 0 0" mass="1" diaginertia="0.1 0.1 0.1"/>'
        '<camera name="eye" pos="0 0 0.3"/><light name="lamp" pos="0 0 0.2"/></body></worldbody></mujoco>'
    )
    robot = validate(path).robots[0]
    out = tmp_path / "out" / "m.urdf"
    from modelkit.convert import write

    notes = write(robot, out)
    assert '<sensor name="eye" type="camera">' in out.read_text()
    dropped = [n.message for n in notes if "MJCF cameras" in n.message or "MJCF lights" in n.message]
    assert dropped == ["1 MJCF lights: URDF has no equivalent; left out"]  # the world's sun only
    assert any(n.code == "MK806" and '"lamp"' in n.message for n in notes)  # the link's lamp, once


@pytest.mark.parametrize("robot", ["mobile_robot_pantilt", "mobile_robot_tracks"])
def test_the_tutorial_robots_wheels_and_tracks_are_not_noted_as_lost(robot: str, tmp_path: Path) -> None:
    """convert's wheel and track passes record what they made in the model for the writers; the URDF
    writer took those records for another format's data and warned "extension data wheels: URDF has no
    equivalent; left out" (MK808) on the tutorial's robots, whose wheels and tracks it does write."""
    from modelkit.convert.api import write

    samples = Path(__file__).resolve().parents[1] / "samples"
    source = samples / "choreonoid_ros2_mobile_robot_tutorial" / "model"
    loaded = validate(source / f"{robot}.body").robot
    assert loaded is not None
    notes = write(loaded, tmp_path / f"{robot}.urdf")
    lost = [n.message for n in notes if n.code == "MK808" and "extension data" in n.message]
    assert lost == []
