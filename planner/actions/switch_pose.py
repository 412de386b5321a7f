"""Where the pusher changes edge: each switch moved to the pose that makes the plan shortest.

A plan with switches is runs of pushes, each on one edge, joined by transits at the *switch
poses*. Where a switch is decides how long the plan is (a part pushed far past a junction before
the pusher walks round it comes back just as far), and no shortening of a run between fixed ends
can move it. :class:`SwitchShortcut` moves it.

For a switch from edge ``a`` to edge ``b`` between the anchors ``A`` (where the run on ``a``
begins) and ``B`` (where the run on ``b`` ends), replacing both runs by Dubins curves of the
edges' cars (:mod:`planner.actions.dubins`) through a switch pose ``P`` makes that stretch cost

    ``D_a(A, P) + D_b(P, B)``

(the centre of friction's path; the switch cost is the same for every ``P``), where ``D_e`` is
the Dubins length of edge ``e``'s car. ``P`` is *feasible* when both curves are free and a transit
from ``a`` to ``b`` exists at ``P``; every piece is then checked like any push and transit, so the
guarantee is kept. The minimum over ``P`` is found in two stages:

1. **A grid.** The centre of friction's Dubins path is at least as long as the straight line, so
   only switch poses whose CF lies in the ellipse ``|A - P| + |P - B| < current`` (foci the
   anchors' CFs) can shorten the stretch; of those, only where the CF's disk fits
   (:attr:`~planner.world.validity.CollisionModel.cf_room`). On a grid of CF positions and headings
   there, the Dubins sums are computed for all, and the cheapest are checked best first.
2. **A pattern search** about the best feasible pose: the 26 neighbours at the current steps,
   cheapest first; a step is halved when none is both cheaper and feasible.

Switches are improved one after another, sweeping the plan until a sweep changes nothing; a
switch is also tried *merged* with the next (``a -> b -> c`` becomes ``a -> c``, or one run
when ``a = c``) where that saves more than the switch cost.
"""

from __future__ import annotations

import itertools
import math
import time
from dataclasses import dataclass

import numpy as np
import shapely

from ..model.bodies import cf_poses, place
from ..model.segments import Push, Transit, rechain
from ..model.scene import Scene
from ..world.grid import grid_spacing
from ..world.validity import CollisionModel
from .dubins import DubinsCurves
from .transit import TransitPlanner

__all__ = ["Grid", "SwitchShortcut", "runs"]

#: Least relative gain for which a stretch of plan is replaced (its Dubins pieces are pushes too).
_GAIN = 1e-3
#: Sweeps over the plan's switches at most (each after the first only if the one before changed something).
_SWEEPS = 3
#: Points along a Dubins curve at which the part's CF is screened before the full check.
_SCREEN = 8
#: The pattern search's moves: every combination of a step back, none or forward in x, y and heading.
_MOVES = np.array([m for m in itertools.product((-1, 0, 1), repeat=3) if any(m)], dtype=float)
#: Neighbours checked per move of the pattern search, cheapest first.
_TRIES = 4
#: Where along each push of the current plan its poses are taken as candidates.
_ALONG = (0.25, 0.5, 0.75, 1.0)
#: Switch poses whose Dubins sums are computed between two looks at the deadline.
_CHUNK = 4096
#: Fewest headings of the stage-1 grid (every 15 degrees).
_LEAST_TURNS = 24
#: Most CF positions of the stage-1 grid over the table, before the ellipse keeps a few (a part of
#: microns would otherwise lay 10^11 at its spacing of half a radius).
_MOST_CELLS = 1_000_000


