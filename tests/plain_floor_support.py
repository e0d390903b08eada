"""Drive a converted wheeled robot as a user would, outside ``verify``: the written MJCF in a MuJoCo
scene with a default plane, the written URDF in PyBullet on pybullet_data's ``plane.urdf``, each
driven by the seed's law ``u = kd·(dq* − dq)`` (kd 0.5, dq* = (v ∓ w·b)/r; pan/tilt kd 0.1, dq* 0).

Nothing of the robot is edited: MuJoCo gets one ``<geom type="plane">`` added to the world (default
contact), PyBullet loads both files as shipped (flags ``URDF_USE_INERTIA_FROM_FILE |
URDF_USE_IMPLICIT_CYLINDER``); the only engine settings are gravity, PyBullet's time step (1 ms, as
the MJCF's ``<option>``) and the zero-force velocity motors a torque-controlled PyBullet joint needs.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

KD, PAN_TILT_KD = 0.5, 0.1
SETTLE, DURATION = 0.5, 10.0


@dataclass(frozen=True)
class Pose2:
    x: float
    y: float
    yaw: float  # unwrapped, relative to the start


def ideal(v: float, w: float, t: float = DURATION) -> Pose2:
    """The ideal unicycle's end pose after ``t`` s at (v, w), from the origin heading +x."""
    if w == 0.0:
        return Pose2(v * t, 0.0, 0.0)
    return Pose2(v / w * math.sin(w * t), v / w * (1.0 - math.cos(w * t)), w * t)


def _relative(start: tuple[np.ndarray, float], end: tuple[np.ndarray, float], turned: float) -> Pose2:
    (p0, yaw0), (p1, _) = start, end
    c, s = math.cos(yaw0), math.sin(yaw0)
    dx, dy = p1[0] - p0[0], p1[1] - p0[1]
    return Pose2(c * dx + s * dy, -s * dx + c * dy, turned)


def _targets(v: float, w: float, r: float, b: float) -> tuple[float, float]:
    return (v - w * b) / r, (v + w * b) / r


def drive_mujoco(xml: Path, v: float, w: float, r: float, b: float,
                 wheels: tuple[str, str] = ("LeftWheel", "RightWheel"),
                 head: tuple[str, ...] = ("PanJoint", "TiltJoint")) -> Pose2:
    import mujoco

    spec = mujoco.MjSpec.from_file(str(xml))
    spec.worldbody.add_geom(type=mujoco.mjtGeom.mjGEOM_PLANE, size=[0.0, 0.0, 1.0])  # default contact
    m = spec.compile()
    d = mujoco.MjData(m)
    free = next(j for j in range(m.njnt) if m.jnt_type[j] == mujoco.mjtJoint.mjJNT_FREE)
    qa = int(m.jnt_qposadr[free])
    dofs = {name: int(m.jnt_dofadr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, name)])
            for name in (*wheels, *head) if mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, name) >= 0}
    targets = _targets(v, w, r, b)
    dt = float(m.opt.timestep)

    def yaw() -> float:
        q = d.qpos[qa + 3:qa + 7]
        return math.atan2(2 * (q[0] * q[3] + q[1] * q[2]), 1 - 2 * (q[2] ** 2 + q[3] ** 2))

    for _ in range(round(SETTLE / dt)):
        mujoco.mj_step(m, d)
    start = (np.array(d.qpos[qa:qa + 3]), yaw())
    turned, last = 0.0, start[1]
    for _ in range(round(DURATION / dt)):
        d.qfrc_applied[:] = 0.0
        for name, target in zip(wheels, targets, strict=True):
            d.qfrc_applied[dofs[name]] = KD * (target - d.qvel[dofs[name]])
        for name in head:
            if name in dofs:
                d.qfrc_applied[dofs[name]] = -PAN_TILT_KD * d.qvel[dofs[name]]
        mujoco.mj_step(m, d)
        now = yaw()
        turned += (now - last + math.pi) % (2 * math.pi) - math.pi
        last = now
    return _relative(start, (np.array(d.qpos[qa:qa + 3]), last), turned)


def drive_pybullet(urdf: Path, v: float, w: float, r: float, b: float, dt: float = 1e-3,
                   wheels: tuple[str, str] = ("LeftWheel", "RightWheel"),
                   head: tuple[str, ...] = ("PanJoint", "TiltJoint")) -> Pose2:
    import pybullet as p
    import pybullet_data

    c = p.connect(p.DIRECT)
    try:
        p.setGravity(0, 0, -9.81, physicsClientId=c)
        p.setTimeStep(dt, physicsClientId=c)
        p.loadURDF(str(Path(pybullet_data.getDataPath()) / "plane.urdf"), physicsClientId=c)
        body = p.loadURDF(str(urdf), flags=p.URDF_USE_INERTIA_FROM_FILE | p.URDF_USE_IMPLICIT_CYLINDER,
                          physicsClientId=c)
        written = {p.getJointInfo(body, j, physicsClientId=c)[1].decode(): j
                   for j in range(p.getNumJoints(body, physicsClientId=c))}
        # the URDF writer keeps a joint named like its link (MK846); with urdf_distinct_names: LeftWheel_joint
        index = {n: written.get(n, written.get(f"{n}_joint", -1)) for n in (*wheels, *head)}
        index = {n: j for n, j in index.items() if j >= 0}
        used = [n for n in (*wheels, *head) if n in index]
        for name in used:  # torque control: the default velocity motors off
            p.setJointMotorControl2(body, index[name], p.VELOCITY_CONTROL, force=0.0, physicsClientId=c)
        targets = dict(zip(wheels, _targets(v, w, r, b), strict=True))

        local_pos, local_orn = p.getDynamicsInfo(body, -1, physicsClientId=c)[3:5]

        def pose() -> tuple[np.ndarray, float]:
            """The root link frame (PyBullet reports the base's inertial frame: moved back)."""
            pos, orn = p.getBasePositionAndOrientation(body, physicsClientId=c)
            inv_pos, inv_orn = p.invertTransform(local_pos, local_orn)
            link_pos, link_orn = p.multiplyTransforms(pos, orn, inv_pos, inv_orn)
            return np.array(link_pos), p.getEulerFromQuaternion(link_orn)[2]

        def step(drive: bool) -> None:
            for name in used:
                dq = p.getJointState(body, index[name], physicsClientId=c)[1]
                gain, target = (KD, targets[name]) if name in targets else (PAN_TILT_KD, 0.0)
                u = gain * (target - dq) if drive else 0.0
                p.setJointMotorControl2(body, index[name], p.TORQUE_CONTROL, force=u, physicsClientId=c)
            p.stepSimulation(physicsClientId=c)

        for _ in range(round(SETTLE / dt)):
            step(False)
        start = pose()
        turned, last = 0.0, start[1]
        for _ in range(round(DURATION / dt)):
            step(True)
            now = pose()[1]
            turned += (now - last + math.pi) % (2 * math.pi) - math.pi
            last = now
        return _relative(start, pose(), turned)
    finally:
        p.disconnect(c)
