"""The PyBullet child process behind :mod:`modelkit.verify.engine_pybullet`.

PyBullet keeps global state and can crash (segfault, abort) on bad input, so it never runs in the
verifying process. This script is started by path (``python pybullet_worker.py``), imports only the
standard library and ``pybullet``, and answers requests on stdin. Framing, both ways: a 4-byte
big-endian length, then a pickle. A request is ``(command, kwargs)``; a reply is ``("ok", result)``
or ``("error", message)``. PyBullet's C code prints to file descriptor 1, so the replies go to a
duplicate of the original stdout and fd 1 is pointed at stderr before PyBullet is imported.

The worker returns raw PyBullet numbers (link COM frames, inertial frames, joint infos); the frame
algebra lives in the parent, where it can be tested and typed.
"""

from __future__ import annotations

import math
import os
import pickle
import struct
import sys
import time
import traceback
from array import array
from typing import Any, BinaryIO


class Engine:
    """One DIRECT PyBullet client holding one fixed-base body."""

    def __init__(self) -> None:
        import pybullet

        self.p = pybullet
        self.client = -1
        self.body = -1
        self.movable: list[int] = []
        self.n_joints = 0

    def load(self, path: str, gravity: float, dt: float) -> dict[str, Any]:
        p = self.p
        self.client = p.connect(p.DIRECT)
        p.setGravity(0.0, 0.0, gravity, physicsClientId=self.client)
        p.setTimeStep(dt, physicsClientId=self.client)
        flags = p.URDF_USE_INERTIA_FROM_FILE | p.URDF_USE_IMPLICIT_CYLINDER
        self.body = p.loadURDF(path, useFixedBase=True, flags=flags, physicsClientId=self.client)
        self.n_joints = p.getNumJoints(self.body, physicsClientId=self.client)
        for link in range(-1, self.n_joints):
            p.changeDynamics(self.body, link, linearDamping=0.0, angularDamping=0.0, jointDamping=0.0,
                             physicsClientId=self.client)
        joints = [p.getJointInfo(self.body, j, physicsClientId=self.client) for j in range(self.n_joints)]
        self.movable = [j[0] for j in joints if j[2] in (p.JOINT_REVOLUTE, p.JOINT_PRISMATIC)]
        # Default velocity motors (target 0, max force from the URDF effort) off on every joint.
        for j in range(self.n_joints):
            p.setJointMotorControl2(self.body, j, p.VELOCITY_CONTROL, targetVelocity=0.0, force=0.0,
                                    physicsClientId=self.client)
        base, _ = p.getBodyInfo(self.body, physicsClientId=self.client)
        return {
            "base": base.decode(),
            "joints": [
                {"index": j[0], "name": j[1].decode(), "type": j[2], "damping": j[6], "friction": j[7],
                 "lower": j[8], "upper": j[9], "max_force": j[10], "max_velocity": j[11],
                 "child": j[12].decode(), "axis": tuple(j[13]), "parent_frame_pos": tuple(j[14]),
                 "parent_frame_orn": tuple(j[15]), "parent": j[16]}
                for j in joints
            ],
            "movable": list(self.movable),
            "types": {"revolute": p.JOINT_REVOLUTE, "prismatic": p.JOINT_PRISMATIC,
                      "spherical": p.JOINT_SPHERICAL, "planar": p.JOINT_PLANAR, "fixed": p.JOINT_FIXED},
        }

    def dynamics(self, path: str) -> list[dict[str, Any]]:
        """``getDynamicsInfo`` of the base (-1) and every link: mass, principal inertia, inertial
        frame (position, quaternion xyzw) in the URDF link frame. PyBullet reports a fixed base as
        massless, so the base's entry comes from a second, floating-base load in its own client."""
        p = self.p
        flags = p.URDF_USE_INERTIA_FROM_FILE | p.URDF_USE_IMPLICIT_CYLINDER
        floating = p.connect(p.DIRECT)
        try:
            body = p.loadURDF(path, useFixedBase=False, flags=flags, physicsClientId=floating)
            base = p.getDynamicsInfo(body, -1, physicsClientId=floating)
        finally:
            p.disconnect(physicsClientId=floating)
        out = []
        for link in range(-1, self.n_joints):
            d = base if link == -1 else p.getDynamicsInfo(self.body, link, physicsClientId=self.client)
            out.append({"link": link, "mass": d[0], "inertia_diagonal": tuple(d[2]),
                        "inertial_pos": tuple(d[3]), "inertial_orn": tuple(d[4])})
        fixed = p.getDynamicsInfo(self.body, -1, physicsClientId=self.client)
        out[0]["fixed_inertial_pos"], out[0]["fixed_inertial_orn"] = tuple(fixed[3]), tuple(fixed[4])
        return out

    def shapes(self) -> list[list[tuple[str, tuple[float, ...], str, tuple[float, ...], tuple[float, ...]]]]:
        """``getCollisionShapeData`` of the base (-1) and every link: (type, dimensions, file name,
        position, quaternion xyzw) per shape, raw. The frame is the link's inertial (COM) frame of
        this (fixed-base) load; dimensions: box full extents, sphere (r, r, r), cylinder and capsule
        (length, radius), mesh its scale. (The object and link ids PyBullet returns for the second
        and later shapes of a compound are garbage; they are not used.)"""
        p = self.p
        kinds = {p.GEOM_SPHERE: "sphere", p.GEOM_BOX: "box", p.GEOM_CYLINDER: "cylinder",
                 p.GEOM_MESH: "mesh", p.GEOM_PLANE: "plane", p.GEOM_CAPSULE: "capsule"}
        out = []
        for link in range(-1, self.n_joints):
            data = p.getCollisionShapeData(self.body, link, physicsClientId=self.client)
            out.append([(kinds.get(s[2], f"type-{s[2]}"), tuple(s[3]), s[4].decode(errors="replace"),
                         tuple(s[5]), tuple(s[6])) for s in data])
        return out

    def _set_q(self, q: list[float], dq: list[float] | None = None) -> None:
        p = self.p
        for i, j in enumerate(self.movable):
            velocity = dq[i] if dq is not None else 0.0
            p.resetJointState(self.body, j, q[i], velocity, physicsClientId=self.client)

    def poses(self, q: list[float]) -> dict[str, Any]:
        """Base COM frame, then per link ``getLinkState(..., computeForwardKinematics=True)``:
        [0:2] the link's COM (inertial) frame, [4:6] the URDF link frame (float32 in PyBullet)."""
        p = self.p
        self._set_q(q)
        readback = [p.getJointState(self.body, j, physicsClientId=self.client)[0] for j in self.movable]
        base_pos, base_orn = p.getBasePositionAndOrientation(self.body, physicsClientId=self.client)
        links = []
        for link in range(self.n_joints):
            s = p.getLinkState(self.body, link, computeForwardKinematics=True, physicsClientId=self.client)
            links.append((tuple(s[0]), tuple(s[1]), tuple(s[4]), tuple(s[5])))
        return {"readback": readback, "base": (tuple(base_pos), tuple(base_orn)), "links": links}

    def mass_matrix(self, q: list[float]) -> list[list[float]]:
        self._set_q(q)
        rows = self.p.calculateMassMatrix(self.body, list(q), physicsClientId=self.client)
        return [list(row) for row in rows]

    def inverse_dynamics(self, q: list[float], dq: list[float], ddq: list[float]) -> list[float]:
        self._set_q(q, dq)
        tau = self.p.calculateInverseDynamics(self.body, list(q), list(dq), list(ddq),
                                              physicsClientId=self.client)
        if tau is None:  # PyBullet returns None, not (), for a body without degrees of freedom (measured)
            if self.movable:
                raise RuntimeError("calculateInverseDynamics returned None")
            return []
        return list(tau)

    def _reset(self, dt: float) -> None:
        n = len(self.movable)
        self._set_q([0.0] * n, [0.0] * n)
        self.p.setTimeStep(dt, physicsClientId=self.client)

    def limits_off(self) -> None:
        """Joint limits out of the replay (MuJoCo's side: ``mjDSBL_LIMIT``). PyBullet keeps a limit
        constraint per limited joint whatever ``changeDynamics`` is given (lower > upper is ignored:
        measured, the joint still stops at its URDF limit); bounds at ±1e30 and a zero limit force
        make it inert (measured: the joint runs through its old limit)."""
        for j in self.movable:
            self.p.changeDynamics(self.body, j, jointLowerLimit=-1e30, jointUpperLimit=1e30,
                                  jointLimitForce=0.0, physicsClientId=self.client)

    def replay(self, kp: list[float], kd: list[float], amplitude: list[float], frequency: list[float],
               phase: list[float], steps: int, dt: float) -> dict[str, Any]:
        """The PD law of ``facts.TorqueLaw`` (joint order = ``movable``), from q = dq = 0, torques
        re-sent before every step (PyBullet's TORQUE_CONTROL lasts one ``stepSimulation``).
        Returns q after every step (row 0 = the start) as a flat float64 array."""
        p = self.p
        self._reset(dt)
        self.limits_off()
        body, client, idx = self.body, self.client, list(self.movable)
        start = time.perf_counter()
        # The targets q*(t_k) first (the same arithmetic as TorqueLaw.torque), then the loop: read
        # the state, send the torques, step. The raw state tuples are kept and unpacked afterwards.
        omega = [2.0 * math.pi * f for f in frequency]
        laws = list(zip(kp, kd, amplitude, omega, phase, strict=True))
        targets = [[a * math.sin(w * (k * dt) + ph) for _, _, a, w, ph in laws] for k in range(steps)]
        gains = [(g, d) for g, d, _, _, _ in laws]
        torque_mode = p.TORQUE_CONTROL
        get_states, set_array, step = p.getJointStates, p.setJointMotorControlArray, p.stepSimulation
        states_log: list[Any] = []
        log = states_log.append
        for k in range(steps):
            states = get_states(body, idx, physicsClientId=client)
            log(states)
            u = [g * (x - s[0]) - d * s[1] for (g, d), x, s in zip(gains, targets[k], states, strict=True)]
            set_array(body, idx, torque_mode, forces=u, physicsClientId=client)
            step(physicsClientId=client)
        log(get_states(body, idx, physicsClientId=client))
        out = array("d", [s[0] for states in states_log for s in states])
        out[: len(idx)] = array("d", [0.0] * len(idx))  # row 0: the reset start, exactly
        wall = time.perf_counter() - start
        return {"q": out.tobytes(), "wall": wall}

    def bench(self, steps: int, dt: float) -> dict[str, float]:
        """Wall time of a bare stepping loop (``stepSimulation`` only, no control, no read-back)
        and of a minimal hand-written closed loop (read states, send torques, step)."""
        p = self.p
        self._reset(dt)
        body, client, step = self.body, self.client, p.stepSimulation
        start = time.perf_counter()
        for _ in range(steps):
            step(physicsClientId=client)
        bare = time.perf_counter() - start
        self._reset(dt)
        idx = list(self.movable)
        zeros = [0.0] * len(idx)
        start = time.perf_counter()
        for _ in range(steps):
            p.getJointStates(body, idx, physicsClientId=client)
            p.setJointMotorControlArray(body, idx, p.TORQUE_CONTROL, forces=zeros, physicsClientId=client)
            step(physicsClientId=client)
        closed = time.perf_counter() - start
        return {"bare": bare, "closed_loop": closed}


