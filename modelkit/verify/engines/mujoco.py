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
import time
from collections.abc import Collection, Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import mujoco
import numpy as np

from modelkit.formats.mjcf.compiled import MENAGERIE_COLLISION_GROUP, collides_nothing
from modelkit.formats.mjcf.quiet import collected_warnings
from modelkit.model import BALL_KEYS, Robot
from modelkit.spatial import Pose, axis_angle, matrix_from_quat_wxyz
from modelkit.verify.engines import ball_law
from modelkit.verify.engines.protocol import Array, JointFacts, LinkFacts, ShapeFacts, StaticFacts, TorqueLaw

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
    messages: list[str] = []
    try:
        with collected_warnings(mujoco) as messages:
            yield
    finally:
        into.extend(messages)  # complete only once the block has ended
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
TENDON_PASSIVE = ("stiffness", "stiffnesspoly", "damping", "dampingpoly", "frictionloss", "armature")


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
    if welded:  # a keyframe holds the free joint's 7 qpos (convert's `home` of a legged robot): MuJoCo
        for key in list(spec.keys):  # refuses it without the joint, and layers 1-3 use no keyframe
            spec.delete(key)
    if actuated:
        drop_actuators(spec)
        for joint in spec.joints:
            if joint.type in (mujoco.mjtJoint.mjJNT_HINGE, mujoco.mjtJoint.mjJNT_SLIDE):
                act = spec.add_actuator()
                act.target, act.trntype = joint.name, mujoco.mjtTrn.mjTRN_JOINT
                act.gaintype, act.biastype = mujoco.mjtGain.mjGAIN_FIXED, mujoco.mjtBias.mjBIAS_AFFINE
                act.gainprm[0] = 0.0
    model = spec.compile()
    reference_world(model)
    return model, welded


def drop_actuators(spec: Any, driven: Collection[str] | None = None) -> list[str]:
    """The file's actuators deleted, with the sensors that read them and the keyframes' controls (a
    ``home`` keyframe holds one control per position servo; MuJoCo refuses a keyframe whose ``ctrl`` has
    another length: the layer-4 worlds of example-robot-data's TIAGo, whose arm has servos, did not
    load).

    ``driven`` (layer 4): only the actuators on those joints go, where verify's controllers take over;
    the others stay, as the user's robot has them (TIAGo's arm and torso servos hold them while the
    base drives; deleted, the arm folded and the robot left its path by 71 cm). Returns the names of
    the actuators kept (unnamed ones as ``actuator <i>``)."""
    actuators = list(spec.actuators)
    kept: list[int] = []
    deleted: set[str] = set()
    for i, actuator in enumerate(actuators):
        on_joint = actuator.trntype in (mujoco.mjtTrn.mjTRN_JOINT, mujoco.mjtTrn.mjTRN_JOINTINPARENT)
        if driven is None or (on_joint and actuator.target in driven):
            deleted.add(actuator.name)
            spec.delete(actuator)
        else:
            kept.append(i)
    for sensor in list(spec.sensors):  # an actuatorpos/vel/frc sensor of a deleted actuator: MuJoCo
        # refuses the model ("unrecognized name of sensorized object": gymnasium-robotics' Adroit hand)
        if sensor.objtype == mujoco.mjtObj.mjOBJ_ACTUATOR and sensor.objname in deleted - {""}:
            spec.delete(sensor)
    for key in spec.keys:
        ctrl = list(key.ctrl)
        key.ctrl = [ctrl[i] for i in kept] if len(ctrl) == len(actuators) and kept else []
    return [actuators[i].name or f"actuator {i}" for i in kept]


