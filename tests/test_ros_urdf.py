"""URDF that ROS tools take (issue 17 item 7): the source's joint names, sensors as TF frames.

Oracles: ``check_urdf`` (urdfdom, what robot_state_publisher parses with), yourdfpy forward kinematics
(the transforms robot_state_publisher would publish), libsdformat 12 (what Gazebo spawns a URDF with).
"""

from __future__ import annotations

import math
import subprocess
from pathlib import Path

import numpy as np
import pytest
from lxml import etree

from modelkit.api import validate
from modelkit.convert.api import render_model
from modelkit.convert.gazebo import plugin_family, source_family
from modelkit.convert.notes import ConversionNote
from modelkit.convert.numbers import fmt
from modelkit.convert.options import WriteOptions
from modelkit.convert.output import OutputPlan
from modelkit.formats.urdf.write_links import TINY_MASS
from modelkit.model import Robot
from tests.conftest import SAMPLES, TUTORIAL, require_tool
from tests.test_sdf_reader import oracle_has_errors, sdf_oracle  # noqa: F401 (the fixture)

PANTILT = TUTORIAL / "mobile_robot_pantilt.body"
SENSORS = TUTORIAL / "mobile_robot_sensors.body"


def _read(path: Path) -> Robot:
    checked = validate(path)
    assert checked.robot is not None, [str(d) for d in checked.diagnostics]
    return checked.robot


def _write(
    robot: Robot, folder: Path, options: WriteOptions | None = None
) -> tuple[Path, list[ConversionNote]]:
    plan = OutputPlan(folder)
    notes = render_model(robot, "urdf", plan, "robot.urdf", options or WriteOptions())
    assert not plan.problems()
    plan.commit()
    return folder / "robot.urdf", notes


def _check_urdf(path: Path) -> str:
    run = subprocess.run([require_tool("check_urdf"), str(path)], capture_output=True, text=True, timeout=30)
    assert run.returncode == 0, run.stderr
    return run.stdout


def _joints(path: Path) -> dict[str, tuple[str, str]]:
    root = etree.parse(str(path)).getroot()
    out: dict[str, tuple[str, str]] = {}
    for joint in root.iter("joint"):
        parent, child = joint.find("parent"), joint.find("child")
        assert parent is not None and child is not None
        out[joint.get("name", "")] = (parent.get("link", ""), child.get("link", ""))
    return out


def test_pantilt_wheel_joints_keep_their_source_names(tmp_path: Path, sdf_oracle: Path) -> None:  # noqa: F811
    """The wheel joints are LeftWheel / RightWheel as in the .body (joint_states drives them in rviz);
    check_urdf takes the file; libsdformat refuses the shared name, which MK846 says and
    urdf_distinct_names avoids."""
    robot = _read(PANTILT)
    path, notes = _write(robot, tmp_path / "kept")
    joints = _joints(path)
    assert joints["LeftWheel"] == ("Chassis", "LeftWheel")
    assert joints["RightWheel"] == ("Chassis", "RightWheel")
    assert {"PanJoint", "TiltJoint"} <= set(joints) and not any(n.endswith("_joint") for n in joints)
    assert "MK800" not in {n.code for n in notes}
    kept = [n for n in notes if n.code == "MK846"]
    assert len(kept) == 1 and '"LeftWheel", "RightWheel"' in kept[0].message
    tree = _check_urdf(path)
    assert "root Link: Chassis has 3 child(ren)" in tree and "child(1):  LeftWheel" in tree
    assert oracle_has_errors(sdf_oracle, path)  # libsdformat: "Non-unique name", a frame-graph cycle

    distinct, notes = _write(robot, tmp_path / "distinct", WriteOptions(urdf_distinct_names=True))
    assert {"LeftWheel_joint", "RightWheel_joint"} <= set(_joints(distinct))
    assert "MK846" not in {n.code for n in notes} and sum(n.code == "MK800" for n in notes) == 2
    _check_urdf(distinct)
    assert not oracle_has_errors(sdf_oracle, distinct)


def _elements(path: Path, tag: str) -> list[bytes]:
    return [etree.tostring(el) for el in etree.parse(str(path)).getroot().iter(tag)]


def _rot(axis: str, degrees: float) -> np.ndarray:
    c, s = math.cos(math.radians(degrees)), math.sin(math.radians(degrees))
    return {
        "x": np.array([[1, 0, 0], [0, c, -s], [0, s, c]]),
        "y": np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]]),
        "z": np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]]),
    }[axis]


