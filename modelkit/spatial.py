"""Rigid transforms, rotations and inertia arithmetic (SI units, radians, right-handed frames).

numpy is imported by the functions that use it, not by this module: :class:`Pose` keeps plain tuples when
a numpy-free reader builds it (see :mod:`modelkit.rot3`) and hands numpy arrays to whoever reads
``.rotation`` / ``.translation``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from modelkit import rot3
from modelkit.rot3 import ArrayField, peek

if TYPE_CHECKING:
    import numpy as np
    from numpy.typing import NDArray

    Vec3 = NDArray[np.float64]
    Mat3 = NDArray[np.float64]
    Mat4 = NDArray[np.float64]
else:  # annotations only: the names exist so that modules can import them without numpy
    Vec3 = Mat3 = Mat4 = Any


@dataclass(eq=False)
class Pose:
    """A rigid transform: ``p_parent = rotation @ p_child + translation``.

    ``rotation`` and ``translation`` read as numpy arrays; ``rotation_tuple`` / ``translation_tuple`` read
    the same values as tuples without importing numpy (the readers and the rules use those).
    """

    rotation: ArrayField[Mat3] = ArrayField(rot3.IDENTITY)  # noqa: RUF009
    translation: ArrayField[Vec3] = ArrayField(rot3.ZERO3)  # noqa: RUF009

    @property
    def rotation_tuple(self) -> rot3.M3:
        value = peek(self, "rotation")
        return value if type(value) is tuple else rot3.mat3(value)

    @property
    def translation_tuple(self) -> rot3.V3:
        value = peek(self, "translation")
        return value if type(value) is tuple else rot3.vec3(value)

    def _plain(self) -> bool:
        return rot3.is_plain(peek(self, "rotation")) and rot3.is_plain(peek(self, "translation"))

    def __matmul__(self, other: Pose) -> Pose:
        if self._plain() and other._plain():
            r = self.rotation_tuple
            return Pose(rot3.matmul(r, other.rotation_tuple),
                        rot3.add(rot3.matvec(r, other.translation_tuple), self.translation_tuple))
        return Pose(self.rotation @ other.rotation, self.rotation @ other.translation + self.translation)

    def inverse(self) -> Pose:
        """The inverse transform: ``p_child = rotationᵀ @ (p_parent - translation)``."""
        if self._plain():
            rt = rot3.transpose(self.rotation_tuple)
            return Pose(rt, rot3.scale(-1.0, rot3.matvec(rt, self.translation_tuple)))
        rt_array = self.rotation.T
        return Pose(rt_array, -(rt_array @ self.translation))

    def is_identity(self, tol: float = 1e-12) -> bool:
        """Every entry within ``tol`` (absolute; no relative tolerance) of the identity transform's."""
        r, t = self.rotation_tuple, self.translation_tuple
        rotation_ok = all(abs(r[i][j] - (1.0 if i == j else 0.0)) <= tol for i in range(3) for j in range(3))
        return rotation_ok and all(abs(x) <= tol for x in t)

    def __repr__(self) -> str:
        return f"Pose(xyz={list(self.translation_tuple)}, rpy={list(rot3.rpy_from(self.rotation_tuple))})"


def axis_angle(axis: Vec3 | list[float], angle: float, normalise: bool = True) -> Mat3:
    """Rodrigues' rotation matrix. With ``normalise=False`` the axis is used as given, as Eigen's
    ``AngleAxis::toRotationMatrix`` does (which Choreonoid's Extrusion relies on)."""
    import numpy as np

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


