"""The seed tutorial's controllers (``choreonoid_ros2_mobile_robot_tutorial``) as Python controllers.

Each follows :class:`~modelkit.verify.drive.Controller`: called once per physics step with the command
in force and the positions/velocities of its ``joints`` (source names, in that order), it returns one
torque (``mode`` "torque") or velocity target (``mode`` "velocity") per joint. The returned array is
**owned by the controller and overwritten by its next call** (no allocation per step: they run
1000 times per simulated second in both engines); copy it to keep it.

* :class:`DriveTester` (``MobileRobotDriveTester``): a constant torque on both wheels (seed: 1.0 N m).
* :class:`DriveController` (``MobileRobotDriveController``): ``dq_x = v/r``, ``dq_yaw = w·b/r``,
  targets ``dq_x − dq_yaw`` (left) and ``dq_x + dq_yaw`` (right), torque ``u = kd·(dq* − dq)``
  (seed: kd 0.5, r 0.076, b 0.145; here r and b come from the model).
* :class:`PanTiltController` (``MobileRobotPanTiltController``): ``dq* = (pan, tilt)`` from the
  command, ``u = kd·(dq* − dq)`` (seed: kd 0.1).
* :class:`TrackController` (``MobileRobotTrackController``): velocity mode, the seed's track
  velocities ``v ∓ w·offset_y`` (m/s) become roller speeds ``(v ∓ w·offset_y) / roller_radius``
  (rad/s) for roller 0 of each track (``convert`` writes roller i > 0 mimicking roller 0; the drivers
  give every roller of the track roller 0's target: ``variant.driven_groups``).

Each wheel or roller joint's ``sign`` (:class:`~modelkit.verify.drive.Drive`) is applied so that a
model whose axis points along −Y still drives forward for a positive ``v``: the seed's controllers
assume +Y axes (sign +1, where these reduce to the seed's formulas exactly).

:func:`make_controllers` builds them from plain data (``Drive.as_dict()`` and
``scenario.scenario_dict(...)``) so that PyBullet's child process builds the very same ones.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from modelkit.verify.drive import Array, Command, ControlMode


class DriveTester:
    """``MobileRobotDriveTester``: ``u = torque`` on both wheels (forward for sign +1)."""

    name = "drive-tester"
    mode: ControlMode = "torque"

    def __init__(self, left: str, right: str, torque: float = 1.0, signs: tuple[float, float] = (1.0, 1.0)):
        self.joints = (left, right)
        self.torque = float(torque)
        self._out = np.array([signs[0] * self.torque, signs[1] * self.torque])

    def output(self, t: float, command: Command, q: Array, dq: Array) -> Array:
        return self._out

    def affine_law(self, command: Command) -> tuple[Array, Array]:
        """``(offset, gain)`` with ``output = offset − gain·dq`` for any state while ``command`` holds
        (optional on a controller: an engine may then apply the law itself, ``engine_mujoco``)."""
        return self._out.copy(), np.zeros(2)


class DriveController:
    """``MobileRobotDriveController``: wheel speed targets from (v, w), ``u = kd·(dq* − dq)``."""

    name = "drive"
    mode: ControlMode = "torque"

    def __init__(
        self,
        left: str,
        right: str,
        radius: float,
        half_axle: float,
        kd: float = 0.5,
        signs: tuple[float, float] = (1.0, 1.0),
    ):
        self.joints = (left, right)
        self.radius = float(radius)
        self.half_axle = float(half_axle)
        self.kd = float(kd)
        self.signs = (float(signs[0]), float(signs[1]))
        self._out = np.zeros(2)
        self._command: Command | None = None
        self._target = (0.0, 0.0)

    def targets(self, command: Command) -> tuple[float, float]:
        """(left, right) joint velocity targets, rad/s, in the joints' own sense."""
        if command is not self._command:
            dq_x = command.v / self.radius
            dq_yaw = command.w * self.half_axle / self.radius
            self._target = (self.signs[0] * (dq_x - dq_yaw), self.signs[1] * (dq_x + dq_yaw))
            self._command = command
        return self._target

    def output(self, t: float, command: Command, q: Array, dq: Array) -> Array:
        left, right = self.targets(command)
        out = self._out
        out[0] = self.kd * (left - dq[0])
        out[1] = self.kd * (right - dq[1])
        return out

    def affine_law(self, command: Command) -> tuple[Array, Array]:
        """``(offset, gain)`` with ``output = offset − gain·dq`` while ``command`` holds (up to rounding)."""
        left, right = self.targets(command)
        return np.array([self.kd * left, self.kd * right]), np.array([self.kd, self.kd])