def _pose(rotation: np.ndarray, translation: tuple[float, float, float]) -> np.ndarray:
    out = np.eye(4)
    out[:3, :3], out[:3, 3] = rotation, translation
    return out


def test_sensors_are_tf_frames_where_the_body_file_puts_them(tmp_path: Path) -> None:
    """The acceptance case: mobile_robot_sensors.body → URDF has links LiDAR, RealSense and
    RealSense_optical on fixed joints; check_urdf shows them, and yourdfpy's forward kinematics (what
    robot_state_publisher publishes) puts them where the .body file does, at a pan/tilt pose.

    Expected poses come from the .body's numbers by hand: PanLink at (-0.02, 0, 0.165) turning about Z,
    TiltLink 0.12 above it turning about Y; the LiDAR 0.025 above TiltLink; the RealSense at
    (0.06, 0, -0.02) with rotation [0 1 0 90°][0 0 1 -90°] and `optical_frame: cv`, which is the
    REP-103 optical frame itself (z forward, x right, y down), the camera link the same point, x forward.
    """
    yourdfpy = pytest.importorskip("yourdfpy")
    robot = _read(SENSORS)
    path, notes = _write(robot, tmp_path)
    framed = [n for n in notes if n.code == "MK847"]
    assert len(framed) == 1 and '"RealSense_optical"' in framed[0].message
    tree = _check_urdf(path)
    for line in ("child(1):  LiDAR", "child(2):  RealSense", "child(1):  RealSense_optical"):
        assert line in tree, tree
    joints = _joints(path)
    assert joints["LiDAR_joint"] == ("TiltLink", "LiDAR")
    assert joints["RealSense_joint"] == ("TiltLink", "RealSense")
    assert joints["RealSense_optical_joint"] == ("RealSense", "RealSense_optical")
    root = etree.parse(str(path)).getroot()
    references = {g.get("reference"): [s.get("name") for s in g.iter("sensor")] for g in root.iter("gazebo")}
    assert references["LiDAR"] == ["LiDAR"] and references["RealSense"] == ["RealSense"]

    pan, tilt = 23.0, -17.0
    model = yourdfpy.URDF.load(str(path), build_scene_graph=True, load_meshes=False)
    model.update_cfg({"PanJoint": math.radians(pan), "TiltJoint": math.radians(tilt),
                      "LeftWheel": 0.3, "RightWheel": -0.2})
    tilt_link = _pose(_rot("z", pan), (-0.02, 0.0, 0.165)) @ _pose(_rot("y", tilt), (0.0, 0.0, 0.12))
    optical = tilt_link @ _pose(_rot("y", 90.0) @ _rot("z", -90.0), (0.06, 0.0, -0.02))
    expected = {
        "LiDAR": tilt_link @ _pose(np.eye(3), (0.0, 0.0, 0.025)),
        "RealSense": tilt_link @ _pose(np.eye(3), (0.06, 0.0, -0.02)),
        "RealSense_optical": optical,
    }
    for frame, pose in expected.items():
        got = model.get_transform(frame_to=frame, frame_from="Chassis")
        assert np.allclose(got, pose, atol=1e-12), (frame, got, pose)
    # REP-103 in the world: the optical z axis is the camera link's x (where it looks), y is its -z
    camera = model.get_transform(frame_to="RealSense", frame_from="Chassis")
    assert np.allclose(optical[:3, 2], camera[:3, 0]) and np.allclose(optical[:3, 1], -camera[:3, 2])


def test_sensor_links_round_trip_and_can_be_left_out(tmp_path: Path) -> None:
    """Read back, a sensor link keeps its sensor, is a massless frame, and is written again unchanged
    (no LiDAR_2, no other mass);
    validate finds no error in the output; --no-urdf-sensor-links keeps the sensors on TiltLink."""
    robot = _read(SENSORS)
    path, _ = _write(robot, tmp_path / "first")
    checked = validate(path)
    assert not [d for d in checked.diagnostics if d.severity.value == "error"]
    back = checked.robot
    assert back is not None
    lidar = back.link("LiDAR")
    assert lidar is not None and [d.name for d in lidar.devices] == ["LiDAR"]
    assert lidar.inertial is None  # a frame: its tiny inertial (not PyBullet's 1 kg) reads back as none
    assert path.read_text().count(f'<mass value="{fmt(TINY_MASS)}"/>') == 3
    # the floating root reads back open (URDF's convention): ask for the floating root it had
    again, notes = _write(back, tmp_path / "again", WriteOptions(base="floating"))
    for tag in ("joint", "gazebo"):  # (the PyBullet <contact> of the links is not read back: MK123)
        assert _elements(again, tag) == _elements(path, tag), tag
    assert [lk.get("name") for lk in etree.parse(str(again)).getroot().iter("link")] == [
        lk.get("name") for lk in etree.parse(str(path)).getroot().iter("link")
    ]
    assert "MK847" not in {n.code for n in notes}  # the frames are the model's links now

    plain, notes = _write(robot, tmp_path / "plain", WriteOptions(urdf_sensor_links=False))
    assert "MK847" not in {n.code for n in notes}
    assert not {"LiDAR", "RealSense", "RealSense_optical"} & {lk.get("name") for lk in
                                                             etree.parse(str(plain)).getroot().iter("link")}
    sensors = {s.get("name"): s for s in etree.parse(str(plain)).getroot().iter("sensor")}
    assert sensors["LiDAR"].findtext("pose") == "0 0 0.025 0 0 0"
    assert sensors["RealSense"].getparent().get("reference") == "TiltLink"


