"""What a writer can be asked to do differently (every option has the safe default); the values the
string options take are in :mod:`modelkit.convert.choices`."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class WriteOptions:
    sdf_version: str = "1.9"
    mesh_format: str = "stl"  # for meshes the writer generates or converts
    keep_collada: bool = False  # URDF/SDF: copy COLLADA files as they are instead of converting
    keep_package_uris: bool = False  # keep package:// and model:// references instead of copying
    merge_fixed: bool = False  # fuse links on fixed joints into their parents
    # URDF `world` link and the root's joint to it: None (default) for a welded root only; True for a
    # floating root too; False never (a consumer that welds the root itself: verify's engines)
    urdf_world_link: bool | None = None
    # URDF: rename a joint named like a link `<name>_joint` (libsdformat's URDF to SDF conversion
    # refuses the shared name, which URDF and ROS allow and the default keeps; MK846)
    urdf_distinct_names: bool = False
    # URDF: each camera, LiDAR and IMU a massless link on a fixed joint (a TF frame for ROS; cameras
    # with a REP-103 optical frame); False keeps the sensors on their links (MK847)
    urdf_sensor_links: bool = True
    # URDF <gazebo> blocks and SDF sensors: auto|classic|sim, the Gazebo whose sensor types and plugins
    # are written (auto: the source's; modelkit/convert/gazebo.py)
    gazebo: str = "auto"
    # Gazebo classic: a sensor the source gave no plugin gets the gazebo_ros plugin that publishes it to
    # ROS 2 (MK850; modelkit/formats/sdf/ros_plugins.py)
    ros_plugins: bool = True
    # URDF and SDF: Gazebo's differential-drive plugin for a robot on two sides of wheels that the source
    # gives no controller (MK858; modelkit/convert/drive_plugin.py)
    drive_plugin: bool = True
    wheel_collision: str = "auto"  # auto|cylinder|sphere|ellipsoid: the wheels' collision (convert.wheels)
    # URDF: compliant (PyBullet contact stiffness and damping on the links a wheeled robot stands on, when
    # they are more than three; MK861, modelkit/convert/contact_compliance.py) | rigid (PyBullet's own)
    support_contact: str = "compliant"
    base: str = "auto"  # fixed | floating | auto: how the root meets the world (modelkit/convert/base.py)
    # actuators for a source without any (MJCF): auto (default: a position servo on each joint with a
    # range or in a leg, a motor on each other) | motor | position | velocity | none; the source's own
    # actuators are written as they are unless ``source_actuators`` replaces them (docs/convert.md,
    # "Actuators")
    actuators: str = "auto"
    # MJCF: the source's own actuators: auto (default: written as they are, except ROS effort interfaces
    # on joints the ``actuators`` choice servos, MK864) | keep (all written as they are) | replace (set
    # aside, MK855: every joint gets the ``actuators`` choice, as for a source without any)
    source_actuators: str = "auto"
    # MJCF: massless frame links (modelkit/convert/frames.py) as <site>s in the body they hang on, as
    # MuJoCo Menagerie writes them (MK873); False writes them as empty bodies
    frame_sites: bool = True
