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


def _held_for_blue(swap) -> tuple[loop._Loop, float]:
    """A loop on swap whose pusher is held for the moves left to be re-planned: red, moved first,
    observed on its plan, and blue, waiting, seen 1 cm off its place on CONFIRM observations."""
    from planner.execution.tracker import CONFIRM

    session, plan = swap
    lone = loop._Loop(session, plan, (0.0, 0.0), 1)
    now = 0.0
    for _ in range(CONFIRM):
        assert not lone.observe(now, {"red": lone.tracker.planned(now), "blue": plan.starts["blue"] + [0.01, 0.0, 0.0]})
        now += 0.05
    held, _, rate, _ = lone.pusher_at(now)
    assert lone.pusher_at(now + 1.0)[0] == pytest.approx(held) and not rate.any()
    return lone, now


def test_a_part_hidden_while_the_moves_left_wait_makes_the_pusher_back_off_to_look_then_give_up(swap):
    """Blue hidden (under the arm's hand, say) while the pusher is held: the mean of the parts at
    rest needs it, so the pusher backs off along its own -x to look (as a tracker does), then
    waits; unseen for LOST_PATIENCE s it gives up, saying so, instead of waiting for ever (a tray
    with an arm over an overhead camera waited 289 s so)."""
    from planner.execution.tracker import LOST_PATIENCE, look_back

    lone, now = _held_for_blue(swap)
    held = lone.pusher_at(now)[0]
    hidden = {"blue": "hidden: something taller stands over 80% of where it was"}
    assert not lone.observe(now, {"red": lone.tracker.planned(now)}, lost=hidden, hidden={"blue"})
    back = look_back(lone.tracker.scene, lone.tracker.session.model, held, now)
    end, duration = back.end, back.duration
    assert np.linalg.norm(end[:2] - held[:2]) > 0.01 and end[2] == pytest.approx(held[2])
    assert lone.pusher_at(now + duration / 2)[0][:2] == pytest.approx((held[:2] + end[:2]) / 2)
    assert lone.pusher_at(now + duration)[0] == pytest.approx(end)
    t, ended = now + duration, False
    while not ended and t < now + duration + 2 * LOST_PATIENCE:
        ended = lone.observe(t, {"red": lone.tracker.planned(now)}, lost=hidden, hidden={"blue"})
        t += 0.05
    assert ended and t - (now + duration) == pytest.approx(LOST_PATIENCE, abs=0.11)
    assert lone.reason.startswith("lost track of blue for 3.0 s"), lone.reason


def test_a_part_seen_again_after_backing_off_is_observed_at_rest_and_the_moves_left_re_planned(swap):
    from planner.execution.tracker import SETTLE, look_back

    lone, now = _held_for_blue(swap)
    red, blue = lone.tracker.planned(now), swap[1].starts["blue"] + [0.01, 0.0, 0.0]
    hidden = {"blue": "hidden: something taller stands over 80% of where it was"}
    duration = look_back(lone.tracker.scene, lone.tracker.session.model, lone.pusher_at(now)[0], now).duration
    lone.observe(now, {"red": red}, lost=hidden, hidden={"blue"})
    # While it backs off nothing is taken; from where it stops, blue is seen.
    assert not lone.observe(now + duration / 2, {"red": red, "blue": blue}) and not lone.replans
    now += duration
    for _ in range(SETTLE):
        assert not lone.observe(now, {"red": red, "blue": blue})
        now += 0.05
    (replan,) = lone.replans
    assert replan.why.startswith("blue is off the plan") and replan.plan.solved


def test_a_waiting_part_is_judged_against_its_estimates_noise():
    """Blue, waiting, seen 1.2 degrees off its place on every observation: beyond half the angle
    tolerance (1 degree), so with exact observations the pusher is held for a re-plan; seen through
    a camera whose estimate has a heading deviation of 0.5 degrees, it is within 3 of them (1.5
    degrees), noise to be expected, and the run goes on (a tray's hexagon, whose heading a camera
    estimates to about that, held a run for nothing)."""
    from planner.execution.tracker import CONFIRM

    session = Planner(load_scene(SWAP))
    plan = session.plan(seed=1)
    turned = plan.starts["blue"] + [0.0, 0.0, math.radians(1.2)]
    noise = np.diag([1e-8, 1e-8, math.radians(0.5) ** 2])
    for covariance, held in ((None, True), (noise, False)):
        lone, now = loop._Loop(session, plan, (0.0, 0.0), 1), 0.0
        for _ in range(CONFIRM):
            covariances = None if covariance is None else {"red": noise, "blue": covariance}
            lone.observe(now, {"red": lone.tracker.planned(now), "blue": turned}, covariances=covariances)
            now += 0.05
        rate = lone.pusher_at(now)[2]
        assert (not rate.any() and lone.pusher_at(now + 1.0)[0] == pytest.approx(lone.pusher_at(now)[0])) == held
