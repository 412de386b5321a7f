"""Squaring a part askew where no flush push has room (planner.execution.squaring, and the
tracker's "Squaring"), without MuJoCo: the 10 x 6 cm block of narrow_junction in a straight
corridor 8.6 cm wide, pushed along it from x = 0.3 m to x = 0 (heading 180 degrees: its front, the
face at its own +x, leads towards -x).

By hand: observed 6 mm towards the north wall and turned 7.5 degrees (heading 187.5), the block's
north-west corner is 1.1 mm from the wall (6 + 30 cos 7.5 + 50 sin 7.5 = 41.9 mm of 43), less than
the 1.46 mm a plan keeps (a fortieth of its 58.3 mm radius): there is no plan from there. Pushed
at its back face the block would turn about the back face's north corner, 0.7 mm from the wall,
and end square 12.3 mm north of the middle: 0.7 mm from the wall. Pushed at its front face it
turns about the front face's south corner, at x = 300 - 50 cos 7.5 + 30 sin 7.5 = 254.3 mm,
y = 6 - 30 cos 7.5 - 50 sin 7.5 = -30.3 mm, and ends square with its centre 50 mm east and 30 mm
north of that corner: at (304.3, -0.3) mm.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from mechanics import Slider, wrap_angle
from planner import Planner
from planner.actions.transit import edge_contact_pose
from planner.execution.squaring import squared
from planner.execution.tracker import CONFIRM, SETTLE, Action, Tracker
from planner.model.scene_file import parse_scene

BLOCK = [[-0.05, -0.03], [0.05, -0.03], [0.05, 0.03], [-0.05, 0.03]]
ASKEW = np.array([0.3, 0.006, math.radians(187.5)])


@pytest.fixture(scope="module")
def corridor() -> Tracker:
    scene = parse_scene({
        "name": "corridor",
        "slider": {"vertices": BLOCK},
        "pusher": {"width": 0.06, "depth": 0.02, "mu": 0.6, "transit": "lift"},
        "obstacles": [{"box": {"center": [0.0, side * (0.043 + 0.0285)], "size": [1.1, 0.057]}} for side in (1, -1)],
        "workspace": {"min": [-0.55, -0.1], "max": [0.55, 0.1]},
        "start": [0.3, 0.0, 180.0], "goal": [0.0, 0.0, 180.0]})
    session = Planner(scene)
    return Tracker(session, session.plan(seed=1), seed=1)


def test_the_squared_pose_keeps_the_far_corner_and_makes_the_face_flush():
    """For any pose, edge and heading: the corner the pusher reaches last stays put, the squared
    edge is square to the push, and the near corner moves the advance along the push."""
    block, rng = Slider(BLOCK), np.random.default_rng(3)
    for _ in range(50):
        pose = np.array([*rng.uniform(-1, 1, 2), rng.uniform(-math.pi, math.pi)])
        edge, heading = int(rng.integers(4)), pose[2] + rng.uniform(-0.3, 0.3)
        square, advance = squared(block, pose, edge, heading)
        push = heading + math.atan2(*block.inward_normal(edge)[::-1])
        along = np.array([math.cos(push), math.sin(push)])

        def corners(p):
            c, s = math.cos(p[2]), math.sin(p[2])
            return [p[:2] + np.array([c * x - s * y, s * x + c * y]) for x, y in block.edge(edge)]

        before, after = corners(pose), corners(square)
        moved = [np.linalg.norm(b - a) for a, b in zip(before, after)]
        far = int(np.argmin(moved))
        assert moved[far] == pytest.approx(0.0, abs=1e-12)
        assert (after[1] - after[0]) @ along == pytest.approx(0.0, abs=1e-12)
        assert (after[1 - far] - before[1 - far]) @ along == pytest.approx(advance, abs=1e-12)
        assert advance >= -1e-12 and square[2] == pytest.approx(float(wrap_angle(heading)))


def observe(tracker: Tracker, t: float, pose: np.ndarray, count: int) -> tuple[float, object]:
    for _ in range(count):
        command = tracker.observe(t, pose)
        t += 0.05
    return t, command


def test_an_askew_part_with_no_plan_is_squared_away_from_the_wall_then_re_planned(corridor):
    t, command = observe(corridor, 0.0, ASKEW, CONFIRM)
    assert command.kind == Action.STOP
    t, command = observe(corridor, t, ASKEW, SETTLE)
    assert command.kind == Action.REPLAN and command.plan.planner == "squaring"
    assert corridor.carried == [] and len(corridor.replans) == 1
    (way,) = command.plan.segments
    square = way.start
    # The front face (at the block's own +x) is pushed: the pusher ends facing +x, flush on it.
    front = int(np.argmax([(a + b)[0] for a, b in (Slider(BLOCK).edge(e) for e in range(4))]))
    assert way.from_edge == front
    c, s = math.cos(math.radians(7.5)), math.sin(math.radians(7.5))
    corner = (0.3 - 0.05 * c + 0.03 * s, 0.006 - 0.03 * c - 0.05 * s)
    assert square[:2] == pytest.approx([corner[0] + 0.05, corner[1] + 0.03], abs=1e-9)
    assert abs(float(wrap_angle(square[2] - math.pi))) < 1e-9
    assert way.pusher_path[-1] == pytest.approx(edge_contact_pose(corridor.scene.slider, front, square))
    assert abs(float(wrap_angle(way.pusher_path[-1][2]))) < 1e-9
    # On the way the part turns against the pusher: not judged, however far off it is seen.
    assert corridor.observe(t, ASKEW + [0.0, -0.01, 0.2]).kind == Action.FOLLOW
    # At the end the part, square, is observed at rest and re-planned from: a plan of pushes now.
    t += corridor.motion.duration + 1.0  # past the squaring, begun after its planning time
    t, command = observe(corridor, t, square, 1 + SETTLE)
    assert command.kind == Action.REPLAN and command.plan.planner != "squaring"
    assert command.plan.segments and len(corridor.replans) == 2
