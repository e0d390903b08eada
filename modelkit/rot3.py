"""Pure-Python 3-vectors, 3×3 matrices and inertia arithmetic: the numpy-free core of the readers and checks.

``validate`` and ``tree`` on a small file must start fast, and importing numpy alone costs about three
times the bare interpreter's start-up. So the readers and the rules build and judge the model with plain
tuples (a vector is ``(x, y, z)``, a matrix a tuple of three rows), and the model's array fields
(:class:`ArrayField`) hand a numpy array to whoever reads them through the attribute: writers, meshes,
``verify`` and ``compare`` see numpy arrays as before, and only they import numpy.

The formulas repeat those of :mod:`modelkit.spatial` operation for operation (same order of operations), so
a value computed here equals the numpy one up to the summation order of a matrix product (a few ulps).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from typing import TYPE_CHECKING, Any, Generic, TypeVar, overload

if TYPE_CHECKING:
    import numpy as np
    from numpy.typing import NDArray

V3 = tuple[float, float, float]
M3 = tuple[V3, V3, V3]

ZERO3: V3 = (0.0, 0.0, 0.0)
IDENTITY: M3 = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
ZERO33: M3 = (ZERO3, ZERO3, ZERO3)


def vec3(values: Iterable[Any]) -> V3:
    """Three floats from any sequence of three numbers (a tuple, a list, a numpy array)."""
    x, y, z = values
    return (float(x), float(y), float(z))


def mat3(rows: Iterable[Iterable[Any]]) -> M3:
    """A 3×3 matrix of floats from any 3×3 nesting (tuples, lists, a numpy array)."""
    a, b, c = rows
    return (vec3(a), vec3(b), vec3(c))


def is_plain(value: object) -> bool:
    """Whether a stored array value is still in plain (tuple or list) form."""
    return isinstance(value, (tuple, list))


def add(a: V3, b: V3) -> V3:
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def sub(a: V3, b: V3) -> V3:
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def scale(k: float, a: V3) -> V3:
    return (k * a[0], k * a[1], k * a[2])


def dot(a: Sequence[float], b: Sequence[float]) -> float:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def norm(a: Sequence[float]) -> float:
    return math.sqrt(sum(float(x) * float(x) for x in a))


def transpose(m: M3) -> M3:
    return ((m[0][0], m[1][0], m[2][0]), (m[0][1], m[1][1], m[2][1]), (m[0][2], m[1][2], m[2][2]))


def matvec(m: M3, v: V3) -> V3:
    return (dot(m[0], v), dot(m[1], v), dot(m[2], v))


def matmul(a: M3, b: M3) -> M3:
    bt = transpose(b)
    return (
        (dot(a[0], bt[0]), dot(a[0], bt[1]), dot(a[0], bt[2])),
        (dot(a[1], bt[0]), dot(a[1], bt[1]), dot(a[1], bt[2])),
        (dot(a[2], bt[0]), dot(a[2], bt[1]), dot(a[2], bt[2])),
    )


def mat_add(a: M3, b: M3) -> M3:
    return (add(a[0], b[0]), add(a[1], b[1]), add(a[2], b[2]))


def mat_scale(k: float, m: M3) -> M3:
    return (scale(k, m[0]), scale(k, m[1]), scale(k, m[2]))


def outer(a: V3, b: V3) -> M3:
    return (scale(a[0], b), scale(a[1], b), scale(a[2], b))


# ---- rotations --------------------------------------------------------------------------------------------


def from_rpy(roll: float, pitch: float, yaw: float) -> M3:
    """URDF/SDF fixed-axis roll-pitch-yaw: R = Rz(yaw)·Ry(pitch)·Rx(roll)."""
    cr, sr = math.cos(roll), math.sin(roll)
    cp, sp = math.cos(pitch), math.sin(pitch)
    cy, sy = math.cos(yaw), math.sin(yaw)
    return (
        (cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr),
        (sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr),
        (-sp, cp * sr, cp * cr),
    )


def from_quat_wxyz(quat: Sequence[float]) -> M3:
    """The rotation of the quaternion (w, x, y, z), normalised first; zero or non-finite: the identity."""
    q = [float(v) for v in quat]
    n = math.sqrt(sum(v * v for v in q))
    if n == 0.0 or not math.isfinite(n):
        return IDENTITY
    w, x, y, z = (v / n for v in q)
    return (
        (1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)),
        (2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)),
        (2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)),
    )


def axis_angle(axis: Sequence[float], angle: float, normalise: bool = True) -> M3:
    """Rodrigues' rotation matrix (see :func:`modelkit.spatial.axis_angle`)."""
    a = vec3(axis)
    if normalise:
        n = norm(a)
        if n == 0.0:
            raise ValueError("rotation axis is the zero vector")
        a = (a[0] / n, a[1] / n, a[2] / n)
    c, s = math.cos(angle), math.sin(angle)
    k = ((0.0, -a[2], a[1]), (a[2], 0.0, -a[0]), (-a[1], a[0], 0.0))
    aa = outer(a, a)
    return mat_add(mat_add(mat_scale(c, IDENTITY), mat_scale(1.0 - c, aa)), mat_scale(s, k))


