"""Poses on SE(2) and the exponential of a body twist (Modern Robotics, ch. 3, in the plane).

A pose ``q = (x, y, theta)`` places a body frame in the world. Moving with a constant body twist
``V = (vx, vy, omega)`` for time ``t`` gives ``q * exp(V t)``: the motion a constant push produces
(Lynch & Mason 1996, §1.1: for a constant control the twist is constant in the slider frame).
The functions are vectorised over leading axes.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

__all__ = ["compose", "exp_twist", "inverse", "log_pose", "pose_error", "relative_pose", "transform_points",
           "wrap_angle"]

def wrap_angle(theta: ArrayLike) -> np.ndarray:
    """Angle in ``[-pi, pi)``.

    >>> float(wrap_angle(3 * np.pi / 2)), float(wrap_angle(np.pi))
    (-1.5707963267948966, -3.141592653589793)
    """
    return (np.asarray(theta, dtype=float) + np.pi) % (2 * np.pi) - np.pi


def _sin_ratio(phi: np.ndarray) -> np.ndarray:
    """sin(phi)/phi, continuous at 0 (numpy's normalised sinc)."""
    return np.sinc(phi / np.pi)


def _cos_ratio(phi: np.ndarray) -> np.ndarray:
    """(1 - cos(phi))/phi = (phi/2) sinc^2(phi/2), continuous at 0."""
    return phi / 2 * np.sinc(phi / (2 * np.pi)) ** 2


def exp_twist(pose: ArrayLike, twist: ArrayLike, t: ArrayLike = 1.0) -> np.ndarray:
    """Pose reached from ``pose`` by moving with body ``twist`` for time ``t``: ``q * exp(V t)``.

    Examples
    --------
    Quarter turn CCW about the body point (0, 1) (twist (1, 0, 1)), from the origin:

    >>> np.round(exp_twist([0, 0, 0], [1.0, 0.0, 1.0], np.pi / 2), 12).tolist()
    [1.0, 1.0, 1.570796326795]

    A translation is the limit omega -> 0, in the body frame:

    >>> exp_twist([1.0, 0.0, np.pi / 2], [2.0, 0.0, 0.0], 0.5).round(12).tolist()
    [1.0, 1.0, 1.570796326795]
    """
    q = np.asarray(pose, dtype=float)
    v = np.asarray(twist, dtype=float)
    t = np.asarray(t, dtype=float)
    phi = v[..., 2] * t
    a, b = _sin_ratio(phi), _cos_ratio(phi)
    # Displacement in the body frame: V(phi) (vx, vy) t with V = [[a, -b], [b, a]].
    dx = (a * v[..., 0] - b * v[..., 1]) * t
    dy = (b * v[..., 0] + a * v[..., 1]) * t
    c, s = np.cos(q[..., 2]), np.sin(q[..., 2])
    return np.stack([q[..., 0] + c * dx - s * dy, q[..., 1] + s * dx + c * dy, q[..., 2] + phi], axis=-1)


def transform_points(p_B: ArrayLike, X_AB: ArrayLike) -> np.ndarray:
    """Points given in frame B, in frame A, where ``X_AB`` is B's pose in A (``(x, y, theta)``);
    both broadcast over leading axes: ``(m, 2)`` points and one pose give ``(m, 2)``, one point and
    ``(n, 3)`` poses give ``(n, 2)``.

    >>> transform_points([[1.0, 0.0]], [0.0, 1.0, np.pi / 2]).round(12).tolist()
    [[0.0, 2.0]]
    >>> transform_points([1.0, 0.0], [[0.0, 0.0, 0.0], [0.0, 0.0, np.pi]]).round(12).tolist()
    [[1.0, 0.0], [-1.0, 0.0]]
    """
    p = np.asarray(p_B, dtype=float)
    X = np.asarray(X_AB, dtype=float)
    c, s = np.cos(X[..., 2]), np.sin(X[..., 2])
    return np.stack([X[..., 0] + c * p[..., 0] - s * p[..., 1], X[..., 1] + s * p[..., 0] + c * p[..., 1]], axis=-1)


def compose(X_AB: ArrayLike, X_BC: ArrayLike) -> np.ndarray:
    """``X_AC = X_AB X_BC``: C's pose in A from C's in B and B's in A, angle in ``[-pi, pi)``.

    >>> compose([1.0, 0.0, np.pi / 2], [1.0, 0.0, np.pi / 2]).round(12).tolist()
    [1.0, 1.0, -3.14159265359]
    """
    X_BC = np.asarray(X_BC, dtype=float)
    xy = transform_points(X_BC[..., :2], X_AB)
    return np.concatenate([xy, wrap_angle(np.asarray(X_AB, dtype=float)[..., 2] + X_BC[..., 2])[..., None]], axis=-1)


def inverse(X_AB: ArrayLike) -> np.ndarray:
    """``X_BA``: A's pose in B.

    >>> inverse([1.0, 2.0, np.pi / 2]).round(12).tolist()
    [-2.0, 1.0, -1.570796326795]
    >>> compose([1.0, 2.0, 0.3], inverse([1.0, 2.0, 0.3])).round(12).tolist()
    [0.0, 0.0, 0.0]
    """
    X = np.asarray(X_AB, dtype=float)
    c, s = np.cos(X[..., 2]), np.sin(X[..., 2])
    return np.stack([-(c * X[..., 0] + s * X[..., 1]), s * X[..., 0] - c * X[..., 1], wrap_angle(-X[..., 2])], axis=-1)


def relative_pose(q0: ArrayLike, q1: ArrayLike) -> np.ndarray:
    """``q0^-1 q1``: pose ``q1`` seen from the body frame at ``q0``, angle in ``[-pi, pi)``.

    >>> relative_pose([1.0, 1.0, np.pi / 2], [1.0, 3.0, np.pi / 2]).round(12).tolist()
    [2.0, 0.0, 0.0]
    """
    a = np.asarray(q0, dtype=float)
    b = np.asarray(q1, dtype=float)
    dx, dy = b[..., 0] - a[..., 0], b[..., 1] - a[..., 1]
    c, s = np.cos(a[..., 2]), np.sin(a[..., 2])
    return np.stack([c * dx + s * dy, -s * dx + c * dy, wrap_angle(b[..., 2] - a[..., 2])], axis=-1)


def log_pose(q0: ArrayLike, q1: ArrayLike) -> np.ndarray:
    """Body twist ``V`` with ``q0 * exp(V) = q1``, turning by the smaller angle (|omega| <= pi).

    This is the paper's COR_total (Lynch 1992, §5.1) as a twist.

    Examples
    --------
    The quarter turn of :func:`exp_twist`, recovered (twist (1, 0, 1) for pi/2 s):

    >>> log_pose([0, 0, 0], [1.0, 1.0, np.pi / 2]).round(12).tolist()
    [1.570796326795, 0.0, 1.570796326795]
    >>> log_pose([0, 0, 0], [0.0, 2.0, 0.0]).tolist()
    [0.0, 2.0, 0.0]
    """
    d = relative_pose(q0, q1)
    phi = d[..., 2]
    a, b = _sin_ratio(phi), _cos_ratio(phi)
    det = a * a + b * b
    # Invert V(phi) = [[a, -b], [b, a]].
    vx = (a * d[..., 0] + b * d[..., 1]) / det
    vy = (-b * d[..., 0] + a * d[..., 1]) / det
    return np.stack([vx, vy, phi], axis=-1)


def pose_error(pose: ArrayLike, target: ArrayLike) -> tuple[float, float]:
    """How far ``pose`` is from ``target``: the distance between their origins and the size of
    their heading difference (wrapped), as goal tolerances and trackers measure it.

    >>> distance, turn = pose_error([3.0, 4.0, np.pi - 0.1], [0.0, 0.0, -np.pi + 0.1])
    >>> distance, round(turn, 12)
    (5.0, 0.2)
    """
    return math.hypot(pose[0] - target[0], pose[1] - target[1]), abs(float(wrap_angle(pose[2] - target[2])))