def _read(stream: BinaryIO, n: int) -> bytes | None:
    data = b""
    while len(data) < n:
        chunk = stream.read(n - len(data))
        if not chunk:
            return None
        data += chunk
    return data


def _send(stream: BinaryIO, message: Any) -> None:
    payload = pickle.dumps(message, protocol=pickle.HIGHEST_PROTOCOL)
    stream.write(struct.pack(">I", len(payload)) + payload)
    stream.flush()


def main() -> int:
    replies = os.fdopen(os.dup(1), "wb")
    os.dup2(2, 1)  # PyBullet's own prints go to stderr, never into the reply stream
    requests = sys.stdin.buffer
    engine = Engine()
    while True:
        header = _read(requests, 4)
        if header is None:
            return 0
        body = _read(requests, struct.unpack(">I", header)[0])
        if body is None:
            return 0
        command, kwargs = pickle.loads(body)
        if command == "quit":
            _send(replies, ("ok", None))
            return 0
        try:
            result = getattr(engine, command)(**kwargs)
        except Exception as exc:  # every failure goes back to the parent as a message
            _send(replies, ("error", f"{type(exc).__name__}: {exc}\n{traceback.format_exc(limit=3)}"))
            continue
        _send(replies, ("ok", result))


if __name__ == "__main__":
    sys.exit(main())
