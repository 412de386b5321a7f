"""Multi-part scenes: reading them, planning the transfer (order, buffer moves, the pusher's
travel between parts) and the plan file stablepush.plan/2, checked by an independent replay."""

from __future__ import annotations

import copy
import json
import subprocess
import sys
import time
from pathlib import Path

import pytest
import yaml

import planner
from planner import Planner, load_scene, parse_scene
from planner.model.fields import SceneError
from planner.model.plan import Plan
from planner.model.plan_file import read_plan
from planner.queries import multi_part
from replay import replay_parts_plan

BLOCK = [[-0.04, -0.025], [0.04, -0.025], [0.04, 0.025], [-0.04, 0.025]]


def spec_of(name: str) -> dict:
    with open(f"scenes/parts/{name}.yaml") as f:
        return yaml.safe_load(f)


@pytest.fixture(scope="module")
def plans() -> dict[str, Plan]:
    return {name: Planner(load_scene(f"scenes/parts/{name}.yaml"), {"seed": 1, "time_limit": 60}).plan()
            for name in ("channel", "swap", "tray")}


@pytest.mark.parametrize("name", ["channel", "swap", "tray"])
def test_shipped_scene_plans_and_replays(plans, name):
    plan = plans[name]
    assert plan.solved, plan.reason
    data = json.loads(plan.to_json())
    assert data["format"] == "stablepush.plan/2"
    replay_parts_plan(spec_of(name), data)


def test_swap_needs_a_buffer_move(plans):
    plan = plans["swap"]
    assert len(plan.moves) >= 3 and plan.buffer_moves >= 1
    # The part pushed aside first is pushed again later, to its goal.
    first = plan.moves[0].part
    assert [m.part for m in plan.moves].count(first) == 2


def test_channel_far_part_goes_first_even_when_tried_last(monkeypatch):
    """The order is searched, not taken from the heuristic: with the heuristic's order reversed,
    the near part is pushed in first, seals the channel, and the search backs out of it."""
    monkeypatch.setattr(multi_part._Search, "_order", lambda self, names, poses: sorted(names, key=lambda n: n != "near"))
    plan = Planner(load_scene("scenes/parts/channel.yaml"), {"seed": 1, "time_limit": 60}).plan()
    assert plan.solved, plan.reason
    assert [m.part for m in plan.moves] == ["far", "near"]
    replay_parts_plan(spec_of("channel"), json.loads(plan.to_json()))


def test_plan_file_round_trip_and_doctored_files(plans):
    data = plans["swap"].to_dict()
    again = read_plan(json.loads(json.dumps(data)))
    assert again.to_dict() == data
    wrong = copy.deepcopy(data)
    wrong["segments"][0]["part"] = "green"
    with pytest.raises(SceneError, match=r"plan.segments\[0\].part"):
        read_plan(wrong)
    moved = copy.deepcopy(data)
    push = next(s for s in moved["segments"] if s["kind"] == "push" and s["part"] != data["segments"][0]["part"])
    push["start"][0] += 0.01
    with pytest.raises(SceneError, match="start"):
        read_plan(moved)
    dear = copy.deepcopy(data)
    dear["cost"] += 0.1
    with pytest.raises(SceneError, match="plan.cost"):
        read_plan(dear)
    hop = copy.deepcopy(data)
    k = next(i for i, s in enumerate(hop["segments"]) if s["kind"] == "transfer")
    del hop["segments"][k]
    with pytest.raises(SceneError, match="transfer must come first"):
        read_plan(hop)


def test_transfer_cost_is_a_switch_each(plans):
    plan = plans["tray"]
    pushes = sum(m.segments[0].kind == "push" for m in plan.moves)
    assert pushes == len(plan.moves) and plan.transfers == len(plan.moves) - 1
    assert plan.cost == pytest.approx(plan.length + plan.switch_cost * (plan.switches + plan.transfers))


def _scene(**changes) -> dict:
    spec = {"parts": [{"name": "a", "vertices": BLOCK, "start": [0, 0, 0], "goal": [0.3, 0, 0]},
                      {"name": "b", "vertices": BLOCK, "start": [0, 0.2, 0], "goal": [0.3, 0.2, 0]}],
            "pusher": {"width": 0.04, "depth": 0.015, "mu": 0.6},
            "workspace": {"min": [-0.5, -0.5], "max": [0.5, 0.5]}}
    for path, value in changes.items():
        *head, last = path.split(".")
        at = spec
        for key in head:
            at = at[int(key)] if isinstance(at, list) else at[key]
        at[last] = value
    return spec


