"""MuJoCo adapter: the written MJCF, base welded, read back from the compiled ``mjModel``.

Static facts: ``body_mass``, ``body_ipos``, ``body_inertia`` rotated by ``body_iquat``, ``jnt_axis``,
``jnt_range``. Poses: ``mj_kinematics``. Dynamics: ``mj_fullM`` of ``qM`` and ``qfrc_bias`` after
``mj_forward`` (gravity + Coriolis/centrifugal). The replay (layer 3b) steps with
``integrator="Euler"`` at the caller's dt, contacts, joint limits and equality constraints off, the
PD law as actuators; nothing is added to the model, and the joints' passive terms (damping, friction
loss, stiffness; armature when the other engine's URDF cannot hold it) are zeroed on the compiled
model, as the PyBullet worker zeroes all damping (``MujocoSimulator.left_out`` says what was there).

Every MuJoCo call runs inside :func:`quiet`: MuJoCo's warnings are collected in ``runtime_warnings`` (the
caller reports them; "unstable" ones fail) instead of going to ``MUJOCO_LOG.TXT`` in the working
directory.
"""

from __future__ import annotations

import contextlib
import math
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import mujoco
import numpy as np

from modelkit.formats.mjcf.quiet import collected_warnings
from modelkit.model import Robot
from modelkit.spatial import Pose, axis_angle, matrix_from_quat_wxyz
from modelkit.verify.facts import Array, JointFacts, LinkFacts, ShapeFacts, StaticFacts, TorqueLaw

Renames = dict[str, dict[str, str]]
GRAVITY = (0.0, 0.0, -9.81)
# MuJoCo's words when mj_checkPos/Vel/Acc find the state blown up (it then resets the data).
UNSTABLE = ("unstable", "Nan, Inf or huge value")


def unstable(messages: list[str]) -> list[str]:
    """The warnings among ``messages`` that say the simulation went unstable."""
    return [m for m in messages if any(word in m for word in UNSTABLE)]


@contextlib.contextmanager
def quiet(into: list[str]) -> Iterator[None]:
    """MuJoCo's warnings go into ``into`` (never MuJoCo's default handler, which writes
    ``MUJOCO_LOG.TXT`` into the working directory): every MuJoCo call here runs inside this."""
    with collected_warnings(mujoco) as messages:
        try:
            yield
        finally:
            into.extend(messages)
_TYPES = {
    int(mujoco.mjtJoint.mjJNT_HINGE): "revolute",
    int(mujoco.mjtJoint.mjJNT_SLIDE): "prismatic",
    int(mujoco.mjtJoint.mjJNT_BALL): "ball",
    int(mujoco.mjtJoint.mjJNT_FREE): "floating",
}
_GEOMS = {
    int(mujoco.mjtGeom.mjGEOM_BOX): "box",
    int(mujoco.mjtGeom.mjGEOM_SPHERE): "sphere",
    int(mujoco.mjtGeom.mjGEOM_CYLINDER): "cylinder",
    int(mujoco.mjtGeom.mjGEOM_CAPSULE): "capsule",
    int(mujoco.mjtGeom.mjGEOM_ELLIPSOID): "ellipsoid",
    int(mujoco.mjtGeom.mjGEOM_MESH): "mesh",
    int(mujoco.mjtGeom.mjGEOM_PLANE): "plane",
    int(mujoco.mjtGeom.mjGEOM_HFIELD): "hfield",
}


_ORIENTATIONS = ("quat", "axisangle", "euler", "xyaxes", "zaxis")
_DOF_WIDTH = {int(mujoco.mjtJoint.mjJNT_FREE): 6, int(mujoco.mjtJoint.mjJNT_BALL): 3}


