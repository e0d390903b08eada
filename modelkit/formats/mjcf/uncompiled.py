"""The fallback: the kinematic tree read from an ``MjSpec`` that MuJoCo could not compile.

MuJoCo's parser has applied defaults and classes and spliced ``<include>`` files, so names, joint
types, anchors, axes and ranges are right; this module resolves what compilation would have:
``<frame>`` nesting, alternative orientations (``euler``, ``axisangle``, ``xyaxes``, ``zaxis``) and
degrees. It does **not** compute inertia from geoms, ``fromto`` placements or mesh geometry: links
carry only an explicitly written ``<inertial>``, and no geoms.
"""

from __future__ import annotations

import math
from typing import Any

from modelkit import rot3
from modelkit.formats.mjcf.bodies import MjBody, MjInertial, MjJoint, pose_of
from modelkit.spatial import Pose

JOINT_KINDS = {"mjJNT_FREE": "free", "mjJNT_BALL": "ball", "mjJNT_SLIDE": "slide", "mjJNT_HINGE": "hinge"}


class SpecReader:
    """Reads bodies and joints from an uncompiled spec, numbering them as MuJoCo would (depth first)."""

    def __init__(self, mujoco: Any, spec: Any) -> None:
        self.mj = mujoco
        self.spec = spec
        self.degree = bool(spec.compiler.degree)
        self.autolimits = bool(spec.compiler.autolimits)
        self._joint_count = 0

    def bodies(self) -> list[MjBody]:
        out: list[MjBody] = []
        stack: list[tuple[Any, int]] = [(b, 0) for b in reversed(list(self.spec.worldbody.bodies))]
        while stack:
            body, parent = stack.pop()
            record = self._body(body, len(out) + 1, parent)
            out.append(record)
            stack.extend((child, record.index) for child in reversed(list(body.bodies)))
        return out

    def _body(self, body: Any, index: int, parent: int) -> MjBody:
        pose = self._frames(body.frame) @ pose_of(body.pos, self._quat(body.quat, body.alt))
        record = MjBody(index, str(body.name) or None, parent, pose, mocap=bool(body.mocap))
        for joint in body.joints:
            record.joints.append(self._joint(joint))
        if bool(body.explicitinertial):
            record.inertial = self._inertial(body)
        return record

    def _frames(self, frame: Any) -> Pose:
        """The pose of a chain of ``<frame>`` elements, outermost first."""
        pose = Pose()
        depth = 0
        while frame is not None and depth < 1000:
            pose = pose_of(frame.pos, self._quat(frame.quat, frame.alt)) @ pose
            frame = frame.frame
            depth += 1
        return pose

    def _quat(self, quat: Any, alt: Any) -> Any:
        if alt is None or getattr(alt.type, "name", "") == "mjORIENTATION_QUAT":
            return quat
        return self.mj.MjSpec.resolve_orientation(self.degree, self.spec.compiler.eulerseq, alt)

    def _joint(self, joint: Any) -> MjJoint:
        kind = JOINT_KINDS.get(getattr(joint.type, "name", ""), "hinge")
        angular = kind in ("hinge", "ball")
        scale = math.pi / 180.0 if self.degree and angular else 1.0
        low, high = (float(x) for x in joint.range)
        limited_word = getattr(joint.limited, "name", "")
        limited = limited_word == "mjLIMITED_TRUE" or (
            limited_word == "mjLIMITED_AUTO" and self.autolimits and low < high
        )
        index = self._joint_count
        self._joint_count += 1
        return MjJoint(
            index=index,
            name=str(joint.name) or None,
            kind=kind,
            pos=rot3.vec3(joint.pos),
            axis=rot3.vec3(joint.axis),  # as written; the builder normalises it
            limited=limited and kind != "free",
            range=(low * scale, high * scale),
            ref=float(joint.ref) * (scale if kind == "hinge" else 1.0),
            damping=first(joint.damping),
            frictionloss=float(joint.frictionloss),
            armature=float(joint.armature),
            stiffness=first(joint.stiffness),
            springref=float(joint.springref),
        )

    def _inertial(self, body: Any) -> MjInertial:
        full = [float(x) for x in body.fullinertia]
        if math.isfinite(full[0]):
            xx, yy, zz, xy, xz, yz = full  # MuJoCo's order
            tensor = rot3.inertia_from_moments(xx, xy, xz, yy, yz, zz)
        else:
            rotation = rot3.from_quat_wxyz(self._quat(body.iquat, body.ialt))
            x, y, z = rot3.vec3(body.inertia)
            tensor = rot3.rotate_inertia(rot3.inertia_from_moments(x, 0.0, 0.0, y, 0.0, z), rotation)
        return MjInertial(float(body.mass), rot3.vec3(body.ipos), tensor)


def first(value: Any) -> float:
    """The first number of a scalar or a (nested) sequence: the spec keeps some scalars as arrays."""
    try:
        items = list(value)
    except TypeError:  # a number (or a 0-d array)
        return float(value)
    return first(items[0])
