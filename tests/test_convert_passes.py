"""The model passes that run before the writers: pseudo continuous tracks as rollers, --merge-fixed."""

from __future__ import annotations

import copy
import math
from pathlib import Path

import numpy as np
import pytest

import modelkit
from modelkit.api import validate
from modelkit.convert.api import prepare
from modelkit.convert.merge import merge_fixed_joints
from modelkit.convert.notes import NoteSink
from modelkit.convert.options import WriteOptions
from modelkit.convert.registry import target_info
from modelkit.convert.tracks import (
    MAX_ROLLERS,
    ROLLER_CLEARANCE,
    approximate_tracks,
    assembly_mass_properties,
)
from modelkit.geometry.extents import support
from modelkit.model import (
    Box,
    Capsule,
    Cone,
    Cylinder,
    Device,
    Ellipsoid,
    Geom,
    Inertial,
    Joint,
    JointType,
    Link,
    LoopConstraint,
    Robot,
    Sphere,
)
from modelkit.spatial import Pose

from .conftest import CORPUS, REPO, TUTORIAL

TRACKS_BODY = TUTORIAL / "mobile_robot_tracks.body"
TRACKS = ("LeftTracks", "RightTracks")


# ---- independent maths (numpy from scratch, not modelkit.spatial) ------------------------------


def rot(axis: str, angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    if axis == "x":
        return np.array([[1, 0, 0], [0, c, -s], [0, s, c]], dtype=float)
    if axis == "y":
        return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]], dtype=float)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]], dtype=float)


def rpy(r: float, p: float, y: float) -> np.ndarray:
    return rot("z", y) @ rot("y", p) @ rot("x", r)


def homogeneous(rotation: np.ndarray, translation: list[float] | np.ndarray) -> np.ndarray:
    t = np.eye(4)
    t[:3, :3] = rotation
    t[:3, 3] = translation
    return t


def as_matrix(pose: Pose) -> np.ndarray:
    return homogeneous(pose.rotation, pose.translation)


def random_inertia(rng: np.random.Generator, mass: float) -> np.ndarray:
    """A valid full tensor: principal moments obeying the triangle inequality, rotated."""
    a, b, c = rng.uniform(0.5, 1.5, 3)
    moments = mass * np.array([b * b + c * c, a * a + c * c, a * a + b * b]) / 12.0
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    return q @ np.diag(moments) @ q.T


# ---- pseudo continuous tracks ------------------------------------------------------------------


@pytest.fixture
def tracks_robot() -> Robot:
    return modelkit.load(TRACKS_BODY)


def total_mass(robot: Robot) -> float:
    return sum(link.inertial.mass for link in robot.links if link.inertial is not None)


