"""Sensors, lights and plugins of the SDF writer.

A device read from SDF keeps its own element (``params["config"]`` as data, plugins as text): it
is written back as it was. Any other device is written from its canonical kind and parameters
(:class:`~modelkit.model.DeviceKind`): the device frame is SDF's sensor frame (+X forward), so its
pose is written unchanged. Devices without a canonical kind are left out (MK806).
"""

from __future__ import annotations

import math
from typing import Any

from lxml.etree import _Element as Element

from modelkit.convert.context import WriteContext
from modelkit.convert.names import unique_name
from modelkit.convert.numbers import fmt, fmt_vec
from modelkit.formats.sdf.ros_plugins import RosPlugin, ros_plugin
from modelkit.formats.sdf.sensors import CONFIG_ELEMENT
from modelkit.formats.sdf.write_xml import (
    add_pose,
    child_or_sub,
    data_to_element,
    num,
    parse_fragment,
    rgba,
    sub,
)
from modelkit.model import CAMERA_KINDS, LIGHT_KINDS, Device, DeviceKind
from modelkit.spatial import Pose

CANONICAL_SENSOR = {
    DeviceKind.CAMERA: "camera",
    DeviceKind.DEPTH_CAMERA: "depth_camera",
    DeviceKind.RGBD_CAMERA: "rgbd_camera",
    DeviceKind.LIDAR: "gpu_lidar",
    DeviceKind.IMU: "imu",
    DeviceKind.ACCELEROMETER: "imu",
    DeviceKind.GYRO: "imu",
    DeviceKind.FORCE_TORQUE: "force_torque",
    DeviceKind.CONTACT: "contact",
}
IMAGE_FORMATS_19 = frozenset(
    {
        "L8",
        "L16",
        "R_FLOAT16",
        "R_FLOAT32",
        "R8G8B8",
        "B8G8R8",
        "BAYER_RGGB8",
        "BAYER_BGGR8",
        "BAYER_GBRG8",
        "BAYER_GRBG8",
    }
)
# Gazebo classic's names where they differ from Gazebo Sim's (modelkit/convert/gazebo.py).
CLASSIC_SENSOR = {
    DeviceKind.LIDAR: "ray",
    DeviceKind.DEPTH_CAMERA: "depth",
    DeviceKind.RGBD_CAMERA: "depth",
}
# The canonical parameters each sensor writes; any other is an MK849 note.
WRITTEN_PARAMS = {
    "camera": frozenset({"width", "height", "horizontal_fov", "near", "far", "noise_stddev", "format"}),
    "lidar": frozenset(
        {
            "horizontal_samples", "horizontal_min_angle", "horizontal_max_angle",
            "vertical_samples", "vertical_min_angle", "vertical_max_angle",
            "range_min", "range_max", "range_resolution", "noise_stddev",
        }
    ),
    "imu": frozenset(),
    "other": frozenset(),
}
# Limits already noted as MK807 by the IMU and force-torque code.
NOTED_PARAMS = frozenset({"max_force", "max_torque", "max_acceleration", "max_angular_velocity"})
LIGHT_TYPE = {
    DeviceKind.SPOT_LIGHT: "spot",
    DeviceKind.POINT_LIGHT: "point",
    DeviceKind.DIRECTIONAL_LIGHT: "directional",
}


def is_sdf_native(device: Device, source_format: str) -> bool:
    """Whether the device still holds the SDF element it was read from."""
    return source_format == "sdf" and (
        device.kind.startswith("light:")
        or "config" in device.params
        or device.kind in ("contact", "imu", "force_torque", "altimeter")
    )


