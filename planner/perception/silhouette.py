"""Where the parts' outlines are in a depth image: the edges between part-high pixels and the table.

A part is a prism whose top is ``top`` over the table. A pixel is *part* if its smoothed height
(:class:`~.table_view.TableView`) is at least half of ``top`` and at most :data:`ABOVE` over it,
*table* if under half of ``top``, and *occluded* if higher (the pusher, a wall, an obstacle), within
:data:`GUARD` pixels of such (the smoothing spreads a tall thing's edge across the part's band), or
over the table within :data:`GUARD` pixels' footprint of where such stands (:func:`_beside_tall`):
the camera sees the walls of tall things that face it, whose heights pass through the part's band
over many pixels where the view slants (16 mm of the pusher's wall over 10 pixels), and a wall
stands over its thing's outline, which its top shows. None of these must be taken for a part. Specks of part pixels, fewer than :data:`SPECK`, are
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
    ``(x, y)`` (m); the image's table pixels (``table``, a mask of the image), which say where
    no part is (:meth:`table_inside`), and its occluded pixels (``occluded``), where something
    taller than the parts stands between the camera and the table (:meth:`occluded_inside`)."""

    points: np.ndarray
    table: np.ndarray
    view: TableView
    occluded: np.ndarray

    def table_inside(self, outline: shapely.Polygon) -> int:
        """How many table pixels, on the table plane, fall inside ``outline`` (world frame)."""
        return self._inside(self.table, outline)

    def occluded_inside(self, outline: shapely.Polygon) -> int:
        """How many occluded pixels' rays meet the table plane inside ``outline`` (world frame)."""
        return self._inside(self.occluded, outline)

    def _inside(self, mask: np.ndarray, outline: shapely.Polygon) -> int:
        """How many pixels of ``mask`` see the table plane inside ``outline``."""
        ring = np.asarray(outline.exterior.coords)
        corners = self.view.camera.pixels(np.column_stack([ring, np.zeros(len(ring))])) - self.view.corner
        (u0, v0), (u1, v1) = corners.min(axis=0), corners.max(axis=0)
        height, width = self.table.shape
        rows = slice(max(int(np.floor(v0)), 0), max(min(int(np.ceil(v1)) + 1, height), 0))
        columns = slice(max(int(np.floor(u0)), 0), max(min(int(np.ceil(u1)) + 1, width), 0))
        v, u = np.nonzero(mask[rows, columns])
        if not len(v):
            return 0
        xy = self.view.on_plane(np.column_stack([u + columns.start, v + rows.start]).astype(float), 0.0)
        return int(shapely.contains_xy(outline, xy[:, 0], xy[:, 1]).sum())


def silhouette(view: TableView, top: float) -> Silhouette:
    """The edge points of the parts of height ``top`` (m) in ``view`` (module docstring)."""
    half = top / 2
    height = view.height
    tall = height > top + ABOVE
    occluded = ndimage.binary_dilation(tall, iterations=GUARD) | ~view.valid
    occluded |= _beside_tall(view, tall, (height >= ABOVE) & ~occluded)
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
        return Silhouette(np.zeros((0, 2)), table, view, occluded)
    pixels, faces = np.vstack(pixels), np.vstack(faces)
    at_top = view.on_plane(pixels, top)
    outward = view.on_plane(pixels + faces, top)[:, :2] - at_top[:, :2]
    facing = np.einsum("ij,ij->i", outward, view.camera.position[:2] - at_top[:, :2]) > 0
    points = np.where(facing[:, None], view.on_plane(pixels, half)[:, :2], at_top[:, :2])
    return Silhouette(points, table, view, occluded)


def _beside_tall(view: TableView, tall: np.ndarray, candidates: np.ndarray) -> np.ndarray:
    """Which of the ``candidates`` pixels stand, over the table, within :data:`GUARD` pixels' footprint
    of a ``tall`` pixel's point: the tall things' points and the candidates' are placed at their
    smoothed heights over the table, and compared on a grid of that footprint."""
    out = np.zeros_like(candidates)
    if not tall.any() or not candidates.any():
        return out
    cell = view.camera.position[2] / view.camera.focal  # a pixel's footprint on the table, about

    def cells(mask: np.ndarray) -> np.ndarray:
        v, u = np.nonzero(mask)
        xy = view.on_plane(np.column_stack([u, v]).astype(float), view.height[v, u])[:, :2]
        return np.floor(xy / cell).astype(np.int64)

    occupied, asked = cells(tall), cells(candidates)
    low = occupied.min(axis=0) - GUARD
    grid = np.zeros(tuple(occupied.max(axis=0) - low + GUARD + 1), dtype=bool)
    grid[tuple((occupied - low).T)] = True
    grid = ndimage.binary_dilation(grid, iterations=GUARD)
    index = asked - low
    inside = ((index >= 0) & (index < grid.shape)).all(axis=1)
    hit = np.zeros(len(asked), dtype=bool)
    hit[inside] = grid[tuple(index[inside].T)]
    out[candidates] = hit
    return out


def _shifted(mask: np.ndarray, step: int, axis: int) -> np.ndarray:
    """``mask`` moved ``step`` pixels along ``axis``, False where nothing comes in."""
    out = np.zeros_like(mask)
    to, source = [slice(None)] * 2, [slice(None)] * 2
    to[axis], source[axis] = (slice(step, None), slice(None, -step)) if step > 0 else (slice(None, step),
                                                                                       slice(-step, None))
    out[tuple(to)] = mask[tuple(source)]
    return out
