"""Whether libsdformat accepts an inertia tensor: gz-math's ``MassMatrix3::IsValid`` redone step by step.

libsdformat refuses a whole file when one link's ``<inertia>`` fails ``IsValid`` ("A link named ... has
invalid inertia"). That test is not the exact eigenvalues': gz-math computes the principal moments in
closed form (Kronenburg's trigonometric formula, arXiv:1306.6291), which loses precision when two
moments nearly coincide, and takes a tensor whose products are within 1e-6 of its largest diagonal
entry as already diagonal. Hello Robot's Stretch gripper puller (moments 1.08e-15, 1.0931711057e-7,
1.0931711165e-7) shows the difference: its source passes, and the tensor lifted to meet A + B ≥ C
exactly was refused. So the SDF writer asks this function, on the values as they are written, rather
than numpy's eigenvalues. The operations follow gz-math 6's header in order, with the same C library
functions (``math.pow``, ``acos``, ``cos``, ``sqrt``), so the rounding is the same.
"""

from __future__ import annotations

import math

from modelkit.spatial import Mat3

DEFAULT_TOLERANCE = 10.0  # IGN_MASSMATRIX3_DEFAULT_TOLERANCE
EPSILON = 2.220446049250313e-16  # std::numeric_limits<double>::epsilon()
PRINCIPAL_TOLERANCE = 1e-6  # PrincipalMoments' default _tol, relative to the largest diagonal entry


def _epsilon(moments: tuple[float, float, float]) -> float:
    """``MassMatrix3::Epsilon``: tolerance × machine epsilon × the largest possible moment (trace / 2)."""
    return DEFAULT_TOLERANCE * EPSILON * (0.5 * abs(moments[0] + moments[1] + moments[2]))


def principal_moments(m: Mat3) -> tuple[float, float, float]:
    """``MassMatrix3::PrincipalMoments()``: ascending, as gz-math computes them."""
    d = (float(m[0, 0]), float(m[1, 1]), float(m[2, 2]))
    p = (float(m[0, 1]), float(m[0, 2]), float(m[1, 2]))
    tol = PRINCIPAL_TOLERANCE * max(d)
    if all(abs(x) <= tol for x in p):  # "already diagonalized"
        return d
    b = d[0] + d[1] + d[2]
    c = (d[0] * d[1] - math.pow(p[0], 2) + d[0] * d[2] - math.pow(p[1], 2)
         + d[1] * d[2] - math.pow(p[2], 2))
    dd = (d[0] * math.pow(p[2], 2) + d[1] * math.pow(p[1], 2) + d[2] * math.pow(p[0], 2)
          - d[0] * d[1] * d[2] - 2 * p[0] * p[1] * p[2])
    pp = math.pow(b, 2) - 3 * c
    if pp < math.pow(tol, 2):
        return (b / 3.0, b / 3.0, b / 3.0)
    q = 2 * math.pow(b, 3) - 9 * b * c - 27 * dd
    delta = math.acos(min(max(0.5 * q / math.pow(pp, 1.5), -1.0), 1.0))
    root = 2 * math.sqrt(pp)
    moments = sorted(((b + root * math.cos(delta / 3.0)) / 3.0,
                      (b + root * math.cos((delta + 2 * math.pi) / 3.0)) / 3.0,
                      (b + root * math.cos((delta - 2 * math.pi) / 3.0)) / 3.0))
    return moments[0], moments[1], moments[2]


def _determinant(m: Mat3) -> float:
    """``Matrix3::Determinant``, in its order of operations."""
    t0 = m[2, 2] * m[1, 1] - m[2, 1] * m[1, 2]
    t1 = -(m[2, 2] * m[1, 0] - m[2, 0] * m[1, 2])
    t2 = m[2, 1] * m[1, 0] - m[2, 0] * m[1, 1]
    return float(t0 * m[0, 0] + t1 * m[0, 1] + t2 * m[0, 2])


def libsdformat_accepts(m: Mat3) -> bool:
    """``MassMatrix3::IsValid()`` of the symmetric tensor ``m`` (a mass ≥ 0 assumed): near positive
    definite, and principal moments that meet the triangle inequality within ``_epsilon``."""
    diagonal = (float(m[0, 0]), float(m[1, 1]), float(m[2, 2]))
    e = _epsilon(diagonal)
    near_positive = (diagonal[0] + e >= 0 and diagonal[0] * diagonal[1] - math.pow(float(m[0, 1]), 2) + e >= 0
                     and _determinant(m) + e >= 0)
    if not near_positive:
        return False
    a, b, c = principal_moments(m)
    e = _epsilon((a, b, c))
    return (a + e >= 0 and b + e >= 0 and c + e >= 0
            and a + b + e >= c and b + c + e >= a and c + a + e >= b)
