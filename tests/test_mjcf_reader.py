"""The MJCF reader, checked against MuJoCo itself.

MuJoCo is the oracle: link world poses from ``Robot.world_poses(q)`` must equal MuJoCo's
``data.xpos``/``data.xmat`` after ``mj_kinematics`` at many configurations, and masses, centres
of mass, inertias and geom placements must equal what MuJoCo compiled. Inputs are the small files
in ``tests/mjcf`` (written for this test), files written into ``tmp_path``, and the MJCF files
shipped with pybullet.
"""

from __future__ import annotations

import math
import textwrap
from pathlib import Path
from typing import Any

import mujoco
import numpy as np
import pytest
from click.testing import CliRunner

from modelkit.api import validate
from modelkit.cli import main
from modelkit.formats import detect_format, read_model
from modelkit.formats.common import ReadOptions, ReadResult
from modelkit.formats.mjcf import read_mjcf
from modelkit.model import Box, Capsule, Cylinder, Ellipsoid, JointType, Mesh, Robot, Sphere
from modelkit.spatial import Pose

HERE = Path(__file__).parent / "mjcf"
LOCAL = sorted(HERE.glob("*.xml"))


def _pybullet_mjcf() -> list[Path]:
    try:
        import pybullet_data
    except ImportError:  # pragma: no cover - pybullet is in the test environment
        return []
    return sorted(Path(pybullet_data.getDataPath(), "mjcf").glob("*.xml"))


PYBULLET = _pybullet_mjcf()
PYBULLET_LOADABLE = []
for _p in PYBULLET:
    try:
        mujoco.MjModel.from_xml_path(str(_p))
    except ValueError:
        continue
    PYBULLET_LOADABLE.append(_p)


def read(path: Path, compiled: bool = True) -> ReadResult:
    return read_mjcf(path, ReadOptions(), path.name, compiled=compiled)


def codes(result: ReadResult) -> list[str]:
    return [d.code for d in result.diagnostics]


def write(tmp_path: Path, text: str, name: str = "model.xml") -> Path:
    path = tmp_path / name
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(textwrap.dedent(text))
    return path


# -- the oracle ---------------------------------------------------------------------------------


def body_pose_in_model(robot_poses: dict[str, Pose], robot: Robot, body: int) -> Pose | None:
    """The MuJoCo body frame of ``body`` according to the model (link pose minus the offset)."""
    for link in robot.links:
        if link.extras.get("mjcf_body_id") == body:
            pose = robot_poses[link.name]
            offset = np.array(link.extras.get("mjcf_body_offset", [0.0, 0.0, 0.0]))
            return Pose(pose.rotation, pose.translation - pose.rotation @ offset)
    return None


def joint_names(model: Any) -> dict[int, str]:
    return {
        j: mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, j) or f"joint{j}" for j in range(model.njnt)
    }


def random_configuration(
    model: Any, rng: np.random.Generator, zero: bool
) -> tuple[np.ndarray, dict[str, float]]:
    """qpos (MuJoCo) and the same configuration as model joint positions (hinges and slides)."""
    qpos = model.qpos0.copy()
    q: dict[str, float] = {}
    for j, name in joint_names(model).items():
        if int(model.jnt_type[j]) in (int(mujoco.mjtJoint.mjJNT_HINGE), int(mujoco.mjtJoint.mjJNT_SLIDE)):
            value = 0.0 if zero else float(rng.uniform(-2.0, 2.0))
            qpos[model.jnt_qposadr[j]] = value
            q[name] = value
    return qpos, q


def max_pose_error(path: Path, result: ReadResult, trials: int = 25) -> float:
    """The largest difference (m, or rotation-matrix entry) between the model's world poses and
    MuJoCo's, over ``trials`` configurations (the first is q = 0)."""
    model = mujoco.MjModel.from_xml_path(str(path))
    data = mujoco.MjData(model)
    rng = np.random.default_rng(1234)
    worst, compared = 0.0, 0
    for trial in range(trials):
        data.qpos[:], q = random_configuration(model, rng, zero=trial == 0)
        mujoco.mj_kinematics(model, data)
        for robot in result.robots:
            poses = robot.world_poses(q)
            for body in range(1, model.nbody):
                pose = body_pose_in_model(poses, robot, body)
                if pose is None:
                    continue
                compared += 1
                worst = max(
                    worst,
                    float(np.abs(pose.translation - data.xpos[body]).max()),
                    float(np.abs(pose.rotation - data.xmat[body].reshape(3, 3)).max()),
                )
    assert compared >= trials * (model.nbody - 1), "every MuJoCo body has a link"
    assert any(model.jnt_type[j] != 0 for j in range(model.njnt)) <= bool(q), "the joints were moved"
    return worst


# -- world poses against MuJoCo -----------------------------------------------------------------


@pytest.mark.parametrize("path", LOCAL + PYBULLET_LOADABLE, ids=lambda p: p.name)
def test_world_poses_match_mujoco(path: Path) -> None:
    result = read(path)
    assert result.robot is not None
    assert [d for d in result.diagnostics if d.severity == "error"] == []
    assert max_pose_error(path, result) < 1e-9


