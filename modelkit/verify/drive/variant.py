"""The files layer 4 drives: the floating-base model written as MJCF and URDF exactly as ``convert``
writes them (no edit afterwards), and what the two drivers share.

The graded run reads ``convert``'s default output, whose wheels are spheres (``--wheel-collision
auto``, :mod:`modelkit.convert.wheels`, MK826) for the reasons below; the report-only ``native``
run reads what ``convert --wheel-collision cylinder`` writes.

Why spheres (verification.md §2.2): MuJoCo and PyBullet give a cylinder lying on a plane different
meanings. MuJoCo's cylinder–plane collision makes two contacts, one on each rim edge, so a yawing
wheel scrubs (about μN·w/2 of resisting moment per wheel); PyBullet's implicit cylinder makes one
contact at whichever rim edge its support mapping picks (the outer one on the left wheel, the inner
one on the right), so the first acceleration yaws the robot. A sphere of the wheel radius at the
wheel centre touches a flat floor at exactly one point under the hub in both engines: the only wheel
shape whose contact means the same thing in the two. It differs from the cylinder only when a wheel
meets an obstacle sideways, which never happens on a flat floor; the oversized sphere cannot touch
the chassis (MuJoCo filters parent/child contacts, PyBullet leaves self-collision off).

Tracks: ``convert`` writes each pseudo continuous track as a row of driven rollers (cylinders of the
track's half height, ``convert/tracks.py``, MK809); the files keep those cylinders (a roller is not a
wheel for ``--wheel-collision``).

Friction, contact parameters and simulator options are the files' (the contact materials against the
floor; MJCF ``priority``/``condim``/``solref``/``<option>``, URDF ``<contact>``); the drivers read them
and edit nothing (``engine_mujoco.driver``, ``engine_pybullet.driver``). ``Scenario.friction`` is not
applied to the engines: layer 4 says so with a Skip (the graded files carry the materials' values).
"""

from __future__ import annotations

import dataclasses
import importlib
import math
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from modelkit.model import Robot
from modelkit.verify.drive import Array, Drive, Profile, Scenario, Trajectory, WheelProxy

Renames = dict[str, dict[str, str]]
SUFFIX = {"mjcf": ".xml", "urdf": ".urdf"}


WRITE_CHOICE: dict[str, str] = {"sphere": "auto", "native": "cylinder"}
"""The ``--wheel-collision`` each layer-4 run writes with: the graded run reads exactly what
``convert`` writes by default (``auto``: sphere wheels for MJCF and URDF, MK826); the report-only
native run what ``convert --wheel-collision cylinder`` writes."""


def write_variant(robot: Robot, drive: Drive, scenario: Scenario, out_dir: Path, proxy: WheelProxy,
                  formats: tuple[str, ...] = ("mjcf", "urdf")) -> tuple[dict[str, Path], dict[str, Renames]]:
    """Write the floating-base ``robot`` (the source model, root not welded) as MJCF and URDF into
    ``out_dir`` exactly as ``convert`` writes it (``<name>.xml`` / ``.urdf``; the native run's
    ``<name>_cylinder.*``; meshes in ``meshes/``): no edit of the written files, the engines load
    them as they are, with ``convert``'s default options but the wheels' collision (``proxy``).

    Returns the files (``"mjcf"``, ``"urdf"``: those of ``formats``) and each file's renames
    (``{"link": {source: written}, "joint": {...}}``, from the writers' MK800 notes), as ``verify``'s
    conversion does."""
    from modelkit.convert.api import write
    from modelkit.convert.notes import renames
    from modelkit.convert.options import WriteOptions

    del scenario, drive
    if proxy not in WRITE_CHOICE:
        raise ValueError(f"wheel proxy must be 'sphere' or 'native', not {proxy!r}")
    options = WriteOptions(wheel_collision=WRITE_CHOICE[proxy])
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    stem = _safe(robot.name or "robot") + ("" if proxy == "sphere" else "_cylinder")
    files: dict[str, Path] = {}
    maps: dict[str, Renames] = {}
    for fmt in formats:
        path = out_dir / f"{stem}{SUFFIX[fmt]}"
        notes = write(robot, path, fmt, options=options, force=True)
        files[fmt] = path
        maps[fmt] = {"link": renames(notes, "link"), "joint": renames(notes, "joint")}
    return files, maps


