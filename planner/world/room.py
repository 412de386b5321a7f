"""Room near a goal: the positions close to a pose at which a body, turned as the pose says, is
inside the workspace and clear of every obstacle (its configuration-space obstacles at that
heading, by Minkowski sums).

A goal is reached anywhere within its tolerance, so a goal drawn against a wall, or a little
into a thin obstacle, is still a goal a plan can end at, only not exactly at the pose asked.
Two uses:

* an *aim* (:meth:`Room.aim`): the pose within tolerance nearest the goal where the part with
  the pusher on an edge keeps a clearance, for the goal region to push towards
  (:mod:`planner.search.goal_region`);
* a *certificate* (:meth:`Room.blocked`): no position within tolerance has room for the body
  even shrunk by what a turn within the angle tolerance can move it, so no plan ends there
  (:mod:`planner.queries.reachability`).

For convex polygons ``A`` (an obstacle) and ``B`` (the body at the origin), the body placed at
``c`` overlaps ``A`` exactly when ``c`` lies in ``A - B = {a - b}``, the convex hull of the
vertex differences; non-convex shapes are unions of convex pieces, and the sum distributes over
unions. The workspace, convex, is left by a body exactly when a vertex is outside it.

>>> import shapely
>>> room = Room([shapely.box(1.0, -1.0, 2.0, 1.0)], (-5.0, -5.0, 5.0, 5.0))
>>> square = [[-0.5, -0.5], [0.5, -0.5], [0.5, 0.5], [-0.5, 0.5]]
>>> room.free(square, 0.0, (0.0, 0.0), 1.0).bounds[2]  # the square's right side must stay left of x = 1
0.5
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import shapely
from numpy.typing import ArrayLike

from ..model.bodies import convex_pieces
from .free_space import QUAD_SEGS

__all__ = ["Room"]

#: A circle's polygon (:data:`~planner.world.free_space.QUAD_SEGS` segments a quarter) reaches
#: this fraction of the radius at its chords' middles; dividing by it gives one that covers the circle.
_INSCRIBED = math.cos(math.pi / (4 * QUAD_SEGS))
#: :meth:`Room.blocked` splits the headings within tolerance into turns that each shrink the body
#: by at most this share of the position tolerance (at most :data:`_MAX_TURNS` of them).
_TURN_SHRINK, _MAX_TURNS = 0.05, 16


class Room:
    """The obstacles (polygons, world frame) and the workspace ``(xmin, ymin, xmax, ymax)``,
    split once into convex pieces for the Minkowski sums."""

    def __init__(self, obstacles: Sequence[shapely.Geometry], workspace: Sequence[float]):
        self.workspace = tuple(float(v) for v in workspace)
        self._pieces = [p for o in obstacles for p in convex_pieces(o)]
        self._boxes = np.array([(*p.min(axis=0), *p.max(axis=0)) for p in self._pieces]).reshape(-1, 4)

    def free(self, body: ArrayLike | Sequence[ArrayLike], theta: float, centre: ArrayLike, radius: float,
             clearance: float = 0.0) -> shapely.Geometry:
        """The positions within ``radius`` of ``centre`` (a polygon covering that disk) where the
        body, given by its convex pieces in its own frame (or one convex polygon) and turned by
        ``theta``, is clear of everything by ``clearance``. Exact but for the disk's and the
        clearance's polygons."""
        pieces = [np.asarray(body, dtype=float)] if np.ndim(body[0]) == 1 else [np.asarray(p, float) for p in body]
        c, s = math.cos(theta), math.sin(theta)
        turn = np.array([[c, s], [-s, c]])
        pieces = [p @ turn for p in pieces]
        points = np.vstack(pieces)
        xmin, ymin, xmax, ymax = self.workspace
        inside = shapely.box(xmin - points[:, 0].min() + clearance, ymin - points[:, 1].min() + clearance,
                             xmax - points[:, 0].max() - clearance, ymax - points[:, 1].max() - clearance)
        x, y = (float(v) for v in centre)
        disk = shapely.Point(x, y).buffer(radius / _INSCRIBED, quad_segs=QUAD_SEGS)
        reach = float(np.linalg.norm(points, axis=1).max()) + radius + clearance
        near = np.flatnonzero((self._boxes[:, 0] <= x + reach) & (self._boxes[:, 2] >= x - reach)
                              & (self._boxes[:, 1] <= y + reach) & (self._boxes[:, 3] >= y - reach))
        sums = [shapely.MultiPoint((self._pieces[k][:, None, :] - p[None, :, :]).reshape(-1, 2)).convex_hull
                for k in near for p in pieces]
        room = inside.intersection(disk)
        if sums:
            blocked = shapely.union_all(sums)
            room = room.difference(blocked.buffer(clearance, quad_segs=QUAD_SEGS) if clearance > 0 else blocked)
        return room

    def blocked(self, body: Sequence[ArrayLike], pose: ArrayLike, radius: float, angle: float,
                clearance: float = 0.0) -> bool:
        """Whether the body (convex pieces, own frame) certainly has less than ``clearance`` at
        every pose within ``radius`` of ``pose``'s position and ``angle`` of its heading: even
        shrunk by the most a turn of ``angle`` moves its points, it has no room within a polygon
        covering that disk (the clearance's round corners are polygons inside the true ones, so
        the room found is if anything too large: the answer stays sound).

        >>> import shapely
        >>> room = Room([shapely.box(-0.01, -1.0, 0.01, 1.0)], (-5.0, -5.0, 5.0, 5.0))  # a thin wall
        >>> square = [np.array([[-0.05, -0.05], [0.05, -0.05], [0.05, 0.05], [-0.05, 0.05]])]
        >>> room.blocked(square, [0.0, 0.0, 0.0], 0.02, 0.0), room.blocked(square, [0.0, 0.0, 0.0], 0.07, 0.0)
        (True, False)
        """
        pose = np.asarray(pose, dtype=float)
        reach = max(float(np.linalg.norm(p, axis=1).max()) for p in body)
        # The headings are split into turns of at most ``step`` either side of their middles, each
        # shrinking the body by what such a turn can move it (a point r from the origin by at most
        # r step): a point of the shrunk body lies in the body however it is turned within the step.
        turns = min(_MAX_TURNS, max(1, math.ceil(reach * angle / (_TURN_SHRINK * radius)))) if radius > 0 else 1
        step = angle / turns
        shrink = reach * step / _INSCRIBED
        core = []
        for p in body:
            piece = shapely.Polygon(p).buffer(-shrink, join_style="mitre") if shrink > 0 else shapely.Polygon(p)
            if not piece.is_empty:
                core.append(np.asarray(shapely.orient_polygons(piece).exterior.coords)[:-1])
        middles = pose[2] + step * (2 * np.arange(turns) + 1 - turns)
        return bool(core) and all(self.free(core, float(t), pose[:2], radius, clearance).is_empty for t in middles)

    def aim(self, body: Sequence[ArrayLike], pose: ArrayLike, radius: float, clearance: float) -> np.ndarray | None:
        """The pose nearest ``pose`` in position, at its heading and within ``radius``, where the
        body (convex pieces, own frame) has ``clearance``: ``pose`` itself where it has; None where
        no position within ``radius`` has.

        >>> import shapely
        >>> room = Room([shapely.box(1.0, -1.0, 2.0, 1.0)], (-5.0, -5.0, 5.0, 5.0))
        >>> square = [np.array([[-0.5, -0.5], [0.5, -0.5], [0.5, 0.5], [-0.5, 0.5]])]
        >>> [round(float(v), 9) for v in room.aim(square, [0.55, 0.0, 0.0], 0.1, 0.01)]  # 5 cm into the wall
        [0.49, 0.0, 0.0]
        >>> room.aim(square, [0.7, 0.0, 0.0], 0.1, 0.01) is None
        True
        """
        pose = np.asarray(pose, dtype=float)
        room = self.free(body, float(pose[2]), pose[:2], radius, clearance)
        if room.is_empty:
            return None
        here = shapely.Point(pose[:2])
        if room.covers(here):
            return pose.copy()
        nearest = shapely.shortest_line(room, here).coords[0]
        if math.hypot(nearest[0] - pose[0], nearest[1] - pose[1]) > radius:
            return None  # only in the covering polygon's sliver beyond the disk
        return np.array([nearest[0], nearest[1], pose[2]])