@pytest.mark.parametrize("path", LOCAL + PYBULLET_LOADABLE, ids=lambda p: p.name)
def test_uncompiled_fallback_gives_the_same_kinematics(path: Path) -> None:
    """The fallback resolves frames, euler/axisangle, degrees and joint refs as MuJoCo does."""
    result = read(path, compiled=False)
    assert "MK174" in codes(result)
    assert max_pose_error(path, result) < 1e-9


def test_pybullet_mjcf_files_are_there() -> None:
    if not PYBULLET:
        pytest.skip("pybullet_data is not installed")
    names = {p.name for p in PYBULLET_LOADABLE}
    assert {"hello_mjcf.xml", "ant.xml", "humanoid.xml"} <= names


# -- mass properties and geometry against MuJoCo --------------------------------------------------


@pytest.mark.parametrize("path", LOCAL + PYBULLET_LOADABLE, ids=lambda p: p.name)
def test_mass_properties_match_mujoco(path: Path) -> None:
    """Mass, world COM (``xipos``) and world inertia (``ximat`` · diag · ``ximat``ᵀ) agree."""
    result = read(path)
    model = mujoco.MjModel.from_xml_path(str(path))
    data = mujoco.MjData(model)
    data.qpos[:], q = random_configuration(model, np.random.default_rng(7), zero=False)
    mujoco.mj_kinematics(model, data)
    for robot in result.robots:
        poses = robot.world_poses(q)
        for link in robot.links:
            body = link.extras.get("mjcf_body_id")
            if body is None:
                assert link.inertial is None  # synthesised links carry no mass
                continue
            assert link.inertial is not None
            assert link.inertial.mass == pytest.approx(model.body_mass[body], abs=1e-12)
            pose = poses[link.name]
            com = pose.rotation @ link.inertial.com + pose.translation
            assert np.allclose(com, data.xipos[body], atol=1e-12)
            frame = data.ximat[body].reshape(3, 3)
            expected = frame @ np.diag(model.body_inertia[body]) @ frame.T
            assert np.allclose(pose.rotation @ link.inertial.inertia @ pose.rotation.T, expected, atol=1e-12)


@pytest.mark.parametrize("path", LOCAL + PYBULLET_LOADABLE, ids=lambda p: p.name)
def test_primitive_geoms_match_mujoco(path: Path) -> None:
    """Every collision geom sits where MuJoCo puts it, with MuJoCo's sizes."""
    result = read(path)
    model = mujoco.MjModel.from_xml_path(str(path))
    data = mujoco.MjData(model)
    data.qpos[:], q = random_configuration(model, np.random.default_rng(7), zero=False)
    mujoco.mj_kinematics(model, data)
    body_geoms = [g for g in range(model.ngeom) if model.geom_bodyid[g] > 0]
    placed = []
    for robot in result.robots:
        poses = robot.world_poses(q)
        for link in robot.links:
            for geom in link.collisions + [v for v in link.visuals if v not in link.collisions]:
                placed.append((poses[link.name] @ geom.pose, geom))
    matched = 0
    for g in body_geoms:
        if int(model.geom_type[g]) in (int(mujoco.mjtGeom.mjGEOM_PLANE), int(mujoco.mjtGeom.mjGEOM_MESH)):
            continue
        centre, rotation = data.geom_xpos[g], data.geom_xmat[g].reshape(3, 3)
        hits = [
            geom
            for pose, geom in placed
            if np.allclose(pose.translation, centre, atol=1e-9)
            and np.allclose(pose.rotation, rotation, atol=1e-9)
            and np.allclose(mujoco_size(geom.geometry), model.geom_size[g][: len(mujoco_size(geom.geometry))])
        ]
        assert hits, f"geom {g} of body {model.geom_bodyid[g]} not found at MuJoCo's pose with its size"
        matched += 1
    assert matched > 0 or not body_geoms


def mujoco_size(geometry: Any) -> list[float]:
    """A model geometry's dimensions as MuJoCo's ``geom_size`` holds them (half-lengths; only
    the entries the shape uses)."""
    if isinstance(geometry, Capsule | Cylinder):
        return [geometry.radius, geometry.length / 2]
    if isinstance(geometry, Ellipsoid):
        return list(geometry.radii)
    if isinstance(geometry, Box):
        return list(np.asarray(geometry.size) / 2)
    if isinstance(geometry, Sphere):
        return [geometry.radius]
    return [math.nan] * 3


