"""The goal region as OMPL sees it: :class:`PushGoal` adapts a
:class:`~planner.search.goal_region.GoalRegion` to ``ob.GoalSampleableRegion``.

A satisfied state's connections (the checked pushes and transit to each goal it reaches) are
kept, keyed by the state's exact floats, so that the path decoder takes them as they are
(:func:`planner.search.decode.segments`): the goal test is the only place a connection is
searched for.
"""

from __future__ import annotations

import math

import numpy as np
from ompl import base as ob

from mechanics import wrap_angle

from ..model.segments import Push, Transit
from .goal_region import GoalRegion
from .spaces import pose_of

__all__ = ["PushGoal"]

Key = tuple[float, float, float, int]


class PushGoal(ob.GoalSampleableRegion):
    """In the goal region of some goal still sought (``active``, indices of the region's goals).

    ``found[key]`` holds, for a satisfied state (``key`` = :func:`~planner.search.spaces.pose_of`),
    its segments per goal reached. With ``nearest = (n, reach)`` a state is tested only against
    the ``n`` active goals nearest it within ``reach`` metres: a tree grown towards many goals
    then pays for a few per state, not for all (each goal is tested from the states that come
    near it).
    """

    def __init__(self, si, region: GoalRegion):
        super().__init__(si)
        self.region = region
        self.active = list(range(len(region.goals)))
        self.found: dict[Key, dict[int, list[Push | Transit]]] = {}
        self._samples = 0
        self._radius = region.scene.slider.radius
        self.nearest: tuple[int, float] | None = None
        self.setThreshold(1e-9)  # OMPL accepts distances strictly below the threshold

    def distanceGoal(self, state) -> float:
        key = pose_of(state)
        state = None  # see pose_of
        x, y, theta, k = key
        if k >= len(self.region.controls):  # the marker of a blocked switch
            return math.inf
        goals = self.region.goals[self.active]
        distance = np.hypot(goals[:, 0] - x, goals[:, 1] - y)
        tested = self.active
        if self.nearest is not None and len(tested) > self.nearest[0]:
            near = np.argsort(distance, kind="stable")[:self.nearest[0]]
            tested = [self.active[i] for i in near if distance[i] <= self.nearest[1]]
        hits = self.region.connections((x, y, theta), k, tested) if tested else None
        if hits:
            self.found[key] = hits
            return 0.0
        return float(np.min(distance + self._radius * np.abs(wrap_angle(goals[:, 2] - theta))))

    def sampleGoal(self, state) -> None:
        # Goal samples take turns among the edges (and the goals), so goal bias pulls every
        # edge's tree towards every goal.
        self._samples += 1
        n = len(self.region.controls)
        goal = self.region.goals[self.active[(self._samples // n) % len(self.active)]]
        try:
            state[0].setXY(float(goal[0]), float(goal[1]))
            state[0].setYaw(float(goal[2]))
            state[1].value = self._samples % n
        finally:
            state = None  # see pose_of

    def maxSampleCount(self) -> int:
        return 1
