"""Sensors and lights of the MJCF writer (from ``device.canonical`` / ``canonical_params``).

The model's device frame has +X forward (viewing / scanning direction), +Y left, +Z up.

* Cameras (``camera``; ``depth_camera`` and ``rgbd_camera`` with MK807: MuJoCo renders depth
  from any camera but has no depth sensor) → ``<camera>``. A MuJoCo camera looks along its −Z
  with +Y up, so its frame is the device frame turned by R = [x: −Y, y: +Z, z: −X]. ``fovy`` is
  the vertical field of view in degrees, 2·atan(tan(hfov/2)·height/width); ``resolution="w h"``.
  Clip distances, frame rate and noise have no per-camera field (MK807).
* Each sensor device gets a ``<site>`` named after it; devices the MJCF reader made of one MuJoCo site
  (``params["site"]``: an accelerometer and a gyro on an IMU site) share the first one's.
* ``lidar`` → a ``<site>`` and a ``<rangefinder>`` sensor (``cutoff`` = range_max). A rangefinder
  casts one ray along the site's +Z, so the site is turned to put +Z on the device's +X (MK807: one
  ray, not a scan).
* ``imu`` → site + ``accelerometer`` + ``gyro``; ``accelerometer``/``gyro`` → site + that sensor;
  ``force_torque`` → site + ``force`` + ``torque`` (MuJoCo measures the force between the body and
  its parent, expressed in the site frame, as Choreonoid's force sensor does). A sensor's range
  (``max_acceleration``, ``max_angular_velocity``, ``max_force``, ``max_torque``: Choreonoid's
  per-axis limits) is MuJoCo's ``cutoff``, which clamps each component's absolute value: one number,
  so three different ones are written as the largest (MK807). ``noise_stddev`` is ``noise``;
  ``update_rate`` has no MJCF field (MK807: MuJoCo computes sensors every step).
* ``contact`` → left out (MK806): MuJoCo's ``touch`` needs a sensing volume the model does not
  give.
* Lights → ``<light type="spot|point|directional">`` at the device position, ``dir`` = the
  device's ``direction`` in the body frame, ``diffuse`` = colour, ``intensity`` as given,
  ``cutoff`` = outer half-angle in degrees, ``exponent`` = falloff, ``attenuation`` = (constant,
  linear, quadratic), ``range``, ``active="false"`` when off.
* ``other`` → left out (MK806).

Sensor names are ``<device>`` (one sensor) or ``<device>_acc``/``_gyro``/``_force``/``_torque``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from modelkit.convert.context import WriteContext
from modelkit.convert.numbers import fmt, fmt_position, fmt_vec
from modelkit.formats.mjcf.write_names import NameTable
from modelkit.formats.mjcf.write_xml import Element, set_pose, sub
from modelkit.model import CAMERA_KINDS, LIGHT_KINDS, Device, DeviceKind, Link
from modelkit.spatial import Pose

# Columns: the MuJoCo camera's x, y, z axes in the device frame.
CAMERA_FROM_DEVICE = np.array([[0.0, 0.0, -1.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
# The rangefinder site's x, y, z axes in the device frame (its +Z is the device's +X).
RAY_FROM_DEVICE = np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
SITE_SIZE = "0.005"
# MuJoCo sensor -> the device parameter that is its range (cutoff)
RANGES = {"accelerometer": "max_acceleration", "gyro": "max_angular_velocity", "force": "max_force",
          "torque": "max_torque"}
SENSORS: dict[DeviceKind, tuple[tuple[str, str], ...]] = {
    DeviceKind.IMU: (("accelerometer", "_acc"), ("gyro", "_gyro")),
    DeviceKind.ACCELEROMETER: (("accelerometer", ""),),
    DeviceKind.GYRO: (("gyro", ""),),
    DeviceKind.FORCE_TORQUE: (("force", "_force"), ("torque", "_torque")),
    DeviceKind.LIDAR: (("rangefinder", ""),),
}


def vertical_fov(hfov: float, width: float | None, height: float | None) -> float:
    if width and height:
        return 2.0 * math.atan(math.tan(hfov / 2.0) * float(height) / float(width))
    return hfov


MAX_FOVY = 180.0  # MuJoCo refuses a camera fovy of 180° or more
MAX_FOVY_WRITTEN = 179.0


@dataclass
class DeviceWriter:
    ctx: WriteContext
    names: NameTable
    sensor: Element
    # what an MJCF source's own elements written back need (:mod:`.write_own`): the source site of a
    # device → the site written for it; a camera's or light's device name → its element
    site_for: dict[str, str] = field(default_factory=dict)
    written: dict[tuple[str, str], Element] = field(default_factory=dict)
    site_body: dict[str, Element] = field(default_factory=dict)  # a device site → the body it is in

    def link_devices(self, body: Element, link: Link, body_name: str) -> None:
        for device in link.devices:
            target = f"body[{body_name}]/device[{device.name}]"
            kind = device.canonical
            if kind in CAMERA_KINDS:
                self.camera(body, device, target)
            elif kind in LIGHT_KINDS:
                self.light(body, device, target)
            elif kind in SENSORS:
                self.sensors(body, device, target)
            else:
                what = device.kind if kind is DeviceKind.OTHER else kind.value
                why = (
                    "MuJoCo's touch sensor needs a sensing volume the model does not give"
                    if kind is DeviceKind.CONTACT
                    else "MJCF has no equivalent"
                )
                self.ctx.note("MK806", f"{what} device {device.name} left out: {why}", device.source, target)

    def camera(self, body: Element, device: Device, target: str) -> None:
        p = device.canonical_params
        el = sub(body, "camera", name=self.names.claim("camera", device.name, device.source, target))
        self.written[("camera", device.name)] = el
        set_pose(el, Pose(device.pose.rotation @ CAMERA_FROM_DEVICE, device.pose.translation))
        hfov = p.get("horizontal_fov")
        width, height = p.get("width"), p.get("height")
        if hfov is not None:
            fovy = math.degrees(vertical_fov(float(hfov), width, height))
            if fovy >= MAX_FOVY:  # MuJoCo: "fovy too large" (a panoramic camera's 180° or 360°)
                self.ctx.note("MK875", f"camera {device.name}: vertical field of view {fmt(fovy)}° is "
                              f"written as {fmt(MAX_FOVY_WRITTEN)}° (MuJoCo's cameras are pinhole cameras, "
                              "below 180°; a panoramic camera has no MJCF equivalent)", device.source, target)
                fovy = MAX_FOVY_WRITTEN
            el.set("fovy", fmt(fovy))
        if width and height:
            el.set("resolution", f"{int(width)} {int(height)}")
        lost = [k for k in ("near", "far", "update_rate", "noise_stddev") if p.get(k) is not None]
        if device.canonical is not DeviceKind.CAMERA:
            lost.insert(0, "depth image (MuJoCo renders depth from any camera, but has no depth sensor)")
        if hfov is None:
            lost.append("field of view not given: MuJoCo's 45° applies")
        if lost:
            self.ctx.note(
                "MK807",
                f"{device.canonical.value} {device.name} written as a <camera>; not held: " + ", ".join(lost),
                device.source,
                target,
            )

    def light(self, body: Element, device: Device, target: str) -> None:
        p = device.canonical_params
        kind = {
            DeviceKind.SPOT_LIGHT: "spot",
            DeviceKind.POINT_LIGHT: "point",
            DeviceKind.DIRECTIONAL_LIGHT: "directional",
        }[device.canonical]
        el = sub(body, "light", name=self.names.claim("light", device.name, device.source, target), type=kind)
        self.written[("light", device.name)] = el
        el.set("pos", fmt_position(device.pose.translation))
        direction = np.asarray(p.get("direction", (0.0, 0.0, -1.0)), dtype=float)
        el.set("dir", fmt_vec(device.pose.rotation @ direction))
        if p.get("color") is not None:
            el.set("diffuse", fmt_vec(np.asarray(p["color"], dtype=float)[:3]))
        if p.get("intensity") is not None:
            el.set("intensity", fmt(float(p["intensity"])))
        if kind == "spot" and p.get("spot_outer_angle") is not None:
            el.set("cutoff", fmt(math.degrees(float(p["spot_outer_angle"]))))
        if kind == "spot" and p.get("spot_falloff") is not None:
            el.set("exponent", fmt(float(p["spot_falloff"])))
        att = [p.get(f"attenuation_{k}") for k in ("constant", "linear", "quadratic")]
        if any(a is not None for a in att):
            el.set("attenuation", fmt_vec([1.0 if att[0] is None else att[0], att[1] or 0.0, att[2] or 0.0]))
        if p.get("range") is not None and math.isfinite(float(p["range"])):
            el.set("range", fmt(float(p["range"])))
        if p.get("on") is False:
            el.set("active", "false")
        if kind == "spot" and p.get("spot_inner_angle") is not None:
            self.ctx.note(
                "MK807",
                f"spot light {device.name}: the inner cone angle is not held (MuJoCo has an "
                "outer cutoff and an exponent)",
                device.source,
                target,
            )

    def sensors(self, body: Element, device: Device, target: str) -> None:
        p = device.canonical_params
        lost: list[str] = []
        turn = RAY_FROM_DEVICE if device.canonical is DeviceKind.LIDAR else np.eye(3)
        source_site = str(device.params.get("site") or "")
        shared = self.site_for.get(source_site) if source_site else None
        if shared is not None and self.site_body.get(shared) is body:
            site_name = shared  # an MJCF site that carries several sensors (accelerometer and gyro): one site
        else:
            site_name = self.names.claim("site", device.name, device.source, target, remember=False)
            site = sub(body, "site", name=site_name, size=SITE_SIZE)
            set_pose(site, Pose(device.pose.rotation @ turn, device.pose.translation))
            self.site_body[site_name] = body
            if source_site:
                self.site_for[source_site] = site_name
        for element, suffix in SENSORS[device.canonical]:
            name = self.names.claim("sensor", device.name + suffix, device.source, target)
            el = sub(self.sensor, element, name=name, site=site_name)
            if element == "rangefinder" and p.get("range_max") is not None:
                el.set("cutoff", fmt(float(p["range_max"])))
            self._cutoff(el, element, p, lost)
            self._noise(el, p)
        rate = p.get("update_rate")
        if rate is not None and math.isfinite(float(rate)) and float(rate) > 0.0:
            lost.append(f"update rate {fmt(float(rate))} Hz (MuJoCo computes sensors every step)")
        if lost:
            self.ctx.note("MK807", f"{device.canonical.value} {device.name}: " + "; ".join(lost),
                          device.source, target)
        if device.canonical is DeviceKind.LIDAR:
            samples = p.get("horizontal_samples")
            scan = f"; the scan had {samples} samples" if samples else ""
            self.ctx.note(
                "MK807",
                f"lidar {device.name} written as one MuJoCo rangefinder ray along its forward "
                f"axis (MuJoCo has no scanning sensor{scan})",
                device.source,
                target,
            )

    @staticmethod
    def _cutoff(el: Element, element: str, p: dict[str, Any], lost: list[str]) -> None:
        """The sensor's range as MuJoCo's ``cutoff`` (module docstring)."""
        key = RANGES.get(element)
        given = p.get(key) if key else None
        if given is None:
            return
        values = [abs(float(v)) for v in (given if isinstance(given, list | tuple) else [given])]
        if not values or not all(math.isfinite(v) for v in values):
            return  # no range (Choreonoid's default: unlimited)
        largest = max(values)
        if largest <= 0.0:
            return
        el.set("cutoff", fmt(largest))
        if any(v != largest for v in values):
            lost.append(f"{key} {fmt_vec(values)} per axis: cutoff is one number, written as the largest, "
                        f"{fmt(largest)}")

    @staticmethod
    def _noise(el: Element, p: dict[str, Any]) -> None:
        noise = p.get("noise_stddev")
        if noise is not None and float(noise) > 0.0:
            el.set("noise", fmt(float(noise)))
