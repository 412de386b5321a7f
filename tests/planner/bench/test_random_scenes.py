"""The random scenes of planner.bench.unseen_scenes: valid scene files, drawn from the seed alone,
with what the module's docstring promises of them, checked from the files (not the draws)."""

from __future__ import annotations

import math

import numpy as np
import shapely
import yaml

from planner.bench.unseen_scenes import CLEAR, EDGE, main, write_scenes
from planner.model.camera import read_camera
from planner.model.scene_file import load_scene


def test_the_same_seed_writes_the_same_scenes_and_another_seed_others(tmp_path):
    first = [p.read_text() for p in write_scenes(tmp_path / "a", 4, 7)]
    again = [p.read_text() for p in write_scenes(tmp_path / "b", 4, 7)]
    other = [p.read_text() for p in write_scenes(tmp_path / "c", 4, 8)]
    assert first == again and first != other


def test_each_scene_loads_and_keeps_its_parts_obstacles_and_camera_where_promised(tmp_path):
    kinds = set()
    for path in write_scenes(tmp_path, 12, 3):
        spec = yaml.safe_load(path.read_text())
        scene = load_scene(path)
        kinds.add(spec["name"].rsplit("-", 1)[1])
        (xmin, ymin), (xmax, ymax) = spec["workspace"]["min"], spec["workspace"]["max"]
        table = shapely.box(xmin, ymin, xmax, ymax)
        outline = shapely.Polygon(spec["slider"]["vertices"])
        placed = []
        for x, y, degrees in (spec["start"], spec["goal"]):
            c, s = math.cos(math.radians(degrees)), math.sin(math.radians(degrees))
            part = shapely.Polygon([(x + c * u - s * v, y + s * u + c * v) for u, v in outline.exterior.coords])
            assert table.buffer(-EDGE + 1e-9).contains(part)
            placed.append(part)
        assert math.dist(spec["start"][:2], spec["goal"][:2]) >= 0.15 - 1e-9
        for obstacle in spec["obstacles"]:
            (cx, cy), (w, h) = obstacle["box"]["center"], obstacle["box"]["size"]
            box = shapely.box(cx - w / 2, cy - h / 2, cx + w / 2, cy + h / 2)
            assert all(box.distance(part) > CLEAR - 0.02 for part in placed)  # the part's circumcircle is kept CLEAR
        # The camera sees the whole table: its corners project inside the image.
        camera = read_camera(spec["camera"], (xmin, ymin, xmax, ymax))
        corners = np.array([[xmin, ymin, 0.0], [xmax, ymin, 0.0], [xmax, ymax, 0.0], [xmin, ymax, 0.0]])
        u, v = camera.pixels(corners).T
        width, height = camera.resolution
        assert (u >= 0).all() and (u <= width).all() and (v >= 0).all() and (v <= height).all(), spec["name"]
        tilt = math.degrees(math.atan2(math.hypot(*camera.position[:2]), camera.position[2]))
        assert tilt <= 10.0 + 0.01  # (the position is rounded to 0.1 mm)
        assert scene.name == spec["name"]
    assert len(kinds) >= 3  # rectangles, squares, trapezoids and Ls are all drawn


def test_the_command_prints_the_files_it_wrote(tmp_path, capsys):
    assert main([str(tmp_path), "--count", "2", "--seed", "1"]) == 0
    printed = capsys.readouterr().out.split()
    assert printed == [str(tmp_path / "unseen-1.yaml"), str(tmp_path / "unseen-2.yaml")]
