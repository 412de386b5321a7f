"""Squaring a part that sits askew where no flush push has room for the pusher.

A part turned a few degrees off its plan in a narrow corridor may leave no room for the pusher
flush on any face: a pusher as wide as the face, turned with it, reaches into the wall. A flat
pusher driven straight at its planned heading then meets the face's corner nearest it first and
turns the part flush against itself (the open loop's runs in MuJoCo show it). While it turns, the
part also moves sideways, and which way depends on the face: it turns about a point near the
face's other corner, the one the pusher reaches last. So in a corridor pushing one face squares
the part into the wall and pushing the opposite face squares it away from it.

:func:`squared` predicts where the part ends up, turning about that far corner: the least the
pusher must advance to make the face flush (a centre of rotation farther away needs more), and
a good guess of the sideways move. The tracker (:mod:`.tracker`, "Squaring") chooses the face
whose squared part keeps most room, checks the way there, drives the pusher to the squared part's
contact and then observes and re-plans: the squared part has room for a flush pusher again. The
prediction only chooses the face and how far to drive: what happened is observed afterwards.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from mechanics import Slider, transform_points, wrap_angle

from ..model.bodies import edge_frame

__all__ = ["squared"]


def squared(slider: Slider, pose: ArrayLike, edge: int, heading: float) -> tuple[np.ndarray, float]:
    """Where the part at ``pose`` is once a flat pusher, driven straight against ``edge`` as if the
    part had ``heading`` (rad), has turned it flush, assuming it turns about the edge's corner the
    pusher reaches last (module docstring); and how far the pusher advances from its first touch
    to there, m (the edge's width times the sine of the turn).

    A 2 x 1 block turned 0.1 rad, squared by a pusher pushing its bottom edge straight up: the
    corner the pusher meets first is the bottom-left one; the block turns about the bottom-right
    one, at ``(cos 0.1, sin 0.1)``, so its centre, 1 to the left of that corner once square, is at
    ``(cos 0.1 - 1, sin 0.1)``, and the pusher advances ``2 sin 0.1``:

    >>> block = Slider([[-1, 0], [1, 0], [1, 1], [-1, 1]])
    >>> pose, advance = squared(block, [0.0, 0.0, 0.1], 0, 0.0)
    >>> pose.round(6).tolist(), round(advance, 6)
    ([-0.004996, 0.099833, 0.0], 0.199667)

    Not turned, it is where it was and the pusher advances nothing:

    >>> pose, advance = squared(block, [0.5, 0.5, 0.0], 0, 0.0)
    >>> pose.tolist(), round(advance, 12)
    ([0.5, 0.5, 0.0], 0.0)
    """
    pose = np.asarray(pose, dtype=float)
    turn = float(wrap_angle(pose[2] - heading))
    corners = transform_points(np.asarray(slider.edge(edge), dtype=float), pose)
    push = heading + float(edge_frame(slider, edge)[2])  # the pusher's +x, as the plan has the part
    along = np.array([math.cos(push), math.sin(push)])
    near, far = sorted(corners, key=lambda p: float(p @ along))
    # The centre turned back by the turn about the far corner.
    centre = far + transform_points((pose[:2] - far)[None], [0.0, 0.0, -turn])[0]
    return np.array([*centre, float(wrap_angle(heading))]), float((far - near) @ along)
