"""The scene's overhead depth camera in a MuJoCo run: depth images of the simulated table.

A depth image is what the camera of a scene's ``camera:`` block (:class:`~planner.model.camera.Camera`)
would report of the :class:`~.mujoco_sim.World` as it is now: one ray per pixel, cast from the
camera's centre through the pixel's centre with MuJoCo's ray caster (``mj_multiRay``), which needs
no OpenGL, so it runs on a bare machine and in CI. MuJoCo tests every ray against every geom, so
only the rays that may meet something standing on the table are cast: those through the image
of a geom's bounding box; every other ray meets the table plane, where its depth is the camera's
height over the ray's fall per unit of depth. Given a *sight* (a mask of the image: the pixels the
pose estimator reads, :func:`planner.perception.estimation.sight`), only its pixels are worked
out, the others left 0, since nothing reads them. A ray stops at the first body it meets: the
pusher, the walls and the obstacles hide what is under them, as they would from a real camera.
The exact depths are then read as the sensor reads them (:meth:`~planner.model.camera.Camera.measured`:
noise growing with the square of the depth, quantisation), from a seeded generator, so a run's
images are repeatable. Pixels whose ray meets nothing (beyond the table) are 0, no return.

:class:`RenderedDepthCamera` draws the same image with MuJoCo's OpenGL renderer instead, ten times
faster, where OpenGL works (``MUJOCO_GL=egl`` before MuJoCo is imported, on a machine with EGL:
Mesa's does, without a GPU); its depths come from the depth buffer, so they differ from the
rays' at the pixels an edge crosses. The runs use the ray caster, which works everywhere
(``docs/camera.md``, "Depth images").
"""

from __future__ import annotations

import numpy as np

from ..model.camera import Camera
from .mujoco_sim import FOOT, THICKNESS, World

__all__ = ["PART_TOP", "DepthCamera", "RenderedDepthCamera"]

#: The height of a part's top over the table in the model (:func:`.mujoco_sim.mjcf`: a prism of
#: ``THICKNESS`` on feet of radius ``FOOT``), m: what the pose estimator looks for.
PART_TOP = THICKNESS + 2 * FOOT


