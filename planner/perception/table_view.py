"""A depth image as heights over the table: the table plane fitted to the image, then each
pixel's height above it.

The calibration says where the table should be (z = 0 of the world frame); the plane is fitted
anyway, since a small error of the camera's tilt puts the table off by millimetres across the
image (a degree at 0.5 m from the nadir is 8.7 mm), as much as a part is high. The fit uses the
heights of a lattice of pixels over the whole image (:func:`plane_pixels`) near z = 0 (the table:
most of the image), twice, the second time only those within :data:`PLANE_BAND` of the first
plane, so that the parts and whatever stands on the table do not pull it.

A view may cover only a rectangle of the image (the pixels round the parts that the estimator
reads): the heights are worked out there only, but the plane is still fitted to the lattice over
the whole image. Fitted to the rectangle alone, it would be pulled by whatever fills it: round a
part beside a wall, the part and the wall's smoothed foot can be a third of the rectangle's pixels.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from ..model.camera import Camera

__all__ = ["PLANE_BAND", "PLANE_STEP", "SMOOTHING", "TableView", "plane_pixels", "smoothed_noise", "table_view"]

#: Deviation, in pixels, of the Gaussian that smooths the heights: it divides the noise of a pixel
#: by about 3.5 and keeps an edge's half-height crossing where it is.
SMOOTHING = 1.0
#: Half-width (m) of the band round the calibrated table, then round the first plane, whose pixels fit the plane.
PLANE_BAND = (0.02, 0.002)
#: Pixels between two of the lattice that fits the plane, along rows and columns: 6 400 pixels of
#: an 848 x 480 image, plenty for three numbers, and few rays for a camera to cast.
PLANE_STEP = 8


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
    + b y + c`` in the world frame (``plane`` = ``(a, b, c)``). The arrays are a rectangle of the
    camera's image whose first pixel is the image's ``corner`` (``(u, v)``); pixels given to
    :meth:`on_plane` are the rectangle's."""

    camera: Camera
    valid: np.ndarray
    height: np.ndarray
    plane: np.ndarray
    corner: tuple[int, int] = (0, 0)

    def on_plane(self, pixels: np.ndarray, height: np.ndarray | float) -> np.ndarray:
        """The world points, ``(..., 3)``, where the rays through ``pixels`` (``(..., 2)``, sub-pixel)
        are ``height`` over the fitted plane."""
        a, b, c = self.plane
        rays = self.camera.rays(np.asarray(pixels, dtype=float) + self.corner)
        origin = self.camera.position
        along = (height + c + a * origin[0] + b * origin[1] - origin[2]) / (rays[..., 2] - a * rays[..., 0]
                                                                          - b * rays[..., 1])
        return origin + along[..., None] * rays


def plane_pixels(shape: tuple[int, int]) -> np.ndarray:
    """The pixels whose heights fit the table plane in an image of ``shape``, a mask of it: every
    :data:`PLANE_STEP`-th pixel along its rows and its columns, over all of the image, however
    little of it a view covers."""
    mask = np.zeros(shape, dtype=bool)
    mask[PLANE_STEP // 2::PLANE_STEP, PLANE_STEP // 2::PLANE_STEP] = True
    return mask


def table_view(depth: np.ndarray, camera: Camera, window: tuple[slice, slice] | None = None) -> TableView:
    """``depth`` (z-depths, m, 0: no return) from ``camera`` as heights over the table (module
    docstring), over the rectangle ``window`` of the image (rows, columns; default: all of it); the
    plane is fitted to :func:`plane_pixels`, wherever ``window`` is."""
    v, u = np.nonzero(plane_pixels(depth.shape) & (depth > 0))
    points = camera.position + depth[v, u][:, None] * camera.rays(np.column_stack([u, v]))
    xy, z = points[:, :2], points[:, 2]
    # The lattice's heights are not smoothed (its pixels are far apart): the bands round the plane are
    # at least three deviations of a pixel's own noise wide, so that they cut its noise evenly.
    spread = 3 * camera.noise * depth[v, u] ** 2
    plane = np.zeros(3)
    for band in (PLANE_BAND[0], *[np.maximum(PLANE_BAND[1], spread)] * 2):
        use = np.abs(z - xy @ plane[:2] - plane[2]) < band
        if use.sum() < 3:
            break
        plane = np.linalg.lstsq(np.column_stack([xy[use], np.ones(use.sum())]), z[use], rcond=None)[0]
    if window is None:
        window = (slice(0, depth.shape[0]), slice(0, depth.shape[1]))
    depth = depth[window]
    corner = (window[1].start, window[0].start)
    valid = depth > 0
    v, u = np.mgrid[0:depth.shape[0], 0:depth.shape[1]]
    points = camera.position + depth[..., None] * camera.rays(np.stack([u + corner[0], v + corner[1]], axis=-1))
    z = ndimage.gaussian_filter(np.where(valid, points[..., 2], 0.0), SMOOTHING)
    height = z - (plane[0] * points[..., 0] + plane[1] * points[..., 1] + plane[2])
    return TableView(camera, valid, np.where(valid, height, 0.0), plane, corner)
