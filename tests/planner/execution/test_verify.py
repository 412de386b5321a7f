"""Verification of plans by the independent simulator (planner.execution.verify, ``plan --verify``).

Sources of truth, none of them the code under test: the planner's guarantee (every shipped plan
must stick under every distribution); twists placed just across the boundary of procedure STABLE
(``mechanics.stable_region(...).contains``, found by bisection) that must break; ends recomputed by
the test-only matrix-exponential replay; ``rerun rrd verify`` for the recording.

STABLE's boundary is exact for translations (the load of a translation is a force through the CF
whatever the distribution), so a translation just outside it slips under every distribution. Its
rotation boundaries are conservative (the tip line is moved out by 2 %): a COR a little past them
still sticks for most distributions, and only the extreme dipods and tripods catch one 10 % past.
"""

from __future__ import annotations

import dataclasses
import json
import subprocess
from functools import cache
from pathlib import Path

import numpy as np
import pytest
import shapely
import yaml

import planner
from mechanics import cor_to_twist, point_velocity, stable_region
from planner.cli import main
from planner.model.files import write_atomic
from planner.outputs.recording import write_recording
from planner.execution.verify import distributions, verify
from replay import advance
from test_cli import PLAN, error_field
from test_recording import entities, rrd_rows
from test_recording import verify as rrd_verify

ROOT = Path(__file__).resolve().parents[3]
SCENES = sorted(p.stem for p in (ROOT / "scenes").glob("*.yaml"))


@cache
def planned(name: str) -> tuple[planner.Scene, planner.Plan]:
    scene = planner.load_scene(ROOT / "scenes" / f"{name}.yaml")
    return scene, planner.plan(scene, seed=1)


def one_push(name: str, twist, duration: float = 1.0) -> tuple[planner.Scene, planner.Plan]:
    """The scene's plan cut to its first push, with ``twist`` (end recomputed by the replay), made
    by hand: it claims no stability margin, so only the re-simulation judges it."""
    scene, plan = planned(name)
    first = plan.segments[0]
    segment = dataclasses.replace(first, twist=np.asarray(twist, dtype=float), duration=duration,
                                  end=advance(first.start, twist, duration))
    return scene, dataclasses.replace(plan.with_segments([segment]), margin=None)


def crossing(inside, steps: int = 60) -> float:
    """Bisection on [0, 1] for the switch of ``inside(s)`` (True at 0) to False (at 1)."""
    lo, hi = 0.0, 1.0
    assert inside(lo) and not inside(hi)
    for _ in range(steps):
        mid = (lo + hi) / 2
        lo, hi = (mid, hi) if inside(mid) else (lo, mid)
    return hi


def all_stick(check) -> bool:
    return all(r.sticks for push in check.pushes for r in push.results)


# -- shipped scenes ----------------------------------------------------------------------------------

@pytest.mark.parametrize("name", SCENES)
def test_every_shipped_plan_sticks_under_every_distribution(name):
    scene, plan = planned(name)
    assert plan.solved
    check = verify(scene, plan, n=30, transit=scene.options.transit)
    assert check.passed and all_stick(check), "\n".join(check.lines())
    position, angle = check.worst
    # One exact exponential per step: rounding grows with the distance travelled (a long straight
    # push of a Dubins shortcut composes 200 steps of a metre), so the bound scales with it.
    scale = scene.slider.radius + plan.path_length(scene.slider.cf)
    assert position <= 1e-12 * scale and angle <= 1e-12
    assert max(check.drift) <= 1e-12 * max(1.0, scale)
    # One check per push, in order (the recording maps them onto the push segments); one line per
    # segment, each saying what it is.
    assert [c.segment for c in check.pushes] == [s for s in plan.segments if s.kind == "push"]
    assert [line.split()[:3] for line in check.lines()] == [
        ["segment", f"{n}/{len(plan.segments)}:", s.kind] for n, s in enumerate(plan.segments, 1)]
    assert check.summary().startswith("verify: passed: ")


