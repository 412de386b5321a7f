"""Path quality: how long plans are against a sound lower bound and the Dubins length.

``python -m planner.bench.quality scenes/*.yaml --runs 10`` plans, for every scene's part, four
obstacle-free tasks (the centre of friction 1 m ahead turned 90 degrees, 0.5 m to the side, 0.5 m
behind turned round, 0.3 m behind) and the scene itself, for seeds ``1..runs``, and prints per
task the median length of the centre of friction's path, the lower bound, the Dubins length at
the tightest car of the part's edges (:mod:`planner.actions.car`) and their ratios, and the
median cost (length plus the switch cost per switch); a scene's row also divides it by the cost
of the scene's best-known plan (:mod:`planner.bench.optimality`, which also compares a time
budget's plans with the default's).

Lower bound (:func:`planner.queries.geodesic.geodesic_bound`): the length of the shortest path the centre
of friction can take at all. The disk of radius ``rho`` about the CF (``rho`` its distance to the
part's boundary) lies inside the part, which never overlaps an obstacle nor leaves the workspace,
so the CF stays in the workspace shrunk by ``rho`` outside the obstacles grown by ``rho``; the
shortest path there (a visibility graph of that region's vertices), less how far the goal
tolerance lets the CF end from its goal position, is at most the CF's path length of any plan
whatever (any pushes, switches, crabbing). It is sound: the grown obstacles' round corners are
polygons inside the true circles, which only enlarges the region and shortens its paths. On an
empty table it is the straight line less that slack; it is weak for tasks that must turn. The
Dubins length is the shortest path of the best edge's car: a bound for plans that stay on one
edge's car, not for plans that crab or switch.
"""

from __future__ import annotations

import argparse
import math
import os
import statistics
import sys
from dataclasses import replace
from pathlib import Path


from ..actions.car import edge_car
from ..actions.dubins import DubinsCurves
from ..queries.geodesic import geodesic_bound
from ..actions.controls import edge_controls
from ..model.bodies import cf_poses
from ..model.scene import Scene
from ..model.scene_file import load_scene
from ..batch.engines import map_ordered
from ..queries.session import plan
from .optimality import best_known

__all__ = ["TASKS", "dubins_length", "open_task", "main"]

#: Obstacle-free tasks: where the CF goes (metres, in the part's start frame) and the turn (degrees).
TASKS = {"ahead+90": ((1.0, 0.0), 90.0), "side": ((0.0, 0.5), 0.0), "behind+180": ((-0.5, 0.0), 180.0),
         "behind": ((-0.3, 0.0), 0.0)}


def open_task(scene: Scene, task: str) -> Scene:
    """``scene``'s part and pusher on an empty 4 x 4 m table, its CF at the origin, heading 0."""
    target, turn = TASKS[task]
    moved = scene.with_part(start=cf_poses(scene.slider.cf, [0.0, 0.0], [0.0])[0],
                            goal=cf_poses(scene.slider.cf, target, [math.radians(turn)])[0])
    return replace(moved, name=f"{scene.name}:{task}", obstacles=(), workspace=(-2.0, -2.0, 2.0, 2.0), path=None)


def dubins_length(scene: Scene) -> float:
    """The shortest Dubins path from start to goal among the allowed edges' cars (obstacles ignored)."""
    cf = scene.slider.cf
    cars = (edge_car(push, cf) for push in edge_controls(scene))
    return min((DubinsCurves(scene, car).between(scene.start, scene.goal) for car in cars if car is not None),
               default=math.inf)


def _run(job: tuple[str, str, int, float],
         shared: None = None) -> tuple[str, str, bool, float, int, int, float, float, float, float]:
    path, task, seed, limit = job
    scene = load_scene(path)
    if task != "scene":
        scene = open_task(scene, task)
    result = plan(scene, seed=seed, time_limit=limit)
    return (path, task, result.solved, result.path_length(scene.slider.cf), result.pushes, result.switches,
            result.planning_time_s, geodesic_bound(scene), dubins_length(scene),
            result.cost if result.solved else math.inf)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m planner.bench.quality", description=__doc__.splitlines()[0])
    p.add_argument("scenes", nargs="+", help="scene files; their parts also get the obstacle-free tasks")
    p.add_argument("--runs", type=int, default=10, help="seeds 1..RUNS per task")
    p.add_argument("--time-limit", type=float, default=10.0, metavar="S")
    p.add_argument("--workers", type=int, default=os.cpu_count() or 1)
    p.add_argument("--best", type=Path, default=Path("scenes/best"), metavar="DIR",
                   help="folder of the best-known plans, whose costs the scenes' rows are divided by "
                        "(planner.bench.optimality; default: %(default)s)")
    args = p.parse_args(argv)
    tasks = [*TASKS, "scene"]
    jobs = [(s, t, seed, args.time_limit) for s in args.scenes for t in tasks for seed in range(1, args.runs + 1)]
    results = map_ordered(_run, jobs, args.workers)  # planner.batch: a killed worker's run is retried
    print(f"{'scene':<16}{'task':<12}{'solved':>7}{'len_med':>9}{'lower':>8}{'dubins':>8}{'len/low':>8}"
          f"{'len/dub':>8}{'pushes':>7}{'switch':>7}{'t_med':>7}{'cost_med':>9}{'best':>7}{'c/best':>7}")
    for s in args.scenes:
        record = best_known(args.best, load_scene(s))
        for t in tasks:
            rows = [r for r in results if r[0] == s and r[1] == t]
            ok = [r for r in rows if r[2]]
            low, dub = rows[0][7], rows[0][8]
            med = statistics.median(r[3] for r in ok) if ok else math.nan
            cost = statistics.median(r[9] for r in rows)
            best = record.cost if record is not None and t == "scene" else math.nan
            print(f"{os.path.basename(s)[:-5]:<16}{t:<12}{len(ok):>4}/{len(rows):<2}{med:>9.3f}{low:>8.3f}{dub:>8.3f}"
                  f"{med / low if low else math.nan:>8.2f}{med / dub:>8.2f}"
                  f"{statistics.median(r[4] for r in ok) if ok else math.nan:>7g}"
                  f"{statistics.median(r[5] for r in ok) if ok else math.nan:>7g}"
                  f"{statistics.median(r[6] for r in rows):>7.2f}{cost:>9.3f}{best:>7.3f}{cost / best:>7.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
