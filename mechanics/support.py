"""Support friction of a sliding part (Lynch 1992, §3.2; docs/mechanics.md, "Effective centre of friction").

**Known pressure.** A support point ``x`` of weight ``w`` (pressure times area) moving with
velocity ``v(x)`` feels Coulomb friction ``-mu_s w v/|v|``. For a rotation about ``c`` with sense
``sigma`` this is the paper's eq. (1) ``f = -mu_s sigma k x sum w (x - c)/|x - c|`` and eq. (2)
``m = -mu_s sigma sum w |x - c|`` (moment about ``c``). The same wrench comes from one support
point, the *effective centre of friction* ``CF_eff = c + |m| d / |d|^2`` with
``d = sum w (x - c)/|x - c|`` and ``|m| = sum w |x - c|`` (eqs. 3-6, ``mu_s`` cancels).

**Unknown pressure.** Only the centre of friction (CF) and a region ``S`` holding the support are
known: the admissible distributions are the probability measures on ``S`` with centroid at the CF.
Two models of ``S``:

* ``disk``: the disk of radius ``r`` about the CF holding the part (the paper's, after Peshkin and
  Sanderson);
* ``footprint``: the part's own polygon (tighter and physically exact; inside the disk).

Quasi-statically the pusher supplies the *load* ``L = sum w g(x)``, ``g(x) = (v^, x x v^)`` with
``v^`` the unit velocity of ``x``: linear in the distribution. For one twist the set of possible
loads is convex, and every question about it is a linear programme over distributions. Here the
distributions are represented by sample points of ``S`` (a polar grid for the disk, a square
grid clipped to the polygon for the footprint), and *certified* by cells covering ``S``:

``sup over admissible distributions of y . L  <=  sup over x in S of y . g(x) + lam . (x - CF)``

for every multiplier ``lam`` (the centroid constraint's Lagrange multiplier: the right side is
the LP's dual). :meth:`SupportLoads.upper_bound` bounds that supremum rigorously, cell by cell
(second-order: the Hessian of ``y . g`` is bounded below away from the COR), so a discrete LP's
dual solution gives a guaranteed bound on the continuum (see :mod:`mechanics.force_status`).

**An uncertain CF** (Lynch 1992, §6): with ``cf_radius = rho > 0`` the distribution's centre may
be anywhere in the disk of radius ``rho`` about the nominal CF. A distribution centred at ``c``
then has ``y . L = integral of psi d mu - lam . (c - CF)``, so the bound above grows by exactly
``rho |lam|``: the centroid constraint's uncertainty is one more linear term, and a P verdict
holds for every CF in the disk. Sample distributions keep their centre in a 32-gon inscribed
in the disk, so they stay admissible.

A support point exactly at the COR does not slide: its static friction may point anywhere (with
at most the sliding magnitude), the limit of pressure concentrated near the COR. The samples
therefore include the COR when it lies in ``S``: with the friction direction that suits the
question best in a support function's LP, with a fan of directions in :meth:`LoadBatch.minimax`.

These LPs have a handful of constraints (total weight, centroid, and for the minimax one per
row of the cone), so they are solved by a simplex method run on many twists and directions at
once in numpy (:class:`LoadBatch`, :func:`~mechanics.simplex.batched_simplex`); HiGHS is only a
fallback.
"""

from __future__ import annotations

import copy
import itertools
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import shapely
from numpy.typing import ArrayLike

from .simplex import batched_simplex
from .slider import Slider
from .twist import point_velocity, twist_to_cor
from .wrenches import point_wrench

__all__ = ["LoadBatch", "SupportCells", "SupportLoads", "SupportModel", "effective_cf", "support_friction", "unit_loads"]

#: Friction directions tried at a support point on the COR (the LP mixes them).
COR_DIRECTIONS = 32
#: Corners of the polygon inscribed in the CF's uncertainty disk that sample centres may reach.
CF_DIRECTIONS = 32
#: Twists whose optimal bases a support model keeps per level and set of directions, and how many
#: such sets (:meth:`SupportModel.warm_bases`).
WARM_TWISTS = 512
WARM_DIRECTIONS = 16
#: Pivots of a warm-started support LP before it starts again from the cold start (a warm basis
#: can lead into a degenerate vertex the cold one avoids: a sample at the CF).
WARM_LIMIT = 32


def unit_loads(twist: ArrayLike, points: ArrayLike) -> np.ndarray:
    """Load ``g(x) = (v^, x x v^)`` (shape ``(..., 3)``) per unit support weight at each point.

    The wrench the pusher must apply to balance the friction of a unit weight at ``x`` when the
    part moves with ``twist``; zero at a point that does not move (the COR).

    >>> unit_loads([0.0, 0.0, 1.0], [[2.0, 0.0], [0.0, 0.0]]).tolist()  # CCW about the origin
    [[0.0, 1.0, 2.0], [0.0, 0.0, 0.0]]
    """
    x = np.asarray(points, dtype=float)
    v = point_velocity(twist, x)
    speed = np.linalg.norm(v, axis=-1, keepdims=True)
    unit = np.divide(v, speed, out=np.zeros_like(v), where=speed > 0)
    return point_wrench(x, unit)


def support_friction(twist: ArrayLike, points: ArrayLike, weights: ArrayLike, mu_s: float = 1.0) -> np.ndarray:
    """Friction wrench ``(fx, fy, m)`` of the support on the part (eqs. 1-2, moment about the origin).

    Examples
    --------
    CCW about the origin, one point ``(2, 0)`` of weight 1, ``mu_s = 0.5``: the point moves up,
    friction pulls down with 0.5 and turns CW with ``0.5 * 2`` about the COR (eq. 2).

    >>> support_friction([0.0, 0.0, 1.0], [[2.0, 0.0]], [1.0], mu_s=0.5).tolist()
    [0.0, -0.5, -1.0]
    """
    w = np.asarray(weights, dtype=float)
    return -mu_s * (w @ unit_loads(twist, points)) + 0.0  # no -0.0


