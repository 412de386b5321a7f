"""Planning pushes among obstacles with OMPL's control planners (Lynch & Mason 1996, §4).

:func:`solve` answers one goal, :func:`solve_many` many with one search tree, each on a
:class:`~planner.search.context.PlanningContext` (a run of a request on a world built once:
:class:`~planner.search.context.SearchWorld`). A run tries the direct connection from the start,
and otherwise grows OMPL trees over the spaces of :mod:`planner.search.spaces` towards the goal
region of :mod:`planner.search.goal_region`; the path found is decoded with the goal test's own
connection (:mod:`planner.search.decode`) and shortened (:mod:`planner.actions.shortcut`).

Every allowed edge gets a start state, so the trees of all edges grow at once; no time is split
between edges.

Switches cost (Lynch & Mason 1996, §4: a cost per contact change): a plan's cost is the length of
its centre of friction's path plus ``switch_cost`` per switch. When the first plan found switches,
a search without switches gets a budget of iterations (:data:`ONE_EDGE_ITERATIONS`; a count, not a
time, so a seed still gives one plan), and its plan wins if it costs no more.
"""

from __future__ import annotations

import time
from collections import deque
from collections.abc import Callable, Container, Iterable, Iterator, Mapping, Sequence

import numpy as np
import shapely
from ompl import base as ob
from ompl import control as oc
from ompl import util as ou

from mechanics import wrap_angle

from ..model.plan import Plan

from ..model.segments import Push, Transit, rechain
from ..model.options import MAX_SEED
from ..model.stop import signals_deferred
from . import decode
from .context import PlanningContext, cost, length
from .goal_region import GoalRegion
from .goal import PushGoal
from .spaces import pose_of, space_information

__all__ = ["solve", "solve_many", "GROW_GOALS", "GROW_REACH", "HOP_GOALS", "HOP_REACH", "MAX_REFINEMENT", "ONE_EDGE_ITERATIONS", "ONE_EDGE_MIN_ITERATIONS",
           "ROUND_ITERATIONS", "ROUND_MIN_ITERATIONS"]

#: When the first plan still switches once shortened (the switch-pose shortcut drops a switch
#: wherever one edge joins its ends through a via pose), a search without switches gets this many
#: times the iterations the first search used (at least ``ONE_EDGE_MIN_ITERATIONS``). Seeds 1-10
#: of gap, junction, narrow_junction and parking: 1x / 250 against the 2x / 500 used before that
#: shortcut gave the same median costs and cut the median planning time by up to a third;
#: ``optimize`` is the way to cheaper plans.
ONE_EDGE_ITERATIONS, ONE_EDGE_MIN_ITERATIONS = 1, 250
#: An improvement round (``optimize``) gets this many times the first search's iterations (and
#: at least ``ROUND_MIN_ITERATIONS``).
ROUND_ITERATIONS, ROUND_MIN_ITERATIONS = 2, 1000

#: Improvement rounds alternate: a new search, then the plan so far shortened on a grid of
#: switch (or via) poses finer by one level (:meth:`~planner.actions.switch_pose.Grid.refined`)
#: than the round before's, up to this level (a grid of 64 times the default's poses; each level
#: also ends at the time limit).
MAX_REFINEMENT = 3
_ROUND_SEEDS = 1_000_003
#: A goal reached is the start of pushes to the goals nearest it not reached yet: this many, within
#: this many part radii (:class:`_Hops`).
HOP_GOALS, HOP_REACH = 6, 4.0
#: Plans found before (:func:`solve_many`'s ``known``) that goals are reached from, at most.
HOP_SOURCES = 256
#: A tree grown towards many goals tests each new state against this many goals nearest it, within
#: this many part radii (:attr:`~planner.search.goal.PushGoal.nearest`).
GROW_GOALS, GROW_REACH = 8, 16.0
_RECHECK = "a switch of the path found no transit when its poses were re-composed"
_PLANNERS: dict[str, Callable] = {"rrt": oc.RRT, "kpiece": oc.KPIECE1, "est": oc.EST}


def _seed_ompl(seed: int) -> None:
    # Re-seeding after the first time prints an OMPL error but works for objects made afterwards
    # (docs/stack.md, "Seeding"), which is all a fresh planning run needs.
    ou.setLogLevel(ou.LOG_NONE)
    ou.RNG.setSeed(seed)
    ou.setLogLevel(ou.LOG_ERROR)


