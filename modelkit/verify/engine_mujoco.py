"""MuJoCo adapter: the written MJCF, base welded, read back from the compiled ``mjModel``.

Static facts: ``body_mass``, ``body_ipos``, ``body_inertia`` rotated by ``body_iquat``, ``jnt_axis``,
``jnt_range``. Poses: ``mj_kinematics``. Dynamics: ``mj_fullM`` of ``qM`` and ``qfrc_bias`` after
``mj_forward`` (gravity + Coriolis/centrifugal). The replay (layer 3b) steps with
``integrator="Euler"`` at the caller's dt, contacts off, torques through ``qfrc_applied``; nothing is
added to the model (no damping, armature or friction beyond what the file has).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import mujoco
import numpy as np

from modelkit.model import Robot
from modelkit.spatial import Pose, matrix_from_quat_wxyz
from modelkit.verify.facts import Array, JointFacts, LinkFacts, StaticFacts, TorqueLaw

Renames = dict[str, dict[str, str]]
GRAVITY = (0.0, 0.0, -9.81)
_TYPES = {
    int(mujoco.mjtJoint.mjJNT_HINGE): "revolute",
    int(mujoco.mjtJoint.mjJNT_SLIDE): "prismatic",
    int(mujoco.mjtJoint.mjJNT_BALL): "ball",
    int(mujoco.mjtJoint.mjJNT_FREE): "floating",
}


def _compile(path: Path, root: str) -> tuple[mujoco.MjModel, bool]:
    """Compile the MJCF with the root body's free joint (if any) deleted: the base welded."""
    spec = mujoco.MjSpec.from_file(str(path))
    body = spec.body(root)
    if body is None:
        raise ValueError(f"{path}: no body named {root!r}")
    welded = False
    for joint in list(body.joints):
        if joint.type == mujoco.mjtJoint.mjJNT_FREE:
            spec.delete(joint)
            welded = True
    model = spec.compile()
    model.opt.gravity[:] = GRAVITY
    return model, welded