def test_mesh_geoms_keep_the_file_frame(tmp_path: Path) -> None:
    """MuJoCo re-centres a mesh on its centre of mass; the model keeps the file's frame, so the
    file's vertices, scaled and placed by the model, land on MuJoCo's vertices."""
    import trimesh

    box = trimesh.creation.box(extents=[0.2, 0.4, 0.1])
    box.apply_transform(trimesh.transformations.rotation_matrix(0.3, [1, 1, 0]))
    box.apply_translation([0.3, -0.2, 0.5])
    (tmp_path / "meshes").mkdir()
    box.export(tmp_path / "meshes" / "part.stl")
    path = write(
        tmp_path,
        """\
        <mujoco model="meshy">
          <compiler meshdir="meshes"/>
          <asset><mesh name="part" file="part.stl" scale="1 2 0.5"/></asset>
          <worldbody>
            <body name="holder" pos="0 0 1" euler="0.1 0.2 0.3">
              <joint name="turn" axis="0 0 1" pos="0.1 0 0"/>
              <geom type="mesh" mesh="part" pos="0.1 0.2 0.3" euler="0.5 0 0"/>
              <geom type="mesh" mesh="part" contype="0" conaffinity="0" group="1" rgba="1 0 0 1"/>
            </body>
          </worldbody>
        </mujoco>
        """,
    )
    result = read(path)
    assert result.robot is not None
    link = result.robot.link("holder")
    assert link is not None and len(link.collisions) == 1 and len(link.visuals) == 1
    mesh = link.collisions[0].geometry
    assert isinstance(mesh, Mesh)
    assert mesh.uri == "part.stl"
    assert mesh.path == str((tmp_path / "meshes" / "part.stl").absolute())
    assert np.allclose(mesh.scale, [1, 2, 0.5])
    model = mujoco.MjModel.from_xml_path(str(path))
    data = mujoco.MjData(model)
    data.qpos[0] = 0.7
    mujoco.mj_kinematics(model, data)
    link_pose = result.robot.world_poses({"turn": 0.7})["holder"]
    loaded: Any = trimesh.load(tmp_path / "meshes" / "part.stl")
    raw = np.asarray(loaded.vertices) * mesh.scale
    for g, geom in enumerate([link.collisions[0], link.visuals[0]]):
        pose = link_pose @ geom.pose
        ours = raw @ pose.rotation.T + pose.translation
        start, count = model.mesh_vertadr[0], model.mesh_vertnum[0]
        theirs = (
            model.mesh_vert[start : start + count] @ data.geom_xmat[g].reshape(3, 3).T + data.geom_xpos[g]
        )
        distances = np.linalg.norm(ours[:, None, :] - theirs[None, :, :], axis=2)
        assert distances.min(axis=1).max() < 1e-6  # MuJoCo stores vertices as float32
        assert distances.min(axis=0).max() < 1e-6
    material = link.visuals[0].material
    assert material is not None and material.rgba == (1.0, 0.0, 0.0, 1.0)


# -- the tree report ----------------------------------------------------------------------------

TREES = {
    "pendulum.xml": """\
        robot name is: pendulum
        ---------- Successfully Parsed XML ---------------
        root Link: base has 1 child(ren)
            child(1):  arm
        """,
    "two_hinges.xml": """\
        robot name is: two_hinges
        ---------- Successfully Parsed XML ---------------
        root Link: torso has 1 child(ren)
            child(1):  hip__hip_x
                child(1):  hip
                    child(1):  shin
        """,
    "classes.xml": """\
        robot name is: classes
        ---------- Successfully Parsed XML ---------------
        root Link: chassis has 2 child(ren)
            child(1):  back_leg
            child(2):  front_leg
                child(1):  front_foot
        """,
    "include_main.xml": """\
        robot name is: included
        ---------- Successfully Parsed XML ---------------
        root Link: stand has 1 child(ren)
            child(1):  link1
                child(1):  body3
        """,
    "coupled.xml": """\
        robot name is: coupled
        ---------- Successfully Parsed XML ---------------
        root Link: base has 3 child(ren)
            child(1):  finger_a
            child(2):  finger_b
            child(3):  finger_c
        """,
    "scene.xml": """\
        robot name is: scene
        ---------- Successfully Parsed XML ---------------
        root Link: arm_base has 1 child(ren)
            child(1):  upper
                child(1):  lower
        robot name is: ball
        ---------- Successfully Parsed XML ---------------
        root Link: ball has 0 child(ren)
        robot name is: table
        ---------- Successfully Parsed XML ---------------
        root Link: table has 0 child(ren)
        robot name is: body6
        ---------- Successfully Parsed XML ---------------
        root Link: body6 has 0 child(ren)
        """,
}

PYBULLET_TREES = {
    "hello_mjcf.xml": """\
        robot name is: hello_mjcf
        ---------- Successfully Parsed XML ---------------
        root Link: body1 has 0 child(ren)
        """,
    "inverted_pendulum.xml": """\
        robot name is: inverted pendulum
        ---------- Successfully Parsed XML ---------------
        root Link: world has 1 child(ren)
            child(1):  cart
                child(1):  pole
        """,
    "ant.xml": """\
        robot name is: ant
        ---------- Successfully Parsed XML ---------------
        root Link: torso has 4 child(ren)
            child(1):  front_left_leg
                child(1):  aux_1
                    child(1):  front_left_foot
            child(2):  front_right_leg
                child(1):  aux_2
                    child(1):  front_right_foot
            child(3):  left_back_leg
                child(1):  aux_3
                    child(1):  left_back_foot
            child(4):  right_back_leg
                child(1):  aux_4
                    child(1):  right_back_foot
        """,
    "humanoid.xml": """\
        robot name is: humanoid
        ---------- Successfully Parsed XML ---------------
        root Link: torso has 3 child(ren)
            child(1):  lwaist__abdomen_z
                child(1):  lwaist
                    child(1):  pelvis
                        child(1):  left_thigh__left_hip_x
                            child(1):  left_thigh__left_hip_z
                                child(1):  left_thigh
                                    child(1):  left_shin
                                        child(1):  left_foot__left_ankle_y
                                            child(1):  left_foot
                        child(2):  right_thigh__right_hip_x
                            child(1):  right_thigh__right_hip_z
                                child(1):  right_thigh
                                    child(1):  right_shin
                                        child(1):  right_foot__right_ankle_y
                                            child(1):  right_foot
            child(2):  left_upper_arm__left_shoulder1
                child(1):  left_upper_arm
                    child(1):  left_lower_arm
            child(3):  right_upper_arm__right_shoulder1
                child(1):  right_upper_arm
                    child(1):  right_lower_arm
        """,
}


