"""The push plane: a chart of an edge's pushes in which a stable region is a bounded polygon.

Every guaranteed-stable push of an edge presses the contact's midpoint ``m`` into the part (its
rotation centre lies beyond the part's extent along the edge, or it is a translation within the
friction cone; Lynch & Mason 1996, Theorem 4). So each such twist ``V``, up to its positive
scale, is one point of the plane ``a(V) = (v + omega k x m) . n = 1``, with coordinates

* ``s``: the tangential speed of ``m`` along ``t = (n_y, -n_x)``,
* ``w``: ``omega`` times the part's radius (a speed).

Rays of twists become points and, since the map is linear before the division by ``a``, straight
lines of twists (positive combinations, Lynch 1992 §2.2) become straight segments. The
straight-ahead push is ``(0, 0)``; translations lie on ``w = 0``; a rotation about ``c`` has
``t . c = t . m - radius / w``, so rotations about centres beyond the part along ``t`` fill a
horizontal strip (:meth:`PushPlane.theorem4_strip`).

Examples
--------
The bottom face of a 2 x 1 block (radius 1.118 from the CF (0, 0.5)): pushing straight up is the
origin; a CCW turn about (-3, 0) has ``omega = 1/3`` per unit normal speed of ``m = (0, 0)``.

>>> import numpy as np
>>> plane = PushPlane([0.0, 1.0], [[-1, 0], [1, 0]], 1.118034)
>>> plane.points([[0.0, 2.0, 0.0], [0.0, 3.0, 1.0]]).round(6).tolist()
[[0.0, 0.0], [0.0, 0.372678]]
>>> plane.twists([[0.0, 0.372678]]).round(5).tolist()
[[0.0, 1.0, 0.33333]]
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

__all__ = ["PushPlane"]


class PushPlane:
    """The chart ``V -> (s, w)`` of an edge's pushes (module docstring).

    Parameters
    ----------
    normal : (2,) array_like
        The edge's unit inward normal ``n`` (the push direction).
    contact : (2, 2) array_like
        The contact segment's end points; ``m`` is their midpoint.
    scale : float
        The part's radius, converting ``omega`` to a speed.
    """

    def __init__(self, normal: ArrayLike, contact: ArrayLike, scale: float):
        n = np.asarray(normal, dtype=float)
        self.normal, self.scale = n, float(scale)
        self.tangent = np.array([n[1], -n[0]])
        self.midpoint = np.asarray(contact, dtype=float).mean(axis=0)
        m, t = self.midpoint, self.tangent
        # Normal and tangential velocity of m, and omega as a speed: an invertible linear map.
        self._to = np.array([
            [n[0], n[1], m[0] * n[1] - m[1] * n[0]],
            [t[0], t[1], m[0] * t[1] - m[1] * t[0]],
            [0.0, 0.0, self.scale],
        ])
        self._from = np.linalg.inv(self._to)

    def coordinates(self, twists: ArrayLike) -> np.ndarray:
        """``(a, a s, a w)`` of each twist (shape ``(..., 3)``): the plane point before division by ``a``."""
        return np.asarray(twists, dtype=float) @ self._to.T

    def points(self, twists: ArrayLike) -> np.ndarray:
        """Plane points ``(s, w)`` of twists with ``a(V) > 0`` (NaN where ``a(V) <= 0``)."""
        y = self.coordinates(twists)
        a = np.where(y[..., :1] > 0, y[..., :1], np.nan)
        return y[..., 1:] / a

    def twists(self, points: ArrayLike) -> np.ndarray:
        """The twists with ``a(V) = 1`` at plane ``points`` (shape ``(..., 2)``)."""
        p = np.asarray(points, dtype=float)
        y = np.concatenate([np.ones_like(p[..., :1]), p], axis=-1)
        return y @ self._from.T

    def theorem4_strip(self, vertices: ArrayLike) -> tuple[float, float]:
        """``(w_lo, w_hi)``: the open strip of plane points whose rotation centre lies beyond the
        part (``vertices``) along the edge, on the side where the push presses ``m`` into it.

        >>> PushPlane([0.0, 1.0], [[-1, 0], [1, 0]], 2.0).theorem4_strip([[-1, 0], [1, 0], [1, 1], [-1, 1]])
        (-2.0, 2.0)
        """
        along = np.asarray(vertices, dtype=float) @ self.tangent
        here = float(self.midpoint @ self.tangent)
        return float(-self.scale / (along.max() - here)), float(self.scale / (here - along.min()))
