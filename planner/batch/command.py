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
from .engines import executor
from .results import summary
from .run import run_batch
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
                                               ("switch_cost", args.switch_cost), ("optimize", args.optimize))
                  if value is not None}
    tasks = make_tasks(args.scene, seeds, overrides=overrides)
    out = Path(args.out) if args.out else Path("logs") / f"batch-{time.strftime('%Y%m%d-%H%M%S')}"
    with executor(args.engine or "local", args.jobs, args.address) as engine:
        records = run_batch(tasks, out, engine, resume=args.resume)
    failed = sum(r["status"] == "failed" for r in records)
    print(summary(records))
    print(f"{len(records)} tasks, {failed} failed -> {out}/results.jsonl", file=sys.stdout)
    return 2 if failed else 0
