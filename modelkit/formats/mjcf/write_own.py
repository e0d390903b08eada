"""MJCF to MJCF: the source's own cameras, lights, world sites and sensors written back.

The MJCF reader keeps what the model does not hold as data (``mjcf_sites``, ``mjcf_world_sites``,
``mjcf_cameras``, ``mjcf_lights``, ``mjcf_sensors``). When an MJCF file is written from an MJCF
source, they go back into the file (the sites of bodies are written with their bodies,
:mod:`.write_bodies`):

* cameras and lights of bodies are the model's devices (:mod:`.write_devices` writes them); their
  ``mode`` and ``target`` body are added here. Those of the world body go into ``<worldbody>`` with
  their pose, ``mode``/``target``, ``fovy``, ``resolution``, ``ipd`` (cameras) and type, direction,
  colours, attenuation, cone, shadow and ``active`` (lights);
* world sites go into ``<worldbody>`` as the sites of bodies do;
* each sensor that is not a device already written (an accelerometer, gyro, force/torque or
  rangefinder of a site) is written into ``<sensor>`` with its ``cutoff`` and ``noise`` when every
  object it names (site, joint, body, actuator, camera, geom, tendon) exists in
  the output: under the name written for it, which may differ from the source's (MK800). A sensor
  whose reading depends on its site's shape (``touch``, ``insidesite``) is not moved to the site a
  device wrote (a small sphere of its own). A frame sensor of a body's frame (``xbody``) needs the
  body written at its source frame.

What cannot be written is returned by kind and named in the MK806/MK808 note of
:func:`.write_foreign.note_unwritten_own`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from modelkit.convert.context import WriteContext
from modelkit.convert.numbers import fmt, fmt_position, fmt_vec
from modelkit.formats.mjcf.site_frames import site_pose
from modelkit.formats.mjcf.write_bodies import BodyTree
from modelkit.formats.mjcf.write_devices import DeviceWriter
from modelkit.formats.mjcf.write_names import NameTable
from modelkit.formats.mjcf.write_refs import WrittenObjects
from modelkit.formats.mjcf.write_xml import Element, set_pose, sub
from modelkit.model import Robot
from modelkit.spatial import Pose

FRAME_SENSORS = frozenset(
    f"frame{x}" for x in ("pos", "quat", "xaxis", "yaxis", "zaxis", "linvel", "angvel", "linacc", "angacc")
)
GEOM_PAIR_SENSORS = frozenset({"geomdist", "geomnormal", "geomfromto"})  # geom1/body1, geom2/body2
NO_OBJECT_SENSORS = frozenset({"clock", "e_potential", "e_kinetic"})
NOT_WRITTEN_SENSORS = frozenset({"user", "plugin", "contact", "tactile"})  # more than names: kept as data
DEVICE_SENSORS = frozenset({"accelerometer", "gyro", "force", "torque", "rangefinder"})  # on a site
SHAPED = frozenset({"touch", "insidesite"})  # read their site's volume
ONE_OBJECT = frozenset({"site", "joint", "tendon", "actuator", "body", "camera"})  # attribute = objtype
ELEMENT = {"jointactfrc": "jointactuatorfrc", "tendonactfrc": "tendonactuatorfrc"}  # enum word → tag
CAMERA_FOVY = 45.0  # MuJoCo's defaults, left out when equal
LIGHT_DEFAULTS: dict[str, Any] = {  # in the order written; MuJoCo's defaults are not written
    "diffuse": [0.7, 0.7, 0.7], "type": "spot", "castshadow": True, "active": True,
    "attenuation": [1.0, 0.0, 0.0], "cutoff": 45.0, "exponent": 10.0, "ambient": [0.0, 0.0, 0.0],
    "specular": [0.3, 0.3, 0.3],
}


@dataclass
class OwnWriter:
    """Writes an MJCF source's own elements back (module docstring) after the body tree."""

    robot: Robot
    ctx: WriteContext
    names: NameTable
    tree: BodyTree
    devices: DeviceWriter
    worldbody: Element
    sensor: Element
    unwritten: dict[str, list[dict[str, Any]]] = field(default_factory=dict)

    def __post_init__(self) -> None:
        self.refs = WrittenObjects(self.robot, self.names, self.tree, self.devices)

    def write_places(self) -> dict[str, list[dict[str, Any]]]:
        """Write the sites, cameras and lights; returns what could not be written, by ``extras`` key."""
        extras = self.robot.extras
        written = {id(s) for s in self.tree.written_sites}
        on_devices = set(self.devices.site_for)
        self.unwritten["mjcf_sites"] = [  # a device's site counts as written: the device wrote one
            s for s in extras.get("mjcf_sites") or []
            if id(s) not in written and s.get("name") not in on_devices
        ]
        self.unwritten["mjcf_world_sites"] = []
        for site in extras.get("mjcf_world_sites") or []:
            self.tree.kept_site(self.worldbody, site, Pose())
        for key in ("mjcf_cameras", "mjcf_lights"):
            kept = extras.get(key) or []
            self.unwritten[key] = [item for item in kept if not self._camera_or_light(key, item)]
        return self.unwritten

    def write_sensors(self) -> dict[str, list[dict[str, Any]]]:
        """Write the sensors (after everything they may name); returns those that could not be."""
        sensors = self.robot.extras.get("mjcf_sensors") or []
        rank = {str(s["name"]): i for i, s in enumerate(sensors) if s.get("name")}  # the devices' too
        unwritten = [s for s in sensors if not self._sensor(s, rank)]
        self._source_order(rank, len(sensors))
        return {"mjcf_sensors": unwritten}

    def _source_order(self, rank: dict[str, int], last: int) -> None:
        """The sensors in the source's order (MuJoCo lays out ``sensordata`` in it): the devices' are
        written with their bodies, in tree order. ``rank``: written name → place in the source; a
        written sensor without one (a device's made-up name) goes after the others, as written."""
        written = list(self.sensor)
        placed = sorted(range(len(written)), key=lambda i: (rank.get(str(written[i].get("name")), last), i))
        if placed != list(range(len(written))):
            for i in placed:
                self.sensor.append(written[i])  # lxml moves the element to the end

    # -- cameras and lights ----------------------------------------------------------------------

    def _camera_or_light(self, key: str, item: dict[str, Any]) -> bool:
        kind = "camera" if key == "mjcf_cameras" else "light"
        target = None
        if item.get("target") is not None:
            target = self.refs.body(str(item["target"]))
            if target is None:
                return False  # MuJoCo needs the target body of a targetbody mode
        link = item.get("link")
        if link is not None:  # a body's: written as a device (unnamed: under a made-up name)
            if link not in self.tree.bodies:
                return False
            el = self.devices.written.get((kind, str(item.get("name"))))
            if el is None:
                return item.get("name") is None
            self._tracking(el, item, target)
            if kind == "light" and item.get("castshadow") is False:
                el.set("castshadow", "false")
            return True
        el = sub(self.worldbody, kind)
        if item.get("name"):
            wanted = str(item["name"])
            el.set("name", self.names.claim(kind, wanted, None, f"worldbody/{kind}[{wanted}]"))
        if kind == "camera":
            set_pose(el, site_pose(item))
            self._tracking(el, item, target)
            self._camera(el, item)
        else:
            el.set("pos", fmt_position([float(x) for x in item["xyz"]]))
            self._tracking(el, item, target)
            self._light(el, item)
        return True

    @staticmethod
    def _tracking(el: Element, item: dict[str, Any], target: str | None) -> None:
        if item.get("mode"):
            el.set("mode", str(item["mode"]))
        if target is not None:
            el.set("target", target)

    @staticmethod
    def _camera(el: Element, item: dict[str, Any]) -> None:
        fovy = float(item.get("fovy", CAMERA_FOVY))
        if fovy != CAMERA_FOVY:
            el.set("fovy", fmt(fovy))
        if item.get("resolution"):
            el.set("resolution", " ".join(str(int(x)) for x in item["resolution"]))
        if item.get("ipd") is not None:
            el.set("ipd", fmt(float(item["ipd"])))

    @staticmethod
    def _light(el: Element, item: dict[str, Any]) -> None:
        el.set("dir", fmt_vec([float(x) for x in item.get("dir", (0.0, 0.0, -1.0))]))
        for key, default in LIGHT_DEFAULTS.items():
            value = item.get(key)
            if isinstance(value, tuple):
                value = list(value)
            if value is None or value == default:
                continue
            if isinstance(value, bool):
                el.set(key, "true" if value else "false")
            elif isinstance(value, list):
                el.set(key, fmt_vec([float(x) for x in value]))
            elif isinstance(value, float):
                el.set(key, fmt(value))
            else:
                el.set(key, str(value))

    # -- sensors ---------------------------------------------------------------------------------

    def _sensor(self, sensor: dict[str, Any], rank: dict[str, int]) -> bool:
        """Write one sensor (``rank`` learns its written name when it differs from the source's)."""
        kind = str(sensor.get("type"))
        if kind in DEVICE_SENSORS and sensor.get("objtype") == "site" and str(sensor.get("object")) in \
                self.devices.site_for:
            return True  # the device wrote it
        attributes = self._references(sensor)
        if attributes is None:
            return False
        el = sub(self.sensor, ELEMENT.get(kind, kind))
        if sensor.get("name"):
            wanted = str(sensor["name"])
            name = self.names.claim("sensor", wanted, None, f"sensor/{kind}[{wanted}]")
            el.set("name", name)
            rank[name] = rank[wanted]
        for key, value in attributes.items():
            el.set(key, value)
        for key in ("cutoff", "noise"):
            if sensor.get(key):
                el.set(key, fmt(float(sensor[key])))
        return True

    def _references(self, sensor: dict[str, Any]) -> dict[str, str] | None:
        """The sensor's object attributes under the written names; ``None`` when one is not written."""
        kind = str(sensor.get("type"))
        objtype, obj = str(sensor.get("objtype")), sensor.get("object")
        reftype, ref = sensor.get("reftype"), sensor.get("refname")
        if kind in NO_OBJECT_SENSORS:
            return {}
        if kind in NOT_WRITTEN_SENSORS or obj is None:
            return None
        shaped = kind in SHAPED
        name = self.refs.object(objtype, str(obj), shaped and kind == "touch")
        other = self.refs.object(str(reftype), str(ref), shaped) if ref is not None else None
        if name is None or (ref is not None and other is None):
            return None
        if kind in FRAME_SENSORS:
            out = {"objtype": objtype, "objname": name}
            if other is not None:
                out.update(reftype=str(reftype), refname=other)
            return out
        if kind in GEOM_PAIR_SENSORS and other is not None:
            return {f"{objtype}1": name, f"{reftype}2": other}
        if kind == "camprojection" and reftype == "camera" and other is not None:
            return {"site": name, "camera": other}
        if kind == "insidesite" and reftype == "site" and other is not None:
            return {"objtype": objtype, "objname": name, "site": other}
        if objtype in ONE_OBJECT and ref is None:
            return {objtype: name}
        return None
