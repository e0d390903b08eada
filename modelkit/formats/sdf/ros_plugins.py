"""The ``gazebo_ros`` plugin that makes a Gazebo classic sensor publish to ROS 2 (gazebo_ros_pkgs).

A Gazebo classic sensor alone publishes on Gazebo's own transport; ROS tools (RViz, a SLAM node, a
bag) see nothing until the sensor carries a ``gazebo_ros`` plugin. A source with no Gazebo meaning (a
``.body`` file, MJCF) has no plugins, so a sensor written for Gazebo classic gets the standard one:

* a LiDAR: ``libgazebo_ros_ray_sensor.so``, ``<name>/scan`` (``sensor_msgs/LaserScan``) with one
  vertical sample, else ``<name>/points`` (``sensor_msgs/PointCloud2``);
* a camera: ``libgazebo_ros_camera.so``, ``<name>/image_raw`` and ``<name>/camera_info``; a depth or
  RGB-D camera also ``<name>/depth/image_raw`` and ``<name>/points``;
* an IMU, accelerometer or gyro: ``libgazebo_ros_imu_sensor.so``, ``<name>/imu`` (``sensor_msgs/Imu``).

Topics are relative to the node's namespace (``/`` unless the launch file sets one).

``frame_name`` is the TF frame the data is stamped with: the sensor's link, for a camera its REP-103
optical frame (the URDF writer's sensor frames); without one the plugin stamps its parent link. A depth
camera's detection range (Choreonoid's ``range_min``/``range_max``) becomes the plugin's
``min_depth``/``max_depth``, the point cloud's range. The IMU reports its orientation in the world
frame (``initial_orientation_as_reference`` false, REP 145), not relative to its pose at start.
Force-torque and contact sensors have no plugin here: their ROS plugins name a joint or collisions,
which a device does not carry.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from modelkit.convert.numbers import fmt
from modelkit.model import CAMERA_KINDS, DeviceKind

RAY = "libgazebo_ros_ray_sensor.so"
CAMERA = "libgazebo_ros_camera.so"
IMU = "libgazebo_ros_imu_sensor.so"
DEPTH_KINDS = frozenset({DeviceKind.DEPTH_CAMERA, DeviceKind.RGBD_CAMERA})
IMU_KINDS = frozenset({DeviceKind.IMU, DeviceKind.ACCELEROMETER, DeviceKind.GYRO})


@dataclass(frozen=True)
class RosPlugin:
    """One plugin: its file, its ``name`` attribute, its child elements as (path, text) in order (a
    path ``ros/remapping`` is a ``<remapping>`` inside ``<ros>``), the canonical parameters it carries
    (not left out) and what it publishes (for the note)."""

    filename: str
    name: str
    elements: tuple[tuple[str, str], ...]
    consumed: frozenset[str]
    publishes: str


def ros_plugin(kind: DeviceKind, sensor: str, frame: str | None, params: dict[str, Any]) -> RosPlugin | None:
    """The plugin of a canonical sensor named ``sensor`` (None: none for this kind)."""
    frame_element = (("frame_name", frame),) if frame else ()
    name = f"{sensor}_ros"
    if kind is DeviceKind.LIDAR:
        vertical = params.get("vertical_samples")
        cloud = isinstance(vertical, int | float) and vertical > 1
        topic, message = (f"{sensor}/points", "sensor_msgs/PointCloud2") if cloud else (
            f"{sensor}/scan", "sensor_msgs/LaserScan")
        ray = (("ros/remapping", f"~/out:={topic}"), ("output_type", message), *frame_element)
        return RosPlugin(RAY, name, ray, frozenset(), f"{message} on {topic}")
    if kind in CAMERA_KINDS:
        elements: tuple[tuple[str, str], ...] = (("camera_name", sensor), *frame_element)
        consumed: set[str] = set()
        topics = [f"{sensor}/image_raw", f"{sensor}/camera_info"]
        if kind in DEPTH_KINDS:
            for key, element in (("range_min", "min_depth"), ("range_max", "max_depth")):
                value = params.get(key)
                if isinstance(value, int | float) and math.isfinite(value) and value > 0.0:
                    elements += ((element, fmt(value)),)
                    consumed.add(key)
            topics += [f"{sensor}/depth/image_raw", f"{sensor}/points"]
        return RosPlugin(CAMERA, name, elements, frozenset(consumed), ", ".join(topics))
    if kind in IMU_KINDS:
        topic = f"{sensor}/imu"
        imu = (("ros/remapping", f"~/out:={topic}"), ("initial_orientation_as_reference", "false"),
               *frame_element)
        return RosPlugin(IMU, name, imu, frozenset(), f"sensor_msgs/Imu on {topic}")
    return None