def reference_world(model: Any) -> None:
    """The world layers 1–3 compare engines in, whatever the file's ``<option>`` says (an MJCF source's
    own options are written back by ``convert``: dm_control's finger and swimmer disable gravity, the
    swimmer swims in a fluid): gravity (0, 0, −9.81), no fluid or wind, every feature flag at
    MuJoCo's default (the replay then disables contact, limits and equalities itself)."""
    model.opt.gravity[:] = GRAVITY
    model.opt.density = 0.0
    model.opt.viscosity = 0.0
    model.opt.wind[:] = 0.0
    model.opt.disableflags = 0
    model.opt.enableflags = 0


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
    free: bool = False  # a free joint of its own that the welding left: a floating subtree (MK813)


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
        self._balls: list[tuple[str, int]] = []  # ball joints: name, qpos address of the quaternion
        for j in range(m.njnt):
            if int(m.jnt_type[j]) in (int(mujoco.mjtJoint.mjJNT_HINGE), int(mujoco.mjtJoint.mjJNT_SLIDE)):
                self._dofs.append(self._jname(j))
                self._qadr.append(int(m.jnt_qposadr[j]))
                self._vadr.append(int(m.jnt_dofadr[j]))
            elif int(m.jnt_type[j]) == int(mujoco.mjtJoint.mjJNT_BALL):
                self._balls.append((self._jname(j), int(m.jnt_qposadr[j])))
        self._bodies = [self._body(b) for b in range(1, m.nbody)]
        self._link_of = {link: body for body in self._bodies for link in body.links}
        self._sites = self._frame_sites()
        self.settings: dict[str, Any] = {
            "version": mujoco.__version__,
            "file": path.name,
            "base": ("root body's free joint deleted through MjSpec" if deleted
                     else "root body has no free joint"),
            "gravity": list(GRAVITY),
            "world": "no fluid or wind, MuJoCo's default feature flags (the file's own <option> set aside)",
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
        loose = any(int(m.jnt_type[j]) == free for j in range(start, start + count))
        return _Body(b, name, self._bname(parent) if parent > 0 else "world", chain, links, offset, loose)

    def _frame_sites(self) -> dict[str, int]:
        """Named sites on a body whose name no link has and that nothing uses (a sensor, an equality, an
        actuator, a tendon): frames a writer made of massless links (MK873)."""
        m = self.model
        site = int(mujoco.mjtObj.mjOBJ_SITE)
        used = {int(m.sensor_objid[i]) for i in range(m.nsensor) if int(m.sensor_objtype[i]) == site}
        for e in range(m.neq):
            if int(m.eq_objtype[e]) == site:
                used.update((int(m.eq_obj1id[e]), int(m.eq_obj2id[e])))
        by_site = (int(mujoco.mjtTrn.mjTRN_SITE), int(mujoco.mjtTrn.mjTRN_SLIDERCRANK))
        for a in range(m.nu):
            if int(m.actuator_trntype[a]) in by_site:
                used.update(int(i) for i in m.actuator_trnid[a])
        used.update(int(m.wrap_objid[w]) for w in range(m.nwrap)
                    if int(m.wrap_type[w]) == int(mujoco.mjtWrap.mjWRAP_SITE))
        links = {link for body in self._bodies for link in body.links} | {"world"}
        out: dict[str, int] = {}
        for s in range(m.nsite):
            name = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_SITE, s)
            if name and name not in links and s not in used and int(m.site_bodyid[s]) > 0:
                out.setdefault(name, s)
        return out

    @property
    def _world_is_root(self) -> bool:
        """The root is MuJoCo's world body (a source whose top bodies hang from a synthesised
        ``world`` link by their joints): it is a link, massless, at the identity."""
        return self._root_id == 0

    def dof_names(self) -> list[str]:
        return list(self._dofs)

    def _locked(self) -> dict[int, float]:
        """Joints held at one value by a joint equality of constant ``polycoef`` (no second joint):
        how the MJCF writer writes a source range whose lower and upper limits are equal, which
        MuJoCo's ``range`` cannot hold (its autolimits read ``0 0`` as no limit)."""
        m = self.model
        locked: dict[int, float] = {}
        for e in range(m.neq):
            if int(m.eq_type[e]) != int(mujoco.mjtEq.mjEQ_JOINT) or int(m.eq_obj2id[e]) != -1:
                continue
            coef = np.asarray(m.eq_data[e][:5], dtype=float)
            if not np.any(coef[1:]):
                locked[int(m.eq_obj1id[e])] = float(coef[0])
        return locked

    def static(self) -> StaticFacts:
        m = self.model
        facts = StaticFacts()
        locked = self._locked()
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
            if body.free and b != self._root_id:  # the MJCF writer's top-level body for a floating joint
                facts.joints[f"floating:{body.name}"] = JointFacts("floating", body.parent, body.name,
                                                                   np.zeros(3))
            elif not body.joints and b != self._root_id:
                facts.joints[f"fixed:{body.name}"] = JointFacts("fixed", body.parent, body.name, np.zeros(3))
            parent = body.parent
            for j, child in zip(body.joints, body.links if body.joints else (), strict=True):
                jtype = _TYPES.get(int(m.jnt_type[j]), "unknown")
                moving = jtype in ("revolute", "prismatic")
                lower, upper = -math.inf, math.inf
                if moving and m.jnt_limited[j]:
                    lower, upper = float(m.jnt_range[j][0]), float(m.jnt_range[j][1])
                elif moving and j in locked:
                    lower = upper = locked[j]
                axis = np.array(m.jnt_axis[j], dtype=float) if moving else np.zeros(3)
                facts.joints[self._jname(j)] = JointFacts(jtype, parent, child, axis, lower, upper)
                parent = child
        for name, s in self._sites.items():
            body = self._bodies[int(m.site_bodyid[s]) - 1]
            facts.frames[name] = JointFacts("fixed", body.name, name, np.zeros(3))
        facts.shapes = self.shapes()
        return facts

    def shapes(self) -> dict[str, list[ShapeFacts]]:
        """Collision geoms (``contype | conaffinity`` non-zero, or named by a ``<pair>``; in a file that
        collides nothing itself, those of group 3) per link, in the link frame.

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
        paired = {int(g) for k in range(m.npair) for g in (m.pair_geom1[k], m.pair_geom2[k])}
        grouped = collides_nothing(m)  # the collisions are the scene's: group 3 holds the shapes
        for g in range(m.ngeom):
            b = int(m.geom_bodyid[g])
            collides = (bool(int(m.geom_contype[g]) | int(m.geom_conaffinity[g])) or g in paired
                        or (grouped and int(m.geom_group[g]) == MENAGERIE_COLLISION_GROUP))
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
        for name, qa in self._balls:  # R = Rx·Ry·Rz from the three angles (BALL_KEYS), after qpos0
            turn = np.eye(3)
            for key, unit in zip(BALL_KEYS, np.eye(3), strict=True):
                turn = turn @ axis_angle(unit, q.get(name + key, 0.0))
            start = matrix_from_quat_wxyz(np.array(self.model.qpos0[qa:qa + 4], dtype=float))
            quat = np.zeros(4)
            mujoco.mju_mat2Quat(quat, np.ascontiguousarray(start @ turn).ravel())
            d.qpos[qa:qa + 4] = quat

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
        for name, s in self._sites.items():
            world[name] = Pose(d.site_xmat[s].reshape(3, 3).copy(), d.site_xpos[s].copy())
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

    # ---- a ball joint in the coordinates of the URDF writer's chain (layer 3a) ----------------

    def dof_names_with_balls(self) -> list[str]:
        """The hinge and slide degrees of freedom, then each ball joint's three (``NAME#x``...)."""
        return [*self._dofs, *(name + key for name, _ in self._balls for key in BALL_KEYS)]

    def _chain_map(self, q: dict[str, float]) -> Array:
        """T (nv × the names of :meth:`dof_names_with_balls`): qvel = T·rates, a ball's rates being
        those of the chain's three angles at ``q`` (ω in the child's frame = J·(ȧ, ḃ, ċ),
        ``ball_law.chain_jacobian``; the rest orientation ``qpos0`` turns nothing of it)."""
        m = self.model
        names = self.dof_names_with_balls()
        out = np.zeros((m.nv, len(names)))
        for column, va in enumerate(self._vadr):
            out[va, column] = 1.0
        column = len(self._vadr)
        for name, _ in self._balls:
            va = int(m.jnt_dofadr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, name)])
            pitch, yaw = (q.get(name + key, 0.0) for key in BALL_KEYS[1:])
            jacobian = ball_law.chain_jacobian(pitch, yaw)
            out[va:va + 3, column:column + 3] = np.array(jacobian, dtype=float).reshape(3, 3)
            column += 3
        return out

    def mass_matrix_with_balls(self, q: dict[str, float]) -> Array:
        """Tᵀ·M·T (:meth:`_chain_map`): the mass matrix in the chain's coordinates, a ball's three
        angles included, comparable with the Pinocchio reference's pieces."""
        self._set(q)
        full = np.zeros((self.model.nv, self.model.nv))
        with quiet(self.runtime_warnings):
            mujoco.mj_forward(self.model, self.data)
            if hasattr(self.data, "qM"):
                mujoco.mj_fullM(self.model, full, self.data.qM)
            else:
                mujoco.mj_fullM(self.model, self.data, full)
        t = self._chain_map(q)
        return np.asarray(t.T @ full @ t)

    def bias_with_balls(self, q: dict[str, float], dq: dict[str, float]) -> Array:
        """Tᵀ·bias, a ball at rest (its chain rates 0, so T's derivative adds nothing)."""
        self._set(q, dq)
        with quiet(self.runtime_warnings):
            mujoco.mj_forward(self.model, self.data)
        return np.asarray(self._chain_map(q).T @ np.array(self.data.qfrc_bias, dtype=float))

    def close(self) -> None:
        return None


def load(model: Path | Robot, renames: Renames, *, root: str) -> MujocoModel:
    if isinstance(model, Robot):
        raise TypeError("the MuJoCo adapter reads the written MJCF file")
    return MujocoModel(Path(model), root)


