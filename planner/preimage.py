"""The goal's preimage under one or two constant stable pushes: the planner's goal region.

Among the variations of their planner, Lynch & Mason (1996) suggest taking as goal region the
set of poses from which one constant stable push reaches the goal exactly (Lynch 1992's one-step
planning, from every tree state). This module extends it by one push, which makes the region
much larger where the goal must be approached at a particular heading: a *waypoint*
``m = goal * exp(-W tau)`` is one push ``W`` (for ``tau`` seconds) before the goal; a state ``s``
is in the two-push preimage if ``COR_total(s -> m)`` is a stable push for some waypoint and both
pushes are collision-free.

Waypoints are a fixed set per edge (a grid of controls times durations growing geometrically),
screened with vectorised ``log_pose`` and ``contains``, then for certain collisions (the part's
CF sampled along each push, outside where its inscribed disk fits:
:meth:`~planner.validity.CollisionModel.surely_blocked`); full collision checks run only for the
few nearest that pass, and each waypoint-to-goal push is checked once. Behind a wall with a gap,
most waypoints fail the cheap screen, and the few tries go to those that may pass.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike

from mechanics import exp_twist, log_pose, wrap_angle

from .one_step import connect
from .plan_file import Segment
from .pushes import EdgePush
from .validity import CollisionModel

__all__ = ["GoalPreimage"]

_U1 = np.linspace(0.0, 1.0, 12, endpoint=False)  # around the boundary of the stable cone
_U2 = (0.5, 1.0)  # half way out, and on the boundary (the sharpest turns)
_LEGS = (1.0, 2.0, 4.0, 8.0)  # waypoint push lengths, in part radii
_TRIES = 4  # waypoints collision-checked per state: this test runs on every new tree state
_SAMPLES = np.linspace(0.0, 1.0, 9)[1:-1]  # where along a push the part's CF is screened


class GoalPreimage:
    """Pushes from a pose to a goal: one push, or two through a waypoint; for one goal or many.

    Many goals share the work: their waypoints are screened in one vectorised pass, so a search
    tree grown towards a batch of goals (:func:`planner.reachability`) tests each new state
    against all of them at about the cost of one.

    Parameters
    ----------
    goals : (3,) pose, or (m, 3) poses
    pushes : the allowed edges' pushes
    model : collision model with a body for each of those edges
    margin : clearance every push must keep
    radius : the part's radius, the unit of waypoint push lengths
    """

    def __init__(self, goals: ArrayLike, pushes: list[EdgePush], model: CollisionModel, margin: float,
                 radius: float):
        self.goals = np.array(goals, dtype=float).reshape(-1, 3)
        self.goals[:, 2] = wrap_angle(self.goals[:, 2])
        self.pushes, self.model, self.margin = pushes, model, margin
        controls = np.array([(0.5, 0.0)] + [(a, b) for a in _U1 for b in _U2])
        legs = np.array(_LEGS) * radius
        # Per edge: the waypoint pushes (unit speed: duration = distance) and, per goal, the
        # waypoints themselves, back along each push from the goal, shape (m, n, 3).
        self._waypoints = []
        for push in pushes:
            w = np.repeat(push.control_twist(controls), len(legs), axis=0)
            tau = np.tile(legs, len(controls))
            self._waypoints.append((exp_twist(self.goals[:, None, :], -w, tau), w, tau))
        self._last_leg: dict[tuple[int, int, int], Segment | None] = {}

    @property
    def goal(self) -> np.ndarray:
        """The first (for one goal, the) goal."""
        return self.goals[0]

    def connect(self, pose: ArrayLike, k: int, goal: int = 0) -> list[Segment] | None:
        """Pushes of ``self.pushes[k]`` from ``pose`` to goal index ``goal`` (one or two), or None."""
        return self.connect_all(pose, k, [goal]).get(goal)

    def connect_all(self, pose: ArrayLike, k: int, goals: Sequence[int]) -> dict[int, list[Segment]]:
        """Pushes of ``self.pushes[k]`` from ``pose`` to each of ``goals`` (indices) it can
        reach by one or two pushes, by goal index."""
        push = self.pushes[k]
        goals = np.asarray(goals, dtype=int)
        found: dict[int, list[Segment]] = {}
        if goals.size == 0:
            return found
        poses, w, tau = self._waypoints[k]
        # One screen for all: COR_total to each goal (column 0) and to each of its waypoints.
        total = log_pose(pose, np.concatenate([self.goals[goals, None], poses[goals]], axis=1))
        ok = push.region.contains(total.reshape(-1, 3)).reshape(total.shape[:2])
        for row, g in enumerate(goals.tolist()):
            # The goal itself first, then the waypoints, shortest two pushes first.
            columns = np.flatnonzero(ok[row])
            speed = push.speed(total[row, columns])
            order = np.argsort(np.where(columns == 0, -1.0, speed + tau[columns - 1]), kind="stable")
            columns, speed = columns[order], speed[order]
            # Pushes whose part certainly hits something on the way (a wall between here and the
            # goal, say) are dropped before any collision check: sampled poses, one screen.
            moving = speed > 0
            columns, speed = columns[moving], speed[moving]
            along = exp_twist(pose, (total[row, columns] / speed[:, None])[:, None], speed[:, None] * _SAMPLES)
            columns = columns[~self.model.surely_blocked(along).any(axis=1)]
            if columns.size and columns[0] == 0:
                one = connect(pose, self.goals[g], push, self.model, self.margin, total=total[row, 0])
                if isinstance(one, Segment):
                    found[g] = [one]
                    continue
                columns = columns[1:]
            for i in columns[:_TRIES] - 1:
                last = self._final_push(k, g, int(i))
                if last is None:
                    continue
                lead = connect(pose, poses[g, i], push, self.model, self.margin, total=total[row, 1 + i])
                if isinstance(lead, Segment):
                    found[g] = [lead, Segment(last.edge, last.contact, last.twist, last.duration, lead.end, last.end)]
                    break
        return found

    def _final_push(self, k: int, g: int, i: int) -> Segment | None:
        """The push from waypoint ``i`` of edge ``k`` to goal ``g``, if collision-free (cached)."""
        if (k, g, i) not in self._last_leg:
            poses, w, tau = self._waypoints[k]
            push = self.pushes[k]
            free = self.model.push_is_free(poses[g, i], w[i], tau[i], push.edge, self.margin)
            start = poses[g, i].copy()
            start[2] = wrap_angle(start[2])
            self._last_leg[(k, g, i)] = (
                Segment(push.edge, push.region.contact, w[i], float(tau[i]), start, self.goals[g].copy())
                if free else None)
        return self._last_leg[(k, g, i)]
