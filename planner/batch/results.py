"""A batch's results file, ``results.jsonl``: one JSON line per finished task, appended as the task
ends, and the summary table of a run.

Each line is written whole with one ``write`` on a file opened for appending, then flushed to disk
(``fsync``): a run killed at any moment leaves every finished task's line, and at worst the start
of one more line, which :class:`ResultsFile` drops when it opens the file again (``--resume``).
A task's plan file, ``<id>.json`` beside it, is written (atomically) before its line, so a line
means its plan is there.

The columns, in this order, are :data:`COLUMNS`: the task (``id``, ``scene``, ``seed``, ``goal``,
``overrides``), its ``status`` (``solved``, ``unreachable``: certified at once, ``unknown``: not
solved within its time limit, ``failed``: ``error`` says why), the plan's ``cost`` (length plus the
switch cost per switch), ``length`` (of the centre of friction's path), ``pushes`` and ``switches``,
``planning_time_s``, ``task_s`` (the whole task's seconds in its worker: reading, certificates,
planning), ``regions_computed`` (exact regions the worker computed itself), the worker's ``host``,
the ``attempts`` it took and the ``plan`` file.

>>> import tempfile
>>> results = ResultsFile(Path(tempfile.mkdtemp()) / "results.jsonl")
>>> results.append({"id": "a-s1", "status": "solved"})
>>> with open(results.path, "a") as f:
...     _ = f.write('{"id": "a-s2", "sta')  # a run killed mid-line
>>> sorted(ResultsFile(results.path).read())
['a-s1']
"""

from __future__ import annotations

import json
import os
import statistics
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

__all__ = ["COLUMNS", "STATUSES", "ResultsFile", "summary"]

COLUMNS = ("id", "scene", "seed", "goal", "overrides", "status", "cost", "length", "pushes", "switches",
           "planning_time_s", "task_s", "regions_computed", "host", "attempts", "error", "plan")
STATUSES = ("solved", "unreachable", "unknown", "failed")


class ResultsFile:
    """``path``, a results file: :meth:`read` the lines there, :meth:`append` one more. Opening
    it cuts off a last line left incomplete by a killed run."""

    def __init__(self, path: str | Path):
        self.path = Path(path)
        self._drop_torn_line()

    def _drop_torn_line(self) -> None:
        try:
            with open(self.path, "rb+") as f:
                data = f.read()
                if data and not data.endswith(b"\n"):
                    f.truncate(data.rfind(b"\n") + 1)
        except FileNotFoundError:
            pass

    def read(self) -> dict[str, dict[str, Any]]:
        """The records in the file by task id (a line that is not a record is skipped)."""
        records = {}
        try:
            lines = self.path.read_text().splitlines()
        except FileNotFoundError:
            return records
        for line in lines:
            try:
                record = json.loads(line)
            except ValueError:
                continue
            if isinstance(record, dict) and isinstance(record.get("id"), str):
                records[record["id"]] = record
        return records

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
