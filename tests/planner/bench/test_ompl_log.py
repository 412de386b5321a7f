"""`python -m planner.bench.planners --ompl-log FILE`: OMPL's benchmark log format (planner.bench.ompl_log), read
back by a parser written here from the format's grammar and by OMPL's own readBenchmarkLog."""

from __future__ import annotations

import contextlib
import io
import math
import sqlite3

import pytest

from planner.bench.planners import main as bench
from planner.bench.ompl_log import PROPERTIES, Run, format_ompl_log, log_paths


def _parse(text: str) -> dict:
    """A minimal reader of OMPL's benchmark log grammar, strict about every count."""
    lines = iter(text.split("\n"))

    def take(suffix: str) -> str:
        line = next(lines)
        assert line.endswith(suffix), (line, suffix)
        return line[:len(line) - len(suffix)]

    def multiline() -> str:
        assert next(lines) == "<<<|"
        body = []
        while (line := next(lines)) != "|>>>":
            body.append(line)
        return "\n".join(body)

    log = {"version": next(lines).split(" version "), "experiment": take("").removeprefix("Experiment ")}
    log["host"] = take("").removeprefix("Running on ")
    log["date"] = take("").removeprefix("Starting at ")
    log["setup"], log["cpu"] = multiline(), multiline()
    log["seed"] = int(take(" is the random seed"))
    log["time limit"] = float(take(" seconds per run"))
    log["memory limit"] = float(take(" MB per run"))
    log["runs per planner"] = int(take(" runs per planner"))
    log["total time"] = float(take(" seconds spent to collect the data"))
    assert [next(lines).split("|") for _ in range(int(take(" enum types")))] == []
    log["planners"] = {}
    for _ in range(int(take(" planners"))):
        name = next(lines)
        assert [next(lines) for _ in range(int(take(" common properties")))] == []
        props = [tuple(next(lines).rsplit(" ", 1)) for _ in range(int(take(" properties for each run")))]
        runs = []
        for _ in range(int(take(" runs"))):
            line = next(lines)
            assert line.endswith("; ")
            values = line.split("; ")[:-1]
            assert len(values) == len(props), line
            runs.append(dict(zip((n for n, _ in props), values)))
        assert next(lines) == "."  # no progress properties
        log["planners"][name] = {"properties": props, "runs": runs}
    assert list(lines) == [""]
    return log


def test_bench_writes_a_log_that_ompl_reads(tmp_path, capsys):
    file = tmp_path / "battery.log"
    assert bench(["scenes/battery.yaml", "--runs", "2", "--planners", "rrt", "--time-limit", "5", "--workers", "2",
                  "--ompl-log", str(file)]) == 0
    assert "battery.yaml" in capsys.readouterr().out  # the table still comes
    assert [p.name for p in tmp_path.iterdir()] == ["battery.log"]  # one scene: FILE itself, no temporary left
    log = _parse(file.read_text())
    assert log["version"][0] == "OMPL" and log["experiment"] == "battery"
    assert (log["seed"], log["time limit"], log["runs per planner"]) == (1, 5.0, 2)
    assert "scene: scenes/battery.yaml" in log["setup"]
    rrt = log["planners"]["rrt"]
    assert rrt["properties"] == list(PROPERTIES)
    assert [r["seed"] for r in rrt["runs"]] == ["1", "2"]
    for r in rrt["runs"]:
        assert r["solved"] == "1" and 0 < float(r["time"]) <= 5 and float(r["solution length"]) > 0
        assert int(r["pushes"]) >= 1 and int(r["switches"]) >= 0
    assert math.isclose(log["total time"], sum(float(r["time"]) for r in rrt["runs"]), abs_tol=1e-5)

    # OMPL's own reader (ompl_benchmark_statistics.py is a front end to it), and its views.
    tools = pytest.importorskip("ompl.tools")
    db = tmp_path / "benchmark.db"
    with contextlib.redirect_stdout(io.StringIO()):
        tools.readBenchmarkLog(str(db), [str(file)], False)
        tools.computeViews(str(db), False)
    with contextlib.closing(sqlite3.connect(db)) as c:
        assert c.execute("SELECT name, timelimit, runcount, seed FROM experiments").fetchall() == [
            ("battery", 5.0, 2, "1")]
        assert c.execute("SELECT name FROM plannerConfigs").fetchall() == [("rrt",)]
        rows = c.execute("SELECT solved, seed, pushes, time, solution_length FROM runs ORDER BY seed").fetchall()
        assert [r[:2] for r in rows] == [(1, 1), (1, 2)] and all(r[2] >= 1 and r[3] > 0 and r[4] > 0 for r in rows)
        assert c.execute("SELECT avg_solved FROM bestPlannerConfigs").fetchall() == [(1.0,)]


