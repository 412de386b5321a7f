"""Plan files: the JSON formats ``stablepush.plan/1`` and ``stablepush.plan/2`` (README, "Outputs"
and "Several parts"), read by other tools.

Both hold one :class:`~planner.model.plan.Plan`. ``plan/1`` is a plan of one part: its start,
goal and final pose and its segments (pushes and transits). ``plan/2`` holds any number of
parts: each part's start, goal, final pose and CF under ``parts``, and one list of segments, each
push and transit naming its ``part``, with the transfers between moves. A plan of the one part of
a ``slider:`` scene (:data:`~planner.model.scene.ONE_PART`) is written as ``plan/1``, as it always
was, so that the tools reading those files keep working; every other plan as ``plan/2``. Both are
read, every field checked: :func:`load_plan`.

>>> from planner.model.segments import Push
>>> push = Push.along(0, np.zeros((2, 2)), [1.0, 0.0, 0.0], 0.5, np.zeros(3))
>>> plan = Plan.of_part("part", np.zeros(3), push.end, [push], scene=None, solved=True, planner="rrt", seed=1,
...                    planning_time_s=0.0, switch_cost=0.25, cf=np.zeros(2))
>>> plan.to_dict()["format"], read_plan(plan.to_dict()).headline() == plan.headline()
('stablepush.plan/1', True)
>>> tray = Plan.of_part("red", np.zeros(3), push.end, [push], scene=None, solved=True, planner="rrt", seed=1,
...                    planning_time_s=0.0, switch_cost=0.25, cf=np.zeros(2))
>>> tray.to_dict()["format"], read_plan(tray.to_dict()).moves[0].part
('stablepush.plan/2', 'red')
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from .fields import SceneError, integer, keys, number, shown, vector
from .json_file import read_json
from .margin import check_margin
from .plan import FORMAT, FORMATS, Move, Plan
from .scene import ONE_PART
from .segments import Push, Transfer, Transit

__all__ = ["FORMAT", "FORMATS", "MAX_BYTES", "load_plan", "part_field", "read_plan"]

#: Largest plan file read: a plan of ten thousand segments with their transits' paths.
MAX_BYTES = 10_000_000


def read_plan(data: Any) -> Plan:
    """A plan from its JSON form, either format, every field checked (errors name ``plan.<field>``)."""
    keys(data, "plan", ("format",), tuple(data) if isinstance(data, dict) else ())  # a mapping with a format
    # A file's huge numbers (a twist of 1e300) overflow to inf in the lengths and costs made from
    # them: refused by the checks that follow, not warned of first.
    with np.errstate(all="ignore"):
        if data.get("format") == FORMATS[0]:
            return _read_one_part(data)
        if data.get("format") == FORMATS[1]:
            return _read_parts(data)
    raise SceneError("plan.format", f"must be one of {', '.join(map(repr, FORMATS))}, got {shown(data.get('format'))}")


def part_field(plan: Plan, part: str, key: str) -> str:
    """Part ``part``'s field ``key`` as ``plan``'s file names it, for errors about it: ``plan.<key>``
    in a ``plan/1`` file (:meth:`Plan.to_dict` writes one for a plan of
    :data:`~planner.model.scene.ONE_PART` alone), ``plan.parts.<part>.<key>`` in a ``plan/2``.

    >>> tray = Plan.of_part("red", np.zeros(3), np.zeros(3), [], scene=None, solved=True, planner="rrt", seed=1,
    ...                     planning_time_s=0.0)
    >>> part_field(tray, "red", "start"), part_field(read_plan(Plan.of_part(ONE_PART, np.zeros(3), np.zeros(3), [],
    ...     scene=None, solved=True, planner="rrt", seed=1, planning_time_s=0.0).to_dict()), ONE_PART, "start")
    ('plan.parts.red.start', 'plan.start')
    """
    return f"plan.{key}" if plan.format == FORMATS[0] else f"plan.parts.{part}.{key}"


def _check(plan: Plan, spec: dict) -> Plan:
    """``plan``, once what its file says of length and cost is what its segments make."""
    for name in ("length", "cost"):
        said, made = number(spec[name], f"plan.{name}") if name in spec else None, getattr(plan, name)
        if said is not None and (made is None or abs(said - made) > 1e-6):
            raise SceneError(f"plan.{name}", f"is {said:g}, but the segments make {_made(made, name)}")
    return plan


def _made(value: float | None, name: str) -> str:
    needs = "cf" if name == "length" else "cf and switch_cost"
    return f"{value:g}" if value is not None else f"no {name} without {needs}"


def _fields(spec: dict) -> dict[str, Any]:
    """The fields both formats share, checked."""
    if not isinstance(spec["solved"], bool):
        raise SceneError("plan.solved", f"must be true or false, got {shown(spec['solved'])}")
    if not isinstance(spec["segments"], list):
        raise SceneError("plan.segments", "must be a list")
    return {"scene": spec["scene"] if isinstance(spec["scene"], str) else None, "solved": spec["solved"],
            "planner": str(spec["planner"]), "seed": integer(spec["seed"], "plan.seed"),
            "planning_time_s": number(spec["planning_time_s"], "plan.planning_time_s"),
            "reason": str(spec.get("reason", "")),
            "switch_cost": number(spec["switch_cost"], "plan.switch_cost") if "switch_cost" in spec else None,
            "margin": check_margin(spec["margin"], "plan.margin") if "margin" in spec else None}


def _read_one_part(data: dict) -> Plan:
    """A ``plan/1`` file's plan: of :data:`~planner.model.scene.ONE_PART`."""
    spec = keys(data, "plan", ("format", "scene", "solved", "planner", "seed", "planning_time_s", "start",
                               "goal", "final", "segments"),
                ("reason", "cf", "length", "switch_cost", "cost", "improvements", "margin"))
    fields = _fields(spec)
    start = vector(spec["start"], "plan.start", 3)
    at = {ONE_PART: start}
    segments = [_segment(item, f"plan.segments[{i}]", at, ONE_PART) for i, item in enumerate(spec["segments"])]
    plan = Plan.of_part(ONE_PART, start, vector(spec["goal"], "plan.goal", 3), segments,
                        cf=vector(spec["cf"], "plan.cf", 2) if "cf" in spec else None,
                        improvements=[tuple(vector(row, f"plan.improvements[{i}]", 3).tolist())
                                      for i, row in enumerate(_list(spec.get("improvements", []), "plan.improvements"))],
                        **fields)
    if not np.allclose(vector(spec["final"], "plan.final", 3), plan.final, atol=1e-9):
        raise SceneError("plan.final", "is not the end of the last segment")
    return _check(plan, spec)