def rpy_from(r: Sequence[Sequence[float]]) -> V3:
    """Roll, pitch, yaw of R = Rz(yaw)·Ry(pitch)·Rx(roll), pitch in [-π/2, π/2] (spatial.rpy_from_matrix)."""
    sy = -float(r[2][0])
    sy = max(-1.0, min(1.0, sy))
    pitch = math.asin(sy)
    if abs(sy) < 1.0 - 1e-12:
        roll = math.atan2(float(r[2][1]), float(r[2][2]))
        yaw = math.atan2(float(r[1][0]), float(r[0][0]))
    else:
        roll = 0.0
        yaw = math.atan2(-float(r[0][1]), float(r[1][1]))
    return (roll, pitch, yaw)


# ---- inertia ----------------------------------------------------------------------------------------------


def inertia_from_moments(ixx: float, ixy: float, ixz: float, iyy: float, iyz: float, izz: float) -> M3:
    return ((float(ixx), float(ixy), float(ixz)), (float(ixy), float(iyy), float(iyz)),
            (float(ixz), float(iyz), float(izz)))


# An inertia matrix is asymmetric (validate's MK301) when an off-diagonal pair differs by more than this
# fraction of its largest diagonal moment; smaller differences are the source's rounding.
ASYMMETRY_TOLERANCE = 1e-4


def inertia_skew(m: M3) -> float:
    """The largest difference of an off-diagonal pair."""
    return max(abs(m[i][j] - m[j][i]) for i in range(3) for j in range(3))


def is_asymmetric(m: M3) -> bool:
    """Whether ``m`` is an asymmetric inertia matrix (:data:`ASYMMETRY_TOLERANCE`), not rounding."""
    return inertia_skew(m) > ASYMMETRY_TOLERANCE * max(abs(m[i][i]) for i in range(3))


def upper_symmetric(m: M3) -> M3:
    """The symmetric matrix of ``m``'s upper triangle (row-major xy, xz, yz): what every six-number format
    gets of a ``.body`` file's asymmetric nine-number inertia (MK301)."""
    return inertia_from_moments(m[0][0], m[0][1], m[0][2], m[1][1], m[1][2], m[2][2])


def rotate_inertia(inertia: M3, rotation: M3) -> M3:
    """R·I·Rᵀ."""
    return matmul(matmul(rotation, inertia), transpose(rotation))


def parallel_axis(mass: float, offset: V3) -> M3:
    """m(|d|²E − d dᵀ)."""
    d2 = dot(offset, offset)
    return mat_scale(mass, mat_add(mat_scale(d2, IDENTITY), mat_scale(-1.0, outer(offset, offset))))


def combine_mass_properties(parts: Sequence[tuple[float, V3, M3]]) -> tuple[float, V3, M3]:
    """Combine (mass, COM, inertia about the COM) triples given in one frame; zero total gives zeros."""
    total = sum(m for m, _, _ in parts)
    if total <= 0.0:
        return 0.0, ZERO3, ZERO33
    acc = ZERO3
    for m, c, _ in parts:
        acc = add(acc, scale(m, vec3(c)))
    com = (acc[0] / total, acc[1] / total, acc[2] / total)
    inertia = ZERO33
    for m, c, i in parts:
        inertia = mat_add(inertia, mat_add(mat3(i), parallel_axis(m, sub(com, vec3(c)))))
    return total, com, inertia