class DeviceWriter:
    def __init__(
        self, ctx: WriteContext, version: tuple[int, int], source_format: str, gazebo: str = "sim"
    ) -> None:
        self.ctx = ctx
        self.version = version
        self.source_format = source_format
        self.gazebo = gazebo  # "classic" | "sim": sensor types and plugins (modelkit/convert/gazebo.py)

    def device(
        self, parent: Element, device: Device, pose: Pose, relative_to: str | None, owner: str,
        used: set[str], frame: str | None = None,
    ) -> None:
        """Write one device under ``parent`` (a link or a joint), or note why it is left out. ``frame``:
        the TF frame its data is stamped with, where the writer made one (URDF sensor frames)."""
        name = unique_name(device.name or device.kind, used)
        if is_sdf_native(device, self.source_format):
            if device.kind.startswith("light:"):
                self._light(
                    parent,
                    name,
                    device.kind.split(":", 1)[1],
                    _sdf_light_params(device.params),
                    pose,
                    relative_to,
                )
            else:
                self._native_sensor(parent, name, device, pose, relative_to, owner)
            return
        kind = device.canonical
        params = device.canonical_params
        target = f"{owner}/{'light' if kind in LIGHT_KINDS else 'sensor'}[{name}]"
        if kind in LIGHT_KINDS:
            self._light(parent, name, LIGHT_TYPE[kind], params, pose, relative_to)
            return
        if kind is DeviceKind.OTHER or kind not in CANONICAL_SENSOR:
            self.ctx.note(
                "MK806",
                f'device "{device.name}" ({device.kind}) has no SDF equivalent; it is left out',
                device.source,
                target,
            )
            return
        wanted = CLASSIC_SENSOR.get(kind) if self.gazebo == "classic" else None
        if wanted == "ray" and device.kind == "gpu_ray":
            wanted = "gpu_ray"
        sensor = sub(parent, "sensor", name=name, type=wanted or CANONICAL_SENSOR[kind])
        add_pose(sensor, pose, relative_to)
        sub(sensor, "always_on", "true")
        rate = params.get("update_rate")
        if isinstance(rate, int | float) and _finite(rate):
            num(sensor, "update_rate", float(rate))
        if kind in CAMERA_KINDS:
            self._camera(sensor, params)
        elif kind is DeviceKind.LIDAR:
            self._lidar(sensor, params)
        elif kind in (DeviceKind.IMU, DeviceKind.ACCELEROMETER, DeviceKind.GYRO):
            self._imu(sensor, kind, params, device, target)
        elif kind is DeviceKind.FORCE_TORQUE:
            ft = sub(sensor, "force_torque")
            sub(ft, "frame", "sensor")
            sub(ft, "measure_direction", "child_to_parent")
            limits = [k for k in ("max_force", "max_torque") if _any_finite(params.get(k))]
            if limits:
                self.ctx.note(
                    "MK807",
                    f'force sensor "{device.name}": {" and ".join(limits)} have no SDF field',
                    device.source,
                    target,
                )
        elif kind is DeviceKind.CONTACT:
            self.ctx.note(
                "MK807",
                f'contact sensor "{device.name}": SDF contact sensors name the collisions '
                "they watch; none is named, so it reports nothing until one is added",
                device.source,
                target,
            )
        generated = self._ros_plugin(device, kind, name, frame)
        self._unmapped(device, kind, params, target, generated.consumed if generated else frozenset())
        self._plugins(sensor, device, target)
        if generated is not None:
            self._write_ros_plugin(sensor, generated, device, target)

    def _unmapped(self, device: Device, kind: DeviceKind, params: dict[str, Any], target: str,
                  carried: frozenset[str] = frozenset()) -> None:
        """One MK849 note naming the canonical parameters the sensor has no element for (``carried``: those a
        generated plugin holds)."""
        group = "camera" if kind in CAMERA_KINDS else "lidar" if kind is DeviceKind.LIDAR else "other"
        if kind in (DeviceKind.IMU, DeviceKind.ACCELEROMETER, DeviceKind.GYRO):
            group = "imu"
        written = WRITTEN_PARAMS[group] | NOTED_PARAMS | {"update_rate"} | carried
        left = {k: v for k, v in sorted(params.items()) if k not in written}
        for axis in ("horizontal", "vertical"):  # the scan's resolution is written as 1
            if group == "lidar" and left.get(f"{axis}_resolution") == 1.0:
                del left[f"{axis}_resolution"]
        if left:
            self.ctx.note(
                "MK849",
                f'{kind.value} "{device.name}": an SDF sensor has no element for '
                + ", ".join(f"{k} {_value(v)}" for k, v in left.items())
                + "; left out",
                device.source,
                target,
            )

    def _plugins(self, sensor: Element, device: Device, target: str) -> None:
        """The source sensor's plugins of the Gazebo written for (or of neither); others an MK848 note."""
        from modelkit.convert.gazebo import plugin_family

        for plugin in device.params.get("plugins") or []:
            if not isinstance(plugin, dict):
                continue
            family = plugin_family(str(plugin.get("filename", "")))
            if family in (None, self.gazebo):
                self.plugin(sensor, plugin, target)
                continue
            self.ctx.note(
                "MK848",
                f'plugin "{plugin.get("name", "")}" ({plugin.get("filename", "")}) of sensor "{device.name}" '
                f"is Gazebo {family} code and this file is written for Gazebo {self.gazebo} "
                f"(--gazebo {family} keeps it); left out",
                device.source,
                target,
            )

    def _ros_plugin(self, device: Device, kind: DeviceKind, name: str, frame: str | None) -> RosPlugin | None:
        """The ``gazebo_ros`` plugin a Gazebo classic sensor gets when its source gave it none (and the
        ``ros_plugins`` option is on): :mod:`modelkit.formats.sdf.ros_plugins`."""
        if self.gazebo != "classic" or not self.ctx.options.ros_plugins or device.params.get("plugins"):
            return None
        return ros_plugin(kind, name, frame, device.canonical_params)

    def _write_ros_plugin(self, sensor: Element, plugin: RosPlugin, device: Device, target: str) -> None:
        element = sub(sensor, "plugin", name=plugin.name, filename=plugin.filename)
        for path, text in plugin.elements:
            holder = element
            *parents, leaf = path.split("/")
            for tag in parents:
                holder = child_or_sub(holder, tag)
            sub(holder, leaf, text)
        frame = dict(plugin.elements).get("frame_name")
        carried = f"; it carries {', '.join(sorted(plugin.consumed))}" if plugin.consumed else ""
        self.ctx.note(
            "MK850",
            f'sensor "{device.name}": a gazebo_ros plugin ({plugin.filename}) publishes {plugin.publishes} '
            f"to ROS 2 in Gazebo classic, stamped {frame or 'with its link'}{carried} (the source has no "
            "plugin; --no-ros-plugins leaves it out)",
            device.source,
            target,
        )

    # -- canonical sensors ---------------------------------------------------------------------

    def _camera(self, sensor: Element, p: dict[str, Any]) -> None:
        camera = sub(sensor, "camera")
        if _finite(p.get("horizontal_fov")):
            num(camera, "horizontal_fov", p["horizontal_fov"])
        image = sub(camera, "image")
        sub(image, "width", str(int(p.get("width") or 320)))
        sub(image, "height", str(int(p.get("height") or 240)))
        fmt_name = p.get("format")
        if isinstance(fmt_name, str) and fmt_name in IMAGE_FORMATS_19:
            sub(image, "format", fmt_name)
        clip = sub(camera, "clip")
        num(clip, "near", p["near"] if _finite(p.get("near")) else 0.1)
        num(clip, "far", p["far"] if _finite(p.get("far")) else 100.0)
        _noise(camera, p.get("noise_stddev"))

    def _lidar(self, sensor: Element, p: dict[str, Any]) -> None:
        # Gazebo classic reads <ray> only; <lidar> is the SDF ≥ 1.7 name Gazebo Sim reads
        lidar = sub(sensor, "lidar" if self.version >= (1, 7) and self.gazebo == "sim" else "ray")
        scan = sub(lidar, "scan")
        for axis, samples in (("horizontal", 640), ("vertical", 1)):
            if axis == "vertical" and not p.get("vertical_samples"):
                continue
            el = sub(scan, axis)
            sub(el, "samples", str(int(p.get(f"{axis}_samples") or samples)))
            num(el, "resolution", 1.0)
            num(el, "min_angle", p.get(f"{axis}_min_angle") or 0.0)
            num(el, "max_angle", p.get(f"{axis}_max_angle") or 0.0)
        rng = sub(lidar, "range")
        num(rng, "min", p.get("range_min") or 0.0)
        num(rng, "max", p.get("range_max") or 0.0)
        if _finite(p.get("range_resolution")):
            num(rng, "resolution", p["range_resolution"])
        _noise(lidar, p.get("noise_stddev"))

    def _imu(self, sensor: Element, kind: DeviceKind, p: dict[str, Any], device: Device, target: str) -> None:
        sub(sensor, "imu")
        limits = [k for k in ("max_acceleration", "max_angular_velocity") if _any_finite(p.get(k))]
        what = {DeviceKind.ACCELEROMETER: "an accelerometer", DeviceKind.GYRO: "a rate gyro"}.get(kind)
        if what or limits:
            detail = (
                f"{what} is written as an SDF imu (it also measures the other quantities)" if what else ""
            )
            if limits:
                detail += ("; " if detail else "") + f"{' and '.join(limits)} have no SDF field"
            self.ctx.note("MK807", f'device "{device.name}": {detail}', device.source, target)

    # -- lights --------------------------------------------------------------------------------

    def _light(
        self, parent: Element, name: str, kind: str, p: dict[str, Any], pose: Pose, relative_to: str | None
    ) -> None:
        light = sub(parent, "light", name=name, type=kind)
        add_pose(light, pose, relative_to)
        if "cast_shadows" in p:
            sub(light, "cast_shadows", "true" if p["cast_shadows"] else "false")
        if _finite(p.get("intensity")) and self.version >= (1, 7):
            num(light, "intensity", p["intensity"])
        color = p.get("color")
        if color is not None:
            sub(light, "diffuse", rgba(color))
        if p.get("specular") is not None:
            sub(light, "specular", rgba(p["specular"]))
        keys = ("range", "attenuation_constant", "attenuation_linear", "attenuation_quadratic")
        if any(_finite(p.get(k)) for k in keys):
            att = sub(light, "attenuation")
            num(att, "range", p["range"] if _finite(p.get("range")) else 10.0)
            for key in ("linear", "constant", "quadratic"):
                if _finite(p.get(f"attenuation_{key}")):
                    num(att, key, p[f"attenuation_{key}"])
        direction = p.get("direction")
        sub(light, "direction", fmt_vec(direction) if direction is not None else "0 0 -1")
        if kind == "spot":
            spot = sub(light, "spot")
            # SDF's angles are whole cone angles (OGRE's spotlight range); canonical ones are half-angles
            for key in ("inner_angle", "outer_angle"):
                num(spot, key, 2.0 * (p.get(f"spot_{key}") or 0.0))
            num(spot, "falloff", p.get("spot_falloff") or 0.0)

    # -- SDF devices as they were ----------------------------------------------------------------

    def _native_sensor(
        self, parent: Element, name: str, device: Device, pose: Pose, relative_to: str | None, owner: str
    ) -> None:
        p = device.params
        sensor = sub(parent, "sensor", name=name, type=device.kind)
        add_pose(sensor, pose, relative_to)
        for key in ("always_on", "visualize"):
            if key in p:
                sub(sensor, key, "true" if p[key] else "false")
        if _finite(p.get("update_rate")):
            num(sensor, "update_rate", p["update_rate"])
        if p.get("topic"):
            sub(sensor, "topic", str(p["topic"]))
        config = p.get("config")
        if isinstance(config, dict) and self.version <= (1, 9):
            config = self._image_format(config, device, f"{owner}/sensor[{name}]")
        if config is not None:
            data_to_element(sensor, CONFIG_ELEMENT.get(device.kind, device.kind), config)
        for plugin in p.get("plugins", []):
            self.plugin(sensor, plugin, f"{owner}/sensor[{name}]")

    def _image_format(self, config: dict[str, Any], device: Device, target: str) -> dict[str, Any]:
        """A camera image format SDFormat ≤ 1.9 lacks (libsdformat 12 refuses the file) becomes R8G8B8."""
        image = config.get("image")
        found = image.get("format") if isinstance(image, dict) else None
        if not isinstance(image, dict) or not isinstance(found, str) or found in IMAGE_FORMATS_19:
            return config
        self.ctx.note(
            "MK807",
            f'camera "{device.name}": image format {found} is not in SDFormat ≤ 1.9 '
            "(libsdformat 12 refuses it); written as R8G8B8",
            device.source,
            target,
        )
        return {**config, "image": {**image, "format": "R8G8B8"}}

    def plugin(self, parent: Element, plugin: dict[str, Any], target: str) -> None:
        element = parse_fragment(str(plugin.get("xml", "")))
        if element is None:
            self.ctx.note(
                "MK808",
                f'plugin "{plugin.get("name", "")}" cannot be copied on its own (its XML '
                "uses names declared elsewhere); it is left out",
                None,
                target,
            )
            return
        element.tail = None
        parent.append(element)


def _sdf_light_params(params: dict[str, Any]) -> dict[str, Any]:
    out = dict(params)
    if "diffuse" in params:
        out["color"] = params["diffuse"]
    return out


def _value(value: Any) -> str:
    if isinstance(value, list | tuple):
        return fmt_vec(value)
    return fmt(value) if isinstance(value, float) else str(value)


def _noise(parent: Element, stddev: Any) -> None:
    if _finite(stddev) and stddev > 0.0:
        noise = sub(parent, "noise")
        sub(noise, "type", "gaussian")
        num(noise, "mean", 0.0)
        num(noise, "stddev", stddev)


def _finite(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(float(value))


def _any_finite(value: Any) -> bool:
    if value is None:
        return False
    values = value if isinstance(value, list | tuple) else [value]
    return any(_finite(v) for v in values)
