"""One-step planning (Lynch 1992, §5.1) on the 9 V battery scene: the paper's Goal1 and Goal3."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from oracle import Reference
from planner import load_scene, one_step, plan
from replay import advance, angle_diff

BATTERY = Path(__file__).resolve().parents[3] / "scenes" / "battery.yaml"


def test_goal1_is_one_stable_push_away():
    scene = load_scene(BATTERY)
    answer = one_step(scene)
    assert answer.reachable and answer.edge == 3, answer.reason
    seg = answer.segment
    # The twist is COR_total: rotating about (0, 0.09) (slider frame), CCW, as the scene was built.
    cor = np.array([-seg.twist[1], seg.twist[0]]) / seg.twist[2]
    np.testing.assert_allclose(cor, [0.0, 0.09], atol=2e-4)
    v = scene.slider.vertices
    ref = Reference(v, scene.slider.cf, 3, 1.0, width=0.04, tip_factor=1.02)
    slack, band = ref.twist_margin(seg.twist)
    assert slack[0] > band[0]
    end = advance(scene.start, seg.twist, seg.duration)
    np.testing.assert_allclose(end[:2], scene.goal[:2], atol=1e-9)
    assert angle_diff(end[2], scene.goal[2]) < 1e-9


def test_goal3_backwards_is_impossible():
    # Pulling the battery back (or sideways) is not a push: no stable COR gives it.
    scene = load_scene(BATTERY)
    for goal in ([-0.05, 0.0, 0.0], [0.0, 0.06, 0.0], [0.02, 0.0, math.radians(120)]):
        answer = one_step(scene, goal=goal)
        assert not answer.reachable and answer.segment is None
        assert "edge 3: COR_total is not a stable push" in answer.reason


def test_blocked_push_is_refused_and_straight_push_is_fine():
    scene = load_scene(BATTERY)
    # Straight ahead along the terminals' axis: a translation through the CF, stable.
    ahead = one_step(scene, goal=[0.08, 0.0, 0.0])
    assert ahead.reachable and np.allclose(ahead.twist[1:], 0.0)
    # Into the obstacle at (0.10, -0.06): same kind of push, but it collides.
    blocked = one_step(scene, start=[0.02, -0.06, 0.0], goal=[0.14, -0.06, 0.0])
    assert not blocked.reachable and "collides" in blocked.reason


def test_plan_uses_the_one_step_push():
    scene = load_scene(BATTERY)
    result = plan(scene, seed=1)
    assert result.solved and result.pushes == 1 and len(result.tree) == 0
    np.testing.assert_allclose(result.final[:2], scene.goal[:2], atol=1e-9)
