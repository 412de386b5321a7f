"""A plan read from a file is checked against the scene it is used with (planner.execution.fit):
the scene's part and pusher, start, goal, obstacles and walls. A plan for another scene is one line
naming what differs, exit 1, nothing written; a plan that fits is run from the scene's start."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import shapely
import yaml

from mechanics import exp_twist
from planner import Push, load_plan, load_scene
from planner.cli import main
from planner.execution.fit import fit_plan
from planner.model.fields import SceneError
from test_cli import error_field

ROOT = Path(__file__).resolve().parents[3]
BEST = ROOT / "scenes" / "best"


def scene_copy(folder: Path, name: str, **changes) -> Path:
    """``scenes/<name>.yaml`` with ``changes`` made, written to ``folder/<name>.yaml``."""
    spec = yaml.safe_load((ROOT / "scenes" / f"{name}.yaml").read_text())
    for key, change in changes.items():
        spec[key] = change(spec.get(key))
    path = folder / f"{name}.yaml"
    path.write_text(yaml.safe_dump(spec))
    return path


def refused(tmp_path: Path, capsys, scene: Path, plan: Path, *flags: str) -> str:
    """Run ``plan SCENE --verify 2 --plan PLAN``; check it exits 1 with one line and writes
    nothing, and return the field the line names."""
    before = sorted(tmp_path.rglob("*"))
    assert main([str(scene), "--verify", "2", "--plan", str(plan), "--out", str(tmp_path / "out"), *flags]) == 1
    captured = capsys.readouterr()
    assert captured.out == "" and len(captured.err.splitlines()) == 1, captured.err
    assert sorted(tmp_path.rglob("*")) == before
    return error_field(captured.err)


@pytest.mark.parametrize("name", sorted(p.stem for p in BEST.glob("*.json")))
def test_every_best_known_plan_fits_its_scene_and_runs_from_its_start(name):
    scene, plan = load_scene(ROOT / "scenes" / f"{name}.yaml"), load_plan(BEST / f"{name}.json")
    fitted = fit_plan(scene, plan, transit=scene.options.transit)
    assert np.array_equal(fitted.start, scene.start) and scene.within_tolerance(fitted.final)
    assert [s.kind for s in fitted.segments] == [s.kind for s in plan.segments]


def test_a_start_moved_18_cm_is_refused_naming_the_start(tmp_path, capsys):
    scene = scene_copy(tmp_path, "parking", start=lambda s: [s[0] + 0.18, s[1], s[2]])
    assert refused(tmp_path, capsys, scene, BEST / "parking.json") == "plan.start"


def test_another_goal_is_refused_naming_where_the_plan_ends(tmp_path, capsys):
    scene = scene_copy(tmp_path, "parking", goal=lambda g: [g[0] + 0.1, g[1] + 0.3, g[2]])
    assert refused(tmp_path, capsys, scene, BEST / "parking.json") == "plan.final"


def test_a_wall_across_a_push_is_refused_naming_that_push(tmp_path, capsys):
    """A 1 cm post where the part's CF is halfway through the second push of parking (25 cm long)."""
    plan = load_plan(BEST / "parking.json")
    push = plan.segments[1]
    middle = exp_twist(push.start, push.twist, push.duration / 2)
    post = {"box": {"center": middle[:2].round(6).tolist(), "size": [0.01, 0.01]}}
    scene = scene_copy(tmp_path, "parking", obstacles=lambda walls: [*walls, post])
    assert refused(tmp_path, capsys, scene, BEST / "parking.json") == "plan.segments[1]"


def test_a_wall_across_a_transit_is_refused_naming_that_transit(tmp_path):
    """A post where the pusher walks round the part, clear of the part itself and of every push."""
    plan = load_plan(BEST / "junction.json")
    k = next(i for i, s in enumerate(plan.segments) if s.kind == "transit")
    path = plan.segments[k].pusher_path
    where = path[len(path) // 2, :2]
    post = {"box": {"center": where.round(6).tolist(), "size": [0.004, 0.004]}}
    moved = load_scene(scene_copy(tmp_path, "junction", obstacles=lambda walls: [*walls, post]))
    with pytest.raises(SceneError) as caught:
        fit_plan(moved, plan)
    assert caught.value.field == f"plan.segments[{k}]" and "transit" in caught.value.problem


def test_a_plan_file_marked_not_solved_is_not_verified(tmp_path, capsys):
    data = json.loads((BEST / "battery.json").read_text())
    data["solved"] = False
    (tmp_path / "unsolved.json").write_text(json.dumps(data))
    assert refused(tmp_path, capsys, ROOT / "scenes" / "battery.yaml", tmp_path / "unsolved.json") == "plan.solved"
    assert refused(tmp_path, capsys, ROOT / "scenes" / "battery.yaml", tmp_path / "unsolved.json",
                   "--trajectory") == "plan.solved"


def test_a_start_within_tolerance_is_run_from_the_scenes_start(tmp_path, capsys):
    """The battery plan begun 1 mm off (the tolerance is 2 mm): verified, and the plan written
    starts where the scene does, each push moved rigidly with it."""
    data = json.loads((BEST / "battery.json").read_text())
    scene = scene_copy(tmp_path, "battery", start=lambda s: [s[0] + 0.001, s[1], s[2]],
                       goal=lambda g: [g[0] + 0.001, g[1], g[2]])
    (tmp_path / "plan.json").write_text(json.dumps(data))
    assert main([str(scene), "--verify", "2", "--plan", str(tmp_path / "plan.json"), "--out", str(tmp_path / "out")]) == 0
    written = json.loads((tmp_path / "out" / "battery.json").read_text())
    assert written["start"] == pytest.approx([0.001, 0.0, 0.0], abs=1e-12)
    assert written["final"] == pytest.approx(np.add(data["final"], [0.001, 0.0, 0.0]), abs=1e-9)


def test_a_multi_part_plan_names_its_parts_fields_and_segments_among_all():
    """plan/2: a part's final is ``plan.parts.<name>.final``; a push of the last move is numbered
    among all the plan's segments, the transfers included."""
    scene = load_scene(ROOT / "scenes" / "parts" / "swap.yaml")
    plan = load_plan(ROOT / "tests" / "data" / "release_plans" / "swap.json")
    assert fit_plan(scene, plan).goals.keys() == {"red", "blue"}
    moved = scene.parts[0].goal + [0.05, 0.0, 0.0]
    other = replace(scene, parts=(replace(scene.parts[0], goal=moved), *scene.parts[1:]))
    with pytest.raises(SceneError) as caught:
        fit_plan(other, plan)
    assert caught.value.field == f"plan.parts.{scene.parts[0].name}.final"
    k = len(plan.segments) - len(plan.moves[-1].segments)  # the last move's first push, after two transfers
    push = plan.segments[k]
    assert isinstance(push, Push) and plan.transfers == 2
    middle = exp_twist(push.start, push.twist, push.duration / 2)
    post = shapely.Point(*middle[:2]).buffer(0.002)
    with pytest.raises(SceneError) as caught:
        fit_plan(replace(scene, obstacles=(*scene.obstacles, post)), plan)
    assert caught.value.field == f"plan.segments[{k}]" and "the push" in caught.value.problem
