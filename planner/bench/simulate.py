"""Benchmark: whole plans run open-loop in MuJoCo (``plan --simulate``), and what they cost.

``python -m planner.bench.simulate scenes/*.yaml --runs 8`` plans each scene with seed 1 and
simulates the plan on ``--runs`` support distributions
(:func:`planner.execution.mujoco_sim.simulate`). It prints a Markdown table, one row per scene:
the plan, its execution time, the worst final error against the goal (position, angle) over the
runs, the worst path deviation and slip, the runs passed, the wall time per run and how much
faster than real time the runs went. Needs the mujoco extra.
"""

from __future__ import annotations

import argparse
import math
import sys

from ..execution.mujoco_sim import Simulation, simulate
from ..model.extras import have, needs
from ..model.plan import Plan
from ..model.scene import Scene
from ..model.scene_file import load_scene
from ..queries.session import plan

__all__ = ["HEADER", "main", "row"]

HEADER = ("| scene | plan | executed | goal error (worst) | path deviation | slip | passed | wall per run | "
          "real time |\n|---|---|---|---|---|---|---|---|---|")


def row(scene: Scene, result: Plan, simulation: Simulation | None, timing: bool = True) -> str:
    """The table's row of ``scene``'s plan ``result`` and its ``simulation`` (None if not solved);
    without ``timing``, the wall time columns are left out (the README's table: a wall time is
    the machine's, not the code's)."""
    if simulation is None:
        return f"| {scene.name} | not solved ({result.reason}) |" + " |" * (7 if timing else 5)
    runs = simulation.runs
    wall = sum(r.seconds for r in runs)
    cells = [scene.name, result.contents(), f"{runs[0].simulated:.1f} s",
             f"{max(r.goal_error[0] for r in runs) * 1e3:.3f} mm, {math.degrees(max(r.goal_error[1] for r in runs)):.4f} deg",
             f"{max(r.deviation for r in runs) * 1e3:.3f} mm", f"{max(r.slip for r in runs) * 1e3:.3f} mm",
             f"{sum(r.passed for r in runs)}/{len(runs)}"]
    if timing:
        cells += [f"{wall / len(runs):.2f} s", f"{sum(r.simulated for r in runs) / wall:.1f}x"]
    return "| " + " | ".join(cells) + " |"


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m planner.bench.simulate", description=__doc__.splitlines()[0])
    p.add_argument("scenes", nargs="+", help="scene files (YAML)")
    p.add_argument("--runs", type=int, default=2, help="support distributions per scene (default 2)")
    args = p.parse_args(argv)
    if not have("mujoco"):
        p.exit(1, f"{p.prog}: error: {needs('mujoco')}\n")
    print(HEADER, flush=True)
    for path in args.scenes:
        scene = load_scene(path)
        result = plan(scene, seed=1)
        simulation = simulate(scene, result, args.runs, seed=1) if result.solved else None
        print(row(scene, result, simulation), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
