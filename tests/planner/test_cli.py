"""The ``plan`` command line: exit codes, its one line of error, its output files, determinism.

Contract (planner/cli.py): exit 0 solved (one ``solved:`` line on stdout), 1 bad input (one line
``plan: error: <field>: <problem>`` on stderr, nothing written), 2 not solved (one line saying
why, the JSON with ``"solved": false`` and the recording written). Argparse's own usage errors also
exit 2, with its usage message.

Most bad-input cases call ``planner.cli.main`` in the test process (they fail before planning, in
milliseconds); a few run the real command to show that no traceback or stray line gets out.
"""

from __future__ import annotations

import contextlib
import copy
import errno
import json
import math
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
import yaml

from ctrl_c import sigint_default
from planner.model import files
from planner.cli import main
from planner.model.files import write_atomic
from planner.model.options import DEFAULT_PLANNER
from planner.model.scene_file import load_scene

ROOT = Path(__file__).resolve().parents[2]
SCENES = ROOT / "scenes"
PLAN = Path(sys.executable).parent / "plan"
BATTERY_TEXT = (SCENES / "battery.yaml").read_text()
BATTERY = yaml.safe_load(BATTERY_TEXT)  # a one-step plan: solved at once
VERTICES = BATTERY["slider"]["vertices"]
ERROR = re.compile(r"plan: error: (.+?): (.+)")
PLAN_KEYS = {"format", "scene", "solved", "planner", "seed", "planning_time_s", "start", "goal", "final", "segments",
             "margin"}
COST_KEYS = {"cf", "length", "switch_cost", "cost", "improvements"}  # a solved plan's
SEGMENT_KEYS = {"push": {"kind", "edge", "contact", "twist", "duration", "start", "end", "margin"},
                "transit": {"kind", "from_edge", "to_edge", "mode", "pusher_path", "duration"}}
L_SHAPE = [[0.0, 0.0], [0.09, 0.0], [0.09, 0.035], [0.035, 0.035], [0.035, 0.09], [0.0, 0.09]]  # edges 2, 3 concave

# The goal sits inside a closed ring of four walls: free of collision, but no path leads there.
# A corridor just wider than the part and too narrow to turn it, pushed on its left edge only
# (pushes go right) with the goal to its left: unreachable, but no certificate of
# planner.queries.reachability shows it, so the search runs out its time limit.
BEHIND = {
    "name": "behind",
    "slider": {"vertices": [[-0.04, -0.03], [0.04, -0.03], [0.04, 0.03], [-0.04, 0.03]]},
    "pusher": {"width": 0.05, "depth": 0.015, "mu": 0.5, "edges": [3], "transit": "none"},
    "workspace": {"min": [-0.5, -0.045], "max": [0.5, 0.045]},
    "start": [0.0, 0.0, 0.0],
    "goal": [-0.2, 0.0, 0.0],
}


def battery(**changes) -> dict:
    """The battery scene with top-level keys replaced (a value of ``None`` deletes the key)."""
    spec = copy.deepcopy(BATTERY)
    for key, value in changes.items():
        if value is None:
            del spec[key]
        else:
            spec[key] = value
    return spec


def nested(path: str, value, delete: bool = False) -> dict:
    """The battery scene with one nested field (``"pusher.mu"``, ``"obstacles.0.box.size"``) set or deleted."""
    spec = copy.deepcopy(BATTERY)
    *parents, last = path.split(".")
    node = spec
    for key in parents:
        node = node[int(key)] if isinstance(node, list) else node[key]
    last = int(last) if isinstance(node, list) else last
    if delete:
        del node[last]
    else:
        node[last] = value
    return spec


def write(folder: Path, scene: dict | str | bytes, name: str = "scene.yaml") -> Path:
    path = folder / name
    if isinstance(scene, dict):
        scene = yaml.safe_dump(scene)
    if isinstance(scene, str):
        scene = scene.encode()
    path.write_bytes(scene)
    return path


def run_plan(*args: str, cwd: Path, timeout: float = 60) -> subprocess.CompletedProcess:
    return subprocess.run([str(PLAN), *args], capture_output=True, text=True, cwd=cwd, timeout=timeout)


def error_field(stderr: str) -> str:
    """The field named by the one error line, after checking there is exactly that one line."""
    lines = stderr.splitlines()
    assert len(lines) == 1, f"expected one line on stderr, got {stderr!r}"
    match = ERROR.fullmatch(lines[0])
    assert match, f"not 'plan: error: <field>: <problem>': {lines[0]!r}"
    return match.group(1)


def plan_json(path: Path) -> dict:
    data = json.loads(path.read_text())
    assert set(data) == PLAN_KEYS | ({"reason"} if not data["solved"] else COST_KEYS)
    assert data["format"] == "stablepush.plan/1"
    for segment in data["segments"]:
        assert set(segment) == SEGMENT_KEYS[segment["kind"]]
    return data


# --- bad input -------------------------------------------------------------------------------------

