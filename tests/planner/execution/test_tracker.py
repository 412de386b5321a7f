"""The closed loop's tracker, without MuJoCo (planner.execution.tracker): synthetic streams of
timed pose observations.

A part observed a known offset from the plan's start makes the tracker stop, settle and re-plan
from exactly that pose (the mean of the settled observations), and the new plan ends in the goal;
a part observed inside a walled pocket the goal is outside of gives up with the certificate's
reason; observations along the plan with 1 mm / 0.5 degree noise finish without a re-plan; a
spent budget is a reason too.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from planner import Planner, load_scene
from planner.actions.transit import edge_contact_pose
from planner.execution.approach import GRAZE, approach, lead_in_pose
from planner.execution.tracker import CONFIRM, SETTLE, Tracker, mean_pose
from planner.execution.trajectory import LIFT_HEIGHT
from planner.model.bodies import slider_at
from planner.model.fields import SceneError
from planner.model.scene_file import parse_scene

ROOT = Path(__file__).resolve().parents[3]
RATE = 10.0  # observations per second


@pytest.fixture(scope="module")
def junction():
    session = Planner(load_scene(ROOT / "scenes" / "junction.yaml"))
    return session, session.plan(seed=1)


def on_plan(tracker: Tracker, now: float) -> np.ndarray:
    """Where the tracker's current plan has the part at ``now`` (its own record, as a perfect perception would see it)."""
    k = min(int(np.searchsorted(tracker.motion.t, now - tracker._since)), len(tracker.motion.t) - 1)
    return tracker.expected[k]


def test_a_known_start_offset_is_re_planned_from_the_observed_pose(junction):
    session, plan = junction
    scene = session.scene
    tracker = Tracker(session, plan, pusher=lead_in_pose(scene, session.model, plan))
    offset = np.array([0.02, -0.015, math.radians(8)])
    observed = scene.start + offset
    kinds = [tracker.observe(k / RATE, observed).kind for k in range(CONFIRM + SETTLE)]
    # Two observations beyond the threshold are not yet a deviation; the third is, and the pusher
    # stops; SETTLE observations at rest later it re-plans.
    assert kinds == ["follow"] * (CONFIRM - 1) + ["stop"] * SETTLE + ["replan"]
    (replan,) = tracker.replans
    assert np.allclose(replan.start, observed) and np.allclose(replan.trigger, observed)
    assert replan.error[0] == pytest.approx(math.hypot(0.02, 0.015)) and replan.error[1] == pytest.approx(offset[2])
    assert np.allclose(replan.plan.start, observed) and scene.within_tolerance(replan.plan.final)
    assert tracker.plan is replan.plan
    # The pusher stopped on its way in, short of the old first contact, and approaches the new
    # plan's first contact from there.
    stopped = (CONFIRM - 1) / RATE
    held, _, _, _ = tracker.pusher_at(stopped)
    pose, height, _, contact = tracker.pusher_at(len(kinds) / RATE - 1 / RATE)
    assert height == 0.0 and not contact and np.allclose(pose, held)
    assert 0 < np.linalg.norm(held[:2] - lead_in_pose(scene, session.model, plan)[:2]) < 0.03
    # The new plan begins once it was found: until then the pusher stays where it stopped.
    begins = replan.time + replan.latency
    waiting, _, rate, _ = tracker.pusher_at(replan.time + replan.latency / 2)
    assert replan.latency > 0 and np.allclose(waiting, held) and not rate.any()
    assert np.linalg.norm(tracker.pusher_at(begins + 0.5)[0][:2] - held[:2]) > 1e-4
    # Followed with the part where the new plan has it, the run ends in the goal with no more re-plans.
    now, last = len(kinds) / RATE, None
    while last not in ("done", "give_up") and now < 100:
        last = tracker.observe(now, on_plan(tracker, now)).kind
        now += 1 / RATE
    assert last == "done" and len(tracker.replans) == 1


