"""Property-based fuzzing of the other files a user hands the command (issue 31): plan files given
with ``--plan`` and a batch's ``results.jsonl`` read back for ``--resume``.

Plan files are real ones (the best-known plans of battery and junction, whose plan switches edges)
with a few fields replaced, deleted, added or shared by hostile values (the mutations and values of
tests/planner/model/test_fuzz_scenes.py), or their JSON text with hostile pieces spliced in (deep nesting,
huge numbers, cut short). Whatever the file, the command line's input stage
(:func:`planner.cli.read_inputs`: reading, checking, fitting the plan to its scene) either accepts
it or raises one :class:`SceneError` whose message is one short line, within a time bound, and
writes nothing. Results files are a real batch's lines, mutated the same way: reading them back
(:class:`planner.batch.results.ResultsFile`, then what ``--resume`` reuses and the summary)
never raises, and keeps only whole records of the batch's tasks. The budget is a tenth of the
Hypothesis profile's (``tests/conftest.py``): a few seconds in CI.
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
import shapely
from hypothesis import example, given, settings
from hypothesis import strategies as st

from planner.batch import make_tasks
from planner.batch.results import COLUMNS, ResultsFile, is_record, summary
from planner.batch.run import batch_records, reusable
from planner.cli import read_inputs
from planner.execution.fit import fit_plan
from planner.execution.verify import REACH_IN, verify
from planner.model.plan_file import load_plan, read_plan
from planner.model.scene_file import load_scene
from planner.model.fields import SceneError
from test_fuzz_scenes import assert_one_line_naming_a_field, inside, long_texts, mutate

ROOT = Path(__file__).resolve().parents[3]
PLANS = {name: json.loads((ROOT / "scenes" / "best" / f"{name}.json").read_text()) for name in ("battery", "junction")}
# A plan/2 file of a tray (its previous release's plan of swap): moves, transfers, parts.
PLANS["parts/swap"] = json.loads((ROOT / "tests" / "data" / "release_plans" / "swap.json").read_text())
#: A tenth of the profile's examples: each example reads a scene and builds a collision model.
FEW = settings(max_examples=max(10, settings().max_examples // 10))
#: Seconds an example may take: the checks of a plan are bounded (planner.execution.fit.MAX_CHECKS).
SLOWEST = 5.0

SPLICES = ["[" * 5000, "{\"a\":" * 3000, "1" * 5000, "1e999", "-1e999", "NaN", "Infinity", "\"\\ud800\"", "null",
           "\"" + "x" * 20000 + "\"", "]", "}", ",", "\x00", "\u2028"]
splices = st.one_of(st.sampled_from(SPLICES), long_texts, st.text(max_size=20))


@st.composite
def plan_docs(draw: Callable) -> tuple[str, dict]:
    """A scene's name and its best-known plan with one to three mutations."""
    name = draw(st.sampled_from(sorted(PLANS)))
    doc = json.loads(json.dumps(PLANS[name]))
    data = draw(st.data())
    for _ in range(draw(st.integers(1, 3))):
        mutate(data, doc)
    return name, doc


@st.composite
def plan_texts(draw: Callable) -> tuple[str, str]:
    """A plan file's text (mutated or not) with hostile pieces spliced in or its end cut off."""
    name, doc = draw(st.one_of(plan_docs(), st.sampled_from(sorted(PLANS)).map(lambda n: (n, PLANS[n]))))
    text = json.dumps(doc)
    for _ in range(draw(st.integers(1, 3))):
        where = draw(st.integers(0, len(text)))
        text = text[:where] if draw(st.booleans()) and where else text[:where] + draw(splices) + text[where:]
    return name, text


@pytest.fixture(scope="module")
def folder(tmp_path_factory) -> Path:
    return tmp_path_factory.mktemp("fuzz-plans")


