"""Checked input fields: each check raises :class:`SceneError` naming the field at fault.

Scene files and plan files share these, so both report bad input the same way: one line,
``field: problem``, which the command line prints before exiting with code 1. Whatever the input
holds, the line stays one line and short: values are quoted by :func:`shown` (plain numbers,
control characters escaped, at most :data:`MAX_SHOWN` characters) and :class:`SceneError` escapes
anything left that could break the line.
"""

from __future__ import annotations

import difflib
import re
import numbers
import reprlib
import sys
from dataclasses import dataclass
from typing import Any

import numpy as np

from mechanics import wrap_angle

__all__ = ["ANGLE", "LENGTH", "MAX_SHOWN", "FileFieldError", "Limit", "SceneError", "counted", "integer", "keys", "member", "number", "pose", "pose_text", "poses", "shown",
           "vector"]

#: Most characters of a bad value a message quotes: enough to recognise it, never a flood.
MAX_SHOWN = 100
#: Longest field name and problem a message keeps (clipped beyond): a line of about 300 characters at most.
_MAX_FIELD, _MAX_PROBLEM = 100, 196


def _printable(text: str) -> str:
    """``text`` with each non-printable character (newlines, tabs, NUL, U+2028...) as its escape."""
    return text if text.isprintable() else "".join(c if c.isprintable() else repr(c)[1:-1] for c in text)


def _clipped(text: str, size: int) -> str:
    """``text``, or if it is longer than ``size`` characters its start and ``...``, ``size`` in all."""
    return text if len(text) <= size else text[:size - 3] + "..."


class SceneError(ValueError):
    """Bad input, with the dotted name of the field at fault (``str()`` is ``"field: problem"``).

    Both parts are escaped and clipped (the field to 100 characters, the problem to 196), so the
    message is one short line whatever input they quote:

    >>> str(SceneError("a\\nb", "unknown key"))
    'a\\\\nb: unknown key'
    """

    def __init__(self, field: str, problem: str):
        self.field = _clipped(_printable(field), _MAX_FIELD)
        self.problem = _clipped(_printable(problem), _MAX_PROBLEM)
        super().__init__(f"{self.field}: {self.problem}")


class FileFieldError(SceneError):
    """A :class:`SceneError` naming a field of a file the command read (a scene's ``part:``), which
    the command prints as it is, never as its flag of the same name (``--part``)."""


_REPR = reprlib.Repr()
_REPR.maxstring = _REPR.maxother = MAX_SHOWN  # reprlib elides the middle of long strings and reprs
_REPR.maxlist = _REPR.maxtuple = _REPR.maxdict = 8


def shown(value: Any) -> str:
    """``value`` as a message quotes it: its ``repr`` (so control characters are escaped), numpy
    numbers as plain ones, long lists, strings and nestings elided, at most :data:`MAX_SHOWN` characters.

    >>> shown(np.array([-0.1, 0.1])), shown("a\\tb"), shown([[0, 0]] * 50)
    ('[-0.1, 0.1]', "'a\\\\tb'", '[[0, 0], [0, 0], [0, 0], [0, 0], [0, 0], [0, 0], [0, 0], [0, 0], ...]')
    >>> len(shown("x" * 10**6)) <= MAX_SHOWN
    True
    """
    if isinstance(value, (np.ndarray, np.generic)):
        value = value.tolist()
    return _clipped(_REPR.repr(value), MAX_SHOWN)


#: A key that names itself plainly in a dotted field name; any other is quoted (:func:`shown`).
_PLAIN_KEY = re.compile(r"[A-Za-z0-9_-]{1,40}")


def counted(n: int, word: str) -> str:
    """``n`` and ``word``, plural unless ``n`` is 1.

    >>> counted(1, "push"), counted(3, "push"), counted(2, "switch"), counted(0, "re-plan")
    ('1 push', '3 pushes', '2 switches', '0 re-plans')
    """
    return f"{n} {word if n == 1 else word + ('es' if word.endswith(('sh', 'ch')) else 's')}"


def pose_text(pose: Any) -> str:
    """A pose ``(x, y, theta)`` (m, m, rad) for a line on screen, every unit named: a heading is
    radians in plan files and degrees in scene files, so both are shown.

    >>> pose_text([0.1, -0.25, np.pi / 2])
    '[0.1000 m, -0.2500 m, 1.5708 rad = 90.00 deg]'
    """
    x, y, theta = (float(v) for v in pose)
    return f"[{x:.4f} m, {y:.4f} m, {theta:.4f} rad = {np.degrees(theta):.2f} deg]"


def member(name: str, key: Any) -> str:
    """The dotted field name of ``key`` in the mapping ``name`` (the top level, ``scene``, adds no prefix).

    >>> member("pusher", "mu"), member("scene", "colour"), member("slider", "a.b\\n")
    ('pusher.mu', 'colour', "slider.'a.b\\\\n'")
    """
    text = key if isinstance(key, str) and _PLAIN_KEY.fullmatch(key) else shown(key)
    return text if name == "scene" else f"{name}.{text}"


