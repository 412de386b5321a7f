"""Benchmark: the camera observer's time per frame and the pose estimator's accuracy.

``python -m planner.bench.camera`` prints two tables.

*Time*: for each scene given (default: battery, junction, parking, corridor and parts/swap), its
camera (its ``camera:`` block or the default camera of its workspace) looks at its parts at their
starts, the pusher off the table, ``--frames`` times through
:class:`~planner.execution.camera_observer.CameraObserver` as the closed loop does (``plan
--closed-loop --observe camera``); a row gives the median seconds per frame of the depth image,
of the estimate and of both.

*Accuracy*: a box of 8 x 5 cm and a square of 6 cm, each alone on a bare square table
``--table`` m across (default 1 m: its default camera hangs 0.947 m high) under its default
camera, at ``--poses`` random poses anywhere on it (up to 8 cm from its walls), the priors
3 mm and 2 degrees off (1-sigma); a row gives the estimates' error against the pose MuJoCo holds
the part at (median, 95th percentile and worst), how many were lost and the mean squared
Mahalanobis distance of the errors under the estimates' covariances (3 for a covariance exactly
as large as the errors). These are the figures of ``docs/camera.md``, "Accuracy".

Only :class:`~planner.execution.camera_observer.CameraObserver`, :class:`~planner.execution.mujoco_sim.World`
and the scene readers are used, so the same script measures an older checkout put first on
``PYTHONPATH`` (run it as a file: ``python planner/bench/camera.py``). Needs the mujoco extra.
"""

from __future__ import annotations

import argparse
import math
import statistics
import time

import numpy as np

from mechanics import pose_error, wrap_angle
from planner.execution.camera_observer import CameraObserver
from planner.execution.mujoco_sim import World, feet
from planner.model.camera import read_camera
from planner.model.scene import Scene
from planner.model.scene_file import load_scene, parse_scene

__all__ = ["main"]

SCENES = ("scenes/battery.yaml", "scenes/junction.yaml", "scenes/parking.yaml", "scenes/corridor.yaml",
          "scenes/parts/swap.yaml")
#: The parts of the accuracy table, in their own frames (m).
PARTS = {"box 8 x 5 cm": [[-0.04, -0.025], [0.04, -0.025], [0.04, 0.025], [-0.04, 0.025]],
         "square 6 cm": [[-0.03, -0.03], [0.03, -0.03], [0.03, 0.03], [-0.03, 0.03]]}
#: The pusher's qpos (x, y, z, theta) off the table, out of the images.
AWAY = (5.0, 5.0, 1.0, 0.0)
#: The priors' error, 1-sigma: m, radians.
PRIOR = (0.003, math.radians(2.0))


def watching(scene: Scene, seed: int) -> tuple[World, CameraObserver]:
    """The MuJoCo world of ``scene``, its parts at their starts and the pusher away, and a camera
    observer of it whose priors are the starts."""
    supports = {name: feet(scene.move_scene(name, scene.starts), 1)[0] for name in scene.names}
    world = World(scene, supports, None, scene.starts)
    world.data.qpos[world.qpos] = AWAY
    camera = scene.camera or read_camera(None, scene.workspace)
    return world, CameraObserver(world, scene, camera, scene.starts, np.random.default_rng(seed))


def timed(observer: CameraObserver, frames: int) -> tuple[float, float, float]:
    """Median seconds of the depth image, of the estimate and of both, over ``frames`` looks (after one
    to warm up)."""
    spent = []
    image = observer.eye.image

    def timed_image(*args, **kwargs):
        clock = time.perf_counter()
        out = image(*args, **kwargs)
        spent.append(time.perf_counter() - clock)
        return out

    observer.eye.image = timed_image  # the observer's own call, timed
    observer.look()
    rows = []
    for _ in range(frames):
        clock = time.perf_counter()
        observer.look()
        total = time.perf_counter() - clock
        rows.append((spent[-1], total - spent[-1], total))
    return tuple(statistics.median(column) for column in zip(*rows))


def accuracy(vertices: list, side: float, poses: int, seed: int) -> str:
    """The accuracy table's row of the part ``vertices`` on a table ``side`` m across (module docstring)."""
    half = side / 2
    scene = parse_scene({"parts": [{"name": "a", "vertices": vertices, "start": [0, -0.3 * half, 0],
                                    "goal": [0, 0.3 * half, 0]}],
                         "pusher": {"width": 0.05, "depth": 0.01, "mu": 0.5},
                         "workspace": {"min": [-half, -half], "max": [half, half]}})
    world, observer = watching(scene, seed)
    rng = np.random.default_rng(seed)
    errors, mahalanobis, lost = [], [], 0
    for _ in range(poses):
        truth = np.array([*rng.uniform(0.08 - half, half - 0.08, 2), rng.uniform(-math.pi, math.pi)])
        world.data.qpos[world.slots["a"]] = truth
        observer.priors["a"] = truth + rng.normal(0.0, [PRIOR[0], PRIOR[0], PRIOR[1]])
        found = observer.look()["a"]
        if not found.tracked:
            lost += 1
            continue
        errors.append(pose_error(found.pose, truth))
        off = np.array([*(found.pose[:2] - truth[:2]), wrap_angle(found.pose[2] - truth[2])])
        mahalanobis.append(float(off @ np.linalg.solve(found.covariance, off)))
    mm, deg = np.array(errors)[:, 0] * 1e3, np.degrees(np.array(errors)[:, 1])
    return (f"{np.median(mm):.2f} / {np.percentile(mm, 95):.2f} / {mm.max():.2f} mm | {np.median(deg):.2f} / "
            f"{np.percentile(deg, 95):.2f} / {deg.max():.2f} degrees | {lost} of {poses} | {np.mean(mahalanobis):.2f}")


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m planner.bench.camera", description=__doc__.splitlines()[0])
    p.add_argument("scenes", nargs="*", default=list(SCENES))
    p.add_argument("--frames", type=int, default=10, help="looks timed per scene (0: no time table)")
    p.add_argument("--poses", type=int, default=40, help="random poses per part of the accuracy table (0: none)")
    p.add_argument("--table", type=float, default=1.0, help="the accuracy table's table, m across")
    p.add_argument("--seed", type=int, default=1)
    args = p.parse_args(argv)
    if args.frames:
        print("| scene | camera | image s | estimate s | frame s |\n|---|---|---|---|---|")
    for path in args.scenes if args.frames else ():
        scene = load_scene(path)
        _, observer = watching(scene, args.seed)
        width, height = observer.camera.resolution
        image, estimate, total = timed(observer, args.frames)
        print(f"| {path} | {width} x {height}, {observer.camera.position[2]:.2f} m high | {image:.4f} | "
              f"{estimate:.4f} | {total:.4f} |", flush=True)
    if args.poses:
        print("\n| part | position error median / p95 / worst | heading error median / p95 / worst | lost | "
              "mean squared Mahalanobis |\n|---|---|---|---|---|")
        for name, vertices in PARTS.items():
            print(f"| {name} | {accuracy(vertices, args.table, args.poses, args.seed)} |", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