def run_cli(*args: str) -> Any:
    return CliRunner().invoke(main, list(args), catch_exceptions=False)


@pytest.mark.parametrize("name", sorted(TREES))
def test_tree_command_output(name: str) -> None:
    done = run_cli("tree", str(HERE / name))
    assert done.exit_code == 0, done.output
    assert done.stdout == textwrap.dedent(TREES[name])


@pytest.mark.parametrize("name", sorted(PYBULLET_TREES))
def test_tree_command_on_pybullet_files(name: str) -> None:
    path = next((p for p in PYBULLET if p.name == name), None)
    if path is None:
        pytest.skip("pybullet_data is not installed")
    done = run_cli("tree", str(path))
    assert done.exit_code == 0, done.output
    assert done.stdout == textwrap.dedent(PYBULLET_TREES[name])


def test_xml_files_are_detected_by_their_top_element() -> None:
    assert detect_format(HERE / "pendulum.xml") == "mjcf"
    assert read_model(HERE / "pendulum.xml").robot is not None


# -- the mapping --------------------------------------------------------------------------------


def test_pendulum_joint_and_link_frames() -> None:
    result = read(HERE / "pendulum.xml")
    robot = result.robot
    assert robot is not None and robot.name == "pendulum" and robot.source_format == "mjcf"
    assert robot.root == "base" and robot.root_joint is JointType.FIXED
    assert np.allclose(robot.root_pose.translation, [0, 0, 1])
    (joint,) = robot.joints
    assert (joint.name, joint.type, joint.parent, joint.child) == ("swing", JointType.REVOLUTE, "base", "arm")
    # The link frame is the joint frame: 5 cm above the MuJoCo body frame.
    assert np.allclose(joint.origin.translation, [0.125, 0, 0.15])
    assert np.allclose(joint.axis, [1, 0, 0])
    assert (joint.limits.lower, joint.limits.upper) == (-1.5, 1.5)
    assert (joint.damping, joint.friction, joint.armature) == pytest.approx((0.3, 0.1, 0.01))
    arm = robot.link("arm")
    assert arm is not None and arm.inertial is not None
    assert arm.extras["mjcf_body_offset"] == [0.0, 0.0, 0.05]
    assert np.allclose(arm.inertial.com, [0, 0, 0.45])
    assert np.allclose(np.diag(arm.inertial.inertia), [0.0835417, 0.0835417, 0.000416667])
    (box,) = arm.collisions
    assert np.allclose(box.pose.translation, [0, 0, 0.45])
    assert np.allclose(box.geometry.size, [0.05, 0.05, 1.0])  # type: ignore[union-attr]
    base = robot.link("base")
    assert base is not None and base.visuals[0].material is not None
    assert base.visuals[0].material.rgba == pytest.approx((0.2, 0.3, 0.4, 1.0))


def test_what_is_kept_as_data() -> None:
    result = read(HERE / "pendulum.xml")
    robot = result.robot
    assert robot is not None
    (motor,) = robot.extras["mjcf_actuators"]
    assert (motor["name"], motor["element"], motor["target"], motor["gear"]) == (
        "swing_motor",
        "motor",
        "swing",
        10.0,
    )
    assert motor["ctrlrange"] == [-1.0, 1.0]
    assert robot.extras["mjcf_sensors"] == [
        {"name": "swing_angle", "type": "jointpos", "objtype": "joint", "object": "swing"}
    ]
    (tip,) = robot.extras["mjcf_sites"]
    assert tip["link"] == "arm" and np.allclose(tip["xyz"], [0, 0, 0.95])  # in the link (joint) frame
    (floor,) = robot.extras["mjcf_world_geoms"]
    assert floor["name"] == "floor" and floor["type"] == "plane"
    note = next(d for d in result.diagnostics if d.code == "MK175")
    assert note.message.startswith("1 actuator, 1 sensor, 1 site, 1 world geom kept as data")


def test_a_body_with_several_joints_becomes_a_chain() -> None:
    result = read(HERE / "two_hinges.xml")
    robot = result.robot
    assert robot is not None
    note = next(d for d in result.diagnostics if d.code == "MK171")
    assert note.severity == "info" and (note.location.line, note.location.col) == (6, 7)  # type: ignore[union-attr]
    assert '"hip__hip_x" → "hip"' in note.message
    by_name = {j.name: j for j in robot.joints}
    assert (by_name["hip_x"].parent, by_name["hip_x"].child) == ("torso", "hip__hip_x")
    assert (by_name["hip_y"].parent, by_name["hip_y"].child) == ("hip__hip_x", "hip")
    middle = robot.link("hip__hip_x")
    assert middle is not None and middle.inertial is None and middle.synthesised is True
    # hip_y's anchor is 6 cm above hip_x's: the second joint's origin moves by that much.
    assert np.allclose(by_name["hip_y"].origin.translation, [0, 0, 0.06])
    assert np.allclose(by_name["hip_y"].axis, np.array([0, 1, 0.5]) / math.sqrt(1.25))
    # Degrees are converted; a joint ref is the initial position and q is MuJoCo's qpos.
    assert by_name["hip_y"].limits.lower == pytest.approx(math.radians(-110))
    assert by_name["hip_y"].initial_position == pytest.approx(math.radians(10))
    assert by_name["knee"].type is JointType.PRISMATIC and by_name["knee"].initial_position == 0.05


