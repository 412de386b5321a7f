"""Plan files: what `plan` writes reads back identically; hand-edited mistakes name their field."""

from __future__ import annotations

import copy
import json
import os
import warnings
from pathlib import Path

import numpy as np
import pytest

from planner import SceneError, load_plan, load_scene, plan

ROOT = Path(__file__).resolve().parents[3]


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
    (lambda d: d.update(format="stablepush.plan/9"), "plan.format"),
    (lambda d: d.pop("segments"), "plan.segments"),
    (lambda d: d.update(extra=1), "plan.extra"),
    (lambda d: d.update(solved="yes"), "plan.solved"),
    (lambda d: d["segments"][1].update(twist=[1, 2]), "plan.segments[1].twist"),
    (lambda d: d["segments"][0].update(kind="pull"), "plan.segments[0].kind"),
    (lambda d: d["segments"][0].update(duration=-1.0), "plan.segments[0].duration"),
    (lambda d: d["segments"][0].update(contact=[[0, 0]]), "plan.segments[0].contact"),
    (lambda d: d["segments"][0]["start"].__setitem__(2, "x"), "plan.segments[0].start[2]"),
    (lambda d: d.update(final=[9.0, 9.0, 0.0]), "plan.final"),
    (lambda d: d.update(length=d["length"] + 0.01), "plan.length"),
    (lambda d: d.update(cf=[d["cf"][0] + 0.01, d["cf"][1]]), "plan.length"),  # another point travels another path
    (lambda d: d.update(cost=d["cost"] + 0.25), "plan.cost"),
    (lambda d: d.pop("switch_cost"), "plan.cost"),
    (lambda d: d.update(improvements=[[0.1, 1.0]]), "plan.improvements[0]"),
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


@pytest.mark.parametrize("twist", [[1e300, 0.0, 0.0], [1e300, 1e300, 1e300]])
def test_a_huge_twist_is_one_error_without_a_warning_first(written, tmp_path, twist):
    """Issue 41: a twist of 1e300 overflowed in the length made from it, and numpy's RuntimeWarning
    came out before the one error line."""
    _, data = written
    bad = copy.deepcopy(data)
    bad["segments"][0]["twist"] = twist
    (tmp_path / "bad.json").write_text(json.dumps(bad))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(SceneError) as err:
            load_plan(tmp_path / "bad.json")
    assert err.value.field == "plan.length" and err.value.problem.endswith("but the segments make inf")


def test_cost_and_length_side_by_side(written):
    """The file says what the plan costs, as the planner counts it, beside its length: the CF's
    path (summed here from the pushes' own speeds and durations) plus the switch cost per switch."""
    _, data = written
    cf = np.asarray(data["cf"])
    length = sum(float(np.hypot(*(np.asarray(s["twist"][:2]) + s["twist"][2] * np.array([-cf[1], cf[0]]))))
                 * s["duration"] for s in data["segments"] if s["kind"] == "push")
    switches = sum(s["kind"] == "transit" for s in data["segments"])
    assert data["length"] == pytest.approx(length, abs=1e-8)
    assert data["cost"] == pytest.approx(length + data["switch_cost"] * switches, abs=1e-8)
    assert data["improvements"][-1][1:] == pytest.approx([data["cost"], data["length"]], abs=1e-8)


def test_unreadable_files(tmp_path):
    with pytest.raises(SceneError, match="cannot read"):
        load_plan(tmp_path / "missing.json")
    (tmp_path / "broken.json").write_text("{not json")
    with pytest.raises(SceneError, match="malformed JSON"):
        load_plan(tmp_path / "broken.json")


@pytest.mark.parametrize("text, problem", [
    ("[" * 1000 + "]" * 1000, "unsupported JSON: nests deeper than 16"),
    ('{"format": ' * 100_000, "unsupported JSON: nests deeper than 16"),  # not even closed
    ("[" + "9" * 5000 + "]", "malformed JSON: Exceeds the limit"),  # an int Python will not convert
    (" " * 10_000_001, "is larger than 10000000 bytes"),
    ("\xff", "is not UTF-8 text"),
], ids=["nested 1000 deep", "nested 100000 deep, unclosed", "5000 digits", "over 10 MB", "not UTF-8"])
def test_hostile_json_is_one_line_naming_the_plan(tmp_path, text, problem):
    path = tmp_path / "plan.json"
    path.write_bytes(text.encode("utf-8", "surrogateescape") if text != "\xff" else b"\xff")
    with pytest.raises(SceneError) as caught:
        load_plan(path)
    assert caught.value.field == "plan" and problem in caught.value.problem and "\n" not in str(caught.value)


def test_only_a_regular_file_is_read_as_a_plan(tmp_path):
    """A named pipe would block the run for ever (nobody writes to it); a folder is no plan."""
    os.mkfifo(tmp_path / "pipe")
    with pytest.raises(SceneError, match="is not a regular file \\(a named pipe\\)"):
        load_plan(tmp_path / "pipe")
    with pytest.raises(SceneError, match="is not a regular file \\(a folder\\)"):
        load_plan(tmp_path)


@pytest.fixture(scope="module")
def switching(tmp_path_factory):
    """A plan that changes edge once, the pusher walking round the part (scenes/junction.yaml)."""
    result = plan(load_scene(ROOT / "scenes" / "junction.yaml"), seed=1)
    assert result.solved and result.switches == 1
    path = tmp_path_factory.mktemp("plan") / "junction.json"
    path.write_text(result.to_json())
    return path, json.loads(result.to_json())


def transit_index(data: dict) -> int:
    return next(k for k, s in enumerate(data["segments"]) if s["kind"] == "transit")


def test_transit_round_trip(switching):
    path, data = switching
    loaded = load_plan(path)
    assert loaded.to_dict() == data
    k = transit_index(data)
    transit = loaded.segments[k]
    assert transit.kind == "transit" and transit.from_edge != transit.to_edge
    assert loaded.switches == 1 and loaded.pushes == len(data["segments"]) - 1
    # The part stands still: the transit's pose is the end of the push before it.
    assert transit.start.tolist() == transit.end.tolist() == data["segments"][k - 1]["end"]


@pytest.mark.parametrize("edit, field", [
    (lambda t: t.update(mode="teleport"), "mode"),
    (lambda t: t.update(mode=None), "mode"),
    (lambda t: t.pop("to_edge"), "to_edge"),
    (lambda t: t.update(from_edge=1.5), "from_edge"),
    (lambda t: t.update(pusher_path=[[0, 0, 0]]), "pusher_path"),
    (lambda t: t.update(pusher_path="none"), "pusher_path"),
    (lambda t: t["pusher_path"][1].__setitem__(2, "x"), "pusher_path[1][2]"),
    (lambda t: t["pusher_path"].__setitem__(0, [0, 0]), "pusher_path[0]"),
    (lambda t: t.update(mode="lift"), "pusher_path"),  # a walk round has more than lift's 4 poses
    (lambda t: t.update(duration=-0.1), "duration"),
    (lambda t: t.update(twist=[0, 0, 0]), "twist"),
])
def test_bad_transit_fields_are_named(switching, tmp_path, edit, field):
    _, data = switching
    bad = copy.deepcopy(data)
    k = transit_index(bad)
    edit(bad["segments"][k])
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(bad))
    with pytest.raises(SceneError) as err:
        load_plan(path)
    assert err.value.field == f"plan.segments[{k}].{field}"
