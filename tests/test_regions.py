"""Which stable regions the planner uses (planner.actions.region_cache): the scene option, the cache, the choice."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml

from mechanics import ExactRegion, Slider, StableSteering, exact_region, stable_region
from planner import SceneError, load_scene, parse_scene, plan
from oracle import guaranteed_stable
from planner.actions.region_cache import compute_regions, edge_region

ROOT = Path(__file__).resolve().parent.parent
BLOCK = Slider([[-0.05, 0.0], [0.05, 0.0], [0.05, 0.06], [-0.05, 0.06]])


def test_bad_regions_option_names_the_field():
    spec = yaml.safe_load((ROOT / "scenes" / "battery.yaml").read_text())
    spec.setdefault("planner", {})["regions"] = "fuzzy"
    with pytest.raises(SceneError, match=r"planner\.regions.*stable, exact.*'fuzzy'"):
        parse_scene(spec)
    spec["planner"]["regions"] = "stable"
    assert parse_scene(spec).planner.regions == "stable"


def test_cached_region_is_the_computed_one(tmp_path, monkeypatch):
    monkeypatch.setenv("STABLEPUSH_CACHE", str(tmp_path))
    monkeypatch.setattr("planner.actions.region_cache._memory", {})
    first = edge_region(BLOCK, 0, 0.5, 0.08)
    assert isinstance(first, ExactRegion) and len(list(tmp_path.iterdir())) == 1
    monkeypatch.setattr("planner.actions.region_cache._memory", {})
    again = edge_region(BLOCK, 0, 0.5, 0.08)
    assert again is not first and again.polygon.equals_exact(first.polygon, 0.0)
    fresh = exact_region(BLOCK, 0, 0.5, 0.08)
    assert fresh.polygon.equals_exact(first.polygon, 0.0)
    assert isinstance(edge_region(BLOCK, 0, 0.5, 0.08, "stable"), type(stable_region(BLOCK, 0, 0.5)))


def test_a_broken_or_unwritable_cache_is_ignored(tmp_path, monkeypatch):
    monkeypatch.setenv("STABLEPUSH_CACHE", str(tmp_path))
    monkeypatch.setattr("planner.actions.region_cache._memory", {})
    good = edge_region(BLOCK, 1, 0.5, None)
    (cached,) = tmp_path.iterdir()
    cached.write_text('{"polygon": [[0, 0], [1')  # cut short
    monkeypatch.setattr("planner.actions.region_cache._memory", {})
    assert edge_region(BLOCK, 1, 0.5, None).polygon.equals_exact(good.polygon, 0.0)
    blocked = tmp_path / "file"
    blocked.write_text("")
    monkeypatch.setenv("STABLEPUSH_CACHE", str(blocked / "sub"))  # cannot be made
    monkeypatch.setattr("planner.actions.region_cache._memory", {})
    assert edge_region(BLOCK, 1, 0.5, None).polygon.equals_exact(good.polygon, 0.0)


def test_stable_regions_plan_only_with_stable_pushes():
    scene = load_scene(ROOT / "scenes" / "nonconvex.yaml")
    result = plan(scene, seed=1, regions="stable")
    assert result.solved
    for seg in result.segments:
        region = stable_region(scene.slider, seg.edge, scene.pusher.mu, scene.pusher.width)
        assert region.contains(seg.twist)
    with pytest.raises(SceneError, match="regions"):
        plan(scene, seed=1, regions="approximate")


def test_regions_flag_overrides_the_scene(tmp_path):
    run = subprocess.run([str(Path(sys.executable).parent / "plan"), "scenes/nonconvex.yaml", "--regions", "stable",
                          "--seed", "1", "--out", str(tmp_path)], capture_output=True, text=True, cwd=ROOT, timeout=120)
    assert run.returncode == 0, run.stderr
    scene = load_scene(ROOT / "scenes" / "nonconvex.yaml")
    segments = json.loads((tmp_path / "nonconvex.json").read_text())["segments"]
    region = stable_region(scene.slider, segments[0]["edge"], scene.pusher.mu, scene.pusher.width)
    assert all(region.contains(s["twist"]) for s in segments)


def test_a_turn_of_the_part_gives_its_twin_edge_the_same_region(tmp_path, monkeypatch):
    """A 10 x 6 cm block is carried onto itself by a half turn about its CF, edge 0 onto edge 2:
    only edge 0's region is computed, edge 2 gets the same section of its own push plane. That is
    sound (every sampled push in it sticks for every support distribution, by the test-only LP
    oracle, and turns about a centre beyond the part) and agrees with edge 2's region computed
    on its own. An off-centre CF breaks the symmetry: nothing is shared."""
    monkeypatch.setenv("STABLEPUSH_CACHE", str(tmp_path))
    monkeypatch.setattr("planner.actions.region_cache._memory", {})
    block = Slider([[-0.05, -0.03], [0.05, -0.03], [0.05, 0.03], [-0.05, 0.03]])
    progress: list[tuple[int, int]] = []
    regions = compute_regions(block, [0, 1, 2, 3], 0.5, 0.05, progress=lambda k, n: progress.append((k, n)))
    assert progress == [(1, 2), (2, 2)] and sorted(regions) == [0, 1, 2, 3]
    twin, alone = regions[2], exact_region(block, 2, 0.5, 0.05)
    assert twin.edge == 2 and twin.polygon.equals(regions[0].polygon)
    assert twin.polygon.symmetric_difference(alone.polygon).area < 0.005 * alone.polygon.area
    rng = np.random.default_rng(1)
    steer = StableSteering(twin)
    for v in steer.twist(rng.random((40, 2))):
        assert guaranteed_stable(block.vertices, block.cf, 2, 0.5, 0.05, v), v
    assert Slider(block.vertices, cf=[0.01, 0.0]).turns == ()
