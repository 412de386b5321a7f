"""How far plans are from the best known, with and without a time budget; the best-known plans kept.

``python -m planner.bench.optimality scenes/*.yaml --seeds 10 --budget 10`` plans every scene
for seeds ``1..seeds`` twice: with the default settings (answer fast) and with ``--time-limit
BUDGET --optimize 100`` (improvement rounds until the time limit). It prints per scene the
best-known cost, the geodesic lower bound (:func:`planner.queries.geodesic.geodesic_bound`; sound
for any plan, weak where the part must turn), and for each setting the median cost (length plus
``switch_cost`` per switch, as the planner counts it), its ratio to the best known and to the
bound, the median length and switches, and the median time to the first plan.

The best-known plans are plan files, one per scene, in a folder (``--best``, default
``scenes/best``): the cheapest plan ever found for the scene by any method. With ``--record``,
every plan that beats its scene's is written there (atomically), so the reference only gets
better; tests/planner/queries/test_best_known.py replays and verifies every one of them.
"""

from __future__ import annotations

import argparse
import statistics
import sys
from pathlib import Path

from ..batch.engines import map_ordered
from ..model.files import write_atomic
from ..model.plan import Plan
from ..model.plan_file import load_plan
from ..model.scene import Scene
from ..model.scene_file import load_scene
from ..queries.geodesic import geodesic_bound
from ..queries.session import plan

__all__ = ["BUDGET_ROUNDS", "best_known", "main"]

#: Improvement rounds of a budgeted run: more than fit in any budget here, so the time limit ends them.
BUDGET_ROUNDS = 100


def best_known(folder: Path, scene: Scene) -> Plan | None:
    """The best-known plan of ``scene`` kept in ``folder`` (``<name>.json``), or None."""
    path = folder / f"{scene.name}.json"
    return load_plan(path) if path.exists() else None


def _run(job: tuple[str, int, float | None], shared: None = None) -> Plan:
    path, seed, budget = job
    scene = load_scene(path)
    if budget is None:
        return plan(scene, seed=seed)
    return plan(scene, seed=seed, time_limit=budget, optimize=BUDGET_ROUNDS)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m planner.bench.optimality", description=__doc__.splitlines()[0])
    p.add_argument("scenes", nargs="+", help="scene files (YAML)")
    p.add_argument("--seeds", type=int, default=10, help="seeds 1..SEEDS per scene and setting (default: %(default)s)")
    p.add_argument("--budget", type=float, default=10.0, metavar="S",
                   help="time limit of the budgeted runs, seconds (default: %(default)g)")
    p.add_argument("--best", type=Path, default=Path("scenes/best"), metavar="DIR",
                   help="folder of the best-known plans (default: %(default)s)")
    p.add_argument("--record", action="store_true", help="write every plan cheaper than its scene's best known to --best")
    p.add_argument("--workers", type=int, default=None, metavar="K", help="runs at once (default: one per core)")
    args = p.parse_args(argv)
    scenes = [load_scene(s) for s in args.scenes]
    jobs = [(s, seed, budget) for s in args.scenes for budget in (None, args.budget) for seed in range(1, args.seeds + 1)]
    plans = dict(zip(jobs, map_ordered(_run, jobs, args.workers)))
    print(f"{'scene':<16}{'best':>7}{'bound':>7} | {'default: cost':>13}{'/best':>6}{'/bound':>7}{'length':>7}"
          f"{'sw':>4}{'t_first':>8} | {f'{args.budget:g} s: cost':>13}{'/best':>6}{'/bound':>7}{'length':>7}{'sw':>4}")
    for path, scene in zip(args.scenes, scenes):
        record = best_known(args.best, scene)
        runs = [[plans[(path, seed, budget)] for seed in range(1, args.seeds + 1)] for budget in (None, args.budget)]
        solved = [r for rs in runs for r in rs if r.solved]
        cheapest = min(solved, key=lambda r: r.cost, default=None)
        if args.record and cheapest is not None and (record is None or cheapest.cost < record.cost - 1e-9):
            args.best.mkdir(parents=True, exist_ok=True)
            write_atomic(args.best / f"{scene.name}.json", cheapest.to_json())
            record = cheapest
        best, bound = (record.cost if record else float("nan")), geodesic_bound(scene)
        row = f"{scene.name:<16}{best:>7.3f}{bound:>7.3f}"
        for k, rs in enumerate(runs):
            ok = [r for r in rs if r.solved] or rs
            cost = statistics.median(r.cost if r.solved else float("inf") for r in rs)
            row += (f" | {cost:>13.3f}{cost / best:>6.2f}{cost / bound:>7.2f}"
                    f"{statistics.median(r.length for r in ok):>7.3f}{statistics.median(r.switches for r in ok):>4g}")
            if k == 0:
                row += f"{statistics.median(r.improvements[0][0] if r.improvements else r.planning_time_s for r in rs):>8.2f}"
        print(row)
    return 0


if __name__ == "__main__":
    sys.exit(main())
