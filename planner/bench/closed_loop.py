"""Benchmark: perturbed runs in MuJoCo, open loop against closed loop (``plan --simulate
--closed-loop``), with success rates and re-plan latencies.

``python -m planner.bench.closed_loop scenes/*.yaml --cases 5`` plans each scene with seed 1 (one
:class:`~planner.Planner` session per scene) and draws ``--cases`` perturbations per scene from
``--seed``, cycling through the kinds:

* ``start``: the part starts up to 15 mm and 8 degrees off the plan's start;
* ``knock``: at a random time of the run the part is displaced by up to 25 mm and 10 degrees;
* ``noisy``: a start error with 1 mm / 0.5 degree noise on the observed pose;
* ``cf``: a start error with the centre of pressure 5 mm off the CF (the ``--sim-cf-offset`` runs);
* ``slippery``: a start error with half the planned pusher friction (``--sim-mu``).

A draw that puts the part on an obstacle or on the pusher is drawn again. Each case runs once
open loop and once closed loop on the grid foot set; a row per case, then the totals: runs in the
goal without touching a wall or obstacle (open loop: slip is not counted, a part met off its
planned contact slides along the face by design), re-plans and their latency (median, max), and
how often the loop went on with its plan for want of a re-plan.

``--observe camera`` runs each case closed loop a second time, seeing the parts through the
scene's depth camera (its ``camera:`` block, or the default camera of its workspace;
``plan --closed-loop --observe camera``), and prints it beside the truth observer's run: whether
it passed, its estimates' error against MuJoCo's poses (median, 95th percentile and worst, over
the run's images) and the time it lost the part. The ``noisy`` kind's noise is the truth
observer's; the camera has its own. Needs the mujoco extra.
"""

from __future__ import annotations

import argparse
import math
import sys

import numpy as np

from ..execution.closed_loop import closed_loop
from ..execution.mujoco_sim import simulate
from ..model.fields import SceneError
from ..model.scene_file import load_scene
from ..queries.session import Planner

__all__ = ["KINDS", "draw", "main"]

KINDS = ("start", "knock", "noisy", "cf", "slippery")
HEADER = ("| scene | case | open loop | closed loop | re-plans | latency (median, max) |\n"
          "|---|---|---|---|---|---|")
#: The columns ``--observe camera`` adds.
CAMERA_HEADER = (" closed loop, camera | camera error (median/p95/worst) | lost |", "---|---|---|")


def draw(kind: str, rng: np.random.Generator, duration: float, mu: float) -> dict:
    """The keyword arguments of one case of ``kind`` (module docstring) for a run of ``duration`` s."""
    def offset(largest: float, degrees: float) -> list[float]:
        angle, size = rng.uniform(0, 2 * math.pi), largest * math.sqrt(rng.uniform(0.25, 1.0))
        return [size * math.cos(angle), size * math.sin(angle), math.radians(rng.uniform(-degrees, degrees))]

    # Each case draws in the order the recorded runs drew: the start error first.
    cases = {"start": lambda: {"start_error": offset(0.015, 8.0)},
             "knock": lambda: {"bumps": [[rng.uniform(0.2, 0.8) * duration, *offset(0.025, 10.0)]]},
             "noisy": lambda: {"start_error": offset(0.015, 8.0), "noise": (0.001, math.radians(0.5))},
             "cf": lambda: {"start_error": offset(0.015, 8.0), "cf_offset": offset(0.005, 0.0)[:2]},
             "slippery": lambda: {"start_error": offset(0.015, 8.0), "mu": mu / 2}}
    return cases[kind]()


def _shown(case: dict) -> str:
    parts = []
    if "start_error" in case:
        dx, dy, dt = case["start_error"]
        parts.append(f"start ({dx * 1e3:.0f}, {dy * 1e3:.0f}) mm {math.degrees(dt):.0f} deg")
    for t, dx, dy, dt in case.get("bumps", []):
        parts.append(f"knock at {t:.1f} s ({dx * 1e3:.0f}, {dy * 1e3:.0f}) mm {math.degrees(dt):.0f} deg")
    if "noise" in case:
        parts.append("noise 1 mm, 0.5 deg")
    if "cf_offset" in case:
        parts.append("CF off by 5 mm")
    if "mu" in case:
        parts.append(f"pusher mu {case['mu']:g}")
    return ", ".join(parts)


