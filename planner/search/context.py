"""What a planning run is asked (:class:`PlanRequest`, checked once), what every run on one scene
shares (:class:`SearchWorld`: the edges' controls, the collision model, the transits and the
shortcuts, built once for a scene and the session's options) and what one run adds to it
(:class:`PlanningContext`: its clock, start and start edges).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from ..actions.controls import EdgeControls, RegionTimeout, clearance_margin, edge_controls, step_length
from ..actions.dubins import DubinsShortcut
from ..actions.region_cache import RegionCache
from ..actions.shortcut import JoinShortcut, Shortcut
from ..actions.switch_pose import Grid, SwitchShortcut
from ..actions.transit import TransitPlanner
from ..model.fields import SceneError
from ..model.options import PlannerOptions, check_optimize, check_planner, check_seed, check_time_limit
from ..model.plan import Plan
from ..model.segments import Push, Transit, path_cost, path_length
from ..model.scene import Scene
from ..world.validity import CollisionModel
from .goal_region import GoalRegion

__all__ = ["DIRECT_CHUNK", "PlanRequest", "PlanningContext", "SearchWorld", "cost", "length"]

#: Goals whose direct connections are looked for between two looks at the deadline: a goal costs
#: up to a few milliseconds (its collision checks), so a batch of thousands stops within a fraction
#: of a second of its time limit.
DIRECT_CHUNK = 64


@dataclass(frozen=True)
class PlanRequest:
    """One run's options, checked: the seed, the time limit, the OMPL planner and the improvement
    rounds. Made by :meth:`of`, which names the argument at fault.

    >>> request = PlanRequest.of(PlannerOptions(), seed=3)
    >>> request.seed, request.planner, request.time_limit
    (3, 'rrt', 10.0)
    >>> PlanRequest.of(PlannerOptions(), planner="prm")
    Traceback (most recent call last):
    ...
    planner.model.fields.SceneError: planner: must be one of rrt, kpiece, est, got 'prm'
    """

    seed: int
    time_limit: float
    planner: str
    optimize: int

    @classmethod
    def of(cls, options: PlannerOptions, *, seed: object = None, time_limit: object = None,
           planner: object = None, optimize: object = None) -> "PlanRequest":
        """The request with ``options``' values where an argument is None.

        Raises
        ------
        SceneError
            Naming the argument at fault (``seed``, ``time_limit``, ``planner`` or ``optimize``).
        """
        return cls(options.seed if seed is None else check_seed(seed, "seed"),
                   options.time_limit if time_limit is None else check_time_limit(time_limit, "time_limit"),
                   options.name if planner is None else check_planner(planner, "planner"),
                   options.optimize if optimize is None else check_optimize(optimize, "optimize"))

    @property
    def out_of_time(self) -> str:
        """Why a goal has no plan when the search ran out of time."""
        return f"no plan found within the time limit of {self.time_limit:g} s"


def length(scene: Scene, segments: list[Push | Transit]) -> float:
    """Length of the centre of friction's path."""
    return path_length(segments, scene.slider.cf)


def cost(scene: Scene, segments: list[Push | Transit], switch_cost: float) -> float:
    """Length of the centre of friction's path plus ``switch_cost`` (metres) per switch."""
    return path_cost(segments, scene.slider.cf, switch_cost)


