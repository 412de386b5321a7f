"""The closed loop on a scene of several parts (issue 37): scenes/parts/swap.yaml, whose plan
pushes red aside, blue to red's place, then red to blue's.

Perturbed as the open loop cannot absorb (red started 2 cm / 8 degrees off; blue knocked 2.5 cm /
12 degrees while it is pushed), the open-loop run misses a goal and the closed loop delivers every
part: each move tracked by the one-part tracker, the moves left re-planned from the observed
parts. A part knocked while another is pushed is seen, and the moves left are re-planned for it.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from planner import load_scene
from planner.cli import main
from planner.execution import closed_loop as loop
from planner.execution.mujoco_sim import foot_sets, perturbations, simulate
from planner.queries.session import Planner

pytest.importorskip("mujoco", reason="MuJoCo is not installed: pip install 'stablepush[mujoco]'")

SWAP = str(Path(__file__).resolve().parents[3] / "scenes" / "parts" / "swap.yaml")
#: Red, moved first, started this far off (m, m, rad).
START_ERROR = (0.02, 0.0, math.radians(8))
#: Blue knocked 20 s into the run, while the plan pushes it to red's place (T s, m, m, rad).
KNOCK = (20.0, 0.0, 0.025, math.radians(12))


@pytest.fixture(scope="module")
def swap():
    session = Planner(load_scene(SWAP))
    plan = session.plan(since=session.clock)
    assert plan.solved and [m.part for m in plan.moves] == ["red", "blue", "red"]
    return session, plan


def _delivers_every_part(closed: loop.ClosedLoop) -> loop.ClosedRun:
    (run,) = closed.runs
    assert closed.passed, closed.lines()
    assert run.delivered == {"red": True, "blue": True} and not run.collisions and not run.reason
    assert max(error for error, _ in run.goal_errors.values()) < 0.005
    return run


def test_a_start_error_the_open_loop_misses_with_is_delivered_closed_loop(swap):
    session, plan = swap
    opened = simulate(session.scene, plan, 1, start_error=START_ERROR)
    assert not opened.passed and not opened.runs[0].delivered["red"]
    run = _delivers_every_part(loop.closed_loop(session, plan, 1, start_error=START_ERROR))
    # Red is seen off its plan at once; each move's end re-plans the moves left from the observed parts.
    first, *rest = run.replans
    assert first.time < 1.0 and first.why.startswith("off the plan by 20.0 mm, 8.0 deg")
    assert [r.why for r in rest] == ["red's move is done", "blue's move is done"]
    assert [m.part for m in rest[0].plan.moves] == ["blue", "red"] and [m.part for m in rest[1].plan.moves] == ["red"]
    # The executed path names the part of the move under way, red first and last.
    assert run.executed.part[0] == run.executed.part[-1] == "red" and "blue" in set(run.executed.part)


def test_a_knock_mid_move_the_open_loop_misses_with_is_delivered_closed_loop(swap):
    session, plan = swap
    opened = simulate(session.scene, plan, 1, bumps=[KNOCK])
    assert not opened.passed and not opened.runs[0].delivered["blue"]
    run = _delivers_every_part(loop.closed_loop(session, plan, 1, bumps=[KNOCK]))
    (knocked,) = [r for r in run.replans if r.time > KNOCK[0]][:1]
    assert knocked.time < KNOCK[0] + 1.0 and knocked.why.startswith("off the plan by")


def test_a_part_knocked_while_another_is_pushed_has_the_moves_left_re_planned(swap):
    session, plan = swap
    setup = perturbations(session.scene, plan)
    # Red, left at its buffer pose, is knocked while blue is pushed to red's place: no perturbation
    # of the command does that (a bump knocks the part the pusher is on), so the run is set up here.
    bumps = ((20.0, "red", 0.02, 0.01, 0.2),)
    run = loop._run(session, plan, foot_sets(session.scene, 1)[0], None, setup.starts, bumps, np.zeros(2),
                    np.random.default_rng(1), 1, loop._after_first_move(plan, setup.motion))
    assert run.passed, run.line(1, 1)
    (seen,) = [r for r in run.replans if r.why.startswith("red is off the plan")]
    assert KNOCK[0] < seen.time < KNOCK[0] + 1.0 and [m.part for m in seen.plan.moves] == ["blue", "red"]


def test_the_command_delivers_a_tray_closed_loop_that_it_misses_open_loop(tmp_path, capsys):
    error = ["--sim-start-error", "0.02", "0", "8"]
    assert main([SWAP, "--simulate", "1", *error, "--out", str(tmp_path / "open")]) == 3
    assert "misses the goal: red" in capsys.readouterr().out
    assert main([SWAP, "--simulate", "1", *error, "--closed-loop", "--out", str(tmp_path / "closed")]) == 0
    out = capsys.readouterr().out
    assert "closed loop: passed: 1/1 runs with every part in its goal without collision" in out
    assert "red started at (-0.1300, 0.0000, 8.00 deg)" in out
