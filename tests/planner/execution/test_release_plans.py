"""Plan files written by the previous release (``tests/data/release_plans``: plan/1 of parking and
junction, plan/2 of swap and channel, made with seed 1 before scenes and plans had one model)
still load, fit their scenes, verify, simulate, and replay through the independent replay
(tests/replay.py)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
import yaml

from planner import load_plan, load_scene, verify
from planner.execution.fit import fit_plan
from replay import replay_parts_plan, replay_plan

ROOT = Path(__file__).resolve().parents[3]
DATA = Path(__file__).resolve().parents[2] / "data" / "release_plans"
FILES = {"parking": "scenes/parking.yaml", "junction": "scenes/junction.yaml", "swap": "scenes/parts/swap.yaml",
         "channel": "scenes/parts/channel.yaml"}


@pytest.mark.parametrize("name", sorted(FILES))
def test_a_release_plan_file_loads_fits_verifies_and_replays(name):
    scene = load_scene(ROOT / FILES[name])
    text = (DATA / f"{name}.json").read_text()
    data = json.loads(text)
    loaded = load_plan(DATA / f"{name}.json")
    assert loaded.names == scene.names and loaded.solved
    assert loaded.to_dict() == data  # what the previous release wrote is what this one writes of it
    fitted = fit_plan(scene, loaded)
    assert fitted.cost == pytest.approx(data["cost"], abs=1e-9)
    spec = yaml.safe_load((ROOT / FILES[name]).read_text())
    (replay_plan if len(scene.parts) == 1 else replay_parts_plan)(spec, data)
    assert verify(scene, fitted, n=3).passed


@pytest.mark.parametrize("name", ["parking", "swap"])
def test_a_release_plan_file_runs_in_mujoco_through_the_command(name, tmp_path, capsys):
    """A plan/1 and a plan/2 file of the previous release, given with ``--plan``, simulate and pass
    (exit 0), the plan file written back as it was read but for where it was run from."""
    pytest.importorskip("mujoco")
    from planner.cli import main

    out = tmp_path / "out"
    assert main([str(ROOT / FILES[name]), "--plan", str(DATA / f"{name}.json"), "--simulate", "1",
                 "--out", str(out)]) == 0
    assert "simulate: passed: 1/1 runs" in capsys.readouterr().out
    written = json.loads(next(out.glob("*.json")).read_text())
    assert written["format"] == json.loads((DATA / f"{name}.json").read_text())["format"]
