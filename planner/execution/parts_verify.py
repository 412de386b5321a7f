"""Checking a multi-part plan push by push: each move re-simulated as a one-part plan
(:func:`planner.execution.verify.verify`), and each push's sweep checked against the other parts
where they stand while it is made.

A move is its part's pushes and transits with the other parts standing still, so its pushes are
verified as any one-part plan's (``n`` support distributions of that part, from each push's
planned start). What a one-part check cannot see is another part in the way: every push (the
part and the pusher on its edge) and every transit of a move is swept against the other parts at
their poses then (:class:`~planner.world.validity.CollisionModel`, conservative advancement), and
a move that meets one fails, naming the part it meets.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, replace

from ..actions.transit import in_plane_moves
from ..model.scene import Scene
from ..model.plan import Move, Plan
from ..model.plan import Plan
from ..world.validity import CollisionModel, advances, pose_along
from .fit import CLEARANCE, body_speed
from .verify import TOLERANCE, Verification, verify

__all__ = ["PartsVerification", "verify_parts"]


@dataclass(frozen=True)
class PartsVerification:
    """Outcome of :func:`verify_parts`: per move, its part, its one-part :class:`Verification`
    and the parts its segments meet (none: clear)."""

    moves: tuple[tuple[str, Verification, tuple[str, ...]], ...]
    seconds: float

    @property
    def passed(self) -> bool:
        return all(check.passed and not met for _, check, met in self.moves)

    def lines(self) -> list[str]:
        out = []
        for k, (part, check, met) in enumerate(self.moves, 1):
            clear = f"meets {', '.join(met)}: FAILED" if met else "clear of the other parts"
            out.append(f"move {k}/{len(self.moves)} ({part}): {check.summary().removeprefix('verify: ')}; {clear}")
        return out

    def summary(self) -> str:
        pushes = sum(len(check.pushes) for _, check, _ in self.moves)
        position = max((check.worst[0] for _, check, _ in self.moves), default=0.0)
        angle = max((check.worst[1] for _, check, _ in self.moves), default=0.0)
        met = sorted({p for _, _, m in self.moves for p in m})
        return (f"verify: {'passed' if self.passed else 'FAILED'}: {pushes} pushes of {len(self.moves)} moves x "
                f"{len(self.moves[0][1].supports) if self.moves else 0} distributions each; worst deviation "
                f"{position:.2e} m, {angle:.2e} rad; "
                + (f"parts met: {', '.join(met)}" if met else "every move clear of the other parts"))


def verify_parts(scene: Scene, plan: Plan, n: int = 200, seed: int = 1,
                 tolerance: float = TOLERANCE) -> PartsVerification:
    """Verify every move of ``plan`` (module docstring) under ``n`` support distributions.

    Raises
    ------
    SceneError
        As :func:`~planner.execution.verify.verify`, for a move that does not hang together.
    """
    clock = time.perf_counter()
    poses, out = scene.starts, []
    for move in plan.moves:
        alone = scene.move_scene(move.part, poses, goal=move.end)
        check = verify(alone, Plan.of_part(move.part, move.start, move.end, move.segments,
                                           scene=plan.scene, solved=True, planner=plan.planner, seed=plan.seed, planning_time_s=0.0, cf=plan.cfs.get(move.part)), n, seed, tolerance)
        met = tuple(other for other in scene.names if other != move.part and _meets(scene, move, poses, other))
        out.append((move.part, check, met))
        poses[move.part] = move.end
    return PartsVerification(tuple(out), time.perf_counter() - clock)


def _meets(scene: Scene, move: Move, poses: dict, other: str) -> bool:
    """Whether a push or transit of ``move`` comes within :data:`~planner.execution.fit.CLEARANCE`
    part radii of part ``other`` at its pose in ``poses`` (as :func:`~planner.execution.fit.fit_plan`
    checks obstacles)."""
    only = replace(scene.move_scene(move.part, poses), obstacles=(scene.body(other, poses[other]),))
    model = CollisionModel(only, sorted({s.edge for s in move.segments if s.kind == "push"}))
    margin = CLEARANCE * only.slider.radius
    for segment in move.segments:
        if segment.kind == "push":
            at = pose_along(segment.start, segment.twist)
            free = advances(lambda t: model.clearance(at(t), segment.edge), segment.duration,
                            body_speed(only, segment), margin)
        else:
            free = all(model.pusher_move_is_free(a, b, margin) for a, b in in_plane_moves(segment))
        if not free:
            return True
    return False
