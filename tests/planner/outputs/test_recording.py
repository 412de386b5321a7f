"""The rerun recording of a plan (planner.outputs.recording), read back from the file.

Sources of truth, none of them the code under test: ``rerun rrd verify`` for the file format; the
scene's own numbers (the YAML written here) and poses applied to the slider's vertices by the
rotation written out below; and a rigid-body fact: while a part turns about a centre of rotation,
that centre stays put in the world.
"""

from __future__ import annotations

import math
import os
import shutil
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pyarrow as pa
import pytest
import shapely
from rerun.chunk import RrdReader

import planner
from mechanics import exp_twist
from planner.actions.margins import smallest, with_margins
from planner.actions.region_cache import RegionCache
from planner.model.segments import Push, Transfer
from planner.outputs import analysis, frames, recording

RERUN = Path(sys.executable).parent / "rerun"

SLIDER = [[-0.04, -0.03], [0.04, -0.03], [0.04, 0.03], [-0.04, 0.03]]
TRIANGLE = [[0.2, 0.1], [0.3, 0.1], [0.25, 0.18]]
BOX = {"center": [0.0, -0.15], "size": [0.1, 0.04], "angle": 30.0}
COR = [0.0, 0.15]  # inside edge 3's CCW stable region (mu = 0.5): a stable turn about it
TURN_START = [0.02, -0.03, math.radians(20.0)]
TURN = math.radians(30.0)

STATIC = {"/world", "/log", "/world/workspace", "/world/obstacles", "/world/start", "/world/goal", "/world/tree",
          "/world/transits", "/world/transfers"}
ANIMATED = {"/world/slider", "/world/pusher", "/world/pusher_lifted", "/world/cf_path", "/world/cor"}
ANALYSIS = {"/analysis", "/analysis/part", "/analysis/contact", "/analysis/cor", "/analysis/stable/ccw", "/analysis/stable/cw",
            "/analysis/exact/ccw", "/analysis/exact/cw"} | {
            f"/analysis/sticking/{side}/{s}" for side in ("ccw", "cw") for s in "PUI"}


def write_scene(folder: Path, name: str, goal: list[float], start: list[float] = (0.0, 0.0, 0.0)) -> planner.Scene:
    # Edge 3 is the face at x = -0.04; pushing it drives the part along +x.
    text = f"""
name: {name}
slider:
  vertices: {SLIDER}
pusher: {{width: 0.05, depth: 0.015, mu: 0.5, edges: [3]}}
obstacles:
  - polygon: {TRIANGLE}
  - box: {{center: {BOX['center']}, size: {BOX['size']}, angle: {BOX['angle']}}}
workspace: {{min: [-0.2, -0.25], max: [0.35, 0.25]}}
start: [{", ".join(repr(float(v)) for v in start)}]
goal: [{", ".join(repr(float(v)) for v in goal)}]
planner: {{time_limit: 1.0}}
"""
    path = folder / f"{name}.yaml"
    path.write_text(text)
    return planner.load_scene(path)


def placed(points, pose) -> np.ndarray:
    """``points`` (body frame) at ``pose = (x, y, theta)``: rotate by theta, then translate."""
    x, y, theta = pose
    rot = np.array([[math.cos(theta), -math.sin(theta)], [math.sin(theta), math.cos(theta)]])
    return np.asarray(points, dtype=float) @ rot.T + [x, y]


def closed(points) -> np.ndarray:
    p = np.asarray(points, dtype=float)
    return np.vstack([p, p[:1]])


def column(batch: pa.RecordBatch, name: str) -> list:
    """A column as Python values; durations as integer nanoseconds (timedelta has only µs)."""
    values = batch.column(batch.schema.names.index(name))
    return (values.cast(pa.int64()) if pa.types.is_duration(values.type) else values).to_pylist()


def rrd_rows(path: Path, entity: str, component: str, timeline: str | None = None) -> list[tuple]:
    """[(time, value)] of one component of one entity, over all chunks, sorted (docs/stack.md, "Reading recordings")."""
    rows = []
    for chunk in RrdReader(str(path)).store().stream():
        if chunk.entity_path != entity:
            continue
        batch = chunk.to_record_batch()
        names = batch.schema.names
        if component not in names:
            continue
        values = column(batch, component)
        if component in FLAT:  # drawn flat on the table: the plane's points, the height checked
            values = [flat(v) for v in values]
        index = column(batch, timeline) if timeline in names else [None] * len(values)
        rows += zip(index, values)
    return sorted(rows, key=lambda r: (r[0] is not None, r[0] or 0))


#: Components of points in the table's plane, read back as 2-D points.
FLAT = {"LineStrips3D:strips", "Points3D:positions"}


def flat(value):
    """A (nested) list of 3-D points as 2-D points, checking each lies within 5 mm of the table."""
    if value and isinstance(value[0], (int, float)):
        assert len(value) == 3 and abs(value[2]) <= 0.005, value
        return value[:2]
    return [flat(v) for v in value]


def entities(path: Path) -> set[str]:
    return {chunk.entity_path for chunk in RrdReader(str(path)).store().stream()} - {"/__properties"}


