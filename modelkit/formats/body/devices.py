"""Device parameters of `.body` files, as data: canonical name, accepted spellings, kind, default;
and their mapping to the shared device model (:class:`~modelkit.model.DeviceKind`, robotics frame).

Kinds: ``number``, ``angle`` (converted by the angle unit), ``int``, ``bool``, ``text``,
``vec3``, ``angle_rotation`` (axis-angle, angle converted). Parameters not listed are kept raw.
"""

from __future__ import annotations

import math
from typing import Any

from modelkit import rot3
from modelkit.diagnostics import DiagnosticSink
from modelkit.formats.body import values as v
from modelkit.model import DeviceKind
from modelkit.spatial import Mat3
from modelkit.yamltree import YMap, to_plain

# modelkit.formats.devices (the frame facts shared with the XML readers) imports lxml: it is imported
# where a camera or a range sensor needs it, so that reading a `.body` file without one stays light.

INF3 = (math.inf, math.inf, math.inf)
_CLIP = (
    ("min_distance", ("min_distance", "minDistance"), "number", 0.1),
    ("max_distance", ("max_distance", "maxDistance"), "number", 10.0),
    ("detection_rate", ("detection_rate",), "number", 1.0),
    ("error_deviation", ("error_deviation",), "number", 0.0),
)
_OPTICAL = (
    ("optical_frame", ("optical_frame",), "text", "gl"),
    ("optical_frame_rotation", ("optical_frame_rotation",), "angle_rotation", None),
)

ParamSpec = tuple[str, tuple[str, ...], str, Any]

DEVICE_PARAMS: dict[str, tuple[ParamSpec, ...]] = {
    "ForceSensor": (
        ("max_force", ("max_force", "maxForce"), "vec3", INF3),
        ("max_torque", ("max_torque", "maxTorque"), "vec3", INF3),
    ),
    "RateGyroSensor": (
        ("max_angular_velocity", ("max_angular_velocity", "maxAngularVelocity"), "vec3", INF3),
    ),
    "AccelerationSensor": (("max_acceleration", ("max_acceleration", "maxAcceleration"), "vec3", INF3),),
    "IMU": (
        ("max_angular_velocity", ("max_angular_velocity",), "vec3", INF3),
        ("max_acceleration", ("max_acceleration",), "vec3", INF3),
    ),
    "Camera": (
        ("format", ("format",), "text", None),
        ("width", ("width",), "int", 640),
        ("height", ("height",), "int", 480),
        ("field_of_view", ("field_of_view", "fieldOfView"), "angle", math.radians(45.0)),
        ("near_clip_distance", ("near_clip_distance", "nearClipDistance"), "number", 0.04),
        ("far_clip_distance", ("far_clip_distance", "farClipDistance"), "number", 200.0),
        ("frame_rate", ("frame_rate", "frameRate"), "number", 30.0),
        ("lens_type", ("lens_type", "lensType"), "text", "NORMAL"),
        *_OPTICAL,
        *_CLIP,
    ),
    "RangeSensor": (
        ("min_distance", ("min_distance", "minDistance"), "number", 0.1),
        ("max_distance", ("max_distance", "maxDistance"), "number", 10.0),
        ("scan_rate", ("scan_rate", "scanRate", "frame_rate", "frameRate"), "number", 10.0),
        ("detection_rate", ("detection_rate",), "number", 1.0),
        ("error_deviation", ("error_deviation",), "number", 0.0),
        *_OPTICAL,
    ),
    "SpotLight": (
        ("color", ("color",), "vec3", (1.0, 1.0, 1.0)),
        ("intensity", ("intensity",), "number", 1.0),
        ("attenuation", ("attenuation",), "vec3", (1.0, 0.0, 0.0)),
        ("direction", ("direction",), "vec3", (0.0, 0.0, -1.0)),
        ("beam_width", ("beam_width", "beamWidth"), "angle", math.radians(90.0)),
        ("cut_off_angle", ("cut_off_angle", "cutOffAngle"), "angle", math.radians(45.0)),
        ("cut_off_exponent", ("cut_off_exponent", "cutOffExponent"), "number", 1.0),
        ("on", ("on",), "bool", True),
    ),
    "PointLight": (
        ("color", ("color",), "vec3", (1.0, 1.0, 1.0)),
        ("intensity", ("intensity",), "number", 1.0),
        ("attenuation", ("attenuation",), "vec3", (1.0, 0.0, 0.0)),
        ("on", ("on",), "bool", True),
    ),
}
DEVICE_PARAMS["CameraDevice"] = DEVICE_PARAMS["Camera"]

