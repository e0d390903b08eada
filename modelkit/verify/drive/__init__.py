"""Layer 4's shared vocabulary: command profiles, scenarios, the drive a controller needs, the
controller contract and the trajectories every engine and reference produces.

Data only (plus small helpers): the modules that do the work import these types.

* :mod:`modelkit.verify.drive.scenario` reads scenario YAML files (schema
  ``schemas/verify-scenario.schema.json``) into :class:`Scenario` and holds the default profiles;
* :mod:`modelkit.verify.drive.vehicle` derives a :class:`Drive` from a model (wheel or track joints,
  radius, half axle width, pan/tilt joints);
* :mod:`modelkit.verify.drive.controllers` holds the seed tutorial's controllers (:class:`Controller`),
  built from plain data by ``make_controllers(drive, scenario)`` so that an engine's child process
  can build the same ones;
* :mod:`modelkit.verify.drive.reference` integrates the rigid no-slip model and the ideal unicycle
  and computes wheel odometry;
* ``engine_mujoco.driver`` / ``engine_pybullet.driver`` run a profile with contact on a floor and
  return a :class:`Trajectory`;
* :mod:`modelkit.verify.drive.variant` writes the verification variant (sphere wheel proxies) of the
  converted model;
* :mod:`modelkit.verify.layers.layer4` runs every profile in every engine, compares, and returns
  ``Check`` (pass/fail) and ``Observation`` (reported only) records plus the trajectories for the
  report's plots.

Conventions: SI units, radians. Joint names are the **source** model's names (engines map them
through their renames). A trajectory's planar pose ``x, y, yaw`` is the root link frame's (not the
COM's), expressed relative to the pose at command start (after settling), so every trajectory
starts at (0, 0, 0).
"""

from __future__ import annotations

import bisect
import math
from dataclasses import dataclass, field
from typing import Any, Literal, Protocol

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]

DriveKind = Literal["wheels", "tracks"]
ControlMode = Literal["torque", "velocity"]
WheelProxy = Literal["sphere", "native"]


@dataclass(frozen=True)
class Command:
    """What the operator commands from time ``t`` (seconds after settling) until the next command:
    the seed's ``cmd_vel`` (``v`` m/s forward, ``w`` rad/s yaw rate) and ``cmd_joint_vel``
    (``pan``, ``tilt``: joint velocities in rad/s, as the seed's pan-tilt controller reads them)."""

    t: float
    v: float = 0.0
    w: float = 0.0
    pan: float = 0.0
    tilt: float = 0.0


@dataclass(frozen=True)
class Profile:
    """A command profile: commands held piecewise constant (zero-order hold), ``duration`` seconds
    after ``settle`` seconds of zero torque on the floor. ``graded`` False: run and reported, never
    pass/fail (slip-dominated reversals, as verification.md §6 advises)."""

    name: str
    duration: float
    commands: tuple[Command, ...]
    settle: float = 0.5
    graded: bool = True
    description: str = ""

    def at(self, t: float) -> Command:
        """The command in force at time ``t`` (the last one with ``command.t <= t``; zeros before the
        first)."""
        times = [c.t for c in self.commands]
        i = bisect.bisect_right(times, t) - 1
        return self.commands[i] if i >= 0 else Command(0.0)


def command_steps(profile: Profile, dt: float, steps: int) -> dict[int, Command]:
    """Step index → the command that takes over at that step (zero-order hold at the physics rate:
    a command at time t acts from the first step k with k·dt ≥ t). The drivers and the references
    all use this, so they switch at the same step."""
    out: dict[int, Command] = {}
    for command in profile.commands:
        k = max(0, math.ceil(command.t / dt - 1e-9))
        if k <= steps:
            out[k] = command
    return out


@dataclass(frozen=True)
class Tolerances:
    """Pass thresholds of layer 4 (verification.md §6), metres and radians."""

    engines_position: float = 0.01
    engines_yaw: float = 0.010
    engines_wheel: float = 0.02
    noslip_position: float = 0.015
    noslip_yaw: float = 0.015


@dataclass(frozen=True)
class Scenario:
    """Everything layer 4 runs: profiles, controller parameters (None = derived from the model),
    contact and time-step settings, tolerances. ``source`` is the scenario file (None: built in)."""

    profiles: tuple[Profile, ...]
    controller: Literal["drive", "drive-tester", "track"] | None = None  # None: by the drive kind
    kd: float = 0.5  # drive controller gain (seed: 0.5)
    pan_tilt_kd: float = 0.1  # pan-tilt velocity controller gain (seed: 0.1)
    tester_torque: float = 1.0  # drive tester: constant wheel torque (seed: 1.0 N m)
    wheel_radius: float | None = None
    half_axle: float | None = None
    left: str | None = None  # drive joints (source names); None: found in the model
    right: str | None = None
    pan: str | None = None
    tilt: str | None = None
    friction: float | None = None  # wheel–floor friction; None: from the model's contact materials
    wheel_proxy: WheelProxy = "sphere"
    # Also run what ``convert --wheel-collision cylinder`` writes, report-only. Off by default: a
    # run of a file the user did not get costs 0.4 s of a 5 s verify and grades nothing.
    native_report: bool = False
    dt: float = 1e-3
    sample_rate: float = 100.0  # Hz, trajectory samples
    tolerances: Tolerances = field(default_factory=Tolerances)
    source: str | None = None


