"""The overhead depth camera that watches the table: a scene's ``camera:`` block (:class:`Camera`,
read by :func:`read_camera`), with its calibration, the pinhole model that both the simulated
sensor and the pose estimator use (``docs/camera.md``).

Frames. The *world frame* is the scene's: x, y on the table top, z up, the table top at z = 0.
The *camera frame* is the optical one (OpenCV's convention): origin at the centre of projection,
z along the optical axis (into the scene), x along the image's rows to the right, y down the
image. :attr:`Camera.T_world_camera` takes camera-frame points to the world frame. The optical
axis meets the table at ``look_at``; ``yaw`` turns the image about it: at yaw 0 the image's x
axis is the world's x axis made square to the optical axis (looking straight down, the image's
right is world +x and its down is world -y).

Depth is a pixel's *z-depth*, the distance along the optical axis, as RGB-D sensors report it
(not the length of the ray); no return is 0. Its noise is Gaussian with a deviation growing with
the square of the depth, as a stereo sensor's does (``noise`` is the deviation at 1 m), and the
reading is rounded to ``quantisation``.

>>> camera = read_camera({}, (-0.5, -0.5, 0.5, 0.5))  # the defaults, for a 1 m table
>>> camera.position.round(3).tolist(), camera.resolution, round(math.degrees(camera.fov), 1)
([0.0, 0.0, 0.947], (848, 480), 58.0)
>>> camera.T_world_camera[:3, :3].round(6).tolist()  # straight down: image right +x, image down -y
[[1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, -1.0]]
>>> read_camera({"position": [0, 0, 0.0]}, (-0.5, -0.5, 0.5, 0.5))
Traceback (most recent call last):
...
planner.model.fields.SceneError: camera.position: must be above the table (z > 0), got z = 0
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from .fields import ANGLE, LENGTH, SceneError, integer, keys, number, shown, vector

__all__ = ["DEFAULTS", "MAX_PIXELS", "MAX_TILT", "Camera", "read_camera"]

#: The default sensor, after Intel's RealSense D435 (``docs/camera.md`` gives the sources): its
#: 848 x 480 depth mode, 58 degrees vertical field of view, 30 frames a second, depth in 1 mm
#: steps, and the deviation at 1 m of its stereo depth (depth^2 x subpixel / (focal x baseline),
#: 0.08 px subpixel, 50 mm baseline, 433 px focal length: 3.7 mm); the latency is assumed, not
#: published: a frame and a half.
DEFAULTS = {"resolution": (848, 480), "fov": 58.0, "noise": 0.0037, "quantisation": 0.001, "rate": 30.0,
            "latency": 0.05}
#: Most pixels along a side: each is a ray cast per frame, so a bound on the work a number asks for.
MAX_PIXELS = 4096
#: Steepest view, degrees from straight down: beyond it the camera looks along the table, not at it.
MAX_TILT = 80.0
#: Margin of the default view round the workspace (a fraction of its half-extents).
_MARGIN = 1.05


@dataclass(frozen=True, eq=False)
class Camera:
    """An overhead depth camera (module docstring). Lengths in m, angles in radians, ``resolution``
    is ``(width, height)`` in pixels, ``fov`` the vertical field of view, ``noise`` the depth's
    deviation at 1 m, ``quantisation`` its step (0: none), ``rate`` frames per second and
    ``latency`` the seconds from exposure to the image in hand."""

    position: np.ndarray
    look_at: np.ndarray
    yaw: float
    resolution: tuple[int, int]
    fov: float
    noise: float
    quantisation: float
    rate: float
    latency: float
    T_world_camera: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        axis = np.array([*self.look_at, 0.0]) - self.position
        z = axis / np.linalg.norm(axis)
        right = np.array([math.cos(self.yaw), math.sin(self.yaw), 0.0])
        x = right - (right @ z) * z
        x /= np.linalg.norm(x)
        pose = np.eye(4)
        pose[:3, :3] = np.column_stack([x, np.cross(z, x), z])
        pose[:3, 3] = self.position
        object.__setattr__(self, "T_world_camera", pose)

    @property
    def focal(self) -> float:
        """The focal length in pixels (square pixels): half the image's height over the tangent of
        half the vertical field of view."""
        return self.resolution[1] / 2 / math.tan(self.fov / 2)

    @property
    def K(self) -> np.ndarray:
        """The intrinsic matrix: pixel ``(u, v)`` (column, row; ``(0, 0)`` the first pixel's
        centre) of a camera-frame point ``p`` is ``K @ p / p[2]``; the principal point is the
        image's centre."""
        width, height = self.resolution
        return np.array([[self.focal, 0.0, (width - 1) / 2], [0.0, self.focal, (height - 1) / 2], [0.0, 0.0, 1.0]])

    def rays(self, pixels: np.ndarray | None = None) -> np.ndarray:
        """The directions, world frame, of the rays through ``pixels`` (``(..., 2)``, ``(u, v)``,
        sub-pixel allowed; default: every pixel's centre, shape ``(height, width, 3)``), scaled to
        unit z-depth: a pixel of depth ``d`` sees ``position + d * ray``."""
        if pixels is None:
            width, height = self.resolution
            v, u = np.mgrid[0:height, 0:width]
            pixels = np.stack([u, v], axis=-1)
        pixels = np.asarray(pixels, dtype=float)
        K = self.K
        local = np.stack([(pixels[..., 0] - K[0, 2]) / K[0, 0], (pixels[..., 1] - K[1, 2]) / K[1, 1],
                          np.ones(pixels.shape[:-1])], axis=-1)
        return local @ self.T_world_camera[:3, :3].T

    def pixels(self, points: Any) -> np.ndarray:
        """The pixels ``(u, v)`` (sub-pixel) where the world points ``points`` (``(..., 3)``, in front
        of the camera) are seen: the inverse of :meth:`rays`.

        >>> camera = read_camera({"position": [0, 0, 1], "resolution": [101, 101], "fov": 90}, (-1, -1, 1, 1))
        >>> camera.pixels([[0.0, 0.0, 0.0], [0.5, 0.5, 0.0]]).round(9).tolist()  # focal 50.5 px, centre (50, 50)
        [[50.0, 50.0], [75.25, 24.75]]
        """
        local = (np.asarray(points, dtype=float) - self.position) @ self.T_world_camera[:3, :3]
        K = self.K
        return local[..., :2] / local[..., 2:] * K[0, 0] + K[:2, 2]

    def measured(self, depth: np.ndarray, rng: np.random.Generator | None) -> np.ndarray:
        """What the sensor reports for the true z-depths ``depth`` (0: no return): each with
        Gaussian noise of deviation ``noise * depth**2`` drawn from ``rng`` (None: none), rounded to
        ``quantisation``; no return stays 0.

        >>> camera = read_camera({"noise": 0.0, "quantisation": 0.001}, (-1, -1, 1, 1))
        >>> camera.measured(np.array([0.9474, 0.0, 1.2]), None).round(9).tolist()
        [0.947, 0.0, 1.2]
        """
        seen = np.asarray(depth, dtype=float).copy()
        hit = seen > 0
        if rng is not None and self.noise > 0:
            seen[hit] += rng.normal(0.0, 1.0, int(hit.sum())) * self.noise * seen[hit] ** 2
        if self.quantisation > 0:
            seen[hit] = np.round(seen[hit] / self.quantisation) * self.quantisation
        return seen

    def moved(self, shift: Any = (0.0, 0.0, 0.0), tilt: float = 0.0) -> "Camera":
        """This camera shifted by ``shift`` (world frame, m) and its view turned by ``tilt``
        (radians) about the image's x axis: a calibration that is off, to study the bias it gives."""
        position = self.position + np.asarray(shift, dtype=float)
        x, _, z = self.T_world_camera[:3, :3].T
        c, s = math.cos(tilt), math.sin(tilt)
        axis = c * z + s * np.cross(x, z)  # z turned about x (Rodrigues, x square to z)
        look_at = position[:2] - position[2] / axis[2] * axis[:2]
        return replace(self, position=position, look_at=look_at)

    def to_dict(self) -> dict:
        """The block as a scene file writes it (angles in degrees)."""
        return {"position": self.position.tolist(), "look_at": self.look_at.tolist(), "yaw": math.degrees(self.yaw),
                "resolution": list(self.resolution), "fov": math.degrees(self.fov), "noise": self.noise,
                "quantisation": self.quantisation, "rate": self.rate, "latency": self.latency}