BAD_SCENES = {
    # (scene, the field the message must name, a word the problem must contain or None)
    "malformed YAML": ("slider: [1, 2\n", "scene", "malformed YAML"),
    "tab indentation": ("\t- a\n", "scene", "malformed YAML"),
    "control character": ("name: a\x07b\n", "scene", "malformed YAML"),
    "not UTF-8": (b"\xff\xfename: x\n", "scene", "UTF-8"),
    "5000-digit int": ("a: " + "1" * 5000 + "\n", "scene", None),
    "nested too deeply": ("a: " + "[" * 20000 + "]" * 20000 + "\n", "scene", None),
    "empty file": ("", "scene", "mapping"),
    "top level is a list": ("- 1\n- 2\n", "scene", "mapping"),
    "top level is a string": ("hello\n", "scene", "mapping"),
    "missing slider": (battery(slider=None), "slider", "missing"),
    "missing pusher": (battery(pusher=None), "pusher", "missing"),
    "missing workspace": (battery(workspace=None), "workspace", "missing"),
    "missing start": (battery(start=None), "start", "missing"),
    "missing goal": (battery(goal=None), "goal", "missing"),
    "missing slider.vertices": (nested("slider.vertices", None, delete=True), "slider.vertices", "missing"),
    "missing pusher.mu": (nested("pusher.mu", None, delete=True), "pusher.mu", "missing"),
    "missing pusher.width": (nested("pusher.width", None, delete=True), "pusher.width", "missing"),
    "missing workspace.max": (nested("workspace.max", None, delete=True), "workspace.max", "missing"),
    "missing box size": (nested("obstacles.0.box.size", None, delete=True), "obstacles[0].box.size", "missing"),
    "unknown top-level key": (battery(colour="red"), "colour", "unknown"),
    "unknown pusher.colour": (nested("pusher.colour", "red"), "pusher.colour", "unknown"),
    "unknown slider key": (nested("slider.mass", 1.0), "slider.mass", "unknown"),
    "unknown box key": (nested("obstacles.0.box.colour", "red"), "obstacles[0].box.colour", "unknown"),
    "unknown tolerance key": (battery(tolerance={"pos": 0.1}), "tolerance.pos", "unknown"),
    "unknown planner key": (battery(planner={"iterations": 5}), "planner.iterations", "unknown"),
    "slider not a mapping": (battery(slider=[1, 2]), "slider", "mapping"),
    "pusher is null": ({**BATTERY, "pusher": None}, "pusher", "mapping"),
    "vertex 'abc'": (nested("slider.vertices.1.0", "abc"), "slider.vertices[1][0]", "number"),
    "vertex true": (nested("slider.vertices.2.1", True), "slider.vertices[2][1]", "number"),
    "vertex null": (nested("slider.vertices.0.0", None), "slider.vertices[0][0]", "number"),
    "vertex with 3 coordinates": (nested("slider.vertices.0", [0.0, 0.0, 0.0]), "slider.vertices[0]", None),
    "vertices a string": (nested("slider.vertices", "abc"), "slider.vertices", None),
    "cf 'abc'": (nested("slider.cf", ["abc", 0.0]), "slider.cf[0]", "number"),
    "cf true": (nested("slider.cf", True), "slider.cf", None),
    "cf null": (nested("slider.cf", None), "slider.cf", None),
    "mu 'abc'": (nested("pusher.mu", "abc"), "pusher.mu", "number"),
    "mu true": (nested("pusher.mu", True), "pusher.mu", "number"),
    "mu null": (nested("pusher.mu", None), "pusher.mu", "number"),
    "mu beyond a float": (BATTERY_TEXT.replace("mu: 1.0", "mu: 1" + "0" * 400), "pusher.mu", "number"),
    "mu .nan": (BATTERY_TEXT.replace("mu: 1.0", "mu: .nan"), "pusher.mu", "number"),
    "width 'abc'": (nested("pusher.width", "abc"), "pusher.width", "number"),
    "width true": (nested("pusher.width", True), "pusher.width", "number"),
    "width null": (nested("pusher.width", None), "pusher.width", "number"),
    "start 'abc'": (battery(start=[0.0, "abc", 0.0]), "start[1]", "number"),
    "start true": (battery(start=True), "start", None),
    "start null": (battery(start=[0.0, 0.0, None]), "start[2]", "number"),
    "start of 2 numbers": (battery(start=[0.0, 0.0]), "start", None),
    "goal 'abc'": (battery(goal="abc"), "goal", None),
    "2 vertices": (nested("slider.vertices", [[0, 0], [0.01, 0]]), "slider.vertices", "3 vertices"),
    "0 vertices": (nested("slider.vertices", []), "slider.vertices", "3 vertices"),
    "bow-tie part": (nested("slider.vertices", [[0, 0], [0.02, 0.02], [0.02, 0], [0, 0.02]]),
                     "slider.vertices", "self-intersecting"),
    "collinear part": (nested("slider.vertices", [[0, 0], [0.01, 0.01], [0.03, 0.03]]), "slider.vertices", "zero area"),
    "first vertex repeated": (nested("slider.vertices", VERTICES + VERTICES[:1]), "slider.vertices", "coincide"),
    "cf outside the part": (nested("slider.cf", [0.1, 0.0]), "slider.cf", "not inside"),
    "cf on the boundary": (nested("slider.cf", [-0.02425, 0.0]), "slider.cf", "not inside"),
    "mu 0": (nested("pusher.mu", 0), "pusher.mu", "> 0"),
    "mu negative": (nested("pusher.mu", -0.5), "pusher.mu", "> 0"),
    "width 0": (nested("pusher.width", 0.0), "pusher.width", "> 0"),
    "width negative": (nested("pusher.width", -0.04), "pusher.width", "> 0"),
    "depth 0": (nested("pusher.depth", 0), "pusher.depth", "> 0"),
    "edge out of range": (nested("pusher.edges", [4]), "pusher.edges", "does not exist"),
    "edge negative": (nested("pusher.edges", [-1]), "pusher.edges", "does not exist"),
    "edge 1.5": (nested("pusher.edges", [1.5]), "pusher.edges[0]", "integer"),
    "edge true": (nested("pusher.edges", [True]), "pusher.edges[0]", "integer"),
    "edges not a list": (nested("pusher.edges", 3), "pusher.edges", "list"),
    "edges empty": (nested("pusher.edges", []), "pusher.edges", "list"),
    "edge listed twice": (nested("pusher.edges", [3, 1, 3]), "pusher.edges", "twice"),
    "non-hull edge of an L": (battery(slider={"vertices": L_SHAPE}, pusher={**BATTERY["pusher"], "edges": [0, 2]}),
                              "pusher.edges", "convex hull"),
    "workspace empty": (battery(workspace={"min": [0.0, 0.0], "max": [0.0, 0.2]}), "workspace", "empty"),
    "workspace inverted": (battery(workspace={"min": [0.2, 0.2], "max": [-0.2, -0.2]}), "workspace", "inverted"),
    "workspace.min 'abc'": (battery(workspace={"min": "abc", "max": [1, 1]}), "workspace.min", None),
    "start in an obstacle": (battery(start=[0.10, -0.06, 0.0]), "start", "obstacle 0"),
    "goal in an obstacle": (battery(goal=[0.09, -0.05, 30.0]), "goal", "obstacle 0"),
    "start outside the workspace": (battery(start=[1.0, 1.0, 0.0]), "start", "workspace"),
    "goal across the workspace edge": (battery(goal=[0.17, 0.0, 0.0]), "goal", "workspace"),
    "box of size 0": (nested("obstacles.0.box.size", [0.0, 0.03]), "obstacles[0].box.size", "positive"),
    "box of negative size": (nested("obstacles.0.box.size", [0.04, -0.03]), "obstacles[0].box.size", "positive"),
    "box angle 'abc'": (nested("obstacles.0.box.angle", "abc"), "obstacles[0].box.angle", "number"),
    "bow-tie obstacle": (battery(obstacles=[{"polygon": [[0.1, 0.1], [0.12, 0.12], [0.12, 0.1], [0.1, 0.12]]}]),
                         "obstacles[0].polygon", "self-intersecting"),
    "collinear obstacle": (battery(obstacles=[{"polygon": [[0.1, 0.1], [0.11, 0.1], [0.12, 0.1]]}]),
                           "obstacles[0].polygon", "zero area"),
    "unknown obstacle kind": (battery(obstacles=[{"circle": {"center": [0.1, 0.1], "radius": 0.01}}]),
                              "obstacles[0]", None),
    "obstacle of two kinds": (battery(obstacles=[{**BATTERY["obstacles"][0], "polygon": [[0, 0], [1, 0], [0, 1]]}]),
                              "obstacles[0]", None),
    "second obstacle null": (battery(obstacles=BATTERY["obstacles"] + [None]), "obstacles[1]", None),
    "obstacles a mapping": (battery(obstacles={"box": 1}), "obstacles", "list"),
    "obstacles false": (battery(obstacles=False), "obstacles", "list"),
    "tolerance position 0": (battery(tolerance={"position": 0.0}), "tolerance.position", "> 0"),
    "tolerance angle negative": (battery(tolerance={"angle": -1.0}), "tolerance.angle", "> 0"),
    "planner name in YAML": (battery(planner={"name": "astar"}), "planner.name", "must be one of"),
    "planner seed 0": (battery(planner={"seed": 0}), "planner.seed", None),
    "planner seed 1.5": (battery(planner={"seed": 1.5}), "planner.seed", "integer"),
    "planner seed beyond 32 bits": (battery(planner={"seed": 2**32}), "planner.seed", None),
    "planner time limit 0": (battery(planner={"time_limit": 0}), "planner.time_limit", "> 0"),
    "planner time limit of years": (battery(planner={"time_limit": 1e9}), "planner.time_limit", "at most"),
    "transit unknown": (nested("pusher.transit", "teleport"), "pusher.transit", "must be one of"),
    "transit a list": (nested("pusher.transit", ["plane"]), "pusher.transit", "must be one of"),
    "transit null": (nested("pusher.transit", None), "pusher.transit", "must be one of"),
    "switch cost negative": (battery(planner={"switch_cost": -0.01}), "planner.switch_cost", ">= 0"),
    "switch cost a string": (battery(planner={"switch_cost": "high"}), "planner.switch_cost", "number"),
    "switch cost infinite": (battery(planner={"switch_cost": float("inf")}), "planner.switch_cost", "finite"),
    "margin negative": (battery(planner={"margin": {"mu": -0.1}}), "planner.margin", "[0, 1)"),
    "margin NaN": (battery(planner={"margin": [0.1, float("nan")]}), "planner.margin", "cf must be"),
    "margin larger than the part": (battery(planner={"margin": {"cf": 1.5}}), "planner.margin", "part's radius"),
    "margin a lone fraction": (battery(planner={"margin": 0.1}), "planner.margin", "{mu: M, cf: C}"),
    "margin unknown key": (battery(planner={"margin": {"friction": 0.1}}), "planner.margin", "no key"),
    "optimize negative": (battery(planner={"optimize": -1}), "planner.optimize", "0..100"),
    "optimize fractional": (battery(planner={"optimize": 1.5}), "planner.optimize", "integer"),
    "optimize a string": (battery(planner={"optimize": "lots"}), "planner.optimize", "integer"),
    "optimize beyond the cap": (battery(planner={"optimize": 101}), "planner.optimize", "0..100"),
    "name with a slash": (battery(name="a/b"), "name", None),
    "name a number": (battery(name=5), "name", None),
    "name with a NUL": (battery(name="a\0b"), "name", None),
    "name too long for a file": (battery(name="n" * 300), "name", None),
    # Found by the planner, not the parser: the pushed face (x = -0.02425) is against a wall.
    "no room for the pusher": (battery(obstacles=[{"box": {"center": [-0.035, 0.0], "size": [0.01, 0.1]}}]),
                               "start", "no room"),
}

