"""The free-space geodesic of the centre of friction (issue 11): hand-derived lengths (straight
line, taut strings round grown corners by tangents and arcs), a walled-off goal, how it moves with
the scene, and no shipped scene's plan shorter than it."""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import shapely

from mechanics import Slider
from planner import Scene, load_scene, parse_scene, plan
from planner.queries.geodesic import geodesic_bound
from planner.world.free_space import QUAD_SEGS

ROOT = Path(__file__).resolve().parents[3]
SCENES = sorted((ROOT / "scenes").glob("*.yaml"))  # not scenes/unreachable/: nothing to plan there
#: A 0.1 m square part, its CF at its centre: 0.05 m from its boundary, and 0 from the origin.
SQUARE = {"vertices": [[-0.05, -0.05], [0.05, -0.05], [0.05, 0.05], [-0.05, 0.05]]}
PUSHER = {"width": 0.05, "depth": 0.01, "mu": 0.5}
TABLE = {"min": [-0.5, -0.5], "max": [0.5, 0.5]}


def cf_at(scene: Scene, pose) -> np.ndarray:
    c, s = math.cos(pose[2]), math.sin(pose[2])
    x, y = scene.slider.cf
    return np.array([pose[0] + c * x - s * y, pose[1] + s * x + c * y])


def taut_string(p, centres, q, r: float) -> float:
    """Length of the path from ``p`` to ``q`` turning clockwise round circles of radius ``r`` about
    ``centres`` (in order), hugging each: a tangent in, arcs joined by the circles' common
    tangents (parallel to the line of their centres, as long), and a tangent out. The arcs add
    ``r`` times the heading turned through, from the tangent in to the tangent out."""
    p, q, c = np.asarray(p, float), np.asarray(q, float), np.asarray(centres, float)
    into, out = c[0] - p, q - c[-1]
    d_in, d_out = np.hypot(*into), np.hypot(*out)
    # A tangent leaves the line to the centre by asin(r / d), turned so the circle is on the right.
    heading_in = math.atan2(into[1], into[0]) + math.asin(r / d_in)
    heading_out = math.atan2(out[1], out[0]) - math.asin(r / d_out)
    between = float(np.sum(np.hypot(*np.diff(c, axis=0).T)))
    return math.sqrt(d_in**2 - r**2) + between + math.sqrt(d_out**2 - r**2) + r * (heading_in - heading_out)


def scene_of(obstacles: list, start: list, goal: list, slider: dict = SQUARE,
             tolerance: dict | None = None) -> Scene:
    spec = {"slider": slider, "pusher": PUSHER, "obstacles": obstacles, "workspace": TABLE,
            "start": start, "goal": goal}
    return parse_scene(spec | ({"tolerance": tolerance} if tolerance else {}))


def test_empty_table_is_the_straight_line_less_the_tolerance():
    # CF 0.02 m from the part's edges and |cf| = sqrt(0.0013) from its origin.
    part = {"vertices": [[0, 0], [0.1, 0], [0.1, 0.1], [0, 0.1]], "cf": [0.02, 0.03]}
    scene = scene_of([], [0.0, 0.0, 0.0], [0.3, 0.2, 90.0], part, {"position": 0.01, "angle": 2.0})
    # Turned 90 degrees, the CF (0.02, 0.03) sits at (-0.03, 0.02) from the goal's origin.
    start, goal = np.array([0.02, 0.03]), np.array([0.27, 0.22])
    slack = 0.01 + math.sqrt(0.0013) * math.radians(2.0)
    bound = geodesic_bound(scene)
    assert bound == pytest.approx(math.hypot(*(goal - start)) - slack, abs=1e-12)
    # No pose the goal test accepts (origin within 0.01, heading within 2 degrees) puts the CF
    # nearer the start than the bound: the slack is enough.
    for angle in np.radians(np.linspace(-2.0, 2.0, 9)):
        for direction in np.linspace(0.0, 2 * math.pi, 36, endpoint=False):
            pose = [0.3 + 0.01 * math.cos(direction), 0.2 + 0.01 * math.sin(direction), math.pi / 2 + angle]
            assert np.hypot(*(cf_at(scene, pose) - start)) >= bound
    assert geodesic_bound(scene.with_part(goal=[0.005, 0.0, 0.0])) == 0.0  # already within tolerance


def test_box_between_start_and_goal_goes_over_its_grown_top():
    # A 0.2 m box in the middle, grown by 0.05: flat sides at +-0.15, corners rounded about
    # (+-0.1, +-0.1). From (-0.35, 0.05) to (0.35, 0.05), above the centre, the path goes over the
    # top: tangents of length sqrt(0.25^2 + 0.05^2 - 0.05^2) = 0.25, arcs of 2 asin(0.05 / 0.255)
    # = 22.6 degrees each, and the flat top, 0.2 m.
    scene = scene_of([{"box": {"center": [0.0, 0.0], "size": [0.2, 0.2]}}], [-0.35, 0.05, 0.0], [0.35, 0.05, 0.0])
    p, q, corners = (-0.35, 0.05), (0.35, 0.05), [(-0.1, 0.1), (0.1, 0.1)]
    true = taut_string(p, corners, q, 0.05)
    assert true == pytest.approx(0.7 + 0.1 * 2 * math.asin(0.05 / math.sqrt(0.065)))
    # The polygons of the round corners lie between circles of radius r cos(pi / (4 QUAD_SEGS))
    # (their chords' distance from the centre) and r, so the path does too (0.3 mm apart); the
    # bound is it less the position tolerance.
    inner = taut_string(p, corners, q, 0.05 * math.cos(math.pi / (4 * QUAD_SEGS)))
    assert inner - 0.01 <= geodesic_bound(scene) <= true - 0.01
    assert geodesic_bound(scene) > 0.7 - 0.01 + 0.03  # well above the straight line less the slack


