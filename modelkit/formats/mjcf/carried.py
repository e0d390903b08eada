"""What of an MJCF source's kept lists the model's own fields carry to another target.

``extras["mjcf_actuators"]``, ``mjcf_sensors``, ``mjcf_cameras``, ``mjcf_lights`` and ``mjcf_sites`` hold
everything the file had; part of it is also in the model (canonical actuators, devices on links, frame
sites made links), which the SDF and ``.body`` writers write. Each function gives, from a kept list and
its robot, the part those targets still leave out, for ``convert``'s note (the MJCF declaration's
``carried_to``; the URDF writer counts the same part itself).
"""

from __future__ import annotations

from typing import Any

from modelkit.model import Robot


def actuators_left(value: list[dict[str, Any]], robot: Robot) -> list[dict[str, Any]]:
    """The actuators the model does not hold as canonical actuators (site transmissions, tendons whose
    joints do not follow one joint, activation dynamics, other laws)."""
    return [a for a in value if not (isinstance(a, dict) and (a.get("canonical") or a.get("as_joint")))]


def sensors_left(value: list[dict[str, Any]], robot: Robot) -> list[dict[str, Any]]:
    """The sensors no device on a link stands for (an accelerometer, gyro, rangefinder or force/torque
    pair of a site is one)."""
    carried: set[str] = set()
    for link in robot.links:
        for device in link.devices:
            carried.add(device.name)
            pair = ("force_sensor", "torque_sensor")  # a force/torque device's two sensors
            carried.update(str(device.params[k]) for k in pair if k in device.params)
    return [s for s in value if not (isinstance(s, dict) and s.get("name") in carried)]


def on_links_left(value: list[dict[str, Any]], robot: Robot) -> list[dict[str, Any]]:
    """The cameras or lights that are not a device of their link (those of the world body)."""
    on_links = {(link.name, device.name) for link in robot.links for device in link.devices}
    return [v for v in value if not (isinstance(v, dict) and (v.get("link"), v.get("name")) in on_links)]


def sites_left(value: list[dict[str, Any]], robot: Robot) -> list[dict[str, Any]]:
    """The sites left once those naming frames became links (``convert`` takes them out of the list):
    all but the sites of devices, which the device's pose carries."""
    device_sites = {str(d.params["site"]) for link in robot.links for d in link.devices if "site" in d.params}
    return [s for s in value if not (isinstance(s, dict) and s.get("name") in device_sites)]


def equalities_left(value: list[dict[str, Any]], robot: Robot) -> list[dict[str, Any]]:
    """The equalities that are not a joint coupling the model holds as a mimic (one joint follows the
    other, as the reader made it of the equality: usually ``joint1`` follows ``joint2``, the other
    way when the source actuates ``joint1``), nor a linear one between two joints that follow the same
    joint (:func:`held_by_mimics`)."""
    leads = {j.name: j.mimic.joint for j in robot.joints if j.mimic is not None}
    return [e for e in value if not (isinstance(e, dict) and held_by_mimics(e, leads))]


def held_by_mimics(equality: dict[str, Any], leads: dict[str, str]) -> bool:
    """Whether the mimics ``leads`` (follower → leader) hold this source equality: a joint equality
    between a follower and its leader, or a linear one between two joints that follow the same joint (a
    group the MJCF reader read from its actuated joint, whose composed mimics imply it)."""
    if equality.get("type") != "joint":
        return False
    one, two = equality.get("obj1"), equality.get("obj2")
    if leads.get(str(one)) == two or leads.get(str(two)) == one:
        return True
    return is_linear(equality) and str(one) in leads and leads[str(one)] == leads.get(str(two), two)


def is_linear(equality: dict[str, Any]) -> bool:
    """Whether a joint equality's polynomial has only its constant and linear terms."""
    data = equality.get("data") or []
    return len(data) >= 5 and not any(abs(float(c)) > 0.0 for c in data[2:5])
