"""Path quality on an empty table (issue 11): plans within 1.10x of the Dubins length of the
part's best edge car, every push still stable by the independent LP oracle and Theorem 4, and the
lower bound never above a plan."""

from __future__ import annotations

from pathlib import Path

import pytest

from oracle import guaranteed_stable
from planner import load_scene, plan
from planner.quality import TASKS, dubins_length, lower_bound, open_task

ROOT = Path(__file__).resolve().parent.parent


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
    assert lower_bound(scene) <= length + 1e-9
    assert length <= 1.10 * dubins_length(scene) + 1e-9, (length, dubins_length(scene))
    assert all(stable_by_oracle(scene, s) for s in result.segments if s.kind == "push")
