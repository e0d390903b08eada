"""URDF writer, sensor frames: each sensor a link of its own on a fixed joint, as ROS describes sensors.

ROS tools know a sensor by its TF frame: ``robot_state_publisher`` publishes one per link, and a scan or a
point cloud names the frame it was taken in. So a device written as a Gazebo sensor (a camera, a LiDAR,
an IMU) gets a link named after the device, on a fixed joint ``<device>_joint`` at the device
pose (the canonical sensor frame: +X forward, +Y left, +Z up); its ``<gazebo reference>`` names that link
and the sensor's own ``<pose>`` is the identity. A camera also gets ``<device>_optical``, the REP-103
optical frame (+Z forward, +X right, +Y down: ``rpy="-π/2 0 -π/2"`` from the camera link), which image
consumers expect in ``header.frame_id``.

Left on their link: devices kept as the ``<gazebo>`` block they were read from (a URDF source has its
own frames), contact and force-torque sensors (Gazebo ties them to the link's collisions and joint),
and a device that already is its link's (a link named like the device: a URDF read back). A device
whose name a link or joint already has gets a fresh one (``_2``...). One MK847 note lists the frames;
``WriteOptions.urdf_sensor_links=False`` keeps every sensor on its link instead.

The frames carry the tiny explicit inertial of every massless link below the root
(:data:`~modelkit.formats.urdf.write_links.TINY_MASS`): PyBullet reads a link without ``<inertial>`` as
1 kg with a unit inertia, so massless frames made the tutorial's sensor robot 3 kg heavier there
(20.6 kg for 17.6 kg); a zero ``<inertial>`` is refused by libsdformat's URDF conversion ("Pose values
must be finite"). With 1e-6 kg each the robot is 3e-6 kg heavier in every consumer, and the URDF
reader reads that exact inertial on a fixed joint back as a massless frame.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from lxml import etree
from lxml.etree import _Element as Element

from modelkit.convert.context import WriteContext
from modelkit.formats.devices import OPTICAL_IN_ROBOTICS
from modelkit.formats.urdf.write_links import TINY_MASS, origin_element, tiny_inertial
from modelkit.formats.urdf.write_names import NameTable
from modelkit.model import CAMERA_KINDS, Device, DeviceKind, Robot
from modelkit.spatial import Pose

FRAMED_KINDS = frozenset(
    {*CAMERA_KINDS, DeviceKind.LIDAR, DeviceKind.IMU, DeviceKind.ACCELEROMETER, DeviceKind.GYRO}
)
OPTICAL_POSE = Pose(OPTICAL_IN_ROBOTICS, (0.0, 0.0, 0.0))


@dataclass
class SensorFrames:
    """Where each device's sensor is written: the link its ``<gazebo reference>`` names and the
    sensor's pose in it, by (link index, device index); the TF frame its data is stamped with (the
    sensor link, a camera's optical frame); and the links and joints to add."""

    where: dict[tuple[int, int], tuple[str, Pose]] = field(default_factory=dict)
    data_frames: dict[tuple[int, int], str] = field(default_factory=dict)
    links: list[str] = field(default_factory=list)
    joints: list[Element] = field(default_factory=list)

    def place(self, link_index: int, device_index: int, link_name: str, device: Device) -> tuple[str, Pose]:
        return self.where.get((link_index, device_index), (link_name, device.pose))


def sensor_frames(robot: Robot, names: NameTable, ctx: WriteContext) -> SensorFrames:
    """The sensor links and joints of ``robot`` (none with ``urdf_sensor_links`` off)."""
    out = SensorFrames()
    if not ctx.options.urdf_sensor_links:
        return out
    listed: list[str] = []
    for link_index, link in enumerate(robot.links):
        parent = names.links[link_index]
        for device_index, device in enumerate(link.devices):
            if (
                device.canonical not in FRAMED_KINDS
                or isinstance(device.params.get("xml"), str)
                or (device.name and device.name == link.name)
            ):
                continue
            wanted = device.name or device.canonical.value
            frame = names.fresh(wanted)
            out.links.append(frame)
            out.joints.append(_fixed(names.fresh(f"{frame}_joint"), parent, frame, device.pose))
            out.where[(link_index, device_index)] = (frame, Pose())
            out.data_frames[(link_index, device_index)] = frame
            text = f'"{frame}" on "{parent}"'
            if frame != wanted:
                text += f' (the name "{wanted}" is taken)'
            if device.canonical in CAMERA_KINDS:
                optical = names.fresh(f"{frame}_optical")
                out.links.append(optical)
                out.joints.append(_fixed(names.fresh(f"{optical}_joint"), frame, optical, OPTICAL_POSE))
                out.data_frames[(link_index, device_index)] = optical
                text += f' with its optical frame "{optical}"'
            listed.append(text)
    if listed:
        ctx.note(
            "MK847",
            f"{len(listed)} sensor(s) written as links on fixed joints (their TF frames for ROS; a tiny "
            f"inertial each, {TINY_MASS:g} kg, so that PyBullet does not give them 1 kg; "
            "their <gazebo reference> names them): " + ", ".join(listed) + "; cameras' optical frames are "
            "REP-103 (z forward, x right, y down; rpy -π/2 0 -π/2); option urdf_sensor_links "
            "(--no-urdf-sensor-links) keeps the sensors on their links",
            robot.source,
            "link",
        )
    return out


def frame_link(name: str) -> Element:
    """A sensor frame's ``<link>``, with the tiny explicit inertial of every massless link below the
    root (so that a read-back frame, now a link of the model, is written again byte for byte)."""
    element = etree.Element("link", name=name)
    tiny_inertial(element)
    return element


def _fixed(name: str, parent: str, child: str, pose: Pose) -> Element:
    el = etree.Element("joint", name=name, type="fixed")
    origin_element(el, pose, always=True)
    etree.SubElement(el, "parent", link=parent)
    etree.SubElement(el, "child", link=child)
    return el
