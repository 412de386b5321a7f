"""Whether a part's segments keep clear of what a scene holds, swept by the planner's own collision
checks (:class:`~planner.world.validity.CollisionModel`, conservative advancement).

A push is swept with the part and the pusher on its edge, at the push's own speed bound (a plan
file's twists need not be scaled to the planner's unit speed); a transit or a transfer, move by
move of the pusher on the table (a lift's flight is not one, :func:`~planner.actions.transit.in_plane_moves`).
Clear means never nearer than :data:`CLEARANCE` part radii. Two checks ask it: a loaded plan
against its scene's obstacles and walls (:mod:`.fit`), and each move of a plan of several parts
against each other part where it stands (:mod:`.verify`).
"""

from __future__ import annotations

from collections.abc import Sequence

from ..actions.transit import in_plane_moves
from ..model.bodies import body_outline, top_speed
from ..model.scene import Scene
from ..model.segments import Push, Transfer, Transit
from ..world.validity import CollisionModel, advances, pose_along

__all__ = ["CLEARANCE", "body_speed", "collision_model", "is_clear"]

#: Least clearance (in part radii) a segment must keep to be clear: a millionth. The planner's
#: searches keep more (their margin, or half a propagation step at every state), so any plan of
#: theirs is clear; one that touches a wall is not.
CLEARANCE = 1e-6


def body_speed(scene: Scene, push: Push) -> float:
    """The largest speed of any point of the body (``scene``'s one part and the pusher) under ``push``'s twist."""
    return float(top_speed(body_outline(scene.slider, push.edge, scene.pusher.width, scene.pusher.depth), push.twist))


def collision_model(scene: Scene, segments: Sequence[Push | Transit]) -> CollisionModel:
    """The collision model of ``scene`` (of one part) with a body for every edge ``segments`` push."""
    return CollisionModel(scene, sorted({s.edge for s in segments if isinstance(s, Push)}))


def is_clear(scene: Scene, model: CollisionModel, segment: Push | Transit | Transfer) -> bool:
    """Whether ``segment`` of ``scene``'s one part keeps :data:`CLEARANCE` part radii from
    ``model``'s obstacles and walls all the way (module docstring)."""
    margin = CLEARANCE * scene.slider.radius
    if isinstance(segment, Push):
        at = pose_along(segment.start, segment.twist)
        return advances(lambda t: model.clearance(at(t), segment.edge), segment.duration, body_speed(scene, segment),
                        margin)
    return all(model.pusher_move_is_free(a, b, margin) for a, b in in_plane_moves(segment))
