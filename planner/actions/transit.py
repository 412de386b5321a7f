"""Moving the pusher from one edge of the part to another while the part stands still.

Lynch & Mason (1996, §4) switch the pushed edge at any time, with an arm that lifts the pusher
over everything; how a pusher that stays on the table gets round the part was left open. Here
each switch carries the pusher's own collision-checked path (:class:`~planner.model.segments.Transit`),
in one of two modes:

* ``'lift'``: back straight off the edge (along the pusher's own -x) by the *standoff*, fly to
  the standoff pose in front of the new edge, move straight in. The two in-plane pieces must be
  clear of obstacles and walls; the airborne piece is not checked.
* ``'plane'``: walk round the part. The pusher backs off onto the boundary of the part's convex
  hull grown by the standoff, follows it (along the hull's edges, and turning about its corners
  with the face tangent to the grown boundary) the shorter of the two ways round that is free,
  and moves in. With the ``transit`` option ``lift`` either may be used, whichever is quicker.

Why a walk round never touches the part: at every pose the pushing face lies on a line that
supports the grown hull, so the whole part lies beyond the face, at least ``standoff x
cos(ARC_STEP)`` away (the corners' arcs are followed by chords of at most :data:`ARC_STEP`,
along which the face turns linearly); the body lies behind the face. Only the two contact poses
touch the part. Obstacles and walls are checked by conservative advancement with the pusher's
own body (:meth:`CollisionModel.pusher_move_is_free`), so no thin obstacle is skipped.

Paths depend only on the part's pose and the two edges; they are cached, so the search and the
plan's segments find the same one.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from mechanics import Slider, compose, transform_points, wrap_angle

from ..model.bodies import edge_frame, pusher_frame_body
from ..model.segments import Transit
from ..model.scene import Scene
from ..world.validity import CollisionModel

__all__ = ["AIRBORNE", "ARC_STEP", "TransitPlanner", "backed_off", "contact_pose", "edge_contact_pose", "in_plane_moves", "path_duration", "piece_times",
           "standoff", "transit_pieces", "transit_poses"]

#: Largest turn of the pusher between two poses of a walk round a corner of the part.
ARC_STEP = math.radians(10.0)
#: The airborne piece of a lift's path: retreat -> approach.
AIRBORNE = 1
_CACHE = 4096  # transits kept; the search asks again for those on its solution path


def _steps(path: np.ndarray) -> np.ndarray:
    """Differences of consecutive poses, the angle the shorter way round."""
    step = np.diff(path, axis=0)
    step[:, 2] = wrap_angle(step[:, 2])
    return step


def _piece_times(step: np.ndarray, reach: float) -> np.ndarray:
    """Time of each piece with no point within ``reach`` of the pusher's origin faster than 1 m/s."""
    return np.hypot(step[:, 0], step[:, 1]) + reach * np.abs(step[:, 2])


def piece_times(path: ArrayLike, reach: float) -> np.ndarray:
    """Time of each piece of ``path`` (pusher poses, linear interpolation) with no point of a body
    of radius ``reach`` about the pusher's origin faster than 1 m/s: ``|dxy| + reach |dtheta|``.

    >>> piece_times([[0, 0, 0], [0.3, 0.4, 0], [0.3, 0.4, np.pi / 2]], 0.02).round(4).tolist()
    [0.5, 0.0314]
    """
    return _piece_times(_steps(np.asarray(path, dtype=float)), reach)


def path_duration(path: ArrayLike, reach: float) -> float:
    """Time to follow ``path`` (pusher poses, linear interpolation) with no point of a body of
    radius ``reach`` about the pusher's origin faster than 1 m/s: ``sum |dxy| + reach |dtheta|``.

    >>> path_duration([[0, 0, 0], [0.3, 0.4, 0], [0.3, 0.4, np.pi / 2]], 0.02)
    0.5314...
    """
    return float(np.sum(piece_times(path, reach)))


def contact_pose(part_pose: ArrayLike, point: ArrayLike, normal: ArrayLike, gap: float = 0.0) -> np.ndarray:
    """World pose of the pusher frame with its face centre ``gap`` outside ``point`` (slider
    frame) along the outward ``normal``, facing the part, with the part at ``part_pose``.

    >>> contact_pose([1.0, 0.0, 0.0], [0.0, -0.5], [0.0, -1.0], gap=0.1).round(12).tolist()
    [1.0, -0.6, 1.570796326795]
    """
    local = np.asarray(point, dtype=float) + gap * np.asarray(normal, dtype=float)
    x, y = transform_points(local[None], part_pose)[0]
    return np.array([x, y, float(wrap_angle(math.atan2(-normal[1], -normal[0]) + part_pose[2]))])


