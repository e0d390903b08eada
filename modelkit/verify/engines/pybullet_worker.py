"""The PyBullet child process behind :mod:`modelkit.verify.engines.pybullet`.

PyBullet keeps global state and can crash (segfault, abort) on bad input, so it never runs in the
verifying process. This script is started by path (``python -P pybullet_worker.py``: ``-P`` keeps its folder,
whose ``pybullet.py`` is the parent's adapter, off ``sys.path``), imports only the
standard library, ``pybullet`` and :mod:`modelkit.verify.engines.child` (itself standard library
only), and answers requests on stdin through :func:`~modelkit.verify.engines.child.serve` (the
framing, and PyBullet's C prints kept out of the replies, are described there).

The worker returns raw PyBullet numbers (link COM frames, inertial frames, joint infos); the frame
algebra lives in the parent, where it can be tested and typed.

The replay of a model with ball joints imports :mod:`modelkit.verify.engines.ball_law` (standard library
only) for the ball's law on the URDF writer's chain.

Layer 4's requests (``drive_setup``, ``drive_run``, ``drive_batch``, ``drive_bench``) are the
exception to "standard library only": they import numpy, :mod:`modelkit.verify.drive` and the
controller factory (``modelkit.verify.drive.controllers:make_controllers``) on first use, so that the seed's
controllers run here, every physics step, without crossing the pipe.
"""

from __future__ import annotations

import math
import os
import sys
import time
from array import array
from typing import Any

SUPPORT_GAP = 1.0e-3
"""m: a link whose closest contact point with the floor is within this distance touches it (its load,
at rest after the settle, goes into the run's ``support``)."""


class _DriveLog:
    """The samples of a driven run: the base pose (position, quaternion) and the recorded joints' q."""

    def __init__(self, p: Any, body: int, client: int, rec_cols: list[int]) -> None:
        self.base_pose = p.getBasePositionAndOrientation
        self.body, self.client, self.rec_cols = body, client, rec_cols
        self.base = array("d")
        self.q = array("d")

    def sample(self, states: Any) -> None:
        pos, orn = self.base_pose(self.body, physicsClientId=self.client)
        self.base.extend(pos)
        self.base.extend(orn)
        self.q.extend(states[i][0] for i in self.rec_cols)