def keys(value: Any, name: str, required: tuple[str, ...], optional: tuple[str, ...] = (),
         suggest: tuple[str, ...] = ()) -> dict:
    """``value`` as a mapping with all of ``required`` and nothing but those and ``optional``; an
    unknown key's error names the known key it most resembles, if one is close, or one of
    ``suggest`` (keys of another form of the same thing, as a tray's ``parts``).

    >>> keys({"worksapce": 1}, "scene", ("workspace", "start"))
    Traceback (most recent call last):
    ...
    planner.model.fields.SceneError: worksapce: unknown key; did you mean workspace?
    >>> keys({"colour": 1}, "pusher", ("width",), ("mu",))
    Traceback (most recent call last):
    ...
    planner.model.fields.SceneError: pusher.colour: unknown key (known: width, mu)
    """
    if not isinstance(value, dict):
        raise SceneError(name, f"must be a mapping with keys {', '.join(required + optional)}")
    for key in value:
        if key not in required + optional:
            close = difflib.get_close_matches(str(key), required + optional + suggest, n=1)
            hint = f"; did you mean {close[0]}?" if close else f" (known: {', '.join(required + optional)})"
            raise SceneError(member(name, key), f"unknown key{hint}")
    for key in required:
        if key not in value:
            raise SceneError(member(name, key), "missing")
    return value


@dataclass(frozen=True)
class Limit:
    """The largest magnitude a kind of number may have (``bound``), in ``unit``."""

    bound: float
    unit: str

    def check(self, value: float, name: str) -> float:
        """``value``, if its magnitude is at most ``bound``; else a :class:`SceneError` naming ``name``."""
        if abs(value) > self.bound:
            raise SceneError(name, f"must be at most {self.bound:g} {self.unit} in absolute value, "
                                   f"got {shown(float(value))}")
        return value


#: Every coordinate and length of the input, in metres: a kilometre is far beyond any table, keeps
#: squares and areas far from overflow, and is where the recording's 32-bit floats still resolve
#: 0.1 mm (float64 resolves 1e-13 m there, so a micron-sized feature anywhere is exact to 1e-7).
LENGTH = Limit(1e3, "m")
#: Every angle of the input, in degrees: 2777 turns, wrapped to within 1e-10 degrees. Beyond some
#: 1e16 degrees a float has no digits left below a turn, so the heading it meant is lost.
ANGLE = Limit(1e6, "degrees")


def number(value: Any, name: str, positive: bool = False, limit: Limit | None = None) -> float:
    """``value`` as a finite float (> 0 if ``positive``; within ``limit`` if given)."""
    # Comparing (exactly, for ints) rather than math.isfinite(), which raises on ints beyond a float.
    if isinstance(value, bool) or not isinstance(value, (numbers.Integral, numbers.Real)) \
            or not abs(value) <= sys.float_info.max:
        raise SceneError(name, f"must be a finite number, got {shown(value)}")
    if positive and not value > 0:
        raise SceneError(name, f"must be > 0, got {shown(value)}")
    return float(value if limit is None else limit.check(value, name))


def integer(value: Any, name: str) -> int:
    """``value`` as an int (booleans are not integers here)."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Integral):
        raise SceneError(name, f"must be an integer, got {shown(value)}")
    return int(value)


def poses(value: Any, name: str) -> np.ndarray:
    """``value`` (one pose ``(x, y, theta)`` or a sequence of them, radians) as finite poses of
    shape ``(n, 3)``, headings wrapped to ``[-pi, pi)``: what the Python API takes where a scene
    file takes degrees.

    >>> poses([0.1, 0.2, 4.0], "goal").round(3).tolist()
    [[0.1, 0.2, -2.283]]
    >>> poses([[0, 0, 0], [1, 2]], "goals")
    Traceback (most recent call last):
    ...
    planner.model.fields.SceneError: goals: must be poses (x, y, theta) of finite numbers, got [[0, 0, 0], [1, 2]]
    """
    try:
        rows = np.array(value, dtype=float)
    except (TypeError, ValueError):
        rows = None
    if rows is not None and rows.ndim == 1:
        rows = rows[None]
    if rows is None or rows.ndim != 2 or rows.shape[1] != 3 or isinstance(value, (str, bytes)) \
            or not np.all(np.isfinite(rows)) or not np.all(np.abs(rows[:, :2]) <= LENGTH.bound):
        raise SceneError(name, f"must be poses (x, y, theta) of finite numbers, got {shown(value)}")
    rows[:, 2] = wrap_angle(rows[:, 2])
    return rows


def pose(value: Any, name: str) -> np.ndarray:
    """``value`` as one pose ``(x, y, theta)`` (:func:`poses`' checks; radians).

    >>> pose([0, 0, float("nan")], "start")
    Traceback (most recent call last):
    ...
    planner.model.fields.SceneError: start: must be poses (x, y, theta) of finite numbers, got [0, 0, nan]
    """
    rows = poses(value, name)
    if len(rows) != 1:
        raise SceneError(name, f"must be one pose (x, y, theta), got {len(rows)}")
    return rows[0]


def vector(value: Any, name: str, size: int, limit: Limit | None = None) -> np.ndarray:
    """``value`` as a list of ``size`` finite numbers (each within ``limit`` if given)."""
    if not isinstance(value, (list, tuple)) or len(value) != size:
        raise SceneError(name, f"must be a list of {size} numbers, got {shown(value)}")
    return np.array([number(v, f"{name}[{i}]", limit=limit) for i, v in enumerate(value)])
