"""Planar twists and signed centres of rotation (Lynch & Mason 1996, §1; docs/mechanics.md, "Conventions").

A planar motion is a twist ``(vx, vy, omega)``: the velocity of the frame origin and the
angular velocity, both in the same frame. For ``omega != 0`` the same motion is a rotation
about a *signed centre of rotation* (COR): the point that does not move, with the sense of
rotation (+1 counter-clockwise, -1 clockwise). A translation is a COR at infinity.

Only directions matter for quasi-static pushing, so a COR gives a twist up to a positive scale.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

__all__ = ["cor_to_twist", "twist_to_cor", "point_velocity"]


def cor_to_twist(cor: ArrayLike, sense: ArrayLike) -> np.ndarray:
    """Unit-angular-speed twist of a rotation about ``cor`` with ``sense`` (+1 CCW, -1 CW).

    Vectorised: ``cor`` has shape ``(..., 2)`` and ``sense`` broadcasts against ``cor[..., 0]``.

    Examples
    --------
    A CCW rotation about (-2, 0) moves the origin straight up at 2 m/s per rad/s:

    >>> cor_to_twist([-2.0, 0.0], 1).tolist()
    [0.0, 2.0, 1.0]
    >>> cor_to_twist([[-2.0, 0.0], [0.0, 0.0]], [-1, 1]).tolist()
    [[-0.0, -2.0, -1.0], [0.0, -0.0, 1.0]]
    """
    c = np.asarray(cor, dtype=float)
    s = np.asarray(sense, dtype=float)
    return np.stack([s * c[..., 1], -s * c[..., 0], s * np.ones_like(c[..., 0])], axis=-1)


def twist_to_cor(twist: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """Signed COR of ``twist``: ``(cor, sense)``; translations give ``cor = (inf, inf)``, sense 0.

    Examples
    --------
    >>> cor, sense = twist_to_cor([0.0, 2.0, 1.0])
    >>> cor.tolist(), float(sense)
    ([-2.0, 0.0], 1.0)
    >>> cor, sense = twist_to_cor([1.0, 0.0, 0.0])
    >>> cor.tolist(), float(sense)
    ([inf, inf], 0.0)
    """
    v = np.asarray(twist, dtype=float)
    w = v[..., 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        cor = np.stack([-v[..., 1] / w, v[..., 0] / w], axis=-1)
    cor = np.where((w == 0)[..., None], np.inf, cor)
    return cor, np.sign(w)


def point_velocity(twist: ArrayLike, points: ArrayLike) -> np.ndarray:
    """Velocity ``v + omega k x p`` of ``points`` (shape ``(..., 2)``) moving with ``twist``.

    ``twist`` (shape ``(..., 3)``) and ``points`` broadcast against each other.

    Examples
    --------
    >>> point_velocity([0.0, 0.0, 1.0], [[1.0, 0.0], [0.0, 2.0]]).tolist()
    [[0.0, 1.0], [-2.0, 0.0]]
    """
    v = np.asarray(twist, dtype=float)
    p = np.asarray(points, dtype=float)
    return np.stack([v[..., 0] - v[..., 2] * p[..., 1], v[..., 1] + v[..., 2] * p[..., 0]], axis=-1)
