"""Support distributions over a part's footprint: uniform grids, random ones, and the extreme
two- and three-point distributions ("dipods", "tripods") that bound what an unknown pressure
distribution with a known CF can do (docs/mechanics.md, "Exact LP oracle": the distributions with centre at the CF
form a polytope whose vertices have at most three points).

Footprints are shapely polygons (``Slider.polygon``). Points on the footprint's boundary count as
inside it.
"""

from __future__ import annotations

import numpy as np
import shapely
from numpy.typing import ArrayLike
import scipy  # scipy.optimize is loaded on first use (0.3 s): planning without --verify never needs it

from .support import SupportDistribution

__all__ = ["dipod_supports", "grid_support", "random_support", "tripod_supports"]


def grid_support(footprint: shapely.Polygon, count: int = 100, cf: ArrayLike | None = None) -> SupportDistribution:
    """About ``count`` equal-weight points at the centres of a grid of cells over ``footprint``.

    The grid divides the bounding box into equal cells, so a rectangle's grid is centred on it.
    With ``cf``, the weights are moved to put the centre there (see :func:`random_support`).

    >>> s = grid_support(shapely.box(-1, 0, 1, 1), 8)
    >>> len(s.points), s.centre.round(12).tolist()
    (8, [0.0, 0.5])
    """
    minx, miny, maxx, maxy = footprint.bounds
    cell = np.sqrt(footprint.area / count)
    nx, ny = max(1, round((maxx - minx) / cell)), max(1, round((maxy - miny) / cell))
    xs = minx + (np.arange(nx) + 0.5) * (maxx - minx) / nx
    ys = miny + (np.arange(ny) + 0.5) * (maxy - miny) / ny
    points = np.array([(x, y) for x in xs for y in ys])
    points = points[shapely.contains_xy(footprint, points[:, 0], points[:, 1])]
    return _centred(points, np.ones(len(points)), cf)


def random_support(footprint: shapely.Polygon, count: int, rng: np.random.Generator,
                   cf: ArrayLike | None = None) -> SupportDistribution:
    """``count`` uniform random points in ``footprint`` with flat-Dirichlet random weights.

    With ``cf``, the weights become the distribution closest to them (least total change) whose
    centre is ``cf``: a linear program, so only a few weights change.

    >>> s = random_support(shapely.box(-1, 0, 1, 1), 50, np.random.default_rng(0), cf=[0.3, 0.4])
    >>> s.centre.round(9).tolist()
    [0.3, 0.4]
    """
    minx, miny, maxx, maxy = footprint.bounds
    points = np.empty((0, 2))
    while len(points) < count:
        batch = rng.uniform([minx, miny], [maxx, maxy], size=(2 * count, 2))
        points = np.vstack([points, batch[shapely.contains_xy(footprint, batch[:, 0], batch[:, 1])]])
    return _centred(points[:count], rng.dirichlet(np.ones(count)), cf)


def dipod_supports(footprint: shapely.Polygon, cf: ArrayLike, count: int = 8) -> list[SupportDistribution]:
    """``count`` two-point distributions with centre ``cf``, along lines through ``cf`` at evenly
    spaced angles, each point as far out on the footprint's boundary as it goes.

    >>> [(s.points.round(12) + 0.0).tolist() for s in dipod_supports(shapely.box(-1, 0, 1, 1), [0.0, 0.5], 2)]
    [[[1.0, 0.5], [-1.0, 0.5]], [[0.0, 1.0], [0.0, 0.0]]]
    """
    c = np.asarray(cf, dtype=float)
    reach = 2 * np.hypot(*np.subtract(footprint.bounds[2:], footprint.bounds[:2]))
    out = []
    for angle in np.pi * np.arange(count) / count:
        u = np.array([np.cos(angle), np.sin(angle)])
        a, b = _farthest_boundary(footprint, c, u, reach), _farthest_boundary(footprint, c, -u, reach)
        # Lever rule: the weights are inversely proportional to the distances to cf.
        out.append(SupportDistribution([a, b], [np.linalg.norm(b - c), np.linalg.norm(a - c)]))
    return out


def tripod_supports(footprint: shapely.Polygon, cf: ArrayLike, count: int,
                    rng: np.random.Generator) -> list[SupportDistribution]:
    """``count`` three-point distributions with centre ``cf``: random boundary points whose
    triangle contains ``cf`` (each weight at least 2 % of the total), barycentric weights.

    >>> [len(s.points) for s in tripod_supports(shapely.box(-1, 0, 1, 1), [0.2, 0.4], 3, np.random.default_rng(1))]
    [3, 3, 3]
    """
    c = np.asarray(cf, dtype=float)
    ring = footprint.exterior
    out = []
    while len(out) < count:
        corners = np.array([ring.interpolate(s).coords[0] for s in rng.uniform(0, ring.length, 3)])
        a = np.vstack([corners.T, np.ones(3)])
        if abs(np.linalg.det(a)) < 1e-12 * footprint.area:
            continue
        weights = np.linalg.solve(a, [*c, 1.0])
        if weights.min() >= 0.02:
            out.append(SupportDistribution(corners, weights))
    return out


def _farthest_boundary(footprint: shapely.Polygon, start: np.ndarray, u: np.ndarray, reach: float) -> np.ndarray:
    """The boundary point of ``footprint`` farthest from ``start`` along the ray of ``u``."""
    ray = shapely.LineString([start, start + reach * u])
    hits = shapely.get_coordinates(ray.intersection(footprint.exterior))
    return hits[np.argmax((hits - start) @ u)]


def _centred(points: np.ndarray, weights: np.ndarray, cf: ArrayLike | None) -> SupportDistribution:
    """The distribution of ``points``, weights moved (least L1 change) to put its centre at ``cf``."""
    w = weights / weights.sum()
    if cf is None:
        return SupportDistribution(points, w)
    c = np.asarray(cf, dtype=float)
    n = len(points)
    # Variables (w, e) with e >= |w - w0|: minimise sum(e), sum(w) = 1, sum(w x) = cf, w >= 0.
    eye = np.eye(n)
    a_eq = np.hstack([np.vstack([np.ones(n), points.T]), np.zeros((3, n))])
    a_ub = np.block([[eye, -eye], [-eye, -eye]])
    result = scipy.optimize.linprog(np.r_[np.zeros(n), np.ones(n)], A_ub=a_ub, b_ub=np.r_[w, -w], A_eq=a_eq,
                     b_eq=np.r_[1.0, c], bounds=(0, None), method="highs")
    if result.status != 0:
        raise ValueError(f"cf {c.tolist()} is not inside the convex hull of the support points")
    keep = result.x[:n] > 1e-12
    return SupportDistribution(points[keep], result.x[:n][keep])
