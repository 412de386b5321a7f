"""Force status of slider motions: P, U or I (Lynch 1992, §3.3-3.4; docs/mechanics.md, "Force status").

For a contact mode with composite wrench cone ``W`` (rows ``a``: ``a . w >= 0`` on ``W``) and a
slider twist, each admissible support distribution ``mu`` needs the load ``L(mu)`` from the
pusher (:mod:`mechanics.support`). The motion is

* **P** (force possible) if every ``L(mu)`` lies in ``W``: ``sup_mu (-a) . L(mu) <= 0`` for every row;
* **I** (impossible) if none does: some ``y = sum beta_j a_j`` (``beta >= 0``, so ``y . w >= 0``
  on ``W``) has ``sup_mu y . L(mu) < 0``, a hyperplane separating the loads from ``W``;
* **U** (undetermined) otherwise.

Each supremum is a linear programme over distributions, solved on sample points. A discrete
solution alone could hide a distribution between the samples; the verdicts here are
**guaranteed** instead. The LP's dual ``lam`` (multiplier of the centroid constraint) makes
``sup_x y . g(x) + lam . (x - CF)`` an upper bound for every admissible distribution, and
:meth:`SupportLoads.upper_bound` bounds that over covering cells with an explicit curvature
margin. So P is reported only when every row's certified bound is ``<= 0`` and I only when the
separating hyperplane's certified bound is ``< 0``. In the other direction a sample distribution
is a real distribution: a discrete violation proves "not P", a discrete load in ``W`` proves "not
I". When neither proof nor certificate settles a question the samples are refined; what is still
open is reported as U (never wrongly P or I), and :attr:`Verdict.consistent` says which statuses
remain possible.

A translation needs no samples: every distribution gives the same load, through the CF, so it is
P or I, never U (§3.4). (With an uncertain CF the loads of a translation form a segment, which can
be U.)

**Ray search (§3.4).** Along a ray from the CF the COR moves from the CF (a pure rotation about
it) to infinity (a translation), and the paper's status follows one of four patterns: always I,
U then I, always P, U then P. The twist ``(1 - tau) V_0 + tau V_inf`` sweeps the ray as ``tau``
goes from 0 to 1 (a positive combination, §2.2), and bisection on ``tau`` finds the transition.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import shapely
from numpy.typing import ArrayLike

from .cones import Cone
from .support import SupportModel, unit_loads
from .twist import cor_to_twist

__all__ = ["LP_LEVELS", "Verdict", "force_possible", "force_status", "force_status_regions", "possible_or_not",
           "ray_twist"]

#: Sample levels whose support LPs are solved in :func:`possible_or_not`; a finer level bounds the
#: continuum with the last multipliers solved for: the finer cells are what tightens the bound (on
#: four test parts, of 218 twists on a traced boundary that level 3 certified with its own LP, 201
#: were certified with level 2's multipliers; level 4's cells with them certified 214).
LP_LEVELS = 2


@dataclass(frozen=True)
class Verdict:
    """Force status of one motion: ``status`` (``'P'``, ``'U'`` or ``'I'``) and ``consistent``,
    the statuses the computation could not rule out (``'P'``, ``'U'``, ``'I'``, ``'UP'`` or
    ``'UI'``). ``status`` is ``P`` or ``I`` only when proven; ``level`` is the refinement used."""

    status: str
    consistent: str
    level: int

    @property
    def exact(self) -> bool:
        """Whether the status is settled (for U: shown by a possible and an impossible sample load)."""
        return self.consistent == self.status


def _verdict(consistent: set[str], level: int) -> Verdict:
    status = next(iter(consistent)) if len(consistent) == 1 else "U"
    return Verdict(status, "".join(s for s in "PUI" if s in consistent), level)


def _tolerance(support: SupportModel) -> float:
    """How far a sample value may pass zero and still count as rounding."""
    return 1e-9 * (1.0 + float(np.linalg.norm(support.cf)) + support.radius)


def _sticking(twists: np.ndarray, cone: Cone, support: SupportModel, level: int, lams: np.ndarray | None = None,
              coarse: np.ndarray | None = None) -> tuple[np.ndarray, ...]:
    """``(certified, refuted, margin, lams, cells)`` per rotation of ``twists`` (``K, 3``) with the
    samples of ``level``: every row's support value certified ``<= 0`` (P proven), or some sample
    distribution's load violating a row (P disproven); ``margin`` is the largest row's certified
    bound (the largest sample value where refuted): ``<= 0`` exactly where certified; ``lams`` the
    multipliers of the certificate (``K, R, 2``), ``cells`` its bounds per cell (``K, R, C``; NaN
    where refuted). Given ``lams`` (the level below's, with its ``coarse`` cell bounds if known) no
    LP is solved and nothing is refuted: this level's cells refine the level below's where its
    bound could be positive (:meth:`~.support.LoadBatch.refined_bound`; ``cells`` is then NaN)."""
    rows = -cone.rows
    if lams is not None:  # the cells of the level below, split where they could decide
        margin = support.batch(twists, level - 1).refined_bound(rows, lams, coarse).max(axis=1)
        return margin <= 0, np.zeros(len(twists), dtype=bool), margin, lams, None
    batch = support.batch(twists, level)
    values, lams = batch.sample_support(rows)
    margin = values.max(axis=1)
    refuted = margin > _tolerance(support)
    certified = np.zeros(len(twists), dtype=bool)
    cells = np.full((len(twists), len(rows), len(batch.cells.cells)), np.nan)
    if not refuted.all():  # bounding the cells costs more than the LPs: only where it can help
        cells[~refuted] = batch[~refuted].cell_bounds(rows, lams[~refuted])[0]
        margin[~refuted] = (cells[~refuted].max(axis=-1)
                            + support.cf_radius * np.linalg.norm(lams[~refuted], axis=-1)).max(axis=1)
        certified[~refuted] = margin[~refuted] <= 0
    return certified, refuted, margin, lams, cells


def _statuses_at(twists: np.ndarray, cone: Cone, support: SupportModel, level: int) -> list[set[str]]:
    """The statuses not ruled out for each rotation of ``twists`` (``K, 3``) with the samples of
    ``level``: the P proofs in one batch, then the I proofs of the others in another."""
    certified, refuted, *_ = _sticking(twists, cone, support, level)
    tol = _tolerance(support)
    value = np.full(len(twists), np.nan)
    impossible = np.zeros(len(twists), dtype=bool)
    rest = np.flatnonzero(~certified)
    if len(rest):
        beta, lam, value[rest] = support.batch(twists[rest], level).minimax(cone.rows)
        separated = value[rest] < -tol  # a hyperplane the samples' loads all miss: prove it for all loads
        if separated.any():
            check = support.batch(twists[rest[separated]], level)
            impossible[rest[separated]] = check.is_negative(beta[separated] @ cone.rows, lam[separated], tol)
    out = []
    for proven, disproven, shown, v in zip(certified, refuted, impossible, value):
        if proven or shown:
            out.append({"P"} if proven else {"I"})
            continue
        consistent = {"P", "U", "I"}
        if disproven or v < -tol:  # the samples show a load outside W
            consistent.discard("P")
        if v >= -tol:  # a sample distribution's load is in W
            consistent.discard("I")
        out.append(consistent)
    return out


def _translation_status(v: np.ndarray, cone: Cone, support: SupportModel) -> Verdict:
    """A translation's load is the unit force along it through the CF, whatever the distribution;
    with the CF anywhere in a disk of radius ``rho`` its moment spans ``m0 +- rho``: a segment of
    loads, P when all of it lies in the cone, I when none does (each row cuts the segment once)."""
    load = unit_loads(v, support.cf)
    if support.cf_radius == 0:
        return Verdict(*("PP" if cone.contains(load) else "II"), 0)
    ends = load + np.array([[0.0, 0.0, -support.cf_radius], [0.0, 0.0, support.cf_radius]])
    if cone.contains(ends).all():
        return Verdict("P", "P", 0)
    lo, hi = 0.0, 1.0  # points (1 - s) ends[0] + s ends[1] of the segment in the cone
    for a0, a1 in (cone.rows @ ends.T).tolist():
        if a0 < 0 and a1 < 0:
            return Verdict("I", "I", 0)
        if a0 < 0 <= a1 or a1 < 0 <= a0:
            cross = a0 / (a0 - a1)
            lo, hi = (max(lo, cross), hi) if a0 < 0 else (lo, min(hi, cross))
    return Verdict(*("UU" if lo <= hi else "II"), 0)  # an equality is a pair of opposite rows


def force_status(twist: ArrayLike, cone: Cone, support: SupportModel, refinements: int = 1) -> Verdict:
    """Force status of the slider ``twist`` for a mode with composite wrench ``cone``.

    ``refinements`` extra sample levels are tried while the verdict is open.

    Examples
    --------
    A 2 x 1 block pushed on its whole bottom face, both ends sticking, mu = 0.5. Pushing straight
    ahead is P (its load, through the CF, is inside the cone); sideways is I. Turning about
    ``(-3, 0.5)``, far to the left, is P (docs/mechanics.md, "Membership table", fixture A); turning about the CF is
    U (a ring of support needs a pure moment, a point support at the CF needs nothing at all).

    >>> from mechanics import ContactConfiguration, Slider, contact_wrench_cone, cor_to_twist
    >>> block = Slider([[-1, 0], [1, 0], [1, 1], [-1, 1]])
    >>> cone = contact_wrench_cone(ContactConfiguration.slider_edge(block, 0, 0.5), "ss")
    >>> support = SupportModel.of_slider(block, "footprint")
    >>> [force_status(v, cone, support).status for v in ([0, 1, 0], [1, 0, 0])]
    ['P', 'I']
    >>> force_status(cor_to_twist([-3, 0.5], 1), cone, support)
    Verdict(status='P', consistent='P', level=0)
    >>> force_status(cor_to_twist([0, 0.5], 1), cone, support).status
    'U'
    """
    return _verdicts(np.asarray(twist, dtype=float)[None], cone, support, refinements)[0]


def _without_samples(v: np.ndarray, cone: Cone, support: SupportModel) -> Verdict | None:
    """The verdict of a twist that needs no support samples, else ``None``."""
    if len(cone.rows) == 0:  # the contact forces span the wrench space
        return Verdict("P", "P", 0)
    if v[2] == 0:
        return _translation_status(v, cone, support)
    if cone.dimension == 0:  # no contact force, and any motion needs one
        return Verdict("I", "I", 0)
    return None


def _verdicts(twists: np.ndarray, cone: Cone, support: SupportModel, refinements: int) -> list[Verdict]:
    """:func:`force_status` of each of ``twists`` (``K, 3``), refining those still open together."""
    verdicts = [_without_samples(v, cone, support) for v in twists]
    rotations = [k for k, verdict in enumerate(verdicts) if verdict is None]
    consistent = {k: {"P", "U", "I"} for k in rotations}
    open_ = rotations
    for level in range(refinements + 1):
        if not open_:
            break
        for k, found in zip(open_, _statuses_at(twists[open_], cone, support, level)):
            consistent[k] &= found
            verdicts[k] = _verdict(consistent[k], level)
        open_ = [k for k in open_ if len(consistent[k]) > 1]
    return verdicts


def force_possible(twists: ArrayLike, cone: Cone, support: SupportModel, refinements: int = 1) -> np.ndarray:
    """Whether each of ``twists`` (shape ``(..., 3)``) is proven force possible (P) for a mode
    with composite wrench ``cone``: ``force_status(twist, cone, support, refinements).status ==
    "P"`` for each, computed for all of them at once (the LPs batched, the I proofs skipped).

    Examples
    --------
    Fixture A (docs/mechanics.md, "Membership table"): turning CCW about (-3, 0.5) or (-3, 1.2) and pushing straight
    are P for both ends sticking; the mirror CW turn and a sideways push are not.

    >>> from mechanics import ContactConfiguration, Slider, contact_wrench_cone, cor_to_twist
    >>> block = Slider([[-1, 0], [1, 0], [1, 1], [-1, 1]])
    >>> cone = contact_wrench_cone(ContactConfiguration.slider_edge(block, 0, 0.5), "ss")
    >>> twists = [*cor_to_twist([[-3, 0.5], [-3, 1.2], [-3, 0.5]], [1, 1, -1]), [0, 1, 0], [1, 0, 0]]
    >>> force_possible(twists, cone, SupportModel.of_slider(block, "footprint")).tolist()
    [True, True, False, True, False]
    """
    return possible_or_not(twists, cone, support, refinements)[0]


def possible_or_not(twists: ArrayLike, cone: Cone, support: SupportModel, refinements: int = 1,
                    start: int | ArrayLike = 0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(proven, disproven, margin)`` for each of ``twists`` (shape ``(..., 3)``): P proven (as
    :func:`force_possible`), or P disproven by a sample distribution whose load leaves ``cone`` (a
    real distribution, so the twist is certainly not P); neither: open at the finest level tried.
    ``margin`` is the certificate's largest row bound at the last level tried (``<= 0`` exactly
    where proven; NaN for a twist settled without samples, a translation): a continuous measure
    of how far a twist is from being certified, for root finding.

    The levels run from ``start`` (one for all twists, or one each) to ``refinements``, each only
    for the twists still open, so a batch whose twists lie far from the boundary of the P set costs
    one level (``start`` skips levels known to leave twists near that boundary open); each level
    is one batch of LPs for all the twists it holds.

    >>> from mechanics import ContactConfiguration, Slider, contact_wrench_cone, cor_to_twist
    >>> block = Slider([[-1, 0], [1, 0], [1, 1], [-1, 1]])
    >>> cone = contact_wrench_cone(ContactConfiguration.slider_edge(block, 0, 0.5), "ss")
    >>> proven, disproven, margin = possible_or_not(cor_to_twist([[-3, 0.5], [-3, 0.5]], [1, -1]), cone,
    ...                                             SupportModel.of_slider(block, "footprint"))
    >>> proven.tolist(), disproven.tolist(), bool(margin[0] <= 0 < margin[1])
    ([True, False], [False, True], True)
    """
    v = np.asarray(twists, dtype=float)
    flat = v.reshape(-1, 3)
    known = [_without_samples(twist, cone, support) for twist in flat]
    proven = np.array([verdict is not None and verdict.status == "P" for verdict in known], dtype=bool)
    disproven = np.array([verdict is not None and verdict.status != "P" and "P" not in verdict.consistent
                          for verdict in known], dtype=bool)
    margin = np.full(len(flat), np.nan)
    first = np.minimum(np.broadcast_to(np.asarray(start, dtype=int), v.shape[:-1]).ravel(), refinements)
    open_ = np.array([k for k, verdict in enumerate(known) if verdict is None], dtype=int)
    lams = np.full((len(flat), len(cone.rows), 2), np.nan)
    cells: dict[int, np.ndarray] = {}  # the cell bounds of the level below, by twist
    for level in range(int(first.min(initial=refinements)), refinements + 1):
        ask = open_[first[open_] <= level]
        # Above LP_LEVELS the multipliers of the level below are kept (they barely change, and the
        # finer cells are what tightens the bound); twists that start there solve their LP.
        keep = ~np.isnan(lams[ask, 0, 0]) & (level > LP_LEVELS)
        kept, solved = ask[keep], ask[~keep]
        have = len(kept) and all(k in cells for k in kept.tolist())
        below = np.array([cells[k] for k in kept.tolist()]) if have else None
        cells = {}
        for part, given, coarse in ((solved, None, None), (kept, lams[kept], below)):
            if len(part):
                certified, refuted, margin[part], lams[part], bounds = _sticking(flat[part], cone, support, level,
                                                                                 given, coarse)
                proven[part[certified]] = True
                disproven[part[refuted]] = True
                if bounds is not None:
                    cells.update(zip(part.tolist(), bounds))
        open_ = open_[~proven[open_] & ~disproven[open_]]
    shape = v.shape[:-1]
    return proven.reshape(shape), disproven.reshape(shape), margin.reshape(shape)


def ray_twist(cf: ArrayLike, angle: float, tau: ArrayLike, sense: int, scale: float) -> np.ndarray:
    """Twist whose COR lies on the ray from ``cf`` at ``angle``, at distance ``scale tau/(1-tau)``.

    ``tau = 0`` turns about the CF, ``tau = 1`` translates (the COR at infinity, with ``sense``
    giving the side: a CCW COR far along ``e`` moves the part along ``e`` turned by -90 deg).

    >>> ray_twist([0, 0], 0.0, [0.0, 0.5, 1.0], 1, 1.0).tolist()  # CORs (0, 0), (1, 0), infinity
    [[0.0, 0.0, 1.0], [0.0, -0.5, 0.5], [0.0, -1.0, 0.0]]
    """
    e = np.array([np.cos(angle), np.sin(angle)])
    tau = np.asarray(tau, dtype=float)[..., None]
    at_cf = cor_to_twist(np.asarray(cf, dtype=float), sense) / scale
    at_infinity = sense * np.array([e[1], -e[0], 0.0])
    return (1 - tau) * at_cf + tau * at_infinity + 0.0


def _rays(cone: Cone, support: SupportModel, rays: list[tuple[float, int]], steps: int,
          refinements: int) -> list[tuple[str, str, float]]:
    """Per ray ``(angle, sense)`` from the CF, ``(inner, outer, distance)``: status near the CF,
    status towards infinity, and the distance of the transition from the CF (0 if the status does
    not change). The rays' bisections run side by side, one batch of verdicts per step."""
    def statuses(which: np.ndarray, taus: np.ndarray) -> np.ndarray:
        twists = np.array([ray_twist(support.cf, rays[j][0], tau, rays[j][1], support.radius) for j, tau in zip(which, taus)])
        return np.array([v.status for v in _verdicts(twists.reshape(-1, 3), cone, support, refinements)], dtype=object)

    every = np.arange(len(rays))
    inner, outer = np.split(statuses(np.r_[every, every], np.r_[np.zeros(len(rays)), np.ones(len(rays))]), 2)
    turning = np.flatnonzero(inner != outer)
    lo, hi = np.zeros(len(rays)), np.ones(len(rays))
    for _ in range(steps):
        mid = (lo[turning] + hi[turning]) / 2
        beyond = statuses(turning, mid) == outer[turning]
        hi[turning[beyond]], lo[turning[~beyond]] = mid[beyond], mid[~beyond]
    tau = (lo + hi) / 2
    distance = np.where(inner != outer, support.radius * tau / (1 - tau), 0.0)
    return list(zip(inner.tolist(), outer.tolist(), distance.tolist()))


def force_status_regions(
    cone: Cone,
    support: SupportModel,
    window: ArrayLike | None = None,
    rays: int = 24,
    steps: int = 10,
    refinements: int = 1,
) -> dict[int, dict[str, shapely.Geometry]]:
    """P, U and I regions of rotation centres per sense, ``{sense: {status: geometry}}``, by ray bisection.

    ``rays`` rays from the CF per sense, ``steps`` bisection steps each; a ray's statuses fill
    the half-sectors on either side of it, and neighbouring rays with the same pattern are joined
    by straight edges (adjoining segments merge into regions, §3.4). The default window is a
    square of half-side ``4 r`` about the CF.

    Examples
    --------
    A single sliding contact (one line of force, up along ``x = 0.5``) on the unit disk: nothing
    is P, the CW CORs are all I (the load's moment about the CF has the sense of rotation), and
    the U region is the COR locus of that line of force, on the far side of the CF.

    >>> from mechanics import ContactConfiguration, contact_wrench_cone
    >>> line = contact_wrench_cone(ContactConfiguration([[0.5, -1]], [[0, 1]], 0.0), "s")
    >>> regions = force_status_regions(line, SupportModel.disk([0, 0], 1.0), rays=8, steps=6)
    >>> regions[1]["P"].is_empty, regions[-1]["U"].is_empty, regions[-1]["P"].is_empty
    (True, True, True)
    >>> regions[1]["U"].bounds[0] < -1 < regions[1]["U"].bounds[2] <= 0.5
    True
    """
    cf = support.cf
    if window is None:
        window = (*(cf - 4 * support.radius), *(cf + 4 * support.radius))
    box = shapely.box(*window)
    corners = np.array(box.exterior.coords)
    far = 2 * float(np.max(np.linalg.norm(corners - cf, axis=1)))
    angles = 2 * np.pi * np.arange(rays) / rays
    traced = _rays(cone, support, [(a, sense) for sense in (1, -1) for a in angles], steps, refinements)
    out = {}
    for sense, found in zip((1, -1), (traced[:rays], traced[rays:])):
        pieces: dict[str, list[shapely.Polygon]] = {"P": [], "U": [], "I": []}
        for j, (inner, outer, dist) in enumerate(found):
            for k in ((j - 1) % rays, (j + 1) % rays):
                # The half-sector between ray j and the bisector towards its neighbour k.
                mid = angles[j] + np.angle(np.exp(1j * (angles[k] - angles[j]))) / 2
                same = found[k][:2] == (inner, outer)
                at_mid = min((dist + found[k][2]) / 2 if same else dist, far)
                e_j, e_m = (np.array([np.cos(a), np.sin(a)]) for a in (angles[j], mid))
                d = min(dist, far)
                if d > 0 or at_mid > 0:
                    pieces[inner].append(shapely.Polygon([cf, cf + d * e_j, cf + at_mid * e_m]))
                pieces[outer].append(shapely.Polygon([cf + d * e_j, cf + far * e_j, cf + far * e_m, cf + at_mid * e_m]))
        out[sense] = {s: shapely.union_all([p for p in pieces[s] if p.is_valid] or [shapely.Polygon()]).intersection(box)
                      for s in "PUI"}
    return out
