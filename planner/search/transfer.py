"""The pusher's travel between two parts of a multi-part scene: a :class:`~planner.model.segments.Transfer`.

The pusher leaves the part it has pushed by backing straight off its contact by the standoff
(:func:`planner.actions.transit.standoff`), goes to the standoff pose in front of the next part's
edge, and moves straight in, every part standing still. Backing off is checked against all but
the part it leaves, moving in against all but the part it reaches (each touches only its own
part, at its end), the way between against everything: obstacles, walls and every part.

The way between is flown in ``'lift'`` mode, where the session's ``transit`` option allows it (as
a lift transit: the airborne piece is not checked). On the table it is the straight move if that is free, else a
path of OMPL's RRT-Connect in the pusher's SE(2) whose every move is checked by conservative
advancement (:meth:`~planner.world.validity.CollisionModel.pusher_move_is_free`), shortened by
OMPL's path simplifier. The search is seeded and capped by iterations, so a seed decides it.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import replace

import numpy as np
from numpy.typing import ArrayLike
from ompl import base as ob
from ompl import geometric as og

from mechanics import wrap_angle

from ..actions.transit import backed_off, path_duration, standoff
from ..model.bodies import pusher_frame_body
from ..model.scene import Scene
from ..model.segments import Transfer
from ..world.validity import CollisionModel
from .planning import _seed_ompl

__all__ = ["TRANSFER_ITERATIONS", "TransferPaths"]

#: Iterations of RRT-Connect for one transfer on the table (a seed then decides its path).
TRANSFER_ITERATIONS = 4000


class TransferPaths:
    """Transfers of ``scene``'s pusher, keeping ``margin`` of clearance on the table, as the
    ``transit`` option ``mode`` allows (``'lift'``: flown; else on the table)."""

    def __init__(self, scene: Scene, margin: float, mode: str):
        self.scene, self.margin, self.mode = scene, margin, mode
        self.reach = float(np.linalg.norm(pusher_frame_body(scene.pusher.width, scene.pusher.depth), axis=1).max())

    def _model(self, poses: Mapping[str, ArrayLike], without: tuple[str, ...]) -> CollisionModel:
        # A one-part scene carries the table: its part is never asked about, only the pusher.
        table = self.scene.move_scene(self.scene.names[0], poses)
        return CollisionModel(replace(table, obstacles=self.scene.obstacles + self.scene.bodies(poses, without)), ())

    def find(self, poses: Mapping[str, ArrayLike], from_part: str, leave: ArrayLike, to_part: str, to_edge: int,
             reach: ArrayLike, seed: int) -> Transfer | None:
        """A transfer from the pusher's contact pose ``leave`` on ``from_part`` to its contact pose
        ``reach`` on ``to_part``'s ``to_edge``, the parts at ``poses``; None if none is found."""
        leave, reach = np.asarray(leave, dtype=float), np.asarray(reach, dtype=float)
        out = backed_off(leave, standoff(self.scene.move_scene(from_part, poses)))
        into = backed_off(reach, standoff(self.scene.move_scene(to_part, poses)))
        if not (self._model(poses, (from_part,)).pusher_move_is_free(leave, out, self.margin)
                and self._model(poses, (to_part,)).pusher_move_is_free(into, reach, self.margin)):
            return None
        if self.mode == "lift":
            path = [leave, out, into, reach]
            return Transfer(from_part, to_part, to_edge, "lift", np.array(path), path_duration(path, self.reach))
        model = self._model(poses, ())
        way = self._way(model, out, into, seed)
        if way is None:
            return None
        path = [leave, *way, reach]
        return Transfer(from_part, to_part, to_edge, "plane", np.array(path), path_duration(path, self.reach))

    def _way(self, model: CollisionModel, a: np.ndarray, b: np.ndarray, seed: int) -> list[np.ndarray] | None:
        """A free path of pusher poses from ``a`` to ``b`` (both included), or None."""
        if model.pusher_clearance(a) < self.margin or model.pusher_clearance(b) < self.margin:
            return None
        if model.pusher_move_is_free(a, b, self.margin):
            return [a, b]
        _seed_ompl(seed)
        space = ob.SE2StateSpace()
        bounds = ob.RealVectorBounds(2)
        xmin, ymin, xmax, ymax = self.scene.workspace
        bounds.setLow(0, xmin), bounds.setLow(1, ymin), bounds.setHigh(0, xmax), bounds.setHigh(1, ymax)
        space.setBounds(bounds)
        setup = og.SimpleSetup(space)
        info = setup.getSpaceInformation()
        margin = self.margin

        def pose(s) -> tuple[float, float, float]:
            return s.getX(), s.getY(), s.getYaw()

        setup.setStateValidityChecker(lambda s: model.pusher_clearance(pose(s)) >= margin)
        info.setMotionValidator(_Moves(info, model, margin, pose))
        start, goal = space.allocState(), space.allocState()
        for state, p in ((start, a), (goal, b)):
            state.setXY(float(p[0]), float(p[1]))
            state.setYaw(float(wrap_angle(p[2])))
        setup.setStartAndGoalStates(start, goal, 1e-9)
        setup.setPlanner(og.RRTConnect(info))
        count = [0]

        def enough() -> bool:
            count[0] += 1
            return count[0] > TRANSFER_ITERATIONS

        if not setup.solve(ob.PlannerTerminationCondition(enough)) or not setup.haveExactSolutionPath():
            return None
        path = setup.getSolutionPath()
        og.PathSimplifier(info).simplifyMax(path)  # by iterations, not time: the seed decides it
        states = [np.array(pose(s)) for s in path.getStates()]
        return [a, *states[1:-1], b]


class _Moves(ob.MotionValidator):
    """OMPL's check of a move between two states: the pusher's, by conservative advancement."""

    def __init__(self, info, model: CollisionModel, margin: float, pose):
        super().__init__(info)
        self.model, self.margin, self.pose = model, margin, pose

    def checkMotion(self, s1, s2) -> bool:  # noqa: N802 (OMPL's name)
        return self.model.pusher_move_is_free(self.pose(s1), self.pose(s2), self.margin)
