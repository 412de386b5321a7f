"""Whether a plan read from a file is a plan for the scene it is used with (:func:`fit_plan`).

A plan file names its scene only by a path, which proves nothing: the same parts and pusher in
another scene (a start moved, a wall across the way, another goal) would otherwise be verified,
simulated and written as if it were that scene's plan. So before a loaded plan is used, it is
checked against the scene, each check naming the field that differs as the file names it
(:func:`~planner.model.plan_file.part_field`: ``plan.start`` in a ``plan/1`` file,
``plan.parts.<name>.start`` in a ``plan/2``; ``plan.segments[k]`` numbered over all segments,
transfers included):

* it says it is solved (an unsolved plan holds no way to the goal);
* its parts and pusher are the scene's: its CFs where the scene's parts have them, every push on
  an edge the scene lets the pusher push with the scene's pusher flush on it, every transit a mode
  the ``transit`` option allows, every transfer flush on the part it leaves and on the part it
  goes to, and the segments chained (:func:`planner.execution.verify.check_chain`);
* every part starts at the scene's start: a plan of one part within the scene's tolerance, a plan
  of several to rounding (its transfers are the pusher's paths between the parts where they
  stand, which would not follow one part moved);
* run from the scene's starts (every move's segments moved rigidly with its part,
  :func:`planner.model.segments.rechain`), every part ends within the goal tolerance;
* every push and every in-plane move of a transit or a transfer, so run, stays clear of the
  scene's obstacles and workspace walls (:mod:`.sweep`: the planner's own collision checks). What
  the parts do to each other (a push that shoves another part) is not refused here: it is what
  ``--verify`` and ``--simulate`` find, exit 3.

The file is untrusted, so the work is bounded by the checking, not by its numbers: a push that
would carry a point of the body beyond :data:`MAX_TRAVEL` is refused before it is followed, and a
plan whose checks would take more than :data:`MAX_CHECKS` clearance computations (a path hugging a
wall for kilometres) is refused rather than checked for ever.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import replace

import numpy as np

from mechanics import pose_error

from ..model.fields import SceneError, pose_text
from ..model.options import DEFAULT_TRANSIT
from ..model.plan import Plan
from ..model.plan_file import part_field
from ..model.scene import Scene
from ..model.segments import Push, Transfer, Transit, rechain
from ..world.validity import CollisionModel
from .sweep import body_speed, collision_model, is_clear
from .verify import check_chain, check_solved, placed_moves

__all__ = ["MAX_CHECKS", "MAX_TRAVEL", "fit_plan"]

#: Longest way (m) a push may carry a point of the body: a hundred times the largest table.
MAX_TRAVEL = 1e5
#: Most clearance computations a plan's check may take (about a second and a half of them).
MAX_CHECKS = 100_000
#: How an error names a segment that is not clear.
_WHAT = {Push: "the push", Transit: "the pusher's transit", Transfer: "the pusher's transfer"}


class _TooMany(Exception):
    """The check of a plan has taken :data:`MAX_CHECKS` clearance computations."""


def _miss(scene: Scene, pose: np.ndarray, target: np.ndarray) -> str:
    gap, turn = pose_error(pose, target)
    turn = math.degrees(turn)
    return (f"{gap:.4f} m and {turn:.2f} deg from it (tolerance {scene.tolerance_position:g} m, "
            f"{math.degrees(scene.tolerance_angle):g} deg)")


def fit_plan(scene: Scene, plan: Plan, *, transit: str = DEFAULT_TRANSIT) -> Plan:
    """``plan`` as run in ``scene``: from the scene's starts, with the scene's goals, after checking
    it is a plan for that scene and the ``transit`` option (module docstring). Any number of parts.

    Raises
    ------
    SceneError
        Naming the plan field that does not fit the scene (``plan.start``, ``plan.final``,
        ``plan.parts.red.final``, ``plan.segments[3]``...) and how.

    Examples
    --------
    >>> from planner import load_scene, plan
    >>> scene = load_scene("scenes/battery.yaml")
    >>> solved = plan(scene, seed=1)
    >>> fit_plan(scene, solved).final.round(3).tolist() == solved.final.round(3).tolist()
    True
    >>> elsewhere = scene.with_part(start=scene.start + [0.05, 0.0, 0.0], goal=scene.goal + [0.05, 0.0, 0.0])
    >>> fit_plan(elsewhere, solved)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    planner.model.fields.SceneError: plan.start: is [0.0000 m, 0.0000 m, 0.0000 rad = 0.00 deg], not the scene's start ...
    """
    with np.errstate(all="ignore"):  # a file's huge numbers overflow to inf, refused below, not warned of
        return _fit(scene, plan, transit)


def _fit(scene: Scene, plan: Plan, transit: str) -> Plan:
    check_solved(plan)
    check_chain(scene, plan, transit)
    _check_starts(scene, plan)
    for move, _, first in placed_moves(plan):
        alone = scene.move_scene(move.part, plan.starts, others=False)  # its part and the pusher
        for k, segment in enumerate(move.segments, first):
            if isinstance(segment, Push) and not (travel := body_speed(alone, segment) * segment.duration) <= MAX_TRAVEL:
                raise SceneError(f"plan.segments[{k}]", f"carries the body {travel:.3g} m, more than {MAX_TRAVEL:g} m")
    poses, moves = scene.starts, []
    for move in plan.moves:
        moves.append(replace(move, segments=rechain(move.segments, poses[move.part])))
        poses[move.part] = moves[-1].end
    moved = replace(plan, starts=scene.starts, goals=scene.goals, moves=moves, delivered=scene.names)
    for part in scene.parts:
        if not scene.delivered(part.name, poses[part.name]):
            raise SceneError(part_field(plan, part.name, "final"),
                             f"run from the scene's start, it ends at {pose_text(poses[part.name])}, not at the "
                             f"part's goal {pose_text(part.goal)}: {_miss(scene, poses[part.name], part.goal)}")
    _check_clear(scene, moved)
    return moved


def _check_starts(scene: Scene, plan: Plan) -> None:
    """Refuse a part that does not start at the scene's start (module docstring)."""
    size = max(1.0, float(np.max(np.abs(scene.workspace))))
    for part in scene.parts:
        start = plan.starts[part.name]
        if len(scene.parts) == 1:  # run from the scene's start, so it may be off by the tolerance
            near, how = scene.within_tolerance(start, part.start), f": {_miss(scene, start, part.start)}"
        else:
            near, how = np.abs(start - part.start).max() <= 1e-9 * size, " (a plan of several parts is not moved)"
        if not near:
            raise SceneError(part_field(plan, part.name, "start"), f"is {pose_text(start)}, not the scene's start "
                                                                   f"{pose_text(part.start)}{how}")