class Engine:
    """One DIRECT PyBullet client holding one fixed-base body."""

    def __init__(self) -> None:
        import pybullet

        self.p = pybullet
        self.client = -1
        self.body = -1
        self.movable: list[int] = []
        self.n_joints = 0
        self.gravity = 0.0

    def load(self, path: str, gravity: float, dt: float) -> dict[str, Any]:
        p = self.p
        self.client = p.connect(p.DIRECT)
        self.gravity = gravity
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

    def accelerations(self, q: list[float], dq: list[float], torques: list[list[float]], gravity: bool,
                      step: float) -> list[list[float]]:
        """PyBullet's forward dynamics: per torque vector, the joint accelerations from (q, dq) under
        it, read as (dq' − dq) / ``step`` after one ``stepSimulation`` of ``step`` seconds (btMultiBody
        updates the velocities with the accelerations of the start state before the positions, so
        this is its articulated-body solution at the start, exactly). Gravity on or off; joint limits
        made inert first (a long step would otherwise meet a limit inside it) and the velocity clamp
        lifted for the step (back to ``limits_off``'s afterwards, with the time step).

        For the mass matrix and bias of a model whose tensors PyBullet's inverse-dynamics library
        refuses (``calculateMassMatrix``, ``calculateInverseDynamics``), which stepping never checks."""
        p, body, client, idx = self.p, self.body, self.client, list(self.movable)
        before = p.getPhysicsEngineParameters(physicsClientId=client)["fixedTimeStep"]
        self.limits_off()
        p.changeDynamics(body, -1, maxJointVelocity=1e30, physicsClientId=client)  # a light link's dq'
        p.setTimeStep(step, physicsClientId=client)
        p.setGravity(0.0, 0.0, self.gravity if gravity else 0.0, physicsClientId=client)
        out = []
        try:
            for tau in torques:
                self._set_q(q, dq)
                p.setJointMotorControlArray(body, idx, p.TORQUE_CONTROL, forces=list(tau),
                                            physicsClientId=client)
                p.stepSimulation(physicsClientId=client)
                after = p.getJointStates(body, idx, physicsClientId=client)
                out.append([(s[1] - v) / step for s, v in zip(after, dq, strict=True)])
        finally:
            p.setGravity(0.0, 0.0, self.gravity, physicsClientId=client)
            p.setTimeStep(before, physicsClientId=client)
            p.changeDynamics(body, -1, maxJointVelocity=1e4, physicsClientId=client)  # limits_off's clamp
            self._set_q(q, dq)
        return out

    def _reset(self, dt: float) -> None:
        n = len(self.movable)
        self._set_q([0.0] * n, [0.0] * n)
        self.p.setTimeStep(dt, physicsClientId=self.client)

    def limits_off(self) -> None:
        """Joint limits out of the replay (MuJoCo's side: ``mjDSBL_LIMIT``). PyBullet keeps a limit
        constraint per limited joint whatever ``changeDynamics`` is given (lower > upper is ignored:
        measured, the joint still stops at its URDF limit); bounds at ±1e30 and a zero limit force
        make it inert (measured: the joint runs through its old limit).

        PyBullet's velocity clamp goes too (``maxJointVelocity``, 100 rad/s by default, one value per
        body, set through the base: given per link, the same call changed the links' dynamics and
        parted the engines by 3e-2 rad in 0.1 s; MuJoCo has no clamp): a light wrist whipped by the
        arm above it passes 100 rad/s under a well-conditioned law (example-robot-data's G1: 157 rad/s
        at 3.3 s), and the clamp then parted the engines by 3.7 rad on a sound model (3e-9 rad
        without it)."""
        for j in self.movable:
            self.p.changeDynamics(self.body, j, jointLowerLimit=-1e30, jointUpperLimit=1e30,
                                  jointLimitForce=0.0, physicsClientId=self.client)
        self.p.changeDynamics(self.body, -1, maxJointVelocity=1e4, physicsClientId=self.client)

    def replay(self, kp: list[float], kd: list[float], amplitude: list[float], frequency: list[float],
               phase: list[float], steps: int, dt: float, balls: list[list[int]] | None = None
               ) -> dict[str, Any]:
        """The PD law of ``facts.TorqueLaw`` (joint order = ``movable``), from q = dq = 0, torques
        re-sent before every step (PyBullet's TORQUE_CONTROL lasts one ``stepSimulation``).
        Returns q after every step (row 0 = the start) as a flat float64 array.

        ``balls``: per ball joint, the positions (in ``movable``) of the URDF writer's three joints
        (MK813); their torques are ``ball_law.chain_torques`` of the state, and the two links between
        them hold no rotational inertia here (their 1e-12 kg·m² per axis cannot be held by a ball,
        the other engine's joint: its mass at the pivot can, and stays)."""
        if balls:
            return self._replay_with_balls(kp, kd, amplitude, frequency, phase, steps, dt, balls)
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

    def _replay_with_balls(self, kp: list[float], kd: list[float], amplitude: list[float],
                           frequency: list[float], phase: list[float], steps: int, dt: float,
                           balls: list[list[int]]) -> dict[str, Any]:
        from modelkit.verify.engines.ball_law import chain_torques

        p = self.p
        self._reset(dt)
        self.limits_off()
        body, client, idx = self.body, self.client, list(self.movable)
        for triple in balls:
            for position in triple[:2]:  # the links between the chain's joints
                p.changeDynamics(body, idx[position], localInertiaDiagonal=[0.0, 0.0, 0.0],
                                 physicsClientId=client)
        in_balls = {i for triple in balls for i in triple}
        scalar = [i for i in range(len(idx)) if i not in in_balls]
        laws = [(triple, kp[triple[0]:triple[0] + 3], kd[triple[0]:triple[0] + 3],
                 amplitude[triple[0]:triple[0] + 3], frequency[triple[0]:triple[0] + 3],
                 phase[triple[0]:triple[0] + 3]) for triple in balls]
        if any(triple != [triple[0], triple[0] + 1, triple[0] + 2] for triple in balls):
            raise ValueError("a ball joint's three joints must be consecutive in the movable order")
        start = time.perf_counter()
        states_log: list[Any] = []
        u = [0.0] * len(idx)
        for k in range(steps):
            t = k * dt
            states = p.getJointStates(body, idx, physicsClientId=client)
            states_log.append(states)
            for i in scalar:
                target = amplitude[i] * math.sin(2.0 * math.pi * frequency[i] * t + phase[i])
                u[i] = kp[i] * (target - states[i][0]) - kd[i] * states[i][1]
            for triple, gains, damping, amp, freq, ph in laws:
                angles = [states[i][0] for i in triple]
                rates = [states[i][1] for i in triple]
                u[triple[0]:triple[0] + 3] = chain_torques(angles, rates, t, gains, damping, amp, freq, ph)
            p.setJointMotorControlArray(body, idx, p.TORQUE_CONTROL, forces=u, physicsClientId=client)
            p.stepSimulation(physicsClientId=client)
        states_log.append(p.getJointStates(body, idx, physicsClientId=client))
        out = array("d", [s[0] for states in states_log for s in states])
        out[: len(idx)] = array("d", [0.0] * len(idx))
        return {"q": out.tobytes(), "wall": time.perf_counter() - start}

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

    def render(self, paths: dict[str, str], configurations: list[dict[str, float]], camera: dict[str, Any]
               ) -> list[dict[str, Any]]:
        """Pictures for the report (``modelkit.verify.report.pictures``): each URDF in ``paths`` (view name →
        file) loaded fixed-base at the identity in a client of its own, at every configuration (joint
        name → q), through ``camera`` (eye, target, up, fovy, width, height, near, far) with
        TinyRenderer (software: no GPU, no display). Raw RGBA bytes and the segmentation buffer
        (int32, −1 = background) per (view, configuration)."""
        p = self.p
        width, height = int(camera["width"]), int(camera["height"])
        out = []
        for view, path in sorted(paths.items()):
            client = p.connect(p.DIRECT)
            try:
                flags = p.URDF_USE_INERTIA_FROM_FILE | p.URDF_USE_IMPLICIT_CYLINDER
                body = p.loadURDF(path, useFixedBase=True, flags=flags, physicsClientId=client)
                index = {p.getJointInfo(body, j, physicsClientId=client)[1].decode(): j
                         for j in range(p.getNumJoints(body, physicsClientId=client))}
                view_matrix = p.computeViewMatrix(camera["eye"], camera["target"], camera["up"],
                                                  physicsClientId=client)
                projection = p.computeProjectionMatrixFOV(camera["fovy"], width / height, camera["near"],
                                                          camera["far"], physicsClientId=client)
                for number, q in enumerate(configurations):
                    for name, value in q.items():
                        if name in index:
                            p.resetJointState(body, index[name], value, 0.0, physicsClientId=client)
                    _, _, rgba, _, seg = p.getCameraImage(
                        width, height, view_matrix, projection, renderer=p.ER_TINY_RENDERER, shadow=0,
                        lightDirection=[float(c) for c in camera["eye"]], physicsClientId=client)
                    rgba_bytes = rgba.tobytes() if hasattr(rgba, "tobytes") else array("B", rgba).tobytes()
                    seg_bytes = (seg.astype("int32").tobytes() if hasattr(seg, "astype")
                                 else array("i", seg).tobytes())
                    out.append({"view": view, "config": number, "rgba": rgba_bytes, "seg": seg_bytes})
            finally:
                p.disconnect(physicsClientId=client)
        return out


    # ---- layer 4: the floating-base robot driven on a floor (engine_pybullet.driver) -------------

    def drive_setup(self, path: str, gravity: float, dt: float, solver_iterations: int,
                    friction: dict[str, float], default_friction: float, floor_friction: float,
                    contact_joints: list[str], contact_friction: float | None,
                    drive: dict[str, Any], scenario: dict[str, Any], factory: str,
                    joint_names: dict[str, str], roller_radius: float,
                    sys_path: list[str] | None = None,
                    engine_parameters: dict[str, Any] | None = None,
                    floor: str = "plane.urdf") -> dict[str, Any]:
        """Keep the layer-4 set-up and build the controllers here, from plain data, with the same
        factory the parent uses (``module:function``), so the stepping loop never crosses the pipe.
        ``joint_names``: source joint name → the URDF's. ``friction``: link → its friction against
        the floor (``default_friction`` for the others); ``contact_friction`` (when set) replaces it
        on the child links of ``contact_joints`` (the wheels, the rollers). Loads the world once to
        report it."""
        import importlib

        for entry in sys_path or []:
            if entry not in sys.path:
                sys.path.insert(0, entry)
        module, _, function = factory.partition(":")
        make = getattr(importlib.import_module(module), function)
        self.drive_cfg: dict[str, Any] = {
                          "path": path, "gravity": gravity, "dt": dt, "iterations": solver_iterations,
                          "friction": dict(friction), "default_friction": default_friction,
                          "floor_friction": floor_friction, "roller_radius": roller_radius,
                          "contact_joints": list(contact_joints), "contact_friction": contact_friction,
                          "engine_parameters": dict(engine_parameters or {}), "floor": floor}
        self.drive_rollers = {k: list(v) for k, v in drive.get("rollers", {}).items()}
        self.drive_names = dict(joint_names)
        self.controllers = make(drive, scenario)
        info = self._drive_world()
        info["controllers"] = [(c.name, str(c.mode), list(c.joints)) for c in self.controllers]
        return info

    def _drive_world(self) -> dict[str, Any]:
        """A fresh world (``resetSimulation``: no contact cache or warm start survives a run, so every
        run starts from the same state): gravity, dt, solver iterations, the engine parameters the
        robot's notes name (MK825), pybullet_data's ``plane.urdf`` as shipped, the URDF as written
        (floating; its contact, friction and link damping untouched: no ``changeDynamics`` on it but
        the control law's joint damping, zero until a profile's law sets it), default motors off but on
        bounded joints nothing drives (they hold the start pose, as in a user's world), the root link
        frame at the origin lowered until the closest point touches the floor."""
        p, cfg = self.p, self.drive_cfg
        if getattr(self, "drive_client", -1) < 0:
            self.drive_client = p.connect(p.DIRECT)
        c = self.drive_client
        p.resetSimulation(physicsClientId=c)
        p.setGravity(0.0, 0.0, cfg["gravity"], physicsClientId=c)
        p.setTimeStep(cfg["dt"], physicsClientId=c)
        p.setPhysicsEngineParameter(numSolverIterations=cfg["iterations"], physicsClientId=c)
        if cfg["engine_parameters"]:
            p.setPhysicsEngineParameter(**cfg["engine_parameters"], physicsClientId=c)
        if cfg["floor"] == "analytic":  # engine_pybullet.ANALYTIC_FLOOR: tests of the control path
            shape = p.createCollisionShape(p.GEOM_PLANE, physicsClientId=c)
            self.floor = p.createMultiBody(0.0, shape, physicsClientId=c)
            p.changeDynamics(self.floor, -1, lateralFriction=1.0, physicsClientId=c)
        else:
            import pybullet_data

            self.floor = p.loadURDF(os.path.join(pybullet_data.getDataPath(), cfg["floor"]),
                                    physicsClientId=c)
        flags = p.URDF_USE_INERTIA_FROM_FILE | p.URDF_USE_IMPLICIT_CYLINDER
        body = p.loadURDF(cfg["path"], useFixedBase=False, flags=flags, physicsClientId=c)
        self.drive_body = body
        n = p.getNumJoints(body, physicsClientId=c)
        joints = [p.getJointInfo(body, j, physicsClientId=c) for j in range(n)]
        link_index = {p.getBodyInfo(body, physicsClientId=c)[0].decode(): -1}
        link_index.update({j[12].decode(): j[0] for j in joints})
        joint_index = {j[1].decode(): j[0] for j in joints}
        friction = {}
        contact = {j[12].decode() for j in joints if j[1].decode() in cfg["contact_joints"]}
        floor_mu = float(p.getDynamicsInfo(self.floor, -1, physicsClientId=c)[1])
        for name, link in link_index.items():
            # PyBullet's own default velocity damping (0.04 on every link: no URDF field holds it, an
            # engine setting a torque-driven robot's user turns off); contact and friction untouched
            p.changeDynamics(body, link, linearDamping=0.0, angularDamping=0.0, jointDamping=0.0,
                             physicsClientId=c)
            # Bullet multiplies the two bodies' lateral friction: the contact's value against the floor
            friction[name] = float(p.getDynamicsInfo(body, link, physicsClientId=c)[1]) * floor_mu
        # PyBullet's default motors (velocity 0, force the URDF effort) off on the joints verify drives
        # and on unbounded ones (casters, passive wheels: a user frees them); kept, as the user's
        # world has them, on bounded joints nothing drives (TIAGo's arm and torso: freed, the arm
        # folded and the robot tipped over).
        driven = {self.drive_names.get(j, j) for ctl in self.controllers for j in ctl.joints}
        driven |= {self.drive_names.get(j, j) for group in self.drive_rollers.values() for j in group}
        driven |= set(cfg["contact_joints"])
        self.held_joints = sorted(j[1].decode() for j in joints
                                  if j[2] in (p.JOINT_REVOLUTE, p.JOINT_PRISMATIC) and j[8] < j[9]
                                  and j[1].decode() not in driven)
        for j in range(n):
            if joints[j][1].decode() not in self.held_joints:
                p.setJointMotorControl2(body, j, p.VELOCITY_CONTROL, targetVelocity=0.0, force=0.0,
                                        physicsClientId=c)
        self.drive_gears = self._belts(body, joint_index)
        inertial = p.getDynamicsInfo(body, -1, physicsClientId=c)
        self.base_inertial = (tuple(inertial[3]), tuple(inertial[4]))
        p.resetBasePositionAndOrientation(body, inertial[3], inertial[4], physicsClientId=c)
        points = p.getClosestPoints(body, self.floor, 10.0, physicsClientId=c)
        gap = min((pt[8] for pt in points), default=0.0)
        com = list(inertial[3])
        com[2] -= gap
        p.resetBasePositionAndOrientation(body, com, inertial[4], physicsClientId=c)
        self.drive_start_height = -gap
        self.drive_joint_index = joint_index
        self.drive_link_names = {index: name for name, index in link_index.items()}
        # The velocity servos' bound, SERVO_FRICTION_SHARE·m·g·μ·r / rollers
        # (``variant.servo_torque_limit``; MuJoCo's too).
        mass = sum(p.getDynamicsInfo(body, link, physicsClientId=c)[0] for link in range(-1, n))
        mu = max((friction[name] for name in contact), default=0.0)
        count = sum(len(g) for g in self.drive_rollers.values())
        from modelkit.verify.drive.variant import servo_torque_limit

        self.servo_limit = servo_torque_limit(mass, mu, cfg["roller_radius"], count, abs(cfg["gravity"]))
        return {"links": sorted(link_index), "friction": friction, "start_height": -gap,
                "servo_limit": self.servo_limit, "belts": [list(pair) for pair in self.drive_gears],
                "base_inertial": self.base_inertial, "joints": sorted(joint_index),
                "held": self.held_joints}

    BELT_MAX_TORQUE = 1.0e4
    """N·m: the gear constraints' bound (far above any servo's; the belt never gives way)."""

    def _belts(self, body: int, joint_index: dict[str, int]) -> list[tuple[str, str]]:
        """Each track's rollers coupled like the belt the URDF's ``<mimic>`` describes (roller i > 0
        turns with roller 0, multiplier 1): PyBullet ignores ``<mimic>``, so a gear constraint
        (``JOINT_GEAR``, gear ratio −1: equal speeds) per roller i > 0. Without it each roller is
        driven alone, and a roller the rigid solver leaves lightly loaded (four coplanar supports: the
        split of the weight among them is not determined; measured 11 N of an average 43 N) slips
        while the others don't, so the robot accelerates slower than its servos' torque allows."""
        p, c = self.p, self.drive_client
        coupled = []
        for group in self.drive_rollers.values():
            ids = [joint_index.get(self.drive_names.get(name, name)) for name in group]
            if len(ids) < 2 or any(i is None for i in ids):
                continue
            for name, other in zip(group[1:], ids[1:], strict=True):
                gear = p.createConstraint(body, ids[0], body, other, jointType=p.JOINT_GEAR,
                                          jointAxis=[0.0, 1.0, 0.0], parentFramePosition=[0.0, 0.0, 0.0],
                                          childFramePosition=[0.0, 0.0, 0.0], physicsClientId=c)
                p.changeConstraint(gear, gearRatio=-1.0, maxForce=self.BELT_MAX_TORQUE, physicsClientId=c)
                coupled.append((group[0], name))
        return coupled

    def drive_run(self, profile: dict[str, Any], sample_every: int, recorded: list[str],
                  fast: bool = False) -> dict[str, Any]:
        """One profile: settle at zero torque (velocity joints held at 0), then the controllers every
        step, torques re-sent before every ``stepSimulation`` (TORQUE_CONTROL lasts one step), velocity
        targets through VELOCITY_CONTROL at the set maximum force on every roller of a track.
        Returns the base COM frame poses and the ``recorded`` joints' positions after every
        ``sample_every`` steps (raw float64 bytes; the frame algebra is the parent's).

        ``fast``: the affine laws applied by Bullet itself when every controller allows it
        (:meth:`_drive_laws`; ``"law"`` in the result says which path ran: ``"bullet"`` or
        ``"per-step"``)."""
        import numpy as np

        from modelkit.verify.drive import Command, Profile, command_steps

        p, cfg = self.p, self.drive_cfg
        self._drive_world()
        c, body, dt = self.drive_client, self.drive_body, cfg["dt"]
        index = self.drive_joint_index

        def jid(name: str) -> int:
            return index[self.drive_names.get(name, name)]

        plan = []  # (controller, columns in the state read, torque?, joint ids that take its outputs)
        read: list[int] = []
        torque_ids: list[int] = []
        velocity_ids: list[int] = []
        velocity_fan: list[int] = []  # per velocity joint id: which velocity output drives it
        v_count = 0
        for ctl in self.controllers:
            cols = []
            for name in ctl.joints:
                if jid(name) not in read:
                    read.append(jid(name))
                cols.append(read.index(jid(name)))
            torque = str(ctl.mode) != "velocity"
            if torque:
                torque_ids.extend(jid(name) for name in ctl.joints)
            else:
                for i, name in enumerate(ctl.joints):
                    group = next((g for g in self.drive_rollers.values() if g and g[0] == name), [name])
                    for member in group:
                        velocity_ids.append(jid(member))
                        velocity_fan.append(v_count + i)
                v_count += len(ctl.joints)
            plan.append((ctl, cols, torque))
        rec_cols = []
        for name in recorded:
            if jid(name) not in read:
                read.append(jid(name))
            rec_cols.append(read.index(jid(name)))
        steps = round(profile["duration"] / dt)
        settle = round(profile["settle"] / dt)
        commands = [Command(**cmd) for cmd in profile["commands"]]
        changes = command_steps(Profile(**{**profile, "commands": tuple(commands)}), dt, steps)
        laws = self._drive_laws(plan, commands, torque_ids) if fast else None
        if laws is not None:
            return self._drive_run_fast(laws, torque_ids, velocity_ids, velocity_fan, read, rec_cols, steps,
                                        settle, changes, sample_every)
        torque_mode, velocity_mode = p.TORQUE_CONTROL, p.VELOCITY_CONTROL
        set_array, step, get_states = p.setJointMotorControlArray, p.stepSimulation, p.getJointStates
        zeros_t = [0.0] * len(torque_ids)
        zeros_v = [0.0] * len(velocity_ids)
        max_force = [self.servo_limit] * len(velocity_ids)
        start = time.perf_counter()
        for _ in range(settle):
            if torque_ids:
                set_array(body, torque_ids, torque_mode, forces=zeros_t, physicsClientId=c)
            if velocity_ids:
                set_array(body, velocity_ids, velocity_mode, targetVelocities=zeros_v, forces=max_force,
                          physicsClientId=c)
            step(physicsClientId=c)
        settled = time.perf_counter() - start
        self._support_at_rest = self._support()
        command = Command(0.0)
        log = _DriveLog(p, body, c, rec_cols)
        asarray = np.array
        for k in range(steps + 1):
            states = get_states(body, read, physicsClientId=c)
            if k % sample_every == 0:
                log.sample(states)
            if k == steps:
                break
            if k in changes:
                command = changes[k]
            t = k * dt
            torques: list[float] = []
            targets: list[float] = []
            for ctl, cols, torque in plan:
                u = ctl.output(t, command, asarray([states[i][0] for i in cols]),
                               asarray([states[i][1] for i in cols]))
                (torques if torque else targets).extend(u)
            if torque_ids:
                set_array(body, torque_ids, torque_mode, forces=torques, physicsClientId=c)
            if velocity_ids:
                set_array(body, velocity_ids, velocity_mode,
                          targetVelocities=[targets[i] for i in velocity_fan], forces=max_force,
                          physicsClientId=c)
            step(physicsClientId=c)
        return self._drive_result(log, time.perf_counter() - start, settled, "per-step")

    def _drive_result(self, log: _DriveLog, wall: float, settled: float, law: str) -> dict[str, Any]:
        return {"base": log.base.tobytes(), "q": log.q.tobytes(), "wall": wall, "settle_wall": settled,
                "base_inertial": self.base_inertial, "start_height": self.drive_start_height, "law": law,
                "support": self._support_at_rest}

    def _support(self) -> dict[str, float]:
        """Each robot link touching the floor (a contact point within 1 mm): the sum of its contact
        points' normal forces, N (0 for a link that touches but carries nothing)."""
        out: dict[str, float] = {}
        for point in self.p.getContactPoints(self.drive_body, self.floor, physicsClientId=self.drive_client):
            if point[8] <= SUPPORT_GAP:
                name = self.drive_link_names.get(point[3], str(point[3]))
                out[name] = out.get(name, 0.0) + float(point[9])
        return out

    @staticmethod
    def _drive_laws(plan: list[Any], commands: list[Any], torque_ids: list[int]
                    ) -> dict[Any, tuple[list[float], list[float], list[float]]] | None:
        """Per command (and the zero command before the first): ``(torque offsets, torque gains,
        velocity targets)`` in the order of ``torque_ids`` / the velocity outputs, from the
        controllers' ``affine_law`` (``output = offset − gain·q̇`` while the command holds). None
        (the per-step path runs) when a controller has no ``affine_law``, a gain is negative or not
        finite, a velocity-mode law has a q̇ term (that is not a velocity target), or a joint takes
        torques from two controllers (Bullet's damping is per joint)."""
        if len(set(torque_ids)) != len(torque_ids):
            return None
        out: dict[Any, tuple[list[float], list[float], list[float]]] = {}
        from modelkit.verify.drive import Command

        for command in [Command(0.0), *commands]:
            offsets: list[float] = []
            gains: list[float] = []
            targets: list[float] = []
            for ctl, _, torque in plan:
                law = getattr(ctl, "affine_law", None)
                if law is None:
                    return None
                offset, gain = law(command)
                offset = [float(x) for x in offset]
                gain = [float(x) for x in gain]
                if len(offset) != len(ctl.joints) or len(gain) != len(ctl.joints):
                    return None
                if not all(math.isfinite(x) for x in offset + gain) or any(g < 0.0 for g in gain):
                    return None
                if torque:
                    offsets.extend(offset)
                    gains.extend(gain)
                elif any(g != 0.0 for g in gain):
                    return None
                else:
                    targets.extend(offset)
            out[command] = (offsets, gains, targets)
        return out

    def _drive_run_fast(self, laws: dict[Any, tuple[list[float], list[float], list[float]]],
                        torque_ids: list[int], velocity_ids: list[int], velocity_fan: list[int],
                        read: list[int], rec_cols: list[int], steps: int, settle: int,
                        changes: dict[int, Any], sample_every: int) -> dict[str, Any]:
        """``drive_run`` with the seed's affine laws ``u = offset − gain·q̇`` applied by Bullet:

        * ``−gain·q̇``: the law joints' ``jointDamping`` (``changeDynamics``), which PyBullet's server
          applies before every ``stepSimulation`` as the explicit joint torque ``−d·q̇`` from the
          velocity at the start of the step (``PhysicsServerCommandProcessor::applyJointDamping``,
          ``addJointTorqueMultiDof``) — the per-step path's ``kd·(q* − q̇)`` from the state it reads
          just before the step, to round-off (``tests/test_verify_drivers_pybullet_fast.py``). 0 on
          every joint while settling (the per-step path sends zero torque) and on every other joint;
        * ``offset``: TORQUE_CONTROL re-sent before every step (it lasts one step), nothing sent
          while it is zero on every joint (a zero torque and no call are the same step: the
          applied torques are cleared after each step);
        * velocity targets: VELOCITY_CONTROL at command changes only (the motor persists; the
          per-step path re-sends the same target and force every step);
        * states and the base pose read at samples only."""
        p = self.p
        c, body = self.drive_client, self.drive_body
        torque_mode, velocity_mode = p.TORQUE_CONTROL, p.VELOCITY_CONTROL
        set_array, step, get_states = p.setJointMotorControlArray, p.stepSimulation, p.getJointStates
        change_dynamics = p.changeDynamics
        max_force = [self.servo_limit] * len(velocity_ids)
        start = time.perf_counter()
        if velocity_ids:
            set_array(body, velocity_ids, velocity_mode, targetVelocities=[0.0] * len(velocity_ids),
                      forces=max_force, physicsClientId=c)
        for _ in range(settle):
            step(physicsClientId=c)
        settled = time.perf_counter() - start
        self._support_at_rest = self._support()
        damping = [0.0] * len(torque_ids)
        targets: list[float] | None = None
        forces: list[float] = []
        log = _DriveLog(p, body, c, rec_cols)
        events = sorted(set(range(0, steps + 1, sample_every)) | {k for k in changes if k < steps} | {steps})
        law = laws[next(iter(laws))]  # the zero command's, until the first change
        for at, until in zip(events, [*events[1:], steps], strict=True):
            if at % sample_every == 0:
                log.sample(get_states(body, read, physicsClientId=c))
            if at == steps:
                break
            if at in changes:
                law = laws[changes[at]]
            offsets, gains, velocity = law
            for joint, gain, old in zip(torque_ids, gains, damping, strict=True):
                if gain != old:
                    change_dynamics(body, joint, jointDamping=gain, physicsClientId=c)
            damping = gains
            if velocity_ids and velocity != targets:
                set_array(body, velocity_ids, velocity_mode,
                          targetVelocities=[velocity[i] for i in velocity_fan], forces=max_force,
                          physicsClientId=c)
                targets = velocity
            forces = offsets
            if torque_ids and any(f != 0.0 for f in forces):
                for _ in range(until - at):
                    set_array(body, torque_ids, torque_mode, forces=forces, physicsClientId=c)
                    step(physicsClientId=c)
            else:
                for _ in range(until - at):
                    step(physicsClientId=c)
        for joint, gain in zip(torque_ids, damping, strict=True):
            if gain != 0.0:  # the world is rebuilt for every run; leave nothing acting anyway
                change_dynamics(body, joint, jointDamping=0.0, physicsClientId=c)
        return self._drive_result(log, time.perf_counter() - start, settled, "bullet")

    def drive_batch(self, runs: list[dict[str, Any]]) -> list[dict[str, Any]]:
        """Several ``drive_run`` requests in one (one pipe round trip for all the profiles)."""
        return [self.drive_run(**run) for run in runs]

    def drive_bench(self, steps: int, at: dict[str, float] | None = None) -> dict[str, float]:
        """Wall times over ``steps`` steps on the layer-4 world (floating robot on the floor): a bare
        ``stepSimulation`` loop (``bare``) and a minimal closed loop (``closed_loop``: read the
        controlled joints' states, call the torque controllers with one fixed command, send the
        torques, step; no sampling, no command schedule). ``at``: that command (plain data;
        default v 0.3, w 0.5). In both loops a velocity-mode controller's servos (the track rollers) are
        engaged once at that command's targets before the loop: velocity constraints the solver
        carries in every step of a driven run, part of the model's physics like MuJoCo's velocity
        actuators, not harness work (``bare_unservoed``: the bare loop without them, robot at rest)."""
        import numpy as np

        from modelkit.verify.drive import Command

        p = self.p
        command = Command(**at) if at is not None else Command(0.0, 0.3, 0.5)
        c, step = self.drive_client, p.stepSimulation
        self._drive_world()
        start = time.perf_counter()
        for _ in range(steps):
            step(physicsClientId=c)
        unservoed = time.perf_counter() - start
        self._drive_world()
        self._engage_servos(command)
        start = time.perf_counter()
        for _ in range(steps):
            step(physicsClientId=c)
        bare = time.perf_counter() - start
        self._drive_world()
        self._engage_servos(command)
        body = self.drive_body
        index = self.drive_joint_index
        plan = [(ctl, [index[self.drive_names.get(j, j)] for j in ctl.joints]) for ctl in self.controllers
                if str(ctl.mode) != "velocity"]
        ids = [i for _, joints in plan for i in joints]
        dt = self.drive_cfg["dt"]
        start = time.perf_counter()
        for k in range(steps):
            states = p.getJointStates(body, ids, physicsClientId=c)
            forces: list[float] = []
            offset = 0
            for ctl, joints in plan:
                part = states[offset:offset + len(joints)]
                offset += len(joints)
                forces.extend(ctl.output(k * dt, command, np.array([s[0] for s in part]),
                                         np.array([s[1] for s in part])))
            p.setJointMotorControlArray(body, ids, p.TORQUE_CONTROL, forces=forces, physicsClientId=c)
            step(physicsClientId=c)
        return {"bare": bare, "closed_loop": time.perf_counter() - start, "bare_unservoed": unservoed}

    def _engage_servos(self, command: Any) -> None:
        """The velocity-mode controllers' targets for ``command`` into their joints' VELOCITY_CONTROL
        servos (every roller of a track gets roller 0's), at the servo force bound."""
        import numpy as np

        p, index = self.p, self.drive_joint_index
        ids: list[int] = []
        targets: list[float] = []
        for ctl in self.controllers:
            if str(ctl.mode) != "velocity":
                continue
            out = ctl.output(0.0, command, np.zeros(len(ctl.joints)), np.zeros(len(ctl.joints)))
            for name, target in zip(ctl.joints, out, strict=True):
                group = next((g for g in self.drive_rollers.values() if g and g[0] == name), [name])
                for member in group:
                    ids.append(index[self.drive_names.get(member, member)])
                    targets.append(float(target))
        if ids:
            p.setJointMotorControlArray(self.drive_body, ids, p.VELOCITY_CONTROL, targetVelocities=targets,
                                        forces=[self.servo_limit] * len(ids),
                                        physicsClientId=self.drive_client)


def main() -> int:
    from modelkit.verify.engines.child import serve

    return serve(Engine)


if __name__ == "__main__":
    sys.exit(main())