def matrix_from_rpy(roll: float, pitch: float, yaw: float) -> Mat3:
    """URDF/SDF fixed-axis roll-pitch-yaw: R = Rz(yaw)·Ry(pitch)·Rx(roll)."""
    import numpy as np

    cr, sr = math.cos(roll), math.sin(roll)
    cp, sp = math.cos(pitch), math.sin(pitch)
    cy, sy = math.cos(yaw), math.sin(yaw)
    return np.array(
        [
            [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
            [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
            [-sp, cp * sr, cp * cr],
        ]
    )


def matrix_from_quat_wxyz(quat: Sequence[float] | NDArray[np.float64]) -> Mat3:
    """The rotation of the quaternion (w, x, y, z), normalised first.

    A zero or non-finite quaternion gives the identity, as MuJoCo does; readers of formats where
    that is an error report it before calling. URDF/SDF write x, y, z, w: pass ``(w, x, y, z)``.
    """
    import numpy as np

    q = np.asarray(quat, dtype=float)
    n = float(np.linalg.norm(q))
    if n == 0.0 or not math.isfinite(n):
        return np.eye(3)
    w, x, y, z = q / n
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


# cos(pitch) below which roll and yaw may need to be found together (:func:`rpy_from_matrix`): above it
# each atan2 is exact to 1e-13 rad. Below it they are, when their triple does not give the matrix back to
# NEAR_LOCK_EXACT (the 1e-12 writers promise); a triple that does is kept as it is, so a source's own
# ``rpy="0 -1.57079632679 -1.57079632679"`` (TIAGo's arm) is still written as it was given.
NEAR_GIMBAL_LOCK = 1e-3
NEAR_LOCK_EXACT = 1e-12


def rpy_from_matrix(r: Mat3) -> Vec3:
    """URDF/SDF fixed-axis roll-pitch-yaw of R = Rz(yaw)·Ry(pitch)·Rx(roll), pitch in [-π/2, π/2].

    The pitch is an atan2, not an asin: exact to the last digits near ±π/2 too (asin(1 - 1e-23)
    is π/2, and a source's ``1.57079632679`` would come back 4.9e-12 away)."""
    import numpy as np

    cos_pitch = math.hypot(float(r[0, 0]), float(r[1, 0]))
    pitch = math.atan2(-float(r[2, 0]), cos_pitch)
    if cos_pitch > 1e-12:
        roll = math.atan2(float(r[2, 1]), float(r[2, 2]))
        yaw = math.atan2(float(r[1, 0]), float(r[0, 0]))
        if (cos_pitch <= NEAR_GIMBAL_LOCK
                and float(np.max(np.abs(matrix_from_rpy(roll, pitch, yaw) - r))) > NEAR_LOCK_EXACT):
            roll, yaw = _near_lock(r, pitch, cos_pitch)
    else:  # gimbal lock: put everything into yaw
        roll = 0.0
        yaw = math.atan2(-float(r[0, 1]), float(r[1, 1]))
    return np.array([roll, pitch, yaw])


def _near_lock(r: Mat3, pitch: float, cos_pitch: float) -> tuple[float, float]:
    """Roll and yaw of ``r`` near the gimbal lock, together. There each is an atan2 of entries of size
    cos(pitch), off by up to 1e-16/cos(pitch) (1.2e-9 rad for Menagerie-style B2 feet 7.3e-8 from the
    lock, which then came back 4e-10 off), and only their difference is well determined. The yaw is
    kept, or a multiple of π/4 when moving it there changes ``r`` below rounding (the B2 feet: 7.6e-10
    from 0, which moves it by 5e-17), and the roll is what yaw and pitch leave:
    Rx(roll) = (Rz(yaw)·Ry(pitch))ᵀ·R, so the triple gives ``r`` back to rounding."""
    import numpy as np

    yaw = math.atan2(float(r[1, 0]), float(r[0, 0]))
    plain = round(yaw / (math.pi / 4)) * (math.pi / 4)
    if abs(yaw - plain) * cos_pitch <= 1e-16:
        yaw = plain
    rest = matrix_from_rpy(0.0, pitch, yaw).T @ np.asarray(r, dtype=float)
    return math.atan2(float(rest[2, 1]), float(rest[1, 1])), yaw


def inertia_from_moments(ixx: float, ixy: float, ixz: float, iyy: float, iyz: float, izz: float) -> Mat3:
    """The symmetric inertia tensor of its six moments (URDF/SDF order: ixx ixy ixz iyy iyz izz)."""
    import numpy as np

    return np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]], dtype=float)


def rotate_inertia(inertia: Mat3, rotation: Mat3) -> Mat3:
    """R·I·Rᵀ: an inertia tensor given in rotated axes, re-expressed in the outer axes."""
    import numpy as np

    r = np.asarray(rotation, dtype=float)
    return r @ np.asarray(inertia, dtype=float) @ r.T


def parallel_axis(mass: float, offset: Vec3) -> Mat3:
    """The term m(|d|²E − d dᵀ) that moves an inertia about the COM to a point offset by d."""
    import numpy as np

    d = np.asarray(offset, dtype=float)
    return mass * (float(d @ d) * np.eye(3) - np.outer(d, d))


def combine_mass_properties(parts: list[tuple[float, Vec3, Mat3]]) -> tuple[float, Vec3, Mat3]:
    """Combine (mass, COM, inertia about COM) triples expressed in one frame.

    Zero total mass gives (0, 0, 0), as Choreonoid does.
    """
    import numpy as np

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
    import numpy as np

    return 10.0 * float(np.finfo(float).eps) * float(np.max(np.abs(principal)) if principal.size else 0.0)


def principal_moments(inertia: Mat3) -> NDArray[np.float64]:
    import numpy as np

    sym = 0.5 * (np.asarray(inertia, dtype=float) + np.asarray(inertia, dtype=float).T)
    return np.sort(np.linalg.eigvalsh(sym))
