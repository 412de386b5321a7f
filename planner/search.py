"""Planning pushes among obstacles with OMPL's control planners (Lynch & Mason 1996, §4).

The OMPL objects are kept separate, as OMPL intends, and none of them knows about pushing:

* state space: SE(2) (the slider pose) x the index of the pushed edge;
* control space: the unit box ``[0, 1]^2``, or ``[0, 1]^3`` when the pusher may switch edges.
  The propagator maps the first two components through the edge's
  :class:`~mechanics.StableSteering`, so every push control is a guaranteed-stable push, and
  applies it exactly (SE(2) exponential, no integration). With switching, a third component in
  the top :data:`SWITCH_SHARE` of its range is instead a *switch* to the edge it selects: the pose
  stays, the edge changes, and the state is valid only if :class:`~planner.transit.TransitPlanner`
  finds a collision-free transit for the pusher (a car with reverse gear: the opposite edge drives
  the part backwards);
* validity: :class:`~planner.validity.CollisionModel` with its clearance rule;
* goal: the pose tolerance, or one or two stable collision-free pushes away
  (:class:`~planner.preimage.GoalPreimage`), on the state's edge or, with switching, on another
  edge the pusher can reach from there.

Every allowed edge gets a start state, so the trees of all edges grow at once; no time is split
between edges.

Switches cost (Lynch & Mason 1996, §4: a cost per contact change): a plan's cost is the length of
its centre of friction's path plus ``switch_cost`` per switch. When the first plan found switches,
a search without switches gets a budget of iterations (:data:`ONE_EDGE_ITERATIONS`; a count, not a
time, so a seed still gives one plan), and its plan wins if it costs no more.
"""

from __future__ import annotations

import math
import signal
import threading
import time
from dataclasses import replace
from collections.abc import Iterator
from typing import Callable

import numpy as np
from numpy.typing import ArrayLike
from ompl import base as ob
from ompl import control as oc
from ompl import util as ou

from mechanics import exp_twist, wrap_angle

from .dubins import DubinsShortcut
from .one_step import connect
from .plan_file import Plan, Segment
from .preimage import GoalPreimage
from .pushes import EdgePush, RegionTimeout, clearance_margin, edge_pushes, resolution
from .scene import MAX_SEED, Scene, SceneError, check_optimize, check_regions, check_switch_cost, check_transit
from .transit import TransitPlanner
from .validity import CollisionModel, pose_along

__all__ = ["plan", "plan_batch", "MAX_CONTROL_STEPS", "ONE_EDGE_ITERATIONS", "ONE_EDGE_MIN_ITERATIONS",
           "ROUND_ITERATIONS", "ROUND_MIN_ITERATIONS", "SWITCH_SHARE"]
#: Longest constant push the planners sample, in collision-check steps.
MAX_CONTROL_STEPS = 30
#: Share of sampled controls that switch edges, when switching is allowed.
SWITCH_SHARE = 0.1
#: When the first plan found switches, a search without switches gets this many times the
#: iterations the first search used (at least ``ONE_EDGE_MIN_ITERATIONS``): one edge alone
#: usually needs more of them. On parking, junction, gap and narrow_junction (20 seeds), 2x / 500
#: against 4x / 1000 raised the mean plan cost by at most 1.6 % and cut the median planning time
#: by up to a third (gap: 0.44 -> 0.28 s); ``optimize`` is the way to shorter plans.
ONE_EDGE_ITERATIONS, ONE_EDGE_MIN_ITERATIONS = 2, 500
#: An improvement round (``optimize``) gets this many times the first search's iterations (and
#: at least ``ROUND_MIN_ITERATIONS``).
ROUND_ITERATIONS, ROUND_MIN_ITERATIONS = 2, 1000

_ROUND_SEEDS = 1_000_003
_RECHECK = "the final push failed its re-check after rounding"
_PLANNERS: dict[str, Callable] = {"rrt": oc.RRT, "kpiece": oc.KPIECE1, "est": oc.EST}


