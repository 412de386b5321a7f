"""Which stable regions the planner uses (planner.regions): the scene option, the cache, the choice."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from mechanics import ExactRegion, Slider, exact_region, stable_region
from planner import SceneError, load_scene, parse_scene, plan
from planner.regions import edge_region

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
    monkeypatch.setattr("planner.regions._memory", {})
    first = edge_region(BLOCK, 0, 0.5, 0.08)
    assert isinstance(first, ExactRegion) and len(list(tmp_path.iterdir())) == 1
    monkeypatch.setattr("planner.regions._memory", {})
    again = edge_region(BLOCK, 0, 0.5, 0.08)
    assert again is not first and again.polygon.equals_exact(first.polygon, 0.0)
    fresh = exact_region(BLOCK, 0, 0.5, 0.08)
    assert fresh.polygon.equals_exact(first.polygon, 0.0)
    assert isinstance(edge_region(BLOCK, 0, 0.5, 0.08, "stable"), type(stable_region(BLOCK, 0, 0.5)))


def test_a_broken_or_unwritable_cache_is_ignored(tmp_path, monkeypatch):
    monkeypatch.setenv("STABLEPUSH_CACHE", str(tmp_path))
    monkeypatch.setattr("planner.regions._memory", {})
    good = edge_region(BLOCK, 1, 0.5, None)
    (cached,) = tmp_path.iterdir()
    cached.write_text('{"polygon": [[0, 0], [1')  # cut short
    monkeypatch.setattr("planner.regions._memory", {})
    assert edge_region(BLOCK, 1, 0.5, None).polygon.equals_exact(good.polygon, 0.0)
    blocked = tmp_path / "file"
    blocked.write_text("")
    monkeypatch.setenv("STABLEPUSH_CACHE", str(blocked / "sub"))  # cannot be made
    monkeypatch.setattr("planner.regions._memory", {})
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
