"""Benchmark: the cost of running whole plans open-loop in MuJoCo (``plan --simulate``).

``python -m planner.bench.simulate scenes/*.yaml --runs 2`` plans each scene with seed 1 and
simulates the plan on ``--runs`` support distributions
(:func:`planner.execution.mujoco_sim.simulate`), printing per scene the plan's execution time,
the wall time of each run and the ratio simulated / wall time (how much faster than real time),
with each run's verdict. Needs the mujoco extra.
"""

from __future__ import annotations

import argparse
import sys

from ..execution.mujoco_sim import simulate
from ..model.scene import load_scene
from ..search import plan

__all__ = ["main"]


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m planner.bench.simulate", description=__doc__.splitlines()[0])
    p.add_argument("scenes", nargs="+", help="scene files (YAML)")
    p.add_argument("--runs", type=int, default=2, help="support distributions per scene (default 2)")
    args = p.parse_args(argv)
    for path in args.scenes:
        scene = load_scene(path)
        result = plan(scene, seed=1)
        if not result.solved:
            print(f"{scene.name}: not solved ({result.reason})")
            continue
        runs = simulate(scene, result, args.runs, seed=1).runs
        walls = ", ".join(f"{r.seconds:.2f}" for r in runs)
        ratio = sum(r.simulated for r in runs) / sum(r.seconds for r in runs)
        verdicts = ", ".join("ok" if r.passed else "FAILED" for r in runs)
        print(f"{scene.name}: {result.contents()}, {runs[0].simulated:.1f} s simulated; wall per run {walls} s; "
              f"{ratio:.1f}x real time; {verdicts}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
