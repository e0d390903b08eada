"""Device mapping shared by several readers: frame conversions and SDF-style sensor/light XML.

Every reader maps its devices to :class:`~modelkit.model.DeviceKind` and the canonical parameter
names at its boundary. What more than one reader needs lives here:

* the rotation between an OpenGL-style camera frame (looking along −Z, +Y up, +X right: Choreonoid's
  default "gl" optical frame and MuJoCo's camera frame) and the canonical robotics sensor frame
  (+X forward, +Y left, +Z up);
* the horizontal field of view from a vertical one and the image size;
* the reading of an SDFormat ``<sensor>`` / ``<light>`` element (SDF files and URDF ``<gazebo>``
  blocks hold the same XML; one function, two callers). SDF's sensor frame already is the
  canonical frame, so no pose change is needed.
"""

from __future__ import annotations

import math
from typing import Any

from lxml import etree
from lxml.etree import _Element as Element

from modelkit import rot3
from modelkit.model import DeviceKind
from modelkit.xmlsource import parse_number, parse_numbers

# The canonical (robotics) sensor frame's axes seen from a GL camera frame: columns are the GL
# camera's X (right), Y (up), Z (backwards) written in the robotics frame. Choreonoid calls this
# R_opt of ``optical_frame: robotics`` (body-format.md §3.7).
GL_IN_ROBOTICS: rot3.M3 = ((0.0, 0.0, -1.0), (-1.0, 0.0, 0.0), (0.0, 1.0, 0.0))


# The REP-103 optical frame (ROS ``*_optical_frame``; Choreonoid's ``optical_frame: cv``): +Z forward,
# +X right, +Y down. Columns are its axes written in the canonical sensor frame; as URDF roll-pitch-yaw
# this is (-π/2, 0, -π/2), the rotation ROS camera descriptions give their optical frame.
OPTICAL_IN_ROBOTICS: rot3.M3 = ((0.0, 0.0, 1.0), (-1.0, 0.0, 0.0), (0.0, -1.0, 0.0))


def canonical_from_gl(gl_rotation: Any) -> rot3.M3:
    """The canonical sensor frame's rotation, given the rotation of a GL-style camera frame.

    ``T_gl = T_canonical · GL_IN_ROBOTICS``, so ``T_canonical = T_gl · GL_IN_ROBOTICSᵀ``.
    """
    return rot3.matmul(rot3.mat3(gl_rotation), rot3.transpose(GL_IN_ROBOTICS))


def horizontal_fov(vertical_fov: float, width: float, height: float) -> float:
    """The horizontal field of view of a pinhole image whose vertical one is ``vertical_fov``."""
    return 2.0 * math.atan(math.tan(vertical_fov / 2.0) * width / height)


# ---- SDF-style XML ---------------------------------------------------------------------------

SDF_CAMERA_KINDS = {
    "camera": DeviceKind.CAMERA,
    "wideanglecamera": DeviceKind.CAMERA,
    "wide_angle_camera": DeviceKind.CAMERA,
    "depth_camera": DeviceKind.DEPTH_CAMERA,
    "depth": DeviceKind.DEPTH_CAMERA,
    "rgbd_camera": DeviceKind.RGBD_CAMERA,
    "rgbd": DeviceKind.RGBD_CAMERA,
}
SDF_LIDAR_TYPES = frozenset({"ray", "gpu_ray", "lidar", "gpu_lidar"})
SDF_SIMPLE_KINDS = {
    "imu": DeviceKind.IMU,
    "force_torque": DeviceKind.FORCE_TORQUE,
    "contact": DeviceKind.CONTACT,
}
SDF_LIGHT_KINDS = {
    "spot": DeviceKind.SPOT_LIGHT,
    "point": DeviceKind.POINT_LIGHT,
    "directional": DeviceKind.DIRECTIONAL_LIGHT,
}


def _tag(el: Element) -> str:
    return etree.QName(el).localname if isinstance(el.tag, str) else ""


def _child(el: Element | None, tag: str) -> Element | None:
    if el is None:
        return None
    for c in el:
        if _tag(c) == tag:
            return c
    return None


def _path(el: Element | None, *tags: str) -> Element | None:
    for tag in tags:
        el = _child(el, tag)
    return el


def _number(el: Element | None) -> float | None:
    if el is None or el.text is None:
        return None
    value = parse_number(el.text.strip())
    return value if value is not None and math.isfinite(value) else None


def _number_or(el: Element | None, default: float) -> float:
    value = _number(el)
    return default if value is None else value


def _put(out: dict[str, Any], key: str, value: Any) -> None:
    if value is not None:
        out[key] = value


def _noise_stddev(owner: Element | None) -> float | None:
    """``<noise><stddev>`` of an element (a Gaussian noise model's standard deviation)."""
    return _number(_path(owner, "noise", "stddev"))


