"""Benchmark: what the stability margin costs, and whether it buys robustness in MuJoCo.

``python -m planner.bench.margin scenes/*.yaml --seeds 5`` plans each scene for each seed with the
default margin (:data:`planner.model.margin.DEFAULT_MARGIN`) and with none (``margin: 0``) and
prints a Markdown table, one row per scene and margin: the plans solved, the median cost and
planning time, and the smallest margin any push keeps (friction, CF; each push certified on its
own, :func:`planner.actions.margins.with_margins`).

``--simulate N`` (needs the mujoco extra) also runs each scene's seed-1 plan of each margin in
MuJoCo on ``N`` support distributions, as planned and perturbed as the margin allows: the pusher
friction ``--mu-drop`` (default 10 %) below the scene's, and the supports' centre moved
``--cf-offset`` (default 1 mm) in each of four directions (slider frame). A row per scene and
margin then says how many runs of each condition passed and the worst slip.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time

from ..actions.margins import smallest, with_margins
from ..model.extras import have, needs
from ..model.margin import DEFAULT_MARGIN, EXACT, Margin
from ..model.scene import Scene
from ..model.scene_file import load_scene
from ..queries.session import Planner

__all__ = ["main", "plans_row", "simulated_row"]

#: The four directions the CF is moved in, slider frame.
DIRECTIONS = ((1, 0), (0, 1), (-1, 0), (0, -1))


def _label(margin: Margin) -> str:
    return "0" if margin.exact else f"{margin.mu:g} / {margin.cf:g}"


def plans_row(scene: Scene, margin: Margin, seeds: list[int]) -> str:
    """The plans of ``scene`` with ``margin`` for ``seeds``: solved, median cost and planning time
    (set-up included), the smallest certified margins."""
    costs, times, least = [], [], []
    for seed in seeds:
        clock = time.perf_counter()
        session = Planner(scene, {"seed": seed, "margin": margin})
        result = session.plan(since=clock)
        times.append(time.perf_counter() - clock)
        if result.solved:
            costs.append(result.cost)
            least.append(smallest(with_margins(scene, result)))
    kept = [m for m in least if m is not None]
    margin_cell = (f"-{min(m.mu for m in kept) * 100:.0f} %, {min(m.cf for m in kept) * 1e3:.2g} mm" if kept else "-")
    cost = f"{statistics.median(costs):.3f} m" if costs else "-"
    return (f"| {scene.name} | {_label(margin)} | {len(costs)}/{len(seeds)} | {cost} | "
            f"{statistics.median(times):.2f} s | {margin_cell} |")


def simulated_row(scene: Scene, margin: Margin, runs: int, mu_drop: float, offset: float) -> str:
    """The seed-1 plan of ``scene`` with ``margin`` run in MuJoCo as planned, with the friction
    ``mu_drop`` lower, and with the CF moved ``offset`` in each of four directions: runs passed per
    condition and the worst slip over all."""
    from ..execution.mujoco_sim import simulate  # loads MuJoCo

    result = Planner(scene, {"seed": 1, "margin": margin}).plan()
    if not result.solved:
        return f"| {scene.name} | {_label(margin)} | not solved ({result.reason}) |" + " |" * 3
    conditions = [("as planned", {}), (f"mu -{mu_drop * 100:g} %", {"mu": scene.pusher.mu * (1 - mu_drop)})]
    conditions += [(f"cf {dx:+d},{dy:+d} mm", {"cf_offset": (dx * offset, dy * offset)}) for dx, dy in DIRECTIONS]
    cells, slip = [], 0.0
    for _, kwargs in conditions:
        simulation = simulate(scene, result, runs, seed=1, **kwargs)
        cells.append(f"{sum(r.passed for r in simulation.runs)}/{runs}")
        slip = max(slip, max(r.slip for r in simulation.runs))
    return (f"| {scene.name} | {_label(margin)} | {cells[0]} | {cells[1]} | {' '.join(cells[2:])} | "
            f"{slip * 1e3:.3f} mm |")


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m planner.bench.margin", description=__doc__.splitlines()[0])
    p.add_argument("scenes", nargs="+", help="scene files (YAML)")
    p.add_argument("--seeds", type=int, default=5, help="seeds 1..N planned per scene and margin (default 5)")
    p.add_argument("--simulate", type=int, metavar="N", help="also run the seed-1 plans in MuJoCo on N distributions")
    p.add_argument("--mu-drop", type=float, default=0.1, help="friction drop simulated (default 0.1)")
    p.add_argument("--cf-offset", type=float, default=0.001, help="CF offset simulated, m (default 0.001)")
    args = p.parse_args(argv)
    if args.simulate and not have("mujoco"):
        p.exit(1, f"{p.prog}: error: {needs('mujoco')}\n")
    scenes = [load_scene(path) for path in args.scenes]
    print("| scene | margin (mu / cf) | solved | median cost | median planning time | smallest kept |\n"
          "|---|---|---|---|---|---|", flush=True)
    for scene in scenes:
        for margin in (DEFAULT_MARGIN, EXACT):
            print(plans_row(scene, margin, list(range(1, args.seeds + 1))), flush=True)
    if args.simulate:
        print(f"\n| scene | margin (mu / cf) | as planned | mu -{args.mu_drop * 100:g} % | "
              f"cf moved {args.cf_offset * 1e3:g} mm (+x +y -x -y) | worst slip |\n|---|---|---|---|---|---|", flush=True)
        for scene in scenes:
            for margin in (DEFAULT_MARGIN, EXACT):
                print(simulated_row(scene, margin, args.simulate, args.mu_drop, args.cf_offset), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