def _split_chains(path: Path, links: set[str]) -> str:
    """The MJCF text with each multi-joint body that has a link of ``links`` among its chain's
    intermediates (``<body>__<joint>``, see :class:`_Body`) split into nested bodies, one per joint:
    ``<body name="B__j1" pos/orientation of B>`` holding j1 and an inertial at j1's anchor, ..., then
    B itself at the identity with its last joint. The kinematics are unchanged (MuJoCo composes a
    body's joints as nested bodies would); the new bodies can then carry the mass another engine
    gives those links (PyBullet's 1 kg for a URDF link without ``<inertial>``)."""
    from lxml import etree

    tree = etree.parse(str(path))
    for el in list(tree.iter("body")):
        name = el.get("name")
        joints = [j for j in el.findall("joint") if j.get("type", "hinge") != "free"]
        if not name or len(joints) < 2 or not any(f"{name}__{j.get('name')}" in links for j in joints[:-1]):
            continue
        parent, index = el.getparent(), el.getparent().index(el)
        outer = holder = None
        for joint in joints[:-1]:
            wrapper = etree.Element("body", name=f"{name}__{joint.get('name')}")
            if el.get("childclass"):
                wrapper.set("childclass", str(el.get("childclass")))
            if outer is None:
                outer = wrapper
                for attribute in ("pos", *_ORIENTATIONS):
                    if el.get(attribute) is not None:
                        wrapper.set(attribute, str(el.get(attribute)))
                        del el.attrib[attribute]
            else:
                assert holder is not None
                holder.append(wrapper)
            etree.SubElement(wrapper, "inertial", pos=joint.get("pos", "0 0 0"), mass="1",
                             diaginertia="1 1 1")  # the caller sets the values it was given
            wrapper.append(joint)  # moved out of the body
            holder = wrapper
        assert outer is not None and holder is not None
        parent.remove(el)
        holder.append(el)
        parent.insert(index, outer)
    return etree.tostring(tree, encoding="unicode")


def _compile(path: Path, root: str, actuated: bool = False,
             split: set[str] | None = None) -> tuple[mujoco.MjModel, bool]:
    """Compile the MJCF with the root body's free joint (if any) deleted: the base welded.

    ``actuated`` (the replay): the file's actuators are deleted and every hinge and slide joint gets
    one affine actuator of zero gain and bias (actuator i ↔ the i-th such joint in model order),
    which the replay turns into the PD law (force = kp·ctrl − kp·q − kd·q̇, ctrl = the target).
    ``split``: intermediate links to make bodies of their own (:func:`_split_chains`)."""
    if split:
        spec = mujoco.MjSpec.from_string(_split_chains(path, split))
        spec.modelfiledir = str(path.parent)
    else:
        spec = mujoco.MjSpec.from_file(str(path))
    body = spec.body(root)
    if body is None:
        raise ValueError(f"{path}: no body named {root!r}")
    welded = False
    for joint in list(body.joints):
        if joint.type == mujoco.mjtJoint.mjJNT_FREE:
            spec.delete(joint)
            welded = True
    if actuated:
        for actuator in list(spec.actuators):
            spec.delete(actuator)
        for joint in spec.joints:
            if joint.type in (mujoco.mjtJoint.mjJNT_HINGE, mujoco.mjtJoint.mjJNT_SLIDE):
                act = spec.add_actuator()
                act.target, act.trntype = joint.name, mujoco.mjtTrn.mjTRN_JOINT
                act.gaintype, act.biastype = mujoco.mjtGain.mjGAIN_FIXED, mujoco.mjtBias.mjBIAS_AFFINE
                act.gainprm[0] = 0.0
    model = spec.compile()
    model.opt.gravity[:] = GRAVITY
    return model, welded


@dataclass(frozen=True)
class _Body:
    """One MuJoCo body seen as the model's links (the MJCF reader's rule, ``formats/mjcf/build.py``).

    A body with joints j1..jn (the free joint aside) is a chain of n links: ``<body>__<j_k>`` for
    k < n, synthesised and massless, at the anchor (``jnt_pos``) of j_k, then the body's own link at
    the anchor of j_n: the body frame moved by ``offset`` = ``jnt_pos[j_n]`` (MuJoCo joints have no
    orientation of their own). A body without joints is one link, its frame the body frame."""

    index: int
    name: str
    parent: str  # the parent body's link ("world" for a top-level body)
    joints: tuple[int, ...]  # the chain's joints (hinge, slide, ball), in the body's order
    links: tuple[str, ...]  # the chain's links, one per joint (the body's own last); (name,) without joints
    offset: Array  # the body's link frame in the body frame (a translation)


