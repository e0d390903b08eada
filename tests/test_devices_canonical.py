"""The canonical device model (model.DeviceKind) as every reader fills it, checked by numbers.

Frames are checked against the formats' own definitions, written out independently here: a
Choreonoid ray in its GL optical frame (body-format.md §3.7), MuJoCo's camera looking along −Z.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from modelkit.formats import read_model
from modelkit.formats.body.reader import BodyOptions, read_body
from modelkit.model import Device, DeviceKind, Robot
from modelkit.spatial import Pose, axis_angle

from .conftest import CORPUS, REPO, TUTORIAL

DEG = math.pi / 180.0
needs_corpus = pytest.mark.skipif(not CORPUS.is_dir(), reason="shared corpus not available")

# Choreonoid's R_opt per optical frame, rows as in body-format.md §3.7.
R_OPT = {
    "gl": np.eye(3),
    "cv": np.array([[1.0, 0, 0], [0, -1, 0], [0, 0, -1]]),
    "robotics": np.array([[0.0, 0, -1], [-1, 0, 0], [0, 1, 0]]),
}


def load_body(path: Path) -> Robot:
    result = read_body(path, BodyOptions(check_resources=False))
    assert result.robot is not None, result.diagnostics
    return result.robot


def device(robot: Robot, name: str) -> tuple[Device, Pose]:
    """The device and its sensor frame in the root frame (q = 0, root at the origin)."""
    robot.root_pose = Pose()
    poses = robot.world_poses()
    for link in robot.links:
        for d in link.devices:
            if d.name == name:
                return d, poses[link.name] @ d.pose
    raise AssertionError(f"no device {name}")


def choreonoid_gl_ray(yaw: float, pitch: float) -> np.ndarray:
    """A RangeSensor ray in the GL optical frame (§3.7): (cos p·sin(−y), sin p, −cos p·cos y)."""
    return np.array([math.cos(pitch) * math.sin(-yaw), math.sin(pitch), -math.cos(pitch) * math.cos(yaw)])


def canonical_ray(yaw: float, pitch: float) -> np.ndarray:
    """The same ray in the canonical frame: +X forward, yaw towards +Y, pitch towards +Z (SDF)."""
    return np.array([math.cos(pitch) * math.cos(yaw), math.cos(pitch) * math.sin(yaw), math.sin(pitch)])


# ---- .body -----------------------------------------------------------------------------------


def test_body_tutorial_lidar() -> None:
    robot = load_body(TUTORIAL / "mobile_robot_sensors.body")
    lidar, pose = device(robot, "LiDAR")
    assert lidar.canonical is DeviceKind.LIDAR
    p = lidar.canonical_params
    # yaw_range 270°, yaw_step 1°: 271 rays over ±135°; planar; max_distance 10, default min 0.1.
    assert (p["horizontal_samples"], p["vertical_samples"]) == (271, 1)
    assert p["horizontal_min_angle"] == pytest.approx(-135 * DEG)
    assert p["horizontal_max_angle"] == pytest.approx(135 * DEG)
    assert p["vertical_min_angle"] == 0.0 and p["vertical_max_angle"] == 0.0
    assert (p["range_min"], p["range_max"], p["update_rate"]) == (0.1, 10.0, 10.0)
    assert (p["noise_stddev"], p["detection_rate"]) == (0.005, 0.9)
    # TiltLink (0, 0, 0.12) above PanLink (-0.02, 0, 0.165), sensor 0.025 above TiltLink.
    np.testing.assert_allclose(pose.translation, [-0.02, 0.0, 0.31], atol=1e-12)
    # It scans in the robot's XY plane: every ray of the scan has z = 0 in the root frame, and the
    # central ray goes along the robot's +X.
    for yaw in np.linspace(p["horizontal_min_angle"], p["horizontal_max_angle"], 7):
        ray = pose.rotation @ canonical_ray(yaw, 0.0)
        assert ray[2] == pytest.approx(0.0, abs=1e-12)
    np.testing.assert_allclose(pose.rotation @ [1, 0, 0], [1, 0, 0], atol=1e-12)


def test_body_tutorial_lidar_rays_match_choreonoid() -> None:
    """Every canonical ray of the 3D LiDAR (yaw and pitch) is the ray Choreonoid casts."""
    robot = load_body(TUTORIAL / "mobile_robot_sensors_ex.body")
    lidar, pose = device(robot, "LiDAR")
    p = lidar.canonical_params
    assert (p["horizontal_samples"], p["vertical_samples"]) == (901, 16)
    assert p["vertical_min_angle"] == pytest.approx(-15 * DEG)
    assert (p["range_max"], p["update_rate"]) == (100.0, 20.0)
    # The node has no rotation; Choreonoid's GL frame is R_opt(robotics) in the link.
    tilt_in_root = robot.world_poses()["TiltLink"].rotation
    for yaw in (-170 * DEG, -30 * DEG, 0.0, 75 * DEG):
        for pitch in (-15 * DEG, 0.0, 10 * DEG):
            choreonoid = tilt_in_root @ R_OPT["robotics"] @ choreonoid_gl_ray(yaw, pitch)
            np.testing.assert_allclose(pose.rotation @ canonical_ray(yaw, pitch), choreonoid, atol=1e-12)


def test_body_tutorial_realsense() -> None:
    robot = load_body(TUTORIAL / "mobile_robot_sensors.body")
    camera, pose = device(robot, "RealSense")
    assert camera.canonical is DeviceKind.RGBD_CAMERA  # format COLOR_DEPTH
    p = camera.canonical_params
    assert (p["width"], p["height"]) == (320, 240)
    # field_of_view 62° is the shorter (vertical) side's: horizontal = 2·atan(tan 31° · 320/240).
    assert p["horizontal_fov"] == pytest.approx(2 * math.atan(math.tan(31 * DEG) * 4 / 3), abs=1e-15)
    assert math.degrees(p["horizontal_fov"]) == pytest.approx(77.39975, abs=1e-5)
    assert (p["near"], p["far"], p["update_rate"]) == (0.04, 200.0, 30.0)
    assert (p["range_min"], p["range_max"], p["noise_stddev"]) == (0.1, 10.0, 0.005)
    # It looks along the robot's +X with the image's top towards +Z.
    np.testing.assert_allclose(pose.rotation @ [1, 0, 0], [1, 0, 0], atol=1e-12)
    np.testing.assert_allclose(pose.rotation @ [0, 0, 1], [0, 0, 1], atol=1e-12)
    np.testing.assert_allclose(pose.translation, [0.04, 0.0, 0.265], atol=1e-12)
    # Independently: the cv optical axis (+Z of the node frame Ry(90)·Rz(−90)) is the viewing axis,
    # and the cv image's "down" (+Y) is the canonical −Z.
    node = axis_angle([0, 1, 0], 90 * DEG) @ axis_angle([0, 0, 1], -90 * DEG)
    np.testing.assert_allclose(node @ [0, 0, 1], pose.rotation @ [1, 0, 0], atol=1e-12)
    np.testing.assert_allclose(node @ [0, 1, 0], pose.rotation @ [0, 0, -1], atol=1e-12)
    assert camera.params["optical_frame"] == "cv"  # the source word, for the .body writer


def test_body_tutorial_spotlight() -> None:
    robot = load_body(TUTORIAL / "mobile_robot_sensors_ex.body")
    light, pose = device(robot, "Light")
    assert light.canonical is DeviceKind.SPOT_LIGHT
    p = light.canonical_params
    # direction [1, 0, 0] in the device frame: it shines along the robot's +X.
    np.testing.assert_allclose(pose.rotation @ np.array(p["direction"]), [1, 0, 0], atol=1e-12)
    np.testing.assert_allclose(pose.translation, [0.05, 0.0, 0.285], atol=1e-12)
    # beam_width 36° (inner), cut_off_angle 40° (outer): half-angles from the beam axis (VRML).
    assert p["spot_inner_angle"] == pytest.approx(36 * DEG)
    assert p["spot_outer_angle"] == pytest.approx(40 * DEG)
    assert p["spot_falloff"] == 6.0
    attenuation = (p["attenuation_constant"], p["attenuation_linear"], p["attenuation_quadratic"])
    assert attenuation == (1.0, 0.0, 0.01)
    assert (p["color"], p["intensity"], p["on"]) == ((1.0, 1.0, 1.0), 1.0, True)


BODY_DEVICES = """\
format: ChoreonoidBody
format_version: 2.0
angle_unit: degree
name: devices
links:
  - name: base
    joint_type: free
    mass: 1.0
    inertia: [0.01, 0, 0, 0, 0.01, 0, 0, 0, 0.01]
    elements:
      - {type: Camera, name: gl_cam, format: COLOR, width: 480, height: 640, field_of_view: 50}
      - {type: Camera, name: turned, format: DEPTH, optical_frame: robotics,
         optical_frame_rotation: [0, 0, 1, 90], rotation: [0, 0, 1, 30]}
      - {type: Camera, name: no_format}
      - {type: IMU, name: imu, max_acceleration: [1, 2, 3]}
      - {type: AccelerationSensor, name: acc, max_acceleration: [4, 5, 6]}
      - {type: RateGyroSensor, name: gyro, max_angular_velocity: [7, 8, 9]}
      - {type: ForceSensor, name: ft, translation: [0, 0, 0.1], max_force: [10, 10, 10],
         max_torque: [1, 1, 1]}
      - {type: PointLight, name: lamp, attenuation: [0.5, 0.25, 0.125], intensity: 0.7}
      - {type: SpotLight, name: wide}
      - {type: Holder, name: hand}