def test_several_top_level_bodies_are_several_robots() -> None:
    result = read(HERE / "scene.xml")
    assert [r.name for r in result.robots] == ["scene", "ball", "table", "body6"]
    main_robot, ball, table, box = result.robots
    assert main_robot.root == "arm_base" and main_robot.root_joint is JointType.FIXED
    assert ball.root_joint is JointType.FLOATING and np.allclose(ball.root_pose.translation, [1, 0, 0.5])
    assert table.root_joint is JointType.FIXED and table.joints == []
    assert box.root_joint is JointType.FLOATING
    assert "MK176" in codes(result)
    unnamed = [d for d in result.diagnostics if d.code == "MK173"]
    assert [d.message for d in unnamed] == [
        'body 6 has no name; it is called "body6"'
    ]  # its free joint: no Joint


def test_top_level_body_with_hinges_hangs_from_a_world_link() -> None:
    path = next((p for p in PYBULLET if p.name == "inverted_pendulum.xml"), None)
    if path is None:
        pytest.skip("pybullet_data is not installed")
    robot = read(path).robot
    assert robot is not None and robot.root == "world" and robot.root_joint is JointType.FIXED
    world = robot.link("world")
    assert world is not None and world.synthesised and world.extras == {}
    slider = next(j for j in robot.joints if j.name == "slider")
    assert slider.type is JointType.PRISMATIC and slider.parent == "world"


def test_defaults_classes_frames_and_fromto() -> None:
    result = read(HERE / "classes.xml")
    robot = result.robot
    assert robot is not None and robot.root_joint is JointType.FLOATING
    by_name = {j.name: j for j in robot.joints}
    assert by_name["front_hip"].damping == 2.0  # childclass "leg"
    assert by_name["back_hip"].damping == 4.0  # written on the joint
    assert by_name["front_knee"].limits.upper == pytest.approx(math.radians(90))
    assert by_name["front_hip"].limits.upper == pytest.approx(math.radians(60))  # class range
    chassis = robot.link("chassis")
    assert chassis is not None
    assert [type(g.geometry).__name__ for g in chassis.collisions] == ["Box"]
    assert [type(g.geometry).__name__ for g in chassis.visuals] == ["Ellipsoid"]  # contype=conaffinity=0
    assert chassis.visuals[0].material is not None and chassis.visuals[0].material.transparency == 0.5
    leg = robot.link("front_leg")
    assert leg is not None
    capsule = leg.collisions[0].geometry
    assert isinstance(capsule, Capsule) and capsule.length == pytest.approx(0.3) and capsule.radius == 0.04
    assert np.allclose(leg.collisions[0].pose.translation, [0, 0, -0.15])
    assert leg.visuals[0].geometry is capsule  # a collision geom doubles as the visual


def test_include_files_give_locations_in_the_included_file() -> None:
    result = read(HERE / "include_main.xml")
    robot = result.robot
    assert robot is not None
    link1 = robot.link("link1")
    assert link1 is not None and str(link1.loc("name")) == "parts/arm.xml:2:9"
    pitch = next(j for j in robot.joints if j.name == "pitch")
    assert str(pitch.loc("axis")) == "parts/arm.xml:6:27"
    assert pitch.damping == 0.7  # the default from parts/defaults.xml
    body3 = robot.link("body3")
    assert body3 is not None and str(body3.source) == "parts/arm.xml:5:5"


def test_joint_equalities_become_mimics() -> None:
    """MuJoCo's constraint residual is zero where the mimic says the follower is."""
    path = HERE / "coupled.xml"
    result = read(path)
    robot = result.robot
    assert robot is not None
    by_name = {j.name: j for j in robot.joints}
    mimic = by_name["b"].mimic
    assert mimic is not None and mimic.joint == "a"
    assert (mimic.multiplier, mimic.offset) == pytest.approx((-0.5, 0.05))
    assert mimic.source is not None and mimic.source.line == 21
    assert by_name["c"].mimic is None  # quadratic: reported
    model = mujoco.MjModel.from_xml_path(str(path))
    data = mujoco.MjData(model)
    for qa in (-1.0, 0.0, 0.3, 2.0):
        data.qpos[:] = model.qpos0
        data.qpos[model.jnt_qposadr[0]] = qa
        data.qpos[model.jnt_qposadr[1]] = mimic.multiplier * qa + mimic.offset
        mujoco.mj_forward(model, data)
        rows = [
            i
            for i in range(data.nefc)
            if int(data.efc_type[i]) == int(mujoco.mjtConstraint.mjCNSTR_EQUALITY) and data.efc_id[i] == 0
        ]
        assert len(rows) == 1 and abs(data.efc_pos[rows[0]]) < 1e-12
    messages = [d.message for d in result.diagnostics if d.code == "MK172"]
    assert any("polynomial of degree 2" in m for m in messages)
    assert any(m.startswith('connect equality "tie" between bodies') for m in messages)
    assert any(m.startswith('fixed tendon "sum"') for m in messages)
    assert robot.extras["mjcf_tendons"][0]["wraps"][0] == {"type": "joint", "object": "a", "coef": 1.0}