def _hanging(m: Any, link: str, frames: Mapping[str, tuple[str, Pose]], offsets: Mapping[int, Array]
             ) -> tuple[int, Array] | None:
    """The body ``link`` hangs from by fixed joints (``frames``: link → parent, pose in the parent) and
    the link origin in that body's frame; None when it hangs from nothing the model holds. A link
    frame is its body's frame moved to the body's last joint's anchor (``offsets``), not turned."""
    position = np.zeros(3)
    for _ in range(len(frames) + 1):
        if link not in frames:
            return None
        parent, pose = frames[link]
        rotation = np.asarray(pose.rotation, dtype=float)
        position = np.asarray(pose.translation, dtype=float) + rotation @ position
        b = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, parent)
        if b >= 0:
            return b, (offsets[b] if b > 0 else np.zeros(3)) + position
        link = parent
    return None


def _add_point_inertia(m: Any, body: int, mass: float, moment: float, pos: Array) -> None:
    """Add ``mass`` kg with ``moment`` kg·m² on each axis at ``pos`` (body frame) to the compiled
    ``body``: what a URDF's link on a fixed joint adds to its parent in any rigid-body engine. The
    body's COM, principal moments and axes are recomputed (parallel axis theorem, then ``eigh``)."""
    m0 = float(m.body_mass[body])
    c0 = np.array(m.body_ipos[body], dtype=float)
    flat = np.zeros(9)
    mujoco.mju_quat2Mat(flat, np.array(m.body_iquat[body], dtype=float))
    r0 = flat.reshape(3, 3)
    total = m0 + mass
    com = (m0 * c0 + mass * pos) / total

    def shifted(d: Array) -> Array:
        return float(d @ d) * np.eye(3) - np.outer(d, d)

    tensor = (r0 @ np.diag(np.array(m.body_inertia[body], dtype=float)) @ r0.T + m0 * shifted(c0 - com)
              + moment * np.eye(3) + mass * shifted(pos - com))
    moments, axes = np.linalg.eigh(0.5 * (tensor + tensor.T))
    if np.linalg.det(axes) < 0.0:
        axes[:, 2] = -axes[:, 2]
    quat = np.zeros(4)
    mujoco.mju_mat2Quat(quat, axes.reshape(-1))
    set_inertial(m, body, total, com, moments, quat)


def set_inertial(m: Any, body: int, mass: float, ipos: Any, moments: Any, iquat: Any) -> None:
    """A compiled body's mass, COM, principal moments and axes, set. ``body_sameframe`` is cleared:
    MuJoCo takes a body flagged there (its COM frame was its body frame at compile time) to have its
    COM at the body origin whatever ``body_ipos`` says (the replay of example-robot-data's UR5 given as
    convert's MJCF, whose ``tool0`` site's 1e-6 kg went to ``wrist_3_link``: 3.7e-7 rad off PyBullet)."""
    m.body_mass[body], m.body_ipos[body] = mass, ipos
    m.body_inertia[body], m.body_iquat[body] = moments, iquat
    m.body_sameframe[body] = 0


