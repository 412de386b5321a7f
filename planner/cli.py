"""The ``plan`` command: plan a scene, print a summary, write the plan JSON and a rerun recording.

Exit codes: 0 solved, 1 bad input (one line naming the field), 2 not solved (one line saying
why). Output files are written atomically, so an interrupted run leaves no half-written file.
"""

from __future__ import annotations

import argparse
import atexit
import os
import sys
import time
from pathlib import Path

from .plan_file import write_atomic
from .scene import DEFAULT_PLANNER, PLANNERS, SceneError, load_scene
from .search import plan

__all__ = ["main"]


def _silence_nanobind_leak_report() -> None:
    # nanobind reports OMPL objects still alive at interpreter exit on stderr; harmless noise
    # (STACK.md §1.13). Runs before finalisation, after everything of ours is flushed.
    sys.stdout.flush()
    sys.stderr.flush()
    os.dup2(os.open(os.devnull, os.O_WRONLY), 2)


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="plan", description="Plan guaranteed-stable pushes for a YAML scene.")
    p.add_argument("scene", help="scene file (YAML)")
    p.add_argument("--planner", choices=PLANNERS, help=f"OMPL control planner (default: the scene's, else {DEFAULT_PLANNER})")
    p.add_argument("--time-limit", type=float, metavar="S", help="planning time limit in seconds")
    p.add_argument("--seed", type=int, metavar="N", help="random seed (>= 1); the same seed gives the same plan")
    p.add_argument("--out", metavar="DIR", help="output folder (default: logs/<name>-<timestamp>/)")
    return p


def main(argv: list[str] | None = None) -> int:
    args = _parser().parse_args(argv)
    atexit.register(_silence_nanobind_leak_report)
    try:
        return _run(args)
    except SceneError as err:
        print(f"plan: error: {err}", file=sys.stderr)
        return 1


def _run(args: argparse.Namespace) -> int:
    if args.time_limit is not None and not args.time_limit > 0:
        raise SceneError("--time-limit", f"must be > 0, got {args.time_limit}")
    if args.seed is not None and args.seed < 1:
        raise SceneError("--seed", f"must be a positive integer, got {args.seed}")
    scene = load_scene(args.scene)
    name = args.planner or scene.planner.name
    limit = args.time_limit or scene.planner.time_limit
    seed = args.seed or scene.planner.seed
    print(f"planning {scene.name} with {name} (seed {seed}, limit {limit:g} s) ...", file=sys.stderr, flush=True)
    result = plan(scene, seed=seed, time_limit=limit, planner=name)
    out = Path(args.out) if args.out else Path("logs") / f"{scene.name}-{time.strftime('%Y%m%d-%H%M%S')}"
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as err:
        raise SceneError("--out", f"cannot create {str(out)!r}: {err.strerror or err}") from None
    write_atomic(out / f"{scene.name}.json", result.to_json())
    from .recording import write_recording  # rerun takes half a second to import

    write_recording(out / f"{scene.name}.rrd", scene, result)
    if not result.solved:
        print(f"plan: not solved: {result.reason} (outputs in {out})", file=sys.stderr)
        return 2
    print(
        f"solved: {result.pushes} pushes, path length {result.path_length(scene.slider.cf):.3f} m, "
        f"planning time {result.planning_time_s:.2f} s -> {out}/{scene.name}.json, {scene.name}.rrd"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
