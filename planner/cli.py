"""The ``plan`` command: plan a scene, print a summary, write the plan JSON and a rerun recording.

``--verify N`` then re-simulates the plan under N support distributions (:func:`planner.verify`)
and prints a line per push and an overall line with the worst deviation; ``--verify N --plan
FILE`` verifies a plan file instead of planning, and writes the same outputs (the plan as read,
and a recording with the simulated ghost). ``--plan`` without ``--verify`` is bad input.

Exit codes: 0 solved (and verified, if asked), 1 bad input (one line naming the field), 2 not
solved (one line saying why; nothing is verified), 3 verified and some push slipped beyond the
tolerance. Output files are written atomically, so an interrupted run leaves no half-written file.
"""

from __future__ import annotations

import argparse
import atexit
import os
import sys
import time
from dataclasses import replace
from pathlib import Path

from .plan_file import Plan, load_plan, write_atomic
from .scene import (DEFAULT_PLANNER, DEFAULT_REGIONS, DEFAULT_TRANSIT, MAX_SEED, MAX_TIME_LIMIT, PLANNERS, REGIONS,
                    TRANSITS, Scene, SceneError, check_seed, check_time_limit, load_scene)
from .search import plan
from .verify import Verification, verify

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
    p.add_argument("--time-limit", type=float, metavar="S",
                   help=f"planning time limit in seconds (at most {MAX_TIME_LIMIT:g})")
    p.add_argument("--seed", type=int, metavar="N",
                   help=f"random seed (1..{MAX_SEED}); the same seed gives the same plan")
    p.add_argument("--regions", choices=REGIONS,
                   help=f"stable pushes: procedure STABLE or the exact region (default: the scene's, else {DEFAULT_REGIONS})")
    p.add_argument("--transit", choices=TRANSITS,
                   help=f"how the pusher may change edges: walk round the part, be lifted, or never "
                        f"(default: the scene's pusher.transit, else {DEFAULT_TRANSIT})")
    p.add_argument("--out", metavar="DIR", help="output folder (default: logs/<name>-<timestamp>/)")
    p.add_argument("--verify", type=int, metavar="N",
                   help="re-simulate the plan under N support distributions; exit 3 if a push slips")
    p.add_argument("--plan", metavar="FILE", help="with --verify: verify this plan file instead of planning")
    return p


def main(argv: list[str] | None = None) -> int:
    args = _parser().parse_args(argv)
    atexit.register(_silence_nanobind_leak_report)
    try:
        return _run(args)
    except SceneError as err:
        print(f"plan: error: {err}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print("plan: interrupted", file=sys.stderr)
        return 130


def _run(args: argparse.Namespace) -> int:
    limit = None if args.time_limit is None else check_time_limit(args.time_limit, "--time-limit")
    seed = None if args.seed is None else check_seed(args.seed, "--seed")
    if args.verify is not None and args.verify < 1:
        raise SceneError("--verify", f"must be at least 1 distribution, got {args.verify}")
    if args.plan is not None and args.verify is None:
        raise SceneError("--plan", "needs --verify N: a plan file is only read to be verified")
    scene = load_scene(args.scene)
    if args.regions:  # the search, the one-step check and the recording all read it from the scene
        scene = replace(scene, planner=replace(scene.planner, regions=args.regions))
    if args.transit:  # and verify checks a plan's lifts against it
        scene = replace(scene, pusher=replace(scene.pusher, transit=args.transit))
    name = args.planner or scene.planner.name
    limit = limit or scene.planner.time_limit
    seed = seed or scene.planner.seed
    out = Path(args.out) if args.out else _fresh_folder(Path("logs") / f"{scene.name}-{time.strftime('%Y%m%d-%H%M%S')}")
    if out.exists() and not out.is_dir():  # found now, not after the search
        raise SceneError("--out", f"{str(out)!r} exists and is not a folder")
    if args.plan is not None:
        result = load_plan(args.plan)
    else:
        if sys.stderr.isatty():  # a search can take seconds; scripts get just the one line of outcome
            print(f"planning {scene.name} with {name} (seed {seed}, limit {limit:g} s) ...", file=sys.stderr,
                  flush=True)
        result = plan(scene, seed=seed, time_limit=limit, planner=name)
    # The planning seed also draws the random distributions, so a run is repeatable as a whole.
    check = verify(scene, result, args.verify, seed) if args.verify and (result.solved or args.plan) else None
    _write_outputs(out, scene, result, check)
    if not result.solved and args.plan is None:
        print(f"plan: not solved: {result.reason} (outputs in {out})", file=sys.stderr)
        return 2
    head = (f"loaded {args.plan}: {result.contents()}{'' if result.solved else ' (not solved)'}" if args.plan
            else f"solved: {result.contents()}, path length {result.path_length(scene.slider.cf):.3f} m, "
                 f"planning time {result.planning_time_s:.2f} s")
    print(f"{head} -> {out}/{scene.name}.json, {scene.name}.rrd")
    if check is None:
        return 0
    print("\n".join([*check.lines(), f"{check.summary()} in {check.seconds:.1f} s"]))
    return 0 if check.passed else 3


def _fresh_folder(base: Path) -> Path:
    """``base``, or ``base-2``, ``base-3``... if runs started in the same second took it."""
    out, k = base, 1
    while out.exists():
        k += 1
        out = base.with_name(f"{base.name}-{k}")
    return out


def _write_outputs(out: Path, scene: Scene, result: Plan, check: Verification | None) -> None:
    """Write the plan JSON and the recording (with ``check``'s ghost) into ``out``, creating it if need be."""
    from .recording import write_recording  # rerun takes half a second to import

    try:
        out.mkdir(parents=True, exist_ok=True)
        write_atomic(out / f"{scene.name}.json", result.to_json())
        write_recording(out / f"{scene.name}.rrd", scene, result, check)
    except OSError as err:
        raise SceneError("--out", f"cannot write to {str(out)!r}: {err.strerror or err}") from None


if __name__ == "__main__":
    sys.exit(main())