CORE_DEVICES = frozenset(
    {*DEVICE_PARAMS, "Attachment", "Holder", "Conveyor", "DigitalIO", "MarkerDevice", "ZmpDevice"}
)
PLUGIN_DEVICES = frozenset(
    {
        "AGXVehicleContinuousTrackDevice",
        "AGXBreakableJointDevice",
        "AGXMagneticJointDevice",
        "AGXWireDevice",
        "PxContinuousTrack",
        "RotorDevice",
        "SmokeDevice",
        "FireDevice",
        "FountainDevice",
        "RainDevice",
        "SnowDevice",
        "LivoxMid360",
        "CompetitorMarker",
    }
)
CAMERA_FORMATS = {
    "COLOR": "Camera",
    "DEPTH": "RangeCamera",
    "COLOR_DEPTH": "RangeCamera",
    "POINT_CLOUD": "RangeCamera",
    "COLOR_POINT_CLOUD": "RangeCamera",
}
DEFAULT_YAW_STEP = 1.0  # rad: Choreonoid's RangeSensor constructor quirk (not 1°)


def read_params(kind: str, node: YMap, angle_scale: float, sink: DiagnosticSink) -> dict[str, Any]:
    """The device's parameters in SI units; unknown keys are kept raw under ``"info"``."""
    params: dict[str, Any] = {}
    known: set[str] = {"type", "name", "id", "on", "translation", "rotation", "scale", "elements"}
    for canonical, spellings, kind_of, default in DEVICE_PARAMS.get(kind, ()):
        known.update(spellings)
        params[canonical] = _read(node, spellings, kind_of, default, angle_scale, sink)
    if kind == "RangeSensor":
        known.update(_range_sensor(node, angle_scale, params))
    info = {k: to_plain(val) for k, val in node.items() if k not in known}
    if info:
        params["info"] = info
    return params


def _read(
    node: YMap, spellings: tuple[str, ...], kind: str, default: Any, angle_scale: float, sink: DiagnosticSink
) -> Any:
    raw = node.get(*spellings)
    if raw is None:
        return default
    if kind == "number":
        value: Any = v.number(raw)
    elif kind == "angle":
        number = v.number(raw)
        value = None if number is None else number * angle_scale
    elif kind == "int":
        value = v.integer(raw)
    elif kind == "bool":
        value = v.boolean(raw)
    elif kind == "text":
        value = v.scalar_text(raw)
    elif kind == "vec3":
        value = v.vector3(raw)
    else:  # angle_rotation
        rot = v.rotation(raw, angle_scale, sink)
        value = None if rot is None else rot
    return default if value is None else value


