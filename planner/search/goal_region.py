"""The search's goal region: the poses from which the goal is reached by one or two stable pushes,
on the pushed edge or after a switch to another (Lynch & Mason 1996, §4, extended).

Among the variations of their planner, Lynch & Mason (1996) suggest taking as goal region the
set of poses from which one constant stable push reaches the goal exactly (Lynch 1992's one-step
planning, from every tree state). This module extends it by one push, which makes the region
much larger where the goal must be approached at a particular heading: a *waypoint*
``m = goal * exp(-W tau)`` is one push ``W`` (for ``tau`` seconds) before the goal; a state ``s``
is in the two-push preimage if ``COR_total(s -> m)`` is a stable push for some waypoint and both
pushes are collision-free. With switching allowed, a state is also in the region if a transit
takes the pusher to another edge from which one or two pushes reach the goal; and every state
within the scene's tolerance of the goal is in it.

:meth:`GoalRegion.connections` is the one test, and it returns what it found: the checked
pushes and transit of each goal reached, which the plan is then made of (no search again).
Cheap screens come before the expensive ones, and none changes an answer:

1. the tolerance (:meth:`~planner.model.scene.Scene.within_tolerance`);
2. the free-space component: every free motion keeps the CF in one connected piece of its disk's
   free space (:class:`~planner.world.free_space.Components`), so a goal in another piece is out
   of reach of any push from here, and of any transit (the part stands still);
3. per edge, ``COR_total`` to the goal and to each of its waypoints in one vectorised
   ``log_pose`` and ``contains``;
4. pushes whose part certainly hits something on the way (its CF sampled along them, outside where
   its inscribed disk fits: :meth:`~planner.world.validity.CollisionModel.surely_blocked`);
5. full collision checks, for the few nearest that pass (:data:`TRIES`), each waypoint-to-goal
   push checked once for all states.

>>> from planner import load_scene
>>> from planner.actions.controls import clearance_margin, edge_controls
>>> from planner.world.validity import CollisionModel
>>> scene = load_scene("scenes/battery.yaml")
>>> controls = edge_controls(scene)
>>> region = GoalRegion(scene, scene.goal, controls, CollisionModel(scene, [c.edge for c in controls]),
...                     clearance_margin(scene))
>>> region.connections(scene.goal, 0, [0])  # within tolerance: reached by no push at all
{0: []}
>>> [s.kind for s in region.connections(scene.start, 0, [0])[0]]
['push']
"""

from __future__ import annotations

import copy
import math
import time
from collections import OrderedDict
from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike

from mechanics import exp_twist, log_pose, transform_points, wrap_angle

from ..actions.controls import EdgeControls
from ..actions.push import connect
from ..actions.transit import TransitPlanner
from ..model.segments import Push, Transit
from ..model.scene import Scene
from ..world.free_space import Components
from ..world.validity import CollisionModel

__all__ = ["AIMS", "GoalRegion", "REMEMBERED", "TRIES"]

_U1 = np.linspace(0.0, 1.0, 12, endpoint=False)  # around the boundary of the stable cone
_U2 = (0.5, 1.0)  # half way out, and on the boundary (the sharpest turns)
_LEGS = (1.0, 2.0, 4.0, 8.0)  # waypoint push lengths, in part radii
#: A goal is aimed at where the part, with the pusher on the edge, has the first of these numbers
#: of push margins of clearance; where it has not (a goal drawn against a wall), at the nearest
#: pose that has, within that share of the position tolerance; failing that, the next pair: less
#: room to spare, nearer the tolerance's edge (never on it, so that rounding keeps it inside).
AIMS = ((2.0, 0.9), (1.1, 0.99))
#: Waypoints collision-checked per state and edge: this test runs on every new tree state.
TRIES = 4
#: Poses whose answers :meth:`GoalRegion.pushes_to` keeps (per edge and set of goals).
REMEMBERED = 512
#: Goals screened at once: the screen holds a pose per goal and waypoint (a hundred a goal), so a
#: batch of a million goals (a map's cells, a reachability query) is screened a chunk at a time.
CHUNK = 1024
_SAMPLES = np.linspace(0.0, 1.0, 9)[1:-1]  # where along a push the part's CF is screened