def _default_height(workspace: tuple[float, float, float, float], resolution: tuple[int, int], fov: float) -> float:
    """The height from which a camera looking straight down at the workspace's centre (yaw 0)
    sees all of it, with a margin: the larger of the heights at which each half-extent fills
    half the image's side."""
    xmin, ymin, xmax, ymax = workspace
    width, height = resolution
    focal = height / 2 / math.tan(fov / 2)
    return _MARGIN * focal * max((xmax - xmin) / width, (ymax - ymin) / height)


def read_camera(value: Any, workspace: tuple[float, float, float, float]) -> Camera:
    """The ``camera:`` block ``value`` (None or ``{}``: every default), checked: a position above
    the table (z > 0), a point on the table it looks at (default: straight below it) at most
    :data:`MAX_TILT` from straight down, the image's yaw (degrees), a resolution of 1 to
    :data:`MAX_PIXELS` pixels a side, a vertical field of view between 0 and 180 degrees, the
    noise and quantisation >= 0, a positive frame rate and a latency >= 0. Defaults: :data:`DEFAULTS`,
    and a position above the workspace's centre that sees all of it."""
    spec = keys({} if value is None else value, "camera", (),
                ("position", "look_at", "yaw", "resolution", "fov", "noise", "quantisation", "rate", "latency"))
    resolution = spec.get("resolution", list(DEFAULTS["resolution"]))
    if not isinstance(resolution, (list, tuple)) or len(resolution) != 2:
        raise SceneError("camera.resolution", f"must be [width, height] in pixels, got {shown(resolution)}")
    size = tuple(integer(v, f"camera.resolution[{i}]") for i, v in enumerate(resolution))
    if not all(1 <= v <= MAX_PIXELS for v in size):
        raise SceneError("camera.resolution", f"must be 1 to {MAX_PIXELS} pixels a side, got {shown(resolution)}")
    fov = number(spec.get("fov", DEFAULTS["fov"]), "camera.fov")
    if not 0 < fov < 180:
        raise SceneError("camera.fov", f"must be between 0 and 180 degrees (the vertical field of view), got {fov:g}")
    fov = math.radians(fov)
    xmin, ymin, xmax, ymax = workspace
    if "position" in spec:
        position = vector(spec["position"], "camera.position", 3, LENGTH)
    else:
        position = np.array([(xmin + xmax) / 2, (ymin + ymax) / 2, _default_height(workspace, size, fov)])
    if not position[2] > 0:
        raise SceneError("camera.position", f"must be above the table (z > 0), got z = {position[2]:g}")
    look_at = vector(spec["look_at"], "camera.look_at", 2, LENGTH) if "look_at" in spec else position[:2].copy()
    tilt = math.degrees(math.atan2(float(np.hypot(*(look_at - position[:2]))), position[2]))
    if tilt > MAX_TILT:
        raise SceneError("camera.look_at", f"tilts the view {tilt:.1f} degrees from straight down (at most "
                                           f"{MAX_TILT:g}: the camera must look at the table)")
    yaw = math.radians(number(spec.get("yaw", 0.0), "camera.yaw", limit=ANGLE))
    amounts = {}
    for key in ("noise", "quantisation", "latency"):
        amounts[key] = number(spec.get(key, DEFAULTS[key]), f"camera.{key}")
        if amounts[key] < 0:
            raise SceneError(f"camera.{key}", f"must be >= 0, got {amounts[key]:g}")
    rate = number(spec.get("rate", DEFAULTS["rate"]), "camera.rate", positive=True)
    return Camera(position, look_at, math.remainder(yaw, 2 * math.pi), size, fov, amounts["noise"],
                  amounts["quantisation"], rate, amounts["latency"])
