"""Benchmark: what planning for the arm costs, and what it buys (a scene's ``robot:`` block).

``python -m planner.bench.arm`` plans each of the scenes with an arm (default: ``scenes/arm/*.yaml``;
``--robot MODEL X Y YAW`` gives scenes without a block one, its tool 0.12 m long) with seeds 1 to
``--seeds``, once for the arm and once for a free pusher (the block taken out), then runs the
arm's joints along each seed-1 plan's trajectory. It prints a Markdown table, one row per scene:

* the median planning time for a free pusher and for the arm, and their ratio. The planner calls
  no inverse kinematics: the arm is its reach zone (:mod:`planner.world.reach`), a clearance the
  collision checks count, drawn once per arm, tool and push height (the ``zone`` column, cold);
* whether the arm follows the free pusher's plan and the arm's (:mod:`planner.arm.joints`);
* the arm plan's trajectory samples, the time its joints took and inverse kinematics solves a
  second (a sample each).

Needs the arm extra.
"""

from __future__ import annotations

import argparse
import math
import statistics
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from ..execution.trajectory import trajectory
from ..model.extras import have, needs
from ..model.robot import Robot
from ..model.scene_file import load_scene
from ..queries.session import plan
from ..world import reach

__all__ = ["HEADER", "main"]

ARM_SCENES = Path(__file__).resolve().parents[2] / "scenes" / "arm"
HEADER = ("| scene | robot | zone | planning (free) | planning (arm) | arm / free | free plan: arm | arm plan: arm | "
          "samples | joints | IK solves/s |\n|---|---|---|---|---|---|---|---|---|---|---|")


def _timed(scene, seeds: int) -> tuple[float, list]:
    """The median planning time of ``scene`` over seeds 1 to ``seeds``, and the plans."""
    times, plans = [], []
    for seed in range(1, seeds + 1):
        clock = time.perf_counter()
        plans.append(plan(scene, seed=seed))
        times.append(time.perf_counter() - clock)
    return statistics.median(times), plans


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m planner.bench.arm", description=__doc__.splitlines()[0])
    p.add_argument("scenes", nargs="*", help="scene files (YAML); default: scenes/arm/*.yaml")
    p.add_argument("--robot", nargs=4, metavar=("MODEL", "X", "Y", "YAW"),
                   help="the arm and its base (m, m, degrees) of scenes without a robot block")
    p.add_argument("--seeds", type=int, default=3, help="seeds 1 to N (default 3)")
    args = p.parse_args(argv)
    if not have("mink"):
        p.exit(1, f"{p.prog}: error: {needs('mink')}\n")
    from ..arm.joints import joints_along  # loads mink

    print(HEADER, flush=True)
    for path in args.scenes or sorted(ARM_SCENES.glob("*.yaml")):
        scene = load_scene(path)
        if scene.robot is None:
            if args.robot is None:
                p.exit(1, f"{p.prog}: error: {path} has no robot block: give one with --robot\n")
            model, x, y, yaw = args.robot
            scene = replace(scene, robot=Robot(model, np.array([float(x), float(y), math.radians(float(yaw))]), 0.12))
        robot = scene.robot
        reach._family.cache_clear()
        clock = time.perf_counter()
        reach.reach_zone(robot)
        zone_time = time.perf_counter() - clock
        free_time, free_plans = _timed(replace(scene, robot=None), args.seeds)
        arm_time, arm_plans = _timed(scene, args.seeds)

        def followed(found) -> str:
            return "not solved" if not found.solved else (
                "follows" if joints_along(robot, trajectory(scene, found)).follows else "cannot follow")

        row = (f"| {scene.name} | {robot.model} | {zone_time * 1e3:.0f} ms | {free_time:.2f} s | {arm_time:.2f} s | "
               f"{arm_time / free_time:.2f} | {followed(free_plans[0])} | ")
        if not arm_plans[0].solved:
            print(row + "not solved | | | |", flush=True)
            continue
        motion = trajectory(scene, arm_plans[0])
        clock = time.perf_counter()
        arm = joints_along(robot, motion)
        joints_time = time.perf_counter() - clock
        print(row + f"{'follows' if arm.follows else 'cannot follow'} | {len(motion.t)} | {joints_time:.2f} s | "
                    f"{len(motion.t) / joints_time:,.0f} |", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
