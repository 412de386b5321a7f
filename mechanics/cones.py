"""Polyhedral convex cones of twists and wrenches, and their pictures in COR space.

Quasi-static pushing only cares about directions, so a set of slider motions or of contact
forces is a cone in R^3: twists ``(vx, vy, omega)`` or wrenches ``(fx, fy, m)`` (moment about
the frame origin). A cone is kept both ways: by *generators* (its edges) and by *rows* ``a`` with
``a . x >= 0`` for every ``x`` in it (its facets). The two are dual: the rows of a cone generate
its dual cone ``{y : y . x >= 0 for all x in the cone}``.

Lynch (1992) draws both kinds of cone in the plane (docs/mechanics.md, "Moment labelling"):

* a cone of twists by the rotation centres of its twists, one picture per sense (§2.2);
* a cone of wrenches by moment labelling (§3.1): the points about which every wrench has a
  non-negative (``P+``) or non-positive (``P-``) moment.

These are one computation. The moment of a wrench ``w`` about a point ``q`` is
``w . (q_y, -q_x, 1)``, the power of ``w`` on a unit CCW rotation about ``q``; so ``P+`` and
``P-`` of a wrench cone are the CCW and CW rotation centres of its dual cone.
"""

from __future__ import annotations

from functools import cached_property
from itertools import combinations

import numpy as np
import shapely
from numpy.typing import ArrayLike

__all__ = ["Cone", "cor_halfplanes"]

# Relative tolerance on unit vectors: directions closer than this are the same.
_TOL = 1e-10


def _unit_rows(a: ArrayLike) -> np.ndarray:
    """Rows scaled to unit length; zero rows are dropped (they constrain nothing)."""
    a = np.asarray(a, dtype=float).reshape(-1, 3)
    norm = np.linalg.norm(a, axis=1)
    keep = norm > _TOL * max(1.0, float(norm.max(initial=0.0)))
    return a[keep] / norm[keep, None] + 0.0  # no -0.0


def _complement(g: np.ndarray) -> np.ndarray:
    """Orthonormal basis (rows) of the orthogonal complement of the span of the rows of ``g``."""
    if len(g) == 0:
        return np.eye(3)
    _, s, vt = np.linalg.svd(g)
    rank = int(np.sum(s > _TOL * s[0]))
    return vt[rank:]


def _dedupe(rows: np.ndarray) -> np.ndarray:
    out: list[np.ndarray] = []
    for r in rows:
        if all(np.linalg.norm(r - o) > 1e-8 for o in out):
            out.append(r)
    return np.array(out).reshape(-1, 3)


def _facets(generators: np.ndarray) -> np.ndarray:
    """Unit rows ``a`` with ``cone(generators) = {x : a . x >= 0 for all a}``.

    In R^3 every facet plane of a cone contains two independent vectors of the cone or of its
    span's complement, so the candidates are the cross products of all pairs of those (both
    signs) and the complement itself; a candidate is a facet if no generator is on its negative
    side. A whole-space cone has no rows; the zero cone has ``+-e1, +-e2, +-e3``.
    """
    g = _unit_rows(generators)
    basis = np.vstack([g, _complement(g)])
    pairs = [np.cross(a, b) for a, b in combinations(basis, 2)]
    candidates = _unit_rows(np.vstack([*pairs, _complement(g)])) if len(basis) > 1 else np.zeros((0, 3))
    candidates = np.vstack([candidates, 0.0 - candidates])
    if len(g):
        candidates = candidates[np.all(candidates @ g.T >= -_TOL, axis=1)]
    return _dedupe(candidates)


def cor_halfplanes(rows: ArrayLike, sense: int) -> tuple[np.ndarray, np.ndarray]:
    """Half-planes ``d . c >= off`` of the rotation centres ``c`` of ``sense`` allowed by ``rows``.

    ``a . cor_to_twist(c, sense) >= 0`` reads ``sense * (a0 c_y - a1 c_x + a2) >= 0``.

    >>> d, off = cor_halfplanes([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0]], 1)
    >>> d.tolist(), off.tolist()
    ([[-0.0, 0.0], [-0.0, 1.0]], [-1.0, -0.0])
    """
    a = np.asarray(rows, dtype=float).reshape(-1, 3)
    return sense * np.stack([-a[:, 1], a[:, 0]], axis=1), -sense * a[:, 2]


def _clip(ring: np.ndarray, d: np.ndarray, off: float) -> np.ndarray:
    """The part of the convex polygon ``ring`` with ``d . c >= off`` (Sutherland-Hodgman)."""
    s = ring @ d - off
    out = []
    for i in range(len(ring)):
        j = (i + 1) % len(ring)
        if s[i] >= 0:
            out.append(ring[i])
        if (s[i] >= 0) != (s[j] >= 0):
            out.append(ring[i] + (ring[j] - ring[i]) * s[i] / (s[i] - s[j]))
    return np.array(out).reshape(-1, 2)