def test_tracks_become_rows_of_rollers(tracks_robot: Robot) -> None:
    original = copy.deepcopy(tracks_robot)
    notes = NoteSink()
    approximate_tracks(tracks_robot, notes)

    assert abs(total_mass(tracks_robot) - total_mass(original)) <= 1e-12
    assert not any(j.type is JointType.PSEUDO_CONTINUOUS_TRACK for j in tracks_robot.joints)
    assert [n.code for n in notes.items] == ["MK809", "MK809"]
    assert all(n.source is not None and n.source.line for n in notes.items)
    record = tracks_robot.extras["tracks"]
    assert sorted(record) == sorted(TRACKS)
    for name in TRACKS:
        track = tracks_robot.link(name)
        source_track = original.link(name)
        assert track is not None and source_track is not None
        assert track.collisions == [] and len(track.visuals) == 1
        assert track.contact_material is None
        assert tracks_robot.joints[[j.name for j in tracks_robot.joints].index(name)].type is JointType.FIXED

        # the track's own geometry (an Extrusion): x = length, y = width, z = height in the track frame
        vertices = source_track.collisions[0].geometry.data.vertices  # type: ignore[union-attr]
        lo, hi = vertices.min(axis=0), vertices.max(axis=0)
        assert np.allclose(hi - lo, [0.34, 0.06, 0.12], atol=1e-12)

        entry = record[name]
        rollers, links = entry["rollers"], entry["roller_links"]
        # documented: r = height / 2 = 0.06; N = 2 (a third roller would touch its neighbours)
        assert entry["radius"] == pytest.approx(0.06, abs=1e-15)
        assert len(rollers) == len(links) == 2
        assert links == [f"{name}_roller0", f"{name}_roller1"]
        assert entry["axis"] == [0.0, 1.0, 0.0] and entry["forward"] == [1.0, 0.0, 0.0]
        joints = {j.name: j for j in tracks_robot.joints}
        centres = []
        for i, (jname, lname) in enumerate(zip(rollers, links, strict=True)):
            joint = joints[jname]
            roller = tracks_robot.link(lname)
            assert roller is not None and roller.synthesised and roller.track == name and roller.extras == {}
            assert joint.type is JointType.REVOLUTE and joint.parent == name and joint.child == lname
            assert not joint.limits.position_limited
            assert np.allclose(joint.axis, [0, 1, 0])
            if i == 0:
                assert joint.mimic is None and joint.joint_id == original.joints[
                    [j.name for j in original.joints].index(name)].joint_id
            else:
                assert joint.mimic is not None and joint.mimic.joint == rollers[0]
                assert joint.mimic.multiplier == 1.0 and joint.mimic.offset == 0.0
            assert roller.contact_material == "TankTracks"
            (geom,) = roller.collisions
            assert isinstance(geom.geometry, Cylinder)
            assert geom.geometry.radius == entry["radius"]
            assert geom.geometry.length == pytest.approx(0.06, abs=1e-15)
            # the cylinder's Z lies along the roller axis
            assert np.allclose(geom.pose.rotation @ [0, 0, 1], [0, 1, 0], atol=1e-15)
            centre = joint.origin.translation + joint.origin.rotation @ geom.pose.translation
            centres.append(centre)
            # the roller's bottom lies on the track's bottom plane, and it spans the track's width
            assert centre[2] - geom.geometry.radius == pytest.approx(lo[2], abs=1e-12)
            assert centre[1] == pytest.approx(0.5 * (lo[1] + hi[1]), abs=1e-12)
        # the first and last rollers touch the track's ends, and the rollers do not touch each other
        assert centres[0][0] - 0.06 == pytest.approx(lo[0], abs=1e-12)
        assert centres[-1][0] + 0.06 == pytest.approx(hi[0], abs=1e-12)
        assert np.linalg.norm(centres[1] - centres[0]) > 2 * 0.06

        # the assembly keeps the track's mass and centre of mass
        mass, com, _ = assembly_mass_properties(tracks_robot, name)
        assert source_track.inertial is not None
        assert mass == pytest.approx(source_track.inertial.mass, abs=1e-12)
        assert np.allclose(com, source_track.inertial.com, atol=1e-12)


def test_rollers_touch_the_ground_where_the_track_did(tracks_robot: Robot) -> None:
    """World frame: the lowest point of every roller is the lowest point of the track geometry."""
    before = tracks_robot.world_poses()
    lowest = {}
    for name in TRACKS:
        link = tracks_robot.link(name)
        assert link is not None
        world = as_matrix(before[name]) @ as_matrix(link.collisions[0].pose)
        vertices = link.collisions[0].geometry.data.vertices  # type: ignore[union-attr]
        lowest[name] = min((world @ np.append(v, 1.0))[2] for v in vertices)
    approximate_tracks(tracks_robot, NoteSink())
    after = tracks_robot.world_poses()
    for name in TRACKS:
        for lname in tracks_robot.extras["tracks"][name]["roller_links"]:
            roller = tracks_robot.link(lname)
            assert roller is not None
            (geom,) = roller.collisions
            world = as_matrix(after[lname]) @ as_matrix(geom.pose)
            assert isinstance(geom.geometry, Cylinder)
            # a cylinder along its local Z: lowest world point = centre_z - r·|horizontal part of axis|
            axis = world[:3, 2]
            bottom = world[2, 3] - geom.geometry.radius * math.hypot(axis[0], axis[1])
            assert bottom == pytest.approx(lowest[name], abs=1e-12)


