"""Running a batch: :func:`run_batch`.

The stable regions every task needs are computed first, here, once for the whole batch
(:func:`~planner.batch.tasks.shared_regions`; read from the cache folder if a run computed them
before), and sent to each worker once (:meth:`~planner.batch.executors.Executor.run`'s ``shared``):
no worker computes a region another has, and none plans with regions cut short by its time limit,
which would make its plan depend on how busy the machine was.
"""

from __future__ import annotations

import sys
import tempfile
from collections import Counter
from collections.abc import Callable, Iterator, Mapping, Sequence
from pathlib import Path
from typing import Any, TextIO

from ..model.fields import SceneError, shown
from ..model.files import write_atomic
from ..model.stop import raise_on_sigterm
from .executors import Executor, LocalExecutor, Outcome
from .progress import Progress
from .results import COLUMNS, ResultsFile
from .tasks import Task, TaskList, run_task, shared_regions

__all__ = ["GRACE", "RETRIES", "BatchFailed", "batch_records", "reusable", "run_batch", "stop_after"]

#: A worker that dies under a task is replaced and the task begun again this many times.
RETRIES = 2
#: Seconds a task may run past its time limit (the plan's shortening and the worker's start-up)
#: before it is stopped.
GRACE = 10.0


class BatchFailed(RuntimeError):
    """Every task of a batch failed (none was solved, certified unreachable or left unknown): most
    likely the set-up, not the tasks, is wrong. ``records`` holds them all, as :func:`run_batch`
    would have returned them; the message names the first failure."""

    def __init__(self, records: list[dict[str, Any]]):
        super().__init__(f"every task of the batch failed ({len(records)}); "
                         f"{records[0]['id']}: {records[0]['error']}")
        self.records = records


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
    (default: standard error). Returns every task's record, sorted by task id.

    A :class:`~planner.batch.tasks.TaskList` streams: each task is made when a worker is free for
    it, so a run of four billion seeds starts as fast as one of four. With ``resume``, a task
    whose line in ``out`` is a whole record of the same task (:meth:`~planner.batch.tasks.Task.is_answered_by`:
    the same scene file content, seed, goal, overrides and planner version) is not run again;
    every other task runs, and a warning on ``stream`` says how many lines were not reused (a
    later line of an id supersedes an earlier one). Finding what is reused, and the records at
    the end, take time linear in the lines and tasks.

    SIGTERM (as :class:`~planner.model.stop.Terminated`) and Ctrl-C stop the run at once: the
    results written are kept and every worker is stopped.

    Raises
    ------
    SceneError
        For tasks with the same id, or an ``out`` holding another batch's results without ``resume``.
    BatchFailed
        When every task failed (a batch of tasks none of which could run says so, not only in
        its records).
    """
    if not isinstance(tasks, TaskList):
        tasks = list(tasks)
        repeated = [i for i, n in Counter(t.id for t in tasks).items() if n > 1]
        if repeated:
            raise SceneError("tasks", f"task ids must differ; {min(repeated)!r} repeats")
    find = tasks.find if isinstance(tasks, TaskList) else {t.id: t for t in tasks}.get
    out = Path(out)
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as err:
        raise SceneError("out", f"cannot make {shown(str(out))}: {err.strerror or err}") from None
    try:
        with tempfile.TemporaryFile(dir=out):  # where the results go is tried before any work
            pass
        results = ResultsFile(out / "results.jsonl")
        done, bad = results.read()
    except OSError as err:
        raise SceneError("out", f"cannot use {shown(str(err.filename or out))}: {err.strerror or err}") from None
    if (done or bad) and not resume:
        raise SceneError("out", f"{shown(str(out))} holds results of a batch already: resume it, or name "
                                  "another folder")
    reused = reusable(find, done, out)
    stale = bad + sum(find(i) is not None for i in done) - len(reused)
    stream = sys.stderr if stream is None else stream
    if stale:
        print(f"plan: warning: {stale} line{'s' if stale > 1 else ''} of {shown(str(results.path))} "
              f"{'are' if stale > 1 else 'is'} not a whole record of a task of this batch (cut or edited, or its "
              "scene file, options or planner version changed): those tasks run again", file=stream, flush=True)
    setups = tasks.setups() if isinstance(tasks, TaskList) else tasks
    todo = (t for t in tasks if t.id not in reused)
    running: dict[int, Task] = {}

    def feed() -> Iterator[Task]:  # notes each task as the executor takes it
        for index, task in enumerate(todo):
            running[index] = task
            yield task

    own = executor is None
    executor = LocalExecutor() if own else executor
    try:
        with raise_on_sigterm(), Progress(len(tasks), len(reused), stream) as progress:
            shared = shared_regions(setups)
            timeout = max((stop_after(t.planned()[1].time_limit) for t in setups), default=None)
            for index, outcome in executor.run(run_task, feed(), shared, retries=retries, timeout=timeout):
                task = running.pop(index)
                record = _record(task, outcome, out)
                results.append(record)
                done[task.id] = record
                progress.update(task.id, record["status"])
    finally:
        if own:
            executor.close()
    records = batch_records(find, done)
    if records and all(r["status"] == "failed" for r in records):
        raise BatchFailed(records)
    return records


def reusable(find: Callable[[str], Task | None], done: Mapping[str, Mapping[str, Any]], out: Path) -> set[str]:
    """The ids of the records in ``done`` (whole records of ``out/results.jsonl`` by id) that
    answer the task ``find`` gives for their id, their plan file in ``out`` if they name one."""
    return {i for i, record in done.items() if (task := find(i)) is not None and task.is_answered_by(record)
            and (record["plan"] is None or (out / record["plan"]).is_file())}


def batch_records(find: Callable[[str], Task | None], done: Mapping[str, dict[str, Any]]) -> list[dict[str, Any]]:
    """The records in ``done`` of the batch's tasks (those ``find`` knows), sorted by task id."""
    return [done[i] for i in sorted(done) if find(i) is not None]


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

