"""Benchmark: re-planning from perturbed starts, a :class:`~planner.Planner` session against the
one-shot :func:`planner.plan`.

``python -m planner.bench.replan scenes/parking.yaml --starts 10`` plans the scene once in a
session, then for each of ``--starts`` starts drawn up to ``--offset`` metres and ``--turn``
degrees off the scene's (a fixed random seed) plans from it both ways, interleaved in one run, and
prints each pair's latency and cost, then the medians and their ratio (issue 27's goal: at most
0.35). The stable regions are cached before anything is timed.
"""

from __future__ import annotations

import argparse
import math
import sys
import time

import numpy as np

from ..actions.controls import edge_controls
from ..model.scene_file import load_scene
from ..queries.session import Planner, plan

__all__ = ["main", "perturbed_starts"]


def perturbed_starts(start: np.ndarray, n: int, offset: float, turn: float, seed: int = 0) -> np.ndarray:
    """``n`` poses within ``offset`` metres (a disk) and ``turn`` radians of ``start``.

    >>> starts = perturbed_starts(np.zeros(3), 50, 0.01, 0.1)
    >>> bool(np.all(np.hypot(starts[:, 0], starts[:, 1]) <= 0.01)), bool(np.all(np.abs(starts[:, 2]) <= 0.1))
    (True, True)
    """
    rng = np.random.default_rng(seed)
    radius, angle = offset * np.sqrt(rng.uniform(0, 1, n)), rng.uniform(-math.pi, math.pi, n)
    return start + np.c_[radius * np.cos(angle), radius * np.sin(angle), rng.uniform(-turn, turn, n)]


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m planner.bench.replan", description=__doc__.splitlines()[0])
    p.add_argument("scene", help="scene file (YAML)")
    p.add_argument("--starts", type=int, default=10, metavar="N", help="perturbed starts (default: %(default)s)")
    p.add_argument("--offset", type=float, default=0.01, metavar="M", help="most position offset (default: %(default)s)")
    p.add_argument("--turn", type=float, default=5.0, metavar="DEG", help="most heading offset (default: %(default)s)")
    p.add_argument("--seed", type=int, default=1, help="planner seed (default: %(default)s)")
    args = p.parse_args(argv)
    scene = load_scene(args.scene)
    edge_controls(scene)  # the regions, cached before anything is timed
    session = Planner(scene, {"seed": args.seed})
    first = session.plan()
    print(f"first plan: {first.headline()} in {first.planning_time_s * 1000:.0f} ms")
    print(f"{'start':>5} {'one-shot ms':>12} {'cost m':>7} {'session ms':>11} {'cost m':>7}  session plan")
    alone, again = [], []
    for k, start in enumerate(perturbed_starts(scene.start, args.starts, args.offset, math.radians(args.turn))):
        clock = time.perf_counter()
        a = plan(scene.with_part(start=start), seed=args.seed)
        alone.append(time.perf_counter() - clock)
        clock = time.perf_counter()
        b = session.plan(start=start)
        again.append(time.perf_counter() - clock)
        costs = [f"{x.cost:7.3f}" if x.solved else f"{'-':>7}" for x in (a, b)]
        print(f"{k + 1:>5} {alone[-1] * 1000:12.1f} {costs[0]} {again[-1] * 1000:11.1f} {costs[1]}  {b.contents()}")
    ratio = float(np.median(again) / np.median(alone))
    print(f"median: one-shot {np.median(alone) * 1000:.1f} ms, session {np.median(again) * 1000:.1f} ms, "
          f"ratio {ratio:.3f} (goal <= 0.35)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
