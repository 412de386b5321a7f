"""Plans of multi-part scenes and their JSON file format ``stablepush.plan/2`` (README, "Several parts").

A multi-part plan is a sequence of *moves*: each pushes one part (its pushes and transits are
those of a one-part plan, :mod:`.plan_file`, in that part's world poses), either to its goal or
aside to a buffer pose it leaves later. Between two moves the pusher travels from the contact it
leaves to the next part's first contact: a :class:`Transfer`. In the file the moves are one list
of segments, each push and transit naming its ``part``, with the transfers between them.

Cost: each part's push length (its CF's path) plus ``switch_cost`` per transit and per transfer:
a transfer, like a switch of edge, is counted as a fixed price for taking the pusher off one
contact and onto another, not by the length of its path.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar, Literal

import numpy as np

from .fields import SceneError, integer, keys, number, shown, vector
from .json_file import read_json
from .plan_file import MAX_BYTES, Push, Transit, _floats, path_cost, path_length, read_pusher_path

__all__ = ["FORMAT", "Move", "PartsPlan", "Transfer", "load_parts_plan"]

FORMAT = "stablepush.plan/2"


@dataclass(frozen=True)
class Transfer:
    """The pusher's travel from its contact on ``from_part`` to the contact on ``to_part``'s
    ``to_edge``, every part standing still. ``pusher_path`` holds world poses of the pusher frame
    with the interpolation rules of a :class:`~planner.model.plan_file.Transit`: straight
    ``(x, y, theta)`` pieces, and in ``'lift'`` mode four poses whose middle piece is airborne."""

    kind: ClassVar[Literal["transfer"]] = "transfer"

    from_part: str
    to_part: str
    to_edge: int
    mode: str
    pusher_path: np.ndarray  # (m, 3) world poses of the pusher frame
    duration: float  # at 1 m/s, as a transit's

    def to_dict(self) -> dict:
        return {"kind": "transfer", "from_part": self.from_part, "to_part": self.to_part, "to_edge": int(self.to_edge),
                "mode": self.mode, "pusher_path": np.asarray(self.pusher_path, dtype=float).tolist(),
                "duration": float(self.duration)}

    @classmethod
    def from_dict(cls, data: Any, name: str, names: tuple[str, ...]) -> "Transfer":
        """Read a transfer of a plan file between parts of ``names``, checking every field."""
        spec = keys(data, name, ("kind", "from_part", "to_part", "to_edge", "mode", "pusher_path", "duration"))
        for key in ("from_part", "to_part"):
            if spec[key] not in names:
                raise SceneError(f"{name}.{key}", f"must name a part of the plan ({', '.join(names)}), got {shown(spec[key])}")
        mode, path, duration = read_pusher_path(spec, name)
        return cls(spec["from_part"], spec["to_part"], integer(spec["to_edge"], f"{name}.to_edge"), mode, path, duration)


@dataclass(frozen=True)
class Move:
    """One part pushed: ``segments`` (pushes and transits, world poses of ``part``), reached by
    ``transfer`` from the move before (None for the first move)."""

    part: str
    segments: list[Push | Transit]
    transfer: Transfer | None = None

    @property
    def start(self) -> np.ndarray:
        return self.segments[0].start

    @property
    def end(self) -> np.ndarray:
        return self.segments[-1].end


@dataclass(frozen=True, kw_only=True)
class PartsPlan:
    """The result of planning a :class:`~planner.model.parts.PartsScene`: made by keyword, once.

    ``starts``, ``goals`` and ``cfs`` map each part's name to its start and goal poses and its CF
    (slider frame); ``delivered`` names the parts that end within tolerance of their goals.

    >>> push = Push.along(0, np.zeros((2, 2)), [1.0, 0.0, 0.0], 0.5, np.zeros(3))
    >>> hop = Transfer("a", "b", 2, "lift", np.zeros((4, 3)), 0.3)
    >>> plan = PartsPlan(scene=None, solved=True, planner="rrt", seed=1, planning_time_s=0.1,
    ...     starts={"a": np.zeros(3), "b": np.ones(3)}, goals={"a": push.end, "b": np.ones(3)},
    ...     moves=[Move("a", [push])], delivered=("a", "b"), switch_cost=0.25, cfs={"a": np.zeros(2), "b": np.zeros(2)})
    >>> plan.length, plan.cost, plan.headline()
    (0.5, 0.5, '2 parts, 1 move, 1 push, cost 0.500 m, length 0.500 m')
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
    note: str = ""  # not in the file
    switch_cost: float | None = None
    cfs: dict[str, np.ndarray] = field(default_factory=dict)

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(self.starts)

    @property
    def finals(self) -> dict[str, np.ndarray]:
        """Where each part ends: where its last move leaves it, or its start."""
        out = {n: np.asarray(p, dtype=float) for n, p in self.starts.items()}
        for move in self.moves:
            out[move.part] = move.end
        return out

    @property
    def segments(self) -> list[tuple[str, Push | Transit | Transfer]]:
        """Every segment in order, each with the part it belongs to (a transfer's: the part it goes to)."""
        out: list[tuple[str, Push | Transit | Transfer]] = []
        for move in self.moves:
            if move.transfer is not None:
                out.append((move.part, move.transfer))
            out += [(move.part, s) for s in move.segments]
        return out

    @property
    def pushes(self) -> int:
        return sum(s.kind == "push" for m in self.moves for s in m.segments)

    @property
    def switches(self) -> int:
        return sum(s.kind == "transit" for m in self.moves for s in m.segments)

    @property
    def transfers(self) -> int:
        return sum(m.transfer is not None for m in self.moves)

    @property
    def buffer_moves(self) -> int:
        """Moves that leave their part aside for a later move of it."""
        return sum(any(later.part == m.part for later in self.moves[k + 1:]) for k, m in enumerate(self.moves))

    def contents(self) -> str:
        """``'3 parts, 4 moves (1 buffer), 9 pushes, 1 switch, 3 transfers'``."""
        def count(n: int, word: str) -> str:
            return f"{n} {word if n == 1 else word + ('es' if word.endswith(('sh', 'ch')) else 's')}"

        buffers = f" ({self.buffer_moves} buffer)" if self.buffer_moves else ""
        words = [count(len(self.starts), "part"), count(len(self.moves), "move") + buffers, count(self.pushes, "push")]
        words += [count(self.switches, "switch")] if self.switches else []
        words += [count(self.transfers, "transfer")] if self.transfers else []
        return ", ".join(words)

    def headline(self) -> str:
        return f"{self.contents()}, cost {self.cost:.3f} m, length {self.length:.3f} m"

    @property
    def length(self) -> float | None:
        """Every part's CF path, added up."""
        if not all(m.part in self.cfs for m in self.moves):
            return None
        return sum(path_length(m.segments, self.cfs[m.part]) for m in self.moves)

    @property
    def cost(self) -> float | None:
        """:attr:`length` plus ``switch_cost`` per transit and per transfer (module docstring)."""
        if self.switch_cost is None or self.length is None:
            return None
        return (sum(path_cost(m.segments, self.cfs[m.part], self.switch_cost) for m in self.moves)
                + self.switch_cost * self.transfers)

    def to_dict(self) -> dict:
        finals = self.finals
        parts = {n: {"start": _floats(self.starts[n]), "goal": _floats(self.goals[n]), "final": _floats(finals[n]),
                     "delivered": n in self.delivered} | ({"cf": _floats(self.cfs[n])} if n in self.cfs else {})
                 for n in self.names}
        segments = [s.to_dict() if s.kind == "transfer" else {**s.to_dict(), "part": part} for part, s in self.segments]
        out = {"format": FORMAT, "scene": self.scene, "solved": bool(self.solved), "planner": self.planner,
               "seed": int(self.seed), "planning_time_s": round(float(self.planning_time_s), 4), "parts": parts,
               "segments": segments}
        if self.reason and not self.solved:
            out["reason"] = self.reason
        if self.switch_cost is not None:
            out["switch_cost"] = float(self.switch_cost)
        if self.length is not None:
            out["length"] = round(self.length, 9)
        if self.cost is not None:
            out["cost"] = round(self.cost, 9)
        return out

    def to_json(self) -> str:
        return json.dumps(self.to_dict(), indent=1)

    @classmethod
    def from_dict(cls, data: Any) -> "PartsPlan":
        """A plan from its JSON form (``stablepush.plan/2``), every field checked: each part's
        segments follow on from where it stands, transfers go from the part just moved to the
        part moved next, and what the file says of finals, length and cost is what its segments make."""
        spec = keys(data, "plan", ("format", "scene", "solved", "planner", "seed", "planning_time_s", "parts", "segments"),
                    ("reason", "switch_cost", "length", "cost"))
        if spec["format"] != FORMAT:
            raise SceneError("plan.format", f"must be {FORMAT!r}, got {shown(spec['format'])}")
        if not isinstance(spec["solved"], bool):
            raise SceneError("plan.solved", f"must be true or false, got {shown(spec['solved'])}")
        listed = spec["parts"]
        if not isinstance(listed, dict) or not listed:
            raise SceneError("plan.parts", "must be a non-empty mapping of part names to their start, goal and final")
        parts = {str(n): keys(p, f"plan.parts.{n}", ("start", "goal", "final"), ("delivered", "cf")) for n, p in listed.items()}
        starts = {n: vector(p["start"], f"plan.parts.{n}.start", 3) for n, p in parts.items()}
        if not isinstance(spec["segments"], list):
            raise SceneError("plan.segments", "must be a list")
        switch_cost = number(spec["switch_cost"], "plan.switch_cost") if "switch_cost" in spec else None
        plan = cls(scene=spec["scene"] if isinstance(spec["scene"], str) else None, solved=spec["solved"],
                   planner=str(spec["planner"]), seed=integer(spec["seed"], "plan.seed"),
                   planning_time_s=number(spec["planning_time_s"], "plan.planning_time_s"), starts=starts,
                   goals={n: vector(p["goal"], f"plan.parts.{n}.goal", 3) for n, p in parts.items()},
                   moves=_read_moves(spec["segments"], starts),
                   delivered=tuple(n for n, p in parts.items() if p.get("delivered") is True),
                   reason=str(spec.get("reason", "")), switch_cost=switch_cost,
                   cfs={n: vector(p["cf"], f"plan.parts.{n}.cf", 2) for n, p in parts.items() if "cf" in p})
        for n, final in plan.finals.items():
            if not np.allclose(vector(parts[n]["final"], f"plan.parts.{n}.final", 3), final, atol=1e-9):
                raise SceneError(f"plan.parts.{n}.final", "is not where the part's last segment leaves it")
        for name in ("length", "cost"):
            said, made = number(spec[name], f"plan.{name}") if name in spec else None, getattr(plan, name)
            if said is not None and (made is None or abs(said - made) > 1e-6):
                raise SceneError(f"plan.{name}", f"is {said:g}, but the segments make {made if made is not None else 'none'}")
        return plan


