"""Engine-independent references for layer 4 (verification.md §1, "References").

* :func:`noslip` — the **rigid no-slip differential drive** built from the model's own mass
  properties and driven by the very same discrete controllers as the engines (1 kHz, zero-order
  hold), integrated with RK4. Newton–Euler about the axle midpoint P (body frame: x forward, y left),
  P moving along x only (no lateral slip), wheels rolling without slip. With v the forward speed of P
  and w the yaw rate::

      M_eff v' − K w' = (τR + τL)/r + M cx w² + M cy w'     (written as the mass matrix below)
      J_eff w' + ...  = b (τR − τL)/r − M cx v w

  i.e. the mass matrix ``[[M + (IsL + IsR)/r², −M cy + b (IsR − IsL)/r²],
  [·, I_P + b² (IsL + IsR)/r²]]`` on (v', w') against the forces ``((τL + τR)/r + M cx w²,
  b (τR − τL)/r − M cx v w)``, where M is the whole robot's mass, (cx, cy) its COM relative to P,
  I_P its yaw inertia about the vertical through P (wheels' diametral inertia and m b² included)
  and Is each wheel's spin inertia about its axle. For the tutorial robot (chassis COM 8 cm behind
  the axle) this gives M_eff = 16.40 kg and J_eff = 0.362 kg m², as §1 lists.

  A pan joint (vertical axis) is a rotor on the chassis: its subtree's yaw inertia ``I_p`` about the
  pan axis adds the row ``I_p (w' + q̈_pan) = u_pan`` and couples into the yaw row, so the reaction of
  the pan torque on the chassis is in the reference. The pan/tilt links otherwise count as chassis
  mass **at q = 0** (their COM lies on their joint axes in the tutorial robots, so moving them shifts
  no mass; a robot whose pan/tilt COM is off-axis is approximated). A tilt joint is integrated as
  ``I_t q̈_tilt = u_tilt`` (gravity and the chassis' motion ignored) for the plots only.

  Tracks: the track controller commands roller **velocities**, which the engines hold with a
  velocity servo whose torque is bounded (``variant.servo_torque_limit``: a share of what friction
  can pass through each roller). The reference models that servo the same way: every control period
  it computes the side torques that bring each side's rollers exactly to their targets by the end of
  the period (a velocity constraint, as PyBullet's motor and MuJoCo's stiff velocity actuator are),
  clips each side to its bound (rollers on a side × the per-roller bound) and integrates the rigid
  no-slip dynamics with them. So a speed step is a torque-saturated ramp of acceleration
  ``n·τ_max / (r·M_eff)`` (the start-up transient, about 0.1 s and 2.6 cm on the tutorial robot's
  0.5 m/s straight), then the target held exactly. For a straight run this is meaningful (a track
  rolling without slip); a turning tracked robot must skid sideways (skid steering), which no rigid
  no-slip model describes: layer 4 grades only what is meaningful (see :mod:`modelkit.verify.layers.layer4`).

* :func:`unicycle` — the ideal unicycle ``x' = v cos θ, y' = v sin θ, θ' = w`` integrated exactly
  from the commanded (v, w) (piecewise constant: arcs and straight segments in closed form).

* :func:`odometry` — an engine trajectory's wheel odometry (its own wheel angles, r and b), to show
  slip: the distance between an engine's path and its own odometry is how far it slipped.

Every trajectory is the **root link frame's** planar pose relative to command start, sampled at the
scenario's rate from t = 0 to the duration inclusive (like the engines'); P's path is converted to
the root frame's through the root origin's offset from P.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from modelkit.model import Robot
from modelkit.spatial import combine_mass_properties, rotate_inertia
from modelkit.verify.drive import Array, Command, Drive, Profile, Scenario, Trajectory, command_steps
from modelkit.verify.drive.controllers import make_controllers
from modelkit.verify.drive.scenario import scenario_dict

RK4_SUBSTEPS = 1  # RK4 steps per control period (1 ms); 10 (0.1 ms, as §1) agrees to 1e-11 m, 5x slower


@dataclass(frozen=True)
class PlanarModel:
    """The mass properties the no-slip reference uses (root frame at q = 0, SI)."""

    mass: float  # M, the whole robot
    com: tuple[float, float]  # (cx, cy) relative to the axle midpoint P
    yaw_inertia: float  # I_P about the vertical through P (wheel spin excluded, diametral included)
    spin: tuple[float, float]  # each wheel's inertia about its axle (left, right)
    radius: float
    half_axle: float
    root_offset: tuple[float, float]  # the root frame origin relative to P (x, y)
    pan_inertia: float = 0.0  # the pan subtree's yaw inertia about the pan axis
    tilt_inertia: float = 0.0  # the tilt subtree's inertia about the tilt axis
    notes: tuple[str, ...] = ()
    servo_limit: float = math.inf  # velocity servos: each roller's torque bound, N m (tracks)
    servo_rollers: tuple[int, int] = (1, 1)  # rollers per side sharing a side's servo torque

    @property
    def m_eff(self) -> float:
        return self.mass + (self.spin[0] + self.spin[1]) / self.radius**2

    @property
    def j_eff(self) -> float:
        return self.yaw_inertia + self.half_axle**2 * (self.spin[0] + self.spin[1]) / self.radius**2

    @property
    def coupling(self) -> float:
        """The off-diagonal (v', w') entry of the mass matrix."""
        return -self.mass * self.com[1] + self.half_axle * (self.spin[1] - self.spin[0]) / self.radius**2

    def as_dict(self) -> dict[str, Any]:
        return {
            "mass": self.mass,
            "com": list(self.com),
            "yaw_inertia": self.yaw_inertia,
            "spin_inertia": list(self.spin),
            "m_eff": self.m_eff,
            "j_eff": self.j_eff,
            "radius": self.radius,
            "half_axle": self.half_axle,
            "root_offset": list(self.root_offset),
            "pan_inertia": self.pan_inertia,
            "tilt_inertia": self.tilt_inertia,
            "servo_limit": self.servo_limit if math.isfinite(self.servo_limit) else None,
            "servo_rollers": list(self.servo_rollers),
            "notes": list(self.notes),
        }


def _subtree(robot: Robot, joint_name: str) -> set[str]:
    joint = next(j for j in robot.joints if j.name == joint_name)
    children = robot.children_of()
    out, stack = set(), [joint.child]
    while stack:
        link = stack.pop()
        out.add(link)
        stack.extend(j.child for j in children.get(link, []))
    return out


def _drive_frame(heading: float) -> np.ndarray:
    """The rotation taking root-frame vectors into the drive frame (the root frame turned by
    ``heading`` about Z, :attr:`Drive.heading`)."""
    c, s = math.cos(heading), math.sin(heading)
    return np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]]) if heading else np.eye(3)


def planar_model(robot: Robot, drive: Drive, friction: float | None = None) -> PlanarModel:
    """The no-slip model's parameters from ``robot``'s own links (the source, or for tracks the
    model with its track approximation), every link's inertial at q = 0 in the root frame.
    ``friction``: the roller–floor friction the engines use (``Scenario.friction``); None: the
    contact materials' (``convert.friction.floor_friction``), for the tracks' servo bound."""
    from modelkit.verify.drive.vehicle import wheel_shape

    poses = robot.world_poses()
    inv = poses[str(robot.root)].inverse()
    frames = {name: inv @ pose for name, pose in poses.items()}
    joints = {j.name: j for j in robot.joints}
    links = {link.name: link for link in robot.links}
    # the axle midpoint P: the wheel (or track) centres
    centres = []
    axes = []
    spin_joints = (
        [drive.left, drive.right]
        if drive.kind == "wheels"
        else [drive.rollers[drive.left][0], drive.rollers[drive.right][0]]
    )
    for link_name, joint_name in zip(drive.wheel_links, spin_joints, strict=True):
        frame = frames[link_name]
        joint = joints.get(joint_name)
        axis = np.asarray(frames[joint.child].rotation @ joint.axis, dtype=float) if joint else np.eye(3)[1]
        axis = axis / np.linalg.norm(axis)
        axes.append(axis)
        shape = wheel_shape(links[link_name], frame.rotation.T @ axis) if drive.kind == "wheels" else None
        centres.append(frame.rotation @ shape[1] + frame.translation if shape else frame.translation)
    p = 0.5 * (centres[0] + centres[1])
    masses: list[tuple[str, float, np.ndarray, np.ndarray]] = []  # link, m, COM in root, inertia in root
    for link in robot.links:
        if link.inertial is None or link.name not in frames or link.inertial.mass <= 0.0:
            continue
        frame = frames[link.name]
        c = frame.rotation @ np.asarray(link.inertial.com, dtype=float) + frame.translation
        masses.append((link.name, float(link.inertial.mass), c,
                       rotate_inertia(link.inertial.inertia, frame.rotation)))
    mass, centre, about_com = combine_mass_properties([(m, c, i) for _, m, c, i in masses])
    turn = _drive_frame(drive.heading)
    com = turn @ (np.asarray(centre) - p)  # relative to the axle midpoint, in the drive frame
    inertia = float(about_com[2, 2]) + mass * float(com[0] ** 2 + com[1] ** 2)  # yaw, about P
    spin = []
    spinning = (
        ([drive.wheel_links[0]], [drive.wheel_links[1]])
        if drive.kind == "wheels"
        else (
            [joints[j].child for j in drive.rollers[drive.left]],
            [joints[j].child for j in drive.rollers[drive.right]],
        )
    )
    by_link = {name: (m, c, i) for name, m, c, i in masses}
    for side, axis in zip(spinning, axes, strict=True):
        spin.append(sum(float(axis @ by_link[n][2] @ axis) for n in side if n in by_link))
    notes = []
    pan_inertia = tilt_inertia = 0.0
    if drive.pan is not None:
        pan = joints[drive.pan]
        axis = frames[pan.child].rotation @ (pan.axis / np.linalg.norm(pan.axis))
        origin = frames[pan.child].translation
        pan_inertia = _axis_inertia(by_link, _subtree(robot, drive.pan), axis, origin)
        notes.append(
            "pan/tilt links counted as chassis mass at q = 0; the pan joint is a rotor on the chassis"
        )
    if drive.tilt is not None:
        tilt = joints[drive.tilt]
        axis = frames[tilt.child].rotation @ (tilt.axis / np.linalg.norm(tilt.axis))
        tilt_inertia = _axis_inertia(
            by_link, _subtree(robot, drive.tilt), axis, frames[tilt.child].translation
        )
    root = turn @ (frames[str(robot.root)].translation - p)  # the root origin relative to P
    servo_limit, servo_rollers = math.inf, (1, 1)
    if drive.kind == "tracks":
        servo_limit, servo_rollers = _servo_bound(robot, drive, mass, friction)
        notes.append(
            "tracks: roller velocities servoed as in the engines (a velocity constraint whose torque is "
            f"bounded by {servo_limit:.4g} N m per roller, m·g·μ·r·share / rollers), no slip, no skid"
        )
    return PlanarModel(
        mass=mass,
        com=(float(com[0]), float(com[1])),
        yaw_inertia=inertia,
        spin=(spin[0], spin[1]),
        radius=drive.radius,
        half_axle=drive.half_axle,
        root_offset=(float(root[0]), float(root[1])),
        pan_inertia=pan_inertia,
        tilt_inertia=tilt_inertia,
        notes=tuple(notes),
        servo_limit=servo_limit,
        servo_rollers=servo_rollers,
    )


def _servo_bound(
    robot: Robot, drive: Drive, mass: float, friction: float | None
) -> tuple[float, tuple[int, int]]:
    """The per-roller torque bound of the engines' velocity servos (``variant.servo_torque_limit``,
    from the whole robot's mass, the rollers' friction against the floor and the roller radius) and
    the number of rollers on each side."""
    from modelkit.convert.friction import floor_friction
    from modelkit.verify.drive.variant import servo_torque_limit

    joints = {j.name: j for j in robot.joints}
    sides = [
        [joints[j].child for j in drive.rollers.get(side, ()) if j in joints]
        for side in (drive.left, drive.right)
    ]
    if friction is None:
        table = floor_friction(robot)
        friction = max((table[link].dynamic for side in sides for link in side if link in table), default=0.0)
    count = sum(len(side) for side in sides)
    radius = drive.roller_radius or drive.radius
    return servo_torque_limit(mass, friction, radius, count), (max(1, len(sides[0])), max(1, len(sides[1])))


def _axis_inertia(
    by_link: dict[str, tuple[float, np.ndarray, np.ndarray]],
    subtree: set[str],
    axis: np.ndarray,
    origin: np.ndarray,
) -> float:
    total = 0.0
    for name in subtree:
        if name in by_link:
            m, c, i = by_link[name]
            d = c - origin
            d_perp = d - axis * float(axis @ d)
            total += float(axis @ i @ axis) + m * float(d_perp @ d_perp)
    return total


def law_too_stiff(model: PlanarModel, drive: Drive, scenario: Scenario) -> str | None:
    """Why the scenario's wheel law cannot drive this robot at its control period (None when it can).

    The seed's ``u = kd (dq* − dq)`` is applied once per control period ``dt`` and held: in wheel
    space the speeds move by ``dt·kd·I⁻¹`` of their error each period, where ``I`` is the robot's
    inertia seen by the two wheels (``Jᵀ M J``, M the no-slip mass matrix over (v, w), J the wheels'
    map to (v, w)). Above 1 for the lightest mode the speeds overshoot their targets at every period
    and ring (diverge above 2), in the engines as in this reference: the driven comparison would grade
    numerical ringing. The tutorial robots: 0.01. safety-gymnasium's car (a 20 g chassis of density
    5 kg/m³, wheels of 5 cm): far above 1."""
    if drive.kind != "wheels" or scenario.controller not in (None, "drive"):
        return None
    r, b = model.radius, model.half_axle
    if r <= 0.0 or b <= 0.0:
        return None
    mass = np.array([[model.m_eff, model.coupling], [model.coupling, model.j_eff]])
    to_body = np.array([[r / 2.0, r / 2.0], [-r / (2.0 * b), r / (2.0 * b)]])  # (dqL, dqR) → (v, w)
    wheel_space = to_body.T @ mass @ to_body
    eigen = np.linalg.eigvalsh(wheel_space)
    lightest = float(eigen[0])
    if not math.isfinite(lightest) or lightest <= 0.0:
        return None
    ratio = scenario.kd * scenario.dt / lightest
    if ratio < 1.0:
        return None
    return (f"the drive law u = kd (dq* - dq), kd {scenario.kd:g}, applied every "
            f"{scenario.dt * 1e3:g} ms, is too stiff for this robot: its wheels' lightest mode has an "
            f"inertia of {lightest:.3g} kg·m², so each control period moves the wheel speeds by "
            f"{ratio:.3g} times their error (above 1 they overshoot and ring, above 2 they diverge, in "
            f"any engine); give a scenario kd below {lightest / scenario.dt:.3g}")


# ----------------------------------------------------------------------------------------------------
# the no-slip reference


@dataclass
class _Plant:
    """Constant parts of the equations of motion: the inverse mass matrix over (v, w, q_pan)."""

    model: PlanarModel
    inverse: list[list[float]] = field(default_factory=list)

    def __post_init__(self) -> None:
        m = self.model
        ip = m.pan_inertia
        matrix = np.array([[m.m_eff, m.coupling, 0.0], [m.coupling, m.j_eff, ip], [0.0, ip, ip]])
        if ip == 0.0:
            matrix[2, 2] = 1.0  # no pan: its row is q̈ = u (u is always 0 then)
        self.inverse = np.linalg.inv(matrix).tolist()


def noslip(
    model: PlanarModel, profile: Profile, scenario: Scenario, drive: Drive, substeps: int = RK4_SUBSTEPS
) -> Trajectory:
    """The rigid no-slip reference driven through ``profile`` by the scenario's controllers (the
    same classes the engines run, called once per control period, outputs held)."""
    controllers = make_controllers(drive.as_dict(), scenario_dict(scenario))
    dt = scenario.dt
    h = dt / substeps
    steps = round(profile.duration / dt)
    changes = command_steps(profile, dt, steps)
    sampled = set(scenario_samples(profile, scenario))
    r, b = model.radius, model.half_axle
    mcx = model.mass * model.com[0]
    (a00, a01, a02), (a10, a11, a12), (a20, a21, a22) = _Plant(model).inverse
    it = model.tilt_inertia
    sl, sr = drive.signs
    servo = _Servo(model, dt)
    # state: x, y, th, v, w, phl, phr (forward wheel angles), qp, dqp, qt, dqt
    x = y = th = v = w = phl = phr = qp = dqp = qt = dqt = 0.0
    plan = [
        (
            c,
            c.mode == "velocity",
            [_WIRES[wire] for wire in wires],
            np.zeros(len(c.joints)),
            np.zeros(len(c.joints)),
        )
        for c, wires in zip(controllers, _wiring(controllers, drive), strict=True)
    ]
    rows = []
    command = Command(0.0)
    half, sixth = 0.5 * h, h / 6.0
    cos, sin = math.cos, math.sin

    def accelerations(v: float, w: float, fv: float, fw: float, u_p: float) -> tuple[float, float, float]:
        """(v̇, ẇ, pan q̈) at forward speed v and yaw rate w under the held generalised forces."""
        rv, rw = fv + mcx * w * w, fw - mcx * v * w
        return (a00 * rv + a01 * rw + a02 * u_p, a10 * rv + a11 * rw + a12 * u_p,
                a20 * rv + a21 * rw + a22 * u_p)

    for step in range(steps + 1):
        t = step * dt
        if step in sampled:
            rows.append((t, x, y, th, phl, phr, qp, qt))
        if step == steps:
            break
        command = changes.get(step, command)
        coordinates = (sl * phl, sr * phr, qp, qt)
        speeds = (sl * (v - b * w) / r, sr * (v + b * w) / r, dqp, dqt)
        torques = [0.0, 0.0, 0.0, 0.0]  # forward wheel torques (L, R), pan, tilt
        targets: tuple[float, float] | None = None
        for c, velocity, wires, qb, dqb in plan:
            for i, k in enumerate(wires):
                qb[i] = coordinates[k]
                dqb[i] = speeds[k]
            u = c.output(t, command, qb, dqb)
            for i, k in enumerate(wires):
                torques[k] = float(u[i])
            if velocity:  # roller speed targets (joint sense) → forward side speeds, rad/s
                targets = (sl * torques[0], sr * torques[1])
        if targets is not None:  # the bounded velocity servo (module docstring)
            torques[0], torques[1] = servo.torques(targets, v, w, torques[2])
            torques[0], torques[1] = sl * torques[0], sr * torques[1]
        fv = (sl * torques[0] + sr * torques[1]) / r
        fw = b * (sr * torques[1] - sl * torques[0]) / r
        u_p, u_t = torques[2], torques[3]
        for _ in range(substeps):
            # RK4 with the torques held (zero-order hold). Positions follow the velocities.
            gv1, gw1, gp1 = accelerations(v, w, fv, fw, u_p)
            v2, w2, p2 = v + half * gv1, w + half * gw1, dqp + half * gp1
            gv2, gw2, gp2 = accelerations(v2, w2, fv, fw, u_p)
            v3, w3, p3 = v + half * gv2, w + half * gw2, dqp + half * gp2
            gv3, gw3, gp3 = accelerations(v3, w3, fv, fw, u_p)
            v4, w4, p4 = v + h * gv3, w + h * gw3, dqp + h * gp3
            gv4, gw4, gp4 = accelerations(v4, w4, fv, fw, u_p)
            th2, th3 = th + half * w, th + half * w2
            th4 = th + h * w3
            x += sixth * (v * cos(th) + 2.0 * v2 * cos(th2) + 2.0 * v3 * cos(th3) + v4 * cos(th4))
            y += sixth * (v * sin(th) + 2.0 * v2 * sin(th2) + 2.0 * v3 * sin(th3) + v4 * sin(th4))
            dth = sixth * (w + 2.0 * w2 + 2.0 * w3 + w4)
            ds = sixth * (v + 2.0 * v2 + 2.0 * v3 + v4)
            th += dth
            phl += (ds - b * dth) / r
            phr += (ds + b * dth) / r
            qp += sixth * (dqp + 2.0 * p2 + 2.0 * p3 + p4)
            v += sixth * (gv1 + 2.0 * gv2 + 2.0 * gv3 + gv4)
            w += sixth * (gw1 + 2.0 * gw2 + 2.0 * gw3 + gw4)
            dqp += sixth * (gp1 + 2.0 * gp2 + 2.0 * gp3 + gp4)
            if it > 0.0:  # tilt: I_t q̈ = u (exact for a held torque)
                qt += h * dqt + 0.5 * h * h * u_t / it
                dqt += h * u_t / it
    out = np.zeros((len(rows), 9))
    out[:, :8] = rows
    return _trajectory(
        "noslip",
        profile,
        model,
        out,
        drive,
        scenario,
        {
            "model": model.as_dict(),
            "integrator": f"RK4, {h * 1e3:g} ms",
            "control": f"{1.0 / dt:g} Hz zero-order hold",
        },
    )


_WIRES = {"L": 0, "R": 1, "P": 2, "T": 3}


class _Servo:
    """The engines' bounded velocity servo on the two sides of a rigid no-slip vehicle: the forward
    side torques (τL, τR) that bring each side's roller speed ``(v ∓ b·w)/r`` to its target by the end
    of one control period ``dt`` (the explicit step of the equations of motion), each clipped to its
    bound (``servo_limit`` × the side's rollers); a box-constrained 2 × 2 problem solved exactly by
    projected Gauss–Seidel (what a velocity constraint with a force bound is in both engines)."""

    SWEEPS = 30

    def __init__(self, model: PlanarModel, dt: float) -> None:
        r, b = model.radius, model.half_axle
        inverse = np.array(_Plant(model).inverse)
        s = np.array([[1.0 / r, -b / r, 0.0], [1.0 / r, b / r, 0.0]])  # (v, w, q̇_pan) → side speeds
        self.sk = dt * s @ inverse  # side speed change per generalized force
        self.g = self.sk @ s.T  # per side torque (B = Sᵀ: τ_side/r along v, ∓b τ/r along w)
        self.mcx = model.mass * model.com[0]
        self.r, self.b = r, b
        self.caps = (model.servo_limit * model.servo_rollers[0], model.servo_limit * model.servo_rollers[1])

    def torques(self, targets: tuple[float, float], v: float, w: float, u_pan: float) -> tuple[float, float]:
        r, b, mcx = self.r, self.b, self.mcx
        drift = self.sk @ np.array([mcx * w * w, -mcx * v * w, u_pan])
        need = (targets[0] - (v - b * w) / r - drift[0], targets[1] - (v + b * w) / r - drift[1])
        g = self.g
        tau = [0.0, 0.0]
        for _ in range(self.SWEEPS):
            for i in (0, 1):
                j = 1 - i
                free = (need[i] - g[i, j] * tau[j]) / g[i, i]
                tau[i] = min(self.caps[i], max(-self.caps[i], free))
        return tau[0], tau[1]


def _wiring(controllers: list[Any], drive: Drive) -> list[list[str]]:
    """Per controller, per joint: which reference coordinate it reads (L/R wheel, P pan, T tilt)."""
    names = {drive.left: "L", drive.right: "R"}
    for side, key in ((drive.left, "L"), (drive.right, "R")):
        for roller in drive.rollers.get(side, ()):
            names[roller] = key
    if drive.pan:
        names[drive.pan] = "P"
    if drive.tilt:
        names[drive.tilt] = "T"
    return [[names[j] for j in c.joints] for c in controllers]


def scenario_samples(profile: Profile, scenario: Scenario) -> list[int]:
    """The physics steps at which a trajectory is sampled: t = i / sample_rate, i = 0 .. duration·rate."""
    n = round(profile.duration * scenario.sample_rate)
    return [round(i / scenario.sample_rate / scenario.dt) for i in range(n + 1)]


def _trajectory(
    source: str,
    profile: Profile,
    model: PlanarModel,
    out: Array,
    drive: Drive,
    scenario: Scenario,
    settings: dict[str, Any],
) -> Trajectory:
    t, x, y, th = out[:, 0], out[:, 1], out[:, 2], out[:, 3]
    ox, oy = model.root_offset
    rx = x + np.cos(th) * ox - np.sin(th) * oy - ox
    ry = y + np.sin(th) * ox + np.cos(th) * oy - oy
    sl, sr = drive.signs
    wheels = np.column_stack([sl * out[:, 4], sr * out[:, 5]])
    joints = {}
    if drive.pan:
        joints[drive.pan] = out[:, 6].copy()
    if drive.tilt:
        joints[drive.tilt] = out[:, 7].copy()
    return Trajectory(source, profile.name, "", t.copy(), rx, ry, th.copy(), wheels, joints, settings)


# ----------------------------------------------------------------------------------------------------
# the ideal unicycle and wheel odometry


def unicycle(model: PlanarModel, profile: Profile, scenario: Scenario, drive: Drive) -> Trajectory:
    """The ideal unicycle integrated exactly from the commanded (v, w), sampled like the engines."""
    every = scenario_samples(profile, scenario)
    times = [k * scenario.dt for k in every]
    breaks = [c.t for c in profile.commands if 0.0 < c.t < profile.duration]
    out = np.zeros((len(times), 9))
    x = y = th = 0.0
    t_now = 0.0
    events = sorted(set(breaks) | set(times))
    samples = {t: i for i, t in enumerate(times)}
    for t_next in events:
        command = profile.at(t_now + 1e-12)
        x, y, th = _arc(x, y, th, command, t_next - t_now)
        t_now = t_next
        if t_next in samples:
            i = samples[t_next]
            dist = _sides(profile, t_next, model.half_axle)
            out[i] = (t_next, x, y, th, dist[0] / model.radius, dist[1] / model.radius, 0.0, 0.0, 0.0)
    return _trajectory(
        "unicycle",
        profile,
        model,
        out,
        drive,
        scenario,
        {"integrator": "exact (piecewise constant commands)"},
    )


def _arc(x: float, y: float, th: float, c: Command, dt: float) -> tuple[float, float, float]:
    if dt <= 0.0:
        return x, y, th
    if abs(c.w) < 1e-12:
        return x + c.v * dt * math.cos(th), y + c.v * dt * math.sin(th), th
    th2 = th + c.w * dt
    return (
        x + c.v / c.w * (math.sin(th2) - math.sin(th)),
        y - c.v / c.w * (math.cos(th2) - math.cos(th)),
        th2,
    )


def _sides(profile: Profile, t: float, b: float) -> tuple[float, float]:
    """Each side's commanded rolling distance up to ``t`` ((v ∓ b w) integrated), for the wheel angles."""
    left = right = 0.0
    cmds = list(profile.commands)
    for i, c in enumerate(cmds):
        end = min(cmds[i + 1].t if i + 1 < len(cmds) else math.inf, t)
        if end > c.t:
            left += (c.v - b * c.w) * (end - c.t)
            right += (c.v + b * c.w) * (end - c.t)
    return left, right


def odometry(trajectory: Trajectory, model: PlanarModel, drive: Drive) -> Trajectory:
    """The pose an engine's own wheel angles imply (no slip, radius r, half axle b), root frame."""
    sl, sr = drive.signs
    phl = sl * trajectory.wheels[:, 0]
    phr = sr * trajectory.wheels[:, 1]
    r, b = model.radius, model.half_axle
    d_left = np.diff(phl) * r
    d_right = np.diff(phr) * r
    ds = 0.5 * (d_left + d_right)
    dth = (d_right - d_left) / (2.0 * b)
    th = np.concatenate([[0.0], np.cumsum(dth)])
    mid = th[:-1] + 0.5 * dth
    x = np.concatenate([[0.0], np.cumsum(ds * np.cos(mid))])
    y = np.concatenate([[0.0], np.cumsum(ds * np.sin(mid))])
    out = np.zeros((len(th), 9))
    out[:, 0], out[:, 1], out[:, 2], out[:, 3] = trajectory.t, x, y, th
    out[:, 4], out[:, 5] = phl, phr
    result = _trajectory(
        f"odometry:{trajectory.source}",
        _named(trajectory.profile),
        model,
        out,
        drive,
        Scenario(profiles=()),
        {"from": trajectory.source, "radius": r, "half_axle": b},
    )
    result.variant = trajectory.variant
    result.joints = {}
    return result


def _named(name: str) -> Profile:
    return Profile(name, 0.0, ())
