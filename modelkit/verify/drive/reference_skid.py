"""The skid-steer reference for tracked robots: what a rigid vehicle does on Coulomb friction when its
belts move at the commanded speeds (engine-independent; docs/verify.md, "Skid-steer reference").

A turning tracked vehicle must slide sideways, so no no-slip model describes it. This one is the
planar rigid-body dynamics of the whole robot (its mass, yaw inertia about its COM and COM, from the
model's own links at q = 0) on contact points spread over each track's ground patch, every point
carrying a static normal load and a regularised Coulomb friction force that opposes the slip of the
belt surface over the floor::

    s_i = v + ω ẑ × r_i − u_side(i) x̂            (body frame, r_i from the COM)
    F_i = −μ N_i s_i / sqrt(|s_i|² + ε²)
    M (v̇ + ω ẑ × v) = Σ F_i,     I ω̇ = Σ r_i × F_i

``u_side`` is the belt speed the seed's ``MobileRobotTrackController`` commands, ``v ∓ w·offset_y``,
imposed exactly (Choreonoid's AIST solver sets the contact point's target velocity to the belt
speed everywhere on the track surface; the engines hold the rollers at it with a stiff servo). The
normal loads are the elastic-floor statics: a pressure linear over the contact points whose sum and
first moments carry the weight at the COM (exact for 2 points per track line; load transfer from
acceleration ignored). ``ε`` = :data:`SLIP_REGULARISATION` m/s. Integrated with the linearly implicit
Euler method (the friction Jacobian taken implicitly, so ε can be small) at the control period.

Contact layouts (the pressure distribution under a track is what the path is most sensitive to):

* ``"rollers"`` — the converted model's own contacts: one line across the track's width (its two
  edges) under each roller's bottom, i.e. what MuJoCo's and PyBullet's cylinder–plane contacts give
  (for the tutorial's tracks, the ends of the flat bottom);
* ``"uniform"`` — the track's flat belt on a uniformly stiff floor: :data:`PATCH_POINTS` lines
  evenly over the segment between the first and last roller bottoms (the track's flat bottom).

:func:`skid_tolerance` turns the spread between the layouts and a μ range into the grading
tolerance (its docstring and docs/verify.md give the derivation).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any, Literal

import numpy as np

from modelkit.model import Robot
from modelkit.spatial import combine_mass_properties, rotate_inertia
from modelkit.verify.drive import Array, Command, Drive, Profile, Scenario, Trajectory, command_steps

Layout = Literal["rollers", "uniform"]

GRAVITY = 9.81
SLIP_REGULARISATION = 1e-3  # m/s: ε, 1–5 % of the slip speeds of a turning track
PATCH_POINTS = 11  # contact lines per track for the uniform layout
MU_RANGE = (0.5, 2.0)  # the friction coefficient's uncertainty, as factors on μ (tolerance)
FLOOR_POSITION = 0.015  # m: the smallest position tolerance (verification.md §6's no-slip one)
FLOOR_YAW = 0.015  # rad: likewise for yaw


@dataclass(frozen=True)
class SkidModel:
    """What the skid reference needs (root frame at q = 0, SI). ``points``: (n, 2) contact points in
    the root frame; ``side``: 0 left / 1 right per point; ``loads``: normal force per point (N)."""

    mass: float
    yaw_inertia: float  # about the vertical through the COM
    com: tuple[float, float]  # in the root frame
    points: Array
    side: Array
    loads: Array
    mu: float
    radius: float  # roller radius: belt speed → roller angle, for the trajectory's wheel columns
    layout: Layout = "rollers"
    regularisation: float = SLIP_REGULARISATION

    def as_dict(self) -> dict[str, Any]:
        return {
            "mass": self.mass, "yaw_inertia": self.yaw_inertia, "com": list(self.com),
            "points": self.points.tolist(), "side": self.side.astype(int).tolist(),
            "loads": self.loads.tolist(), "mu": self.mu, "radius": self.radius, "layout": self.layout,
            "regularisation": self.regularisation,
        }


@dataclass(frozen=True)
class TrackPatch:
    """One track's ground contact in the root frame: the segment [x0, x1] at lateral position y
    (the rollers' bottoms), its width and the roller x positions."""

    x0: float
    x1: float
    y: float
    width: float
    rollers: tuple[float, ...]


def track_patches(robot: Robot, drive: Drive) -> tuple[TrackPatch, TrackPatch]:
    """(left, right) patches from the rollers ``convert`` wrote (``robot`` has the approximation:
    ``vehicle.prepare_tracks``; ``drive.rollers`` names them)."""
    poses = robot.world_poses()
    inv = poses[str(robot.root)].inverse()
    joints = {j.name: j for j in robot.joints}
    record = robot.extras.get("tracks", {})
    out = []
    for side in (drive.left, drive.right):
        names = drive.rollers[side]
        centres = np.array([(inv @ poses[joints[n].child]).translation for n in names])
        width = float(record.get(side, {}).get("width", 0.0))
        xs = tuple(sorted(float(c[0]) for c in centres))
        out.append(TrackPatch(xs[0], xs[-1], float(np.mean(centres[:, 1])), width, xs))
    return out[0], out[1]


def _mass_properties(robot: Robot) -> tuple[float, np.ndarray, float]:
    poses = robot.world_poses()
    inv = poses[str(robot.root)].inverse()
    parts = []
    for link in robot.links:
        if link.inertial is None or link.inertial.mass <= 0.0 or link.name not in poses:
            continue
        frame = inv @ poses[link.name]
        parts.append((float(link.inertial.mass),
                      frame.rotation @ np.asarray(link.inertial.com, dtype=float) + frame.translation,
                      rotate_inertia(link.inertial.inertia, frame.rotation)))
    mass, com, inertia = combine_mass_properties(parts)
    return float(mass), np.asarray(com, dtype=float), float(np.asarray(inertia)[2, 2])


def static_loads(points: Array, mass: float, com: Array, gravity: float = GRAVITY) -> Array:
    """Normal loads linear over the points (an elastic floor) carrying ``mass`` at ``com``: the
    minimum-norm solution of ΣN = W, ΣN·x = W·cx, ΣN·y = W·cy."""
    a = np.vstack([np.ones(len(points)), points[:, 0], points[:, 1]])
    rhs = mass * gravity * np.array([1.0, com[0], com[1]])
    return np.asarray(a.T @ np.linalg.solve(a @ a.T, rhs), dtype=float)


def skid_model(robot: Robot, drive: Drive, friction: float | None = None,
               layout: Layout = "rollers") -> SkidModel:
    """The skid reference's parameters from ``robot`` (with its track approximation) and its drive.
    ``friction``: the belt–floor μ (None: the rollers' contact material against the floor)."""
    mass, com, inertia = _mass_properties(robot)
    patches = track_patches(robot, drive)
    if friction is None:
        friction = _roller_friction(robot, drive)
    points, side = [], []
    for k, patch in enumerate(patches):
        if layout == "rollers":
            xs = list(patch.rollers)
        else:
            xs = list(np.linspace(patch.x0, patch.x1, PATCH_POINTS))
        for x in xs:
            for dy in ((-0.5 * patch.width, 0.5 * patch.width) if patch.width > 0.0 else (0.0,)):
                points.append((x, patch.y + dy))
                side.append(k)
    pts = np.array(points, dtype=float)
    loads = static_loads(pts, mass, com[:2])
    inertia_com = inertia  # combine_mass_properties gives the inertia about the COM
    return SkidModel(mass, inertia_com, (float(com[0]), float(com[1])), pts, np.array(side), loads,
                     float(friction), drive.roller_radius or drive.radius, layout)


def _roller_friction(robot: Robot, drive: Drive) -> float:
    from modelkit.convert.friction import floor_friction

    table = floor_friction(robot)
    joints = {j.name: j for j in robot.joints}
    values = [table[joints[n].child].dynamic for side in (drive.left, drive.right)
              for n in drive.rollers.get(side, ()) if n in joints and joints[n].child in table]
    return max(values, default=1.0)


def skid_reference(model: SkidModel, profile: Profile, scenario: Scenario, drive: Drive) -> Trajectory:
    """The skid-steer path of ``profile`` under the track controller (``v ∓ w·offset_y`` belt speeds,
    zero-order hold at ``scenario.dt``), the root frame's planar pose sampled like the engines'."""
    dt = scenario.dt
    steps = round(profile.duration / dt)
    changes = command_steps(profile, dt, steps)
    every = max(1, round(1.0 / scenario.sample_rate / dt))
    r = model.points - np.asarray(model.com)  # from the COM
    rx, ry = r[:, 0], r[:, 1]
    mu_n = model.mu * model.loads
    eps2 = model.regularisation**2
    inv_mass = np.array([1.0 / model.mass, 1.0 / model.mass, 1.0 / model.yaw_inertia])
    left = model.side == 0
    offset = drive.track_offset_y
    vx = vy = om = 0.0
    x = y = th = 0.0
    ang = np.zeros(2)
    command = Command(0.0)
    belts = np.zeros(2)
    rows = []
    for k in range(steps + 1):
        if k % every == 0:
            ox, oy = -model.com[0], -model.com[1]  # the root origin from the COM (body frame)
            c, s = math.cos(th), math.sin(th)
            rows.append((k * dt, x + c * ox - s * oy - ox, y + s * ox + c * oy - oy, th, ang[0], ang[1]))
        if k == steps:
            break
        if k in changes:
            command = changes[k]
            belts = np.array([command.v - command.w * offset, command.v + command.w * offset])
        u = np.where(left, belts[0], belts[1])
        sx = vx - om * ry - u
        sy = vy + om * rx
        rho = np.sqrt(sx * sx + sy * sy + eps2)
        g = mu_n / rho
        fx, fy = -g * sx, -g * sy
        force = np.array([fx.sum(), fy.sum(), float(rx @ fy - ry @ fx)])
        # ∂F/∂s = −μN (I/ρ − s sᵀ/ρ³); ∂s/∂(vx, vy, ω) = [[1, 0, −ry], [0, 1, rx]]
        h3 = g / (rho * rho)
        kxx, kyy, kxy = -g + h3 * sx * sx, -g + h3 * sy * sy, h3 * sx * sy
        jac = np.empty((3, 3))
        jac[0, 0], jac[0, 1], jac[1, 1] = kxx.sum(), kxy.sum(), kyy.sum()
        jac[1, 0] = jac[0, 1]
        jac[0, 2] = float((-kxx * ry + kxy * rx).sum())
        jac[1, 2] = float((-kxy * ry + kyy * rx).sum())
        jac[2, 0] = float((-ry * kxx + rx * kxy).sum())
        jac[2, 1] = float((-ry * kxy + rx * kyy).sum())
        jac[2, 2] = float((ry * ry * kxx - 2.0 * rx * ry * kxy + rx * rx * kyy).sum())
        rate = inv_mass * force + np.array([om * vy, -om * vx, 0.0])
        system = np.eye(3) - dt * inv_mass[:, None] * jac
        dv = np.linalg.solve(system, dt * rate)
        vx, vy, om = vx + dv[0], vy + dv[1], om + dv[2]
        c, s = math.cos(th + 0.5 * dt * om), math.sin(th + 0.5 * dt * om)
        x += dt * (c * vx - s * vy)
        y += dt * (s * vx + c * vy)
        th += dt * om
        ang += dt * belts / model.radius
    out = np.array(rows)
    sl, sr = drive.signs
    wheels = np.column_stack([sl * out[:, 4], sr * out[:, 5]])
    settings = {"model": model.as_dict(), "integrator": f"linearly implicit Euler, {dt * 1e3:g} ms",
                "belts": "imposed exactly (Choreonoid's pseudo continuous track)"}
    return Trajectory(f"skid:{model.layout}", profile.name, "", out[:, 0].copy(), out[:, 1].copy(),
                      out[:, 2].copy(), out[:, 3].copy(), wheels, {}, settings)


# ---- the grading tolerance ----------------------------------------------------------------------


@dataclass(frozen=True)
class SkidTolerance:
    """Per profile: the position (m) and yaw (rad) within which an engine's path must follow the
    skid reference, and the spreads they were derived from (``parts``: variation → (m, rad))."""

    position: float
    yaw: float
    parts: dict[str, tuple[float, float]]

    def as_dict(self) -> dict[str, Any]:
        return {"position": self.position, "yaw": self.yaw,
                "parts": {k: list(v) for k, v in self.parts.items()}}


def path_difference(a: Trajectory, b: Trajectory) -> tuple[float, float]:
    """(max planar position distance, max |yaw difference|) over the common samples."""
    n = min(len(a.t), len(b.t))
    pos = np.hypot(a.x[:n] - b.x[:n], a.y[:n] - b.y[:n])
    yaw = np.abs(a.yaw[:n] - b.yaw[:n])
    return float(pos.max()), float(yaw.max())


def skid_tolerance(model: SkidModel, profile: Profile, scenario: Scenario, drive: Drive,
                   robot: Robot | None = None, nominal: Trajectory | None = None) -> SkidTolerance:
    """How far the skid path of ``profile`` moves within the uncertainty of what decides it:

    * the pressure distribution under the belt: the reference's layout against the other one
      (``rollers`` — the load at the ends of the flat bottom — and ``uniform``; Choreonoid's own
      contact points on a track mesh lie between), needs ``robot`` (else skipped);
    * the friction coefficient: μ × each factor of :data:`MU_RANGE`.

    The tolerance is the largest of these spreads (position and yaw separately), at least
    :data:`FLOOR_POSITION` / :data:`FLOOR_YAW` (what the engines reach on a no-slip path).
    ``nominal``: ``skid_reference(model, profile, ...)`` when already computed."""
    if nominal is None:
        nominal = skid_reference(model, profile, scenario, drive)
    parts: dict[str, tuple[float, float]] = {}
    if robot is not None:
        other: Layout = "uniform" if model.layout == "rollers" else "rollers"
        varied = skid_model(robot, drive, model.mu, other)
        parts[f"layout {other}"] = path_difference(nominal, skid_reference(varied, profile, scenario, drive))
    for factor in MU_RANGE:
        varied_mu = replace(model, mu=model.mu * factor)
        parts[f"mu x{factor:g}"] = path_difference(
            nominal, skid_reference(varied_mu, profile, scenario, drive))
    position = max([FLOOR_POSITION] + [p for p, _ in parts.values()])
    yaw = max([FLOOR_YAW] + [q for _, q in parts.values()])
    return SkidTolerance(position, yaw, parts)
