"""MuJoCo cameras, lights and site sensors as canonical devices (:class:`~modelkit.model.DeviceKind`).

Read from the compiled ``MjModel``; each device goes to the link of its body, in the link frame
(a body whose frame the builder moved to its joint keeps its devices where they were):

* ``<camera>`` → ``camera``. A MuJoCo camera looks along its −Z with +Y up (the GL convention),
  turned here into the canonical frame (+X viewing, +Z image top). ``fovy`` is the vertical field
  of view in degrees; with a ``resolution`` the horizontal one is 2·atan(tan(fovy/2)·w/h), without
  one (MuJoCo's 1×1 default: the aspect is the viewport's) it is taken as square.
* ``<light>`` → ``spot_light``, ``directional_light`` or ``point_light``: ``dir`` (body frame) is
  the ``direction``, ``cutoff`` (degrees, an OpenGL half-angle) the outer half-angle, ``exponent``
  the falloff.
* sensors on sites: ``rangefinder`` → a one-ray ``lidar`` (MuJoCo casts it along the site's +Z,
  which becomes the device's +X; ``cutoff`` → ``range_max``), ``accelerometer`` → ``accelerometer``,
  ``gyro`` → ``gyro``, ``force`` and ``torque`` → one ``force_torque`` per site (named after the
  site; MuJoCo measures between the body and its parent, in the site frame).

Cameras and lights of the world body stay only in ``extras`` (no link holds them).
"""

from __future__ import annotations

import math
from typing import Any

from modelkit import rot3
from modelkit.formats.devices import canonical_from_gl, horizontal_fov
from modelkit.formats.mjcf.bodies import pose_of, single, singles, translation
from modelkit.formats.mjcf.build import Built, RobotBuilder
from modelkit.formats.mjcf.compiled import enum_word
from modelkit.model import Device, DeviceKind
from modelkit.spatial import Pose

# The device frame's axes seen from a rangefinder site (columns: site x, y, z in the device frame):
# the site's +Z (the ray) is the device's +X.
RAY_SITE_IN_DEVICE: rot3.M3 = ((0.0, 0.0, 1.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0))
LIGHT_KINDS = {
    "spot": DeviceKind.SPOT_LIGHT,
    "directional": DeviceKind.DIRECTIONAL_LIGHT,
    "point": DeviceKind.POINT_LIGHT,
}


def add_devices(mujoco: Any, m: Any, builder: RobotBuilder, built: Built) -> None:
    """Append the cameras, lights and site sensors of ``m`` to the links of ``built``'s robots."""
    placer = _Placer(mujoco, m, builder, built)
    for c in range(m.ncam):
        placer.camera(c)
    for lt in range(m.nlight):
        placer.light(lt)
    placer.site_sensors()


