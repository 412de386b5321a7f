"""The OMPL objects of the search, each separate and none knowing of pushing but through the
actions it is handed:

* state space: SE(2) (the slider pose) x the index of the pushed edge;
* control space: the unit box ``[0, 1]^2``, or ``[0, 1]^3`` when the pusher may switch edges.
  The propagator maps the first two components through the edge's
  :class:`~mechanics.StableSteering`, so every push control is a guaranteed-stable push, and
  applies it exactly (SE(2) exponential, no integration). With switching, a third component in
  the top :data:`SWITCH_SHARE` of its range is instead a *switch* to the edge it selects
  (:func:`switch_target`): the pose stays, the edge changes, and the state is valid only if the
  :class:`~planner.actions.transit.TransitPlanner` finds a collision-free transit for the pusher
  (a car with reverse gear: the opposite edge drives the part backwards);
* validity: :class:`~planner.world.validity.CollisionModel` with its clearance rule;
* projection: ``(x, y, r theta)`` for the grid-based planners (:class:`PoseProjection`).
"""

from __future__ import annotations

import math

from ompl import base as ob
from ompl import control as oc

from ..actions.controls import EdgeControls
from ..actions.transit import TransitPlanner
from ..model.scene import Scene
from ..world.validity import CollisionModel, pose_along

__all__ = ["MAX_CONTROL_STEPS", "SWITCH_SHARE", "PoseProjection", "pose_of", "space_information", "switch_target"]

#: Longest constant push the planners sample, in collision-check steps.
MAX_CONTROL_STEPS = 30
#: Share of sampled controls that switch edges, when switching is allowed.
SWITCH_SHARE = 0.1


class PoseProjection(ob.ProjectionEvaluator):
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
        pass  # OMPL infers them from samples (setting them here fails before setup: docs/stack.md, "Projection cell sizes")

    def project(self, state, out) -> None:
        try:
            p = state[0]
            out[0], out[1], out[2] = p.getX(), p.getY(), p.getYaw() * self.radius
        finally:
            state = out = p = None  # see pose_of


def switch_target(u: float, n: int) -> int | None:
    """The edge index a third control component selects, or None if it is a push.

    >>> [switch_target(u, 4) for u in (0.0, 0.89, 0.9, 0.949, 0.96, 1.0)]
    [None, None, 0, 1, 2, 3]
    """
    if u < 1.0 - SWITCH_SHARE:
        return None
    return min(n - 1, int((u - (1.0 - SWITCH_SHARE)) / SWITCH_SHARE * n))


def pose_of(state) -> tuple[float, float, float, int]:
    """``(x, y, theta, k)`` of a search state, copied out of C++.

    Every function handed an OMPL state (or a component of one) drops its references before it
    returns, as this one does. A frame can outlive its call (a sampling profiler such as
    dask.distributed's holds every thread's frames, so do tracebacks), and with it the frame's
    locals; a wrapper kept alive so outlives the state OMPL frees, and nanobind, which finds
    wrappers by address, hands it back for the next state or component allocated there, whatever
    its type (``'CompoundState' object has no attribute 'value'``)
    (docs/stack.md, "Stale state wrappers").
    """
    try:
        p = state[0]
        return p.getX(), p.getY(), p.getYaw(), state[1].value
    finally:
        state = p = None


def space_information(scene: Scene, controls: list[EdgeControls], model: CollisionModel, step: float,
                      transits: TransitPlanner | None) -> tuple[ob.CompoundStateSpace, oc.SpaceInformation]:
    """The state space and the set-up space information (control space, propagator, validity
    checker) for planning with ``controls``; ``transits`` None: no switches."""
    se2 = ob.SE2StateSpace()
    bounds = ob.RealVectorBounds(2)
    xmin, ymin, xmax, ymax = scene.workspace
    bounds.setLow(0, xmin), bounds.setLow(1, ymin), bounds.setHigh(0, xmax), bounds.setHigh(1, ymax)
    se2.setBounds(bounds)
    space = ob.CompoundStateSpace()
    space.addSubspace(se2, 1.0)
    # Index len(controls) is never valid: it marks a switch with no transit. The index weighs as
    # much as crossing the workspace: nearest-neighbour planners (RRT) then extend each edge's
    # tree towards samples of that edge, instead of only the first edge's tree (all start states
    # share one pose, so ties would always go to edge 0).
    blocked = len(controls)
    span = math.hypot(xmax - xmin, ymax - ymin)
    space.addSubspace(ob.DiscreteStateSpace(0, blocked), span)
    space.lock()
    space.registerDefaultProjection(PoseProjection(space, scene.slider.radius))
    control_space = oc.RealVectorControlSpace(space, 2 if transits is None else 3)
    unit = ob.RealVectorBounds(2 if transits is None else 3)
    unit.setLow(0.0), unit.setHigh(1.0)
    control_space.setBounds(unit)
    si = oc.SpaceInformation(space, control_space)
    cache: dict[tuple, tuple[float, float, float]] = {}

    def step_of(k: int, u0: float, u1: float, duration: float) -> tuple[float, float, float]:
        # The body-frame displacement of one step. A control is propagated for many steps in a
        # row, so it is mapped and exponentiated once; this loop is the planner's hot path.
        key = (k, u0, u1, duration)
        if key not in cache:
            cache.clear()
            cache[key] = pose_along((0.0, 0.0, 0.0), controls[k].control_twist((u0, u1)))(duration)
        return cache[key]

    def propagate(start, control, duration, result) -> None:
        try:
            x, y, yaw, k = pose_of(start)
            r = result[0]
            target = None if transits is None else switch_target(control[2], len(controls))
            if target is not None:
                # A switch: the part stays; the pusher must find its way round (every step of the
                # control after the first is a switch to the edge it is already on, i.e. nothing).
                r.setXY(x, y)
                r.setYaw(yaw)
                free = target == k or transits.find((x, y, yaw), controls[k].edge,
                                                    controls[target].edge) is not None
                result[1].value = target if free else blocked
                return
            dx, dy, dth = step_of(k, control[0], control[1], duration)
            c, s = math.cos(yaw), math.sin(yaw)
            r.setXY(x + c * dx - s * dy, y + s * dx + c * dy)
            r.setYaw((yaw + dth + math.pi) % (2 * math.pi) - math.pi)
            result[1].value = k
        finally:
            start = control = result = r = None  # see pose_of

    def is_valid(state) -> bool:
        try:
            x, y, yaw, k = pose_of(state)
            return k < blocked and si.satisfiesBounds(state) and model.is_clear((x, y, yaw), controls[k].edge, step / 2)
        finally:
            state = None  # see pose_of

    si.setStatePropagator(propagate)
    si.setStateValidityChecker(is_valid)
    si.setPropagationStepSize(step)
    si.setMinMaxControlDuration(1, MAX_CONTROL_STEPS)
    si.setup()
    return space, si