BAD_FLAGS = {
    # (extra arguments, the flag the message must name)
    "--time-limit 0": (["--time-limit", "0"], "--time-limit"),
    "--time-limit -1": (["--time-limit", "-1"], "--time-limit"),
    "--time-limit nan": (["--time-limit", "nan"], "--time-limit"),
    "--time-limit inf": (["--time-limit", "inf"], "--time-limit"),  # OMPL would give up at once
    "--time-limit of years": (["--time-limit", "1e9"], "--time-limit"),
    "--seed 0": (["--seed", "0"], "--seed"),
    "--seed -3": (["--seed", "-3"], "--seed"),
    "--seed beyond 32 bits": (["--seed", str(2**64)], "--seed"),  # OMPL's binding raises TypeError on it
    "--optimize -1": (["--optimize", "-1"], "--optimize"),
    "--optimize 1000": (["--optimize", "1000"], "--optimize"),
    "--margin negative": (["--margin", "-0.1", "0.02"], "--margin"),
    "--margin nan": (["--margin", "nan", "0.02"], "--margin"),
    "--margin beyond the part": (["--margin", "0.1", "1"], "--margin"),
    "--margin three values": (["--margin", "0.1", "0.02", "0.3"], "--margin"),
    "--margin one nonzero value": (["--margin", "0.1"], "--margin"),
    # The work a number asks for is bounded: no typo runs for days.
    "--verify 100000": (["--verify", "100000"], "--verify"),
    "--simulate 5000": (["--simulate", "5000"], "--simulate"),
}


