"""Every shipped scene: `plan` solves it with seed 1, and the plan JSON replays correctly.

The replay shares nothing with the planner: poses by the matrix exponential, collisions by
shapely on densely sampled poses, stability by the test-only linear programme over support
distributions on the part and Theorem 4's condition (tests/oracle.py; the plans use the exact
regions by default, larger than STABLE's), scene geometry read straight from the YAML. Transits
(switches of the pushed edge) are replayed from the README's pusher frame and interpolation.
"""

from __future__ import annotations

import json
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
import yaml

from replay import blocked_region, replay_plan, replay_transit

ROOT = Path(__file__).resolve().parents[3]
SCENES = sorted((ROOT / "scenes").glob("*.yaml"))
BIN = Path(sys.executable).parent
#: A scene, its ``plan`` run, and the plan and recording files.
Planned = tuple[dict, subprocess.CompletedProcess, Path, Path]


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
    assert plan["segments"], "a solved plan with no push must start at the goal"
    replay_plan(spec, plan)


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
