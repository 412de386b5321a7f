"""Planning pushes among obstacles with OMPL's control planners (Lynch & Mason 1996, §4).

The OMPL objects are kept separate, as OMPL intends, and none of them knows about pushing:

* state space: SE(2) (the slider pose) x the index of the pushed edge (constant along a plan);
* control space: the unit box ``[0, 1]^2``; the propagator maps a control through the edge's
  :class:`~mechanics.StableSteering`, so every control is a guaranteed-stable push, and applies it
  exactly (SE(2) exponential, no integration);
* validity: :class:`~planner.validity.CollisionModel` with its clearance rule;
* goal: the pose tolerance, or one or two stable collision-free pushes away
  (:class:`~planner.preimage.GoalPreimage`).

Every allowed edge gets a start state, so the trees of all edges grow at once and a plan uses
the one edge whose tree reaches the goal first; no time is split between edges.
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

from .one_step import connect
from .plan_file import Plan, Segment
from .preimage import GoalPreimage
from .pushes import EdgePush, clearance_margin, edge_pushes, resolution
from .scene import Scene, SceneError, check_regions
from .validity import CollisionModel

__all__ = ["plan", "MAX_CONTROL_STEPS"]
#: Longest constant push the planners sample, in collision-check steps.
MAX_CONTROL_STEPS = 30

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


class _PushGoal(ob.GoalSampleableRegion):
    """Within the scene tolerance of the goal, or in its preimage under one or two stable pushes."""

    def __init__(self, si, scene: Scene, preimage: GoalPreimage):
        super().__init__(si)
        self.scene, self.preimage = scene, preimage
        self._samples = 0
        self.setThreshold(1e-9)  # OMPL accepts distances strictly below the threshold

    def distanceGoal(self, state) -> float:
        p = state[0]
        pose = np.array([p.getX(), p.getY(), p.getYaw()])
        if _within_tolerance(self.scene, pose) or self.preimage.connect(pose, state[1].value) is not None:
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
         regions: str | None = None) -> Plan:
    """Plan guaranteed-stable pushes from ``scene.start`` to ``scene.goal``.

    Arguments left as ``None`` take the scene's ``planner`` options; ``regions`` is ``'stable'``
    (procedure STABLE) or ``'exact'`` (the exact region, the default). With a given seed, a run that
    solves within the time limit returns the same plan every time.

    Raises
    ------
    SceneError
        If the planner name is unknown or no allowed edge can start pushing.
    """
    opts = scene.planner
    if regions is not None:
        scene = replace(scene, planner=replace(opts, regions=check_regions(regions, "regions")))
    seed = opts.seed if seed is None else seed
    time_limit = opts.time_limit if time_limit is None else time_limit
    name = opts.name if planner is None else planner
    if name not in _PLANNERS:
        raise SceneError("planner", f"must be one of {', '.join(_PLANNERS)}, got {name!r}")
    pushes = edge_pushes(scene)  # per part, and cached (planner.regions): not part of the search's time
    clock = time.perf_counter()
    model = CollisionModel(scene, [p.edge for p in pushes])
    step, margin = resolution(scene), clearance_margin(scene)
    result = Plan(scene.path, False, name, seed, 0.0, scene.start.copy(), scene.goal.copy())

    def done(segments: list[Segment], reason: str = "", tree=None) -> Plan:
        result.solved = not reason
        result.segments = segments
        result.reason = reason
        if tree is not None:
            result.tree = tree
        result.planning_time_s = time.perf_counter() - clock
        return result

    starts = [k for k, p in enumerate(pushes) if model.clearance(scene.start, p.edge) > step / 2]
    if not starts:
        raise SceneError("start", f"the pusher has no room on any allowed edge (needs {step / 2:.4g} m clearance)")
    if _within_tolerance(scene, scene.start):
        return done([])
    preimage = GoalPreimage(scene.goal, pushes, model, margin, scene.slider.radius)
    for k in starts:  # one or two pushes may do, as in the paper's one-step planning
        direct = preimage.connect(scene.start, k)
        if direct is not None:
            return done(_shortcut(direct, pushes[k], model, margin))
    _seed_ompl(seed)
    space, si = _spaces(scene, pushes, model, step)
    ss = oc.SimpleSetup(si)
    for k in starts:
        s = space.allocState()
        s[0].setXY(float(scene.start[0]), float(scene.start[1]))
        s[0].setYaw(float(wrap_angle(scene.start[2])))
        s[1].value = k
        ss.addStartState(s)
    ss.setGoal(_PushGoal(si, scene, preimage))
    ss.setPlanner(_PLANNERS[name](si))
    ss.solve(float(time_limit))
    tree = _tree(ss, si)
    if not ss.haveExactSolutionPath():
        return done([], f"no plan found within the time limit of {time_limit:g} s", tree)
    segments = _segments(ss.getSolutionPath(), scene, pushes, model, margin, preimage)
    if segments is None:
        return done([], "the final push failed its re-check after rounding", tree)
    return done(segments, tree=tree)


def _spaces(scene: Scene, pushes: list[EdgePush], model: CollisionModel, step: float):
    se2 = ob.SE2StateSpace()
    bounds = ob.RealVectorBounds(2)
    xmin, ymin, xmax, ymax = scene.workspace
    bounds.setLow(0, xmin), bounds.setLow(1, ymin), bounds.setHigh(0, xmax), bounds.setHigh(1, ymax)
    se2.setBounds(bounds)
    space = ob.CompoundStateSpace()
    space.addSubspace(se2, 1.0)
    # OMPL needs a discrete range of positive extent; with one edge, index 1 exists but is invalid.
    # The index weighs as much as crossing the workspace: nearest-neighbour planners (RRT) then
    # extend each edge's tree towards samples of that edge, instead of only the first edge's tree
    # (all start states share one pose, so ties would always go to edge 0).
    span = math.hypot(xmax - xmin, ymax - ymin)
    space.addSubspace(ob.DiscreteStateSpace(0, max(1, len(pushes) - 1)), span)
    space.lock()
    space.registerDefaultProjection(_PoseProjection(space, scene.slider.radius))
    controls = oc.RealVectorControlSpace(space, 2)
    unit = ob.RealVectorBounds(2)
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
        dx, dy, dth = step_of(k, control[0], control[1], duration)
        x, y, yaw = p.getX(), p.getY(), p.getYaw()
        c, s = math.cos(yaw), math.sin(yaw)
        r = result[0]
        r.setXY(x + c * dx - s * dy, y + s * dx + c * dy)
        r.setYaw((yaw + dth + math.pi) % (2 * math.pi) - math.pi)
        result[1].value = k

    def is_valid(state) -> bool:
        p, k = state[0], state[1].value
        return k < len(pushes) and si.satisfiesBounds(state) and model.clearance(
            (p.getX(), p.getY(), p.getYaw()), pushes[k].edge) > step / 2

    si.setStatePropagator(propagate)
    si.setStateValidityChecker(is_valid)
    si.setPropagationStepSize(step)
    si.setMinMaxControlDuration(1, MAX_CONTROL_STEPS)
    si.setup()
    return space, si


def _segments(path, scene: Scene, pushes: list[EdgePush], model: CollisionModel, margin: float,
              preimage: GoalPreimage) -> list[Segment] | None:
    """Segments of an OMPL control path (copied out at once: its states live in C++), merged where
    consecutive controls are equal, plus the final push onto the goal if the path stops short."""
    states = [(s[0].getX(), s[0].getY(), s[0].getYaw(), s[1].value) for s in path.getStates()]
    controls = [(u[0], u[1]) for u in path.getControls()]
    durations = list(path.getControlDurations())
    k = states[0][3]
    push = pushes[k]
    merged: list[tuple[tuple, float]] = []
    for u, d in zip(controls, durations):
        if merged and merged[-1][0] == u:
            merged[-1] = (u, merged[-1][1] + d)
        else:
            merged.append((u, d))
    segments = []
    pose = np.array(states[0][:3])
    for u, d in merged:
        twist = push.control_twist(u)
        end = exp_twist(pose, twist, d)
        end[2] = wrap_angle(end[2])
        segments.append(Segment(push.edge, push.region.contact, twist, float(d), pose, end))
        pose = end
    if not _within_tolerance(scene, pose):
        # The goal test accepted the tree's last state; the re-composed pose differs by rounding only.
        last = preimage.connect(pose, k)
        if last is None:
            return None
        segments += last
    return _shortcut(segments, push, model, margin)


def _shortcut(segments: list[Segment], push: EdgePush, model: CollisionModel, margin: float) -> list[Segment]:
    """Replace runs of pushes by one push wherever one stable collision-free push joins their
    ends (the one-step test between plan waypoints); greedy, farthest waypoint first.

    Random controls make plans zig-zag; this keeps the guarantee (every replacement is checked
    like any push) and usually removes most pushes.
    """
    out, i = [], 0
    while i < len(segments):
        for j in range(len(segments) - 1, i, -1):
            joined = connect(segments[i].start, segments[j].end, push, model, margin)
            if isinstance(joined, Segment):
                out.append(joined)
                i = j + 1
                break
        else:
            out.append(segments[i])
            i += 1
    return out


def _tree(ss, si) -> np.ndarray:
    """The search tree as world-frame segments (vertex to vertex), shape ``(m, 2, 2)``."""
    data = ob.PlannerData(si)
    ss.getPlannerData(data)
    data.decoupleFromPlanner()
    xy = np.array([(data.getVertex(i).getState()[0].getX(), data.getVertex(i).getState()[0].getY())
                   for i in range(data.numVertices())]).reshape(-1, 2)
    pairs = [(i, j) for i in range(data.numVertices()) for j in data.getEdges(i)]
    return xy[np.array(pairs, dtype=int).reshape(-1, 2)] if pairs else np.zeros((0, 2, 2))
