"""Free space of a disk inside the part: where its centre may be, and which of it is connected.

Every pose a plan passes through keeps the part clear of the obstacles and inside the workspace,
so a disk the part contains (the largest inscribed one, or the one about the centre of friction,
of radius :attr:`mechanics.Slider.cf_depth`) stays clear too: its centre moves in the workspace
shrunk by the radius, outside the obstacles grown by it (:func:`disk_free_space`), and a motion,
being continuous, never leaves the connected piece of that region it starts in
(:class:`Components`). The collision screen, the goal region's screen, the unreachability
certificates and the geodesic lower bound all rest on these two facts.

Every circle here is a polygon of :data:`QUAD_SEGS` segments per quarter: inscribed in the true
circle where obstacles are grown (the free space comes out a little larger than the true one,
which keeps every use above sound), circumscribed where a disk must be covered (:func:`cover`).
"""

from __future__ import annotations

import math

import numpy as np
import shapely
from numpy.typing import ArrayLike

from ..model.scene import Scene

__all__ = ["QUAD_SEGS", "ROUNDING_SHRINK", "SCREEN_SHRINK", "Components", "cover", "disk_free_space"]

#: Segments per quarter circle of every round buffer. Six (15 degrees a chord) loses under 0.3 %
#: of an arc's length and keeps polygons (and the geodesic's visibility graph) a few hundred
#: vertices for the shipped scenes.
QUAD_SEGS = 6
#: A disk's radius is taken this much smaller (relative) where the question is whether a gap as
#: wide as the disk is open: rounding then never closes it, and a centre exactly one radius from
#: an obstacle, as where the part touches it, is inside rather than on a boundary that rounding
#: may put either side of it.
ROUNDING_SHRINK = 1e-6
#: The collision screen's disk is a thousandth smaller: the screen must never call a pose with
#: clearance blocked, and a part a hair from an obstacle has its CF disk that close too.
SCREEN_SHRINK = 1e-3


def disk_free_space(scene: Scene, radius: float) -> shapely.Geometry:
    """Where the centre of a disk of ``radius`` may be, the disk inside the workspace and clear
    of the obstacles: the workspace shrunk by ``radius`` minus the obstacles grown by it.

    The grown obstacles are polygons inscribed in the true ones (:data:`QUAD_SEGS`), so the region
    returned contains the true one. Empty if the disk does not fit in the workspace.

    In ``scenes/corridor.yaml`` the inside of the L fills the table but a corridor 0.25 m wide;
    for a disk of radius 0.025 the table shrinks to 0.95 m square and the inside grows to 0.75 m
    square (but for its rounded corner), leaving an L of ``0.95**2 - 0.75**2 = 0.34`` square metres:

    >>> from planner.model.scene_file import load_scene
    >>> round(disk_free_space(load_scene("scenes/corridor.yaml"), 0.025).area, 3)
    0.34
    """
    # A mitred inward buffer of a rectangle is the rectangle shrunk exactly (or empty).
    room = shapely.box(*scene.workspace).buffer(-radius, join_style="mitre")
    obstacles = shapely.union_all(scene.obstacles)
    return room.difference(obstacles.buffer(radius, quad_segs=QUAD_SEGS))


def cover(geometry: shapely.Geometry, radius: float) -> shapely.Geometry:
    """``geometry`` grown by a polygon that covers every true disk of ``radius`` about it: a
    chord of a circle is ``cos(pi / (4 QUAD_SEGS))`` of the radius from the centre, so the
    buffer's radius is divided by that.

    >>> grown = cover(shapely.Point(0.0, 0.0), 1.0)
    >>> bool(grown.covers(shapely.Point(math.cos(0.1), math.sin(0.1)))), round(grown.area / math.pi, 3)
    (True, 1.006)
    """
    return geometry.buffer(radius / math.cos(math.pi / (4 * QUAD_SEGS)), quad_segs=QUAD_SEGS)


class Components:
    """The connected pieces of a closed region, for asking which piece points are in.

    Pieces of a shapely geometry that touch (at a point, say) are one piece here: a path may pass
    from one to the other through the point they share.

    >>> room = shapely.box(0, 0, 3, 1).difference(shapely.box(1, 0, 2, 1))  # a wall across the room
    >>> left, right, also_left, in_wall = Components(room).label([[0.5, 0.5], [2.5, 0.5], [0.9, 0.1], [1.5, 0.5]])
    >>> bool(left == also_left != right), int(in_wall)
    (True, -1)
    >>> corners = shapely.box(0, 0, 1, 1).union(shapely.box(1, 1, 2, 2))  # two squares touching at a corner
    >>> Components(corners).label([[0.5, 0.5], [1.5, 1.5]]).tolist()
    [0, 0]
    """

    def __init__(self, region: shapely.Geometry):
        pieces = [g for g in getattr(region, "geoms", [region]) if not g.is_empty]
        group = list(range(len(pieces)))

        def root(i: int) -> int:
            while group[i] != i:
                i = group[i]
            return i

        for i in range(len(pieces)):
            for j in range(i + 1, len(pieces)):
                if pieces[i].intersects(pieces[j]):
                    group[root(j)] = root(i)
        roots = sorted({root(i) for i in range(len(pieces))})
        self._pieces = pieces
        self._label = np.array([roots.index(root(i)) for i in range(len(pieces))], dtype=int)
        for piece in pieces:
            shapely.prepare(piece)

    def label(self, points: ArrayLike) -> np.ndarray:
        """Per point (shape ``(..., 2)``), the index of the piece that covers it, or -1 for none
        (numbered from 0, in no particular order)."""
        xy = np.asarray(points, dtype=float)
        out = np.full(xy.shape[:-1], -1, dtype=int)
        for piece, label in zip(self._pieces, self._label):
            out[(out < 0) & shapely.intersects_xy(piece, xy[..., 0], xy[..., 1])] = label
        return out
