"""The exact guaranteed-stable pushes of an edge (Lynch 1992, §4-5; docs/mechanics.md, "Exact edge region").

A flat pusher on an edge pushes stably when the slider stays stuck to it whatever the support
pressure: sticking ``ss`` is force possible (**P**) for every distribution on the part's footprint
with its centre at the CF (:func:`~.force_status.force_possible`, certified), and, by Lynch & Mason's
Theorem 4, a rotation's centre lies beyond the part along the edge so that no other mode can
occur. Procedure STABLE (:mod:`.stable`) is a closed-form inner bound of this set; here the set
itself is traced, so it contains STABLE's and is as large as the guarantee allows.

Construction, in the push plane (:mod:`.push_plane`), where the set is a bounded region:

1. STABLE's section ``S`` (convex) and its centroid ``C``. STABLE finds every stable translation
   (Lynch & Mason 1996, §3.3.1), so the translation range is STABLE's, and an empty STABLE means
   no stable push at all (Proposition 6).
2. ``rays`` rays from ``C``; along each, the last certified-P point by bisection between ``S``'s
   boundary and the edge of Theorem 4's strip (or a distance far beyond any stable push).
3. The vertices are pulled back towards ``S`` by ``margin`` of their reach beyond it, and every
   vertex and ``checks`` points on every edge between neighbouring rays are certified P; an edge
   with a failure gets a new ray in its middle (the region can be far from convex), and one that
   still fails at the finest spacing has both its vertices pulled halfway back to ``S``, until
   all pass.
4. The region is that star-shaped polygon united with ``S``.

The certifications are batched: the rays' bisections run side by side, one batch of twists per
step, and a pass of step 3 checks all its edges in one batch (in order, an edge whose end an
earlier edge pulled back being checked again), so each batch's support LPs are solved together
(:func:`~.force_status.force_possible`); no step depends on the order, so the region is the one a
twist-by-twist trace gives. ``deadline`` stops the construction between batches.

**Robustness (Lynch 1992, §6).** A friction coefficient known only within an interval gives the
region of its lowest value (sticking there implies sticking above it). A CF known only within a
disk is a linear constraint on the distribution's centre (:class:`~.support.SupportModel`
``cf_radius``): the certified verdicts then hold for every CF in the disk. STABLE's region, drawn
for the nominal CF, is then not trusted: the trace starts from its centroid and certifies
everything.

What is guaranteed: every twist on the boundary samples checked in step 3 is certified P (a
discretised distribution cannot produce a false P, :mod:`.force_status`); between samples the
boundary is trusted at the ray resolution with the inward margin, and the interior is trusted to be
star-shaped about ``C`` (the bisection assumes one P-to-not-P crossing per ray). The tests check
both against a much finer grid and an independent linear programme over explicit distributions.

Examples
--------
docs/mechanics.md, "Membership table", fixture A (2 x 1 block pushed on its whole bottom face, mu = 0.5): CCW about
(-3, 1.2) and (-1.5, 0.5) are stable, though STABLE misses both; the mirror CW turn is not.

>>> from mechanics import Slider, cor_to_twist, stable_region
>>> block = Slider([[-1, 0], [1, 0], [1, 1], [-1, 1]])
>>> exact = exact_region(block, 0, 0.5, rays=24)
>>> twists = cor_to_twist([[-3, 1.2], [-1.5, 0.5], [-3, 0.5]], [1, 1, -1])
>>> exact.contains(twists).tolist(), stable_region(block, 0, 0.5).contains(twists).tolist()
([True, True, False], [False, False, False])
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from functools import cached_property

import numpy as np
import shapely
from numpy.typing import ArrayLike

from .contacts import ContactConfiguration
from .force_status import force_possible
from .slider import Slider
from .stable import StableRegion, procedure_stable
from .support import SupportModel
from .twist import twist_to_cor
from .wrenches import contact_wrench_cone

__all__ = ["DeadlineExceeded", "ExactRegion", "exact_region"]

#: How far beyond STABLE's section a ray is searched, in units of that section's size: far past any
#: stable push (sideways pushes are force impossible), so the cap never binds in practice.
_REACH = 8.0


class DeadlineExceeded(RuntimeError):
    """An exact region was not finished by the deadline it was given."""


@dataclass(frozen=True, eq=False)
class ExactRegion:
    """The exact stable pushes of one edge, with the interface of :class:`~.stable.StableRegion`.

    ``polygon`` is the region's section in the push plane (:attr:`plane`), star-shaped about
    ``centre``; ``stable`` is procedure STABLE's region for the same edge (at the lowest friction
    and the nominal CF; contained in this one when the CF is known); ``cf_radius`` the radius of
    the CF's uncertainty disk the region allows for.
    """

    stable: StableRegion
    polygon: shapely.Geometry
    centre: np.ndarray
    cf_radius: float = 0.0

    edge = property(lambda self: self.stable.edge)
    contact = property(lambda self: self.stable.contact)
    normal = property(lambda self: self.stable.normal)
    mu = property(lambda self: self.stable.mu)
    cf = property(lambda self: self.stable.cf)
    scale = property(lambda self: self.stable.scale)
    plane = property(lambda self: self.stable.plane)
    is_empty = property(lambda self: self.polygon.is_empty)

    @cached_property
    def translation_range(self) -> tuple[float, float] | None:
        """Angles from the normal (positive tilted towards ``-t``) of the stable translations.

        With a known CF they are STABLE's (it finds every stable translation, Lynch & Mason 1996,
        §3.3.1); with an uncertain one, the region's chord along ``w = 0``.
        """
        if self.is_empty:
            return None
        if self.cf_radius == 0:
            return self.stable.translation_range
        chord = self.polygon.intersection(shapely.LineString([(-1e9, 0.0), (1e9, 0.0)]))
        if chord.is_empty:
            return None
        s_lo, _, s_hi, _ = chord.bounds
        return float(np.arctan(-s_hi)), float(np.arctan(-s_lo))  # s = -tan(angle)

    def contains(self, twist: ArrayLike, tol: float = 1e-9) -> np.ndarray:
        """Whether each slider-frame twist (shape ``(..., 3)``, any positive scale) is stable.

        ``tol`` is a tolerance in the push plane's units (speeds per unit normal speed).
        """
        v = np.asarray(twist, dtype=float)
        if self.is_empty:
            return np.zeros(v.shape[:-1], dtype=bool)
        p = self.plane.points(v)
        ok = np.all(np.isfinite(p), axis=-1)
        if not shapely.is_prepared(self.polygon):  # asked of every search state: prepared, twice as fast
            shapely.prepare(self.polygon)  # (here, not on construction: an unpickled region comes unprepared)
        inside = shapely.dwithin(self.polygon, shapely.points(np.where(ok[..., None], p, 0.0)), tol)
        return ok & inside

    def section(self) -> tuple[shapely.Polygon, np.ndarray]:
        """The region in the push plane and the centre it is star-shaped about."""
        return self.polygon, self.centre

    def extremal_twists(self) -> np.ndarray:
        """The corners of the region's convex hull, as twists with ``|omega| = 1`` (rotations) or
        unit speed (translations); the controls of the 1996 planner."""
        if self.is_empty:
            return np.zeros((0, 3))
        corners = shapely.get_coordinates(self.polygon.convex_hull)  # a point or segment if degenerate
        v = self.plane.twists(np.unique(corners, axis=0))
        size = np.where(np.abs(v[:, 2]) > 1e-12, np.abs(v[:, 2]), np.linalg.norm(v[:, :2], axis=1))
        return v / size[:, None]

    def cor_polygons(self, window: ArrayLike | None = None) -> dict[int, shapely.Polygon]:
        """COR regions per sense clipped to ``window = (xmin, ymin, xmax, ymax)`` (for drawing).

        Straight lines of the push plane are straight lines of CORs (the map is projective), so
        each sense's half of the section maps vertex by vertex; the band next to ``w = 0``, whose
        CORs lie beyond the window, is left out. The default window is a square of half-side
        ``4 r`` about the CF.
        """
        if window is None:
            window = (*(self.cf - 4 * self.scale), *(self.cf + 4 * self.scale))
        box = shapely.box(*window)
        if self.is_empty:
            return {1: shapely.Polygon(), -1: shapely.Polygon()}
        corners = np.asarray(box.exterior.coords)
        # A COR at plane height w sits |scale / w| from m along the edge: beyond the window when
        # |w| < delta.
        delta = self.scale / (2.0 * float(np.max(np.linalg.norm(corners - self.plane.midpoint, axis=1))))
        big = 1e3 * (1.0 + float(np.max(np.abs(self.polygon.bounds))))
        out = {}
        for sense in (1, -1):
            half = self.polygon.intersection(shapely.box(-big, delta, big, big) if sense > 0
                                             else shapely.box(-big, -big, big, -delta))
            pieces = []
            for part in getattr(half, "geoms", [half]):
                if isinstance(part, shapely.Polygon) and part.area > 0:
                    cors, _ = twist_to_cor(self.plane.twists(np.asarray(part.exterior.coords)))
                    pieces.append(shapely.Polygon(cors).buffer(0).intersection(box))
            out[sense] = shapely.union_all(pieces) if pieces else shapely.Polygon()
        return out


def exact_region(
    slider: Slider,
    edge: int,
    mu: float | tuple[float, float],
    width: float | None = None,
    cf_radius: float = 0.0,
    rays: int = 48,
    steps: int = 12,
    margin: float = 0.02,
    checks: int = 4,
    deadline: float | None = None,
) -> ExactRegion:
    """The exact guaranteed-stable pushes of ``edge`` (module docstring).

    Parameters
    ----------
    slider, edge, width
        As for :func:`~.stable.procedure_stable`.
    mu : float or (float, float)
        Pusher-slider friction, or an interval holding it (Lynch 1992, §6). Sticking is force
        possible for every value once it is at the lowest, whose friction cone lies inside the
        others', so an interval's region is exactly its lowest value's.
    cf_radius : float
        Radius of a disk about the slider's CF holding the true CF (§6); the region is then stable
        for every CF in it (:class:`~.support.SupportModel`). STABLE is no longer an inner bound, so
        every point of the trace is certified, from STABLE's centroid out.
    rays : int
        Rays of the search (at least 8).
    steps : int
        Bisection steps per ray.
    margin : float
        Fraction of each vertex's reach (beyond STABLE's region, or from the centre) given up as a
        safety margin.
    checks : int
        Points certified on each boundary edge between neighbouring rays, besides the vertices.
    deadline : float, optional
        A :func:`time.perf_counter` time; past it the construction stops with
        :class:`DeadlineExceeded` (checked before each batch of certifications).

    Examples
    --------
    An empty STABLE region means no stable push (Proposition 6):

    >>> off_centre = Slider([[-1, 0], [1, 0], [1, 1], [-1, 1]], cf=[0.9, 0.5])
    >>> exact_region(off_centre, 0, 0.5, width=0.5).is_empty
    True

    Friction known only within [0.4, 0.6] gives the region of 0.4; a CF known only within 0.05 shrinks it:

    >>> block = Slider([[-1, 0], [1, 0], [1, 1], [-1, 1]])
    >>> loose = exact_region(block, 0, (0.4, 0.6), rays=16)
    >>> loose.polygon.equals(exact_region(block, 0, 0.4, rays=16).polygon)
    True
    >>> bool(exact_region(block, 0, 0.5, cf_radius=0.05, rays=16).polygon.area < exact_region(block, 0, 0.5, rays=16).polygon.area)
    True
    """
    mu_lo, mu_hi = (float(mu), float(mu)) if np.isscalar(mu) else (float(min(mu)), float(max(mu)))
    if not 0 < mu_lo <= mu_hi:
        raise ValueError(f"mu must be > 0 (an interval: low <= high), got {mu}")
    if not cf_radius >= 0:
        raise ValueError(f"cf_radius must be >= 0, got {cf_radius}")
    stable = procedure_stable(slider, edge, mu_lo, width)
    if stable.is_empty:
        return ExactRegion(stable, shapely.Polygon(), np.zeros(2), cf_radius)
    if rays < 8:
        raise ValueError(f"rays must be at least 8, got {rays}")
    inner, centre = stable.section()
    if not (isinstance(inner, shapely.Polygon) and inner.area > 0):  # translations only: nothing to trace
        # ...and with an uncertain CF not even those are proven: give none.
        return ExactRegion(stable, inner if cf_radius == 0 else shapely.Polygon(), centre, cf_radius)
    plane = stable.plane
    cone = contact_wrench_cone(ContactConfiguration.slider_edge(slider, edge, mu_lo, width), "s" * 2)
    support = SupportModel.of_slider(slider, "footprint", cf_radius=cf_radius)
    w_lo, w_hi = plane.theorem4_strip(slider.vertices)
    trusted = cf_radius == 0  # STABLE's region is proven only for a known CF

    def stable_at(points: np.ndarray) -> np.ndarray:
        """Certified P, strictly inside Theorem 4's strip, or (if trusted) inside STABLE's region;
        all ``points`` (``k, 2``) at once."""
        if deadline is not None and time.perf_counter() > deadline:
            raise DeadlineExceeded(f"the exact region of edge {edge} was not finished by the deadline")
        points = np.atleast_2d(points)
        twists = plane.twists(points)
        known = stable.contains(twists) if trusted else np.zeros(len(points), dtype=bool)
        ask = ~known & (w_lo < points[:, 1]) & (points[:, 1] < w_hi)
        known[ask] = force_possible(twists[ask], cone, support)
        return known

    if not trusted and not stable_at(centre)[0]:
        return ExactRegion(stable, shapely.Polygon(), np.zeros(2), cf_radius)
    size = max(float(np.ptp(np.asarray(inner.bounds).reshape(2, 2), axis=0).max()), 1e-9)

    def along(angles: float | np.ndarray) -> np.ndarray:
        # Exact zeros on the axes: a ray along w = 0 must stay on the translations, not turn
        # about centres 1e16 away.
        e = np.stack([np.cos(angles), np.sin(angles)], axis=-1)
        return np.where(np.abs(e) < 1e-12, 0.0, e)

    def trace(angles: list[float]) -> dict[float, list[float]]:
        """``{angle: [base, reach]}`` of the rays at ``angles``: where STABLE's region ends (or 0)
        and the last certified point found by bisection, less the margin. The rays' bisections
        run side by side, one batch of certifications per step."""
        e = along(np.asarray(angles, dtype=float))
        if trusted:
            spokes = shapely.linestrings(np.stack([np.broadcast_to(centre, e.shape), centre + 2 * _REACH * size * e], axis=1))
            base = shapely.length(shapely.intersection(inner, spokes))
        else:
            base = np.zeros(len(e))
        cap = np.full(len(e), _REACH * size)
        with np.errstate(divide="ignore", invalid="ignore"):
            strip = (np.where(e[:, 1] > 0, w_hi, w_lo) - centre[1]) / e[:, 1]
        cap = np.where(e[:, 1] != 0, np.minimum(cap, strip), cap)
        lo, hi = base.copy(), cap * (1 - 1e-9)
        at_cap = stable_at(centre + hi[:, None] * e)
        lo[at_cap] = hi[at_cap]
        open_ = np.flatnonzero(~at_cap)
        for _ in range(steps):
            mid = (lo[open_] + hi[open_]) / 2
            ok = stable_at(centre + mid[:, None] * e[open_])
            lo[open_[ok]], hi[open_[~ok]] = mid[ok], mid[~ok]
        reach = base + (1 - margin) * (lo - base)
        return {a: [b, r] for a, b, r in zip(angles, base.tolist(), reach.tolist())}

    found = trace(list(2 * np.pi * np.arange(rays) / rays))
    # Certify every vertex and ``checks`` points of every edge. A failing edge gets a ray of its
    # own in the middle (down to 1/16 of the initial spacing), then, if still failing, has its
    # ends pulled halfway back to their base.
    finest = 2 * np.pi / rays / 16
    fractions = np.arange(checks + 1) / (checks + 1)

    def samples(edges: list[float], following: dict[float, float]) -> np.ndarray:
        """The vertex and ``checks`` points of each edge from ray ``a`` to ray ``following[a]`` (``k, checks + 1, 2``)."""
        ends = np.array([[centre + found[k][1] * along(k) for k in (a, following[a])] for a in edges])
        return ends[:, :1] + fractions[None, :, None] * (ends[:, 1:] - ends[:, :1])

    pending = set(found)
    while True:
        keys = sorted(found)
        following = dict(zip(keys, keys[1:] + keys[:1]))
        preceding = {b: a for a, b in following.items()}
        # An edge between two base points lies in STABLE's convex region (or is the certified
        # centre) and cannot fail.
        pending = {a for a in pending if found[a][1] > found[a][0] or found[following[a]][1] > found[following[a]][0]}
        if not pending:
            break
        edges = sorted(pending)
        passed = dict(zip(edges, stable_at(samples(edges, following).reshape(-1, 2)).reshape(len(edges), -1).all(axis=1)))
        grown, moved, new_rays = set(), set(), []
        for a in edges:
            b = following[a]
            if {a, b} & moved:  # checked before an end moved
                passed[a] = bool(stable_at(samples([a], following)[0]).all())
            if passed[a]:
                continue
            gap = (b - a) % (2 * np.pi)
            if gap > finest:
                mid = (a + gap / 2) % (2 * np.pi)
                new_rays.append(mid)
                grown |= {a, mid}
                continue
            for k in (a, b):
                base, reach = found[k]
                found[k][1] = base if reach - base < 1e-6 * size else base + 0.5 * (reach - base)
            moved |= {a, b}
            grown |= {preceding[a], a, b}
        if new_rays:
            found.update(trace(new_rays))
        pending = grown
    traced = shapely.Polygon([centre + found[k][1] * along(k) for k in keys]).buffer(0)
    polygon = shapely.union_all([traced, inner.buffer(0)]) if trusted else traced
    return ExactRegion(stable, polygon, np.asarray(centre, dtype=float), cf_radius)
