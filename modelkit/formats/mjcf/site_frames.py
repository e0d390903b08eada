"""MJCF sites that are named frames, and the pass that makes them frame links for targets without sites.

The MJCF reader keeps every site of a body in ``robot.extras["mjcf_sites"]`` (its name, the link it is
on, its pose in that link's frame, its type and size). A site is a **named frame** when it has a name
and nothing else uses it: no sensor, equality, actuator transmission or tendon of the source names it
(the reader marks such sites ``used``: the file's sensors and equalities are on its main robot only),
and no device was made of it. The MJCF writer writes named frames back as sites; the frame links of a
model (:mod:`modelkit.convert.frames`) go the other way, MJCF → URDF → MJCF keeps them as sites.
MJCF → MJCF writes back every site (:func:`own_sites`): the used ones too, which the source's own
sensors, written back by :mod:`.write_own`, refer to.

URDF, SDF and ``.body`` have no sites: :func:`sites_as_links` (run by ``convert.api.prepare`` for those
targets, ``WriteOptions.frame_sites``) makes each named frame a massless link on a fixed joint from
its link, named after the site (a URDF link is a TF frame; the SDF writer writes such a link as a
``<frame attached_to>``, MK816). One MK873 note lists them; a name a link or joint already has gets
``_2``... (MK800). The sites made links are taken out of ``mjcf_sites``; the others stay there.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from modelkit.convert.names import unique_name
from modelkit.convert.notes import NoteSink
from modelkit.formats.mjcf.transmissions import transmission_sites
from modelkit.model import Joint, JointType, Link, Robot
from modelkit.spatial import Pose

SITES = "mjcf_sites"


def used_sites(robot: Robot) -> set[str]:
    """Names of the sites something of the source uses (sensors, equalities, actuators, tendons, devices)."""
    extras = robot.extras
    used: set[str] = set()
    for sensor in extras.get("mjcf_sensors") or []:
        if sensor.get("objtype") == "site":
            used.add(str(sensor.get("object")))
    for eq in extras.get("mjcf_equalities") or []:
        if eq.get("objtype") == "site":
            used.update(str(eq.get(key)) for key in ("obj1", "obj2"))
    used |= transmission_sites(extras.get("mjcf_actuators") or [], extras.get("mjcf_tendons") or [])
    for link in robot.links:
        used.update(str(d.params["site"]) for d in link.devices if "site" in d.params)
    used.update(str(s.get("name")) for s in extras.get(SITES) or [] if s.get("used"))  # the reader's mark
    return used


def named_frames(robot: Robot) -> list[dict[str, Any]]:
    """The sites of ``mjcf_sites`` that are named frames on a link of the model, in the source's order."""
    sites = robot.extras.get(SITES) or []
    links = {link.name for link in robot.links}
    used = used_sites(robot)
    return [s for s in sites if s.get("name") and s.get("link") in links and s["name"] not in used]


def device_sites(robot: Robot) -> set[str]:
    """Names of the sites the MJCF reader made devices of (an accelerometer's, a rangefinder's...)."""
    return {str(d.params["site"]) for link in robot.links for d in link.devices if "site" in d.params}


def own_sites(robot: Robot) -> list[dict[str, Any]]:
    """MJCF to MJCF: every site of ``mjcf_sites`` on a link of the model, named or used, but those a
    device was made of (the device writes its own site), in the source's order."""
    links = {link.name for link in robot.links}
    devices = device_sites(robot)
    sites = robot.extras.get(SITES) or []
    return [s for s in sites if s.get("link") in links and s.get("name") not in devices]


def site_pose(site: dict[str, Any]) -> Pose:
    """A site's pose in its link's frame."""
    return Pose(np.asarray(site["rotation"], dtype=float), np.asarray(site["xyz"], dtype=float))


def sites_as_links(robot: Robot, notes: NoteSink) -> None:
    """Each named-frame site a massless link on a fixed joint (module docstring), with one MK873 note."""
    frames = named_frames(robot)
    if not frames:
        return
    link_names = {link.name for link in robot.links}
    joint_names = {joint.name for joint in robot.joints}
    listed = []
    for site in frames:
        wanted = str(site["name"])
        name = unique_name(wanted, link_names)
        if name != wanted:
            notes.rename("site", wanted, name, "a link has the site's name", robot.source, f"link[{name}]")
        joint = unique_name(f"{name}_joint", joint_names)
        robot.links.append(Link(name))
        robot.joints.append(Joint(joint, JointType.FIXED, str(site["link"]), name, origin=site_pose(site)))
        listed.append(f"{name} (on {site['link']})")
    kept = {id(s) for s in frames}
    robot.extras[SITES] = [s for s in robot.extras[SITES] if id(s) not in kept]
    notes.note(
        "MK873",
        f"{len(frames)} MJCF site(s) that name a frame written as massless links on fixed joints (the "
        f"target has no sites): {', '.join(listed)}; --frame-bodies (WriteOptions.frame_sites=False) "
        "leaves them out",
        robot.source,
        "link",
    )