class PanTiltController:
    """``MobileRobotPanTiltController``: ``dq* = (cmd.pan, cmd.tilt)``, ``u = kd·(dq* − dq)``.
    ``joints`` holds the pan and/or tilt joint the robot has (pan first)."""

    name = "pan-tilt"
    mode: ControlMode = "torque"

    def __init__(self, pan: str | None, tilt: str | None, kd: float = 0.1):
        self.joints = tuple(j for j in (pan, tilt) if j is not None)
        self._which = tuple(i for i, j in enumerate((pan, tilt)) if j is not None)
        self.kd = float(kd)
        self._out = np.zeros(len(self.joints))

    def output(self, t: float, command: Command, q: Array, dq: Array) -> Array:
        target = (command.pan, command.tilt)
        out = self._out
        for k, i in enumerate(self._which):
            out[k] = self.kd * (target[i] - dq[k])
        return out

    def affine_law(self, command: Command) -> tuple[Array, Array]:
        """``(offset, gain)`` with ``output = offset − gain·dq`` while ``command`` holds (up to rounding)."""
        target = (command.pan, command.tilt)
        return np.array([self.kd * target[i] for i in self._which]), np.full(len(self.joints), self.kd)


class TrackController:
    """``MobileRobotTrackController`` on the rollers: velocity targets
    ``sign·(v ∓ w·offset_y) / roller_radius`` for roller 0 of the left (−) and right (+) track."""

    name = "track"
    mode: ControlMode = "velocity"

    def __init__(
        self,
        left_roller: str,
        right_roller: str,
        roller_radius: float,
        offset_y: float,
        signs: tuple[float, float] = (1.0, 1.0),
    ):
        self.joints = (left_roller, right_roller)
        self.roller_radius = float(roller_radius)
        self.offset_y = float(offset_y)
        self.signs = (float(signs[0]), float(signs[1]))
        self._out = np.zeros(len(self.joints))
        self._command: Command | None = None

    def output(self, t: float, command: Command, q: Array, dq: Array) -> Array:
        if command is not self._command:
            v_angular = command.w * self.offset_y
            self._out[0] = self.signs[0] * (command.v - v_angular) / self.roller_radius
            self._out[1] = self.signs[1] * (command.v + v_angular) / self.roller_radius
            self._command = command
        return self._out

    def affine_law(self, command: Command) -> tuple[Array, Array]:
        """``(offset, gain)``: the velocity targets while ``command`` holds, gain 0 (no dq feedback)."""
        return self.output(0.0, command, np.zeros(0), np.zeros(0)).copy(), np.zeros(2)


Controller = DriveTester | DriveController | PanTiltController | TrackController


def make_controllers(drive: dict[str, Any], scenario: dict[str, Any]) -> list[Controller]:
    """The controllers of a scenario for a drive (both plain data): the drive (or tester, or track)
    controller first, then the pan-tilt controller when the robot has pan or tilt joints."""
    signs = (float(drive["signs"][0]), float(drive["signs"][1]))
    kind = scenario.get("controller") or ("track" if drive["kind"] == "tracks" else "drive")
    out: list[Controller] = []
    if kind == "track":
        if drive["kind"] != "tracks":
            raise ValueError("the track controller needs a tracked robot")
        rollers = drive["rollers"]
        out.append(
            TrackController(
                rollers[drive["left"]][0],
                rollers[drive["right"]][0],
                float(drive["roller_radius"]),
                float(drive["track_offset_y"]),
                signs,
            )
        )
    elif kind == "drive-tester":
        if drive["kind"] != "wheels":
            raise ValueError("the drive tester needs a wheeled robot")
        out.append(
            DriveTester(drive["left"], drive["right"], float(scenario.get("tester_torque", 1.0)), signs)
        )
    elif kind == "drive":
        if drive["kind"] != "wheels":
            raise ValueError("the drive controller needs a wheeled robot (tracks take the track controller)")
        out.append(
            DriveController(
                drive["left"],
                drive["right"],
                float(drive["radius"]),
                float(drive["half_axle"]),
                float(scenario.get("kd", 0.5)),
                signs,
            )
        )
    else:
        raise ValueError(f"unknown controller {kind!r}")
    if drive.get("pan") or drive.get("tilt"):
        out.append(
            PanTiltController(drive.get("pan"), drive.get("tilt"), float(scenario.get("pan_tilt_kd", 0.1)))
        )
    return out