@dataclass(frozen=True)
class Grid:
    """How finely switch poses are searched, in part radii and degrees.

    Attributes
    ----------
    spacing : float
        CF grid spacing of stage 1, in part radii.
    heading : float
        Heading grid step of stage 1, degrees.
    finest : float
        The pattern search stops below this step, in part radii (headings: ``finest`` times
        ``heading / spacing``).
    checks : int
        Full feasibility checks of stage 1 at most (cheapest candidates first).
    candidates : int
        Switch poses of stage 1 at most (the grid is made coarser to keep to it).
    """

    spacing: float = 0.5
    heading: float = 5.0
    finest: float = 0.05
    checks: int = 24
    candidates: int = 4000

    def refined(self, level: int) -> "Grid":
        """This grid ``level`` times finer: steps smaller by a factor of the square root of 2 a
        level, twice the checks and four times the candidates (the number of poses grows as the
        cube of the steps' ratio: a little faster than the candidates, so the finest grids keep to
        their bound by coarsening).

        >>> Grid().refined(2)
        Grid(spacing=0.25, heading=2.5, finest=0.025, checks=96, candidates=64000)
        """
        shrink = 2.0 ** (-level / 2)
        return Grid(round(self.spacing * shrink, 12), round(self.heading * shrink, 12),
                    round(self.finest * shrink, 12), self.checks * 2 ** level, self.candidates * 4 ** level)


def runs(segments: list[Push | Transit]) -> tuple[list[list[Push]], list[Transit]]:
    """The plan as runs of pushes (one per edge used, possibly empty) and the transits between
    them: ``len(runs) == len(transits) + 1``.

    >>> from planner.model.plan_file import Push, Transit
    >>> p = Push.along(0, np.zeros((2, 2)), [1.0, 0.0, 0.0], 1.0, np.zeros(3))
    >>> t = Transit(0, 2, "lift", np.zeros((4, 3)), 1.0, p.end)
    >>> [len(r) for r in runs([p, t, p.moved(p.end)])[0]], [len(r) for r in runs([t, p])[0]], runs([])
    ([1, 1], [0, 1], ([[]], []))
    """
    out: list[list[Push]] = [[]]
    transits: list[Transit] = []
    for s in segments:
        if isinstance(s, Transit):
            transits.append(s)
            out.append([])
        else:
            out[-1].append(s)
    return out, transits


#: A stretch of plan through one switch pose: the pushes to it, the transit there (None for a
#: via pose on one edge) and the pushes from it.
Stretch = tuple[list[Push], "Transit | None", list[Push]]


class _Legs:
    """A plan as legs of pushes, the edge of each and the transits between them."""

    def __init__(self, legs: list[list[Push]], edges: list[int], transits: list[Transit]):
        self.legs, self.edges, self.transits = legs, edges, transits

    def begin(self, i: int) -> np.ndarray:
        """Where leg ``i`` begins."""
        return self.legs[i][0].start if self.legs[i] else self.transits[max(i - 1, 0)].pose

    def end(self, j: int) -> np.ndarray:
        """Where leg ``j`` ends."""
        return self.legs[j][-1].end if self.legs[j] else self.transits[min(j, len(self.transits) - 1)].pose

    def replace(self, i: int, j: int, stretch: Stretch, edges: list[int]) -> None:
        """Legs ``i`` to ``j`` and the transits between them replaced by ``stretch``, whose legs
        are on ``edges`` (one edge: the stretch's two halves make one leg)."""
        first, transit, second = stretch
        self.legs[i:j + 1] = [first + second] if transit is None else [first, second]
        self.transits[i:j] = [] if transit is None else [transit]
        self.edges[i:j + 1] = edges