def _range_sensor(node: YMap, angle_scale: float, params: dict[str, Any]) -> set[str]:
    """Yaw/pitch coverage and sample counts as the RangeSensor constructor computes them."""

    def angle(*keys: str) -> float | None:
        return v.get_angle(node, angle_scale, *keys)

    used = {
        "min_yaw_angle",
        "max_yaw_angle",
        "yaw_range",
        "yawRange",
        "scanAngle",
        "min_pitch_angle",
        "max_pitch_angle",
        "pitch_range",
        "pitchRange",
        "yaw_step",
        "yawStep",
        "scanStep",
        "yaw_samples",
        "pitch_step",
        "pitchStep",
        "pitch_samples",
    }
    for axis, default_range, step_keys in (
        ("yaw", math.radians(120.0), ("yaw_step", "yawStep", "scanStep")),
        ("pitch", 0.0, ("pitch_step", "pitchStep")),
    ):
        lo, hi = angle(f"min_{axis}_angle"), angle(f"max_{axis}_angle")
        if lo is not None and hi is not None and lo <= hi:
            low, high = lo, hi
        else:
            keys = ("yaw_range", "yawRange", "scanAngle") if axis == "yaw" else ("pitch_range", "pitchRange")
            total = angle(*keys)
            total = default_range if total is None else total
            low, high = -total / 2.0, total / 2.0
        coverage = high - low
        samples = v.integer(node.get(f"{axis}_samples"))
        step = angle(*step_keys)
        if samples is not None and samples > 1:
            step = coverage / (samples - 1)
        else:
            if step is None:
                step = DEFAULT_YAW_STEP if axis == "yaw" else 0.0
            samples = 1 if step <= 0.0 else math.floor(coverage / step + 1e-7) + 1
        params[f"min_{axis}_angle"] = low
        params[f"max_{axis}_angle"] = high
        params[f"{axis}_step"] = step
        params[f"{axis}_samples"] = samples
    return used


# ---- the canonical device model (DeviceKind) -------------------------------------------------

# R_opt of each `optical_frame` (body-format.md §3.7): columns are the GL camera frame's axes in
# the device frame, T_glcam = T_device · R_opt · Rot(optical_frame_rotation).
OPTICAL_FRAMES: dict[str, rot3.M3] = {
    "gl": rot3.IDENTITY,
    "cv": ((1.0, 0.0, 0.0), (0.0, -1.0, 0.0), (0.0, 0.0, -1.0)),
    "robotics": ((0.0, 0.0, -1.0), (-1.0, 0.0, 0.0), (0.0, 1.0, 0.0)),  # devices.GL_IN_ROBOTICS
}
OPTICAL_DEVICES = frozenset({"Camera", "CameraDevice", "RangeSensor"})
CANONICAL_CAMERAS = {
    "COLOR": DeviceKind.CAMERA,
    "DEPTH": DeviceKind.DEPTH_CAMERA,
    "POINT_CLOUD": DeviceKind.DEPTH_CAMERA,
    "COLOR_DEPTH": DeviceKind.RGBD_CAMERA,
    "COLOR_POINT_CLOUD": DeviceKind.RGBD_CAMERA,
}
CANONICAL_KINDS = {
    "RangeSensor": DeviceKind.LIDAR,
    "IMU": DeviceKind.IMU,
    "AccelerationSensor": DeviceKind.ACCELEROMETER,
    "RateGyroSensor": DeviceKind.GYRO,
    "ForceSensor": DeviceKind.FORCE_TORQUE,
    "SpotLight": DeviceKind.SPOT_LIGHT,
    "PointLight": DeviceKind.POINT_LIGHT,
}


def canonical_rotation(kind: str, params: dict[str, Any], rotation: Any) -> Any:
    """The canonical (robotics) sensor frame of a device whose node frame has ``rotation``.

    Cameras and range sensors look through their optical frame: the GL camera frame is
    R·R_opt·R_ofr, and the canonical frame is that times GL_IN_ROBOTICSᵀ (§8.7). Other devices'
    frames are their node frames (``rotation`` itself is returned). Otherwise a tuple rotation
    (:mod:`modelkit.rot3`), whatever ``rotation`` was (a tuple or a numpy array).
    """
    if kind not in OPTICAL_DEVICES:
        return rotation
    from modelkit.formats.devices import canonical_from_gl

    r_opt = OPTICAL_FRAMES.get(str(params.get("optical_frame", "gl")), rot3.IDENTITY)
    extra = params.get("optical_frame_rotation")
    if extra is not None:
        r_opt = rot3.matmul(r_opt, rot3.mat3(extra))
    return canonical_from_gl(rot3.matmul(rot3.mat3(rotation), r_opt))