def _safe(name: str) -> str:
    """The robot's name as a file stem: safe characters, at most 100 of them (a valid model may be
    named with 300: the file name would pass the 255-byte limit of most file systems)."""
    return "".join(c if c.isalnum() or c in "-_" else "_" for c in name)[:100] or "robot"



# ---- shared by the two drivers (engine_mujoco.driver, engine_pybullet.driver) --------------------

CONTROLLERS = "modelkit.verify.drive.controllers:make_controllers"
"""The controller factory (``make_controllers(drive: dict, scenario: dict) -> list[Controller]``),
as ``module:function`` so that PyBullet's child process imports the very same one."""


def scenario_data(scenario: Scenario) -> dict[str, Any]:
    """The scenario as plain data for ``make_controllers`` (``scenario.scenario_dict`` when the
    scenario module has it, else the dataclass fields)."""
    try:
        from modelkit.verify.drive.scenario import scenario_dict
    except ImportError:
        return dataclasses.asdict(scenario)
    return dict(scenario_dict(scenario))


def profile_data(profile: Profile) -> dict[str, Any]:
    """Plain data for PyBullet's child, which builds the Profile again (``Command(**c)`` each)."""
    return dataclasses.asdict(profile)


def load_factory(spec: str) -> Callable[[dict[str, Any], dict[str, Any]], list[Any]]:
    module, _, function = spec.partition(":")
    factory: Callable[[dict[str, Any], dict[str, Any]], list[Any]] = getattr(importlib.import_module(module),
                                                                             function)
    return factory


def controlled_joints(controllers: list[Any]) -> list[tuple[str, str]]:
    """(joint, mode) of every joint some controller drives, in controller order (source names)."""
    out: list[tuple[str, str]] = []
    for c in controllers:
        out.extend((j, str(c.mode)) for j in c.joints)
    return out


def driven_groups(drive: Drive, joint: str) -> tuple[str, ...]:
    """The joints a velocity target for ``joint`` drives: for a track's roller 0, every roller of
    that track (roller i > 0 mimics roller 0 with multiplier 1; the servo of each gets the target);
    otherwise the joint itself."""
    for rollers in drive.rollers.values():
        if rollers and rollers[0] == joint:
            return tuple(rollers)
    return (joint,)


def wheel_joints(drive: Drive) -> tuple[str, str]:
    """The joints whose angles a trajectory's ``wheels`` holds: the wheels, or each track's roller 0."""
    if drive.kind == "tracks":
        left, right = drive.rollers.get(drive.left, ()), drive.rollers.get(drive.right, ())
        if left and right:
            return left[0], right[0]
    return drive.left, drive.right


def yaw_of(rotations: Array) -> Array:
    """Heading of each rotation matrix (n, 3, 3): the angle of its x axis in the world XY plane."""
    return np.arctan2(rotations[:, 1, 0], rotations[:, 0, 0])


def planar(source: str, profile: Profile, variant: str, t: Array, positions: Array, rotations: Array,
           joints: dict[str, Array], wheels: tuple[str, str], heading: float = 0.0) -> Trajectory:
    """A trajectory from raw samples of the root link frame (world positions (n, 3), rotations
    (n, 3, 3)) and joint positions: x, y in the start pose's drive frame (the root frame turned by
    ``heading``, :attr:`Drive.heading`), yaw unwrapped relative to the start, joint angles relative to
    the start."""
    yaw = np.unwrap(yaw_of(rotations))
    c, s = math.cos(yaw[0] + heading), math.sin(yaw[0] + heading)
    dx, dy = positions[:, 0] - positions[0, 0], positions[:, 1] - positions[0, 1]
    rel = {name: q - q[0] for name, q in joints.items()}
    return Trajectory(source=source, profile=profile.name, variant=variant, t=t,
                      x=c * dx + s * dy, y=-s * dx + c * dy, yaw=yaw - yaw[0],
                      wheels=np.column_stack([rel[wheels[0]], rel[wheels[1]]]), joints=rel)


