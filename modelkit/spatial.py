"""Rigid transforms, rotations and inertia arithmetic (SI units, radians, right-handed frames)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

Vec3 = NDArray[np.float64]
Mat3 = NDArray[np.float64]
Mat4 = NDArray[np.float64]


def _identity3() -> Mat3:
    return np.eye(3)


def _zero3() -> Vec3:
    return np.zeros(3)


@dataclass(eq=False)
class Pose:
    """A rigid transform: ``p_parent = rotation @ p_child + translation``."""

    rotation: Mat3 = field(default_factory=_identity3)
    translation: Vec3 = field(default_factory=_zero3)

    def __matmul__(self, other: Pose) -> Pose:
        return Pose(self.rotation @ other.rotation, self.rotation @ other.translation + self.translation)

    def __repr__(self) -> str:
        return f"Pose(xyz={self.translation.tolist()}, rpy={rpy_from_matrix(self.rotation).tolist()})"


def axis_angle(axis: Vec3 | list[float], angle: float, normalise: bool = True) -> Mat3:
    """Rodrigues' rotation matrix. With ``normalise=False`` the axis is used as given, as Eigen's
    ``AngleAxis::toRotationMatrix`` does (which Choreonoid's Extrusion relies on)."""
    a = np.asarray(axis, dtype=float)
    if normalise:
        n = float(np.linalg.norm(a))
        if n == 0.0:
            raise ValueError("rotation axis is the zero vector")
        a = a / n
    c, s = math.cos(angle), math.sin(angle)
    k = np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])
    return c * np.eye(3) + (1.0 - c) * np.outer(a, a) + s * k


def rot_x(angle: float) -> Mat3:
    return axis_angle([1.0, 0.0, 0.0], angle)


def rpy_from_matrix(r: Mat3) -> Vec3:
    """URDF/SDF fixed-axis roll-pitch-yaw of R = Rz(yaw)·Ry(pitch)·Rx(roll), pitch in [-π/2, π/2]."""
    sy = -float(r[2, 0])
    sy = max(-1.0, min(1.0, sy))
    pitch = math.asin(sy)
    if abs(sy) < 1.0 - 1e-12:
        roll = math.atan2(float(r[2, 1]), float(r[2, 2]))
        yaw = math.atan2(float(r[1, 0]), float(r[0, 0]))
    else:  # gimbal lock: put everything into yaw
        roll = 0.0
        yaw = math.atan2(-float(r[0, 1]), float(r[1, 1]))
    return np.array([roll, pitch, yaw])


def parallel_axis(mass: float, offset: Vec3) -> Mat3:
    """The term m(|d|²E − d dᵀ) that moves an inertia about the COM to a point offset by d."""
    d = np.asarray(offset, dtype=float)
    return mass * (float(d @ d) * np.eye(3) - np.outer(d, d))


def combine_mass_properties(parts: list[tuple[float, Vec3, Mat3]]) -> tuple[float, Vec3, Mat3]:
    """Combine (mass, COM, inertia about COM) triples expressed in one frame.

    Zero total mass gives (0, 0, 0), as Choreonoid does.
    """
    total = sum(m for m, _, _ in parts)
    if total <= 0.0:
        return 0.0, np.zeros(3), np.zeros((3, 3))
    com = sum((m * np.asarray(c, dtype=float) for m, c, _ in parts), np.zeros(3)) / total
    inertia = np.zeros((3, 3))
    for m, c, i in parts:
        inertia += np.asarray(i, dtype=float) + parallel_axis(m, com - np.asarray(c, dtype=float))
    return total, com, inertia


# Tolerance of libsdformat / gz-math MassMatrix3::IsValid: eigenvalues and the triangle inequality
# are checked with ε = 10 · machine-epsilon · (largest principal moment).
def inertia_tolerance(principal: NDArray[np.float64]) -> float:
    return 10.0 * float(np.finfo(float).eps) * float(np.max(np.abs(principal)) if principal.size else 0.0)


def principal_moments(inertia: Mat3) -> NDArray[np.float64]:
    sym = 0.5 * (np.asarray(inertia, dtype=float) + np.asarray(inertia, dtype=float).T)
    return np.sort(np.linalg.eigvalsh(sym))