UNICYCLE = SAMPLES / "gazebo_unicycle" / "unicycle.sdf"


def _sensors(path: Path) -> dict[str, tuple[str | None, str | None, list[str]]]:
    """reference → (sensor name, type, plugin files) of each <gazebo> block holding a sensor."""
    out = {}
    for block in etree.parse(str(path)).getroot().iter("gazebo"):
        for sensor in block.iter("sensor"):
            plugins = [p.get("filename", "") for p in sensor.iter("plugin")]
            out[block.get("reference", "")] = (sensor.get("name"), sensor.get("type"), plugins)
    return out


def test_gazebo_family_follows_the_source_or_the_option(tmp_path: Path) -> None:
    """The lecture's unicycle SDF is Gazebo classic (`ray` sensors, gazebo_ros plugins): its URDF keeps
    the sensor types and the three plugins; --gazebo sim writes gz-sim types and notes each dropped
    plugin (MK848). plugin_family tells the families apart by file name."""
    robot = _read(UNICYCLE)
    assert source_family(robot) == "classic"
    path, notes = _write(robot, tmp_path / "auto")
    assert _sensors(path) == {
        "sensor": ("sensor", "ray", ["libgazebo_ros_velodyne_laser.so"]),
        "sensor_2": ("sensor", "ray", ["libgazebo_ros_velodyne_laser.so"]),
        "camera1": ("camera1", "camera", ["libgazebo_ros_camera.so"]),
    }
    assert "MK848" not in {n.code for n in notes}
    _check_urdf(path)
    sim, notes = _write(robot, tmp_path / "sim", WriteOptions(gazebo="sim"))
    assert {ref: (t, files) for ref, (_, t, files) in _sensors(sim).items()} == {
        "sensor": ("gpu_lidar", []), "sensor_2": ("gpu_lidar", []), "camera1": ("camera", [])}
    dropped = [n for n in notes if n.code == "MK848"]
    assert len(dropped) == 3 and all("Gazebo classic code" in n.message for n in dropped)
    assert plugin_family("libgazebo_ros_camera.so") == "classic"
    assert plugin_family("gz-sim-diff-drive-system") == "sim"
    assert plugin_family("ignition-gazebo-sensors-system") == "sim"
    assert plugin_family("libmy_controller.so") is None
    assert plugin_family("libroboticsgroup_gazebo_mimic_joint_plugin.so") == "classic"  # a classic .so


def test_unmapped_sensor_parameters_are_notes_and_classic_sdf_loads(
    tmp_path: Path, sdf_oracle: Path  # noqa: F811
) -> None:
    """Choreonoid's detection_rate (and the RealSense's depth range) have no SDF element: an MK849 note
    each, with the value. --gazebo classic writes `ray` with a <ray> element and `depth` (Gazebo 11's
    names) in URDF and SDF; libsdformat 12 loads the SDF."""
    robot = _read(SENSORS)
    path, notes = _write(robot, tmp_path / "sim")
    unmapped = {n.message.split('"')[1]: n.message for n in notes if n.code == "MK849"}
    assert set(unmapped) == {"LiDAR", "RealSense"}
    assert "detection_rate 0.9" in unmapped["LiDAR"]
    assert "range_max 10" in unmapped["RealSense"] and "detection_rate 0.9" in unmapped["RealSense"]
    types = {ref: t for ref, (_, t, _) in _sensors(path).items()}
    assert types == {"LiDAR": "gpu_lidar", "RealSense": "rgbd_camera"}
    classic, _ = _write(robot, tmp_path / "classic", WriteOptions(gazebo="classic"))
    assert {ref: t for ref, (_, t, _) in _sensors(classic).items()} == {"LiDAR": "ray", "RealSense": "depth"}
    plan = OutputPlan(tmp_path / "sdf")
    render_model(robot, "sdf", plan, "robot.sdf", WriteOptions(gazebo="classic"))
    plan.commit()
    sdf = etree.parse(str(tmp_path / "sdf" / "robot.sdf")).getroot()
    lidar = next(s for s in sdf.iter("sensor") if s.get("name") == "LiDAR")
    assert lidar.get("type") == "ray" and lidar.find("ray") is not None and lidar.find("lidar") is None
    assert not oracle_has_errors(sdf_oracle, tmp_path / "sdf" / "robot.sdf")