class MujocoSimulator:
    """The fixed-base model integrated by MuJoCo (semi-implicit Euler, contacts off)."""

    engine = "mujoco"

    def __init__(self, path: Path, renames: Renames, root: str, dt: float, armature: bool = True,
                 inertials: dict[str, tuple[float, float]] | None = None,
                 principal: dict[str, tuple[float, Array, Array, Array]] | None = None,
                 frames: dict[str, tuple[str, Pose]] | None = None) -> None:
        # Another engine's documented approximation: a mass on links that are no MuJoCo body of their
        # own (the intermediates of a multi-joint body) needs the body split (same kinematics).
        self.inner = MujocoModel(path, root, actuated=True, split={n for n in inertials or {} if "__" in n})
        self.runtime_warnings = self.inner.runtime_warnings  # compiling and stepping (see ``quiet``)
        m = self.inner.model
        offsets = {body.index: body.offset for body in self.inner._bodies}
        hung: list[tuple[int, float, float, Array]] = []
        for body, (mass, moment) in (inertials or {}).items():
            b = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, body)
            if b == 0 or body == root:
                continue  # the world, or the welded root: its mass takes part in no dynamics
            if b < 0:  # a link the MJCF holds as no body (a frame as a site, MK873; a sensor): its mass
                placed = _hanging(m, body, frames or {}, offsets)  # goes to the body it hangs from,
                if placed is None:  # once that body's own inertia is set
                    raise ValueError(f"{path.name}: no body named {body!r}")
                if placed[0] not in (0, self.inner._root_id):
                    hung.append((placed[0], mass, moment, placed[1]))
                continue
            # At the link origin (where the other engine puts it): the body's last joint's anchor, which
            # is not the body frame when the joint has a pos (humanoid's abdomen joints: 0 0 .065).
            set_inertial(m, b, mass, offsets[b], (moment, moment, moment), (1.0, 0.0, 0.0, 0.0))
        # Another engine's diagonalised tensors (``principal``: mass, COM in the link frame, principal
        # moments, axes as a quaternion xyzw), for bodies that are one link each: both engines then
        # integrate the same numbers, and the replay tests the dynamics, not PyBullet's importer.
        single = {body.index for body in self.inner._bodies if len(body.links) == 1}
        for body, (mass, com, moments, quat_xyzw) in (principal or {}).items():
            b = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, body)
            if b <= 0 or body == root or b not in single:
                continue
            set_inertial(m, b, mass, offsets[b] + com, moments,
                         (quat_xyzw[3], quat_xyzw[0], quat_xyzw[1], quat_xyzw[2]))
        for b, mass, moment, pos in hung:  # after ``principal``, which sets the whole body
            _add_point_inertia(m, b, mass, moment, pos)
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
                                                 + ("" if armature else ", dof_armature zeroed")
                                                 + "; tendon stiffness, damping, friction loss and armature "
                                                   "zeroed; body_gravcomp zeroed"),
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
        # An MJCF source's tendons are written back to MJCF only: their springs, damping, friction loss
        # and armature act on the joints they couple, which the other engine's URDF has no tendon for
        for quantity in TENDON_PASSIVE:
            values = getattr(m, f"tendon_{quantity}", None)
            if values is None:
                continue
            for t in range(m.ntendon):
                value = float(np.max(np.abs(values[t])))
                if value:
                    name = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_TENDON, t) or f"tendon {t}"
                    left_out.setdefault(f"tendon {quantity}", {})[name] = value
            values[...] = 0.0
        # An MJCF source's gravity compensation (body gravcomp) is MuJoCo's alone: no URDF holds it
        # (MK808), so PyBullet's arm falls under gravity where MuJoCo's would float
        for b in range(m.nbody):
            if m.body_gravcomp[b]:
                name = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, b) or f"body {b}"
                left_out.setdefault("body gravity compensation", {})[name] = float(m.body_gravcomp[b])
        m.body_gravcomp[:] = 0.0
        return left_out

    def dof_names(self) -> list[str]:
        return self.inner.dof_names()

    def replay(self, law: TorqueLaw, seconds: float, dt: float) -> Array:
        """The law as MuJoCo actuators, stepped in C by ``mujoco.rollout``, from q = dq = 0
        (:meth:`replay_from`)."""
        return self.replay_from(law, seconds, dt, None)

    def replay_from(self, law: TorqueLaw, seconds: float, dt: float, start_q: Array | None) -> Array:
        """The law as MuJoCo actuators, stepped in C by ``mujoco.rollout``, from q = ``start_q``
        (one value per law joint, source order; None: q = 0) and dq = 0. Layer 3b replays from a
        start perturbed by 1e-12 rad to measure how much the model itself amplifies a tiny difference.

        Each law joint's actuator gets gain kp and bias (0, −kp, −kd), so MuJoCo computes
        kp·q*(t_k) − kp·q − kd·q̇ from the state inside every ``mj_step`` (the law of
        :class:`TorqueLaw`, up to the order of the rounding: measured 3e-16 rad from applying
        ``TorqueLaw.torque`` through ``qfrc_applied`` step by step); the targets q*(t_k) are the
        controls, computed beforehand for every step. The other joints' actuators stay at zero."""
        from mujoco import rollout

        m, d = self.inner.model, self.inner.data
        m.opt.timestep = dt
        in_balls = {c + k for _, c in law.ball_columns() for k in range(3)}
        scalar = [i for i in range(len(law.joints)) if i not in in_balls]
        names = [self.renames.get("joint", {}).get(law.joints[i], law.joints[i]) for i in scalar]
        where = {n: i for i, n in enumerate(self.inner.dof_names())}
        qadr = np.asarray([self.inner._qadr[where[n]] for n in names], dtype=int)
        actuator = {int(m.actuator_trnid[a, 0]): a for a in range(m.nu)}
        columns = np.asarray([actuator[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, n)] for n in names],
                             dtype=int)
        kp = np.asarray([law.kp[i] for i in scalar], dtype=float)
        kd = np.asarray([law.kd[i] for i in scalar], dtype=float)
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
        control[:, columns] = np.asarray([law.amplitude[i] for i in scalar]) * np.sin(
            2.0 * math.pi * np.asarray([law.frequency[i] for i in scalar]) * t
            + np.asarray([law.phase[i] for i in scalar]))
        if law.balls:
            return self._replay_with_balls(law, scalar, qadr, control, dt, start_q)
        with quiet(self.runtime_warnings):
            mujoco.mj_resetData(m, d)
            full = int(mujoco.mjtState.mjSTATE_FULLPHYSICS)
            start = np.empty(mujoco.mj_stateSize(m, full))
            mujoco.mj_getState(m, d, start, full)
            if start_q is not None:
                start[mujoco.mj_stateSize(m, int(mujoco.mjtState.mjSTATE_TIME)) + qadr] += np.asarray(start_q)
            state, _ = rollout.rollout(m, d, start, control)
        offset = mujoco.mj_stateSize(m, int(mujoco.mjtState.mjSTATE_TIME))  # the state: time, qpos, ...
        out = np.empty((steps + 1, len(names)))
        out[0] = d.qpos[qadr] if steps == 0 else start[offset + qadr]
        out[1:] = state[0][:, offset + qadr]
        return out

    def _replay_with_balls(self, law: TorqueLaw, scalar: list[int], qadr: Array, control: Array, dt: float,
                           start_q: Array | None) -> Array:
        """:meth:`replay_from` for a law with ball joints: stepped from Python, each ball's torque
        (``ball_law.ball_torque``, child frame: MuJoCo's ball coordinates) set in ``qfrc_applied``
        from the state before every ``mj_step``; the scalar joints keep their actuators. A ball's
        columns are the rotation vector of its orientation; ``start_q`` turns it by that vector."""
        m, d = self.inner.model, self.inner.data
        written = self.renames.get("joint", {})
        balls = []
        for name, column in law.ball_columns():
            j = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, written.get(name, name))
            balls.append((column, int(m.jnt_qposadr[j]), int(m.jnt_dofadr[j]), law.kp[column:column + 3],
                          law.kd[column:column + 3], law.amplitude[column:column + 3],
                          law.frequency[column:column + 3], law.phase[column:column + 3]))
        steps = len(control)
        out = np.empty((steps + 1, len(law.joints)))
        scalar_columns = np.asarray(scalar, dtype=int)

        def record(row: int) -> None:
            out[row, scalar_columns] = d.qpos[qadr]
            for column, qa, *_ in balls:
                orientation = ball_law.quaternion_matrix(*d.qpos[qa:qa + 4])
                out[row, column:column + 3] = ball_law.rotation_log(orientation)

        with quiet(self.runtime_warnings):
            mujoco.mj_resetData(m, d)
            if start_q is not None:
                start = np.asarray(start_q, dtype=float)
                d.qpos[qadr] += start[scalar_columns]
                for column, qa, *_ in balls:
                    turn = np.array(ball_law.rotation_exp(list(start[column:column + 3])), dtype=float)
                    mujoco.mju_mat2Quat(d.qpos[qa:qa + 4], turn)
            step, applied = mujoco.mj_step, d.qfrc_applied
            for k in range(steps):
                record(k)
                d.ctrl[:] = control[k]
                time_k = k * dt
                for _, qa, va, kp, kd, amplitude, frequency, phase in balls:
                    orientation = ball_law.quaternion_matrix(*d.qpos[qa:qa + 4])
                    applied[va:va + 3] = ball_law.ball_torque(orientation, d.qvel[va:va + 3], time_k, kp, kd,
                                                              amplitude, frequency, phase)
                step(m, d)
            record(steps)
        return out

    def close(self) -> None:
        return None


def simulator(model: Path, renames: Renames, *, root: str, dt: float, armature: bool = True,
              inertials: dict[str, tuple[float, float]] | None = None,
              principal: dict[str, tuple[float, Array, Array, Array]] | None = None,
              frames: dict[str, tuple[str, Pose]] | None = None) -> MujocoSimulator:
    return MujocoSimulator(Path(model), renames, root, dt, armature, inertials, principal, frames)


# ---- layer 4: the floating-base robot driven on a floor ----------------------------------------

VELOCITY_KV = 100.0
"""Gain (N·m·s/rad) of the velocity servo of a velocity-mode joint (the track rollers): MuJoCo's
``velocity`` actuator, force ``kv·(target − q̇)`` bounded by ``variant.servo_torque_limit`` (the
same bound as PyBullet's VELOCITY_CONTROL maximum force), its damping integrated implicitly by
``implicitfast``. Choreonoid's velocity mode and PyBullet's motor are velocity constraints; at this
gain the speed error under a load of 1 N·m is 0.01 rad/s (0.1 % at 0.5 m/s)."""

