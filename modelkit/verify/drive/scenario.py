"""Layer 4's scenarios: the built-in command profiles and the scenario files users write.

A scenario file is YAML (schema ``schemas/verify-scenario.schema.json``, explained with examples in
``docs/scenarios.md``). It is read with the project's own YAML reader (:mod:`modelkit.yamltree`), so a
bad file gets diagnostics located at ``file:line:col`` with a stable code, like a model file:
YAML faults keep the reader's codes (MK010 syntax, MK004 empty ...), scenario faults are MK900
(wrong type), MK901 (unknown key), MK902 (value out of range), MK903 (missing key), MK904 (unknown
built-in profile).

Plain YAML scalars are typed as YAML 1.2's core schema does (``0.5`` a number, ``true`` a boolean,
``~`` null); quoted scalars stay strings, so ``duration: "10"`` is a wrong type, not a number.

The built-in profiles are verification.md §1's: 10 s each after 0.5 s of zero-torque settling;
``straight`` v = 0.5 m/s, ``spin`` w = 1 rad/s, ``arc`` v = 0.3 m/s with w = 0.5 rad/s (graded) and
``steps`` (0.3, 0) → (0.3, 0.6) → (0, −1) → (−0.2, 0) → (0.4, −0.4) every 2 s (report-only: its hard
reversals are slip-dominated, §2.1/§6). When the robot has pan/tilt joints, :func:`default_scenario`
moves them during every profile (:data:`PAN_TILT_MOVES`: out and back, so they end where they began).
"""

from __future__ import annotations

import dataclasses
import json
import math
import re
from collections.abc import Iterable
from functools import cache
from importlib import resources
from pathlib import Path
from typing import Any

import jsonschema
from jsonschema.exceptions import ValidationError, best_match

from modelkit.diagnostics import Diagnostic, DiagnosticSink, SourceLocation, did_you_mean, sorted_diagnostics
from modelkit.verify.drive import Command, DriveKind, Profile, Scenario, Tolerances
from modelkit.yamltree import YMap, YNode, YScalar, YSeq, locate, parse_yaml, read_text

BUILTIN_DURATION = 10.0
BUILTIN_SETTLE = 0.5
# Physics steps the profiles may take together, per engine run (the built-in scenario: 42,000 at 1 ms).
# Each number has its range in the schema; this bounds their combination (dt: 1e-5 with 100 profiles
# of 600 s would be 6e9 steps, days of simulation).
MAX_STEPS = 5_000_000

# (t, v, w) of the built-in profiles (verification.md §1)
_BUILTIN: dict[str, tuple[tuple[tuple[float, float, float], ...], bool, str]] = {
    "straight": (((0.0, 0.5, 0.0),), True, "v = 0.5 m/s for 10 s"),
    "spin": (((0.0, 0.0, 1.0),), True, "w = 1 rad/s on the spot for 10 s"),
    "arc": (((0.0, 0.3, 0.5),), True, "v = 0.3 m/s, w = 0.5 rad/s for 10 s"),
    "steps": (
        ((0.0, 0.3, 0.0), (2.0, 0.3, 0.6), (4.0, 0.0, -1.0), (6.0, -0.2, 0.0), (8.0, 0.4, -0.4)),
        False,
        "(v, w) = (0.3, 0) → (0.3, 0.6) → (0, −1) → (−0.2, 0) → (0.4, −0.4), every 2 s; report-only: the "
        "hard reversals are slip-dominated (verification.md §2.1)",
    ),
}
BUILTIN_PROFILES: tuple[str, ...] = tuple(_BUILTIN)

# Pan/tilt joint velocity commands (t, pan, tilt) during the default profiles: out at moderate speed
# for 2 s, back for 2 s, then still (about ±1 rad of pan, ±0.6 rad of tilt at most).
PAN_TILT_MOVES: tuple[tuple[float, float, float], ...] = ((1.0, 0.5, 0.3), (3.0, -0.5, -0.3), (5.0, 0.0, 0.0))

CODES = {"type": "MK900", "unknown": "MK901", "value": "MK902", "required": "MK903", "profile": "MK904"}


# ----------------------------------------------------------------------------------------------------
# Built-in profiles and the default scenario


