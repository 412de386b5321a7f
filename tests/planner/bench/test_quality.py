"""Path quality on an empty table (issue 11): plans within 1.10x of the Dubins length of the
part's best edge car, every push still stable by the independent LP oracle and Theorem 4, and the
lower bound never above a plan; improvement rounds."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from oracle import guaranteed_stable
from planner import load_scene, plan
from planner.queries.geodesic import geodesic_bound
from planner.bench.quality import TASKS, dubins_length, open_task
from replay import replay_plan

ROOT = Path(__file__).resolve().parents[3]


def stable_by_oracle(scene, segment) -> bool:
    return guaranteed_stable(scene.slider.vertices, scene.slider.cf, segment.edge, scene.pusher.mu,
                             scene.pusher.width, segment.twist)


@pytest.mark.parametrize("part", ["battery", "parking", "nonconvex"])
@pytest.mark.parametrize("task", list(TASKS))
def test_open_table_plans_are_near_dubins_and_stable(part, task):
    scene = open_task(load_scene(ROOT / "scenes" / f"{part}.yaml"), task)
    result = plan(scene, seed=1, time_limit=10)
    assert result.solved
    length = result.path_length(scene.slider.cf)
    assert geodesic_bound(scene) <= length + 1e-9
    assert length <= 1.10 * dubins_length(scene) + 1e-9, (length, dubins_length(scene))
    assert all(stable_by_oracle(scene, s) for s in result.segments if s.kind == "push")


def test_improvement_rounds_only_shorten_and_repeat():
    """Corridor, seed 1: two improvement rounds (a search, then the plan on a finer grid) find a
    cheaper plan. The improved plan costs no more than the first, whose cost and length (and each
    better plan's) its improvements report, in the order found; it is the same plan on a second
    run with the seed, and replays independently."""
    path = ROOT / "scenes" / "corridor.yaml"
    scene = load_scene(path)
    first = plan(scene, seed=1, time_limit=30)
    better = plan(scene, seed=1, time_limit=30, optimize=2)
    again = plan(scene, seed=1, time_limit=30, optimize=2)
    cost = [p.path_length(scene.slider.cf) + scene.options.switch_cost * p.switches for p in (first, better)]
    assert better.improvements[0][1:] == pytest.approx((cost[0], first.path_length(scene.slider.cf)), abs=1e-12)
    assert better.improvements[-1][1:] == pytest.approx((cost[1], better.path_length(scene.slider.cf)), abs=1e-12)
    assert len(better.improvements) >= 2 and cost[1] < cost[0]
    times, costs, _ = zip(*better.improvements)
    assert list(times) == sorted(times) and all(b < a for a, b in zip(costs, costs[1:]))
    assert better.cost == pytest.approx(cost[1], abs=1e-12) and better.length == pytest.approx(cost[1], abs=1e-12)
    drop = {"planning_time_s": 0, "improvements": 0}
    assert again.to_dict() | drop == better.to_dict() | drop
    replay_plan(yaml.safe_load(path.read_text()), better.to_dict())
