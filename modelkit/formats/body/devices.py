"""Device parameters of `.body` files, as data: canonical name, accepted spellings, kind, default.

Kinds: ``number``, ``angle`` (converted by the angle unit), ``int``, ``bool``, ``text``,
``vec3``, ``angle_rotation`` (axis-angle, angle converted). Parameters not listed are kept raw.
"""

from __future__ import annotations

import math
from typing import Any

from modelkit.diagnostics import DiagnosticSink
from modelkit.formats.body import values as v
from modelkit.yamltree import YMap, to_plain

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
        vec = v.vector(raw, 3)
        value = None if vec is None else tuple(float(x) for x in vec)
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
