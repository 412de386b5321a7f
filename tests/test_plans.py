"""Every shipped scene: `plan` solves it with seed 1, and the plan JSON replays correctly.

The replay shares nothing with the planner: poses by the matrix exponential, collisions by
shapely on densely sampled poses, stability by the test-only linear programme over support
distributions on the part and Theorem 4's condition (tests/oracle.py; the plans use the exact
regions by default, larger than STABLE's), scene geometry read straight from the YAML.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import shapely
import yaml

from oracle import LPOracle, Reference, support_samples
from replay import advance, angle_diff, max_point_speed, place, pusher_body

ROOT = Path(__file__).resolve().parent.parent
SCENES = sorted((ROOT / "scenes").glob("*.yaml"))
BIN = Path(sys.executable).parent
SAMPLE = 0.001  # metres any body point moves between replay samples


def obstacle_polygons(spec) -> list[shapely.Polygon]:
    out = []
    for o in spec.get("obstacles") or []:
        if "polygon" in o:
            out.append(shapely.Polygon(o["polygon"]))
        else:
            b = o["box"]
            (cx, cy), (w, h), a = b["center"], b["size"], math.radians(b.get("angle", 0.0))
            c, s = math.cos(a), math.sin(a)
            corners = [(-w / 2, -h / 2), (w / 2, -h / 2), (w / 2, h / 2), (-w / 2, h / 2)]
            out.append(shapely.Polygon([(cx + c * x - s * y, cy + s * x + c * y) for x, y in corners]))
    return out


def degrees_pose(p) -> np.ndarray:
    return np.array([p[0], p[1], math.radians(p[2])])


@pytest.fixture(scope="module", params=SCENES, ids=lambda p: p.stem)
def planned(request, tmp_path_factory):
    scene_path = request.param
    out = tmp_path_factory.mktemp(scene_path.stem)
    run = subprocess.run([str(BIN / "plan"), str(scene_path), "--seed", "1", "--out", str(out)],
                         capture_output=True, text=True, timeout=120, cwd=ROOT)
    spec = yaml.safe_load(scene_path.read_text())
    name = spec.get("name", scene_path.stem)
    return spec, run, out / f"{name}.json", out / f"{name}.rrd"


def test_solves_with_seed_1(planned):
    spec, run, plan_file, _ = planned
    assert run.returncode == 0, run.stderr
    assert run.stdout.startswith("solved:") and len(run.stdout.strip().splitlines()) == 1
    plan = json.loads(plan_file.read_text())
    assert plan["format"] == "stablepush.plan/1" and plan["solved"] is True and plan["seed"] == 1
    assert plan["planning_time_s"] < 10.0


def test_recording_verifies(planned):
    *_, rrd = planned
    rerun = BIN / "rerun"
    if not rerun.exists():
        pytest.skip("rerun CLI not installed")
    check = subprocess.run([str(rerun), "rrd", "verify", str(rrd)], capture_output=True, text=True, timeout=120)
    assert check.returncode == 0, check.stderr


def test_plan_replays(planned):
    spec, run, plan_file, _ = planned
    assert run.returncode == 0, run.stderr
    plan = json.loads(plan_file.read_text())
    verts = np.asarray(spec["slider"]["vertices"], float)
    cf = spec["slider"].get("cf", list(shapely.Polygon(verts).centroid.coords[0]))
    pusher = spec["pusher"]
    obstacles = shapely.union_all(obstacle_polygons(spec))
    lo, hi = spec["workspace"]["min"], spec["workspace"]["max"]
    walls = shapely.box(lo[0] - 1, lo[1] - 1, hi[0] + 1, hi[1] + 1).difference(shapely.box(*lo, *hi))
    blocked = shapely.union_all([obstacles, walls])
    tol = spec.get("tolerance", {})
    pose = degrees_pose(spec["start"])
    np.testing.assert_allclose(plan["start"], pose, atol=1e-9)
    assert plan["segments"], "a solved plan with no push must start at the goal"
    edges = {s["edge"] for s in plan["segments"]}
    assert len(edges) == 1, "one edge per plan"
    for seg in plan["segments"]:
        np.testing.assert_allclose(seg["start"][:2], pose[:2], atol=1e-9)
        assert angle_diff(seg["start"][2], pose[2]) < 1e-9
        edge = seg["edge"]
        # Stability: sticking for every support distribution on the part (re-derived LP), and a
        # turn's centre beyond the part along the edge (Theorem 4).
        ref = Reference(verts, cf, edge, pusher["mu"], width=pusher["width"])
        np.testing.assert_allclose(sorted(map(tuple, seg["contact"])), sorted(map(tuple, [ref.eL, ref.eR])), atol=1e-12)
        v = np.asarray(seg["twist"])
        assert LPOracle(ref, support_samples(verts, 12)).max_violation(v) <= 1e-9, f"push {seg} is not stable"
        if v[2] != 0:
            along = verts @ ref.t
            c_t = np.array([-v[1], v[0]]) / v[2] @ ref.t
            assert (c_t <= along.min()) if v[2] > 0 else (c_t >= along.max()), f"push {seg} may pivot"
        # Motion: the end is start * exp(twist * duration); sample it densely against obstacles.
        body = [verts, pusher_body(verts, edge, pusher["width"], pusher["depth"])]
        speed = max(max_point_speed(b, seg["twist"]) for b in body)
        n = max(2, math.ceil(speed * seg["duration"] / SAMPLE) + 1)
        for t in np.linspace(0.0, seg["duration"], n):
            q = advance(pose, seg["twist"], t)
            placed = shapely.union_all([place(b, q) for b in body])
            # Samples <= SAMPLE apart and clear by more than SAMPLE/2: nothing is crossed between.
            assert placed.distance(blocked) > SAMPLE / 2, f"collision at {q} in push {seg}"
        end = advance(pose, seg["twist"], seg["duration"])
        np.testing.assert_allclose(seg["end"][:2], end[:2], atol=1e-9)
        assert angle_diff(seg["end"][2], end[2]) < 1e-9
        pose = end
    goal = degrees_pose(spec["goal"])
    assert math.dist(pose[:2], goal[:2]) <= tol.get("position", 0.01)
    assert angle_diff(pose[2], goal[2]) <= math.radians(tol.get("angle", 2.0))
    np.testing.assert_allclose(plan["final"][:2], pose[:2], atol=1e-9)
