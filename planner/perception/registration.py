"""Registration of a known outline to edge points: the pose that puts the outline through them.

The points are the edge points a depth image gives of one part (:mod:`.silhouette`), world
``(x, y)``; the outline is the part's polygon in its own frame. The pose minimises the sum of a
robust function (scipy's ``soft_l1``, linear beyond ``scale``) of each point's distance to the
outline placed there, so that a few points of something else (a corner rounded by the smoothing,
a speck) pull it little. Distances to the nearest edge are those to the nearest point of any
segment, so the fit is 2-D ICP with the matching done exactly at every step.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

from mechanics import transform_points, wrap_angle
from mechanics.se2 import inverse

__all__ = ["Fit", "distances", "register"]


@dataclass(frozen=True)
class Fit:
    """A registration: the ``pose`` (world ``(x, y, theta)``), each point's distance to the outline
    there (``distance``, m) and the Jacobian in the pose of each point's distance to the line of its
    nearest edge (``jacobian``, ``(n, 3)``): what an edge point measures is how far the edge is
    across it, not where the edge ends, since an edge may end in the image where something hides
    the rest of it (the pusher, the image's border). With only parallel edges seen, the pose along
    them is not fixed, and the Jacobian says so."""

    pose: np.ndarray
    distance: np.ndarray
    jacobian: np.ndarray

    def cost(self, scale: float) -> float:
        """The robust cost minimised (``soft_l1`` at ``scale``), per point."""
        return float(np.mean(2 * scale ** 2 * (np.sqrt(1 + (self.distance / scale) ** 2) - 1)))


def distances(points: np.ndarray, outline: np.ndarray, pose: np.ndarray) -> np.ndarray:
    """The distance of each world point of ``points`` (``(n, 2)``) to the closed polygon ``outline``
    (``(m, 2)``, its own frame) placed at ``pose``.

    >>> square = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=float)
    >>> distances(np.array([[0.5, -0.25], [1.5, 1.5], [0.5, 0.5]]), square, np.zeros(3)).round(6).tolist()
    [0.25, 0.707107, 0.5]
    """
    return _nearest(points, outline, pose)[0]


def _nearest(points: np.ndarray, outline: np.ndarray,
             pose: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """For each world point of ``points``, with ``outline`` at ``pose``: its distance to the outline,
    the gradient of that distance in the pose (``(n, 3)``), its nearest edge (an index) and how far
    along that edge's line from its first vertex it is (m; below 0 or beyond the edge's length: it is
    nearest a corner)."""
    theta = pose[2]
    local = transform_points(points, inverse(pose))
    a, b = outline, np.roll(outline, -1, axis=0)
    edge = b - a
    length = np.linalg.norm(edge, axis=1)
    along = np.einsum("nmk,mk->nm", local[:, None, :] - a, edge) / length ** 2
    gap = local[:, None, :] - (a + np.clip(along, 0.0, 1.0)[..., None] * edge)
    each = np.linalg.norm(gap, axis=-1)
    rows, edges = np.arange(len(points)), each.argmin(axis=1)
    distance = each[rows, edges]
    # The distance grows along the unit vector from the nearest point to the point (the outline's
    # frame; none for a point on the outline), which the pose moves by -R(-theta) per step of (x,
    # y) and by (y, -x) (the point in the outline's frame) per radian.
    unit = gap[rows, edges] / np.maximum(distance, 1e-300)[:, None]
    c, s = np.cos(theta), np.sin(theta)
    gradient = np.column_stack([-(unit[:, 0] * c - unit[:, 1] * s), -(unit[:, 0] * s + unit[:, 1] * c),
                                unit[:, 0] * local[:, 1] - unit[:, 1] * local[:, 0]])
    return distance, gradient, edges, along[rows, edges] * length[edges]


def register(points: np.ndarray, outline: np.ndarray, start: np.ndarray, scale: float) -> Fit:
    """The pose of ``outline`` nearest ``start`` through ``points`` (module docstring); ``scale``
    (m) is the distance beyond which a point counts as an outlier, about a pixel's footprint."""
    found = least_squares(lambda pose: _nearest(points, outline, pose)[0], np.asarray(start, dtype=float),
                          jac=lambda pose: _nearest(points, outline, pose)[1], loss="soft_l1", f_scale=scale,
                          x_scale=np.array([scale, scale, scale / max(float(np.abs(outline).max()), scale)]),
                          max_nfev=200)
    pose = np.array([*found.x[:2], float(wrap_angle(found.x[2]))])
    distance, jacobian, edges, at = _nearest(points, outline, pose)
    # Inside its edge's span a point's gradient is the edge's normal: it measures the edge across.
    # A point at a corner (within two scales of its edge's ends, or beyond them) says where the edge
    # ends, which may be where the rest of it is hidden: it measures nothing (Fit).
    length = np.linalg.norm(np.roll(outline, -1, axis=0) - outline, axis=1)[edges]
    jacobian[(at < 2 * scale) | (at > length - 2 * scale)] = 0.0
    return Fit(pose, distance, jacobian)
