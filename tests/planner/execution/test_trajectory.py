"""Pusher trajectories (planner.execution.trajectory), checked from the CSV they write.

Every check recomputes what it needs from the samples and the plan alone: the pusher's corners
from the scene, the planned path from the plan's twists and transit poses, the time-optimal
profile of a straight push in closed form. Limits are checked by finite differences, with 2 %
for sampling.
"""

from __future__ import annotations

import io
import math
from pathlib import Path
from typing import NamedTuple

import numpy as np
import pytest

from mechanics import exp_twist, relative_pose, wrap_angle
from planner import load_scene, plan
from planner.actions.transit import AIRBORNE, edge_contact_pose, transit_poses
from planner.cli import main
from planner.execution.trajectory import trajectory
from planner.model.bodies import pusher_frame_body
from planner.model.plan import Plan
from planner.model.segments import Push

ROOT = Path(__file__).resolve().parents[3]
SCENES = ROOT / "scenes"
HEADER = "t,x,y,theta,vx,vy,omega,z,contact,segment"
SPEED, ACCEL, JERK, RATE = 0.05, 0.5, 5.0, 100.0
SLACK = 1.02  # finite differences of samples 10 ms apart


class Run(NamedTuple):
    """A plan's trajectory, as read from its CSV: the scene (its pusher), the plan's segments in
    order with the part each moves (transfers of a multi-part plan included), the samples."""

    scene: object
    segments: list
    sliders: list
    rows: np.ndarray
    motion: object
    parts: list  # the CSV's part column (multi-part plans), else []
    owners: list  # the part each segment moves, from the plan (multi-part plans), else []


#: A walk round, a lift, and several parts with a switch and transfers between them.
CASES = ["junction", "narrow_junction", "parts/tray"]


@pytest.fixture(scope="module")
def runs() -> dict:
    """Each case's plan and its trajectory's samples, read from the CSV."""
    out = {}
    for name in CASES:
        scene = load_scene(SCENES / f"{name}.yaml")
        # The tray's seed-1 plan switches edge once at the exact limit (with the default margin it
        # needs no switch): a plan with transits and transfers both.
        result = plan(scene, seed=1, margin=0 if len(scene.parts) > 1 else None)
        assert result.solved
        motion = trajectory(scene, result, SPEED, ACCEL, JERK, RATE)
        segments = result.segments
        sliders = [scene.part(n).slider for n, _ in result.steps]
        if len(scene.parts) > 1:
            assert any(s.kind == "transfer" for s in segments) and any(s.kind == "transit" for s in segments)
        else:
            assert result.switches
        text = motion.to_csv()
        header = text.splitlines()[0]
        assert header == HEADER + (",part" if len(scene.parts) > 1 else "")
        parts = [line.rsplit(",", 1)[1] for line in text.splitlines()[1:]] if "part" in header else []
        owners = [n for n, _ in result.steps] if len(scene.parts) > 1 else []
        out[name] = Run(scene, segments, sliders, np.loadtxt(io.StringIO(text), delimiter=",", skiprows=1,
                                                             usecols=range(10)), motion, parts, owners)
    return out


def corner_positions(scene, rows: np.ndarray) -> np.ndarray:
    """World positions (n, corners, 3) of the pusher's outline corners at each sample."""
    body = pusher_frame_body(scene.pusher.width, scene.pusher.depth)
    c, s = np.cos(rows[:, 3])[:, None], np.sin(rows[:, 3])[:, None]
    x = rows[:, 1:2] + c * body[:, 0] - s * body[:, 1]
    y = rows[:, 2:3] + s * body[:, 0] + c * body[:, 1]
    return np.stack([x, y, np.broadcast_to(rows[:, 7:8], x.shape)], axis=-1)