def _box_track_robot(track_axis: list[float], track_rotation: np.ndarray) -> Robot:
    """A chassis with one box-shaped track whose inertia is that of a uniform box (so the exact
    inertia split is possible), its frame turned by ``track_rotation``."""
    size = np.array([0.6, 0.1, 0.2])  # in the track's (forward, axis, up) directions, see below
    chassis = Link("chassis", Inertial(10.0, np.zeros(3), np.diag([0.5, 0.6, 0.7])),
                   collisions=[Geom(Box(np.array([0.4, 0.3, 0.1])))])
    # the box lies along the root's axes: in the track frame (the root frame turned by
    # track_rotation) its pose is turned back by the transpose
    box_pose = Pose(track_rotation.T, np.zeros(3))
    mass = 2.0
    box_inertia = mass / 12.0 * np.diag([size[1] ** 2 + size[2] ** 2, size[0] ** 2 + size[2] ** 2,
                                         size[0] ** 2 + size[1] ** 2])
    track = Link("track", Inertial(mass, np.array([0.01, 0.0, -0.02]),
                                   track_rotation.T @ box_inertia @ track_rotation),
                 collisions=[Geom(Box(size), box_pose)], visuals=[Geom(Box(size), box_pose)],
                 contact_material="Tracks")
    joint = Joint("track_joint", JointType.PSEUDO_CONTINUOUS_TRACK, "chassis", "track",
                  Pose(track_rotation, np.array([0.0, 0.3, 0.0])), np.array(track_axis, dtype=float))
    return Robot("box_tank", [chassis, track], [joint], root="chassis", root_joint=JointType.FLOATING)


@pytest.mark.parametrize("turn", [0.0, math.pi / 2, -math.pi / 3])
def test_box_track_keeps_mass_com_and_inertia_exactly(turn: float) -> None:
    # the track frame is turned about Z; its axis is given so that it is the root's +Y in every case
    rotation = rot("z", turn)
    axis = rotation.T @ np.array([0.0, 1.0, 0.0])
    robot = _box_track_robot(axis.tolist(), rotation)
    source = copy.deepcopy(robot.link("track"))
    assert source is not None and source.inertial is not None
    notes = NoteSink()
    approximate_tracks(robot, notes)
    entry = robot.extras["tracks"]["track_joint"]
    # box: length 0.6, height 0.2 → r = 0.1, N = 1 + floor(0.4 / 0.204) = 2
    assert entry["radius"] == pytest.approx(0.1, abs=1e-12)
    assert len(entry["rollers"]) == 2
    # forward = axis × up: the root's +X whatever the track frame's turn (Choreonoid's convention)
    assert np.allclose(rotation @ np.array(entry["forward"]), [1.0, 0.0, 0.0], atol=1e-12)
    mass, com, inertia = assembly_mass_properties(robot, "track")
    assert mass == pytest.approx(2.0, abs=1e-12)
    assert np.allclose(com, source.inertial.com, atol=1e-12)
    assert np.allclose(inertia, source.inertial.inertia, atol=1e-12)
    assert "the assembly's inertia is the track's" in notes.items[0].message
    track = robot.link("track")
    assert track is not None and track.inertial is not None
    assert np.all(np.linalg.eigvalsh(track.inertial.inertia) > 0)


def test_prepare_approximates_tracks_except_for_body() -> None:
    robot = modelkit.load(TRACKS_BODY)
    as_body = prepare(robot, target_info("body"), WriteOptions(), NoteSink())
    assert sum(j.type is JointType.PSEUDO_CONTINUOUS_TRACK for j in as_body.joints) == 2
    notes = NoteSink()
    as_urdf = prepare(robot, target_info("urdf"), WriteOptions(), notes)
    assert not any(j.type is JointType.PSEUDO_CONTINUOUS_TRACK for j in as_urdf.joints)
    assert sum(n.code == "MK809" for n in notes.items) == 2
    # the source robot is untouched
    assert sum(j.type is JointType.PSEUDO_CONTINUOUS_TRACK for j in robot.joints) == 2
    assert "tracks" not in robot.extras


def test_tracks_then_merge_fixed() -> None:
    robot = modelkit.load(TRACKS_BODY)
    notes = NoteSink()
    merged = prepare(robot, target_info("urdf"), WriteOptions(merge_fixed=True), notes)
    assert merged.link("LeftTracks") is None
    roller = next(j for j in merged.joints if j.child == "LeftTracks_roller0")
    assert roller.parent == "Chassis"
    assert np.allclose(roller.origin.translation, [-0.08 - 0.11, 0.155, 0.06], atol=1e-12)
    assert abs(total_mass(merged) - total_mass(robot)) <= 1e-12
    assert sum(n.code == "MK815" for n in notes.items) == 2


