"""Time limits and progress while the stable regions are computed (issue 10).

``mechanics.exact_region`` stops at a deadline with ``DeadlineExceeded``; ``planner.actions.controls.edge_controls``
computes the edges that fit before it and raises ``RegionTimeout`` holding them; a progress
callback hears of each region actually computed; and an input with no stable push anywhere is
refused before any exact region is computed. Sources of truth: the clock, the cache folder's
contents, and procedure STABLE's emptiness (Proposition 6: no push stable for STABLE's CF-only
knowledge means none stable at all).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import yaml

from mechanics import DeadlineExceeded, Slider, exact_region
from planner import SceneError, parse_scene
from planner.actions.controls import RegionTimeout, edge_controls
from planner.actions.region_cache import RegionCache, is_cached

ROOT = Path(__file__).resolve().parents[3]


@pytest.fixture()
def empty_cache(tmp_path):
    return RegionCache(tmp_path / "cache")


def many_edged(n: int = 200) -> dict:
    """The battery scene with its part replaced by an n-gon (an ellipse 9 x 5 cm) pushable on
    every edge by a pusher wider than them all, its CF a millimetre off the centre: no turn of
    the part carries one edge onto another, so every edge's region is computed."""
    spec = yaml.safe_load((ROOT / "scenes" / "battery.yaml").read_text())
    angle = 2 * np.pi * np.arange(n) / n
    spec["slider"] = {"vertices": np.c_[0.045 * np.cos(angle), 0.025 * np.sin(angle)].round(6).tolist(),
                      "cf": [0.001, 0.0]}
    spec["pusher"].pop("edges")
    spec["obstacles"] = []
    return spec


def test_exact_region_stops_at_its_deadline():
    block = Slider([[-1, 0], [1, 0], [1, 1], [-1, 1]])
    with pytest.raises(DeadlineExceeded, match="edge 0"):
        exact_region(block, 0, 0.5, deadline=time.perf_counter())
    start = time.perf_counter()
    with pytest.raises(DeadlineExceeded):
        exact_region(block, 0, 0.5, deadline=start + 0.02)
    assert time.perf_counter() - start < 0.5  # a batch of certifications, not the whole trace
    assert exact_region(block, 0, 0.5, deadline=time.perf_counter() + 60).polygon.area > 0


def test_a_many_edged_part_computes_what_fits_and_says_so(empty_cache):
    """A 200-gon with two seconds: the edges done before the deadline come back in the
    exception, in order and cached; the rest are named as pending, and none of them is cached.
    Edges are begun in order, one per core at a time, so those done are among the first ones
    and those still running at the deadline, at most one per core."""
    scene = parse_scene(many_edged(), "ellipse")
    edges = scene.edges
    assert len(edges) == 200
    start = time.perf_counter()
    with pytest.raises(RegionTimeout) as caught:
        edge_controls(scene, deadline=start + 2.0, cache=empty_cache)
    assert time.perf_counter() - start < 3.0
    done = [p.edge for p in caught.value.controls]
    pending = caught.value.pending
    assert len(done) >= 2 and done == sorted(done) and list(pending) == sorted(pending)
    assert sorted(done + list(pending)) == list(edges) and len(pending) > 100
    assert set(done) <= set(edges[:len(done) + len(os.sched_getaffinity(0))])
    assert f"edges {pending[0]}, {pending[1]}" in str(caught.value) and "time limit" in str(caught.value)
    p = scene.pusher
    assert all(is_cached(scene.slider, e, p.mu, p.width, cache=empty_cache) for e in done)
    assert not any(is_cached(scene.slider, e, p.mu, p.width, cache=empty_cache) for e in pending)
    assert len(list(empty_cache.folder.iterdir())) == len(done)


def test_past_the_deadline_cached_edges_are_still_read(empty_cache):
    """Edges 0 and 2 of the corridor's part cached, 1 and 3 not: with the deadline already past,
    the cached two come back and only the others are pending."""
    spec = yaml.safe_load((ROOT / "scenes" / "corridor.yaml").read_text())
    spec["pusher"]["edges"] = [0, 2]
    edge_controls(parse_scene(spec, "corridor"), cache=empty_cache)
    spec["pusher"].pop("edges")
    with pytest.raises(RegionTimeout) as caught:
        edge_controls(parse_scene(spec, "corridor"), deadline=time.perf_counter(), cache=empty_cache)
    assert [p.edge for p in caught.value.controls] == [0, 2] and caught.value.pending == (1, 3)


