"""Test-only replay of a plan JSON: SE(2) by matrix exponential, geometry by shapely.

Shares nothing with ``planner``: the pusher body, the body motion and the collision test are
written out again here from the README's definitions.
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


def angle_diff(a, b) -> float:
    return abs((a - b + math.pi) % (2 * math.pi) - math.pi)


def pusher_body(vertices, edge, width, depth) -> np.ndarray:
    """The width x depth rectangle behind the face centred on the edge, outside the part."""
    v = np.asarray(vertices, float)
    a, b = v[edge], v[(edge + 1) % len(v)]
    d = (b - a) / np.linalg.norm(b - a)
    out = np.array([d[1], -d[0]])  # right of the edge direction
    if shapely.Polygon(v).contains(shapely.Point((a + b) / 2 + out * 1e-6)):
        out = -out
    mid = (a + b) / 2
    return np.array([mid - d * width / 2, mid + d * width / 2, mid + d * width / 2 + out * depth,
                     mid - d * width / 2 + out * depth])


def place(points, q) -> shapely.Polygon:
    m = pose_matrix(q)
    p = np.asarray(points, float)
    return shapely.Polygon(p @ m[:2, :2].T + m[:2, 2])


def max_point_speed(points, twist) -> float:
    vx, vy, w = twist
    p = np.asarray(points, float)
    return float(np.max(np.hypot(vx - w * p[:, 1], vy + w * p[:, 0])))
