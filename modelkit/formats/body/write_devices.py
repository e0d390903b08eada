"""Devices as `.body` device elements (body-format.md §3.7).

Two routes:

* A device read from a `.body` file (``kind`` is a Choreonoid device type) is written back from its
  ``kind`` and ``params`` — every typed parameter the reader knows (:data:`DEVICE_PARAMS`), angles
  back in degrees, plus the raw keys it kept under ``info`` — so `.body → .body` keeps it exactly.
* Any other device is mapped from ``canonical`` / ``canonical_params`` (:class:`DeviceKind`).

Poses: the model's device pose of a camera or range sensor is its sensor frame, robotics style
(+X forward, +Z up). Choreonoid's ``optical_frame: robotics`` means exactly that frame, so those
devices are written with it and no optical rotation is needed. A `.body` device whose reader gave
no canonical kind (an older reader: pose = the node's own frame) keeps its ``optical_frame``.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from modelkit.convert.context import WriteContext
from modelkit.convert.numbers import clean_angle
from modelkit.formats.body.devices import CORE_DEVICES, DEVICE_PARAMS, PLUGIN_DEVICES
from modelkit.formats.body.write_yaml import Flow, axis_angle_of, deg, num, nums, put_pose
from modelkit.model import CAMERA_KINDS, Device, DeviceKind

OPTICAL_KINDS = frozenset({"Camera", "CameraDevice", "RangeSensor"})
CAMERA_FORMAT = {
    DeviceKind.CAMERA: "COLOR",
    DeviceKind.DEPTH_CAMERA: "DEPTH",
    DeviceKind.RGBD_CAMERA: "COLOR_DEPTH",
}
SIMPLE_SENSORS = {
    DeviceKind.IMU: ("IMU", ("max_angular_velocity", "max_acceleration")),
    DeviceKind.ACCELEROMETER: ("AccelerationSensor", ("max_acceleration",)),
    DeviceKind.GYRO: ("RateGyroSensor", ("max_angular_velocity",)),
    DeviceKind.FORCE_TORQUE: ("ForceSensor", ("max_force", "max_torque")),
}
MERGE_KEY = "<<"


def device_node(device: Device, from_body: bool, ctx: WriteContext, target: str) -> dict[str, Any] | None:
    """The element of one device, or None (MK806 note) when Choreonoid has nothing for it."""
    if from_body and (device.kind in CORE_DEVICES or device.kind in PLUGIN_DEVICES):
        return _native(device)
    return _canonical(device, ctx, target)


def _has_canonical(device: Device) -> bool:
    return device.canonical is not DeviceKind.OTHER or bool(device.canonical_params)


def _head(kind: str, device: Device) -> dict[str, Any]:
    node: dict[str, Any] = {"type": kind}
    if device.name:
        node["name"] = device.name
    device_id = device.params.get("id")
    if isinstance(device_id, int):
        node["id"] = num(device_id)
    put_pose(node, device.pose.rotation, device.pose.translation)
    return node


def _value(kind_of: str, value: Any) -> Any:
    if kind_of == "angle":
        return deg(float(value))
    if kind_of in ("number", "int"):
        return num(float(value))
    if kind_of == "bool":
        return bool(value)
    if kind_of == "text":
        return str(value)
    if kind_of == "vec3":
        return nums([float(x) for x in value])
    found = axis_angle_of(np.asarray(value, dtype=float))  # angle_rotation
    if found is None:
        return Flow([num(0.0), num(0.0), num(1.0), num(0.0)])
    axis, angle = found
    return Flow([*nums(axis, tidy=True), deg(clean_angle(angle))])


def _differs(value: Any, default: Any) -> bool:
    if default is None:
        return value is not None
    if isinstance(default, tuple):
        return tuple(float(x) for x in value) != tuple(float(x) for x in default)
    if isinstance(value, np.ndarray):
        return True
    return bool(value != default)


def _native(device: Device) -> dict[str, Any]:
    node = _head(device.kind, device)
    params = dict(device.params)
    robotics = device.kind in OPTICAL_KINDS and _has_canonical(device)
    if robotics:
        params["optical_frame"] = "robotics"
        params["optical_frame_rotation"] = None
    for key, _spellings, kind_of, default in DEVICE_PARAMS.get(device.kind, ()):
        value = params.get(key)
        if value is None or (key != "format" and not _differs(value, default)):
            continue
        if kind_of in ("number", "angle") and not _finite(value):
            continue
        node[key] = _value(kind_of, value)
    if device.kind == "RangeSensor":
        _range_angles(node, params)
    info = params.get("info")
    if isinstance(info, dict):
        for key, value in info.items():
            if key != MERGE_KEY and key not in node:
                node[key] = value
    return node


def _finite(value: Any) -> bool:
    return all(math.isfinite(float(x)) for x in np.asarray(value, dtype=float).ravel())


def _range_angles(node: dict[str, Any], params: dict[str, Any]) -> None:
    """Yaw and pitch coverage as explicit min/max angles and steps (the sample counts follow)."""
    for axis in ("yaw", "pitch"):
        lo, hi = params.get(f"min_{axis}_angle"), params.get(f"max_{axis}_angle")
        step = params.get(f"{axis}_step")
        if lo is None or hi is None:
            continue
        if axis == "pitch" and lo == 0.0 and hi == 0.0 and not step:
            continue
        node[f"min_{axis}_angle"] = deg(lo)
        node[f"max_{axis}_angle"] = deg(hi)
        if step is not None:
            node[f"{axis}_step"] = deg(step)


def _canonical(device: Device, ctx: WriteContext, target: str) -> dict[str, Any] | None:
    kind, p = device.canonical, device.canonical_params
    if kind in CAMERA_KINDS:
        return _camera(device, kind, p)
    if kind is DeviceKind.LIDAR:
        return _lidar(device, p)
    if kind in SIMPLE_SENSORS:
        type_name, keys = SIMPLE_SENSORS[kind]
        node = _head(type_name, device)
        for key in keys:
            if p.get(key) is not None and _finite(p[key]):
                node[key] = nums(p[key])
        return node
    if kind in (DeviceKind.SPOT_LIGHT, DeviceKind.POINT_LIGHT):
        return _light(device, kind, p)
    what = device.kind if kind is DeviceKind.OTHER else kind.value
    ctx.note("MK806", f'{what} "{device.name}": Choreonoid has no such device', device.source, target)
    return None


def _put(node: dict[str, Any], key: str, value: Any, convert: Any = num) -> None:
    if value is not None and _finite(value):
        node[key] = convert(value)


def _camera(device: Device, kind: DeviceKind, p: dict[str, Any]) -> dict[str, Any]:
    node = _head("Camera", device)
    node["format"] = CAMERA_FORMAT[kind]
    node["optical_frame"] = "robotics"
    width, height = p.get("width"), p.get("height")
    if width is not None:
        node["width"] = num(int(width))
    if height is not None:
        node["height"] = num(int(height))
    hfov = p.get("horizontal_fov")
    if hfov is not None:
        # Choreonoid's field_of_view is that of the shorter image side (§3.7).
        w, h = int(width or 640), int(height or 480)
        fov = 2.0 * math.atan(math.tan(hfov / 2.0) * h / w) if w >= h else float(hfov)
        node["field_of_view"] = deg(fov)
    _put(node, "near_clip_distance", p.get("near"))
    _put(node, "far_clip_distance", p.get("far"))
    _put(node, "frame_rate", p.get("update_rate"))
    if kind is not DeviceKind.CAMERA:  # a RangeCamera: its depth range and noise
        _put(node, "min_distance", p.get("range_min"))
        _put(node, "max_distance", p.get("range_max"))
        _put(node, "detection_rate", p.get("detection_rate"))
        _put(node, "error_deviation", p.get("noise_stddev"))
    return node


def _lidar(device: Device, p: dict[str, Any]) -> dict[str, Any]:
    node = _head("RangeSensor", device)
    node["optical_frame"] = "robotics"
    for axis, prefix, default_samples in (("yaw", "horizontal", 1), ("pitch", "vertical", 1)):
        lo, hi = p.get(f"{prefix}_min_angle"), p.get(f"{prefix}_max_angle")
        samples = int(p.get(f"{prefix}_samples") or default_samples)
        if lo is None or hi is None:
            if axis == "pitch":
                continue
            lo, hi = lo or 0.0, hi or 0.0
        if axis == "pitch" and samples <= 1 and lo == hi == 0.0:
            continue
        node[f"min_{axis}_angle"] = deg(lo)
        node[f"max_{axis}_angle"] = deg(hi)
        node[f"{axis}_step"] = deg((hi - lo) / (samples - 1)) if samples > 1 else num(0.0)
    _put(node, "min_distance", p.get("range_min"))
    _put(node, "max_distance", p.get("range_max"))
    _put(node, "scan_rate", p.get("update_rate"))
    _put(node, "detection_rate", p.get("detection_rate"))
    _put(node, "error_deviation", p.get("noise_stddev"))
    return node


def _light(device: Device, kind: DeviceKind, p: dict[str, Any]) -> dict[str, Any]:
    node = _head("SpotLight" if kind is DeviceKind.SPOT_LIGHT else "PointLight", device)
    if p.get("on") is not None:
        node["on"] = bool(p["on"])
    _put(node, "color", p.get("color"), nums)
    _put(node, "intensity", p.get("intensity"))
    attenuation = [p.get(f"attenuation_{k}") for k in ("constant", "linear", "quadratic")]
    if any(a is not None for a in attenuation):
        defaults = (1.0, 0.0, 0.0)  # Choreonoid's
        node["attenuation"] = nums([d if a is None else a
                                    for a, d in zip(attenuation, defaults, strict=True)])
    if kind is DeviceKind.SPOT_LIGHT:
        _put(node, "direction", p.get("direction"), nums)
        # VRML/Choreonoid beam_width and cut_off_angle are half-angles from the axis, as the model's.
        _put(node, "beam_width", p.get("spot_inner_angle"), deg)
        _put(node, "cut_off_angle", p.get("spot_outer_angle"), deg)
        _put(node, "cut_off_exponent", p.get("spot_falloff"))
    return node
