"""Pinocchio built directly from the in-memory source model: the dynamics reference no writer touched.

The tree is rebuilt joint by joint: a revolute or prismatic joint becomes
``JointModelRevoluteUnaligned``/``JointModelPrismaticUnaligned`` about its (unit) axis, placed at its
origin composed with the fixed joints above it; a fixed joint adds no Pinocchio joint, its child
link's inertia is appended to the supporting joint at the composed placement. A ball joint is three
revolute joints about its X, Y and Z through two massless bodies, turned by the configuration's
``NAME#x``... angles; their degrees of freedom are held at rest and left out of the mass matrix and
bias (:meth:`PinocchioModel.dof_names`), which compare the revolute and prismatic ones. A planar joint
(two slides and a turn) and a floating joint in the tree (three slides, three turns) are held at rest
the same way: the mass matrix and bias of the other joints do not depend on them there. Every link gets a
body frame carrying its own inertia (read back by layer 1; ``addFrame(..., append_inertia=False)``
so it is not counted twice). The root link is welded to the
universe at the identity. Joint armature (rotor inertia) goes to ``model.armature``, which
``crba`` adds to the mass matrix as MuJoCo's ``qM`` does. Dynamics: ``pin.crba`` (upper triangle,
symmetrised) and ``pin.rnea`` with zero acceleration for the bias.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin

from modelkit.model import BALL_KEYS, Joint, JointType, Robot
from modelkit.spatial import Pose
from modelkit.verify.engines import ball_law
from modelkit.verify.engines.protocol import Array, JointFacts, LinkFacts, StaticFacts
from modelkit.verify.engines.reference import unit

Renames = dict[str, dict[str, str]]
GRAVITY = (0.0, 0.0, -9.81)


class UnsupportedJoint(ValueError):
    """A joint type the fixed-base Pinocchio model cannot hold (planar, floating in the tree)."""

    engine_limit = True  # the reference's limit, not the file's fault: verify reports a skip


# pinocchio.Data holds four nv × nv × nv tensors (second-order derivatives of the dynamics) whatever is
# computed with it: 4 · nv³ · 8 bytes, 262 MB at 200 joints, 2 GB at 400, 32 GB at 1000 (measured with
# Pinocchio 4.0: 36 MB at 100, 876 MB at 300). Above this size the reference is not built.
MAX_DATA_TENSOR_BYTES = 128 * 2**20


class TooManyDofs(ValueError):
    """The model has more degrees of freedom than a Pinocchio Data of :data:`MAX_DATA_TENSOR_BYTES` holds."""

    engine_limit = True  # verify reports a skip, not a failed load


def max_dofs() -> int:
    """The most degrees of freedom whose Data tensors stay within :data:`MAX_DATA_TENSOR_BYTES` (161)."""
    return int((MAX_DATA_TENSOR_BYTES / 32) ** (1 / 3))


def _se3(pose: Pose) -> pin.SE3:
    return pin.SE3(np.array(pose.rotation, dtype=float), np.array(pose.translation, dtype=float))


def _inertia(robot: Robot, link_name: str) -> pin.Inertia:
    """The link's inertia. A principal moment below zero by no more than ``ZERO_MOMENT`` is zero
    (validate's MK302 rule): iCub's ``r_hip_2`` gives -5.4e-20 on the diagonal, which Pinocchio refuses
    ("The 3d inertia should be positive") and PyBullet and Drake hold as a zero inertia."""
    from modelkit.checks.physics import ZERO_MOMENT

    link = robot.link(link_name)
    if link is None or link.inertial is None:
        return pin.Inertia.Zero()
    i = link.inertial
    tensor = np.array(i.inertia, dtype=float)
    moments, axes = np.linalg.eigh(0.5 * (tensor + tensor.T))
    if -ZERO_MOMENT <= moments.min() < 0.0:
        tensor = axes @ np.diag(np.maximum(moments, 0.0)) @ axes.T
    return pin.Inertia(float(i.mass), np.array(i.com, dtype=float), tensor)


class PinocchioModel:
    engine = "pinocchio"

    def __init__(self, robot: Robot) -> None:
        if robot.root is None:
            raise ValueError("the model has no root link")
        self.robot = robot
        widths = {JointType.REVOLUTE: 1, JointType.PRISMATIC: 1, JointType.BALL: 3, JointType.PLANAR: 3,
                  JointType.FLOATING: 6}
        dofs = sum(widths.get(j.type, 0) for j in robot.joints)
        if dofs > max_dofs():
            raise TooManyDofs(
                f"{dofs} degrees of freedom: pinocchio.Data holds four nv³ tensors (second-order "
                f"derivatives), {4 * dofs**3 * 8 / 1e9:.3g} GB here; the Pinocchio reference is built for at "
                f"most {max_dofs()} (128 MiB)")
        model = pin.Model()
        model.name = robot.name
        model.gravity = pin.Motion(np.array(GRAVITY), np.zeros(3))
        children = robot.children_of()
        armature: list[float] = []
        # link -> (supporting joint id, link frame in that joint's frame)
        self._support: dict[str, tuple[int, pin.SE3]] = {}
        self._joint_types: dict[str, str] = {}
        self._joint_child: dict[str, str] = {}
        self._ball_pieces: set[str] = set()  # the three revolute joints holding each ball joint
        self._held_pieces: set[str] = set()  # the single-axis joints holding a planar or floating joint
        self._balls: dict[str, str] = {}  # ball joint -> child link
        # planar and floating joints in the tree: their pieces (held at rest, like a ball's) -> type
        self._held: dict[str, tuple[str, str]] = {}  # joint -> (type, child link)
        # a ball joint's armature, per axis of the child's angular velocity (MuJoCo's ball dofs)
        self.ball_armature: dict[str, float] = {}
        root_frame = model.addFrame(pin.Frame(robot.root, 0, 0, pin.SE3.Identity(), pin.FrameType.BODY,
                                              _inertia(robot, robot.root)), False)
        model.appendBodyToJoint(0, _inertia(robot, robot.root), pin.SE3.Identity())
        self._support[robot.root] = (0, pin.SE3.Identity())
        # depth-first, in document order: crba needs each joint's subtree to be contiguous in v
        stack: list[tuple[Joint, int]] = [(j, root_frame) for j in reversed(children.get(robot.root, []))]
        while stack:
            joint, parent_frame = stack.pop()
            if joint.child in self._support:
                continue
            pjid, pplace = self._support[joint.parent]
            placement = pplace * _se3(joint.origin)
            if joint.type in (JointType.REVOLUTE, JointType.PRISMATIC):
                axis = unit(joint.axis)
                jm = (pin.JointModelRevoluteUnaligned(axis) if joint.type is JointType.REVOLUTE
                      else pin.JointModelPrismaticUnaligned(axis))
                inf = np.array([math.inf])
                jid = model.addJoint(pjid, jm, placement, joint.name, inf, inf,
                                     np.array([joint.limits.lower]), np.array([joint.limits.upper]))
                armature.append(float(joint.armature))
                frame = self._carry(model, joint, jid, parent_frame)
            elif joint.type is JointType.BALL:
                frame = self._carry(model, joint, self._add_ball(model, joint, pjid, placement), parent_frame)
                armature.extend([0.0, 0.0, 0.0])  # a ball's is not diagonal in the pieces' rates:
                if joint.armature:  # mass_matrix_with_balls adds it
                    self.ball_armature[joint.name] = float(joint.armature)
                self._balls[joint.name] = joint.child
            elif joint.type in (JointType.PLANAR, JointType.FLOATING):
                frame = self._carry(model, joint, self._add_held(model, joint, pjid, placement), parent_frame)
                armature.extend([0.0] * widths[joint.type])
                self._held[joint.name] = (joint.type.value, joint.child)
            elif joint.type in (JointType.FIXED, JointType.PSEUDO_CONTINUOUS_TRACK):
                model.appendBodyToJoint(pjid, _inertia(robot, joint.child), placement)
                self._support[joint.child] = (pjid, placement)
                jframe = model.addFrame(pin.Frame(joint.name, pjid, parent_frame, placement,
                                                  pin.FrameType.FIXED_JOINT))
                frame = model.addFrame(pin.Frame(joint.child, pjid, jframe, placement, pin.FrameType.BODY,
                                                 _inertia(robot, joint.child)), False)
            else:
                raise UnsupportedJoint(f"joint {joint.name!r} is {joint.type.value}: the fixed-base "
                                       "Pinocchio reference holds revolute, prismatic, ball, planar, "
                                       "floating and fixed joints")
            self._joint_child[joint.name] = joint.child
            self._joint_types[joint.name] = ("fixed" if joint.type is JointType.PSEUDO_CONTINUOUS_TRACK
                                             else joint.type.value)
            stack.extend((j, frame) for j in reversed(children.get(joint.child, [])))
        model.armature = np.array(armature, dtype=float)
        self.model = model
        self.data = model.createData()
        self._all = [model.names[j] for j in range(1, model.njoints)]  # one q and one v each
        self._at_rest = self._ball_pieces | self._held_pieces
        self._visible = [i for i, name in enumerate(self._all) if name not in self._at_rest]
        self._with_balls = [i for i, name in enumerate(self._all) if name not in self._held_pieces]
        self._dofs = [self._all[i] for i in self._visible]
        self.settings: dict[str, Any] = {
            "version": pin.__version__,
            "built_from": "the in-memory source model (no file)",
            "joints": "JointModelRevoluteUnaligned / JointModelPrismaticUnaligned; fixed joints merged "
                      "into the supporting body, one BODY frame per link; a ball joint three revolute "
                      "joints about X, Y, Z (massless between), at rest in the dynamics; a planar joint "
                      "two prismatic joints and a revolute one, a floating joint in the tree three "
                      "prismatic and three revolute ones, likewise",
            "base": "root link welded to the universe at the identity",
            "gravity": list(GRAVITY),
            "mass_matrix": "crba (upper triangle symmetrised), armature on the diagonal",
            "bias": "rnea(q, v, 0)",
        }

    def _carry(self, model: Any, joint: Joint, jid: int, parent_frame: int) -> int:
        """The child link on the moving joint ``jid``: its inertia, a JOINT frame named after the
        joint and the link's BODY frame (returned)."""
        inertia = _inertia(self.robot, joint.child)
        model.appendBodyToJoint(jid, inertia, pin.SE3.Identity())
        self._support[joint.child] = (jid, pin.SE3.Identity())
        jframe = model.addFrame(pin.Frame(joint.name, jid, parent_frame, pin.SE3.Identity(),
                                          pin.FrameType.JOINT))
        return int(model.addFrame(pin.Frame(joint.child, jid, jframe, pin.SE3.Identity(), pin.FrameType.BODY,
                                            inertia), False))

    def _add_ball(self, model: Any, joint: Joint, pjid: int, placement: Any) -> int:
        """A ball joint as three revolute joints about its frame's X, Y and Z (``NAME#x``...,
        ``BALL_KEYS``: R = Rx·Ry·Rz, as the other engines turn a ball), the two between them massless;
        returns the last. Their degrees of freedom are not among :meth:`dof_names`: layer 3 holds a ball
        at rest at each sampled orientation, and each engine parametrises a ball's velocity its own way."""
        jid = pjid
        inf = np.array([math.inf])
        for key, unit_axis in zip(BALL_KEYS, np.eye(3), strict=True):
            jid = model.addJoint(jid, pin.JointModelRevoluteUnaligned(unit_axis), placement, joint.name + key,
                                 inf, inf, -inf, inf)  # no limits: a ball turns freely
            placement = pin.SE3.Identity()
            self._ball_pieces.add(joint.name + key)
            if key != BALL_KEYS[-1]:
                model.appendBodyToJoint(jid, pin.Inertia.Zero(), pin.SE3.Identity())
        return int(jid)

    def _add_held(self, model: Any, joint: Joint, pjid: int, placement: Any) -> int:
        """A planar joint (slides along two axes of its plane, a turn about its normal) or a floating
        one (slides along X, Y, Z, turns about X, Y, Z) as single-axis joints through massless bodies;
        returns the last. Like a ball's pieces, they are held at rest at zero and are not among
        :meth:`dof_names`: the other engines hold these joints as one joint each, or as a chain of
        their own (the MJCF's, compared through the source holding that chain)."""
        from modelkit.formats.mjcf.write_bodies import planar_axes

        if joint.type is JointType.PLANAR:
            u, v, n = planar_axes(joint.axis)
            pieces = [("#tx", False, u), ("#ty", False, v), ("#rz", True, n)]
        else:
            pieces = [(f"#t{key}", False, axis) for key, axis in zip("xyz", np.eye(3), strict=True)]
            pieces += [(f"#r{key}", True, axis) for key, axis in zip("xyz", np.eye(3), strict=True)]
        jid = pjid
        inf = np.array([math.inf])
        for i, (key, turns, axis) in enumerate(pieces):
            jm = pin.JointModelRevoluteUnaligned(axis) if turns else pin.JointModelPrismaticUnaligned(axis)
            jid = model.addJoint(jid, jm, placement, joint.name + key, inf, inf, -inf, inf)
            placement = pin.SE3.Identity()
            self._held_pieces.add(joint.name + key)
            if i < len(pieces) - 1:
                model.appendBodyToJoint(jid, pin.Inertia.Zero(), pin.SE3.Identity())
        return int(jid)

    def dof_names(self) -> list[str]:
        return list(self._dofs)

    def _q(self, q: dict[str, float]) -> Array:
        return np.array([q.get(n, 0.0) for n in self._all], dtype=float)

    def static(self) -> StaticFacts:
        m = self.model
        facts = StaticFacts()
        for frame in m.frames:
            if frame.type == pin.FrameType.BODY:
                inertia = frame.inertia
                facts.links[frame.name] = LinkFacts(float(inertia.mass), np.array(inertia.lever, dtype=float),
                                                    np.array(inertia.inertia, dtype=float))
        parent_of = {j.child: j.parent for j in self.robot.joints}
        for frame in m.frames:
            if frame.type == pin.FrameType.JOINT and frame.name in self._balls:
                child = self._balls[frame.name]
                facts.joints[frame.name] = JointFacts("ball", parent_of[child], child, np.zeros(3))
            elif frame.type == pin.FrameType.JOINT and frame.name in self._held:
                kind, child = self._held[frame.name]
                facts.joints[frame.name] = JointFacts(kind, parent_of[child], child, np.zeros(3))
            elif frame.type == pin.FrameType.JOINT:
                jid = m.getJointId(frame.name)
                jm = m.joints[jid].extract()
                child = self._joint_child[frame.name]
                kind = "revolute" if "Revolute" in jm.shortname() else "prismatic"
                facts.joints[frame.name] = JointFacts(
                    kind, parent_of[child], child, np.array(jm.axis, dtype=float),
                    float(m.lowerPositionLimit[m.idx_qs[jid]]), float(m.upperPositionLimit[m.idx_qs[jid]]))
            elif frame.type == pin.FrameType.FIXED_JOINT and frame.name in self._joint_child:
                child = self._joint_child[frame.name]
                facts.joints[frame.name] = JointFacts(self._joint_types[frame.name], parent_of[child], child,
                                                      np.zeros(3))
        return facts

    def link_poses(self, q: dict[str, float]) -> dict[str, Pose]:
        pin.framesForwardKinematics(self.model, self.data, self._q(q))
        out: dict[str, Pose] = {}
        for fid, frame in enumerate(self.model.frames):
            if frame.type == pin.FrameType.BODY:
                placement = self.data.oMf[fid]
                out[frame.name] = Pose(np.array(placement.rotation), np.array(placement.translation))
        return out

    def mass_matrix(self, q: dict[str, float]) -> Array:
        upper = np.array(pin.crba(self.model, self.data, self._q(q)))
        full = np.triu(upper) + np.triu(upper, 1).T
        return full[np.ix_(self._visible, self._visible)]

    def dof_names_with_balls(self) -> list[str]:
        """Every degree of freedom, a ball joint's three pieces (``NAME#x``...) included (a planar or
        floating joint's left out)."""
        return [self._all[i] for i in self._with_balls]

    def mass_matrix_with_balls(self, q: dict[str, float]) -> Array:
        """The mass matrix over :meth:`dof_names_with_balls`: a ball's pieces in the coordinates of
        the URDF writer's chain (R = Rx·Ry·Rz). At a ball's zero orientation their rates are the
        child's angular velocity in the child's frame, the coordinates MuJoCo gives a ball."""
        upper = np.array(pin.crba(self.model, self.data, self._q(q)))
        full = np.triu(upper) + np.triu(upper, 1).T
        for name, armature in self.ball_armature.items():  # a·JᵀJ: a per axis of ω = J·(ȧ, ḃ, ċ)
            first = self._all.index(name + BALL_KEYS[0])
            pitch, yaw = (q.get(name + key, 0.0) for key in BALL_KEYS[1:])
            jacobian = np.array(ball_law.chain_jacobian(pitch, yaw), dtype=float).reshape(3, 3)
            full[first:first + 3, first:first + 3] += armature * jacobian.T @ jacobian
        return full[np.ix_(self._with_balls, self._with_balls)]

    def bias_with_balls(self, q: dict[str, float], dq: dict[str, float]) -> Array:
        """The bias over :meth:`dof_names_with_balls`, a ball's pieces at rest."""
        hidden = self._at_rest
        v = np.array([0.0 if n in hidden else dq.get(n, 0.0) for n in self._all], dtype=float)
        full = np.array(pin.rnea(self.model, self.data, self._q(q), v, np.zeros(self.model.nv)))
        return full[self._with_balls]

    def bias(self, q: dict[str, float], dq: dict[str, float]) -> Array:
        """rnea with zero acceleration; a ball joint's pieces at rest (their velocity 0)."""
        hidden = self._at_rest
        v = np.array([0.0 if n in hidden else dq.get(n, 0.0) for n in self._all], dtype=float)
        full = np.array(pin.rnea(self.model, self.data, self._q(q), v, np.zeros(self.model.nv)))
        return full[self._visible]

    def close(self) -> None:
        return None


def load(model: Path | Robot, renames: Renames, *, root: str) -> PinocchioModel:
    if not isinstance(model, Robot):
        raise TypeError("the Pinocchio reference is built from the in-memory source model, not a file")
    return PinocchioModel(model)
