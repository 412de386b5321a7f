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
2. ``rays`` even rays from ``C``; along each, the boundary is bracketed by certifying a few points
   between ``S``'s boundary and the edge of Theorem 4's strip (or a distance far beyond any stable
   push) in one batch, then narrowed to ``resolution`` by a bracketed search on the certificate's
   margin (:func:`~.force_status.possible_or_not`): each round certifies points evenly spaced in
   the bracket (up to ``_SECTIONS - 1``) and two points a step apart about the secant's root,
   which usually ends the search at once; a round costs far more than a point in it, so a few
   rounds of several points beat many rounds of two. Each vertex is the last certified point: no
   safety margin.
3. Adaptively, where the boundary turns or thins: every interval between neighbouring rays gets
   a ray in its middle, searched outwards from the chord of its neighbours; a boundary within
   ``_CHORD`` steps of the chord ends the refinement there, else both halves are refined again
   (down to ``2**-depth`` of the first spacing; both sides of a vertex where the boundary turns by
   more than ``_TURN`` one halving further, since a corner can hide between a midpoint that fits
   the chord and its neighbour). A needle caught by one ray makes the chords to its neighbours
   miss, so rays gather along it to its tip.
4. ``checks`` points on every edge are certified; an edge with a failure gets a new ray in its
   middle (the region can be far from convex), and one that still fails at the finest spacing
   has its ends pulled back, by one step and then twice as far each time, until all pass.
5. The region is that star-shaped polygon united with ``S``.

The certificate is refined only near the boundary: each twist starts at the coarsest support
grid and goes to the next ``refinements`` levels only while neither certified nor refuted, and a
twist known to lie near the boundary (a new ray's points next to the chord, the checks, the last
steps of a search) skips the coarsest level, which leaves such twists open. Above level 2 no LP
is solved: the level-2 multipliers are kept and only the level-2 cells whose bound could be
positive are split (:data:`~.force_status.LP_LEVELS`, :meth:`~.support.LoadBatch.refined_bound`),
so level 3 costs a fraction of level 2.

**Gap bound.** Along each ray the true boundary lies between the vertex (certified) and the
nearest point proven unstable (a sample distribution's load leaves the cone, or Theorem 4's strip
ends); between rays, within the last chords' misfit. :attr:`ExactRegion.gap` is the largest of
these (push-plane units): an a-posteriori bound of how much stable set the polygon leaves out,
under the same assumptions as the trace (one crossing per ray, a boundary that does not turn
between samples).

The certifications are batched: the rays' searches run side by side, one batch of twists per
round, and a pass of step 4 checks all its edges in one batch (an edge whose end another edge
pulled back being checked again), so each batch's support LPs are solved together; no step
depends on the order within a batch, so the region does not depend on how the rays are stored.
``deadline`` stops the construction between batches.

**Robustness (Lynch 1992, §6).** A friction coefficient known only within an interval gives the
region of its lowest value (sticking there implies sticking above it). A CF known only within a
disk is a linear constraint on the distribution's centre (:class:`~.support.SupportModel`
``cf_radius``): the certified verdicts then hold for every CF in the disk. STABLE's region, drawn
for the nominal CF, is then not trusted: the trace starts from its centroid and certifies
everything.

What is guaranteed: every vertex and every twist on the boundary samples of step 4 is certified P
(a discretised distribution cannot produce a false P, :mod:`.force_status`); between samples the
boundary is trusted at the ray resolution, and the interior is trusted to be star-shaped about
``C`` (the search assumes one P-to-not-P crossing per ray). The tests check both against a much
finer grid and an independent linear programme over explicit distributions.

Examples
--------
docs/mechanics.md, "Membership table", fixture A (2 x 1 block pushed on its whole bottom face, mu = 0.5): CCW about
(-3, 1.2) and (-1.5, 0.5) are stable, though STABLE misses both; the mirror CW turn is not.

>>> from mechanics import Slider, cor_to_twist, stable_region
>>> block = Slider([[-1, 0], [1, 0], [1, 1], [-1, 1]])
>>> exact = exact_region(block, 0, 0.5)
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
from .force_status import possible_or_not
from .slider import Slider
from .stable import StableRegion, procedure_stable
from .support import SupportModel
from .twist import twist_to_cor
from .wrenches import contact_wrench_cone

__all__ = ["DeadlineExceeded", "ExactRegion", "exact_region"]