def backed_off(pose: ArrayLike, distance: float) -> np.ndarray:
    """The pusher frame's pose ``distance`` behind ``pose``, along its own -x.

    >>> backed_off([1.0, 0.0, math.pi / 2], 0.1).round(12).tolist()
    [1.0, -0.1, 1.570796326795]
    """
    x, y, theta = np.asarray(pose, dtype=float)
    return np.array([x - distance * math.cos(theta), y - distance * math.sin(theta), theta])


def edge_contact_pose(slider: Slider, edge: int, part_pose: ArrayLike) -> np.ndarray:
    """World pose of the pusher frame pushing ``edge``: face centred on the edge's midpoint, flush,
    facing the part (:func:`planner.model.bodies.pusher_polygon`), with the part at ``part_pose``.

    >>> block = Slider([[-1, 0], [1, 0], [1, 1], [-1, 1]])
    >>> edge_contact_pose(block, 0, [0.0, 0.0, 0.0]).round(12).tolist()
    [0.0, 0.0, 1.570796326795]
    """
    return compose(part_pose, edge_frame(slider, edge))


def transit_pieces(transit: Transit) -> list[tuple[np.ndarray, bool]]:
    """The path of the pusher's face centre on ``transit`` as world polylines, each with whether
    it is airborne: the whole path for a walk round the part; for a lift, the backing off, the
    flight and the moving in (the face centre goes straight between poses, their ``(x, y)``
    being interpolated linearly).

    >>> lift = Transit(0, 2, "lift", np.array([[0, 0, 0], [-1, 0, 0], [3, 0, 3], [2, 0, 3]]), 6.0, np.zeros(3))
    >>> [(xy[:, 0].tolist(), up) for xy, up in transit_pieces(lift)]
    [([0.0, -1.0], False), ([-1.0, 3.0], True), ([3.0, 2.0], False)]
    """
    xy = np.asarray(transit.pusher_path, dtype=float)[:, :2]
    if transit.mode == "lift":
        return [(xy[: AIRBORNE + 1], False), (xy[AIRBORNE: AIRBORNE + 2], True), (xy[AIRBORNE + 1:], False)]
    return [(xy, False)]


def in_plane_moves(transit: Transit) -> list[tuple[np.ndarray, np.ndarray]]:
    """The moves of ``transit``'s pusher on the table, each from one pose of its path to the next
    (a lift's flight is not one).

    >>> lift = Transit(0, 2, "lift", np.array([[0, 0, 0], [-1, 0, 0], [3, 0, 3], [2, 0, 3]]), 6.0, np.zeros(3))
    >>> [(a[0].item(), b[0].item()) for a, b in in_plane_moves(lift)]
    [(0.0, -1.0), (3.0, 2.0)]
    """
    path = np.asarray(transit.pusher_path, dtype=float)
    if transit.mode == "lift":
        return [(path[AIRBORNE - 1], path[AIRBORNE]), (path[AIRBORNE + 1], path[AIRBORNE + 2])]
    return list(zip(path, path[1:]))