def test_distributions_mix_kinds_with_centre_at_the_cf_and_depend_on_the_seed_only():
    scene, _ = planned("nonconvex")  # non-convex: dipod and tripod points must still be on the part
    supports, kinds = distributions(scene, 10, seed=3)
    assert kinds == ["grid"] + ["dipod"] * 3 + ["tripod"] * 3 + ["random"] * 3
    assert [len(s.points) for s in supports[1:7]] == [2, 2, 2, 3, 3, 3]
    for s in supports:
        np.testing.assert_allclose(s.centre, scene.slider.cf, atol=1e-9)
        assert scene.slider.polygon.buffer(1e-9).contains(shapely.MultiPoint(s.points))
    again, _ = distributions(scene, 10, seed=3)
    other, _ = distributions(scene, 10, seed=4)
    assert all(np.array_equal(a.points, b.points) for a, b in zip(supports, again))
    assert all(np.array_equal(a.points, b.points) for a, b in zip(supports[:4], other[:4]))  # no randomness
    assert not any(np.array_equal(a.points, b.points) for a, b in zip(supports[4:], other[4:]))
    with pytest.raises(ValueError):
        distributions(scene, 0)
    with pytest.raises(planner.SceneError) as err:  # a bound on the work, named as the flag's field
        distributions(scene, 10**9)
    assert err.value.field == "verify"


# -- twists across STABLE's boundary ----------------------------------------------------------------

@pytest.mark.parametrize("name", ["battery", "parking"])
@pytest.mark.parametrize("side", [1, -1])
def test_translation_just_outside_the_stable_region_slips_for_every_distribution(name, side):
    scene, plan = planned(name)
    edge = plan.segments[0].edge
    region = stable_region(scene.slider, edge, scene.pusher.mu, width=scene.pusher.width)
    n = scene.slider.inward_normal(edge)
    straight, sideways = np.r_[n, 0.0], np.r_[side * n[1], -side * n[0], 0.0]
    s = crossing(lambda s: bool(region.contains((1 - s) * straight + s * sideways)))
    for past, stable in ((-1e-3, True), (1e-3, False)):
        twist = 0.05 * ((1 - s - past) * straight + (s + past) * sideways)
        check = verify(*one_push(name, twist), n=12)
        assert check.passed is stable and all_stick(check) is stable, "\n".join(check.lines())
        if not stable:
            assert not any(r.sticks for r in check.pushes[0].results)


@pytest.mark.parametrize("sense", [1, -1])
def test_rotation_past_the_tip_line_is_caught_by_the_extreme_distributions(sense):
    scene, plan = planned("battery")
    edge, cf, radius = plan.segments[0].edge, scene.slider.cf, scene.slider.radius
    region = stable_region(scene.slider, edge, scene.pusher.mu, width=scene.pusher.width)
    n = scene.slider.inward_normal(edge)
    along = np.array([n[1], -n[0]])
    if point_velocity(cor_to_twist(cf + radius * along, sense), cf) @ n < 0:
        along = -along  # the side from which a rotation of this sense pushes the part forward

    def twist(d: float) -> np.ndarray:  # rotation about the COR at distance d from the CF, along the edge
        v = cor_to_twist(cf + d * along, sense)
        return 0.05 * v / np.linalg.norm(point_velocity(v, cf))

    # COR distance d = radius / u for u in (0, 1]: stable far away (u -> 0), not at the radius.
    u = crossing(lambda u: bool(region.contains(twist(radius / max(u, 1e-12)))))
    inside = verify(*one_push("battery", twist(1.01 * radius / u)), n=60)
    assert inside.passed and all_stick(inside), "\n".join(inside.lines())
    outside = verify(*one_push("battery", twist(0.9 * radius / u)), n=60)
    assert not outside.passed, "\n".join(outside.lines())
    push = outside.pushes[0]
    caught = [outside.kinds[k] for k in np.flatnonzero(push.slipped)]
    assert "dipod" in caught and set(caught) <= {"dipod", "tripod"}, caught  # the grid and random ones stick
    assert outside.kinds[push.worst] in {"dipod", "tripod"} and push.position_error.max() > 1e-3


# -- the deviation metric and plans that do not fit the scene -----------------------------------------

def test_an_end_moved_by_hand_is_reported_as_the_deviation():
    scene, plan = planned("battery")
    segment = plan.segments[0]
    moved = dataclasses.replace(segment, end=segment.end + [1e-3, 0.0, 2e-3])
    check = verify(scene, plan.with_segments([moved]), n=4)
    np.testing.assert_allclose(check.pushes[0].position_error, _cf_shift(scene, segment.end, moved.end), rtol=1e-9)
    np.testing.assert_allclose(check.pushes[0].angle_error, 2e-3, rtol=1e-9)
    assert all_stick(check) and not check.passed  # sticks, but not where the plan says
    turned = dataclasses.replace(segment, end=segment.end + [0.0, 0.0, 2 * np.pi])  # the same pose
    assert verify(scene, plan.with_segments([turned]), n=4).passed


