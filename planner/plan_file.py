"""Plans and their JSON file format ``stablepush.plan/1`` (read by other tools; see the README).

A plan is a list of push segments. Each holds the edge pushed, the contact segment (slider
frame), the body twist of the slider and the push's duration, so that ``end = start *
exp(twist * duration)`` on SE(2). Angles are radians.
"""

from __future__ import annotations

import json
import os
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from mechanics import point_velocity

from .fields import SceneError, integer, keys, number, vector

__all__ = ["FORMAT", "Segment", "Plan", "atomic_path", "load_plan", "write_atomic"]

FORMAT = "stablepush.plan/1"


def _floats(values) -> list[float]:
    return [float(v) for v in np.asarray(values, dtype=float).ravel()]


@dataclass(frozen=True)
class Segment:
    """One constant push."""

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
    def from_dict(cls, data: Any, name: str) -> "Segment":
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

    def cf_path_length(self, cf: np.ndarray) -> float:
        """Distance the centre of friction travels: its speed is constant under a constant twist."""
        return float(np.linalg.norm(point_velocity(self.twist, cf)) * self.duration)


@dataclass
class Plan:
    """The result of :func:`planner.plan`."""

    scene: str | None
    solved: bool
    planner: str
    seed: int
    planning_time_s: float
    start: np.ndarray
    goal: np.ndarray
    segments: list[Segment] = field(default_factory=list)
    reason: str = ""  # why it is not solved
    tree: np.ndarray = field(default_factory=lambda: np.zeros((0, 2, 2)), repr=False)  # search tree, world xy

    @property
    def final(self) -> np.ndarray:
        return self.segments[-1].end if self.segments else self.start

    @property
    def pushes(self) -> int:
        return len(self.segments)

    def path_length(self, cf: np.ndarray) -> float:
        """Length of the path of the centre of friction ``cf`` (slider frame)."""
        return sum(s.cf_path_length(cf) for s in self.segments)

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
        }

    def to_json(self) -> str:
        return json.dumps(self.to_dict(), indent=1)

    @classmethod
    def from_dict(cls, data: Any) -> "Plan":
        """A plan from its JSON form (``stablepush.plan/1``), every field checked."""
        spec = keys(data, "plan", ("format", "scene", "solved", "planner", "seed", "planning_time_s", "start",
                                   "goal", "final", "segments"))
        if spec["format"] != FORMAT:
            raise SceneError("plan.format", f"must be {FORMAT!r}, got {spec['format']!r}")
        if not isinstance(spec["solved"], bool):
            raise SceneError("plan.solved", f"must be true or false, got {spec['solved']!r}")
        if not isinstance(spec["segments"], list):
            raise SceneError("plan.segments", "must be a list")
        plan = cls(
            scene=spec["scene"] if isinstance(spec["scene"], str) else None,
            solved=spec["solved"],
            planner=str(spec["planner"]),
            seed=integer(spec["seed"], "plan.seed"),
            planning_time_s=number(spec["planning_time_s"], "plan.planning_time_s"),
            start=vector(spec["start"], "plan.start", 3),
            goal=vector(spec["goal"], "plan.goal", 3),
            segments=[Segment.from_dict(s, f"plan.segments[{i}]") for i, s in enumerate(spec["segments"])],
        )
        final = vector(spec["final"], "plan.final", 3)
        if not np.allclose(final, plan.final, atol=1e-9):
            raise SceneError("plan.final", "is not the end of the last segment")
        return plan


def load_plan(path: str | Path) -> Plan:
    """Read a plan file written by ``plan`` (or by hand, or another tool), checking every field.

    Raises
    ------
    SceneError
        Naming the field at fault (``plan.segments[2].twist: ...``) or the file if unreadable.
    """
    try:
        data = json.loads(Path(path).read_text())
    except OSError as err:
        raise SceneError("plan", f"cannot read {str(path)!r}: {err.strerror or err}") from None
    except (UnicodeDecodeError, json.JSONDecodeError) as err:
        raise SceneError("plan", f"{str(path)!r} is not valid JSON: {err}") from None
    return Plan.from_dict(data)


@contextmanager
def atomic_path(path: str | Path) -> Iterator[Path]:
    """Yield a temporary path beside ``path``; when the block succeeds, flush it to disk and rename
    it onto ``path``; when it fails, delete it. Readers see the old file or the whole new one."""
    path = Path(path)
    fd, name = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    os.close(fd)
    tmp = Path(name)
    try:
        yield tmp
        umask = os.umask(0)
        os.umask(umask)
        tmp.chmod(0o666 & ~umask)  # mkstemp makes files private; outputs are ordinary files
        with open(tmp, "rb") as f:
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise


def write_atomic(path: str | Path, data: str | bytes) -> None:
    """Write ``data`` to ``path`` atomically (see :func:`atomic_path`)."""
    with atomic_path(path) as tmp:
        tmp.write_bytes(data.encode() if isinstance(data, str) else data)
