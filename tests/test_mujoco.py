"""Whole plans run open-loop in MuJoCo (planner.execution.mujoco_sim, ``plan --simulate``).

The battery's seed-1 plan (one push) is run on a few support distributions: as planned it ends
within the scene's tolerance without slip or collision; with far less pusher friction than planned,
or the centre of pressure moved well off the CF, some run slips or misses the goal (exit 3).
Without MuJoCo, ``--simulate`` is bad input with one line saying how to install it.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from planner import load_scene, plan
from planner.cli import main

ROOT = Path(__file__).resolve().parents[1]
BATTERY = str(ROOT / "scenes" / "battery.yaml")


def test_without_mujoco_simulate_is_one_line_of_bad_input(tmp_path):
    """``import mujoco`` made to fail in a fresh interpreter: the line, exit 1, nothing written."""
    script = f"""
import sys
sys.modules["mujoco"] = None  # an import of it raises ImportError
from planner.cli import main
sys.exit(main([{BATTERY!r}, "--simulate", "2", "--out", {str(tmp_path / 'out')!r}]))
"""
    run = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, cwd=ROOT, timeout=120)
    assert run.returncode == 1
    assert run.stderr.strip() == "plan: error: --simulate: needs MuJoCo: pip install 'stablepush[mujoco]'"
    assert not (tmp_path / "out").exists()


mujoco = pytest.importorskip("mujoco", reason="MuJoCo is not installed: pip install 'stablepush[mujoco]'")


@pytest.fixture(scope="module")
def battery():
    scene = load_scene(BATTERY)
    return scene, plan(scene, seed=1)


def test_the_battery_plan_reaches_the_goal_in_mujoco(battery):
    from planner.execution.mujoco_sim import SLIP, simulate

    scene, result = battery
    simulation = simulate(scene, result, n=3, seed=1)
    assert [r.feet.kind for r in simulation.runs] == ["grid", "extreme", "random"]
    for run in simulation.runs:
        assert run.goal_error[0] <= scene.tolerance_position and run.goal_error[1] <= scene.tolerance_angle
        assert run.in_goal and run.slip <= SLIP and run.collisions == 0
        assert run.deviation < scene.tolerance_position
    assert simulation.passed


def test_plan_simulate_passes_and_writes_a_model_mujoco_reads(tmp_path, capsys):
    model = tmp_path / "battery.xml"
    code = main([BATTERY, "--simulate", "3", "--mjcf", str(model), "--out", str(tmp_path / "out")])
    lines = capsys.readouterr().out.splitlines()
    assert code == 0
    assert [line.split(" (")[0] for line in lines[1:4]] == ["simulate 1/3", "simulate 2/3", "simulate 3/3"]
    assert lines[4].startswith("simulate: passed: 3/3 runs")
    loaded = mujoco.MjModel.from_xml_path(str(model))
    assert loaded.nkey == 1 and loaded.body("part").id > 0 and loaded.body("pusher").id > 0


@pytest.mark.parametrize("flags", [["--sim-mu", "0.01"], ["--sim-cf-offset", "0", "-0.012"]],
                         ids=["friction-far-below-plan", "centre-of-pressure-off-the-cf"])
def test_a_plan_simulated_outside_its_assumptions_fails(tmp_path, capsys, flags):
    code = main([BATTERY, "--simulate", "3", "--out", str(tmp_path / "out"), *flags])
    out = capsys.readouterr().out
    assert code == 3
    assert "simulate: FAILED" in out and ("SLIPS" in out or "misses the goal" in out)
    assert (tmp_path / "out" / "battery.json").is_file()


@pytest.mark.parametrize("argv, field", [(["--sim-mu", "0.5"], "--sim-mu"), (["--simulate", "0"], "--simulate"),
                                         (["--simulate", "1", "--sim-cf-offset", "1", "0"], "--sim-cf-offset")])
def test_bad_simulation_flags_are_bad_input(tmp_path, capsys, argv, field):
    assert main([BATTERY, "--out", str(tmp_path / "out"), *argv]) == 1
    assert capsys.readouterr().err.startswith(f"plan: error: {field}: ")
    assert not (tmp_path / "out").exists()
