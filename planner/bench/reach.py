"""Benchmark: a batch of reachability queries against one query per goal.

``python -m planner.bench.reach scenes/unreachable/sealed.yaml --goals 100 --time-limit 2``
samples goals uniformly over the scene's workspace (positions) and headings (a fixed random seed),
answers them with one :func:`planner.reachability` call, then with one call per goal (the
certificates and a :func:`planner.plan`, as ``plan`` on the command line does), and prints the
answers of each, their wall times and the ratio batch / separate (issue 9's goal: below 0.25). The
stable regions are computed (or read from the cache) before either is timed.
"""

from __future__ import annotations

import argparse
import sys
import time
from collections import Counter

import numpy as np

from ..actions.controls import edge_controls
from ..queries.session import reachability
from ..model.scene import load_scene

__all__ = ["main", "sample_goals"]


def sample_goals(workspace: tuple[float, float, float, float], n: int, seed: int = 0) -> np.ndarray:
    """``n`` goals ``(x, y, theta)``, uniform over the workspace and the headings.

    >>> sample_goals((0.0, 0.0, 1.0, 2.0), 3).shape
    (3, 3)
    """
    rng = np.random.default_rng(seed)
    xmin, ymin, xmax, ymax = workspace
    return np.c_[rng.uniform(xmin, xmax, n), rng.uniform(ymin, ymax, n), rng.uniform(-np.pi, np.pi, n)]


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m planner.bench.reach", description=__doc__.splitlines()[0])
    p.add_argument("scene", help="scene file (YAML)")
    p.add_argument("--goals", type=int, default=100, metavar="N", help="goals to sample (default: %(default)s)")
    p.add_argument("--time-limit", type=float, default=2.0, metavar="S",
                   help="time limit of the batch's search and of each separate plan (default: %(default)s)")
    p.add_argument("--seed", type=int, default=1, help="planner seed (default: %(default)s)")
    args = p.parse_args(argv)
    scene = load_scene(args.scene)
    edge_controls(scene)  # the regions, cached before anything is timed
    goals = sample_goals(scene.workspace, args.goals)
    clock = time.perf_counter()
    batch = reachability(scene, goals, time_limit=args.time_limit, seed=args.seed)
    t_batch = time.perf_counter() - clock
    clock = time.perf_counter()
    separate = [reachability(scene, [g], time_limit=args.time_limit, seed=args.seed)[0] for g in goals]
    t_separate = time.perf_counter() - clock
    for name, answers, seconds in (("batch", batch, t_batch), ("separate", separate, t_separate)):
        counts = Counter(a.status for a in answers)
        print(f"{name:<9} {seconds:8.2f} s   " + ", ".join(f"{counts[s]} {s}" for s in
                                                        ("reachable", "unreachable", "unknown")))
    # Search answers may differ (a time limit, two different trees); certificates may not.
    disagree = sum(a.status != b.status for a, b in zip(batch, separate))
    print(f"ratio batch/separate {t_batch / t_separate:.3f} (goal < 0.25); {disagree} goals answered differently")
    return 0


if __name__ == "__main__":
    sys.exit(main())