@dataclass(frozen=True)
class Drive:
    """What the controllers and the references need to know about a mobile robot (source names).

    ``kind`` "wheels": ``left``/``right`` are the wheel joints; "tracks": they are the pseudo
    continuous track joints of the source, and ``rollers`` maps each to the roller joints that
    ``convert`` wrote for it (roller 0 first), of radius ``roller_radius``.
    ``half_axle`` is b (half the distance between the wheel or track centres, along the root's Y);
    ``track_offset_y`` is the seed's ``trackUnits[0]->offsetTranslation().y()`` (left track).
    ``sign`` maps a joint's positive rotation to forward motion: +1 when a positive joint velocity
    drives that side forward, −1 when the axis is reversed (per joint, in ``signs``)."""

    kind: DriveKind
    left: str
    right: str
    radius: float
    half_axle: float
    wheel_links: tuple[str, str]
    signs: tuple[float, float] = (1.0, 1.0)
    pan: str | None = None
    tilt: str | None = None
    rollers: dict[str, tuple[str, ...]] = field(default_factory=dict)
    roller_radius: float = 0.0
    track_offset_y: float = 0.0
    casters: tuple[str, ...] = ()  # caster wheel joints (round, about Y, on a swivel): not driven
    heading: float = 0.0
    """Forward in the root frame, as an angle about its Z: 0 when the axle is the root's Y (x forward,
    REP-103), π/2 when the axle is the root's X (forward +Y: safety-gymnasium's car). Every planar
    quantity of layer 4 (the engines' paths, the references' COM and root offset, "left" at +Y) is
    in the drive frame, the root frame turned by ``heading``."""

    def as_dict(self) -> dict[str, Any]:
        """Plain data (for the report and for an engine's child process)."""
        return {
            "kind": self.kind, "left": self.left, "right": self.right, "radius": self.radius,
            "half_axle": self.half_axle, "wheel_links": list(self.wheel_links), "signs": list(self.signs),
            "pan": self.pan, "tilt": self.tilt,
            "rollers": {k: list(v) for k, v in sorted(self.rollers.items())},
            "roller_radius": self.roller_radius, "track_offset_y": self.track_offset_y,
            "casters": list(self.casters), "heading": self.heading,
        }

    @staticmethod
    def from_dict(data: dict[str, Any]) -> Drive:
        return Drive(
            kind=data["kind"], left=data["left"], right=data["right"], radius=float(data["radius"]),
            half_axle=float(data["half_axle"]), wheel_links=tuple(data["wheel_links"]),
            signs=tuple(data["signs"]),
            pan=data.get("pan"), tilt=data.get("tilt"),
            rollers={k: tuple(v) for k, v in data.get("rollers", {}).items()},
            roller_radius=float(data.get("roller_radius", 0.0)),
            track_offset_y=float(data.get("track_offset_y", 0.0)),
            casters=tuple(data.get("casters", ())),
            heading=float(data.get("heading", 0.0)),
        )


class Controller(Protocol):
    """One of the seed's controllers. Called once per physics step (1 kHz by default) with the
    command in force and the current positions/velocities of ``joints`` (source names, in that
    order); returns one output per joint: a torque (``mode`` "torque", N m) or a velocity target
    (``mode`` "velocity", rad/s; the engine tracks it with its velocity servo)."""

    name: str
    joints: tuple[str, ...]
    mode: ControlMode

    def output(self, t: float, command: Command, q: Array, dq: Array) -> Array: ...


@dataclass
class Trajectory:
    """One run of one profile, sampled at the scenario's sample rate from command start.

    ``x``, ``y``, ``yaw``: the root link frame's planar pose relative to its pose at command start
    (yaw unwrapped). ``joints``: positions of the controlled joints (source names), relative to
    command start. ``wheels``: (left, right) joint angles relative to command start (for tracks,
    roller 0's). ``settings``: every engine setting that matters for reproducing it. ``support``
    (engines): the links touching the floor at rest, after the settle, and the load each carries."""

    source: str  # "mujoco", "pybullet", "noslip", "unicycle", "odometry:mujoco", ...
    profile: str
    variant: str  # "sphere" (the verification variant), "native" (report-only), "" for references
    t: Array
    x: Array
    y: Array
    yaw: Array
    wheels: Array  # (n, 2)
    joints: dict[str, Array] = field(default_factory=dict)
    settings: dict[str, Any] = field(default_factory=dict)
    warnings: list[str] = field(default_factory=list)
    # engines: each link touching the floor at rest (after the settle) → its normal load, N
    support: dict[str, float] = field(default_factory=dict)


class Driver(Protocol):
    """One engine loaded with the floating-base model on a floor, ready to run profiles."""

    engine: str
    settings: dict[str, Any]

    def run(self, profile: Profile, scenario: Scenario, drive: Drive) -> Trajectory: ...

    def close(self) -> None: ...
