"""From an OMPL control path to a plan's segments.

The path's controls are copied out at once (its states live in C++), consecutive equal pushes
merged into one (:func:`~planner.model.segments.append_push`), and a switch control becomes the transit the pusher takes there.
The poses are composed from the start by the exact exponential, so the plan's pushes chain
exactly; the goal test's connection from the path's last state (:class:`~planner.search.goal.PushGoal`)
is then re-anchored where the composed path ends, which differs from the tree's state by rounding
only.
"""

from __future__ import annotations

import numpy as np

from ..actions.controls import EdgeControls
from ..actions.transit import TransitPlanner
from ..model.segments import Push, Transit, append_push, rechain
from .spaces import pose_of, switch_target

__all__ = ["moves", "segments"]


def moves(path, n_edges: int, switching: bool) -> list[tuple]:
    """The path's moves in order: ``(k, u, duration)`` per push (``u`` the push control of edge
    index ``k``) and ``(from, to)`` per switch of edge index."""
    k = pose_of(path.getState(0))[3]
    width = 3 if switching else 2
    out: list[tuple] = []
    for control, d in zip(path.getControls(), list(path.getControlDurations())):
        u = tuple(control[i] for i in range(width))
        target = switch_target(u[2], n_edges) if switching else None
        if target is not None:
            if target != k:
                out.append((k, target))
                k = target
        else:
            out.append((k, u[:2], d))
    return out


def segments(path, controls: list[EdgeControls], transits: TransitPlanner | None,
             connection: list[Push | Transit]) -> list[Push | Transit] | None:
    """The segments of ``path``, followed by ``connection`` (the goal test's, from its last
    state); None if a switch on it finds no transit when re-composed (rounding can move a pose
    that had one onto the edge of an obstacle's reach)."""
    start = np.array(pose_of(path.getState(0))[:3])
    out: list[Push | Transit] = []
    pose = start
    for move in moves(path, len(controls), transits is not None):
        if len(move) == 2:
            transit = transits.find(pose, controls[move[0]].edge, controls[move[1]].edge)
            if transit is None:
                return None
            out.append(transit)
            continue
        k, u, d = move
        append_push(out, controls[k].push(pose, controls[k].control_twist(u), float(d)))
        pose = out[-1].end
    return out + rechain(connection, pose)
