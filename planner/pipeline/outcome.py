"""What a run of the pipeline found (:class:`Outcome`), and the lines the command prints of it."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..actions.margins import smallest
from ..model.plan import Plan
from ..model.scene import Scene

__all__ = ["Outcome", "OutputError"]


class OutputError(Exception):
    """An output file could not be written (the message names it as the user named it, and says why)."""


@dataclass(frozen=True)
class Outcome:
    """Everything :func:`~planner.pipeline.run` found: the scene it was given, the plan (planned, or
    read from ``loaded`` and fitted to the scene), why the goal is certainly unreachable (if it
    is), and each check's result where it was asked: ``verification``
    (:class:`~planner.execution.verify.Verification`), ``simulation`` (open or closed loop),
    ``trajectory``, ``reach`` (:class:`~planner.queries.reachable_set.ReachableSet`); ``out`` and
    ``files``: where the outputs were written, the plan file first (it is written last: where it
    is, the run wrote everything)."""

    scene: Scene
    plan: Plan
    loaded: str | None = None  # the plan file's path, where the plan was read rather than planned
    unreachable: str | None = None  # the certificate's reason, where the goal is certified unreachable
    verification: Any = None
    simulation: Any = None
    trajectory: Any = None
    arm: Any = None  # the arm's joint trajectory along ``trajectory`` (planner.arm.joints), for a scene with a robot
    reach: Any = None
    out: Path | None = None
    files: list[str] = field(default_factory=list)

    @property
    def passed(self) -> bool:
        """The checks asked all passed (True where none was asked)."""
        return all(check is None or check.passed for check in (self.verification, self.arm, self.simulation))

    @property
    def code(self) -> int:
        """The command's exit code: 0 solved (and every check passed), 2 not solved or certified
        unreachable, 3 a check failed (a push slipped, the arm cannot follow, a run missed or collided)."""
        if self.unreachable or not self.plan.solved:
            return 2
        return 0 if self.passed else 3

    def problem(self) -> str | None:
        """Why there is no plan (``'unreachable: ...'`` or ``'not solved: ...'``), or None."""
        if self.unreachable:
            return f"unreachable: {self.unreachable}"
        return None if self.plan.solved else f"not solved: {self.plan.reason}"

    def headline(self) -> str:
        """The first line the command prints of a plan: what it is and what was written."""
        plan = self.plan
        least = "" if (m := smallest(plan)) is None else f", smallest margin {m}"
        if self.loaded is not None:
            head = f"loaded {self.loaded}: {plan.contents()}{least}"
        else:
            head = (f"solved: {plan.headline()}{least}, planning time {plan.planning_time_s:.2f} s"
                    f"{_first_found(plan)}")
        if self.out is None:
            return head
        shown = [f"{self.out}/{self.files[0]}", *self.files[1:]] if self.files else [str(self.out)]
        return f"{head} -> {', '.join(shown)}"

    def lines(self) -> list[str]:
        """What the command prints of a solved plan: :meth:`headline`, then each check's lines and
        summary; the last line says where the files are."""
        lines = [self.headline()]
        if self.verification is not None:
            lines += [*self.verification.lines(), f"{self.verification.summary()} in {self.verification.seconds:.1f} s"]
        if self.arm is not None:
            lines += [*self.arm.lines(), self.arm.summary()]
        if self.simulation is not None:
            lines += [*self.simulation.lines(), self.simulation.summary()]
        if len(lines) > 1 and self.out is not None:
            lines[-1] += f" (outputs in {self.out})"
        return lines


def _first_found(plan: Plan) -> str:
    """What the first plan cost and when it was found, when improvement rounds found better ones
    (cost against time: the answer only got better), else nothing.

    >>> plan = Plan.of_part("part", [0, 0, 0], [0, 0, 0], [], scene=None, solved=True, planner="rrt", seed=1,
    ...                     planning_time_s=2.5, improvements=[(0.4, 1.2, 0.95), (1.1, 0.8, 0.55)])
    >>> _first_found(plan)
    ' (first plan: cost 1.200 m at 0.40 s; 1 better, the last at 1.10 s)'
    """
    if len(plan.improvements) < 2:
        return ""
    (t, c, _), later = plan.improvements[0], len(plan.improvements) - 1
    return f" (first plan: cost {c:.3f} m at {t:.2f} s; {later} better, the last at {plan.improvements[-1][0]:.2f} s)"
