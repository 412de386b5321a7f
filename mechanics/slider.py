"""The slider: a rigid planar part sliding on the table (Lynch & Mason 1996, §1.1).

The slider is a simple polygon in its own frame (the *slider frame*) with a centre of friction
(CF). Support pressure is unknown but lies inside the polygon with its centre at the CF.
Edge ``i`` joins vertex ``i`` and vertex ``(i + 1) mod n``; a flat pusher can only touch an edge
along its length if the edge lies on the polygon's convex hull (it is *pushable*).
"""

from __future__ import annotations

from functools import cached_property

import numpy as np
import shapely
from numpy.typing import ArrayLike

__all__ = ["Slider"]


class Slider:
    """A simple polygon with a centre of friction.

    Parameters
    ----------
    vertices : (n, 2) array_like
        Simple polygon, either winding, possibly non-convex, metres, in the slider frame.
    cf : (2,) array_like, optional
        Centre of friction; strictly inside the polygon. Default: the area centroid.

    Raises
    ------
    ValueError
        With a one-line message if the polygon or the CF is not acceptable.

    Examples
    --------
    A 2 x 1 rectangle given clockwise; edge 0 is its bottom face:

    >>> s = Slider([[-1, 0], [-1, 1], [1, 1], [1, 0]])
    >>> s.cf.tolist(), s.area
    ([0.0, 0.5], 2.0)
    >>> s.edge(3).tolist(), s.inward_normal(3).tolist()
    ([[1.0, 0.0], [-1.0, 0.0]], [0.0, 1.0])
    >>> s.pushable_edges
    (0, 1, 2, 3)
    >>> Slider([[0, 0], [1, 1], [1, 0], [0, 1]])
    Traceback (most recent call last):
    ...
    ValueError: polygon is self-intersecting
    >>> Slider([[0, 0], [1, 0], [0, 1]], cf=[1, 1])
    Traceback (most recent call last):
    ...
    ValueError: cf [1.0, 1.0] is not inside the polygon
    """

    def __init__(self, vertices: ArrayLike, cf: ArrayLike | None = None):
        v = np.asarray(vertices, dtype=float)
        if v.ndim != 2 or v.shape[1] != 2:
            raise ValueError("vertices must be a list of [x, y] pairs")
        if len(v) < 3:
            raise ValueError(f"polygon needs at least 3 vertices, got {len(v)}")
        if not np.all(np.isfinite(v)):
            raise ValueError("vertices must be finite numbers")
        ring = shapely.LinearRing(v)
        polygon = shapely.Polygon(v)
        if not ring.is_simple:
            raise ValueError("polygon is self-intersecting")
        if polygon.area <= 1e-12 * max(1.0, float(np.ptp(v)) ** 2) or not polygon.is_valid:
            raise ValueError("polygon has zero area")
        self.vertices: np.ndarray = v
        self.polygon: shapely.Polygon = polygon
        # +1 if the vertices run counter-clockwise: the inward normal is then left of each edge.
        self.winding: int = 1 if ring.is_ccw else -1
        c = np.asarray(polygon.centroid.coords[0] if cf is None else cf, dtype=float) + 0.0  # no -0.0
        if c.shape != (2,) or not np.all(np.isfinite(c)):
            raise ValueError("cf must be a pair [x, y]")
        if not polygon.contains(shapely.Point(c)):
            raise ValueError(f"cf {c.tolist()} is not inside the polygon")
        self.cf: np.ndarray = c

    def __repr__(self) -> str:
        return f"Slider(vertices={self.vertices.tolist()}, cf={self.cf.tolist()})"

    @property
    def n(self) -> int:
        """Number of vertices (and edges)."""
        return len(self.vertices)

    @property
    def area(self) -> float:
        return float(self.polygon.area)

    @cached_property
    def radius(self) -> float:
        """Distance from the CF to the farthest point of the part (``r`` of procedure STABLE)."""
        return float(np.max(np.linalg.norm(self.vertices - self.cf, axis=1)))

    def _check_edge(self, i: int) -> int:
        if not (isinstance(i, (int, np.integer)) and 0 <= i < self.n):
            raise ValueError(f"edge index {i!r} is not in 0..{self.n - 1}")
        return int(i)

    def edge(self, i: int) -> np.ndarray:
        """End points ``[[ax, ay], [bx, by]]`` of edge ``i``, in vertex order."""
        i = self._check_edge(i)
        return np.array([self.vertices[i], self.vertices[(i + 1) % self.n]])

    def inward_normal(self, i: int) -> np.ndarray:
        """Unit normal of edge ``i`` pointing into the part: the direction a pusher pushes it."""
        return self._inward_normals[self._check_edge(i)].copy()

    @cached_property
    def _inward_normals(self) -> np.ndarray:
        # Every edge's at once: a part of a hundred thousand edges (a circle from CAD) asks for all.
        d = np.roll(self.vertices, -1, axis=0) - self.vertices
        d /= np.sqrt(d[:, None, :] @ d[:, :, None])[:, 0]  # each row's dot, as norm() of one edge rounds it
        return self.winding * np.column_stack([-d[:, 1], d[:, 0]])

    def is_pushable(self, i: int) -> bool:
        """True if edge ``i`` lies on the convex hull, so a flat face can touch all of it."""
        return bool(self._on_hull[self._check_edge(i)])

    @cached_property
    def pushable_edges(self) -> tuple[int, ...]:
        """Indices of the edges on the convex hull."""
        return tuple(np.flatnonzero(self._on_hull).tolist())

    @cached_property
    def _on_hull(self) -> np.ndarray:
        # Edge i is on the hull when no vertex lies beyond its line (depth below -1e-9 of the radius);
        # the deepest vertex is the hull's farthest along the outward normal, found in O(log n).
        return -self.extent(-self._inward_normals, self.vertices) >= -1e-9 * self.radius

    @property
    def hull(self) -> np.ndarray:
        """The vertices of the part's convex hull (some of the part's, exactly), counter-clockwise,
        those exactly on a line through their neighbours left out: where any convex function of
        position (a point's speed, its distance to a wall) peaks over the part. Side ``j`` joins
        vertex ``j`` to vertex ``j + 1``; the sides' directions ascend from the first, the one
        nearest the x axis's (angle 0) counter-clockwise.

        >>> Slider([[0, 2], [0, 1], [0, 0], [2, 0], [1, 1], [2, 2]]).hull.tolist()  # a notch on the right
        [[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]]
        """
        return self._hull_sides[0]

    @cached_property
    def _hull_sides(self) -> tuple[np.ndarray, np.ndarray]:
        """:attr:`hull`, and the angles of its sides' directions in ``[0, 2 pi)``, ascending."""
        ring = shapely.orient_polygons(shapely.convex_hull(shapely.multipoints(self.vertices))).exterior
        hull = np.asarray(ring.coords)[:-1]
        side = np.roll(hull, -1, axis=0) - hull
        angles = np.arctan2(side[:, 1], side[:, 0]) % (2 * np.pi)
        first = int(np.argmin(angles))
        return np.roll(hull, -first, axis=0), np.roll(angles, -first)

    def _sides_near(self, directions: np.ndarray) -> np.ndarray:
        """For each of ``directions`` (shape ``(..., 2)``), three consecutive hull indices: the first
        side that points at least a quarter turn left of it, whose first vertex reaches farthest
        along it, and the two around it (against rounding of the angles). O(log n) a direction."""
        angles = self._hull_sides[1]
        quarter_left = (np.arctan2(directions[..., 1], directions[..., 0]) + np.pi / 2) % (2 * np.pi)
        return (np.searchsorted(angles, quarter_left)[..., None] + np.arange(-1, 2)) % len(angles)

    def extent(self, directions: ArrayLike, origin: ArrayLike = (0.0, 0.0)) -> np.ndarray:
        """How far the part reaches along each of ``directions`` (shape ``(..., 2)``) from
        ``origin`` (broadcast with them): the largest ``(v - origin) . d`` over its vertices
        ``v``, found on the hull in O(log n) per direction instead of over all n vertices.

        >>> s = Slider([[0, 0], [2, 0], [1, 1], [2, 2], [0, 2], [0, 1]])
        >>> s.extent([[1, 0], [-1, 0], [1, 1], [0, -1]]).tolist()
        [2.0, 0.0, 4.0, 0.0]
        >>> s.extent([1, 0], origin=[2, 5]).tolist()
        0.0
        """
        d = np.asarray(directions, dtype=float)
        candidates = self.hull[self._sides_near(d)] - np.asarray(origin, dtype=float)[..., None, :]
        return (candidates @ d[..., :, None])[..., 0].max(axis=-1)

    def hull_side(self, edge: int) -> int:
        """The side of :attr:`hull` (side ``j`` joins vertices ``j`` and ``j + 1``) that pushable
        edge ``edge`` lies on.

        >>> s = Slider([[0, 2], [0, 1], [0, 0], [2, 0], [1, 1], [2, 2]])
        >>> s.pushable_edges, [s.hull_side(e) for e in s.pushable_edges]
        ((0, 1, 2, 5), [3, 3, 0, 2])
        """
        e = self._check_edge(edge)
        # Counter-clockwise, the edge begins at its first vertex; clockwise, at its second.
        return int(self._hull_sides_of_vertices[e if self.winding > 0 else (e + 1) % self.n])

    @cached_property
    def _hull_sides_of_vertices(self) -> np.ndarray:
        """Per vertex, the hull side it begins, or lies on, counter-clockwise: the boundary visits
        the hull's vertices in the hull's order, so a vertex's side is that of the last hull
        vertex at or before it. (The hull's vertices are some of the part's, exactly.)"""
        index = {tuple(p): j for j, p in enumerate(self.hull.tolist())}
        ccw = np.arange(self.n) if self.winding > 0 else np.arange(self.n)[::-1]
        side = np.array([index.get(tuple(p), -1) for p in self.vertices[ccw].tolist()])
        last = np.maximum.accumulate(np.where(side >= 0, np.arange(self.n), -1))
        # Before the first hull vertex, the boundary is still on the side of the last one.
        last[last < 0] = np.flatnonzero(side >= 0)[-1]
        out = np.empty(self.n, dtype=int)
        out[ccw] = side[last]
        return out

    @cached_property
    def cf_depth(self) -> float:
        """Distance from the CF to the part's boundary: the radius of the largest disk about the
        CF that lies inside the part.

        >>> Slider([[-2, -1], [2, -1], [2, 1], [-2, 1]], cf=[0.5, 0]).cf_depth
        1.0
        """
        return float(self.polygon.exterior.distance(shapely.Point(self.cf)))

    @cached_property
    def turns(self) -> tuple[int, ...]:
        """The part's rotational symmetries about its CF, as vertex shifts: the multiples ``r``
        in ``1..n-1`` of the least shift ``d`` such that a rotation about the CF carries every
        vertex ``k`` onto vertex ``k + d`` (mod ``n``), within ``1e-10`` of the radius (the turn
        ``r`` is that rotation taken ``r / d`` times). It carries edge ``k`` onto edge ``k + r``
        with everything that acts on it (part, CF, a pusher centred on the edge), so the two
        edges' pushes are the same in each edge's own frame.

        >>> Slider([[-2, -1], [2, -1], [2, 1], [-2, 1]]).turns   # a rectangle: the half turn
        (2,)
        >>> Slider([[-1, -1], [1, -1], [1, 1], [-1, 1]]).turns   # a square: quarter turns too
        (1, 2, 3)
        >>> Slider([[-2, -1], [2, -1], [2, 1], [-2, 1]], cf=[0.5, 0]).turns  # the CF off the centre
        ()
        """
        # The turns are a group (two make a third), the multiples of the least, which divides n:
        # trying n's divisors costs n times their count, not n^2 (a circle from CAD has every turn).
        rel = self.vertices - self.cf
        for r in (r for r in range(1, self.n // 2 + 1) if self.n % r == 0):
            c, s = np.cos(self.turn_angle(r)), np.sin(self.turn_angle(r))
            turned = rel @ np.array([[c, s], [-s, c]])  # each row rotated
            if np.all(np.linalg.norm(turned - np.roll(rel, -r, axis=0), axis=1) <= 1e-10 * self.radius):
                return tuple(range(r, self.n, r))
        return ()

    def turn_angle(self, r: int) -> float:
        """The angle (radians, in ``[-pi, pi)``) of the rotation about the CF that carries vertex
        0 towards vertex ``r``: the angle of the turn ``r`` of :attr:`turns`.

        >>> round(Slider([[-1, -1], [1, -1], [1, 1], [-1, 1]]).turn_angle(1) / np.pi, 12)
        0.5
        """
        rel = self.vertices[[0, r % self.n]] - self.cf
        angle = np.arctan2(rel[1, 1], rel[1, 0]) - np.arctan2(rel[0, 1], rel[0, 0])
        return float((angle + np.pi) % (2 * np.pi) - np.pi)

    def contact(self, i: int, width: float | None = None) -> np.ndarray:
        """The central part of edge ``i`` of length ``min(width, edge length)`` a flat face touches.

        >>> Slider([[-1, 0], [1, 0], [1, 1], [-1, 1]]).contact(0, 0.5).tolist()
        [[-0.25, 0.0], [0.25, 0.0]]
        """
        a, b = self.edge(i)
        length = float(np.linalg.norm(b - a))
        if width is None or width >= length:
            return np.array([a, b])
        mid, d = (a + b) / 2, (b - a) / length
        return np.array([mid - d * width / 2, mid + d * width / 2])
