"""Scenes no one has seen, for the benchmarks to run on: random tables, parts, obstacles and
overhead depth cameras, written as scene files.

``python -m planner.bench.unseen_scenes OUT --count 10 --seed 1`` writes ``OUT/unseen-<k>.yaml``
and prints their paths, so that ``python -m planner.bench.closed_loop OUT/*.yaml --observe camera``
runs its battery on them (issue 40, acceptance 1). The draws come from ``--seed`` alone.

A scene: a table 0.5-1.0 m by 0.4-0.8 m; one part, a rectangle (4-10 by 3-8 cm), a square (4-8 cm),
a trapezoid (a wedge: the far side 40-80 % of the near one) or an L (its arms 30-60 % of its
sides wide), with the centre of friction at its centroid; its start and goal on the table, the whole part at least 3 cm inside the edges, at
least 15 cm apart, at any headings; up to two box obstacles kept 6 cm clear of the start and goal;
a pusher 3-6 cm wide with friction 0.4-1.0. The camera looks at the table's centre, tilted by up
to 10 degrees from straight down, its image turned by any yaw, from the least height (in steps of
5 % from the default camera's) at which that image holds the whole table, raised by 0-20 %; at
one of the resolutions of the default
sensor's modes (848 x 480, 640 x 360, 424 x 240), a field of view of 50-65 degrees, the default
sensor's noise times 0.5-1.5, at 15 or 30 frames a second. A draw whose scene file is refused
(:func:`planner.model.scene_file.load_scene`: the part on an obstacle, say) is drawn again.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np
import shapely
import yaml

from ..model.camera import DEFAULTS, read_camera
from ..model.fields import SceneError
from ..model.scene_file import load_scene

__all__ = ["MODES", "draw_scene", "main", "write_scenes"]

#: The resolutions the cameras are drawn from (width, height): the default sensor's depth modes.
MODES = ((848, 480), (640, 360), (424, 240))
#: Clearance of the part from the table's edges, and of the obstacles from the start and goal, m.
EDGE, CLEAR = 0.03, 0.06


def _outline(rng: np.random.Generator) -> tuple[str, list[list[float]]]:
    """A part's kind and vertices (counter-clockwise, centred on the bounding box)."""
    kind = rng.choice(["rectangle", "square", "trapezoid", "L"])
    a, b = rng.uniform(0.04, 0.10), rng.uniform(0.03, 0.08)
    if kind == "square":
        b = a = rng.uniform(0.04, 0.08)
    if kind == "trapezoid":
        top = a * rng.uniform(0.4, 0.8)
        points = [[-a / 2, -b / 2], [a / 2, -b / 2], [top / 2, b / 2], [-top / 2, b / 2]]
    elif kind == "L":
        u, v = a * rng.uniform(0.3, 0.6), b * rng.uniform(0.3, 0.6)
        points = [[-a / 2, -b / 2], [a / 2, -b / 2], [a / 2, -b / 2 + v], [-a / 2 + u, -b / 2 + v],
                  [-a / 2 + u, b / 2], [-a / 2, b / 2]]
    else:
        points = [[-a / 2, -b / 2], [a / 2, -b / 2], [a / 2, b / 2], [-a / 2, b / 2]]
    return str(kind), [[round(x, 5), round(y, 5)] for x, y in points]


