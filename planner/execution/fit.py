"""Whether a plan read from a file is a plan for the scene it is used with (:func:`fit_plan`).

A plan file names its scene only by a path, which proves nothing: the same part and pusher in
another scene (its start moved, a wall across the way, another goal) would otherwise be verified,
simulated and written as if it were that scene's plan. So before a loaded plan is used, it is
checked against the scene, each check naming the field that differs:

* it says it is solved (an unsolved plan holds no way to the goal);
* its part and pusher are the scene's: its CF where the scene's part has it, every push on an
  edge the scene lets the pusher push with the scene's pusher flush on it, every transit a mode
  the scene allows, and the segments chained (:func:`planner.execution.verify.check_chain`);
* its start is the scene's start within the scene's tolerance, and run from the scene's start
  (every segment moved rigidly with it, :func:`planner.model.plan_file.rechain`) it ends within
  the goal tolerance;
* every push and every in-plane move of a transit, so run, stays clear of the scene's obstacles
  and workspace walls by the planner's own collision checks (:class:`~planner.world.validity.CollisionModel`,
  conservative advancement with each push's own speed bound, since a file's twists need not be
  scaled to the planner's unit speed).

Clear means never nearer than :data:`CLEARANCE` part radii. The planner's searches keep more
(their margin, or half a propagation step at every state), so any plan of theirs passes; a plan
that touches a wall does not. The file is untrusted, so the work is bounded by the checking, not by
its numbers: a push that would carry a point of the body beyond :data:`MAX_TRAVEL` is refused
before it is followed, and a plan whose checks would take more than :data:`MAX_CHECKS` clearance
computations (a path hugging a wall for kilometres) is refused rather than checked for ever.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from mechanics import point_velocity, wrap_angle

from ..actions.transit import in_plane_moves
from ..model.bodies import body_outline
from ..model.fields import SceneError, pose_text
from ..model.plan_file import Plan, Push, rechain
from ..model.scene import Scene
from ..world.validity import CollisionModel, advances, pose_along
from .verify import check_chain

__all__ = ["CLEARANCE", "MAX_CHECKS", "MAX_TRAVEL", "fit_plan"]

#: Least clearance (in part radii) a loaded plan's pushes and transits must keep: a millionth.
CLEARANCE = 1e-6
#: Longest way (m) a push may carry a point of the body: a hundred times the largest table.
MAX_TRAVEL = 1e5
#: Most clearance computations a plan's check may take (about a second and a half of them).
MAX_CHECKS = 100_000


class _TooMany(Exception):
    """The check of a plan has taken :data:`MAX_CHECKS` clearance computations."""


def _miss(scene: Scene, pose: np.ndarray, target: np.ndarray) -> str:
    gap = math.hypot(pose[0] - target[0], pose[1] - target[1])
    turn = abs(math.degrees(float(wrap_angle(pose[2] - target[2]))))
    return (f"{gap:.4f} m and {turn:.2f} deg from it (tolerance {scene.tolerance_position:g} m, "
            f"{math.degrees(scene.tolerance_angle):g} deg)")


def fit_plan(scene: Scene, plan: Plan) -> Plan:
    """``plan`` as run in ``scene``: from the scene's start, with the scene's goal, after checking
    it is a plan for that scene (module docstring).

    Raises
    ------
    SceneError
        Naming the plan field that does not fit the scene (``plan.start``, ``plan.final``,
        ``plan.segments[3]``...) and how.

    Examples
    --------
    >>> from planner import load_scene, plan
    >>> scene = load_scene("scenes/battery.yaml")
    >>> solved = plan(scene, seed=1)
    >>> fit_plan(scene, solved).final.round(3).tolist() == solved.final.round(3).tolist()
    True
    >>> from dataclasses import replace
    >>> elsewhere = replace(scene, start=scene.start + [0.05, 0.0, 0.0], goal=scene.goal + [0.05, 0.0, 0.0])
    >>> fit_plan(elsewhere, solved)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    planner.model.fields.SceneError: plan.start: is [0.0000 m, 0.0000 m, 0.0000 rad = 0.00 deg], not the scene's start ...
    """
    with np.errstate(all="ignore"):  # a file's huge numbers overflow to inf, refused below, not warned of
        return _fit(scene, plan)


def _fit(scene: Scene, plan: Plan) -> Plan:
    if not plan.solved:
        raise SceneError("plan.solved", "is false: the file holds no way to the goal to check or run"
                                        + (f" ({plan.reason})" if plan.reason else ""))
    if plan.cf is not None and np.abs(plan.cf - scene.slider.cf).max() > CLEARANCE * scene.slider.radius:
        raise SceneError("plan.cf", f"is {np.round(plan.cf, 6).tolist()}, but the scene's part has its CF at "
                                    f"{np.round(scene.slider.cf, 6).tolist()}: a plan for another part")
    check_chain(scene, plan)
    if not scene.within_tolerance(plan.start, scene.start):
        raise SceneError("plan.start", f"is {pose_text(plan.start)}, not the scene's start {pose_text(scene.start)}: "
                                       f"{_miss(scene, plan.start, scene.start)}")
    for k, segment in enumerate(plan.segments):
        if segment.kind == "push":
            travel = _speed(scene, segment) * segment.duration
            if not travel <= MAX_TRAVEL:
                raise SceneError(f"plan.segments[{k}]", f"carries the body {travel:.3g} m, more than {MAX_TRAVEL:g} m")
    moved = replace(plan, start=scene.start.copy(), goal=scene.goal.copy(), segments=rechain(plan.segments, scene.start))
    if not scene.within_tolerance(moved.final):
        raise SceneError("plan.final", f"run from the scene's start, it ends at {pose_text(moved.final)}, not at the "
                                       f"scene's goal {pose_text(scene.goal)}: {_miss(scene, moved.final, scene.goal)}")
    _check_clear(scene, moved)
    return moved


def _speed(scene: Scene, push: Push) -> float:
    """The largest speed of any point of the body (part and pusher) under ``push``'s twist."""
    outline = body_outline(scene.slider, push.edge, scene.pusher.width, scene.pusher.depth)
    return float(np.linalg.norm(point_velocity(push.twist, outline), axis=1).max())