def _cf_shift(scene, a, b) -> float:
    """Distance between the CF placed at poses ``a`` and ``b`` (rotation matrices written out)."""
    def at(q):
        c, s = np.cos(q[2]), np.sin(q[2])
        return np.array([q[0], q[1]]) + np.array([[c, -s], [s, c]]) @ scene.slider.cf
    return float(np.linalg.norm(at(a) - at(b)))


@pytest.mark.parametrize("change, field", [
    ({"edge": 0}, "plan.segments[0].edge"),
    ({"contact": np.array([[-0.02425, -0.01], [-0.02425, 0.0]])}, "plan.segments[0].contact"),
    ({"duration": 0.0}, "plan.segments[0].duration"),
])
def test_a_plan_that_does_not_fit_the_scene_names_the_field(change, field):
    scene, plan = planned("battery")  # pushes edge 3 only, the face at x = -0.02425
    bad = plan.with_segments([dataclasses.replace(plan.segments[0], **change)])
    with pytest.raises(planner.SceneError) as err:
        verify(scene, bad, n=2)
    assert err.value.field == field


# -- transits -----------------------------------------------------------------------------------------

def switching(name: str) -> tuple[planner.Scene, planner.Plan, int]:
    """The scene's seed-1 plan and the index of its first transit (it has one: the scene needs it)."""
    scene, plan = planned(name)
    return scene, plan, next(k for k, s in enumerate(plan.segments) if s.kind == "transit")


@pytest.mark.parametrize("name, mode", [("junction", "plane"), ("narrow_junction", "lift")])
def test_a_switching_plan_verifies_with_a_line_for_its_transit(name, mode):
    scene, plan, k = switching(name)
    transit = plan.segments[k]
    assert transit.mode == mode and plan.segments[k - 1].edge == transit.from_edge != transit.to_edge
    check = verify(scene, plan, n=6, transit=scene.options.transit)
    assert check.passed, "\n".join(check.lines())
    assert check.lines()[k] == (f"segment {k + 1}/{len(plan.segments)}: transit 1/{plan.switches} (edge {transit.from_edge} -> {transit.to_edge}, {mode}, "
                                f"{transit.duration:.3f} s): part still, flush on both edges: ok")


def _moved_path(t, at: int, by=(1e-3, 0.0, 0.0)):
    path = t.pusher_path.copy()
    path[at] += by
    return dataclasses.replace(t, pusher_path=path)


def _lifted(t):
    return dataclasses.replace(t, mode="lift", pusher_path=t.pusher_path[[0, 1, -2, -1]])


# Each: the transit's replacement, the replacement of the push after it, and the field at fault
# (relative to the transit's index k).
TAMPERED = {
    "first pose shifted": (lambda t: _moved_path(t, 0), None, (0, "pusher_path")),
    "first pose turned": (lambda t: _moved_path(t, 0, (0.0, 0.0, 1e-4)), None, (0, "pusher_path")),
    "last pose shifted": (lambda t: _moved_path(t, -1, (0.0, -1e-4, 0.0)), None, (0, "pusher_path")),
    "wrong from_edge": (lambda t: dataclasses.replace(t, from_edge=t.to_edge), None, (0, "from_edge")),
    "to_edge not the path's": (lambda t: dataclasses.replace(t, to_edge=(t.to_edge + 1) % 4), None, (0, "pusher_path")),
    "edge not pushable": (lambda t: dataclasses.replace(t, to_edge=7), None, (0, "to_edge")),
    "lift in a plane scene": (_lifted, None, (0, "mode")),
    "part moved": (lambda t: dataclasses.replace(t, pose=t.pose + [0.0, 1e-3, 0.0]), None, (0, None)),
    "next push on another edge": (None, lambda p, t: dataclasses.replace(p, edge=t.from_edge), (1, "edge")),
    "next push elsewhere": (None, lambda p, t: dataclasses.replace(p, start=p.start + [1e-3, 0.0, 0.0]),
                            (1, "start")),
}