def test_corridor_goes_round_the_inside_corner():
    # The inside of the L is the box x <= 0.25, y >= -0.25; the part's CF is 0.025 m from its long
    # sides, so the CF's path hugs a circle of radius 0.025 about the corner (0.25, -0.25). Backwards
    # (goal to start) it turns clockwise round it.
    scene = load_scene(ROOT / "scenes" / "corridor.yaml")
    start, goal = cf_at(scene, scene.start), cf_at(scene, scene.goal)
    true = taut_string(goal, [(0.25, -0.25)], start, 0.025)
    # The start and goal are mirror images across the corner's diagonal, each 0.65 m along and
    # 0.125 m across from it: the path turns through the right angle, less twice the angle of the
    # line to the corner, plus twice the tangents' offset from that line, asin(r / d).
    d = math.hypot(0.65, 0.125)
    turn = math.pi / 2 - 2 * math.atan2(0.125, 0.65) + 2 * math.asin(0.025 / d)
    assert true == pytest.approx(2 * math.sqrt(d**2 - 0.025**2) + 0.025 * turn)
    inner = taut_string(goal, [(0.25, -0.25)], start, 0.025 * math.cos(math.pi / (4 * QUAD_SEGS)))
    assert inner - 0.01 <= geodesic_bound(scene) <= true - 0.01
    assert geodesic_bound(scene) > np.hypot(*(goal - start)) + 0.2  # the straight line is 1.096 m


def test_walled_off_goal_is_infinitely_far():
    wall = {"box": {"center": [0.0, 0.0], "size": [0.1, 1.0]}}  # across the whole table
    assert geodesic_bound(scene_of([wall], [-0.3, 0.0, 0.0], [0.3, 0.0, 0.0])) == math.inf
    # A gap of 0.11 m, wider than the part (0.1 m): open again, over the wall's end.
    gap = {"box": {"center": [0.0, -0.055], "size": [0.1, 0.89]}}
    assert geodesic_bound(scene_of([gap], [-0.3, 0.0, 0.0], [0.3, 0.0, 0.0])) < 2.0


def test_start_outside_the_free_space_falls_back_to_the_straight_line():
    # Not a valid scene (the part overlaps the box at the start), built round the checks: the
    # geodesic has no start to leave from, and the straight line, sound for any path, is kept.
    scene = scene_of([{"box": {"center": [0.0, 0.0], "size": [0.2, 0.2]}}], [-0.35, 0.05, 0.0], [0.35, 0.05, 0.0])
    inside = scene.with_part(start=[-0.12, 0.05, 0.0])
    assert geodesic_bound(inside) == pytest.approx(0.47 - 0.01, abs=1e-12)


def moved(scene: Scene, scale: float, shift: tuple[float, float]) -> Scene:
    """The whole scene scaled about the origin by ``scale``, then shifted by ``shift``."""
    shift = np.asarray(shift, float)

    def pose(p):
        return np.array([*(scale * p[:2] + shift), p[2]])

    moved = scene.with_part(slider=Slider(scene.slider.vertices * scale, scene.slider.cf * scale),
                            start=pose(scene.start), goal=pose(scene.goal))
    return replace(moved, obstacles=tuple(shapely.transform(o, lambda xy: scale * xy + shift) for o in scene.obstacles),
                   workspace=tuple(scale * np.asarray(scene.workspace) + np.tile(shift, 2)),
                   tolerance_position=scene.tolerance_position * scale)


@pytest.mark.parametrize("name", ["parking", "nonconvex"])
def test_bound_scales_with_the_scene_and_ignores_where_it_is(name):
    scene = load_scene(ROOT / "scenes" / f"{name}.yaml")
    bound = geodesic_bound(scene)
    assert geodesic_bound(moved(scene, 1.0, (3.0, -2.0))) == pytest.approx(bound, rel=1e-9)
    assert geodesic_bound(moved(scene, 2.5, (0.0, 0.0))) == pytest.approx(2.5 * bound, rel=1e-9)


@pytest.mark.parametrize("path", SCENES, ids=lambda p: p.stem)
def test_no_plan_is_shorter_than_the_bound(path):
    scene = load_scene(path)
    result = plan(scene, seed=1, time_limit=10)
    assert result.solved
    assert result.path_length(scene.slider.cf) >= geodesic_bound(scene)
