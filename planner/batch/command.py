"""The ``plan`` command's batch mode: ``plan A.yaml B.yaml ... --seeds 1:100 --jobs N [--engine
local|ray] [--address ADDR] [--resume] --out DIR``.

Several scenes, or ``--seeds``, make a batch: a task per scene and seed, with the options given
(``--planner``, ``--time-limit``, ``--regions``, ``--transit``, ``--optimize``) overriding each
scene's; ``--seed N`` alone gives every scene that seed. Results go to ``DIR/results.jsonl`` as
tasks end, plans beside them (:func:`planner.batch.run_batch`), and a summary table per scene is
printed at the end. Exit 0 when every task was answered (solved, unreachable or unknown), 2 when
some failed (their ``error`` says why); bad input is one line and exit 1, before anything runs.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from ..model.fields import SceneError
from ..model.options import check_seed
from ..model.processes import cores
from .engines import executor
from .results import summary
from .run import BatchFailed, run_batch
from .tasks import make_tasks, parse_seeds

__all__ = ["run_command"]

#: Flags of a single plan that a batch does not take.
_SINGLE_ONLY = ("verify", "plan", "reach", "simulate", "sim_mu", "sim_cf_offset", "mjcf")


def run_command(args: argparse.Namespace) -> int:
    """Run the batch that the ``plan`` command's parsed ``args`` ask for (module docstring)."""
    for name in (*_SINGLE_ONLY, "trajectory"):
        if getattr(args, name) not in (None, False):
            raise SceneError(name, "is for one plan, not a batch (several scenes or seeds)")
    if args.resume and not args.out:
        raise SceneError("resume", "needs the folder of the batch to resume (out)")
    seeds = (parse_seeds(args.seeds) if args.seeds is not None
             else None if args.seed is None else [check_seed(args.seed, "seed")])
    overrides = {key: value for key, value in (("planner", args.planner), ("time_limit", args.time_limit),
                                               ("regions", args.regions), ("transit", args.transit),
                                               ("switch_cost", args.switch_cost), ("optimize", args.optimize),
                                               ("margin", args.margin))
                  if value is not None}
    tasks = make_tasks(args.scene, seeds, overrides=overrides)
    out = Path(args.out) if args.out else Path("logs") / f"batch-{time.strftime('%Y%m%d-%H%M%S')}"
    with executor(args.engine or "local", args.jobs, args.address) as engine:
        if (args.engine or "local") == "local" and args.jobs is not None:
            _note_workers(args.jobs, len(tasks))
        try:
            records = run_batch(tasks, out, engine, resume=args.resume)
        except BatchFailed as err:  # said at once, then the table and exit 2 as for any failure
            print(f"plan: {err}", file=sys.stderr)
            records = err.records
    failed = sum(r["status"] == "failed" for r in records)
    print(summary(records))
    print(f"{len(records)} tasks, {failed} failed -> {out}/results.jsonl", file=sys.stdout)
    return 2 if failed else 0


def _note_workers(jobs: int, tasks: int) -> None:
    """Say so when ``--jobs`` asks for more workers than there are tasks (a worker is started
    only for a task) or cores (the workers then share them)."""
    workers = min(jobs, tasks)
    notes = [f"{workers} worker{'s' if workers > 1 else ''}, one per task"] if jobs > tasks else []
    if workers > cores():
        n = cores()
        notes.append(f"more than the {n} core{'s' if n > 1 else ''}: the tasks share them, each running slower")
    if notes:
        print(f"plan: note: --jobs {jobs}: {'; '.join(notes)}", file=sys.stderr)
