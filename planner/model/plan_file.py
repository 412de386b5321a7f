"""Plans and their JSON file format ``stablepush.plan/1`` (read by other tools; see the README).

A plan is a list of segments of two kinds. A push (:class:`Push`) holds the edge pushed, the
contact segment (slider frame), the body twist of the slider and the push's duration, so that
``end = start * exp(twist * duration)`` on SE(2). A transit (:class:`Transit`) moves the pusher
from one edge to another while the part stays still: the world poses of the pusher frame along
the way (:mod:`planner.actions.transit`). Angles are radians.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, ClassVar, Literal

import numpy as np
from numpy.typing import ArrayLike

from mechanics import exp_twist, point_velocity, relative_pose, transform_points, wrap_angle

from .fields import SceneError, integer, keys, number, vector
from .json_file import read_json

__all__ = ["FORMAT", "MAX_BYTES", "TRANSIT_MODES", "Push", "Transit", "Plan", "append_push", "load_plan", "path_cost",
           "path_length", "read_pusher_path", "rechain"]

FORMAT = "stablepush.plan/1"
#: Largest plan file read: a plan of ten thousand segments with their transits' paths.
MAX_BYTES = 10_000_000
#: How a transit moves the pusher: on the table, or lifted over it between two standoff poses.
TRANSIT_MODES = ("plane", "lift")


def _floats(values) -> list[float]:
    return [float(v) for v in np.asarray(values, dtype=float).ravel()]


@dataclass(frozen=True)
class Push:
    """One constant push: the slider pushed on ``edge`` with the body ``twist`` for ``duration``,
    from pose ``start`` to pose ``end``. :meth:`along` makes one from its start, so that its end
    is the exponential and the heading is wrapped, the same way everywhere.

    >>> push = Push.along(0, np.zeros((2, 2)), [1.0, 0.0, 0.0], 0.5, [0.0, 0.0, np.pi / 2])
    >>> push.end.round(12).tolist(), push.kind
    ([0.0, 0.5, 1.570796326795], 'push')
    """

    kind: ClassVar[Literal["push"]] = "push"

    edge: int
    contact: np.ndarray  # (2, 2), slider frame
    twist: np.ndarray  # slider-frame body twist (vx, vy, omega)
    duration: float
    start: np.ndarray  # pose (x, y, theta)
    end: np.ndarray

    def to_dict(self) -> dict:
        return {
            "kind": "push",
            "edge": int(self.edge),
            "contact": np.asarray(self.contact, dtype=float).tolist(),
            "twist": _floats(self.twist),
            "duration": float(self.duration),
            "start": _floats(self.start),
            "end": _floats(self.end),
        }

    @classmethod
    def from_dict(cls, data: Any, name: str) -> "Push":
        """Read a segment of a plan file, checking every field (errors name ``name``.field)."""
        spec = keys(data, name, ("kind", "edge", "contact", "twist", "duration", "start", "end"))
        if spec["kind"] != "push":
            raise SceneError(f"{name}.kind", f"must be 'push', got {spec['kind']!r}")
        contact = spec["contact"]
        if not isinstance(contact, list) or len(contact) != 2:
            raise SceneError(f"{name}.contact", "must be two [x, y] points")
        duration = number(spec["duration"], f"{name}.duration")
        if duration < 0:
            raise SceneError(f"{name}.duration", f"must be >= 0, got {duration}")
        return cls(
            edge=integer(spec["edge"], f"{name}.edge"),
            contact=np.array([vector(p, f"{name}.contact[{i}]", 2) for i, p in enumerate(contact)]),
            twist=vector(spec["twist"], f"{name}.twist", 3),
            duration=duration,
            start=vector(spec["start"], f"{name}.start", 3),
            end=vector(spec["end"], f"{name}.end", 3),
        )

    @classmethod
    def along(cls, edge: int, contact: np.ndarray, twist: ArrayLike, duration: float, start: ArrayLike) -> "Push":
        """The push of ``twist`` for ``duration`` from ``start``: it ends at
        ``start * exp(twist * duration)``, heading wrapped to ``[-pi, pi)``."""
        start = np.array(start, dtype=float)
        end = exp_twist(start, twist, duration)
        end[2] = wrap_angle(end[2])
        return cls(edge, contact, np.asarray(twist, dtype=float), float(duration), start, end)

    def moved(self, start: ArrayLike) -> "Push":
        """The same push begun at ``start``."""
        return Push.along(self.edge, self.contact, self.twist, self.duration, start)

    @property
    def from_edge(self) -> int:
        """The edge the pusher is on as the push begins (as a :class:`Transit`'s): its own."""
        return self.edge

    def cf_path_length(self, cf: np.ndarray) -> float:
        """Distance the centre of friction travels: its speed is constant under a constant twist."""
        return float(np.linalg.norm(point_velocity(self.twist, cf)) * self.duration)


@dataclass(frozen=True)
class Transit:
    """The pusher's move from the contact on ``from_edge`` to the contact on ``to_edge``.

    ``pusher_path`` holds world poses of the pusher frame (origin at the middle of the pushing
    face, x along the push direction): the first is the contact pose on ``from_edge``, the last
    the contact pose on ``to_edge``, both with the part at ``pose``, which does not move. In
    ``'plane'`` mode the pusher moves between consecutive poses by linear interpolation of
    ``(x, y, theta)`` (theta the shorter way); in ``'lift'`` mode there are four poses (contact,
    retreat, approach, contact) and the middle piece is airborne. ``duration`` is the time at 1 m/s.

    >>> t = Transit(0, 2, "lift", np.array([[0, 0, 0], [-0.1, 0, 0], [0.5, 0, np.pi], [0.4, 0, np.pi]]), 0.7,
    ...             np.zeros(3))
    >>> t.to_dict()["kind"], t.end.tolist(), t.twist.tolist()
    ('transit', [0.0, 0.0, 0.0], [0.0, 0.0, 0.0])
    """

    kind: ClassVar[Literal["transit"]] = "transit"

    from_edge: int
    to_edge: int
    mode: str
    pusher_path: np.ndarray  # (m, 3) world poses of the pusher frame
    duration: float
    pose: np.ndarray  # the part's pose throughout (not in the file: the previous segment's end)

    @property
    def start(self) -> np.ndarray:
        return self.pose

    @property
    def end(self) -> np.ndarray:
        return self.pose

    @property
    def twist(self) -> np.ndarray:
        """The part's body twist: zero, it stands still."""
        return np.zeros(3)

    @property
    def edge(self) -> int:
        """The edge the pusher is on once the transit is over."""
        return self.to_edge

    def cf_path_length(self, cf: np.ndarray) -> float:
        return 0.0

    def moved(self, pose: ArrayLike) -> "Transit":
        """The same transit with the part at ``pose``: the pusher's path moves rigidly with it."""
        local = relative_pose(self.pose, self.pusher_path)
        path = np.column_stack([transform_points(local[:, :2], pose), wrap_angle(local[:, 2] + pose[2])])
        return replace(self, pose=np.asarray(pose, dtype=float), pusher_path=path)

    def to_dict(self) -> dict:
        return {
            "kind": "transit",
            "from_edge": int(self.from_edge),
            "to_edge": int(self.to_edge),
            "mode": self.mode,
            "pusher_path": np.asarray(self.pusher_path, dtype=float).tolist(),
            "duration": float(self.duration),
        }

    @classmethod
    def from_dict(cls, data: Any, name: str, pose: np.ndarray) -> "Transit":
        """Read a transit of a plan file with the part at ``pose``, checking every field."""
        spec = keys(data, name, ("kind", "from_edge", "to_edge", "mode", "pusher_path", "duration"))
        mode, path, duration = read_pusher_path(spec, name)
        return cls(
            from_edge=integer(spec["from_edge"], f"{name}.from_edge"),
            to_edge=integer(spec["to_edge"], f"{name}.to_edge"),
            mode=mode,
            pusher_path=path,
            duration=duration,
            pose=np.array(pose, dtype=float),
        )


def read_pusher_path(spec: dict, name: str) -> tuple[str, np.ndarray, float]:
    """The ``mode``, ``pusher_path`` and ``duration`` of a transit (or a multi-part plan's
    transfer) read from a file, checked: a known mode, at least two poses (a lift exactly four),
    a duration >= 0."""
    if spec["mode"] not in TRANSIT_MODES:
        raise SceneError(f"{name}.mode", f"must be one of {', '.join(TRANSIT_MODES)}, got {spec['mode']!r}")
    path = spec["pusher_path"]
    if not isinstance(path, list) or len(path) < 2:
        raise SceneError(f"{name}.pusher_path", "must be a list of at least two [x, y, theta] poses")
    if spec["mode"] == "lift" and len(path) != 4:
        raise SceneError(f"{name}.pusher_path", f"a lift has exactly 4 poses, got {len(path)}")
    duration = number(spec["duration"], f"{name}.duration")
    if duration < 0:
        raise SceneError(f"{name}.duration", f"must be >= 0, got {duration}")
    return spec["mode"], np.array([vector(p, f"{name}.pusher_path[{i}]", 3) for i, p in enumerate(path)]), duration


def append_push(segments: list, push: Push) -> None:
    """Append ``push`` to ``segments``, as one push with the last if that is a push of the same
    edge and twist: one push of both durations from its start, its end composed once.

    >>> segments = [Push.along(0, np.zeros((2, 2)), [1.0, 0.0, 0.0], 0.25, [0.0, 0.0, 0.0])]
    >>> append_push(segments, segments[0].moved(segments[0].end))
    >>> len(segments), segments[0].duration, segments[0].end.tolist()
    (1, 0.5, [0.5, 0.0, 0.0])
    """
    last = segments[-1] if segments else None
    if last is not None and last.kind == "push" and last.edge == push.edge and np.array_equal(last.twist, push.twist):
        segments[-1] = Push.along(last.edge, last.contact, last.twist, last.duration + push.duration, last.start)
    else:
        segments.append(push)


def path_length(segments: Sequence[Push | Transit], cf: ArrayLike) -> float:
    """Length of the path of the centre of friction ``cf`` (slider frame) along ``segments``."""
    return sum(s.cf_path_length(np.asarray(cf, dtype=float)) for s in segments)


def path_cost(segments: Sequence[Push | Transit], cf: ArrayLike, switch_cost: float) -> float:
    """What the planner minimises (Lynch & Mason 1996, §4: a cost per contact change): the centre
    of friction's path length plus ``switch_cost`` per switch (transit). The one definition: a
    plan's :attr:`Plan.cost`, the search's and the benchmarks' all come from it."""
    return path_length(segments, cf) + switch_cost * sum(s.kind == "transit" for s in segments)


def rechain(segments: list, start: ArrayLike | None = None) -> list:
    """Each segment re-anchored where the one before it ends, the first at ``start`` (default:
    where it begins): a push begun there, a transit's path moved rigidly with the part. Pieces
    made apart (a Dubins curve's pushes, a connection found from a pose equal but for rounding)
    then chain exactly, as a plan's poses must.

    >>> a = Push.along(0, np.zeros((2, 2)), [1.0, 0.0, 0.0], 1.0, [0.0, 0.0, 0.0])
    >>> b = Push.along(0, np.zeros((2, 2)), [0.0, 1.0, 0.0], 1.0, [1.0 + 1e-13, 0.0, 0.0])
    >>> [s.end.tolist() for s in rechain([a, b])]
    [[1.0, 0.0, 0.0], [1.0, 1.0, 0.0]]
    """
    out: list = []
    for s in segments:
        pose = out[-1].end if out else (s.start if start is None else start)
        out.append(s.moved(pose))
    return out


@dataclass(frozen=True, kw_only=True)
class Plan:
    """The result of :func:`planner.plan`: made by keyword, once, never changed after."""

    scene: str | None
    solved: bool
    planner: str
    seed: int
    planning_time_s: float
    start: np.ndarray
    goal: np.ndarray
    segments: list[Push | Transit] = field(default_factory=list)
    reason: str = ""  # why it is not solved
    note: str = ""  # what the user should know of a plan made with less than asked (not in the file)
    #: Metres a switch costs, as the planner counted: ``cost = length + switch_cost * switches``.
    switch_cost: float | None = None
    #: The part's centre of friction (slider frame), whose path :attr:`length` measures.
    cf: np.ndarray | None = field(default=None, repr=False)
    #: ``(planning time s, cost m, length m)`` of the first plan found and of each better one after it.
    improvements: list[tuple[float, float, float]] = field(default_factory=list)
    tree: np.ndarray = field(default_factory=lambda: np.zeros((0, 2, 2)), repr=False)  # search tree, world xy

    @property
    def final(self) -> np.ndarray:
        return self.segments[-1].end if self.segments else self.start

    @property
    def pushes(self) -> int:
        return sum(s.kind == "push" for s in self.segments)

    @property
    def switches(self) -> int:
        """How many times the pusher changes edge (transits)."""
        return sum(s.kind == "transit" for s in self.segments)

    def contents(self, joiner: str = ", ") -> str:
        """What the plan is made of, in words: ``'3 pushes'``, ``'1 push, 2 switches'``.

        >>> Plan(scene=None, solved=True, planner="rrt", seed=1, planning_time_s=0.0, start=np.zeros(3),
        ...      goal=np.zeros(3)).contents()
        '0 pushes'
        """
        def count(n: int, word: str, plural: str) -> str:
            return f"{n} {word if n == 1 else plural}"

        pushes = count(self.pushes, "push", "pushes")
        return f"{pushes}{joiner}{count(self.switches, 'switch', 'switches')}" if self.switches else pushes

    def headline(self) -> str:
        """What a solved plan is and costs, as the ``plan`` command's line says it after ``solved:``
        (and the README quotes it): ``'6 pushes, 1 switch, cost 0.789 m, length 0.539 m'``."""
        return f"{self.contents()}, cost {self.cost:.3f} m, length {self.length:.3f} m"

    def path_length(self, cf: np.ndarray) -> float:
        """Length of the path of the centre of friction ``cf`` (slider frame)."""
        return path_length(self.segments, cf)

    @property
    def length(self) -> float | None:
        """Length of the centre of friction's path, where the plan knows its part's CF."""
        return None if self.cf is None else self.path_length(self.cf)

    @property
    def cost(self) -> float | None:
        """What the planner minimises: :attr:`length` plus :attr:`switch_cost` per switch, where
        both are known.

        >>> push = Push.along(0, np.zeros((2, 2)), [1.0, 0.0, 0.0], 0.5, np.zeros(3))
        >>> transit = Transit(0, 2, "lift", np.zeros((4, 3)), 0.1, push.end)
        >>> plan = Plan(scene=None, solved=True, planner="rrt", seed=1, planning_time_s=0.0, start=np.zeros(3),
        ...             goal=push.end, segments=[push, transit], switch_cost=0.25, cf=np.zeros(2))
        >>> plan.length, plan.cost
        (0.5, 0.75)
        """
        return None if self.cf is None or self.switch_cost is None else path_cost(self.segments, self.cf, self.switch_cost)

    def to_dict(self) -> dict:
        return {
            "format": FORMAT,
            "scene": self.scene,
            "solved": bool(self.solved),
            "planner": self.planner,
            "seed": int(self.seed),
            "planning_time_s": round(float(self.planning_time_s), 4),
            "start": _floats(self.start),
            "goal": _floats(self.goal),
            "final": _floats(self.final),
            "segments": [s.to_dict() for s in self.segments],
        } | ({"reason": self.reason} if self.reason and not self.solved else {}) | self._costs()

    def _costs(self) -> dict:
        """The file's cost fields, those a solved plan knows: the CF, length, switch cost, cost and
        improvements (an unsolved plan's segments are not a way to the goal: no cost is said)."""
        out: dict[str, Any] = {}
        if not self.solved:
            return out
        if self.cf is not None:
            out["cf"] = _floats(self.cf)
            out["length"] = round(self.length, 9)
        if self.switch_cost is not None:
            out["switch_cost"] = float(self.switch_cost)
        if self.cost is not None:
            out["cost"] = round(self.cost, 9)
        if self.improvements:
            out["improvements"] = [[round(t, 4), round(c, 9), round(n, 9)] for t, c, n in self.improvements]
        return out

    def to_json(self) -> str:
        return json.dumps(self.to_dict(), indent=1)

    @classmethod
    def from_dict(cls, data: Any) -> "Plan":
        """A plan from its JSON form (``stablepush.plan/1``), every field checked."""
        spec = keys(data, "plan", ("format", "scene", "solved", "planner", "seed", "planning_time_s", "start",
                                   "goal", "final", "segments"),
                    ("reason", "cf", "length", "switch_cost", "cost", "improvements"))
        if spec["format"] != FORMAT:
            raise SceneError("plan.format", f"must be {FORMAT!r}, got {spec['format']!r}")
        if not isinstance(spec["solved"], bool):
            raise SceneError("plan.solved", f"must be true or false, got {spec['solved']!r}")
        if not isinstance(spec["segments"], list):
            raise SceneError("plan.segments", "must be a list")
        start = vector(spec["start"], "plan.start", 3)
        plan = cls(
            scene=spec["scene"] if isinstance(spec["scene"], str) else None,
            solved=spec["solved"],
            planner=str(spec["planner"]),
            seed=integer(spec["seed"], "plan.seed"),
            planning_time_s=number(spec["planning_time_s"], "plan.planning_time_s"),
            start=start,
            goal=vector(spec["goal"], "plan.goal", 3),
            segments=_read_segments(spec["segments"], start),
            reason=str(spec.get("reason", "")),
            switch_cost=number(spec["switch_cost"], "plan.switch_cost") if "switch_cost" in spec else None,
            cf=vector(spec["cf"], "plan.cf", 2) if "cf" in spec else None,
            improvements=[tuple(vector(row, f"plan.improvements[{i}]", 3).tolist())
                          for i, row in enumerate(_list(spec.get("improvements", []), "plan.improvements"))],
        )
        final = vector(spec["final"], "plan.final", 3)
        if not np.allclose(final, plan.final, atol=1e-9):
            raise SceneError("plan.final", "is not the end of the last segment")
        for name in ("length", "cost"):  # what the file says must be what its segments make
            said, made = number(spec[name], f"plan.{name}") if name in spec else None, getattr(plan, name)
            if said is not None and (made is None or abs(said - made) > 1e-6):
                raise SceneError(f"plan.{name}", f"is {said:g}, but the segments make {_made(made, name)}")
        return plan


def _made(value: float | None, name: str) -> str:
    needs = "cf" if name == "length" else "cf and switch_cost"
    return f"{value:g}" if value is not None else f"no {name} without {needs}"


def _list(value: Any, name: str) -> list:
    if not isinstance(value, list):
        raise SceneError(name, "must be a list")
    return value


def _read_segments(items: list, start: np.ndarray) -> list[Push | Transit]:
    """Pushes and transits, each transit taking the part's pose from the segment before it."""
    out: list[Push | Transit] = []
    for i, item in enumerate(items):
        name = f"plan.segments[{i}]"
        kind = item.get("kind") if isinstance(item, dict) else None
        if kind == "transit":
            out.append(Transit.from_dict(item, name, out[-1].end if out else start))
        elif kind == "push" or not isinstance(item, dict):
            out.append(Push.from_dict(item, name))
        else:
            raise SceneError(f"{name}.kind", f"must be 'push' or 'transit', got {kind!r}")
    return out


def load_plan(path: str | Path) -> Plan:
    """Read a plan file written by ``plan`` (or by hand, or another tool), checking every field.

    Raises
    ------
    SceneError
        Naming the field at fault (``plan.segments[2].twist: ...``), or ``plan`` for a file that
        cannot be read, is not a regular file, is larger than :data:`MAX_BYTES`, nests deeper than
        :data:`~planner.model.json_file.MAX_DEPTH` or is not JSON.
    """
    data = read_json(path, "plan", MAX_BYTES)
    return Plan.from_dict(data)