class MujocoModel:
    engine = "mujoco"

    def __init__(self, path: Path, root: str, actuated: bool = False, split: set[str] | None = None) -> None:
        self.runtime_warnings: list[str] = []  # MuJoCo's warnings, collected (see ``quiet``)
        with quiet(self.runtime_warnings):
            self.model, deleted = _compile(path, root, actuated, split)
            self.data = mujoco.MjData(self.model)
        self.root = root
        m = self.model
        self._root_id = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, root)
        self._dofs: list[str] = []
        self._qadr: list[int] = []
        self._vadr: list[int] = []
        for j in range(m.njnt):
            if int(m.jnt_type[j]) in (int(mujoco.mjtJoint.mjJNT_HINGE), int(mujoco.mjtJoint.mjJNT_SLIDE)):
                self._dofs.append(self._jname(j))
                self._qadr.append(int(m.jnt_qposadr[j]))
                self._vadr.append(int(m.jnt_dofadr[j]))
        self._bodies = [self._body(b) for b in range(1, m.nbody)]
        self._link_of = {link: body for body in self._bodies for link in body.links}
        self.settings: dict[str, Any] = {
            "version": mujoco.__version__,
            "file": path.name,
            "base": ("root body's free joint deleted through MjSpec" if deleted
                     else "root body has no free joint"),
            "gravity": list(GRAVITY),
            "links": ("the model's links, as modelkit's MJCF reader makes them from MuJoCo's compiled "
                      "bodies: a body's link frame is the body frame moved to its last joint's anchor "
                      "(jnt_pos); a body with n joints is a chain of n links, the first n - 1 massless "
                      "<body>__<joint> at their joints' anchors; COM, inertia and collision shapes "
                      "re-expressed in the link frame; the world body is the link 'world' when it is "
                      "the root"),
            "poses": "mj_kinematics (xpos, xmat, moved to the link frames), relative to the root link",
            "mass_matrix": "mj_fullM after mj_forward",
            "bias": "qfrc_bias after mj_forward",
            "nq": int(m.nq), "nv": int(m.nv),
        }

    def _jname(self, j: int) -> str:
        return mujoco.mj_id2name(self.model, mujoco.mjtObj.mjOBJ_JOINT, j) or f"joint{j}"

    def _bname(self, b: int) -> str:
        return mujoco.mj_id2name(self.model, mujoco.mjtObj.mjOBJ_BODY, b) or f"body{b}"

    def _body(self, b: int) -> _Body:
        m = self.model
        free = int(mujoco.mjtJoint.mjJNT_FREE)
        start, count = int(m.body_jntadr[b]), int(m.body_jntnum[b])
        chain = tuple(j for j in range(start, start + count) if int(m.jnt_type[j]) != free)
        name = self._bname(b)
        links = (*(f"{name}__{self._jname(j)}" for j in chain[:-1]), name)
        offset = np.array(m.jnt_pos[chain[-1]], dtype=float) if chain else np.zeros(3)
        parent = int(m.body_parentid[b])
        return _Body(b, name, self._bname(parent) if parent > 0 else "world", chain, links, offset)

    @property
    def _world_is_root(self) -> bool:
        """The root is MuJoCo's world body (a source whose top bodies hang from a synthesised
        ``world`` link by their joints): it is a link, massless, at the identity."""
        return self._root_id == 0

    def dof_names(self) -> list[str]:
        return list(self._dofs)

    def static(self) -> StaticFacts:
        m = self.model
        facts = StaticFacts()
        if self._world_is_root:
            facts.links["world"] = LinkFacts(0.0, np.zeros(3), np.zeros((3, 3)))
        for body in self._bodies:
            b = body.index
            for link in body.links[:-1]:
                facts.links[link] = LinkFacts(0.0, np.zeros(3), np.zeros((3, 3)))
            rot = matrix_from_quat_wxyz(m.body_iquat[b])
            inertia = rot @ np.diag(m.body_inertia[b]) @ rot.T
            com = np.array(m.body_ipos[b], dtype=float) - body.offset
            facts.links[body.name] = LinkFacts(float(m.body_mass[b]), com, inertia)
            if not body.joints and b != self._root_id:
                facts.joints[f"fixed:{body.name}"] = JointFacts("fixed", body.parent, body.name, np.zeros(3))
            parent = body.parent
            for j, child in zip(body.joints, body.links if body.joints else (), strict=True):
                jtype = _TYPES.get(int(m.jnt_type[j]), "unknown")
                moving = jtype in ("revolute", "prismatic")
                lower, upper = -math.inf, math.inf
                if moving and m.jnt_limited[j]:
                    lower, upper = float(m.jnt_range[j][0]), float(m.jnt_range[j][1])
                axis = np.array(m.jnt_axis[j], dtype=float) if moving else np.zeros(3)
                facts.joints[self._jname(j)] = JointFacts(jtype, parent, child, axis, lower, upper)
                parent = child
        facts.shapes = self.shapes()
        return facts

    def shapes(self) -> dict[str, list[ShapeFacts]]:
        """Collision geoms (``contype | conaffinity`` non-zero) per link, in the link frame.

        ``geom_size`` holds half sizes (box half edges, cylinder/capsule radius and half length).
        A mesh geom's compiled frame is moved to the mesh's centroid and principal axes
        (``mesh_pos``/``mesh_quat``, the offset applied to the vertices): undoing it gives back the
        frame the file placed the mesh in; its scale is ``mesh_scale``. A body's geoms belong to its
        own link (the last of its chain), re-expressed in the link frame (moved by ``offset``).
        """
        m = self.model
        out: dict[str, list[ShapeFacts]] = {"world": []} if self._world_is_root else {}
        shift: dict[int, Pose] = {0: Pose()}
        owner: dict[int, str] = {0: "world"}
        for body in self._bodies:
            out.update({link: [] for link in body.links})
            shift[body.index] = Pose(np.eye(3), -body.offset)
            owner[body.index] = body.name
        for g in range(m.ngeom):
            b = int(m.geom_bodyid[g])
            collides = bool(int(m.geom_contype[g]) | int(m.geom_conaffinity[g]))
            if (b == 0 and not self._world_is_root) or not collides:
                continue
            kind = _GEOMS.get(int(m.geom_type[g]), f"type-{int(m.geom_type[g])}")
            size = np.array(m.geom_size[g], dtype=float)
            pose = Pose(matrix_from_quat_wxyz(m.geom_quat[g]), np.array(m.geom_pos[g], dtype=float))
            if kind == "box":
                size = 2.0 * size
            elif kind == "sphere":
                size = size[:1]
            elif kind in ("cylinder", "capsule"):
                size = np.array([size[0], 2.0 * size[1]])
            elif kind == "mesh":
                mesh = int(m.geom_dataid[g])
                size = np.array(m.mesh_scale[mesh], dtype=float)
                offset = Pose(matrix_from_quat_wxyz(m.mesh_quat[mesh]),
                              np.array(m.mesh_pos[mesh], dtype=float))
                pose = pose @ offset.inverse()
            out[owner[b]].append(ShapeFacts(kind, size, shift[b] @ pose))
        return out

    def _set(self, q: dict[str, float], dq: dict[str, float] | None = None) -> None:
        d = self.data
        d.qpos[:] = self.model.qpos0
        d.qvel[:] = 0.0
        for name, qa, va in zip(self._dofs, self._qadr, self._vadr, strict=True):
            d.qpos[qa] = q.get(name, 0.0)
            if dq is not None:
                d.qvel[va] = dq.get(name, 0.0)

    def _motion(self, j: int) -> Pose:
        """Joint j's motion from MuJoCo's qpos (relative to ``qpos0``, where the body sits as compiled),
        as ``mj_kinematics`` applies it: a hinge turns about ``jnt_axis``, a slide moves along it, a
        ball turns by its quaternion."""
        m, d = self.model, self.data
        adr = int(m.jnt_qposadr[j])
        kind = int(m.jnt_type[j])
        if kind == int(mujoco.mjtJoint.mjJNT_HINGE):
            return Pose(axis_angle(np.array(m.jnt_axis[j], dtype=float), float(d.qpos[adr] - m.qpos0[adr])),
                        np.zeros(3))
        if kind == int(mujoco.mjtJoint.mjJNT_SLIDE):
            return Pose(np.eye(3), np.array(m.jnt_axis[j], dtype=float) * float(d.qpos[adr] - m.qpos0[adr]))
        if kind == int(mujoco.mjtJoint.mjJNT_BALL):
            quat = np.array(d.qpos[adr:adr + 4], dtype=float)
            return Pose(matrix_from_quat_wxyz(quat / np.linalg.norm(quat)), np.zeros(3))
        return Pose()

    def link_poses(self, q: dict[str, float]) -> dict[str, Pose]:
        """Every link's frame relative to the root link's. A body's link is its frame (``xpos``,
        ``xmat``) moved to the last joint's anchor; the chain's earlier links follow backwards:
        link_k = link_(k+1) · motion(j_(k+1))⁻¹ · translation(anchor_k − anchor_(k+1))."""
        self._set(q)
        with quiet(self.runtime_warnings):
            mujoco.mj_kinematics(self.model, self.data)
        m, d = self.model, self.data
        world: dict[str, Pose] = {"world": Pose()} if self._world_is_root else {}
        for body in self._bodies:
            b = body.index
            frame = Pose(d.xmat[b].reshape(3, 3).copy(), d.xpos[b].copy()) @ Pose(np.eye(3), body.offset)
            world[body.name] = frame
            for k in range(len(body.joints) - 2, -1, -1):
                later = body.joints[k + 1]
                step = np.asarray(m.jnt_pos[body.joints[k]], dtype=float) - m.jnt_pos[later]
                frame = frame @ self._motion(later).inverse() @ Pose(np.eye(3), step)
                world[body.links[k]] = frame
        base = world.get(self.root, Pose()).inverse()
        return {name: base @ pose for name, pose in world.items()}

    def mass_matrix(self, q: dict[str, float]) -> Array:
        self._set(q)
        full = np.zeros((self.model.nv, self.model.nv))
        with quiet(self.runtime_warnings):
            mujoco.mj_forward(self.model, self.data)
            if hasattr(self.data, "qM"):  # MuJoCo < 4: mj_fullM(m, dst, qM)
                mujoco.mj_fullM(self.model, full, self.data.qM)
            else:  # MuJoCo ≥ 4: mj_fullM(m, d, dst)
                mujoco.mj_fullM(self.model, self.data, full)
        idx = np.asarray(self._vadr, dtype=int)
        return full[np.ix_(idx, idx)]

    def bias(self, q: dict[str, float], dq: dict[str, float]) -> Array:
        self._set(q, dq)
        with quiet(self.runtime_warnings):
            mujoco.mj_forward(self.model, self.data)
        return np.array(self.data.qfrc_bias[np.asarray(self._vadr, dtype=int)], dtype=float)

    def close(self) -> None:
        return None