def test_source_locations_point_at_the_elements() -> None:
    robot = read(HERE / "pendulum.xml").robot
    assert robot is not None
    arm = robot.link("arm")
    assert arm is not None and arm.inertial is not None
    assert str(arm.source) == "pendulum.xml:8:7"
    assert str(arm.loc("name")) == "pendulum.xml:8:13"
    assert str(arm.inertial.source) == "pendulum.xml:11:9"
    assert str(arm.inertial.sources["mass"]) == "pendulum.xml:11:33"
    assert str(arm.collisions[0].source) == "pendulum.xml:12:9"
    (joint,) = robot.joints
    assert str(joint.source) == "pendulum.xml:9:9"
    assert str(joint.loc("name")) == "pendulum.xml:9:16"
    assert str(joint.loc("range")) == "pendulum.xml:9:70"


def test_unnamed_model_takes_the_file_stem(tmp_path: Path) -> None:
    path = write(
        tmp_path, '<mujoco><worldbody><body><geom size="1"/></body></worldbody></mujoco>', "anon.xml"
    )
    result = read(path)
    assert result.robot is not None and result.robot.name == "anon" and result.robot.root == "body1"
    assert codes(result).count("MK173") == 2  # the model and the body


def test_unsupported_geoms_are_reported(tmp_path: Path) -> None:
    path = write(
        tmp_path,
        """\
        <mujoco model="m">
          <worldbody>
            <body name="b">
              <geom type="plane" size="1 1 1"/>
              <geom type="sphere" size="0.1"/>
            </body>
          </worldbody>
        </mujoco>
        """,
    )
    result = read(path)
    (warning,) = [d for d in result.diagnostics if d.code == "MK172"]
    assert warning.location is not None and (warning.location.line, warning.location.col) == (4, 7)
    link = result.robot.link("b") if result.robot else None
    assert link is not None and [type(g.geometry).__name__ for g in link.collisions] == ["Sphere"]


# -- bad input: a diagnostic with a line, never a traceback -----------------------------------------


BAD_INPUTS = {
    "malformed": ("<mujoco>\n  <worldbody>\n    <body>\n  </worldbody>\n</mujoco>\n", "MK020", 4),
    "unknown-attribute": (
        '<mujoco>\n  <worldbody>\n    <body name="b">\n      <geom size="1" colour="red"/>\n'
        "    </body>\n  </worldbody>\n</mujoco>\n",
        "MK170",
        4,
    ),
    "entity": (
        '<?xml version="1.0"?>\n<!DOCTYPE m [\n  <!ENTITY x "y">\n]>\n<mujoco model="&x;"/>\n',
        "MK021",
        3,
    ),
    "bad-keyword": (
        '<mujoco>\n  <worldbody>\n    <body>\n      <joint type="fixed"/>\n      <geom size="1"/>\n'
        "    </body>\n  </worldbody>\n</mujoco>\n",
        "MK170",
        4,
    ),
}


@pytest.mark.parametrize("case", sorted(BAD_INPUTS))
def test_bad_input_gives_a_located_diagnostic(case: str, tmp_path: Path) -> None:
    text, code, line = BAD_INPUTS[case]
    path = tmp_path / f"{case}.xml"
    path.write_text(text)
    result = read_model(path, fmt="mjcf")
    found = [d for d in result.diagnostics if d.code == code]
    assert found and found[0].location is not None and found[0].location.line == line, result.diagnostics
    done = CliRunner().invoke(main, ["validate", str(path)])
    assert done.exception is None or isinstance(done.exception, SystemExit)
    assert done.exit_code in (1, 2)
    assert f":{line}:" in done.output and code in done.output


def test_unknown_attribute_points_at_the_attribute(tmp_path: Path) -> None:
    text, _, _ = BAD_INPUTS["unknown-attribute"]
    path = write(tmp_path, text)
    (error,) = [d for d in read(path).diagnostics if d.code == "MK170"]
    assert str(error.location) == "model.xml:4:22"
    assert error.message.startswith("MuJoCo: Schema violation: unrecognized attribute: 'colour'")


def test_missing_mesh_falls_back_to_the_uncompiled_tree(tmp_path: Path) -> None:
    path = write(
        tmp_path,
        """\
        <mujoco model="broken">
          <asset>
            <mesh name="shell" file="nowhere/shell.stl"/>
          </asset>
          <worldbody>
            <body name="base">
              <body name="lid" pos="0 0 0.1" euler="0 0 90">
                <joint name="lid_hinge" axis="1 0 0" range="0 90"/>
                <inertial pos="0 0 0" mass="0.5" diaginertia="0.01 0.01 0.01"/>
                <geom type="mesh" mesh="shell"/>
              </body>
            </body>
          </worldbody>
        </mujoco>
        """,
    )
    result = read(path)
    by_code = {d.code: d for d in result.diagnostics}
    assert {"MK170", "MK174", "MK500"} <= set(by_code)
    assert str(by_code["MK170"].location) == "model.xml:3:24"  # the file attribute of <mesh>
    assert "shell.stl" in by_code["MK170"].message
    robot = result.robot
    assert robot is not None and robot.extras["mjcf_compiled"] is False
    lid = robot.link("lid")
    assert lid is not None and lid.collisions == [] and lid.inertial is not None and lid.inertial.mass == 0.5
    (joint,) = robot.joints
    assert joint.limits.upper == pytest.approx(math.pi / 2)
    assert np.allclose(joint.origin.rotation, [[0, -1, 0], [1, 0, 0], [0, 0, 1]], atol=1e-12)
    done = run_cli("tree", str(path))
    assert done.exit_code == 1 and "MK170" in done.stderr  # printed, but MuJoCo cannot compile the file
    assert done.stdout.endswith("root Link: base has 1 child(ren)\n    child(1):  lid\n")