def _read_moves(items: list, starts: Mapping[str, np.ndarray]) -> list[Move]:
    """The moves of a plan file's segments: a new move at each transfer, each segment checked to
    follow on from where its part stands."""
    names = tuple(starts)
    at = {n: np.asarray(p, dtype=float) for n, p in starts.items()}
    moves: list[Move] = []
    transfer: Transfer | None = None
    for i, item in enumerate(items):
        name = f"plan.segments[{i}]"
        kind = item.get("kind") if isinstance(item, dict) else None
        if kind == "transfer":
            hop = Transfer.from_dict(item, name, names)
            if transfer is not None or not moves:
                raise SceneError(name, "a transfer must come between two parts' segments")
            if hop.from_part != moves[-1].part:
                raise SceneError(f"{name}.from_part", f"the pusher is on part {shown(moves[-1].part)}, not {shown(hop.from_part)}")
            transfer = hop
            continue
        if kind not in ("push", "transit"):
            raise SceneError(f"{name}.kind", f"must be 'push', 'transit' or 'transfer', got {shown(kind)}")
        part = item.get("part")
        if part not in names:
            raise SceneError(f"{name}.part", f"must name a part of the plan ({', '.join(names)}), got {shown(part)}")
        body = {k: v for k, v in item.items() if k != "part"}
        segment = Push.from_dict(body, name) if kind == "push" else Transit.from_dict(body, name, at[part])
        if not np.allclose(segment.start, at[part], atol=1e-9):
            raise SceneError(f"{name}.start", f"is not where part {shown(part)} stands then")
        if transfer is not None or not moves:
            if transfer is not None and (transfer.to_part != part or transfer.to_edge != segment.from_edge):
                raise SceneError(f"plan.segments[{i - 1}]", f"the transfer goes to part {shown(transfer.to_part)}'s edge "
                                                            f"{transfer.to_edge}, but the next segment pushes part "
                                                            f"{shown(part)}'s edge {segment.from_edge}")
            moves.append(Move(part, [segment], transfer))
            transfer = None
        elif moves[-1].part != part:
            raise SceneError(f"{name}.part", f"the pusher is on part {shown(moves[-1].part)}: a transfer must come first")
        else:
            moves[-1].segments.append(segment)
        at[part] = segment.end
    if transfer is not None:
        raise SceneError("plan.segments", "ends with a transfer")
    return moves


def load_parts_plan(path: str | Path) -> PartsPlan:
    """Read a ``stablepush.plan/2`` file, checking every field (as :func:`~planner.model.plan_file.load_plan`)."""
    return PartsPlan.from_dict(read_json(path, "plan", MAX_BYTES))