def test_unsolved_runs_leave_what_they_lack_empty(tmp_path):
    runs = {"rrt": [Run(1, True, 0.5, 1.25, 3, 1), Run(2, False, 10.0, math.nan, 0, 0)],
            "est": [Run(1, True, float("inf"), 0.5, 1, 0)]}
    text = format_ompl_log("two words", runs, 10, 1, setup="a\nb", host="my host", version="2.0.1")
    log = _parse(text)
    assert (log["experiment"], log["host"], log["setup"], log["runs per planner"]) == ("two_words", "my_host",
                                                                                        "a\nb", 2)
    assert list(log["planners"]) == ["rrt", "est"]
    rrt = log["planners"]["rrt"]["runs"]
    assert rrt[0] == {"time": "0.5", "solved": "1", "solution length": "1.25", "pushes": "3", "switches": "1",
                      "seed": "1"}
    assert rrt[1] == {"time": "10.0", "solved": "0", "solution length": "", "pushes": "", "switches": "",
                      "seed": "2"}
    assert log["planners"]["est"]["runs"][0]["time"] == "nan"  # stored as NULL by OMPL's reader
    tools = pytest.importorskip("ompl.tools")
    (tmp_path / "x.log").write_text(text)
    with contextlib.redirect_stdout(io.StringIO()):
        tools.readBenchmarkLog(str(tmp_path / "x.db"), [str(tmp_path / "x.log")], False)
    with contextlib.closing(sqlite3.connect(tmp_path / "x.db")) as c:
        assert c.execute("SELECT seed, solved, time, solution_length, pushes FROM runs ORDER BY id").fetchall() == [
            (1, 1, 0.5, 1.25, 3), (2, 0, 10.0, None, None), (1, 1, None, 0.5, 1)]
    with pytest.raises(ValueError, match=r"\|>>>"):
        format_ompl_log("x", runs, 10, 1, setup="ok\n|>>> not ok")


def test_one_log_per_scene(tmp_path):
    assert log_paths(tmp_path / "b.log", ["parking"]) == [tmp_path / "b.log"]
    assert log_paths(tmp_path / "b.log", ["parking", "junction"]) == [tmp_path / "b-parking.log",
                                                                     tmp_path / "b-junction.log"]
    assert log_paths("b", ["a b", "c"]) == [log_paths("b-a_b.log", ["x"])[0], log_paths("b-c.log", ["x"])[0]]
    with pytest.raises(ValueError, match="share a name"):
        log_paths("b.log", ["parking", "parking"])


@pytest.mark.parametrize("extra, message", [(["--ompl-log", "no/such/folder/b.log"], "no folder"),
                                            (["--ompl-log", "b.log", "--quality"], "not --quality"),
                                            (["scenes/battery.yaml", "--ompl-log", "b.log"], "share a name")])
def test_bench_refuses_a_log_it_cannot_write_before_planning(extra, message, capsys):
    with pytest.raises(SystemExit) as exit_:
        bench(["scenes/battery.yaml", *extra])
    assert exit_.value.code == 2 and message in capsys.readouterr().err