def assert_nothing_written(folder: Path, expected: set[str]) -> None:
    assert {p.name for p in folder.iterdir()} == expected, "bad input must write nothing (no out/, no logs/)"


@pytest.mark.parametrize("with_out", [True, False], ids=["--out", "no --out"])
@pytest.mark.parametrize("case", BAD_SCENES, ids=str)
def test_bad_scene_exits_1_with_one_line_naming_the_field(case, with_out, tmp_path, monkeypatch, capsys):
    scene, field, word = BAD_SCENES[case]
    write(tmp_path, scene)
    monkeypatch.chdir(tmp_path)  # the default output folder is logs/ under the cwd
    assert main(["scene.yaml", *(["--out", "out"] if with_out else [])]) == 1
    captured = capsys.readouterr()
    assert captured.out == ""
    assert error_field(captured.err) == field
    if word:
        assert word in captured.err
    assert_nothing_written(tmp_path, {"scene.yaml"})


@pytest.mark.parametrize("case", BAD_FLAGS, ids=str)
def test_bad_flag_exits_1_with_one_line_naming_it(case, tmp_path, monkeypatch, capsys):
    args, flag = BAD_FLAGS[case]
    write(tmp_path, BATTERY)
    monkeypatch.chdir(tmp_path)
    assert main(["scene.yaml", *args]) == 1
    captured = capsys.readouterr()
    assert error_field(captured.err) == flag and captured.out == ""
    assert_nothing_written(tmp_path, {"scene.yaml"})


