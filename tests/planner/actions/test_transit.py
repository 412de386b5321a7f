"""Transits (planner.actions.transit): the pusher's way from one edge to another, checked with shapely.

The checks place the pusher's rectangle from the README's definition of the pusher frame and
measure distances with shapely on densely interpolated poses; they share no geometry code with
the transit planner (which uses fcl and its own offset curve).
"""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
import shapely

from planner import parse_scene
from planner.actions.transit import ARC_STEP, TransitPlanner
from planner.world.validity import CollisionModel

RECT = [[-0.05, -0.03], [0.05, -0.03], [0.05, 0.03], [-0.05, 0.03]]
L_SHAPE = [[0.0, 0.0], [0.09, 0.0], [0.09, 0.035], [0.035, 0.035], [0.035, 0.09], [0.0, 0.09]]
WIDTH, DEPTH = 0.04, 0.02


def scene(vertices, obstacles=(), transit="plane", start=(0.0, 0.0, 0.3)):
    return parse_scene({
        "slider": {"vertices": vertices},
        "pusher": {"width": WIDTH, "depth": DEPTH, "mu": 0.6, "transit": transit},
        "obstacles": [{"box": {"center": list(c), "size": list(s)}} for c, s in obstacles],
        "workspace": {"min": [-0.5, -0.5], "max": [0.5, 0.5]},
        "start": [*start[:2], math.degrees(start[2])], "goal": [0.3, 0.3, 0.0]})


def planner_for(sc) -> TransitPlanner:
    edges = sc.edges
    return TransitPlanner(sc, edges, CollisionModel(sc, edges), sc.slider.radius / 40, sc.options.transit)


def pusher_at(pose) -> shapely.Polygon:
    x, y, th = pose
    c, s = math.cos(th), math.sin(th)
    local = [(-DEPTH, -WIDTH / 2), (0, -WIDTH / 2), (0, WIDTH / 2), (-DEPTH, WIDTH / 2)]
    return shapely.Polygon([(x + c * px - s * py, y + s * px + c * py) for px, py in local])


def part_at(vertices, pose) -> shapely.Polygon:
    x, y, th = pose
    c, s = math.cos(th), math.sin(th)
    return shapely.Polygon([(x + c * px - s * py, y + s * px + c * py) for px, py in vertices])


def flush_pose(vertices, edge, part_pose) -> np.ndarray:
    """Contact pose on ``edge``: face centre at its midpoint, x along the inward normal (world)."""
    v = np.asarray(vertices, float)
    a, b = v[edge], v[(edge + 1) % len(v)]
    d = (b - a) / np.linalg.norm(b - a)
    inward = np.array([-d[1], d[0]])
    if not shapely.Polygon(v).contains(shapely.Point((a + b) / 2 + 1e-6 * inward)):
        inward = -inward
    x, y, th = part_pose
    c, s = math.cos(th), math.sin(th)
    mid = (a + b) / 2
    world = np.array([x + c * mid[0] - s * mid[1], y + s * mid[0] + c * mid[1]])
    n = np.array([c * inward[0] - s * inward[1], s * inward[0] + c * inward[1]])
    return np.array([*world, math.atan2(n[1], n[0])])


def samples(path, step=0.0005, turn=math.radians(0.5)):
    """Poses along ``path`` by linear interpolation, theta the shorter way; (piece, pose) pairs."""
    for k, (p, q) in enumerate(zip(path, path[1:])):
        dth = (q[2] - p[2] + math.pi) % (2 * math.pi) - math.pi
        n = max(2, math.ceil(math.hypot(q[0] - p[0], q[1] - p[1]) / step), math.ceil(abs(dth) / turn)) + 1
        for t in np.linspace(0, 1, n):
            yield k, np.array([p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1]), p[2] + t * dth])


def angle(a, b) -> float:
    return abs((a - b + math.pi) % (2 * math.pi) - math.pi)


@pytest.mark.parametrize("vertices", [RECT, L_SHAPE], ids=["rectangle", "L-shape"])
def test_walks_round_the_part_between_every_pair_of_edges(vertices):
    sc = scene(vertices)
    tp = planner_for(sc)
    part = part_at(vertices, sc.start)
    for a, b in itertools.permutations(sc.edges, 2):
        t = tp.find(sc.start, a, b)
        assert t is not None and t.mode == "plane" and (t.from_edge, t.to_edge) == (a, b)
        path = t.pusher_path
        for end, edge in ((path[0], a), (path[-1], b)):
            flush = flush_pose(vertices, edge, sc.start)
            assert np.allclose(end[:2], flush[:2], atol=1e-12) and angle(end[2], flush[2]) < 1e-12
        assert all(angle(p[2], q[2]) <= ARC_STEP + 1e-12 for p, q in zip(path, path[1:]))
        poses = list(samples(path))
        for i, (_, pose) in enumerate(poses):
            gap = pusher_at(pose).distance(part)
            if i in (0, len(poses) - 1):
                assert gap < 1e-12, "the contact poses touch the part"
            else:
                assert gap > 0 or np.allclose(pose, path[0]) or np.allclose(pose, path[-1]), (a, b, pose)
        # Away from the two straight moves in and out, the face stays the standoff off the part.
        inner = [pose for k, pose in poses if 0 < k < len(path) - 2]
        assert min(pusher_at(p).distance(part) for p in inner) >= tp.standoff * math.cos(ARC_STEP) - 1e-12