def corner_velocities(scene, rows: np.ndarray) -> np.ndarray:
    """Planar corner velocities (n, corners, 2) from the velocity columns."""
    body = pusher_frame_body(scene.pusher.width, scene.pusher.depth)
    c, s = np.cos(rows[:, 3])[:, None], np.sin(rows[:, 3])[:, None]
    w = rows[:, 6:7]
    vx = rows[:, 4:5] - w * (s * body[:, 0] + c * body[:, 1])
    vy = rows[:, 5:6] + w * (c * body[:, 0] - s * body[:, 1])
    return np.stack([vx, vy], axis=-1)


@pytest.mark.parametrize("name", CASES)
def test_corners_respect_the_speed_and_acceleration_limits(runs, name):
    scene, rows = runs[name].scene, runs[name].rows
    p, dt = corner_positions(scene, rows), np.diff(rows[:, 0])
    v = np.diff(p, axis=0) / dt[:, None, None]
    assert np.linalg.norm(v, axis=2).max() <= SPEED * SLACK
    assert np.linalg.norm(corner_velocities(scene, rows), axis=2).max() <= SPEED * (1 + 1e-9)
    full = (dt[:-1] > 1e-3) & (dt[1:] > 1e-3)  # the last interval may be very short
    a = np.diff(v, axis=0)[full] / ((dt[:-1] + dt[1:]) / 2)[full, None, None]
    assert np.linalg.norm(a, axis=2).max() <= ACCEL * SLACK


@pytest.mark.parametrize("name", CASES)
def test_velocity_is_continuous_and_matches_the_poses(runs, name):
    scene, rows = runs[name].scene, runs[name].rows
    v, dt = corner_velocities(scene, rows), np.diff(rows[:, 0])
    assert (np.linalg.norm(np.diff(v, axis=0), axis=2).max(axis=1) <= ACCEL * dt * SLACK + 1e-12).all()
    moved = np.diff(corner_positions(scene, rows)[:, :, :2], axis=0)
    mean = (v[1:] + v[:-1]) / 2 * dt[:, None, None]  # the trapezoid rule, exact to O(jerk dt^3)
    assert np.abs(moved - mean).max() <= JERK * dt.max() ** 3


def _push_error(slider, push, pose: np.ndarray) -> tuple[float, float]:
    """How far the pusher pose ``pose`` is from the push's planned pusher path, and its parameter s
    there: s found from the part pose the pusher pose implies."""
    local = edge_contact_pose(slider, push.edge, np.zeros(3))
    theta = pose[2] - local[2]
    c, s = math.cos(theta), math.sin(theta)
    part = np.array([pose[0] - c * local[0] + s * local[1], pose[1] - s * local[0] - c * local[1], theta])
    rel = relative_pose(push.start, part)
    v, w = push.twist[:2], push.twist[2]
    if abs(w) < 1e-12:
        candidates = [float(rel[:2] @ v / (v @ v))]
    else:
        turn = 2 * math.pi / abs(w)
        candidates = [rel[2] / w + m * turn for m in range(-3, 4)]
    best = (math.inf, 0.0)
    for s_ in candidates:
        if -1e-9 <= s_ <= push.duration + 1e-9:
            on = edge_contact_pose(slider, push.edge, exp_twist(push.start, push.twist, s_))
            best = min(best, (max(math.dist(on[:2], pose[:2]), abs(float(wrap_angle(on[2] - pose[2])))), s_))
    return best


def _transit_place(transit, pose: np.ndarray) -> tuple[float, int, float]:
    """How far ``pose`` is from the transit's piecewise-linear path, and the piece and its
    parameter u in [0, 1] where it is nearest."""
    path = np.asarray(transit.pusher_path)
    best = (math.inf, -1, 0.0)
    for k in range(len(path) - 1):
        step = path[k + 1] - path[k]
        step[2] = wrap_angle(step[2])
        d = pose - path[k]
        d[2] = wrap_angle(d[2])
        if math.hypot(*step[:2]) > 1e-12:
            u = float(d[:2] @ step[:2] / (step[:2] @ step[:2]))
        else:
            u = float(d[2] / step[2]) if abs(step[2]) > 1e-12 else 0.0
        u = min(max(u, 0.0), 1.0)
        gap = pose - (path[k] + u * step)
        error = max(math.hypot(*gap[:2]), abs(float(wrap_angle(gap[2]))))
        best = min(best, (error, k, u))
    return best