def test_missing_file_names_the_scene(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main(["nowhere.yaml", "--out", "out"]) == 1
    captured = capsys.readouterr()
    assert error_field(captured.err) == "scene" and "nowhere.yaml" in captured.err
    assert_nothing_written(tmp_path, set())


def test_out_that_is_a_file_is_refused_before_planning(tmp_path, monkeypatch, capsys):
    write(tmp_path, BATTERY)
    (tmp_path / "taken").write_text("keep")
    monkeypatch.chdir(tmp_path)
    assert main(["scene.yaml", "--out", "taken"]) == 1
    assert error_field(capsys.readouterr().err) == "--out"
    assert (tmp_path / "taken").read_text() == "keep"


@pytest.mark.parametrize("argv, word", [
    (["scene.yaml", "--planner", "astar"], "invalid choice"),
    (["scene.yaml", "--seed", "abc"], "invalid int value"),
    (["scene.yaml", "--time-limit", "soon"], "invalid float value"),
    ([], "required"),
], ids=["planner", "seed", "time-limit", "no scene"])
def test_argparse_errors_exit_2_with_usage(argv, word, tmp_path, monkeypatch, capsys):
    write(tmp_path, BATTERY)
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SystemExit) as exit_:
        main(argv)
    assert exit_.value.code == 2
    err = capsys.readouterr().err
    assert err.startswith("usage: plan ") and word in err and "Traceback" not in err
    assert_nothing_written(tmp_path, {"scene.yaml"})


def test_exponent_without_a_dot_is_a_number(tmp_path):
    # PyYAML alone reads "5e-1" as a string (YAML 1.1), which the scene would reject as not a number.
    text = BATTERY_TEXT.replace("mu: 1.0", "mu: 5e-1").replace("width: 0.04", "width: 4E-2")
    scene = load_scene(write(tmp_path, text))
    assert scene.pusher.mu == 0.5 and scene.pusher.width == 0.04


# The real command, for what in-process calls cannot show: no traceback and no stray line get out of
# the process (the nanobind leak report, warnings, a progress line), and the exit status is right.
SUBPROCESS_CASES = {
    "missing file": (None, [], "scene"),
    "malformed YAML": ("slider: [1, 2\n", [], "scene"),
    "unknown pusher.colour": (nested("pusher.colour", "red"), ["--out", "out"], "pusher.colour"),
    "no room for the pusher": (BAD_SCENES["no room for the pusher"][0], ["--out", "out"], "start"),
    "--time-limit 0": (BATTERY, ["--time-limit", "0", "--out", "out"], "--time-limit"),
    "--seed 0": (BATTERY, ["--seed", "0"], "--seed"),
}


@pytest.mark.parametrize("case", SUBPROCESS_CASES, ids=str)
def test_command_bad_input(case, tmp_path):
    scene, args, field = SUBPROCESS_CASES[case]
    expected = set()
    if scene is not None:
        write(tmp_path, scene)
        expected = {"scene.yaml"}
    run = run_plan("scene.yaml", *args, cwd=tmp_path)
    assert run.returncode == 1, run.stderr
    assert "Traceback" not in run.stderr + run.stdout and run.stdout == ""
    assert error_field(run.stderr) == field
    assert_nothing_written(tmp_path, expected)


def test_command_bad_planner_name_is_argparse_usage_error(tmp_path):
    write(tmp_path, BATTERY)
    run = run_plan("scene.yaml", "--planner", "astar", "--out", "out", cwd=tmp_path)
    assert run.returncode == 2
    assert run.stderr.startswith("usage: plan ") and "invalid choice: 'astar'" in run.stderr
    assert "Traceback" not in run.stderr
    assert_nothing_written(tmp_path, {"scene.yaml"})


# --- not solved ------------------------------------------------------------------------------------

def test_unreachable_goal_exits_2_within_the_time_limit(tmp_path):
    write(tmp_path, BEHIND)
    # The time limit bounds the search; the part's exact regions are computed once per part and
    # cached on disk (planner.actions.region_cache), so compute them first, as any earlier run would have.
    from planner import load_scene
    from planner.actions.controls import edge_controls

    edge_controls(load_scene(tmp_path / "scene.yaml"))
    clock = time.perf_counter()
    run = run_plan("scene.yaml", "--time-limit", "2", "--out", "out", cwd=tmp_path, timeout=30)
    wall = time.perf_counter() - clock
    assert run.returncode == 2, run.stderr
    assert wall < 6.0, f"took {wall:.1f} s with a 2 s limit"
    lines = run.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("plan: not solved: ") and "time limit" in lines[0], run.stderr
    assert run.stdout == ""
    data = plan_json(tmp_path / "out" / "behind.json")
    assert data["solved"] is False and data["segments"] == [] and data["final"] == data["start"]
    assert 1.9 <= data["planning_time_s"] <= 3.0
    assert (tmp_path / "out" / "behind.rrd").stat().st_size > 0
    assert {p.name for p in (tmp_path / "out").iterdir()} == {"behind.json", "behind.rrd"}


def test_a_sealed_goal_exits_2_at_once_saying_why(tmp_path):
    """The shipped sealed scene: certified unreachable before any search or region."""
    clock = time.perf_counter()
    run = run_plan(str(SCENES / "unreachable" / "sealed.yaml"), "--out", "out", cwd=tmp_path)
    assert run.returncode == 2 and time.perf_counter() - clock < 10.0  # interpreter start-up included
    assert run.stderr.splitlines() == ["plan: unreachable: component: the goal is cut off from the start for the "
                                       "part's inscribed disk (radius 0.03 m) (outputs in out)"]
    data = plan_json(tmp_path / "out" / "sealed.json")
    assert data["solved"] is False and data["segments"] == [] and data["reason"].startswith("component")
    assert data["planning_time_s"] < 1.0
    assert (tmp_path / "out" / "sealed.rrd").stat().st_size > 0