def test_noise_alone_does_not_re_plan(junction):
    """1 mm (per axis) and 0.5 degree of noise: the thresholds are never below 3 sigma (3 mm, 1.5
    degrees, and the sweep's 3 x (1 mm + R x 0.5 degree), R the block's half-diagonal; the
    position's is half the tolerance's 1 cm, the larger) and three observations in a row must
    exceed them, so nothing triggers, though the plan passes 1.6 mm from a wall."""
    session, plan = junction
    noise = (0.001, math.radians(0.5))
    tracker = Tracker(session, plan, noise=noise)
    assert tracker.threshold == pytest.approx((0.005, math.radians(1.5)))
    least = min(tracker.threshold_at(t)[2] for t in tracker.motion.t)
    assert least == pytest.approx(3 * (0.001 + math.hypot(0.05, 0.03) * math.radians(0.5)))
    rng = np.random.default_rng(7)
    now, kinds = 0.0, []
    while not kinds or kinds[-1] not in ("done", "give_up"):
        kinds.append(tracker.observe(now, on_plan(tracker, now) + rng.normal(0.0, [noise[0], noise[0], noise[1]])).kind)
        now += 1 / RATE
    assert kinds[-1] == "done" and tracker.replans == []
    assert kinds.count("stop") == SETTLE  # only the final check at rest
    assert len(kinds) > 200  # the whole plan was observed


def test_a_spent_budget_is_the_reason_to_give_up(junction):
    session, plan = junction
    tracker = Tracker(session, plan, budget=0)
    kinds = [tracker.observe(k / RATE, session.scene.start + [0.0, 0.01, 0.0]).kind for k in range(CONFIRM + SETTLE)]
    assert kinds[-1] == "give_up" and tracker.reason == "the re-plan budget (0) is spent"
    assert tracker.observe(5.0, session.scene.start).kind == "give_up"  # and stays so


def test_a_part_knocked_into_a_sealed_pocket_gives_up_with_the_certificate():
    scene = parse_scene({
        "name": "pocket",
        "slider": {"vertices": [[-0.04, -0.03], [0.04, -0.03], [0.04, 0.03], [-0.04, 0.03]]},
        "pusher": {"width": 0.05, "depth": 0.015, "mu": 0.5, "transit": "none", "edges": [3]},
        "obstacles": [{"box": {"center": c, "size": s}} for c, s in (([0.16, 0.25], [0.02, 0.2]), ([0.34, 0.25], [0.02, 0.2]),
                                                                    ([0.25, 0.16], [0.2, 0.02]), ([0.25, 0.34], [0.2, 0.02]))],
        "workspace": {"min": [-0.5, -0.5], "max": [0.5, 0.5]},
        "start": [-0.35, -0.35, 0.0], "goal": [-0.2, -0.35, 0.0]})
    session = Planner(scene)
    tracker = Tracker(session, session.plan(seed=1))
    inside = [0.25, 0.25, 0.0]
    kinds = [tracker.observe(k / RATE, inside).kind for k in range(CONFIRM + SETTLE)]
    assert kinds[-1] == "give_up" and tracker.replans == []
    assert tracker.reason.startswith("the goal is unreachable from the observed pose: component")


def test_bad_arguments_name_their_field(junction):
    session, plan = junction
    for kwargs, field in (({"noise": (-0.001, 0.0)}, "noise"), ({"noise": (math.nan, 0.0)}, "noise"),
                          ({"confirm": 0}, "confirm")):
        with pytest.raises(SceneError) as err:
            Tracker(session, plan, **kwargs)
        assert err.value.field == field
    with pytest.raises(SceneError) as err:
        Tracker(session, plan).observe(0.0, [0.0, math.inf, 0.0])
    assert err.value.field.startswith("pose")


def test_the_mean_of_headings_across_the_cut_is_near_pi():
    assert abs(abs(mean_pose([[0, 0, math.pi - 0.2], [0, 0, -math.pi + 0.1]])[2]) - (math.pi - 0.05)) < 1e-12


