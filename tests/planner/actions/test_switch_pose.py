"""Moving a plan's switch pose (planner.actions.switch_pose) against an exhaustive grid.

On scenes/junction.yaml a deliberately long plan pushes the part far past the branch, switches
edge there and pushes it back into the branch. The grid optimum of the plans of that form
(Dubins curve of the first edge's car, walk round the part, Dubins curve of the second edge's
car), over switch poses every centimetre and 5 degrees, is computed here by brute force: every
candidate's length from OMPL's Dubins space directly, then the cheapest candidate that the
planner's collision model and transit planner accept. The shortcut must come within 5 % of it
(it searches a coarser grid, then refines), and its plan must replay independently.
"""

from __future__ import annotations

import math
import time
from pathlib import Path

import numpy as np
import pytest
import shapely
import yaml
from ompl import base as ob

from planner.actions.car import edge_car
from planner.actions.controls import clearance_margin, edge_controls
from planner.actions.dubins import DubinsCurves
from planner.actions.push import connect
from planner.actions.switch_pose import Grid, SwitchShortcut, runs
from planner.actions.transit import TransitPlanner
from planner.model.bodies import cf_poses
from planner.model.plan import Plan
from planner.model.segments import rechain
from planner.model.scene_file import load_scene
from planner.queries.geodesic import geodesic_bound
from planner import plan as plan_of
from planner.world.validity import CollisionModel
from replay import replay_plan

ROOT = Path(__file__).resolve().parents[3]
SCENE = ROOT / "scenes" / "junction.yaml"
PUSH_EAST, PUSH_WEST = 3, 1  # the left face pushes the part along +x, the right face along -x


@pytest.fixture(scope="module")
def junction():
    scene = load_scene(SCENE)
    controls = {c.edge: c for c in edge_controls(scene)}
    model = CollisionModel(scene, list(controls))
    margin = clearance_margin(scene)
    curves = {e: DubinsCurves(scene, edge_car(c, scene.slider.cf), model, margin) for e, c in controls.items()}
    transits = TransitPlanner(scene, list(controls), model, margin, scene.options.transit)
    return scene, controls, model, margin, curves, transits


def _long_plan(junction, far: float) -> list:
    """Straight east from the start by ``far``, walk round, straight back west to x = 0 (where
    the branch opens), Dubins curve into the branch."""
    scene, controls, model, margin, curves, transits = junction
    switch = scene.start + [far, 0.02, 0.0]  # off the middle: room below the part to walk round it
    out = connect(scene.start, switch, controls[PUSH_EAST], model, margin)
    walk = transits.find(switch, PUSH_EAST, PUSH_WEST)
    back = connect(switch, np.array([0.0, 0.02, 0.0]), controls[PUSH_WEST], model, margin)
    turn = curves[PUSH_WEST].connect(np.array([0.0, 0.02, 0.0]), scene.goal)
    assert not isinstance(out, str) and walk is not None and not isinstance(back, str) and turn is not None
    return rechain([out, walk, back, *turn])


def _length(scene, segments) -> float:
    return sum(s.cf_path_length(scene.slider.cf) for s in segments)


def _grid_optimum(junction, below: float) -> tuple[float, np.ndarray]:
    """The least CF length of a Dubins -> walk -> Dubins plan over switch poses on a 1 cm / 5 degree
    grid, and its switch pose: candidates sorted by their Dubins lengths (OMPL's space, set up
    here), the first feasible one wins."""
    scene, controls, model, margin, curves, transits = junction
    cf = scene.slider.cf
    cars = {e: edge_car(controls[e], cf) for e in (PUSH_EAST, PUSH_WEST)}
    xmin, ymin, xmax, ymax = scene.workspace
    x, y = (v.ravel() for v in np.meshgrid(np.arange(xmin, xmax, 0.01), np.arange(ymin, ymax, 0.01)))
    room = shapely.contains_xy(model.cf_room, x, y)
    xy = np.column_stack([x[room], y[room]])
    headings = np.radians(np.arange(-180, 180, 5.0))
    poses = cf_poses(cf, np.repeat(xy, len(headings), axis=0), np.tile(headings, len(xy)))

    def dubins(e: int, a: np.ndarray, b: np.ndarray) -> float:
        space = ob.DubinsStateSpace(cars[e].radius)
        s, t = space.allocState(), space.allocState()
        for state, pose in ((s, a), (t, b)):
            c, sn = math.cos(pose[2]), math.sin(pose[2])
            state.setXY(pose[0] + c * cf[0] - sn * cf[1], pose[1] + sn * cf[0] + c * cf[1])
            state.setYaw(pose[2] + cars[e].heading_angle)
        return space.distance(s, t)

    lengths = np.array([dubins(PUSH_EAST, scene.start, p) + dubins(PUSH_WEST, p, scene.goal) for p in poses])
    for i in np.argsort(lengths):
        if lengths[i] >= below:
            break
        if transits.find(poses[i], PUSH_EAST, PUSH_WEST) is None:
            continue
        first = curves[PUSH_EAST].connect(scene.start, poses[i])
        second = curves[PUSH_WEST].connect(poses[i], scene.goal) if first is not None else None
        if second is not None:
            return _length(scene, first) + _length(scene, second), poses[i]
    raise AssertionError("no feasible switch pose on the grid")