def effective_cf(twist: ArrayLike, points: ArrayLike, weights: ArrayLike) -> np.ndarray:
    """Effective centre of friction of a known distribution (eqs. 3-6).

    The single support point reproducing the friction wrench; the centroid for a translation and
    ``(inf, inf)`` when the friction is a pure moment.

    Examples
    --------
    CCW about the origin, unit weights at ``(1, 0)`` and ``(0, 1)``: ``d = (1, 1)``, ``|m| = 2``,
    so ``CF_eff = 2 (1, 1) / 2 = (1, 1)``, farther from the COR than the CF ``(0.5, 0.5)``.

    >>> effective_cf([0.0, 0.0, 1.0], [[1.0, 0.0], [0.0, 1.0]], [1.0, 1.0]).tolist()
    [1.0, 1.0]
    >>> effective_cf([1.0, 0.0, 0.0], [[1.0, 0.0], [0.0, 1.0]], [1.0, 3.0]).tolist()
    [0.25, 0.75]
    """
    x = np.asarray(points, dtype=float)
    w = np.asarray(weights, dtype=float)
    cor, sense = twist_to_cor(twist)
    if sense == 0:
        return w @ x / w.sum()
    rel = x - cor
    dist = np.linalg.norm(rel, axis=1)
    d = w @ np.divide(rel, dist[:, None], out=np.zeros_like(rel), where=dist[:, None] > 0)
    m = w @ dist
    dd = float(d @ d)
    if dd <= 1e-300:
        return np.array([np.inf, np.inf])
    return cor + m * d / dd


@dataclass(frozen=True)
class SupportCells:
    """Sample points of a support region and convex cells covering it.

    ``points`` (N, 2) lie in the region (the LP's support points). Cell ``i`` is the convex hull of
    ``nodes[cells[i]]``; the cells together cover the region, and every node inside the region is a
    sample point. ``anchors`` and ``reach``: a centre per cell and its largest distance to the
    cell's vertices.
    """

    points: np.ndarray
    nodes: np.ndarray
    cells: np.ndarray
    anchors: np.ndarray
    reach: np.ndarray

    @classmethod
    def from_polygons(cls, polygons: list[np.ndarray], inside: Callable[[np.ndarray], np.ndarray]) -> SupportCells:
        """Cells from convex vertex rings; ``inside(points)`` says which nodes are samples."""
        ring = np.concatenate(polygons)
        nodes, index = np.unique(np.round(ring, 12), axis=0, return_inverse=True)
        index = index.ravel()
        counts = np.array([len(p) for p in polygons])
        start = np.cumsum(counts) - counts
        # Pad each cell with its first vertex: repeats do not change a maximum over vertices.
        column = np.arange(counts.max())
        cells = index[start[:, None] + np.where(column[None] < counts[:, None], column[None], 0)]
        anchors = np.add.reduceat(ring, start, axis=0) / counts[:, None]
        reach = np.linalg.norm(nodes[cells] - anchors[:, None], axis=2).max(axis=1)
        return cls(nodes[inside(nodes)], nodes, cells, anchors, reach)


def _centre_directions() -> np.ndarray:
    """Corners of the unit ``CF_DIRECTIONS``-gon: where sample distributions may put their centre
    (times the CF's uncertainty radius)."""
    angle = 2 * np.pi * np.arange(CF_DIRECTIONS) / CF_DIRECTIONS
    return np.stack([np.cos(angle), np.sin(angle)], axis=1)


def _triangle_around(x: np.ndarray, target: np.ndarray) -> np.ndarray:
    """Indices of three of the points ``x`` whose triangle holds ``target`` (a feasible simplex
    basis): among at most 16 corners of their hull, evenly spread, the one whose smallest
    barycentric weight of ``target`` is largest; failing that (``target`` near a side of the hull
    they cut off), the same among the triangles fanned out from the first corner, which cover the
    hull. Time and memory grow with the points, not their square (a part drawn as a circle of a
    hundred thousand vertices has as many corners).

    >>> sorted(_triangle_around(np.array([[0.0, 0], [2, 0], [0, 2], [0.5, 0.5]]), np.array([0.5, 0.5])).tolist())
    [0, 1, 2]
    """
    corners = shapely.points(np.asarray(shapely.MultiPoint(x).convex_hull.exterior.coords)[:-1])
    index = shapely.STRtree(shapely.points(x)).query_nearest(corners, all_matches=False)[1]  # each corner is a point
    spread = index[np.linspace(0, len(index), min(16, len(index)), endpoint=False).astype(int)]
    fan = np.column_stack([np.full(len(index) - 2, index[0]), index[1:-1], index[2:]])
    for triples in (np.array(list(itertools.combinations(spread, 3))), fan):
        m = np.stack([np.ones(triples.shape), x[triples, 0], x[triples, 1]], axis=1)  # columns: the corners
        ok = np.abs(np.linalg.det(m)) > 1e-12
        weights = np.linalg.solve(m[ok], np.broadcast_to(np.r_[1.0, target], (int(ok.sum()), 3))[..., None])[..., 0]
        best = int(np.argmax(weights.min(axis=1))) if len(weights) else 0
        if len(weights) and weights[best].min() >= -1e-12:
            return triples[ok][best]
    raise ValueError("the target lies outside the samples' hull")


def _disk_cells(cf: np.ndarray, radius: float, n: int) -> list[np.ndarray]:
    """Polar grid: ``n`` rings, sectors with arcs ``<= radius / n``; each sector's outer arc is
    replaced by its two tangents (apex outside the arc) so the cells cover the disk."""

    def at(r: float, angle: float) -> np.ndarray:
        return cf + r * np.array([np.cos(angle), np.sin(angle)])

    h = radius / n
    out = []
    for i in range(n):
        r0, r1 = i * h, (i + 1) * h
        m = max(6, int(np.ceil(2 * np.pi * (i + 1))))
        half = np.pi / m
        for a0 in 2 * half * np.arange(m):
            a1 = a0 + 2 * half
            inner = [at(r0, a0)] if i == 0 else [at(r0, a1), at(r0, a0)]
            out.append(np.array([*inner, at(r1, a0), at(r1 / np.cos(half), a0 + half), at(r1, a1)]))
    return out


