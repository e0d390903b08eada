"""Sensors, lights and plugins: SDF elements that become :class:`~modelkit.model.Device` or data.

A sensor becomes ``Device(kind=<its type as written>)``; cameras and range sensors also get their
main parameters under flat snake_case names (``width``, ``horizontal_fov``, ``range_max`` ...),
and every sensor keeps its whole type-specific element as ``params["config"]``. A light becomes
``Device(kind="light:<type>")``. Plugins are simulator code: they are kept verbatim as data.
Every device also gets its canonical kind and parameters (:mod:`modelkit.formats.devices`; SDF's
sensor frame is the canonical one). The caller places devices (their pose is set when the link
frame is known).
"""

from __future__ import annotations

from typing import Any

from lxml import etree
from lxml.etree import _Element as Element

from modelkit.diagnostics import did_you_mean
from modelkit.formats.devices import sdf_light_canonical, sdf_sensor_canonical
from modelkit.formats.sdf.context import Context
from modelkit.formats.sdf.document import SdfDocument
from modelkit.formats.sdf.geometry import element_data
from modelkit.formats.sdf.values import child, children
from modelkit.model import Device

CAMERAS = frozenset(
    {
        "camera",
        "depth_camera",
        "depth",
        "rgbd_camera",
        "rgbd",
        "multicamera",
        "thermal_camera",
        "thermal",
        "segmentation_camera",
        "segmentation",
        "boundingbox_camera",
        "boundingbox",
        "wideanglecamera",
        "wide_angle_camera",
    }
)
RANGES = frozenset({"ray", "gpu_ray", "lidar", "gpu_lidar"})
OTHERS = frozenset(
    {
        "air_pressure",
        "air_speed",
        "air_flow",
        "altimeter",
        "contact",
        "custom",
        "force_torque",
        "gps",
        "imu",
        "logical_camera",
        "magnetometer",
        "navsat",
        "rfid",
        "rfidtag",
        "sonar",
        "wireless_receiver",
        "wireless_transmitter",
    }
)
SENSOR_TYPES = CAMERAS | RANGES | OTHERS
LIGHT_TYPES = ("point", "directional", "spot")
# The element that configures each sensor type, when it is not named like the type.
CONFIG_ELEMENT = {
    "depth_camera": "camera",
    "depth": "camera",
    "rgbd_camera": "camera",
    "rgbd": "camera",
    "thermal_camera": "camera",
    "thermal": "camera",
    "segmentation_camera": "camera",
    "segmentation": "camera",
    "boundingbox_camera": "camera",
    "boundingbox": "camera",
    "wideanglecamera": "camera",
    "wide_angle_camera": "camera",
    "multicamera": "camera",
    "gpu_ray": "ray",
    "gpu_lidar": "lidar",
    "gps": "navsat",
    "wireless_receiver": "transceiver",
    "wireless_transmitter": "transceiver",
}


def plugin_data(ctx: Context, src: SdfDocument, el: Element, owner: str) -> dict[str, Any]:
    """A ``<plugin>`` as data: name, filename and the element verbatim."""
    name = el.get("name") or ""
    filename = el.get("filename") or ""
    ctx.sink.emit(
        "MK631",
        f'plugin "{name}" ({filename}) of {owner} is simulator code; it is kept only as data',
        src.values.loc(el),
    )
    return {
        "name": name,
        "filename": filename,
        "owner": owner,
        "xml": etree.tostring(el, encoding="unicode", with_tail=False),
    }


def sensor_device(ctx: Context, src: SdfDocument, el: Element, owner: str) -> Device | None:
    """A ``<sensor>`` as a device (pose left at identity for the caller to set)."""
    values = src.values
    name = el.get("name")
    kind = (el.get("type") or "").strip()
    if name is None:
        ctx.sink.emit("MK120", f"a <sensor> of {owner} has no name attribute", values.loc(el))
        name = ""
    if not kind:
        ctx.sink.emit("MK120", f'sensor "{name}" of {owner} has no type attribute', values.loc(el))
        return None
    if kind not in SENSOR_TYPES:
        ctx.sink.emit(
            "MK630",
            f'sensor "{name}" of {owner} has type "{kind}", which is not an SDFormat sensor type',
            values.loc(el, "type"),
            hint=did_you_mean(kind, SENSOR_TYPES),
        )
        return None
    params: dict[str, Any] = {}
    for key, tag in (("update_rate", "update_rate"),):
        value = values.number(child(el, tag))
        if value is not None:
            params[key] = value
    for key in ("always_on", "visualize"):
        flag = child(el, key)
        if flag is not None:
            params[key] = values.boolean(flag)
    topic = values.text(child(el, "topic"))
    if topic:
        params["topic"] = topic
    config_tag = CONFIG_ELEMENT.get(kind, kind)
    config = child(el, config_tag)
    if kind in RANGES and config is None:
        config = child(el, "ray" if config_tag == "lidar" else "lidar")
    if kind in CAMERAS:
        cameras = children(el, "camera")
        if cameras:
            params.update(_camera(src, cameras[0]))
        if kind == "multicamera":
            params["cameras"] = [_camera(src, c) for c in cameras]
    elif kind in RANGES and config is not None:
        params.update(_ranges(src, config))
    if config is not None:
        params["config"] = element_data(config)
    plugins = [plugin_data(ctx, src, p, f'sensor "{name}"') for p in children(el, "plugin")]
    if plugins:
        params["plugins"] = plugins
    canonical, canonical_params = sdf_sensor_canonical(el)
    return Device(
        kind,
        name,
        params=params,
        source=values.loc(el),
        canonical=canonical,
        canonical_params=canonical_params,
    )


