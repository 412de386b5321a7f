"""The closed loop's eyes in camera mode: the scene's depth camera and the pose estimator.

An observer sees the run's :class:`~.mujoco_sim.World` only through
:class:`~.depth_camera.DepthCamera` images, and finds the parts in them with
:func:`planner.perception.estimation.estimate_poses`; it never reads MuJoCo's pose of a part. Its
priors begin as the plan's starts (where the loop believes the parts are) and follow its own
estimates: each part's last good one. The camera casts rays only where the estimator will read
(:func:`planner.perception.estimation.sight`: round each part's prior), which makes an image of a
part on a large table a fraction of the whole image's cost.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
from numpy.typing import ArrayLike

from ..model.camera import Camera
from ..model.scene import Scene
from ..perception.estimation import Estimate, estimate_poses, sight
from .depth_camera import PART_TOP, DepthCamera
from .mujoco_sim import World

__all__ = ["CameraObserver"]


class CameraObserver:
    """``camera`` watching ``world``, a run of ``scene``, its priors ``priors`` (by part name) and
    its noise drawn from ``rng``."""

    def __init__(self, world: World, scene: Scene, camera: Camera, priors: Mapping[str, ArrayLike],
                 rng: np.random.Generator):
        self.camera, self.rng = camera, rng
        self.eye = DepthCamera(world, camera)
        self.outlines = {part.name: part.slider.vertices for part in scene.parts}
        self.priors = {name: np.asarray(pose, dtype=float) for name, pose in priors.items()}
        self.image: np.ndarray | None = None  # the last depth image taken (0 where no ray was cast)

    def look(self) -> dict[str, Estimate]:
        """Every part's estimate from an image taken now; the tracked ones become the priors."""
        self.image = self.eye.image(self.rng, sight(self.camera, self.outlines, PART_TOP, self.priors))
        found = estimate_poses(self.image, self.camera, self.outlines, PART_TOP, self.priors)
        self.priors.update({name: e.pose for name, e in found.items() if e.tracked})
        return found
