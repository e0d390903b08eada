"""The Gazebo plugin that drives a wheeled robot from a velocity command, where the source names none.

A ``.body`` file's robot is driven by a Choreonoid controller, an MJCF's by its actuators; converted
for Gazebo, its wheels would not turn at all. When the model has **two sides of wheels**
(:mod:`modelkit.convert.wheels` found them), the URDF and SDF writers add Gazebo's differential-drive
plugin, which turns a ``geometry_msgs/Twist`` (forward speed v, yaw rate ω) into wheel speeds
``(v ∓ ω s/2) / r``, the law the tutorial's controller uses:

* Gazebo Sim: the ``gz::sim::systems::DiffDrive`` system (``gz-sim-diff-drive-system``): every left and
  right wheel joint, ``wheel_separation`` s, ``wheel_radius`` r; commands on
  ``/model/<model>/cmd_vel``, odometry on ``/model/<model>/odometry`` (bridged to ROS 2 with
  ``ros_gz_bridge``);
* Gazebo classic: ``gazebo_ros``'s ``libgazebo_ros_diff_drive.so`` (ROS 2): ``num_wheel_pairs`` when more
  than one, the joints in pairs front to back, ``wheel_separation``, ``wheel_diameter`` 2r,
  ``max_wheel_torque`` the wheels' effort limit where the source gives one (the plugin's default, 5 N·m,
  otherwise), odometry and its TF from ``odom`` to the root link; commands on ``cmd_vel``.

Which robots: wheels whose axes lie along the root's Y at q = 0, as many at +Y (left) as at −Y
(right), one radius, each axis pointing to +Y (a positive turn rolls the robot towards +X: both
plugins command one sign for all wheels). None where the wheels carry the model's own actuators (the
writers turn those into joint controllers) or the output keeps a drive plugin the source names (an
SDF model plugin, a URDF ``<gazebo>`` block where the target holds it).
``--no-drive-plugin`` leaves it out. MK858 says what was written, MK859 why a robot with wheels got none.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from lxml import etree

from modelkit.convert.gazebo import plugin_family
from modelkit.convert.notes import NoteSink
from modelkit.convert.numbers import fmt
from modelkit.convert.wheels import WHEELS_KEY
from modelkit.diagnostics import SourceLocation
from modelkit.model import Cylinder, Ellipsoid, Link, Robot, Sphere

PARALLEL = 1e-6  # |1 − |cos|| below this: an axis lies along the root's Y
SAME = 1e-9  # relative: two radii are one
DRIVE_WORDS = ("diff_drive", "diff-drive", "diffdrive", "skid_steer", "skid-steer", "skidsteer",
               "tracked_vehicle", "tracked-vehicle", "trackedvehicle", "planar_move", "ackermann")
SIM_FILE, SIM_NAME = "gz-sim-diff-drive-system", "gz::sim::systems::DiffDrive"
CLASSIC_FILE, CLASSIC_NAME = "libgazebo_ros_diff_drive.so", "diff_drive"


@dataclass(frozen=True)
class DiffDrive:
    """The wheels a plugin drives (source joint names, front to back), their spacing and radius."""

    left: tuple[str, ...]
    right: tuple[str, ...]
    separation: float
    radius: float
    effort: float  # the smallest finite effort limit of the wheels (inf: none given)
    base: str  # the root link (source name)


def find_drive(robot: Robot, target: str, family: str) -> tuple[DiffDrive | None, str]:
    """The model's differential drive for a ``target`` (``urdf``/``sdf``) written for Gazebo
    ``family``, or None and why (an empty why: the model has no wheels)."""
    wheels = robot.extras.get(WHEELS_KEY)
    if not isinstance(wheels, dict) or not wheels or robot.root is None:
        return None, ""
    if _kept_source_drive(robot, target, family):
        return None, "the source names its own drive plugin, which is kept"
    joints = {j.name: j for j in robot.joints}
    actuated = sorted(a.joint for a in robot.actuators if a.joint in wheels.values())
    if actuated:
        return None, (f"the wheels have the source's actuators ({', '.join(actuated)}), written as joint "
                      "controllers")
    links = {link.name: link for link in robot.links}
    poses = robot.world_poses()
    root_inv = poses[robot.root].inverse()
    sides: dict[str, list[tuple[float, str, float]]] = {"left": [], "right": []}  # (x, joint, y) in the base
    radii: list[float] = []
    for link_name, joint_name in sorted(wheels.items()):
        joint, link = joints.get(joint_name), links.get(link_name)
        if joint is None or link is None or link_name not in poses:
            continue
        frame = root_inv @ poses[link_name]
        axis = np.asarray(joint.axis, dtype=float)
        axis = frame.rotation @ (axis / float(np.linalg.norm(axis)))
        if abs(1.0 - abs(float(axis[1]))) > PARALLEL:
            return None, (f"wheel joint {joint_name}'s axis does not lie along the base's Y axis (steered "
                          "wheels?)")
        if float(axis[1]) < 0.0:
            return None, (f"wheel joint {joint_name}'s axis points to the base's −Y: a positive speed turns "
                          "it backwards, and the plugin commands one sign for all wheels")
        shape = _round_shape(link)
        if shape is None:
            return None, f"wheel {link_name} has no round collision shape"
        radius, centre = shape
        centre = frame.rotation @ centre + frame.translation
        sides["left" if centre[1] > 0.0 else "right"].append((float(centre[0]), joint_name, float(centre[1])))
        radii.append(radius)
    left, right = sides["left"], sides["right"]
    if not left or len(left) != len(right):
        return None, f"{len(left)} wheel(s) at the base's left and {len(right)} at its right, not pairs"
    if max(radii) - min(radii) > SAME * max(radii):
        return None, f"the wheels' radii differ ({', '.join(f'{r:g}' for r in sorted(set(radii)))} m)"
    left.sort(key=lambda item: -item[0])  # front to back
    right.sort(key=lambda item: -item[0])
    separation = float(np.mean([item[2] for item in left]) - np.mean([item[2] for item in right]))
    efforts = [joints[name].limits.effort for _, name, _ in left + right]
    finite = [e for e in efforts if math.isfinite(e) and e > 0.0]
    return DiffDrive(
        left=tuple(name for _, name, _ in left),
        right=tuple(name for _, name, _ in right),
        separation=separation,
        radius=radii[0],
        effort=min(finite) if finite else math.inf,
        base=robot.root,
    ), ""


def _round_shape(link: Link) -> tuple[float, np.ndarray] | None:
    """(radius, centre in the link frame) of the link's largest round collision shape."""
    best: tuple[float, np.ndarray] | None = None
    for geom in link.collisions:
        g = geom.geometry
        if isinstance(g, Cylinder | Sphere):
            radius = float(g.radius)
        elif isinstance(g, Ellipsoid):
            radius = float(g.radii[0])
        else:
            continue
        if best is None or radius > best[0]:
            best = (radius, np.asarray(geom.pose.translation, dtype=float))
    return best