SERVO_INTEGRAL_TIME = 0.05
"""s: the integral time of the roller servos (an ``intvelocity`` actuator beside the ``velocity`` one:
force ``kp·(∫target − q)``, ``kp = kv / SERVO_INTEGRAL_TIME``). A proportional velocity servo turns
slower than its target by ``τ / kv`` under a load τ: a skidding track's roller carries up to μ·N·r
(about 1.1 N·m on the tutorial's spin), so MuJoCo's rollers lost 0.08–0.7 rad over 10 s against
PyBullet's velocity constraint, which keeps the speed exactly. With the integral part the roller's
angle follows ``∫target`` to ``τ / kp`` (under 5 mrad), as a velocity constraint's does. Stable
explicitly: ``sqrt(kp / J)·dt`` is 0.9 on a roller alone (J 0.36 g·m², kp 317), below 2."""

LAW_PLUGIN = "mujoco.pid"
"""MuJoCo's bundled PID actuator plugin (``plugin/libactuator.so``, loaded by ``import mujoco``): with
only ``kd`` set its force is ``kd·(0 − q̇)``, computed in C inside every ``mj_step``. It is the one
velocity feedback MuJoCo integrates **explicitly** under ``implicitfast``: plugins add no
``∂force/∂q̇`` to the implicit step (MuJoCo's own TODO in ``pid.cc``), whereas a ``general``/
``velocity`` actuator's ``kv`` term is integrated implicitly (measured: 6e-8 rad/s off the explicit
``qfrc_applied`` law after 20 steps on a 1 kg test wheel), which would change the physics."""


def affine_laws(controllers: list[Any], command: Any) -> list[tuple[np.ndarray, np.ndarray]] | None:
    """Each controller's law for ``command`` as ``(offset, gain)``, ``output = offset − gain·q̇``
    (the controllers' optional ``affine_law``), or None when one of them has no such method (its
    law is not affine in q̇ with command-only coefficients: the driver calls it every step)."""
    out = []
    for c in controllers:
        law = getattr(c, "affine_law", None)
        if law is None:
            return None
        offset, gain = law(command)
        out.append((np.array(offset, dtype=float), np.array(gain, dtype=float)))
    return out


def floor_clearance(model: mujoco.MjModel, data: mujoco.MjData, floor: int) -> float:
    """The smallest distance between the floor geom and any robot geom that collides with it, at
    the data's current pose (``mj_geomDistance``: MuJoCo's own collision geometry)."""
    best = math.inf
    fromto = np.zeros(6)
    for g in range(model.ngeom):
        if g == floor or int(model.geom_bodyid[g]) == 0:
            continue
        if not (int(model.geom_contype[g]) & int(model.geom_conaffinity[floor])
                or int(model.geom_conaffinity[g]) & int(model.geom_contype[floor])):
            continue
        best = min(best, float(mujoco.mj_geomDistance(model, data, floor, g, 10.0, fromto)))
    return best