def load(model: Path | Robot, renames: Renames, *, root: str) -> MujocoModel:
    if isinstance(model, Robot):
        raise TypeError("the MuJoCo adapter reads the written MJCF file")
    return MujocoModel(Path(model), root)


class MujocoSimulator:
    """The fixed-base model integrated by MuJoCo (semi-implicit Euler, contacts off)."""

    engine = "mujoco"

    def __init__(self, path: Path, renames: Renames, root: str, dt: float, armature: bool = True,
                 inertials: dict[str, tuple[float, float]] | None = None) -> None:
        # Another engine's documented approximation: a mass on links that are no MuJoCo body of their
        # own (the intermediates of a multi-joint body) needs the body split (same kinematics).
        self.inner = MujocoModel(path, root, actuated=True, split={n for n in inertials or {} if "__" in n})
        self.runtime_warnings = self.inner.runtime_warnings  # compiling and stepping (see ``quiet``)
        m = self.inner.model
        offsets = {body.index: body.offset for body in self.inner._bodies}
        for body, (mass, moment) in (inertials or {}).items():
            b = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, body)
            if b == 0 or body == root:
                continue  # the world, or the welded root: its mass takes part in no dynamics
            if b < 0:
                raise ValueError(f"{path.name}: no body named {body!r}")
            # At the link origin (where the other engine puts it): the body's last joint's anchor, which
            # is not the body frame when the joint has a pos (humanoid's abdomen joints: 0 0 .065).
            m.body_mass[b], m.body_inertia[b] = mass, (moment, moment, moment)
            m.body_ipos[b], m.body_iquat[b] = offsets[b], (1.0, 0.0, 0.0, 0.0)
        m.opt.timestep = dt
        m.opt.integrator = int(mujoco.mjtIntegrator.mjINT_EULER)
        m.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_CONTACT)
        # The replay tests contact-free inertial dynamics: joint limits are layer 1's, and MuJoCo's
        # soft limit constraints differ from PyBullet's (which the PyBullet worker makes inert too).
        m.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_LIMIT)
        # Equality constraints (mimic couplings, closed loops) are off too: PyBullet ignores URDF
        # <mimic> and a URDF holds no loop, so both integrate the open tree (the caller says so).
        m.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_EQUALITY)
        self.equalities = int(m.neq)
        # The replay tests inertial data (mass matrix, bias, integrator): the joints' passive terms
        # are left out, as the PyBullet worker zeroes all damping (its 0.04 default and the URDF's
        # <dynamics damping>). MuJoCo's joint damping, friction loss and stiffness are zeroed on the
        # compiled model, and armature too unless the caller keeps it; ``left_out`` says what was there.
        self.left_out = self._zero_passive(keep_armature=armature)
        self.renames = renames
        self.settings = {**self.inner.settings, "integrator": "Euler", "timestep": dt, "contacts": "disabled",
                         "joint_limits": "disabled (mjDSBL_LIMIT)",
                         "equality_constraints": f"disabled (mjDSBL_EQUALITY), {int(m.neq)} in the model",
                         "armature": ("as in the file" if armature
                                      else "zeroed (the URDF cannot hold it, MK820)"),
                         "passive_joint_terms": ("dof_damping, dof_frictionloss and jnt_stiffness zeroed"
                                                 + ("" if armature else ", dof_armature zeroed")),
                         "left_out": {k: dict(sorted(v.items())) for k, v in sorted(self.left_out.items())},
                         "inertials_replaced": {k: list(v) for k, v in sorted((inertials or {}).items())},
                         "torques": ("the PD law as affine actuators (gain kp, bias 0, -kp, -kd; the file's "
                                     "actuators removed, joint actuatorfrcrange off), targets as controls, "
                                     "stepped by mujoco.rollout")}

    def _zero_passive(self, keep_armature: bool) -> dict[str, dict[str, float]]:
        """Zero the joints' damping, friction loss, stiffness (and armature unless kept) on the compiled
        model; returns, per quantity, the joints (written names) that had a non-zero value."""
        m = self.inner.model
        fields = {"damping": m.dof_damping, "frictionloss": m.dof_frictionloss}
        if not keep_armature:
            fields["armature"] = m.dof_armature
        left_out: dict[str, dict[str, float]] = {}
        for j in range(m.njnt):
            name = self.inner._jname(j)
            adr, width = int(m.jnt_dofadr[j]), _DOF_WIDTH.get(int(m.jnt_type[j]), 1)
            for quantity, values in fields.items():
                value = float(np.max(np.abs(values[adr:adr + width])))
                if value:
                    left_out.setdefault(quantity, {})[name] = value
            if m.jnt_stiffness[j]:
                left_out.setdefault("stiffness", {})[name] = float(m.jnt_stiffness[j])
        for values in fields.values():
            values[:] = 0.0
        m.jnt_stiffness[:] = 0.0
        return left_out

    def dof_names(self) -> list[str]:
        return self.inner.dof_names()

    def replay(self, law: TorqueLaw, seconds: float, dt: float) -> Array:
        """The law as MuJoCo actuators, stepped in C by ``mujoco.rollout``.

        Each law joint's actuator gets gain kp and bias (0, −kp, −kd), so MuJoCo computes
        kp·q*(t_k) − kp·q − kd·q̇ from the state inside every ``mj_step`` (the law of
        :class:`TorqueLaw`, up to the order of the rounding: measured 3e-16 rad from applying
        ``TorqueLaw.torque`` through ``qfrc_applied`` step by step); the targets q*(t_k) are the
        controls, computed beforehand for every step. The other joints' actuators stay at zero."""
        from mujoco import rollout

        m, d = self.inner.model, self.inner.data
        m.opt.timestep = dt
        names = [self.renames.get("joint", {}).get(j, j) for j in law.joints]
        where = {n: i for i, n in enumerate(self.inner.dof_names())}
        qadr = np.asarray([self.inner._qadr[where[n]] for n in names], dtype=int)
        actuator = {int(m.actuator_trnid[a, 0]): a for a in range(m.nu)}
        columns = np.asarray([actuator[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, n)] for n in names],
                             dtype=int)
        kp, kd = np.asarray(law.kp, dtype=float), np.asarray(law.kd, dtype=float)
        m.actuator_gainprm[:, 0] = 0.0
        m.actuator_biasprm[:, :3] = 0.0
        # A joint's actuatorfrcrange (the URDF effort limit, as our MJCF writer keeps it) would clamp
        # the law's torque; qfrc_applied and PyBullet's TORQUE_CONTROL are not clamped: off here.
        m.jnt_actfrclimited[:] = 0
        m.actuator_gainprm[columns, 0] = kp
        m.actuator_biasprm[columns, 1] = -kp
        m.actuator_biasprm[columns, 2] = -kd
        steps = round(seconds / dt)
        t = np.arange(steps, dtype=float)[:, None] * dt
        control = np.zeros((steps, m.nu))
        control[:, columns] = np.asarray(law.amplitude) * np.sin(
            2.0 * math.pi * np.asarray(law.frequency) * t + np.asarray(law.phase))
        with quiet(self.runtime_warnings):
            mujoco.mj_resetData(m, d)
            full = int(mujoco.mjtState.mjSTATE_FULLPHYSICS)
            start = np.empty(mujoco.mj_stateSize(m, full))
            mujoco.mj_getState(m, d, start, full)
            state, _ = rollout.rollout(m, d, start, control)
        offset = mujoco.mj_stateSize(m, int(mujoco.mjtState.mjSTATE_TIME))  # the state: time, qpos, ...
        out = np.empty((steps + 1, len(names)))
        out[0] = d.qpos[qadr] if steps == 0 else start[offset + qadr]
        out[1:] = state[0][:, offset + qadr]
        return out

    def close(self) -> None:
        return None


def simulator(model: Path, renames: Renames, *, root: str, dt: float, armature: bool = True,
              inertials: dict[str, tuple[float, float]] | None = None) -> MujocoSimulator:
    return MujocoSimulator(Path(model), renames, root, dt, armature, inertials)