def node_rotation(kind: str, params: dict[str, Any], canonical: Mat3) -> Mat3:
    """The inverse of :func:`canonical_rotation`: the node rotation a `.body` writer writes back,
    given the device's ``optical_frame`` / ``optical_frame_rotation`` words in ``params``."""
    import numpy as np

    identity = np.eye(3)
    return np.asarray(canonical, dtype=float) @ np.asarray(canonical_rotation(kind, params, identity)).T


def canonical_device(kind: str, params: dict[str, Any]) -> tuple[DeviceKind, dict[str, Any]]:
    """The device in the shared vocabulary: canonical kind and parameters (SI, radians).

    Values that mean "no effect" in Choreonoid (infinite limits, zero noise, detection rate 1)
    are left out; everything else Choreonoid defines by default is filled in.
    """
    if kind in ("Camera", "CameraDevice"):
        canonical = CANONICAL_CAMERAS.get(str(params.get("format")), DeviceKind.OTHER)
        return canonical, (_camera(params, canonical) if canonical is not DeviceKind.OTHER else {})
    canonical = CANONICAL_KINDS.get(kind, DeviceKind.OTHER)
    out: dict[str, Any] = {}
    if canonical is DeviceKind.LIDAR:
        out = {
            "horizontal_samples": params["yaw_samples"],
            "horizontal_min_angle": params["min_yaw_angle"] + 0.0,
            "horizontal_max_angle": params["max_yaw_angle"],
            "vertical_samples": params["pitch_samples"],
            "vertical_min_angle": params["min_pitch_angle"] + 0.0,  # no -0.0 from -range/2
            "vertical_max_angle": params["max_pitch_angle"],
            "range_min": params["min_distance"],
            "range_max": params["max_distance"],
            "update_rate": params["scan_rate"],
        }
        _noise(params, out)
    elif canonical in (DeviceKind.IMU, DeviceKind.ACCELEROMETER, DeviceKind.GYRO, DeviceKind.FORCE_TORQUE):
        for key in ("max_acceleration", "max_angular_velocity", "max_force", "max_torque"):
            value = params.get(key)
            if value is not None and all(math.isfinite(x) for x in value):
                out[key] = tuple(value)
    elif canonical in (DeviceKind.SPOT_LIGHT, DeviceKind.POINT_LIGHT):
        constant, linear, quadratic = params["attenuation"]
        out = {
            "color": tuple(params["color"]),
            "intensity": params["intensity"],
            "attenuation_constant": constant,
            "attenuation_linear": linear,
            "attenuation_quadratic": quadratic,
            "on": params["on"],
        }
        if canonical is DeviceKind.SPOT_LIGHT:
            # VRML/Choreonoid: beam_width is the full-intensity inner half-angle, cut_off_angle the
            # outer one, both from the beam axis; a beam wider than the cut-off acts as the cut-off.
            out["direction"] = tuple(params["direction"])
            out["spot_inner_angle"] = min(params["beam_width"], params["cut_off_angle"])
            out["spot_outer_angle"] = params["cut_off_angle"]
            out["spot_falloff"] = params["cut_off_exponent"]
    return canonical, out


def _camera(params: dict[str, Any], canonical: DeviceKind) -> dict[str, Any]:
    from modelkit.formats.devices import horizontal_fov

    width, height, fov = params["width"], params["height"], params["field_of_view"]
    # field_of_view is the shorter side's (§3.7): the vertical one unless the image is taller than wide.
    hfov = fov if width < height else horizontal_fov(fov, width, height)
    out: dict[str, Any] = {
        "width": width,
        "height": height,
        "horizontal_fov": hfov,
        "near": params["near_clip_distance"],
        "far": params["far_clip_distance"],
        "update_rate": params["frame_rate"],
    }
    if canonical is not DeviceKind.CAMERA:  # a RangeCamera: depth range and noise
        out["range_min"] = params["min_distance"]
        out["range_max"] = params["max_distance"]
        _noise(params, out)
    return out


def _noise(params: dict[str, Any], out: dict[str, Any]) -> None:
    if params.get("error_deviation"):
        out["noise_stddev"] = params["error_deviation"]
    if params.get("detection_rate", 1.0) != 1.0:
        out["detection_rate"] = params["detection_rate"]
