"""Benchmark: ``python -m planner.bench.planners scenes/*.yaml --runs 20``.

Plans every scene with every planner for seeds ``1..runs`` and prints, per scene and planner, the
success rate, the median and 90th-percentile planning time, and the median cost (length plus the
switch cost per switch), path length (of the centre of friction), number of pushes and number of
switches (edge changes) of the solved runs.
``--transit`` overrides every scene's ``pusher.transit`` (``none``: one edge per plan). Runs go to worker processes, one per
core, each building its own OMPL objects (they cannot be pickled; docs/stack.md, "Worker processes"), on planner.batch's
executors (``--engine local`` or ``ray``): a run whose worker is killed is run again. ``--ompl-log FILE``
also writes the runs in OMPL's benchmark log format (planner.bench.ompl_log), one log per scene, for
``ompl_benchmark_statistics.py`` and Planner Arena.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time
from pathlib import Path

import numpy as np

from .ompl_log import Run, log_paths, write_ompl_log
from ..model.options import PLANNERS, TRANSITS
from ..model.scene_file import load_scene
from ..batch.engines import ENGINES, map_ordered
from ..queries.session import plan

__all__ = ["main"]


def _run(job: tuple[str, str, int, float, str | None],
         shared: None = None) -> tuple[str, str, bool, float, float, int, int, float]:
    path, name, seed, limit, transit = job
    scene = load_scene(path)
    result = plan(scene, seed=seed, time_limit=limit, planner=name, transit=transit)
    return (path, name, result.solved, result.planning_time_s, result.path_length(scene.slider.cf), result.pushes,
            result.switches, result.cost if result.solved else float("inf"))


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(
        prog="python -m planner.bench.planners",
        description="Plan every scene with every planner for seeds 1..N and print one row per scene and planner.",
        epilog="Columns: success rate; median and 90th-percentile planning time (unsolved runs count with the time "
               "they used); median path length of the centre of friction, pushes and switches of the solved runs.")
    p.add_argument("scenes", nargs="+", metavar="SCENE", help="scene files (YAML) to plan")
    p.add_argument("--runs", type=int, default=20, metavar="N",
                   help="plan each scene with each planner for seeds 1..N (default: %(default)s)")
    p.add_argument("--planners", nargs="+", choices=PLANNERS, default=list(PLANNERS), metavar="NAME",
                   help=f"OMPL planners to compare, of {', '.join(PLANNERS)} (default: all)")
    p.add_argument("--time-limit", type=float, default=10.0, metavar="S",
                   help="planning time limit of each run in seconds (default: %(default)g)")
    p.add_argument("--transit", choices=TRANSITS,
                   help="override every scene's pusher.transit (none: one edge per plan; default: each scene's)")
    p.add_argument("--workers", type=int, default=os.cpu_count() or 1, metavar="K",
                   help="runs in parallel, one process each (default: the number of cores, %(default)s)")
    p.add_argument("--engine", choices=ENGINES, default="local",
                   help="run on this machine's processes or on Ray (planner.batch; default: %(default)s)")
    p.add_argument("--address", metavar="ADDR", help="with --engine ray: an existing cluster's")
    p.add_argument("--quality", action="store_true",
                   help="instead, path quality with the default planner: lengths against a lower bound and the "
                        "Dubins length, on obstacle-free tasks for each scene's part and on the scenes "
                        "(python -m planner.bench.quality)")
    p.add_argument("--ompl-log", metavar="FILE",
                   help="also write the runs in OMPL's benchmark log format, for ompl_benchmark_statistics.py and "
                        "Planner Arena: one log (experiment) per scene, FILE itself for one scene, else FILE with "
                        "-<scene name> before its suffix (out.log: out-parking.log, ...)")
    args = p.parse_args(argv)
    if args.ompl_log and args.quality:
        p.error("--ompl-log logs the planner comparison, not --quality")
    if args.ompl_log:
        names = [load_scene(s).name for s in args.scenes]
        try:
            logs = log_paths(args.ompl_log, names)
        except ValueError as e:
            p.error(str(e))
        if not logs[0].parent.is_dir():  # before the runs, not after them
            p.error(f"--ompl-log: no folder {logs[0].parent}")
    if args.quality:
        from . import quality

        return quality.main([*args.scenes, "--runs", str(args.runs), "--time-limit", str(args.time_limit),
                             "--workers", str(args.workers)])
    jobs = [(s, name, seed, args.time_limit, args.transit) for s in args.scenes for name in args.planners
            for seed in range(1, args.runs + 1)]
    clock = time.perf_counter()
    results = map_ordered(_run, jobs, args.workers, args.engine, args.address)  # a killed worker's run is retried
    wall = time.perf_counter() - clock
    print(f"{'scene':<22}{'planner':<8}{'success':>8}{'t_med[s]':>10}{'t_p90[s]':>10}{'cost_med[m]':>12}"
          f"{'len_med[m]':>11}{'pushes':>8}{'switches':>9}")
    for s in args.scenes:
        for name in args.planners:
            rows = [r for r in results if r[0] == s and r[1] == name]
            solved = [r for r in rows if r[2]]
            times = [r[3] for r in rows]  # unsolved runs count with the time they used
            cost, length = (f"{statistics.median(r[i] for r in solved):.3f}" if solved else "-" for i in (7, 4))
            pushes, switches = (f"{statistics.median(r[i] for r in solved):g}" if solved else "-" for i in (5, 6))
            print(f"{os.path.basename(s):<22}{name:<8}{len(solved) / len(rows):>8.0%}"
                  f"{statistics.median(times):>10.3f}{float(np.percentile(times, 90)):>10.3f}{cost:>12}{length:>11}{pushes:>8}"
                  f"{switches:>9}")
    if args.ompl_log:
        _write_ompl_logs(args, names, logs, jobs, results, wall, argv)
    return 0


def _write_ompl_logs(args: argparse.Namespace, names: list[str], logs: list[Path], jobs: list, results: list,
                     wall: float, argv: list[str] | None) -> None:
    """One OMPL benchmark log per scene (planner.bench.ompl_log); the runs of each planner in seed order."""
    command = " ".join(["python -m planner.bench.planners", *(sys.argv[1:] if argv is None else argv)])
    for s, name, log in zip(args.scenes, names, logs):
        by_planner = {planner: [Run(job[2], *r[2:7]) for job, r in zip(jobs, results) if r[0] == s and r[1] == planner]
                      for planner in args.planners}
        setup = (f"stablepush benchmark: {command}\nscene: {s}\ntransit: {args.transit or 'as the scene'}\n"
                 f"wall time of the whole benchmark: {wall:.3f} s\n" + Path(s).read_text())
        write_ompl_log(log, name, by_planner, args.time_limit, 1, runs_per_planner=args.runs, setup=setup)


if __name__ == "__main__":
    sys.exit(main())