def solve(context: PlanningContext, goal: np.ndarray) -> Plan:
    """Plan guaranteed-stable pushes from ``context.start`` to ``goal`` (radians) on the context's
    world, within its deadline: the search, the shortcuts and the improvement rounds
    (``request.optimize``: odd rounds search again with a seed of their own drawn from the
    request's and twice the first search's iterations, even rounds shorten the plan so far on a
    grid of switch or via poses finer each time, :data:`MAX_REFINEMENT`; a round's plan replaces
    the plan if it costs less, and rounds stop early at the deadline). A plan of one or two
    pushes from the start (found before any search) is not searched again.
    """
    request, scene, switch_cost = context.request, context.scene, context.world.options.switch_cost
    if scene.within_tolerance(context.start, goal):
        return context.result(goal, [])
    if far := context.world.model.out_of_reach(goal, [c.edge for c in context.world.controls], near=scene.tolerance_slack):
        return context.result(goal, [], f"the goal is {far}")
    region = context.goal_region(goal)
    direct = context.direct(region)
    if direct:
        return context.result(goal, direct)
    if not context.search_starts:
        return context.result(goal, [], f"no plan of one or two pushes, and the pusher has too little room for a search "
                                        f"at the start (needs {context.step / 2:.4g} m clearance)")
    search = _Search(context)
    segments, tree, iterations = search.run(region)
    if segments is None:
        return context.result(goal, [], _RECHECK if tree is None else request.out_of_time, tree)
    segments = context.shortcut(segments)
    if any(isinstance(s, Transit) for s in segments):
        budget = max(ONE_EDGE_ITERATIONS * iterations, ONE_EDGE_MIN_ITERATIONS)
        plain, _, _ = search.run(region.without_switches(), budget)
        if (plain is not None
                and cost(scene, plain := context.shortcut(plain), switch_cost) <= cost(scene, segments, switch_cost)):
            segments = plain
    improvements = [(time.perf_counter() - context.clock, cost(scene, segments, switch_cost), length(scene, segments))]
    budget = max(ROUND_ITERATIONS * iterations, ROUND_MIN_ITERATIONS)
    refined: tuple[int, int] | None = None  # the grid level and plan last refined
    for r in range(1, request.optimize + 1):
        if time.perf_counter() >= context.deadline:
            break
        if r % 2 == 0:  # the plan so far on a grid finer every other round
            level = min(r // 2, MAX_REFINEMENT)
            if refined == (level, id(segments)):
                continue  # the same grid gives the same plan
            refined = (level, id(segments))
            other = context.refine(segments, level)
        else:
            other, _, _ = search.run(region, budget, (request.seed + r * _ROUND_SEEDS) % MAX_SEED + 1)
            other = context.shortcut(other) if other is not None else None
        if other is not None and cost(scene, other, switch_cost) < cost(scene, segments, switch_cost):
            segments = other
            improvements.append((time.perf_counter() - context.clock, cost(scene, segments, switch_cost),
                                 length(scene, segments)))
    return context.result(goal, segments, tree=tree, improvements=improvements)


def solve_many(context: PlanningContext, goals: np.ndarray, shorten: bool = True,
               timings: dict[str, float] | None = None,
               known: Mapping[tuple[float, ...], list[Push | Transit]] | None = None) -> list[Plan]:
    """One :class:`Plan` per goal (rows ``(x, y, theta)``, radians) from ``context.start``, grown
    as one search tree.

    Each goal first gets the direct connection (one or two pushes, as in :func:`solve`); the goals
    left share one OMPL search: every new tree state is tested against all goals not yet reached,
    and when one is, its path is taken and the same tree grows on towards the rest, until the
    context's deadline, so each goal gets the full time of tree growth for the price of one.
    Plans are shortcut as :func:`solve`'s are (unless not ``shorten``: a plan as found still
    reaches its goal and verifies), but a plan with switches gets no second, one-edge search: a
    batch answers where the part can go, :func:`solve` also what it costs. ``timings``, if
    given, gets the seconds spent on the direct connections (``'connections'``) and on the tree
    (``'growth'``). ``known`` maps goals (as tuples) to plans from the start found before: a goal
    among them is answered by its plan, and goals are also reached from where those near them end,
    as from the goals reached here.
    """
    clock = time.perf_counter()
    found: dict[int, list[Push | Transit]] = {}  # segments, as found
    timed: dict[int, Plan] = {}  # each plan timed when found
    region = context.goal_region(goals)
    hops = _Hops(context, region, found)

    def take(i: int, segments: list[Push | Transit] | None) -> None:
        if segments is None:
            timed[i] = context.result(goals[i], [], _RECHECK)
            return
        found[i] = segments
        timed[i] = context.result(goals[i], context.shortcut(segments) if shorten and segments else segments)

    known = known or {}
    for i, goal in enumerate(goals):
        if context.scene.within_tolerance(context.start, goal):
            take(i, [])
        elif (before := known.get(tuple(goal.tolist()))) is not None:
            take(i, before)
    for i, direct in context.direct_many(region, [i for i in range(len(goals)) if i not in timed], False).items():
        take(i, direct)
    for i, segments in hops.spread([*hops.near_open(known.values()), *found.values()]):
        take(i, segments)
    grown = time.perf_counter()
    rest = [i for i in range(len(goals)) if i not in timed]
    if rest:
        search = _Search(context).grow(region, rest, timed)
        for i, segments in search:
            take(i, segments)
            for j, hopped in hops.spread([segments] if segments is not None else []):
                take(j, hopped)
    if timings is not None:
        timings.update(connections=grown - clock, growth=time.perf_counter() - grown)
    return [timed[i] if i in timed else context.result(g, [], context.request.out_of_time)
            for i, g in enumerate(goals)]


class _Hops:
    """Goals reached from goals: from where the plan of a goal reached ends, one or two pushes on
    the edge the pusher is on (the goal region's) to the nearest goals not reached yet
    (:data:`HOP_GOALS` of them, within :data:`HOP_REACH` part radii). A grid of goals a part's
    length or two apart is mostly reached so, a goal from its neighbour, once the first of them is
    reached at all; the tree reaches the rest."""

    def __init__(self, context: PlanningContext, region: GoalRegion, found: dict[int, list[Push | Transit]]):
        self.context, self.region, self.found = context, region, found
        self._index = {c.edge: k for k, c in enumerate(context.controls)}
        self._reach = HOP_REACH * context.scene.slider.radius

    def near_open(self, plans: Iterable[list[Push | Transit]]) -> list[list[Push | Transit]]:
        """Those of ``plans`` (each ending with a push) that end within hopping reach of a goal not
        reached yet, nearest first (:data:`HOP_SOURCES` at most)."""
        plans = [p for p in plans if p]
        rest = [g for g in range(len(self.region.goals)) if g not in self.found]
        if not plans or not rest:
            return []
        ends = shapely.points(np.array([p[-1].end[:2] for p in plans]))
        # A tree of the goals, not every end against every goal: both may number a hundred thousand.
        _, nearest = shapely.STRtree(shapely.points(self.region.goals[rest][:, :2])).query_nearest(
            ends, all_matches=False, return_distance=True)
        order = [i for i in np.argsort(nearest, kind="stable")[:HOP_SOURCES] if nearest[i] <= self._reach]
        return [plans[i] for i in order]

    def spread(self, sources: Sequence[list[Push | Transit]]) -> Iterator[tuple[int, list[Push | Transit]]]:
        """Each goal reached, breadth first, from where the plans ``sources`` end and from the
        goals reached so, with its segments; until none is left or the deadline."""
        queue, xy = deque(sources), self.region.goals[:, :2]
        while queue and time.perf_counter() < self.context.deadline:
            segments = queue.popleft()
            pose = segments[-1].end if segments else self.context.start
            rest = np.array([g for g in range(len(xy)) if g not in self.found], dtype=int)
            if rest.size == 0:
                return
            distance = np.hypot(*(xy[rest] - pose[:2]).T)
            near = rest[np.argsort(distance, kind="stable")[:HOP_GOALS]]
            near = near[np.hypot(*(xy[near] - pose[:2]).T) <= self._reach].tolist()
            for k in [self._index[segments[-1].edge]] if segments else self.context.starts:
                for g, more in self.region.pushes_to(pose, k, [g for g in near if g not in self.found]).items():
                    self.found[g] = rechain(segments + more)
                    queue.append(self.found[g])
                    yield g, self.found[g]


class _Search:
    """OMPL control searches from the start states into a goal region, re-seeded per search."""

    def __init__(self, context: PlanningContext):
        self.context = context

    def _setup(self, region: GoalRegion, seed: int | None = None):
        context = self.context
        _seed_ompl(context.request.seed if seed is None else seed)
        space, si = space_information(context.scene, context.controls, context.model, context.step, region.transits)
        ss = oc.SimpleSetup(si)
        start = context.start
        for k in context.search_starts:
            s = space.allocState()
            s[0].setXY(float(start[0]), float(start[1]))
            s[0].setYaw(float(wrap_angle(start[2])))
            s[1].value = k
            ss.addStartState(s)
        goal = PushGoal(si, region)
        ss.setGoal(goal)
        ss.setPlanner(_PLANNERS[context.request.planner](si))
        return ss, si, goal

    def _decoded(self, path, goal: PushGoal, g: int) -> list[Push | Transit] | None:
        """The segments of ``path`` to goal index ``g``: its own, then the goal test's connection."""
        connection = goal.found[pose_of(path.getState(path.getStateCount() - 1))][g]
        return decode.segments(path, self.context.controls, goal.region.transits, connection)

    def run(self, region: GoalRegion, iterations: int | None = None,
            seed: int | None = None) -> tuple[list[Push | Transit] | None, np.ndarray | None, int]:
        """Segments of the plan found to the region's first goal (None if none), the search tree
        (None if the plan failed to decode) and the iterations used; the search stops at the
        context's deadline or after ``iterations``."""
        ss, si, goal = self._setup(region, seed)
        goal.active = [0]
        count = [0]
        deadline = self.context.deadline

        def stop() -> bool:
            count[0] += 1
            return time.perf_counter() >= deadline or (iterations is not None and count[0] > iterations)

        _solve(ss, stop)
        tree = _tree(ss, si)
        if not ss.haveExactSolutionPath():
            return None, tree, count[0]
        segments = self._decoded(ss.getSolutionPath(), goal, 0)
        return segments, tree if segments is not None else None, count[0]

    def grow(self, region: GoalRegion, goals: list[int],
             done: Container[int] = ()) -> Iterator[tuple[int, list[Push | Transit] | None]]:
        """One tree towards all of ``goals``: yields each goal index reached with its segments
        (None if the plan failed to decode), until every goal is reached (here, or by the caller
        between yields: ``done``) or the deadline.

        OMPL's planners keep their tree between calls of ``solve`` (only ``clear`` empties it), so
        each call goes on growing it towards the goals left; every state joins the tree tested
        against all goals not reached by then.
        """
        ss, si, goal = self._setup(region)
        goal.active = list(goals)
        goal.nearest = (GROW_GOALS, GROW_REACH * self.context.scene.slider.radius)
        deadline = self.context.deadline
        while goal.active and time.perf_counter() < deadline:
            ss.getProblemDefinition().clearSolutionPaths()
            _solve(ss, lambda: time.perf_counter() >= deadline)
            if not ss.haveExactSolutionPath():
                return
            path = ss.getSolutionPath()
            hits = list(goal.found[pose_of(path.getState(path.getStateCount() - 1))])
            found = [(g, self._decoded(path, goal, g)) for g in hits]
            # Python wrappers of C++ states must not outlive them: nanobind would hand a stale one,
            # typed as it was, to the propagator when the next solve reuses the address
            # (docs/stack.md, "Solution states").
            del path
            goal.active = [g for g in goal.active if g not in hits]
            yield from found
            goal.active = [g for g in goal.active if g not in done]


def _solve(ss, stop: Callable[[], bool]) -> None:
    """``ss.solve()`` until ``stop()``; Ctrl-C or SIGTERM also stops it, and is raised (as
    KeyboardInterrupt or :class:`~planner.model.stop.Terminated`) once OMPL has returned: raised
    inside OMPL's callbacks it would be lost, and the search would end as if it had run out of time."""
    with signals_deferred() as noted:
        ss.solve(ob.PlannerTerminationCondition(lambda: bool(noted) or stop()))


def _tree(ss, si) -> np.ndarray:
    """The search tree as world-frame segments (vertex to vertex), shape ``(m, 2, 2)``."""
    data = ob.PlannerData(si)
    ss.getPlannerData(data)
    data.decoupleFromPlanner()
    xy = np.array([(data.getVertex(i).getState()[0].getX(), data.getVertex(i).getState()[0].getY())
                   for i in range(data.numVertices())]).reshape(-1, 2)
    pairs = [(i, j) for i in range(data.numVertices()) for j in data.getEdges(i)]
    return xy[np.array(pairs, dtype=int).reshape(-1, 2)] if pairs else np.zeros((0, 2, 2))