def builtin_profile(
    name: str,
    pan_tilt: bool = False,
    duration: float | None = None,
    settle: float | None = None,
    graded: bool | None = None,
) -> Profile:
    """A built-in profile by name (KeyError for an unknown one), with pan/tilt moves if asked."""
    steps, grade, description = _BUILTIN[name]
    commands = tuple(Command(t, v, w) for t, v, w in steps)
    if pan_tilt:
        commands = with_pan_tilt(commands, PAN_TILT_MOVES)
        description += "; pan 0.5 rad/s and tilt 0.3 rad/s out from 1 s to 3 s, back from 3 s to 5 s"
    return Profile(
        name,
        BUILTIN_DURATION if duration is None else duration,
        commands,
        BUILTIN_SETTLE if settle is None else settle,
        grade if graded is None else graded,
        description,
    )


def with_pan_tilt(
    commands: Iterable[Command], moves: Iterable[tuple[float, float, float]]
) -> tuple[Command, ...]:
    """Merge (t, pan, tilt) joint commands into a drive command sequence (both held piecewise)."""
    base = sorted(commands, key=lambda c: c.t)
    joint = sorted(moves)
    times = sorted({c.t for c in base} | {m[0] for m in joint})
    out = []
    for t in times:
        drive = [c for c in base if c.t <= t]
        moving = [m for m in joint if m[0] <= t]
        v, w = (drive[-1].v, drive[-1].w) if drive else (0.0, 0.0)
        pan, tilt = (moving[-1][1], moving[-1][2]) if moving else (0.0, 0.0)
        out.append(Command(t, v, w, pan, tilt))
    return tuple(out)


def default_scenario(drive_kind: DriveKind = "wheels", has_pan_tilt: bool = False) -> Scenario:
    """The built-in scenario: straight, spin, arc graded, steps report-only (verification.md §1/§6);
    pan and tilt moving during every profile when the robot has them."""
    profiles = tuple(builtin_profile(name, has_pan_tilt) for name in BUILTIN_PROFILES)
    return Scenario(profiles=profiles, controller="track" if drive_kind == "tracks" else "drive")


# ----------------------------------------------------------------------------------------------------
# Plain data (the report, the PyBullet child process)


def scenario_dict(scenario: Scenario) -> dict[str, Any]:
    """The scenario as plain, deterministic data (JSON-ready; commands as [t, v, w, pan, tilt])."""
    out: dict[str, Any] = {}
    for f in dataclasses.fields(scenario):
        value = getattr(scenario, f.name)
        if f.name == "profiles":
            value = [_profile_dict(p) for p in value]
        elif f.name == "tolerances":
            value = dataclasses.asdict(value)
        out[f.name] = value
    return out


def _profile_dict(profile: Profile) -> dict[str, Any]:
    return {
        "name": profile.name,
        "duration": profile.duration,
        "settle": profile.settle,
        "graded": profile.graded,
        "description": profile.description,
        "commands": [[c.t, c.v, c.w, c.pan, c.tilt] for c in profile.commands],
    }


def scenario_from_dict(data: dict[str, Any]) -> Scenario:
    """The inverse of :func:`scenario_dict`."""
    fields = {f.name for f in dataclasses.fields(Scenario)}
    kwargs = {k: v for k, v in data.items() if k in fields and k not in ("profiles", "tolerances")}
    profiles = tuple(
        Profile(
            p["name"],
            float(p["duration"]),
            tuple(Command(*map(float, c)) for c in p["commands"]),
            float(p.get("settle", BUILTIN_SETTLE)),
            bool(p.get("graded", True)),
            p.get("description", ""),
        )
        for p in data["profiles"]
    )
    return Scenario(profiles=profiles, tolerances=Tolerances(**data.get("tolerances", {})), **kwargs)


# ----------------------------------------------------------------------------------------------------
# Reading a scenario file


@cache
def schema() -> dict[str, Any]:
    """The scenario JSON Schema (draft 2020-12), from the package data (``schemas/`` in a checkout)."""
    try:
        text = resources.files("modelkit").joinpath("data", "verify-scenario.schema.json").read_text("utf-8")
    except FileNotFoundError:  # pragma: no cover - a checkout without the data link
        text = (Path(__file__).resolve().parents[2] / "schemas" / "verify-scenario.schema.json").read_text()
    loaded: dict[str, Any] = json.loads(text)
    return loaded


@cache
def _validator() -> jsonschema.Draft202012Validator:
    return jsonschema.Draft202012Validator(schema())