def test_compile_error_in_the_tree_names_the_body(tmp_path: Path) -> None:
    path = write(
        tmp_path,
        """\
        <mujoco model="m">
          <worldbody>
            <body name="a">
              <body name="b">
                <freejoint/>
                <geom size="0.1"/>
              </body>
            </body>
          </worldbody>
        </mujoco>
        """,
    )
    result = read(path)
    error = next(d for d in result.diagnostics if d.code == "MK170")
    assert str(error.location) == "model.xml:4:7"
    assert "free joint can only be used on top level" in error.message
    assert result.robot is not None and result.robot.link("b") is not None


def test_included_file_errors_point_into_the_included_file(tmp_path: Path) -> None:
    write(
        tmp_path, '<mujoco>\n  <body name="x">\n    <joint bogus="1"/>\n  </body>\n</mujoco>\n', "parts/x.xml"
    )
    path = write(
        tmp_path, '<mujoco>\n  <worldbody>\n    <include file="parts/x.xml"/>\n  </worldbody>\n</mujoco>\n'
    )
    (error,) = [d for d in read(path).diagnostics if d.code == "MK170"]
    assert error.location is not None
    assert (Path(error.location.file).as_posix(), error.location.line, error.location.col) == (
        "parts/x.xml",
        3,
        12,
    )


def test_not_a_mujoco_file(tmp_path: Path) -> None:
    path = write(tmp_path, "<robot name='r'/>", "r.mjcf")
    result = read(path)
    assert codes(result) == ["MK022"] and result.robot is None


def test_repeated_includes_are_refused_without_blowing_up(tmp_path: Path) -> None:
    """MuJoCo refuses a file included twice; modelkit's own walk expands each file once, so an
    include graph that doubles at every level costs nothing."""
    write(
        tmp_path,
        '<mujoco><include file="b.xml"/><include file="b.xml"/><include file="a.xml"/></mujoco>',
        "b.xml",
    )
    path = write(
        tmp_path,
        '<mujoco model="a">\n  <include file="a.xml"/>\n  <include file="b.xml"/>\n</mujoco>\n',
        "a.xml",
    )
    result = read(path)
    (error,) = [d for d in result.diagnostics if d.code == "MK170"]
    assert "already included" in error.message and str(error.location) == "a.xml:2:3"
    assert result.robot is None


def test_ball_joints_cameras_and_keyframes(tmp_path: Path) -> None:
    path = write(
        tmp_path,
        """\
        <mujoco model="camera_arm">
          <compiler angle="radian"/>
          <worldbody>
            <body name="target" mocap="true" pos="0 0 1">
              <geom size="0.05" contype="0" conaffinity="0"/>
            </body>
            <body name="arm">
              <joint name="shoulder" type="ball" pos="0 0 0.1" range="0 0.8"/>
              <geom size="0.1"/>
              <camera name="eye" pos="0 0 0.3" fovy="60"/>
            </body>
          </worldbody>
          <keyframe><key name="home" qpos="1 0 0 0"/></keyframe>
        </mujoco>
        """,
    )
    result = read(path)
    robot, target = result.robots
    assert robot.root == "world" and target.root == "target" and target.root_joint is JointType.FIXED
    (shoulder,) = robot.joints
    assert shoulder.type is JointType.BALL and shoulder.extras["mjcf_ball_range"] == [0.0, 0.8]
    assert not shoulder.limits.position_limited
    (eye,) = robot.extras["mjcf_cameras"]
    assert eye["name"] == "eye" and eye["link"] == "arm" and np.allclose(eye["xyz"], [0, 0, 0.2])
    assert eye["fovy"] == 60.0
    assert robot.extras["mjcf_keyframes"] == [{"name": "home", "time": 0.0, "qpos": [1.0, 0.0, 0.0, 0.0]}]
    link = target.link("target")
    assert link is not None and link.extras["mjcf_mocap"] is True


def test_uncompiled_fallback_does_not_guess_missing_masses(tmp_path: Path) -> None:
    """When MuJoCo cannot compile the file, masses it would infer from geoms are unknown: no MK313."""
    path = tmp_path / "missing_mesh.xml"
    path.write_text(
        '<mujoco model="m"><asset><mesh name="m" file="nope.stl"/></asset><worldbody>'
        '<body name="b"><joint type="hinge"/><geom type="mesh" mesh="m"/></body></worldbody></mujoco>'
    )
    codes = sorted(d.code for d in validate(path).diagnostics)
    assert "MK313" not in codes
    assert {"MK170", "MK174", "MK500"} <= set(codes)