@pytest.mark.parametrize("changes, field, words", [
    ({"parts.1.name": "a"}, "parts[1].name", "named twice"),
    ({"parts.1.start": [0.02, 0.02, 0]}, "parts[1].start", "overlaps part 'a' at their starts"),
    ({"parts.1.goal": [0.3, 0.03, 0]}, "parts[1].goal", "overlaps part 'a' at their goals"),
    ({"parts.0.start": [0.49, 0, 0]}, "parts[0].start", "not inside the workspace"),
    ({"obstacles": [{"box": {"center": [0.3, 0], "size": [0.05, 0.05]}}]}, "parts[0].goal", "collides with obstacle 0"),
    ({"slider": {"vertices": BLOCK}}, "slider", "parts"),
    ({"parts": []}, "parts", "non-empty"),
    ({"parts.0.vertices": [[0, 0], [1, 1], [1, 0], [0, 1]]}, "parts[0].vertices", "self-intersecting"),
    ({"parts.0.speed": 3}, "parts[0].speed", "unknown key"),
    ({"pusher.edges": [0]}, "pusher.edges", "unknown key"),
    ({"parts.0.edges": [7]}, "parts[0].edges", "does not exist"),
])
def test_bad_multi_part_scenes_name_the_field(changes, field, words):
    with pytest.raises(SceneError) as err:
        parse_scene(_scene(**changes))
    assert err.value.field == field and words in err.value.problem


def test_a_part_that_stays_put_is_an_obstacle_in_the_way():
    """b stands on a's straight way and must stay: a goes round it, b is never pushed."""
    spec = _scene(**{"parts.1.start": [0.15, 0.0, 90], "parts.1.goal": [0.15, 0.0, 90]})
    scene = parse_scene(spec)
    assert len(scene.parts) > 1
    plan = Planner(scene, {"seed": 1, "time_limit": 30}).plan()
    assert plan.solved, plan.reason
    assert [m.part for m in plan.moves] == ["a"]
    replay_parts_plan(spec, json.loads(plan.to_json()))


def run_plan(*args, cwd=None):
    import subprocess
    import sys
    return subprocess.run([sys.executable, "-m", "planner.cli", *map(str, args)], capture_output=True, text=True,
                          cwd=cwd)


def test_cli_plans_a_multi_part_scene(tmp_path):
    done = run_plan("scenes/parts/swap.yaml", "--out", tmp_path / "out", "--trajectory")
    assert done.returncode == 0, done.stderr
    line = done.stdout.strip()
    assert line.startswith("solved: 2 parts, 3 moves (1 buffer), ") and line.endswith("swap.rrd, swap.trajectory.csv")
    # The README's "Several parts" shows this line, times left out.
    [said] = [row for row in Path("README.md").read_text().splitlines() if row.startswith("solved: 2 parts, ")]
    assert line.split(", planning time")[0] == said.split(", planning time")[0]
    csv = (tmp_path / "out" / "swap.trajectory.csv").read_text().splitlines()
    assert csv[0].endswith(",segment,part") and {row.rsplit(",", 1)[1] for row in csv[1:]} == {"red", "blue"}
    data = json.loads((tmp_path / "out" / "swap.json").read_text())
    assert data["format"] == "stablepush.plan/2" and set(data["parts"]) == {"red", "blue"}
    assert (tmp_path / "out" / "swap.rrd").stat().st_size > 0
    replay_parts_plan(spec_of("swap"), data)


@pytest.mark.parametrize("changes, args, words", [
    ({"parts.1.start": [0.02, 0.02, 0]}, [], "parts[1].start: part 'b' overlaps part 'a' at their starts"),
    ({"parts.1.name": "a"}, [], "parts[1].name: part 'a' is named twice"),
    ({}, ["--reach", "1"], "--part: the reachable set is one part's: name one of a, b"),
])
def test_cli_bad_multi_part_input_is_one_line(tmp_path, changes, args, words):
    scene = tmp_path / "bad.yaml"
    scene.write_text(yaml.safe_dump(_scene(**changes)))
    done = run_plan(scene, "--out", tmp_path / "out", *args)
    assert done.returncode == 1 and done.stderr.startswith(f"plan: error: {words}")
    assert done.stderr.count("\n") == 1 and not done.stdout
    assert not (tmp_path / "out").exists()


def test_channel_simulates_with_every_part_delivered(tmp_path):
    pytest.importorskip("mujoco")
    done = run_plan("scenes/parts/channel.yaml", "--simulate", "2", "--out", tmp_path / "out")
    assert done.returncode == 0, done.stdout + done.stderr
    assert "simulate: passed: 2/2 runs with every part in its goal" in done.stdout
    assert "at least 2/2 parts delivered" in done.stdout