def _footprint_cells(polygon: shapely.Polygon, cf: np.ndarray, h: float,
                     squares: np.ndarray | None = None) -> list[np.ndarray]:
    """Squares of side ``h`` (grid through the CF) clipped to the polygon, as convex hulls: all
    those over the polygon, or the ``squares`` given by their indices ``(i, j)`` (``n, 2``; square
    ``(i, j)`` has its lower left corner at ``cf + (i, j) h``)."""
    if squares is None:
        x0, y0, x1, y1 = polygon.bounds
        i = np.arange(np.floor((x0 - cf[0]) / h), np.ceil((x1 - cf[0]) / h))
        j = np.arange(np.floor((y0 - cf[1]) / h), np.ceil((y1 - cf[1]) / h))
        ii, jj = (a.ravel() for a in np.meshgrid(i, j))
    else:
        ii, jj = np.asarray(squares, dtype=float).T
    boxes = shapely.box(cf[0] + ii * h, cf[1] + jj * h, cf[0] + (ii + 1) * h, cf[1] + (jj + 1) * h)
    shapely.prepare(polygon)
    inside = shapely.contains_properly(polygon, boxes)  # whole squares: nothing to clip
    edge = ~inside & shapely.intersects(polygon, boxes)
    pieces = boxes.copy()
    pieces[edge] = shapely.convex_hull(shapely.intersection(boxes[edge], polygon))
    pieces = pieces[inside | edge]
    pieces = pieces[shapely.area(pieces) > 1e-12 * h * h]
    coords, which = shapely.get_coordinates(shapely.get_exterior_ring(pieces), return_index=True)
    rings = np.split(coords, np.flatnonzero(np.diff(which)) + 1)
    return [ring[:-1] for ring in rings]


