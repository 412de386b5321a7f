"""The best-known plans (scenes/best/<scene>.json): one per shipped scene, each the cheapest plan
ever found for it (planner.bench.optimality --record raises them), and each a sound plan.

They are the reference the benchmark's ratios are taken to, so each is checked as any plan is:
read back with its cost and length consistent with its segments, replayed by the test-only replay
(tests/replay.py: collisions by shapely, stability by the oracle's linear programme, transits
from the README's definitions; it shares nothing with the planner), and re-simulated by the
quasi-static verifier under support distributions.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml

from planner import load_plan, load_scene, verify
from planner.queries.geodesic import geodesic_bound
from replay import replay_plan

ROOT = Path(__file__).resolve().parents[3]
SCENES = sorted((ROOT / "scenes").glob("*.yaml"))


@pytest.mark.parametrize("path", SCENES, ids=lambda p: p.stem)
def test_each_best_known_plan_is_sound_and_costs_what_it_says(path):
    scene = load_scene(path)
    best = load_plan(ROOT / "scenes" / "best" / f"{scene.name}.json")
    assert best.solved and best.scene == f"scenes/{path.name}"
    assert np.allclose(best.cf, scene.slider.cf) and best.switch_cost == scene.options.switch_cost
    assert np.allclose(best.start, scene.start) and scene.within_tolerance(best.final)
    length = sum(s.cf_path_length(scene.slider.cf) for s in best.segments)
    assert best.cost == pytest.approx(length + scene.options.switch_cost * best.switches, abs=1e-12)
    assert best.length >= geodesic_bound(scene) - 1e-9  # no plan beats the lower bound
    replay_plan(yaml.safe_load(path.read_text()), best.to_dict())
    check = verify(scene, best, n=6, transit=scene.options.transit)
    assert check.passed, check.summary()
