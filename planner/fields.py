"""Checked input fields: each check raises :class:`SceneError` naming the field at fault.

Scene files and plan files share these, so both report bad input the same way: one line,
``field: problem``, which the command line prints before exiting with code 1.
"""

from __future__ import annotations

import sys
from typing import Any

import numpy as np

__all__ = ["SceneError", "integer", "keys", "number", "vector"]


class SceneError(ValueError):
    """Bad input, with the dotted name of the field at fault (``str()`` is ``"field: problem"``)."""

    def __init__(self, field: str, problem: str):
        super().__init__(f"{field}: {problem}")
        self.field = field
        self.problem = problem


def keys(value: Any, name: str, required: tuple[str, ...], optional: tuple[str, ...] = ()) -> dict:
    """``value`` as a mapping with all of ``required`` and nothing but those and ``optional``."""
    if not isinstance(value, dict):
        raise SceneError(name, f"must be a mapping with keys {', '.join(required + optional)}")
    for key in value:
        if key not in required + optional:
            raise SceneError(f"{name}.{key}" if name != "scene" else str(key), "unknown key")
    for key in required:
        if key not in value:
            raise SceneError(f"{name}.{key}" if name != "scene" else key, "missing")
    return value


def number(value: Any, name: str, positive: bool = False) -> float:
    """``value`` as a finite float (> 0 if ``positive``)."""
    # Comparing (exactly, for ints) rather than math.isfinite(), which raises on ints beyond a float.
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not abs(value) <= sys.float_info.max:
        raise SceneError(name, f"must be a finite number, got {value!r}")
    if positive and not value > 0:
        raise SceneError(name, f"must be > 0, got {value!r}")
    return float(value)


def integer(value: Any, name: str) -> int:
    """``value`` as an int (booleans are not integers here)."""
    if isinstance(value, bool) or not isinstance(value, int):
        raise SceneError(name, f"must be an integer, got {value!r}")
    return value


def vector(value: Any, name: str, size: int) -> np.ndarray:
    """``value`` as a list of ``size`` finite numbers."""
    if not isinstance(value, (list, tuple)) or len(value) != size:
        raise SceneError(name, f"must be a list of {size} numbers, got {value!r}")
    return np.array([number(v, f"{name}[{i}]") for i, v in enumerate(value)])