MJCF_WRITER = REPO / "modelkit" / "formats" / "mjcf" / "writer.py"


def test_tracks_robot_written_as_mjcf_loads_in_mujoco(tmp_path: Path) -> None:
    if not MJCF_WRITER.is_file():
        pytest.skip("the MJCF writer (modelkit/formats/mjcf/writer.py) does not exist yet")
    mujoco = pytest.importorskip("mujoco")
    from modelkit.convert import write

    robot = modelkit.load(TRACKS_BODY)
    out = tmp_path / "x.xml"
    notes = write(robot, out)
    assert sum(n.code == "MK809" for n in notes) == 2
    model = mujoco.MjModel.from_xml_path(str(out))
    assert float(np.sum(model.body_mass)) == pytest.approx(total_mass(robot), abs=1e-9)
    names = {mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, i) for i in range(model.njnt)}
    for name in TRACKS:
        assert {f"{name}_roller0_joint", f"{name}_roller1_joint"} <= names

    # Drive it on a floor: the lead rollers at ω = v / r (velocity servos added here; the mimic
    # equalities written by the writer carry the others). A positive track velocity drives the
    # tutorial robot forward (+X) in Choreonoid, so it must here too, at the track speed.
    spec = mujoco.MjSpec.from_file(str(out))
    spec.worldbody.add_geom(type=mujoco.mjtGeom.mjGEOM_PLANE, size=[5, 5, 0.1], friction=[1, 0.005, 0.0001])
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    speed, radius = 0.2, 0.06
    for name in TRACKS:
        servo = spec.add_actuator(name=f"{name}_servo", target=f"{name}_roller0_joint",
                                  trntype=mujoco.mjtTrn.mjTRN_JOINT)
        servo.set_to_velocity(kv=2.0)
    model = spec.compile()
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    chassis = model.body("Chassis").id
    start = data.xpos[chassis].copy()
    for name in TRACKS:
        data.ctrl[model.actuator(f"{name}_servo").id] = speed / radius
    for _ in range(int(2.0 / model.opt.timestep)):
        mujoco.mj_step(model, data)
    moved = data.xpos[chassis] - start
    assert moved[0] > 0.3  # 2 s at 0.2 m/s, after the start-up
    assert abs(moved[1]) < 0.02 and abs(moved[2]) < 0.01
    assert data.qvel[0] == pytest.approx(speed, rel=0.05)
    for name in TRACKS:
        follower = model.joint(f"{name}_roller1_joint").dofadr[0]
        assert data.qvel[follower] == pytest.approx(speed / radius, rel=0.05)


# ---- --merge-fixed ---------------------------------------------------------------------------------