def symmetric_eigenvalues(m: Sequence[Sequence[float]]) -> V3:
    """The eigenvalues of the symmetric part of a 3×3 matrix, ascending (cyclic Jacobi rotations).

    Jacobi's method is accurate to a few ulps of the largest eigenvalue, also for repeated and zero
    eigenvalues, where the closed form (trigonometric) loses digits.
    """
    a = [[0.5 * (float(m[i][j]) + float(m[j][i])) for j in range(3)] for i in range(3)]
    for _ in range(50):
        off = a[0][1] ** 2 + a[0][2] ** 2 + a[1][2] ** 2
        if off == 0.0 or not math.isfinite(off):
            break
        for p, q in ((0, 1), (0, 2), (1, 2)):
            apq = a[p][q]
            if apq == 0.0:
                continue
            theta = (a[q][q] - a[p][p]) / (2.0 * apq)
            t = math.copysign(1.0, theta) / (abs(theta) + math.sqrt(theta * theta + 1.0))
            if not math.isfinite(t):  # theta overflowed: the rotation is negligible
                t = 1.0 / (2.0 * theta)
            c = 1.0 / math.sqrt(t * t + 1.0)
            s = t * c
            for k in range(3):  # A ← A·J
                akp, akq = a[k][p], a[k][q]
                a[k][p] = c * akp - s * akq
                a[k][q] = s * akp + c * akq
            for k in range(3):  # A ← Jᵀ·A
                apk, aqk = a[p][k], a[q][k]
                a[p][k] = c * apk - s * aqk
                a[q][k] = s * apk + c * aqk
            a[p][q] = a[q][p] = 0.0
    low, mid, high = sorted((a[0][0], a[1][1], a[2][2]))
    return (low, mid, high)


def inertia_tolerance(principal: Sequence[float]) -> float:
    """libsdformat's ε: 10 · machine epsilon · the largest principal moment (spatial.inertia_tolerance)."""
    return 10.0 * 2.220446049250313e-16 * (max(abs(float(v)) for v in principal) if len(principal) else 0.0)


def all_finite(values: Iterable[Any]) -> bool:
    """Every number finite, for a vector or a matrix (nested one level)."""
    for value in values:
        if isinstance(value, (int, float)):
            if not math.isfinite(value):
                return False
        elif not all(math.isfinite(float(x)) for x in value):
            return False
    return True


# ---- array fields of the model ----------------------------------------------------------------------------

T = TypeVar("T")
_NO_DEFAULT: Any = object()


class ArrayField(Generic[T]):
    """A dataclass field holding a float vector or matrix, stored as given and read as a numpy array.

    Readers store plain tuples (numpy-free); reading the attribute converts the stored value to a numpy
    float array once and keeps that array on the instance (so in-place changes stick, as with a plain
    numpy field). :func:`peek` reads the stored value without converting it: the numpy-free path.
    ``None`` is stored and returned as is (optional fields). The default, when given, is a tuple shared
    by the class (immutable), turned into a fresh array per instance on first read.
    """

    def __init__(self, default: Any = _NO_DEFAULT) -> None:
        self.default = default
        self.slot = ""

    def __set_name__(self, owner: type, name: str) -> None:
        self.slot = "_" + name

    @overload
    def __get__(self, obj: None, owner: type | None = None) -> ArrayField[T]: ...
    @overload
    def __get__(self, obj: object, owner: type | None = None) -> T: ...

    def __get__(self, obj: object | None, owner: type | None = None) -> Any:
        if obj is None:
            if self.default is _NO_DEFAULT:
                raise AttributeError(self.slot[1:])  # dataclasses: the field has no default
            return self.default
        value = obj.__dict__[self.slot]
        if isinstance(value, (tuple, list)):
            import numpy as np  # only here: the reason this module exists

            value = np.array(value, dtype=float)
            obj.__dict__[self.slot] = value
        return value

    def __set__(self, obj: object, value: Any) -> None:
        obj.__dict__[self.slot] = value


def peek(obj: object, name: str) -> Any:
    """The stored value of the array field ``name`` of ``obj`` (a tuple or a numpy array, or None),
    without converting it to numpy."""
    return obj.__dict__["_" + name]


if TYPE_CHECKING:
    FloatArray = NDArray[np.float64]
    OptionalFloatArray = NDArray[np.float64] | None
