"""A welded robot whose moving links reach below the floor plane at its start pose (MK888).

A user who loads a fixed-base arm adds a floor at z = 0 (MuJoCo's plane, PyBullet's ``plane.urdf``,
Gazebo's ground). A robot mounted overhead or on a wall (synriard's "vertical" Alicia arms hang 0.63 m
below their mount), or whose home folds below its base, then starts with links inside that floor:
the floor's contacts push them off their pose and the position servos fight it (the arm swings
through 1 m in MuJoCo's first 0.15 s). Nothing in the file is wrong, so nothing is changed; the note
says where the robot reaches and what the user can do. The pose judged is the one the written file
starts at: the MJCF's ``home`` key, q = 0 for the targets without one. A welded link (the base and
what is fixed to it) is left out: MuJoCo, PyBullet and Gazebo collide no static body with the floor.
"""

from __future__ import annotations

from modelkit.checks.physics import moving_links
from modelkit.convert.notes import NoteSink
from modelkit.convert.numbers import fmt
from modelkit.convert.registry import TargetInfo
from modelkit.convert.servo_gains import home_position
from modelkit.model import JointType, Robot

CLEARANCE = 0.001
"""m: how far below z = 0 a moving link's collision shapes must reach to be said."""


def note_below_floor(robot: Robot, target: TargetInfo, notes: NoteSink) -> None:
    """MK888 when the robot is welded (its root does not float) and a link that a joint moves has
    collision shapes more than :data:`CLEARANCE` below z = 0 where the written file starts it."""
    from modelkit.convert.wheels import link_lows

    if robot.root is None or robot.root_joint is JointType.FLOATING:
        return
    moving = moving_links(robot)  # the root is welded: the links below a moving joint
    if not moving:
        return
    start = "" if target.spawn else "home "  # a target that stands a robot itself has the `home` key
    positions = {joint.name: home_position(joint) for joint in robot.joints} if start else {}
    lows = link_lows(robot, robot.world_poses(positions))
    below = sorted((low, name) for name, low in lows.items() if name in moving and low < -CLEARANCE)
    if not below:
        return
    depth, deepest = below[0]
    shown = ", ".join(name for _, name in below[:4])
    shown += f" and {len(below) - 4} more" if len(below) > 4 else ""
    pose = f"its {start}pose" if start else "q = 0"
    notes.note(
        "MK888",
        f"the welded robot reaches {fmt(round(-depth * 1000.0, 1))} mm below z = 0 at {pose} ({deepest}; "
        f"moving links below: {shown}): a floor added at z = 0 cuts through them, and its contacts push "
        "the robot off its pose. Put the floor lower, the robot higher (the base's pose) or leave the "
        "floor out (a robot mounted overhead or on a wall), or start it from a pose above its base",
        robot.source,
        "model",
    )