def transit_poses(transit: Transit, body: ArrayLike, times: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """World poses ``(n, 3)`` of the pusher frame ``times`` (s) into ``transit``, and whether
    each is airborne.

    Between path poses the pusher moves by linear interpolation of ``(x, y, theta)``, theta the
    shorter way, each piece taking the time :func:`planner.actions.transit.path_duration` gives it (no
    point of ``body``, the pusher's outline in its own frame, faster than 1 m/s); the pace is
    stretched to the transit's ``duration`` in case a plan file states another. Only the inside
    of a lift's middle piece is airborne: its ends, the standoff poses, are on the table.

    >>> lift = Transit(0, 2, "lift", np.array([[0, 0, 0], [-1, 0, 0], [3, 0, 0], [2, 0, 0]]), 6.0, np.zeros(3))
    >>> poses, lifted = transit_poses(lift, [[0.0, 0.0]], [0.5, 1.0, 3.0, 5.0, 5.5])
    >>> poses[:, 0].tolist(), lifted.tolist()
    ([-0.5, -1.0, 1.0, 3.0, 2.5], [False, False, True, False, False])
    """
    path = np.asarray(transit.pusher_path, dtype=float)
    step = _steps(path)
    pieces = _piece_times(step, np.linalg.norm(np.asarray(body, dtype=float), axis=1).max())
    ends = np.cumsum(pieces)
    scale = ends[-1] / transit.duration if transit.duration > 0 else 0.0
    t = np.clip(np.asarray(times, dtype=float) * scale, 0.0, ends[-1])
    k = np.minimum(np.searchsorted(ends, t, side="right"), len(pieces) - 1)  # zero-length pieces are skipped
    into = t - (ends[k] - pieces[k])
    u = np.divide(into, pieces[k], out=np.ones_like(t), where=pieces[k] > 0)
    lifted = (transit.mode == "lift") & (k == AIRBORNE) & (u > 0) & (u < 1)
    return path[k] + u[:, None] * step[k], lifted


def standoff(scene: Scene) -> float:
    """How far the pusher backs off the part to go round it or be lifted: a tenth of the part's
    radius, far enough that a face turning by up to :data:`ARC_STEP` about a hull corner stays off
    the part, near enough that the walk round stays short."""
    return scene.slider.radius / 10.0


class TransitPlanner:
    """Transits between the allowed edges of ``scene``'s part at any of its poses.

    Parameters
    ----------
    scene : Scene
    edges : sequence of int
        The edges the pusher may be placed on.
    model : CollisionModel
        Checks the pusher's own body against obstacles and walls.
    margin : float
        Clearance every in-plane move must keep.
    mode : str
        The ``transit`` option: ``'plane'`` (walks round the part only) or ``'lift'`` (lifts too).
    """

    def __init__(self, scene: Scene, edges, model: CollisionModel, margin: float, mode: str):
        self.mode = mode
        self.model, self.margin = model, margin
        self.standoff = standoff(scene)
        self.reach = float(np.linalg.norm(pusher_frame_body(scene.pusher.width, scene.pusher.depth), axis=1).max())
        slider = scene.slider
        self._hull = slider.hull  # counter-clockwise
        along = np.roll(self._hull, -1, axis=0) - self._hull
        along /= np.linalg.norm(along, axis=1)[:, None]
        self._normal = np.c_[along[:, 1], -along[:, 0]]  # outward
        self._sides = {}  # edge -> (hull side, midpoint, outward normal)
        for e in edges:
            a, b = slider.edge(e)
            mid, out = (a + b) / 2, -slider.inward_normal(e)
            self._sides[e] = (slider.hull_side(e), mid, out)
        self._cache: dict[tuple, Transit | None] = {}

    @property
    def edges(self) -> tuple[int, ...]:
        """The edges it finds transits between."""
        return tuple(self._sides)

    def find(self, part_pose: ArrayLike, a: int, b: int) -> Transit | None:
        """The quickest free transit from edge ``a`` to edge ``b`` with the part at ``part_pose``, or None."""
        key = (tuple(float(v) for v in part_pose), a, b)
        if key not in self._cache:
            if len(self._cache) >= _CACHE:
                self._cache.clear()
            pose = np.asarray(part_pose, dtype=float)
            candidates = [self._walk(pose, a, b, +1), self._walk(pose, a, b, -1)]
            if self.mode == "lift":
                candidates.append(self._lift(pose, a, b))
            # Collision checks cost far more than building paths: check the quickest first.
            candidates.sort(key=lambda t: t.duration)
            self._cache[key] = next((t for t in candidates if self._is_free(t)), None)
        return self._cache[key]

    def _is_free(self, transit: Transit) -> bool:
        """Every in-plane piece of ``transit`` keeps the margin from obstacles and walls."""
        return all(self.model.pusher_move_is_free(p, q, self.margin) for p, q in in_plane_moves(transit))

    def _transit(self, pose: np.ndarray, a: int, b: int, mode: str, path: list[np.ndarray]) -> Transit:
        return Transit(a, b, mode, np.array(path), path_duration(path, self.reach), pose.copy())

    def _lift(self, pose: np.ndarray, a: int, b: int) -> Transit:
        (_, ma, na), (_, mb, nb) = self._sides[a], self._sides[b]
        path = [contact_pose(pose, ma, na), contact_pose(pose, ma, na, self.standoff),
                contact_pose(pose, mb, nb, self.standoff), contact_pose(pose, mb, nb)]
        return self._transit(pose, a, b, "lift", path)

    def _walk(self, pose: np.ndarray, a: int, b: int, turn: int) -> Transit:
        """Round the part counter-clockwise (``turn = +1``) or clockwise (``-1``)."""
        (ja, ma, na), (jb, mb, nb) = self._sides[a], self._sides[b]
        g, n = self.standoff, len(self._hull)
        path = [contact_pose(pose, ma, na), contact_pose(pose, ma, na, g)]
        side = ja
        while side != jb:
            corner = (side + 1) % n if turn > 0 else side
            following = (side + turn) % n
            path.append(contact_pose(pose, self._hull[corner], self._normal[side], g))
            # Turn about the corner from one side's normal to the next's (the exterior angle).
            start = math.atan2(self._normal[side][1], self._normal[side][0])
            sweep = float(wrap_angle(math.atan2(self._normal[following][1], self._normal[following][0]) - start))
            steps = max(1, math.ceil(abs(sweep) / ARC_STEP))
            for phi in start + sweep * np.arange(1, steps + 1) / steps:
                path.append(contact_pose(pose, self._hull[corner], (math.cos(phi), math.sin(phi)), g))
            side = following
        path += [contact_pose(pose, mb, nb, g), contact_pose(pose, mb, nb)]
        return self._transit(pose, a, b, "plane", path)
