"""Plan files: what `plan` writes reads back identically; hand-edited mistakes name their field."""

from __future__ import annotations

import copy
import json
from pathlib import Path

import pytest

from planner import SceneError, load_plan, load_scene, plan

ROOT = Path(__file__).resolve().parent.parent


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    result = plan(load_scene(ROOT / "scenes" / "corridor.yaml"), seed=1)
    path = tmp_path_factory.mktemp("plan") / "corridor.json"
    path.write_text(result.to_json())
    return path, json.loads(result.to_json())


def test_round_trip(written):
    path, data = written
    loaded = load_plan(path)
    assert loaded.to_dict() == data
    assert loaded.solved and loaded.pushes == len(data["segments"]) >= 2


@pytest.mark.parametrize("edit, field", [
    (lambda d: d.update(format="stablepush.plan/2"), "plan.format"),
    (lambda d: d.pop("segments"), "plan.segments"),
    (lambda d: d.update(extra=1), "plan.extra"),
    (lambda d: d.update(solved="yes"), "plan.solved"),
    (lambda d: d["segments"][1].update(twist=[1, 2]), "plan.segments[1].twist"),
    (lambda d: d["segments"][0].update(kind="pull"), "plan.segments[0].kind"),
    (lambda d: d["segments"][0].update(duration=-1.0), "plan.segments[0].duration"),
    (lambda d: d["segments"][0].update(contact=[[0, 0]]), "plan.segments[0].contact"),
    (lambda d: d["segments"][0]["start"].__setitem__(2, "x"), "plan.segments[0].start[2]"),
    (lambda d: d.update(final=[9.0, 9.0, 0.0]), "plan.final"),
])
def test_bad_fields_are_named(written, tmp_path, edit, field):
    _, data = written
    bad = copy.deepcopy(data)
    edit(bad)
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(bad))
    with pytest.raises(SceneError) as err:
        load_plan(path)
    assert err.value.field == field


def test_unreadable_files(tmp_path):
    with pytest.raises(SceneError, match="cannot read"):
        load_plan(tmp_path / "missing.json")
    (tmp_path / "broken.json").write_text("{not json")
    with pytest.raises(SceneError, match="not valid JSON"):
        load_plan(tmp_path / "broken.json")