def _kept_source_drive(robot: Robot, target: str, family: str) -> bool:
    """Whether the output keeps a drive plugin of the source's own: an SDF model plugin (the SDF writer
    copies an SDF source's; the URDF writer those of ``family`` or of none), a URDF robot-level
    ``<gazebo>`` block (the URDF writer keeps them; the SDF writer copies their plugins of ``family`` or
    of none)."""
    texts: list[str] = []
    for entry in robot.extras.get("sdf_plugins") or []:
        if not isinstance(entry, dict):
            continue
        filename = str(entry.get("filename", ""))
        kept = robot.source_format == "sdf" if target == "sdf" else plugin_family(filename) in (None, family)
        if kept:
            texts += [filename, str(entry.get("name", ""))]
    for entry in robot.extras.get("gazebo") or []:
        if not isinstance(entry, dict) or entry.get("reference"):
            continue
        if target == "urdf":  # the URDF writer keeps every robot-level block
            texts.append(str(entry.get("xml", "")))
        else:  # the SDF writer copies their plugins of the family written for (write_gazebo_tags)
            texts += [f'{p.get("filename", "")} {p.get("name", "")}' for p in _block_plugins(entry)
                      if plugin_family(p.get("filename", "")) in (None, family)]
    lowered = " ".join(texts).lower()
    return any(word in lowered for word in DRIVE_WORDS)