class DepthCamera:
    """``camera`` looking at ``world``: :meth:`image` is a depth image of it now."""

    def __init__(self, world: World, camera: Camera):
        self.world, self.camera = world, camera
        self._rays = camera.rays()
        self._length = np.linalg.norm(self._rays, axis=-1)  # a ray's length per unit of z-depth
        model = world.model
        self._table = model.geom("table").id
        self._others = [g for g in range(model.ngeom) if g != self._table]
        # A box's corners, as signs of its half sizes.
        self._corners = np.array([[i, j, k] for i in (-1, 1) for j in (-1, 1) for k in (-1, 1)], dtype=float)

    def exact(self, sight: np.ndarray | None = None) -> np.ndarray:
        """The true z-depth at every pixel, ``(height, width)``, m (0: the ray meets nothing); with
        ``sight`` (a mask of the image), only at its pixels, the others 0 (no ray cast there)."""
        mujoco, model, data = self.world.mujoco, self.world.model, self.world.data
        mujoco.mj_kinematics(model, data)  # the bodies where the last step left them
        width, height = self.camera.resolution
        sight = np.ones((height, width), dtype=bool) if sight is None else sight
        depth = np.zeros((height, width))
        depth[sight] = self._on_table(model, data, self._rays[sight])
        cast = self._near_geoms(data) & sight
        rays = self._rays[cast]
        length = self._length[cast]
        geom, distance = np.empty(len(rays), dtype=np.int32), np.empty(len(rays))
        if len(rays):
            mujoco.mj_multiRay(model, data, self.camera.position.astype(float), (rays / length[:, None]).ravel(), None,
                               1, -1, geom, distance, None, len(rays), np.inf)
        depth[cast] = np.where(geom >= 0, distance / length, 0.0)
        return depth

    def _on_table(self, model, data, rays: np.ndarray) -> np.ndarray:
        """The depth of each of ``rays`` if it met nothing but the table plane (0 where it passes
        beyond the plane's extent)."""
        origin, axes = data.geom_xpos[self._table], data.geom_xmat[self._table].reshape(3, 3)
        normal = axes[:, 2]
        fall = rays @ normal
        with np.errstate(divide="ignore", invalid="ignore"):
            depth = (origin - self.camera.position) @ normal / fall
        local = (self.camera.position + depth[..., None] * rays - origin) @ axes[:, :2]
        inside = (depth > 0) & (np.abs(local) <= model.geom_size[self._table, :2]).all(axis=-1)
        return np.where(inside, depth, 0.0)

    def _near_geoms(self, data) -> np.ndarray:
        """The pixels whose rays may meet a geom other than the table: those inside the image's
        bounding rectangle of some geom's bounding box (all of them if a box reaches behind the camera)."""
        model, camera = self.world.model, self.camera
        width, height = camera.resolution
        K, pose = camera.K, camera.T_world_camera
        near = np.zeros((height, width), dtype=bool)
        for g in self._others:
            centre, half = model.geom_aabb[g, :3], model.geom_aabb[g, 3:]
            axes = data.geom_xmat[g].reshape(3, 3)
            corners = data.geom_xpos[g] + (centre + self._corners * half) @ axes.T
            local = (corners - pose[:3, 3]) @ pose[:3, :3]
            if (local[:, 2] <= 1e-9).any():
                near[:] = True
                break
            pixels = local[:, :2] / local[:, 2:] * K[0, 0] + K[:2, 2]
            (u0, v0), (u1, v1) = np.floor(pixels.min(axis=0)), np.ceil(pixels.max(axis=0))
            if u1 < 0 or v1 < 0 or u0 > width - 1 or v0 > height - 1:
                continue
            near[int(max(v0, 0)):int(min(v1, height - 1)) + 1, int(max(u0, 0)):int(min(u1, width - 1)) + 1] = True
        return near

    def image(self, rng: np.random.Generator | None, sight: np.ndarray | None = None) -> np.ndarray:
        """The depth image the sensor reports now: :meth:`exact` (at the pixels of ``sight``) with
        its noise (from ``rng``; None: none) and quantisation."""
        return self.camera.measured(self.exact(sight), rng)


class RenderedDepthCamera(DepthCamera):
    """:class:`DepthCamera` whose :meth:`exact` depths are drawn by MuJoCo's renderer (module
    docstring): the world's model with the camera added, posed as the world is at each image."""

    def __init__(self, world: World, camera: Camera):
        mujoco = world.mujoco
        self.world, self.camera = world, camera
        spec = mujoco.MjSpec.from_string(world.xml)
        width, height = camera.resolution
        spec.visual.global_.offwidth, spec.visual.global_.offheight = width, height
        axes = camera.T_world_camera[:3, :3] @ np.diag([1.0, -1.0, -1.0])  # MuJoCo's cameras look along -z, y up
        quat = np.zeros(4)
        mujoco.mju_mat2Quat(quat, axes.ravel())
        spec.worldbody.add_camera(name="depth", pos=camera.position, quat=quat, fovy=float(np.degrees(camera.fov)))
        self._model = spec.compile()
        self._data = mujoco.MjData(self._model)
        self._renderer = mujoco.Renderer(self._model, height, width)
        self._renderer.enable_depth_rendering()
        # What the renderer draws where nothing is: its far clipping plane (a shade nearer, as a float32).
        self._far = 0.999 * self._model.vis.map.zfar * self._model.stat.extent

    def exact(self, sight: np.ndarray | None = None) -> np.ndarray:
        """The z-depth at every pixel as the renderer draws it, ``(height, width)``, m (0: nothing
        before the far clipping plane); with ``sight``, 0 outside it, as :meth:`DepthCamera.exact`
        (the renderer draws every pixel anyway)."""
        self._data.qpos[:] = self.world.data.qpos
        self.world.mujoco.mj_kinematics(self._model, self._data)
        self.world.mujoco.mj_camlight(self._model, self._data)  # the camera's pose
        self._renderer.update_scene(self._data, camera="depth")
        depth = np.asarray(self._renderer.render(), dtype=float)
        return np.where((depth < self._far) & (True if sight is None else sight), depth, 0.0)  # the far plane: nothing there
