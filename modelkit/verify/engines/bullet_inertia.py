"""What PyBullet's URDF importer does to an inertia tensor with products of inertia.

The importer keeps a link's inertia as principal moments and a rotation of the inertial frame, found
by Bullet's ``btMatrix3x3::diagonalize``: cyclic Jacobi rotations, each zeroing the largest
off-diagonal element, stopping when that element is at most ``threshold`` times the sum of the
diagonal's magnitudes (one more rotation is made then), after at most ``max_steps`` rotations. The
off-diagonal terms left at that point are dropped, so the tensor PyBullet holds differs from the
file's by up to about ``threshold`` × trace: measured on example-robot-data's TIAGo wheel, 1.21e-6
of its largest element, which :func:`diagonalised` reproduces to the last digit."""

from __future__ import annotations

import math

import numpy as np

from modelkit.verify.engines.protocol import Array

IMPORTER_THRESHOLD = 1.0e-6  # BulletURDFImporter's diagonalize call
IMPORTER_STEPS = 30
EPSILON = 2.220446049250313e-16  # SIMD_EPSILON in a double-precision build


def diagonalised(tensor: Array, threshold: float = IMPORTER_THRESHOLD,
                 max_steps: int = IMPORTER_STEPS) -> Array:
    """The 3×3 tensor as Bullet holds it after diagonalising: R·diag·Rᵀ."""
    rot, moments = _jacobi(tensor, threshold, max_steps)
    out: Array = rot @ np.diag(moments) @ rot.T
    return out


def refuses(tensor: Array) -> bool:
    """Whether PyBullet's URDF importer replaces ``tensor`` by zero ("Bad inertia tensor properties"):
    its principal moments as the importer finds them (the diagonal itself when there are no products
    of inertia, else :func:`diagonalised`'s) fail x ≥ 0 and x ≤ y + z for some axis, compared exactly.
    A tensor on the triangle bound (Robotiq 2F-85's knuckle: moments 8.77e-7 + 9.123e-6 = 1e-5) can
    fail by the rounding of the diagonalisation, where validate's test (MK303) finds nothing."""
    t = np.array(tensor, dtype=float).reshape(3, 3)
    if t[0, 1] == 0.0 and t[0, 2] == 0.0 and t[1, 2] == 0.0:
        x, y, z = (float(v) for v in np.diag(t))
    else:
        x, y, z = (float(v) for v in _jacobi(t, IMPORTER_THRESHOLD, IMPORTER_STEPS)[1])
    return x < 0 or x > y + z or y < 0 or y > x + z or z < 0 or z > x + y


def _jacobi(tensor: Array, threshold: float, max_steps: int) -> tuple[Array, Array]:
    """``btMatrix3x3::diagonalize``: the rotation and the diagonal it leaves."""
    a = np.array(tensor, dtype=float).reshape(3, 3)
    rot = np.eye(3)
    step = max_steps
    while step > 0:
        p, q, r = 0, 1, 2
        largest = abs(a[0, 1])
        if abs(a[0, 2]) > largest:
            q, r, largest = 2, 1, abs(a[0, 2])
        if abs(a[1, 2]) > largest:
            p, q, r, largest = 1, 2, 0, abs(a[1, 2])
        bound = threshold * (abs(a[0, 0]) + abs(a[1, 1]) + abs(a[2, 2]))
        if largest <= bound:
            if largest <= EPSILON * bound:
                break
            step = 1  # one last rotation
        apq = a[p, q]
        theta = (a[q, q] - a[p, p]) / (2.0 * apq)
        theta2 = theta * theta
        if theta2 * theta2 < 10.0 / EPSILON:
            root = math.sqrt(1.0 + theta2)
            t = 1.0 / (theta + root) if theta >= 0 else 1.0 / (theta - root)
            cos = 1.0 / math.sqrt(1.0 + t * t)
        else:  # nearly diagonal: Bullet's series for a large theta
            t = 1.0 / (theta * (2.0 + 0.5 / theta2))
            cos = 1.0 - 0.5 * t * t
        sin = cos * t
        a[p, q] = a[q, p] = 0.0
        a[p, p] -= t * apq
        a[q, q] += t * apq
        arp, arq = a[r, p], a[r, q]
        a[r, p] = a[p, r] = cos * arp - sin * arq
        a[r, q] = a[q, r] = cos * arq + sin * arp
        for i in range(3):
            rp, rq = rot[i, p], rot[i, q]
            rot[i, p] = cos * rp - sin * rq
            rot[i, q] = cos * rq + sin * rp
        step -= 1
    return rot, np.diag(a).copy()
