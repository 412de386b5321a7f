"""A batch's results file, ``results.jsonl``: one JSON line per finished task, appended as the task
ends, and the summary table of a run.

Each line is written whole with one ``write`` on a file opened for appending, then flushed to disk
(``fsync``): a run killed at any moment leaves every finished task's line, and at worst the start
of one more line, which :class:`ResultsFile` drops when it opens the file again (``--resume``).
A task's plan file, ``<id>.json`` beside it, is written (atomically) before its line, so a line
means its plan is there.

The columns, in this order, are :data:`COLUMNS`: the task (``id``, ``scene``, ``seed``, ``goal``,
``overrides``, and what its plan depends on besides: ``scene_digest``, the SHA-256 of the scene
file's bytes, and the planner's ``version``), its ``status`` (``solved``, ``unreachable``: certified at once, ``unknown``: not
solved within its time limit, ``failed``: ``error`` says why), the plan's ``cost`` (length plus the
switch cost per switch), ``length`` (of the centre of friction's path), ``pushes`` and ``switches``,
``planning_time_s``, ``task_s`` (the whole task's seconds in its worker: reading, certificates,
planning), ``regions_computed`` (exact regions the worker computed itself), the worker's ``host``,
the ``attempts`` it took and the ``plan`` file.

A results file is read back (:meth:`ResultsFile.read`) as untrusted input: a line at a time, each
line bounded in size and nesting and checked field by field (:func:`is_record`); a line that is
not a whole record is not reused, and its task runs again.

>>> import tempfile
>>> results = ResultsFile(Path(tempfile.mkdtemp()) / "results.jsonl")
>>> results.append(dict.fromkeys(COLUMNS) | {"id": "a-s1", "scene": "a.yaml", "seed": 1, "overrides": {},
...                 "status": "unknown", "pushes": 0, "switches": 0, "planning_time_s": 1.0, "attempts": 1})
>>> with open(results.path, "a") as f:
...     _ = f.write('{"id": "a-s3"}\\n{"id": "a-s2", "sta')  # a line not a record, then a run killed mid-line
>>> records, bad = ResultsFile(results.path).read()
>>> sorted(records), bad
(['a-s1'], 1)
"""

from __future__ import annotations

import errno
import json
import math
import os
import statistics
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

from ..model.fields import SceneError
from ..model.json_file import parse_json

__all__ = ["COLUMNS", "MAX_LINE", "STATUSES", "ResultsFile", "is_record", "summary"]

COLUMNS = ("id", "scene", "seed", "goal", "overrides", "scene_digest", "version", "status", "cost", "length", "pushes", "switches",
           "planning_time_s", "task_s", "regions_computed", "host", "attempts", "error", "plan")
STATUSES = ("solved", "unreachable", "unknown", "failed")
#: Longest results line read (a task's line is some 500 bytes; its overrides are a few numbers).
MAX_LINE = 100_000
#: Deepest nesting of a results line (``overrides.cf_offset`` goes 2 deep).
_MAX_DEPTH = 4


def _is_number(value: Any, optional: bool = False, whole: bool = False) -> bool:
    if value is None:
        return optional
    kinds = (int,) if whole else (int, float)
    if not isinstance(value, kinds) or isinstance(value, bool):
        return False
    return (math.isfinite(value) if isinstance(value, float) else True) and value >= 0  # an int may exceed a float


def _is_text(value: Any, optional: bool = False) -> bool:
    return (value is None and optional) or (isinstance(value, str) and len(value) <= MAX_LINE)


def is_record(record: Any) -> bool:
    """Whether ``record`` (a results line as JSON gives it) is a whole record: every column, each
    of its kind (a ``solved`` one with its cost, length and plan file ``<id>.json``).

    >>> is_record({"id": "battery-s2"}), is_record(dict.fromkeys(COLUMNS))
    (False, False)
    """
    if not isinstance(record, dict) or set(record) != set(COLUMNS):
        return False
    r = record
    goal = r["goal"]
    solved = r["status"] == "solved"
    return bool(
        _is_text(r["id"]) and _is_text(r["scene"]) and _is_number(r["seed"], whole=True)
        and (goal is None or (isinstance(goal, list) and len(goal) == 3
                              and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in goal)))
        and isinstance(r["overrides"], dict) and _is_text(r["scene_digest"], True) and _is_text(r["version"], True)
        and r["status"] in STATUSES and _is_number(r["cost"], not solved) and _is_number(r["length"], not solved)
        and all(_is_number(r[k], True, whole=True) for k in ("pushes", "switches", "regions_computed", "attempts"))
        and all(_is_number(r[k], True) for k in ("planning_time_s", "task_s"))
        and _is_text(r["host"], True) and _is_text(r["error"], True)
        and (r["plan"] == f"{r['id']}.json" if solved else _is_text(r["plan"], True)))


