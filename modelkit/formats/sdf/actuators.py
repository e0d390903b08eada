"""Gazebo's joint-controller systems of a model as the robot's canonical actuators.

SDF has no actuator element: Gazebo drives a joint through a model ``<plugin>``. The gz-sim systems
that drive one joint each (their parameters as gz-sim's sources read them; names with the
``gz-sim-`` prefix, or ``ignition-gazebo-`` / ``ignition::gazebo::`` of Fortress and older):

* ``JointPositionController`` (``gz-sim-joint-position-controller-system``): a PID on the position
  error gives the joint force, ``force = −p·e − i·∫e − d·ė`` (``e`` = position − target), clamped to
  ``[cmd_min, cmd_max]`` when ``cmd_max ≥ cmd_min``. Position actuator, ``kp`` = ``p_gain``, ``kv`` =
  ``d_gain`` (with a constant target ``ė`` is the joint velocity), force range = the clamp. gz-sim's
  defaults when a gain is absent (p 1, i 0.1, d 0.01, clamp ±1000) are not copied into the model: a
  gain left out stays None. ``<use_velocity_commands>`` bypasses the PID (the joint is moved at up to
  ``cmd_max``): no gains, no force range.
* ``JointController`` (``gz-sim-joint-controller-system``): velocity mode by default (the physics
  engine is told the target velocity: no gains); with ``<use_force_commands>`` a PID on the velocity
  error gives the force, clamped to ``[cmd_min, cmd_max]``: velocity actuator with ``kv`` = ``p_gain``.
* ``ApplyJointForce`` (``gz-sim-apply-joint-force-system``): the command is the joint force: effort.

Each ``<joint_name>`` (JointPositionController and JointController take several, "for identical
joints") that names a joint of the model gets one actuator. Parameters with no canonical field
(``i_gain``, ``i_max``, ``cmd_offset``, ``topic``, ``initial_position``...) stay in the plugin's verbatim
copy (``extras["sdf_plugins"]``), which the SDF writer merges back. Gazebo classic ships no such
per-joint system (its robots are driven by ``gazebo_ros_control`` from URDF transmissions).
"""

from __future__ import annotations

import math
from typing import Any

from lxml.etree import _Element as Element

from modelkit.formats.sdf.document import SdfDocument
from modelkit.formats.sdf.values import child, children
from modelkit.model import Actuator, ActuatorKind, Robot
from modelkit.xmlsource import parse_number

# system → (kind, the word its filename and class name carry)
SYSTEMS = {
    "JointPositionController": "joint-position-controller",
    "JointController": "joint-controller",
    "ApplyJointForce": "apply-joint-force",
}
SIM_PREFIXES = ("gz-sim-", "ignition-gazebo-", "libignition-gazebo-", "libgz-sim-")


def system_of(filename: str, name: str) -> str | None:
    """``JointPositionController``, ``JointController``, ``ApplyJointForce`` or None."""
    file_word = filename.strip().lower()
    for prefix in SIM_PREFIXES:
        if file_word.startswith(prefix):
            file_word = file_word[len(prefix):]
            break
    else:
        file_word = ""
    file_word = file_word.removesuffix(".so").removesuffix("-system")
    file_word = "".join(c for c in file_word if not c.isdigit()).rstrip("-")  # ignition-gazebo6-...
    class_word = name.strip().rsplit("::", 1)[-1]
    for system, word in SYSTEMS.items():
        if file_word == word or (class_word == system and "::systems::" in name):
            return system
    return None


def _number(el: Element, tag: str) -> float | None:
    found = child(el, tag)
    value = parse_number((found.text or "").strip()) if found is not None else None
    return value if value is not None and math.isfinite(value) else None


def _flag(el: Element, tag: str) -> bool:
    found = child(el, tag)
    return found is not None and (found.text or "").strip().lower() in ("1", "true")


def _clamp(el: Element) -> tuple[float, float] | None:
    high, low = _number(el, "cmd_max"), _number(el, "cmd_min")
    high = 1000.0 if high is None else high  # gz-sim's defaults when one side is given
    low = -1000.0 if low is None else low
    if _number(el, "cmd_max") is None and _number(el, "cmd_min") is None:
        return None
    return (low, high) if high >= low else None


def plugin_actuators(src: SdfDocument, el: Element, joints: set[str]) -> list[Actuator]:
    """The actuators one model ``<plugin>`` stands for (none: not a joint-controller system)."""
    system = system_of(el.get("filename") or "", el.get("name") or "")
    if system is None:
        return []
    names = [(c.text or "").strip() for c in children(el, "joint_name")]
    out: list[Actuator] = []
    for joint in names:
        if joint not in joints or any(a.joint == joint for a in out):
            continue
        actuator = Actuator(joint=joint, source=src.values.loc(el), source_kind=f"gz-sim {system}")
        if system == "JointPositionController":
            actuator.kind = ActuatorKind.POSITION
            if _flag(el, "use_velocity_commands"):
                actuator.source_kind += " (velocity commands)"
            else:
                actuator.kp, actuator.kv = _number(el, "p_gain"), _number(el, "d_gain")
                actuator.force_range = _clamp(el)
        elif system == "JointController":
            actuator.kind = ActuatorKind.VELOCITY
            if _flag(el, "use_force_commands"):
                actuator.source_kind += " (force commands)"
                actuator.kv = _number(el, "p_gain")
                actuator.force_range = _clamp(el)
            else:
                actuator.source_kind += " (velocity mode)"
        else:
            actuator.kind = ActuatorKind.EFFORT
        out.append(actuator)
    return out


def read_actuators(robot: Robot, plugins: list[tuple[SdfDocument, Element, dict[str, Any]]]) -> None:
    """Fill ``robot.actuators`` from the model's plugins (document order; the first plugin naming a
    joint wins) and mark each plugin dict that became actuators with ``actuates`` (joint names)."""
    joints = {j.name for j in robot.joints}
    found: dict[str, Actuator] = {}
    for src, el, data in plugins:
        taken = [a for a in plugin_actuators(src, el, joints) if a.joint not in found]
        for actuator in taken:
            found[actuator.joint] = actuator
        if taken:
            data["actuates"] = [a.joint for a in taken]
    if found:
        robot.actuators = list(found.values())
