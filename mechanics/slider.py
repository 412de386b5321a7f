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
        a, b = self.edge(i)
        d = (b - a) / np.linalg.norm(b - a)
        return self.winding * np.array([-d[1], d[0]])

    def is_pushable(self, i: int) -> bool:
        """True if edge ``i`` lies on the convex hull, so a flat face can touch all of it."""
        a, _ = self.edge(i)
        depth = (self.vertices - a) @ self.inward_normal(i)
        return bool(np.all(depth >= -1e-9 * self.radius))

    @cached_property
    def pushable_edges(self) -> tuple[int, ...]:
        """Indices of the edges on the convex hull."""
        return tuple(i for i in range(self.n) if self.is_pushable(i))

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
        """The part's rotational symmetries about its CF, as vertex shifts: each ``r`` in
        ``1..n-1`` such that a rotation about the CF carries every vertex ``k`` onto vertex
        ``k + r`` (mod ``n``), within ``1e-10`` of the radius. It carries edge ``k`` onto edge
        ``k + r`` with everything that acts on it (part, CF, a pusher centred on the edge), so
        the two edges' pushes are the same in each edge's own frame.

        >>> Slider([[-2, -1], [2, -1], [2, 1], [-2, 1]]).turns   # a rectangle: the half turn
        (2,)
        >>> Slider([[-1, -1], [1, -1], [1, 1], [-1, 1]]).turns   # a square: quarter turns too
        (1, 2, 3)
        >>> Slider([[-2, -1], [2, -1], [2, 1], [-2, 1]], cf=[0.5, 0]).turns  # the CF off the centre
        ()
        """
        rel = self.vertices - self.cf
        found = []
        for r in range(1, self.n):
            c, s = np.cos(self.turn_angle(r)), np.sin(self.turn_angle(r))
            turned = rel @ np.array([[c, s], [-s, c]])  # each row rotated
            if np.all(np.linalg.norm(turned - np.roll(rel, -r, axis=0), axis=1) <= 1e-10 * self.radius):
                found.append(r)
        return tuple(found)

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
