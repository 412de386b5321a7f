"""A depth image as heights over the table: the table plane fitted to the image, then each
pixel's height above it.

The calibration says where the table should be (z = 0 of the world frame); the plane is fitted
anyway, since a small error of the camera's tilt puts the table off by millimetres across the
image (a degree at 0.5 m from the nadir is 8.7 mm), as much as a part is high. The fit uses the
smoothed heights of the pixels near z = 0 (the table: most of the image), twice, the second time
only those within :data:`PLANE_BAND` of the first plane, so that the parts and whatever stands on
the table do not pull it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from ..model.camera import Camera

__all__ = ["PLANE_BAND", "SMOOTHING", "TableView", "smoothed_noise", "table_view"]

#: Deviation, in pixels, of the Gaussian that smooths the heights: it divides the noise of a pixel
#: by about 3.5 and keeps an edge's half-height crossing where it is.
SMOOTHING = 1.0
#: Half-width (m) of the band round the calibrated table, then round the first plane, whose pixels fit the plane.
PLANE_BAND = (0.02, 0.002)


def smoothed_noise(sigma: float) -> float:
    """The deviation of the smoothed heights where each pixel's own has deviation ``sigma``, its
    noise independent of its neighbours': ``sigma`` times the root of the sum of the squared weights
    of the smoothing (about a third, at :data:`SMOOTHING` one pixel).

    >>> round(smoothed_noise(1.0), 3)
    0.282
    """
    impulse = np.zeros((17, 17))
    impulse[8, 8] = 1.0
    return sigma * float(np.sqrt((ndimage.gaussian_filter(impulse, SMOOTHING) ** 2).sum()))


@dataclass(frozen=True)
class TableView:
    """A depth image seen against the table: the camera, whether each pixel has a return
    (``valid``), its smoothed height over the fitted plane (m, ``height``) and the plane, ``z = a x
    + b y + c`` in the world frame (``plane`` = ``(a, b, c)``)."""

    camera: Camera
    valid: np.ndarray
    height: np.ndarray
    plane: np.ndarray

    def on_plane(self, pixels: np.ndarray, height: np.ndarray | float) -> np.ndarray:
        """The world points, ``(..., 3)``, where the rays through ``pixels`` (``(..., 2)``, sub-pixel)
        are ``height`` over the fitted plane."""
        a, b, c = self.plane
        rays = self.camera.rays(pixels)
        origin = self.camera.position
        along = (height + c + a * origin[0] + b * origin[1] - origin[2]) / (rays[..., 2] - a * rays[..., 0]
                                                                          - b * rays[..., 1])
        return origin + along[..., None] * rays


def table_view(depth: np.ndarray, camera: Camera) -> TableView:
    """``depth`` (z-depths, m, 0: no return) from ``camera`` as heights over the table (module docstring)."""
    valid = depth > 0
    points = camera.position + depth[..., None] * camera.rays()
    z = ndimage.gaussian_filter(np.where(valid, points[..., 2], 0.0), SMOOTHING)
    plane = np.zeros(3)
    sample = np.zeros_like(valid)
    sample[::4, ::4] = True  # a sixteenth of the pixels is plenty for three numbers
    for band in PLANE_BAND:
        fitted = plane[0] * points[..., 0] + plane[1] * points[..., 1] + plane[2]
        use = sample & valid & (np.abs(z - fitted) < band)
        if use.sum() < 3:
            break
        xy = points[use][:, :2]
        plane = np.linalg.lstsq(np.column_stack([xy, np.ones(len(xy))]), z[use], rcond=None)[0]
    height = z - (plane[0] * points[..., 0] + plane[1] * points[..., 1] + plane[2])
    return TableView(camera, valid, np.where(valid, height, 0.0), plane)
