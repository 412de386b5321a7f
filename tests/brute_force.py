"""Test-only brute force for the multi-contact mechanics (Lynch 1992), written without ``mechanics``.

Everything here is re-derived from the paper: point velocities of a twist, the load a support
distribution needs (eqs. 1-2), explicit random support distributions with a given centroid,
composite cones by their generators (membership by non-negative least squares) and linear
programmes over dense point sets. Conventions: twist ``(vx, vy, omega)``, the velocity of ``x`` is
``(vx - omega y, vy + omega x)``, wrench ``(fx, fy, m)`` with the moment about the origin.
"""

from __future__ import annotations

import numpy as np
import shapely
from scipy.optimize import linprog, nnls


def cross(a, b):
    a, b = np.asarray(a, float), np.asarray(b, float)
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def velocity(twist, x):
    t, x = np.asarray(twist, float), np.asarray(x, float)
    return np.stack([t[0] - t[2] * x[..., 1], t[1] + t[2] * x[..., 0]], axis=-1)


def twist_about(c, sense):
    """Rotation about ``c``: every point turns about it, so the origin moves with ``sense k x (0 - c)``."""
    return np.array([sense * c[1], -sense * c[0], float(sense)])


def loads(twist, x):
    """Per unit weight at ``x``, the wrench the pusher supplies: (unit velocity, x cross it)."""
    v = velocity(twist, x)
    u = v / np.linalg.norm(v, axis=-1, keepdims=True)
    return np.concatenate([u, cross(x, u)[..., None]], axis=-1)


def wrench(p, f):
    p, f = np.asarray(p, float), np.asarray(f, float)
    return np.concatenate([f, cross(p, f)[..., None]], axis=-1)


def in_cone(w, generators, tol=1e-7):
    """Whether ``w`` is a non-negative combination of the rows of ``generators`` (relative tol)."""
    w = np.asarray(w, float)
    g = np.asarray(generators, float).reshape(-1, 3)
    if len(g) == 0:
        return bool(np.linalg.norm(w) <= tol)
    _, residual = nnls(g.T, w)
    return bool(residual <= tol * max(1.0, np.linalg.norm(w)))


def friction_generators(points, normals, mu, mode):
    """Generators of the composite cone from the paper's §3.1, re-derived: s both edges, r the
    edge tilted against +t (n - mu t), l the other, f none; t = (n_y, -n_x)."""
    out = []
    for p, n, label in zip(points, normals, mode):
        n = np.asarray(n, float) / np.linalg.norm(n)
        t = np.array([n[1], -n[0]])
        if label in "sr":
            out.append(wrench(p, n - mu * t))
        if label in "sl":
            out.append(wrench(p, n + mu * t))
    return np.array(out).reshape(-1, 3)


# ----------------------------------------------------------------------------------------------
# Support regions and distributions


def points_in_region(rng, region: shapely.Polygon, n, boundary=0):
    """``n`` uniform points in ``region``, and with ``boundary`` its vertices and that many uniform
    points on its boundary."""
    x0, y0, x1, y1 = region.bounds
    out = np.zeros((0, 2))
    while len(out) < n:
        p = rng.uniform([x0, y0], [x1, y1], (4 * n, 2))
        out = np.vstack([out, p[shapely.contains_xy(region, p[:, 0], p[:, 1])]])
    if not boundary:
        return out[:n]
    ring = region.exterior
    edge = shapely.get_coordinates(shapely.line_interpolate_point(ring, rng.random(boundary), normalized=True))
    return np.vstack([out[:n], edge, shapely.get_coordinates(ring)[:-1]])


def disk_region(cf, r):
    """The disk as a fine polygon *inside* it (so its points are admissible)."""
    a = np.linspace(0, 2 * np.pi, 720, endpoint=False)
    return shapely.Polygon(np.asarray(cf) + r * np.stack([np.cos(a), np.sin(a)], 1))


def random_distributions(rng, region, cf, count, size=12):
    """Explicit admissible distributions (points in ``region``, weights >= 0 summing to 1, centroid
    ``cf``): vertices of the LP over random points (dipods, tripods: the adversaries) and mixtures."""
    out = []
    while len(out) < count:
        x = points_in_region(rng, region, size, boundary=size // 2)
        a_eq = np.vstack([np.ones(len(x)), x.T])
        res = linprog(rng.normal(size=len(x)), A_eq=a_eq, b_eq=np.r_[1.0, cf], bounds=(0, None), method="highs")
        if res.status != 0:
            continue
        w = res.x
        if rng.random() < 0.5:  # a spread-out one: mix with the uniform-ish solution
            res2 = linprog(np.zeros(len(x)), A_eq=a_eq, b_eq=np.r_[1.0, cf], bounds=(0.01 / len(x), None), method="highs")
            if res2.status == 0:
                w = 0.5 * w + 0.5 * res2.x
        out.append((x, w))
    return out


def load_of(twist, x, w):
    return w @ loads(twist, x)


def dense_support_max(twist, x, cf, y):
    """max over distributions on the points ``x`` with centroid ``cf`` of ``y . load`` (primal LP).

    HiGHS's default choice of algorithm now and then ends with an unknown model status on these
    degenerate LPs; the oracle then asks its dual simplex, then its interior point method."""
    g = loads(twist, x) @ np.asarray(y, float)
    for method in ("highs", "highs-ds", "highs-ipm"):
        res = linprog(-g, A_eq=np.vstack([np.ones(len(x)), x.T]), b_eq=np.r_[1.0, cf], bounds=(0, None),
                      method=method)
        if res.status == 0:
            return -res.fun
    raise AssertionError(f"no HiGHS method solved the oracle's LP: {res.message}")


def dense_some_in_cone(twist, x, cf, generators):
    """Whether some distribution on ``x`` with centroid ``cf`` has its load in cone(generators)."""
    g = loads(twist, x)
    k, m = len(x), len(generators)
    a_eq = np.block([[g.T, -np.asarray(generators).T], [np.ones((1, k)), np.zeros((1, m))], [x.T, np.zeros((2, m))]])
    res = linprog(np.zeros(k + m), A_eq=a_eq, b_eq=np.r_[0, 0, 0, 1.0, cf], bounds=(0, None), method="highs")
    return res.status == 0


# ----------------------------------------------------------------------------------------------
# Rigid motions and reflections


def isometry(angle=0.0, shift=(0.0, 0.0), mirror=False):
    c, s = np.cos(angle), np.sin(angle)
    a = np.array([[c, -s], [s, c]]) @ (np.diag([-1.0, 1.0]) if mirror else np.eye(2))
    return a, np.asarray(shift, float)


def move_points(p, a, b):
    return np.asarray(p, float) @ a.T + b


def move_twist(twist, a, b):
    """The same motion seen after ``x -> a x + b``: velocities map by ``a``; recover the twist
    from the velocities of two points."""
    p = np.array([[0.0, 0.0], [1.0, 0.0]])
    v = velocity(twist, (p - b) @ a) @ a.T  # velocities at the preimages, mapped
    omega = cross(p[1] - p[0], v[1] - v[0])
    return np.array([v[0, 0], v[0, 1], omega])
