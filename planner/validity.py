"""Collision checking of the pushed body (slider + pusher) against obstacles and the workspace.

Resolution rule (why nothing is skipped). Push twists are scaled so that no point of the body
moves faster than 1 m/s; then from a pose with clearance ``d`` (distance from the body to the
nearest obstacle or workspace wall) the body can move for ``d`` seconds without touching
anything, however thin the obstacle. Two uses:

* search states: a state is *valid* when its clearance exceeds ``delta / 2``, where ``delta`` is
  the propagation step; a step joins two such states, and at any instant of it the body is within
  ``delta / 2`` of one of them, so no step between valid states touches an obstacle;
* whole pushes (:meth:`CollisionModel.push_is_free`): conservative advancement, stepping by the
  clearance itself, and rejecting the push if the clearance ever drops below ``margin``.

Obstacles and the body are python-fcl convex prisms; non-convex shapes are split into convex
pieces (STACK.md §2: solid ``Convex`` detects containment, meshes do not). Exact narrow-phase
``fcl.distance`` is called per pair, nearest bounding box first, stopping once no remaining box
can be nearer. (``DynamicAABBTreeCollisionManager.distance`` was tried and over-reported
clearances, e.g. 0.154 m for a true 0.150 m, which would make the rule above unsafe.)
"""

from __future__ import annotations

import math

import fcl
import numpy as np
from numpy.typing import ArrayLike

from mechanics import exp_twist, wrap_angle

from .bodies import body_outline, convex_pieces, pusher_frame_body, pusher_polygon
from .scene import Scene

__all__ = ["CollisionModel"]

_HEIGHT = 1.0  # every 2-D shape is a prism over the same z-range
_PUSHER = "pusher"  # the key of the pusher's own body, beside the per-edge bodies


def _prism(points: np.ndarray) -> fcl.Convex:
    n = len(points)
    verts = np.vstack([np.c_[points, np.full(n, -_HEIGHT / 2)], np.c_[points, np.full(n, _HEIGHT / 2)]])
    faces = [n, *range(n - 1, -1, -1), n, *range(n, 2 * n)]
    for i in range(n):
        j = (i + 1) % n
        faces += [4, i, j, n + j, n + i]
    return fcl.Convex(verts, n + 2, faces)


class CollisionModel:
    """Clearance of the slider with the pusher on a given edge, or of the pusher alone, at any pose.

    Parameters
    ----------
    scene : Scene
    edges : sequence of int
        The edges a pusher may be placed on (each gets its own body).
    """

    def __init__(self, scene: Scene, edges):
        self.workspace = tuple(float(v) for v in scene.workspace)
        pieces = [p for o in scene.obstacles for p in convex_pieces(o)]
        self._obstacles = [fcl.CollisionObject(_prism(p)) for p in pieces]
        self._boxes = [(*p.min(axis=0).tolist(), *p.max(axis=0).tolist()) for p in pieces]
        # Per body: its convex pieces, outline vertices (as floats) and farthest point from its origin.
        self._bodies: dict[int | str, tuple[list[fcl.CollisionObject], list, float]] = {}
        p = scene.pusher
        for e in edges:
            pusher = pusher_polygon(scene.slider, e, p.width, p.depth)
            outline = body_outline(scene.slider, e, p.width, p.depth)
            self._add(e, convex_pieces(scene.slider.polygon) + convex_pieces(pusher), outline)
        alone = pusher_frame_body(p.width, p.depth)
        self._add(_PUSHER, [alone], alone)
        self._request = fcl.DistanceRequest()

    def _add(self, key: int | str, shapes: list[np.ndarray], outline: np.ndarray) -> None:
        self._bodies[key] = ([fcl.CollisionObject(_prism(s)) for s in shapes], outline.tolist(),
                             float(np.linalg.norm(outline, axis=1).max()))

    def clearance(self, pose: ArrayLike, edge: int) -> float:
        """Distance from the body (slider and pusher on ``edge``) to the nearest obstacle or
        workspace wall; <= 0 if colliding."""
        return self._clearance(pose, edge)

    def pusher_clearance(self, pose: ArrayLike) -> float:
        """The same for the pusher alone, ``pose`` being its own frame's (:func:`pusher_frame_body`)."""
        return self._clearance(pose, _PUSHER)

    def _clearance(self, pose: ArrayLike, key: int | str) -> float:
        pieces, hull, reach = self._bodies[key]
        x, y, theta = (float(v) for v in pose)
        c, s = math.cos(theta), math.sin(theta)
        xmin, ymin, xmax, ymax = self.workspace
        # The workspace is convex, so the body's distance to its walls is attained at a vertex.
        best = math.inf
        for px, py in hull:
            wx, wy = x + c * px - s * py, y + s * px + c * py
            best = min(best, wx - xmin, xmax - wx, wy - ymin, ymax - wy)
        if best <= 0 or not self._obstacles:
            return best
        # The body lies in the disc of radius reach about (x, y): a lower bound per obstacle.
        bounds = sorted(
            (math.hypot(max(bx0 - x, 0.0, x - bx1), max(by0 - y, 0.0, y - by1)) - reach, k)
            for k, (bx0, by0, bx1, by1) in enumerate(self._boxes)
        )
        tf = fcl.Transform(np.array([math.cos(theta / 2), 0.0, 0.0, math.sin(theta / 2)]), np.array([x, y, 0.0]))
        for piece in pieces:
            piece.setTransform(tf)
        for bound, k in bounds:
            if bound >= best:
                break
            for piece in pieces:
                best = min(best, fcl.distance(piece, self._obstacles[k], self._request, fcl.DistanceResult()))
                if best <= 0:
                    return best
        return best

    def pusher_move_is_free(self, a: ArrayLike, b: ArrayLike, margin: float) -> bool:
        """True if the pusher alone, moving from pose ``a`` to pose ``b`` by linear interpolation
        of ``(x, y, theta)`` (theta the shorter way), keeps at least ``margin`` from obstacles and
        walls all the way: conservative advancement, as for pushes, with the speed bound
        ``|dxy| + reach |dtheta|`` of any body point per unit of the interpolation parameter."""
        a = np.asarray(a, dtype=float)
        delta = np.asarray(b, dtype=float) - a
        delta[2] = wrap_angle(delta[2])
        speed = math.hypot(delta[0], delta[1]) + self._bodies[_PUSHER][2] * abs(delta[2])
        t = 0.0
        while True:
            d = self.pusher_clearance(a + t * delta)
            if d < margin:
                return False
            if t >= 1.0 or speed == 0.0:
                return True
            t = min(1.0, t + d / speed)

    def push_is_free(self, pose: ArrayLike, twist: ArrayLike, duration: float, edge: int, margin: float) -> bool:
        """True if pushing from ``pose`` with unit-speed ``twist`` for ``duration`` keeps the body
        at least ``margin`` away from obstacles and walls all the way (rule above)."""
        t = 0.0
        while True:
            d = self.clearance(exp_twist(pose, twist, t), edge)
            if d < margin:
                return False
            if t >= duration:
                return True
            t = min(duration, t + d)
