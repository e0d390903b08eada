"""MoveIt's SRDF beside a URDF: its named joint states give the robot's home pose (``--srdf``, ``--home``).

A URDF says where each joint can go, never where the robot rests; MoveIt users keep that in the SRDF
as ``<group_state name="ready" group="arm"><joint name="joint1" value="0.3"/>...</group_state>``. The
state chosen becomes the joints' initial positions, so every writer's home follows it: the MJCF
``home`` keyframe and its servo targets, the gains made at home, the ``.body`` initial angles.

Which state: the one ``--home`` names; without ``--home``, the first of :data:`PREFERRED_STATES` the
file holds, else its only state, else none (a note lists the states). Several states of one name (one
per group) are merged in document order. A hinge's value outside its range that a whole turn brings
into it is written so (the same orientation; Kinova's SRDF gives -1.5707 for a joint whose range is
[0.33, 5.95]), an info. A joint the robot does not move, a value that is not a number and a value
still outside the joint's range (the writers clamp it) are warnings (MK149); a ``--home`` state the
file does not hold is an error (MK148) naming those it holds; the state used, or that none was found,
is an info (MK147).

``<disable_collisions link1 link2 reason>`` pairs become the robot's collision exclusions (the MJCF
writer excludes them, MK866; the other targets have no per-pair exclusion and say so); a pair naming
a link the robot lacks is not used (MK126, a warning). Groups and end effectors are not used.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from modelkit.diagnostics import DiagnosticSink, Severity, SourceLocation
from modelkit.model import CollisionExclusion, JointType, Robot
from modelkit.xmlsource import parse_number, read_xml

PREFERRED_STATES = ("home", "ready", "default", "standing", "half_sitting")
"""The state used when ``--home`` names none: the first of these the SRDF holds (MoveIt's usual names,
and example-robot-data's for legged robots and humanoids), else its only state when it has one."""


@dataclass
class JointState:
    """One named joint state of an SRDF: joint → value (rad or m), with where each value is written."""

    name: str
    values: dict[str, float] = field(default_factory=dict)
    where: dict[str, SourceLocation] = field(default_factory=dict)
    groups: list[str] = field(default_factory=list)


@dataclass
class SrdfFile:
    """What modelkit uses of an SRDF: its named joint states and its disabled collision pairs."""

    states: dict[str, JointState]
    exclusions: list[CollisionExclusion]


def read_srdf(path: Path, sink: DiagnosticSink, max_bytes: int) -> SrdfFile | None:
    """The SRDF at ``path`` (None when the file cannot be read or parsed: said in ``sink``)."""
    doc = read_xml(path, sink, max_bytes)
    if doc is None:
        return None
    if doc.root.tag != "robot":
        sink.emit("MK148", f"an SRDF has a <robot> top element; this file's is <{doc.root.tag}>",
                  doc.loc(doc.root))
        return None
    exclusions = [CollisionExclusion(element.get("link1", ""), element.get("link2", ""),
                                     element.get("reason", ""), doc.loc(element))
                  for element in doc.root.iter("disable_collisions")]
    return SrdfFile(_states(doc, sink), exclusions)


def _states(doc: Any, sink: DiagnosticSink) -> dict[str, JointState]:
    """The ``<group_state>``s by name."""
    states: dict[str, JointState] = {}
    for element in doc.root.iter("group_state"):
        name = element.get("name", "")
        state = states.setdefault(name, JointState(name))
        state.groups.append(element.get("group", ""))
        for joint in element.iter("joint"):
            value = parse_number(joint.get("value"))
            joint_name = joint.get("name", "")
            if value is None or not math.isfinite(value):
                sink.emit("MK149", f'group_state "{name}": joint "{joint_name}" has no finite value '
                          f'({joint.get("value")!r}); it is not set', doc.loc(joint, "value"),
                          severity=Severity.WARNING)
                continue
            state.values[joint_name] = value
            state.where[joint_name] = doc.loc(joint, "value")
    return states


def chosen_state(states: dict[str, JointState], wanted: str | None) -> JointState | None:
    """The state ``wanted`` names, or the first of :data:`PREFERRED_STATES` the file holds."""
    if wanted is not None:
        return states.get(wanted)
    preferred = next((states[name] for name in PREFERRED_STATES if name in states), None)
    if preferred is None and len(states) == 1:
        return next(iter(states.values()))
    return preferred


def apply_srdf(robot: Robot, srdf: Path, wanted: str | None, sink: DiagnosticSink, max_bytes: int) -> None:
    """Set ``robot``'s joint initial positions from the SRDF state chosen and its collision exclusions
    from the disabled pairs (see the module docstring)."""
    read = read_srdf(srdf, sink, max_bytes)
    if read is None:
        return
    _apply_exclusions(robot, read.exclusions, sink)
    _apply_home(robot, read.states, str(srdf), wanted, sink)


def _apply_exclusions(robot: Robot, exclusions: list[CollisionExclusion], sink: DiagnosticSink) -> None:
    """The pairs whose links the robot has become its collision exclusions; the others are said once
    (an SRDF written for another variant of the robot names links this one lacks)."""
    links = {link.name for link in robot.links}
    unused: list[tuple[CollisionExclusion, str]] = []
    for pair in exclusions:
        unknown = next((name for name in (pair.link1, pair.link2) if name not in links), None)
        if unknown is not None:
            unused.append((pair, unknown))
        elif pair.link1 != pair.link2:
            robot.collision_exclusions.append(pair)
    if unused:
        shown = ", ".join(f"{pair.link1!r}-{pair.link2!r} ({name!r})" for pair, name in unused[:3])
        more = " ..." if len(unused) > 3 else ""
        sink.emit("MK126", f"{len(unused)} disable_collisions pair(s) name a link the robot lacks and are "
                  f"not used: {shown}{more}", unused[0][0].source or SourceLocation(""),
                  severity=Severity.WARNING)


def _apply_home(robot: Robot, states: dict[str, JointState], shown: str, wanted: str | None,
                sink: DiagnosticSink) -> None:
    state = chosen_state(states, wanted)
    held = ", ".join(f'"{name}"' for name in states) or "none"
    if state is None:
        if wanted is not None:
            sink.emit("MK148", f'--home "{wanted}": the SRDF has no such group_state (it has {held})',
                      SourceLocation(shown))
        else:
            sink.emit("MK147", f"the SRDF has no state named {', '.join(PREFERRED_STATES)} and more than one "
                      f"state: the home pose stays q = 0 (its states: {held}; choose one with --home)",
                      SourceLocation(shown),
                      severity=Severity.INFO)
        return
    joints = {joint.name: joint for joint in robot.joints}
    applied = 0
    for name, value in state.values.items():
        joint = joints.get(name)
        where = state.where[name]
        if joint is None or not joint.type.moves:
            what = "no joint" if joint is None else f"a {joint.type.value} joint"
            sink.emit("MK149", f'group_state "{state.name}": "{name}" is {what} of the robot; the value is '
                      "not used", where, severity=Severity.WARNING)
            continue
        lower, upper = joint.limits.lower, joint.limits.upper
        if math.isfinite(lower) and math.isfinite(upper) and lower <= upper and not lower <= value <= upper:
            turned = _turned_into(value, lower, upper) if joint.type is JointType.REVOLUTE else None
            if turned is not None:
                sink.emit("MK149", f'group_state "{state.name}": joint "{name}" at {value:g} is outside its '
                          f"range [{lower:g}, {upper:g}]; used as {turned:g}, the same orientation a whole "
                          "turn away, inside it", where, severity=Severity.INFO)
                value = turned
            else:
                sink.emit("MK149", f'group_state "{state.name}": joint "{name}" at {value:g} is outside its '
                          f"range [{lower:g}, {upper:g}]; the writers put it at the nearer bound", where,
                          severity=Severity.WARNING)
        joint.initial_position = value
        applied += 1
    for joint in robot.joints:  # a mimic joint follows its leader's home (MoveIt lists leaders only)
        if joint.mimic is not None and joint.name not in state.values and joint.mimic.joint in state.values:
            leader = joints[joint.mimic.joint].initial_position
            joint.initial_position = joint.mimic.multiplier * leader + joint.mimic.offset
    groups = ", ".join(g for g in dict.fromkeys(state.groups) if g) or "no group"
    sink.emit("MK147", f'home pose: SRDF group_state "{state.name}" ({groups}) sets {applied} joint(s)',
              SourceLocation(shown), severity=Severity.INFO)


def _turned_into(value: float, lower: float, upper: float) -> float | None:
    """``value`` plus the whole turns that bring it into [lower, upper], or None when none does."""
    turns = math.ceil((lower - value) / math.tau) if value < lower else -math.ceil((value - upper) / math.tau)
    turned = value + turns * math.tau
    return turned if lower <= turned <= upper else None