def _counted(model: CollisionModel, count: Callable[[], None]) -> CollisionModel:
    """``model``, calling ``count`` before each clearance it computes (the moves of a transit are
    checked by its own method, which asks its pusher_clearance)."""
    def counting(method: Callable[..., float]) -> Callable[..., float]:
        def counted(*args) -> float:
            count()
            return method(*args)
        return counted

    model.clearance, model.pusher_clearance = counting(model.clearance), counting(model.pusher_clearance)
    return model


def _check_clear(scene: Scene, plan: Plan) -> None:
    """Refuse the first segment of ``plan`` whose motion is not clear of the obstacles and walls of
    ``scene`` (:mod:`.sweep`), or the plan if checking it takes over :data:`MAX_CHECKS` clearance
    computations."""
    checks = 0

    def count() -> None:
        nonlocal checks
        checks += 1
        if checks > MAX_CHECKS:
            raise _TooMany

    for move, poses, first in placed_moves(plan):
        alone = scene.move_scene(move.part, poses, others=False)
        model = _counted(collision_model(alone, move.segments), count)
        # Its transfer (the part reached stands at the move's start) and its own segments.
        named = [(first - 1, move.transfer, move.start)] * (move.transfer is not None)
        for k, segment, pose in named + [(k, s, s.start) for k, s in enumerate(move.segments, first)]:
            try:
                free = is_clear(alone, model, segment)
            except _TooMany:
                raise SceneError(f"plan.segments[{k}]", f"takes more than {MAX_CHECKS} clearance computations to "
                                                        "check: a path too long, or too close to obstacles") from None
            if not free:
                raise SceneError(f"plan.segments[{k}]", f"{_WHAT[type(segment)]} {_blocked(alone, model, segment)} "
                                                        f"(from the part at {pose_text(pose)})")


def _blocked(scene: Scene, model: CollisionModel, segment: Push | Transit | Transfer) -> str:
    """What ``segment``, not clear in ``model``, meets: the arm's reach where it is clear without
    the arm, else an obstacle or a wall."""
    if model.zone is not None:
        free = replace(scene, robot=None)
        if is_clear(free, collision_model(free, [segment]), segment):
            return f"leaves the {scene.robot.model} arm's reach zone (docs/arm.md)"
    return "meets an obstacle or a workspace wall of the scene"
