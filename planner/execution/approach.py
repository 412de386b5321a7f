"""The pusher's way to a plan's first contact from wherever it is: at the start of a run, or after
it stopped to re-plan.

A plan begins with the pusher on the part. A robot does not: it starts a little behind the first
contact and moves in (:func:`lead_in_pose`), so that a part that is not quite where the plan says
is met by the face, not overlapped by it. After a re-plan the pusher is wherever it stopped, by
the part; it backs off along its own -x (away from the face it was pushing), goes to the standoff
pose in front of the new first edge (straight, or walking round the part as a transit does,
:class:`~planner.actions.transit.TransitPlanner`) and moves in. Every in-plane move is checked
against obstacles and walls by conservative advancement; every move but the last (the move in)
is also kept off the part, sampled every :data:`PART_STEP` (the pusher's body shrunk by
:data:`GRAZE`, so that a pusher leaving a face it was pressing, a fraction of a millimetre into
it in a simulation, is not taken for one going through the part). Where the scene's arm lifts the
pusher (``transit: lift``) and no way on the table is free, the pusher backs off, is lifted over
to the standoff pose and moves in, as a lift transit does: only the two moves on the table are
checked.
"""

from __future__ import annotations

import math

import numpy as np
import shapely
from numpy.typing import ArrayLike

from mechanics import wrap_angle

from ..actions.transit import TransitPlanner, backed_off, edge_contact_pose, in_plane_moves, path_duration, standoff
from ..model.bodies import pusher_frame_body, slider_at
from ..model.plan import Plan
from ..model.segments import Transit
from ..model.scene import Scene
from ..world.validity import CollisionModel

__all__ = ["CLEARANCE", "GRAZE", "LEAD_IN", "PART_STEP", "approach", "first_edge", "free_back_off", "lead_in_pose"]

#: How far behind the first contact a run begins, m: more than the start errors a perception
#: system makes (a centimetre or two), so the part is met, not overlapped.
LEAD_IN = 0.03
#: Spacing of the poses at which a move is checked against the part, m (and radians per part radius).
PART_STEP = 0.001
#: How much a move may graze the part, m.
GRAZE = 0.001
#: Least distance of the pusher's moves from obstacles and walls, m: conservative advancement
#: needs one above zero to end (it steps by the clearance, which a grazing move runs down to 0).
CLEARANCE = 0.0005


def first_edge(plan: Plan) -> int:
    """The edge the pusher is on when ``plan`` begins."""
    return plan.segments[0].from_edge


def lead_in_pose(scene: Scene, model: CollisionModel, plan: Plan) -> np.ndarray:
    """Where a run's pusher starts: :data:`LEAD_IN` behind ``plan``'s first contact, or nearer
    (halving down to the transits' standoff) where a wall or obstacle is in the way."""
    contact = edge_contact_pose(scene.slider, first_edge(plan), plan.start)
    back = free_back_off(scene, model, contact, LEAD_IN)
    return backed_off(contact, standoff(scene) if back is None else back)


def free_back_off(scene: Scene, model: CollisionModel, pose: ArrayLike, distance: float) -> float | None:
    """The farthest of ``distance``, its half, its quarter, ... above the transits' standoff by
    which the pusher at ``pose`` backs straight off along its own -x keeping :data:`CLEARANCE` from
    obstacles and walls; None if none is."""
    while distance > standoff(scene):
        if model.pusher_move_is_free(backed_off(pose, distance), pose, CLEARANCE):
            return distance
        distance /= 2
    return None


def _off_part(scene: Scene, part: shapely.Polygon, a: np.ndarray, b: np.ndarray) -> bool:
    """The pusher moving from ``a`` to ``b`` (linear in ``(x, y, theta)``) never touches ``part``."""
    body = shapely.Polygon(pusher_frame_body(scene.pusher.width, scene.pusher.depth)).buffer(-GRAZE, join_style="mitre")
    turn = float(wrap_angle(b[2] - a[2]))
    span = math.hypot(*(b[:2] - a[:2])) + abs(turn) * scene.slider.radius
    for u in np.linspace(0.0, 1.0, max(2, math.ceil(span / PART_STEP) + 1))[1:]:
        pose = a + u * np.array([*(b[:2] - a[:2]), turn])
        if slider_at(body, pose).intersects(part):
            return False
    return True