"""


def test_body_device_kinds_and_frames(tmp_path: Path) -> None:
    path = tmp_path / "devices.body"
    path.write_text(BODY_DEVICES)
    robot = load_body(path)
    base = robot.link("base")
    assert base is not None
    devices = {d.name: d for d in base.devices}
    assert "no_format" not in devices  # Choreonoid creates no camera without a format
    kinds = {name: d.canonical for name, d in devices.items()}
    assert kinds == {
        "gl_cam": DeviceKind.CAMERA,
        "turned": DeviceKind.DEPTH_CAMERA,
        "imu": DeviceKind.IMU,
        "acc": DeviceKind.ACCELEROMETER,
        "gyro": DeviceKind.GYRO,
        "ft": DeviceKind.FORCE_TORQUE,
        "lamp": DeviceKind.POINT_LIGHT,
        "wide": DeviceKind.SPOT_LIGHT,
        "hand": DeviceKind.OTHER,
    }
    # Portrait image: field_of_view is the shorter (horizontal) side's, used as is.
    gl_cam = devices["gl_cam"]
    assert gl_cam.canonical_params["horizontal_fov"] == pytest.approx(50 * DEG)
    assert "range_min" not in gl_cam.canonical_params and "noise_stddev" not in gl_cam.canonical_params
    # The default gl optical frame looks along the link's −Z with the image's top towards +Y.
    np.testing.assert_allclose(gl_cam.pose.rotation @ [1, 0, 0], [0, 0, -1], atol=1e-12)
    np.testing.assert_allclose(gl_cam.pose.rotation @ [0, 0, 1], [0, 1, 0], atol=1e-12)
    # robotics frame turned 30° about the link Z, then the image turned 90° about its optical axis
    # (GL Z): it still looks along the turned X, the image's top is the turned +Y (to the left).
    turned = devices["turned"].pose.rotation
    c, s = math.cos(30 * DEG), math.sin(30 * DEG)
    np.testing.assert_allclose(turned @ [1, 0, 0], [c, s, 0], atol=1e-12)
    np.testing.assert_allclose(turned @ [0, 0, 1], [-s, c, 0], atol=1e-12)
    assert devices["imu"].canonical_params == {"max_acceleration": (1.0, 2.0, 3.0)}  # ∞ gyro left out
    assert devices["acc"].canonical_params == {"max_acceleration": (4.0, 5.0, 6.0)}
    assert devices["gyro"].canonical_params == {"max_angular_velocity": (7.0, 8.0, 9.0)}
    ft = devices["ft"]
    assert ft.canonical_params == {"max_force": (10.0, 10.0, 10.0), "max_torque": (1.0, 1.0, 1.0)}
    np.testing.assert_allclose(ft.pose.translation, [0, 0, 0.1])
    np.testing.assert_allclose(ft.pose.rotation, np.eye(3))  # not an optical device: node frame
    lamp = devices["lamp"].canonical_params
    assert (lamp["attenuation_constant"], lamp["attenuation_linear"], lamp["attenuation_quadratic"]) == (
        0.5,
        0.25,
        0.125,
    )
    assert lamp["intensity"] == 0.7 and "direction" not in lamp
    # Choreonoid's defaults: beam_width 90° wider than cut_off_angle 45° acts as 45° (VRML rule).
    wide = devices["wide"].canonical_params
    assert (wide["spot_inner_angle"], wide["spot_outer_angle"]) == pytest.approx((45 * DEG, 45 * DEG))
    assert wide["direction"] == (0.0, 0.0, -1.0) and wide["spot_falloff"] == 1.0
    assert devices["hand"].canonical_params == {}


# ---- SDF and URDF <gazebo> sensors ---------------------------------------------------------------

GZ_WORLDS = CORPUS / "gz_sim_worlds" / "examples" / "worlds"
UNICYCLE = REPO / "samples" / "gazebo_unicycle" / "unicycle.sdf"


def read_robots(path: Path) -> list[Robot]:
    result = read_model(path)
    assert result.robots, [str(d) for d in result.diagnostics]
    return result.robots


def devices_of(robots: list[Robot]) -> dict[str, tuple[str, Device]]:
    return {d.name: (link.name, d) for r in robots for link in r.links for d in link.devices}


def test_sdf_unicycle_ray_and_camera() -> None:
    (robot,) = read_robots(UNICYCLE)
    top = robot.link("top")
    assert top is not None
    (ray,) = top.devices
    assert ray.canonical is DeviceKind.LIDAR
    assert ray.canonical_params == {
        "update_rate": 30.0,
        "horizontal_samples": 2,
        "horizontal_min_angle": 0.0,
        "horizontal_max_angle": 1.5707,
        "horizontal_resolution": 1.0,
        "vertical_samples": 1,
        "vertical_min_angle": 0.0,
        "vertical_max_angle": 0.0,
        "range_min": 0.05,
        "range_max": 70.0,
        "range_resolution": 0.02,
        "noise_stddev": 0.002,  # <ray><noise><stddev>
    }
    base = robot.link("base")
    assert base is not None and "noise_stddev" not in base.devices[0].canonical_params
    camera_link = robot.link("camera_link")
    assert camera_link is not None
    (camera,) = camera_link.devices
    assert camera.canonical is DeviceKind.CAMERA
    # No <horizontal_fov>: SDF's default 1.047 rad.
    assert camera.canonical_params == {
        "update_rate": 30.0,
        "width": 800,
        "height": 800,
        "horizontal_fov": 1.047,
        "near": 0.02,
        "far": 300.0,
        "format": "R8G8B8",
    }
    # SDF's sensor frame is the canonical one: the camera looks along the link's +X.
    np.testing.assert_allclose(camera.pose.rotation, np.eye(3), atol=1e-12)


@needs_corpus
def test_sdf_gz_sim_sensor_worlds() -> None:
    _, lidar = devices_of(read_robots(GZ_WORLDS / "gpu_lidar_sensor.sdf"))["gpu_lidar"]
    assert lidar.kind == "gpu_lidar" and lidar.canonical is DeviceKind.LIDAR
    p = lidar.canonical_params
    assert (p["horizontal_samples"], p["vertical_samples"], p["update_rate"]) == (640, 16, 10.0)
    assert (p["horizontal_min_angle"], p["horizontal_max_angle"]) == (-1.396263, 1.396263)
    assert (p["vertical_min_angle"], p["vertical_max_angle"]) == (-0.261799, 0.261799)
    assert (p["range_min"], p["range_max"], p["range_resolution"]) == (0.08, 10.0, 0.01)
    _, camera = devices_of(read_robots(GZ_WORLDS / "camera_sensor.sdf"))["camera"]
    assert camera.canonical is DeviceKind.CAMERA
    assert camera.canonical_params == {
        "update_rate": 30.0,
        "width": 320,
        "height": 240,
        "horizontal_fov": 1.047,
        "near": 0.1,
        "far": 100.0,
    }
    _, contact = devices_of(read_robots(GZ_WORLDS / "contact_sensor.sdf"))["sensor_contact"]
    assert contact.canonical is DeviceKind.CONTACT
    assert contact.canonical_params == {"update_rate": 100.0, "collision": "collision_sphere"}


@needs_corpus
def test_sdf_lights() -> None:
    robots = read_robots(GZ_WORLDS / "lights.sdf")
    world_lights = {d.name: d for d in robots[0].extras["sdf_world"]["lights"]}
    spot = world_lights["spot"]
    assert spot.canonical is DeviceKind.SPOT_LIGHT
    # <inner_angle> 0.1 and <outer_angle> 0.5 are whole cone angles (OGRE): half-angles 0.05, 0.25.
    assert spot.canonical_params == {
        "color": (0.0, 1.0, 0.0),
        "range": 4.0,
        "attenuation_constant": 0.2,
        "attenuation_linear": 0.5,
        "attenuation_quadratic": 0.01,
        "direction": (0.0, 0.0, -1.0),
        "spot_inner_angle": 0.05,
        "spot_outer_angle": 0.25,
        "spot_falloff": 0.8,
    }
    np.testing.assert_allclose(spot.pose.translation, [0, 0, 3])
    sun = world_lights["directional"]
    assert sun.canonical is DeviceKind.DIRECTIONAL_LIGHT
    assert sun.canonical_params["direction"] == (0.5, 0.2, -0.9)
    assert world_lights["point"].canonical is DeviceKind.POINT_LIGHT
    assert "direction" not in world_lights["point"].canonical_params
    _, link_light = devices_of(robots)["link_light_point"]
    assert link_light.canonical is DeviceKind.POINT_LIGHT
    assert link_light.canonical_params["color"] == (0.0, 0.0, 1.0)
    assert link_light.canonical_params["range"] == 2.0


SDF_SENSORS = """<?xml version="1.0"?>
<sdf version="1.9"><model name="m">
  <link name="a">
    <sensor name="side_cam" type="rgbd_camera">
      <pose>0.1 0 0.2 0 0 1.5707963267948966</pose>
      <camera><horizontal_fov>1.2</horizontal_fov><image><width>640</width><height>480</height></image>
        <clip><near>0.05</near><far>20</far></clip><noise><type>gaussian</type><stddev>0.01</stddev></noise>
      </camera>
    </sensor>
    <sensor name="imu" type="imu"><update_rate>200</update_rate><imu>
      <angular_velocity><x><noise type="gaussian"><stddev>0.003</stddev></noise></x>
        <y><noise type="gaussian"><stddev>0.003</stddev></noise></y>
        <z><noise type="gaussian"><stddev>0.003</stddev></noise></z></angular_velocity>
      <linear_acceleration><x><noise type="gaussian"><stddev>0.003</stddev></noise></x>
        <y><noise type="gaussian"><stddev>0.003</stddev></noise></y>
        <z><noise type="gaussian"><stddev>0.003</stddev></noise></z></linear_acceleration>
    </imu></sensor>
    <sensor name="alt" type="altimeter"/>
  </link>
  <link name="b"/>
  <joint name="j" type="revolute"><parent>a</parent><child>b</child><axis><xyz>0 0 1</xyz></axis>
    <sensor name="ft" type="force_torque"><update_rate>50</update_rate>
      <force_torque><frame>child</frame><measure_direction>child_to_parent</measure_direction></force_torque>
    </sensor></joint>
