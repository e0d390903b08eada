"""The simulator settings a driven robot needs, for the writers: one place that merges what the
wheels (:mod:`modelkit.convert.wheels`) and the tracks (:mod:`modelkit.convert.tracks`) ask for.

MJCF holds them in ``<option>`` (MK825 names them); a URDF cannot hold any, so the URDF writer's
MK825 note names the PyBullet setting a user sets (tracks: ``enableConeFriction=0``).

Why these values (measured on the tutorial's pan-tilt robot, docs/convert.md): a wheeled robot
driven by a torque law on a floor is a stiff friction problem (wheel friction 3 against a 14 kg body);
MuJoCo's defaults (2 ms, Euler, pyramidal cones, impratio 1) let the wheels creep sideways in a turn.
1 ms, ``implicitfast`` (stable with the joints' damping), elliptic cones and ``impratio`` 10 (friction
ten times stiffer than the normal direction) make the contact hold as Coulomb's law says. Tracks
keep their own ``impratio`` (0.03: soft friction so that the rollers skid, MK809).
"""

from __future__ import annotations

from modelkit.model import Robot

WHEEL_OPTIONS: dict[str, str] = {
    "timestep": "0.001",
    "integrator": "implicitfast",
    "cone": "elliptic",
    "impratio": "10",
}
"""MJCF ``<option>`` attributes for a wheeled robot."""

TRACK_OPTIONS: dict[str, str] = {
    "timestep": "0.001",
    "integrator": "implicitfast",
    "cone": "elliptic",
}
"""MJCF ``<option>`` attributes for a tracked robot, besides the tracks' ``impratio``."""


def mujoco_options(robot: Robot) -> tuple[dict[str, str], str]:
    """The ``<option>`` attributes the robot needs and why (empty for a robot that drives nothing)."""
    from modelkit.convert.numbers import fmt
    from modelkit.convert.tracks import track_impratio
    from modelkit.convert.wheels import WHEELS_KEY

    impratio = track_impratio(robot)
    if impratio is not None:
        out = dict(TRACK_OPTIONS)
        out["impratio"] = fmt(impratio)
        return out, "the robot drives on pseudo continuous tracks (rollers, MK809)"
    wheels = robot.extras.get(WHEELS_KEY)
    if isinstance(wheels, dict) and wheels:
        return dict(WHEEL_OPTIONS), f"the robot drives on wheels ({', '.join(sorted(wheels))})"
    return {}, ""


CONTACT: dict[str, str] = {"solref": "0.004 1", "solimp": "0.99 0.999 0.001 0.5 2"}
"""MJCF contact parameters of a driven robot's collision geoms (with priority 1 they are the contact's
against a default floor). MuJoCo's default (solref 0.02 1, solimp 0.9 0.95 0.001) lets a wheel sink
into the floor far enough to shorten its rolling radius: measured on the tutorial's pan-tilt robot,
0.26 % (75.8 mm of 76), so a 10 rad spin came out 20 mrad short of the rigid no-slip reference.
A time constant of 4 ms (≥ 2 timesteps at 1 ms) and impedance 0.99–0.999 keep it at 0.1 mm."""


def mujoco_contact(robot: Robot) -> dict[str, str]:
    """solref/solimp for every collision geom of a wheeled robot; {} otherwise. Tracks keep MuJoCo's
    default contact: their skid turning (TRACK_IMPRATIO) was measured with it, and the stiff contact
    changes it (the tutorial's tracked robot's arc then ends 2.2 m from the skid reference)."""
    from modelkit.convert.tracks import track_impratio
    from modelkit.convert.wheels import WHEELS_KEY

    wheels = robot.extras.get(WHEELS_KEY)
    return dict(CONTACT) if track_impratio(robot) is None and isinstance(wheels, dict) and wheels else {}


def pybullet_settings(robot: Robot) -> dict[str, str]:
    """Engine settings a PyBullet user sets for the robot (a URDF cannot carry them)."""
    from modelkit.convert.tracks import PYBULLET_CONE_FRICTION, track_impratio

    if track_impratio(robot) is not None:
        return {"enableConeFriction": str(PYBULLET_CONE_FRICTION)}
    return {}
