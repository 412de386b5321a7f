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
  (every segment moved rigidly with it, :func:`planner.model.segments.rechain`) it ends within
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
import re
from dataclasses import replace

import numpy as np

from mechanics import point_velocity, wrap_angle

from ..actions.transit import edge_contact_pose, in_plane_moves
from ..model.bodies import body_outline
from ..model.fields import SceneError, pose_text
from ..model.scene import Scene
from ..model.plan import Move, Plan
from ..model.segments import Push, Transfer, rechain
from ..world.validity import CollisionModel, advances, pose_along
from .verify import check_chain

__all__ = ["CLEARANCE", "MAX_CHECKS", "MAX_TRAVEL", "body_speed", "fit_parts_plan", "fit_plan"]

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
    >>> elsewhere = scene.with_part(start=scene.start + [0.05, 0.0, 0.0], goal=scene.goal + [0.05, 0.0, 0.0])
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
            travel = body_speed(scene, segment) * segment.duration
            if not travel <= MAX_TRAVEL:
                raise SceneError(f"plan.segments[{k}]", f"carries the body {travel:.3g} m, more than {MAX_TRAVEL:g} m")
    part = scene.part().name
    moved = replace(plan, starts={part: scene.start.copy()}, goals={part: scene.goal.copy()},
                    moves=[Move(part, rechain(m.segments, scene.start)) for m in plan.moves],
                    delivered=(part,), cfs={part: c for c in plan.cfs.values()})
    if not scene.within_tolerance(moved.final):
        raise SceneError("plan.final", f"run from the scene's start, it ends at {pose_text(moved.final)}, not at the "
                                       f"scene's goal {pose_text(scene.goal)}: {_miss(scene, moved.final, scene.goal)}")
    _check_clear(scene, moved)
    return moved


def body_speed(scene: Scene, push: Push) -> float:
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
                free = advances(lambda t: clearance(at(t), segment.edge), segment.duration, body_speed(scene, segment),
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


def fit_parts_plan(scene: Scene, plan: Plan) -> Plan:
    """``plan`` (a ``stablepush.plan/2``) checked to be a plan for the multi-part ``scene``: solved,
    the scene's parts at the scene's starts, each move a plan of its part that :func:`fit_plan`
    accepts with the scene's obstacles and walls (a buffer move ending where it ends), each
    transfer flush on the part it leaves and the part it reaches and clear of obstacles and walls,
    and every part ending within tolerance of its goal. What the parts do to each other (a push
    that shoves another part, a transfer through one) is not refused here: it is what ``--verify``
    and ``--simulate`` find, exit 3.

    Raises
    ------
    SceneError
        Naming the plan field that does not fit the scene.
    """
    if not plan.solved:
        raise SceneError("plan.solved", "is false: the file holds no way to the goals to check or run"
                                        + (f" ({plan.reason})" if plan.reason else ""))
    if sorted(plan.names) != sorted(scene.names):
        raise SceneError("plan.parts", f"are {', '.join(plan.names)}, but the scene's parts are {', '.join(scene.names)}")
    size = max(1.0, float(np.max(np.abs(scene.workspace))))
    for part in scene.parts:
        if np.abs(plan.starts[part.name] - part.start).max() > 1e-9 * size:
            raise SceneError(f"plan.parts.{part.name}.start", f"is {pose_text(plan.starts[part.name])}, not the scene's "
                                                              f"start {pose_text(part.start)}")
    poses, offset = scene.starts, 0
    last_move = {m.part: k for k, m in enumerate(plan.moves)}
    for k, move in enumerate(plan.moves):
        if move.transfer is not None:
            _fit_transfer(scene, move.transfer, poses, plan.moves[k - 1], move, offset)
            offset += 1
        goal = None if last_move[move.part] == k else move.end
        alone = scene.move_scene(move.part, poses, goal, others=False)
        try:
            fit_plan(alone, Plan.of_part(move.part, move.start, alone.goal, move.segments, scene=plan.scene,
                                         solved=True, planner=plan.planner, seed=plan.seed, planning_time_s=0.0,
                                         cf=plan.cfs.get(move.part)))
        except SceneError as err:
            raise SceneError(_in_plan(err.field, offset, move.part), err.problem) from None
        offset += len(move.segments)
        poses[move.part] = move.end
    for part in scene.parts:
        if not scene.delivered(part.name, poses[part.name]):
            raise SceneError(f"plan.parts.{part.name}.final", f"is {pose_text(poses[part.name])}, not within tolerance "
                                                              f"of the part's goal {pose_text(part.goal)}")
    return replace(plan, goals=scene.goals)


def _in_plan(field: str, offset: int, part: str) -> str:
    """A one-part plan's field as the multi-part plan names it: its segments numbered among all of them.

    >>> _in_plan("plan.segments[2].twist", 5, "a"), _in_plan("plan.final", 5, "a")
    ('plan.segments[7].twist', 'plan.parts.a.final')
    """
    if (m := re.match(r"plan\.segments\[(\d+)\]", field)) is not None:
        return f"plan.segments[{int(m.group(1)) + offset}]{field[m.end():]}"
    return f"plan.parts.{part}.{field.removeprefix('plan.')}"


def _fit_transfer(scene: Scene, transfer: Transfer, poses: dict[str, np.ndarray], before: Move, after: Move,
                  index: int) -> None:
    """Refuse ``transfer`` (segment ``index``) unless it leaves ``before``'s part from its last contact, reaches
    ``after``'s first contact, and its in-plane moves keep clear of the obstacles and walls."""
    name = f"plan.segments[{index}]"
    ends = ((transfer.pusher_path[0], before.part, before.segments[-1].edge),
            (transfer.pusher_path[-1], after.part, after.segments[0].from_edge))
    for pose, part, edge in ends:
        flush = edge_contact_pose(scene.part(part).slider, edge, poses[part])
        if np.abs(pose[:2] - flush[:2]).max() > 1e-9 or abs(float(wrap_angle(pose[2] - flush[2]))) > 1e-9:
            raise SceneError(f"{name}.pusher_path", f"does not {'start' if part == before.part else 'end'} flush on "
                                                    f"part {part}'s edge {edge}")
    alone = scene.move_scene(after.part, poses, others=False)
    model = CollisionModel(alone, ())
    margin = CLEARANCE * alone.slider.radius
    if not all(model.pusher_move_is_free(a, b, margin) for a, b in in_plane_moves(transfer)):
        raise SceneError(name, "the pusher's transfer meets an obstacle or a workspace wall of the scene")
