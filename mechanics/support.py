"""Support friction of a sliding part (Lynch 1992, §3.2; MECHANICS.md §3.6).

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
therefore include the COR with a fan of friction directions when the COR lies in ``S``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import cached_property

import numpy as np
import shapely
from numpy.typing import ArrayLike
from scipy.optimize import linprog
from scipy.spatial import ConvexHull, QhullError

from .slider import Slider
from .twist import point_velocity, twist_to_cor
from .wrenches import point_wrench

__all__ = ["SupportCells", "SupportLoads", "SupportModel", "effective_cf", "support_friction", "unit_loads"]

#: Friction directions tried at a support point on the COR (the LP mixes them).
COR_DIRECTIONS = 32
#: Corners of the polygon inscribed in the CF's uncertainty disk that sample centres may reach.
CF_DIRECTIONS = 32


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
        size = max(len(p) for p in polygons)
        start = np.cumsum([0] + [len(p) for p in polygons[:-1]])
        # Pad each cell with its first vertex: repeats do not change a maximum over vertices.
        cells = np.array([np.r_[index[s:s + len(p)], np.full(size - len(p), index[s])] for s, p in zip(start, polygons)])
        anchors = np.array([p.mean(axis=0) for p in polygons])
        reach = np.linalg.norm(nodes[cells] - anchors[:, None], axis=2).max(axis=1)
        return cls(nodes[inside(nodes)], nodes, cells, anchors, reach)


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


def _footprint_cells(polygon: shapely.Polygon, cf: np.ndarray, h: float) -> list[np.ndarray]:
    """Squares of side ``h`` (grid through the CF) clipped to the polygon, as convex hulls."""
    x0, y0, x1, y1 = polygon.bounds
    i = np.arange(np.floor((x0 - cf[0]) / h), np.ceil((x1 - cf[0]) / h))
    j = np.arange(np.floor((y0 - cf[1]) / h), np.ceil((y1 - cf[1]) / h))
    ii, jj = (a.ravel() for a in np.meshgrid(i, j))
    boxes = shapely.box(cf[0] + ii * h, cf[1] + jj * h, cf[0] + (ii + 1) * h, cf[1] + (jj + 1) * h)
    pieces = shapely.convex_hull(shapely.intersection(boxes, polygon))
    pieces = pieces[shapely.area(pieces) > 1e-12 * h * h]
    return [np.asarray(p.exterior.coords)[:-1] for p in pieces]


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
        return SupportLoads(self, np.asarray(twist, dtype=float), self.cells(level))


class SupportLoads:
    """Loads of one twist over the admissible distributions of a :class:`SupportModel`.

    ``points`` and ``wrenches`` are the sample points and their unit loads, with the fan of
    friction directions at the COR when it lies in the region. For a direction ``y`` the *support
    function* ``sup y . L`` over distributions is bracketed by :meth:`sample_support` (the discrete
    LP: a lower bound, attained by a sample distribution) and :meth:`upper_bound`.

    A distribution entirely at the COR moves nothing and needs no force (a zero load lies in every
    cone of contact forces); it is left out. Only a COR at the CF admits it, and there
    :meth:`minimax` normalises the moving weight instead of the total.

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

    def __init__(self, model: SupportModel, twist: np.ndarray, cells: SupportCells):
        self.model, self.twist, self.cells = model, twist, cells
        self.cf = model.cf
        cor, sense = twist_to_cor(twist)
        self.sense = int(sense)
        self.cor = cor if self.sense else None
        points, wrenches = cells.points, unit_loads(twist, cells.points)
        self._cor_in_region = self.sense != 0 and bool(model.covers(cor))
        if self._cor_in_region:
            angle = 2 * np.pi * np.arange(COR_DIRECTIONS) / COR_DIRECTIONS
            fan = np.stack([np.cos(angle), np.sin(angle)], axis=1)
            points = np.vstack([points, np.broadcast_to(cor, fan.shape)])
            wrenches = np.vstack([wrenches, point_wrench(cor, fan)])
        self.points, self.wrenches = points, wrenches
        self._moving = np.linalg.norm(point_velocity(twist, points), axis=1) > 0
        self._at_cf = self.sense != 0 and bool(np.linalg.norm(cor - self.cf) <= 1e-9 * model.radius)

    def _arm(self, y: np.ndarray) -> np.ndarray:
        """``u`` with ``y . g(x) = u . v^(x) + sense y_m |x - c|`` for a rotation about ``c``."""
        return y[:2] + y[2] * np.array([-self.cor[1], self.cor[0]])

    def sample_support(self, y: ArrayLike) -> tuple[float, np.ndarray]:
        """``(value, lam)``: the largest ``y . L`` over sample distributions, and the LP's dual
        ``lam`` (value ``= max over samples of y . g + lam . (x - CF)``)."""
        y = np.asarray(y, dtype=float)
        if self.model.cf_radius > 0:  # the centre may move: one LP (module docstring)
            _, lam, value = self.minimax(y[None])
            return value, lam
        h, x = self.wrenches @ y, self.points - self.cf
        if self._cor_in_region:  # the best friction direction at the COR, exactly
            h, x = np.r_[h, np.linalg.norm(self._arm(y))], np.vstack([x, self.cor - self.cf])
        try:
            hull = ConvexHull(np.c_[x, h])
        except QhullError:  # flat (e.g. a translation: y . g is affine): the LP copes
            _, lam, value = self.minimax(y[None])
            return value, lam
        # The upper hull is the concave envelope of the samples; at the CF it is the lowest of its
        # facet planes h = t - lam . x (outward normal pointing up).
        eq = hull.equations[hull.equations[:, 2] > 1e-12]
        k = int(np.argmin(-eq[:, 3] / eq[:, 2]))
        return float(-eq[k, 3] / eq[k, 2]), eq[k, :2] / eq[k, 2]

    def minimax(self, rows: ArrayLike) -> tuple[np.ndarray, np.ndarray, float]:
        """``(beta, lam, value)`` minimising over convex weights ``beta`` of ``rows`` the largest
        ``(beta . rows) . L`` over sample distributions (one LP; its dual is the max-min).

        ``value`` is ``inf`` when no weights bound it (a COR at the CF whose fan of friction
        forces reaches into every half-space the rows allow).
        """
        rows = np.asarray(rows, dtype=float).reshape(-1, 3)
        k, n = len(rows), len(self.points)
        # Rows of points that do not move carry no "t" when the moving weight is normalised.
        t_column = np.where(self._moving | (not self._at_cf), -1.0, 0.0)
        a_ub = np.c_[self.wrenches @ rows.T, self.points - self.cf, t_column, np.zeros(n)]
        rho = self.model.cf_radius
        if rho > 0:
            # u >= -e_j . lam for the inscribed polygon's corners e_j: the LP's dual lets the
            # centre move to any point of that polygon, and the objective pays rho u for it.
            angle = 2 * np.pi * np.arange(CF_DIRECTIONS) / CF_DIRECTIONS
            e = np.stack([np.cos(angle), np.sin(angle)], axis=1)
            a_ub = np.r_[a_ub, np.c_[np.zeros((CF_DIRECTIONS, k)), -e, np.zeros(CF_DIRECTIONS), -np.ones(CF_DIRECTIONS)]]
        res = linprog(
            np.r_[np.zeros(k + 2), 1.0, rho], A_ub=a_ub, b_ub=np.zeros(len(a_ub)),
            A_eq=np.r_[np.ones(k), 0.0, 0.0, 0.0, 0.0][None], b_eq=[1.0],
            bounds=[(0, None)] * k + [(None, None)] * 3 + [(0, None)], method="highs",
        )
        if res.status == 2 and self._at_cf:
            return np.full(k, np.nan), np.zeros(2), np.inf
        if res.status != 0:
            raise RuntimeError(f"support LP failed: {res.message}")
        return res.x[:k], res.x[k:k + 2], float(res.x[k + 2] + rho * res.x[-1])

    @cached_property
    def _cell_geometry(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Per cell, seen from the COR ``c``: its distance (0 if it holds ``c``), the largest
        distance to a vertex, and the angular range ``[lo, hi]`` of the directions from ``c`` to its
        points, measured from the direction of its anchor (exact for a convex cell)."""
        cells = self.cells
        v = cells.nodes[cells.cells] - self.cor  # (cells, vertices, 2), relative to c
        edge = np.roll(v, -1, axis=1) - v
        length2 = np.sum(edge**2, axis=2)
        along = np.clip(np.divide(-np.sum(v * edge, axis=2), length2, out=np.zeros_like(length2), where=length2 > 0), 0, 1)
        outside = np.linalg.norm(v + along[..., None] * edge, axis=2).min(axis=1)
        turn = edge[..., 0] * -v[..., 1] + edge[..., 1] * v[..., 0]  # side of c for each edge
        eps = 1e-12 * self.model.radius**2
        holds = np.all(turn >= -eps, axis=1) | np.all(turn <= eps, axis=1)
        base = cells.anchors - self.cor
        angle = np.arctan2(base[:, None, 0] * v[..., 1] - base[:, None, 1] * v[..., 0], np.sum(base[:, None] * v, axis=2))
        return np.where(holds, 0.0, outside), np.linalg.norm(v, axis=2).max(axis=1), angle.min(axis=1), angle.max(axis=1)

    def _cell_bounds(self, y: np.ndarray, lam: np.ndarray) -> tuple[np.ndarray, np.ndarray, float, float]:
        """Upper bounds of ``psi(x) = y . g(x) + lam . (x - CF)`` per cell, which cells hold the
        COR ``c``, and (for those) ``psi``'s envelope ``E`` at ``c`` and its slope ``k`` away from it:
        ``psi <= E + k |x - c|``."""
        cells = self.cells
        psi = unit_loads(self.twist, cells.nodes) @ y + (cells.nodes - self.cf) @ lam
        vertex_max = psi[cells.cells].max(axis=1)
        if self.sense == 0:  # psi is affine: its maximum on a cell is at a vertex
            return vertex_max, np.zeros(len(vertex_max), dtype=bool), -np.inf, 0.0
        # psi = w . (x - c)/r + sense y_m r + lam . (x - CF), r = |x - c|, w = sense (u_y, -u_x).
        arm = self._arm(y)
        w = self.sense * np.array([arm[1], -arm[0]])
        u = float(np.linalg.norm(w))
        radial = self.sense * y[2]
        dist, reach_c, lo, hi = self._cell_geometry
        away = dist > 0
        # Second order: psi + M/2 |x - a|^2 is convex on a cell away from c when M bounds psi's
        # Hessian from below: the Hessian of w . (x - c)/r is >= -1.5 |w| / r^2, that of
        # sense y_m r is >= min(0, sense y_m) / r. So psi <= max over vertices + M/2 reach^2.
        with np.errstate(divide="ignore", invalid="ignore"):
            curvature = 1.5 * u / dist**2 + max(0.0, -radial) / dist
            second = np.where(away, vertex_max + curvature / 2 * cells.reach**2, np.inf)
        # First order, term by term: w . (x - c)/r over the cell's range of directions, the
        # radial term at the nearest or farthest point, lam . x at a vertex.
        base = cells.anchors - self.cor
        phi = np.arctan2(base[:, 0] * w[1] - base[:, 1] * w[0], base @ w)
        direction = np.where((lo <= phi) & (phi <= hi), u, u * np.maximum(np.cos(phi - lo), np.cos(phi - hi)))
        linear = ((cells.nodes - self.cf) @ lam)[cells.cells].max(axis=1)
        first = direction + radial * np.where(radial > 0, reach_c, dist) + linear
        # A cell holding c: u . v^ <= |u| and lam . (x - c) <= |lam| r.
        envelope = u + float(lam @ (self.cor - self.cf))
        slope = radial + float(np.linalg.norm(lam))
        first = np.where(away, first, envelope + slope * np.where(slope > 0, reach_c, 0.0))
        return np.minimum(first, second), ~away, envelope, slope

    def upper_bound(self, y: ArrayLike, lam: ArrayLike) -> float:
        """A guaranteed upper bound on ``y . L`` over *all* admissible distributions.

        Weak duality: ``y . L(mu) = integral of psi d mu`` for any multiplier ``lam``, with
        ``psi(x) = y . g(x) + lam . (x - CF)``, so the supremum of ``psi`` over the region bounds
        it; that supremum is bounded cell by cell (second order away from the COR, first order
        near it, where the static friction of a point at the COR may point anywhere). An uncertain
        CF adds ``cf_radius |lam|``.
        """
        lam = np.asarray(lam, dtype=float)
        bounds, *_ = self._cell_bounds(np.asarray(y, dtype=float), lam)
        return float(bounds.max()) + self.model.cf_radius * float(np.linalg.norm(lam))

    def is_negative(self, y: ArrayLike, lam: ArrayLike, tol: float = 0.0) -> bool:
        """Whether ``y . L < 0`` is guaranteed for every admissible distribution.

        True when ``psi < 0`` on the region except at the COR, where ``psi``'s envelope is
        ``<= tol`` and ``psi`` falls away from it (then a distribution with any moving weight has
        ``y . L < 0``; one wholly at the COR is not a motion).
        """
        lam = np.asarray(lam, dtype=float)
        bounds, touching, envelope, slope = self._cell_bounds(np.asarray(y, dtype=float), lam)
        if self.model.cf_radius > 0:  # no exemption at the COR: the centre term is positive
            return bool(np.all(bounds + self.model.cf_radius * float(np.linalg.norm(lam)) < 0))
        at_cor_ok = envelope <= tol and slope < 0
        return bool(np.all((bounds < 0) | (touching & at_cor_ok)))