</model></sdf>
"""


def test_sdf_posed_camera_imu_force_torque(tmp_path: Path) -> None:
    path = tmp_path / "sensors.sdf"
    path.write_text(SDF_SENSORS)
    found = devices_of(read_robots(path))
    _, camera = found["side_cam"]
    assert camera.canonical is DeviceKind.RGBD_CAMERA
    p = camera.canonical_params
    assert (p["width"], p["height"], p["horizontal_fov"], p["near"], p["far"]) == (640, 480, 1.2, 0.05, 20.0)
    assert p["noise_stddev"] == 0.01
    # Yawed 90°: the camera looks along the link's +Y, image top +Z.
    np.testing.assert_allclose(camera.pose.rotation @ [1, 0, 0], [0, 1, 0], atol=1e-12)
    np.testing.assert_allclose(camera.pose.rotation @ [0, 0, 1], [0, 0, 1], atol=1e-12)
    _, imu = found["imu"]
    assert imu.canonical is DeviceKind.IMU and imu.canonical_params == {
        "update_rate": 200.0,
        "noise_stddev": 0.003,
    }
    link, ft = found["ft"]
    assert link == "b" and ft.canonical is DeviceKind.FORCE_TORQUE
    assert ft.canonical_params == {
        "update_rate": 50.0,
        "frame": "child",
        "measure_direction": "child_to_parent",
    }
    _, alt = found["alt"]
    assert alt.canonical is DeviceKind.OTHER and alt.kind == "altimeter"


URDF_GAZEBO = """<?xml version="1.0"?>
<robot name="r">
  <link name="base"/>
  <link name="laser"/>
  <joint name="j" type="fixed"><parent link="base"/><child link="laser"/>
    <origin xyz="0.2 0 0.3"/></joint>
  <gazebo reference="laser">
    <sensor name="scan" type="gpu_ray">
      <pose>0 0 0.05 0 0 0</pose>
      <update_rate>40</update_rate>
      <ray>
        <scan><horizontal><samples>720</samples><resolution>1</resolution>
          <min_angle>-1.570796</min_angle><max_angle>1.570796</max_angle></horizontal></scan>
        <range><min>0.10</min><max>30.0</max><resolution>0.01</resolution></range>
        <noise><type>gaussian</type><mean>0.0</mean><stddev>0.01</stddev></noise>
      </ray>
    </sensor>
  </gazebo>