def _check_clear(scene: Scene, plan: Plan) -> None:
    """Refuse the first segment of ``plan`` whose motion comes within :data:`CLEARANCE` of an
    obstacle or a wall of ``scene``, or the plan if checking it takes over :data:`MAX_CHECKS`
    clearance computations."""
    edges = sorted({s.edge for s in plan.segments if s.kind == "push"})
    model = CollisionModel(scene, edges)
    margin = CLEARANCE * scene.slider.radius
    checks = 0

    def counted(clearance):
        def count(*args) -> float:
            nonlocal checks
            checks += 1
            if checks > MAX_CHECKS:
                raise _TooMany
            return clearance(*args)
        return count

    # The transits' moves are checked by the model's own method, which asks its pusher_clearance.
    model.pusher_clearance = counted(model.pusher_clearance)
    clearance = counted(model.clearance)
    for k, segment in enumerate(plan.segments):
        try:
            if segment.kind == "push":
                at = pose_along(segment.start, segment.twist)
                free = advances(lambda t: clearance(at(t), segment.edge), segment.duration, _speed(scene, segment),
                                margin)
            else:
                free = all(model.pusher_move_is_free(a, b, margin) for a, b in in_plane_moves(segment))
        except _TooMany:
            raise SceneError(f"plan.segments[{k}]", f"takes more than {MAX_CHECKS} clearance computations to "
                                                    "check: a path too long, or too close to obstacles") from None
        if not free:
            what = "the push" if segment.kind == "push" else "the pusher's transit"
            raise SceneError(f"plan.segments[{k}]", f"{what} meets an obstacle or a workspace wall of the scene "
                                                    f"(from the part at {pose_text(segment.start)})")