@pytest.mark.parametrize("transit, push, fault", TAMPERED.values(), ids=TAMPERED.keys())
def test_a_transit_that_does_not_join_up_names_the_field(transit, push, fault):
    scene, plan, k = switching("junction")
    segments = list(plan.segments)
    if transit is not None:
        segments[k] = transit(segments[k])
    if push is not None:
        segments[k + 1] = push(segments[k + 1], segments[k])
    offset, field = fault
    with pytest.raises(planner.SceneError) as err:
        verify(scene, plan.with_segments(segments), n=2)
    assert err.value.field == ".".join(filter(None, [f"plan.segments[{k + offset}]", field]))


def test_a_change_of_edge_needs_a_transit():
    scene, plan, k = switching("junction")
    with pytest.raises(planner.SceneError) as err:
        verify(scene, plan.with_segments(plan.segments[:k] + plan.segments[k + 1:]), n=2)
    assert err.value.field == f"plan.segments[{k}].edge" and "needs a transit" in str(err.value)


@pytest.mark.parametrize("allowed, name", [("none", "junction"), ("plane", "narrow_junction")])
def test_a_transit_the_options_do_not_allow_names_its_mode(allowed, name):
    scene, plan, k = switching(name)
    with pytest.raises(planner.SceneError) as err:
        verify(scene, plan, n=2, transit=allowed)
    assert err.value.field == f"plan.segments[{k}].mode" and repr(allowed) in str(err.value)
    assert verify(scene, plan, n=2, transit=scene.options.transit).passed  # the scene's file allows it



def _straight(t):
    """The transit cut to its two contact poses: straight from one edge to the other."""
    return dataclasses.replace(t, pusher_path=t.pusher_path[[0, -1]])


def _flight_on_the_table(t):
    """A lift's four poses (backed off each edge by its standoff) relabelled 'plane'."""
    heading = t.pusher_path[[0, -1], 2]
    back = 0.03 * np.c_[np.cos(heading), np.sin(heading), np.zeros(2)]
    return dataclasses.replace(t, mode="plane", pusher_path=np.array(
        [t.pusher_path[0], t.pusher_path[0] - back[0], t.pusher_path[-1] - back[1], t.pusher_path[-1]]))


def _body_overlap(scene, transit) -> float:
    """Independently of verify: the largest area the pusher's rectangle shares with the part at 21
    poses along each straight piece of ``transit``'s path (shapely, no sweeping)."""
    part = scene.body(scene.part().name, transit.pose)
    w, d = scene.pusher.width / 2, scene.pusher.depth
    worst = 0.0
    for a, b in zip(transit.pusher_path, transit.pusher_path[1:]):
        turn = (b[2] - a[2] + np.pi) % (2 * np.pi) - np.pi
        for t in np.linspace(0, 1, 21):
            x, y, th = a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]), a[2] + t * turn
            c, s_ = np.cos(th), np.sin(th)
            box = shapely.Polygon([(x + c * px - s_ * py, y + s_ * px + c * py) for px, py in
                                   [(-d, -w), (0, -w), (0, w), (-d, w)]])
            worst = max(worst, box.intersection(part).area)
    return worst


@pytest.mark.parametrize("doctor", [_straight, _flight_on_the_table], ids=["cut to its ends", "lift as plane"])
def test_a_transit_whose_pusher_goes_through_the_part_fails(doctor):
    """Issue 41: a transit that joins up (flush at both ends) but whose pusher crosses the part on
    the way used to pass, its pushes being fine."""
    scene, plan, k = switching("junction")
    segments = list(plan.segments)
    segments[k] = doctor(segments[k])
    assert _body_overlap(scene, segments[k]) > 0.1 * scene.pusher.width * scene.pusher.depth
    check = verify(scene, plan.with_segments(segments), n=2)
    assert not check.passed and all(p.passed for p in check.pushes)
    assert check.lines()[k].endswith("the pusher goes through the part: FAILED")
    assert "the pusher goes through the part on 1 segment" in check.summary()


def test_the_pusher_touching_the_part_only_at_its_contacts_is_not_going_through():
    """The planner's own transits walk round the part, touching it only flush at their two ends."""
    for name in ("junction", "narrow_junction"):
        scene, plan, k = switching(name)
        assert not any(verify(scene, plan, n=1, transit=scene.options.transit).moves[0].crossed)