def _shove(tmp_path):
    """A scene where b stands on a's straight way and stays put, and a doctored plan that pushes a
    straight through b (the plan of a alone, as if b were not there)."""
    from planner.model.plan import Move
    from planner.queries.session import plan as plan_one

    spec = _scene(**{"parts.1.start": [0.15, 0.0, 90], "parts.1.goal": [0.15, 0.0, 90]})
    scene = parse_scene(spec)
    alone = plan_one(parse_scene({"slider": {"vertices": BLOCK}, "pusher": spec["pusher"],
                                  "workspace": spec["workspace"], "start": [0, 0, 0], "goal": [0.3, 0, 0]}), seed=1)
    assert alone.solved
    doctored = Plan(scene=None, solved=True, planner="rrt", seed=1, planning_time_s=0.0, starts=scene.starts,
                         goals=scene.goals, moves=[Move("a", alone.segments)], delivered=("a", "b"),
                         switch_cost=0.25, cfs={p.name: p.slider.cf for p in scene.parts})
    (tmp_path / "shove.yaml").write_text(yaml.safe_dump(spec))
    (tmp_path / "shove.json").write_text(doctored.to_json())
    return tmp_path / "shove.yaml", tmp_path / "shove.json"


def test_a_doctored_plan_that_shoves_a_part_fails_verify_and_simulate(tmp_path):
    scene, doctored = _shove(tmp_path)
    checked = run_plan(scene, "--verify", "4", "--plan", doctored, "--out", tmp_path / "v")
    assert checked.returncode == 3, checked.stdout + checked.stderr
    assert "move 1/1 (a)" in checked.stdout and "meets b: FAILED" in checked.stdout
    pytest.importorskip("mujoco")
    run = run_plan(scene, "--simulate", "1", "--plan", doctored, "--out", tmp_path / "s")
    assert run.returncode == 3, run.stdout + run.stderr
    assert "a touches b" in run.stdout and "misses the goal: b" in run.stdout


def test_a_plan_file_for_other_starts_is_bad_input(tmp_path, plans):
    data = plans["swap"].to_dict()
    data["parts"]["red"]["start"][0] += 0.05  # and so no segment of red follows on from it
    (tmp_path / "other.json").write_text(json.dumps(data))
    done = run_plan("scenes/parts/swap.yaml", "--verify", "2", "--plan", tmp_path / "other.json", "--out", tmp_path / "o")
    assert done.returncode == 1 and done.stderr.startswith("plan: error: plan.")
    assert not (tmp_path / "o").exists()


def test_a_batch_plans_multi_part_scenes_as_the_command_does(tmp_path):
    """Two workers or one, the batch's plan files are the plans the seed decides."""
    for jobs in (1, 2):
        done = run_plan("scenes/parts/swap.yaml", "--seeds", "1:2", "--jobs", jobs, "--out", tmp_path / f"j{jobs}")
        assert done.returncode == 0, done.stdout + done.stderr
    for seed in (1, 2):
        one, two = (json.loads((tmp_path / f"j{j}" / f"swap-s{seed}.json").read_text()) for j in (1, 2))
        assert one["format"] == "stablepush.plan/2" and one["solved"]
        assert one["segments"] == two["segments"]
    replay_parts_plan(spec_of("swap"), one)


def test_a_part_that_cannot_be_delivered_gives_a_partial_plan_naming_it(tmp_path):
    """c's goal lies inside a closed ring of walls: the others are delivered, the plan is not
    solved, and both the plan and the command's line say which part is missing and why."""
    ring = [{"box": {"center": c, "size": s}} for c, s in (([0.3, -0.3], [0.2, 0.02]), ([0.3, -0.1], [0.2, 0.02]),
                                                          ([0.21, -0.2], [0.02, 0.2]), ([0.39, -0.2], [0.02, 0.2]))]
    spec = _scene(obstacles=ring)
    spec["parts"].append({"name": "c", "vertices": BLOCK, "start": [-0.3, -0.3, 0], "goal": [0.3, -0.2, 0]})
    plan = Planner(parse_scene(spec), {"seed": 1, "time_limit": 20}).plan()
    assert not plan.solved and plan.delivered == ("a", "b")
    assert "not delivered: c" in plan.reason
    (tmp_path / "ring.yaml").write_text(yaml.safe_dump(spec))
    done = run_plan(tmp_path / "ring.yaml", "--out", tmp_path / "out", "--time-limit", "20")
    assert done.returncode == 2 and done.stderr.startswith("plan: not solved: ") and "not delivered: c" in done.stderr
    data = json.loads((tmp_path / "out" / "ring.json").read_text())
    assert not data["solved"] and [n for n, p in data["parts"].items() if p["delivered"]] == ["a", "b"]
    replay_parts_plan({**spec, "parts": spec["parts"][:2]}, {**data, "parts": {k: data["parts"][k] for k in "ab"}})


def test_transfers_fly_where_the_scene_lets_the_pusher_lift(tmp_path):
    spec = spec_of("swap")
    spec["pusher"]["transit"] = "lift"
    plan = Planner(parse_scene(spec), {"seed": 1}).plan()
    assert plan.solved and plan.transfers and all(m.transfer.mode == "lift" for m in plan.moves[1:])
    replay_parts_plan(spec, json.loads(plan.to_json()))


