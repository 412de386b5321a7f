"""The collision rule never skips a thin obstacle, in one push or in a planned path."""

from __future__ import annotations

import math
import time

import numpy as np
import shapely

from planner import parse_scene, plan
from planner.actions.controls import clearance_margin, edge_controls, step_length
from planner.world.validity import CollisionModel, pose_along
from replay import advance, angle_diff, place, pusher_body

BLOCK = [[-0.04, -0.025], [0.04, -0.025], [0.04, 0.025], [-0.04, 0.025]]
WALL = 0.0005  # 0.5 mm thick: a tenth of the search step


def scene(obstacles, start=(-0.2, 0.0, 0.0), goal=(0.2, 0.0, 0.0), **extra):
    return parse_scene({
        "slider": {"vertices": BLOCK},
        "pusher": {"width": 0.05, "depth": 0.015, "mu": 0.5, "edges": [3]},
        "obstacles": obstacles,
        "workspace": {"min": [-0.5, -0.5], "max": [0.5, 0.5]},
        "start": list(start), "goal": list(goal), **extra})


THIN = [{"box": {"center": [0.0, 0.0], "size": [WALL, 0.3]}}]


def test_wall_is_much_thinner_than_the_search_step():
    s = scene(THIN)
    assert s.obstacles[0].bounds[2] - s.obstacles[0].bounds[0] < step_length(s) / 5


def test_push_through_thin_wall_is_rejected():
    s = scene(THIN)
    push = edge_controls(s)[0]
    model = CollisionModel(s, [push.edge])
    straight = np.array([1.0, 0.0, 0.0]) / push.speed([1.0, 0.0, 0.0])
    assert not model.push_is_free(s.start, straight, 0.4, push.edge, clearance_margin(s))
    # The same push with the wall moved out of the way is free.
    clear = scene([{"box": {"center": [0.0, 0.3], "size": [WALL, 0.1]}}])
    model = CollisionModel(clear, [push.edge])
    assert model.push_is_free(clear.start, straight, 0.4, push.edge, clearance_margin(clear))


def test_clearance_is_distance_to_nearest_obstacle_or_wall():
    s = scene([{"box": {"center": [0.0, 0.0], "size": [0.02, 0.02]}}])
    model = CollisionModel(s, [3])
    # Body at x = -0.2: slider spans x in [-0.24, -0.16], the pusher 1.5 cm behind its -x face.
    assert math.isclose(model.clearance((-0.2, 0.0, 0.0), 3), 0.16 - 0.01, rel_tol=1e-9)
    # Near the workspace wall: the pusher's back is at x = -0.455 -> 0.045 from x = -0.5.
    assert math.isclose(model.clearance((-0.4, 0.2, 0.0), 3), 0.045, rel_tol=1e-9)
    assert model.clearance((0.0, 0.0, 0.0), 3) <= 0


def test_planned_path_goes_around_a_thin_wall():
    # The goal is straight ahead, one push away but for the wall, which leaves gaps above/below.
    s = scene([{"box": {"center": [0.0, 0.0], "size": [WALL, 0.3]}}], goal=(0.25, 0.05, 0.0))
    result = plan(s, seed=1)
    assert result.solved, result.reason
    wall = s.obstacles[0]
    body = [np.array(BLOCK), pusher_body(BLOCK, 3, 0.05, 0.015)]
    for seg in result.segments:
        n = max(2, math.ceil(seg.duration / 0.0002))
        for t in np.linspace(0.0, seg.duration, n):  # points move <= 0.2 mm between samples
            q = advance(seg.start, seg.twist, t)
            assert not any(place(b, q).intersects(wall) for b in body), f"crossed the wall at {q}"


def test_clearance_matches_shapely_distance_on_random_poses():
    # Non-convex part, a polygon and a rotated box: fcl's distances must be exact (they bound
    # how far the body may move), so compare with shapely's, computed independently.
    ell = [[0.0, 0.0], [0.09, 0.0], [0.09, 0.035], [0.035, 0.035], [0.035, 0.09], [0.0, 0.09]]
    s = parse_scene({
        "slider": {"vertices": ell},
        "pusher": {"width": 0.05, "depth": 0.015, "mu": 0.5},
        "obstacles": [{"box": {"center": [0.1, 0.1], "size": [0.1, 0.04], "angle": 30}},
                      {"polygon": [[-0.2, -0.1], [-0.1, -0.15], [-0.05, 0.0], [-0.15, -0.02]]}],
        "workspace": {"min": [-0.4, -0.4], "max": [0.4, 0.4]},
        "start": [0.2, -0.2, 0.0], "goal": [-0.2, 0.2, 0.0]})
    walls = shapely.box(-1, -1, 1, 1).difference(shapely.box(-0.4, -0.4, 0.4, 0.4))
    blocked = shapely.union_all([*s.obstacles, walls])
    rng = np.random.default_rng(7)
    model = CollisionModel(s, s.edges)
    checked = 0
    for _ in range(300):
        q = (*rng.uniform(-0.35, 0.35, 2), rng.uniform(-math.pi, math.pi))
        edge = int(rng.choice(s.edges))
        body = shapely.union_all([place(ell, q), place(pusher_body(ell, edge, 0.05, 0.015), q)])
        expected = body.distance(blocked)
        got = model.clearance(q, edge)
        if expected > 0:
            assert math.isclose(got, expected, rel_tol=1e-7, abs_tol=1e-9), (q, edge)
            checked += 1
        else:
            assert got <= 1e-12, (q, edge)
    assert checked > 100


