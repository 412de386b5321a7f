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

import numpy as np

from mechanics import point_velocity

__all__ = ["FORMAT", "Segment", "Plan", "atomic_path", "write_atomic"]

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
