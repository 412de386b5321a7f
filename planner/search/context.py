"""What a planning run is asked (:class:`PlanRequest`, validated once) and what it builds once for
every search it runs (:class:`PlanningContext`): the clock, the edges' controls, the collision
model, the start edges, the transits and the shortcuts.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from ..actions.controls import EdgeControls, RegionTimeout, clearance_margin, edge_controls, step_length
from ..actions.dubins import DubinsShortcut
from ..actions.shortcut import JoinShortcut
from ..actions.switch_pose import Grid, SwitchShortcut
from ..actions.transit import TransitPlanner
from ..model.plan_file import Plan, Push, Transit
from ..model.fields import SceneError
from ..model.options import check_optimize, check_planner, check_regions, check_switch_cost, check_transit
from ..model.scene import Scene
from ..world.validity import CollisionModel
from .goal_region import GoalRegion

__all__ = ["PlanRequest", "PlanningContext", "Prebuilt", "cost", "length"]

#: The edges' controls and the collision model built for them, as a caller that plans many times
#: for one part shares them (:func:`planner.reachability`).
Prebuilt = tuple[list[EdgeControls], CollisionModel]


@dataclass(frozen=True)
class PlanRequest:
    """A planning run's options, checked: the scene with the overrides applied, and the seed, time
    limit, planner and improvement rounds. Made by :meth:`of`.

    >>> from planner import load_scene
    >>> request = PlanRequest.of(load_scene("scenes/parking.yaml"), seed=3, regions="stable")
    >>> request.seed, request.planner, request.scene.planner.regions
    (3, 'rrt', 'stable')
    >>> PlanRequest.of(request.scene, planner="prm")
    Traceback (most recent call last):
    ...
    planner.model.fields.SceneError: planner: must be one of rrt, kpiece, est, got 'prm'
    """

    scene: Scene
    seed: int
    time_limit: float
    planner: str
    optimize: int

    @classmethod
    def of(cls, scene: Scene, *, seed: int | None = None, time_limit: float | None = None, planner: str | None = None,
           regions: str | None = None, transit: str | None = None, switch_cost: float | None = None,
           optimize: int | None = None) -> "PlanRequest":
        """The request for ``scene``; options left as None take the scene's.

        Raises
        ------
        SceneError
            Naming the option at fault.
        """
        opts = scene.planner
        if regions is not None:
            opts = replace(opts, regions=check_regions(regions, "regions"))
        if switch_cost is not None:
            opts = replace(opts, switch_cost=check_switch_cost(switch_cost, "switch_cost"))
        pusher = scene.pusher if transit is None else replace(scene.pusher, transit=check_transit(transit, "transit"))
        name = check_planner(opts.name if planner is None else planner, "planner")
        return cls(replace(scene, planner=opts, pusher=pusher), opts.seed if seed is None else seed,
                   float(opts.time_limit if time_limit is None else time_limit), name,
                   opts.optimize if optimize is None else check_optimize(optimize, "optimize"))

    def result(self, clock: float, goal: np.ndarray, segments: list[Push | Transit], reason: str = "",
               note: str = "", tree: np.ndarray | None = None) -> Plan:
        """The plan for ``goal`` (solved if no ``reason``), timed from ``clock`` (perf_counter)."""
        found = Plan(self.scene.path, not reason, self.planner, self.seed, 0.0, self.scene.start.copy(), goal.copy(),
                     segments, f"{reason}; {note}" if reason and note else reason, note,
                     switch_cost=self.scene.planner.switch_cost, cf=self.scene.slider.cf)
        if tree is not None:
            found.tree = tree
        found.planning_time_s = time.perf_counter() - clock
        return found

    @property
    def out_of_time(self) -> str:
        """Why a goal has no plan when the search ran out of time."""
        return f"no plan found within the time limit of {self.time_limit:g} s"


def length(scene: Scene, segments: list[Push | Transit]) -> float:
    """Length of the centre of friction's path."""
    return sum(s.cf_path_length(scene.slider.cf) for s in segments)


def cost(scene: Scene, segments: list[Push | Transit]) -> float:
    """Length of the centre of friction's path plus the switch cost per switch."""
    return length(scene, segments) + scene.planner.switch_cost * sum(s.kind == "transit" for s in segments)