</robot>
"""


def test_urdf_gazebo_sensor(tmp_path: Path) -> None:
    path = tmp_path / "r.urdf"
    path.write_text(URDF_GAZEBO)
    link, scan = devices_of(read_robots(path))["scan"]
    assert link == "laser" and scan.kind == "gpu_ray" and scan.canonical is DeviceKind.LIDAR
    assert scan.canonical_params == {
        "update_rate": 40.0,
        "horizontal_samples": 720,
        "horizontal_min_angle": -1.570796,
        "horizontal_max_angle": 1.570796,
        "horizontal_resolution": 1.0,
        "vertical_samples": 1,
        "vertical_min_angle": 0.0,
        "vertical_max_angle": 0.0,
        "range_min": 0.1,
        "range_max": 30.0,
        "range_resolution": 0.01,
        "noise_stddev": 0.01,
    }
    np.testing.assert_allclose(scan.pose.translation, [0, 0, 0.05])


@needs_corpus
def test_urdf_gazebo_sensors_in_corpus_xacro() -> None:
    """The pioneer3dx xacro's hokuyo laser and camera, through xacro and the URDF reader."""
    found = devices_of(
        read_robots(
            CORPUS / "gazebo_ros_pkgs/gazebo_plugins/test/multi_robot_scenario/xacro/p3dx/pioneer3dx.xacro"
        )
    )
    link, laser = found["laser"]
    assert link == "front_laser" and laser.canonical is DeviceKind.LIDAR
    p = laser.canonical_params
    assert (p["horizontal_samples"], p["horizontal_min_angle"], p["horizontal_max_angle"]) == (
        683,
        -2.0944,
        2.0944,
    )
    assert (p["range_min"], p["range_max"], p["update_rate"]) == (0.08, 5.0, 30.0)
    _, camera = found["camera1"]
    assert camera.canonical is DeviceKind.CAMERA
    c = camera.canonical_params
    assert (c["width"], c["height"], c["horizontal_fov"], c["noise_stddev"]) == (800, 800, 1.3962634, 0.007)


