"""The stability margin a plan keeps (planner.model.margin, planner.actions.margins), checked against
the independent LP oracle of tests/oracle.py, which shares no code with the regions."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

import oracle as O
from planner import Planner, load_scene
from planner.actions.controls import certified_for
from planner.actions.margins import with_margins
from planner.cli import main
from planner.model.fields import SceneError
from planner.model.margin import EXACT, Margin
from planner.model.segments import Push

ROOT = Path(__file__).resolve().parents[3]

# A part whose CF sits so far to the side of the pushed face that only the full friction keeps a
# push through it: with 10 % less there is no stable push at all.
TIGHT = """\
name: tight
slider:
  vertices: [[-0.05, 0], [0.05, 0], [0.05, 0.1], [-0.05, 0.1]]
  cf: [0.029, 0.05]
pusher: {width: 0.02, depth: 0.01, mu: 0.5, edges: [0]}
workspace: {min: [-0.5, -0.5], max: [0.5, 0.5]}
start: [0, 0, 0]
goal: [0.1, 0.2, -40]
"""


def _oracle_holds(scene, name: str, push: Push, mu: float, radius: float, points: int = 8) -> bool:
    """The oracle: sticking for every sampled support distribution, at friction ``mu``, with the
    CF at the scene's and at ``points`` CFs on the circle of ``radius`` about it."""
    slider = scene.part(name).slider
    angles = np.linspace(0, 2 * np.pi, points, endpoint=False)
    cfs = [slider.cf, *(slider.cf + radius * np.column_stack([np.cos(angles), np.sin(angles)]))]
    return all(O.guaranteed_stable(slider.vertices, cf, push.edge, mu, scene.pusher.width, push.twist) for cf in cfs)


@pytest.mark.slow
@pytest.mark.parametrize("name", ["parking", "corridor", "nonconvex", "junction"])
def test_pushes_planned_with_the_default_margin_hold_for_less_friction_and_a_moved_cf(name):
    """Every push of a default plan sticks, by the oracle, at 90 % of the scene's friction with the
    CF anywhere on the margin's circle (and at its centre); and each push's own certified margins
    are at least the plan's."""
    scene = load_scene(ROOT / "scenes" / f"{name}.yaml")
    plan = Planner(scene, {"seed": 1}).plan()
    assert plan.solved and plan.margin == Margin()
    mu, rho = certified_for(scene, plan.margin)
    assert math.isclose(mu, 0.9 * scene.pusher.mu) and rho >= 0.001
    pushes = [s for _, s in plan.steps if isinstance(s, Push)]
    for push in pushes:
        assert _oracle_holds(scene, "part", push, mu, rho), push
    margins = with_margins(scene, plan).margins
    assert len(margins) == len(pushes)
    # The planned friction and disk are rungs of the margins' ladders: each push keeps them exactly.
    assert min(m.mu for m in margins) >= 0.1 - 1e-9
    assert min(m.cf for m in margins) >= rho - 1e-12


def test_a_push_on_the_exact_limit_breaks_with_a_cf_moved_where_the_margin_keeps_it():
    """The exact limit has nothing to spare: corridor's plan at margin 0 has pushes whose line of
    action passes the end of the contact, so their certified CF margin is below the default
    margin's disk, and a CF moved by that much breaks them (the oracle finds a distribution)."""
    scene = load_scene(ROOT / "scenes" / "corridor.yaml")
    exact = Planner(scene, {"seed": 1, "margin": 0}).plan()
    assert exact.solved and exact.margin == EXACT
    _, rho = certified_for(scene, Margin())
    pushes = [s for _, s in exact.steps if isinstance(s, Push)]
    margins = with_margins(scene, exact).margins
    weak = [k for k, m in enumerate(margins) if m.cf < rho]
    assert weak, [str(m) for m in margins]
    for k in weak:
        assert not _oracle_holds(scene, "part", pushes[k], scene.pusher.mu, rho, points=16), k


def test_a_scene_whose_pushes_need_the_exact_limit_names_the_margin_and_plans_without_it(tmp_path, monkeypatch, capsys):
    (tmp_path / "tight.yaml").write_text(TIGHT)
    monkeypatch.chdir(tmp_path)
    assert main(["tight.yaml", "--out", "a"]) == 1
    captured = capsys.readouterr()
    assert captured.out == "" and captured.err.count("\n") == 1
    assert captured.err.startswith("plan: error: planner.margin: no allowed edge has a push stable with the margin")
    assert "exact limit (margin 0) some have" in captured.err and not (tmp_path / "a").exists()
    assert main(["tight.yaml", "--out", "b", "--margin", "0"]) == 0
    data = json.loads((tmp_path / "b" / "tight.json").read_text())
    assert data["solved"] and data["margin"] == {"mu": 0.0, "cf": 0.0}
    # Its pushes keep less than the default margin's 10 % friction, each on its own.
    assert min(s["margin"]["mu"] for s in data["segments"] if s["kind"] == "push") < 0.1