def _plugins_by_sensor(root: etree._Element) -> dict[str, dict[str, str]]:
    """Sensor name → its plugin's file name and each leaf element's text by its path in the plugin
    (``ros/remapping`` for a ``<remapping>`` in ``<ros>``)."""
    out: dict[str, dict[str, str]] = {}
    for sensor in root.iter("sensor"):
        for plugin in sensor.iter("plugin"):
            fields = {"filename": plugin.get("filename", "")}
            stack = [(child, child.tag) for child in plugin]
            while stack:
                element, path = stack.pop()
                stack.extend((child, f"{path}/{child.tag}") for child in element)
                if len(element) == 0:
                    fields[path] = (element.text or "").strip()
            out[sensor.get("name", "")] = fields
    return out


EXPECTED_PLUGINS = {
    "LiDAR": {"filename": "libgazebo_ros_ray_sensor.so", "ros/remapping": "~/out:=LiDAR/scan",
              "output_type": "sensor_msgs/LaserScan", "frame_name": "LiDAR"},
    "RealSense": {"filename": "libgazebo_ros_camera.so", "camera_name": "RealSense",
                  "frame_name": "RealSense_optical", "min_depth": "0.1", "max_depth": "10"},
}


def test_classic_sensors_publish_to_ros(tmp_path: Path, sdf_oracle: Path) -> None:  # noqa: F811
    """A .body robot for Gazebo classic: the LiDAR gets gazebo_ros's ray-sensor plugin (LaserScan, stamped
    with its TF frame) and the RealSense the camera plugin (stamped with its REP-103 optical frame, its
    detection range as min/max depth, no longer an MK849 loss); MK850 names the topics. check_urdf takes
    the file, and libsdformat's URDF conversion (what Gazebo spawns) keeps both plugins in the sensors."""
    robot = _read(SENSORS)
    options = WriteOptions(gazebo="classic", urdf_distinct_names=True)
    path, notes = _write(robot, tmp_path / "classic", options)
    assert _plugins_by_sensor(etree.parse(str(path)).getroot()) == EXPECTED_PLUGINS
    added = {n.message.split('"')[1]: n.message for n in notes if n.code == "MK850"}
    assert set(added) == {"LiDAR", "RealSense"}
    assert "sensor_msgs/LaserScan on LiDAR/scan" in added["LiDAR"]
    assert "RealSense/depth/image_raw, RealSense/points" in added["RealSense"]
    (unmapped,) = [n.message for n in notes if n.code == "MK849" and '"RealSense"' in n.message]
    assert "detection_rate 0.9" in unmapped and "range_" not in unmapped
    _check_urdf(path)
    run = subprocess.run([str(sdf_oracle), "--print", path.name], cwd=path.parent, capture_output=True,
                         text=True, timeout=60)
    assert run.returncode == 0, run.stderr
    converted = _plugins_by_sensor(etree.fromstring(run.stdout.encode()))
    assert {name: fields["filename"] for name, fields in converted.items()} == {
        name: fields["filename"] for name, fields in EXPECTED_PLUGINS.items()}
    assert converted["RealSense"]["frame_name"] == "RealSense_optical"