def _seed_ompl(seed: int) -> None:
    # Re-seeding after the first time prints an OMPL error but works for objects made afterwards
    # (STACK.md §1.1), which is all a fresh planning run needs.
    ou.setLogLevel(ou.LOG_NONE)
    ou.RNG.setSeed(seed)
    ou.setLogLevel(ou.LOG_ERROR)


class _PoseProjection(ob.ProjectionEvaluator):
    """Projects a state to ``(x, y, r theta)`` for KPIECE's and EST's grids.

    Including the heading matters: the system is a forward-only car, so states at one place but
    turned differently reach different places; a position-only grid treats them as one cell.
    """

    def __init__(self, space, radius: float):
        super().__init__(space)
        self.radius = radius

    def getDimension(self) -> int:
        return 3

    def defaultCellSizes(self) -> None:
        pass  # OMPL infers them from samples (setting them here fails before setup; STACK.md §1.3)

    def project(self, state, out) -> None:
        p = state[0]
        out[0], out[1], out[2] = p.getX(), p.getY(), p.getYaw() * self.radius


def _within_tolerance(scene: Scene, pose: np.ndarray, goal: np.ndarray | None = None) -> bool:
    g = scene.goal if goal is None else goal
    return (math.hypot(pose[0] - g[0], pose[1] - g[1]) <= scene.tolerance_position
            and abs(float(wrap_angle(pose[2] - g[2]))) <= scene.tolerance_angle)


def _to_goals(preimage: GoalPreimage, transits: TransitPlanner | None, pose: np.ndarray, k: int,
              goals: list[int]) -> dict[int, list]:
    """Per goal index of ``goals`` that one or two pushes on edge index ``k`` reach from
    ``pose``, those pushes; for the others (with ``transits``) a switch to another edge and one or
    two pushes on it, where there is one."""
    found = preimage.connect_all(pose, k, goals)
    if transits is None:
        return found
    for other, push in enumerate(preimage.pushes):
        rest = [g for g in goals if g not in found]
        if not rest:
            break
        if other == k or not (lasts := preimage.connect_all(pose, other, rest)):
            continue
        transit = transits.find(pose, preimage.pushes[k].edge, push.edge)
        if transit is not None:
            found.update({g: [transit, *last] for g, last in lasts.items()})
    return found


def _to_goal(preimage: GoalPreimage, transits: TransitPlanner | None, pose: np.ndarray, k: int,
             goal: int = 0) -> list | None:
    """:func:`_to_goals` for one goal: its pushes (and switch), or None."""
    return _to_goals(preimage, transits, pose, k, [goal]).get(goal)


