"""The search's step rate: how fast a tree grows when the search runs its whole time limit.

``python -m planner.bench.step_rate [SCENE] --time-limit 4 --seeds 1 2 3`` plans ``SCENE``
(default ``scenes/unreachable/sealed.yaml``, whose goal no plan reaches, so every search runs
its whole limit) with :func:`planner.plan`, which runs no certificate of unreachability, once
to warm the region cache and the imports, then once per seed, and prints per seed the tree's
edges (one per control propagated), the CPU seconds and their ratio. Only :func:`planner.plan`,
:func:`planner.load_scene` and :attr:`planner.Plan.tree` are used, so the same script times an
older checkout put first on ``PYTHONPATH``.
"""

from __future__ import annotations

import argparse
import statistics
import time

from planner import load_scene, plan


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m planner.bench.step_rate", description=__doc__.splitlines()[0])
    p.add_argument("scene", nargs="?", default="scenes/unreachable/sealed.yaml")
    p.add_argument("--time-limit", type=float, default=4.0)
    p.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3])
    args = p.parse_args(argv)
    scene = load_scene(args.scene)
    plan(scene, seed=args.seeds[0], time_limit=min(1.0, args.time_limit))
    rates = []
    print(f"{'seed':>4} {'solved':>6} {'tree edges':>10} {'CPU s':>6} {'edges / CPU s':>13}")
    for seed in args.seeds:
        cpu = time.process_time()
        result = plan(scene, seed=seed, time_limit=args.time_limit)
        cpu = time.process_time() - cpu
        edges = len(result.tree) if result.tree is not None else 0
        rates.append(edges / cpu)
        print(f"{seed:>4} {str(result.solved):>6} {edges:>10} {cpu:>6.2f} {rates[-1]:>13.0f}")
    print(f"median {statistics.median(rates):.0f} tree edges per CPU second ({args.scene}, limit {args.time_limit:g} s)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