def _camera(run) -> str:
    """The columns of a camera run (:data:`CAMERA_HEADER`)."""
    errors = run.seen.errors
    error = (f"{np.median(errors[:, 0]) * 1e3:.2f}/{np.percentile(errors[:, 0], 95) * 1e3:.2f}/"
             f"{errors[:, 0].max() * 1e3:.2f} mm, {np.degrees(np.median(errors[:, 1])):.2f}/"
             f"{np.degrees(np.percentile(errors[:, 1], 95)):.2f}/{np.degrees(errors[:, 1].max()):.2f} deg"
             if len(errors) else "no estimate")
    return (f" {'ok' if run.passed else 'FAIL'} ({_outcome(run)}; {len(run.replans)} re-plans) | {error} "
            f"| {run.seen.lost:.1f} s |")


def _outcome(run) -> str:
    """How a closed-loop run ended, in brief: its goal error, whether it touched a wall or
    obstacle, why it gave up and the times it went on with its plan."""
    return (f"{run.goal_error[0] * 1e3:.1f} mm{', collides' if run.collisions else ''}"
            f"{'; ' + run.reason if run.reason else ''}"
            f"{f'; went on {len(run.carried)} times' if run.carried else ''}")


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m planner.bench.closed_loop", description=__doc__.splitlines()[0])
    p.add_argument("scenes", nargs="+", help="scene files (YAML)")
    p.add_argument("--cases", type=int, default=5, help="perturbations per scene (default 5, one of each kind)")
    p.add_argument("--seed", type=int, default=1, help="seed of the draws (default 1)")
    p.add_argument("--observe", choices=("truth", "camera"), default="truth",
                   help="camera: also run each case closed loop through the scene's depth camera, beside the truth "
                        "observer (module docstring)")
    args = p.parse_args(argv)
    rng = np.random.default_rng(args.seed)
    looks = args.observe == "camera"
    top, rule = HEADER.split("\n")
    print(f"{top}{CAMERA_HEADER[0]}\n{rule}{CAMERA_HEADER[1]}" if looks else HEADER, flush=True)
    opened = closed = seen = total = 0
    latencies: list[float] = []
    for path in args.scenes:
        session = Planner(load_scene(path))
        scene = session.scene
        result = session.plan(seed=1)
        if not result.solved:
            print(f"| {scene.name} | not solved ({result.reason}) | | | | |", flush=True)
            continue
        duration = simulate(scene, result, 1).runs[0].simulated  # with its lead-in
        for k in range(args.cases):
            kind = KINDS[k % len(KINDS)]
            for _ in range(50):
                case = draw(kind, rng, duration, scene.pusher.mu)
                noise = case.pop("noise", (0.0, 0.0))
                try:
                    open_run = simulate(scene, result, 1, **case).runs[0]
                    closed_run = closed_loop(session, result, 1, noise=noise, **case).runs[0]
                    break
                except SceneError:  # the part on an obstacle or on the pusher: draw again
                    continue
            else:
                print(f"| {scene.name} | {kind}: no free draw in 50 | | | | |", flush=True)
                continue
            case["noise"] = noise if noise != (0.0, 0.0) else None
            total += 1
            open_ok = open_run.in_goal and not open_run.collisions
            opened += open_ok
            closed += closed_run.passed
            latencies += closed_run.latencies
            timing = (f"{np.median(closed_run.latencies) * 1e3:.0f} ms, {max(closed_run.latencies) * 1e3:.0f} ms"
                      if closed_run.latencies else "")
            if looks:
                case.pop("noise")
                camera_run = closed_loop(session, result, 1, observe="camera", **case).runs[0]
                case["noise"] = noise if noise != (0.0, 0.0) else None
                seen += camera_run.passed
            print(f"| {scene.name} | {kind}: {_shown({k: v for k, v in case.items() if v is not None})} "
                  f"| {'ok' if open_ok else 'FAIL'} ({open_run.goal_error[0] * 1e3:.1f} mm"
                  f"{', collides' if open_run.collisions else ''}) "
                  f"| {'ok' if closed_run.passed else 'FAIL'} ({_outcome(closed_run)}) "
                  f"| {len(closed_run.replans)} | {timing} |{_camera(camera_run) if looks else ''}",
                  flush=True)
    if total:
        timing = (f"re-plans {len(latencies)}, latency median {np.median(latencies) * 1e3:.0f} ms, "
                  f"max {max(latencies) * 1e3:.0f} ms" if latencies else "no re-plans")
        camera = f", closed loop with the camera {seen}/{total} ({100 * seen / total:.1f} %)" if looks else ""
        print(f"\nopen loop {opened}/{total} ({100 * opened / total:.1f} %), closed loop {closed}/{total} "
              f"({100 * closed / total:.1f} %){camera}; {timing}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
