"""Every shipped scene: `plan` solves it with seed 1, and the plan JSON replays correctly.

The replay shares nothing with the planner: poses by the matrix exponential, collisions by
shapely on densely sampled poses, stability by the test-only linear programme over support
distributions on the part and Theorem 4's condition (tests/oracle.py; the plans use the exact
regions by default, larger than STABLE's), scene geometry read straight from the YAML. Transits
(switches of the pushed edge) are replayed from the README's pusher frame and interpolation.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
import shapely
import yaml

from oracle import Reference, guaranteed_stable
from replay import advance, angle_diff, flush_pose, interpolate, max_point_speed, place, pusher_body, pusher_rectangle

ROOT = Path(__file__).resolve().parent.parent
SCENES = sorted((ROOT / "scenes").glob("*.yaml"))
BIN = Path(sys.executable).parent
SAMPLE = 0.001  # metres any body point moves between replay samples
TURN = math.radians(1.0)  # and the most a transit's pusher turns between them
#: A scene, its ``plan`` run, and the plan and recording files.
Planned = tuple[dict, subprocess.CompletedProcess, Path, Path]


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


def blocked_region(spec) -> shapely.Geometry:
    """The obstacles and everything outside the workspace, where no body may go."""
    lo, hi = spec["workspace"]["min"], spec["workspace"]["max"]
    walls = shapely.box(lo[0] - 1, lo[1] - 1, hi[0] + 1, hi[1] + 1).difference(shapely.box(*lo, *hi))
    return shapely.union_all([*obstacle_polygons(spec), walls])


def degrees_pose(p) -> np.ndarray:
    return np.array([p[0], p[1], math.radians(p[2])])


@pytest.fixture(scope="module")
def plans(tmp_path_factory) -> Callable[[Path], Planned]:
    """``plan --seed 1`` of a scene, run once per scene for the whole module."""
    done: dict[Path, Planned] = {}

    def planned_once(scene_path: Path) -> Planned:
        if scene_path not in done:
            out = tmp_path_factory.mktemp(scene_path.stem)
            run = subprocess.run([str(BIN / "plan"), str(scene_path), "--seed", "1", "--out", str(out)],
                                 capture_output=True, text=True, timeout=120, cwd=ROOT)
            spec = yaml.safe_load(scene_path.read_text())
            name = spec.get("name", scene_path.stem)
            done[scene_path] = spec, run, out / f"{name}.json", out / f"{name}.rrd"
        return done[scene_path]

    return planned_once


@pytest.fixture(params=SCENES, ids=lambda p: p.stem)
def planned(request, plans) -> Planned:
    return plans(request.param)


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
    blocked = blocked_region(spec)
    tol = spec.get("tolerance", {})
    pose = degrees_pose(spec["start"])
    np.testing.assert_allclose(plan["start"][:2], pose[:2], atol=1e-9)
    assert angle_diff(plan["start"][2], pose[2]) < 1e-9  # the file's angles are in [-pi, pi)
    assert plan["segments"], "a solved plan with no push must start at the goal"
    assert plan["segments"][-1]["kind"] == "push", "a transit must lead to a push on its edge"
    edge = None  # the edge the pusher is on, once the plan has placed it
    for seg in plan["segments"]:
        if seg["kind"] == "transit":
            assert edge is None or seg["from_edge"] == edge, f"transit {seg} leaves from another edge than {edge}"
            replay_transit(spec, seg, pose, blocked)
            edge = seg["to_edge"]
            continue  # the part stands still: the next push must start from the same pose
        assert seg["kind"] == "push"
        assert edge is None or seg["edge"] == edge, f"push {seg} is not on edge {edge}, where the pusher is"
        edge = seg["edge"]
        np.testing.assert_allclose(seg["start"][:2], pose[:2], atol=1e-9)
        assert angle_diff(seg["start"][2], pose[2]) < 1e-9
        # Stability: sticking for every support distribution on the part (re-derived LP), and a
        # turn's centre beyond the part along the edge (Theorem 4).
        ref = Reference(verts, cf, edge, pusher["mu"], width=pusher["width"])
        np.testing.assert_allclose(sorted(map(tuple, seg["contact"])), sorted(map(tuple, [ref.eL, ref.eR])), atol=1e-12)
        assert guaranteed_stable(verts, cf, edge, pusher["mu"], pusher["width"], seg["twist"]), \
            f"push {seg} is not stable for every support distribution, or may pivot"
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


def replay_transit(spec: dict, seg: dict, part_pose: np.ndarray, blocked: shapely.Geometry) -> None:
    """Check a transit against the README with the part standing at ``part_pose``: a mode the scene
    allows, flush contact poses at both ends, every in-plane piece clear of obstacles, walls and
    the part (which it touches only at the two ends), and the duration at 1 m/s."""
    verts, pusher = spec["slider"]["vertices"], spec["pusher"]
    allowed = pusher.get("transit", "plane")
    assert allowed in ("plane", "lift"), f"transit {seg} in a scene whose pusher may not switch edges"
    path = np.asarray(seg["pusher_path"], float)
    assert seg["mode"] in ("plane", "lift") and len(path) >= 2
    if seg["mode"] == "lift":
        assert allowed == "lift", f"lift {seg} in a scene whose pusher stays on the table"
        assert len(path) == 4, "a lift is contact, retreat, approach, contact"
    for at, edge in ((path[0], seg["from_edge"]), (path[-1], seg["to_edge"])):
        flush = flush_pose(verts, edge, part_pose)
        np.testing.assert_allclose(at[:2], flush[:2], atol=1e-9, err_msg=f"transit {seg} not flush on edge {edge}")
        assert angle_diff(at[2], flush[2]) < 1e-9, f"transit {seg} not square to edge {edge}"
    part = place(verts, part_pose)
    rectangle = pusher_rectangle(pusher["width"], pusher["depth"])
    reach = math.hypot(pusher["depth"], pusher["width"] / 2)  # the body point farthest from the face centre
    last = len(path) - 2
    duration = 0.0
    for k, (p, q) in enumerate(zip(path, path[1:])):
        shift, turn = math.dist(p[:2], q[:2]), angle_diff(p[2], q[2])
        duration += shift + reach * turn
        if seg["mode"] == "lift" and k == 1:
            continue  # airborne: over everything
        # Between samples no body point moves more than SAMPLE (and the body turns at most TURN);
        # clear by more than SAMPLE/2, nothing is crossed between them.
        n = max(1, math.ceil((shift + reach * turn) / SAMPLE), math.ceil(turn / TURN)) + 1
        for s in np.linspace(0.0, 1.0, n):
            q_s = interpolate(p, q, s)
            body = place(rectangle, q_s)
            assert body.distance(blocked) > SAMPLE / 2, f"pusher collides at {q_s} in transit {seg}"
            gap = body.distance(part)
            if (k, s) in ((0, 0.0), (last, 1.0)):
                assert gap < 1e-9, f"pusher not touching the part at {q_s}, an end of transit {seg}"
            else:
                assert gap > 0, f"pusher touches the part at {q_s} in transit {seg}"
    assert abs(duration - seg["duration"]) <= 1e-9, f"transit {seg} takes {duration} s at 1 m/s"


@pytest.mark.parametrize("scene, mode", [("junction", "plane"), ("narrow_junction", "lift")])
def test_switching_scenes_plan_a_transit(plans, scene, mode):
    """The transit checks of test_plan_replays must not pass vacuously: these scenes cannot be
    solved on one edge, so their plans switch, one walking the pusher round, one lifting it."""
    _, run, plan_file, _ = plans(ROOT / "scenes" / f"{scene}.yaml")
    assert run.returncode == 0, run.stderr
    modes = [s["mode"] for s in json.loads(plan_file.read_text())["segments"] if s["kind"] == "transit"]
    assert mode in modes, f"{scene}: transits {modes}"


@pytest.mark.parametrize("tamper", [
    lambda seg: {**seg, "pusher_path": [[*seg["pusher_path"][0][:2], seg["pusher_path"][0][2] + 1e-6],
                                        *seg["pusher_path"][1:]]},
    lambda seg: {**seg, "to_edge": (seg["to_edge"] + 1) % 4},
    lambda seg: {**seg, "duration": seg["duration"] * (1 + 1e-6)},
    lambda seg: {**seg, "pusher_path": [seg["pusher_path"][0], seg["pusher_path"][-1]]},
    lambda seg: {**seg, "mode": "lift", "pusher_path": [seg["pusher_path"][k] for k in (0, 1, -2, -1)]},
], ids=["first pose turned", "wrong to_edge", "duration", "through the part", "lift in a plane scene"])
def test_transit_replay_catches_a_tampered_transit(plans, tamper):
    """The replay of a transit is strict enough to fail on small or plausible changes of the
    junction plan's walk round the part."""
    spec, run, plan_file, _ = plans(ROOT / "scenes" / "junction.yaml")
    assert run.returncode == 0, run.stderr
    segments = json.loads(plan_file.read_text())["segments"]
    k = next(k for k, s in enumerate(segments) if s["kind"] == "transit")
    part_pose = np.asarray(segments[k - 1]["end"])
    replay_transit(spec, segments[k], part_pose, blocked_region(spec))
    with pytest.raises(AssertionError):
        replay_transit(spec, tamper(segments[k]), part_pose, blocked_region(spec))
