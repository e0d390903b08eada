"""Where a free robot written to URDF, SDF or ``.body`` stands on the ground (MK884).

MJCF carries the answer in the file: its ``home`` key puts a free base where the lowest collision
shape rests on z = 0 (MK882, :mod:`modelkit.formats.mjcf.write_home`). The other targets have no key.
A URDF's root has no pose at all: Gazebo's and PyBullet's spawn put the root frame at the height the
user passes, 0 by default, and a quadruped whose feet hang 0.45 m below its base then starts with its
legs in the ground. An SDF model's ``<pose>`` and a ``.body`` root's ``translation`` place it where the
source put it, which for a URDF source is the origin too. Those formats start the joints at 0
(Gazebo, PyBullet, Choreonoid without a project), so the height is taken at q = 0, with the target's
collision shapes (a wheel's sphere). The note gives the root frame's height at which the lowest one
touches z = 0, in the words of the target's own tools (each format's ``spawn`` declaration).
"""

from __future__ import annotations

import math

from modelkit.convert.notes import NoteSink
from modelkit.convert.registry import TargetInfo
from modelkit.model import JointType, Robot

REST_TOLERANCE = 1e-4
"""m: a free robot whose lowest collision shape is this close to z = 0 where the file puts it stands
there (MK882 and MK884 say nothing)."""
HEIGHT_STEP = 1e-6
"""m: a height that stands a robot on the floor is rounded up to this (it starts at most 1 µm above)."""


def rest_height(height: float) -> float:
    """``height`` rounded up to :data:`HEIGHT_STEP` (the digits a file or a command line holds)."""
    return math.ceil(round(height / HEIGHT_STEP, 3)) * HEIGHT_STEP


def note_spawn_height(robot: Robot, target: TargetInfo, notes: NoteSink) -> None:
    """MK884 for a free robot of a target without a ``home`` key whose lowest collision shape at q = 0
    starts more than :data:`REST_TOLERANCE` inside the ground where the written file (or a spawn at 0)
    puts its root: the simulator throws it out. A robot that starts above the ground drops onto it and
    is not told."""
    from modelkit.convert.numbers import fmt
    from modelkit.convert.wheels import link_lows

    if not target.spawn or robot.root is None or robot.root_joint is not JointType.FLOATING:
        return
    lows = link_lows(robot, robot.world_poses())
    if not lows:
        return
    body, low = min(lows.items(), key=lambda item: (item[1], item[0]))
    root_z = float(robot.root_pose.translation[2])
    placed = root_z if target.places_root else 0.0  # where the root frame starts without the user
    height = rest_height(root_z - low)  # the root frame's height at which the lowest shape touches z = 0
    if placed >= height - REST_TOLERANCE:
        return  # on the ground, or above it: the robot drops onto it (SR1's .body root, 5 mm)
    where = f"{fmt(round((height - placed) * 1000.0, 1))} mm inside the ground"
    start = (f"where the file puts its root (z = {fmt(round(placed, 6))} m)" if target.places_root
             else "when spawned at z = 0")
    link = robot.link(body)
    notes.note(
        "MK884",
        f"the free robot's lowest collision shape at q = 0 ({body}) starts {where} {start}; it stands on "
        f"z = 0 with its root frame at z = {fmt(height)} m: "
        + target.spawn.format(z=fmt(height)),
        link.source if link is not None and link.source is not None else robot.source,
        "spawn",
    )
