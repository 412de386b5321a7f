"""Shared by the arm's tests (tests/planner/arm, tests/planner/execution): a shipped scene with a
``robot:`` block added, and the ``plan`` command run on it in a fresh process."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[2]


def with_robot(tmp_path: Path, scene: str, robot: dict) -> Path:
    """``scenes/<scene>`` with ``robot`` as its ``robot:`` block, written in ``tmp_path``."""
    spec = yaml.safe_load((ROOT / "scenes" / scene).read_text())
    spec["robot"] = robot
    path = tmp_path / Path(scene).name
    path.write_text(yaml.safe_dump(spec))
    return path


def plan(*args: str, cwd: Path) -> subprocess.CompletedProcess:
    """``plan *args`` run from ``cwd`` on this tree."""
    return subprocess.run([sys.executable, "-m", "planner.cli", *args], capture_output=True, text=True, cwd=cwd,
                          timeout=600, env={"PYTHONPATH": str(ROOT), "PATH": "/usr/bin:/bin"})