def _list(value: Any, name: str) -> list:
    if not isinstance(value, list):
        raise SceneError(name, "must be a list")
    return value


def _segment(item: Any, name: str, at: dict[str, np.ndarray], part: str) -> Push | Transit:
    """A push or transit of part ``part``, which stands at ``at[part]`` (moved to its end): a
    transit's part stands there, a push must begin there."""
    kind = item.get("kind") if isinstance(item, dict) else None
    if kind == "transit":
        segment = Transit.from_dict(item, name, at[part])
    elif kind == "push" or not isinstance(item, dict):
        segment = Push.from_dict(item, name)
    else:
        raise SceneError(f"{name}.kind", f"must be 'push' or 'transit', got {shown(kind)}")
    at[part] = segment.end
    return segment


def _read_parts(data: dict) -> Plan:
    """A ``plan/2`` file's plan: each part's segments follow on from where it stands, transfers go
    from the part just moved to the part moved next, and what the file says of finals, length and
    cost is what its segments make."""
    spec = keys(data, "plan", ("format", "scene", "solved", "planner", "seed", "planning_time_s", "parts", "segments"),
                ("reason", "switch_cost", "length", "cost", "margin"))
    fields = _fields(spec)
    listed = spec["parts"]
    if not isinstance(listed, dict) or not listed:
        raise SceneError("plan.parts", "must be a non-empty mapping of part names to their start, goal and final")
    parts = {str(n): keys(p, f"plan.parts.{n}", ("start", "goal", "final"), ("delivered", "cf")) for n, p in listed.items()}
    starts = {n: vector(p["start"], f"plan.parts.{n}.start", 3) for n, p in parts.items()}
    plan = Plan(starts=starts, goals={n: vector(p["goal"], f"plan.parts.{n}.goal", 3) for n, p in parts.items()},
                moves=_read_moves(spec["segments"], starts),
                delivered=tuple(n for n, p in parts.items() if p.get("delivered") is True),
                cfs={n: vector(p["cf"], f"plan.parts.{n}.cf", 2) for n, p in parts.items() if "cf" in p}, **fields)
    for n, final in plan.finals.items():
        if not np.allclose(vector(parts[n]["final"], f"plan.parts.{n}.final", 3), final, atol=1e-9):
            raise SceneError(f"plan.parts.{n}.final", "is not where the part's last segment leaves it")
    return _check(plan, spec)


def _read_moves(items: list, starts: Mapping[str, np.ndarray]) -> list[Move]:
    """The moves of a ``plan/2`` file's segments: a new move at each transfer, each segment checked
    to follow on from where its part stands."""
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
        before = at[part]
        segment = _segment({k: v for k, v in item.items() if k != "part"}, name, at, part)
        if not np.allclose(segment.start, before, atol=1e-9):
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
    if transfer is not None:
        raise SceneError("plan.segments", "ends with a transfer")
    return moves


def load_plan(path: str | Path) -> Plan:
    """Read a plan file of either format (written by ``plan``, by hand, or by another tool),
    checking every field.

    Raises
    ------
    SceneError
        Naming the field at fault (``plan.segments[2].twist: ...``), or ``plan`` for a file that
        cannot be read, is not a regular file, is larger than :data:`MAX_BYTES`, nests deeper than
        :data:`~planner.model.json_file.MAX_DEPTH` or is not JSON.
    """
    return read_plan(read_json(path, "plan", MAX_BYTES))
