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
from planner.actions.region_cache import (MEMORY_SIZE, RegionCache, cache_folder, compute_regions, default_cache,
                                          edge_region)

ROOT = Path(__file__).resolve().parents[3]
BLOCK = Slider([[-0.05, 0.0], [0.05, 0.0], [0.05, 0.06], [-0.05, 0.06]])


def test_bad_regions_option_names_the_field():
    spec = yaml.safe_load((ROOT / "scenes" / "battery.yaml").read_text())
    spec.setdefault("planner", {})["regions"] = "fuzzy"
    with pytest.raises(SceneError, match=r"planner\.regions.*stable, exact.*'fuzzy'"):
        parse_scene(spec)
    spec["planner"]["regions"] = "stable"
    assert parse_scene(spec).options.regions == "stable"


def refuse(*args, **kwargs):
    """A region computation for a cache that must answer from what it holds."""
    raise AssertionError("an exact region was computed")


def test_cached_region_is_the_computed_one(tmp_path):
    cache = RegionCache(tmp_path)
    first = edge_region(BLOCK, 0, 0.5, 0.08, cache=cache)
    assert isinstance(first, ExactRegion) and len(list(tmp_path.iterdir())) == 1
    assert edge_region(BLOCK, 0, 0.5, 0.08, cache=cache) is first  # from memory
    again = edge_region(BLOCK, 0, 0.5, 0.08, cache=RegionCache(tmp_path, compute=refuse))  # from the file
    assert again is not first and again.polygon.equals_exact(first.polygon, 0.0)
    fresh = exact_region(BLOCK, 0, 0.5, 0.08)
    assert fresh.polygon.equals_exact(first.polygon, 0.0)
    stable = edge_region(BLOCK, 0, 0.5, 0.08, "stable", cache=RegionCache(tmp_path, compute=refuse))
    assert isinstance(stable, type(stable_region(BLOCK, 0, 0.5)))


def test_a_broken_or_unwritable_cache_is_ignored(tmp_path):
    good = edge_region(BLOCK, 1, 0.5, None, cache=RegionCache(tmp_path))
    (cached,) = tmp_path.iterdir()
    cached.write_text('{"polygon": [[0, 0], [1')  # cut short
    with pytest.raises(AssertionError, match="computed"):  # not read as a region: computed again
        edge_region(BLOCK, 1, 0.5, None, cache=RegionCache(tmp_path, compute=refuse))
    assert edge_region(BLOCK, 1, 0.5, None, cache=RegionCache(tmp_path)).polygon.equals_exact(good.polygon, 0.0)
    assert edge_region(BLOCK, 1, 0.5, None, cache=RegionCache(tmp_path, compute=refuse)).polygon.equals_exact(
        good.polygon, 0.0)  # and written again whole
    blocked = tmp_path / "file"
    blocked.write_text("")
    unwritable = RegionCache(blocked / "sub")  # cannot be made
    assert edge_region(BLOCK, 1, 0.5, None, cache=unwritable).polygon.equals_exact(good.polygon, 0.0)
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([cached.name, "file"])


def test_a_hostile_cache_file_is_computed_again(tmp_path):
    """A cache file is read as untrusted JSON: nested 100000 deep, a number of 5000 digits, values
    of the wrong kinds; whatever it holds, the region is computed again."""
    good = edge_region(BLOCK, 1, 0.5, None, cache=RegionCache(tmp_path))
    (cached,) = tmp_path.iterdir()
    for content in ["[" * 100_000, '{"polygon": ' + "1" * 5000 + "}", '{"polygon": {}, "centre": 1}']:
        cached.write_text(content)
        with pytest.raises(AssertionError, match="computed"):
            edge_region(BLOCK, 1, 0.5, None, cache=RegionCache(tmp_path, compute=refuse))
    assert edge_region(BLOCK, 1, 0.5, None, cache=RegionCache(tmp_path)).polygon.equals_exact(good.polygon, 0.0)


def test_the_cache_keeps_the_most_recently_used_in_memory(tmp_path):
    """A cache of two regions: a third drops the least recently used from memory, which is then
    read from its file, not computed; every file stays."""
    block = Slider(BLOCK.vertices, cf=[0.01, 0.03])  # no turn carries one edge onto another
    cache = RegionCache(tmp_path, size=2)
    zero, one = (edge_region(block, e, 0.5, 0.08, cache=cache) for e in (0, 1))
    assert edge_region(block, 0, 0.5, 0.08, cache=cache) is zero  # edge 0 now the more recent
    two = edge_region(block, 2, 0.5, 0.08, cache=cache)
    cache.compute = refuse
    assert edge_region(block, 0, 0.5, 0.08, cache=cache) is zero
    assert edge_region(block, 2, 0.5, 0.08, cache=cache) is two
    again = edge_region(block, 1, 0.5, 0.08, cache=cache)
    assert again is not one and again.polygon.equals_exact(one.polygon, 0.0)
    assert len(list(tmp_path.iterdir())) == 3
    assert RegionCache(tmp_path).size == MEMORY_SIZE


def test_calls_given_no_cache_share_one_made_from_the_environment(region_cache):
    """The default cache is one object, in the folder the environment named when it was made
    (this session's, tests/conftest.py), computing with mechanics.exact_region."""
    assert default_cache() is default_cache()
    assert default_cache().folder == cache_folder() == region_cache
    assert default_cache().compute is exact_region and default_cache().size == MEMORY_SIZE
    region = edge_region(BLOCK, 3, 0.5, 0.08)
    assert edge_region(BLOCK, 3, 0.5, 0.08, cache=default_cache()) is region


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


def test_a_turn_of_the_part_gives_its_twin_edge_the_same_region(tmp_path):
    """A 10 x 6 cm block is carried onto itself by a half turn about its CF, edge 0 onto edge 2:
    only edge 0's region is computed, edge 2 gets the same section of its own push plane. That is
    sound (every sampled push in it sticks for every support distribution, by the test-only LP
    oracle, and turns about a centre beyond the part) and agrees with edge 2's region computed
    on its own. An off-centre CF breaks the symmetry: nothing is shared."""
    block = Slider([[-0.05, -0.03], [0.05, -0.03], [0.05, 0.03], [-0.05, 0.03]])
    progress: list[tuple[int, int]] = []
    regions = compute_regions(block, [0, 1, 2, 3], 0.5, 0.05, progress=lambda k, n: progress.append((k, n)),
                              cache=RegionCache(tmp_path))
    assert progress == [(1, 2), (2, 2)] and sorted(regions) == [0, 1, 2, 3]
    twin, alone = regions[2], exact_region(block, 2, 0.5, 0.05)
    assert twin.edge == 2 and twin.polygon.equals(regions[0].polygon)
    assert twin.polygon.symmetric_difference(alone.polygon).area < 0.005 * alone.polygon.area
    rng = np.random.default_rng(1)
    steer = StableSteering(twin)
    for v in steer.twist(rng.random((40, 2))):
        assert guaranteed_stable(block.vertices, block.cf, 2, 0.5, 0.05, v), v
    assert Slider(block.vertices, cf=[0.01, 0.0]).turns == ()