class MujocoModel:
    engine = "mujoco"

    def __init__(self, path: Path, root: str) -> None:
        self.model, deleted = _compile(path, root)
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
        self.settings: dict[str, Any] = {
            "version": mujoco.__version__,
            "file": path.name,
            "base": ("root body's free joint deleted through MjSpec" if deleted
                     else "root body has no free joint"),
            "gravity": list(GRAVITY),
            "poses": "mj_kinematics (xpos, xmat), relative to the root body",
            "mass_matrix": "mj_fullM after mj_forward",
            "bias": "qfrc_bias after mj_forward",
            "nq": int(m.nq), "nv": int(m.nv),
        }

    def _jname(self, j: int) -> str:
        return mujoco.mj_id2name(self.model, mujoco.mjtObj.mjOBJ_JOINT, j) or f"joint{j}"

    def _bname(self, b: int) -> str:
        return mujoco.mj_id2name(self.model, mujoco.mjtObj.mjOBJ_BODY, b) or f"body{b}"

    def dof_names(self) -> list[str]:
        return list(self._dofs)

    def static(self) -> StaticFacts:
        m = self.model
        facts = StaticFacts()
        for b in range(1, m.nbody):
            rot = matrix_from_quat_wxyz(m.body_iquat[b])
            inertia = rot @ np.diag(m.body_inertia[b]) @ rot.T
            com = np.array(m.body_ipos[b], dtype=float)
            facts.links[self._bname(b)] = LinkFacts(float(m.body_mass[b]), com, inertia)
            joints = [j for j in range(m.njnt) if int(m.jnt_bodyid[j]) == b]
            parent = self._bname(int(m.body_parentid[b])) if m.body_parentid[b] > 0 else "world"
            if not joints and b != self._root_id:
                name = self._bname(b)
                facts.joints[f"fixed:{name}"] = JointFacts("fixed", parent, name, np.zeros(3))
            for j in joints:
                jtype = _TYPES.get(int(m.jnt_type[j]), "unknown")
                moving = jtype in ("revolute", "prismatic")
                lower, upper = -math.inf, math.inf
                if moving and m.jnt_limited[j]:
                    lower, upper = float(m.jnt_range[j][0]), float(m.jnt_range[j][1])
                axis = np.array(m.jnt_axis[j], dtype=float) if moving else np.zeros(3)
                facts.joints[self._jname(j)] = JointFacts(jtype, parent, self._bname(b), axis, lower, upper)
        return facts

    def _set(self, q: dict[str, float], dq: dict[str, float] | None = None) -> None:
        d = self.data
        d.qpos[:] = self.model.qpos0
        d.qvel[:] = 0.0
        for name, qa, va in zip(self._dofs, self._qadr, self._vadr, strict=True):
            d.qpos[qa] = q.get(name, 0.0)
            if dq is not None:
                d.qvel[va] = dq.get(name, 0.0)

    def link_poses(self, q: dict[str, float]) -> dict[str, Pose]:
        self._set(q)
        mujoco.mj_kinematics(self.model, self.data)
        d = self.data
        base = Pose(d.xmat[self._root_id].reshape(3, 3).copy(), d.xpos[self._root_id].copy()).inverse()
        return {self._bname(b): base @ Pose(d.xmat[b].reshape(3, 3).copy(), d.xpos[b].copy())
                for b in range(1, self.model.nbody)}

    def mass_matrix(self, q: dict[str, float]) -> Array:
        self._set(q)
        mujoco.mj_forward(self.model, self.data)
        full = np.zeros((self.model.nv, self.model.nv))
        if hasattr(self.data, "qM"):  # MuJoCo < 4: mj_fullM(m, dst, qM)
            mujoco.mj_fullM(self.model, full, self.data.qM)
        else:  # MuJoCo ≥ 4: mj_fullM(m, d, dst)
            mujoco.mj_fullM(self.model, self.data, full)
        idx = np.asarray(self._vadr, dtype=int)
        return full[np.ix_(idx, idx)]

    def bias(self, q: dict[str, float], dq: dict[str, float]) -> Array:
        self._set(q, dq)
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

    def __init__(self, path: Path, renames: Renames, root: str, dt: float) -> None:
        self.inner = MujocoModel(path, root)
        m = self.inner.model
        m.opt.timestep = dt
        m.opt.integrator = int(mujoco.mjtIntegrator.mjINT_EULER)
        m.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_CONTACT)
        self.renames = renames
        self.settings = {**self.inner.settings, "integrator": "Euler", "timestep": dt, "contacts": "disabled",
                         "torques": "qfrc_applied, recomputed from the state before every mj_step"}

    def dof_names(self) -> list[str]:
        return self.inner.dof_names()

    def replay(self, law: TorqueLaw, seconds: float, dt: float) -> Array:
        m, d = self.inner.model, self.inner.data
        m.opt.timestep = dt
        mujoco.mj_resetData(m, d)
        names = [self.renames.get("joint", {}).get(j, j) for j in law.joints]
        where = {n: i for i, n in enumerate(self.inner.dof_names())}
        qadr = np.asarray([self.inner._qadr[where[n]] for n in names], dtype=int)
        vadr = np.asarray([self.inner._vadr[where[n]] for n in names], dtype=int)
        steps = round(seconds / dt)
        out = np.empty((steps + 1, len(names)))
        out[0] = d.qpos[qadr]
        for k in range(steps):
            d.qfrc_applied[vadr] = law.torque(k * dt, d.qpos[qadr], d.qvel[vadr])
            mujoco.mj_step(m, d)
            out[k + 1] = d.qpos[qadr]
        return out

    def close(self) -> None:
        return None


def simulator(model: Path, renames: Renames, *, root: str, dt: float) -> MujocoSimulator:
    return MujocoSimulator(Path(model), renames, root, dt)
