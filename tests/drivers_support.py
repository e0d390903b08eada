"""Shared by the tests of layer 4's drivers (and of their fast paths: MuJoCo's actuators, PyBullet's
joint damping): the robots, the seed's drive built by hand, the profiles, and the comparisons of a
fast run with the per-step run."""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any

import numpy as np

from modelkit.verify.drive import Command, Drive, Profile, Trajectory
from modelkit.verify.drive.controllers import make_controllers

MODELS = Path(__file__).resolve().parent.parent / "samples/choreonoid_ros2_mobile_robot_tutorial/model"
PANTILT = MODELS / "mobile_robot_pantilt.body"
TRACKS = MODELS / "mobile_robot_tracks.body"
DRIVE = Drive("wheels", "LeftWheel", "RightWheel", 0.076, 0.145, ("LeftWheel", "RightWheel"),
              pan="PanJoint", tilt="TiltJoint")
PAN_TILT = (Command(1.0, pan=0.5, tilt=0.3), Command(3.0, pan=-0.5, tilt=-0.3), Command(5.0))
ROUND_OFF = 1e-9  # m / rad over 10 s


def profile(name: str, v: float, w: float) -> Profile:
    commands = (Command(0.0, v, w), *(dataclasses.replace(c, v=v, w=w) for c in PAN_TILT))
    return Profile(name, 10.0, commands)


# straight and arc with pan and tilt moving; a command change between two samples (t = 6.0005 s)
PROFILES = (
    profile("straight", 0.5, 0.0),
    profile("arc", 0.3, 0.5),
    Profile("steps", 10.0, (Command(0.0, 0.3), Command(2.0, 0.3, 0.6, pan=0.4),
                            Command(4.0, 0.0, -1.0, tilt=0.2), Command(6.0005, -0.2, 0.0),
                            Command(8.0, 0.4, -0.4)), graded=False),
)


def run_difference(a: Trajectory, b: Trajectory, until: int | None = None) -> float:
    """The largest difference of two runs (root position, yaw, wheel and joint angles), over the
    samples before ``until`` (all when None)."""
    assert np.array_equal(a.t, b.t) and set(a.joints) == set(b.joints)
    s = slice(0, until)
    return max(float(np.hypot(a.x[s] - b.x[s], a.y[s] - b.y[s]).max()),
               float(np.abs(a.yaw[s] - b.yaw[s]).max()),
               float(np.abs(a.wheels[s] - b.wheels[s]).max()),
               *(float(np.abs(a.joints[j][s] - b.joints[j][s]).max()) for j in a.joints))


def assert_same_layer4(robot: Any, engine: str, per_step: str, tmp_path: Path, monkeypatch: Any
                       ) -> list[tuple[Trajectory, Trajectory]]:
    """Layer 4 on ``robot`` (its default scenario, with the report-only native run asked for) with
    ``engine``'s fast driver, then with the per-step one (``per_step``: "module:function" building
    it), every check and observation the same to round-off and the same pass/fail; returns the
    engine's pairs of runs (each equal to round-off)."""
    from modelkit.verify.drive import vehicle
    from modelkit.verify.drive.scenario import default_scenario
    from modelkit.verify.layers import layer4

    scenario = dataclasses.replace(default_scenario("wheels", True), native_report=True)
    drive = vehicle.find_drive(robot, scenario)
    fast = layer4.run(robot, drive, scenario, tmp_path / "fast", engines=(engine,))
    monkeypatch.setitem(layer4.DRIVERS, engine, per_step)
    slow = layer4.run(robot, drive, scenario, tmp_path / "slow", engines=(engine,))
    print("layer 4 wall s: fast", fast.timings, "per step", slow.timings)
    assert [(c.engine, c.quantity, c.where, c.passed) for c in fast.checks] == \
        [(c.engine, c.quantity, c.where, c.passed) for c in slow.checks]
    assert fast.checks and all(abs(a.error - b.error) <= ROUND_OFF for a, b in zip(fast.checks, slow.checks,
                                                                                     strict=True))
    assert [(o.engine, o.quantity, o.where) for o in fast.observations] == \
        [(o.engine, o.quantity, o.where) for o in slow.observations]
    assert all(abs(a.value - b.value) <= ROUND_OFF for a, b in zip(fast.observations, slow.observations,
                                                                    strict=True))
    runs = [(a, b) for a, b in zip(fast.trajectories, slow.trajectories, strict=True) if a.source == engine]
    assert runs and all(run_difference(a, b) <= ROUND_OFF for a, b in runs)
    return runs


def no_affine_law(drive: dict[str, Any], scenario: dict[str, Any]) -> list[Any]:
    """The seed's controllers without ``affine_law`` (a controller the driver must call every step)."""

    class PerStep:
        def __init__(self, inner: Any) -> None:
            self.inner, self.name, self.joints, self.mode = inner, inner.name, inner.joints, inner.mode

        def output(self, t: float, command: Command, q: Any, dq: Any) -> Any:
            return self.inner.output(t, command, q, dq)

    return [PerStep(c) for c in make_controllers(drive, scenario)]