_INT = re.compile(r"[-+]?[0-9]+|0o[0-7]+|0x[0-9a-fA-F]+")
_FLOAT = re.compile(r"[-+]?(\.[0-9]+|[0-9]+(\.[0-9]*)?)([eE][-+]?[0-9]+)?")
_INF = re.compile(r"[-+]?\.(inf|Inf|INF)")
_NAN = re.compile(r"\.(nan|NaN|NAN)")


def typed(node: YNode) -> Any:
    """A Y-node as plain Python data with YAML 1.2 core typing of plain scalars (quoted: strings)."""
    if isinstance(node, YScalar):
        if not node.plain:
            return node.value
        text = node.value
        if text in ("", "~", "null", "Null", "NULL"):
            return None
        if text in ("true", "True", "TRUE"):
            return True
        if text in ("false", "False", "FALSE"):
            return False
        if _INT.fullmatch(text):
            return int(text, 0) if text[:2] in ("0o", "0x") else int(text)
        if _FLOAT.fullmatch(text):
            return float(text)
        if _INF.fullmatch(text):
            return -math.inf if text.startswith("-") else math.inf
        if _NAN.fullmatch(text):
            return math.nan
        return text
    if isinstance(node, YSeq):
        return [typed(item) for item in node.items]
    assert isinstance(node, YMap)
    return {key: typed(value) for key, value in node.items()}


def load(path: str | Path) -> tuple[Scenario | None, list[Diagnostic]]:
    """Read a scenario file: the scenario (None when the file has an error) and every diagnostic."""
    name = str(path)
    sink = DiagnosticSink()
    text = read_text(Path(path), sink, display=name)
    if text is None:
        return None, sorted_diagnostics(sink.items)
    document = parse_yaml(text, name, sink)
    if document.root is None:
        return None, sorted_diagnostics(sink.items)
    root = document.root
    if not isinstance(root, YMap):
        sink.emit("MK017", "the top-level node of a scenario must be a mapping", root.loc)
        return None, sorted_diagnostics(sink.items)
    data = typed(root)
    errors = list(_validator().iter_errors(data))
    for error in errors:
        _report(error, root, name, sink)
    if not errors:
        _check_values(data, root, sink)
    if any(d.severity.value == "error" for d in sink.items):
        return None, sorted_diagnostics(sink.items)
    return _build(data, name), sorted_diagnostics(sink.items)


def _label(path: tuple[str | int, ...]) -> str:
    out = ""
    for step in path:
        out += f"[{step}]" if isinstance(step, int) else (f".{step}" if out else step)
    return out or "the scenario"


def _loc(root: YNode, path: tuple[str | int, ...], key: bool = False) -> SourceLocation:
    value, key_node = locate(root, path)
    node = key_node if key and key_node is not None else value
    return node.loc if node is not None else root.loc


def _show(value: Any) -> str:
    if isinstance(value, str):
        return f'the string "{value}"'
    if isinstance(value, bool):
        return f"the boolean {str(value).lower()}"
    if value is None:
        return "nothing (null)"
    if isinstance(value, dict):
        return "a mapping"
    if isinstance(value, list):
        return "a list"
    return f"{value:g}" if isinstance(value, float) else str(value)


_EXPECTED = {
    "number": "a number",
    "string": "a string",
    "boolean": "true or false",
    "object": "a mapping",
    "array": "a list",
    "integer": "an integer",
}