def check_plan(folder: Path, name: str, content: bytes) -> None:
    """``plan SCENE --verify 2 --plan plan.json``'s input stage: the plan, fitted, or one good line,
    soon, and nothing written."""
    (folder / "plan.json").write_bytes(content)
    began = time.monotonic()
    with inside(folder):
        try:
            scene, options, planner_options = read_inputs([str(ROOT / "scenes" / f"{name}.yaml"), "--verify=2",
                                                           "--plan=plan.json"])
            given = fit_plan(scene, load_plan(options.plan_file), transit=planner_options.transit)  # the run's first step
            assert given.solved and all((given.starts[n] == scene.starts[n]).all() for n in scene.names)
        except SceneError as err:
            assert_one_line_naming_a_field(err)
            assert err.field.split(".")[0].split("[")[0] == "plan", str(err)
    assert time.monotonic() - began < SLOWEST
    assert [p.name for p in folder.iterdir()] == ["plan.json"], "reading input must write nothing"


@FEW
@given(case=plan_docs())
def test_mutated_plan_files(folder, case):
    name, doc = case
    check_plan(folder, name, json.dumps(doc).encode())


@FEW
@given(case=plan_texts())
def test_hostile_plan_text(folder, case):
    name, text = case
    check_plan(folder, name, text.encode("utf-8", "surrogatepass"))


# --- pusher paths doctored: no wrong pass ------------------------------------------------------------------

#: Plans whose pusher travels between contacts: junction's transit walks round its part, swap's two
#: transfers go from one part to the other.
TRAVELS = {"junction": "transit", "parts/swap": "transfer"}


@st.composite
def doctored_paths(draw: Callable) -> tuple[str, dict]:
    """A plan whose transits or transfers have their pusher paths doctored: inner poses dropped or
    moved (up to a part's size), or the mode relabelled (a lift's four poses, its flight then on the table)."""
    name = draw(st.sampled_from(sorted(TRAVELS)))
    doc = json.loads(json.dumps(PLANS[name]))
    travels = [s for s in doc["segments"] if s["kind"] == TRAVELS[name]]
    for segment in draw(st.lists(st.sampled_from(travels), min_size=1, max_size=len(travels))):
        path = segment["pusher_path"]
        how = draw(st.sampled_from(["drop", "move", "relabel"]))
        if how == "drop" and len(path) > 2:
            keep = sorted(draw(st.sets(st.integers(1, len(path) - 2), max_size=len(path) - 3)))
            segment["pusher_path"] = [path[0], *(path[k] for k in keep), path[-1]]
        elif how == "move" and len(path) > 2:
            k = draw(st.integers(1, len(path) - 2))
            offset = draw(st.tuples(*[st.floats(-0.06, 0.06)] * 2, st.floats(-1.0, 1.0)))
            path[k] = [v + d for v, d in zip(path[k], offset)]
        elif how == "relabel":
            segment["mode"] = "lift" if segment["mode"] == "plane" and len(path) == 4 else "plane"
    return name, doc


def overlap(scene, plan) -> float:
    """Independently of the planner: the largest area (m^2) the pusher's rectangle shares with a
    part, over 41 poses of each of its moves on the table between contacts (a lift's flight, the
    middle of its four poses, excepted), every part where it stands then (shapely only)."""
    w, d = scene.pusher.width / 2, scene.pusher.depth
    poses, worst = dict(plan.starts), 0.0
    for move in plan.moves:
        for segment in [move.transfer] * (move.transfer is not None) + list(move.segments):
            if segment.kind == "push":
                continue
            if segment.kind == "transit":
                poses[move.part] = segment.pose
            parts = [scene.body(n, poses[n]) for n in scene.names]
            path = np.asarray(segment.pusher_path, dtype=float)
            pieces = [(0, 1), (2, 3)] if segment.mode == "lift" else list(zip(range(len(path) - 1), range(1, len(path))))
            for a, b in ((path[i], path[j]) for i, j in pieces):
                turn = (b[2] - a[2] + np.pi) % (2 * np.pi) - np.pi
                for t in np.linspace(0.0, 1.0, 41):
                    x, y, th = a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]), a[2] + t * turn
                    c, s_ = np.cos(th), np.sin(th)
                    box = shapely.Polygon([(x + c * px - s_ * py, y + s_ * px + c * py)
                                           for px, py in [(-d, -w), (0, -w), (0, w), (-d, w)]])
                    worst = max(worst, max(box.intersection(part).area for part in parts))
        poses[move.part] = move.end
    return worst