class _Placer:
    def __init__(self, mujoco: Any, m: Any, builder: RobotBuilder, built: Built) -> None:
        self.mj, self.m, self.builder, self.built = mujoco, m, builder, built

    def name(self, kind: str, index: int) -> str:
        obj = getattr(self.mj.mjtObj, f"mjOBJ_{kind.upper()}")
        return str(self.mj.mj_id2name(self.m, obj, int(index)) or f"{kind}{index}")

    def attach(self, body: int, device: Device, pose_in_body: Pose) -> None:
        robot = self.built.robot_of_body.get(body)
        link = (
            robot.link(self.builder.link_name[body])
            if robot is not None and body in self.builder.link_name
            else None
        )
        if link is None:
            return
        placed = self.builder.offset.get(body, Pose()).inverse() @ pose_in_body
        device.pose = placed
        link.devices.append(device)

    def camera(self, c: int) -> None:
        m = self.m
        body = int(m.cam_bodyid[c])
        pose = pose_of(m.cam_pos[c], m.cam_quat[c])
        fovy = math.radians(float(m.cam_fovy[c]))
        width, height = (int(x) for x in m.cam_resolution[c])
        params: dict[str, Any] = {"fovy": float(m.cam_fovy[c]), "resolution": [width, height]}
        canonical: dict[str, Any] = {"horizontal_fov": fovy}
        if (width, height) != (1, 1) and width > 0 and height > 0:
            canonical = {
                "width": width,
                "height": height,
                "horizontal_fov": horizontal_fov(fovy, width, height),
            }
        device = Device(
            "camera",
            self.name("camera", c),
            params=params,
            source=self.builder.loc.body(body),
            canonical=DeviceKind.CAMERA,
            canonical_params=canonical,
        )
        self.attach(body, device, Pose(canonical_from_gl(pose.rotation_tuple), pose.translation_tuple))

    def light(self, lt: int) -> None:
        m = self.m
        body = int(m.light_bodyid[lt])
        light_type = enum_word(self.mj.mjtLightType(int(m.light_type[lt])), "mjLIGHT_")
        kind = LIGHT_KINDS.get(light_type, DeviceKind.OTHER)
        constant, linear, quadratic = singles(m.light_attenuation[lt])
        canonical: dict[str, Any] = {
            "color": singles(m.light_diffuse[lt]),
            "attenuation_constant": constant,
            "attenuation_linear": linear,
            "attenuation_quadratic": quadratic,
            "on": bool(m.light_active[lt]),
        }
        if float(m.light_intensity[lt]) > 0.0:
            canonical["intensity"] = single(m.light_intensity[lt])
        if float(m.light_range[lt]) > 0.0:
            canonical["range"] = single(m.light_range[lt])
        if kind is not DeviceKind.POINT_LIGHT:
            canonical["direction"] = tuple(float(x) for x in m.light_dir[lt])
        if kind is DeviceKind.SPOT_LIGHT:
            canonical["spot_outer_angle"] = math.radians(single(m.light_cutoff[lt]))
            canonical["spot_falloff"] = single(m.light_exponent[lt])
        device = Device(
            f"light:{light_type}",
            self.name("light", lt),
            params={"cutoff": single(m.light_cutoff[lt]), "exponent": single(m.light_exponent[lt])},
            source=self.builder.loc.body(body),
            canonical=kind,
            canonical_params=canonical,
        )
        self.attach(body, device, translation(m.light_pos[lt]))

    def site_sensors(self) -> None:
        m = self.m
        force_torque: dict[int, Device] = {}
        for s in range(m.nsensor):
            if enum_word(self.mj.mjtObj(int(m.sensor_objtype[s])), "mjOBJ_") != "site":
                continue
            kind = enum_word(self.mj.mjtSensor(int(m.sensor_type[s])), "mjSENS_")
            site = int(m.sensor_objid[s])
            body = int(m.site_bodyid[site])
            site_pose = pose_of(m.site_pos[site], m.site_quat[site])
            params: dict[str, Any] = {"site": self.name("site", site), "sensor": kind}
            noise = float(m.sensor_noise[s])
            if kind in ("force", "torque"):
                device = force_torque.get(site)
                if device is None:
                    device = Device(
                        "force_torque",
                        self.name("site", site),
                        params={"site": self.name("site", site)},
                        source=self.builder.loc.site(site),
                        canonical=DeviceKind.FORCE_TORQUE,
                    )
                    force_torque[site] = device
                    self.attach(body, device, site_pose)
                device.params[f"{kind}_sensor"] = self.name("sensor", s)
                continue
            canonical: dict[str, Any] = {}
            if kind == "rangefinder":
                canonical_kind = DeviceKind.LIDAR
                canonical = {
                    "horizontal_samples": 1,
                    "horizontal_min_angle": 0.0,
                    "horizontal_max_angle": 0.0,
                    "vertical_samples": 1,
                    "vertical_min_angle": 0.0,
                    "vertical_max_angle": 0.0,
                    "range_min": 0.0,
                }
                if float(m.sensor_cutoff[s]) > 0.0:
                    canonical["range_max"] = float(m.sensor_cutoff[s])
                pose = Pose(
                    rot3.matmul(site_pose.rotation_tuple, rot3.transpose(RAY_SITE_IN_DEVICE)),
                    site_pose.translation_tuple,
                )
            elif kind in ("accelerometer", "gyro"):
                canonical_kind = DeviceKind.ACCELEROMETER if kind == "accelerometer" else DeviceKind.GYRO
                pose = site_pose
            else:
                continue
            if noise > 0.0:
                canonical["noise_stddev"] = noise
            device = Device(
                kind,
                self.name("sensor", s),
                params=params,
                source=self.builder.loc.site(site),
                canonical=canonical_kind,
                canonical_params=canonical,
            )
            self.attach(body, device, pose)