def _three_link_robot() -> Robot:
    rng = np.random.default_rng(7)
    base = Link("base", Inertial(2.0, np.array([0.1, -0.2, 0.05]), random_inertia(rng, 2.0)),
                visuals=[Geom(Box(np.array([0.1, 0.2, 0.3])),
                              Pose(rpy(0.1, 0.2, 0.3), np.array([0.0, 0.1, 0.0])))])
    a = Link("a", Inertial(1.5, np.array([0.03, 0.2, -0.1]), random_inertia(rng, 1.5)),
             visuals=[Geom(Box(np.array([0.1, 0.1, 0.1])),
                           Pose(rpy(0.5, -0.2, 0.1), np.array([0.1, 0.0, 0.2])))],
             collisions=[Geom(Cylinder(0.05, 0.2), Pose(rpy(0.0, 1.0, 0.0), np.array([0.0, 0.0, 0.1])))],
             devices=[Device("Camera", "cam", Pose(rpy(0.0, 0.0, 1.2), np.array([0.05, 0.0, 0.0])))])
    b = Link("b", Inertial(0.7, np.array([-0.3, 0.05, 0.12]), random_inertia(rng, 0.7)),
             collisions=[Geom(Box(np.array([0.2, 0.1, 0.05])),
                              Pose(rpy(-0.3, 0.4, 0.9), np.array([0.0, 0.2, 0.0])))])
    c = Link("c", Inertial(0.4, np.array([0.0, 0.0, 0.2]), random_inertia(rng, 0.4)))
    frame = Link("frame")  # massless, on a fixed joint below the moving link
    joints = [
        Joint("j_a", JointType.FIXED, "base", "a", Pose(rpy(0.3, -0.4, 1.1), np.array([0.2, 0.1, -0.3]))),
        Joint("j_b", JointType.FIXED, "a", "b", Pose(rpy(-0.7, 0.2, 0.5), np.array([-0.1, 0.25, 0.15]))),
        Joint("j_c", JointType.REVOLUTE, "b", "c", Pose(rpy(0.2, 0.0, -0.6), np.array([0.0, 0.0, 0.4])),
              np.array([0.0, 1.0, 0.0])),
        Joint("j_frame", JointType.FIXED, "c", "frame", Pose(rpy(0.0, 0.5, 0.0), np.array([0.1, 0.0, 0.0]))),
    ]
    loop = LoopConstraint("loop", "hinge", "b", "c", Pose(rpy(0.1, 0.0, 0.0), np.array([0.1, 0.0, 0.0])),
                          Pose(np.eye(3), np.array([0.0, 0.0, -0.1])))
    return Robot("three", [base, a, b, c, frame], joints, root="base", root_joint=JointType.FLOATING,
                 root_pose=Pose(rpy(0.2, 0.1, -0.4), np.array([1.0, 2.0, 0.5])), loops=[loop])


def test_merge_fixed_combines_mass_properties_exactly() -> None:
    robot = _three_link_robot()
    # independent: each body's world transform composed from the joint origins by hand
    t_base = homogeneous(rpy(0.2, 0.1, -0.4), [1.0, 2.0, 0.5])
    t_a = t_base @ homogeneous(rpy(0.3, -0.4, 1.1), [0.2, 0.1, -0.3])
    t_b = t_a @ homogeneous(rpy(-0.7, 0.2, 0.5), [-0.1, 0.25, 0.15])
    parts = []
    for link, t in zip(robot.links[:3], (t_base, t_a, t_b), strict=True):
        assert link.inertial is not None
        r = t[:3, :3]
        parts.append((link.inertial.mass, r @ link.inertial.com + t[:3, 3], r @ link.inertial.inertia @ r.T))
    mass = sum(m for m, _, _ in parts)
    com_world = sum(m * c for m, c, _ in parts) / mass
    inertia_world = np.zeros((3, 3))
    for m, c, i in parts:
        d = c - com_world
        inertia_world += i + m * (d @ d * np.eye(3) - np.outer(d, d))
    before = robot.world_poses({"j_c": 0.7})
    cam_world = t_a @ homogeneous(rpy(0.0, 0.0, 1.2), [0.05, 0.0, 0.0])
    loop_world = (as_matrix(before["b"]) @ as_matrix(robot.loops[0].pose_in_link1),
                  as_matrix(before["c"]) @ as_matrix(robot.loops[0].pose_in_link2))
    geoms_world = sorted(
        (as_matrix(before[link.name]) @ as_matrix(g.pose)).round(12).tobytes()
        for link in robot.links[:3] for g in [*link.visuals, *link.collisions]
    )

    notes = NoteSink()
    merge_fixed_joints(robot, notes)

    assert [link.name for link in robot.links] == ["base", "c"]
    assert [(j.name, j.parent, j.child) for j in robot.joints] == [("j_c", "base", "c")]
    assert sorted(n.message.split()[1] for n in notes.items) == ["a", "b", "frame"]
    assert all(n.code == "MK815" for n in notes.items)
    base = robot.link("base")
    assert base is not None and base.inertial is not None
    r_base = t_base[:3, :3]
    assert base.inertial.mass == pytest.approx(mass, abs=1e-12)
    assert np.allclose(r_base @ base.inertial.com + t_base[:3, 3], com_world, atol=1e-12)
    assert np.allclose(r_base @ base.inertial.inertia @ r_base.T, inertia_world, atol=1e-12)
    # the massless frame merged into c leaves c's mass properties as they were
    c = robot.link("c")
    assert c is not None and c.inertial is not None and c.inertial.mass == 0.4

    after = robot.world_poses({"j_c": 0.7})
    assert np.allclose(as_matrix(after["c"]), as_matrix(before["c"]), atol=1e-12)
    assert np.allclose(as_matrix(after["base"]), as_matrix(before["base"]), atol=1e-12)
    (device,) = base.devices
    assert np.allclose(as_matrix(after["base"]) @ as_matrix(device.pose), cam_world, atol=1e-12)
    assert sorted((as_matrix(after["base"]) @ as_matrix(g.pose)).round(12).tobytes()
                  for g in [*base.visuals, *base.collisions]) == geoms_world
    (loop,) = robot.loops
    assert loop.link1 == "base" and loop.link2 == "c"
    assert np.allclose(as_matrix(after["base"]) @ as_matrix(loop.pose_in_link1), loop_world[0], atol=1e-12)
    assert np.allclose(as_matrix(after["c"]) @ as_matrix(loop.pose_in_link2), loop_world[1], atol=1e-12)