class GoalRegion:
    """Where one or many goals are reached from: within tolerance, by one or two pushes on an
    edge, or (with ``transits``) by a switch to another edge and one or two pushes on it.

    Many goals share the work: their waypoints are screened in one vectorised pass (:data:`CHUNK`
    goals at a time), so a search tree grown towards a batch of goals
    (:func:`planner.reachability`) tests each new state against all of them at about the cost of
    one. What a goal needs (its aims, the free-space pieces they lie in) is worked out when the
    goal is first asked about, so setting up a region of many goals costs nothing per goal.

    Parameters
    ----------
    scene : Scene
        Its tolerance, and its part's CF.
    goals : (3,) pose, or (m, 3) poses
    controls : the allowed edges' controls, indexed ``k`` below
    model : collision model with a body for each of those edges
    margin : clearance every push must keep
    transits : the pusher's transits between those edges, or None where it may not switch
    aim : bool
        Whether pushes may end anywhere within tolerance of a goal where the goal itself has too
        little room (:meth:`_aims_at`); else they end exactly at it, or not at all.
    deadline : float
        A ``time.perf_counter()`` time after which :meth:`connections` tries no further edge to
        switch to (a part of thousands of edges has as many to try from every state).
    """

    def __init__(self, scene: Scene, goals: ArrayLike, controls: list[EdgeControls], model: CollisionModel,
                 margin: float, transits: TransitPlanner | None = None, aim: bool = True, deadline: float = math.inf):
        self.scene, self.controls, self.model, self.margin, self.transits = scene, controls, model, margin, transits
        self.deadline = deadline
        self.goals = np.array(goals, dtype=float).reshape(-1, 3)
        self.goals[:, 2] = wrap_angle(self.goals[:, 2])
        # Per edge: each goal's aim (NaN: none; aim=False: the goal) and whether it is worked out yet.
        self._aims = [np.full_like(self.goals, np.nan) if aim else self.goals for _ in controls]
        self._aimed = [np.full(len(self.goals), not aim) for _ in controls]
        # Per edge asked about, the waypoint pushes (unit speed: duration = distance); a goal's
        # waypoints lie back along each from its aim.
        self._legs: dict[int, tuple[np.ndarray, np.ndarray]] = {}
        self._last_leg: dict[tuple[int, int, int], Push | None] = {}
        self._asked: OrderedDict[tuple, dict[int, list[Push]]] = OrderedDict()
        self._cf = scene.slider.cf
        self._pieces = Components(model.cf_room)
        # The pieces a goal's aims lie in (None: any, where one is on no piece): others are out of reach.
        self._goal_pieces: dict[int, set[int] | None] = {}

    def _legs_of(self, k: int) -> tuple[np.ndarray, np.ndarray]:
        """The waypoint pushes of ``controls[k]`` (twists, durations), made when first asked for: a
        part of many edges may use few of them, and each costs a look at every hull vertex."""
        if k not in self._legs:
            grid = np.array([(0.5, 0.0)] + [(a, b) for a in _U1 for b in _U2])
            legs = np.array(_LEGS) * self.scene.slider.radius
            self._legs[k] = (np.repeat(self.controls[k].control_twist(grid), len(legs), axis=0), np.tile(legs, len(grid)))
        return self._legs[k]

    def _aims_at(self, k: int, goals: np.ndarray) -> np.ndarray:
        """Where pushes on ``controls[k]`` aim, for each of ``goals`` (indices): the goal itself
        where the part with the pusher there has room (the first of :data:`AIMS`' clearances),
        else the nearest pose at its heading that has, within that share of the position tolerance
        (a goal drawn against a wall, say), trying each of :data:`AIMS` in turn; NaN where none
        has, so that no push on that edge aims at it. Each is worked out once, when first asked."""
        aims, edge = self._aims[k], self.controls[k].edge
        for g in goals[~self._aimed[k][goals]].tolist():
            goal = self.goals[g]
            if self.model.is_clear(goal, edge, AIMS[0][0] * self.margin):
                aims[g] = goal
                continue
            for clearance, reach in AIMS:
                aim = self.model.room.aim(self.model.body_pieces(edge), goal, reach * self.scene.tolerance_position,
                                          clearance * self.margin)
                if aim is not None and self.model.is_clear(aim, edge, self.margin):
                    aims[g] = aim
                    break
        self._aimed[k][goals] = True
        return aims[goals]

    def _pieces_of(self, goals: list[int]) -> list[set[int] | None]:
        """The free-space pieces each of ``goals``' aims lie in (None: any), worked out once."""
        new = np.array([g for g in dict.fromkeys(goals) if g not in self._goal_pieces], dtype=int)
        if new.size:
            found: dict[int, set[int] | None] = {g: set() for g in new.tolist()}
            for k in range(len(self.controls)):
                aims = self._aims_at(k, new)
                aimed = ~np.isnan(aims[:, 0])
                for g, label in zip(new[aimed].tolist(), self._pieces.label(self._cf_at(aims[aimed])).tolist()):
                    if found[g] is not None:
                        found[g] = None if label < 0 else found[g] | {int(label)}
            self._goal_pieces.update(found)
        return [self._goal_pieces[g] for g in goals]

    @property
    def goal(self) -> np.ndarray:
        """The first (for one goal, the) goal."""
        return self.goals[0]

    def without_switches(self) -> "GoalRegion":
        """The same region for a search that stays on its edges (its checked pushes shared)."""
        plain = copy.copy(self)
        plain.transits = None
        return plain

    def _cf_at(self, poses: np.ndarray) -> np.ndarray:
        return transform_points(self._cf, poses)

    def within_reach(self, pose: ArrayLike, goals: Sequence[int]) -> list[int]:
        """Those of ``goals`` (indices) in the free-space piece of ``pose``'s CF: the others no
        push, and no transit, from ``pose`` can reach (screen 2). Where a CF is in no piece (on a
        boundary, by rounding) nothing is ruled out."""
        here = int(self._pieces.label(self._cf_at(np.asarray(pose, dtype=float)[None]))[0])
        if here < 0:
            return list(goals)
        return [g for g, pieces in zip(goals, self._pieces_of(list(goals))) if pieces is None or here in pieces]

    def connections(self, pose: ArrayLike, k: int, goals: Sequence[int]) -> dict[int, list[Push | Transit]]:
        """Per goal index of ``goals`` reached from ``pose`` with the pusher on ``controls[k]``,
        its segments: none if ``pose`` is within tolerance of it, else one or two pushes on that
        edge, else (with transits) a transit to another edge and one or two pushes there."""
        pose = np.asarray(pose, dtype=float)
        found: dict[int, list[Push | Transit]] = {g: [] for g in goals if self.scene.within_tolerance(pose, self.goals[g])}
        rest = self.within_reach(pose, [g for g in goals if g not in found])
        if not rest:
            return found
        found.update(self.pushes_to(pose, k, rest))
        if self.transits is None:
            return found
        for other, c in enumerate(self.controls):
            rest = [g for g in rest if g not in found]
            if not rest or time.perf_counter() >= self.deadline:
                break
            if other == k or not (lasts := self.pushes_to(pose, other, rest)):
                continue
            transit = self.transits.find(pose, self.controls[k].edge, c.edge)
            if transit is not None:
                found.update({g: [transit, *last] for g, last in lasts.items()})
        return found

    def pushes_to(self, pose: ArrayLike, k: int, goals: Sequence[int]) -> dict[int, list[Push]]:
        """Per goal index of ``goals`` that one or two pushes of ``controls[k]`` reach from
        ``pose``, those pushes (screens 3-5; no tolerance, no switch).

        The answers for the last :data:`REMEMBERED` poses are kept: a switch makes a state at its
        parent's very pose, and the parent's test has asked every edge already."""
        key = (tuple(float(v) for v in np.ravel(pose)), k, tuple(goals))
        if key not in self._asked:
            if len(self._asked) >= REMEMBERED:
                self._asked.popitem(last=False)
            self._asked[key] = self._pushes_to(np.asarray(pose, dtype=float), k, goals)
        return self._asked[key]

    def _pushes_to(self, pose: np.ndarray, k: int, goals: Sequence[int]) -> dict[int, list[Push]]:
        found: dict[int, list[Push]] = {}
        goals = np.asarray(goals, dtype=int)
        for first in range(0, len(goals), CHUNK):
            found.update(self._chunk_pushes_to(pose, k, goals[first:first + CHUNK]))
        return found

    def _chunk_pushes_to(self, pose: np.ndarray, k: int, goals: np.ndarray) -> dict[int, list[Push]]:
        """:meth:`_pushes_to` of at most :data:`CHUNK` goals."""
        controls = self.controls[k]
        aims = self._aims_at(k, goals)
        goals, aims = goals[~np.isnan(aims[:, 0])], aims[~np.isnan(aims[:, 0])]
        found: dict[int, list[Push]] = {}
        if goals.size == 0:
            return found
        w, tau = self._legs_of(k)
        poses = exp_twist(aims[:, None, :], -w, tau)  # each goal's waypoints, shape (goals, waypoints, 3)
        # One screen for all: COR_total to each goal's aim (column 0) and to each of its waypoints.
        total = log_pose(pose, np.concatenate([aims[:, None], poses], axis=1))
        ok = controls.region.contains(total.reshape(-1, 3)).reshape(total.shape[:2])
        for row, g in enumerate(goals.tolist()):
            # The goal itself first, then the waypoints, shortest two pushes first.
            columns = np.flatnonzero(ok[row])
            speed = controls.speed(total[row, columns])
            order = np.argsort(np.where(columns == 0, -1.0, speed + tau[columns - 1]), kind="stable")
            columns, speed = columns[order], speed[order]
            moving = speed > 0
            columns, speed = columns[moving], speed[moving]
            along = exp_twist(pose, (total[row, columns] / speed[:, None])[:, None], speed[:, None] * _SAMPLES)
            columns = columns[~self.model.surely_blocked(along).any(axis=1)]
            if columns.size and columns[0] == 0:
                one = connect(pose, aims[row], controls, self.model, self.margin, total=total[row, 0])
                if isinstance(one, Push):
                    found[g] = [one]
                    continue
                columns = columns[1:]
            for i in columns[:TRIES] - 1:
                last = self._final_push(k, g, int(i), poses[row, i])
                if last is None:
                    continue
                lead = connect(pose, poses[row, i], controls, self.model, self.margin, total=total[row, 1 + i])
                if isinstance(lead, Push):
                    found[g] = [lead, Push(last.edge, last.contact, last.twist, last.duration, lead.end, last.end)]
                    break
        return found

    def _final_push(self, k: int, g: int, i: int, waypoint: np.ndarray) -> Push | None:
        """The push from ``waypoint``, waypoint ``i`` of edge ``k`` for goal ``g``, to the goal's
        aim, if collision-free (cached)."""
        if (k, g, i) not in self._last_leg:
            w, tau = self._legs_of(k)
            c = self.controls[k]
            free = self.model.push_is_free(waypoint, w[i], tau[i], c.edge, self.margin)
            start = waypoint.copy()
            start[2] = wrap_angle(start[2])
            self._last_leg[(k, g, i)] = (
                Push(c.edge, c.region.contact, w[i], float(tau[i]), start, self._aims[k][g].copy()) if free else None)
        return self._last_leg[(k, g, i)]