def test_pose_along_follows_the_matrix_exponential():
    """The rotation-about-the-COR form matches the replay's matrix exponential for turns, slow
    turns near the translation threshold and pure translations."""
    rng = np.random.default_rng(5)
    for omega in [*rng.uniform(-20, 20, 20), 1e-6, -3e-8, 1.9e-8, 0.0]:
        pose = np.r_[rng.uniform(-1, 1, 2), rng.uniform(-np.pi, np.pi)]
        twist = np.r_[rng.uniform(-1, 1, 2), omega]
        at = pose_along(pose, twist)
        for t in (0.0, 0.3, 2.0):
            got, want = at(t), advance(pose, twist, t)
            np.testing.assert_allclose(got[:2], want[:2], rtol=0, atol=1e-8 * (1 + t * t))
            assert angle_diff(got[2], want[2]) < 1e-9


def test_clear_tests_at_one_pose_agree_whatever_their_thresholds_and_order():
    """The part's clearance at a pose is found once and read by every edge's test there (the body
    is the part and the pusher: its clearance the least of theirs); a test that asked for less
    (a lower bound above its threshold) is not taken for an exact value by a later one."""
    s = parse_scene({"slider": {"vertices": BLOCK}, "pusher": {"width": 0.05, "depth": 0.015, "mu": 0.5},
                     "obstacles": [{"box": {"center": [0.0, 0.0], "size": [0.02, 0.3]}}],
                     "workspace": {"min": [-0.5, -0.5], "max": [0.5, 0.5]},
                     "start": [-0.2, 0.0, 0.0], "goal": [0.2, 0.0, 0.0]})
    rng = np.random.default_rng(3)
    shared = CollisionModel(s, s.edges)
    for _ in range(200):
        q = (*rng.uniform(-0.4, 0.4, 2), rng.uniform(-math.pi, math.pi))
        for e in rng.permutation(s.edges).tolist():
            distance = float(rng.choice([0.0, 0.001, 0.05, 0.3, math.inf]))
            exact = CollisionModel(s, s.edges).clearance(q, e)  # a fresh model: nothing remembered
            assert shared.is_clear(q, e, distance) == (exact > distance)
            if rng.random() < 0.3:
                assert shared.clearance(q, e) == exact


def test_every_edge_of_a_part_of_five_thousand_edges_is_checked_at_a_pose_in_seconds():
    """A circle of 5,000 edges: its outline is shared by the edges' bodies (each held all of it
    before, 5,000 copies of 5,000 points) and its clearance found once for all at a pose, so the
    start's test on every edge takes seconds. Independently, by shapely: the clearance of the part
    with the pusher on a sample of edges."""
    n = 5_000
    t = 2 * np.pi * np.arange(n) / n
    circle = (np.c_[np.cos(t), np.sin(t)] * 0.05).tolist()
    s = parse_scene({"slider": {"vertices": circle}, "pusher": {"width": 0.03, "depth": 0.01, "mu": 0.5},
                     "obstacles": [{"box": {"center": [0.0, 0.0], "size": [0.02, 0.3]}}],
                     "workspace": {"min": [-0.5, -0.5], "max": [0.5, 0.5]},
                     "start": [-0.2, 0.0, 0.0], "goal": [0.2, 0.0, 0.0]})
    q = (-0.065, 0.02, 0.3)  # 5 mm from the wall: the pushers facing it hit it
    began = time.perf_counter()
    model = CollisionModel(s, s.edges)
    clear = [model.is_clear(q, e, 0.002) for e in s.edges]
    assert time.perf_counter() - began < 60.0
    walls = shapely.box(-1, -1, 1, 1).difference(shapely.box(-0.5, -0.5, 0.5, 0.5))
    blocked = shapely.union_all([*s.obstacles, walls])
    for e in range(0, n, 97):
        body = shapely.union_all([place(circle, q), place(pusher_body(circle, e, 0.03, 0.01), q)])
        expected, got = body.distance(blocked), model.clearance(q, e)
        assert math.isclose(got, expected, rel_tol=1e-7, abs_tol=1e-9) if expected > 0 else got <= 1e-12, e
        assert clear[e] == (expected > 0.002)
    assert 0 < sum(clear) < n  # the pushers facing the wall are too near it, the others not