class MujocoDriver:
    """The written floating-base MJCF on a floor plane, verification.md §6's settings, the seed's
    controllers (``make_controllers``) applied every physics step: :class:`modelkit.verify.drive.Driver`.

    Two ways of applying them, the same physics (``tests/test_verify_drivers_fast.py``: ≤ 1e-9 m/rad
    apart over 10 s; they differ in the rounding of ``kd·q* − kd·q̇`` against ``kd·(q* − q̇)``):

    * **laws as actuators** (``fast``, the default, when every controller has ``affine_law``): the
      seed's laws are ``u = offset − gain·q̇`` with offset and gain fixed between command changes.
      MuJoCo computes ``−gain·q̇`` itself, in every step, through a :data:`LAW_PLUGIN` actuator per
      torque joint (``kd`` = the gain; gear 1 while a profile runs, 0 otherwise, which makes it
      inert), ``offset`` goes into ``qfrc_applied`` and a velocity target into the servo's ``ctrl``,
      set at each command change; Python steps ``mj_step(m, d, nstep)`` from one sample or command
      change to the next, so no Python runs per physics step. A joint's ``actuatorfrcrange`` (the
      file's effort limit) is switched off on those joints (``jnt_actfrclimited`` 0) and the law
      actuators have no force range: the Python law is not clamped either;
    * **per step** (the fallback: a controller without ``affine_law``, a gain that changes with the
      command, ``fast=False``): ``output`` called before every ``mj_step``, torques through
      ``qfrc_applied``, velocity targets through the servo's ``ctrl``.

    The robot is loaded as written (its ``<option>``, contact parameters and collision filters
    untouched, MK825); the world around it: a floor plane with MuJoCo's default contact
    (``modelkit_floor``, z = 0: what a user adds); the timestep set to the scenario's ``dt`` only when
    the file's differs (said in the settings); the file's actuators on the joints verify drives
    deleted, as a controller takes them, the others kept and holding the start pose (torques go
    through ``qfrc_applied`` on the controlled dofs, not clamped; a
    velocity-mode joint gets a ``velocity`` actuator, the tracks' servo)."""

    engine = "mujoco"

    def __init__(self, model: Path, renames: Renames, drive: Any, scenario: Any,
                 factory: str | None = None, fast: bool = True) -> None:
        from modelkit.verify.drive import Command
        from modelkit.verify.drive import variant as v

        self.path = Path(model)
        self.renames = renames
        self.drive = drive
        self.factory = factory or v.CONTROLLERS
        self.warnings: list[str] = []
        self.controllers = v.load_factory(self.factory)(drive.as_dict(), v.scenario_data(scenario))
        joints = renames.get("joint", {})
        links = renames.get("link", {})
        controlled = v.controlled_joints(self.controllers)
        velocity = [j for j, mode in controlled if mode == "velocity"]
        servoed = [g for j in velocity for g in v.driven_groups(drive, j)]
        # The joints verify drives (controllers, servoed rollers, wheels): the file's actuators on
        # them go; the others' stay and hold their joints as in the user's world.
        driven_joints = {joints.get(j, j) for j in
                         {j for j, _ in controlled} | set(servoed) | set(v.wheel_joints(drive))
                         | {r for rollers in drive.rollers.values() for r in rollers}}
        # The laws' gains at the zero command: one explicit damping actuator per torque joint of
        # non-zero gain. A velocity-mode law with a q̇ term is not the servo's: per step, then.
        probe = affine_laws(self.controllers, Command(0.0)) if fast else None
        if probe is not None and any(c.mode == "velocity" and np.any(gain != 0.0)
                                     for c, (_, gain) in zip(self.controllers, probe, strict=True)):
            probe = None
        law_gain: dict[str, float] = {}
        for c, law in zip(self.controllers, probe, strict=True) if probe is not None else ():
            if c.mode == "torque":
                law_gain.update((j, float(g)) for j, g in zip(c.joints, law[1], strict=True) if g != 0.0)
        def build(with_laws: bool) -> mujoco.MjModel:
            """The world's spec compiled: options, floor, servos; ``with_laws``: the law actuators."""
            spec = mujoco.MjSpec.from_file(str(self.path))
            o = spec.option
            self.file_timestep = float(o.timestep)
            if o.timestep != scenario.dt:  # the scenario's step; said in the settings
                o.timestep = scenario.dt
            self.file_actuators = drop_actuators(spec, driven_joints)
            floor = spec.worldbody.add_geom()  # MuJoCo's default contact: what a user's floor has
            floor.name, floor.type = "modelkit_floor", mujoco.mjtGeom.mjGEOM_PLANE
            floor.size = [0.0, 0.0, 1.0]
            for name in servoed:
                act = spec.add_actuator()
                act.name, act.target, act.trntype = f"modelkit_servo_{name}", joints.get(name, name), \
                    mujoco.mjtTrn.mjTRN_JOINT
                act.set_to_velocity(kv=VELOCITY_KV)
                act = spec.add_actuator()  # the servo's integral part (see SERVO_INTEGRAL_TIME)
                act.name, act.target, act.trntype = f"modelkit_servoint_{name}", joints.get(name, name), \
                    mujoco.mjtTrn.mjTRN_JOINT
                act.set_to_intvelocity(kp=1.0)
                act.actlimited = mujoco.mjtLimited.mjLIMITED_FALSE
            if with_laws:
                spec.activate_plugin(LAW_PLUGIN)
            for name, gain in (law_gain if with_laws else {}).items():
                # repr(gain) is the shortest string strtod reads back as the same double
                spec.add_plugin(name=f"modelkit_law_{name}", plugin_name=LAW_PLUGIN, active=False
                                ).config = {"kd": repr(gain)}
                act = spec.add_actuator()
                act.name, act.target, act.trntype = f"modelkit_law_{name}", joints.get(name, name), \
                    mujoco.mjtTrn.mjTRN_JOINT
                act.plugin.name, act.plugin.active = f"modelkit_law_{name}", True
            return spec.compile()

        with quiet(self.warnings):
            try:
                self.model = build(bool(law_gain))
            except (AttributeError, ValueError) as exc:  # no mujoco.pid plugin here: per step
                if not law_gain:
                    raise
                self.warnings.append(f"the laws as actuators: {exc}; the controllers run per step")
                probe, law_gain = None, {}
                self.model = build(False)
            self.data = mujoco.MjData(self.model)
        m = self.model
        self.floor = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, "modelkit_floor")
        free = [j for j in range(m.njnt) if int(m.jnt_type[j]) == int(mujoco.mjtJoint.mjJNT_FREE)]
        if not free:
            raise ValueError(f"{self.path.name}: no free joint; layer 4 needs the floating-base model")
        self.root_body = int(m.jnt_bodyid[free[0]])
        self.root_qadr = int(m.jnt_qposadr[free[0]])
        # Contact links (wheels, rollers): their geoms get the scenario's friction when it is set.
        prepared_links = set(drive.wheel_links) if drive.kind == "wheels" else set()
        for rollers in drive.rollers.values():
            for j in rollers:
                jid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, joints.get(j, j))
                if jid >= 0:
                    prepared_links.add(mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, int(m.jnt_bodyid[jid])))
        wheel_bodies = {mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, links.get(n, n))
                        for n in prepared_links}
        # The contacts as the file makes them against the default floor (nothing edited): a pair's
        # friction is the higher-priority geom's (the writer's priority 1), else the larger.
        self.friction: dict[str, float] = {}
        contact_mu = 0.0
        fp = int(m.geom_priority[self.floor])
        for g in range(m.ngeom):
            if g == self.floor or not (int(m.geom_contype[g]) & int(m.geom_conaffinity[self.floor])
                                       or int(m.geom_conaffinity[g]) & int(m.geom_contype[self.floor])):
                continue
            own, floor_mu = float(m.geom_friction[g, 0]), float(m.geom_friction[self.floor, 0])
            gp = int(m.geom_priority[g])
            mu = own if gp > fp else floor_mu if gp < fp else max(own, floor_mu)
            if int(m.geom_bodyid[g]) in wheel_bodies:
                contact_mu = max(contact_mu, mu)
            body = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, int(m.geom_bodyid[g])) or ""
            self.friction[body] = max(self.friction.get(body, 0.0), mu)
        self.servo_limit = v.servo_torque_limit(float(m.body_subtreemass[self.root_body]), contact_mu,
                                                drive.roller_radius or drive.radius, len(servoed))
        servos = [mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_ACTUATOR, f"modelkit_servo_{n}") for n in servoed]
        m.actuator_forcelimited[servos] = 1
        m.actuator_forcerange[servos] = (-self.servo_limit, self.servo_limit)
        # kv = J/dt (variant.servo_gain): stiffer chatters between the bounds once clamped (explicit).
        self.servo_kv = v.servo_gain(float(m.body_subtreemass[self.root_body]),
                                     drive.roller_radius or drive.radius, len(servoed),
                                     float(m.opt.timestep)) if servoed else 0.0
        m.actuator_gainprm[servos, 0] = self.servo_kv
        m.actuator_biasprm[servos, 2] = -self.servo_kv
        # The integral part, kp = kv / SERVO_INTEGRAL_TIME, bounded like the proportional one (each
        # actuator bounded on its own: a joint-level bound on their sum slowed the friction-limited
        # start, 1.5 cm behind the reference at 0.1 s, since implicitfast still damps through the
        # velocity actuator's kv while the joint clamps its force).
        self.servo_kp = self.servo_kv / SERVO_INTEGRAL_TIME
        integral = [mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_ACTUATOR, f"modelkit_servoint_{n}")
                    for n in servoed]
        m.actuator_gainprm[integral, 0] = self.servo_kp
        m.actuator_biasprm[integral, 1] = -self.servo_kp
        m.actuator_forcelimited[integral] = 1
        m.actuator_forcerange[integral] = (-self.servo_limit, self.servo_limit)
        # The law actuators, gear 0 (inert) until a profile runs them (``_run_laws``).
        self._law_gain = law_gain if probe is not None else None
        actuator = mujoco.mjtObj.mjOBJ_ACTUATOR
        self._law_actuators = np.array([mujoco.mj_name2id(m, actuator, f"modelkit_law_{n}")
                                        for n in law_gain], dtype=int)
        for name in law_gain:
            jid = self._joint(joints.get(name, name))
            m.jnt_actfrclimited[jid] = 0
        m.actuator_forcelimited[self._law_actuators] = 0
        m.actuator_gear[self._law_actuators, 0] = 0.0
        # The controlled joints: qpos/qvel addresses, torque (qfrc_applied) or servo (ctrl) columns.
        self._plan: list[tuple[Any, np.ndarray, np.ndarray, np.ndarray | None, list[list[int]]]] = []
        servo_of = {mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_ACTUATOR, a): a for a in range(m.nu)}
        for c in self.controllers:
            ids = [self._joint(joints.get(j, j)) for j in c.joints]
            qadr = np.array([int(m.jnt_qposadr[i]) for i in ids])
            vadr = np.array([int(m.jnt_dofadr[i]) for i in ids])
            if c.mode == "velocity":
                groups = [[servo_of[f"modelkit_{part}_{g}"] for g in v.driven_groups(drive, j)
                           for part in ("servo", "servoint")] for j in c.joints]
                self._plan.append((c, qadr, vadr, None, groups))
            else:
                self._plan.append((c, qadr, vadr, vadr.copy(), []))
        self.recorded = sorted({j for j, _ in controlled} | set(v.wheel_joints(drive)))
        self._rec_qadr = np.array([int(m.jnt_qposadr[self._joint(joints.get(j, j))]) for j in self.recorded])
        with quiet(self.warnings):
            self._start = self._initial_state()
        self.settings: dict[str, Any] = {
            "version": mujoco.__version__, "file": self.path.name, "base": "free joint (floating)",
            "timestep": float(m.opt.timestep) if self.file_timestep == scenario.dt
            else f"{scenario.dt:g} (the scenario's dt; the file says {self.file_timestep:g})",
            "option": ("the file's <option> as written (MK825): integrator "
                       f"{mujoco.mjtIntegrator(int(m.opt.integrator)).name}, cone "
                       f"{mujoco.mjtCone(int(m.opt.cone)).name}, impratio {float(m.opt.impratio):g}, solver "
                       f"{mujoco.mjtSolver(int(m.opt.solver)).name}, iterations {int(m.opt.iterations)}"),
            "gravity": [float(x) for x in m.opt.gravity],
            "floor": "plane z = 0 with MuJoCo's default contact (friction 1, priority 0): what a user adds",
            "contact": "the file's geoms as written: priority, friction, condim, solref, solimp, collision "
                       "filters (nothing edited)",
            "friction": dict(sorted(self.friction.items())),
            "friction_rule": "the higher-priority geom's values, else the larger (MuJoCo's rule)",
            "torque": "qfrc_applied on the controlled dofs (see control), not clamped",
            "control": (("the laws u = offset - gain·dq as MuJoCo computes them: offset in qfrc_applied "
                         "and velocity targets in the servos' ctrl, set at each command change; -gain·dq "
                         f"by a {LAW_PLUGIN} actuator per torque joint (kd = gain; explicit, as the Python "
                         "law; gear 1 while a profile runs, 0 otherwise); actuatorfrcrange off on those "
                         "joints, no forcerange (the Python law is not clamped); mj_step(nstep) between "
                         "samples and command changes (no Python per step)")
                        if self._law_gain is not None else
                        "the controllers' output() called before every mj_step (per step, in Python)"),
            "law_actuators": dict(sorted(law_gain.items())),
            "velocity_servo": (f"MuJoCo velocity actuator kv {self.servo_kv:.4g} N·m·s/rad (m·r²/(n·dt)), "
                               "force within "
                               f"±{self.servo_limit:.4g} N·m (SERVO_FRICTION_SHARE·m·g·μ·r / rollers), "
                               "on every roller of a "
                               "track, all with roller 0's target (roller i > 0 also keeps the file's "
                               "mimic equality); beside each, an intvelocity actuator kp "
                               f"{self.servo_kp:.4g} N·m/rad (kv / SERVO_INTEGRAL_TIME), same bound: the "
                               "servo's integral part") if servoed else "none",
            "file_actuators": (("deleted on the driven joints; kept, holding the start pose, on the others: "
                                + ", ".join(self.file_actuators)) if self.file_actuators
                               else "deleted (none on a joint verify does not drive)"),
            "start_height": self._start_height,
            "settle": "zero torque; velocity servos held at 0",
            "controllers": [f"{c.name} ({c.mode}: {', '.join(c.joints)})" for c in self.controllers],
        }

    def _joint(self, name: str) -> int:
        jid = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_JOINT, name)
        if jid < 0:
            raise ValueError(f"{self.path.name}: no joint named {name!r}")
        return int(jid)

    def _initial_state(self) -> np.ndarray:
        """The root at the origin, lowered (or raised) so that the robot's lowest collision point
        touches the floor; q = 0."""
        m, d = self.model, self.data
        mujoco.mj_resetData(m, d)
        d.qpos[self.root_qadr:self.root_qadr + 7] = (0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0)
        mujoco.mj_forward(m, d)
        gap = floor_clearance(m, d, self.floor)
        self._start_height = 0.0 if not math.isfinite(gap) else -gap
        d.qpos[self.root_qadr + 2] = self._start_height
        mujoco.mj_forward(m, d)
        # The file's kept actuators (the first ones, see drop_actuators) hold the start pose: a
        # position-type one (affine bias on its length, its control not integrated) gets its length as
        # its control, others 0 (an intvelocity servo's control is a velocity).
        self._start_ctrl = np.zeros(m.nu)
        integrated = int(mujoco.mjtDyn.mjDYN_INTEGRATOR)
        for a in range(len(self.file_actuators)):
            affine = int(m.actuator_biastype[a]) == int(mujoco.mjtBias.mjBIAS_AFFINE)
            if affine and m.actuator_biasprm[a, 1] != 0.0 and int(m.actuator_dyntype[a]) != integrated:
                self._start_ctrl[a] = float(d.actuator_length[a])
        return np.array(d.qpos)

    def run(self, profile: Any, scenario: Any, drive: Any) -> Any:
        from modelkit.verify.drive import command_steps
        from modelkit.verify.drive import variant as v

        m, d = self.model, self.data
        wall = time.perf_counter()
        warned = len(self.warnings)
        dt = float(m.opt.timestep)
        every = max(1, round(1.0 / (scenario.sample_rate * dt)))
        steps = round(profile.duration / dt)
        settle = round(profile.settle / dt)
        changes = command_steps(profile, dt, steps)
        laws = self._laws(changes)
        n = steps // every + 1
        base = np.empty((n, 7))
        qrec = np.empty((n, len(self.recorded)))
        with quiet(self.warnings):
            mujoco.mj_resetData(m, d)
            d.qpos[:] = self._start
            d.ctrl[:] = self._start_ctrl
            mujoco.mj_forward(m, d)
            step = mujoco.mj_step
            if settle:  # zero torque, servos at 0, law actuators inert (gear 0), file servos holding
                step(m, d, nstep=settle)
            support = self._support()
            if laws is not None:
                self._run_laws(laws, changes, steps, every, base, qrec)
            else:
                self._run_per_step(changes, steps, every, base, qrec)
        self.last_wall = time.perf_counter() - wall
        out = v.planar("mujoco", profile, "", np.arange(n) * every * dt, base[:, :3],
                       v.rotations_wxyz(base[:, 3:]),
                       {name: qrec[:, i] for i, name in enumerate(self.recorded)}, v.wheel_joints(drive),
                       drive.heading)
        out.settings = dict(self.settings)
        out.support = support
        if laws is None and self._law_gain is not None:
            out.settings["control"] = ("the controllers' output() called before every mj_step: a law's "
                                       "gain changed with the command")
        out.warnings = self.warnings[warned:]  # "unstable" ones: MuJoCo reset the state mid-run
        return out

    def _support(self) -> dict[str, float]:
        """Each body touching the floor (a contact within 1 mm): the sum of its contacts' normal
        forces, N."""
        m, d = self.model, self.data
        out: dict[str, float] = {}
        force = np.zeros(6)
        for i in range(d.ncon):
            contact = d.contact[i]
            if self.floor not in (contact.geom1, contact.geom2) or contact.dist > 1.0e-3:
                continue
            other = contact.geom2 if contact.geom1 == self.floor else contact.geom1
            mujoco.mj_contactForce(m, d, i, force)
            name = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, int(m.geom_bodyid[other])) or ""
            out[name] = out.get(name, 0.0) + float(force[0])
        return out

    def _laws(self, changes: dict[int, Any]) -> dict[int, list[tuple[np.ndarray, np.ndarray]]] | None:
        """Step → the controllers' affine laws from that step (step 0: the zero command until the
        profile's first), or None (per step) when the driver has no law actuators or a law's gain is
        not the one compiled into them."""
        from modelkit.verify.drive import Command

        if self._law_gain is None:
            return None
        out: dict[int, list[tuple[np.ndarray, np.ndarray]]] = {}
        for k, command in [(0, Command(0.0)), *sorted(changes.items(), key=lambda kc: kc[0])]:
            laws = affine_laws(self.controllers, command)
            if laws is None:
                return None
            for c, (_, gain) in zip(self.controllers, laws, strict=True):
                expected = [0.0 if c.mode == "velocity" else self._law_gain.get(j, 0.0) for j in c.joints]
                if gain.shape != (len(c.joints),) or not np.array_equal(gain, expected):
                    return None
            out[k] = laws
        return out

    def _run_laws(self, laws: dict[int, list[tuple[np.ndarray, np.ndarray]]], changes: dict[int, Any],
                  steps: int, every: int, base: np.ndarray, qrec: np.ndarray) -> None:
        """The profile with the laws as actuators (see the class): Python only at samples and command
        changes, ``mj_step(nstep)`` in between."""
        m, d = self.model, self.data
        applied, ctrl = d.qfrc_applied, d.ctrl
        stops = sorted({*range(0, steps + 1, every), *laws, steps})
        m.actuator_gear[self._law_actuators, 0] = 1.0
        try:
            s = 0
            for i, k in enumerate(stops):
                if k % every == 0:
                    self._sample(base, qrec, s)
                    s += 1
                if k == steps:
                    break
                if k in laws:
                    for (_, _, _, torque_dofs, groups), (offset, _) in zip(self._plan, laws[k], strict=True):
                        if torque_dofs is not None:
                            applied[torque_dofs] = offset
                        else:
                            for group, target in zip(groups, offset, strict=True):
                                ctrl[group] = target
                mujoco.mj_step(m, d, nstep=stops[i + 1] - k)
        finally:
            m.actuator_gear[self._law_actuators, 0] = 0.0

    def _sample(self, base: np.ndarray, qrec: np.ndarray, s: int) -> None:
        """Sample ``s``: the state after the steps so far (the free joint's qpos is the root's pose)."""
        qpos, ra = self.data.qpos, self.root_qadr
        base[s] = qpos[ra:ra + 7]
        qrec[s] = qpos[self._rec_qadr]

    def _run_per_step(self, changes: dict[int, Any], steps: int, every: int, base: np.ndarray,
                      qrec: np.ndarray) -> None:
        """The profile with every controller's ``output`` called before every ``mj_step``."""
        from modelkit.verify.drive import Command

        m, d = self.model, self.data
        dt = float(m.opt.timestep)
        step = mujoco.mj_step
        plan, qpos, qvel, applied, ctrl = self._plan, d.qpos, d.qvel, d.qfrc_applied, d.ctrl
        command = Command(0.0)
        s = 0
        for k in range(steps + 1):
            if k % every == 0:
                self._sample(base, qrec, s)
                s += 1
            if k == steps:
                break
            if k in changes:
                command = changes[k]
            t = k * dt
            for c, qa, va, torque_dofs, groups in plan:
                u = c.output(t, command, qpos[qa], qvel[va])
                if torque_dofs is not None:
                    applied[torque_dofs] = u
                else:
                    for group, target in zip(groups, u, strict=True):
                        ctrl[group] = target
            step(m, d)

    def bench(self, seconds: float, command: Any = None) -> dict[str, float]:
        """Wall seconds over ``seconds`` of simulated time on this model, from the start pose, of a
        bare Python ``mj_step`` loop (``bare``: no control, no read-back, actuation off by
        ``mjDSBL_ACTUATION``: not even the inert law actuators or idle servos) and of a minimal closed
        loop (``closed_loop``: the same controllers called with one fixed ``command``, torques set, step;
        no sampling, no command schedule): what the harness adds is the rest."""
        from modelkit.verify.drive import Command

        m, d = self.model, self.data
        steps = round(seconds / float(m.opt.timestep))
        command = command or Command(0.0, 0.3, 0.5)
        with quiet(self.warnings):
            mujoco.mj_resetData(m, d)
            d.qpos[:] = self._start
            step = mujoco.mj_step
            actuation = int(mujoco.mjtDisableBit.mjDSBL_ACTUATION)
            m.opt.disableflags |= actuation
            try:
                start = time.perf_counter()
                for _ in range(steps):
                    step(m, d)
                bare = time.perf_counter() - start
            finally:
                m.opt.disableflags &= ~actuation
            mujoco.mj_resetData(m, d)
            d.qpos[:] = self._start
            plan, qpos, qvel, applied, ctrl = self._plan, d.qpos, d.qvel, d.qfrc_applied, d.ctrl
            dt = float(m.opt.timestep)
            start = time.perf_counter()
            for k in range(steps):
                for c, qa, va, torque_dofs, groups in plan:
                    u = c.output(k * dt, command, qpos[qa], qvel[va])
                    if torque_dofs is not None:
                        applied[torque_dofs] = u
                    else:
                        for group, target in zip(groups, u, strict=True):
                            ctrl[group] = target
                step(m, d)
            closed = time.perf_counter() - start
        return {"bare": bare, "closed_loop": closed}

    def close(self) -> None:
        return None


def driver(model: Path, renames: Renames, *, drive: Any, scenario: Any, factory: str | None = None,
           fast: bool = True) -> MujocoDriver:
    """Layer 4's entry point (:class:`modelkit.verify.drive.Driver`). ``fast`` False: the controllers'
    ``output`` every step even when they have affine laws (the reference the fast path is tested
    against)."""
    return MujocoDriver(Path(model), renames, drive, scenario, factory, fast)