def _region(d: np.ndarray, off: np.ndarray, eq: np.ndarray, window: ArrayLike) -> shapely.Geometry:
    """``{c in window : d_i . c >= off_i, with equality where eq_i}`` as a shapely geometry."""
    x0, y0, x1, y1 = map(float, window)
    box_d = np.array([[1.0, 0], [-1, 0], [0, 1], [0, -1]])
    d = np.vstack([d, box_d])
    off = np.concatenate([off, [x0, -x1, y0, -y1]])
    eq = np.concatenate([eq, np.zeros(4, dtype=bool)])
    scale = max(abs(x0), abs(x1), abs(y0), abs(y1), x1 - x0, y1 - y0)
    flat = np.linalg.norm(d, axis=1) <= _TOL
    # A row with d = 0 (a condition on translations only) keeps all or none of the plane.
    if np.any(flat & (off > _TOL * scale)) or np.any(flat & eq & (np.abs(off) > _TOL * scale)):
        return shapely.Polygon()
    d, off, eq = d[~flat], off[~flat], eq[~flat]
    if not eq.any():
        ring = np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]])
        for di, oi in zip(d, off):
            ring = _clip(ring, di, oi)
            if len(ring) < 3:
                return shapely.Polygon()
        return shapely.Polygon(ring)
    # Equalities: a line or a point, then the inequalities along it.
    base, *_ = np.linalg.lstsq(d[eq], off[eq], rcond=None)
    if np.any(np.abs(d[eq] @ base - off[eq]) > 1e-9 * scale):
        return shapely.Polygon()
    _, s, vt = np.linalg.svd(d[eq])
    slack = d[~eq] @ base - off[~eq]
    if np.sum(s > _TOL * s[0]) == 2:
        return shapely.Point(base) if np.all(slack >= -1e-9 * scale) else shapely.Polygon()
    u = vt[1]
    rate = d[~eq] @ u  # slack + rate * s >= 0 along base + s u
    lo = np.max(np.where(rate > 0, -slack / np.where(rate > 0, rate, 1), -np.inf), initial=-np.inf)
    hi = np.min(np.where(rate < 0, -slack / np.where(rate < 0, rate, 1), np.inf), initial=np.inf)
    if np.any((rate == 0) & (slack < -1e-9 * scale)) or lo > hi:
        return shapely.Polygon()
    return shapely.Point(base + lo * u) if hi - lo <= 1e-12 * scale else shapely.LineString([base + lo * u, base + hi * u])


class Cone:
    """A polyhedral convex cone in R^3 (twists or wrenches).

    Build it with :meth:`from_generators` or :meth:`from_rows`; the other description is
    computed. ``rows`` are unit vectors; a row whose value is zero on the whole cone is one of its
    *equalities* (the cone then lies in a plane, a line or is the zero cone).

    Examples
    --------
    The first octant: three edges, three facets.

    >>> octant = Cone.from_generators(np.eye(3))
    >>> sorted(octant.rows.tolist())
    [[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]]
    >>> octant.contains([[1, 2, 3], [1, -1, 0], [1, 0, 0]]).tolist()
    [True, False, True]
    >>> octant.contains([[1, 2, 3], [1, 0, 0]], interior=True).tolist()
    [True, False]

    A ray ``(1, 0, 0)``: two equalities and one inequality.

    >>> ray = Cone.from_generators([[2.0, 0.0, 0.0]])
    >>> int(ray.equalities.sum()), ray.contains([[5, 0, 0], [-1, 0, 0]], interior=True).tolist()
    (4, [True, False])
    """

    def __init__(self, generators: np.ndarray, rows: np.ndarray):
        self.generators = generators
        self.rows = rows

    @classmethod
    def from_generators(cls, generators: ArrayLike) -> Cone:
        """The cone of all non-negative combinations of ``generators`` (shape ``(k, 3)``)."""
        g = _unit_rows(generators)
        return cls(g, _facets(g))

    @classmethod
    def from_rows(cls, rows: ArrayLike) -> Cone:
        """The cone ``{x : a . x >= 0 for every row a}`` (an equality is a pair ``a, -a``)."""
        a = _unit_rows(rows)
        return cls(_facets(a), a)

    def __repr__(self) -> str:
        return f"Cone(generators={self.generators.round(6).tolist()})"

    def dual(self) -> Cone:
        """``{y : y . x >= 0 for all x in the cone}``: generated by the rows."""
        return Cone(self.rows, self.generators)

    @cached_property
    def equalities(self) -> np.ndarray:
        """Boolean mask of the rows that vanish on the whole cone."""
        if len(self.generators) == 0:
            return np.ones(len(self.rows), dtype=bool)
        return np.all(np.abs(self.rows @ self.generators.T) <= 1e-9, axis=1)

    @cached_property
    def dimension(self) -> int:
        """Dimension of the cone's span: 0 (zero cone) to 3."""
        return 0 if len(self.generators) == 0 else int(np.linalg.matrix_rank(self.generators, tol=1e-9))

    def contains(self, x: ArrayLike, *, interior: bool = False, tol: float = 1e-9) -> np.ndarray:
        """Whether each ``x`` (shape ``(..., 3)``) is in the cone.

        ``interior=True`` asks for the *relative* interior (the cone without its boundary, inside
        its own span): strict on every row but the equalities. ``tol`` is relative to ``|x|``.
        """
        x = np.asarray(x, dtype=float)
        value = x @ self.rows.T
        eps = tol * np.linalg.norm(x, axis=-1, keepdims=True)
        if not interior:
            return np.all(value >= -eps, axis=-1)
        eq = self.equalities
        return np.all(np.abs(value[..., eq]) <= eps, axis=-1) & np.all(value[..., ~eq] > eps, axis=-1)

    def cor_region(self, sense: int, window: ArrayLike) -> shapely.Geometry:
        """Rotation centres ``c`` of ``sense`` with ``cor_to_twist(c, sense)`` in the cone.

        Clipped to ``window = (xmin, ymin, xmax, ymax)``: a polygon, or a segment or point for a
        cone of dimension 2 or 1 whose span holds rotations (empty otherwise).

        >>> from mechanics.twist import cor_to_twist
        >>> cone = Cone.from_generators(cor_to_twist([[0, 0], [2, 0]], [1, 1]))
        >>> cone.cor_region(1, (-5, -5, 5, 5)).normalize().wkt, cone.cor_region(-1, (-5, -5, 5, 5)).is_empty
        ('LINESTRING (0 0, 2 0)', True)
        """
        d, off = cor_halfplanes(self.rows, sense)
        return _region(d, off, self.equalities, window)