#: How far beyond STABLE's section a ray is searched, in units of that section's size: far past any
#: stable push (sideways pushes are force impossible), so the cap never binds in practice.
_REACH = 8.0
#: Where the first rays are certified in one batch, as fractions of the way from STABLE's boundary
#: to the end of the search: a bracket of the boundary before the secant search.
_SPREAD = np.array([1 / 16, 1 / 8, 1 / 4, 1 / 2, 1.0])
#: Most pieces a round of the search cuts a ray's bracket into.
_SECTIONS = 4
#: How far (in steps of the resolution) a new ray's boundary may lie from the chord of its
#: neighbours and end the refinement there.
_CHORD = 4.0
#: A turn of the boundary (radians) at a vertex beyond which both its sides are refined.
_TURN = 0.8
#: Where a new ray is certified in one batch, in units of ``_CHORD`` steps from the chord of its
#: neighbours.
_GALLOP = np.array([-16.0, -4.0, -1.0, 1.0, 4.0, 16.0])


class DeadlineExceeded(RuntimeError):
    """An exact region was not finished by the deadline it was given."""


@dataclass(frozen=True, eq=False)
class ExactRegion:
    """The exact stable pushes of one edge, with the interface of :class:`~.stable.StableRegion`.

    ``polygon`` is the region's section in the push plane (:attr:`plane`), star-shaped about
    ``centre``; ``stable`` is procedure STABLE's region for the same edge (at the lowest friction
    and the nominal CF; contained in this one when the CF is known); ``cf_radius`` the radius of
    the CF's uncertainty disk the region allows for; ``gap`` the a-posteriori bound on how far
    the true boundary may lie beyond the polygon (module docstring; NaN when not known, e.g. for a
    region read from a cache that did not keep it).
    """

    stable: StableRegion
    polygon: shapely.Geometry
    centre: np.ndarray
    cf_radius: float = 0.0
    gap: float = float("nan")

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
    rays: int = 16,
    resolution: float = 0.002,
    refinements: int = 3,
    checks: int = 1,
    depth: int = 2,
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
        Rays of the first, even trace (at least 8); more are placed where the boundary needs them.
    resolution : float
        Length, as a fraction of STABLE's section's size, to which each ray is bisected; a new ray's
        boundary within twice that of the chord of its neighbours ends the refinement there.
    refinements : int
        Finer levels of the certificate tried where a twist is neither certified nor refuted (only
        near the boundary, so they cost little).
    checks : int
        Points certified on each boundary edge between neighbouring rays, besides the vertices.
    depth : int
        How many times an interval between rays may be halved where the boundary needs it (also
        for an edge whose checks fail): the finest spacing is ``2**-depth`` of the first, and half
        that next to a corner. On fifteen test geometries (three each of a triangle, a hexagon, an
        off-centre-CF rectangle pushed by part of a face, an L, a trapezoid) the defaults cover
        0.991 to 0.998 of an independent LP oracle's stable twists (docs/mechanics.md).
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
    >>> loose = exact_region(block, 0, (0.4, 0.6))
    >>> loose.polygon.equals(exact_region(block, 0, 0.4).polygon)
    True
    >>> bool(exact_region(block, 0, 0.5, cf_radius=0.05).polygon.area < exact_region(block, 0, 0.5).polygon.area)
    True
    """
    mu_lo, mu_hi = (float(mu), float(mu)) if np.isscalar(mu) else (float(min(mu)), float(max(mu)))
    if not 0 < mu_lo <= mu_hi:
        raise ValueError(f"mu must be > 0 (an interval: low <= high), got {mu}")
    if not cf_radius >= 0:
        raise ValueError(f"cf_radius must be >= 0, got {cf_radius}")
    stable = procedure_stable(slider, edge, mu_lo, width)
    if stable.is_empty:
        return ExactRegion(stable, shapely.Polygon(), np.zeros(2), cf_radius, 0.0)
    if rays < 8:
        raise ValueError(f"rays must be at least 8, got {rays}")
    if not resolution > 0:
        raise ValueError(f"resolution must be > 0, got {resolution}")
    if depth < 0:
        raise ValueError(f"depth must be >= 0, got {depth}")
    inner, centre = stable.section()
    if not (isinstance(inner, shapely.Polygon) and inner.area > 0):  # translations only: nothing to trace
        # ...and with an uncertain CF not even those are proven: give none.
        return ExactRegion(stable, inner if cf_radius == 0 else shapely.Polygon(), centre, cf_radius, 0.0)
    plane = stable.plane
    cone = contact_wrench_cone(ContactConfiguration.slider_edge(slider, edge, mu_lo, width), "s" * 2)
    support = SupportModel.of_slider(slider, "footprint", cf_radius=cf_radius)
    w_lo, w_hi = plane.theorem4_strip(slider.vertices)
    trusted = cf_radius == 0  # STABLE's region is proven only for a known CF

    def settled(points: np.ndarray, near: np.ndarray | bool = False) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(stable, unstable, margin)`` of ``points`` (``k, 2``), all at once: certified P
        strictly inside Theorem 4's strip, or (if trusted) inside STABLE's region; or proven not
        stable (outside the strip, or a sample distribution's load leaves the cone); neither: open.
        ``margin`` is the certificate's (:func:`~.force_status.possible_or_not`; NaN where none was
        needed). Points ``near`` the boundary start at the first refinement: the coarsest level
        leaves them open."""
        if deadline is not None and time.perf_counter() > deadline:
            raise DeadlineExceeded(f"the exact region of edge {edge} was not finished by the deadline")
        points = np.atleast_2d(points)
        twists = plane.twists(points)
        proven = stable.contains(twists) if trusted else np.zeros(len(points), dtype=bool)
        inside = (w_lo < points[:, 1]) & (points[:, 1] < w_hi)
        refuted, margin = ~inside, np.full(len(points), np.nan)
        ask = ~proven & inside
        if ask.any():
            start = np.broadcast_to(near, ask.shape)[ask].astype(int)
            proven[ask], refuted[ask], margin[ask] = possible_or_not(twists[ask], cone, support, refinements, start)
        return proven, refuted, margin

    if not trusted and not settled(centre)[0][0]:
        return ExactRegion(stable, shapely.Polygon(), np.zeros(2), cf_radius, 0.0)
    size = max(float(np.ptp(np.asarray(inner.bounds).reshape(2, 2), axis=0).max()), 1e-9)
    step = resolution * size

    def along(angles: float | np.ndarray) -> np.ndarray:
        # Exact zeros on the axes: a ray along w = 0 must stay on the translations, not turn
        # about centres 1e16 away.
        e = np.stack([np.cos(angles), np.sin(angles)], axis=-1)
        return np.where(np.abs(e) < 1e-12, 0.0, e)

    ring = np.asarray(shapely.orient_polygons(inner).exterior.coords)
    normals = np.c_[ring[1:, 1] - ring[:-1, 1], ring[:-1, 0] - ring[1:, 0]]  # outward for a CCW ring
    offsets = np.einsum("ij,ij->i", normals, ring[:-1] - centre)

    def spokes(e: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Where each ray (unit ``e``) leaves STABLE's region (or 0), the farthest point searched
        (Theorem 4's strip, or a distance far beyond any stable push), and where it leaves the
        strip (nothing beyond is stable; ``inf`` if never)."""
        if trusted:  # the exit from a convex polygon holding the centre: its nearest edge ahead
            with np.errstate(divide="ignore", invalid="ignore"):
                ahead = e @ normals.T
                base = np.min(np.where(ahead > 0, offsets / ahead, np.inf), axis=1)
        else:
            base = np.zeros(len(e))
        with np.errstate(divide="ignore", invalid="ignore"):
            strip = np.where(e[:, 1] != 0, (np.where(e[:, 1] > 0, w_hi, w_lo) - centre[1]) / e[:, 1], np.inf)
        return base, np.minimum(_REACH * size, strip) * (1 - 1e-9), strip

    def bracket(e: np.ndarray, base: np.ndarray, cap: np.ndarray, reach: np.ndarray,
                near: np.ndarray | bool) -> tuple[np.ndarray, ...]:
        """Each ray's bracket from the points ``reach`` (``k, j``, increasing) along it, certified
        in one batch: ``(lo, hi, margin at lo, margin at hi, nearest proven unstable)``, ``lo`` the
        last certified point before the first that is not (one crossing per ray is assumed).
        Points not beyond ``base`` (certified already, or inside STABLE's region: a row's unused
        places) are not certified again."""
        k, j = reach.shape
        ok, no, margin = np.ones((k, j), dtype=bool), np.zeros((k, j), dtype=bool), np.full((k, j), np.nan)
        new = reach > base[:, None]
        ok[new], no[new], margin[new] = settled((centre + reach[..., None] * e[:, None])[new],
                                                np.broadcast_to(near, (k, j))[new])
        first = np.where(ok.all(axis=1), j, np.argmin(ok, axis=1))
        rows = np.arange(k)
        below, above = np.maximum(first - 1, 0), np.minimum(first, j - 1)
        lo = np.where(first > 0, reach[rows, below], base)
        f_lo = np.where(first > 0, margin[rows, below], np.nan)
        hi = np.where(first < j, reach[rows, above], cap)
        f_hi = np.where(first < j, margin[rows, above], np.nan)
        out = np.min(np.where(no & (reach > lo[:, None]), reach, np.inf), axis=1)
        return lo, hi, f_lo, f_hi, out

    def search(e: np.ndarray, lo: np.ndarray, hi: np.ndarray, f_lo: np.ndarray, f_hi: np.ndarray,
               out: np.ndarray) -> None:
        """Narrow each ray's bracket (``lo`` certified, ``hi`` not) to ``step``, side by side, one
        batch per round; ``out`` keeps the nearest point proven unstable. A round certifies points
        evenly spaced in each bracket (as many as it has steps, up to ``_SECTIONS - 1``) and,
        where both margins are known, two points a step apart about the secant's root: the margin
        is close to linear near the boundary, so the secant often ends the search at once, and
        where it misses, the even points cut the bracket into many pieces (a batch costs far more
        than a twist in it)."""
        while len(open_ := np.flatnonzero(hi - lo > step)):
            a, b, fa, fb = lo[open_], hi[open_], f_lo[open_], f_hi[open_]
            width = b - a
            with np.errstate(divide="ignore", invalid="ignore"):
                root = a + width * fa / (fa - fb)
            secant = np.isfinite(root) & (width > 2 * step)
            count = np.clip(np.ceil(width / step).astype(int) - 1, 1, _SECTIONS - 1)
            places = np.arange(1, count.max() + 1)
            # A row's unused places repeat its certified end, which bracket() skips.
            even = np.where(places <= count[:, None], a[:, None] + width[:, None] * places / (count[:, None] + 1),
                            a[:, None])
            x = np.clip(root, a + step / 2, b - step / 2)[:, None]
            pair = np.where(secant[:, None], np.c_[x - step / 2, x + step / 2], a[:, None])
            new = bracket(e[open_], a, b, np.sort(np.c_[even, pair], axis=1), (width <= 16 * step)[:, None])
            lo[open_], hi[open_], out[open_] = new[0], new[1], np.minimum(out[open_], new[4])
            f_lo[open_] = np.where(new[0] > a, new[2], fa)
            f_hi[open_] = np.where(new[1] < b, new[3], fb)

    # Per ray angle: [base, reach (certified), nearest point not certified, nearest proven unstable].
    found: dict[float, list[float]] = {}
    angles = 2 * np.pi * np.arange(rays) / rays
    e = along(angles)
    base, cap, strip = spokes(e)
    lo, hi, f_lo, f_hi, out = bracket(e, base, cap, base[:, None] + (cap - base)[:, None] * _SPREAD[None], False)
    search(e, lo, hi, f_lo, f_hi, out)
    found.update(zip(angles.tolist(), np.c_[base, lo, hi, np.minimum(out, strip)].tolist()))

    def vertex(a: float) -> np.ndarray:
        return centre + found[a][1] * along(a)

    finest = 2 * np.pi / rays / 2**depth
    fractions = np.arange(1, checks + 1) / (checks + 1)
    pending, unchecked = set(found), set(found)  # intervals to probe; edges whose samples are not certified
    pulls: dict[float, float] = {}
    chord_gap = 0.0
    while True:
        keys = sorted(found)
        following = dict(zip(keys, keys[1:] + keys[:1]))
        preceding = {b: a for a, b in following.items()}
        # Where the boundary turns sharply (a corner, a needle's tip) a midpoint can fall on the
        # chord while the corner lies between it and a neighbour: both sides of such a vertex are
        # refined however well their midpoints fit.
        corners = np.array([vertex(k) for k in keys])
        ahead, behind = np.roll(corners, -1, axis=0) - corners, corners - np.roll(corners, 1, axis=0)
        turn = np.abs(np.arctan2(behind[:, 0] * ahead[:, 1] - behind[:, 1] * ahead[:, 0], np.einsum("ij,ij->i", behind, ahead)))
        # Corners are followed one halving further than the rest of the boundary.
        sharp = {j for k in np.array(keys)[turn > _TURN].tolist() for j in (preceding[k], k)}
        # Neighbours both on STABLE's boundary (convex, and united with the trace) or both on the
        # strip's edge (a straight line) leave nothing between them to find.
        probe = sorted(a for a in pending | sharp if (following[a] - a) % (2 * np.pi) > (finest / 2 if a in sharp else finest)
                       and not all(found[k][1] <= found[k][0] for k in (a, following[a]))
                       and not all(found[k][1] >= found[k][2] for k in (a, following[a])))
        pending = set()
        if probe:
            # A ray in the middle of each interval, searched from the chord of its neighbours
            # outwards: a boundary within 2 steps of the chord ends the refinement there, else
            # both halves go on.
            mids = np.array([(a + (following[a] - a) % (2 * np.pi) / 2) % (2 * np.pi) for a in probe])
            e = along(mids)
            base, cap, strip = spokes(e)
            ends = np.array([[vertex(a), vertex(following[a])] for a in probe])
            chord = ends[:, 1] - ends[:, 0]
            start = ends[:, 0] - centre
            with np.errstate(divide="ignore", invalid="ignore"):
                guess = (start[:, 0] * -chord[:, 1] + start[:, 1] * chord[:, 0]) / (e[:, 0] * -chord[:, 1] + e[:, 1] * chord[:, 0])
            guess = np.clip(np.where(np.isfinite(guess), guess, base), base, cap)
            reach = np.clip(guess[:, None] + _CHORD * step * _GALLOP[None], base[:, None], cap[:, None])
            lo, hi, f_lo, f_hi, out = bracket(e, base, cap, reach, np.abs(_GALLOP) <= 4)
            held = (lo >= guess - _CHORD * step) & (hi <= guess + _CHORD * step)
            search(e, lo, hi, f_lo, f_hi, out)
            chord_gap = max(chord_gap, float(np.max(np.abs(lo - guess)[held], initial=0.0)))
            for a, m, b, l, h, o, kept in zip(probe, mids.tolist(), base, lo, hi, np.minimum(out, strip), held):
                found[m] = [b, l, h, o]
                unchecked |= {a, m}
                if not kept:
                    pending |= {a, m}
            continue
        # An edge between two base points lies in STABLE's convex region (or is the certified
        # centre) and cannot fail.
        edges = sorted(a for a in unchecked if found[a][1] > found[a][0] or found[following[a]][1] > found[following[a]][0])
        unchecked = set()
        if not edges:
            break
        ends = np.array([[vertex(a), vertex(following[a])] for a in edges])
        samples = ends[:, :1] + fractions[None, :, None] * (ends[:, 1:] - ends[:, :1])
        passed = settled(samples.reshape(-1, 2), True)[0].reshape(len(edges), -1).all(axis=1)
        moved: set[float] = set()
        for a, ok in zip(edges, passed):
            b = following[a]
            if {a, b} & moved:  # checked before an end moved: check again
                unchecked.add(a)
                continue
            if ok:
                continue
            if (b - a) % (2 * np.pi) > finest:
                pending.add(a)
                continue
            # At the finest spacing, pull both ends back, by twice as much each time.
            for k in (a, b):
                pulls[k] = 2 * pulls.get(k, step / 2)
                found[k][1] = max(found[k][0], found[k][1] - pulls[k])
                moved.add(k)
                unchecked |= {preceding[k], k}
    keys = sorted(found)
    reach = np.array([found[k] for k in keys])
    # The gap: how far the true boundary may lie beyond the polygon, along each ray (to the nearest
    # twist proven unstable) and between rays (the last chords' misfit).
    gap = max(float(np.max(reach[:, 3] - reach[:, 1])), chord_gap)
    traced = shapely.Polygon(centre + reach[:, 1:2] * along(np.array(keys))).buffer(0)
    polygon = shapely.union_all([traced, inner.buffer(0)]) if trusted else traced
    return ExactRegion(stable, polygon, np.asarray(centre, dtype=float), cf_radius, gap)