# -- recording ---------------------------------------------------------------------------------------

def test_the_recording_shows_the_worst_run_as_a_ghost(tmp_path):
    scene, plan = planned("parking")
    outline = np.vstack([scene.slider.vertices, scene.slider.vertices[:1]])
    good = tmp_path / "good.rrd"
    write_recording(good, scene, plan, verify(scene, plan, n=6))
    rrd_verify(good)
    assert {"/world/ghost", "/log/verify"} <= entities(good)
    ghost = rrd_rows(good, "/world/ghost", "LineStrips3D:strips", "step")
    slider = dict(rrd_rows(good, "/world/slider", "LineStrips3D:strips", "step"))
    assert len(ghost) <= 10 * plan.pushes + 1
    for frame, strips in ghost:  # a sticking run is the plan itself
        np.testing.assert_allclose(strips[0], slider[frame][0], atol=1e-6)
    # A push beyond the friction cone: the ghost ends where the worst run stopped, not at the plan's end.
    n = scene.slider.inward_normal(plan.segments[0].edge)
    scene, bad = one_push("parking", 0.05 * np.r_[n + 2 * np.array([n[1], -n[0]]), 0.0])
    check = verify(scene, bad, n=6)
    path = tmp_path / "bad.rrd"
    write_recording(path, scene, bad, check)
    rrd_verify(path)
    (_, last), = [row for row in rrd_rows(path, "/world/ghost", "LineStrips3D:strips", "step")][-1:]
    pose = check.pushes[0].results[check.pushes[0].worst].final_pose
    c, s = np.cos(pose[2]), np.sin(pose[2])
    np.testing.assert_allclose(last[0], outline @ np.array([[c, s], [-s, c]]) + pose[:2], atol=1e-6)
    (_, level), = rrd_rows(path, "/log/verify", "TextLog:level")
    assert level == ["WARN"]


# -- command line ------------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def plan_files(tmp_path_factory):
    """The battery plan as written by ``plan``, and a copy whose push is turned sideways beyond the
    friction cone (its end recomputed, so only the mechanics give it away)."""
    folder = tmp_path_factory.mktemp("plans")
    scene, plan = planned("battery")
    good = folder / "good.json"
    write_atomic(good, plan.to_json())
    data = json.loads(plan.to_json())
    segment = data["segments"][0]
    n = scene.slider.inward_normal(segment["edge"])
    twist = np.r_[n + 3 * np.array([n[1], -n[0]]), 0.0] * 0.05
    segment["twist"], segment["end"] = twist.tolist(), advance(segment["start"], twist, segment["duration"]).tolist()
    data["final"] = segment["end"]
    for stale in ("length", "cost", "improvements"):  # the edited push no longer makes them (load_plan says so)
        data.pop(stale)
    bad = folder / "tampered.json"
    bad.write_text(json.dumps(data))
    # A plan is checked against its scene first: the tampered push ends elsewhere, so it is verified
    # in a copy of the scene whose goal is where it ends (the mechanics alone then give it away).
    spec = yaml.safe_load((ROOT / "scenes" / "battery.yaml").read_text())
    spec["goal"] = [*segment["end"][:2], float(np.degrees(segment["end"][2]))]
    (folder / "battery.yaml").write_text(yaml.safe_dump(spec))
    return good, bad


def test_command_verifies_a_good_plan_file_and_exits_0(plan_files, tmp_path):
    good, _ = plan_files
    run = subprocess.run([str(PLAN), str(ROOT / "scenes" / "battery.yaml"), "--verify", "12", "--plan", str(good),
                          "--out", "out"], capture_output=True, text=True, cwd=tmp_path, timeout=60)
    assert run.returncode == 0, run.stderr
    assert run.stderr == ""
    head, push, overall = run.stdout.splitlines()
    assert head.startswith(f"loaded {good}: 1 push, smallest margin friction -") and "-> out/battery.json" in head
    assert push.startswith("segment 1/1: push 1/1 (edge 3,") and push.endswith(": ok") and "12/12 stick" in push
    assert overall.startswith("verify: passed: 1 push x 12 distributions") and "worst deviation" in overall
    assert {p.name for p in (tmp_path / "out").iterdir()} == {"battery.json", "battery.rrd"}
    rrd_verify(tmp_path / "out" / "battery.rrd")


