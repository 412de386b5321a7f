"""Perturbed runs in MuJoCo, open and closed loop (``plan --simulate N --sim-start-error ...
--closed-loop``; planner.execution.closed_loop).

Bad perturbations are one line of bad input naming the flag, exit 1, nothing written. On the
junction, the part starting 2 cm / -1.5 cm / 8 degrees off the plan's start misses the goal open
loop (exit 3) and reaches it closed loop after one re-plan (exit 0).
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest

from planner.cli import main
from test_recording import entities, rrd_rows

ROOT = Path(__file__).resolve().parents[3]
JUNCTION = str(ROOT / "scenes" / "junction.yaml")
BATTERY = str(ROOT / "scenes" / "battery.yaml")

pytest.importorskip("mujoco", reason="MuJoCo is not installed: pip install 'stablepush[mujoco]'")


@pytest.mark.parametrize("argv, flag", [
    (["--simulate", "1", "--sim-pose-noise", "-0.001", "0.5"], "--sim-pose-noise"),
    (["--simulate", "1", "--sim-start-error", "nan", "0", "0"], "--sim-start-error"),
    (["--simulate", "1", "--sim-bump", "1", "inf", "0", "0"], "--sim-bump"),
    (["--simulate", "1", "--sim-bump", "-1", "0", "0", "0"], "--sim-bump"),
    (["--closed-loop"], "--closed-loop"),
    (["--sim-start-error", "0.01", "0", "0"], "--sim-start-error"),
    # 5 cm north puts the block into the corridor's north wall.
    (["--simulate", "1", "--sim-start-error", "0", "0.05", "0"], "--sim-start-error"),
], ids=["negative-noise", "nan-start-error", "infinite-bump", "bump-before-the-run", "closed-loop-alone",
        "start-error-alone", "start-error-into-a-wall"])
def test_bad_perturbations_are_one_line_of_bad_input(tmp_path, capsys, argv, flag):
    assert main([JUNCTION, "--out", str(tmp_path / "out"), *argv]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith(f"plan: error: {flag}: ")
    assert not (tmp_path / "out").exists()


def test_a_pose_noise_of_minus_zero_is_no_noise():
    """Issue 41: -0 passed the ">= 0" check and then failed in numpy ("scale < 0"), a traceback."""
    from planner.cli import read_inputs

    noise = read_inputs([BATTERY, "--simulate", "1", "--closed-loop", "--sim-pose-noise", "-0", "-0"]).options.pose_noise
    assert noise == (0.0, 0.0) and all(math.copysign(1.0, v) == 1.0 for v in noise)


def test_a_bump_after_the_run_is_bad_input_once_the_plan_says_how_long_it_is(tmp_path, capsys):
    assert main([BATTERY, "--simulate", "1", "--sim-bump", "1000", "0.01", "0", "0", "--out", str(tmp_path / "out")]) == 1
    err = capsys.readouterr().err
    assert re.fullmatch(r"plan: error: --sim-bump: time 1000 s is outside the run \(0 to [\d.]+ s\)\n", err)
    assert not (tmp_path / "out").exists()


def test_a_start_error_the_open_loop_carries_to_the_end_is_recovered_closed_loop(tmp_path, capsys):
    error = ["--sim-start-error", "0.02", "-0.015", "8"]
    assert main([JUNCTION, "--simulate", "1", *error, "--out", str(tmp_path / "open")]) == 3
    out = capsys.readouterr().out
    assert "misses the goal" in out and "simulate: FAILED: 0/1" in out
    assert main([JUNCTION, "--simulate", "1", *error, "--closed-loop", "--trajectory", "--out", str(tmp_path / "closed")]) == 0
    out = capsys.readouterr().out
    summary = next(line for line in out.splitlines() if line.startswith("closed loop:"))
    assert summary.startswith("closed loop: passed: 1/1 runs in the goal") and " 1 re-plan," in summary
    assert "the part started at (-0.3800, -0.0150, 8.00 deg)" in summary  # rounded, not float noise
    (trigger,) = re.findall(r"triggered by t=([\d.]+) s", out)
    latency = float(re.search(r"latency median (\d+) ms", summary).group(1)) / 1000
    # The executed pusher path starts behind the planned first contact and is where the pusher was.
    executed = np.loadtxt(tmp_path / "closed" / "junction.executed.csv", delimiter=",", skiprows=1)
    planned = np.loadtxt(tmp_path / "closed" / "junction.trajectory.csv", delimiter=",", skiprows=1)
    assert executed[0, 1] < planned[0, 1] - 0.02 and executed[0, 2] == pytest.approx(planned[0, 2])
    assert set(executed[:, 9].astype(int)) == {1, 2}  # the first plan, then the re-plan (numbered from 1)
    # Simulated time runs on while the tracker plans: the pusher, stopped, is held still for the
    # planning's latency after the re-plan, then moves.
    assert np.allclose(np.diff(executed[:, 0]), 0.01)
    after = executed[executed[:, 9] == 2]
    moved = after[np.abs(after[:, 1:4] - after[0, 1:4]).max(axis=1) > 1e-9]
    assert after[0, 0] == pytest.approx(float(trigger), abs=0.011)
    assert moved[0, 0] >= float(trigger) + latency - 0.02
    # The recording draws the run: the part at its perturbed start, the re-plan where it was
    # planned from and when, and the pusher's executed path.
    rrd = tmp_path / "closed" / "junction.rrd"
    assert {"/world/closed_loop/1/part", "/world/closed_loop/1/pusher_path",
            "/world/closed_loop/1/replan/1", "/world/closed_loop/1/replan/1/start"} <= entities(rrd)
    (when, first), *_ = rrd_rows(rrd, "/world/closed_loop/1/part", "LineStrips3D:strips", "time")
    start = np.array([-0.38, -0.015, math.radians(8)])
    corners = np.array([[-0.05, -0.03], [0.05, -0.03], [0.05, 0.03], [-0.05, 0.03]])  # junction.yaml's block
    rotation = np.array([[math.cos(start[2]), -math.sin(start[2])], [math.sin(start[2]), math.cos(start[2])]])
    assert when == 0 and np.allclose(np.array(first[0])[:4], corners @ rotation.T + start[:2], atol=1e-6)
    ((when, marker),) = rrd_rows(rrd, "/world/closed_loop/1/replan/1/start", "Points3D:positions", "time")
    assert when / 1e9 == pytest.approx(float(trigger), abs=0.005)
    assert np.allclose(marker[0], start[:2], atol=1e-3)  # the block's centre is its CF; it had not moved yet
    path = rrd_rows(rrd, "/world/closed_loop/1/pusher_path", "LineStrips3D:strips", "time")
    assert np.allclose(path[-1][1][0][-1], executed[-1, 1:3], atol=1e-9)