# --- solved ----------------------------------------------------------------------------------------

def test_battery_solves_and_writes_plan_and_recording(tmp_path):
    run = run_plan(str(SCENES / "battery.yaml"), "--out", "out", cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    assert run.stderr == ""
    lines = run.stdout.splitlines()
    assert len(lines) == 1 and lines[0].startswith("solved: 1 push,"), run.stdout
    out = tmp_path / "out"
    assert {p.name for p in out.iterdir()} == {"battery.json", "battery.rrd"}  # and no temporary files
    data = plan_json(out / "battery.json")
    assert data["solved"] is True and data["scene"] == str(SCENES / "battery.yaml")
    assert data["planner"] == DEFAULT_PLANNER and data["seed"] == 1 and len(data["segments"]) == 1
    goal = BATTERY["goal"]
    assert data["goal"] == pytest.approx([goal[0], goal[1], math.radians(goal[2])])
    assert math.dist(data["final"][:2], data["goal"][:2]) <= BATTERY["tolerance"]["position"]
    segment = data["segments"][0]
    assert segment["edge"] == 3 and segment["start"] == data["start"] and segment["end"] == data["final"]
    assert (out / "battery.rrd").stat().st_size > 0


def test_default_output_folder_is_logs_name_timestamp_under_the_cwd(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main([str(SCENES / "battery.yaml")]) == 0
    stdout = capsys.readouterr().out
    (folder,) = (tmp_path / "logs").iterdir()
    assert re.fullmatch(r"battery-\d{8}-\d{6}", folder.name)
    assert {p.name for p in folder.iterdir()} == {"battery.json", "battery.rrd"}
    assert plan_json(folder / "battery.json")["solved"] is True
    assert f"logs/{folder.name}/battery.json" in stdout


# --- determinism -----------------------------------------------------------------------------------

@pytest.mark.parametrize("scene, seed", [("corridor", 3), ("cluttered", 1), ("junction", 2)])
def test_same_seed_same_plan_across_processes(scene, seed, tmp_path):
    runs = [subprocess.Popen([str(PLAN), str(SCENES / f"{scene}.yaml"), "--seed", str(seed), "--out", out],
                             cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
            for out in ("A", "B")]
    for run in runs:
        _, err = run.communicate(timeout=60)
        assert run.returncode == 0, err
    a, b = (plan_json(tmp_path / out / f"{scene}.json") for out in ("A", "B"))
    assert a["solved"] and a["seed"] == seed and a["segments"]
    for times in ("planning_time_s", "improvements"):  # when each plan was found varies; nothing else may
        del a[times], b[times]
    assert a == b


# --- atomic output ---------------------------------------------------------------------------------

@pytest.mark.parametrize("case", ["mu 0", "no room for the pusher"])
def test_bad_input_leaves_an_earlier_plan_untouched(case, tmp_path, monkeypatch, capsys):
    out = tmp_path / "out"
    out.mkdir()
    (out / "battery.json").write_text("old plan")
    write(tmp_path, BAD_SCENES[case][0])
    monkeypatch.chdir(tmp_path)
    assert main(["scene.yaml", "--out", "out"]) == 1
    capsys.readouterr()
    assert (out / "battery.json").read_text() == "old plan"
    assert [p.name for p in out.iterdir()] == ["battery.json"]


def test_write_atomic_replaces_and_leaves_no_temporary_file(tmp_path):
    target = tmp_path / "plan.json"
    write_atomic(target, "old")
    write_atomic(target, b"new")
    assert target.read_text() == "new"
    assert [p.name for p in tmp_path.iterdir()] == ["plan.json"]


@pytest.mark.parametrize("failing", ["replace", "fsync"])
@pytest.mark.parametrize("error", [OSError("disk full"), KeyboardInterrupt()], ids=["OSError", "KeyboardInterrupt"])
def test_write_atomic_failure_keeps_the_old_file(failing, error, tmp_path, monkeypatch):
    target = tmp_path / "plan.json"
    target.write_text("old")

    def fail(*args):
        raise error

    monkeypatch.setattr(files.os, failing, fail)
    with pytest.raises(type(error)):
        write_atomic(target, "new")
    assert target.read_text() == "old"
    assert [p.name for p in tmp_path.iterdir()] == ["plan.json"]


def test_failed_write_is_one_error_line_and_keeps_the_old_plan(tmp_path, monkeypatch, capsys):
    out = tmp_path / "out"
    out.mkdir()
    (out / "battery.json").write_text("old plan")
    monkeypatch.chdir(tmp_path)

    def fail(*args):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(files.os, "replace", fail)
    assert main([str(SCENES / "battery.yaml"), "--out", "out"]) == 4
    captured = capsys.readouterr()
    assert captured.err == "plan: error: cannot write 'out/battery.rrd': No space left on device\n"
    assert captured.out == ""
    assert (out / "battery.json").read_text() == "old plan"
    assert [p.name for p in out.iterdir()] == ["battery.json"]


# --- flags override the scene ----------------------------------------------------------------------

def test_flags_override_the_scenes_planner_options(tmp_path, monkeypatch, capsys):
    write(tmp_path, battery(planner={"name": "est", "seed": 5}))
    monkeypatch.chdir(tmp_path)
    assert main(["scene.yaml", "--out", "scene_options"]) == 0
    assert main(["scene.yaml", "--planner", "rrt", "--seed", "2", "--out", "flags"]) == 0
    capsys.readouterr()
    by_scene = plan_json(tmp_path / "scene_options" / "battery.json")
    by_flags = plan_json(tmp_path / "flags" / "battery.json")
    assert (by_scene["planner"], by_scene["seed"]) == ("est", 5)
    assert (by_flags["planner"], by_flags["seed"]) == ("rrt", 2)


def test_time_limit_flag_overrides_the_scenes(tmp_path, monkeypatch, capsys):
    write(tmp_path, BEHIND | {"planner": {"name": "rrt", "time_limit": 60}})
    monkeypatch.chdir(tmp_path)
    clock = time.perf_counter()
    assert main(["scene.yaml", "--time-limit", "0.5", "--out", "out"]) == 2
    assert time.perf_counter() - clock < 5.0
    assert "0.5 s" in capsys.readouterr().err
    data = plan_json(tmp_path / "out" / "behind.json")
    assert data["planner"] == "rrt" and data["planning_time_s"] < 2.0


# --- help ------------------------------------------------------------------------------------------

def test_help_lists_exit_codes_defaults_and_the_region_cache(region_cache, capsys):
    with pytest.raises(SystemExit) as exit_:
        main(["--help"])
    assert exit_.value.code == 0
    text = " ".join(capsys.readouterr().out.split())  # argparse wraps lines at the terminal's width
    assert re.search(r"exit codes: 0 solved .* 1 bad input.* 2 not solved.* 3 .*slips.* 130 interrupted", text), text
    for default in ["--planner rrt", "--time-limit 10", "--seed 1", "--regions exact", "--transit plane"]:
        assert default in text
    assert "$STABLEPUSH_CACHE" in text and "~/.cache/stablepush" in text
    assert f"(here: {region_cache})" in text  # where this run's regions are


def test_ctrl_c_during_the_search_ends_as_interrupted(tmp_path):
    """SIGINT while OMPL searches (junction on one edge never solves): the run stops at once with
    exit 130 and its one line, writing nothing, instead of ending as if out of time."""
    run = subprocess.Popen(sigint_default([sys.executable, "-m", "planner.cli", str(SCENES / "junction.yaml"),
                                           "--transit", "none", "--time-limit", "60", "--out", str(tmp_path / "out")]),
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=ROOT)
    time.sleep(3.0)  # imports and regions (about a second, cold) are done: it is searching
    run.send_signal(signal.SIGINT)
    out, err = run.communicate(timeout=30)  # well before the time limit
    assert (run.returncode, out, err) == (130, "", "plan: interrupted\n")
    assert not (tmp_path / "out").exists()


def test_a_mistyped_key_gets_a_did_you_mean(tmp_path, capsys):
    text = (SCENES / "junction.yaml").read_text().replace("workspace:", "worksapce:")
    (tmp_path / "typo.yaml").write_text(text)
    assert main([str(tmp_path / "typo.yaml"), "--out", str(tmp_path / "out")]) == 1
    assert capsys.readouterr().err == "plan: error: worksapce: unknown key; did you mean workspace?\n"
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("change, line", [
    # A tray's parts: mistyped in a scene of one part's keys: the tray's key is suggested, not start.
    (lambda text: yaml.safe_dump({"part": yaml.safe_load(text)["parts"][0], **{k: v for k, v in yaml.safe_load(text).items()
                                                                                 if k != "parts"}}),
     "plan: error: part: unknown key; did you mean parts?"),
    # Neither form: say both, not what a scene of one part misses.
    (lambda text: yaml.safe_dump({k: v for k, v in yaml.safe_load(text).items() if k != "parts"}),
     "plan: error: parts: missing: a scene has parts: (each with its own start and goal) or slider, start and goal "
     "(one part)"),
    # A scene's field named as a flag is (--seed) is the file's, not the flag's.
    (lambda text: text + "\nseed: 3\n", "plan: error: seed: unknown key (known: parts, pusher, workspace, name, "
                                         "obstacles, tolerance, planner, robot, camera)")])
def test_a_tray_file_with_a_wrong_key_is_told_about_the_tray_form(change, line, tmp_path, capsys):
    """Issue 41: "part:" for "parts:" suggested "start", and a scene field named like a flag was
    printed as the flag (--part)."""
    (tmp_path / "tray.yaml").write_text(change((SCENES / "parts" / "swap.yaml").read_text()))
    assert main([str(tmp_path / "tray.yaml"), "--out", str(tmp_path / "out")]) == 1
    assert capsys.readouterr().err == line + "\n"
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("argv, code, line", [
    (["--reach", "3"], 1, "plan: error: --reach: must be 1 or 2 pushes, got 3"),
    (["--no-such-option"], 2, "plan: error: unrecognized arguments: --no-such-option"),
    (["--seed"], 2, "plan: error: argument --seed: expected one argument")])
def test_exit_codes_of_option_errors_are_as_help_says(tmp_path, capsys, argv, code, line):
    """A bad value of an option is bad input (1); argparse's usage errors are 2 (``plan --help``)."""
    with pytest.raises(SystemExit) if code == 2 else contextlib.nullcontext() as stopped:
        result = main([str(SCENES / "junction.yaml"), "--out", str(tmp_path / "out"), *argv])
    assert (stopped.value.code if code == 2 else result) == code
    assert capsys.readouterr().err.splitlines()[-1] == line
    assert not (tmp_path / "out").exists()



def test_an_output_folder_that_cannot_be_made_is_named_as_given(tmp_path, capsys, monkeypatch):
    """The folder is staged under a temporary name beside it; where that cannot be made (a folder
    the user may not write, /proc, ...), the line names the folder asked for, not the stage."""
    out = tmp_path / "out"

    def refused(dir, prefix, suffix):
        raise PermissionError(errno.EACCES, "Permission denied", os.path.join(dir, f"{prefix}x{suffix}"))

    monkeypatch.setattr(files.tempfile, "mkdtemp", refused)
    assert main([str(SCENES / "battery.yaml"), "--out", str(out)]) == 4
    assert capsys.readouterr().err == f"plan: error: cannot write {str(out)!r}: Permission denied\n"
    assert not out.exists()


def test_a_named_pipe_given_as_the_scene_is_refused_at_once(tmp_path, capsys):
    """Opening a pipe for reading waits for a writer: none comes, so it is refused unopened."""
    os.mkfifo(tmp_path / "scene.yaml")
    began = time.monotonic()
    assert main([str(tmp_path / "scene.yaml"), "--out", str(tmp_path / "out")]) == 1
    assert time.monotonic() - began < 5
    assert capsys.readouterr().err == (f"plan: error: scene: {str(tmp_path / 'scene.yaml')!r} is not a regular "
                                       "file (a named pipe)\n")
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("flags, named", [
    (["--out", "file/out"], "file/out"),
    (["--simulate", "1", "--mjcf", "file/model.xml", "--out", "out"], "file/model.xml"),
], ids=["--out", "--mjcf"])
def test_an_output_place_that_cannot_be_written_is_refused_before_planning(tmp_path, capsys, monkeypatch, flags, named):
    """Under a regular file nothing can be made: found before the search (and the simulation),
    not after them; exit 4, one line naming the place, nothing written."""
    pytest.importorskip("mujoco")
    (tmp_path / "file").write_text("a file, not a folder")
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr("planner.queries.session.Planner.plan", lambda *args, **kwargs: pytest.fail("planned before the check"))
    assert main([str(SCENES / "battery.yaml"), *flags]) == 4
    assert capsys.readouterr().err == f"plan: error: cannot write {named!r}: Not a directory\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["file"]


def test_every_planner_setting_has_its_flag_and_the_flag_sets_it():
    """A scene's planner: block and the command line name the same settings: each option of
    PlannerOptions has a flag, and giving the flag changes that option alone."""
    import dataclasses

    from planner.flags import FLAGS, options_of, parser as _parser
    from planner.model.options import PlannerOptions

    assert set(FLAGS) == {f.name for f in dataclasses.fields(PlannerOptions)}
    from planner.model.margin import Margin

    given = {"name": "kpiece", "time_limit": 3.0, "seed": 7, "regions": "stable", "switch_cost": 0.5, "optimize": 2,
             "transit": "lift", "margin": Margin(0.2, 0.05)}
    typed = {"margin": ["0.2", "0.05"]}
    base = PlannerOptions()
    for field, flag in FLAGS.items():
        changed = options_of(_parser().parse_args(["s.yaml", flag, *typed.get(field, [str(given[field])])]), base)
        assert getattr(changed, field) == given[field] != getattr(base, field)
        assert {f.name for f in dataclasses.fields(base) if getattr(changed, f.name) != getattr(base, f.name)} == {field}


@pytest.mark.parametrize("values, field", [(["-1e-3", "0", "0"], None), (["-1E-3", "-0", "-0.0"], None),
                                           (["-inf", "0", "0"], "--sim-start-error"),
                                           (["-nan", "0", "0"], "--sim-start-error")])
def test_negative_numbers_in_every_notation_are_values(values, field):
    """argparse knows negatives only as -1 and -.5: "-1e-3" and "-inf" were taken for options
    ("expected 3 arguments"). They are values, and the checks refuse what is not finite."""
    from planner.cli import read_inputs
    from planner.model.fields import SceneError

    argv = [str(SCENES / "battery.yaml"), "--simulate", "1", "--sim-start-error", *values]
    if field is None:
        assert read_inputs(argv).options.start_error[0] == float(values[0])
    else:
        with pytest.raises(SceneError) as err:
            read_inputs(argv)
        assert err.value.field == field