def test_progress_hears_of_each_region_computed_and_none_cached(empty_cache):
    spec = yaml.safe_load((ROOT / "scenes" / "corridor.yaml").read_text())
    spec["pusher"]["edges"] = [0, 1, 3]
    scene = parse_scene(spec, "corridor")
    heard = []
    first = edge_controls(scene, progress=lambda k, n: heard.append((k, n)), cache=empty_cache)
    assert heard == [(1, 2), (2, 2)]  # edge 3 is edge 1 turned half round the block: not computed
    heard.clear()
    again = edge_controls(scene, progress=lambda k, n: heard.append((k, n)), cache=empty_cache)
    assert heard == [] and [p.edge for p in again] == [p.edge for p in first] == [0, 1, 3]


def test_no_stable_push_anywhere_is_refused_before_any_region(tmp_path):
    """A friction cone too narrow to push through the CF from any allowed edge: procedure STABLE
    is empty on each (Proposition 6), so the exact regions are not computed."""
    spec = yaml.safe_load((ROOT / "scenes" / "battery.yaml").read_text())
    # Face 3 (x = -24.25 mm) pushed by a 1 cm face (|y| <= 5 mm), the CF 12 mm off its axis: with
    # mu = 0.05 a contact force through the CF would need |y| >= 12 - 0.05 * 48.5 = 9.6 mm.
    spec["slider"]["cf"] = [0.0, 0.012]
    spec["pusher"].update(mu=0.05, width=0.01)
    scene = parse_scene(spec, "battery")

    def refuse(*args, **kwargs):
        raise AssertionError("an exact region was computed")

    with pytest.raises(SceneError, match="pusher.edges: no allowed edge has a stable push"):
        edge_controls(scene, cache=RegionCache(tmp_path, compute=refuse))


def test_the_plan_command_honours_its_time_limit_on_a_200_gon(empty_cache, tmp_path):
    """Regions and search share the limit: ``plan --time-limit 5`` ends well within 10 s, with
    one line saying what was not done in time. At the exact limit: the ellipse's facets are far
    shorter than the default margin's CF disk, which none of them can hold (the margin is named)."""
    scene = tmp_path / "ellipse.yaml"
    scene.write_text(yaml.safe_dump(many_edged()))
    started = time.perf_counter()
    run = subprocess.run([str(Path(sys.executable).parent / "plan"), str(scene), "--time-limit", "5", "--margin", "0",
                          "--out", str(tmp_path / "out")], capture_output=True, text=True, timeout=60, cwd=tmp_path,
                         env={**os.environ, "STABLEPUSH_CACHE": str(empty_cache.folder)})
    assert time.perf_counter() - started < 10.0
    assert run.returncode in (0, 2), run.stderr
    assert "time limit" in run.stderr and len(run.stderr.strip().splitlines()) == 1, run.stderr


def test_no_room_for_the_pusher_is_found_before_any_region(tmp_path):
    """``plan`` in a fresh interpreter whose default cache is an empty folder: it refuses the
    start before any exact region, which would have been kept in memory and written to the folder."""
    spec = yaml.safe_load((ROOT / "scenes" / "battery.yaml").read_text())
    spec["obstacles"] = [{"box": {"center": [-0.035, 0.0], "size": [0.01, 0.1]}}]  # against the pushed face
    script = f"""
import json
from planner import SceneError, parse_scene, plan
from planner.actions.region_cache import is_cached
scene = parse_scene({spec!r})
try:
    plan(scene)
except SceneError as err:
    p = scene.pusher
    print(json.dumps([err.field, err.problem, [is_cached(scene.slider, e, p.mu, p.width) for e in scene.edges]]))
"""
    folder = tmp_path / "cache"
    run = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, cwd=ROOT, timeout=120,
                         env={**os.environ, "STABLEPUSH_CACHE": str(folder)})
    assert run.returncode == 0, run.stderr
    field, problem, cached = json.loads(run.stdout)
    assert field == "start" and "no room" in problem
    assert cached and not any(cached) and not folder.exists()