def test_a_long_switching_plan_is_brought_within_5_percent_of_the_grid_optimum(junction):
    scene, controls, model, margin, curves, transits = junction
    long = _long_plan(junction, 0.75)
    shortcut = SwitchShortcut(scene, curves, model, transits, scene.options.switch_cost)
    better = shortcut(long)
    optimum, pose = _grid_optimum(junction, _length(scene, long))
    assert _length(scene, long) > 1.3 * optimum  # the test starts far from the optimum
    legs, switches = runs(better)
    assert len(switches) == 1 and [leg[0].edge for leg in legs] == [PUSH_EAST, PUSH_WEST]
    assert _length(scene, better) <= 1.05 * optimum, (_length(scene, better), optimum, pose)
    assert np.allclose(better[0].start, scene.start) and np.allclose(better[-1].end, scene.goal, atol=1e-9)
    plan = Plan.of_part("part", scene.start, scene.goal, better,
                        scene=str(SCENE), solved=True, planner="rrt", seed=1, planning_time_s=0.0)
    replay_plan(yaml.safe_load(SCENE.read_text()), plan.to_dict())


def test_a_needless_switch_is_dropped_and_a_needed_one_kept(junction):
    """A switch and back onto the first edge costs a switch for nothing: replaced by one edge. The
    junction's branch cannot be entered on the first edge alone: that switch stays."""
    scene, controls, model, margin, curves, transits = junction
    shortcut = SwitchShortcut(scene, curves, model, transits, scene.options.switch_cost)
    a = scene.start + [0.2, 0.02, 0.0]
    b = a + [0.2, 0.0, 0.0]
    there = connect(scene.start, a, controls[PUSH_EAST], model, margin)
    walk = transits.find(a, PUSH_EAST, PUSH_WEST)
    walk_back = transits.find(a, PUSH_WEST, PUSH_EAST)
    on = connect(a, b, controls[PUSH_EAST], model, margin)
    detour = rechain([there, walk, walk_back, on])
    plain = shortcut(detour)
    assert [s.kind for s in plain] == ["push"] * len(plain) and np.allclose(plain[-1].end, b, atol=1e-9)
    assert _length(scene, plain) <= _length(scene, detour) + 1e-9
    needed = shortcut(_long_plan(junction, 0.5))
    assert sum(s.kind == "transit" for s in needed) == 1


def test_a_finer_via_grid_finds_a_way_the_plan_did_not_take():
    """Cluttered, seed 1: the plan goes round the obstacles in the middle (about 1.41 m). Two Dubins
    curves through a via pose on a grid twice as fine as the default's (a quarter of a part
    radius, 2.5 degrees) find the narrow way between them (about 1.24 m; the geodesic bound is
    1.15 m), a plan that replays independently. With its deadline already past, the same search
    leaves the plan as it is."""
    path = ROOT / "scenes" / "cluttered.yaml"
    scene = load_scene(path)
    first = plan_of(scene, margin=0)  # in the exact regions, as the controls below
    controls = edge_controls(scene)
    model = CollisionModel(scene, [c.edge for c in controls])
    margin = clearance_margin(scene)
    curves = {c.edge: DubinsCurves(scene, edge_car(c, scene.slider.cf), model, margin) for c in controls}
    fine = Grid(spacing=0.25, heading=2.5, checks=60, candidates=200_000)
    via = SwitchShortcut(scene, curves, model, None, scene.options.switch_cost, fine, via=True)
    better = via(first.segments)
    assert _length(scene, better) < 0.9 * _length(scene, first.segments)
    assert _length(scene, better) >= geodesic_bound(scene) - 1e-9
    assert np.allclose(better[0].start, scene.start) and np.allclose(better[-1].end, first.segments[-1].end)
    better_plan = Plan.of_part("part", scene.start, scene.goal, better,
                               scene=str(path), solved=True, planner="rrt", seed=1, planning_time_s=0.0)
    replay_plan(yaml.safe_load(path.read_text()), better_plan.to_dict())
    late = SwitchShortcut(scene, curves, model, None, scene.options.switch_cost, fine, via=True,
                          deadline=time.perf_counter())
    given = first.segments
    assert late(given) is given
