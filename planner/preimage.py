"""The goal's preimage under one or two constant stable pushes: the planner's goal region.

Among the variations of their planner, Lynch & Mason (1996) suggest taking as goal region the
set of poses from which one constant stable push reaches the goal exactly (Lynch 1992's one-step
planning, from every tree state). This module extends it by one push, which makes the region
much larger where the goal must be approached at a particular heading: a *waypoint*
``m = goal * exp(-W tau)`` is one push ``W`` (for ``tau`` seconds) before the goal; a state ``s``
is in the two-push preimage if ``COR_total(s -> m)`` is a stable push for some waypoint and both
pushes are collision-free.

Waypoints are a fixed set per edge (a grid of controls times durations growing geometrically),
screened with vectorised ``log_pose`` and ``contains``; collision checks run only for the few
nearest that pass, and each waypoint-to-goal push is checked once.
"""

from __future__ import annotations

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


class GoalPreimage:
    """Pushes from a pose to ``goal``: one push, or two through a waypoint.

    Parameters
    ----------
    goal : (3,) pose
    pushes : the allowed edges' pushes
    model : collision model with a body for each of those edges
    margin : clearance every push must keep
    radius : the part's radius, the unit of waypoint push lengths
    """

    def __init__(self, goal: ArrayLike, pushes: list[EdgePush], model: CollisionModel, margin: float, radius: float):
        self.goal = np.array([goal[0], goal[1], wrap_angle(goal[2])], dtype=float)
        self.pushes, self.model, self.margin = pushes, model, margin
        controls = np.array([(0.5, 0.0)] + [(a, b) for a in _U1 for b in _U2])
        self._waypoints = []
        for push in pushes:
            twists = push.control_twist(controls)  # unit speed: duration = distance
            legs = np.array(_LEGS) * radius
            w = np.repeat(twists, len(legs), axis=0)
            tau = np.tile(legs, len(twists))
            poses = exp_twist(self.goal, -w, tau)  # back along each push from the goal
            self._waypoints.append((poses, w, tau))
        self._last_leg: dict[tuple[int, int], Segment | None] = {}

    def connect(self, pose: ArrayLike, k: int) -> list[Segment] | None:
        """Pushes of ``self.pushes[k]`` from ``pose`` to the goal (one or two), or None."""
        push = self.pushes[k]
        one = connect(pose, self.goal, push, self.model, self.margin)
        if isinstance(one, Segment):
            return [one]
        poses, w, tau = self._waypoints[k]
        first = log_pose(pose, poses)
        ok = np.flatnonzero(push.region.contains(first))
        if ok.size == 0:
            return None
        total = push.speed(first[ok]) + tau[ok]
        for i in ok[np.argsort(total, kind="stable")][:_TRIES]:
            last = self._final_push(k, int(i))
            if last is None:
                continue
            lead = connect(pose, poses[i], push, self.model, self.margin)
            if isinstance(lead, Segment):
                return [lead, Segment(last.edge, last.contact, last.twist, last.duration, lead.end, last.end)]
        return None

    def _final_push(self, k: int, i: int) -> Segment | None:
        """The push from waypoint ``i`` of edge ``k`` to the goal, if collision-free (cached)."""
        if (k, i) not in self._last_leg:
            poses, w, tau = self._waypoints[k]
            push = self.pushes[k]
            free = self.model.push_is_free(poses[i], w[i], tau[i], push.edge, self.margin)
            start = poses[i].copy()
            start[2] = wrap_angle(start[2])
            self._last_leg[(k, i)] = (
                Segment(push.edge, push.region.contact, w[i], float(tau[i]), start, self.goal.copy()) if free else None)
        return self._last_leg[(k, i)]