class PlanningContext:
    """Everything the searches of one request share, built once when the run starts.

    The time limit bounds the regions and the search together: the regions may take half of it
    (``note`` says which edges were left out when they did not all finish).

    Parameters
    ----------
    request : PlanRequest
    clock : float
        When the run started (perf_counter): the time limit counts from there.
    progress : callable, optional
        ``progress(k, n)`` before computing the ``k``-th of the ``n`` regions not cached.
    prebuilt : the edges' controls and collision model, shared by a caller planning often
        (the time limit is then the search's alone)

    Raises
    ------
    SceneError
        If the pusher has no room at the start on any edge (found before any region is computed),
        or only on edges with no stable push.
    RegionTimeout
        If no edge's region was computed within half the time limit.
    """

    def __init__(self, request: PlanRequest, clock: float, progress: Callable[[int, int], None] | None = None,
                 prebuilt: Prebuilt | None = None):
        self.request = request
        scene = self.scene = request.scene
        self.clock = clock
        self.deadline = self.clock + request.time_limit  # for the regions and the search alike
        self.step, self.margin = step_length(scene), clearance_margin(scene)
        self.note = ""  # what the regions' time-out left out
        controls, self.model = prebuilt or (None, CollisionModel(scene, scene.pusher.edges))
        if not any(self.model.is_clear(scene.start, e, self.step / 2) for e in scene.pusher.edges):
            raise SceneError("start", f"the pusher has no room on any allowed edge (needs {self.step / 2:.4g} m "
                                      "clearance)")
        if controls is None:
            try:
                controls = edge_controls(scene, self.clock + request.time_limit / 2, progress)
            except RegionTimeout as timeout:
                if not timeout.controls:
                    raise
                controls, self.note = timeout.controls, str(timeout)
        self.controls: list[EdgeControls] = controls
        self.starts = [k for k, c in enumerate(controls) if self.model.is_clear(scene.start, c.edge, self.step / 2)]
        if not self.starts:
            raise SceneError("start", "the pusher has room only on edges with no stable push")
        switching = scene.pusher.transit != "none" and len(controls) > 1
        self.transits = TransitPlanner(scene, [c.edge for c in controls], self.model,
                                       self.margin) if switching else None
        self._joined = JoinShortcut(controls, self.model, self.margin, self.transits)
        self._dubins = DubinsShortcut(scene, controls, self.model, self.margin)
        self._grid = Grid()
        self._switches = SwitchShortcut(scene, self._dubins.curves, self.model, self.transits,
                                        scene.planner.switch_cost, self._grid) if switching else None

    def result(self, goal: np.ndarray, segments: list[Push | Transit], reason: str = "",
               tree: np.ndarray | None = None) -> Plan:
        """The plan for ``goal`` (solved if no ``reason``), timed from the start of the run."""
        return self.request.result(self.clock, goal, segments, reason, self.note, tree)

    def goal_region(self, goals: np.ndarray) -> GoalRegion:
        """The goal region of ``goals``, with switches where transits are allowed."""
        return GoalRegion(self.scene, goals, self.controls, self.model, self.margin, self.transits)

    def shortcut(self, segments: list[Push | Transit]) -> list[Push | Transit]:
        """Fewer pushes where one joins several, switches moved where the plan is shortest, then
        shorter Dubins curves where they are free."""
        joined = self._joined(segments)
        return self._dubins(self._switches(joined) if self._switches is not None else joined)

    def refine(self, segments: list[Push | Transit], level: int) -> list[Push | Transit]:
        """``segments`` shortened across their switches (or, without switches, through a via
        pose) on a grid ``level`` times finer than :meth:`shortcut`'s, until the deadline: the
        refining grid of the improvement rounds."""
        grid = self._grid.refined(level)
        refined = SwitchShortcut(self.scene, self._dubins.curves, self.model, self.transits,
                                 self.scene.planner.switch_cost, grid, via=True, deadline=self.deadline)(segments)
        return self._dubins(refined)

    def direct(self, region: GoalRegion, goal: int = 0) -> list[Push | Transit] | None:
        """The cheapest plan of one or two pushes on a start edge, as in the paper's one-step
        planning, or None."""
        found = [d for k in self.starts if (d := region.pushes_to(self.scene.start, k, [goal]).get(goal))]
        return min((self.shortcut(d) for d in found), key=lambda d: cost(self.scene, d)) if found else None