@pytest.mark.parametrize("name", CASES)
def test_the_csv_numbers_the_segments_from_1_to_their_count_as_the_screen_does(runs, name):
    run = runs[name]
    assert sorted(set(run.rows[:, 9].astype(int))) == list(range(1, len(run.segments) + 1))


def test_the_part_column_names_the_part_each_sample_moves(runs):
    run = runs["parts/tray"]
    assert run.parts == [run.owners[int(k) - 1] for k in run.rows[:, 9]]
    assert set(run.parts) == set(run.scene.names)


@pytest.mark.parametrize("name", CASES)
def test_every_sample_lies_on_the_planned_path(runs, name):
    run = runs[name]
    for row in run.rows[::5]:  # every fifth sample keeps it quick
        k = int(row[9]) - 1  # numbered from 1, as on screen
        segment = run.segments[k]
        if segment.kind == "push":
            error, s = _push_error(run.sliders[k], segment, row[1:4])
        else:
            error = _transit_place(segment, row[1:4])[0]
        assert error <= 1e-9, (row, segment.kind)


@pytest.mark.parametrize("name", CASES)
def test_plan_time_places_each_sample_on_the_plans_own_clock(runs, name):
    """The plan time of a sample is where the plan (and the recording's ``time`` timeline) has the
    pusher there: a push's path parameter, recovered from the pose alone, or the transit time at
    which :func:`transit_poses` (the recording's placing) puts the pusher at the sample's pose."""
    run = runs[name]
    scene, motion = run.scene, run.motion
    clocks = np.concatenate([[0.0], np.cumsum([s.duration for s in run.segments])])
    assert (np.diff(motion.plan_time) >= -1e-12).all()
    assert motion.plan_time[0] == 0.0 and motion.plan_time[-1] == pytest.approx(clocks[-1], abs=1e-9)
    body = pusher_frame_body(scene.pusher.width, scene.pusher.depth)
    for k, segment in enumerate(run.segments):
        rows = np.flatnonzero(motion.segment == k)
        into = motion.plan_time[rows] - clocks[k]
        assert (into >= -1e-12).all() and (into <= segment.duration + 1e-9).all()
        poses = np.column_stack([motion.x, motion.y, motion.theta])[rows]
        if segment.kind == "push":
            found = np.array([_push_error(run.sliders[k], segment, pose)[1] for pose in poses])
            assert np.abs(found - into).max() <= 1e-9
        else:
            placed, _ = transit_poses(segment, body, into)
            gap = placed - poses
            gap[:, 2] = wrap_angle(gap[:, 2])
            assert np.abs(gap).max() <= 1e-9


@pytest.mark.parametrize("name", CASES)
def test_rests_at_the_ends_and_at_every_change_of_segment(runs, name):
    run = runs[name]
    scene, segments, rows = run.scene, run.segments, run.rows
    t, segment = rows[:, 0], rows[:, 9].astype(int) - 1  # the CSV numbers them from 1
    assert t[0] == 0.0 and np.allclose(np.diff(t)[:-1], 1 / RATE) and 0 < t[-1] - t[-2] <= 1 / RATE + 1e-12
    speed = np.linalg.norm(corner_velocities(scene, rows), axis=2).max(axis=1)
    assert speed[0] == 0.0 and speed[-1] <= 1e-12
    change = np.flatnonzero(np.diff(segment)) + 1
    assert len(change) == len(segments) - 1  # every segment of these plans has samples
    # At rest at the change, somewhere between the two samples: neither can be faster than that allows.
    assert (speed[change] <= ACCEL / RATE * SLACK).all() and (speed[change - 1] <= ACCEL / RATE * SLACK).all()
    assert (np.diff(segment) >= 0).all() and segment[0] == 0 and segment[-1] == len(segments) - 1
    kinds = np.array([s.kind == "push" for s in segments])
    assert (rows[:, 8] == kinds[segment]).all()
    first = segments[0]
    assert np.allclose(rows[0, 1:4], edge_contact_pose(run.sliders[0], first.edge, first.start), atol=1e-12)
    last = segments[-1]
    assert _push_error(run.sliders[-1], last, rows[-1, 1:4]) == pytest.approx((0.0, last.duration), abs=1e-9)