class SearchWorld:
    """Everything the runs on one scene share, built once: the allowed edges' controls (their
    stable regions), the collision model, the transits between edges and the shortcuts.

    Parameters
    ----------
    scene : Scene
    options : PlannerOptions
        The session's: its ``transit`` and ``switch_cost`` shape the transits and the shortcuts
        (and its ``regions`` the controls, :meth:`build`); a run's own are its
        :class:`PlanRequest`.
    controls : the edges' controls (:meth:`build` computes them)
    model : collision model with a body for each allowed edge
    note : what the user should know of the controls (edges left out at a time-out)
    """

    def __init__(self, scene: Scene, options: PlannerOptions, controls: list[EdgeControls], model: CollisionModel,
                 note: str = ""):
        self.scene, self.options, self.controls, self.model, self.note = scene, options, controls, model, note
        self.step, self.margin = step_length(scene), clearance_margin(scene)
        switching = options.transit != "none" and len(controls) > 1
        self.transits = (TransitPlanner(scene, [c.edge for c in controls], model, self.margin, options.transit)
                         if switching else None)
        self._joined: Shortcut = JoinShortcut(controls, model, self.margin, self.transits)
        self._dubins = DubinsShortcut(scene, controls, model, self.margin)
        self._grid = Grid()
        self._switches: Shortcut | None = SwitchShortcut(scene, self._dubins.curves, model, self.transits,
                                        options.switch_cost, self._grid) if switching else None

    @classmethod
    def build(cls, scene: Scene, options: PlannerOptions, deadline: float | None = None,
              progress: Callable[[int, int], None] | None = None, cache: RegionCache | None = None,
              model: CollisionModel | None = None) -> "SearchWorld":
        """The world of ``scene`` planned with ``options``, its regions (``options.regions``)
        computed (or read from ``cache``) by ``deadline`` (perf_counter); ``progress(k, n)`` hears
        of the ``k``-th of ``n`` regions computed.

        Raises
        ------
        SceneError
            If the pusher has no room at the scene's start on any edge (found before any region is
            computed); :class:`NoStablePush` if no edge has a stable push.
        RegionTimeout
            If no edge's region was computed by ``deadline``.
        """
        model = model or CollisionModel(scene, scene.edges)
        step = step_length(scene)
        if not any(model.is_clear(scene.start, e, step / 2) for e in scene.edges):
            raise SceneError("start", model.out_of_reach(scene.start, scene.edges, step / 2)
                             or f"the pusher has no room on any allowed edge (needs {step / 2:.4g} m clearance)")
        note = ""
        try:
            controls = edge_controls(scene, deadline, progress, cache, regions=options.regions, margin=options.margin)
        except RegionTimeout as timeout:
            if not timeout.controls:
                raise
            controls, note = timeout.controls, str(timeout)
        return cls(scene, options, controls, model, note)

    def start_edges(self, start: np.ndarray, room: float | None = None) -> list[int]:
        """The indices of the controls whose edge has room for the pusher at ``start``: a
        clearance above ``room`` (default: half the search's step, :class:`PlanningContext`).

        Raises
        ------
        SceneError
            If none has (naming ``start``).
        """
        room = self.step / 2 if room is None else room
        starts = [k for k, c in enumerate(self.controls) if self.model.is_clear(start, c.edge, room)]
        if not starts:
            if not any(self.model.is_clear(start, e, room) for e in self.scene.edges):
                raise SceneError("start", self.model.out_of_reach(start, self.scene.edges, room)
                                 or f"the pusher has no room on any allowed edge (needs {room:.4g} m clearance)")
            raise SceneError("start", "the pusher has room only on edges with no stable push")
        return starts

    def goal_region(self, goals: ArrayLike, aim: bool = True, deadline: float = math.inf) -> GoalRegion:
        """The goal region of ``goals``, with switches where transits are allowed (``aim`` and
        ``deadline``: as :class:`~planner.search.goal_region.GoalRegion`'s)."""
        return GoalRegion(self.scene, goals, self.controls, self.model, self.margin, self.transits, aim, deadline)

    def shortcut_cheaply(self, segments: list[Push | Transit]) -> list[Push | Transit]:
        """:meth:`shortcut` but for the switch poses, which stay where they are."""
        return self._dubins(self._joined(segments))

    def shortcut(self, segments: list[Push | Transit]) -> list[Push | Transit]:
        """Fewer pushes where one joins several, switches moved where the plan is shortest, then
        shorter Dubins curves where they are free."""
        joined = self._joined(segments)
        return self._dubins(self._switches(joined) if self._switches is not None else joined)

    def refine(self, segments: list[Push | Transit], level: int, deadline: float) -> list[Push | Transit]:
        """``segments`` shortened across their switches (or, without switches, through a via
        pose) on a grid ``level`` times finer than :meth:`shortcut`'s, until ``deadline``: the
        refining grid of the improvement rounds."""
        grid = self._grid.refined(level)
        refined = SwitchShortcut(self.scene, self._dubins.curves, self.model, self.transits,
                                 self.options.switch_cost, grid, via=True, deadline=deadline)(segments)
        return self._dubins(refined)