# ---- MJCF ----------------------------------------------------------------------------------------

MJCF_DEVICES = """<mujoco model="m">
  <worldbody>
    <body name="base" pos="0 0 1">
      <freejoint/>
      <geom type="box" size="0.1 0.1 0.1"/>
      <body name="head" pos="0.2 0 0.1" euler="0 0 30">
        <joint name="pan" type="hinge" axis="0 0 1" pos="0.05 0.02 0"/>
        <geom type="sphere" size="0.05"/>
        <camera name="eye" pos="0.06 0 0.01" xyaxes="0 -1 0 0 0 1" fovy="45" resolution="640 480"/>
        <light name="torch" pos="0.06 0 0" dir="1 0 0" cutoff="30" exponent="8" attenuation="1 0.2 0.03"/>
        <site name="ray" pos="0.06 0 -0.02" zaxis="1 0 -1"/>
        <site name="ft" pos="0 0 -0.05"/>
      </body>
    </body>
  </worldbody>
  <sensor>
    <rangefinder name="range" site="ray" cutoff="4"/>
    <accelerometer name="acc" site="ft" noise="0.02"/>
    <force name="f" site="ft"/>
    <torque name="t" site="ft"/>
  </sensor>
</mujoco>
"""


def test_mjcf_camera_light_and_site_sensors(tmp_path: Path) -> None:
    mujoco = pytest.importorskip("mujoco")
    path = tmp_path / "m.xml"
    path.write_text(MJCF_DEVICES)
    (robot,) = read_robots(path)
    found = devices_of([robot])
    link, eye = found["eye"]
    assert link == "head" and eye.canonical is DeviceKind.CAMERA
    # fovy 45° vertical, 640×480: horizontal = 2·atan(tan 22.5° · 4/3).
    assert eye.canonical_params == {
        "width": 640,
        "height": 480,
        "horizontal_fov": pytest.approx(2 * math.atan(math.tan(22.5 * DEG) * 4 / 3), abs=1e-15),
    }
    assert math.degrees(eye.canonical_params["horizontal_fov"]) == pytest.approx(57.8224, abs=1e-4)
    # MuJoCo itself places the devices: compare with its forward kinematics at qpos0 (root at its pose).
    model = mujoco.MjModel.from_xml_path(str(path))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    poses = robot.world_poses()
    eye_world = poses["head"] @ eye.pose
    cam_xmat = data.cam_xmat[0].reshape(3, 3)
    np.testing.assert_allclose(eye_world.translation, data.cam_xpos[0], atol=1e-12)
    np.testing.assert_allclose(eye_world.rotation @ [1, 0, 0], -cam_xmat[:, 2], atol=1e-12)  # looks along −Z
    np.testing.assert_allclose(eye_world.rotation @ [0, 0, 1], cam_xmat[:, 1], atol=1e-12)  # image top +Y
    # xyaxes "0 -1 0  0 0 1" in a body yawed 30°: it looks along the body's +X, top +Z.
    np.testing.assert_allclose(
        eye_world.rotation @ [1, 0, 0], [math.cos(30 * DEG), math.sin(30 * DEG), 0], atol=1e-12
    )

    _, torch = found["torch"]
    assert torch.canonical is DeviceKind.SPOT_LIGHT
    p = torch.canonical_params
    assert p["spot_outer_angle"] == pytest.approx(30 * DEG) and p["spot_falloff"] == 8.0
    assert (p["attenuation_constant"], p["attenuation_linear"], p["attenuation_quadratic"]) == pytest.approx(
        (1.0, 0.2, 0.03)
    )
    torch_world = poses["head"] @ torch.pose
    np.testing.assert_allclose(torch_world.translation, data.light_xpos[0], atol=1e-12)
    np.testing.assert_allclose(
        torch_world.rotation @ np.array(p["direction"]), data.light_xdir[0], atol=1e-12
    )

    _, ray = found["range"]
    assert ray.canonical is DeviceKind.LIDAR
    assert (ray.canonical_params["horizontal_samples"], ray.canonical_params["range_max"]) == (1, 4.0)
    ray_world = poses["head"] @ ray.pose
    site_xmat = data.site_xmat[0].reshape(3, 3)
    np.testing.assert_allclose(ray_world.translation, data.site_xpos[0], atol=1e-12)
    np.testing.assert_allclose(
        ray_world.rotation @ [1, 0, 0], site_xmat[:, 2], atol=1e-12
    )  # the ray: site +Z

    _, acc = found["acc"]
    assert acc.canonical is DeviceKind.ACCELEROMETER and acc.canonical_params == {"noise_stddev": 0.02}
    _, ft = found["ft"]  # force and torque on one site: one force_torque device named after the site
    assert ft.canonical is DeviceKind.FORCE_TORQUE and (
        ft.params["force_sensor"],
        ft.params["torque_sensor"],
    ) == (
        "f",
        "t",
    )
    np.testing.assert_allclose((poses["head"] @ ft.pose).translation, data.site_xpos[1], atol=1e-12)