def test_takes_the_shorter_way_round_and_the_other_when_blocked():
    # Edge 0 faces -y, edge 1 +x, edge 2 +y. From 0 to 1 the short way is past the corner between.
    sc = scene(RECT, start=(0.0, 0.0, 0.0))
    quarter = planner_for(sc).find(sc.start, 0, 1)
    assert min(p[0] for p in quarter.pusher_path) > -0.05 and max(p[1] for p in quarter.pusher_path) < 0.03
    # From 0 to 2 a wall 3 cm east of the part leaves only the west way.
    blocked = scene(RECT, obstacles=[((0.09, 0.0), (0.02, 0.3))], start=(0.0, 0.0, 0.0))
    detour = planner_for(blocked).find(blocked.start, 0, 2)
    assert max(p[0] for p in detour.pusher_path) <= 0.02 and min(p[0] for p in detour.pusher_path) < -0.05
    wall = shapely.box(0.08, -0.15, 0.1, 0.15)
    assert all(pusher_at(p).distance(wall) > 0 for _, p in samples(detour.pusher_path))


def test_boxed_in_part_has_no_walk_but_a_lift():
    # Walls 1.5 cm from the long sides: the 2 cm deep pusher cannot pass between them and the part.
    walls = [((0.0, 0.0475), (0.3, 0.005)), ((0.0, -0.0475), (0.3, 0.005))]
    plane = scene(RECT, obstacles=walls, start=(0.0, 0.0, 0.0))
    assert planner_for(plane).find(plane.start, 1, 3) is None
    lift = scene(RECT, obstacles=walls, transit="lift", start=(0.0, 0.0, 0.0))
    t = planner_for(lift).find(lift.start, 1, 3)
    assert t is not None and t.mode == "lift" and len(t.pusher_path) == 4
    part = part_at(RECT, lift.start)
    blocked = shapely.union_all([shapely.box(-0.15, 0.045, 0.15, 0.05), shapely.box(-0.15, -0.05, 0.15, -0.045)])
    for k, pose in samples(t.pusher_path):
        if k != 1:  # the airborne piece is not on the table
            assert pusher_at(pose).distance(blocked) > 0
    # Retreat and approach: straight back off the face, x unchanged in direction.
    assert angle(t.pusher_path[0][2], t.pusher_path[1][2]) < 1e-12
    assert angle(t.pusher_path[2][2], t.pusher_path[3][2]) < 1e-12
    assert pusher_at(t.pusher_path[1]).distance(part) == pytest.approx(planner_for(lift).standoff)


def test_a_thin_wall_across_the_way_is_not_skipped():
    # A 0.1 mm wall 5 mm off the part's corner, outwards, cuts the walk round the east side.
    sc = scene(RECT, obstacles=[((0.08, 0.03), (0.05, 0.0001))], start=(0.0, 0.0, 0.0))
    t = planner_for(sc).find(sc.start, 0, 2)
    wall = shapely.box(0.055, 0.02995, 0.105, 0.03005)
    assert t is not None and min(p[0] for p in t.pusher_path) < -0.05, "went round the free side"
    assert all(pusher_at(p).distance(wall) > 0 for _, p in samples(t.pusher_path))


def test_duration_bounds_every_point_speed():
    sc = scene(L_SHAPE)
    t = planner_for(sc).find(sc.start, 0, 5)
    reach = math.hypot(DEPTH, WIDTH / 2)
    corners = np.array([(-DEPTH, -WIDTH / 2), (0, -WIDTH / 2), (0, WIDTH / 2), (-DEPTH, WIDTH / 2)])
    travelled = 0.0
    path = t.pusher_path
    for p, q in zip(path, path[1:]):
        dth = (q[2] - p[2] + math.pi) % (2 * math.pi) - math.pi
        # Farthest a corner travels over the piece (sampled finely) is within its share of time.
        ts = np.linspace(0, 1, 200)
        travel = max(np.sum(np.hypot(*np.diff(np.array(
            [[p[0] + t * (q[0] - p[0]) + math.cos(p[2] + t * dth) * cx - math.sin(p[2] + t * dth) * cy,
              p[1] + t * (q[1] - p[1]) + math.sin(p[2] + t * dth) * cx + math.cos(p[2] + t * dth) * cy]
             for t in ts]), axis=0).T)) for cx, cy in corners)
        share = math.hypot(q[0] - p[0], q[1] - p[1]) + reach * abs(dth)
        assert travel <= share + 1e-12
        travelled += share
    assert t.duration == pytest.approx(travelled, abs=1e-12)
