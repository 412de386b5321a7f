"""Running a batch: :func:`run_batch`.

The stable regions every task needs are computed first, here, once for the whole batch
(:func:`~planner.batch.tasks.shared_regions`; read from the cache folder if a run computed them
before), and sent to each worker once (:meth:`~planner.batch.executors.Executor.run`'s ``shared``):
no worker computes a region another has, and none plans with regions cut short by its time limit,
which would make its plan depend on how busy the machine was.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any, TextIO

from ..model.fields import SceneError, shown
from ..model.files import write_atomic
from ..model.stop import raise_on_sigterm
from .executors import Executor, LocalExecutor, Outcome
from .progress import Progress
from .results import COLUMNS, ResultsFile
from .tasks import Task, run_task, shared_regions

__all__ = ["GRACE", "RETRIES", "run_batch", "stop_after"]

#: A worker that dies under a task is replaced and the task begun again this many times.
RETRIES = 2
#: Seconds a task may run past its time limit (the plan's shortening and the worker's start-up)
#: before it is stopped.
GRACE = 10.0


def stop_after(time_limit: float) -> float:
    """When a task of ``time_limit`` seconds is stopped: twice its limit (the regions and the
    search share the limit, but the plan's decoding and shortening come after it) plus :data:`GRACE`.

    >>> stop_after(1.0)
    12.0
    """
    return 2 * time_limit + GRACE


def run_batch(tasks: Sequence[Task], out: str | Path, executor: Executor | None = None, *, resume: bool = False,
              retries: int = RETRIES, stream: TextIO | None = None) -> list[dict[str, Any]]:
    """Run ``tasks`` on ``executor`` (default: a :class:`~planner.batch.executors.LocalExecutor`
    of one worker per core), appending each result to ``out/results.jsonl`` as it comes
    (:mod:`planner.batch.results`) and writing its plan beside it, with progress on ``stream``
    (default: standard error). With ``resume``, tasks that have a result in ``out`` already are
    not run again. Returns every task's record, sorted by task id.

    SIGTERM (as :class:`~planner.model.stop.Terminated`) and Ctrl-C stop the run at once: the
    results written are kept and every worker is stopped.

    Raises
    ------
    SceneError
        For tasks with the same id, or an ``out`` holding another batch's results without ``resume``.
    """
    ids = [t.id for t in tasks]
    if len(set(ids)) != len(ids):
        raise SceneError("tasks", f"task ids must differ; {sorted({i for i in ids if ids.count(i) > 1})[0]!r} repeats")
    out = Path(out)
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as err:
        raise SceneError("out", f"cannot make {shown(str(out))}: {err.strerror or err}") from None
    results = ResultsFile(out / "results.jsonl")
    done = results.read()
    if done and not resume:
        raise SceneError("out", f"{shown(str(out))} holds results of a batch already: resume it, or name "
                                  "another folder")
    todo = [t for t in tasks if t.id not in done]
    own = executor is None
    executor = LocalExecutor() if own else executor
    try:
        with raise_on_sigterm(), Progress(len(tasks), len(tasks) - len(todo), stream) as progress:
            shared = shared_regions(todo)
            timeout = max((stop_after(t.planned_scene().planner.time_limit) for t in todo), default=None)
            for index, outcome in executor.run(run_task, todo, shared, retries=retries, timeout=timeout):
                task = todo[index]
                record = _record(task, outcome, out)
                results.append(record)
                done[task.id] = record
                progress.update(task.id, record["status"])
    finally:
        if own:
            executor.close()
    return [done[i] for i in sorted(done) if i in set(ids)]


def _record(task: Task, outcome: Outcome, out: Path) -> dict[str, Any]:
    """The results line of ``task``, whose call ended with ``outcome``; its plan file is written first."""
    record: dict[str, Any] = dict.fromkeys(COLUMNS)
    record |= task.record() | {"status": "failed", "host": outcome.host, "attempts": outcome.attempts,
                               "error": outcome.error, "task_s": outcome.seconds if not outcome.failed else None}
    if not outcome.failed:
        value = dict(outcome.value)
        plan_file = f"{task.id}.json"
        write_atomic(out / plan_file, value.pop("plan"))
        reason = value.pop("reason")
        record |= value | {"plan": plan_file, "error": reason or None}
    return record

