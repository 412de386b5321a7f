"""Plans: what the planner answers, for a scene of one part or of several.

A plan is a sequence of *moves* (:class:`Move`): each pushes one part, by pushes and the
pusher's transits between its edges (:mod:`.segments`), in that part's world poses, either to
its goal or aside to a pose it leaves later. Between two moves the pusher travels from the
contact it leaves to the next part's first contact: the later move's ``transfer``. A plan of one
part is one move (or none, if the part starts at its goal). Plans are read and written by
:mod:`.plan_file`.

Cost: each part's push length (its CF's path) plus ``switch_cost`` per transit and per transfer:
a transfer, like a switch of edge, is counted as a fixed price for taking the pusher off one
contact and onto another, not by the length of its path (Lynch & Mason 1996, §4: a cost per
contact change).

>>> push = Push.along(0, np.zeros((2, 2)), [1.0, 0.0, 0.0], 0.5, np.zeros(3))
>>> one = Plan.of_part("part", np.zeros(3), push.end, [push], scene=None, solved=True, planner="rrt", seed=1,
...                    planning_time_s=0.0, switch_cost=0.25, cf=np.zeros(2))
>>> one.headline(), one.final.tolist()
('1 push, cost 0.500 m, length 0.500 m', [0.5, 0.0, 0.0])
>>> hop = Transfer("a", "b", 2, "lift", np.zeros((4, 3)), 0.3)
>>> two = Plan(scene=None, solved=True, planner="rrt", seed=1, planning_time_s=0.1,
...     starts={"a": np.zeros(3), "b": np.ones(3)}, goals={"a": push.end, "b": np.ones(3)},
...     moves=[Move("a", [push])], delivered=("a", "b"), switch_cost=0.25, cfs={"a": np.zeros(2), "b": np.zeros(2)})
>>> two.length, two.cost, two.headline()
(0.5, 0.5, '2 parts, 1 move, 1 push, cost 0.500 m, length 0.500 m')
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from .fields import SceneError, counted
from .margin import Margin, PushMargin
from .scene import ONE_PART
from .segments import Push, Transfer, Transit, floats, path_length

__all__ = ["FORMAT", "FORMATS", "Move", "Plan", "Segment", "Step"]

#: The plan file formats (:mod:`.plan_file`): one part, any number of parts.
FORMATS = ("stablepush.plan/1", "stablepush.plan/2")
#: The format of a plan of several parts (and of one part not named ONE_PART).
FORMAT = FORMATS[1]

#: A segment of a move.
Segment = Push | Transit
#: A step of a plan in order: the part it concerns (a transfer's: the part it goes to) and the segment.
Step = tuple[str, Push | Transit | Transfer]


@dataclass(frozen=True)
class Move:
    """One part pushed: ``segments`` (pushes and transits, world poses of ``part``), reached by
    ``transfer`` from the move before (None for the first move)."""

    part: str
    segments: list[Segment]
    transfer: Transfer | None = None

    @property
    def start(self) -> np.ndarray:
        return self.segments[0].start

    @property
    def end(self) -> np.ndarray:
        return self.segments[-1].end


@dataclass(frozen=True, kw_only=True)
class Plan:
    """The result of planning a :class:`~planner.model.scene.Scene`: made by keyword, once,
    never changed after (:meth:`of_part` makes a plan of one part).

    ``starts``, ``goals`` and ``cfs`` map each part's name to its start and goal poses and its CF
    (slider frame); ``delivered`` names the parts that end within tolerance of their goals.
    ``start``, ``goal``, ``final`` and ``cf`` are the one part's, for a plan of one part.
    """

    scene: str | None
    solved: bool
    planner: str
    seed: int
    planning_time_s: float
    starts: dict[str, np.ndarray]
    goals: dict[str, np.ndarray]
    moves: list[Move] = field(default_factory=list)
    delivered: tuple[str, ...] = ()
    reason: str = ""  # why it is not solved
    note: str = ""  # what the user should know of a plan made with less than asked (not in the file)
    #: Metres a switch or transfer costs, as the planner counted.
    switch_cost: float | None = None
    #: Each part's centre of friction (slider frame), whose path :attr:`length` measures.
    cfs: dict[str, np.ndarray] = field(default_factory=dict, repr=False)
    #: ``(planning time s, cost m, length m)`` of the first plan found and of each better one after it.
    improvements: list[tuple[float, float, float]] = field(default_factory=list)
    tree: np.ndarray = field(default_factory=lambda: np.zeros((0, 2, 2)), repr=False)  # search tree, world xy
    #: The stability margin the pushes were planned to keep (None: not known, as in older plan files).
    margin: Margin | None = None
    #: Each push's own certified margin, in the order of :attr:`steps` (empty: not computed;
    #: :func:`planner.actions.margins.with_margins`).
    margins: tuple[PushMargin, ...] = ()

    @classmethod
    def of_part(cls, part: str, start: ArrayLike, goal: ArrayLike, segments: list[Segment], *,
                cf: ArrayLike | None = None, **fields: Any) -> "Plan":
        """The plan of one ``part`` from ``start`` to ``goal`` by ``segments`` (one move, or none),
        the other fields as :class:`Plan`'s; a solved plan delivers its part."""
        return cls(starts={part: np.array(start, dtype=float)}, goals={part: np.array(goal, dtype=float)},
                   moves=[Move(part, list(segments))] if segments else [],
                   delivered=(part,) if fields.get("solved") else (),
                   cfs={} if cf is None else {part: np.asarray(cf, dtype=float)}, **fields)

    def move_plan(self, k: int = 0) -> "Plan":
        """Move ``k`` as the plan of its one part (solved, planning time 0): from where the moves
        before it leave the part to where this one does, without its transfer."""
        move = self.moves[k]
        where = {**self.starts, **{m.part: m.end for m in self.moves[:k]}}
        return Plan.of_part(move.part, where[move.part], move.end, move.segments, scene=None, solved=True,
                            planner=self.planner, seed=self.seed, planning_time_s=0.0)

    def with_segments(self, segments: list[Segment]) -> "Plan":
        """This plan of one part, by ``segments`` instead of its own (whose pushes' margins it drops)."""
        return replace(self, moves=[Move(self.part, list(segments))] if segments else [], margins=())

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(self.starts)

    @property
    def part(self) -> str:
        """The name of the plan's one part."""
        if len(self.starts) != 1:
            raise SceneError("plan.parts", f"the plan moves {len(self.starts)} parts ({', '.join(self.names)}): "
                                           "name one")
        return next(iter(self.starts))

    @property
    def start(self) -> np.ndarray:
        return self.starts[self.part]

    @property
    def goal(self) -> np.ndarray:
        return self.goals[self.part]

    @property
    def final(self) -> np.ndarray:
        return self.finals[self.part]

    @property
    def cf(self) -> np.ndarray | None:
        return self.cfs.get(self.part)

    @property
    def finals(self) -> dict[str, np.ndarray]:
        """Where each part ends: where its last move leaves it, or its start."""
        out = {n: np.asarray(p, dtype=float) for n, p in self.starts.items()}
        for move in self.moves:
            out[move.part] = move.end
        return out

    @property
    def steps(self) -> list[Step]:
        """Every segment in order, each with the part it belongs to (a transfer's: the part it goes to)."""
        out: list[Step] = []
        for move in self.moves:
            if move.transfer is not None:
                out.append((move.part, move.transfer))
            out += [(move.part, s) for s in move.segments]
        return out

    @property
    def segments(self) -> list[Push | Transit | Transfer]:
        """Every segment in order, transfers included (:attr:`steps` without the parts)."""
        return [s for _, s in self.steps]

    @property
    def pushes(self) -> int:
        return sum(isinstance(s, Push) for m in self.moves for s in m.segments)

    @property
    def switches(self) -> int:
        """How many times the pusher changes edge of a part (transits)."""
        return sum(isinstance(s, Transit) for m in self.moves for s in m.segments)

    @property
    def transfers(self) -> int:
        return sum(m.transfer is not None for m in self.moves)

    @property
    def buffer_moves(self) -> int:
        """Moves that leave their part aside for a later move of it."""
        return sum(any(later.part == m.part for later in self.moves[k + 1:]) for k, m in enumerate(self.moves))

    def contents(self, joiner: str = ", ") -> str:
        """What the plan is made of, in words, joined by ``joiner``: ``'3 pushes'``, ``'1 push, 2 switches'``,
        ``'3 parts, 4 moves (1 buffer), 9 pushes, 1 switch, 3 transfers'``.

        >>> Plan.of_part("part", np.zeros(3), np.zeros(3), [], scene=None, solved=True, planner="rrt", seed=1,
        ...              planning_time_s=0.0).contents()
        '0 pushes'
        """
        words = []
        if len(self.starts) > 1:
            buffers = f" ({self.buffer_moves} buffer)" if self.buffer_moves else ""
            words += [counted(len(self.starts), "part"), counted(len(self.moves), "move") + buffers]
        words.append(counted(self.pushes, "push"))
        words += [counted(self.switches, "switch")] if self.switches else []
        words += [counted(self.transfers, "transfer")] if self.transfers else []
        return joiner.join(words)

    def headline(self) -> str:
        """What a solved plan is and costs, as the ``plan`` command's line says it after ``solved:``
        (and the README quotes it): ``'6 pushes, 1 switch, cost 0.789 m, length 0.539 m'``."""
        return f"{self.contents()}, cost {self.cost:.3f} m, length {self.length:.3f} m"

    def path_length(self, cf: ArrayLike) -> float:
        """Length of the path of the point ``cf`` (slider frame) of the plan's one part."""
        return sum(path_length(m.segments, cf) for m in self.moves if m.part == self.part)

    @property
    def length(self) -> float | None:
        """Every part's CF path, added up, where the plan knows the CFs."""
        if not all(m.part in self.cfs for m in self.moves):
            return None
        return sum(path_length(m.segments, self.cfs[m.part]) for m in self.moves)

    @property
    def cost(self) -> float | None:
        """What the planner minimises: :attr:`length` plus :attr:`switch_cost` per transit and per
        transfer (module docstring), where both are known.

        >>> push = Push.along(0, np.zeros((2, 2)), [1.0, 0.0, 0.0], 0.5, np.zeros(3))
        >>> transit = Transit(0, 2, "lift", np.zeros((4, 3)), 0.1, push.end)
        >>> plan = Plan.of_part("part", np.zeros(3), push.end, [push, transit], scene=None, solved=True,
        ...                     planner="rrt", seed=1, planning_time_s=0.0, switch_cost=0.25, cf=np.zeros(2))
        >>> plan.length, plan.cost
        (0.5, 0.75)
        """
        length = self.length
        if self.switch_cost is None or length is None:
            return None
        return length + self.switch_cost * (self.switches + self.transfers)

    @property
    def format(self) -> str:
        """The file format the plan is written in: ``plan/1`` for the one part of a ``slider:``
        scene (as the tools reading those files expect), else ``plan/2`` (:mod:`.plan_file` reads both)."""
        return FORMATS[0] if self.names == (ONE_PART,) else FORMATS[1]

    def to_dict(self) -> dict:
        """The plan as its file holds it, in :attr:`format`."""
        return _one_part_dict(self) if self.format == FORMATS[0] else _parts_dict(self)

    def to_json(self) -> str:
        return json.dumps(self.to_dict(), indent=1)


