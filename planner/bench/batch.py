"""Benchmark: a batch of plan tasks on each engine (planner.batch).

``python -m planner.bench.batch --seeds 50`` plans corridor, nonconvex, cluttered and battery for
seeds 1..50 (200 tasks) with 1 and 2 local workers, on a Ray cluster of 2 CPUs started for the
run (``ray.init``), and on a two-node Ray cluster on 127.0.0.1 (``ray start --head --num-cpus 1``
and a second ``ray start --address ... --num-cpus 1``), and prints for each: the start-up time (of
Ray), the batch's wall time, the tasks' own seconds (summed over workers), the scaling efficiency
against one local worker (``T1 / (k T_k)``, k workers), the most the machine allowed (``S1 / S_k``,
S the tasks' own seconds: where k tasks at once each run slower, on shared or busy cores, no
executor scales better) and the per-task overhead (``(k T_k - S_k) / tasks``: dispatch, results
written, workers started, the idle tail). It also checks that every engine gave the same results,
times the stable regions computed once in the driver on a cold cache (the workers then compute
none), and the round trip of an empty call on each engine (its workers started). The Ray rows need
the ``ray`` extra; they are skipped without it.

``python -m planner.bench.batch --tasks 100000 --dry`` plans nothing: for a hundredth, a tenth and
all of that many tasks (one scene, a seed range) it times the batch's own bookkeeping, each of
which must grow linearly with the tasks: making every task and its id, reading a results file of a
line per task back for ``--resume`` and finding which it answers (a plan file each, as a run
leaves them), and the records and summary table at the end.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
import time
from pathlib import Path

from ..batch import LocalExecutor, make_tasks, run_batch
from ..batch.results import COLUMNS, ResultsFile, summary
from ..batch.run import batch_records, reusable
from ..batch.tasks import shared_regions

__all__ = ["main"]

SCENES = ("corridor", "nonconvex", "cluttered", "battery")
#: What may differ between two runs of the same task.
_VARYING = {"planning_time_s", "task_s", "host", "attempts"}


def _same(a: list[dict], b: list[dict]) -> bool:
    return [{k: v for k, v in r.items() if k not in _VARYING} for r in a] == \
           [{k: v for k, v in r.items() if k not in _VARYING} for r in b]


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m planner.bench.batch", description=__doc__.splitlines()[0])
    p.add_argument("--seeds", type=int, default=50, help="seeds per scene (default: %(default)s; 4 scenes)")
    p.add_argument("--time-limit", type=float, default=5.0, metavar="S")
    p.add_argument("--no-ray", action="store_true", help="local workers only")
    p.add_argument("--dry", action="store_true", help="plan nothing: time the bookkeeping of --tasks tasks")
    p.add_argument("--tasks", type=int, default=100_000, help="with --dry: the most tasks (default: %(default)s)")
    args = p.parse_args(argv)
    if args.dry:
        return _dry(args.tasks)
    # Another program busy on the machine slows the workers, not the one worker alone: say so.
    print(f"{os.cpu_count()} cores, load average {os.getloadavg()[0]:.2f} before the runs")
    root = Path(__file__).resolve().parents[2] / "scenes"
    tasks = make_tasks([root / f"{s}.yaml" for s in SCENES], range(1, args.seeds + 1),
                       overrides={"time_limit": args.time_limit})
    with tempfile.TemporaryDirectory() as cache:
        os.environ["STABLEPUSH_CACHE"] = cache  # cold, for this process and the workers it starts
        clock = time.perf_counter()
        regions = shared_regions(tasks)
        print(f"stable regions: {len(regions)} computed once, in the driver, in {time.perf_counter() - clock:.2f} s "
              f"(cold cache)")
        rows = [_row("local, 1 worker", lambda: LocalExecutor(1), tasks, 1)]
        rows.append(_row("local, 2 workers", lambda: LocalExecutor(2), tasks, 2))
        if not args.no_ray:
            from ..batch.ray_cluster import ENVIRONMENT, LocalRayCluster
            from ..batch.ray_engine import RayExecutor, needs_ray

            os.environ.update(ENVIRONMENT)
            needs_ray()
            rows.append(_row("ray, 2 CPUs (ray.init)", lambda: RayExecutor(2), tasks, 2))
            with LocalRayCluster((1, 1)) as cluster:
                rows.append(_row("ray, 2 nodes x 1 CPU", lambda: RayExecutor(address=cluster.address), tasks, 2))
    one = rows[0][2]
    print(f"{len(tasks)} tasks ({', '.join(SCENES)} x seeds 1..{args.seeds}, time limit {args.time_limit:g} s), "
          f"{sum(r['status'] == 'solved' for r in rows[0][4])} solved")
    print(f"{'engine':<26}{'workers':>8}{'start[s]':>10}{'wall[s]':>9}{'tasks[s]':>10}{'efficiency':>11}"
          f"{'machine':>9}{'overhead[ms/task]':>19}{'empty call[ms]':>16}{'same results':>14}")
    alone = sum(r["task_s"] for r in rows[0][4])
    for name, workers, wall, start, records, call in rows:
        busy = sum(r["task_s"] or 0.0 for r in records)
        print(f"{name:<26}{workers:>8}{start:>10.2f}{wall:>9.2f}{busy:>10.2f}{one / (workers * wall):>11.0%}"
              f"{alone / busy:>9.0%}{1000 * (workers * wall - busy) / len(records):>19.1f}{1000 * call:>16.2f}"
              f"{'yes' if _same(records, rows[0][4]) else 'NO':>14}")
    return 0


def _dry(most: int) -> int:
    """Time the bookkeeping of a batch of ``most // 100``, ``most // 10`` and ``most`` tasks (module docstring)."""
    scene = Path(__file__).resolve().parents[2] / "scenes" / "battery.yaml"
    print(f"{'tasks':>8}{'make[s]':>9}{'resume[s]':>11}{'summary[s]':>12}{'make[us/task]':>15}{'resume[us/task]':>17}"
          f"{'summary[us/task]':>18}")
    for n in (most // 100, most // 10, most):
        tasks = make_tasks([scene], range(1, n + 1))
        clock = time.perf_counter()
        ids = [t.id for t in tasks]
        make = time.perf_counter() - clock
        with tempfile.TemporaryDirectory() as out:
            folder = Path(out)
            with open(folder / "results.jsonl", "w") as f:  # as a run leaves it: a line and a plan file a task
                for task in tasks:
                    record = dict.fromkeys(COLUMNS) | task.record() | {
                        "status": "solved", "cost": 1.0, "length": 1.0, "pushes": 1, "switches": 0,
                        "planning_time_s": 0.1, "task_s": 0.2, "regions_computed": 0, "host": "h", "attempts": 1,
                        "plan": f"{task.id}.json"}
                    f.write(json.dumps(record) + "\n")
                    (folder / record["plan"]).touch()
            clock = time.perf_counter()
            done, bad = ResultsFile(folder / "results.jsonl").read()
            reused = reusable(tasks.find, done, folder)
            resume = time.perf_counter() - clock
            assert len(reused) == n and not bad
            clock = time.perf_counter()
            table = summary(batch_records(tasks.find, done))
            end = time.perf_counter() - clock
            assert f"{n:>7}" in table and len(ids) == n
        print(f"{n:>8}{make:>9.3f}{resume:>11.3f}{end:>12.3f}{1e6 * make / n:>15.1f}{1e6 * resume / n:>17.1f}"
              f"{1e6 * end / n:>18.1f}")
    return 0


def _empty(item: int, shared: None) -> int:
    return item


#: Empty calls timed per engine; the first (workers starting) is not counted.
_CALLS = 500


def _row(name: str, make, tasks, workers: int) -> tuple[str, int, float, float, list[dict], float]:
    """Run ``tasks`` on the executor ``make()`` gives: (name, workers, wall time, start-up time,
    records, seconds per empty call)."""
    clock = time.perf_counter()
    with make() as executor, tempfile.TemporaryDirectory() as out:
        start = time.perf_counter() - clock
        clock = time.perf_counter()
        records = run_batch(tasks, out, executor, stream=open(os.devnull, "w"))
        wall = time.perf_counter() - clock
        calls = executor.run(_empty, range(_CALLS + 1))
        next(calls)
        clock = time.perf_counter()
        for _ in calls:
            pass
        call = (time.perf_counter() - clock) / _CALLS
    print(f"  {name}: {wall:.2f} s (load average after: {os.getloadavg()[0]:.2f})", file=sys.stderr, flush=True)
    return name, workers, wall, start, records, call


if __name__ == "__main__":
    sys.exit(main())