def _report(error: ValidationError, root: YMap, name: str, sink: DiagnosticSink) -> None:
    """One jsonschema error as a located diagnostic."""
    if error.validator in ("anyOf", "oneOf") and error.context:
        if _is_profile_name(error):
            _unknown_profile(error, root, sink)
            return
        for inner in _matching_branch(error):
            _report(inner, root, name, sink)
        return
    path = tuple(error.absolute_path)
    label = _label(path)
    kind = error.validator
    if kind == "additionalProperties":
        known = sorted(error.schema.get("properties", {}))
        assert isinstance(error.instance, dict)
        for key in error.instance:
            if key not in known:
                sink.emit(
                    CODES["unknown"],
                    f'{label}: unknown key "{key}" (known: {", ".join(known)})',
                    _loc(root, (*path, key), key=True),
                    did_you_mean(key, known),
                )
    elif kind == "type":
        expected = _EXPECTED.get(str(error.validator_value), str(error.validator_value))
        sink.emit(
            CODES["type"],
            f"{label}: expected {expected}, got {_show(error.instance)}",
            _loc(root, path),
            'a quoted scalar is a string: write 0.5, not "0.5"'
            if isinstance(error.instance, str) and _FLOAT.fullmatch(error.instance)
            else None,
        )
    elif kind == "required":
        assert isinstance(error.validator_value, list) and isinstance(error.instance, dict)
        for missing in error.validator_value:
            if missing not in error.instance:
                sink.emit(CODES["required"], f'{label}: missing required key "{missing}"', _loc(root, path))
    elif kind == "enum":
        words = [str(w) for w in error.validator_value]
        sink.emit(
            CODES["value"],
            f"{label}: {_show(error.instance)} is not one of {', '.join(words)}",
            _loc(root, path),
            did_you_mean(str(error.instance), words),
        )
    elif kind in ("minimum", "exclusiveMinimum", "maximum", "exclusiveMaximum"):
        relation = {
            "minimum": "at least",
            "exclusiveMinimum": "above",
            "maximum": "at most",
            "exclusiveMaximum": "below",
        }[kind]
        sink.emit(
            CODES["value"],
            f"{label}: {_show(error.instance)} must be {relation} {error.validator_value:g}",
            _loc(root, path),
        )
    elif kind in ("minItems", "maxItems"):
        sink.emit(CODES["value"], f"{label}: {error.message}", _loc(root, path))
    else:
        sink.emit(CODES["value"], f"{label}: {error.message}", _loc(root, path))


def _matching_branch(error: ValidationError) -> list[ValidationError]:
    """The errors of the ``anyOf`` branch meant by the value's shape (a list or a mapping): the first
    branch whose failure is not a mismatch of the value itself (a wrong type or enum at its path)."""
    branches: dict[int, list[ValidationError]] = {}
    for inner in error.context or ():
        branches.setdefault(int(inner.relative_schema_path[0]), []).append(inner)
    here = tuple(error.absolute_path)
    for _, errors in sorted(branches.items()):
        if not any(e.validator in ("type", "enum") and tuple(e.absolute_path) == here for e in errors):
            return errors
    return [best_match(error.context or ())]


def _is_profile_name(error: ValidationError) -> bool:
    """An entry of ``profiles`` given as a string that is no built-in name."""
    path = tuple(error.absolute_path)
    return len(path) == 2 and path[0] == "profiles" and isinstance(error.instance, str)


def _unknown_profile(error: ValidationError, root: YMap, sink: DiagnosticSink) -> None:
    path = tuple(error.absolute_path)
    word = str(error.instance)
    sink.emit(
        CODES["profile"],
        f'{_label(path)}: "{word}" is not a built-in profile ({", ".join(BUILTIN_PROFILES)}); a profile '
        "of your own is a mapping with a name and commands",
        _loc(root, path),
        did_you_mean(word, BUILTIN_PROFILES),
    )


def _check_values(data: dict[str, Any], root: YMap, sink: DiagnosticSink) -> None:
    """What the schema cannot say: increasing command times below the duration, commands for every
    profile that is not built in, unique profile names."""
    seen: dict[str, int] = {}
    for i, entry in enumerate(data.get("profiles", [])):
        if isinstance(entry, str):
            entry = {"name": entry}
        name = entry["name"]
        where: tuple[str | int, ...] = ("profiles", i)
        if name in seen:
            sink.emit(
                CODES["value"],
                f'{_label(where)}: profile name "{name}" is used twice (first at profiles[{seen[name]}])',
                _loc(root, (*where, "name") if len(entry) > 1 else where),
            )
        seen.setdefault(name, i)
        commands = entry.get("commands")
        if commands is None:
            if name not in _BUILTIN:
                sink.emit(
                    CODES["required"],
                    f'{_label(where)}: profile "{name}" is not built in, so it needs "commands"',
                    _loc(root, where),
                    did_you_mean(name, BUILTIN_PROFILES),
                )
            continue
        duration = float(entry.get("duration", BUILTIN_DURATION))
        previous = -math.inf
        for k, command in enumerate(commands):
            t = float(command[0] if isinstance(command, list) else command["t"])
            at = (*where, "commands", k)
            if not math.isfinite(t) or t <= previous:
                sink.emit(
                    CODES["value"],
                    f"{_label(at)}: t = {t:g} s must be after the previous command's "
                    f"{previous:g} s (commands in increasing time)",
                    _loc(root, at),
                )
            elif t >= duration:
                sink.emit(
                    CODES["value"],
                    f"{_label(at)}: t = {t:g} s is not before the profile's duration {duration:g} s",
                    _loc(root, at),
                )
            previous = t
            values = command if isinstance(command, list) else list(command.values())
            if any(isinstance(x, float) and not math.isfinite(x) for x in values):
                sink.emit(CODES["value"], f"{_label(at)}: values must be finite", _loc(root, at))
    _check_steps(data, root, sink)


