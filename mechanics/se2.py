"""Poses on SE(2) and the exponential of a body twist (Modern Robotics, ch. 3, in the plane).

A pose ``q = (x, y, theta)`` places a body frame in the world. Moving with a constant body twist
``V = (vx, vy, omega)`` for time ``t`` gives ``q * exp(V t)``: the motion a constant push produces
(Lynch & Mason 1996, §1.1: for a constant control the twist is constant in the slider frame).
The functions are vectorised over leading axes.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

__all__ = ["exp_twist", "log_pose", "relative_pose", "wrap_angle"]

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