def _camera(src: SdfDocument, camera: Element) -> dict[str, Any]:
    values = src.values
    image = child(camera, "image")
    clip = child(camera, "clip")
    out: dict[str, Any] = {
        "horizontal_fov": values.child_number(camera, "horizontal_fov", 1.047),
        "width": _int(values.child_number(image, "width", 320.0)),
        "height": _int(values.child_number(image, "height", 240.0)),
        "format": values.text(child(image, "format")) if image is not None else None,
        "near": values.child_number(clip, "near", 0.1),
        "far": values.child_number(clip, "far", 100.0),
    }
    if not out["format"]:
        out["format"] = "R8G8B8"
    if camera.get("name"):
        out["camera_name"] = camera.get("name")
    return out


def _int(value: float | None) -> int | None:
    return None if value is None else int(value)


def _ranges(src: SdfDocument, config: Element) -> dict[str, Any]:
    values = src.values
    scan = child(config, "scan")
    out: dict[str, Any] = {}
    for axis, samples in (("horizontal", 640.0), ("vertical", 1.0)):
        el = child(scan, axis) if scan is not None else None
        if el is None and axis == "vertical":
            continue
        out[f"{axis}_samples"] = _int(values.child_number(el, "samples", samples))
        out[f"{axis}_resolution"] = values.child_number(el, "resolution", 1.0)
        out[f"{axis}_min_angle"] = values.child_number(el, "min_angle", 0.0)
        out[f"{axis}_max_angle"] = values.child_number(el, "max_angle", 0.0)
    rng = child(config, "range")
    out["range_min"] = values.child_number(rng, "min", 0.0)
    out["range_max"] = values.child_number(rng, "max", 0.0)
    out["range_resolution"] = values.child_number(rng, "resolution", 0.0)
    return out


def light_device(ctx: Context, src: SdfDocument, el: Element, owner: str) -> Device | None:
    """A ``<light>`` as ``Device(kind="light:<type>")`` (pose left for the caller)."""
    values = src.values
    name = el.get("name") or ""
    kind = (el.get("type") or "point").strip()
    if kind not in LIGHT_TYPES:
        ctx.sink.emit(
            "MK630",
            f'light "{name}" of {owner} has type "{kind}"; SDFormat lights are point, directional or spot',
            values.loc(el, "type"),
        )
        return None
    params: dict[str, Any] = {}
    cast = child(el, "cast_shadows")
    if cast is not None:
        params["cast_shadows"] = values.boolean(cast)
    for key in ("diffuse", "specular"):
        color = values.color(child(el, key))
        if color is not None:
            params[key] = list(color)
    intensity = values.number(child(el, "intensity"))
    if intensity is not None:
        params["intensity"] = intensity
    attenuation = child(el, "attenuation")
    if attenuation is not None:
        for key, tag in (
            ("range", "range"),
            ("constant", "constant"),
            ("linear", "linear"),
            ("quadratic", "quadratic"),
        ):
            value = values.number(child(attenuation, tag))
            if value is not None:
                params[f"attenuation_{key}" if key != "range" else "range"] = value
    direction = values.vector(child(el, "direction"), 3)
    if direction is not None:
        params["direction"] = list(direction)
    spot = child(el, "spot")
    if spot is not None:
        for key in ("inner_angle", "outer_angle", "falloff"):
            value = values.number(child(spot, key))
            if value is not None:
                params[f"spot_{key}"] = value
    canonical, canonical_params = sdf_light_canonical(el)
    return Device(
        f"light:{kind}",
        name,
        params=params,
        source=values.loc(el),
        canonical=canonical,
        canonical_params=canonical_params,
    )