def test_the_margin_reaches_the_plan_file_the_summary_and_verify(tmp_path, monkeypatch, capsys):
    """The plan file says the margin it was planned with and each push's own; the summary line the
    smallest; --verify each push's, and a file that claims a margin its pushes do not keep fails."""
    monkeypatch.chdir(tmp_path)
    corridor = str(ROOT / "scenes" / "corridor.yaml")
    assert main([corridor, "--out", "d", "--verify", "2"]) == 0
    out = capsys.readouterr().out.splitlines()
    data = json.loads((tmp_path / "d" / "corridor.json").read_text())
    assert data["margin"] == {"mu": 0.1, "cf": 0.02}
    pushes = [s for s in data["segments"] if s["kind"] == "push"]
    least = min(p["margin"]["mu"] for p in pushes), min(p["margin"]["cf"] for p in pushes)
    assert f"smallest margin friction -{least[0] * 100:.0f} %, CF {least[1] * 1e3:.2g} mm" in out[0]
    assert all("margin friction -" in line for line in out if ": push " in line)
    assert "(planned: friction -10 %" in out[-1] and out[-1].startswith("verify: passed")
    # The plan at the exact limit, relabelled as kept with the default margin.
    assert main([corridor, "--out", "e", "--margin", "0"]) == 0
    capsys.readouterr()
    exact = json.loads((tmp_path / "e" / "corridor.json").read_text())
    exact["margin"] = {"mu": 0.1, "cf": 0.02}
    (tmp_path / "claims.json").write_text(json.dumps(exact))
    assert main([corridor, "--plan", "claims.json", "--verify", "2", "--out", "f"]) == 3
    out = capsys.readouterr()
    assert "BELOW THE PLAN'S MARGIN" in out.out + out.err
    assert "below the plan's margin" in out.out + out.err


def test_margin_options_are_checked_and_reach_the_session():
    scene = load_scene(ROOT / "scenes" / "battery.yaml")
    assert Planner(scene).options.margin == Margin(0.1, 0.02)
    assert Planner(scene, {"margin": [0.2, 0.05]}).options.margin == Margin(0.2, 0.05)
    assert Planner(scene, {"margin": 0}).options.margin.exact
    for bad in (-0.1, float("nan"), [0.1, 1.0], {"mu": 1.0}, "big", [0.1]):
        with pytest.raises(SceneError) as err:
            Planner(scene, {"margin": bad})
        assert err.value.field == "margin"


def test_a_larger_margin_shrinks_the_regions_and_a_friction_interval_counts_from_its_middle():
    from planner.model.scene_file import parse_scene

    scene = load_scene(ROOT / "scenes" / "parking.yaml")
    areas = []
    for margin in (EXACT, Margin(), Margin(0.3, 0.05)):
        world = Planner(scene, {"margin": margin}).world
        areas.append(sum(c.region.section()[0].area for c in world.controls))
    assert areas[0] > areas[1] > areas[2] > 0
    spec = {"slider": {"vertices": [[0, 0], [0.1, 0], [0.1, 0.1], [0, 0.1]]},
            "pusher": {"width": 0.05, "depth": 0.01, "mu": [0.45, 0.55]},
            "workspace": {"min": [-1, -1], "max": [1, 1]}, "start": [0, 0, 0], "goal": [0.3, 0, 0]}
    interval = parse_scene(spec)
    # 10 % below the middle (0.5) is the interval's low end: the interval is the margin.
    assert certified_for(interval, Margin())[0] == pytest.approx(0.45)
    assert certified_for(interval, Margin(0.2, 0.0))[0] == pytest.approx(0.4)


def test_the_margin_survives_the_scene_and_plan_files(tmp_path):
    """--export-scene writes the margin the run used and reading it back gives the same; a plan
    file keeps the margin it was planned with (an older file without one has none)."""
    from planner.model.plan_file import load_plan, read_plan
    from planner.model.scene_file import load_scene as load, write_scene

    scene = load_scene(ROOT / "scenes" / "parts" / "swap.yaml")
    options = scene.options.merged({"margin": [0.25, 0.04]})
    write_scene(scene, tmp_path / "s.yaml", options)
    assert load(tmp_path / "s.yaml").options.margin == Margin(0.25, 0.04)
    plan = with_margins(scene, Planner(scene, options).plan())
    (tmp_path / "p.json").write_text(plan.to_json())
    again = load_plan(tmp_path / "p.json")
    assert again.margin == Margin(0.25, 0.04) and again.margins == ()  # certified again where shown
    older = plan.to_dict()
    del older["margin"]
    assert read_plan(older).margin is None
    older["margin"] = {"mu": 2}
    with pytest.raises(SceneError) as err:
        read_plan(older)
    assert err.value.field == "plan.margin"


def test_a_bad_margin_for_a_batch_names_the_flag(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    battery = str(ROOT / "scenes" / "battery.yaml")
    assert main([battery, battery, "--margin", "0.1", "-0.02", "--jobs", "1", "--out", "b"]) == 1
    captured = capsys.readouterr()
    assert captured.err.startswith("plan: error: --margin: cf must be a fraction in [0, 1)")
    assert captured.err.count("\n") == 1 and not (tmp_path / "b").exists()