class SupportModel:
    """What is known about the support: the CF and a region holding every admissible distribution.

    Build with :meth:`disk`, :meth:`footprint` or :meth:`of_slider`. ``kind`` is ``'disk'`` or
    ``'footprint'``, ``radius`` the CF's distance to the farthest support point, ``polygon`` the
    footprint (``None`` for the disk). ``resolution`` is the number of grid cells across the radius
    at refinement level 0; level ``k`` has ``2**k`` times more. ``cf_radius`` is the radius of the
    CF's uncertainty disk (module docstring; 0: the CF is known).

    Examples
    --------
    >>> block = Slider([[-1, 0], [1, 0], [1, 1], [-1, 1]])
    >>> disk = SupportModel.of_slider(block, "disk")
    >>> disk.kind, disk.cf.tolist(), round(disk.radius, 6)
    ('disk', [0.0, 0.5], 1.118034)
    >>> SupportModel.of_slider(block, "footprint").covers([[0.9, 0.9], [0.0, 1.1]]).tolist()
    [True, False]
    """

    def __init__(self, kind: str, cf: ArrayLike, radius: float, polygon: shapely.Polygon | None, resolution: int,
                 cf_radius: float = 0.0):
        if not cf_radius >= 0:
            raise ValueError(f"cf_radius must be >= 0, got {cf_radius}")
        self.cf_radius = float(cf_radius)
        self.kind = kind
        self.cf = np.asarray(cf, dtype=float)
        self.radius = float(radius)
        self.polygon = polygon
        self.resolution = int(resolution)
        self._cells: dict[int, SupportCells] = {}
        self._lp: dict[int, tuple[np.ndarray, np.ndarray, np.ndarray]] = {}
        self._triangle: dict[int, np.ndarray] = {}
        self._warm: dict[tuple[int, bytes], tuple[np.ndarray, np.ndarray]] = {}
        self._lift: dict[int, np.ndarray] = {}

    def __repr__(self) -> str:
        extra = f", cf_radius={self.cf_radius:g}" if self.cf_radius else ""
        return f"SupportModel({self.kind!r}, cf={self.cf.tolist()}, radius={self.radius:g}{extra})"

    @classmethod
    def disk(cls, cf: ArrayLike, radius: float, resolution: int = 6, cf_radius: float = 0.0) -> SupportModel:
        """Any distribution in the disk of ``radius`` about ``cf``, centred at ``cf``."""
        if not radius > 0:
            raise ValueError(f"radius must be > 0, got {radius}")
        c = np.asarray(cf, dtype=float)
        return cls("disk", c, radius, None, resolution, cf_radius)

    @classmethod
    def footprint(cls, vertices: ArrayLike, cf: ArrayLike, resolution: int = 6, cf_radius: float = 0.0) -> SupportModel:
        """Any distribution on the polygon ``vertices``, centred at ``cf`` (inside it)."""
        polygon = shapely.Polygon(np.asarray(vertices, dtype=float))
        c = np.asarray(cf, dtype=float)
        if not (polygon.is_valid and polygon.contains(shapely.Point(c))):
            raise ValueError("the footprint must be a valid polygon with the CF inside")
        radius = float(np.max(np.linalg.norm(np.asarray(polygon.exterior.coords) - c, axis=1)))
        return cls("footprint", c, radius, polygon, resolution, cf_radius)

    @classmethod
    def of_slider(cls, slider: Slider, kind: str = "footprint", resolution: int = 6,
                  cf_radius: float = 0.0) -> SupportModel:
        """The ``disk`` (radius :attr:`Slider.radius`) or ``footprint`` model of a slider."""
        if kind == "disk":
            return cls.disk(slider.cf, slider.radius, resolution, cf_radius)
        if kind == "footprint":
            return cls.footprint(slider.vertices, slider.cf, resolution, cf_radius)
        raise ValueError(f"support model must be 'disk' or 'footprint', got {kind!r}")

    def with_cf_radius(self, cf_radius: float) -> SupportModel:
        """The same support with the CF known only within ``cf_radius``, sharing this model's
        sample cells (they do not depend on the CF's uncertainty, and building the finer levels
        costs more than a batch of LPs); its LPs and warm bases are its own.

        >>> block = SupportModel.of_slider(Slider([[-1, 0], [1, 0], [1, 1], [-1, 1]]))
        >>> loose = block.with_cf_radius(0.1)
        >>> loose.cf_radius, loose.cells(1) is block.cells(1)
        (0.1, True)
        """
        other = SupportModel(self.kind, self.cf, self.radius, self.polygon, self.resolution, cf_radius)
        other._cells, other._triangle = self._cells, self._triangle
        return other

    def covers(self, points: ArrayLike) -> np.ndarray:
        """Whether each point lies in the support region (boundary included)."""
        p = np.asarray(points, dtype=float)
        tol = 1e-9 * self.radius
        if self.kind == "disk":
            return np.linalg.norm(p - self.cf, axis=-1) <= self.radius + tol
        return shapely.dwithin(self.polygon, shapely.points(p), tol)

    def cells(self, level: int = 0) -> SupportCells:
        """Samples and covering cells at refinement ``level`` (cached)."""
        if level not in self._cells:
            n = self.resolution * 2**level
            polygons = (_disk_cells(self.cf, self.radius, n) if self.kind == "disk"
                        else _footprint_cells(self.polygon, self.cf, self.radius / n))
            self._cells[level] = SupportCells.from_polygons(polygons, self.covers)
        return self._cells[level]

    def loads(self, twist: ArrayLike, level: int = 0) -> SupportLoads:
        """The possible loads of ``twist``, represented by the samples of ``level``."""
        return SupportLoads(self, np.asarray(twist, dtype=float), level)

    def batch(self, twists: ArrayLike, level: int = 0) -> LoadBatch:
        """The possible loads of each of ``twists`` (shape ``(K, 3)``), represented by the samples of ``level``."""
        return LoadBatch(self, twists, level)

    def envelope_lp(self, level: int = 0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(columns, rhs, basis)``: the discrete LP of :meth:`LoadBatch.sample_support` at
        ``level`` and a feasible starting basis for it (cached).

        Lengths are in units of :attr:`radius`. A sample ``x`` is the column ``(1, (x - CF)/r)``: the
        rows are the total weight and the centroid. With an uncertain CF a fourth row holds the
        centre's weight ``rho/r``, spread over columns ``(0, -e_j, 1)`` for the corners ``e_j`` of the
        32-gon, so that the centroid may be any point of the 32-gon of radius ``rho``. The start is
        a triangle of samples holding the CF (:meth:`cf_triangle`), or a corner of that 32-gon.
        """
        if level not in self._lp:
            cells = self.cells(level)
            x = (cells.points - self.cf) / self.radius
            columns = np.vstack([np.ones(len(x)), x.T])
            rhs = np.array([1.0, 0.0, 0.0])
            start = self.cf_triangle(level)
            if self.cf_radius > 0:
                e = _centre_directions()
                hull = shapely.MultiPoint(x).convex_hull
                depth = shapely.distance(hull.exterior, shapely.points(self.cf_radius / self.radius * e))
                inside = shapely.contains_xy(hull, *(self.cf_radius / self.radius * e).T)
                if not inside.any():
                    raise ValueError("the CF's uncertainty disk leaves the support region")
                j = int(np.argmax(np.where(inside, depth, -np.inf)))
                columns = np.r_[columns, np.zeros((1, len(x)))]
                columns = np.c_[columns, np.r_[np.zeros((1, CF_DIRECTIONS)), -e.T, np.ones((1, CF_DIRECTIONS))]]
                rhs = np.r_[rhs, self.cf_radius / self.radius]
                start = np.r_[_triangle_around(x, self.cf_radius / self.radius * e[j]), len(x) + j]
            self._lp[level] = columns, rhs, start
        return self._lp[level]

    def warm_bases(self, level: int, ys: np.ndarray, twists: np.ndarray) -> np.ndarray:
        """Starting bases (``K, R, m``) for the LPs of :meth:`LoadBatch.sample_support` at ``level``,
        directions ``ys`` (``R, 3``) and ``twists`` (``K, 3``): the optimal bases of the nearest
        twist (by direction, moments in units of :attr:`radius`) :meth:`remember` kept for these
        directions at this level or the one below (whose samples are among this level's), else
        :meth:`envelope_lp`'s start. Any basis of these LPs is feasible for all of them (the
        constraints do not depend on the twist), and neighbouring twists' optima are a pivot or
        two apart: a search along a ray pivots little, and so does a twist refined a level."""
        start = self.envelope_lp(level)[2]
        out = np.array(np.broadcast_to(start, (len(twists), len(ys), len(start))))
        near = np.full(len(twists), -np.inf)
        probe = self._twist_keys(twists)
        for source in (level - 1, level):  # this level wins ties: its bases need no lifting
            kept = self._warm.get((source, ys.tobytes()))
            if kept is None:
                continue
            keys, bases = kept
            closeness = probe @ keys.T
            best = np.argmax(closeness, axis=1)
            bases = bases[best] if source == level else self._lifted(level)[bases[best]]
            take = (closeness[np.arange(len(twists)), best] >= near)[:, None] & np.all(bases >= 0, axis=2)
            out = np.where(take[..., None], bases, out)
            near = np.maximum(near, closeness[np.arange(len(twists)), best])
        return out

    def _lifted(self, level: int) -> np.ndarray:
        """The column of ``level``'s LP (:meth:`envelope_lp`) of each column of the level below
        (-1 if it has none: the grids nest, so a sample always has one, and so does a centre),
        matched by coordinates to a billionth of :attr:`radius`."""
        if level not in self._lift:
            below, here = self.cells(level - 1).points, self.cells(level).points
            at = {key: j for j, key in enumerate(map(tuple, np.round(here / (1e-9 * self.radius)).tolist()))}
            match = np.array([at.get(key, -1) for key in map(tuple, np.round(below / (1e-9 * self.radius)).tolist())])
            extra = self.envelope_lp(level)[0].shape[1] - len(here)  # the centre's columns, after the samples
            self._lift[level] = np.r_[match, len(here) + np.arange(extra)]
        return self._lift[level]

    def remember(self, level: int, ys: np.ndarray, twists: np.ndarray, bases: np.ndarray) -> None:
        """Keep the optimal ``bases`` (``K, R, m``) of ``twists`` for :meth:`warm_bases`, the last
        ``WARM_TWISTS`` per level and directions (memory bounded whatever the calls)."""
        key = (level, ys.tobytes())
        new = self._twist_keys(twists)
        if key in self._warm:
            keys, old = self._warm[key]
            new, bases = np.r_[keys, new], np.concatenate([old, bases])
        self._warm[key] = new[-WARM_TWISTS:], bases[-WARM_TWISTS:]
        if len(self._warm) > WARM_DIRECTIONS:  # a caller cycling through many direction sets
            del self._warm[next(iter(self._warm))]

    def _twist_keys(self, twists: np.ndarray) -> np.ndarray:
        scaled = twists * np.array([1.0, 1.0, self.radius])
        return scaled / np.linalg.norm(scaled, axis=1, keepdims=True)

    def children(self, level: int, parents: ArrayLike) -> SupportCells:
        """The cells of ``level`` inside the given cells of the level below (footprint only), built
        for them alone. The footprint's cells are a grid of squares through the CF clipped to the
        part, the side halving with each level: a cell's anchor (inside its square) names its
        square, whose four quarters are the next level's squares; clipped to the part they cover
        its piece of it."""
        if self.kind != "footprint" or level < 1:
            raise ValueError("only a footprint's cells of level 1 and above have parents")
        h = self.radius / (self.resolution * 2**level)
        squares = np.floor((self.cells(level - 1).anchors[np.asarray(parents, dtype=int)] - self.cf) / (2 * h))
        quarters = (2 * squares[:, None] + np.array([[0, 0], [1, 0], [0, 1], [1, 1]])[None]).reshape(-1, 2)
        return SupportCells.from_polygons(_footprint_cells(self.polygon, self.cf, h, quarters), self.covers)

    def cf_triangle(self, level: int = 0) -> np.ndarray:
        """Indices of three samples of ``level`` whose triangle holds the CF as deep inside as can be
        (a feasible start for the LPs over distributions centred at the CF; cached)."""
        if level not in self._triangle:
            self._triangle[level] = _triangle_around((self.cells(level).points - self.cf) / self.radius, np.zeros(2))
        return self._triangle[level]


class LoadBatch:
    """Loads of many twists over the admissible distributions of a :class:`SupportModel`, batched.

    ``twists`` has shape ``(K, 3)``; every method takes directions ``ys`` of shape ``(R, 3)`` (the
    same for every twist) or ``(K, R, 3)`` and answers per twist and direction, shape ``(K, R)``.
    For a direction ``y`` the *support function* ``sup y . L`` over distributions is bracketed by
    :meth:`sample_support` (the discrete LP: a lower bound, attained by a sample distribution, or
    its limit at the COR) and :meth:`upper_bound` (guaranteed for the continuum).

    The discrete LP has three constraints (total weight and centroid; four with an uncertain CF),
    so each is solved by a few pivots of the simplex method, all of them at once in numpy
    (:func:`~mechanics.simplex.batched_simplex`). A sample at the COR, when the COR lies in the
    region, carries the friction direction that suits ``y`` best (static friction may point
    anywhere there).

    Examples
    --------
    CCW turns about the CF of the unit disk and about points 1.5, 10 and 10^6 to its left: the
    largest moment of the load about the CF falls from 1 (all the weight on the rim) towards 0 (a
    translation's load passes through the CF), while the largest force along ``y`` stays 1 (a
    sample moving straight up). The guaranteed bounds lie above.

    >>> from mechanics import cor_to_twist
    >>> batch = SupportModel.disk([0, 0], 1.0).batch(cor_to_twist([[0, 0], [-1.5, 0], [-10, 0], [-1e6, 0]], 1))
    >>> moment_and_push = [[0.0, 0.0, 1.0], [0.0, 1.0, 0.0]]
    >>> values, lams = batch.sample_support(moment_and_push)
    >>> values.round(3).tolist()
    [[1.0, 1.0], [0.553, 1.0], [0.099, 1.0], [0.0, 1.0]]
    >>> bool(np.all(batch.upper_bound(moment_and_push, lams) >= values))
    True
    """

    def __init__(self, model: SupportModel, twists: ArrayLike, level: int = 0):
        self.model, self.level, self.cells = model, level, model.cells(level)
        self.cf = model.cf
        self.twists = np.asarray(twists, dtype=float).reshape(-1, 3)
        cor, sense = twist_to_cor(self.twists)
        self.sense = sense.astype(int)
        rotation = self.sense != 0
        self.cor = np.where(rotation[:, None], cor, model.cf)  # a translation's stands in, unused
        self.cor_in_region = rotation & model.covers(self.cor)

    def __len__(self) -> int:
        return len(self.twists)

    def __getitem__(self, index: ArrayLike) -> LoadBatch:
        """The batch of some of the twists (an index or mask), without locating their CORs again."""
        part = copy.copy(self)
        part.twists, part.sense, part.cor, part.cor_in_region = (
            self.twists[index], self.sense[index], self.cor[index], self.cor_in_region[index])
        return part

    def _directions(self, ys: ArrayLike) -> np.ndarray:
        """``ys`` as ``(K, R, 3)``: one set for every twist, or a set per twist."""
        ys = np.asarray(ys, dtype=float)
        return np.broadcast_to(ys, (len(self), *ys.shape[-2:]))

    def _arm(self, ys: np.ndarray) -> np.ndarray:
        """``u`` with ``y . g(x) = u . v^(x) + sense y_m |x - c|`` for a rotation about ``c``, shape ``(K, R, 2)``."""
        spin = np.stack([-self.cor[:, 1], self.cor[:, 0]], axis=-1)
        return ys[..., :2] + ys[..., 2:] * spin[:, None, :]

    def sample_support(self, ys: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """``(values, lams)``: the largest ``y . L`` over sample distributions, shape ``(K, R)``, and
        the LP's duals ``lam`` (``K, R, 2``), with ``value = max over samples of y . g + lam . (x - CF)``
        (plus ``cf_radius`` times the support of ``-lam`` on the 32-gon of centres)."""
        shared = np.asarray(ys, dtype=float)
        ys = self._directions(ys)
        k, r = ys.shape[:2]
        columns, rhs, start = self.model.envelope_lp(self.level)
        costs = np.einsum("knj,krj->krn", unit_loads(self.twists[:, None, :], self.cells.points[None]), ys)
        # The centre's columns (uncertain CF) cost nothing.
        costs = np.concatenate([costs, np.zeros((k, r, columns.shape[1] - costs.shape[2]))], axis=2)
        # One set of directions for all twists (the usual case: a cone's rows) warm-starts each LP
        # from the optimum of the nearest twist solved before; a twist whose COR lies in the region
        # has a column of its own, and starts from the CF's triangle.
        warm = shared.ndim == 2 and k > 0
        basis = np.array(np.broadcast_to(start, (k, r, len(rhs))))
        plain = ~self.cor_in_region
        if warm and plain.any():
            basis[plain] = self.model.warm_bases(self.level, shared, self.twists[plain])
        if self.cor_in_region.any():
            at_cor = np.where(self.cor_in_region[:, None], np.linalg.norm(self._arm(ys), axis=-1), -np.inf)
            costs = np.concatenate([costs, at_cor[..., None]], axis=2)
            extra = np.zeros((k, len(rhs), 1))
            extra[:, :3, 0] = np.c_[np.ones(k), (self.cor - self.cf) / self.model.radius]
            per_twist = np.concatenate([np.broadcast_to(columns, (k, *columns.shape)), extra], axis=2)
            columns = np.broadcast_to(per_twist[:, None], (k, r, *per_twist.shape[1:])).reshape(k * r, len(rhs), -1)
        cold = np.broadcast_to(start, (k * r, len(rhs)))
        duals, _, final = (batched_simplex(costs.reshape(k * r, -1), columns, rhs, basis.reshape(k * r, -1),
                                           WARM_LIMIT, restart=cold) if warm
                           else batched_simplex(costs.reshape(k * r, -1), columns, rhs, cold))
        if warm and plain.any():
            self.model.remember(self.level, shared, self.twists[plain], final.reshape(k, r, -1)[plain])
        return (duals @ rhs).reshape(k, r), (-duals[:, 1:3] / self.model.radius).reshape(k, r, 2)

    def _cell_geometry(self, k: np.ndarray, c: np.ndarray) -> tuple[np.ndarray, ...]:
        """For twist ``k[p]`` and cell ``c[p]`` of each pair ``p``, seen from the COR: the cell's
        distance (0 if it holds the COR), the largest distance to a vertex, the angular range
        ``[lo, hi]`` of the directions from the COR to its points, measured from the direction of
        its anchor (exact for a convex cell), and that anchor direction; shapes ``(P,)`` and ``(P, 2)``."""
        cells = self.cells
        # Components apart, (pairs, vertices) each: the vertices relative to the COR, and the edges.
        corners = cells.nodes[cells.cells[c]]
        cor = self.cor[k]
        vx, vy = (corners[..., i] - cor[:, None, i] for i in (0, 1))
        ex, ey = np.roll(vx, -1, axis=1) - vx, np.roll(vy, -1, axis=1) - vy
        length2 = ex * ex + ey * ey
        along = np.clip(np.divide(-(vx * ex + vy * ey), length2, out=np.zeros_like(length2), where=length2 > 0), 0, 1)
        outside = np.hypot(vx + along * ex, vy + along * ey).min(axis=1)
        turn = ex * -vy + ey * vx  # side of the COR for each edge
        eps = 1e-12 * self.model.radius**2
        holds = np.all(turn >= -eps, axis=1) | np.all(turn <= eps, axis=1)
        base = cells.anchors[c] - cor
        bx, by = base[:, :1], base[:, 1:]
        angle = np.arctan2(bx * vy - by * vx, bx * vx + by * vy)
        return np.where(holds, 0.0, outside), np.hypot(vx, vy).max(axis=1), angle.min(axis=1), angle.max(axis=1), base

    def cell_bounds(self, ys: ArrayLike, lams: ArrayLike) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Upper bounds of ``psi(x) = y . g(x) + lam . (x - CF)`` per cell (``K, R, C``), which cells
        hold the COR ``c`` (``K, C``), and (for those) ``psi``'s envelope ``E`` at ``c`` and its slope
        ``k`` away from it (``K, R``): ``psi <= E + k |x - c|``. A translation has no COR (``E = -inf``).

        A cell's bound is tightened (its exact geometry seen from ``c``) only where it could decide
        a sign: a cell whose cheap bound (second order, with its distance from ``c`` bounded below
        by its anchor's distance less its reach) lies below 0 (less the uncertain CF's term
        ``cf_radius |lam|`` of :meth:`upper_bound`) keeps that bound. The largest bound is then
        looser where it is negative, but no sign changes (half the time of tightening every cell
        that could be the largest, at the sample levels the exact regions use).
        """
        ys, cells = self._directions(ys), self.cells
        lams = np.broadcast_to(np.asarray(lams, dtype=float), (*ys.shape[:2], 2))
        linear_nodes = np.einsum("nj,krj->krn", cells.nodes - self.cf, lams)
        psi = np.einsum("knj,krj->krn", unit_loads(self.twists[:, None, :], cells.nodes[None]), ys) + linear_nodes
        vertex_max = psi[..., cells.cells].max(axis=-1)
        rotation = self.sense != 0
        # psi = w . (x - c)/r + sense y_m r + lam . (x - CF), r = |x - c|, w = sense (u_y, -u_x).
        arm = self._arm(ys)
        sense = self.sense[:, None, None]
        w = sense * np.stack([arm[..., 1], -arm[..., 0]], axis=-1)
        u = np.linalg.norm(w, axis=-1)
        radial = self.sense[:, None] * ys[..., 2]
        # Second order: psi + M/2 |x - a|^2 is convex on a cell away from c when M bounds psi's
        # Hessian from below: the Hessian of w . (x - c)/r is >= -1.5 |w| / r^2, that of
        # sense y_m r is >= min(0, sense y_m) / r. So psi <= max over vertices + M/2 reach^2;
        # M falls with the distance r, so a lower bound on it gives a valid (looser) bound.
        near = np.maximum(np.linalg.norm(cells.anchors[None] - self.cor[:, None], axis=-1) - cells.reach[None], 0.0)
        with np.errstate(divide="ignore", invalid="ignore"):
            curvature = 1.5 * u[..., None] / near[:, None] ** 2 + np.maximum(0.0, -radial)[..., None] / near[:, None]
            cheap = np.where(near[:, None] > 0, vertex_max + curvature / 2 * cells.reach**2, np.inf)
        floor = -self.model.cf_radius * np.linalg.norm(lams, axis=-1)[..., None]
        k, c = np.nonzero(rotation[:, None] & np.any(cheap >= floor, axis=1))
        bounds = np.where(rotation[:, None, None], cheap, vertex_max)
        envelope = u + np.einsum("krj,kj->kr", lams, self.cor - self.cf)
        slope = radial + np.linalg.norm(lams, axis=-1)
        touching = np.zeros(near.shape, dtype=bool)
        if len(k):
            dist, reach_c, lo, hi, base = self._cell_geometry(k, c)
            dist_, reach_, lo_, hi_ = (g[:, None] for g in (dist, reach_c, lo, hi))
            away = dist_ > 0
            u_k, radial_k, w_k = u[k], radial[k], w[k]
            with np.errstate(divide="ignore", invalid="ignore"):
                curvature = 1.5 * u_k / dist_**2 + np.maximum(0.0, -radial_k) / dist_
                second = np.where(away, vertex_max[k, :, c] + curvature / 2 * cells.reach[c, None] ** 2, np.inf)
            # First order, term by term: w . (x - c)/r over the cell's range of directions, the
            # radial term at the nearest or farthest point, lam . x at a vertex.
            bx, by = base[:, :1], base[:, 1:]
            phi = np.arctan2(bx * w_k[..., 1] - by * w_k[..., 0], bx * w_k[..., 0] + by * w_k[..., 1])
            direction = np.where((lo_ <= phi) & (phi <= hi_), u_k, u_k * np.maximum(np.cos(phi - lo_), np.cos(phi - hi_)))
            linear = np.einsum("pvj,prj->prv", cells.nodes[cells.cells[c]] - self.cf, lams[k]).max(axis=-1)
            first = direction + radial_k * np.where(radial_k > 0, reach_, dist_) + linear
            # A cell holding c: u . v^ <= |u| and lam . (x - c) <= |lam| r.
            slope_k = slope[k]
            first = np.where(away, first, envelope[k] + slope_k * np.where(slope_k > 0, reach_, 0.0))
            bounds[k, :, c] = np.minimum(first, second)
            touching[k, c] = dist == 0
        return bounds, touching, np.where(rotation[:, None], envelope, -np.inf), np.where(rotation[:, None], slope, 0.0)

    def upper_bound(self, ys: ArrayLike, lams: ArrayLike) -> np.ndarray:
        """Guaranteed upper bounds on ``y . L`` over *all* admissible distributions, shape ``(K, R)``.

        Weak duality: ``y . L(mu) = integral of psi d mu`` for any multiplier ``lam``, with
        ``psi(x) = y . g(x) + lam . (x - CF)``, so the supremum of ``psi`` over the region bounds
        it; that supremum is bounded cell by cell (second order away from the COR, first order
        near it, where the static friction of a point at the COR may point anywhere). An uncertain
        CF adds ``cf_radius |lam|``.
        """
        bounds, *_ = self.cell_bounds(ys, lams)
        return bounds.max(axis=-1) + self.model.cf_radius * np.linalg.norm(lams, axis=-1)

    def refined_bound(self, ys: ArrayLike, lams: ArrayLike, coarse: np.ndarray | None = None) -> np.ndarray:
        """:meth:`upper_bound` one level finer than the batch's, with the finer cells only where
        they can help: this level's cells bound ``psi``, and those whose bound could be positive
        (for any twist and direction of the batch: the uncertain CF's term aside) are replaced by
        the next level's cells inside them (:meth:`SupportModel.children`), built for them alone.
        Every piece of the region is still bounded by a cell holding it, so the bound is valid; a
        cell whose bound is already negative is not split, so the sign is the finer level's
        wherever a cell bounds ``psi`` no lower than its quarters do (the usual case: the bounds
        loosen with a cell's size), at a fraction of the cells. A disk's polar cells do not nest,
        and the next level's are all bounded.
        ``coarse``: this level's :meth:`cell_bounds` for the same ``ys`` and ``lams``, if known.

        >>> from mechanics import cor_to_twist
        >>> block = SupportModel.footprint([[-1, 0], [1, 0], [1, 1], [-1, 1]], [0.0, 0.5])
        >>> twists = cor_to_twist([[-3.0, 0.5], [-1.2, 0.2]], 1)
        >>> ys = [[0.0, 0.0, 1.0], [0.3, -1.0, 0.2]]
        >>> coarse = block.batch(twists, level=1)
        >>> lams = coarse.sample_support(ys)[1]
        >>> full, refined = block.batch(twists, level=2).upper_bound(ys, lams), coarse.refined_bound(ys, lams)
        >>> bool(np.all(refined >= full - 1e-12) and np.array_equal(refined > 0, full > 0))
        True
        """
        finer = copy.copy(self)
        finer.level = self.level + 1
        if self.model.kind != "footprint":
            finer.cells = self.model.cells(finer.level)
            return finer.upper_bound(ys, lams)
        if coarse is None:
            coarse, *_ = self.cell_bounds(ys, lams)
        lams = np.broadcast_to(np.asarray(lams, dtype=float), (*coarse.shape[:2], 2))
        centre = self.model.cf_radius * np.linalg.norm(lams, axis=-1)
        hot = np.flatnonzero(np.any(coarse + centre[..., None] > 0, axis=(0, 1)))
        best = np.delete(coarse, hot, axis=-1).max(axis=-1, initial=-np.inf)
        if len(hot):
            finer.cells = self.model.children(finer.level, hot)
            best = np.maximum(best, finer.cell_bounds(ys, lams)[0].max(axis=-1, initial=-np.inf))
        return best + centre

    def is_negative(self, ys: ArrayLike, lams: ArrayLike, tol: float = 0.0) -> np.ndarray:
        """Whether ``y . L < 0`` is guaranteed for every admissible distribution, one direction
        ``y`` (``K, 3``) and multiplier ``lam`` (``K, 2``) per twist.

        True when ``psi < 0`` on the region except at the COR, where ``psi``'s envelope is
        ``<= tol`` and ``psi`` falls away from it (then a distribution with any moving weight has
        ``y . L < 0``; one wholly at the COR is not a motion).
        """
        lams = np.asarray(lams, dtype=float)
        bounds, touching, envelope, slope = self.cell_bounds(np.asarray(ys, dtype=float)[:, None], lams[:, None])
        bounds, envelope, slope = bounds[:, 0], envelope[:, 0], slope[:, 0]  # the one direction per twist
        if self.model.cf_radius > 0:  # no exemption at the COR: the centre term is positive
            return np.all(bounds + self.model.cf_radius * np.linalg.norm(lams, axis=-1)[:, None] < 0, axis=1)
        at_cor_ok = (envelope <= tol) & (slope < 0)
        return np.all((bounds < 0) | (touching & at_cor_ok[:, None]), axis=1)

    def minimax(self, rows: ArrayLike) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(beta, lam, values)`` per twist: the convex weights ``beta`` (``K, R``) of ``rows``
        minimising the largest ``(beta . rows) . L`` over sample distributions, the centroid
        multiplier ``lam`` (``K, 2``) of that minimum, and the minimum (``K``).

        The LP solved is its dual, over sample distributions: the largest least row value
        ``min_j rows_j . L``. A sample at the COR, when the COR lies in the region, stands for a
        fan of ``COR_DIRECTIONS`` friction directions. A distribution entirely at the COR moves
        nothing and needs no force; only a COR at the CF admits it, and there the moving weight is
        normalised instead of the total: the value is ``inf`` when no weights bound it (the fan
        reaches into every half-space the rows allow).
        """
        rows = np.asarray(rows, dtype=float).reshape(-1, 3)
        k, r = len(self), len(rows)
        rho, radius, cf = self.model.cf_radius, self.model.radius, self.cf
        points = np.broadcast_to(self.cells.points, (k, *self.cells.points.shape))
        loads, present = unit_loads(self.twists[:, None, :], points), np.ones(points.shape[:2], dtype=bool)
        if self.cor_in_region.any():
            angle = 2 * np.pi * np.arange(COR_DIRECTIONS) / COR_DIRECTIONS
            fan = np.stack([np.cos(angle), np.sin(angle)], axis=1)
            at_cor = np.broadcast_to(self.cor[:, None, :], (k, COR_DIRECTIONS, 2))
            points = np.concatenate([points, at_cor], axis=1)
            loads = np.concatenate([loads, point_wrench(at_cor, fan[None])], axis=1)
            present = np.c_[present, np.broadcast_to(self.cor_in_region[:, None], at_cor.shape[:2])]
        n = points.shape[1]
        moving = np.linalg.norm(point_velocity(self.twists[:, None, :], points), axis=-1) > 0
        at_cf = (self.sense != 0) & (np.linalg.norm(self.cor - cf, axis=1) <= 1e-9 * radius)
        # Columns: samples (rows' values, weight, centroid / r), z+ and z- (the least row value),
        # a slack per row, and with an uncertain CF the centre's 32-gon and its slack.
        z, centres = n, n + 2 + r
        a = np.zeros((k, r + 3 + (rho > 0), centres + (CF_DIRECTIONS + 1 if rho > 0 else 0)))
        a[:, :r, :n] = np.einsum("knj,rj->krn", loads, rows) * present[:, None]
        a[:, r, :n] = present & (moving | ~at_cf[:, None])
        a[:, r + 1:r + 3, :n] = np.swapaxes((points - cf) / radius * present[..., None], 1, 2)
        a[:, :r, z], a[:, :r, z + 1], a[:, :r, z + 2:centres] = -1.0, 1.0, -np.eye(r)
        rhs = np.zeros(a.shape[1])
        rhs[r] = 1.0
        if rho > 0:
            a[:, r + 1:r + 3, centres:-1] = -rho / radius * _centre_directions().T
            a[:, r + 3, centres:] = rhs[r + 3] = 1.0
        costs = np.zeros((k, a.shape[2]))
        costs[:, z], costs[:, z + 1] = 1.0, -1.0
        # Start: the CF's triangle, z its least row value, the other rows' slacks (and the centre's).
        triangle = self.model.cf_triangle(self.level)
        weights = np.linalg.solve(a[0, r:r + 3, triangle].T, [1.0, 0.0, 0.0])
        values = a[:, :r, triangle] @ weights
        least = np.argmin(values, axis=1)
        slacks = np.broadcast_to(z + 2 + np.arange(r), (k, r))
        basis = np.c_[np.broadcast_to(triangle, (k, 3)), np.where(values[np.arange(k), least] >= 0, z, z + 1),
                      slacks[slacks != (z + 2 + least)[:, None]].reshape(k, r - 1),
                      np.full((k, int(rho > 0)), a.shape[2] - 1)].astype(int)
        duals, unbounded, _ = batched_simplex(costs, a, rhs, basis)
        beta, lam, value = -duals[:, :r], -duals[:, r + 1:r + 3] / radius, duals @ rhs
        beta[unbounded], lam[unbounded], value[unbounded] = np.nan, 0.0, np.inf
        return beta, lam, value


class SupportLoads:
    """Loads of one twist over the admissible distributions of a :class:`SupportModel`: a
    :class:`LoadBatch` of one, answering with scalars.

    For a direction ``y`` the *support function* ``sup y . L`` over distributions is bracketed by
    :meth:`sample_support` (the discrete LP: a lower bound, attained by a sample distribution) and
    :meth:`upper_bound`; :meth:`minimax` and :meth:`is_negative` find and check a hyperplane
    separating every load from a cone.

    Examples
    --------
    CCW about the CF of the unit disk: the moment about the CF of any load is at most 1 (all the
    weight on the rim), and the samples on the rim attain it. The bound is a little higher: the
    cells on the rim reach out to ``1 / cos(pi / 38)`` (38 sectors on the outer ring).

    >>> loads = SupportModel.disk([0, 0], 1.0).loads([0.0, 0.0, 1.0])
    >>> value, lam = loads.sample_support([0.0, 0.0, 1.0])
    >>> round(value, 9), round(loads.upper_bound([0.0, 0.0, 1.0], lam), 6), round(float(1 / np.cos(np.pi / 38)), 6)
    (1.0, 1.003427, 1.003427)
    """

    def __init__(self, model: SupportModel, twist: np.ndarray, level: int = 0):
        self.model, self.twist, self.cf = model, twist, model.cf
        self.batch = LoadBatch(model, twist[None], level)

    def sample_support(self, y: ArrayLike) -> tuple[float, np.ndarray]:
        """``(value, lam)``: the largest ``y . L`` over sample distributions, and the LP's dual
        ``lam`` (value ``= max over samples of y . g + lam . (x - CF)``)."""
        values, lams = self.batch.sample_support(np.asarray(y, dtype=float)[None])
        return float(values[0, 0]), lams[0, 0]

    def minimax(self, rows: ArrayLike) -> tuple[np.ndarray, np.ndarray, float]:
        """``(beta, lam, value)`` of :meth:`LoadBatch.minimax`."""
        beta, lam, value = self.batch.minimax(rows)
        return beta[0], lam[0], float(value[0])

    def upper_bound(self, y: ArrayLike, lam: ArrayLike) -> float:
        """A guaranteed upper bound on ``y . L`` over *all* admissible distributions
        (:meth:`LoadBatch.upper_bound`)."""
        return float(self.batch.upper_bound(np.asarray(y, dtype=float)[None], np.asarray(lam, dtype=float)[None, None])[0, 0])

    def is_negative(self, y: ArrayLike, lam: ArrayLike, tol: float = 0.0) -> bool:
        """Whether ``y . L < 0`` is guaranteed for every admissible distribution (:meth:`LoadBatch.is_negative`)."""
        return bool(self.batch.is_negative(np.asarray(y, dtype=float)[None], np.asarray(lam, dtype=float)[None], tol)[0])
