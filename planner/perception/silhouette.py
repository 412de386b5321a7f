"""Where the parts' outlines are in a depth image: the edges between part-high pixels and the table.

A part is a prism whose top is ``top`` over the table. A pixel is *part* if its smoothed height
(:class:`~.table_view.TableView`) is at least half of ``top`` and at most :data:`ABOVE` over it,
*table* if under half of ``top``, and *occluded* if higher (the pusher, a wall, an obstacle) or
within :data:`GUARD` pixels of such: the smoothing spreads a tall thing's edge across the part's
band, which must not be taken for a part. Specks of part pixels, fewer than :data:`SPECK`, are
noise. An *edge point* lies between a part pixel and a table pixel next to it (in a row or a
column), where the smoothed height crosses half of ``top``; only those count: where a part meets
something taller its outline is hidden, not seen.

Seen from above, a prism's silhouette is its top outline on the sides that face away from the
camera, and on those that face it, its wall cut at the height where the pixels stop counting as
part: half of ``top``. So an edge point is put on the plane ``top`` over the table if the camera is
behind its side (the table pixel is on the side away from the camera's foot), else on the plane at
half of ``top``: both are then over the outline, whose side walls are vertical.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import shapely
from scipy import ndimage

from .table_view import TableView

__all__ = ["ABOVE", "GUARD", "SPECK", "Silhouette", "silhouette"]

#: How far over a part's top (m) a pixel may be and still be the part's (noise after smoothing).
ABOVE = 0.003
#: Pixels round something taller than the parts that are not trusted (the smoothing's reach).
GUARD = 2
#: Fewest pixels of a patch of part pixels that is not noise.
SPECK = 10


@dataclass(frozen=True)
class Silhouette:
    """The edge points of a depth image's part-high regions (module docstring): ``points``, world
    ``(x, y)`` (m); and the image's table pixels (``table``, a mask of the image), which say where
    no part is (:meth:`table_inside`)."""

    points: np.ndarray
    table: np.ndarray
    view: TableView

    def table_inside(self, outline: shapely.Polygon) -> int:
        """How many table pixels, on the table plane, fall inside ``outline`` (world frame)."""
        ring = np.asarray(outline.exterior.coords)
        corners = self.view.camera.pixels(np.column_stack([ring, np.zeros(len(ring))]))
        (u0, v0), (u1, v1) = corners.min(axis=0), corners.max(axis=0)
        height, width = self.table.shape
        rows = slice(max(int(np.floor(v0)), 0), max(min(int(np.ceil(v1)) + 1, height), 0))
        columns = slice(max(int(np.floor(u0)), 0), max(min(int(np.ceil(u1)) + 1, width), 0))
        v, u = np.nonzero(self.table[rows, columns])
        if not len(v):
            return 0
        xy = self.view.on_plane(np.column_stack([u + columns.start, v + rows.start]).astype(float), 0.0)
        return int(shapely.contains_xy(outline, xy[:, 0], xy[:, 1]).sum())


def silhouette(view: TableView, top: float) -> Silhouette:
    """The edge points of the parts of height ``top`` (m) in ``view`` (module docstring)."""
    half = top / 2
    height = view.height
    occluded = ndimage.binary_dilation(height > top + ABOVE, iterations=GUARD) | ~view.valid
    part = (height >= half) & ~occluded
    labels, count = ndimage.label(part)
    if count:
        sizes = np.bincount(labels.ravel(), minlength=count + 1)
        part &= sizes[labels] >= SPECK
    table = (height < half) & ~occluded
    pixels, faces = [], []
    for axis in (0, 1):  # rows, then columns: a part pixel and its table neighbour, either way round
        for step in (1, -1):
            pairs = np.argwhere(_shifted(part, step, axis) & table)  # the table pixel q, its part neighbour q - step
            if not len(pairs):
                continue
            p = pairs.copy()
            p[:, axis] -= step
            h_p, h_q = height[p[:, 0], p[:, 1]], height[pairs[:, 0], pairs[:, 1]]
            f = np.clip((h_p - half) / np.maximum(h_p - h_q, 1e-12), 0.0, 1.0)
            crossing = p + f[:, None] * (pairs - p)
            pixels.append(crossing[:, ::-1])  # (row, column) to (u, v)
            faces.append((pairs - p)[:, ::-1].astype(float))
    if not pixels:
        return Silhouette(np.zeros((0, 2)), table, view)
    pixels, faces = np.vstack(pixels), np.vstack(faces)
    at_top = view.on_plane(pixels, top)
    outward = view.on_plane(pixels + faces, top)[:, :2] - at_top[:, :2]
    facing = np.einsum("ij,ij->i", outward, view.camera.position[:2] - at_top[:, :2]) > 0
    points = np.where(facing[:, None], view.on_plane(pixels, half)[:, :2], at_top[:, :2])
    return Silhouette(points, table, view)


def _shifted(mask: np.ndarray, step: int, axis: int) -> np.ndarray:
    """``mask`` moved ``step`` pixels along ``axis``, False where nothing comes in."""
    out = np.zeros_like(mask)
    to, source = [slice(None)] * 2, [slice(None)] * 2
    to[axis], source[axis] = (slice(step, None), slice(None, -step)) if step > 0 else (slice(None, step),
                                                                                       slice(-step, None))
    out[tuple(to)] = mask[tuple(source)]
    return out
