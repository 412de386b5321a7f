"""The command's flags on a scene of several parts, through the same pipeline as one part:
``--reach N --part NAME`` maps one part among the others, ``--export-scene`` writes the tray back,
``--mjcf`` writes a model with every part; a part not named, or not in the scene, is refused with one line."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import shapely
import yaml

from planner import load_scene
from planner.cli import main

ROOT = Path(__file__).resolve().parents[3]
SWAP = ROOT / "scenes" / "parts" / "swap.yaml"


def outline(part: dict, pose) -> shapely.Polygon:
    """The part of the scene file's spec at ``pose`` (x, y, radians), written out again here."""
    c, s = math.cos(pose[2]), math.sin(pose[2])
    points = np.asarray(part["vertices"], dtype=float) @ np.array([[c, s], [-s, c]]) + pose[:2]
    return shapely.Polygon(points)


def test_reach_maps_one_part_of_a_tray_with_the_others_standing_as_obstacles(tmp_path):
    pytest.importorskip("matplotlib")
    from planner import RunOptions, run

    spec = yaml.safe_load(SWAP.read_text())
    red, blue = (next(p for p in spec["parts"] if p["name"] == n) for n in ("red", "blue"))
    blue_there = outline(blue, [*blue["start"][:2], math.radians(blue["start"][2])])
    reach = run(load_scene(SWAP), RunOptions(reach=1, part="red")).reach
    rows, cols = np.nonzero(reach.count > 0)
    assert len(rows) > 10  # red can be pushed somewhere
    for j, i in zip(rows, cols):  # nowhere it is pushed to overlaps blue where blue stands
        assert not outline(red, [reach.xs[i], reach.ys[j], reach.theta[j, i]]).intersects(blue_there)
    j, i = (np.abs(reach.ys - blue["start"][1]).argmin(), np.abs(reach.xs - blue["start"][0]).argmin())
    assert reach.blocked[j, i] and reach.count[j, i] == 0  # blue's own place is taken
    assert main([str(SWAP), "--reach", "1", "--part", "red", "--out", str(tmp_path / "out")]) == 0
    assert (tmp_path / "out" / "swap-reach.png").is_file()


@pytest.mark.parametrize("flags, named", [
    (["--reach", "1"], "--part: the reachable set is one part's: name one of red, blue"),
    (["--reach", "1", "--part", "green"], "--part: no part is named 'green' (the parts: red, blue)"),
])
def test_what_a_tray_does_not_take_is_one_line_naming_the_flag(tmp_path, capsys, monkeypatch, flags, named):
    pytest.importorskip("matplotlib")
    monkeypatch.chdir(tmp_path)
    assert main([str(SWAP), *flags, "--out", "out"]) == 1
    err = capsys.readouterr().err
    assert err.startswith(f"plan: error: {named}") and err.count("\n") == 1
    assert list(tmp_path.iterdir()) == []


def test_export_scene_writes_a_tray_that_reads_back_as_the_same_tray(tmp_path):
    assert main([str(SWAP), "--export-scene", str(tmp_path / "again.yaml"), "--out", str(tmp_path / "out")]) == 0
    scene, again = load_scene(SWAP), load_scene(tmp_path / "again.yaml")
    assert again.names == scene.names and again.obstacles == scene.obstacles
    for a, b in zip(scene.parts, again.parts):
        assert np.allclose(a.start, b.start) and np.allclose(a.goal, b.goal) and a.edges == b.edges
        assert np.array_equal(a.slider.vertices, b.slider.vertices) and np.array_equal(a.slider.cf, b.slider.cf)


def test_mjcf_of_a_tray_is_a_model_with_every_part_that_mujoco_loads(tmp_path):
    mujoco = pytest.importorskip("mujoco")
    model_file = tmp_path / "swap.xml"
    assert main([str(SWAP), "--simulate", "1", "--mjcf", str(model_file), "--out", str(tmp_path / "out")]) == 0
    model = mujoco.MjModel.from_xml_path(str(model_file))
    names = {model.body(i).name for i in range(model.nbody)}
    assert {"part0", "part1", "pusher"} <= names