def pushing(tracker: Tracker, after: float = 1.0) -> float:
    """A time ``after`` seconds into the plan's first push (on the tracker's clock)."""
    m = tracker.motion
    begins = float(m.t[np.flatnonzero(m.contact)[0]])
    assert m.contact[np.searchsorted(m.t, begins + after)]
    return tracker._since + begins + after


def drifted(tracker: Tracker, now: float, along: float) -> np.ndarray:
    """The planned part pose at ``now`` moved ``along`` metres along the pusher's face (its own y)."""
    pusher, _, _, _ = tracker.pusher_at(now)
    return on_plan(tracker, now) + along * np.array([-math.sin(pusher[2]), math.cos(pusher[2]), 0.0])


def test_a_part_sliding_along_the_pusher_is_re_planned_for_less_friction(junction):
    """The part drifts along the face, 1 mm an observation, while the plan pushes it: slip. The
    re-plan assumes half the planned friction, and says so. A part knocked 12 mm along the face
    in one observation (a jump past the 5 mm threshold) is re-planned for the planned friction."""
    session, plan = junction
    planned = session.scene.pusher.mu
    for offset, mu in ((lambda j: 0.001 * j, planned / 2), (lambda j: 0.012 * (j > 0), planned)):
        tracker = Tracker(session, plan)
        now, j, kinds = pushing(tracker), -1, []
        while not kinds or kinds[-1] in ("follow", "stop"):
            j += kinds[-1:] != ["stop"]  # the part stays where it is once the pusher stops
            kinds.append(tracker.observe(now, drifted(tracker, now, offset(j))).kind)
            now += 1 / RATE
        assert kinds[-1] == "replan" and kinds.count("stop") == SETTLE, tracker.reason
        (replan,) = tracker.replans
        assert replan.mu == mu and ("slid" in replan.why) == (mu < planned)
        assert tracker.session.scene.pusher.mu == mu and replan.plan.solved


def test_where_no_plan_starts_the_pusher_goes_on_with_its_plan_then_looks_again():
    """narrow_junction's block 12 mm along and 12.5 mm across its corridor, turned half a degree,
    is 0.06 mm from the wall (12.5 + 30 cos 0.5 + 50 sin 0.5 = 42.94 mm of 43), less than the
    margin a plan keeps: no plan starts there; and it is turned less than the heading threshold
    (1 degree), so squaring it would not help. The pusher goes on with the plan from where it
    stopped, deaf to the part being off it until it has moved the part's radius on; then a part
    back on the plan is followed to the goal."""
    scene = load_scene(ROOT / "scenes" / "narrow_junction.yaml")
    session = Planner(scene)
    plan = session.plan(seed=1)
    tracker = Tracker(session, plan, pusher=lead_in_pose(scene, session.model, plan))
    askew = scene.start + [0.012, 0.0125, math.radians(-0.5)]
    assert max(session.model.clearance(askew, e) for e in scene.edges) < scene.slider.radius / 40
    kinds = [tracker.observe(k / RATE, askew).kind for k in range(CONFIRM + SETTLE)]
    assert kinds[-1] == "follow" and tracker.replans == [] and not tracker.reason
    ((when, reason),) = tracker.carried
    assert when == (len(kinds) - 1) / RATE and "no room" in reason
    stopped, _, _, _ = tracker.pusher_at(when)
    # Deaf while the pusher moves the part's radius on: the part still off the plan changes nothing.
    now = when + 1 / RATE
    while np.linalg.norm(tracker.pusher_at(now)[0][:2] - stopped[:2]) < 0.9 * scene.slider.radius:
        assert tracker.observe(now, askew).kind == "follow"
        now += 1 / RATE
    last = None
    while last not in ("done", "give_up") and now < 200:
        last = tracker.observe(now, on_plan(tracker, now)).kind
        now += 1 / RATE
    assert last == "done" and tracker.replans == [] and len(tracker.carried) == 1


