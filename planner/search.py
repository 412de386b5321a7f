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
import time
from dataclasses import replace
from typing import Callable

import numpy as np
from ompl import base as ob
from ompl import control as oc
from ompl import util as ou

from mechanics import exp_twist, wrap_angle

from .dubins import DubinsShortcut
from .one_step import connect
from .plan_file import Plan, Segment
from .preimage import GoalPreimage
from .pushes import EdgePush, RegionTimeout, clearance_margin, edge_pushes, resolution
from .scene import Scene, SceneError, check_regions, check_switch_cost, check_transit
from .transit import TransitPlanner
from .validity import CollisionModel

__all__ = ["plan", "MAX_CONTROL_STEPS", "ONE_EDGE_ITERATIONS", "ONE_EDGE_MIN_ITERATIONS", "SWITCH_SHARE"]
#: Longest constant push the planners sample, in collision-check steps.
MAX_CONTROL_STEPS = 30
#: Share of sampled controls that switch edges, when switching is allowed.
SWITCH_SHARE = 0.1
#: When the first plan found switches, a search without switches gets this many times the
#: iterations the first search used (at least ``ONE_EDGE_MIN_ITERATIONS``): its iterations cost
#: about a fifth as much (no transits to find), but one edge alone usually needs more of them.
ONE_EDGE_ITERATIONS, ONE_EDGE_MIN_ITERATIONS = 4, 1000

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


def _within_tolerance(scene: Scene, pose: np.ndarray) -> bool:
    g = scene.goal
    return (math.hypot(pose[0] - g[0], pose[1] - g[1]) <= scene.tolerance_position
            and abs(float(wrap_angle(pose[2] - g[2]))) <= scene.tolerance_angle)


def _to_goal(preimage: GoalPreimage, transits: TransitPlanner | None, pose: np.ndarray, k: int) -> list | None:
    """One or two pushes on edge index ``k`` from ``pose`` to the goal, or else (with ``transits``)
    a switch to another edge and one or two pushes on it; None if neither."""
    last = preimage.connect(pose, k)
    if last is not None or transits is None:
        return last
    for other, push in enumerate(preimage.pushes):
        if other != k and (last := preimage.connect(pose, other)) is not None:
            transit = transits.find(pose, preimage.pushes[k].edge, push.edge)
            if transit is not None:
                return [transit, *last]
    return None


class _PushGoal(ob.GoalSampleableRegion):
    """Within the scene tolerance of the goal, or in its preimage under one or two stable pushes
    (after a switch of edge, when switching is allowed)."""

    def __init__(self, si, scene: Scene, preimage: GoalPreimage, transits: TransitPlanner | None):
        super().__init__(si)
        self.scene, self.preimage, self.transits = scene, preimage, transits
        self._samples = 0
        self.setThreshold(1e-9)  # OMPL accepts distances strictly below the threshold

    def distanceGoal(self, state) -> float:
        p, k = state[0], state[1].value
        pose = np.array([p.getX(), p.getY(), p.getYaw()])
        if k >= len(self.preimage.pushes):  # the marker of a blocked switch
            return math.inf
        if _within_tolerance(self.scene, pose) or _to_goal(self.preimage, self.transits, pose, k) is not None:
            return 0.0
        g = self.scene.goal
        return math.hypot(pose[0] - g[0], pose[1] - g[1]) + self.scene.slider.radius * abs(
            float(wrap_angle(pose[2] - g[2])))

    def sampleGoal(self, state) -> None:
        state[0].setXY(float(self.scene.goal[0]), float(self.scene.goal[1]))
        state[0].setYaw(float(wrap_angle(self.scene.goal[2])))
        # Goal samples take turns among the edges, so goal bias pulls every edge's tree.
        self._samples += 1
        state[1].value = self._samples % len(self.preimage.pushes)

    def maxSampleCount(self) -> int:
        return 1