def test_a_lift_rises_and_lands_straight_and_flies_at_full_height(runs):
    """Off the table only over the flight's two standoff poses or between them, and moving
    across the table only at full height: the face never swings low over the part it left."""
    segments, rows = runs["narrow_junction"].segments, runs["narrow_junction"].rows
    z = rows[:, 7]
    assert z.min() == 0.0 and z.max() == pytest.approx(0.05, abs=1e-12)
    for row in rows:
        segment = segments[int(row[9]) - 1]  # numbered from 1, as on screen
        if segment.kind == "push" or segment.mode != "lift":
            assert row[7] == 0.0
            continue
        _, piece, u = _transit_place(segment, row[1:4])
        between = piece == AIRBORNE and 1e-9 < u < 1 - 1e-9
        ends = [np.asarray(segment.pusher_path[k]) for k in (AIRBORNE, AIRBORNE + 1)]
        at_an_end = any(np.abs(row[1:4] - e).max() <= 1e-9 for e in ends)
        if between:
            assert row[7] == pytest.approx(0.05, abs=1e-12), (row, u)
        elif row[7] > 0:
            assert at_an_end, row
    assert (np.abs(z - 0.05) <= 1e-12).sum() > 10


def _rest_to_rest_time(length: float, v: float, a: float, j: float) -> tuple[str, float]:
    """The time-optimal jerk-limited rest-to-rest time over ``length``, in closed form."""
    if v >= a * a / j:  # a is reached on the way to v
        if length >= v * (v / a + a / j):
            return "v and a reached", length / v + v / a + a / j
    elif length >= 2 * v * math.sqrt(v / j):
        return "v reached, a not", length / v + 2 * math.sqrt(v / j)
    # v is not reached: peak velocity p below v
    p = a / 2 * (-(a / j) + math.sqrt((a / j) ** 2 + 4 * length / a))
    if p >= a * a / j:
        return "a reached, v not", 2 * (p / a + a / j)
    return "neither reached", 4 * (length / (2 * j)) ** (1 / 3)


@pytest.mark.parametrize("length, jerk, case", [(0.3, 10.0, "v and a reached"), (0.1, 2.0, "v reached, a not"),
                                                (0.004, 50.0, "a reached, v not"),
                                                (0.005, 5.0, "neither reached")])
def test_a_straight_push_takes_the_time_optimal_time(length, jerk, case):
    scene = load_scene(SCENES / "junction.yaml")
    push = Push.along(0, np.array(scene.slider.edge(0)), [0.0, 1.0, 0.0], length, scene.start)  # 1 m/s per unit s
    found, expected = _rest_to_rest_time(length, SPEED, ACCEL, jerk)
    assert found == case
    run = trajectory(scene, Plan.of_part("part", scene.start, scene.goal, [push],
                                         scene=None, solved=True, planner="rrt", seed=1, planning_time_s=0.0), SPEED, ACCEL, jerk)
    assert run.duration == pytest.approx(expected, rel=0.05)


def test_the_command_writes_the_trajectory_of_a_solved_plan_only(tmp_path, capsys):
    assert main([str(SCENES / "junction.yaml"), "--trajectory", "--out", str(tmp_path / "solved")]) == 0
    assert "junction.trajectory.csv" in capsys.readouterr().out
    text = (tmp_path / "solved" / "junction.trajectory.csv").read_text()
    assert text.splitlines()[0] == HEADER and len(text.splitlines()) > 100
    sealed = SCENES / "unreachable" / "sealed.yaml"
    assert main([str(sealed), "--trajectory", "--out", str(tmp_path / "unsolved")]) == 2
    assert {p.name for p in (tmp_path / "unsolved").iterdir()} == {"sealed.json", "sealed.rrd"}