def _head(plan: Plan, format: str) -> dict:
    return {"format": format, "scene": plan.scene, "solved": bool(plan.solved), "planner": plan.planner,
            "seed": int(plan.seed), "planning_time_s": round(float(plan.planning_time_s), 4)} | (
        {} if plan.margin is None else {"margin": plan.margin.to_dict()})


def _segment_dicts(plan: Plan, named: bool) -> list[dict]:
    """The plan's segments as its file holds them, each push with its own margin where known and
    (``named``) each push and transit with its part's name."""
    margins = iter(plan.margins)
    out = []
    for part, s in plan.steps:
        item = s.to_dict() | ({"part": part} if named and not isinstance(s, Transfer) else {})
        if isinstance(s, Push) and plan.margins:
            item["margin"] = next(margins).to_dict()
        out.append(item)
    return out


def _one_part_dict(plan: Plan) -> dict:
    out = _head(plan, FORMATS[0]) | {
        "start": floats(plan.start), "goal": floats(plan.goal), "final": floats(plan.final),
        "segments": _segment_dicts(plan, named=False)}
    if plan.reason and not plan.solved:
        out["reason"] = plan.reason
    if not plan.solved:  # an unsolved plan's segments are not a way to the goal: no cost is said
        return out
    if plan.cf is not None:
        out["cf"] = floats(plan.cf)
        out["length"] = round(plan.length, 9)
    if plan.switch_cost is not None:
        out["switch_cost"] = float(plan.switch_cost)
    if plan.cost is not None:
        out["cost"] = round(plan.cost, 9)
    if plan.improvements:
        out["improvements"] = [[round(t, 4), round(c, 9), round(n, 9)] for t, c, n in plan.improvements]
    return out


def _parts_dict(plan: Plan) -> dict:
    finals = plan.finals
    parts = {n: {"start": floats(plan.starts[n]), "goal": floats(plan.goals[n]), "final": floats(finals[n]),
                 "delivered": n in plan.delivered} | ({"cf": floats(plan.cfs[n])} if n in plan.cfs else {})
             for n in plan.names}
    out = _head(plan, FORMATS[1]) | {"parts": parts, "segments": _segment_dicts(plan, named=True)}
    if plan.reason and not plan.solved:
        out["reason"] = plan.reason
    if plan.switch_cost is not None:
        out["switch_cost"] = float(plan.switch_cost)
    if plan.length is not None:
        out["length"] = round(plan.length, 9)
    if plan.cost is not None:
        out["cost"] = round(plan.cost, 9)
    return out
