"""Benchmark: multi-part transfers (issue 28).

``python -m planner.bench.multi`` plans every scene of ``scenes/parts/`` (or the scenes given)
for ``--seeds`` seeds each with ``--time-limit``, and prints per scene and seed whether it was
solved, the planning time, the moves (buffer moves among them), pushes, transfers and cost, then
each scene's median time. Each scene's parts' stable regions are computed (or read from the
cache) before anything is timed, so the times are the search's.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

from ..actions.controls import edge_controls
from ..model.scene_file import load_scene
from ..queries.session import Planner

__all__ = ["main"]

SCENES = Path(__file__).resolve().parents[2] / "scenes" / "parts"


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m planner.bench.multi", description=__doc__.splitlines()[0])
    p.add_argument("scenes", nargs="*", help="multi-part scene files (default: scenes/parts/*.yaml)")
    p.add_argument("--seeds", type=int, default=3, metavar="N", help="seeds 1..N per scene (default: %(default)s)")
    p.add_argument("--time-limit", type=float, default=120.0, metavar="S",
                   help="time limit per plan, seconds (default: %(default)s)")
    args = p.parse_args(argv)
    paths = [Path(s) for s in args.scenes] or sorted(SCENES.glob("*.yaml"))
    print(f"{'scene':<14} {'seed':>4} {'solved':>6} {'time s':>7} {'moves':>5} {'buffer':>6} {'pushes':>6} "
          f"{'transfers':>9} {'cost m':>7}")
    for path in paths:
        scene = load_scene(path)
        if len(scene.parts) == 1:
            print(f"{path}: not a multi-part scene", file=sys.stderr)
            return 1
        for part in scene.parts:  # the regions, cached before anything is timed
            edge_controls(scene.move_scene(part.name, scene.starts))
        times = []
        for seed in range(1, args.seeds + 1):
            clock = time.perf_counter()
            result = Planner(scene, {"seed": seed, "time_limit": args.time_limit}).plan()
            times.append(time.perf_counter() - clock)
            cost = f"{result.cost:7.3f}" if result.solved else f"{'-':>7}"
            print(f"{scene.name:<14} {seed:>4} {str(result.solved):>6} {times[-1]:7.2f} {len(result.moves):>5} "
                  f"{result.buffer_moves:>6} {result.pushes:>6} {result.transfers:>9} {cost}", flush=True)
        print(f"{scene.name:<14} median {np.median(times):.2f} s, max {max(times):.2f} s over {args.seeds} seeds")
    return 0


if __name__ == "__main__":
    sys.exit(main())