def test_body_node_rotation_inverts_the_optical_frame() -> None:
    """A .body writer gets the node rotation back from the canonical pose and the kept words."""
    from modelkit.formats.body.devices import canonical_rotation, node_rotation

    node = axis_angle([0.3, -0.5, 0.8], 1.1)
    extra = axis_angle([1, 2, 3], 0.7)
    for frame in ("gl", "cv", "robotics"):
        for params in ({"optical_frame": frame}, {"optical_frame": frame, "optical_frame_rotation": extra}):
            canonical = canonical_rotation("Camera", params, node)
            np.testing.assert_allclose(node_rotation("Camera", params, canonical), node, atol=1e-12)
    assert canonical_rotation("SpotLight", {}, node) is node


SENSOR_RANGES_BODY = """format: ChoreonoidBody
format_version: 2.0
angle_unit: degree
name: Ranges
links:
  - name: Base
    joint_type: free
    mass: 1.0
    inertia: [ 0.01, 0, 0, 0, 0.01, 0, 0, 0, 0.01 ]
    elements:
      - { type: RateGyroSensor, name: gyro, max_angular_velocity: [ 10, 10, 10 ] }
      - { type: AccelerationSensor, name: acc, max_acceleration: [ 20, 30, 40 ] }
      - { type: ForceSensor, name: ft, max_force: [ 100, 100, 100 ] }
      - { type: IMU, name: imu }
"""


def test_sensor_ranges_become_mujoco_cutoffs(tmp_path: Path) -> None:
    """Choreonoid's per-axis sensor ranges clamp the reading, as MuJoCo's cutoff does (one number per
    sensor: three different ones are written as the largest, with an MK807 note); no range, no cutoff.
    Before, the ranges were left out of the MJCF without a note."""
    import mujoco

    from modelkit.convert.api import convert

    source = tmp_path / "ranges.body"
    source.write_text(SENSOR_RANGES_BODY)
    out = tmp_path / "out" / "ranges.xml"
    notes = convert([source], out).notes
    model = mujoco.MjModel.from_xml_path(str(out))
    cutoff = {mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_SENSOR, s): float(model.sensor_cutoff[s])
              for s in range(model.nsensor)}
    assert cutoff == {"gyro": 10.0, "acc": 40.0, "ft_force": 100.0, "ft_torque": 0.0, "imu_acc": 0.0,
                      "imu_gyro": 0.0}
    said = [n.message for n in notes if n.code == "MK807"]
    assert len(said) == 1, said
    assert "acc: max_acceleration 20 30 40 per axis" in said[0] and "largest, 40" in said[0]