def draw_scene(rng: np.random.Generator, name: str) -> dict:
    """One scene's contents as a scene file holds them (module docstring)."""
    width, depth = rng.uniform(0.5, 1.0), rng.uniform(0.4, 0.8)
    low, high = [round(-width / 2, 4), round(-depth / 2, 4)], [round(width / 2, 4), round(depth / 2, 4)]
    kind, vertices = _outline(rng)
    polygon = shapely.Polygon(vertices)
    radius = float(np.max(np.hypot(*np.asarray(vertices).T)))
    cf = [round(polygon.centroid.x, 5), round(polygon.centroid.y, 5)]

    def pose() -> list[float]:
        x, y = (rng.uniform(low[i] + radius + EDGE, high[i] - radius - EDGE) for i in range(2))
        return [round(x, 4), round(y, 4), round(rng.uniform(-180.0, 180.0), 2)]

    start = pose()
    goal = pose()
    for _ in range(100):
        if math.dist(start[:2], goal[:2]) >= 0.15:
            break
        goal = pose()
    keep_clear = [shapely.Point(p[:2]).buffer(radius + CLEAR) for p in (start, goal)]
    obstacles = []
    for _ in range(int(rng.integers(0, 3))):
        centre = [rng.uniform(low[0], high[0]), rng.uniform(low[1], high[1])]
        size = [rng.uniform(0.02, 0.15), rng.uniform(0.02, 0.15)]
        box = shapely.box(centre[0] - size[0] / 2, centre[1] - size[1] / 2, centre[0] + size[0] / 2,
                          centre[1] + size[1] / 2)
        if not any(box.intersects(c) for c in keep_clear):
            obstacles.append({"box": {"center": [round(v, 4) for v in centre], "size": [round(v, 4) for v in size]}})
    resolution = MODES[int(rng.integers(len(MODES)))]
    fov, yaw = rng.uniform(50.0, 65.0), rng.uniform(-180.0, 180.0)
    tilt, way, raised = math.radians(rng.uniform(0.0, 10.0)), rng.uniform(0.0, 2 * math.pi), rng.uniform(1.0, 1.2)
    height = float(read_camera({"resolution": list(resolution), "fov": fov}, (*low, *high)).position[2])
    corners = np.array([[x, y, 0.0] for x in (low[0], high[0]) for y in (low[1], high[1])])
    for _ in range(100):  # up in steps of 5 % until the turned, tilted image holds the whole table
        aside = height * raised * math.tan(tilt)
        camera = {"position": [round(aside * math.cos(way), 4), round(aside * math.sin(way), 4),
                               round(height * raised, 4)],
                  "look_at": [0.0, 0.0], "yaw": round(yaw, 1), "resolution": list(resolution), "fov": round(fov, 1)}
        u, v = read_camera(camera, (*low, *high)).pixels(corners).T
        if (u > 0).all() and (u < resolution[0]).all() and (v > 0).all() and (v < resolution[1]).all():
            break
        height *= 1.05
    camera.update(noise=round(DEFAULTS["noise"] * rng.uniform(0.5, 1.5), 6), rate=int(rng.choice([15, 30])))
    return {"name": f"{name}-{kind}", "slider": {"vertices": vertices, "cf": cf},
            "pusher": {"width": round(rng.uniform(0.03, 0.06), 4), "depth": 0.01, "mu": round(rng.uniform(0.4, 1.0), 2)},
            "obstacles": obstacles, "workspace": {"min": low, "max": high}, "start": start, "goal": goal,
            "camera": camera, "planner": {"time_limit": 4.0}}


def write_scenes(folder: str | Path, count: int, seed: int) -> list[Path]:
    """Draw ``count`` scenes from ``seed`` (module docstring) and write them in ``folder``."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(seed)
    paths = []
    for k in range(1, count + 1):
        path = folder / f"unseen-{k}.yaml"
        for _ in range(100):
            path.write_text(yaml.safe_dump(draw_scene(rng, f"unseen-{k}"), sort_keys=False, default_flow_style=None))
            try:
                load_scene(path)
                break
            except SceneError:
                continue
        else:
            raise RuntimeError(f"no valid scene in 100 draws for {path}")
        paths.append(path)
    return paths


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m planner.bench.unseen_scenes", description=__doc__.splitlines()[0])
    p.add_argument("out", help="folder to write the scene files in")
    p.add_argument("--count", type=int, default=10, help="scenes to draw (default 10)")
    p.add_argument("--seed", type=int, default=1, help="seed of the draws (default 1)")
    args = p.parse_args(argv)
    for path in write_scenes(args.out, args.count, args.seed):
        print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