def _block_plugins(entry: dict[str, Any]) -> list[Any]:
    """The ``<plugin>`` children of a kept robot-level ``<gazebo>`` block."""
    try:
        block = etree.fromstring(str(entry.get("xml", "")))
    except etree.XMLSyntaxError:
        return []
    return [child for child in block if child.tag == "plugin"]


def plugin_elements(drive: DiffDrive, family: str, joint: dict[str, str], base: str
                    ) -> tuple[str, str, list[tuple[str, str]]]:
    """(filename, name, children as (tag, text) in order) of the plugin for Gazebo ``family``;
    ``joint`` maps source joint names to written ones, ``base`` is the written root link."""
    if family == "classic":
        children: list[tuple[str, str]] = []
        if len(drive.left) > 1:
            children.append(("num_wheel_pairs", str(len(drive.left))))
        for left, right in zip(drive.left, drive.right, strict=True):
            children += [("left_joint", joint.get(left, left)), ("right_joint", joint.get(right, right))]
        children += [("wheel_separation", fmt(drive.separation)), ("wheel_diameter", fmt(2.0 * drive.radius))]
        if math.isfinite(drive.effort):
            children.append(("max_wheel_torque", fmt(drive.effort)))
        children += [("publish_odom", "true"), ("publish_odom_tf", "true"), ("publish_wheel_tf", "false"),
                     ("odometry_frame", "odom"), ("robot_base_frame", base)]
        return CLASSIC_FILE, CLASSIC_NAME, children
    children = [("left_joint", joint.get(name, name)) for name in drive.left]
    children += [("right_joint", joint.get(name, name)) for name in drive.right]
    children += [("wheel_separation", fmt(drive.separation)), ("wheel_radius", fmt(drive.radius))]
    return SIM_FILE, SIM_NAME, children


def planned_drive(robot: Robot, target: str, family: str, model: str, notes: NoteSink) -> DiffDrive | None:
    """The drive a ``target`` writer (``urdf``/``sdf``) writes for Gazebo ``family`` into the model named
    ``model``, said (MK858), or None, with MK859 when the robot has wheels."""
    drive, why = find_drive(robot, target, family)
    _say(drive, why, family, model, notes, robot.source)
    return drive


def _say(drive: DiffDrive | None, why: str, family: str, model: str, notes: NoteSink,
         where: SourceLocation | None) -> None:
    """MK858 (written: which plugin, wheels, numbers, topics) or MK859 (wheels, but no plugin: why)."""
    if drive is None:
        if why:
            notes.note("MK859", f"no Gazebo drive plugin written: {why}", where, "gazebo")
        return
    if family == "classic":
        what = (f"gazebo_ros's differential drive ({CLASSIC_FILE}, Gazebo classic with ROS 2): commands on "
                "cmd_vel (geometry_msgs/Twist), odometry on odom and its TF from odom")
    else:
        what = (f"Gazebo Sim's DiffDrive system ({SIM_FILE}): commands on /model/{model}/cmd_vel "
                f"(gz.msgs.Twist), odometry on /model/{model}/odometry")
    notes.note(
        "MK858",
        f"wheels driven by {what}: left {', '.join(drive.left)}, right {', '.join(drive.right)}, "
        f"wheel separation {fmt(drive.separation)} m, radius {fmt(drive.radius)} m (--no-drive-plugin "
        "leaves it out)",
        where,
        "gazebo",
    )