class ResultsFile:
    """``path``, a results file: :meth:`read` the lines there, :meth:`append` one more. Opening
    it cuts off a last line left incomplete by a killed run.

    Raises
    ------
    OSError
        If ``path`` is there but is not a regular file, or cannot be opened."""

    def __init__(self, path: str | Path):
        self.path = Path(path)
        if self.path.exists() and not self.path.is_file():  # a folder or a pipe: never opened
            raise OSError(errno.EINVAL, "not a regular file", str(self.path))
        self._drop_torn_line()

    def _drop_torn_line(self) -> None:
        """Cut the file after its last newline, reading back from its end only as far as that."""
        try:
            with open(self.path, "rb+") as f:
                end = f.seek(0, os.SEEK_END)
                if end == 0:
                    return
                f.seek(end - 1)
                if f.read(1) == b"\n":
                    return
                where = end
                while where > 0:
                    step = min(1 << 16, where)
                    where -= step
                    f.seek(where)
                    newline = f.read(step).rfind(b"\n")
                    if newline >= 0:
                        f.truncate(where + newline + 1)
                        return
                f.truncate(0)
        except FileNotFoundError:
            pass

    def read(self) -> tuple[dict[str, dict[str, Any]], int]:
        """The whole records in the file by task id (the last line of an id wins), and how many
        lines were not whole records (:func:`is_record`: cut, edited, longer than :data:`MAX_LINE`)."""
        records: dict[str, dict[str, Any]] = {}
        bad = 0
        try:
            f = open(self.path, "rb")
        except FileNotFoundError:
            return records, bad
        with f:
            for raw in f:
                record = None
                if len(raw) <= MAX_LINE:
                    try:
                        record = parse_json(raw.decode("utf-8"), "results", _MAX_DEPTH)
                    except (UnicodeDecodeError, SceneError):
                        pass
                if is_record(record):
                    records[record["id"]] = record
                else:
                    bad += 1
        return records, bad

    def append(self, record: Mapping[str, Any]) -> None:
        """Append ``record`` as one line, written whole and flushed to disk."""
        line = (json.dumps(record, sort_keys=False) + "\n").encode()
        fd = os.open(self.path, os.O_WRONLY | os.O_APPEND | os.O_CREAT, 0o666)
        try:
            written = os.write(fd, line)
            if written != len(line):
                raise OSError(5, f"only {written} of {len(line)} bytes were written", str(self.path))
            os.fsync(fd)
        finally:
            os.close(fd)


def summary(records: Iterable[Mapping[str, Any]]) -> str:
    """A table of ``records`` per scene file (named, in order of their first task ids): tasks, how many
    of each status, and the median cost, length and planning time of the solved ones.

    >>> print(summary([{"id": "a-s1", "scene": "a.yaml", "status": "solved", "cost": 1.0, "length": 1.0,
    ...                 "planning_time_s": 0.5}, {"id": "a-s2", "scene": "a.yaml", "status": "failed"}]))
    scene                       tasks  solved  unreach  unknown  failed  cost_med  len_med  t_med[s]
    a.yaml                          2       1        0        0       1     1.000    1.000     0.500
    """
    by_scene: dict[str, list[Mapping[str, Any]]] = {}
    for record in sorted(records, key=lambda r: r["id"]):
        by_scene.setdefault(str(record.get("scene")), []).append(record)
    lines = [f"{'scene':<26}{'tasks':>7}{'solved':>8}{'unreach':>9}{'unknown':>9}{'failed':>8}{'cost_med':>10}"
             f"{'len_med':>9}{'t_med[s]':>10}"]
    for scene, rows in by_scene.items():
        counts = [sum(r.get("status") == s for r in rows) for s in STATUSES]
        solved = [r for r in rows if r.get("status") == "solved"]
        medians = [f"{statistics.median(r[k] for r in solved):.3f}" if solved else "-"
                   for k in ("cost", "length", "planning_time_s")]
        lines.append(f"{Path(scene).name[:25]:<26}{len(rows):>7}{counts[0]:>8}{counts[1]:>9}{counts[2]:>9}{counts[3]:>8}"
                     f"{medians[0]:>10}{medians[1]:>9}{medians[2]:>10}")
    return "\n".join(lines)