@FEW
@given(case=doctored_paths())
def test_a_doctored_pusher_path_never_passes_verify_through_a_part(folder, case):
    """Issue 41: whatever is done to the pusher's paths between contacts, ``--verify`` either
    refuses the plan (one line), fails it, or passes it only if the pusher, sampled independently,
    never reaches into a part (beyond twice the rounding room verify allows)."""
    name, doc = case
    (folder / "plan.json").write_text(json.dumps(doc))
    with inside(folder):
        try:
            scene, options, planner_options = read_inputs([str(ROOT / "scenes" / f"{name}.yaml"), "--verify=1",
                                                           "--plan=plan.json"])
            given = fit_plan(scene, load_plan(options.plan_file), transit=planner_options.transit)
            check = verify(scene, given, n=1, transit=planner_options.transit)
        except SceneError as err:
            assert_one_line_naming_a_field(err)
            return
    if check.passed:
        allowed = 2 * REACH_IN * max(p.slider.radius for p in scene.parts) * scene.pusher.width
        assert overlap(scene, given) <= allowed, "\n".join(check.lines())


def test_the_doctored_paths_oracle_sees_a_path_through_the_part():
    """The oracle above is not blind: the plans as shipped keep out, a transit cut to its ends does not."""
    scene = load_scene(ROOT / "scenes" / "junction.yaml")
    good = fit_plan(scene, read_plan(PLANS["junction"]))
    assert overlap(scene, good) < 1e-9
    doc = json.loads(json.dumps(PLANS["junction"]))
    for segment in doc["segments"]:
        if segment["kind"] == "transit":
            segment["pusher_path"] = segment["pusher_path"][:: len(segment["pusher_path"]) - 1]
    assert overlap(scene, fit_plan(scene, read_plan(doc))) > 1e-4


# --- results files -----------------------------------------------------------------------------------

TASKS = make_tasks([ROOT / "scenes" / "battery.yaml"], range(1, 4))
RECORDS = [dict.fromkeys(COLUMNS) | task.record() | {
    "status": "solved", "cost": 0.1, "length": 0.1, "pushes": 1, "switches": 0, "planning_time_s": 0.01,
    "task_s": 0.02, "regions_computed": 0, "host": "h", "attempts": 1, "plan": f"{task.id}.json"} for task in TASKS]


@st.composite
def results_texts(draw: Callable) -> str:
    """A batch's results lines, some mutated, some spliced or cut, some repeated."""
    lines = []
    for record in RECORDS:
        doc = json.loads(json.dumps(record))
        if draw(st.booleans()):
            data = draw(st.data())
            for _ in range(draw(st.integers(1, 2))):
                mutate(data, doc)
        line = json.dumps(doc)
        if draw(st.booleans()):
            where = draw(st.integers(0, len(line)))
            line = line[:where] + draw(splices) + line[where + draw(st.integers(0, 3)):]
        lines += [line] * draw(st.integers(1, 2))
    return "\n".join(lines) + ("\n" if draw(st.booleans()) else "")


@FEW
@given(text=results_texts())
@example(text=json.dumps(RECORDS[0] | {"seed": 10**400}) + "\n")  # an int beyond a float (found by this test)
def test_mutated_results_files(tmp_path_factory, text):
    out = tmp_path_factory.mktemp("results")
    for record in RECORDS:
        (out / record["plan"]).write_text("{}")
    (out / "results.jsonl").write_bytes(text.encode("utf-8", "surrogatepass"))
    done, bad = ResultsFile(out / "results.jsonl").read()
    assert all(is_record(r) for r in done.values()) and len(done) + bad <= text.count("\n") + 1
    reused = reusable(TASKS.find, done, out)
    assert reused <= {t.id for t in TASKS} and all(TASKS.find(i).is_answered_by(done[i]) for i in reused)
    summary(batch_records(TASKS.find, done))
    assert sorted(p.name for p in out.iterdir()) == sorted([r["plan"] for r in RECORDS] + ["results.jsonl"])
