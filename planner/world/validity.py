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
pieces (docs/stack.md, "Solid convex prisms": solid ``Convex`` detects containment, meshes do not). Exact narrow-phase
``fcl.distance`` is called per pair, nearest bounding box first, stopping once no remaining box
can be nearer. (``DynamicAABBTreeCollisionManager.distance`` was tried and over-reported
clearances, e.g. 0.154 m for a true 0.150 m, which would make the rule above unsafe.)
"""

from __future__ import annotations

import math
from collections.abc import Callable

import fcl
import numpy as np
import shapely
from numpy.typing import ArrayLike

from mechanics import transform_points, wrap_angle

from ..model.bodies import body_outline, convex_pieces, edge_frame, pusher_frame_body, pusher_polygon
from .free_space import SCREEN_SHRINK, disk_free_space
from .reach import reach_zone
from .room import Room
from ..model.scene import Scene

__all__ = ["CollisionModel", "advances", "pose_along"]

_HEIGHT = 1.0  # every 2-D shape is a prism over the same z-range
_PUSHER = "pusher"  # the key of the pusher's own body (its frame), beside the per-edge pushers' (the part's)
_PART = "part"  # the key of the part's body
#: Below this turning rate (rad/s, for unit-speed twists) a push is taken as a translation, off by
#: at most 1e-8 t^2 m; above it the centre of rotation is near enough (|v| / omega <= 5e7 m) that
#: rounding its position costs about as little.
_STRAIGHT = 2e-8


def _prism(points: np.ndarray) -> fcl.Convex:
    n = len(points)
    verts = np.vstack([np.c_[points, np.full(n, -_HEIGHT / 2)], np.c_[points, np.full(n, _HEIGHT / 2)]])
    faces = [n, *range(n - 1, -1, -1), n, *range(n, 2 * n)]
    for i in range(n):
        j = (i + 1) % n
        faces += [4, i, j, n + j, n + i]
    return fcl.Convex(verts, n + 2, faces)


def pose_along(pose: ArrayLike, twist: ArrayLike) -> Callable[[float], tuple[float, float, float]]:
    """``t -> pose * exp(twist t)`` (as :func:`mechanics.exp_twist`), for one pose and twist.

    A constant twist turns the body about a centre of rotation fixed in the world (or translates
    it), so each pose is one rotation of the start about that point. In plain floats: this runs at
    every step of conservative advancement, where numpy's per-call overhead would dominate.

    >>> at = pose_along([1.0, 0.0, 0.0], [0.0, 1.0, 1.0])  # a turn about the world origin
    >>> [round(v, 12) for v in at(math.pi / 2)]
    [0.0, 1.0, 1.570796326795]
    >>> at = pose_along([1.0, 0.0, math.pi / 2], [2.0, 0.0, 0.0])  # a translation along body x
    >>> [round(v, 12) for v in at(0.5)]
    [1.0, 1.0, 1.570796326795]
    """
    x, y, theta = (float(v) for v in pose)
    vx, vy, omega = (float(v) for v in twist)
    c, s = math.cos(theta), math.sin(theta)
    if abs(omega) < _STRAIGHT:
        dx, dy = c * vx - s * vy, s * vx + c * vy
        return lambda t: (x + dx * t, y + dy * t, theta + omega * t)
    px, py = -vy / omega, vx / omega  # the centre of rotation, body frame
    rx, ry = -(c * px - s * py), -(s * px + c * py)  # the body origin seen from it, world frame
    cx, cy = x - rx, y - ry

    def at(t: float) -> tuple[float, float, float]:
        ca, sa = math.cos(omega * t), math.sin(omega * t)
        return cx + ca * rx - sa * ry, cy + sa * rx + ca * ry, theta + omega * t

    return at


def advances(clearance: Callable[[float], float], length: float, speed: float, margin: float) -> bool:
    """Conservative advancement: whether a motion over ``t`` in ``[0, length]``, no body point
    of which moves faster than ``speed`` per unit of ``t``, keeps ``clearance(t) >= margin`` all
    the way. From clearance ``d`` nothing can be touched for ``d / speed``, so ``t`` steps by that
    and no obstacle, however thin, is skipped.

    >>> wall = lambda t: 1.0 - t  # the body 1 m from a wall, moving straight at it at 1 m/s
    >>> advances(wall, 0.75, 1.0, 0.2), advances(wall, 0.85, 1.0, 0.2), advances(wall, 0.0, 0.0, 0.2)
    (True, False, True)
    """
    t = 0.0
    while True:
        d = clearance(t)
        if d < margin:
            return False
        if t >= length or speed == 0.0:
            return True
        t = min(length, t + d / speed)


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
        # Per body: its convex pieces, outline vertices (as floats: body_outline) and farthest point
        # from its origin. The body of a push is the part's and the pusher's on the edge, each
        # checked on its own (a union's clearance is the least of its members'): the part's is made
        # once and its clearance at a pose reused for every edge (a part of many edges would
        # otherwise cost as many copies, and a pose checked on each edge as many checks of the part).
        # A pusher's body is made when first asked for: a part of many edges may use few of them.
        self._bodies: dict[int | str, tuple[list[fcl.CollisionObject], list[list], float]] = {}
        p = scene.pusher
        self._slider, self._width, self._depth, self.edges = scene.slider, p.width, p.depth, tuple(edges)
        self.part_pieces = convex_pieces(scene.slider.polygon)
        self._add(_PART, [fcl.CollisionObject(_prism(s)) for s in self.part_pieces], scene.slider.hull)
        self._part_at: tuple[tuple[float, float, float], float, float] | None = None  # pose, clearance, enough
        self._pieces: dict[int, list[np.ndarray]] = {}
        alone = pusher_frame_body(p.width, p.depth)
        self._add(_PUSHER, [fcl.CollisionObject(_prism(alone))], alone)
        self._request = fcl.DistanceRequest()
        # Where the CF may be: the disk about it inside the part must stay clear (planner.world.free_space).
        slider = scene.slider
        self._cf = slider.cf
        self.cf_room = disk_free_space(scene, slider.cf_depth * (1.0 - SCREEN_SHRINK))
        shapely.prepare(self.cf_room)
        self.room = Room(scene.obstacles, scene.workspace)
        # With an arm, the pusher frame must stay in its reach zone: a rim the clearances count as
        # they count a wall (planner.world.reach).
        self.zone = None if scene.robot is None else reach_zone(scene.robot)
        self.robot = None if scene.robot is None else scene.robot.model
        # The obstacles tall enough for the arm's links to meet (none, mostly: planner.world.reach).
        tall = [] if self.zone is None else [o for o, h in zip(scene.obstacles, scene.obstacle_heights)
                                             if h > self.zone.floor]
        self._tall = shapely.union_all(tall) if tall else None
        if self._tall is not None:
            shapely.prepare(self._tall)
        # Per body, the pusher frame in its frame and how fast it turns (2 over its diameter, rad/m).
        self._holds: dict[int | str, tuple[float, float, float, float]] = {}

    def _add(self, key: int | str, pieces: list[fcl.CollisionObject], outline: np.ndarray) -> None:
        self._bodies[key] = (pieces, outline.tolist(), float(np.linalg.norm(outline, axis=1).max()))

    def body_pieces(self, edge: int) -> list[np.ndarray]:
        """The convex pieces of the part and of the pusher on ``edge`` (slider frame)."""
        if edge not in self._pieces:
            if edge not in self.edges:
                raise KeyError(edge)
            pusher = convex_pieces(pusher_polygon(self._slider, edge, self._width, self._depth))
            self._pieces[edge] = self.part_pieces + pusher
            self._add(edge, [fcl.CollisionObject(_prism(s)) for s in pusher],
                      body_outline(self._slider, edge, self._width, self._depth)[1])
        return self._pieces[edge]

    def clearance(self, pose: ArrayLike, edge: int) -> float:
        """Distance from the body (slider and pusher on ``edge``) to the nearest obstacle or
        workspace wall; <= 0 if colliding."""
        return self._clearance(pose, edge)

    def pusher_clearance(self, pose: ArrayLike) -> float:
        """The same for the pusher alone, ``pose`` being its own frame's (:func:`pusher_frame_body`)."""
        return self._clearance(pose, _PUSHER)

    def part_clearance(self, pose: ArrayLike, enough: float = math.inf) -> float:
        """The same for the part alone at ``pose``; where it exceeds ``enough``, possibly only a
        lower bound that is itself at least ``enough`` (cheaper far from everything)."""
        x, y, theta = pose
        return self._body_clearance((float(x), float(y), float(theta)), _PART, enough, [])

    def surely_blocked(self, poses: ArrayLike) -> np.ndarray:
        """Per pose (shape ``(..., 3)``), True if the part itself certainly overlaps an obstacle or
        leaves the workspace there: its CF lies outside where the disk about the CF inside the part
        can be. A cheap, vectorised screen: it never says True of a pose with clearance.

        >>> from planner import load_scene
        >>> scene = load_scene("scenes/corridor.yaml")
        >>> CollisionModel(scene, [0]).surely_blocked([scene.start, [0.0, 0.0, 0.0]]).tolist()
        [False, True]
        """
        return self.cf_blocked(transform_points(self._cf, poses))

    def cf_blocked(self, points: ArrayLike) -> np.ndarray:
        """:meth:`surely_blocked` of the poses whose CF is at each of ``points`` (shape
        ``(..., 2)``, world), whatever their heading."""
        p = np.asarray(points, dtype=float)
        return ~shapely.contains_xy(self.cf_room, p[..., 0], p[..., 1])

    def is_clear(self, pose: ArrayLike, edge: int, distance: float) -> bool:
        """Whether :meth:`clearance` exceeds ``distance``; cheaper where the body is far from
        everything (the search's validity test, at every propagation step)."""
        return self._clearance(pose, edge, distance) > distance

    def _clearance(self, pose: ArrayLike, key: int | str, enough: float = math.inf) -> float:
        """The clearance of the pusher alone (``key`` :data:`_PUSHER`) or of the part with the pusher
        on edge ``key`` where it is below ``enough``; where it is not, possibly only a lower bound
        that is itself at least ``enough``."""
        x, y, theta = pose
        at = (float(x), float(y), float(theta))
        placed: list = []  # the pose's fcl transform and obstacles nearest first, made once if asked for
        if key == _PUSHER:
            body = self._body_clearance(at, _PUSHER, enough, placed)
            return body if self.zone is None else min(body, self._zone_clearance(at, _PUSHER))
        if key not in self._bodies:
            self.body_pieces(key)
        zone = math.inf if self.zone is None else self._zone_clearance(at, key)
        if zone <= 0:
            return zone
        if self._part_at is not None and self._part_at[0] == at and (self._part_at[1] < self._part_at[2]
                                                                     or self._part_at[2] >= enough):
            part = self._part_at[1]  # exact, or a lower bound at least as high as asked
        else:
            part = self._body_clearance(at, _PART, enough, placed)
            self._part_at = (at, part, enough)
        # Below enough the least is exact; else each is a lower bound at least min(part, enough).
        return part if part <= 0 else min(part, zone, self._body_clearance(at, key, min(part, zone, enough), placed))

    def out_of_reach(self, pose: ArrayLike, edges, room: float = 0.0, near: Callable[[float], float] | None = None) -> str | None:
        """Why the arm cannot hold the pusher on any of ``edges`` with the part at ``pose`` (with
        ``room`` to spare), or None if it can on one or there is no arm. With ``near``, the part
        may be anywhere within ``near(reach)`` of ``pose`` for a point ``reach`` from its origin
        (:meth:`planner.model.scene.Scene.tolerance_slack`): the zone's clearance is a lower bound
        on how far the body moves, inside or out."""
        if self.zone is None:
            return None
        at = tuple(float(v) for v in pose)
        for e in edges:
            self.body_pieces(e)
        least = {e: room - (near(self._bodies[e][2]) if near else 0.0) for e in edges}
        if any(self._zone_clearance(at, e) > least[e] for e in edges):
            return None
        if any(self._zone_clearance(at, e, shadow=False) > least[e] for e in edges):
            return (f"out of the {self.robot} arm's reach: its links would pass over an obstacle taller than the "
                    f"{self.zone.floor:.3f} m they keep above the table (docs/arm.md)")
        return f"out of the {self.robot} arm's reach: its reach zone is {self.zone.text()} (docs/arm.md)"

    def _zone_clearance(self, pose: tuple[float, float, float], key: int | str, shadow: bool = True) -> float:
        """The reach zone's clearance (:meth:`~planner.world.reach.ReachZone.clearance`) of the
        pusher of body ``key`` at ``pose`` (an arm's model only), and with ``shadow`` of the arm's
        links over the obstacles taller than they keep above the table."""
        if key not in self._holds:
            outline = np.array(self._bodies[key][1])
            turn = 2.0 / float(np.linalg.norm(outline[:, None] - outline[None], axis=2).max())
            if key == _PUSHER:
                self._holds[key] = (0.0, 0.0, 0.0, turn)
            else:
                self._holds[key] = (*edge_frame(self._slider, key).tolist(), turn)
        hx, hy, hphi, turn = self._holds[key]
        x, y, theta = pose
        c, s = math.cos(theta), math.sin(theta)
        px, py = x + c * hx - s * hy, y + s * hx + c * hy
        zone = self.zone.clearance((px, py, theta + hphi), turn)
        if self._tall is None or zone <= 0 or not shadow:
            return zone
        # The arm's links over the tall obstacles: the points of the segment they stand within
        # move no faster than its ends (planner.world.reach.ReachZone.shadow).
        # (A float: a numpy one's comparisons give numpy booleans, which OMPL's callbacks refuse.)
        shadow = float(shapely.distance(shapely.LineString(self.zone.shadow(px, py)), self._tall)) - self.zone.spread
        return min(zone, shadow / self.zone.shadow_rate)

    def _body_clearance(self, pose: tuple[float, float, float], key: int | str, enough: float, placed: list) -> float:
        """:meth:`_clearance` of body ``key`` alone; ``placed`` holds what the bodies at ``pose``
        share (filled by the first that needs it)."""
        pieces, hull, reach = self._bodies[key]
        x, y, theta = pose
        xmin, ymin, xmax, ymax = self.workspace
        # The body lies in the disc of radius reach about (x, y): lower bounds, walls and obstacles.
        best = min(x - xmin, xmax - x, y - ymin, ymax - y) - reach
        if best < enough:
            # The workspace is convex, so the body's distance to its walls is attained at a vertex.
            c, s = math.cos(theta), math.sin(theta)
            wx = [x + c * px - s * py for px, py in hull]
            wy = [y + s * px + c * py for px, py in hull]
            best = min(min(wx) - xmin, xmax - max(wx), min(wy) - ymin, ymax - max(wy))
        if best <= 0 or not self._obstacles:
            return best
        if not placed:
            placed += [fcl.Transform(np.array([math.cos(theta / 2), 0.0, 0.0, math.sin(theta / 2)]),
                                     np.array([x, y, 0.0])),
                       sorted((math.hypot(max(bx0 - x, 0.0, x - bx1), max(by0 - y, 0.0, y - by1)), k)
                              for k, (bx0, by0, bx1, by1) in enumerate(self._boxes))]
        tf, nearest = placed
        for piece in pieces:
            piece.setTransform(tf)
        for distance, k in nearest:
            if distance - reach >= min(best, enough):  # no obstacle left can be nearer, or matter
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
        return advances(lambda t: self.pusher_clearance(a + t * delta), 1.0, speed, margin)

    def push_is_free(self, pose: ArrayLike, twist: ArrayLike, duration: float, edge: int, margin: float) -> bool:
        """True if pushing from ``pose`` with unit-speed ``twist`` for ``duration`` keeps the body
        at least ``margin`` away from obstacles and walls all the way (rule above)."""
        at = pose_along(pose, twist)
        return advances(lambda t: self._clearance(at(t), edge), duration, 1.0, margin)
