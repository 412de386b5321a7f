"""Certified stability margins of pushes: how far each push is from slipping (docs/mechanics.md, "Stability margins").

A push of an edge is guaranteed stable (:mod:`.exact_region`) when it lies strictly inside
Theorem 4's strip and sticking is certified force possible for every support distribution centred
anywhere in the CF's uncertainty disk. Two numbers say how much of that guarantee is to spare:

* ``mu_low``: the lowest pusher friction at which the push is still certified (with the scene's CF
  disk). Sticking at a friction implies sticking at any higher one (the contact's friction cone,
  and so its wrench cone, only grows), so the push holds for every friction from ``mu_low`` up:
  ``1 - mu_low / mu`` is the share of the nominal friction that may be lost.
* ``cf_radius``: the largest disk about the CF for which the push is still certified at the
  nominal friction. A larger disk admits more distributions, so the push holds for every CF within
  that distance of the nominal one.

Both are searched on a ladder of ``rungs`` evenly spaced values (frictions ``k mu / rungs``; radii
``k r / rungs``, ``r`` the part's radius, up to the CF's depth in the part, the radius of the
largest disk of CFs the part can have, plus the scene's own radius), by bisection of each twist's
bracket, and the reported value is the last rung a certificate proved: never an interpolation, so
each is a certified bound whatever the certificate does between rungs; where the certificate is
monotone along the ladder (as the property it certifies is) what it can prove lies within one rung
of it. A bisection round certifies every twist at the rung in the middle of its bracket, one batch
of LPs per distinct rung (one wrench cone or one support model serves all of a rung's twists):
each ladder takes about ``log2(rungs)`` rounds, round ``j`` at most ``min(k, 2**(j-1))`` batches
for ``k`` twists.

The certificate is the exact region's (:func:`~.force_status.possible_or_not` with the same
refinements, and procedure STABLE's region, proven in closed form, where the CF is known), and the
ladders hold the nominal values, so a certified vertex of an exact region at ``(mu, cf_radius)``
gets ``mu_low <= mu`` and a radius of at least ``cf_radius``. A twist not certified even at the
nominal values (outside Theorem 4's strip, or on a stretch of a region's boundary between its
certified vertices) has no margin to state: ``mu_low`` is NaN where ``(mu, cf_radius)`` is not
certified, the radius NaN where no radius is at ``mu``.

Examples
--------
A 2 x 2 square (CF at its centre, ``(0, 1)``) pushed up on its bottom face by a pusher 0.5 wide,
``mu = 0.5``. A translation's load is a force along the motion through the CF, whatever the
distribution. Straight ahead it is a normal force: no friction needed, so ``mu_low`` is the lowest
rung, ``mu / 64 = 1/128``; its line must cross the pusher, so a CF up to 0.25 to either side is
fine: 11 rungs of ``sqrt(2) / 64 = 0.0221`` (12 would be 0.265). Tilted by ``tan = 0.2`` it needs
``mu >= 0.2`` (26 rungs of 1/128 = 0.203); its line meets the face 0.2 from the middle, so a CF may
move ``(0.25 - 0.2) cos(atan 0.2) = 0.049`` across it: 2 rungs.

>>> from mechanics import Slider
>>> square = Slider([[-1, 0], [1, 0], [1, 2], [-1, 2]])
>>> margins = push_margins(square, 0, [[0, 1, 0], [-0.2, 1, 0]], 0.5, width=0.5)
>>> margins.mu_low.tolist(), margins.friction_margin.round(3).tolist()
([0.0078125, 0.203125], [0.984, 0.594])
>>> (margins.cf_radius / margins.radius_step).round(9).tolist()
[11.0, 2.0]

Sideways is never stable: no margin.

>>> push_margins(square, 0, [[1, 0, 0]], 0.5).mu_low.tolist()
[nan]
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from .cones import Cone
from .contacts import ContactConfiguration
from .force_status import possible_or_not
from .slider import Slider
from .stable import procedure_stable
from .support import SupportModel
from .wrenches import contact_wrench_cone

__all__ = ["RUNGS", "PushMargins", "push_margins"]

#: Steps of the ladders the margins are searched on: friction to ``mu / RUNGS``, the CF's radius to
#: the part's radius over ``RUNGS``.
RUNGS = 64


@dataclass(frozen=True)
class PushMargins:
    """The certified margins of some pushes of one edge (module docstring).

    ``mu_low`` and ``cf_radius`` have one entry per twist (NaN: not certified at the nominal
    values); ``mu`` is the nominal friction, ``mu_step`` and ``radius_step`` the ladders' rungs.
    """

    mu: float
    mu_low: np.ndarray
    cf_radius: np.ndarray
    mu_step: float
    radius_step: float

    @property
    def friction_margin(self) -> np.ndarray:
        """``1 - mu_low / mu``: the share of the nominal friction each push may lose and still hold."""
        return 1.0 - self.mu_low / self.mu


def _last_certified(lo: np.ndarray, hi: np.ndarray, certify: Callable[[int, np.ndarray], np.ndarray]) -> np.ndarray:
    """Bisect each twist's bracket on a ladder of rungs, easiest first: ``lo`` the last rung known
    certified (-1: none), ``hi`` the first known not to be (the ladder's length: none).
    ``certify(rung, which)`` certifies the twists ``which`` at one rung, so a round costs one
    batch per distinct middle rung. Returns the last certified rung of each (-1: none)."""
    lo, hi = lo.copy(), hi.copy()
    while len(open_ := np.flatnonzero(hi - lo > 1)):
        middle = (lo[open_] + hi[open_]) // 2
        for rung in np.unique(middle).tolist():
            which = open_[middle == rung]
            ok = certify(rung, which)
            lo[which[ok]] = rung
            hi[which[~ok]] = rung
    return lo


def push_margins(
    slider: Slider,
    edge: int,
    twists: ArrayLike,
    mu: float,
    width: float | None = None,
    cf_radius: float = 0.0,
    rungs: int = RUNGS,
    refinements: int = 3,
    mu_rung: float | None = None,
) -> PushMargins:
    """The certified friction and CF margins of pushing ``edge`` with each of ``twists``.

    Parameters
    ----------
    slider, edge, width
        As for :func:`~.stable.procedure_stable`.
    twists : (k, 3) array_like
        Slider-frame twists of pushes of ``edge`` (any positive scale).
    mu : float
        The nominal pusher friction.
    cf_radius : float
        The scene's own CF uncertainty: ``mu_low`` holds for every CF in this disk.
    rungs : int
        Steps of the ladders (module docstring).
    refinements : int
        Finer support levels the certificate may try (:func:`~.exact_region.exact_region`'s).
    mu_rung : float, optional
        One more rung of the friction ladder, in ``(0, mu]``: a friction a push was planned to
        hold at is then reported exactly where it is certified, not at the rung above it.
    """
    if not mu > 0:
        raise ValueError(f"mu must be > 0, got {mu}")
    if not cf_radius >= 0:
        raise ValueError(f"cf_radius must be >= 0, got {cf_radius}")
    if rungs < 1:
        raise ValueError(f"rungs must be at least 1, got {rungs}")
    if mu_rung is not None and not 0 < mu_rung <= mu:
        raise ValueError(f"mu_rung must be in (0, mu], got {mu_rung}")
    v = np.asarray(twists, dtype=float).reshape(-1, 3)
    stable = procedure_stable(slider, edge, mu, width)
    points = stable.plane.points(v)
    w_lo, w_hi = stable.plane.theorem4_strip(slider.vertices)
    inside = np.isfinite(points).all(axis=1) & (w_lo < points[:, 1]) & (points[:, 1] < w_hi)
    known = SupportModel.of_slider(slider, "footprint")
    cones: dict[float, Cone] = {}

    def certified(which: np.ndarray, friction: float, support: SupportModel) -> np.ndarray:
        if friction not in cones:
            cones[friction] = contact_wrench_cone(ContactConfiguration.slider_edge(slider, edge, friction, width), "ss")
        ok = possible_or_not(v[which], cones[friction], support, refinements)[0]
        if support.cf_radius == 0:  # STABLE's region is proven for a known CF
            region = stable if friction == mu else procedure_stable(slider, edge, friction, width)
            ok |= region.contains(v[which])
        return ok

    nominal = known.with_cf_radius(cf_radius)
    ok = np.zeros(len(v), dtype=bool)
    if inside.any():
        ok[inside] = certified(np.flatnonzero(inside), mu, nominal)
    # That batch settles each ladder's rung of the nominal values.
    frictions = np.unique(np.r_[mu * np.arange(1, rungs + 1) / rungs, [] if mu_rung is None else [mu_rung]])[::-1]
    lowest = _last_certified(np.where(ok, 0, -1), np.where(ok, len(frictions), 0),
                             lambda rung, which: certified(which, float(frictions[rung]), nominal))

    step = slider.radius / rungs
    depth = slider.cf_depth
    radii = np.unique(np.r_[0.0, step * np.arange(1, rungs + 1), depth, cf_radius])
    radii = radii[(radii <= depth) | (radii == cf_radius)]
    at = int(np.searchsorted(radii, cf_radius))
    supports: dict[int, SupportModel] = {at: nominal}

    def at_radius(rung: int, which: np.ndarray) -> np.ndarray:
        if rung not in supports:
            supports[rung] = known.with_cf_radius(float(radii[rung]))
        return certified(which, mu, supports[rung])

    widest = _last_certified(np.where(ok, at, -1), np.select([ok, inside], [len(radii), at], 0), at_radius)
    return PushMargins(
        mu=float(mu),
        mu_low=np.where(lowest >= 0, frictions[np.maximum(lowest, 0)], np.nan),
        cf_radius=np.where(widest >= 0, radii[np.maximum(widest, 0)], np.nan),
        mu_step=float(mu / rungs),
        radius_step=float(step),
    )
