"""Rotations, poses and inertia arithmetic of ``modelkit.spatial``, against first principles."""

from __future__ import annotations

import math

import numpy as np
import pytest

from modelkit.spatial import (
    Pose,
    axis_angle,
    inertia_from_moments,
    matrix_from_quat_wxyz,
    matrix_from_rpy,
    rotate_inertia,
    rpy_from_matrix,
)

X, Y, Z = np.eye(3)


def random_rotation(rng: np.random.Generator) -> np.ndarray:
    return axis_angle(rng.normal(size=3), float(rng.uniform(-math.pi, math.pi)))


def random_inertia(rng: np.random.Generator) -> np.ndarray:
    """A physical inertia tensor: principal moments obeying the triangle inequality, random axes."""
    a, b = rng.uniform(0.1, 2.0, size=2)
    moments = np.array([a, b, rng.uniform(abs(a - b), a + b)])
    r = random_rotation(rng)
    return r @ np.diag(moments) @ r.T


# -- roll, pitch, yaw ------------------------------------------------------------------------


def test_rpy_is_z_y_x_product_of_axis_rotations() -> None:
    rng = np.random.default_rng(1)
    for _ in range(200):
        roll, pitch, yaw = rng.uniform(-math.pi, math.pi, size=3)
        expected = axis_angle(Z, yaw) @ axis_angle(Y, pitch) @ axis_angle(X, roll)
        assert np.allclose(matrix_from_rpy(roll, pitch, yaw), expected, atol=1e-14, rtol=0.0)


@pytest.mark.parametrize("axis, index", [(X, 0), (Y, 1), (Z, 2)])
def test_rpy_single_angle_is_the_axis_rotation(axis: np.ndarray, index: int) -> None:
    angles = [0.0, 0.0, 0.0]
    angles[index] = 0.7
    assert np.allclose(matrix_from_rpy(*angles), axis_angle(axis, 0.7), atol=1e-15, rtol=0.0)


def test_rpy_round_trips_through_rpy_from_matrix() -> None:
    rng = np.random.default_rng(2)
    for _ in range(100):
        rpy = np.array([rng.uniform(-3.0, 3.0), rng.uniform(-1.5, 1.5), rng.uniform(-3.0, 3.0)])
        assert np.allclose(rpy_from_matrix(matrix_from_rpy(*rpy)), rpy, atol=1e-12, rtol=0.0)


@pytest.mark.parametrize("cos_pitch", [1e-4, 3.7e-8, 1e-10, 2e-12])
def test_rpy_near_gimbal_lock_gives_the_matrix_back(cos_pitch: float) -> None:
    """Near pitch ±π/2 roll and yaw are each atan2s of entries of size cos(pitch): apart, each was off
    by up to 1e-16/cos(pitch), and the triple gave the matrix back only to 4e-10 at 7.3e-8 from the lock
    (Menagerie-style Unitree B2 feet; verify saw the URDF's feet turned by 1.17e-9 rad). The roll is
    found from what yaw and pitch leave when their two atan2s do not give the matrix back to 1e-12."""
    rng = np.random.default_rng(3)
    worst = 0.0
    for sign in (1.0, -1.0):
        for _ in range(200):
            half = [0.5 * float(rng.uniform(-3.0, 3.0)), 0.5 * sign * math.acos(cos_pitch),
                    0.5 * float(rng.uniform(-3.0, 3.0))]
            c, s = np.cos(half), np.sin(half)  # quaternion of Rz(y)·Ry(p)·Rx(r), as sources have it
            quat = (c[0] * c[1] * c[2] + s[0] * s[1] * s[2], s[0] * c[1] * c[2] - c[0] * s[1] * s[2],
                    c[0] * s[1] * c[2] + s[0] * c[1] * s[2], c[0] * c[1] * s[2] - s[0] * s[1] * c[2])
            r = matrix_from_quat_wxyz(quat)  # entries near 0 off by rounding of the O(1) terms
            worst = max(worst, float(np.max(np.abs(matrix_from_rpy(*rpy_from_matrix(r)) - r))))
    assert worst <= 1e-12  # what writers promise (the text's own rounding aside)


def test_rpy_near_gimbal_lock_keeps_a_plain_yaw() -> None:
    """The B2 foot's rotation 3.7e-8 rad from the lock: a yaw 7.6e-10 from 0 moves the matrix by 5e-17,
    so it is 0 (the roll takes the rest), and URDF gets ``1.5707964 1.5707964 0``."""
    from modelkit.convert.numbers import fmt_rpy

    r = matrix_from_quat_wxyz((0.4999999633974483, 0.49999999999999867, 0.49999999999999867,
                               -0.5000000366025518))
    assert rpy_from_matrix(r)[2] in (0.0, math.pi, -math.pi)
    text = fmt_rpy(r)
    assert text == "1.5707964 1.5707964 0"
    assert np.max(np.abs(matrix_from_rpy(*(float(v) for v in text.split())) - r)) <= 1e-15


# -- quaternions -----------------------------------------------------------------------------


