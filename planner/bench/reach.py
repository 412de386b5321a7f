"""Benchmark: a grid of reachability goals answered by one :class:`~planner.Planner` session,
against one query per goal.

``python -m planner.bench.reach scenes/parking.yaml --grid 10`` lays ``grid x grid`` positions 5 cm
inside the workspace at headings 0 and 90 degrees (200 goals for 10), answers them with
``Planner(scene).reachability(goals)`` at its default settings and prints, per scene, the wall
time per goal (the session's set-up included; the stable regions are cached before anything is
timed), how it splits (set-up, certificates, direct connections, the tree's growth) and the
answers by status. Then ``--separate N`` of the goals (every k-th) are asked one at a time as a
user without a session would: ``planner.reachability(scene, [goal])`` each, with the scene's
time limit (or ``--separate-limit S``), and their time per goal is printed beside it.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from collections import Counter

import numpy as np

from ..actions.controls import edge_controls
from ..model.scene import Scene
from ..model.scene_file import load_scene
from ..queries.session import Planner, reachability

__all__ = ["grid_goals", "main", "sample_goals"]

_STATUSES = ("reachable", "unreachable", "unknown")


def sample_goals(workspace: tuple[float, float, float, float], n: int, seed: int = 0) -> np.ndarray:
    """``n`` goals ``(x, y, theta)``, uniform over the workspace and the headings.

    >>> sample_goals((0.0, 0.0, 1.0, 2.0), 3).shape
    (3, 3)
    """
    rng = np.random.default_rng(seed)
    xmin, ymin, xmax, ymax = workspace
    return np.c_[rng.uniform(xmin, xmax, n), rng.uniform(ymin, ymax, n), rng.uniform(-np.pi, np.pi, n)]


def grid_goals(workspace: tuple[float, float, float, float], n: int, inset: float = 0.05) -> np.ndarray:
    """``n`` x ``n`` positions ``inset`` inside the workspace, each at headings 0 and 90 degrees
    (heading first, then rows of x).

    >>> grid_goals((0.0, 0.0, 1.0, 1.0), 2).tolist()[:3]
    [[0.05, 0.05, 0.0], [0.95, 0.05, 0.0], [0.05, 0.95, 0.0]]
    """
    xmin, ymin, xmax, ymax = workspace
    xs, ys = np.linspace(xmin + inset, xmax - inset, n), np.linspace(ymin + inset, ymax - inset, n)
    return np.array([(x, y, t) for t in (0.0, math.pi / 2) for y in ys for x in xs])


def _counts(answers) -> str:
    counts = Counter(a.status for a in answers)
    return " ".join(f"{counts[s]:>4}" for s in _STATUSES)


def bench(scene: Scene, n: int, separate: int, separate_limit: float | None, seed: int) -> list[str]:
    """The table rows of one scene."""
    edge_controls(scene)  # the regions, cached before anything is timed
    goals = grid_goals(scene.workspace, n)
    clock = time.perf_counter()
    session = Planner(scene)
    answers = session.reachability(goals, seed=seed)
    wall = time.perf_counter() - clock
    t = session.timings
    rows = [f"{scene.name:<16} session  {len(goals):>5} {1000 * wall / len(goals):8.1f} "
            f"{1000 * session.setup_s:8.0f} {1000 * t['certificates']:8.0f} {1000 * t['connections']:8.0f} "
            f"{1000 * t['growth']:8.0f}  {_counts(answers)}"]
    if separate:
        picked = goals[:: max(1, len(goals) // separate)][:separate]
        clock = time.perf_counter()
        alone = [reachability(scene, [g], time_limit=separate_limit, seed=seed)[0] for g in picked]
        wall = time.perf_counter() - clock
        rows.append(f"{scene.name:<16} per goal {len(picked):>5} {1000 * wall / len(picked):8.1f} "
                    f"{'':>8} {'':>8} {'':>8} {'':>8}  {_counts(alone)}")
    return rows


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m planner.bench.reach", description=__doc__.splitlines()[0])
    p.add_argument("scenes", nargs="+", help="scene files (YAML)")
    p.add_argument("--grid", type=int, default=10, metavar="N", help="N x N positions, 2 headings (default: %(default)s)")
    p.add_argument("--separate", type=int, default=10, metavar="N",
                   help="goals also asked one at a time, without a session (default: %(default)s; 0: none)")
    p.add_argument("--separate-limit", type=float, metavar="S",
                   help="time limit of each goal asked alone (default: the scene's)")
    p.add_argument("--seed", type=int, default=1, help="planner seed (default: %(default)s)")
    args = p.parse_args(argv)
    print(f"{'scene':<16} {'how':<8} {'goals':>5} {'ms/goal':>8} {'setup':>8} {'certs':>8} {'direct':>8} "
          f"{'growth':>8}  {'reach':>4} {'unre':>4} {'unkn':>4}   (set-up and phases in ms)")
    for path in args.scenes:
        for row in bench(load_scene(path), args.grid, args.separate, args.separate_limit, args.seed):
            print(row, flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
