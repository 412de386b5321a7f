"""Shorter plans from a found one: greedy replacement of runs of segments, farthest first.

Random controls make plans zig-zag. :class:`JoinShortcut` replaces runs of segments by one push
wherever one stable collision-free push joins their ends (the one-step test between plan
waypoints); the Dubins shortcut (:class:`~planner.actions.dubins.DubinsShortcut`) then replaces
runs on one edge by shorter Dubins curves. Both walk the plan the same way
(:func:`farthest_first`), and every replacement is checked like any push, so the guarantee is
kept.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Protocol

from ..model.segments import Push, Transit
from ..world.validity import CollisionModel
from .controls import EdgeControls
from .push import connect
from .transit import TransitPlanner

__all__ = ["JoinShortcut", "Shortcut", "farthest_first"]


class Shortcut(Protocol):
    """A shortening of plans: :class:`JoinShortcut`, the Dubins shortcut and the switch-pose
    shortcut are each one, applied in turn. What it returns goes between the same two poses as
    what it is given, every replacement checked like any push or transit."""

    def __call__(self, segments: list[Push | Transit]) -> list[Push | Transit]: ...


def farthest_first(items: Sequence, join: Callable[[int, int], list | None], least: int = 1) -> list:
    """``items`` with runs replaced greedily: from each ``i``, the farthest ``j`` (down to runs
    of ``least`` items) for which ``join(i, j)`` gives a replacement of ``items[i:j]``; an item
    no run from it replaces is kept as it is.

    >>> words = ["a", "b", "c", "d", "e"]
    >>> farthest_first(words, lambda i, j: ["".join(words[i:j])] if j - i <= 2 else None)
    ['ab', 'cd', 'e']
    >>> farthest_first(words, lambda i, j: None, least=2)
    ['a', 'b', 'c', 'd', 'e']
    """
    out, i = [], 0
    while i < len(items):
        for j in range(len(items), i + least - 1, -1):
            joined = join(i, j)
            if joined is not None:
                out += joined
                i = j
                break
        else:
            out.append(items[i])
            i += 1
    return out


class JoinShortcut:
    """Replace runs of segments by one push wherever one joins their ends.

    A run may hold transits: it is replaced by a push on the edge in use where it begins, followed
    by a transit to the edge its end was on if the plan goes on from there (or, at the very start,
    by a push on that edge), so switches that are not needed disappear.
    """

    def __init__(self, controls: list[EdgeControls], model: CollisionModel, margin: float,
                 transits: TransitPlanner | None):
        self.by_edge = {c.edge: c for c in controls}
        self.model, self.margin, self.transits = model, margin, transits

    def __call__(self, segments: list[Push | Transit]) -> list[Push | Transit]:
        return farthest_first(segments, lambda i, j: self._join(segments, i, j - 1), least=2)

    def _join(self, segments: list, i: int, j: int) -> list | None:
        """A replacement of segments ``i`` to ``j`` (both included), or None."""
        a, b = segments[i], segments[j]
        if not (isinstance(a, Push) and isinstance(b, Push)):
            return None
        last = j == len(segments) - 1
        for edge in (a.edge, b.edge) if i == 0 and a.edge != b.edge else (a.edge,):
            joined = connect(a.start, b.end, self.by_edge[edge], self.model, self.margin)
            if not isinstance(joined, Push):
                continue
            if edge == b.edge or last:
                return [joined]
            transit = self.transits.find(b.end, edge, b.edge) if self.transits is not None else None
            if transit is not None:
                return [joined, transit]
        return None