def test_merge_keeps_world_welds_and_tracks() -> None:
    world = Link("world")
    base = Link("base", Inertial(1.0, np.zeros(3), np.eye(3)))
    track = Link("track", Inertial(1.0, np.zeros(3), np.eye(3)))
    robot = Robot("r", [world, base, track], [
        Joint("weld", JointType.FIXED, "world", "base", Pose(np.eye(3), np.array([0.0, 0.0, 1.0]))),
        Joint("track", JointType.PSEUDO_CONTINUOUS_TRACK, "base", "track"),
    ], root="world")
    merge_fixed_joints(robot, NoteSink())
    assert [link.name for link in robot.links] == ["world", "base", "track"]
    assert len(robot.joints) == 2


def test_merge_removes_a_loop_that_joins_a_link_to_itself() -> None:
    base = Link("base", Inertial(1.0, np.zeros(3), np.eye(3)))
    tip = Link("tip", Inertial(1.0, np.zeros(3), np.eye(3)))
    robot = Robot("r", [base, tip], [Joint("j", JointType.FIXED, "base", "tip")], root="base",
                  loops=[LoopConstraint("l", "fixed", "base", "tip")])
    notes = NoteSink()
    merge_fixed_joints(robot, notes)
    assert robot.loops == []
    assert "loop l" in notes.items[0].message


CORPUS_XACROS = [
    "franka_description/robots/fer/fer.urdf.xacro",
    "franka_description/robots/fr3/fr3.urdf.xacro",
    "franka_description/robots/multi_arm/multi_arm.urdf.xacro",
    "kuka_experimental/kuka_kr16_support/urdf/kr16_2.xacro",
    "kuka_experimental/kuka_lbr_iiwa_support/urdf/lbr_iiwa_14_r820.xacro",
]


@pytest.mark.parametrize("relpath", CORPUS_XACROS)
def test_corpus_arms_merge_without_error(relpath: str) -> None:
    path = CORPUS / relpath
    if not path.is_file():
        pytest.skip(f"corpus file {relpath} is not available")
    (robot,) = validate(path).robots
    mass = total_mass(robot)
    fixed = sum(j.type is JointType.FIXED for j in robot.joints)
    assert fixed > 0  # the massless frames on fixed joints are what this exercises
    moving = sorted(j.name for j in robot.joints if j.type.moves)
    before = robot.world_poses()
    notes = NoteSink()
    merge_fixed_joints(robot, notes)
    assert not any(j.type is JointType.FIXED for j in robot.joints)
    assert len(notes.items) == fixed
    assert sorted(j.name for j in robot.joints) == moving
    assert abs(total_mass(robot) - mass) <= 1e-9
    after = robot.world_poses()
    for name, pose in after.items():
        assert np.allclose(as_matrix(pose), as_matrix(before[name]), atol=1e-12)


