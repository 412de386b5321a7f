"""Reachable-set maps (planner/queries/reachable_set.py) agree with one_step and the goal region, and the
``plan --reach N`` flag writes them."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest
import shapely
from rerun.chunk import RrdReader

from planner import load_scene, one_step
from planner.cli import main
from planner.search.goal_region import GoalRegion
from planner.actions.controls import clearance_margin, edge_controls
from planner.queries.reachable_set import reach_points, reachable_set, write_png
from planner.world.validity import CollisionModel

SCENES = Path(__file__).resolve().parents[3] / "scenes"
PNG = b"\x89PNG\r\n\x1a\n"
RES = 0.05  # parking's workspace: 20 x 19 cells


@pytest.fixture(scope="module")
def scene():
    return load_scene(SCENES / "parking.yaml")


@pytest.fixture(scope="module")
def one(scene):
    return reachable_set(scene, pushes=1, heading=scene.start[2], resolution=RES)


@pytest.fixture(scope="module")
def two(scene):
    return reachable_set(scene, pushes=2, heading=scene.start[2], resolution=RES)


def cells(reach, mask, n, seed=0) -> list[tuple[int, int]]:
    rows, cols = np.nonzero(mask)
    pick = np.random.default_rng(seed).permutation(len(rows))[:n]
    return [(int(rows[k]), int(cols[k])) for k in pick]


def goal(reach, j, i, theta) -> np.ndarray:
    return np.array([reach.xs[i], reach.ys[j], theta])


def test_grid_covers_the_workspace(scene, one):
    assert one.count.shape == (19, 20) and one.count.dtype == np.int8
    assert one.extent == scene.workspace
    assert math.isclose(one.xs[0] - one.cell[0] / 2, scene.workspace[0])
    assert math.isclose(one.ys[-1] + one.cell[1] / 2, scene.workspace[3])
    assert set(np.unique(one.count)) == {0, 1}
    assert one.heading == pytest.approx(scene.start[2])


def test_one_push_map_agrees_with_one_step_on_sampled_cells(scene, one):
    free = ~one.blocked
    sample = cells(one, free & (one.count == 1), 8) + cells(one, free & (one.count == 0), 7, seed=1)
    assert len(sample) == 15
    for j, i in sample:
        answer = one_step(scene, goal=goal(one, j, i, one.heading))
        assert answer.reachable == (one.count[j, i] == 1), (j, i, answer.reason)


def test_any_heading_map_agrees_with_one_step(scene):
    reach = reachable_set(scene, pushes=1, resolution=0.1, headings=8)
    assert reach.heading is None and len(reach.headings) == 8
    for j, i in cells(reach, reach.count == 1, 5):
        assert one_step(scene, goal=goal(reach, j, i, reach.theta[j, i])).reachable
    for j, i in cells(reach, (reach.count == 0) & ~reach.blocked, 3):
        assert np.isnan(reach.theta[j, i])
        assert not any(one_step(scene, goal=goal(reach, j, i, th)).reachable for th in reach.headings)


def test_two_push_map_agrees_with_the_goal_region(scene, one, two):
    assert np.array_equal(two.count == 1, one.count == 1), "two pushes keep every one-push cell at 1"
    assert (two.count == 2).any()
    pushes = edge_controls(scene)
    model = CollisionModel(scene, [p.edge for p in pushes])
    free = ~two.blocked
    for j, i in cells(two, two.count == 2, 3) + cells(two, free & (two.count == 0), 3, seed=2):
        g = goal(two, j, i, two.heading)
        region = GoalRegion(scene, g, pushes, model, clearance_margin(scene))
        found = [region.pushes_to(scene.start, k, [0]).get(0) for k in range(len(pushes))]
        found = [f for f in found if f]
        assert bool(found) == (two.count[j, i] == 2), (j, i)
        for segments in found:  # two pushes, ending at the cell's pose
            assert len(segments) == 2 and np.allclose(segments[-1].end[:2], g[:2])
        assert not one_step(scene, goal=g).reachable


def test_cells_where_the_part_collides_are_zero(scene, one, two):
    for reach in (one, two):
        assert reach.blocked.any() and not reach.count[reach.blocked].any()
    obstacle = scene.obstacles[3]  # the box in the way
    centre = obstacle.centroid
    j, i = one.cell_of(centre.x, centre.y)
    assert one.blocked[j, i] and one.count[j, i] == 0
    assert not one_step(scene, goal=goal(one, j, i, one.heading)).reachable
    # and a cell whose part fits is not blocked
    part = shapely.Polygon(scene.slider.vertices)
    j, i = one.cell_of(-0.2, 0.3)
    placed = shapely.affinity.translate(shapely.affinity.rotate(part, one.heading, origin=(0, 0), use_radians=True),
                                        one.xs[i], one.ys[j])
    assert not any(placed.intersects(o) for o in scene.obstacles) and not one.blocked[j, i]


def test_the_start_cell_agrees_with_one_step(scene, one):
    """The start itself needs no push and is not marked; the cell holding it answers for its centre."""
    assert not one_step(scene, goal=scene.start).reachable  # "the start is the goal": no push
    j, i = one.cell_of(*scene.start[:2])
    assert one_step(scene, goal=goal(one, j, i, scene.start[2])).reachable == (one.count[j, i] == 1)


def test_bad_arguments_are_refused(scene):
    with pytest.raises(ValueError, match="pushes"):
        reachable_set(scene, pushes=3)
    with pytest.raises(ValueError, match="resolution"):
        reachable_set(scene, resolution=0.0)


def test_png_and_rerun_points(scene, two, tmp_path):
    path = tmp_path / "reach.png"
    write_png(two, scene, str(path))
    assert path.read_bytes().startswith(PNG)
    centres, counts = reach_points(two)
    assert centres.shape == (int((two.count > 0).sum()), 2) and set(counts) == {1, 2}


def test_plan_reach_writes_the_png_and_the_rerun_layer(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main([str(SCENES / "battery.yaml"), "--reach", "1", "--out", "out"]) == 0
    out = capsys.readouterr().out
    assert out.strip().endswith("battery-reach.png")
    assert (tmp_path / "out" / "battery-reach.png").read_bytes().startswith(PNG)
    paths = {chunk.entity_path for chunk in RrdReader(str(tmp_path / "out" / "battery.rrd")).store().stream()}
    assert "/world/reach" in paths


@pytest.mark.parametrize("n", ["0", "3", "-1"])
def test_plan_bad_reach_exits_1_with_one_line(n, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main([str(SCENES / "battery.yaml"), "--reach", n, "--out", "out"]) == 1
    captured = capsys.readouterr()
    assert captured.out == "" and captured.err.count("\n") == 1
    assert captured.err.startswith("plan: error: --reach: ")
    assert not (tmp_path / "out").exists()


def test_without_matplotlib_reach_is_one_line_naming_the_extra_before_any_work(monkeypatch, capsys, tmp_path):
    monkeypatch.setitem(sys.modules, "matplotlib", None)  # as after a plain pip install -e .
    assert main([str(SCENES / "parking.yaml"), "--reach", "2", "--out", str(tmp_path / "out")]) == 1
    assert capsys.readouterr().err == ("plan: error: --reach: the map's PNG needs matplotlib, which the figures "
                                       "extra installs: pip install 'stablepush[figures]'\n")
    assert not (tmp_path / "out").exists()
    with pytest.raises(ModuleNotFoundError, match=r"^needs matplotlib, which the figures extra installs"):
        write_png(None, load_scene(SCENES / "parking.yaml"), str(tmp_path / "map.png"))
