"""Benchmark results in OMPL's benchmark log format (``python -m planner.bench.planners --ompl-log FILE``).

The format is the one OMPL's ``ompl::tools::Benchmark::saveResultsToStream`` writes and
``ompl_benchmark_statistics.py`` (``ompl.tools.readBenchmarkLog``) reads into the SQLite database
that Planner Arena shows: the grammar of OMPL's "Benchmark log file format" (OMPL 1.5 and later:
optional experiment properties, ``N enum types``, optional progress properties), checked against
the parser shipped with OMPL 2.0.1. One log is one *experiment*, that is one problem, so the
benchmark writes one log per scene.

Each log holds one planner block per planner, with one run per seed and these run properties:
``time REAL`` (planning time in seconds, the time used when unsolved), ``solved BOOLEAN`` (0 or 1),
``solution length REAL`` (path length of the centre of friction), ``pushes INTEGER``,
``switches INTEGER`` and ``seed INTEGER``. The last three and the length are empty (NULL in the
database) for unsolved runs. No enum types, common properties or progress properties are written.
"""

from __future__ import annotations

import datetime
import math
import os
import platform
import socket
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

from ..model.files import write_atomic

__all__ = ["PROPERTIES", "Run", "format_ompl_log", "log_paths", "write_ompl_log"]

#: The run properties, in the order of each run's values: (name, OMPL property type).
PROPERTIES = (("time", "REAL"), ("solved", "BOOLEAN"), ("solution length", "REAL"), ("pushes", "INTEGER"),
              ("switches", "INTEGER"), ("seed", "INTEGER"))


@dataclass(frozen=True)
class Run:
    """One planning run of a benchmark."""

    seed: int
    solved: bool
    time: float
    length: float
    pushes: int
    switches: int

    def values(self) -> list[str]:
        """The run's values in the order of :data:`PROPERTIES` ('' for what an unsolved run lacks)."""
        if not self.solved:
            return [_real(self.time), "0", "", "", "", str(int(self.seed))]
        return [_real(self.time), "1", _real(self.length), str(int(self.pushes)), str(int(self.switches)),
                str(int(self.seed))]


def _real(x: float) -> str:
    x = float(x)
    return repr(x) if math.isfinite(x) else "nan"  # the parser stores inf and nan as NULL


def _word(text: str) -> str:
    """``text`` as one token: the parser keeps only the last word of the experiment's and host's names."""
    return "_".join(str(text).split()) or "unnamed"


def _line(text: str) -> str:
    return " ".join(str(text).split())


def log_paths(file: str | os.PathLike, names: Sequence[str]) -> list[Path]:
    """The log file of each experiment: ``file`` itself for one, else ``file`` with ``-<name>``
    before its suffix (``.log`` when it has none): ``out.log`` -> ``out-parking.log``.

    Raises ValueError when two experiments would share a file."""
    file = Path(file)
    if len(names) == 1:
        return [file]
    paths = [file.with_name(f"{file.stem}-{_word(n)}{file.suffix or '.log'}") for n in names]
    if len(set(paths)) != len(paths):
        raise ValueError(f"scenes share a name, so their OMPL logs would share a file: {', '.join(names)}")
    return paths


def format_ompl_log(experiment: str, runs_by_planner: Mapping[str, Sequence[Run]], time_limit: float, seed: int,
                    *, runs_per_planner: int | None = None, setup: str = "", total_time: float | None = None,
                    version: str | None = None, host: str | None = None,
                    date: datetime.datetime | None = None) -> str:
    """The text of the OMPL benchmark log of one experiment (see the module's docstring).

    ``seed`` is the experiment's random seed (the first run's); ``total_time`` defaults to the sum of
    the runs' times; ``version`` to the installed OMPL's; ``setup`` is free text (no line may
    start with ``|>>>``)."""
    if any(line.startswith("|>>>") for line in setup.splitlines()):
        raise ValueError("a setup line starts with |>>>, which ends the setup in the log")
    if version is None:
        from importlib.metadata import PackageNotFoundError
        from importlib.metadata import version as package_version

        try:
            version = package_version("ompl")
        except PackageNotFoundError:
            version = "0.0.0"
    runs = [r for planner_runs in runs_by_planner.values() for r in planner_runs]
    if total_time is None:
        total_time = sum(r.time for r in runs)
    if runs_per_planner is None:
        runs_per_planner = max((len(v) for v in runs_by_planner.values()), default=0)
    date = date or datetime.datetime.now().astimezone()
    cpu = f"{platform.machine()} {platform.processor()}".strip()
    out = [f"OMPL version {_word(version)}",
           f"Experiment {_word(experiment)}",
           f"Running on {_word(host or socket.gethostname())}",
           f"Starting at {date.strftime('%Y-%m-%d %H:%M:%S')}",
           "<<<|", *setup.splitlines(), "|>>>",
           "<<<|", f"{platform.platform()}, {cpu}, {os.cpu_count()} cores", "|>>>",
           f"{int(seed)} is the random seed",
           f"{float(time_limit):g} seconds per run",
           "0 MB per run",  # no memory limit
           f"{int(runs_per_planner)} runs per planner",
           f"{float(total_time):.6f} seconds spent to collect the data",
           "0 enum types",
           f"{len(runs_by_planner)} planners"]
    for planner, planner_runs in runs_by_planner.items():
        out += [_line(planner), "0 common properties", f"{len(PROPERTIES)} properties for each run",
                *(f"{name} {kind}" for name, kind in PROPERTIES), f"{len(planner_runs)} runs",
                *("".join(f"{v}; " for v in r.values()) for r in planner_runs), "."]
    return "\n".join(out) + "\n"


def write_ompl_log(path: str | os.PathLike, experiment: str, runs_by_planner: Mapping[str, Sequence[Run]],
                   time_limit: float, seed: int, **options) -> None:
    """Write :func:`format_ompl_log`'s text to ``path`` atomically."""
    write_atomic(path, format_ompl_log(experiment, runs_by_planner, time_limit, seed, **options))