def test_a_pusher_stopped_in_the_air_over_the_part_comes_down_beside_it_not_on_it():
    """narrow_junction's plan lifts the pusher over the block to its opposite face. Stopped half way
    over (the block seen 8 mm off the plan there), the pusher is held in the air above the block;
    the re-plan's way to the block must keep it up until it is over the standoff pose and come down
    there: wherever it is lower than it was held on that way, the pusher is off the block."""
    scene = load_scene(ROOT / "scenes" / "narrow_junction.yaml")
    session = Planner(scene)
    tracker = Tracker(session, session.plan(seed=1))
    m = tracker.motion
    flight = np.flatnonzero(m.z >= LIFT_HEIGHT - 1e-12)
    middle = m.t[flight[len(flight) // 2]]
    now = 0.0
    while now < middle:
        assert tracker.observe(now, on_plan(tracker, now)).kind == "follow"
        now += 1 / RATE
    off = on_plan(tracker, now) + [0.008, 0.0, 0.0]
    block = slider_at(scene.slider.polygon, off)
    held, height, _, _ = tracker.pusher_at(now)
    assert height == pytest.approx(LIFT_HEIGHT) and slider_at(tracker._body, held).intersects(block)
    kinds = [tracker.observe(now + k / RATE, off).kind for k in range(CONFIRM + SETTLE)]
    assert kinds[-1] == "replan" and tracker.pusher_at(now + 1.0)[1] == pytest.approx(LIFT_HEIGHT)
    m, lower = tracker.motion, tracker.motion.z < height - 1e-9
    assert lower.any() and m.z[0] == pytest.approx(height)
    body = tracker._body.buffer(-GRAZE, join_style="mitre")
    for k in np.flatnonzero(lower & (m.segment == 0)):  # the way to the block, before any push
        assert not slider_at(body, [m.x[k], m.y[k], m.theta[k]]).intersects(block), m.t[k]


def test_where_the_arm_lifts_the_pusher_is_lifted_over_to_a_face_it_cannot_walk_to():
    """In narrow_junction's corridor the pusher cannot walk round the block (transit: lift): from
    the face it pushes, the way to the opposite face is a lift. Its two moves on the table are
    clear of the walls, it lands at the standoff in front of that face and moves in flush."""
    scene = load_scene(ROOT / "scenes" / "narrow_junction.yaml")
    session = Planner(scene)
    edges = list(scene.edges)
    pushed, opposite = 1, 3  # the block's two ends (its +x and -x faces), across it along the corridor
    at = edge_contact_pose(scene.slider, pushed, scene.start)
    way = approach(scene, session.model, session.world.transits, at, scene.start, opposite, edges)
    assert way is not None and way.mode == "lift"
    path = np.asarray(way.pusher_path)
    contact = edge_contact_pose(scene.slider, opposite, scene.start)
    assert np.allclose(path[0], at) and np.allclose(path[-1], contact)
    assert all(session.model.pusher_clearance(p) > 0 for p in path)
    # Backed straight off the face it left; landed in front of the new one, facing it.
    assert np.isclose(path[1][2], at[2]) and np.isclose(path[2][2], contact[2])
    assert 0 < np.linalg.norm(path[2][:2] - contact[:2]) <= 0.02


def test_an_approach_to_an_edge_the_transits_do_not_serve_goes_straight_and_does_not_fail():
    """After slip the tracker re-plans with less friction, where the edge the pusher was on may push
    no stable push and the session's transits not know it (an L part in a random scene once raised
    a KeyError there): the approach to it is then tried without the walk round."""
    from planner.actions.transit import TransitPlanner

    scene = load_scene(ROOT / "scenes" / "junction.yaml")
    session = Planner(scene)
    served = list(session.stable_edges)
    target = served[-1]
    fewer = TransitPlanner(scene, served[:-1], session.model, 0.001, "plane")
    assert target not in fewer.edges
    at = edge_contact_pose(scene.slider, target, scene.start)
    backed = at.copy()
    backed[:2] -= 0.05 * np.array([np.cos(at[2]), np.sin(at[2])])  # 5 cm behind the contact, facing it
    way = approach(scene, session.model, fewer, backed, scene.start, target, served[:-1])
    assert way is not None and np.allclose(way.pusher_path[-1], at)