def rotations_wxyz(q: Array) -> Array:
    """Rotation matrices (n, 3, 3) of unit quaternions (n, 4) in MuJoCo's (w, x, y, z) order."""
    q = q / np.linalg.norm(q, axis=1, keepdims=True)
    w, x, y, z = q[:, 0], q[:, 1], q[:, 2], q[:, 3]
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], axis=1),
        np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], axis=1),
        np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], axis=1),
    ], axis=1)


SERVO_FRICTION_SHARE = 3.0
"""The roller servos' torque bound as a multiple of the average friction limit ``m·g·μ·r / n`` (the
track rollers are the only velocity-servoed joints). Choreonoid imposes a track's surface speed
without a bound, and the skid-steer reference (``reference_skid``) assumes the same: a turning track's
belt slips lengthwise while it slides sideways, so each roller must keep its speed against the whole
Coulomb force of the load it carries. That load is not the average: a rigid solver's split of the
weight among the coplanar roller contacts is not determined (PyBullet split the tutorial robot's
172 N as 16/70/65/21 N, 1.63 × the average on the heaviest); 3 × the average covers it, and the servo
still bounds MuJoCo's reaction at a speed step (``servo_torque_limit``). Was ½ (a torque-limited,
slip-free start for the no-slip reference); at ½ no roller can pass the force a skid turn needs
(about 0.58 μN on the tutorial's spin) and neither engine turned the robot on the spot. A straight
start is now friction-limited, as in the skid reference (lag v²/2μg)."""


def servo_torque_limit(mass: float, mu: float, radius: float, count: int, gravity: float = 9.81,
                       share: float | None = None) -> float:
    """The torque bound of each roller's velocity servo (both engines): the most that friction can
    pass to the floor through one of ``count`` rollers sharing the robot's weight, ``m·g·μ·r / count``.
    A servo never needs more in steady driving; at a command step it saturates where friction would
    anyway. The bound is needed in MuJoCo: its constraint solver computes the contact forces from
    the actuator's explicit force ``kv·(target − q̇)`` before the implicit integration damps it, so
    an unbounded stiff servo's reaction at a speed step throws the robot off the floor (measured:
    kv 1000 launched the tracked robot 24 m; kv 10 still hopped 1.3 cm)."""
    share = SERVO_FRICTION_SHARE if share is None else share
    return share * mass * gravity * mu * radius / max(1, count)


def servo_gain(mass: float, radius: float, count: int, dt: float) -> float:
    """The gain kv (N·m·s/rad) of MuJoCo's roller velocity servos: ``J / dt`` with ``J = m·r² / n`` the
    robot's mass reflected onto one of the ``n`` rollers, i.e. a servo time constant of one step.

    Why not stiffer: a MuJoCo actuator at its force bound is integrated explicitly (``implicitfast``
    takes no ``∂force/∂q̇`` from a clamped actuator), and an explicit velocity loop on the inertia J
    is stable only for ``kv·dt / J < 2``. Above that the servo chatters between its two bounds at the
    step rate once the speed error enters its linear band ``τ_max / kv``: measured on the tracked
    tutorial robot (J = 0.0158 kg m², dt 1 ms, so the limit is 32): kv 30 settles exactly, kv 100
    chatters ±0.04 rad/s with the mean 0.24 % fast (1.2 cm over the 5 m straight, growing). At ``J / dt``
    (half the limit) the servo reaches its target within about a step after a saturated start, as
    PyBullet's velocity constraint does."""
    return mass * radius * radius / max(1, count) / dt
