"""Parts placed at chosen poses in the simulation's MuJoCo model and photographed by the scene's
camera: the ground truth the camera tests compare against (the pose is the model's, never the
estimator's)."""

from __future__ import annotations

import numpy as np

from planner.execution.depth_camera import DepthCamera
from planner.execution.mujoco_sim import World, feet
from planner.model.scene import Scene
from planner.model.scene_file import parse_scene

#: A 1 m square table with nothing on it; its part is a box 8 x 5 cm (radius 4.7 cm).
BOX = [[-0.04, -0.025], [0.04, -0.025], [0.04, 0.025], [-0.04, 0.025]]
SQUARE = [[-0.03, -0.03], [0.03, -0.03], [0.03, 0.03], [-0.03, 0.03]]
#: Where the pusher is put when it should be out of the way: far off the table, high.
AWAY = (5.0, 5.0, 1.0, 0.0)


def table(parts: dict[str, list], half: float = 0.5, camera: dict | None = None,
          pusher: tuple[float, float] = (0.05, 0.01)) -> Scene:
    """A bare table ``2 half`` square with ``parts`` (name: vertices), the ``camera`` block
    (default: the default camera) and a pusher ``(width, depth)``."""
    spec = {"parts": [{"name": name, "vertices": vertices, "start": [0.6 * half * (k - 1), -0.6 * half, 0],
                       "goal": [0.6 * half * (k - 1), 0.6 * half, 0]}
                      for k, (name, vertices) in enumerate(parts.items())],
            "pusher": {"width": pusher[0], "depth": pusher[1], "mu": 0.5},
            "workspace": {"min": [-half, -half], "max": [half, half]}, "camera": camera or {}}
    return parse_scene(spec)


def staged(scene: Scene, poses: dict[str, np.ndarray], pusher=AWAY) -> tuple[World, DepthCamera]:
    """The MuJoCo world of ``scene`` with its parts at ``poses`` and the pusher at ``pusher``
    (``x, y, z, theta``; its body spans z 0 to 16 mm over that), and its camera looking at it."""
    supports = {name: feet(scene.move_scene(name, scene.starts), 1)[0] for name in scene.names}
    world = World(scene, supports, None, {n: np.asarray(p, dtype=float) for n, p in poses.items()})
    world.data.qpos[world.qpos] = pusher
    return world, DepthCamera(world, scene.camera)
