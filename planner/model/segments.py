"""The segments of a plan: pushes of a part, the pusher's transits between two edges of it, and
its transfers from one part to another.

A push (:class:`Push`) holds the edge pushed, the contact segment (slider frame), the body twist
of the slider and the push's duration, so that ``end = start * exp(twist * duration)`` on SE(2).
A transit (:class:`Transit`) moves the pusher from one edge to another while the part stays
still: the world poses of the pusher frame along the way (:mod:`planner.actions.transit`). A
transfer (:class:`Transfer`) moves it from the contact on one part to the first contact on the
next, every part standing still. Angles are radians.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Any, ClassVar, Literal

import numpy as np
from numpy.typing import ArrayLike

from mechanics import exp_twist, point_velocity, relative_pose, transform_points, wrap_angle

from .fields import SceneError, integer, keys, number, shown, vector

__all__ = ["TRANSIT_MODES", "Push", "Transfer", "Transit", "append_push", "floats", "path_cost", "path_length",
           "read_pusher_path", "rechain"]

#: How a transit moves the pusher: on the table, or lifted over it between two standoff poses.
TRANSIT_MODES = ("plane", "lift")


def floats(values) -> list[float]:
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
            "twist": floats(self.twist),
            "duration": float(self.duration),
            "start": floats(self.start),
            "end": floats(self.end),
        }

    @classmethod
    def from_dict(cls, data: Any, name: str) -> "Push":
        """Read a segment of a plan file, checking every field (errors name ``name``.field)."""
        # A push's "margin" is what the planner certified; it is certified again where it is shown.
        spec = keys(data, name, ("kind", "edge", "contact", "twist", "duration", "start", "end"), ("margin",))
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


@dataclass(frozen=True)
class Transfer:
    """The pusher's travel from its contact on ``from_part`` to the contact on ``to_part``'s
    ``to_edge``, every part standing still. ``pusher_path`` holds world poses of the pusher frame
    with the interpolation rules of a :class:`~planner.model.segments.Transit`: straight
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
    if isinstance(last, Push) and last.edge == push.edge and np.array_equal(last.twist, push.twist):
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
    return path_length(segments, cf) + switch_cost * sum(isinstance(s, Transit) for s in segments)


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