def summary_rows(path: Path) -> list[str]:
    """The summary panel's rows as the viewer lists them: ``/log``'s text on the ``time`` timeline."""
    rows = rrd_rows(path, "/log", "TextLog:text", "time")
    assert rows and all(t == 0 for t, _ in rows)  # on the timeline (a static row is not listed)
    return [text for _, (text,) in rows]


def verify(path: Path) -> None:
    if not RERUN.exists():
        pytest.skip(f"no rerun CLI next to {sys.executable}")
    done = subprocess.run([str(RERUN), "rrd", "verify", str(path)], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr


@pytest.fixture(scope="module")
def straight(tmp_path_factory):
    """A one-step plan: a straight push along edge 3's normal, recorded."""
    folder = tmp_path_factory.mktemp("straight")
    scene = write_scene(folder, "straight", [0.12, 0.0, 0.0])
    plan = planner.plan(scene)
    assert plan.solved and plan.pushes == 1
    recording.write_recording(folder / "straight.rrd", scene, plan)
    return scene, plan, folder / "straight.rrd"


@pytest.fixture(scope="module")
def turn(tmp_path_factory):
    """A one-step plan: a 30 degree CCW turn about ``COR`` (slider frame), recorded."""
    folder = tmp_path_factory.mktemp("turn")
    centre = placed([COR], TURN_START)[0]
    goal = [*placed([TURN_START[:2] - centre], [*centre, TURN])[0], TURN_START[2] + TURN]
    scene = write_scene(folder, "turn", [goal[0], goal[1], math.degrees(goal[2])],
                        [TURN_START[0], TURN_START[1], math.degrees(TURN_START[2])])
    plan = planner.plan(scene)
    assert plan.solved and plan.pushes == 1
    recording.write_recording(folder / "turn.rrd", scene, plan)
    return scene, plan, folder / "turn.rrd"


def test_the_file_is_complete_and_has_every_entity(straight):
    _, plan, path = straight
    verify(path)
    assert entities(path) == STATIC | ANIMATED | ANALYSIS
    assert RrdReader(str(path)).recordings()[0].recording_id == f"straight-{plan.planner}-seed1"


def test_the_file_opens_in_its_own_layout(straight):
    """The viewer takes the recording's blueprint (the world view named after the scene, the
    pushed edge's view, the summary) only if the file activates it: a default alone is overridden
    by the layout the viewer makes up as the data arrives first (seen in the web viewer)."""
    if not RERUN.exists():
        pytest.skip(f"no rerun CLI next to {sys.executable}")
    _, _, path = straight
    shown = subprocess.run([str(RERUN), "rrd", "print", "-vvv", str(path)], capture_output=True, text=True,
                           timeout=60).stdout
    assert "make_active: true, make_default: true" in shown
    assert all(name in shown for name in ("straight", "pushed edge (slider frame)", "summary"))


def blueprint_rows(path: Path) -> dict[str, dict[str, list]]:
    """The recording's blueprint as the viewer reads it: per blueprint entity, its components."""
    reader = RrdReader(str(path))
    (store,) = reader.blueprints()
    out: dict[str, dict[str, list]] = {}
    for chunk in reader.store(store=store).stream():
        batch = chunk.to_record_batch()
        out.setdefault(chunk.entity_path, {}).update(
            {n: column(batch, n)[-1] for n in batch.schema.names if ":" in n})
    return out


def test_the_viewer_shows_the_plan_from_above_y_up_beside_a_summary(straight):
    """Both spatial views look straight down with y up (the world one at the workspace's middle),
    the summary panel lists the plan's rows, and only the moving entities are on the timelines."""
    scene, plan, path = straight
    views = blueprint_rows(path)
    kinds = {v["ViewBlueprint:space_origin"][0]: v["ViewBlueprint:class_identifier"][0]
             for v in views.values() if "ViewBlueprint:class_identifier" in v}
    assert kinds == {"/world": "3D", "/analysis": "3D", "/log": "TextLog"}
    eyes = {e.rsplit("/", 1)[0]: v for e, v in views.items() if e.endswith("/EyeControls3D")}
    targets = []
    for view, eye in eyes.items():
        (up,), (target,), (position,) = (eye[f"EyeControls3D:{k}"] for k in ("eye_up", "look_target", "position"))
        assert up == [0.0, 1.0, 0.0] and target[2] == 0.0 and position[2] > 0
        assert position[:2] == pytest.approx(target[:2])  # straight down
        targets.append(target[:2])
    assert len(eyes) == 2 and [0.075, 0.0] in [pytest.approx(t, abs=1e-6) for t in targets]  # the workspace's middle
    # The one push: 0.12 m along +x, every point at the same speed, no switch.
    assert summary_rows(path) == ["straight: planner rrt, seed 1: solved with 1 push",
                                  "CF path length 0.1200 m; cost 0.1200 m (length + 0.25 m per switch)",
                                  "push time 0.1200 s (every point of the pusher at most 1 m/s)",
                                  "stability margin friction -10 %, CF within 2 % of the part radius (>= 1 mm)",
                                  f"search tree: {len(plan.tree)} edges"]
    timelines = {}
    for chunk in RrdReader(str(path)).store().stream():
        names = set(chunk.to_record_batch().schema.names)
        timelines.setdefault(chunk.entity_path, set()).update(names & {"step", "time"})
    assert all(timelines[e] == {"step", "time"} for e in ANIMATED | {"/log"})
    assert all(not timelines[e] for e in (STATIC | ANALYSIS) - {"/log"})


def test_the_slider_moves_from_the_start_to_the_plans_final_pose(straight, turn):
    for scene, plan, path in (straight, turn):
        rows = rrd_rows(path, "/world/slider", "LineStrips3D:strips", "step")
        assert [t for t, _ in rows] == list(range(len(rows)))
        assert 10 <= len(rows) <= frames.MAX_FRAMES
        outlines = np.array([strips[0] for _, strips in rows])
        # Smooth: no vertex jumps more than a twentieth of the part's radius (0.05) between frames.
        assert np.linalg.norm(np.diff(outlines, axis=0), axis=-1).max() <= 0.05 / 20 + 1e-6
        first, last = outlines[0], outlines[-1]
        np.testing.assert_allclose(first, closed(placed(SLIDER, scene.start)), atol=1e-5)
        np.testing.assert_allclose(last, closed(placed(SLIDER, plan.final)), atol=1e-5)
        np.testing.assert_allclose(last, closed(placed(SLIDER, scene.goal)), atol=1e-5)
        cf = rrd_rows(path, "/world/cf_path", "LineStrips3D:strips", "step")
        np.testing.assert_allclose(cf[-1][1][0][-1], plan.final[:2], atol=1e-5)  # the CF is the centroid (0, 0)
        assert len(cf[-1][1][0]) == len(rows)
        times = [t for _, t in rrd_rows(path, "/world/slider", "time", "step")]
        assert times[0] == 0 and np.all(np.diff(times) > 0)
        assert times[-1] == pytest.approx(plan.segments[0].duration * 1e9, abs=1)


def test_the_pusher_stays_behind_the_pushed_edge(straight):
    _, _, path = straight
    slider = rrd_rows(path, "/world/slider", "LineStrips3D:strips", "step")
    pusher = rrd_rows(path, "/world/pusher", "LineStrips3D:strips", "step")
    for (_, part), (_, face) in zip(slider, pusher):
        body, tool = shapely.Polygon(part[0]), shapely.Polygon(face[0])
        assert tool.area == pytest.approx(0.05 * 0.015, rel=1e-4)
        assert body.intersection(tool).area < 1e-9 and body.distance(tool) < 1e-6


def test_the_obstacles_and_the_ghosts_match_the_scene(straight):
    scene, _, path = straight
    (_, strips), = rrd_rows(path, "/world/obstacles", "LineStrips3D:strips")
    (_, labels), = rrd_rows(path, "/world/obstacles", "LineStrips3D:labels")
    assert labels == ["obstacle 0", "obstacle 1"]
    np.testing.assert_allclose(strips[0], closed(TRIANGLE), atol=1e-6)
    w, h = BOX["size"]
    box = placed([[-w / 2, -h / 2], [w / 2, -h / 2], [w / 2, h / 2], [-w / 2, h / 2]],
                 [*BOX["center"], math.radians(BOX["angle"])])
    np.testing.assert_allclose(strips[1], closed(box), atol=1e-6)
    (_, goal), = rrd_rows(path, "/world/goal", "LineStrips3D:strips")
    np.testing.assert_allclose(goal[0], closed(placed(SLIDER, [0.12, 0.0, 0.0])), atol=1e-6)
    (_, workspace), = rrd_rows(path, "/world/workspace", "LineStrips3D:strips")
    np.testing.assert_allclose(workspace[0], closed([[-0.2, -0.25], [0.35, -0.25], [0.35, 0.25], [-0.2, 0.25]]),
                               atol=1e-6)


def test_the_centre_of_a_turn_stays_put_and_lies_in_its_stable_region(turn, straight):
    _, _, path = turn
    cors = rrd_rows(path, "/world/cor", "Points3D:positions", "step")
    assert len(cors) == len(rrd_rows(path, "/world/slider", "LineStrips3D:strips", "step"))
    centre = placed([COR], TURN_START)[0]
    np.testing.assert_allclose(np.array([c for _, c in cors]).reshape(-1, 2), [centre] * len(cors), atol=1e-5)
    # In the slider frame, where the regions are drawn, it is the turn's COR, in the CCW region only.
    (_, shown), = rrd_rows(path, "/analysis/cor", "Points3D:positions")
    np.testing.assert_allclose(shown, [COR], atol=1e-6)
    (_, ccw), = rrd_rows(path, "/analysis/exact/ccw", "LineStrips3D:strips")
    (_, cw), = rrd_rows(path, "/analysis/exact/cw", "LineStrips3D:strips")
    assert any(shapely.Polygon(ring).contains(shapely.Point(COR)) for ring in ccw)
    assert not any(shapely.Polygon(ring).contains(shapely.Point(COR)) for ring in cw)
    # A translation has no centre of rotation: no point is drawn.
    assert all(c == [] for _, c in rrd_rows(straight[2], "/world/cor", "Points3D:positions", "step"))


def test_an_unsolved_plan_records_the_scene_and_the_tree(tmp_path):
    scene = write_scene(tmp_path, "stuck", [0.12, 0.0, 0.0])
    plan = planner.Plan.of_part("part", scene.start, scene.goal, [], scene=scene.path, solved=False, planner="rrt",
                                seed=1, planning_time_s=0.0, reason="no plan found",
                                tree=np.array([[[0.0, 0.0], [0.05, 0.01]], [[0.05, 0.01], [0.08, -0.02]]]))
    path = tmp_path / "stuck.rrd"
    recording.write_recording(path, scene, plan)
    verify(path)
    assert entities(path) == STATIC
    (_, tree), = rrd_rows(path, "/world/tree", "LineStrips3D:strips")
    np.testing.assert_allclose(tree, plan.tree, atol=1e-6)
    assert summary_rows(path) == ["stuck: planner rrt, seed 1: not solved: no plan found", "search tree: 2 edges"]


def test_the_same_plan_gives_the_same_file(straight, tmp_path):
    if not RERUN.exists():
        pytest.skip(f"no rerun CLI next to {sys.executable}")
    scene, plan, path = straight
    again = tmp_path / "again.rrd"
    recording.write_recording(again, scene, plan)
    done = subprocess.run([str(RERUN), "rrd", "compare", "--unordered", str(path), str(again)],
                          capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr[-2000:]


def test_a_long_plan_is_capped_and_its_cf_path_thinned(straight, tmp_path):
    scene, _, _ = straight
    twists = [[1.0, 0.0, 0.0], [0.1, 0.0, 1.0], [0.8, 0.2, 0.0]]  # 1800 frames' worth at 0.0025 m each
    durations = [2.0, 1.5, 1.0]
    segments, pose = [], np.array(scene.start)
    for twist, duration in zip(twists, durations):
        end = exp_twist(pose, twist, duration)
        segments.append(planner.Push(3, np.array(SLIDER[3::-3]), np.array(twist), duration, pose, end))
        pose = end
    plan = planner.Plan.of_part("part", scene.start, pose, segments, scene=scene.path, solved=True, planner="rrt",
                                seed=1, planning_time_s=0.0)
    path = tmp_path / "long.rrd"
    recording.write_recording(path, scene, plan)
    slider = rrd_rows(path, "/world/slider", "LineStrips3D:strips", "step")
    assert 0.9 * frames.MAX_FRAMES <= len(slider) <= frames.MAX_FRAMES
    times = [t for _, t in rrd_rows(path, "/world/slider", "time", "step")]
    for s, t in zip(segments, np.cumsum([0.0] + durations)):  # each push starts on a frame
        k = int(np.argmin(np.abs(np.array(times) - t * 1e9)))
        assert abs(times[k] - t * 1e9) <= 1
        np.testing.assert_allclose(slider[k][1][0], closed(placed(SLIDER, s.start)), atol=1e-5)
    np.testing.assert_allclose(slider[-1][1][0], closed(placed(SLIDER, pose)), atol=1e-5)
    cf = rrd_rows(path, "/world/cf_path", "LineStrips3D:strips", "step")
    assert max(len(strips[0]) for _, strips in cf) <= frames.PATH_POINTS + len(segments) + 1
    drawn = np.array(cf[-1][1][0])
    for s in segments:  # the path keeps its corners
        assert np.linalg.norm(drawn - s.start[:2], axis=1).min() < 1e-5
    np.testing.assert_allclose(drawn[-1], pose[:2], atol=1e-5)


class FailingVerification:
    """Stands in for a Verification whose pushes cannot be read: the ghost is drawn after the
    file sink has started and the animation has been sent."""

    def __init__(self):
        self.asked = 0

    @property
    def pushes(self):
        self.asked += 1
        raise RuntimeError("disk on fire")


def test_a_failed_write_keeps_the_old_file_and_leaves_no_temporary(straight, tmp_path, monkeypatch):
    scene, plan, _ = straight
    path = tmp_path / "straight.rrd"
    path.write_bytes(b"the previous recording")
    failing = FailingVerification()
    with pytest.raises(RuntimeError, match="disk on fire"):
        recording.write_recording(path, scene, plan, failing)
    assert failing.asked
    assert path.read_bytes() == b"the previous recording"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["straight.rrd"]

    renamed = []

    def replace(src, dst):  # the file must be finished (footer written) before it is put in place
        renamed.append(Path(src).read_bytes())
        real_replace(src, dst)

    real_replace = os.replace
    monkeypatch.setattr(os, "replace", replace)
    recording.write_recording(path, scene, plan)  # a good write replaces the old file
    monkeypatch.undo()
    assert renamed == [path.read_bytes()]
    verify(path)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["straight.rrd"]


def strips(path: Path, entity: str) -> list[np.ndarray]:
    (_, value), = rrd_rows(path, entity, "LineStrips3D:strips")
    return [np.asarray(v, dtype=float) for v in value]


def test_the_analysis_shows_the_pushed_edge_in_the_slider_frame(turn):
    """The part at the origin of its frame, the pushed face (edge 3, x = -0.04, the central 5 cm),
    STABLE's COR regions inside the exact ones, and the plan's turn about COR inside the exact CCW
    region and the CCW sticking P region, and in the CW I region (turning the other way about it
    would pull the part off the pusher)."""
    scene, plan, path = turn
    np.testing.assert_allclose(strips(path, "/analysis/part")[0], closed(SLIDER))
    (contact,) = strips(path, "/analysis/contact")
    np.testing.assert_allclose(sorted(map(tuple, contact)), [(-0.04, -0.025), (-0.04, 0.025)], atol=1e-12)
    for side in ("ccw", "cw"):
        exact = shapely.union_all([shapely.Polygon(r) for r in strips(path, f"/analysis/exact/{side}")])
        stable = shapely.union_all([shapely.Polygon(r) for r in strips(path, f"/analysis/stable/{side}")])
        assert stable.area > 0 and exact.buffer(1e-9).contains(stable) and exact.area > 1.05 * stable.area
    (_, points), = rrd_rows(path, "/analysis/cor", "Points3D:positions")
    np.testing.assert_allclose(points, [COR], atol=1e-9)
    centre = shapely.Point(COR)
    def region(entity):
        return shapely.union_all([shapely.Polygon(r) for r in strips(path, entity)])

    assert region("/analysis/exact/ccw").contains(centre) and not region("/analysis/exact/cw").contains(centre)
    assert region("/analysis/sticking/ccw/P").contains(centre)
    assert not region("/analysis/sticking/ccw/I").contains(centre)
    assert region("/analysis/sticking/cw/I").contains(centre)


def test_the_analysis_shows_the_exact_region_even_when_planning_with_stable(turn, tmp_path):
    scene, _, _ = turn
    plan = planner.plan(scene, regions="stable")
    assert plan.solved
    recording.write_recording(tmp_path / "stable.rrd", scene, plan)
    for side in ("ccw", "cw"):
        exact = shapely.union_all([shapely.Polygon(r) for r in strips(tmp_path / "stable.rrd", f"/analysis/exact/{side}")])
        stable = shapely.union_all([shapely.Polygon(r) for r in strips(tmp_path / "stable.rrd", f"/analysis/stable/{side}")])
        assert exact.area > 1.05 * stable.area


# Plans that switch edge: the shipped junction scenes, each solved at seed 1 with one transit,
# walking round the part ("junction") or lifted over it ("narrow_junction").
SCENES = Path(__file__).resolve().parents[3] / "scenes"


@pytest.fixture(scope="module", params=["junction", "narrow_junction"])
def switching(request, tmp_path_factory):
    scene = planner.load_scene(SCENES / f"{request.param}.yaml")
    plan = planner.plan(scene, seed=1)
    assert plan.solved and plan.switches == 1
    path = tmp_path_factory.mktemp(request.param) / f"{request.param}.rrd"
    recording.write_recording(path, scene, plan)
    return scene, plan, path


def frame_times(path: Path) -> np.ndarray:
    """Each frame's time on the ``time`` line, seconds."""
    return np.array([t for _, t in rrd_rows(path, "/world/slider", "time", "step")]) / 1e9


def segment_frames(plan, times: np.ndarray, k: int) -> np.ndarray:
    """Frames inside segment ``k`` by the time line: from its start, before the next's."""
    start = sum(s.duration for s in plan.segments[:k])
    return np.flatnonzero((times >= start - 1e-9) & (times < start + plan.segments[k].duration - 1e-9))


def the_transit(plan) -> tuple[int, planner.model.segments.Transit]:
    (k,) = [k for k, s in enumerate(plan.segments) if s.kind == "transit"]
    return k, plan.segments[k]


def along(path: np.ndarray, reach: float, t: float) -> tuple[np.ndarray, int, float]:
    """The pose ``t`` seconds into a pusher path at 1 m/s (each piece takes |dxy| + reach |dtheta|,
    theta the shorter way), with the piece it lies on and how far along it (0 to 1)."""
    for k, (a, b) in enumerate(zip(path, path[1:])):
        turn = (b[2] - a[2] + math.pi) % (2 * math.pi) - math.pi
        piece = math.hypot(*(b[:2] - a[:2])) + reach * abs(turn)
        if t < piece or k == len(path) - 2:
            u = min(t / piece, 1.0) if piece > 0 else 1.0
            return np.array([*(a[:2] + u * (b[:2] - a[:2])), a[2] + u * turn]), k, u
        t -= piece
    raise AssertionError("a path has at least two poses")


def test_the_pusher_follows_the_transit_path_and_is_drawn_lifted_in_the_air(switching):
    """During the transit the pusher's rectangle (x in [-depth, 0], y in [-width/2, width/2] of its
    frame) sits at the path pose for the frame's time; it is on ``/world/pusher_lifted`` exactly
    when it is inside a lift's middle piece, and on ``/world/pusher`` otherwise."""
    scene, plan, path = switching
    width, depth = scene.pusher.width, scene.pusher.depth
    reach = math.hypot(depth, width / 2)
    rectangle = [[-depth, -width / 2], [0.0, -width / 2], [0.0, width / 2], [-depth, width / 2]]
    times = frame_times(path)
    k, transit = the_transit(plan)
    frames = segment_frames(plan, times, k)
    assert len(frames) >= 10
    start = times[frames[0]]
    assert start == pytest.approx(sum(s.duration for s in plan.segments[:k]), abs=1e-9)
    table = rrd_rows(path, "/world/pusher", "LineStrips3D:strips", "step")
    air = rrd_rows(path, "/world/pusher_lifted", "LineStrips3D:strips", "step")
    airborne = 0
    for f in frames:
        pose, piece, u = along(transit.pusher_path, reach, times[f] - start)
        lifted = transit.mode == "lift" and piece == 1 and 0 < u < 1
        airborne += lifted
        shown, hidden = (air, table) if lifted else (table, air)
        assert hidden[f][1] == []
        (outline,) = np.asarray(shown[f][1])
        expected = placed(rectangle, pose)
        assert len(outline) == 5 and np.allclose(outline[0], outline[-1])
        assert np.abs(outline[:-1, None] - expected[None]).sum(axis=-1).min(axis=0).max() < 1e-6  # same corners
    assert (airborne > 0) == (transit.mode == "lift")


def test_the_part_stands_still_and_nothing_is_pushed_during_a_transit(switching):
    scene, plan, path = switching
    times = frame_times(path)
    k, transit = the_transit(plan)
    frames = segment_frames(plan, times, k)
    slider = rrd_rows(path, "/world/slider", "LineStrips3D:strips", "step")
    for f in frames:
        np.testing.assert_allclose(slider[f][1][0], closed(placed(scene.slider.vertices, transit.pose)), atol=1e-6)
    rows = rrd_rows(path, "/world/cor", "Points3D:positions", "step")
    assert all(rows[f][1] == [] for f in frames)
    # Pushing again, on the transit's new edge: the pusher touches the part.
    after = segment_frames(plan, times, k + 1)[0]
    (face,) = rrd_rows(path, "/world/pusher", "LineStrips3D:strips", "step")[after][1]
    assert shapely.Polygon(slider[after][1][0]).distance(shapely.Polygon(face)) < 1e-6


def test_lifted_frames_are_on_their_own_entity_only_for_a_lift(switching):
    _, plan, path = switching
    table = rrd_rows(path, "/world/pusher", "LineStrips3D:strips", "step")
    air = rrd_rows(path, "/world/pusher_lifted", "LineStrips3D:strips", "step")
    assert [t for t, _ in table] == [t for t, _ in air] == list(range(len(table)))
    assert all(len(a) + len(b) == 1 for (_, a), (_, b) in zip(table, air))  # one pusher per frame
    lifts = [s for s in plan.segments if s.kind == "transit" and s.mode == "lift"]
    assert any(b for _, b in air) == bool(lifts)
    (_, labels), = rrd_rows(path, "/world/pusher_lifted", "LineStrips3D:labels")
    assert labels == ["lifted"]


def test_the_time_line_runs_through_every_segment(switching):
    _, plan, path = switching
    times = frame_times(path)
    assert times[0] == 0 and np.all(np.diff(times) > 0)
    assert times[-1] == pytest.approx(sum(s.duration for s in plan.segments), abs=1e-9)
    for k in range(len(plan.segments)):  # each segment starts on a frame
        assert times[segment_frames(plan, times, k)[0]] == pytest.approx(
            sum(s.duration for s in plan.segments[:k]), abs=1e-9)
    assert f"solved with {plan.pushes} pushes and 1 switch" in summary_rows(path)[0]


def test_a_switching_recording_verifies_and_draws_its_transit(switching):
    _, plan, path = switching
    verify(path)
    assert entities(path) == STATIC | ANIMATED | ANALYSIS
    _, transit = the_transit(plan)
    (_, labels), = rrd_rows(path, "/world/transits", "LineStrips3D:labels")
    drawn = strips(path, "/world/transits")
    xy = transit.pusher_path[:, :2]
    if transit.mode == "lift":
        assert labels == ["transit 1", "transit 1 lifted", "transit 1"]
        for strip, (a, b) in zip(drawn, [(0, 2), (1, 3), (2, 4)]):
            np.testing.assert_allclose(strip, xy[a:b], atol=1e-6)
    else:
        assert labels == ["transit 1"]
        np.testing.assert_allclose(drawn[0], xy, atol=1e-6)


class PlannedGhost:
    """Stands in for a Verification (planner.execution.verify) whose pushes all stick: one check per push,
    in plan order, transits skipped, and every run's poses the planned ones."""

    passed = True

    def __init__(self, scene, plan):
        self.scene, self.pushes = scene, [s for s in plan.segments if s.kind == "push"]

    def poses(self, push: int, times) -> np.ndarray:
        s = self.pushes[push]
        return exp_twist(s.start, s.twist, np.asarray(times, dtype=float))

    def summary(self) -> str:
        return "verify: passed"


def test_the_ghost_follows_the_pushes_and_skips_the_transit(switching, tmp_path):
    scene, plan, _ = switching
    path = tmp_path / "ghost.rrd"
    recording.write_recording(path, scene, plan, PlannedGhost(scene, plan))
    times = frame_times(path)
    k, _ = the_transit(plan)
    slider = rrd_rows(path, "/world/slider", "LineStrips3D:strips", "step")
    ghost = rrd_rows(path, "/world/ghost", "LineStrips3D:strips", "step")
    steps = {step for step, _ in ghost}
    assert not steps & set(segment_frames(plan, times, k))
    for j in range(len(plan.segments)):
        if j != k:
            assert segment_frames(plan, times, j)[0] in steps
    for step, outline in ghost:  # a push that sticks: the ghost hides under the part
        np.testing.assert_allclose(outline[0], slider[step][1][0], atol=1e-6)


def refuse(*args, **kwargs):
    """A region computation for a cache that must answer from what it holds."""
    raise AssertionError("an exact region was computed")


def test_a_half_turn_of_the_part_gives_the_twin_edges_analysis(tmp_path):
    """Parking's block: edge 2's analysis is edge 0's turned half round the CF, and equals the one
    computed for edge 2 itself (the force-status map exactly, the exact regions to 0.1 %). A cache
    holding edge 0's analysis and no region gives edge 2's without computing a region; edge 1's
    it must compute (its twin is edge 3, whose analysis it does not hold)."""
    scene = planner.load_scene(SCENES / "parking.yaml")
    computed = RegionCache(tmp_path / "computed")
    analysis.analysis(scene, 0, computed)
    held = RegionCache(tmp_path / "held", compute=refuse)
    held.folder.mkdir()
    for file in computed.folder.glob("analysis-*.json"):  # edge 0's analysis, not its region
        shutil.copy(file, held.folder)
    alone = analysis.analysis(scene, 2, RegionCache(computed.folder))  # nothing in memory to turn
    assert analysis.analysis(scene, 0, held) is analysis.analysis(scene, 0, held)  # read once
    twin = analysis.analysis(scene, 2, held)
    np.testing.assert_allclose(twin.contact, alone.contact, atol=1e-12)
    for name, by_sense in alone.polygons.items():
        for sense, polygon in by_sense.items():
            turned = twin.polygons[name][sense]
            assert turned.symmetric_difference(polygon).area <= 1e-3 * polygon.area + 1e-12, (name, sense)
    with pytest.raises(AssertionError, match="an exact region was computed"):
        analysis.analysis(scene, 1, held)


@pytest.fixture(scope="module")
def swap(tmp_path_factory):
    """The shipped swap (two parts trading places), planned and recorded."""
    scene = planner.load_scene(SCENES / "parts" / "swap.yaml")
    result = with_margins(scene, planner.Planner(scene).plan())
    assert result.solved and result.transfers == 2
    path = tmp_path_factory.mktemp("swap") / "swap.rrd"
    recording.write_recording(path, scene, result)
    return scene, result, path


def test_a_part_name_with_a_space_is_one_entity_without_a_warning(tmp_path):
    """Issue 41: a part named "red part" made rerun print WARN lines (unescaped whitespace) for each
    of its entities; the name is now escaped as one part of the entity path."""
    text = (SCENES / "parts" / "swap.yaml").read_text().replace("name: red,", 'name: "red part",')
    (tmp_path / "named.yaml").write_text(text)
    run = subprocess.run([sys.executable, "-m", "planner.cli", str(tmp_path / "named.yaml"), "--out", "out"],
                         capture_output=True, text=True, cwd=tmp_path, timeout=120,
                         env={**os.environ, "PYTHONPATH": str(SCENES.parent)})
    assert run.returncode == 0 and run.stderr == "", run.stderr
    assert {"/world/parts/red\\ part/slider", "/world/parts/blue/slider"} <= entities(tmp_path / "out" / "swap.rrd")


def test_a_multi_part_recording_moves_every_part_on_one_timeline(swap):
    """Every part is its own labelled entity; at the last frame each outline is where the plan
    leaves the part (placed here from the scene's vertices), at the first where it starts; the
    transfers are drawn, one strip per piece; the summary names the parts delivered."""
    scene, result, path = swap
    verify(path)
    assert {"/world/parts/red/slider", "/world/parts/blue/slider", "/world/transfers", "/world/pusher"} <= entities(path)
    for part in scene.parts:
        strips = rrd_rows(path, f"/world/parts/{part.name}/slider", "LineStrips3D:strips", "time")
        (_, first), (_, last) = strips[0], strips[-1]
        np.testing.assert_allclose(first[0], closed(placed(part.slider.vertices, part.start)), atol=1e-6)
        np.testing.assert_allclose(last[0], closed(placed(part.slider.vertices, result.finals[part.name])), atol=1e-6)
        [(_, labels)] = rrd_rows(path, f"/world/parts/{part.name}/slider", "LineStrips3D:labels")
        assert labels == [part.name]
    [(_, transfers)] = rrd_rows(path, "/world/transfers", "LineStrips3D:strips")
    assert len(transfers) == result.transfers  # walks on the table: one strip each
    assert "delivered: 2 of 2 parts" in summary_rows(path)


def test_a_multi_part_recording_has_each_parts_ghosts_and_path_and_the_first_pushed_edge(swap):
    """Each part's start and goal ghosts where the scene puts them, labelled with its name; its CF's
    path ends at the CF of its final pose (the CF is the block's centre, the pose's origin); the
    analysis is drawn for the first part pushed; nothing is at the one-part paths."""
    scene, result, path = swap
    for part in scene.parts:
        for word, pose in (("start", part.start), ("goal", part.goal)):
            (_, ghost), = rrd_rows(path, f"/world/parts/{part.name}/{word}", "LineStrips3D:strips")
            np.testing.assert_allclose(ghost[0], closed(placed(part.slider.vertices, pose)), atol=1e-6)
            (_, labels), = rrd_rows(path, f"/world/parts/{part.name}/{word}", "LineStrips3D:labels")
            assert labels == [f"{part.name} {word}"]
        cf = rrd_rows(path, f"/world/parts/{part.name}/cf_path", "LineStrips3D:strips", "step")
        np.testing.assert_allclose(cf[-1][1][0][-1], result.finals[part.name][:2], atol=1e-5)
    assert ANALYSIS <= entities(path)
    first = next(s for _, s in result.steps if isinstance(s, Push))
    (contact,) = strips(path, "/analysis/contact")
    np.testing.assert_allclose(sorted(map(tuple, contact)), sorted(map(tuple, first.contact)), atol=1e-6)
    assert not {"/world/slider", "/world/start", "/world/goal", "/world/cf_path"} & entities(path)


def test_a_part_stands_still_while_another_is_pushed_and_the_pusher_touches_the_pushed_one(swap):
    scene, result, path = swap
    outlines = {p.name: rrd_rows(path, f"/world/parts/{p.name}/slider", "LineStrips3D:strips", "step")
                for p in scene.parts}
    pusher = rrd_rows(path, "/world/pusher", "LineStrips3D:strips", "step")
    times = np.array([t for _, t in rrd_rows(path, "/world/parts/red/slider", "time", "step")]) / 1e9
    clock = 0.0
    for name, step in result.steps:
        inside = np.flatnonzero((times >= clock - 1e-9) & (times < clock + step.duration - 1e-9))
        clock += step.duration
        assert len(inside)
        for other in outlines:
            if other != name or not isinstance(step, Push):
                shown = {tuple(np.round(outlines[other][f][1][0], 6).ravel()) for f in inside}
                assert len(shown) == 1, (other, step)  # stands still
        if isinstance(step, Push):
            for f in inside:
                body, (face,) = shapely.Polygon(outlines[name][f][1][0]), pusher[f][1]
                assert body.intersection(shapely.Polygon(face)).area < 1e-9
                assert body.distance(shapely.Polygon(face)) < 1e-6


def test_a_multi_part_summary_counts_moves_transfers_and_their_times(swap):
    scene, result, path = swap
    pushes = sum(s.duration for s in result.segments if isinstance(s, Push))
    transfers = sum(s.duration for s in result.segments if isinstance(s, Transfer))
    assert summary_rows(path) == [
        "swap: planner rrt, seed 1: solved with 2 parts, 3 moves (1 buffer), 4 pushes and 2 transfers",
        f"CF path length {result.length:.4f} m; cost {result.cost:.4f} m (length + 0.25 m per switch and per transfer)",
        f"push time {pushes:.4f} s, transfer time {transfers:.4f} s (every point of the pusher at most 1 m/s)",
        f"stability margin friction -10 %, CF within 2 % of the part radius (>= 1 mm); least kept: {smallest(result)}",
        "delivered: 2 of 2 parts"]


def test_each_push_s_own_margin_labels_the_pusher_while_it_pushes(swap):
    """/world/pusher: while a push runs, its label is that push's number and its own certified
    margin; during a transfer, none."""
    scene, result, path = swap
    pushes = [k for k, (_, s) in enumerate(result.steps) if isinstance(s, Push)]
    said = {f"push {j}/{len(pushes)}: margin {m}" for j, m in enumerate(result.margins, 1)}
    labels = [row[0] if row else None for _, row in rrd_rows(path, "/world/pusher", "LineStrips3D:labels", "time")]
    shown = {label for label in labels if label}
    assert shown == said and "" in labels  # every push labelled, transfers not
    assert all(m.mu >= 0.1 - 1e-9 and m.cf >= 0.001 for m in result.margins)


def test_an_unsolved_multi_part_plan_records_the_moves_it_made_and_who_was_not_delivered(swap, tmp_path):
    """The first move alone (the red block pushed aside): the red block moves, the blue one stands,
    and the summary says neither was delivered."""
    scene, result, _ = swap
    first = replace(result, moves=result.moves[:1], delivered=(), solved=False, reason="stopped")
    path = tmp_path / "stopped.rrd"
    recording.write_recording(path, scene, first)
    verify(path)
    moved = first.moves[0].part
    for part in scene.parts:
        (_, last) = rrd_rows(path, f"/world/parts/{part.name}/slider", "LineStrips3D:strips", "step")[-1]
        np.testing.assert_allclose(last[0], closed(placed(part.slider.vertices, first.finals[part.name])), atol=1e-6)
    assert not np.allclose(first.finals[moved], scene.part(moved).start)
    assert summary_rows(path) == ["swap: planner rrt, seed 1: not solved: stopped",
                                  "delivered: 0 of 2 parts; not delivered: red, blue"]
