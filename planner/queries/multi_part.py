"""Planning a multi-part scene: which part to push when, where to leave one aside, and the
pusher's travel between them.

The search is over orders of *moves*. A move pushes one part, with every other part an obstacle
where it stands at that moment (:meth:`~planner.model.scene.Scene.move_scene`), either to
its goal or to a *buffer* pose out of the way, to be fetched later; it is planned by a
:class:`~planner.queries.session.Planner` session of that part among those obstacles, which
plans the buffer poses tried from there too. Between two moves the pusher travels from where it
left the last part to the next part's first contact (:mod:`planner.search.transfer`).

Depth first, from the scene's starts: every part not at its goal whose goal is free is tried, in
an order that tries first the parts that block others least (their goals farthest from the
other parts' ways); a move the geometry proves impossible (the session's certificates: the goal
sealed off by the parts standing) costs no search. When no part can go to its goal, a part
standing on another's goal (or, failing that, any part not delivered) is pushed aside to one of
the free buffer poses nearest its way. A branch that fails is undone and the next is tried, so a
forced order (a dead end filled from the far end) is found, and a cycle of parts each on the
next's goal (a swap) is broken by one buffer move. Poses already seen are not searched again.

The time limit bounds everything; if it runs out, the plan is the furthest the search got: the
most parts delivered, which the plan names. A :class:`~planner.queries.session.Planner` of a
scene of several parts runs this search.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Protocol

import numpy as np
import shapely

from ..actions.controls import NoStablePush
from ..actions.transit import edge_contact_pose
from ..model.bodies import place
from ..model.options import PlannerOptions
from ..model.scene import Scene
from ..model.plan import Move, Plan
from ..search.transfer import TransferPaths
from ..world.grid import grid_spacing

__all__ = ["BUFFER_CELLS", "BUFFER_TRIES", "BUFFER_VERTICES", "MOVE_SHARE", "PartSession", "buffer_cells", "plan_parts"]

#: Buffer poses tried for one part in one state, nearest its way first.
BUFFER_TRIES = 4
#: The buffer grid's most cells, and the most vertices of the part placed at them all
#: (:func:`buffer_cells`): a part a radius apart on a metre's table makes hundreds of cells, a part
#: of microns would make 10^11.
BUFFER_CELLS, BUFFER_VERTICES = 4096, 1_000_000
#: Share of the time limit one move's search may take (at least a second, or what is left).
MOVE_SHARE = 0.1
#: Rounding of poses (metres, radians) by which a state counts as seen.
_SEEN = 3


class PartSession(Protocol):
    """What the search asks of a one-part session (:class:`~planner.queries.session.Planner`)."""

    def certify_unreachable(self, goal: np.ndarray) -> str | None: ...

    def plan(self, *, goal: np.ndarray, seed: int, time_limit: float) -> Plan: ...


def buffer_cells(vertices: int) -> int:
    """The most cells of the buffer grid of a part of ``vertices`` vertices: :data:`BUFFER_CELLS`,
    fewer for a part so detailed that placing it at them all would place more than
    :data:`BUFFER_VERTICES` vertices, but never fewer than 64 (a grid of 8 x 8 at least).

    >>> buffer_cells(4), buffer_cells(1000), buffer_cells(131072)
    (4096, 1000, 64)
    """
    return min(BUFFER_CELLS, max(64, BUFFER_VERTICES // vertices))


@dataclass
class _Best:
    """The furthest the search got: its moves and how many parts they deliver."""

    moves: list[Move]
    delivered: int


def plan_parts(scene: Scene, options: PlannerOptions,
               session_of: Callable[[str, dict[str, np.ndarray] | None], PartSession], paths: TransferPaths,
               seed: int, time_limit: float) -> Plan:
    """Plan every part of ``scene`` from its start to its goal (module docstring) within
    ``time_limit`` seconds, each move planned by ``session_of(part, poses)`` (a one-part session
    of the part with the others at ``poses``; with ``poses`` None, among the obstacles alone) and
    each transfer by ``paths``, seeded by ``seed``; ``options`` are the sessions' (the plan is
    costed with their ``switch_cost``).

    A part whose goal the certificates show unreachable among the obstacles alone cannot be
    delivered in any order: it is left where it is (an obstacle to the others), the rest are
    planned, and the plan, not solved, says why."""
    clock = time.perf_counter()
    hopeless = {p.name: reason for p in scene.parts if not scene.delivered(p.name, p.start)
                and (reason := session_of(p.name, None).certify_unreachable(p.goal)) is not None}
    search = _Search(scene, session_of, paths, seed, clock + time_limit, time_limit, tuple(hopeless))
    found = search.run(scene.starts)
    moves = found if found is not None else search.best.moves
    finals = scene.starts | {m.part: m.end for m in moves}
    delivered = tuple(n for n in scene.names if scene.delivered(n, finals[n]))
    solved = found is not None and not hopeless
    reason = "" if solved else search.why(delivered) if found is None else "; ".join(
        f"not delivered: {n}: its goal is certified unreachable among the obstacles: {r}" for n, r in hopeless.items())
    return Plan(scene=scene.path, solved=solved, planner=options.name, seed=seed,
                     planning_time_s=time.perf_counter() - clock, starts=scene.starts, goals=scene.goals,
                     moves=moves, delivered=delivered, reason=reason,
                     switch_cost=options.switch_cost, cfs={p.name: p.slider.cf.copy() for p in scene.parts})


class _Search:
    """One depth-first search of :func:`plan_parts`."""

    def __init__(self, scene: Scene, session_of: Callable[[str, dict[str, np.ndarray] | None], PartSession],
                 paths: TransferPaths, seed: int, deadline: float, limit: float, hopeless: tuple[str, ...] = ()):
        self.scene, self.session_of, self.paths, self.seed, self.deadline = scene, session_of, paths, seed, deadline
        self.hopeless = hopeless
        #: Each part's outline at its goal (goals do not move; every state asks for them).
        self.goals = {p.name: scene.body(p.name, p.goal) for p in scene.parts}
        self.per_move = max(1.0, MOVE_SHARE * limit)
        self.seen: set[tuple] = set()
        self.best = _Best([], -1)
        self.failures: dict[str, str] = {}

    def why(self, delivered: tuple[str, ...]) -> str:
        missing = [n for n in self.scene.names if n not in delivered]
        cause = "the time limit ran out" if time.perf_counter() >= self.deadline else "no order of moves was found"
        last = "; ".join(f"{n}: {r}" for n, r in self.failures.items() if n in missing)
        return f"{cause}; not delivered: {', '.join(missing)}" + (f" ({last})" if last else "")

    def run(self, poses: dict[str, np.ndarray]) -> list[Move] | None:
        return self._search(poses, [], 0)

    def _search(self, poses: dict[str, np.ndarray], moves: list[Move], buffers: int) -> list[Move] | None:
        scene = self.scene
        pending = [n for n in scene.names if not scene.delivered(n, poses[n]) and n not in self.hopeless]
        delivered = len(scene.names) - len(pending) - len(self.hopeless)
        if delivered > self.best.delivered or (delivered == self.best.delivered and len(moves) < len(self.best.moves)):
            self.best = _Best(list(moves), delivered)
        if not pending:
            return moves
        key = tuple(tuple(np.round(poses[n], _SEEN).tolist()) for n in scene.names)
        if key in self.seen or time.perf_counter() >= self.deadline:
            return None
        self.seen.add(key)
        bodies = {n: scene.body(n, poses[n]) for n in scene.names}
        free = [n for n in pending if not any(bodies[m].intersects(self.goals[n]) for m in scene.names if m != n)]
        for name in self._order(free, poses):
            if (found := self._try(poses, moves, buffers, name, scene.part(name).goal)) is not None:
                return found
        if buffers >= len(scene.names):
            return None
        for name in self._blockers(pending, bodies):
            if moves and moves[-1].part == name:  # from one buffer pose to another: nothing gained
                continue
            for spot in self._buffers(name, poses, bodies, pending):
                if (found := self._try(poses, moves, buffers + 1, name, spot)) is not None:
                    return found
                if time.perf_counter() >= self.deadline:
                    return None
        return None

    def _try(self, poses: dict[str, np.ndarray], moves: list[Move], buffers: int, name: str,
             goal: np.ndarray) -> list[Move] | None:
        """The search after moving ``name`` to ``goal`` from ``poses``, or None."""
        left = self.deadline - time.perf_counter()
        if left <= 0:
            return None
        try:
            session = self.session_of(name, poses)
        except NoStablePush as err:
            self.failures[name] = f"no stable push: {err.problem}"
            return None
        if (reason := session.certify_unreachable(goal)) is not None:
            self.failures[name] = reason
            return None
        try:
            plan = session.plan(goal=goal, seed=self.seed, time_limit=min(left, self.per_move))
        except NoStablePush as err:
            self.failures[name] = f"no stable push: {err.problem}"
            return None
        if not plan.solved or not plan.segments:
            self.failures[name] = plan.reason or "no plan"
            return None
        transfer = None
        if moves:
            last = moves[-1]
            edge = plan.segments[0].from_edge
            leave = edge_contact_pose(self.scene.part(last.part).slider, last.segments[-1].edge, last.end)
            reach = edge_contact_pose(self.scene.part(name).slider, edge, plan.start)
            transfer = self.paths.find(poses, last.part, leave, name, edge, reach, self.seed)
            if transfer is None:
                self.failures[name] = f"the pusher found no way from part {last.part} to it"
                return None
        after = dict(poses)
        after[name] = plan.final.copy()
        return self._search(after, [*moves, Move(name, list(plan.segments), transfer)], buffers)

    def _order(self, names: list[str], poses: Mapping[str, np.ndarray]) -> list[str]:
        """``names`` with those whose goals lie farthest from the other pending parts' straight
        ways first: a part put where others pass would block them."""
        scene = self.scene
        ways = {n: shapely.LineString([poses[n][:2], scene.part(n).goal[:2]]) for n in names}

        def blocking(n: str) -> float:
            near = [self.goals[n].distance(ways[m]) for m in names if m != n]
            return -min(near) if near else 0.0

        return sorted(names, key=lambda n: (blocking(n), n))

    def _blockers(self, pending: list[str], bodies: dict) -> list[str]:
        """The parts to push aside: those standing on a pending part's goal, then the rest pending."""
        on_goal = [n for n in pending if any(bodies[n].intersects(self.goals[m]) for m in pending if m != n)]
        return on_goal + [n for n in pending if n not in on_goal]

    def _buffers(self, name: str, poses: Mapping[str, np.ndarray], bodies: dict, pending: list[str]) -> list[np.ndarray]:
        """Up to :data:`BUFFER_TRIES` poses to leave ``name`` at: on a grid of the workspace a part
        radius apart (or coarser: :func:`buffer_cells`), at its present heading, clear of
        obstacles, of the other parts and of every pending goal by the pusher's depth and a part
        radius, nearest the way from where it is to its goal first."""
        scene = self.scene
        part = scene.part(name)
        radius = part.slider.radius
        room = scene.pusher.depth + radius
        xmin, ymin, xmax, ymax = scene.workspace
        step = grid_spacing(xmax - xmin - 2 * radius, ymax - ymin - 2 * radius, radius, buffer_cells(part.slider.n))
        xs, ys = np.meshgrid(np.arange(xmin + radius, xmax - radius + 1e-12, step),
                             np.arange(ymin + radius, ymax - radius + 1e-12, step))
        spots = np.column_stack([xs.ravel(), ys.ravel(), np.full(xs.size, poses[name][2])])
        taken = [*scene.obstacles, *(b for n, b in bodies.items() if n != name),
                 *(self.goals[n] for n in pending)]
        keep = shapely.union_all(taken).buffer(room) if taken else shapely.Polygon()
        inside = shapely.box(xmin, ymin, xmax, ymax)
        outlines = shapely.polygons(place(part.slider.vertices, spots))
        ok = shapely.contains(inside, outlines) & ~shapely.intersects(keep, outlines)
        spots = spots[ok]
        if not len(spots):
            return []
        way = shapely.LineString([poses[name][:2], part.goal[:2]])
        cost = shapely.distance(way, shapely.points(spots[:, :2])) + 0.1 * np.hypot(*(spots[:, :2] - poses[name][:2]).T)
        return [spots[k] for k in np.argsort(cost, kind="stable")[:BUFFER_TRIES]]