def test_uncompiled_fallback_keeps_full_and_rotated_inertias(tmp_path: Path) -> None:
    """``fullinertia`` is the written tensor; ``diaginertia`` with an orientation is R·diag·Rᵀ; both
    agree with what MuJoCo compiles (principal moments and ``body_iquat``)."""
    path = tmp_path / "inertia.xml"
    path.write_text(
        '<mujoco model="m"><worldbody><body name="a"><joint type="hinge"/><geom size="0.1"/>'
        '<body name="b" euler="10 20 30">'
        '<joint type="hinge" axis="1 2 2"/><inertial pos="0.1 0.2 0.3" mass="2" '
        'fullinertia="0.3 0.4 0.5 0.01 -0.02 0.03"/></body><body name="c"><joint type="slide"/>'
        '<inertial pos="0 0 0" mass="1" diaginertia="0.1 0.2 0.3" euler="30 40 50"/></body>'
        "</body></worldbody></mujoco>"
    )
    model = mujoco.MjModel.from_xml_path(str(path))
    robot = read(path, compiled=False).robot
    assert robot is not None
    for name in ("b", "c"):
        link = robot.link(name)
        assert link is not None and link.inertial is not None
        body = link.extras["mjcf_body_id"]
        r = np.zeros(9)
        mujoco.mju_quat2Mat(r, model.body_iquat[body])
        compiled = r.reshape(3, 3) @ np.diag(model.body_inertia[body]) @ r.reshape(3, 3).T
        assert np.allclose(link.inertial.inertia, compiled, atol=1e-12, rtol=0.0)
    b = robot.link("b")
    assert b is not None and b.inertial is not None
    written = [[0.3, 0.01, -0.02], [0.01, 0.4, 0.03], [-0.02, 0.03, 0.5]]
    assert np.array_equal(b.inertial.inertia, written)


def test_a_relative_path_reads_meshes_an_include_names_from_its_own_folder(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """genesis-world 1.4.5's franka_sim: ``assets/assets.xml`` names ``../meshes/collision/link0.stl``.
    MuJoCo finds it from the model's absolute path, and not from a relative one with folders
    (``x/franka_sim/bi-franka_panda.xml``: "Error opening file"), so validate, tree and convert
    failed when the user typed such a path. The reader gives MuJoCo the absolute path."""
    import struct

    folder = tmp_path / "pkg" / "sim"
    (folder / "assets").mkdir(parents=True)
    (folder / "meshes").mkdir()
    triangles = [((0, 0, 0), (1, 0, 0), (0, 1, 0)), ((0, 0, 0), (0, 1, 0), (0, 0, 1)),
                 ((0, 0, 0), (0, 0, 1), (1, 0, 0)), ((1, 0, 0), (0, 0, 1), (0, 1, 0))]
    stl = b"\0" * 80 + struct.pack("<I", len(triangles)) + b"".join(
        struct.pack("<12fH", 0, 0, 0, *[c * 0.1 for v in t for c in v], 0) for t in triangles)
    (folder / "meshes" / "part.stl").write_bytes(stl)
    (folder / "assets" / "assets.xml").write_text(
        '<mujocoinclude><asset><mesh name="part" file="../meshes/part.stl"/></asset></mujocoinclude>')
    (folder / "robot.xml").write_text(
        '<mujoco model="r"><include file="assets/assets.xml"/><compiler meshdir=""/><worldbody>'
        '<body name="b"><joint type="hinge"/><geom type="mesh" mesh="part"/></body></worldbody></mujoco>')
    monkeypatch.chdir(tmp_path)
    relative = Path("pkg/sim/robot.xml")
    v = validate(relative)
    assert v.errors == [], [d.message for d in v.errors]
    assert v.robot is not None and v.robot.name == "r"
    assert all(d.location is None or not Path(d.location.file).is_absolute() for d in v.diagnostics)


def test_a_body_gets_a_look_only_from_the_colliding_geoms_mujoco_draws(tmp_path: Path) -> None:
    """A body without a visual-only geom gets copies of its colliding geoms as its look, as MuJoCo draws
    it: geoms of groups 0-2 that are not fully transparent. A body whose colliders are hidden (group 3, as
    Menagerie keeps collisions) looked like nothing in the source; it got a visible copy of them, so
    MJCF -> MJCF wrote each such geom twice and drew what the source hid."""
    path = tmp_path / "looks.xml"
    path.write_text("""<mujoco><worldbody><body name="base"><freejoint/>
      <geom name="hidden" type="box" size=".1 .1 .1" group="3" mass="1"/>
      <body name="leg" pos="0 0 -.2"><joint name="j" axis="0 1 0"/>
        <geom name="drawn" type="capsule" size=".02" fromto="0 0 0 0 0 -.2" mass=".2"/>
        <geom name="clear" type="sphere" size=".03" rgba="1 0 0 0" mass=".1"/></body>
    </body></worldbody></mujoco>""")
    robot = validate(path).robot
    assert robot is not None
    links = {link.name: link for link in robot.links}
    assert [g.name for g in links["base"].collisions] == ["hidden"] and links["base"].visuals == []
    assert [g.name for g in links["leg"].collisions] == ["drawn", "clear"]
    assert [g.name for g in links["leg"].visuals] == ["drawn"]
    out = tmp_path / "out.xml"
    result = CliRunner().invoke(main, ["convert", str(path), "-o", str(out)])
    assert result.exit_code == 0, result.output
    model = mujoco.MjModel.from_xml_path(str(out))
    base = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "base")
    assert int(model.body_geomnum[base]) == 1  # the hidden box, once