class _PushGoal(ob.GoalSampleableRegion):
    """Within the scene tolerance of a goal, or in its preimage under one or two stable pushes
    (after a switch of edge, when switching is allowed).

    The goals are the preimage's; ``active`` (indices) are those still sought. A state that
    reaches some of them is satisfied, and what it reaches is kept in ``hits``, keyed by the
    state, so that the search that stops there knows which goals its path serves (their pushes
    are found again from the path's re-composed end).
    """

    def __init__(self, si, scene: Scene, preimage: GoalPreimage, transits: TransitPlanner | None):
        super().__init__(si)
        self.scene, self.preimage, self.transits = scene, preimage, transits
        self.active = list(range(len(preimage.goals)))
        self.hits: dict[tuple, list[int]] = {}
        self._samples = 0
        self.setThreshold(1e-9)  # OMPL accepts distances strictly below the threshold

    def distanceGoal(self, state) -> float:
        p, k = state[0], state[1].value
        pose = np.array([p.getX(), p.getY(), p.getYaw()])
        if k >= len(self.preimage.pushes):  # the marker of a blocked switch
            return math.inf
        goals = self.preimage.goals[self.active]
        near = [g for g, goal in zip(self.active, goals) if _within_tolerance(self.scene, pose, goal)]
        hits = near + list(_to_goals(self.preimage, self.transits, pose, k, [g for g in self.active if g not in near]))
        if hits:
            self.hits[(*pose, k)] = hits
            return 0.0
        return float(np.min(np.hypot(goals[:, 0] - pose[0], goals[:, 1] - pose[1])
                            + self.scene.slider.radius * np.abs(wrap_angle(goals[:, 2] - pose[2]))))

    def sampleGoal(self, state) -> None:
        # Goal samples take turns among the edges (and the goals), so goal bias pulls every
        # edge's tree towards every goal.
        self._samples += 1
        n = len(self.preimage.pushes)
        goal = self.preimage.goals[self.active[(self._samples // n) % len(self.active)]]
        state[0].setXY(float(goal[0]), float(goal[1]))
        state[0].setYaw(float(goal[2]))
        state[1].value = self._samples % n

    def maxSampleCount(self) -> int:
        return 1


class _Problem:
    """What :func:`plan` and :func:`plan_batch` share for one scene: the options, the edges'
    pushes, the collision model, the start edges, the transits and the shortcuts."""

    def __init__(self, scene: Scene, seed: int | None, time_limit: float | None, planner: str | None,
                 regions: str | None, transit: str | None, switch_cost: float | None,
                 progress: Callable[[int, int], None] | None, prebuilt: tuple[list[EdgePush], CollisionModel] | None):
        opts = scene.planner
        if regions is not None:
            opts = replace(opts, regions=check_regions(regions, "regions"))
        if switch_cost is not None:
            opts = replace(opts, switch_cost=check_switch_cost(switch_cost, "switch_cost"))
        pusher = scene.pusher if transit is None else replace(scene.pusher, transit=check_transit(transit, "transit"))
        self.scene = scene = replace(scene, planner=opts, pusher=pusher)
        self.seed = opts.seed if seed is None else seed
        self.time_limit = float(opts.time_limit if time_limit is None else time_limit)
        self.name = opts.name if planner is None else planner
        if self.name not in _PLANNERS:
            raise SceneError("planner", f"must be one of {', '.join(_PLANNERS)}, got {self.name!r}")
        self.clock = time.perf_counter()
        self.deadline = self.clock + self.time_limit  # for the regions and the search alike
        self.step, self.margin = resolution(scene), clearance_margin(scene)
        self.note = self.failure = ""  # what the regions' time-out left out, or that it left nothing
        self.pushes: list[EdgePush] | None = None
        # Found before any region is computed: the pusher has no room at the start on any edge.
        pushes, self.model = prebuilt or (None, CollisionModel(scene, scene.pusher.edges))
        if not any(self.model.is_clear(scene.start, e, self.step / 2) for e in scene.pusher.edges):
            raise SceneError("start", f"the pusher has no room on any allowed edge (needs {self.step / 2:.4g} m "
                                      "clearance)")
        try:  # regions are cached per part (planner.regions); they may take half the time, not all
            self.pushes = pushes or edge_pushes(scene, self.clock + self.time_limit / 2, progress)
        except RegionTimeout as timeout:
            if not timeout.pushes:
                self.failure = str(timeout)
                return
            self.pushes, self.note = timeout.pushes, str(timeout)
        self.starts = [k for k, p in enumerate(self.pushes) if self.model.is_clear(scene.start, p.edge, self.step / 2)]
        if not self.starts:
            raise SceneError("start", "the pusher has room only on edges with no stable push")
        switching = scene.pusher.transit != "none" and len(self.pushes) > 1
        self.transits = TransitPlanner(scene, [p.edge for p in self.pushes], self.model,
                                       self.margin) if switching else None
        self._joined = _Shortcut(self.pushes, self.model, self.margin, self.transits)
        self._dubins = DubinsShortcut(scene, self.pushes, self.model, self.margin)

    def result(self, goal: np.ndarray, segments: list, reason: str = "", tree=None) -> Plan:
        """The plan for ``goal`` (solved if no ``reason``), timed from the start of the problem."""
        found = Plan(self.scene.path, not reason, self.name, self.seed, 0.0, self.scene.start.copy(), goal.copy(),
                     segments, f"{reason}; {self.note}" if reason and self.note else reason, self.note)
        if tree is not None:
            found.tree = tree
        found.planning_time_s = time.perf_counter() - self.clock
        return found

    @property
    def out_of_time(self) -> str:
        """Why a goal has no plan when the search ran out of time."""
        return f"no plan found within the time limit of {self.time_limit:g} s"

    def preimage(self, goals: np.ndarray) -> GoalPreimage:
        return GoalPreimage(goals, self.pushes, self.model, self.margin, self.scene.slider.radius)

    def shortcut(self, segments: list) -> list:
        """Fewer pushes where one joins several, then shorter Dubins curves where they are free."""
        return self._dubins(self._joined(segments))

    def direct(self, preimage: GoalPreimage, goal: int = 0) -> list | None:
        """The cheapest plan of one or two pushes on a start edge, as in the paper's one-step
        planning, or None."""
        found = [d for k in self.starts if (d := preimage.connect(self.scene.start, k, goal))]
        return min((self.shortcut(d) for d in found), key=lambda d: _cost(self.scene, d)) if found else None


def plan(scene: Scene, seed: int | None = None, time_limit: float | None = None, planner: str | None = None,
         regions: str | None = None, transit: str | None = None, switch_cost: float | None = None,
         progress: Callable[[int, int], None] | None = None, *, optimize: int | None = None,
         prebuilt: tuple[list[EdgePush], CollisionModel] | None = None) -> Plan:
    """Plan guaranteed-stable pushes from ``scene.start`` to ``scene.goal``.

    Arguments left as ``None`` take the scene's options: ``regions`` is ``'stable'`` (procedure
    STABLE) or ``'exact'`` (the exact region, the default); ``transit`` is ``'plane'``, ``'lift'``
    or ``'none'`` (``pusher.transit``); ``switch_cost`` is in metres (``planner.switch_cost``). With a
    given seed, a run that solves within the time limit returns the same plan every time.

    The time limit bounds the edges' stable regions (computed once per part and cached; they may
    take half of it: a part with many edges plans with those done in time, and says so in
    ``Plan.note``, or ends unsolved if none is) and the search together; ``progress(k, n)`` hears of the ``k``-th of the ``n``
    regions that must be computed.

    ``optimize`` (default: ``planner.optimize``) is a number of improvement rounds: after the
    first plan, each round searches again with a seed of its own (drawn from ``seed``) and twice
    the first search's iterations, and its plan, shortened like the first, replaces the plan if it
    costs less. Rounds are counted, not timed, so a seed still gives one plan; they stop early at
    the time limit. ``Plan.first_length`` is the first plan's length. A plan of one or two pushes
    from the start (found before any search) is not searched again.

    ``prebuilt`` is the edges' pushes and the collision model (built with ``scene.pusher.edges``)
    for this scene's part, pusher and options, as :func:`planner.reachability` shares them between
    goals; they are then not rebuilt, and the time limit is the search's alone.

    Raises
    ------
    SceneError
        If an option is invalid or no allowed edge can start pushing.
    """
    problem = _Problem(scene, seed, time_limit, planner, regions, transit, switch_cost, progress, prebuilt)
    scene = problem.scene
    if problem.failure:
        return problem.result(scene.goal, [], problem.failure)
    if _within_tolerance(scene, scene.start):
        return problem.result(scene.goal, [])
    preimage = problem.preimage(scene.goal)
    direct = problem.direct(preimage)
    if direct:
        return problem.result(scene.goal, direct)
    search = _Search(problem, preimage)
    segments, tree, iterations = search.run(problem.deadline, problem.transits)
    if segments is None:
        return problem.result(scene.goal, [], _RECHECK if tree is None else problem.out_of_time, tree)
    segments = problem.shortcut(segments)
    if any(s.kind == "transit" for s in segments):
        budget = max(ONE_EDGE_ITERATIONS * iterations, ONE_EDGE_MIN_ITERATIONS)
        plain, _, _ = search.run(problem.deadline, None, budget)
        if plain is not None and _cost(scene, plain := problem.shortcut(plain)) <= _cost(scene, segments):
            segments = plain
    first = segments
    rounds = scene.planner.optimize if optimize is None else check_optimize(optimize, "optimize")
    budget = max(ROUND_ITERATIONS * iterations, ROUND_MIN_ITERATIONS)
    for r in range(1, rounds + 1):
        seed = (problem.seed + r * _ROUND_SEEDS) % MAX_SEED + 1
        other, _, _ = search.run(problem.deadline, problem.transits, budget, seed)
        if other is not None and _cost(scene, other := problem.shortcut(other)) < _cost(scene, segments):
            segments = other
    result = problem.result(scene.goal, segments, tree=tree)
    result.first_length = _length(scene, first)
    return result


def plan_batch(scene: Scene, goals: ArrayLike, seed: int | None = None, time_limit: float | None = None, *,
               prebuilt: tuple[list[EdgePush], CollisionModel] | None = None) -> list[Plan]:
    """One :class:`Plan` per goal (rows ``(x, y, theta)``, radians) from ``scene.start``, grown
    as one search tree.

    Each goal first gets the direct connection (one or two pushes, as in :func:`plan`); the goals
    left share one OMPL search: every new tree state is tested against all goals not yet reached,
    and when one is, its path is taken and the same tree grows on towards the rest. The time limit
    (default: the scene's) bounds that shared search as a whole, so each goal gets the full time
    limit of tree growth for the price of one. Plans are shortcut as :func:`plan`'s are, but
    a plan with switches gets no second, one-edge search: a batch answers where the part can go,
    :func:`plan` also what it costs. ``seed`` and ``prebuilt`` are as for :func:`plan`.

    >>> from planner import load_scene
    >>> scene = load_scene("scenes/battery.yaml")
    >>> [p.solved for p in plan_batch(scene, [scene.goal, scene.start])]
    [True, True]
    """
    problem = _Problem(scene, seed, time_limit, None, None, None, None, None, prebuilt)
    scene = problem.scene
    goals = np.array(goals, dtype=float).reshape(-1, 3)
    goals[:, 2] = wrap_angle(goals[:, 2])
    if problem.failure:
        return [problem.result(g, [], problem.failure) for g in goals]
    preimage = problem.preimage(goals)
    found: dict[int, Plan] = {}  # each timed when found
    for i, goal in enumerate(goals):
        if _within_tolerance(scene, scene.start, goal):
            found[i] = problem.result(goal, [])
        elif (direct := problem.direct(preimage, i)) is not None:
            found[i] = problem.result(goal, direct)
    rest = [i for i in range(len(goals)) if i not in found]
    if rest:
        for i, segments in _Search(problem, preimage).grow(rest, problem.deadline, problem.transits):
            found[i] = (problem.result(goals[i], [], _RECHECK) if segments is None
                        else problem.result(goals[i], problem.shortcut(segments)))
    return [found[i] if i in found else problem.result(g, [], problem.out_of_time) for i, g in enumerate(goals)]


def _length(scene: Scene, segments: list) -> float:
    """Length of the centre of friction's path."""
    return sum(s.cf_path_length(scene.slider.cf) for s in segments)


def _cost(scene: Scene, segments: list) -> float:
    """Length of the centre of friction's path plus the switch cost per switch."""
    return _length(scene, segments) + scene.planner.switch_cost * sum(s.kind == "transit" for s in segments)


class _Search:
    """OMPL control searches from the start states to the goal preimage, re-seeded per search."""

    def __init__(self, problem: _Problem, preimage: GoalPreimage):
        self.problem, self.preimage = problem, preimage

    def _setup(self, transits: TransitPlanner | None, seed: int | None = None):
        _seed_ompl(self.problem.seed if seed is None else seed)
        scene, pushes = self.problem.scene, self.problem.pushes
        space, si = _spaces(scene, pushes, self.problem.model, self.problem.step, transits)
        ss = oc.SimpleSetup(si)
        for k in self.problem.starts:
            s = space.allocState()
            s[0].setXY(float(scene.start[0]), float(scene.start[1]))
            s[0].setYaw(float(wrap_angle(scene.start[2])))
            s[1].value = k
            ss.addStartState(s)
        goal = _PushGoal(si, scene, self.preimage, transits)
        ss.setGoal(goal)
        ss.setPlanner(_PLANNERS[self.problem.name](si))
        return ss, si, goal

    def run(self, deadline: float, transits: TransitPlanner | None, iterations: int | None = None,
            seed: int | None = None) -> tuple[list | None, np.ndarray | None, int]:
        """Segments of the plan found to the first goal (None if none), the search tree (None if
        the plan failed its re-check) and the iterations used; the search stops at ``deadline``
        (perf_counter time) or after ``iterations``."""
        ss, si, goal = self._setup(transits, seed)
        goal.active = [0]
        count = [0]

        def stop() -> bool:
            count[0] += 1
            return time.perf_counter() >= deadline or (iterations is not None and count[0] > iterations)

        _solve(ss, stop)
        tree = _tree(ss, si)
        if not ss.haveExactSolutionPath():
            return None, tree, count[0]
        segments = _segments(ss.getSolutionPath(), self.problem, self.preimage, transits)
        return segments, tree if segments is not None else None, count[0]

    def grow(self, goals: list[int], deadline: float,
             transits: TransitPlanner | None) -> Iterator[tuple[int, list | None]]:
        """One tree towards all of ``goals``: yields each goal index reached with its segments
        (None if the plan failed its re-check), until every goal is reached or ``deadline``.

        OMPL's planners keep their tree between calls of ``solve`` (only ``clear`` empties it), so
        each call goes on growing it towards the goals left; every state joins the tree tested
        against all goals not reached by then.
        """
        ss, si, goal = self._setup(transits)
        goal.active = list(goals)
        while goal.active and time.perf_counter() < deadline:
            ss.getProblemDefinition().clearSolutionPaths()
            _solve(ss, lambda: time.perf_counter() >= deadline)
            if not ss.haveExactSolutionPath():
                return
            path = ss.getSolutionPath()
            last = path.getState(path.getStateCount() - 1)
            hits = goal.hits[(last[0].getX(), last[0].getY(), last[0].getYaw(), last[1].value)]
            found = [(g, _segments(path, self.problem, self.preimage, transits, g)) for g in hits]
            # Python wrappers of C++ states must not outlive them: nanobind would hand a stale one,
            # typed as it was, to the propagator when the next solve reuses the address.
            del path, last
            goal.active = [g for g in goal.active if g not in hits]
            yield from found


def _solve(ss, stop: Callable[[], bool]) -> None:
    """``ss.solve()`` until ``stop()``; Ctrl-C also stops it, and is raised as KeyboardInterrupt
    once OMPL has returned (raised inside OMPL's callbacks it would be lost, and the search would
    end as if it had run out of time)."""
    if threading.current_thread() is not threading.main_thread():  # signals reach the main thread only
        ss.solve(ob.PlannerTerminationCondition(stop))
        return
    pressed: list[int] = []
    previous = signal.signal(signal.SIGINT, lambda signum, frame: pressed.append(signum))
    try:
        ss.solve(ob.PlannerTerminationCondition(lambda: bool(pressed) or stop()))
    finally:
        signal.signal(signal.SIGINT, previous)
    if pressed:
        raise KeyboardInterrupt


def _switch_target(u: float, n: int) -> int | None:
    """The edge index a third control component selects, or None if it is a push.

    >>> [_switch_target(u, 4) for u in (0.0, 0.89, 0.9, 0.949, 0.96, 1.0)]
    [None, None, 0, 1, 2, 3]
    """
    if u < 1.0 - SWITCH_SHARE:
        return None
    return min(n - 1, int((u - (1.0 - SWITCH_SHARE)) / SWITCH_SHARE * n))


def _spaces(scene: Scene, pushes: list[EdgePush], model: CollisionModel, step: float,
            transits: TransitPlanner | None):
    se2 = ob.SE2StateSpace()
    bounds = ob.RealVectorBounds(2)
    xmin, ymin, xmax, ymax = scene.workspace
    bounds.setLow(0, xmin), bounds.setLow(1, ymin), bounds.setHigh(0, xmax), bounds.setHigh(1, ymax)
    se2.setBounds(bounds)
    space = ob.CompoundStateSpace()
    space.addSubspace(se2, 1.0)
    # Index len(pushes) is never valid: it marks a switch with no transit. The index weighs as
    # much as crossing the workspace: nearest-neighbour planners (RRT) then extend each edge's
    # tree towards samples of that edge, instead of only the first edge's tree (all start states
    # share one pose, so ties would always go to edge 0).
    blocked = len(pushes)
    span = math.hypot(xmax - xmin, ymax - ymin)
    space.addSubspace(ob.DiscreteStateSpace(0, blocked), span)
    space.lock()
    space.registerDefaultProjection(_PoseProjection(space, scene.slider.radius))
    controls = oc.RealVectorControlSpace(space, 2 if transits is None else 3)
    unit = ob.RealVectorBounds(2 if transits is None else 3)
    unit.setLow(0.0), unit.setHigh(1.0)
    controls.setBounds(unit)
    si = oc.SpaceInformation(space, controls)
    cache: dict[tuple, tuple[float, float, float]] = {}

    def step_of(k: int, u0: float, u1: float, duration: float) -> tuple[float, float, float]:
        # The body-frame displacement of one step. A control is propagated for many steps in a
        # row, so it is mapped and exponentiated once; this loop is the planner's hot path.
        key = (k, u0, u1, duration)
        if key not in cache:
            cache.clear()
            cache[key] = pose_along((0.0, 0.0, 0.0), pushes[k].control_twist((u0, u1)))(duration)
        return cache[key]

    def propagate(start, control, duration, result) -> None:
        p, k = start[0], start[1].value
        r = result[0]
        target = None if transits is None else _switch_target(control[2], len(pushes))
        if target is not None:
            # A switch: the part stays; the pusher must find its way round (every step of the
            # control after the first is a switch to the edge it is already on, i.e. nothing).
            r.setXY(p.getX(), p.getY())
            r.setYaw(p.getYaw())
            free = target == k or transits.find((p.getX(), p.getY(), p.getYaw()), pushes[k].edge,
                                                pushes[target].edge) is not None
            result[1].value = target if free else blocked
            return
        dx, dy, dth = step_of(k, control[0], control[1], duration)
        x, y, yaw = p.getX(), p.getY(), p.getYaw()
        c, s = math.cos(yaw), math.sin(yaw)
        r.setXY(x + c * dx - s * dy, y + s * dx + c * dy)
        r.setYaw((yaw + dth + math.pi) % (2 * math.pi) - math.pi)
        result[1].value = k

    def is_valid(state) -> bool:
        p, k = state[0], state[1].value
        return k < blocked and si.satisfiesBounds(state) and model.is_clear(
            (p.getX(), p.getY(), p.getYaw()), pushes[k].edge, step / 2)

    si.setStatePropagator(propagate)
    si.setStateValidityChecker(is_valid)
    si.setPropagationStepSize(step)
    si.setMinMaxControlDuration(1, MAX_CONTROL_STEPS)
    si.setup()
    return space, si


def _segments(path, problem: _Problem, preimage: GoalPreimage, transits: TransitPlanner | None,
              goal: int = 0) -> list | None:
    """Segments of an OMPL control path (copied out at once: its states live in C++): pushes,
    merged where consecutive controls are equal, and transits where the edge changes, plus the
    final push onto goal index ``goal`` if the path stops short; None if a re-check after
    rounding fails."""
    pushes = problem.pushes
    states = [(s[0].getX(), s[0].getY(), s[0].getYaw(), s[1].value) for s in path.getStates()]
    width = 2 if transits is None else 3
    controls = [tuple(u[i] for i in range(width)) for u in path.getControls()]
    durations = list(path.getControlDurations())
    k = states[0][3]
    # (edge index, push control, duration) per push and (from, to) per switch, in order.
    moves: list[tuple] = []
    for u, d in zip(controls, durations):
        target = None if transits is None else _switch_target(u[2], len(pushes))
        if target is not None:
            if target != k:
                moves.append((k, target))
                k = target
        elif moves and len(moves[-1]) == 3 and moves[-1][:2] == (k, u[:2]):
            moves[-1] = (k, u[:2], moves[-1][2] + d)
        else:
            moves.append((k, u[:2], d))
    segments: list = []
    pose = np.array(states[0][:3])
    for move in moves:
        if len(move) == 2:
            transit = transits.find(pose, pushes[move[0]].edge, pushes[move[1]].edge)
            if transit is None:
                return None
            segments.append(transit)
            k = move[1]
            continue
        k, u, d = move
        push = pushes[k]
        twist = push.control_twist(u)
        end = exp_twist(pose, twist, d)
        end[2] = wrap_angle(end[2])
        segments.append(Segment(push.edge, push.region.contact, twist, float(d), pose, end))
        pose = end
    if not _within_tolerance(problem.scene, pose, preimage.goals[goal]):
        # The goal test accepted the tree's last state; the re-composed pose differs by rounding only.
        last = _to_goal(preimage, transits, pose, k, goal)
        if last is None:
            return None
        segments += last
    return segments


class _Shortcut:
    """Replace runs of segments by one push wherever one stable collision-free push joins their
    ends (the one-step test between plan waypoints); greedy, farthest waypoint first.

    Random controls make plans zig-zag; this keeps the guarantee (every replacement is checked
    like any push) and usually removes most pushes. A run may hold transits: it is replaced by a
    push on the edge in use where it begins, followed by a transit to the edge its end was on if
    the plan goes on from there (or, at the very start, by a push on that edge), so switches that
    are not needed disappear.
    """

    def __init__(self, pushes: list[EdgePush], model: CollisionModel, margin: float,
                 transits: TransitPlanner | None):
        self.by_edge = {p.edge: p for p in pushes}
        self.model, self.margin, self.transits = model, margin, transits

    def __call__(self, segments: list) -> list:
        out, i = [], 0
        while i < len(segments):
            for j in range(len(segments) - 1, i, -1):
                joined = self._join(segments, i, j, first=not out)
                if joined is not None:
                    out += joined
                    i = j + 1
                    break
            else:
                out.append(segments[i])
                i += 1
        return out

    def _join(self, segments: list, i: int, j: int, first: bool) -> list | None:
        a, b = segments[i], segments[j]
        if a.kind != "push" or b.kind != "push":
            return None
        last = j == len(segments) - 1
        for edge in (a.edge, b.edge) if first and a.edge != b.edge else (a.edge,):
            joined = connect(a.start, b.end, self.by_edge[edge], self.model, self.margin)
            if not isinstance(joined, Segment):
                continue
            if edge == b.edge or last:
                return [joined]
            transit = self.transits.find(b.end, edge, b.edge) if self.transits is not None else None
            if transit is not None:
                return [joined, transit]
        return None


def _tree(ss, si) -> np.ndarray:
    """The search tree as world-frame segments (vertex to vertex), shape ``(m, 2, 2)``."""
    data = ob.PlannerData(si)
    ss.getPlannerData(data)
    data.decoupleFromPlanner()
    xy = np.array([(data.getVertex(i).getState()[0].getX(), data.getVertex(i).getState()[0].getY())
                   for i in range(data.numVertices())]).reshape(-1, 2)
    pairs = [(i, j) for i in range(data.numVertices()) for j in data.getEdges(i)]
    return xy[np.array(pairs, dtype=int).reshape(-1, 2)] if pairs else np.zeros((0, 2, 2))
