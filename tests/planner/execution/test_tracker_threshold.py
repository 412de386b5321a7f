"""The tracker's re-plan thresholds (planner.execution.tracker, "When to re-plan"), without MuJoCo:
an 8 x 6 cm box pushed 20 cm straight along a slot whose walls are 3 mm from its long sides, and
the same push in the open.

By hand: the position and heading thresholds are half the default goal tolerance, 5 mm and 1
degree. In the open the sweep (the position's error plus the box's half-diagonal of 5 cm times the
heading's) is never stricter than those two together, 5 mm + 50 mm x 1 degree; in the slot a
deviation may sweep half the 3 mm clearance, 1.5 mm. An observation whose deviation is 1 mm and 0.5
degree raises the heading's to 3 sigma, 1.5 degrees, and the sweep's to 3 x (1 mm + 50 mm x 0.5
degree), 4.31 mm; the position's 3 sigma, 3 mm, is below the tolerance's 5 mm.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from planner import Planner
from planner.execution.tracker import CONFIRM, Tracker
from planner.model.scene_file import parse_scene

GAP = 0.003  # between the box's long sides and the slot's walls, m


def pushed(slot: float | None) -> Tracker:
    """A tracker of the straight push, in the open (``slot`` None) or into a slot whose walls begin
    at x = ``slot`` (and end at 0.25 m, beyond the push's end)."""
    obstacles = [] if slot is None else [
        {"box": {"center": [(slot + 0.25) / 2, side * (0.03 + GAP + 0.01)], "size": [0.25 - slot, 0.02]}}
        for side in (1, -1)]
    scene = parse_scene({
        "name": "slot",
        "slider": {"vertices": [[-0.04, -0.03], [0.04, -0.03], [0.04, 0.03], [-0.04, 0.03]]},
        "pusher": {"width": 0.05, "depth": 0.015, "mu": 0.5, "transit": "none", "edges": [3]},
        "obstacles": obstacles,
        "workspace": {"min": [-0.4, -0.2], "max": [0.4, 0.2]},
        "start": [-0.1, 0.0, 0.0], "goal": [0.1, 0.0, 0.0]})
    session = Planner(scene)
    return Tracker(session, session.plan(seed=1))


@pytest.fixture(scope="module")
def slot() -> Tracker:
    return pushed(-0.25)  # the box starts inside it


@pytest.fixture(scope="module")
def open_table() -> Tracker:
    return pushed(None)


def along(tracker: Tracker) -> np.ndarray:
    """The thresholds at every sample of the plan (the box stays inside the slot's length throughout)."""
    return np.array([tracker.threshold_at(t) for t in tracker.motion.t])


def test_in_the_open_the_thresholds_are_half_the_goal_tolerance(open_table):
    thresholds = along(open_table)
    assert np.allclose(thresholds[:, :2], [0.005, math.radians(1.0)], rtol=0, atol=1e-12)
    assert (thresholds[:, 2] >= 0.005 + 0.05 * math.radians(1.0) - 1e-12).all()


def test_in_a_slot_the_sweep_may_take_half_the_clearance(slot):
    assert np.allclose(along(slot), [0.005, math.radians(1.0), 0.0015], rtol=0, atol=1e-9)


@pytest.mark.parametrize("ahead, sweep", [(0.03, 0.0015), (0.08, None)])
def test_the_room_is_the_least_the_plan_keeps_over_the_part_s_half_diagonal_ahead(ahead, sweep):
    """The box starts outside the slot, its front ``ahead`` short of the walls. 3 cm short, it is in
    the slot before it has moved its 5 cm half-diagonal on: at the start the sweep's threshold is
    already the slot's. 8 cm short, the walls are farther than that, and the room there (3 cm to the
    walls' ends at least) leaves the position's and the heading's thresholds the stricter."""
    tracker = pushed(-0.06 + ahead)  # the box's front starts at x = -6 cm
    first = tracker.threshold_at(0.0)[2]
    if sweep is None:
        assert first >= 0.005 + 0.05 * math.radians(1.0) - 1e-12
    else:
        assert first == pytest.approx(sweep)


def test_a_noisy_observation_raises_them_to_three_sigma(slot, open_table):
    sigma = (0.001, math.radians(0.5))
    raised = (0.005, math.radians(1.5), 3 * (0.001 + 0.05 * math.radians(0.5)))
    covariance = np.diag([0.0004 ** 2, sigma[0] ** 2, sigma[1] ** 2])  # the worst axis counts
    assert slot.threshold_at(1.0, covariance) == pytest.approx(raised)
    # Turned 45 degrees, the same ellipse: its worst axis is still 1 mm.
    turn = np.array([[1.0, -1.0], [1.0, 1.0]]) / math.sqrt(2)
    covariance[:2, :2] = turn @ covariance[:2, :2] @ turn.T
    assert slot.threshold_at(1.0, covariance) == pytest.approx(raised)
    # Without a covariance, the configured noise.
    assert Tracker(slot.session, slot.plan, noise=sigma).threshold_at(1.0) == pytest.approx(raised)


@pytest.mark.parametrize("offset", [(0.0, 0.002, 0.0), (0.0, 0.001, math.radians(0.9))],
                         ids=["2 mm sideways", "1 mm and 0.9 degree"])
def test_a_deviation_within_the_tolerance_stops_the_pusher_in_the_slot_only(slot, open_table, offset):
    """2 mm sideways (a sweep of 2 mm), or 1 mm and 0.9 degree (1 mm + 50 mm x 0.9 degree, 1.8 mm)
    are within half the tolerance but sweep more than half the slot's 3 mm: the third observation
    of it stops the pusher. Not so in the open, nor in the slot for an observer whose deviation
    is 1 mm and 0.5 degree (the sweep's 3 sigma is 4.31 mm)."""
    rate = 10.0

    def kinds(tracker: Tracker, covariance: np.ndarray | None = None) -> list[str]:
        fresh = Tracker(tracker.session, tracker.plan)
        return [str(fresh.observe(k / rate, fresh.expected[fresh._sample(k / rate)] + offset,
                                  covariance=covariance).kind) for k in range(CONFIRM)]

    assert kinds(slot) == ["follow"] * (CONFIRM - 1) + ["stop"]
    assert kinds(open_table) == ["follow"] * CONFIRM
    assert kinds(slot, np.diag([1e-6, 1e-6, math.radians(0.5) ** 2])) == ["follow"] * CONFIRM