def test_a_picture_of_a_multi_part_plan_holds_its_headline(plans, tmp_path):
    """The one picture function draws a plan of several parts, as it does one of one part."""
    pytest.importorskip("matplotlib")
    from PIL import Image

    from planner.outputs.picture import draw_plan

    draw_plan(load_scene("scenes/parts/swap.yaml"), plans["swap"], str(tmp_path / "swap.png"))
    assert Image.open(tmp_path / "swap.png").text["Description"] == f"swap: {plans['swap'].headline()}"


def test_a_tray_with_a_tiny_part_plans_within_a_memory_cap_and_one_too_tiny_is_one_line(tmp_path):
    """Swap with its red block shrunk: the buffer grid was spaced a part radius apart (a square of
    2 um asked for 2.55 TiB, a MemoryError); now each grid is held to a number of cells the table
    sets (planner.world.grid), so under a 4 GB address space a square of 0.6 mm (just above
    the units hint's 1/100 of the pusher's width, planner.model.scale) is planned in seconds, the
    tiny part pushed aside and fetched, and replays; one of 2 um is refused at once, one line."""
    spec = spec_of("swap")
    script = ("import resource, sys\nresource.setrlimit(resource.RLIMIT_AS, (4 << 30, 4 << 30))\n"
              "from planner import Planner, SceneError, load_scene\n"
              "try:\n    scene = load_scene(sys.argv[1])\n"
              "except SceneError as err:\n    sys.exit(f'error: {err}')\n"
              "print(Planner(scene, {'seed': 1, 'time_limit': 30, 'margin': 0}).plan().to_json())\n")
    for half in (3e-4, 1e-6):
        spec["parts"][0]["vertices"] = [[-half, -half], [half, -half], [half, half], [-half, half]]
        path = tmp_path / f"tiny-{half}.yaml"
        path.write_text(yaml.safe_dump(spec))
        began = time.perf_counter()
        run = subprocess.run([sys.executable, "-c", script, str(path)], capture_output=True, text=True, timeout=300)
        assert time.perf_counter() - began < 120.0
        if half < 1e-5:
            assert run.returncode == 1 and run.stderr.startswith("error: parts[0].vertices: the part is 2.828 um across, less than 1/100 of the pusher")
            assert run.stderr.count("\n") == 1, run.stderr
            continue
        assert run.returncode == 0, run.stderr[-3000:]
        data = json.loads(run.stdout)
        assert data["solved"], data["reason"]
        moves = [s["part"] for k, s in enumerate(data["segments"])
                 if s["kind"] != "transfer" and (k == 0 or data["segments"][k - 1]["kind"] == "transfer")]
        assert len(moves) >= 3 and moves.count(moves[0]) == 2  # one of them left at a buffer pose, then fetched
        replay_parts_plan(spec, data)


ASKED = {  # each query of one part, and what it is asked of a scene (or of a session of it)
    "reachability": ("reachability", lambda scene, session: planner.reachability(scene, [[0.0, 0.0, 0.0]])),
    "session.reachability": ("reachability", lambda scene, session: session.reachability([[0.0, 0.0, 0.0]],
                                                                                          start=[-0.1, 0.0, 0.0])),
    "one_step": ("one_step", lambda scene, session: planner.one_step(scene, [0.0, 0.0, 0.0], [0.1, 0.0, 0.0])),
    "reachable_set": ("reachable_set", lambda scene, session: planner.reachable_set(scene)),
    "session.reachable_set": ("reachable_set", lambda scene, session: session.reachable_set()),
    "controllability": ("controllability", lambda scene, session: planner.controllability(scene)),
    "certify_unreachable": ("certify_unreachable",
                            lambda scene, session: planner.certify_unreachable(scene, [0.0, 0.0, 0.0])),
    "session.certify_unreachable": ("certify_unreachable", lambda scene, session: session.certify_unreachable(
        [0.0, 0.0, 0.0], start=[-0.1, 0.0, 0.0])),
}


@pytest.mark.parametrize("query, ask", ASKED.values(), ids=ASKED.keys())
def test_queries_of_one_part_refuse_a_tray_naming_the_scene(query, ask):
    """The queries that answer for one part, asked of swap's two, say so in one line naming the
    scene and the query and how to pick a part; the move scene of one part is then answered."""
    scene = load_scene("scenes/parts/swap.yaml")
    session = Planner(scene)
    with pytest.raises(SceneError) as refused:
        ask(scene, session)
    assert refused.value.field == "scene" and query in refused.value.problem and "move_scene" in refused.value.problem
    assert len(str(refused.value).splitlines()) == 1
    one = scene.move_scene("red", scene.starts)
    ask(one, Planner(one))