def sdf_sensor_canonical(sensor: Element) -> tuple[DeviceKind, dict[str, Any]]:
    """The canonical kind and parameters of an SDFormat ``<sensor type=...>`` element.

    SDF defaults are filled where SDFormat defines the device by them (image 320×240, 60° field
    of view, ...); values SDF leaves open (noise, update rate when absent) stay absent.
    """
    sensor_type = (sensor.get("type") or "").strip()
    params: dict[str, Any] = {}
    _put(params, "update_rate", _number(_child(sensor, "update_rate")))
    if sensor_type in SDF_CAMERA_KINDS:
        params.update(_camera(_child(sensor, "camera")))
        return SDF_CAMERA_KINDS[sensor_type], params
    if sensor_type in SDF_LIDAR_TYPES:
        # <lidar> (SDF ≥ 1.7 name) and <ray> configure both kinds of scanner; take either.
        first, second = ("lidar", "ray") if sensor_type in ("lidar", "gpu_lidar") else ("ray", "lidar")
        config = _child(sensor, first)
        params.update(_lidar(config if config is not None else _child(sensor, second)))
        return DeviceKind.LIDAR, params
    if sensor_type == "imu":
        params.update(_imu(_child(sensor, "imu")))
    elif sensor_type == "force_torque":
        ft = _child(sensor, "force_torque")
        for key in ("frame", "measure_direction"):
            el = _child(ft, key)
            if el is not None and el.text and el.text.strip():
                params[key] = el.text.strip()
    elif sensor_type == "contact":
        collision = _path(sensor, "contact", "collision")
        if collision is not None and collision.text and collision.text.strip():
            params["collision"] = collision.text.strip()
    return SDF_SIMPLE_KINDS.get(sensor_type, DeviceKind.OTHER), params


def _camera(camera: Element | None) -> dict[str, Any]:
    image = _child(camera, "image")
    clip = _child(camera, "clip")
    out: dict[str, Any] = {
        "width": int(_number_or(_child(image, "width"), 320)),
        "height": int(_number_or(_child(image, "height"), 240)),
        "horizontal_fov": _number_or(_child(camera, "horizontal_fov"), 1.047),
        "near": _number_or(_child(clip, "near"), 0.1),
        "far": _number_or(_child(clip, "far"), 100.0),
    }
    _put(out, "noise_stddev", _noise_stddev(camera))
    fmt = _child(image, "format")
    if fmt is not None and fmt.text and fmt.text.strip():
        out["format"] = fmt.text.strip()
    return out


def _lidar(config: Element | None) -> dict[str, Any]:
    scan = _child(config, "scan")
    out: dict[str, Any] = {}
    for axis, default_samples in (("horizontal", 640), ("vertical", 1)):
        el = _child(scan, axis)
        samples = _number(_child(el, "samples"))
        out[f"{axis}_samples"] = int(samples) if samples is not None else default_samples
        out[f"{axis}_min_angle"] = _number_or(_child(el, "min_angle"), 0.0)
        out[f"{axis}_max_angle"] = _number_or(_child(el, "max_angle"), 0.0)
        _put(out, f"{axis}_resolution", _number(_child(el, "resolution")))
    rng = _child(config, "range")
    out["range_min"] = _number_or(_child(rng, "min"), 0.0)
    out["range_max"] = _number_or(_child(rng, "max"), 0.0)
    _put(out, "range_resolution", _number(_child(rng, "resolution")))
    _put(out, "noise_stddev", _noise_stddev(config))
    return out


def _imu(imu: Element | None) -> dict[str, Any]:
    """The IMU's noise when every axis of both quantities has the same standard deviation."""
    stddevs = {
        _noise_stddev(_path(imu, quantity, axis))
        for quantity in ("angular_velocity", "linear_acceleration")
        for axis in ("x", "y", "z")
    }
    if len(stddevs) == 1:
        (value,) = stddevs
        if value is not None:
            return {"noise_stddev": value}
    return {}


def sdf_light_canonical(light: Element) -> tuple[DeviceKind, dict[str, Any]]:
    """The canonical kind and parameters of an SDFormat ``<light type=...>`` element.

    SDF's spot ``inner_angle`` / ``outer_angle`` are whole cone angles (OGRE's spotlight range;
    its OpenGL cutoff is half the outer angle); the canonical ones are half-angles, so they are
    halved here. The colour is the diffuse colour.
    """
    kind = SDF_LIGHT_KINDS.get((light.get("type") or "point").strip(), DeviceKind.OTHER)
    params: dict[str, Any] = {}
    diffuse = _child(light, "diffuse")
    if diffuse is not None:
        rgba = parse_numbers((diffuse.text or "").strip())
        if rgba is not None and len(rgba) in (3, 4):
            params["color"] = tuple(float(x) for x in rgba[:3])
    _put(params, "intensity", _number(_child(light, "intensity")))
    attenuation = _child(light, "attenuation")
    _put(params, "range", _number(_child(attenuation, "range")))
    for key in ("constant", "linear", "quadratic"):
        _put(params, f"attenuation_{key}", _number(_child(attenuation, key)))
    if kind is not DeviceKind.POINT_LIGHT:
        direction = _child(light, "direction")
        values = parse_numbers((direction.text or "").strip()) if direction is not None else None
        params["direction"] = (
            tuple(float(x) for x in values) if values is not None and len(values) == 3 else (0.0, 0.0, -1.0)
        )
    if kind is DeviceKind.SPOT_LIGHT:
        spot = _child(light, "spot")
        for key in ("inner_angle", "outer_angle"):
            value = _number(_child(spot, key))
            _put(params, f"spot_{key}", None if value is None else value / 2.0)
        _put(params, "spot_falloff", _number(_child(spot, "falloff")))
    on = _child(light, "light_on")
    if on is not None and on.text is not None:
        params["on"] = on.text.strip().lower() in ("1", "true")
    return kind, params
