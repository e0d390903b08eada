"""The ``home`` keyframe: the robot's initial joint positions, its servos' controls, and a free robot
standing on the floor.

MuJoCo wants every qpos value of a key, in its order (joints in document order): a free joint gets its
body's pose, a ball joint the identity, the other hinges and slides their initial positions (0 where the
source gives none). Position servos put their targets in the key's ``ctrl``.

A free robot's source places its root where its format does: a URDF's root is at the origin, so a
quadruped's feet and a rover's wheels reach below z = 0, and on a user's floor ``mj_resetDataKeyframe``
starts them inside it, 58 cm deep for example-robot-data's ANYmal-Kinova, and MuJoCo throws the robot
out (3.1 m up in 0.5 s). The key therefore puts the free root at the height where the lowest collision
shape at home rests on z = 0, where a floor is added, as MuJoCo Menagerie's keys stand its robots. The
height is rounded up to the micrometre, so the robot starts at most 1 µm above the floor. The body's own
``pos`` (``qpos0``, MuJoCo's reset without a key) stays the source's root pose: reading the file back
gives the source's robot. A key is changed when the lowest collision shape is more than
:data:`HEIGHT_STEP` off z = 0, and a free robot without a key gets one when it is more than
:data:`REST_TOLERANCE` off (the tutorial's ``.body`` robots rest on z = 0 and get none). The lowest
shape is found by MuJoCo itself, on the compiled file (:mod:`modelkit.convert.self_contact`).
"""

from __future__ import annotations

import math

import numpy as np

from modelkit.convert.context import WriteContext
from modelkit.convert.numbers import fmt, fmt_vec
from modelkit.convert.self_contact import Lowest
from modelkit.convert.spawn import HEIGHT_STEP, REST_TOLERANCE, rest_height
from modelkit.formats.mjcf.write_xml import Element, quat_wxyz, sub
from modelkit.model import Robot
from modelkit.spatial import Pose


class HomeKey:
    """The ``home`` key of one written file: :meth:`write` after the body tree and the actuators,
    :meth:`rest_on_floor` once MuJoCo has found the lowest collision shape at home."""

    def __init__(self, robot: Robot, ctx: WriteContext, keyframe: Element, worldbody: Element,
                 body_pose: dict[Element, Pose]) -> None:
        self.robot = robot
        self.ctx = ctx
        self.keyframe = keyframe
        self.worldbody = worldbody
        self.body_pose = body_pose
        self.qpos: list[float] = []
        self.ctrl: list[float] = []
        self.key: Element | None = None
        self.free_root = False  # the first joint is free, on a body of the world: qpos[2] is its height

    def write(self, home: dict[str, float], ctrl: list[float], any_position: bool) -> None:
        """The key, when the robot has initial positions or its servos a non-zero target (zero is
        MuJoCo's own ctrl of a key)."""
        self.ctrl = ctrl if any_position or any(ctrl) else []
        for index, el in enumerate(self.worldbody.iter("joint", "freejoint")):
            kind = "free" if el.tag == "freejoint" else el.get("type", "hinge")
            if kind == "free":
                parent = el.getparent()
                pose = self.body_pose.get(parent, Pose()) if parent is not None else Pose()
                self.qpos.extend([*np.asarray(pose.translation, dtype=float), *quat_wxyz(pose.rotation)])
                if index == 0 and parent is not None and parent.getparent() is self.worldbody:
                    self.free_root = True
            elif kind == "ball":
                self.qpos.extend([1.0, 0.0, 0.0, 0.0])
            else:
                self.qpos.append(home.get(el.get("name", ""), 0.0))
        if home or self.ctrl:
            self._element()

    def rest_on_floor(self, lowest: Lowest | None) -> None:
        """The free root's height in the key such that its lowest collision shape at home rests on
        z = 0 (MK882)."""
        if not self.free_root or lowest is None or not math.isfinite(lowest.height):
            return
        if abs(lowest.height) <= (HEIGHT_STEP if self.key is not None else REST_TOLERANCE):
            return  # it rests on z = 0 already
        source = self.qpos[2]
        self.qpos[2] = rest_height(source - lowest.height)
        self._element()
        depth = fmt(round(abs(lowest.height) * 1000.0, 1))
        where = f"{depth} mm {'below' if lowest.height < 0 else 'above'} it"
        self.ctx.note(
            "MK882",
            f"the home keyframe puts the free base at z = {fmt(self.qpos[2])} m, where the lowest collision "
            f"shape at home ({lowest.body}) rests on z = 0, the floor a user adds; the source's root pose "
            f"puts that shape {where}, and the body's pos (MuJoCo's reset without a key) stays the source's",
            self.robot.source,
            "keyframe/key[home]",
        )

    def _element(self) -> None:
        if self.key is None:
            self.key = sub(self.keyframe, "key", name="home")
        self.key.set("qpos", fmt_vec(np.asarray(self.qpos)))
        if self.ctrl:
            self.key.set("ctrl", fmt_vec(np.asarray(self.ctrl)))
