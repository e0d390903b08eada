"""Which Gazebo a URDF's ``<gazebo>`` blocks or an SDF's sensors are written for: classic or Sim.

The two read the same SDF but name sensors and plugins differently: Gazebo classic (11, with the
``gazebo_ros`` plugins of ROS 1 and ROS 2 Foxy/Humble) knows a LiDAR as ``ray`` / ``gpu_ray`` and an
RGB-D camera as ``depth``, and loads ``libgazebo_ros_*.so`` plugins; Gazebo Sim (gz-sim, Ignition)
knows ``gpu_lidar`` and ``rgbd_camera`` and loads ``gz-sim-*-system`` / ``ignition-gazebo-*`` systems.
A plugin of one family does nothing in the other.

``WriteOptions.gazebo``: ``classic``, ``sim``, or ``auto`` (default): what the source used (its sensor
types and plugin files), Sim when it says nothing (a ``.body`` or MJCF file).
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

from modelkit.convert.choices import GAZEBO_CHOICES
from modelkit.model import Robot

__all__ = ["GAZEBO_CHOICES", "gazebo_family", "plugin_family", "source_family"]
CLASSIC_SENSOR_TYPES = frozenset({"ray", "gpu_ray", "depth", "multicamera", "wideanglecamera"})
SIM_SENSOR_TYPES = frozenset(
    {"gpu_lidar", "lidar", "rgbd_camera", "rgbd", "depth_camera", "wide_angle_camera", "boundingbox_camera"}
)


def plugin_family(filename: str) -> str | None:
    """``classic``, ``sim`` or None (a plugin that names neither: kept whatever the target)."""
    name = filename.strip().lower()
    if "gz-sim" in name or "ignition-gazebo" in name or name.startswith(("gz::sim", "ignition::gazebo")):
        return "sim"
    if "gazebo_ros" in name or name.startswith("libgazebo") or "gazebo_plugins" in name:
        return "classic"
    if "gazebo" in name and name.endswith(".so"):  # libroboticsgroup_gazebo_mimic_joint_plugin.so...
        return "classic"
    return None


def _plugins(robot: Robot) -> Iterable[dict[str, Any]]:
    for entry in robot.extras.get("sdf_plugins") or []:
        if isinstance(entry, dict):
            yield entry
    for link in robot.links:
        for device in link.devices:
            for entry in device.params.get("plugins") or []:
                if isinstance(entry, dict):
                    yield entry


def source_family(robot: Robot) -> str | None:
    """The Gazebo the source was written for, from its sensor types and plugins (None: no sign)."""
    votes = {"classic": 0, "sim": 0}
    for link in robot.links:
        for device in link.devices:
            if device.kind in CLASSIC_SENSOR_TYPES:
                votes["classic"] += 1
            elif device.kind in SIM_SENSOR_TYPES:
                votes["sim"] += 1
    for plugin in _plugins(robot):
        family = plugin_family(str(plugin.get("filename", "")))
        if family is not None:
            votes[family] += 1
    if votes["classic"] == votes["sim"]:
        return None
    return "classic" if votes["classic"] > votes["sim"] else "sim"


def gazebo_family(robot: Robot, option: str) -> str:
    """The family to write for: the option's, or with ``auto`` the source's (Sim when it has none)."""
    if option in ("classic", "sim"):
        return option
    return source_family(robot) or "sim"
