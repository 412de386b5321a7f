"""Dubins curves as chains of stable pushes (planner.actions.dubins): the pieces recovered from OMPL's
interpolation compose, by the test-only matrix exponential, to exactly the curve's end, with the
curve's length, as at most three pushes of the car's three motions."""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import yaml

from planner import load_scene, plan
from planner.actions.car import edge_car
from planner.actions.dubins import DubinsCurves
from planner.actions.controls import clearance_margin, edge_controls
from planner.world.validity import CollisionModel
from replay import advance, angle_diff, replay_plan

ROOT = Path(__file__).resolve().parents[3]


def test_curves_become_pushes_that_end_at_the_goal():
    scene = load_scene(ROOT / "scenes" / "parking.yaml")
    scene = replace(scene, obstacles=(), workspace=(-2.0, -2.0, 2.0, 2.0))
    push = edge_controls(scene)[0]
    car = edge_car(push, scene.slider.cf)
    curves = DubinsCurves(scene, car, CollisionModel(scene, [push.edge]), clearance_margin(scene))
    rng = np.random.default_rng(7)
    cf = scene.slider.cf
    for _ in range(25):
        start, goal = rng.uniform([-0.5, -0.5, -math.pi], [0.5, 0.5, math.pi], (2, 3))
        segments = curves.connect(start, goal)
        assert segments is not None and 1 <= len(segments) <= 3
        pose = start
        for s in segments:
            # Each push is one of the car's motions: the CF along the heading, turning at 0 or +-1/R.
            twist = np.asarray(s.twist)
            cf_velocity = twist[:2] + twist[2] * np.array([-cf[1], cf[0]])
            turn = twist[2] / np.linalg.norm(cf_velocity) * car.radius
            assert min(abs(turn), abs(abs(turn) - 1.0)) < 1e-9
            assert push.region.contains(twist)
            pose = advance(pose, s.twist, s.duration)
        assert np.allclose(pose[:2], goal[:2], atol=1e-8) and angle_diff(pose[2], goal[2]) < 1e-8
        curves.states(car.state(start), car.state(goal))
        assert sum(s.cf_path_length(cf) for s in segments) == pytest.approx(curves.length(), abs=1e-9)


@pytest.mark.parametrize("goal", [[-0.3005, -0.1437, 0.2602], [-0.1349, 0.4372, -0.5847]])
def test_a_shortened_plan_changes_edge_only_by_a_transit(goal):
    """Parking goals whose one-edge plans the shortcut once rebuilt with a first part on another
    edge's car and the rest on the old edge, the pusher jumping between edges unseen. The plan
    must replay: every push on the edge the pusher is on, a transit between edges."""
    scene = load_scene(ROOT / "scenes" / "parking.yaml")
    found = plan(scene.with_part(goal=goal), seed=1, time_limit=10.0)
    assert found.solved
    replay_plan(yaml.safe_load((ROOT / "scenes" / "parking.yaml").read_text()), found.to_dict(), goal)
