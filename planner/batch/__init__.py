"""Batch runs: many scenes, seeds, goals and option overrides planned at once, in worker processes
on this machine or on a Ray cluster, each result written as it comes.

:mod:`.tasks` says what a task is and runs one in a worker; :mod:`.executors` runs picklable calls
in a pool of this machine's processes that retries a call whose worker died and stops one past
its time; :mod:`.ray_engine` does the same on Ray (an existing cluster, or one started and stopped
for the run), :mod:`.engines` names them, and :mod:`.ray_cluster` starts and stops local Ray
nodes by pid; :mod:`.results`
appends each finished task to ``results.jsonl`` and reads it back for ``--resume``;
:mod:`.progress` shows the run's progress; :mod:`.run` is :func:`run_batch`, driving them all;
:mod:`.reach` computes reachable-set maps on an executor; :mod:`.command` is the ``plan``
command's batch mode.

Allowed imports: every package below it (:mod:`planner.model` to :mod:`planner.pipeline`) and this one.
"""

from .engines import ENGINES, executor
from .executors import Executor, LocalExecutor, Outcome
from .run import BatchFailed, run_batch
from .tasks import Task, make_tasks, parse_seeds

__all__ = ["ENGINES", "BatchFailed", "Executor", "LocalExecutor", "Outcome", "Task", "executor", "make_tasks", "parse_seeds", "run_batch"]