def test_ros_plugins_only_where_the_source_has_none_and_for_classic(tmp_path: Path) -> None:
    """No plugin for Gazebo Sim (its sensors reach ROS through ros_gz_bridge), none with --no-ros-plugins,
    and a source's own plugins stay the only ones (the lecture's unicycle); the SDF target gets them too,
    stamped with the sensor's link (no frame_name: the SDF has no TF frames of its own)."""
    robot = _read(SENSORS)
    for folder, options in (("sim", WriteOptions(gazebo="sim")),
                            ("off", WriteOptions(gazebo="classic", ros_plugins=False))):
        path, notes = _write(robot, tmp_path / folder, options)
        assert _plugins_by_sensor(etree.parse(str(path)).getroot()) == {}
        assert "MK850" not in {n.code for n in notes}
    path, notes = _write(_read(UNICYCLE), tmp_path / "unicycle", WriteOptions(gazebo="classic"))
    assert "MK850" not in {n.code for n in notes}
    assert {f["filename"] for f in _plugins_by_sensor(etree.parse(str(path)).getroot()).values()} == {
        "libgazebo_ros_velodyne_laser.so", "libgazebo_ros_camera.so"}
    plan = OutputPlan(tmp_path / "sdf")
    render_model(robot, "sdf", plan, "robot.sdf", WriteOptions(gazebo="classic"))
    plan.commit()
    in_sdf = _plugins_by_sensor(etree.parse(str(tmp_path / "sdf" / "robot.sdf")).getroot())
    assert in_sdf == {name: {k: v for k, v in fields.items() if k != "frame_name"}
                      for name, fields in EXPECTED_PLUGINS.items()}


def test_imu_colour_camera_and_3d_lidar_get_their_plugins(tmp_path: Path) -> None:
    """The other kinds: a colour camera (no depth topics), a LiDAR with a vertical field (a point cloud),
    and Choreonoid's acceleration and rate-gyro sensors (the IMU plugin, world-frame orientation)."""
    text = SENSORS.read_text()
    text = text.replace("format: COLOR_DEPTH", "format: COLOR")
    vertical = "yaw_range: 270.0\n        pitch_range: 30.0\n        pitch_step: 2.0"
    text = text.replace("yaw_range: 270.0", vertical)
    imu = ("      -\n        type: AccelerationSensor\n        name: Accel\n      -\n"
           "        type: RateGyroSensor\n        name: Gyro\n")
    marker = "    elements:\n"
    at = text.index(marker) + len(marker)  # the first link's elements (the chassis)
    source = tmp_path / "model" / "robot.body"
    source.parent.mkdir()
    for item in TUTORIAL.iterdir():  # the robot's resources, beside it
        if item.name != source.name and not (source.parent / item.name).exists():
            (source.parent / item.name).symlink_to(item)
    source.write_text(text[:at] + imu + text[at:])
    path, notes = _write(_read(source), tmp_path / "out", WriteOptions(gazebo="classic"))
    plugins = _plugins_by_sensor(etree.parse(str(path)).getroot())
    assert plugins["LiDAR"]["output_type"] == "sensor_msgs/PointCloud2"
    assert plugins["LiDAR"]["ros/remapping"] == "~/out:=LiDAR/points"
    assert plugins["RealSense"] == {"filename": "libgazebo_ros_camera.so", "camera_name": "RealSense",
                                    "frame_name": "RealSense_optical"}
    for name in ("Accel", "Gyro"):
        assert plugins[name] == {"filename": "libgazebo_ros_imu_sensor.so",
                                 "ros/remapping": f"~/out:={name}/imu",
                                 "initial_orientation_as_reference": "false", "frame_name": name}
    assert len([n for n in notes if n.code == "MK850"]) == 4
    _check_urdf(path)


def test_a_urdf_sensors_own_plugins_reach_sdf(tmp_path: Path, sdf_oracle: Path) -> None:  # noqa: F811
    """A URDF sensor's plugins (the lecture's unicycle, written to URDF) are carried to SDF as an SDF
    sensor's are: the three gazebo_ros plugins stay the only ones (no MK850), no MK808 claims the sensor
    blocks are lost, and libsdformat accepts the file. Before, URDF → SDF dropped them."""
    urdf, _ = _write(_read(UNICYCLE), tmp_path / "urdf")
    plan = OutputPlan(tmp_path / "sdf")
    notes = render_model(_read(urdf), "sdf", plan, "robot.sdf", WriteOptions())
    plan.commit()
    sdf = tmp_path / "sdf" / "robot.sdf"
    sensors = etree.parse(str(sdf)).getroot().iter("sensor")
    plugins = [p.get("filename") for s in sensors for p in s.iter("plugin")]
    assert sorted(plugins) == [
        "libgazebo_ros_camera.so", "libgazebo_ros_velodyne_laser.so", "libgazebo_ros_velodyne_laser.so"]
    assert "MK850" not in {n.code for n in notes}
    assert not [n for n in notes if n.code == "MK808" and "extension of link" in n.message]
    assert not oracle_has_errors(sdf_oracle, sdf)