def _check_steps(data: dict[str, Any], root: YMap, sink: DiagnosticSink) -> None:
    """MK902 when the profiles take more than :data:`MAX_STEPS` physics steps at the scenario's dt."""
    simulation = data.get("simulation", {})
    dt = float(simulation.get("dt", Scenario(profiles=()).dt))
    seconds = 0.0
    for entry in data.get("profiles", BUILTIN_PROFILES):
        entry = {"name": entry} if isinstance(entry, str) else entry
        seconds += float(entry.get("duration", BUILTIN_DURATION)) + float(entry.get("settle", BUILTIN_SETTLE))
    steps = seconds / dt
    if steps > MAX_STEPS:
        where: tuple[str | int, ...] = ("simulation", "dt") if "dt" in simulation else ("profiles",)
        sink.emit(
            CODES["value"],
            f"the profiles simulate {seconds:g} s at dt = {dt:g} s: {steps:.3g} physics steps, more than "
            f"{MAX_STEPS:,} per engine run",
            _loc(root, where),
            hint="a larger dt, fewer or shorter profiles",
        )


def _build(data: dict[str, Any], source: str) -> Scenario:
    profiles = []
    for entry in data.get("profiles", BUILTIN_PROFILES):
        if isinstance(entry, str):
            entry = {"name": entry}
        name = entry["name"]
        if "commands" not in entry:
            profiles.append(
                builtin_profile(
                    name,
                    False,
                    _float_or_none(entry.get("duration")),
                    _float_or_none(entry.get("settle")),
                    entry.get("graded"),
                )
            )
            profiles[-1] = dataclasses.replace(
                profiles[-1], description=entry.get("description", profiles[-1].description)
            )
            continue
        commands = tuple(_command(c) for c in entry["commands"])
        profiles.append(
            Profile(
                name,
                float(entry.get("duration", BUILTIN_DURATION)),
                commands,
                float(entry.get("settle", BUILTIN_SETTLE)),
                bool(entry.get("graded", True)),
                str(entry.get("description", "")),
            )
        )
    controller = data.get("controller", {})
    robot = data.get("robot", {})
    contact = data.get("contact", {})
    simulation = data.get("simulation", {})
    defaults = Scenario(profiles=())
    return Scenario(
        profiles=tuple(profiles),
        controller=controller.get("type"),
        kd=float(controller.get("kd", defaults.kd)),
        pan_tilt_kd=float(controller.get("pan_tilt_kd", defaults.pan_tilt_kd)),
        tester_torque=float(controller.get("tester_torque", defaults.tester_torque)),
        wheel_radius=_float_or_none(robot.get("wheel_radius")),
        half_axle=_float_or_none(robot.get("half_axle")),
        left=robot.get("left"),
        right=robot.get("right"),
        pan=robot.get("pan"),
        tilt=robot.get("tilt"),
        friction=_float_or_none(contact.get("friction")),
        wheel_proxy=contact.get("wheel_proxy", defaults.wheel_proxy),
        native_report=bool(contact.get("native_report", defaults.native_report)),
        dt=float(simulation.get("dt", defaults.dt)),
        sample_rate=float(simulation.get("sample_rate", defaults.sample_rate)),
        tolerances=Tolerances(**{k: float(v) for k, v in data.get("tolerances", {}).items()}),
        source=source,
    )


def _float_or_none(value: Any) -> float | None:
    return None if value is None else float(value)


def _command(item: list[float] | dict[str, float]) -> Command:
    if isinstance(item, list):
        return Command(*(float(x) for x in item))
    return Command(
        float(item["t"]),
        float(item.get("v", 0.0)),
        float(item.get("w", 0.0)),
        float(item.get("pan", 0.0)),
        float(item.get("tilt", 0.0)),
    )