def test_command_exits_3_on_a_tampered_plan(plan_files, tmp_path):
    _, bad = plan_files
    run = subprocess.run([str(PLAN), str(bad.with_name("battery.yaml")), "--verify", "6", "--plan", str(bad),
                          "--out", "out"], capture_output=True, text=True, cwd=tmp_path, timeout=60)
    assert run.returncode == 3, run.stderr
    assert "Traceback" not in run.stderr + run.stdout
    lines = run.stdout.splitlines()
    assert lines[1].endswith(": SLIPS") and "0/6 stick" in lines[1]
    assert lines[2].startswith("verify: FAILED: ") and "worst deviation" in lines[2]


def test_planning_with_verify_prints_the_verdict(tmp_path, capsys):
    assert main([str(ROOT / "scenes" / "battery.yaml"), "--verify", "3", "--out", str(tmp_path)]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].startswith("solved: 1 push,") and lines[-1].startswith("verify: passed: 1 push x 3")


@pytest.mark.parametrize("args, field", [
    (["--verify", "0"], "--verify"),
    (["--verify", "-2"], "--verify"),
    (["--plan", "good.json"], "--plan"),  # a plan file is only read to be verified
    (["--verify", "3", "--plan", "nowhere.json"], "plan"),
    (["--verify", "3", "--plan", "broken.json"], "plan"),
    (["--verify", "3", "--plan", "keyless.json"], "plan.segments"),
    (["--verify", "3", "--plan", "parking.json"], "plan.segments[0].edge"),  # a plan for another scene
], ids=["N 0", "N negative", "--plan alone", "missing file", "not JSON", "no segments", "other scene"])
def test_bad_verify_input_exits_1_with_one_line_and_writes_nothing(args, field, plan_files, tmp_path, monkeypatch,
                                                                     capsys):
    good, _ = plan_files
    (tmp_path / "good.json").write_text(good.read_text())
    (tmp_path / "broken.json").write_text('{"format": ')
    data = json.loads(good.read_text())
    del data["segments"]
    (tmp_path / "keyless.json").write_text(json.dumps(data))
    write_atomic(tmp_path / "parking.json", planned("parking")[1].to_json())
    before = {p.name for p in tmp_path.iterdir()}
    monkeypatch.chdir(tmp_path)
    assert main([str(ROOT / "scenes" / "battery.yaml"), *args]) == 1
    captured = capsys.readouterr()
    assert captured.out == "" and error_field(captured.err) == field
    assert {p.name for p in tmp_path.iterdir()} == before  # no logs/, no outputs


def test_command_verifies_a_switching_plan_file_and_refuses_a_tampered_transit(tmp_path):
    """Through ``plan --verify N --plan FILE``: a transit shows as a line; a transit whose pusher
    does not start flush on the edge it leaves is bad input (exit 1, one line naming the field)."""
    scene, plan, k = switching("junction")
    good = tmp_path / "good.json"
    write_atomic(good, plan.to_json())
    data = json.loads(plan.to_json())
    data["segments"][k]["pusher_path"][0][1] += 1e-3
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(data))
    command = [str(PLAN), str(ROOT / "scenes" / "junction.yaml"), "--verify", "3", "--out"]
    run = subprocess.run([*command, "good", "--plan", str(good)], capture_output=True, text=True, cwd=tmp_path,
                         timeout=60)
    assert run.returncode == 0, run.stderr
    lines = run.stdout.splitlines()[1:-1]
    assert [line.split()[2] for line in lines] == [s.kind for s in plan.segments] and lines[k].endswith(": ok")
    run = subprocess.run([*command, "bad", "--plan", str(bad)], capture_output=True, text=True, cwd=tmp_path,
                         timeout=60)
    assert run.returncode == 1 and run.stdout == ""
    assert error_field(run.stderr) == f"plan.segments[{k}].pusher_path"
    assert not (tmp_path / "bad").exists()


# -- plans of several parts and plans not solved ---------------------------------------------------------

def release(name: str) -> tuple[planner.Scene, planner.Plan]:
    """A multi-part scene and its previous release's plan file (tests/data/release_plans)."""
    scene = planner.load_scene(ROOT / "scenes" / "parts" / f"{name}.yaml")
    return scene, planner.load_plan(ROOT / "tests" / "data" / "release_plans" / f"{name}.json")


