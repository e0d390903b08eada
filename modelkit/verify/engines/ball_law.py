"""The replay's PD law on a ball joint, in the two coordinates the engines integrate a ball in.

MuJoCo holds a ball joint as a quaternion and an angular velocity in the child's frame; the URDF
PyBullet reads holds it as the writer's chain of three continuous joints about X, Y and Z (MK813:
R = Rx(a)·Ry(b)·Rz(c)). The law is one physical torque in the child's frame,

    τ = kp ⊙ log(Rᵀ·exp(q*(t))) − kd ⊙ ω,   q*_i(t) = amp_i·sin(2π·f_i·t + φ_i),

with ``log``/``exp`` the rotation vector ↔ matrix maps (the target a rotation vector in the ball's
rest frame) and ω the child's angular velocity relative to the parent, in the child's frame. MuJoCo
takes τ as the ball's generalised force; the chain takes Jᵀ·τ, J the map from its three angle rates to
ω. A ball's recorded position is the rotation vector of R in both engines.

Standard library only: PyBullet's child process (``pybullet_worker``) imports it.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

Vec3 = tuple[float, float, float]
Mat3 = tuple[float, float, float, float, float, float, float, float, float]  # row-major

SMALL_ANGLE = 1e-6  # rad: below it the series of sin θ / θ is used (exact to round-off there)


def rotation_exp(v: Sequence[float]) -> Mat3:
    """The rotation matrix of the rotation vector ``v`` (Rodrigues)."""
    x, y, z = float(v[0]), float(v[1]), float(v[2])
    theta2 = x * x + y * y + z * z
    theta = math.sqrt(theta2)
    if theta < SMALL_ANGLE:
        a, b = 1.0 - theta2 / 6.0, 0.5 - theta2 / 24.0
    else:
        a, b = math.sin(theta) / theta, (1.0 - math.cos(theta)) / theta2
    return (1.0 - b * (y * y + z * z), b * x * y - a * z, b * x * z + a * y,
            b * x * y + a * z, 1.0 - b * (x * x + z * z), b * y * z - a * x,
            b * x * z - a * y, b * y * z + a * x, 1.0 - b * (x * x + y * y))


def rotation_log(r: Sequence[float]) -> Vec3:
    """The rotation vector of the rotation matrix ``r`` (row-major), angle in [0, π]."""
    cosine = max(-1.0, min(1.0, 0.5 * (r[0] + r[4] + r[8] - 1.0)))
    wx, wy, wz = r[7] - r[5], r[2] - r[6], r[3] - r[1]
    theta = math.acos(cosine)
    if theta < SMALL_ANGLE:
        k = 0.5 * (1.0 + theta * theta / 6.0)
        return (k * wx, k * wy, k * wz)
    if math.pi - theta > 1e-4:
        k = 0.5 * theta / math.sin(theta)
        return (k * wx, k * wy, k * wz)
    # Near π the antisymmetric part vanishes: the axis from the symmetric part's largest diagonal.
    diagonal = [(r[4 * n] - cosine) / (1.0 - cosine) for n in range(3)]
    i = max(range(3), key=lambda n: diagonal[n])
    axis = [0.0, 0.0, 0.0]
    axis[i] = math.sqrt(max(diagonal[i], 0.0))
    for j in range(3):
        if j != i:
            axis[j] = 0.5 * (r[3 * i + j] + r[3 * j + i]) / ((1.0 - cosine) * axis[i])
    sign = 1.0 if axis[0] * wx + axis[1] * wy + axis[2] * wz >= 0.0 else -1.0
    norm = math.sqrt(sum(a * a for a in axis))
    return (sign * theta * axis[0] / norm, sign * theta * axis[1] / norm, sign * theta * axis[2] / norm)


def quaternion_matrix(w: float, x: float, y: float, z: float) -> Mat3:
    """The rotation matrix of the unit quaternion (w, x, y, z) (MuJoCo's order)."""
    return (1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y - w * z), 2.0 * (x * z + w * y),
            2.0 * (x * y + w * z), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z - w * x),
            2.0 * (x * z - w * y), 2.0 * (y * z + w * x), 1.0 - 2.0 * (x * x + y * y))


def chain_matrix(a: float, b: float, c: float) -> Mat3:
    """R = Rx(a)·Ry(b)·Rz(c): the URDF writer's chain of three continuous joints (MK813)."""
    ca, sa, cb, sb, cc, sc = math.cos(a), math.sin(a), math.cos(b), math.sin(b), math.cos(c), math.sin(c)
    return (cb * cc, -cb * sc, sb,
            sa * sb * cc + ca * sc, -sa * sb * sc + ca * cc, -sa * cb,
            -ca * sb * cc + sa * sc, ca * sb * sc + sa * cc, ca * cb)


def chain_jacobian(b: float, c: float) -> Mat3:
    """J (row-major) with ω = J·(ȧ, ḃ, ċ), ω in the child's frame: its columns are the chain's three
    axes seen from the child, Rz(c)ᵀ·Ry(b)ᵀ·X, Rz(c)ᵀ·Y and Z."""
    cb, sb, cc, sc = math.cos(b), math.sin(b), math.cos(c), math.sin(c)
    return (cb * cc, sc, 0.0,
            -cb * sc, cc, 0.0,
            sb, 0.0, 1.0)


def _transpose_times(r: Mat3, s: Mat3) -> Mat3:
    """rᵀ·s."""
    return tuple(sum(r[3 * k + i] * s[3 * k + j] for k in range(3)) for i in range(3) for j in range(3))  # type: ignore[return-value]


def ball_torque(r: Mat3, omega: Sequence[float], t: float, kp: Sequence[float], kd: Sequence[float],
                amplitude: Sequence[float], frequency: Sequence[float], phase: Sequence[float]) -> Vec3:
    """τ (child frame) of the module's law at time ``t``, orientation ``r`` and angular velocity
    ``omega`` (child frame)."""
    target = [amplitude[i] * math.sin(2.0 * math.pi * frequency[i] * t + phase[i]) for i in range(3)]
    error = rotation_log(_transpose_times(r, rotation_exp(target)))
    return (kp[0] * error[0] - kd[0] * omega[0], kp[1] * error[1] - kd[1] * omega[1],
            kp[2] * error[2] - kd[2] * omega[2])


def chain_torques(angles: Sequence[float], rates: Sequence[float], t: float, kp: Sequence[float],
                  kd: Sequence[float], amplitude: Sequence[float], frequency: Sequence[float],
                  phase: Sequence[float]) -> Vec3:
    """The generalised forces Jᵀ·τ of the law on the chain's three joints at ``angles``/``rates``."""
    a, b, c = angles
    j = chain_jacobian(b, c)
    omega = [j[3 * i] * rates[0] + j[3 * i + 1] * rates[1] + j[3 * i + 2] * rates[2] for i in range(3)]
    tau = ball_torque(chain_matrix(a, b, c), omega, t, kp, kd, amplitude, frequency, phase)
    return (j[0] * tau[0] + j[3] * tau[1] + j[6] * tau[2], j[1] * tau[0] + j[4] * tau[1] + j[7] * tau[2],
            j[2] * tau[0] + j[5] * tau[1] + j[8] * tau[2])
