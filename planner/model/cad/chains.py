"""Open pieces of a drawing (lines, arcs, open polylines) joined end to end into closed outlines.

Ends on one point of a grid a hundredth of the chord tolerance apart are one end. A piece drawn
twice (either way) counts once. Pieces that lead nowhere (a stray line, even one touching an
outline) are cut off first, each chain of them counted open; what is left closes where every end
joins exactly two pieces, and stays open where three or more meet (which way the outline goes
there is not drawn). Time and memory are linear in the points: the pieces are never overlaid, as
a union of them was (300 overlapping arcs of one circle took 24 s, 2,000 copies of one arc more
memory than the machine had).
"""

from __future__ import annotations

from collections import defaultdict

import numpy as np

__all__ = ["chains"]


def chains(pieces: list[np.ndarray], chord: float) -> tuple[list[np.ndarray], int]:
    """The closed rings (each ``(n, 2)``, not repeating its first point) that the open polylines
    ``pieces`` (each ``(k, 2)``, ``k >= 2``) form end to end, and how many chains stay open.

    >>> square = [np.array([[0, 0], [1, 0.]]), np.array([[1, 1], [1, 0.]]), np.array([[1, 1], [0, 1.]]),
    ...           np.array([[0, 0], [0, 1.]])]
    >>> rings, left_open = chains(square + [square[0], np.array([[1, 1], [2, 2.]])], 0.1)
    >>> [ring.tolist() for ring in rings], left_open  # drawn twice, a stray line touching a corner
    ([[[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]], 1)
    >>> chains(square[:3], 0.1)[1], chains(square + [np.array([[0, 0], [1, 1.]])], 0.1)[1]  # a path; a fork
    (1, 1)
    """
    grid = chord / 100
    drawn: dict[bytes, int] = {}  # each piece once, by its points on the grid, either way
    ends: list[tuple[tuple, tuple]] = []
    for k, piece in enumerate(pieces):
        snapped = np.round(piece / grid).astype(np.int64)  # within the limit: far inside int64
        key = min(snapped.tobytes(), snapped[::-1].tobytes())
        if key not in drawn:
            drawn[key] = k
            ends.append((tuple(snapped[0]), tuple(snapped[-1])))
    kept = [pieces[k] for k in drawn.values()]
    at: dict[tuple, set[int]] = defaultdict(set)  # the pieces (their place in kept) at each end
    for j, (start, end) in enumerate(ends):
        at[start].add(j)
        at[end].add(j)
    degree = {node: sum(2 if ends[j][0] == ends[j][1] else 1 for j in js) for node, js in at.items()}
    open_ = _pruned(ends, at, degree)
    rings, left = [], set(range(len(ends))) - open_
    while left:
        component = _component(min(left), ends, at, left)
        left -= component
        if all(degree[node] == 2 for j in component for node in ends[j]):
            rings.append(_ring(component, ends, at, kept))
        else:
            open_ |= component
    return rings, _count_components(open_, ends)


def _pruned(ends: list[tuple], at: dict[tuple, set[int]], degree: dict[tuple, int]) -> set[int]:
    """Remove from ``at`` and ``degree`` the pieces that lead nowhere (one end free), until none
    does; return them."""
    removed: set[int] = set()
    loose = [node for node, d in degree.items() if d == 1]
    while loose:
        node = loose.pop()
        if degree[node] != 1:
            continue
        (j,) = at[node]
        removed.add(j)
        for end in ends[j]:
            at[end].discard(j)
            degree[end] -= 1
            if degree[end] == 1:
                loose.append(end)
    return removed


def _component(first: int, ends: list[tuple], at: dict[tuple, set[int]], among: set[int]) -> set[int]:
    """The pieces of ``among`` joined to piece ``first`` through their ends."""
    found, todo = {first}, [first]
    while todo:
        for end in ends[todo.pop()]:
            for j in at[end] - found:
                if j in among:
                    found.add(j)
                    todo.append(j)
    return found


def _ring(component: set[int], ends: list[tuple], at: dict[tuple, set[int]], points: list[np.ndarray]) -> np.ndarray:
    """The pieces of ``component``, each of whose ends joins two, walked round as one ring."""
    first = min(component)
    walked, node, used = [points[first]], ends[first][1], {first}
    while len(used) < len(component):
        (j,) = at[node] - used
        forward = ends[j][0] == node
        walked.append((points[j] if forward else points[j][::-1])[1:])
        node = ends[j][1] if forward else ends[j][0]
        used.add(j)
    return np.concatenate(walked)[:-1]  # the last point is the first again


def _count_components(pieces: set[int], ends: list[tuple]) -> int:
    """How many chains the ``pieces`` make (joined through shared ends)."""
    at: dict[tuple, set[int]] = defaultdict(set)
    for j in pieces:
        for end in ends[j]:
            at[end].add(j)
    left, count = set(pieces), 0
    while left:
        left -= _component(min(left), ends, at, left)
        count += 1
    return count