def test_a_multi_part_plan_verifies_move_by_move_with_a_line_per_segment():
    scene, plan = release("swap")
    check = verify(scene, plan, n=3)
    assert check.passed and all_stick(check), "\n".join(check.lines())
    lines = check.lines()
    moves = [line for line in lines if line.startswith("move ")]
    assert moves == [f"move {k}/{len(plan.moves)} ({m.part}): clear of the other parts" for k, m in enumerate(plan.moves, 1)]
    segments = [line for line in lines if line.startswith("segment ")]
    assert [line.split()[:3] for line in segments] == [
        ["segment", f"{n}/{len(plan.segments)}:", s.kind] for n, s in enumerate(plan.segments, 1)]
    assert [c.segment for c in check.pushes] == [s for s in plan.segments if isinstance(s, planner.Push)]
    assert check.summary().startswith(f"verify: passed: {plan.pushes} pushes of {len(plan.moves)} moves x 3 ")
    assert check.summary().endswith("every move clear of the other parts")


def test_a_transfer_that_does_not_reach_its_part_names_the_field():
    scene, plan = release("swap")
    k = next(k for k, s in enumerate(plan.segments) if isinstance(s, planner.Transfer))
    move = next(m for m in plan.moves if m.transfer is not None)
    off = dataclasses.replace(move.transfer, pusher_path=move.transfer.pusher_path + [0.0, 1e-3, 0.0])
    moves = [dataclasses.replace(m, transfer=off) if m is move else m for m in plan.moves]
    with pytest.raises(planner.SceneError) as err:
        verify(scene, dataclasses.replace(plan, moves=moves), n=2)
    assert err.value.field == f"plan.segments[{k}].pusher_path" and "starts at" in err.value.problem


def test_a_transfer_straight_through_the_parts_fails_through_the_command(tmp_path):
    """Issue 41: a plan/2 transfer cut to its ends (so straight across both parts) used to pass
    ``--verify`` (exit 0); now the transfer's line names the parts it goes through, exit 3."""
    scene, plan = release("swap")
    data = json.loads(plan.to_json())
    cut = [k for k, s in enumerate(data["segments"]) if s["kind"] == "transfer"]
    for k in cut:
        data["segments"][k]["pusher_path"] = data["segments"][k]["pusher_path"][:: len(data["segments"][k]["pusher_path"]) - 1]
        data["segments"][k]["mode"] = "plane"
    doctored = tmp_path / "doctored.json"
    doctored.write_text(json.dumps(data))
    run = subprocess.run([str(PLAN), str(ROOT / "scenes" / "parts" / "swap.yaml"), "--plan", str(doctored), "--verify", "2",
                          "--out", "out"], capture_output=True, text=True, cwd=tmp_path, timeout=120)
    assert run.returncode == 3, run.stdout + run.stderr
    lines = [line for line in run.stdout.splitlines() if line.startswith("segment ")]
    assert all("the pusher goes through" in lines[k] and lines[k].endswith(": FAILED") for k in cut)
    assert "verify: FAILED" in run.stdout


@pytest.mark.parametrize("edge", [99, -1])
def test_a_transfer_to_an_edge_the_part_has_not_is_one_line(edge, tmp_path, capsys):
    """Issue 41: a plan/2 transfer with to_edge 99 or -1 was a ValueError traceback (the transfer
    was checked before the move's edges)."""
    scene, plan = release("swap")
    data = json.loads(plan.to_json())
    k = next(k for k, s in enumerate(data["segments"]) if s["kind"] == "transfer")
    data["segments"][k]["to_edge"] = edge
    (tmp_path / "bad.json").write_text(json.dumps(data))
    assert main([str(ROOT / "scenes" / "parts" / "swap.yaml"), "--plan", str(tmp_path / "bad.json"), "--verify", "2",
                 "--out", str(tmp_path / "out")]) == 1
    assert error_field(capsys.readouterr().err) == f"plan.segments[{k}]"
    assert not (tmp_path / "out").exists()


def test_a_plan_not_solved_is_refused():
    scene, plan = planned("battery")
    with pytest.raises(planner.SceneError) as err:
        verify(scene, dataclasses.replace(plan, solved=False), n=2)
    assert err.value.field == "plan.solved"