def test_quaternion_matches_axis_angle() -> None:
    rng = np.random.default_rng(3)
    for _ in range(200):
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        angle = float(rng.uniform(-math.pi, math.pi))
        q = np.array([math.cos(angle / 2), *(math.sin(angle / 2) * axis)])
        expected = axis_angle(axis, angle)
        assert np.allclose(matrix_from_quat_wxyz(q), expected, atol=1e-14, rtol=0.0)
        # not unit: normalised first; and q and -q are the same rotation
        assert np.allclose(matrix_from_quat_wxyz(3.5 * q), expected, atol=1e-14, rtol=0.0)
        assert np.allclose(matrix_from_quat_wxyz(-q), expected, atol=1e-14, rtol=0.0)


def test_quaternion_accepts_a_tuple_and_orders_w_first() -> None:
    s = math.sqrt(0.5)
    assert np.allclose(matrix_from_quat_wxyz((s, 0.0, 0.0, s)), axis_angle(Z, math.pi / 2), atol=1e-15)
    assert np.allclose(matrix_from_quat_wxyz((1.0, 0.0, 0.0, 0.0)), np.eye(3))


@pytest.mark.parametrize("q", [(0.0, 0.0, 0.0, 0.0), (math.nan, 0.0, 0.0, 1.0), (math.inf, 0.0, 0.0, 0.0)])
def test_zero_or_non_finite_quaternion_is_the_identity(q: tuple[float, ...]) -> None:
    assert np.array_equal(matrix_from_quat_wxyz(q), np.eye(3))


# -- poses -----------------------------------------------------------------------------------


def test_inverse_composes_to_identity() -> None:
    rng = np.random.default_rng(4)
    for _ in range(100):
        pose = Pose(random_rotation(rng), rng.normal(size=3) * 5.0)
        inverse = pose.inverse()
        assert (pose @ inverse).is_identity(1e-12)
        assert (inverse @ pose).is_identity(1e-12)
        point = rng.normal(size=3)
        moved = pose.rotation @ point + pose.translation
        assert np.allclose(inverse.rotation @ moved + inverse.translation, point, atol=1e-12, rtol=0.0)


def test_inverse_of_identity_is_identity() -> None:
    assert Pose().inverse().is_identity(0.0)


def test_is_identity_uses_an_absolute_tolerance() -> None:
    assert Pose().is_identity()
    assert Pose(translation=np.array([0.0, 0.0, 1e-13])).is_identity()
    assert not Pose(translation=np.array([0.0, 0.0, 1e-11])).is_identity()
    assert Pose(translation=np.array([0.0, 0.0, 1e-11])).is_identity(1e-10)
    assert not Pose(axis_angle(Z, 1e-9)).is_identity()
    # rtol = 0: a relative tolerance on the 1s of the diagonal would accept this
    assert not Pose(np.diag([1.0 + 1e-9, 1.0, 1.0])).is_identity(1e-12)


# -- inertia ---------------------------------------------------------------------------------


def test_inertia_from_moments_is_symmetric_and_placed() -> None:
    tensor = inertia_from_moments(1.0, 0.1, 0.2, 2.0, 0.3, 3.0)
    assert np.array_equal(tensor, tensor.T)
    assert tensor.dtype == np.float64
    assert np.array_equal(np.diag(tensor), [1.0, 2.0, 3.0])
    assert (tensor[0, 1], tensor[0, 2], tensor[1, 2]) == (0.1, 0.2, 0.3)


def test_inertia_from_integer_moments_is_float() -> None:
    assert inertia_from_moments(1, 0, 0, 1, 0, 1).dtype == np.float64


def test_rotate_inertia_is_r_i_rt_and_keeps_eigenvalues() -> None:
    rng = np.random.default_rng(5)
    for _ in range(100):
        tensor = random_inertia(rng)
        r = random_rotation(rng)
        rotated = rotate_inertia(tensor, r)
        assert np.array_equal(rotated, r @ tensor @ r.T)
        assert np.allclose(rotated, rotated.T, atol=1e-14, rtol=0.0)
        assert np.allclose(np.linalg.eigvalsh(rotated), np.linalg.eigvalsh(tensor), atol=1e-12, rtol=0.0)
        assert np.allclose(rotate_inertia(rotated, r.T), tensor, atol=1e-12, rtol=0.0)


def test_rotate_inertia_of_principal_moments_by_a_quaternion() -> None:
    """What MuJoCo stores (principal moments and their axes as a quaternion) gives back the tensor."""
    r = axis_angle(Z, math.pi / 2)
    tensor = rotate_inertia(np.diag([1.0, 2.0, 3.0]), r)
    assert np.allclose(tensor, np.diag([2.0, 1.0, 3.0]), atol=1e-15)
    s = math.sqrt(0.5)
    assert np.allclose(rotate_inertia(np.diag([1.0, 2.0, 3.0]), matrix_from_quat_wxyz((s, 0, 0, s))), tensor)


def test_the_identity_test_of_the_bounds_rule_takes_numpy_poses() -> None:
    """A pose computed with numpy (a re-parented SDF joint) holds arrays: comparing them with a tuple once
    raised "The truth value of an array ... is ambiguous" inside validate."""
    from modelkit.checks.bounds import _is_identity

    assert _is_identity(Pose(np.eye(3), np.zeros(3)))
    assert not _is_identity(Pose(np.eye(3), np.array([0.0, 0.0, 1.0])))
    assert _is_identity(Pose())