def approach(scene: Scene, model: CollisionModel, transits: TransitPlanner | None, pusher: ArrayLike,
             part: ArrayLike, edge: int, edges: list[int], behind: float = 0.0,
             actual: ArrayLike | None = None, airborne: bool = False) -> Transit | None:
    """The pusher's collision-checked path from its pose ``pusher`` to the contact on ``edge`` of
    the part at ``part`` (module docstring), as a transit (mode ``'plane'``, or ``'lift'`` where
    the scene lifts), or None if none of the ways tried is free. ``edges`` are those the pusher may be put on (for a walk round).

    The ways, in order: straight to the standoff pose and in; backed off (by the transits'
    standoff, three times it, or :data:`LEAD_IN`: a pusher stopped after a knock may be on the
    part, and its backing off is not checked against the part), then so, or round the part from
    the standoff pose of the edge of ``edges`` nearest the pusher as a transit goes. The standoff
    in front of ``edge`` is tried at a half and a quarter of the transits' where a wall is close
    behind the edge.

    To square a part (:mod:`.squaring`), ``part`` is where it will be and ``actual`` where it is:
    the moves but the last keep off it there too, and the standoff poses are ``behind`` (m)
    farther back, by as much as its face sticks out towards the pusher.

    A pusher stopped ``airborne`` (on a lift's flight) is not put down where it is, which may be
    over the part: it flies on to the standoff pose and comes down there (a lift transit whose
    first move has no length; the caller keeps it at its height until the flight,
    :meth:`.tracker.Tracker.pusher_at`)."""
    pusher, part = np.asarray(pusher, dtype=float), np.asarray(part, dtype=float)
    gap = standoff(scene)
    contact = edge_contact_pose(scene.slider, edge, part)
    fronts = [backed_off(contact, near + behind) for near in (gap, gap / 2, gap / 4)]
    ways = [[pusher, front, contact] for front in fronts]
    walks = []
    # (A session with less friction, after slip, may not push the edge the pusher was on: no walk to it.)
    if transits is not None and edge in transits.edges:
        others = {e: backed_off(edge_contact_pose(scene.slider, e, part), gap)
                  for e in edges if e != edge and e in transits.edges}
        if others:
            near = min(others, key=lambda e: np.linalg.norm(others[e][:2] - pusher[:2]))
            walk = transits.find(part, near, edge)
            walks = [] if walk is None else [list(walk.pusher_path[1:])]
    # Backing off farther where the pusher, stopped after a knock, is still on the part.
    for back in (gap, 3 * gap, LEAD_IN):
        retreat = backed_off(pusher, back)
        ways += [[pusher, retreat, front, contact] for front in fronts] + [[pusher, retreat, *w] for w in walks]
    body = slider_at(scene.slider.polygon, part)
    if actual is not None:
        body = body.union(slider_at(scene.slider.polygon, actual))
    reach = float(np.linalg.norm(pusher_frame_body(scene.pusher.width, scene.pusher.depth), axis=1).max())
    for way in [] if airborne else ways:
        way = [p for k, p in enumerate(way) if k == 0 or np.abs(p - way[k - 1]).max() > 1e-12]
        moves = list(zip(way, way[1:]))
        backing = len(way) > 3  # the first move backs straight off, away from the face: not checked on the part
        if all(model.pusher_move_is_free(a, b, CLEARANCE) for a, b in moves) and all(
                _off_part(scene, body, a, b) for a, b in moves[int(backing):-1]):
            path = np.array(way)
            return Transit(edge, edge, "plane", path, path_duration(path, reach), part.copy())
    if transits is not None and transits.mode == "lift":
        for back in (0.0,) if airborne else (gap, 3 * gap, LEAD_IN):
            for front in fronts:
                path = np.array([pusher, backed_off(pusher, back), front, contact])
                lift = Transit(edge, edge, "lift", path, path_duration(path, reach), part.copy())
                if all(model.pusher_move_is_free(a, b, CLEARANCE) for a, b in in_plane_moves(lift)[int(airborne):]):
                    return lift
    return None
