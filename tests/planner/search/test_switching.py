"""Plans that switch the pushed edge (planner.search.planning with planner.actions.transit): when they switch,
what a switch costs, and the options that forbid it.

The transits' geometry is checked independently in tests/planner/queries/test_plans.py (replay of every shipped
plan) and tests/planner/actions/test_transit.py; here the planner's choices are.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from planner import SceneError, load_scene, plan

ROOT = Path(__file__).resolve().parents[3]
SCENES = ROOT / "scenes"


def cost(result, scene, switch_cost: float) -> float:
    return result.path_length(scene.slider.cf) + switch_cost * result.switches


def test_junctions_need_a_switch_and_get_one():
    for name, mode in (("junction", "plane"), ("narrow_junction", "lift")):
        scene = load_scene(SCENES / f"{name}.yaml")
        result = plan(scene, seed=1)
        assert result.solved and result.switches >= 1
        assert {s.mode for s in result.segments if s.kind == "transit"} == {mode}
        # One edge cannot: the corridors are too narrow to turn the part round (the benchmark's
        # --transit none runs show 0 of 20 in 30 s; here a short look).
        assert not plan(scene, seed=1, time_limit=2.0, transit="none").solved


def test_narrow_junction_has_no_walk_round():
    scene = load_scene(SCENES / "narrow_junction.yaml")
    assert not plan(scene, seed=1, time_limit=2.0, transit="plane").solved


def test_switch_cost_trades_length_for_switches():
    scene = load_scene(SCENES / "parking.yaml")
    differed = 0
    for seed in range(5, 9):  # seed 7 differs
        free, dear = plan(scene, seed=seed, switch_cost=0.0), plan(scene, seed=seed, switch_cost=10.0)
        assert free.solved and dear.solved
        # The switch cost reshapes the whole search, so plans without a switch can differ too
        # (seed 6 since issue 33's regions); the trade shows where the switches differ.
        if free.switches != dear.switches:
            differed += 1
            # A dear switch is avoided when one edge does it; a free one is kept if it is shorter.
            assert dear.switches < free.switches
            assert cost(dear, scene, 10.0) <= cost(free, scene, 10.0)
            assert free.path_length(scene.slider.cf) <= dear.path_length(scene.slider.cf)
    assert differed, "no seed where the switch cost changed the switches: the test shows nothing"


def test_one_edge_options_never_switch():
    scene = load_scene(SCENES / "parking.yaml")
    assert all(plan(scene, seed=seed, transit="none").switches == 0 for seed in (1, 2, 5))
    single = scene.with_part(edges=(1,))  # the one edge that parks it
    result = plan(single, seed=1)
    assert result.solved and result.switches == 0


@pytest.mark.parametrize("option, value", [("transit", "teleport"), ("switch_cost", -1.0), ("switch_cost", "x")])
def test_bad_options_name_themselves(option, value):
    with pytest.raises(SceneError) as err:
        plan(load_scene(SCENES / "battery.yaml"), **{option: value})
    assert err.value.field == option


def test_the_cheapest_direct_connection_wins():
    # The CF 0.3 m straight behind, on an empty table: edge 0 finds a two-push way round through a
    # waypoint, but edge 1 (the right face, pushing -x) does it in one straight push of 0.3 m.
    scene = load_scene(SCENES / "parking.yaml")
    start = np.array([0.0, 0.0, 0.0])
    open_table = replace(scene.with_part(start=start, goal=start + [-0.3, 0.0, 0.0]), obstacles=(),
                         workspace=(-2.0, -2.0, 2.0, 2.0))
    result = plan(open_table, seed=1)
    assert result.solved and result.pushes == 1 and result.segments[0].edge == 1
    assert result.path_length(scene.slider.cf) == pytest.approx(0.3, abs=1e-9)
