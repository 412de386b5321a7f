"""Test-only replay of a plan JSON: SE(2) by matrix exponential, geometry by shapely.

Shares nothing with ``planner``: the pusher body and its frame, the body motion, the pusher's
interpolation during a transit and the collision test are written out again here from the
README's definitions.
"""

from __future__ import annotations

import math

import numpy as np
import shapely
from scipy.linalg import expm


def pose_matrix(q) -> np.ndarray:
    x, y, th = q
    return np.array([[math.cos(th), -math.sin(th), x], [math.sin(th), math.cos(th), y], [0, 0, 1.0]])


def matrix_pose(m) -> np.ndarray:
    return np.array([m[0, 2], m[1, 2], math.atan2(m[1, 0], m[0, 0])])


def advance(q, twist, t) -> np.ndarray:
    """q * exp([twist] t) with the 3x3 matrix exponential."""
    vx, vy, w = twist
    xi = np.array([[0.0, -w, vx], [w, 0.0, vy], [0.0, 0.0, 0.0]])
    return matrix_pose(pose_matrix(q) @ expm(xi * t))


def wrap(angle) -> float:
    """``angle`` in [-pi, pi)."""
    return (angle + math.pi) % (2 * math.pi) - math.pi


def angle_diff(a, b) -> float:
    return abs(wrap(a - b))


def transform(points, q) -> np.ndarray:
    """Points given in the frame at pose ``q``, in the frame ``q`` is given in."""
    m = pose_matrix(q)
    return np.asarray(points, float) @ m[:2, :2].T + m[:2, 2]


def place(points, q) -> shapely.Polygon:
    return shapely.Polygon(transform(points, q))


def pusher_rectangle(width, depth) -> np.ndarray:
    """The pusher in its own frame (README): origin at the middle of the pushing face, x along the
    push direction, so the body is x in [-depth, 0], y in [-width/2, width/2]."""
    return np.array([[-depth, -width / 2], [0.0, -width / 2], [0.0, width / 2], [-depth, width / 2]])


def edge_pose(vertices, edge) -> np.ndarray:
    """Slider-frame pose of the pusher frame flush on ``edge``: origin at the edge's midpoint, x
    along the inward normal (found by probing which side of the midpoint is inside the polygon)."""
    v = np.asarray(vertices, float)
    a, b = v[edge], v[(edge + 1) % len(v)]
    d = (b - a) / np.linalg.norm(b - a)
    inward = np.array([-d[1], d[0]])  # left of the edge direction
    mid = (a + b) / 2
    if not shapely.Polygon(v).contains(shapely.Point(mid + inward * 1e-6)):
        inward = -inward
    return np.array([*mid, math.atan2(inward[1], inward[0])])


def compose(a, b) -> np.ndarray:
    """The pose ``b`` (given in the frame at ``a``) in the frame ``a`` is given in."""
    return matrix_pose(pose_matrix(a) @ pose_matrix(b))


def flush_pose(vertices, edge, part_pose) -> np.ndarray:
    """World pose of the pusher frame in contact with ``edge`` of the part at ``part_pose``."""
    return compose(part_pose, edge_pose(vertices, edge))


def pusher_body(vertices, edge, width, depth) -> np.ndarray:
    """The width x depth rectangle behind the face centred on the edge, outside the part (slider frame)."""
    return transform(pusher_rectangle(width, depth), edge_pose(vertices, edge))


def interpolate(p, q, s) -> np.ndarray:
    """The pose a fraction ``s`` of the way from ``p`` to ``q``: (x, y, theta) linearly, theta the
    shorter way round."""
    p, q = np.asarray(p, float), np.asarray(q, float)
    return p + s * np.array([q[0] - p[0], q[1] - p[1], wrap(q[2] - p[2])])


def max_point_speed(points, twist) -> float:
    vx, vy, w = twist
    p = np.asarray(points, float)
    return float(np.max(np.hypot(vx - w * p[:, 1], vy + w * p[:, 0])))
