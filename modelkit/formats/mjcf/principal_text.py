"""An inertia tensor with products as MuJoCo's ``quat`` and ``diaginertia``, when that text is plainer.

MJCF sources (MuJoCo Menagerie, robosuite, mjlab) give almost every inertia in its principal form,
``quat="0 0.0728458 0 0.997343" diaginertia="0.00911338 0.008925 0.000759317"``. The model holds the
tensor in the link's axes, so written back as ``fullinertia`` it reads
``0.0089369971999583 0.008925 0.0009356998000417 0 -0.0012010004710716 0``: the same tensor, in numbers
nobody wrote. The principal axes come back from an eigen-decomposition in some order and with some
signs; one of the 24 ways to order and sign them (a proper rotation) is the source's, and its
quaternion rounds to the source's digits (:func:`short_quat`).
"""

from __future__ import annotations

import itertools

import numpy as np

from modelkit.convert.numbers import fmt_tensor
from modelkit.formats.mjcf.write_xml import SOURCE_DIGITS, plainness, short_quat
from modelkit.spatial import matrix_from_quat_wxyz


def _arrangements() -> list[tuple[tuple[int, ...], tuple[float, ...]]]:
    """The 24 proper rotations that reorder and re-sign three axes: (which old axis, its sign) per
    new axis, the identity first."""
    out = []
    for order in itertools.permutations(range(3)):
        for signs in itertools.product((1.0, -1.0), repeat=3):
            matrix = np.zeros((3, 3))
            for new, (old, sign) in enumerate(zip(order, signs, strict=True)):
                matrix[old, new] = sign
            if np.linalg.det(matrix) > 0.0:
                out.append((order, signs))
    return out


ARRANGEMENTS = _arrangements()


def principal_text(tensor: np.ndarray, moments: np.ndarray, axes: np.ndarray) -> tuple[str, str] | None:
    """``(quat, diaginertia)`` texts for ``tensor`` (principal ``moments`` along the columns of
    ``axes``), when one arrangement of the axes has a quaternion as a source writes one
    (:func:`short_quat`: at most nine digits), the texts give the tensor back to 1e-12 of its largest
    entry, and the full tensor has a number longer than a source writes (:data:`SOURCE_DIGITS`) and
    they have none. Else None: ``fullinertia``."""
    t = np.asarray(tensor, dtype=float)
    full = fmt_tensor([t[0, 0], t[1, 1], t[2, 2], t[0, 1], t[0, 2], t[1, 2]], t)
    if plainness(full) <= SOURCE_DIGITS:
        return None
    best: tuple[tuple[int, float], str, str] | None = None
    for order, signs in ARRANGEMENTS:
        turned = axes[:, list(order)] * np.asarray(signs)
        quat = short_quat(turned)
        if quat is None:
            continue
        diagonal = fmt_tensor(moments[list(order)], t)
        # the fewest digits, then the smallest turn from the link's axes (the largest w)
        rank = (max(plainness(quat), plainness(diagonal)), -float(quat.split()[0]))
        if best is None or rank < best[0]:
            best = (rank, quat, diagonal)
    if best is None or best[0][0] > SOURCE_DIGITS:
        return None
    _, quat, diagonal = best
    rotation = matrix_from_quat_wxyz([float(x) for x in quat.split()])
    back = rotation @ np.diag([float(x) for x in diagonal.split()]) @ rotation.T
    if float(np.max(np.abs(back - t))) > 1e-12 * float(np.max(np.abs(t))):
        return None
    return quat, diagonal