def plan(scene: Scene, seed: int | None = None, time_limit: float | None = None, planner: str | None = None,
         regions: str | None = None, transit: str | None = None, switch_cost: float | None = None,
         progress: Callable[[int, int], None] | None = None, *,
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

    ``prebuilt`` is the edges' pushes and the collision model (built with ``scene.pusher.edges``)
    for this scene's part, pusher and options, as :func:`planner.reachability` shares them between
    goals; they are then not rebuilt, and the time limit is the search's alone.

    Raises
    ------
    SceneError
        If an option is invalid or no allowed edge can start pushing.
    """
    opts = scene.planner
    if regions is not None:
        opts = replace(opts, regions=check_regions(regions, "regions"))
    if switch_cost is not None:
        opts = replace(opts, switch_cost=check_switch_cost(switch_cost, "switch_cost"))
    pusher = scene.pusher if transit is None else replace(scene.pusher, transit=check_transit(transit, "transit"))
    scene = replace(scene, planner=opts, pusher=pusher)
    seed = opts.seed if seed is None else seed
    time_limit = opts.time_limit if time_limit is None else time_limit
    name = opts.name if planner is None else planner
    if name not in _PLANNERS:
        raise SceneError("planner", f"must be one of {', '.join(_PLANNERS)}, got {name!r}")
    clock = time.perf_counter()
    deadline = clock + float(time_limit)  # for the regions and the search alike
    step, margin = resolution(scene), clearance_margin(scene)
    result = Plan(scene.path, False, name, seed, 0.0, scene.start.copy(), scene.goal.copy())

    def done(segments: list, reason: str = "", tree=None) -> Plan:
        result.solved = not reason
        result.segments = segments
        result.reason = f"{reason}; {result.note}" if reason and result.note else reason
        if tree is not None:
            result.tree = tree
        result.planning_time_s = time.perf_counter() - clock
        return result

    # Found before any region is computed: the pusher has no room at the start on any edge.
    pushes, model = prebuilt or (None, CollisionModel(scene, scene.pusher.edges))
    if not any(model.clearance(scene.start, e) > step / 2 for e in scene.pusher.edges):
        raise SceneError("start", f"the pusher has no room on any allowed edge (needs {step / 2:.4g} m clearance)")
    try:  # regions are cached per part (planner.regions); they may take half the time, not all
        pushes = pushes or edge_pushes(scene, clock + float(time_limit) / 2, progress)
    except RegionTimeout as timeout:
        if not timeout.pushes:
            return done([], str(timeout))
        pushes, result.note = timeout.pushes, str(timeout)
    starts = [k for k, p in enumerate(pushes) if model.clearance(scene.start, p.edge) > step / 2]
    if not starts:
        raise SceneError("start", "the pusher has room only on edges with no stable push")
    if _within_tolerance(scene, scene.start):
        return done([])
    preimage = GoalPreimage(scene.goal, pushes, model, margin, scene.slider.radius)
    switching = scene.pusher.transit != "none" and len(pushes) > 1
    transits = TransitPlanner(scene, [p.edge for p in pushes], model, margin) if switching else None
    joined, dubins = _Shortcut(pushes, model, margin, transits), DubinsShortcut(scene, pushes, model, margin)

    def shortcut(segments: list) -> list:
        """Fewer pushes where one joins several, then shorter Dubins curves where they are free."""
        return dubins(joined(segments))
    # One or two pushes may do, as in the paper's one-step planning: the cheapest over the edges.
    direct = [found for k in starts if (found := preimage.connect(scene.start, k)) is not None]
    if direct:
        return done(min((shortcut(d) for d in direct), key=lambda d: _cost(scene, d)))
    search = _Search(scene, pushes, model, preimage, name, seed, step)
    segments, tree, iterations = search.run(starts, deadline, transits)
    if segments is None:
        reason = ("the final push failed its re-check after rounding" if tree is None
                  else f"no plan found within the time limit of {time_limit:g} s")
        return done([], reason, tree)
    segments = shortcut(segments)
    if any(s.kind == "transit" for s in segments):
        budget = max(ONE_EDGE_ITERATIONS * iterations, ONE_EDGE_MIN_ITERATIONS)
        plain, _, _ = search.run(starts, deadline, None, budget)
        if plain is not None and _cost(scene, plain := shortcut(plain)) <= _cost(scene, segments):
            segments = plain
    return done(segments, tree=tree)


def _cost(scene: Scene, segments: list) -> float:
    """Length of the centre of friction's path plus the switch cost per switch."""
    return sum(s.cf_path_length(scene.slider.cf) for s in segments) + scene.planner.switch_cost * sum(
        s.kind == "transit" for s in segments)


class _Search:
    """One OMPL control search from the start states to the goal preimage, re-seeded per run."""

    def __init__(self, scene: Scene, pushes: list[EdgePush], model: CollisionModel, preimage: GoalPreimage,
                 name: str, seed: int, step: float):
        self.scene, self.pushes, self.model, self.preimage = scene, pushes, model, preimage
        self.name, self.seed, self.step = name, seed, step

    def run(self, starts: list[int], deadline: float, transits: TransitPlanner | None,
            iterations: int | None = None) -> tuple[list | None, np.ndarray | None, int]:
        """Segments of the plan found (None if none), the search tree (None if the plan failed
        its re-check) and the iterations used; the search stops at ``deadline`` (perf_counter
        time) or after ``iterations``."""
        _seed_ompl(self.seed)
        space, si = _spaces(self.scene, self.pushes, self.model, self.step, transits)
        ss = oc.SimpleSetup(si)
        for k in starts:
            s = space.allocState()
            s[0].setXY(float(self.scene.start[0]), float(self.scene.start[1]))
            s[0].setYaw(float(wrap_angle(self.scene.start[2])))
            s[1].value = k
            ss.addStartState(s)
        ss.setGoal(_PushGoal(si, self.scene, self.preimage, transits))
        ss.setPlanner(_PLANNERS[self.name](si))
        count = [0]

        def stop() -> bool:
            count[0] += 1
            return time.perf_counter() >= deadline or (iterations is not None and count[0] > iterations)

        ss.solve(ob.PlannerTerminationCondition(stop))
        tree = _tree(ss, si)
        if not ss.haveExactSolutionPath():
            return None, tree, count[0]
        segments = _segments(ss.getSolutionPath(), self.scene, self.pushes, self.preimage, transits)
        return segments, tree if segments is not None else None, count[0]


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
            dx, dy, dth = exp_twist((0.0, 0.0, 0.0), pushes[k].control_twist((u0, u1)), duration)
            cache[key] = (float(dx), float(dy), float(dth))
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
        return k < blocked and si.satisfiesBounds(state) and model.clearance(
            (p.getX(), p.getY(), p.getYaw()), pushes[k].edge) > step / 2

    si.setStatePropagator(propagate)
    si.setStateValidityChecker(is_valid)
    si.setPropagationStepSize(step)
    si.setMinMaxControlDuration(1, MAX_CONTROL_STEPS)
    si.setup()
    return space, si


def _segments(path, scene: Scene, pushes: list[EdgePush], preimage: GoalPreimage,
              transits: TransitPlanner | None) -> list | None:
    """Segments of an OMPL control path (copied out at once: its states live in C++): pushes,
    merged where consecutive controls are equal, and transits where the edge changes, plus the
    final push onto the goal if the path stops short; None if a re-check after rounding fails."""
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
    if not _within_tolerance(scene, pose):
        # The goal test accepted the tree's last state; the re-composed pose differs by rounding only.
        last = _to_goal(preimage, transits, pose, k)
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
