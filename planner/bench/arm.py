"""Benchmark: what the arm costs (a scene's ``robot:`` block, :mod:`planner.arm`).

``python -m planner.bench.arm scenes/parking.yaml --robot panda 0 -0.4 90`` plans each scene with
seed 1 as it is and with the robot block given (the flag's model, base x, y and yaw in degrees, the
tool 0.12 m long), then the trajectory and the arm's joints along it. It prints a Markdown table,
one row per scene: planning time without and with the block, the trajectory's samples and time,
the joints' time, inverse kinematics solves per second (a sample each, after the first pose's),
and whether the arm follows. Needs the arm extra. (The planner does not yet plan for the arm, so
the two planning times differ only by the scene's reading: the column is there for when it does.)
"""

from __future__ import annotations

import argparse
import math
import time
from dataclasses import replace

import numpy as np

from ..execution.trajectory import trajectory
from ..model.extras import have, needs
from ..model.robot import Robot
from ..model.scene_file import load_scene
from ..queries.session import plan

__all__ = ["HEADER", "main"]

HEADER = ("| scene | robot | planning (free) | planning (robot) | samples | trajectory | joints | IK solves/s | "
          "arm |\n|---|---|---|---|---|---|---|---|---|")


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m planner.bench.arm", description=__doc__.splitlines()[0])
    p.add_argument("scenes", nargs="+", help="scene files (YAML)")
    p.add_argument("--robot", nargs=4, metavar=("MODEL", "X", "Y", "YAW"), default=["panda", "0", "-0.4", "90"],
                   help="the arm and its base (m, m, degrees); default panda 0 -0.4 90")
    args = p.parse_args(argv)
    if not have("mink"):
        p.exit(1, f"{p.prog}: error: {needs('mink')}\n")
    from ..arm.joints import joints_along  # loads mink

    model, *base = args.robot
    robot = Robot(model, np.array([float(base[0]), float(base[1]), math.radians(float(base[2]))]), 0.12)
    print(HEADER, flush=True)
    for path in args.scenes:
        free = load_scene(path)
        clock = time.perf_counter()
        result = plan(free, seed=1)
        free_time = time.perf_counter() - clock
        scene = replace(free, robot=robot)
        clock = time.perf_counter()
        result = plan(scene, seed=1)
        robot_time = time.perf_counter() - clock
        if not result.solved:
            print(f"| {scene.name} | {model} | {free_time:.2f} s | {robot_time:.2f} s | not solved | | | | |", flush=True)
            continue
        clock = time.perf_counter()
        motion = trajectory(scene, result)
        motion_time = time.perf_counter() - clock
        clock = time.perf_counter()
        arm = joints_along(robot, motion)
        joints_time = time.perf_counter() - clock
        print(f"| {scene.name} | {model} | {free_time:.2f} s | {robot_time:.2f} s | {len(motion.t)} | "
              f"{motion_time:.2f} s | {joints_time:.2f} s | {len(motion.t) / joints_time:,.0f} | "
              f"{'follows' if arm.follows else 'cannot follow'} |", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