class PlanningContext:
    """One run on a :class:`SearchWorld`: its request, start, clock and deadline, and the edges
    the pusher may start on.

    The search checks its states a step apart, each clear by half a step, so that the motion
    between two is clear too; a start must be as clear for the search to leave it
    (:attr:`search_starts`). The plans of one or two pushes (:meth:`direct`, and a session's
    joins) are checked all along by conservative advancement and need only the margin every push
    keeps (:func:`~planner.actions.controls.clearance_margin`). For a part ``observed`` where it
    is (a robot re-planning after a knock: the part and the pusher are there, not asked for),
    :attr:`starts` are the edges with that margin; else the search's.

    Parameters
    ----------
    world : SearchWorld
    request : PlanRequest
    start : the part's start pose (radians)
    clock : float
        When the run started (perf_counter): the time limit counts from there.
    observed : bool
        The part is observed at ``start`` (above).

    Raises
    ------
    SceneError
        If the pusher has no room at ``start`` on an edge with stable pushes.
    """

    def __init__(self, world: SearchWorld, request: PlanRequest, start: np.ndarray, clock: float,
                 observed: bool = False):
        self.world, self.request, self.start, self.clock = world, request, start, clock
        self.scene, self.controls, self.model, self.step = world.scene, world.controls, world.model, world.step
        self.deadline = clock + request.time_limit
        self.starts = world.start_edges(start, world.margin if observed else None)
        half = self.step / 2
        self.search_starts = [k for k in self.starts if not observed or self.model.is_clear(start, self.controls[k].edge, half)]

    def result(self, goal: np.ndarray, segments: list[Push | Transit], reason: str = "",
               tree: np.ndarray | None = None, improvements: list[tuple[float, float, float]] | None = None) -> Plan:
        """The plan for ``goal`` (solved if no ``reason``), timed from the start of the run."""
        return plan_result(self.scene, self.request, self.world.options.switch_cost, self.clock, self.start, goal,
                           segments, reason, self.world.note, tree, improvements)

    def goal_region(self, goals: ArrayLike) -> GoalRegion:
        return self.world.goal_region(goals, deadline=self.deadline)

    def shortcut(self, segments: list[Push | Transit]) -> list[Push | Transit]:
        return self.world.shortcut(segments)

    def refine(self, segments: list[Push | Transit], level: int) -> list[Push | Transit]:
        return self.world.refine(segments, level, self.deadline)

    def direct(self, region: GoalRegion, goal: int = 0, shorten: bool = True) -> list[Push | Transit] | None:
        """The cheapest plan of one or two pushes on a start edge, as in the paper's one-step
        planning (each shortened first, unless not ``shorten``), or None."""
        return self.direct_many(region, [goal], shorten).get(goal)

    def direct_many(self, region: GoalRegion, goals: list[int], shorten: bool = True) -> dict[int, list[Push | Transit]]:
        """:meth:`direct` for each of ``goals`` (indices) that has one, screened
        :data:`DIRECT_CHUNK` at once on each start edge in turn; after the first chunk on the first
        edge, only until the deadline (what is left is the caller's to answer: many goals, or a
        part of many edges)."""
        found: dict[int, list[list[Push | Transit]]] = {}
        chunks = [goals[first:first + DIRECT_CHUNK] for first in range(0, len(goals), DIRECT_CHUNK)]
        for n, (chunk, k) in enumerate((chunk, k) for chunk in chunks for k in self.starts):
            if n and time.perf_counter() >= self.deadline:
                break
            for g, pushes in region.pushes_to(self.start, k, chunk).items():
                found.setdefault(g, []).append(self.world.shortcut(pushes) if shorten else pushes)
        switch_cost = self.world.options.switch_cost
        return {g: min(options, key=lambda d: cost(self.scene, d, switch_cost)) for g, options in found.items()}


def plan_result(scene: Scene, request: PlanRequest, switch_cost: float, clock: float, start: np.ndarray,
                goal: np.ndarray, segments: list[Push | Transit], reason: str = "", note: str = "",
                tree: np.ndarray | None = None, improvements: list[tuple[float, float, float]] | None = None) -> Plan:
    """The plan for ``goal`` from ``start`` (solved if no ``reason``), costed with ``switch_cost``
    per switch and timed from ``clock`` (perf_counter)."""
    elapsed = time.perf_counter() - clock
    if not improvements and not reason:  # a plan found at once: its one improvement is itself
        improvements = [(elapsed, cost(scene, segments, switch_cost), length(scene, segments))]
    return Plan.of_part(scene.part().name, start, goal, segments, scene=scene.path, solved=not reason,
                        planner=request.planner, seed=request.seed, planning_time_s=elapsed,
                        reason=f"{reason}; {note}" if reason and note else reason, note=note,
                        switch_cost=switch_cost, cf=scene.slider.cf, improvements=list(improvements or []),
                        **({} if tree is None else {"tree": tree}))