class SwitchShortcut:
    """Move each switch of a plan to the pose that makes the plan shortest (module docstring).

    Parameters
    ----------
    scene : Scene
    curves : dict of edge -> DubinsCurves
        Each allowed edge's car curves, with a collision model (edges without a car are not moved).
    model : CollisionModel
        With a body for each of those edges.
    transits : TransitPlanner
        The transits between the edges.
    switch_cost : float
        What a switch costs (metres), weighed when switches are merged.
    grid : Grid
        How finely switch poses are searched.
    via : bool
        Also search a via pose for a plan without switches: the whole plan replaced by two Dubins
        curves of its edge's car through it (a grid over the whole table finds ways round the
        obstacles that the plan did not take).
    deadline : float
        A ``time.perf_counter()`` time: the search stops there, keeping what it found.
    """

    def __init__(self, scene: Scene, curves: dict[int, DubinsCurves], model: CollisionModel,
                 transits: TransitPlanner | None, switch_cost: float, grid: Grid = Grid(), *, via: bool = False,
                 deadline: float = math.inf):
        self.curves, self.model, self.transits, self.switch_cost = curves, model, transits, switch_cost
        self.cf = scene.slider.cf
        self.radius = scene.slider.radius
        self.grid, self.via, self.deadline = grid, via, deadline
        self._ends: dict[tuple[int, bytes], np.ndarray] = {}
        self._workspace = scene.workspace

    def __call__(self, segments: list[Push | Transit]) -> list[Push | Transit]:
        legs, transits = runs(segments)
        if not transits:
            return self._via(segments) if self.via and segments else segments
        plan = _Legs(legs, [t.from_edge for t in transits] + [transits[-1].to_edge], transits)
        self._tried: set[tuple] = set()
        for _ in range(_SWEEPS):
            changed = False
            for r in range(1, len(plan.legs)):
                changed |= self._move(plan, r)
            changed |= self._drop(plan) or self._merge(plan)
            if not changed:
                break
        out: list[Push | Transit] = []
        for r, leg in enumerate(plan.legs):
            out += leg
            if r < len(plan.transits):
                out.append(plan.transits[r])
        return rechain(out, segments[0].start)

    def _cf_length(self, run: list[Push]) -> float:
        return sum(p.cf_path_length(self.cf) for p in run)

    def _late(self) -> bool:
        return time.perf_counter() >= self.deadline

    def _via(self, segments: list[Push]) -> list[Push]:
        """A plan without switches replaced by two Dubins curves of its edge's car through a via
        pose, where that is cheaper."""
        begin, end, edge = segments[0].start, segments[-1].end, segments[0].edge
        if edge not in self.curves:
            return segments
        along = np.array([_part_of(p, f).end for p in segments for f in _ALONG])
        found = self.best(begin, edge, end, edge, self._cf_length(segments) * (1.0 - _GAIN), along[len(along) // 2],
                          along)
        return segments if found is None else rechain(found[0] + found[2], begin)

    def _search(self, plan: "_Legs", i: int, j: int, a: int, b: int, extra: float) -> Stretch | None:
        """The best stretch from where leg ``i`` begins to where leg ``j`` ends, on edge ``a``
        then (after a switch, unless ``a == b``) edge ``b``, that is cheaper than those legs plus
        ``extra``; None if none is found, or if this very question was asked before."""
        if a not in self.curves or b not in self.curves:
            return None
        begin, end = plan.begin(i), plan.end(j)
        current = sum(self._cf_length(plan.legs[k]) for k in range(i, j + 1)) + extra
        key = (tuple(begin.tolist()), a, tuple(end.tolist()), b)
        if key in self._tried:
            return None
        self._tried.add(key)
        along = np.array([_part_of(p, f).end
                          for k in range(i, j + 1) for p in plan.legs[k] for f in _ALONG])
        return self.best(begin, a, end, b, current * (1.0 - _GAIN), plan.transits[i].pose, along)

    def _move(self, plan: "_Legs", r: int) -> bool:
        """Move switch ``r`` (between legs ``r - 1`` and ``r``) if that shortens the plan."""
        found = self._search(plan, r - 1, r, plan.edges[r - 1], plan.edges[r], 0.0)
        if found is not None:
            plan.replace(r - 1, r, found, [plan.edges[r - 1], plan.edges[r]])
        return found is not None

    def _drop(self, plan: "_Legs") -> bool:
        """Drop the last switch, the legs on both sides joined on one edge through a via pose,
        where that costs less than the switch and the legs: on the edge before it, or on the
        edge after it when the plan has no other switch (its first push may be on any edge)."""
        r = len(plan.transits)
        if r == 0:
            return False
        for e in dict.fromkeys([plan.edges[r - 1], plan.edges[r]] if r == 1 else [plan.edges[r - 1]]):
            found = self._search(plan, r - 1, r, e, e, self.switch_cost)
            if found is not None:
                plan.replace(r - 1, r, found, [e])
                return True
        return False

    def _merge(self, plan: "_Legs") -> bool:
        """Merge a pair of successive switches into one (none where the edges before and after
        are the same) where that is cheaper."""
        for r in range(1, len(plan.transits)):
            a, c = plan.edges[r - 1], plan.edges[r + 1]
            found = self._search(plan, r - 1, r + 1, a, c, self.switch_cost)
            if found is not None:
                plan.replace(r - 1, r + 1, found, [a] if a == c else [a, c])
                return True
        return False

    def sums(self, begin: np.ndarray, a: int, end: np.ndarray, b: int, poses: np.ndarray) -> np.ndarray:
        """``D_a(begin, P) + D_b(P, end)`` for each switch pose ``P`` of ``poses`` ``(n, 3)``
        (``inf`` for those left when the deadline passes)."""
        ca, cb = self.curves[a], self.curves[b]
        out = np.full(len(poses), np.inf)
        for k in range(0, len(poses), _CHUNK):
            if self._late():
                break
            chunk = poses[k:k + _CHUNK]
            out[k:k + _CHUNK] = (ca.lengths(self._end_state(a, begin)[None], ca.car.states(chunk))
                                 + cb.lengths(cb.car.states(chunk), self._end_state(b, end)[None]))
        return out

    def best(self, begin: np.ndarray, a: int, end: np.ndarray, b: int, below: float,
             near: np.ndarray, along: np.ndarray | None = None) -> Stretch | None:
        """The cheapest feasible stretch ``begin -> P`` on ``a``, transit to ``b``, ``P -> end`` on
        ``b`` (a via pose ``P`` on ``a`` alone if ``a == b``) that the search finds with a CF
        path shorter than ``below``, or None.

        The pattern search starts from ``near`` (the current switch pose: in a narrow passage
        it is often the only kind of pose that fits, and the search slides it along), from the
        grid's cheapest feasible pose, the grid going through ``near``, and from the cheapest
        feasible of the poses ``along`` ``(n, 3)`` (the current plan's: they thread its
        passages)."""
        self._ends = {}
        starts = [near]
        for candidates in (self._grid(begin, end, below, near), along):
            if self._late():
                return None
            if candidates is not None and len(candidates):
                found = self._cheapest_feasible(begin, a, end, b, below, candidates)
                if found is not None:
                    starts.append(found)
        best, cost = None, below
        for pose in starts:
            length = float(self.sums(begin, a, end, b, pose[None])[0])
            if length < cost and self._feasible(begin, a, end, b, pose):
                best, cost = self._descend(begin, a, end, b, pose, length)
        return None if best is None else self._stretch(begin, a, end, b, best)

    def _cheapest_feasible(self, begin: np.ndarray, a: int, end: np.ndarray, b: int, below: float,
                           candidates: np.ndarray) -> np.ndarray | None:
        """The cheapest feasible of ``candidates`` below ``below``, best first, within
        :attr:`Grid.checks` full checks; None if none is found."""
        costs = self.sums(begin, a, end, b, candidates)
        checks = 0
        for i in np.argsort(costs, kind="stable"):
            if costs[i] >= below or checks >= self.grid.checks or self._late():
                break
            feasible = self._feasible(begin, a, end, b, candidates[i])
            checks += feasible is not None
            if feasible:
                return candidates[i]
        return None

    def _descend(self, begin: np.ndarray, a: int, end: np.ndarray, b: int, pose: np.ndarray,
                 cost: float) -> tuple[np.ndarray, float]:
        """Pattern search from the feasible switch ``pose`` of Dubins sum ``cost`` (stage 2):
        the best pose found and its sum."""
        g = self.grid
        step = np.array([g.spacing * self.radius, g.spacing * self.radius, math.radians(g.heading)]) / 2
        while step[0] >= g.finest * self.radius and not self._late():
            near = pose + _MOVES * step
            near_costs = self.sums(begin, a, end, b, near)
            moved = False
            for i in np.argsort(near_costs, kind="stable")[:_TRIES]:
                if near_costs[i] >= cost:
                    break
                if self._feasible(begin, a, end, b, near[i]):
                    cost, pose, moved = float(near_costs[i]), near[i], True
                    break
            if not moved:
                step = step / 2
        return pose, cost

    def _grid(self, begin: np.ndarray, end: np.ndarray, below: float, near: np.ndarray) -> np.ndarray:
        """Switch poses on the stage-1 grid through ``near`` whose CF is in the ellipse and
        where its disk fits: headings every :attr:`Grid.heading` degrees, or coarser (down to
        every 15 degrees, then with the CF spacing doubled) to keep to :attr:`Grid.candidates`;
        the CF spacing is never so fine that the table holds more than :data:`_MOST_CELLS`."""
        g = self.grid
        fa, fb, fn = place(self.cf[None], np.array([begin, end, near]))[:, 0]
        xmin, ymin, xmax, ymax = self._workspace
        h = grid_spacing(xmax - xmin, ymax - ymin, g.spacing * self.radius, _MOST_CELLS)
        while True:
            xs = fn[0] + h * np.arange(math.ceil((xmin - fn[0]) / h), math.floor((xmax - fn[0]) / h) + 1)
            ys = fn[1] + h * np.arange(math.ceil((ymin - fn[1]) / h), math.floor((ymax - fn[1]) / h) + 1)
            x, y = (v.ravel() for v in np.meshgrid(xs, ys))
            inside = np.hypot(x - fa[0], y - fa[1]) + np.hypot(x - fb[0], y - fb[1]) < below
            inside[inside] = shapely.contains_xy(self.model.cf_room, x[inside], y[inside])
            turns = min(int(360.0 / g.heading), g.candidates // max(int(inside.sum()), 1))
            if turns >= _LEAST_TURNS:
                break
            h *= 2.0
        xy = np.column_stack([x[inside], y[inside]])
        headings = near[2] + np.linspace(-np.pi, np.pi, turns, endpoint=False)
        return cf_poses(self.cf, np.repeat(xy, len(headings), axis=0), np.tile(headings, len(xy)))

    def _feasible(self, begin: np.ndarray, a: int, end: np.ndarray, b: int, pose: np.ndarray) -> bool | None:
        """Whether both Dubins curves through switch pose ``pose`` (a via pose when ``a == b``)
        are free and a transit exists there; None where the cheap screens rule it out (that is
        not counted as a check)."""
        ca, cb = self.curves[a], self.curves[b]
        first = (self._end_state(a, begin), ca.car.state(pose))
        second = (first[1] if a == b else cb.car.state(pose), self._end_state(b, end))
        ca.states(*first)
        if ca.blocked(_SCREEN):
            return None
        cb.states(*second)
        if cb.blocked(_SCREEN):
            return None
        if a != b and self.transits.find(pose, a, b) is None:
            return False
        ca.states(*first)
        if not ca.is_free():
            return False
        cb.states(*second)
        return cb.is_free()

    def _end_state(self, edge: int, pose: np.ndarray) -> np.ndarray:
        """The car state of ``edge`` at an end of the stretch searched (the same for every
        candidate: kept, as the screens of fine grids ask for it tens of thousands of times)."""
        key = (edge, pose.tobytes())
        if key not in self._ends:
            self._ends[key] = self.curves[edge].car.state(pose)
        return self._ends[key]

    def _stretch(self, begin: np.ndarray, a: int, end: np.ndarray, b: int, pose: np.ndarray) -> Stretch | None:
        """The pushes and transit through feasible switch ``pose``; None if a push fails its
        re-check (stability, clearance) after rounding."""
        first = self.curves[a].connect(begin, pose)
        second = self.curves[b].connect(pose, end) if first is not None else None
        if second is None:
            return None
        return first, self.transits.find(pose, a, b) if a != b else None, second


def _part_of(push: Push, fraction: float) -> Push:
    """The first ``fraction`` of ``push``."""
    return Push.along(push.edge, push.contact, push.twist, push.duration * fraction, push.start)
