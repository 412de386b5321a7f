"""SE(2) poses and twists (mechanics.se2, mechanics.twist) against hand-derived motions and an
independent matrix exponential (scipy.linalg.expm of the 3 x 3 se(2) matrix)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.linalg import expm

from mechanics import cor_to_twist, exp_twist, log_pose, point_velocity, relative_pose, twist_to_cor, wrap_angle

PI = np.pi


def pose_matrix(q):
    x, y, th = q
    return np.array([[np.cos(th), -np.sin(th), x], [np.sin(th), np.cos(th), y], [0, 0, 1.0]])


def matrix_pose(T):
    return np.array([T[0, 2], T[1, 2], np.arctan2(T[1, 0], T[0, 0])])


def se2_hat(v):
    vx, vy, w = v
    return np.array([[0, -w, vx], [w, 0, vy], [0, 0, 0.0]])


def expm_pose(q, v, t):
    return matrix_pose(pose_matrix(q) @ expm(se2_hat(v) * t))


def assert_pose_close(a, b, atol=1e-10):
    a, b = np.asarray(a, float), np.asarray(b, float)
    np.testing.assert_allclose(a[..., :2], b[..., :2], atol=atol)
    dth = (a[..., 2] - b[..., 2] + PI) % (2 * PI) - PI  # compare angles modulo 2 pi
    np.testing.assert_allclose(dth, 0.0, atol=atol)


# ----------------------------------------------------------------------------------------------
# hand-derived motions

HAND = [
    # (pose, twist, t, expected pose)
    ((0, 0, 0), (1, 0, 0), 2.0, (2, 0, 0)),  # straight ahead
    ((0, 0, 0), (0, 0, 1), PI / 2, (0, 0, PI / 2)),  # spin in place
    ((1, 2, PI / 2), (1, 0, 0), 1.0, (1, 3, PI / 2)),  # body x is world y
    ((1, 2, PI), (0, 3, 0), 1.0, (1, -1, PI)),  # body y is world -y
    # CCW about the body point (0, 1): twist (c_y, -c_x, 1) = (1, 0, 1); a half turn takes the
    # origin to (0, 2), facing backwards
    ((0, 0, 0), (1, 0, 1), PI, (0, 2, PI)),
    # CW about (0, -1): twist (-c_y, c_x, -1) = (1, 0, -1); a quarter turn: origin to (1, -1)
    ((0, 0, 0), (1, 0, -1), PI / 2, (1, -1, -PI / 2)),
    # same, starting from a rotated, translated pose (1, 1, pi/2): body (1, -1) -> world (2, 2)
    ((1, 1, PI / 2), (1, 0, -1), PI / 2, (2, 2, 0)),
    # full turn comes back
    ((0.3, -0.2, 0.1), (2, -1, 1), 2 * PI, (0.3, -0.2, 0.1 + 2 * PI)),
]


@pytest.mark.parametrize("q, v, t, want", HAND)
def test_exp_twist_hand_cases(q, v, t, want):
    assert_pose_close(exp_twist(q, v, t), want, atol=1e-12)


def test_exp_twist_keeps_the_cor_fixed():
    """A rotation about COR c leaves the world image of c in place (docs/mechanics.md, "Conventions")."""
    rng = np.random.default_rng(1)
    for _ in range(50):
        q = rng.uniform(-3, 3, 3)
        c = rng.uniform(-4, 4, 2)
        sense = rng.choice([-1, 1])
        v = cor_to_twist(c, sense)
        q1 = exp_twist(q, v, rng.uniform(0.1, 6))
        w0 = pose_matrix(q) @ np.r_[c, 1]
        w1 = pose_matrix(q1) @ np.r_[c, 1]
        np.testing.assert_allclose(w1, w0, atol=1e-10)


def test_relative_pose_hand_cases():
    np.testing.assert_allclose(relative_pose([1, 1, PI / 2], [1, 3, PI / 2]), [2, 0, 0], atol=1e-12)
    np.testing.assert_allclose(relative_pose([0, 0, 0], [1, 2, 3 * PI / 2]), [1, 2, -PI / 2], atol=1e-12)
    np.testing.assert_allclose(relative_pose([1, 0, PI], [0, 0, 0]), [1, 0, -PI], atol=1e-12)  # wraps to -pi
    np.testing.assert_allclose(relative_pose([2, -1, 0.4], [2, -1, 0.4]), [0, 0, 0], atol=1e-12)


def test_log_pose_hand_cases():
    # the quarter turn about (0, 1): twist (1, 0, 1) for pi/2, i.e. (pi/2, 0, pi/2) for time 1
    np.testing.assert_allclose(log_pose([0, 0, 0], [1, 1, PI / 2]), [PI / 2, 0, PI / 2], atol=1e-12)
    np.testing.assert_allclose(log_pose([0, 0, 0], [0, 2, 0]), [0, 2, 0], atol=1e-15)
    np.testing.assert_allclose(log_pose([1, 2, PI / 2], [1, 3, PI / 2]), [1, 0, 0], atol=1e-12)
    # half turn: the relative angle wraps to -pi, so the log turns CW about (0, 1): (-pi, 0, -pi)
    np.testing.assert_allclose(log_pose([0, 0, 0], [0, 2, PI]), [-PI, 0, -PI], atol=1e-12)


def test_wrap_angle():
    np.testing.assert_allclose(wrap_angle([PI, -PI, 3 * PI / 2, 2 * PI, -0.5, 7.0]),
                               [-PI, -PI, -PI / 2, 0, -0.5, 7.0 - 2 * PI], atol=1e-15)
    x = np.random.default_rng(2).uniform(-50, 50, 1000)
    w = wrap_angle(x)
    assert np.all((w >= -PI) & (w < PI))
    np.testing.assert_allclose(np.sin(w), np.sin(x), atol=1e-12)
    np.testing.assert_allclose(np.cos(w), np.cos(x), atol=1e-12)


# ----------------------------------------------------------------------------------------------
# against the matrix exponential; algebraic identities


def random_twists(rng, n):
    v = rng.uniform(-2, 2, (n, 3))
    # include zero and tiny angular speeds (the 0/0 limit of sin(phi)/phi and (1 - cos(phi))/phi)
    v[: n // 4, 2] = rng.choice([0.0, 1e-12, -1e-9, 3e-7, -9.9e-7, 1.01e-6, 1e-5], n // 4)
    return v


def test_exp_matches_matrix_exponential():
    rng = np.random.default_rng(3)
    V = random_twists(rng, 200)
    Q = rng.uniform(-5, 5, (200, 3))
    t = rng.uniform(-3, 3, 200)
    got = exp_twist(Q, V, t)  # vectorised
    want = np.array([expm_pose(q, v, s) for q, v, s in zip(Q, V, t)])
    assert_pose_close(got, want, atol=1e-9)
    np.testing.assert_allclose(got[:, 2], Q[:, 2] + V[:, 2] * t, atol=1e-12)  # angle not wrapped


def test_relative_pose_matches_matrices():
    rng = np.random.default_rng(4)
    for _ in range(100):
        a, b = rng.uniform(-5, 5, 3), rng.uniform(-5, 5, 3)
        want = matrix_pose(np.linalg.inv(pose_matrix(a)) @ pose_matrix(b))
        got = relative_pose(a, b)
        assert_pose_close(got, want, atol=1e-12)
        assert -PI <= got[2] < PI


def test_log_of_exp_is_identity():
    rng = np.random.default_rng(5)
    V = random_twists(rng, 400)
    V[:, 2] = np.where(np.abs(V[:, 2]) > 1, rng.uniform(-0.999, 0.999, 400) * PI, V[:, 2])  # |omega t| < pi
    Q = rng.uniform(-5, 5, (400, 3))
    np.testing.assert_allclose(log_pose(Q, exp_twist(Q, V)), V, atol=1e-9)
    # with a time: log(q, exp(q, V, t)) = V t
    t = rng.uniform(0.1, 0.9, 400)
    np.testing.assert_allclose(log_pose(Q, exp_twist(Q, V, t)), V * t[:, None], atol=1e-9)


def test_exp_of_log_reaches_the_pose():
    rng = np.random.default_rng(6)
    Q0 = rng.uniform(-5, 5, (300, 3)) * [1, 1, 3]
    Q1 = rng.uniform(-5, 5, (300, 3)) * [1, 1, 3]
    Q1[:20] = Q0[:20] + rng.uniform(-1e-8, 1e-8, (20, 3))  # nearly equal poses
    V = log_pose(Q0, Q1)
    assert np.all(np.abs(V[:, 2]) <= PI)
    assert_pose_close(exp_twist(Q0, V), Q1, atol=1e-9)
    # and the matrix logarithm agrees: expm(hat(V)) = q0^-1 q1
    for q0, q1, v in zip(Q0[:50], Q1[:50], V[:50]):
        np.testing.assert_allclose(expm(se2_hat(v)), np.linalg.inv(pose_matrix(q0)) @ pose_matrix(q1), atol=1e-9)


def test_group_property():
    """Moving with V for t1 then t2 equals moving for t1 + t2 (one-parameter subgroup)."""
    rng = np.random.default_rng(7)
    V = random_twists(rng, 200)
    Q = rng.uniform(-5, 5, (200, 3))
    t1, t2 = rng.uniform(-2, 2, 200), rng.uniform(-2, 2, 200)
    assert_pose_close(exp_twist(exp_twist(Q, V, t1), V, t2), exp_twist(Q, V, t1 + t2), atol=1e-9)
    # left invariance: q * exp(V t) = q * (0 * exp(V t)), composed with matrices
    E0 = exp_twist(np.zeros(3), V, t1)
    for q, e, got in zip(Q[:50], E0[:50], exp_twist(Q, V, t1)[:50]):
        assert_pose_close(got, matrix_pose(pose_matrix(q) @ pose_matrix(e)), atol=1e-10)


def test_small_rotations_are_accurate():
    """omega -> 0 (near the 0/0 limit): exp and log still agree with the matrix exponential."""
    for w in (0.0, 5e-7, 9.99e-7, 1e-6, 1.001e-6, 2e-6):
        for t in (1.0, 1000.0):
            v = np.array([0.7, -0.3, w])
            assert_pose_close(exp_twist([0.2, 0.1, 0.3], v, t), expm_pose([0.2, 0.1, 0.3], v, t), atol=1e-9)
            if abs(w * t) < PI:
                np.testing.assert_allclose(log_pose([0, 0, 0], exp_twist([0, 0, 0], v, t)), v * t, atol=1e-9)


# ----------------------------------------------------------------------------------------------
# twist helpers (mechanics.twist)


def test_cor_twist_conventions():
    """docs/mechanics.md, "Conventions": COR of (vx, vy, w) is (-vy/w, vx/w); CCW about c is (c_y, -c_x, 1)."""
    np.testing.assert_allclose(cor_to_twist([-2.0, 0.0], 1), [0, 2, 1])
    np.testing.assert_allclose(cor_to_twist([3.0, 1.0], -1), [-1, 3, -1])
    cor, sense = twist_to_cor([0.0, 4.0, 2.0])
    np.testing.assert_allclose(cor, [-2, 0])
    assert sense == 1
    cor, sense = twist_to_cor([1.0, -1.0, 0.0])
    assert np.all(np.isinf(cor)) and sense == 0
    rng = np.random.default_rng(8)
    C = rng.uniform(-10, 10, (100, 2))
    S = rng.choice([-1, 1], 100)
    scale = rng.uniform(0.1, 10, (100, 1))
    cor, sense = twist_to_cor(cor_to_twist(C, S) * scale)
    np.testing.assert_allclose(cor, C, atol=1e-12)
    np.testing.assert_array_equal(sense, S)


def test_point_velocity():
    rng = np.random.default_rng(9)
    C = rng.uniform(-5, 5, (100, 2))
    S = rng.choice([-1, 1], 100)
    V = cor_to_twist(C, S)
    np.testing.assert_allclose(point_velocity(V, C), 0.0, atol=1e-12)  # the COR does not move
    P = rng.uniform(-5, 5, (100, 2))
    vel = point_velocity(V, P)
    # rotation about c with sense s: v(p) = s k x (p - c) = s (-(p - c)_y, (p - c)_x)
    d = P - C
    np.testing.assert_allclose(vel, S[:, None] * np.column_stack([-d[:, 1], d[:, 0]]), atol=1e-12)
    # agrees with the finite difference of exp_twist at the pose origin
    h = 1e-6
    for v, p, want in zip(V[:20], P[:20], vel[:20]):
        T = pose_matrix(exp_twist([0, 0, 0], v, h))
        fd = ((T @ np.r_[p, 1])[:2] - p) / h
        np.testing.assert_allclose(fd, want, atol=1e-4 * (1 + np.abs(want).max()))