def _surface_points(geometry: object, n: int = 200) -> np.ndarray:
    """Dense points on a primitive's surface (its Z axis along the length), for the support check."""
    t = np.linspace(0.0, 2 * math.pi, n, endpoint=False)
    if isinstance(geometry, Box):
        corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=float)
        return corners * 0.5 * np.asarray(geometry.size)
    if isinstance(geometry, Cylinder | Cone):
        half = 0.5 * geometry.length
        ring = np.stack([geometry.radius * np.cos(t), geometry.radius * np.sin(t)], axis=1)
        bottom = np.column_stack([ring, np.full(n, -half)])
        top = (np.column_stack([ring, np.full(n, half)]) if isinstance(geometry, Cylinder)
               else np.array([[0.0, 0.0, half]]))
        return np.vstack([bottom, top])
    # spheres, capsules, ellipsoids: a fine latitude-longitude grid
    u, v = np.meshgrid(t, np.linspace(0.0, math.pi, n // 2))
    unit = np.stack([np.sin(v) * np.cos(u), np.sin(v) * np.sin(u), np.cos(v)], axis=-1).reshape(-1, 3)
    if isinstance(geometry, Sphere):
        return geometry.radius * unit
    if isinstance(geometry, Ellipsoid):
        return unit * np.asarray(geometry.radii)
    assert isinstance(geometry, Capsule)
    return np.vstack([geometry.radius * unit + [0, 0, s * 0.5 * geometry.length] for s in (-1, 1)])


@pytest.mark.parametrize("geometry", [
    Box(np.array([0.3, 0.1, 0.2])), Sphere(0.2), Cylinder(0.1, 0.4), Capsule(0.05, 0.3), Cone(0.2, 0.5),
    Ellipsoid(np.array([0.1, 0.2, 0.3])),
], ids=lambda g: type(g).__name__)
def test_track_extents_use_exact_support_functions(geometry: object) -> None:
    rng = np.random.default_rng(3)
    points = _surface_points(geometry)
    for _ in range(20):
        d = rng.normal(size=3)
        d /= np.linalg.norm(d)
        exact = support(geometry, d)  # type: ignore[arg-type]
        assert exact is not None
        sampled = float(np.max(points @ d))
        assert sampled <= exact + 1e-12
        assert exact - sampled < 2e-3  # the sampling's own error


def test_a_short_track_gets_two_overlapping_rollers_and_says_so() -> None:
    rotation = np.eye(3)
    robot = _box_track_robot([0.0, 1.0, 0.0], rotation)
    track = robot.link("track")
    assert track is not None
    for geom in [*track.collisions, *track.visuals]:
        geom.geometry = Box(np.array([0.3, 0.1, 0.2]))  # length 0.3 < 4r = 0.4
    notes = NoteSink()
    approximate_tracks(robot, notes)
    entry = robot.extras["tracks"]["track_joint"]
    assert len(entry["rollers"]) == 2 and entry["overlap"] is True
    assert "the rollers overlap" in notes.items[0].message


@pytest.mark.parametrize("length", [1.0e6, 1.0e30])
def test_an_absurdly_long_track_gets_at_most_max_rollers_and_says_so(length: float) -> None:
    """A track whose extent is absurd for its height (a semantic fuzz mutant: an Extrusion point at
    3.5e38 m) once asked for ~1e38 rollers and ran the machine out of memory."""
    robot = _box_track_robot([0.0, 1.0, 0.0], np.eye(3))
    track = robot.link("track")
    assert track is not None
    for geom in [*track.collisions, *track.visuals]:
        geom.geometry = Box(np.array([length, 0.1, 0.2]))
    notes = NoteSink()
    approximate_tracks(robot, notes)
    entry = robot.extras["tracks"]["track_joint"]
    assert len(entry["rollers"]) == MAX_ROLLERS
    assert entry["overlap"] is False
    assert f"longer than {MAX_ROLLERS} rollers of its height cover" in notes.items[0].message


def test_a_track_that_fits_max_rollers_gets_them_all_without_gaps_note() -> None:
    robot = _box_track_robot([0.0, 1.0, 0.0], np.eye(3))
    track = robot.link("track")
    assert track is not None
    r = 0.1  # the box's height 0.2 / 2
    fits = 2 * r + (MAX_ROLLERS - 1) * 2 * r * (1 + ROLLER_CLEARANCE)  # exactly MAX_ROLLERS rollers
    for geom in [*track.collisions, *track.visuals]:
        geom.geometry = Box(np.array([fits, 0.1, 0.2]))
    notes = NoteSink()
    approximate_tracks(robot, notes)
    assert len(robot.extras["tracks"]["track_joint"]["rollers"]) == MAX_ROLLERS
    assert "longer than" not in notes.items[0].message
