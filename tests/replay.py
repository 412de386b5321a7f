"""Test-only replay of a plan JSON: SE(2) by matrix exponential, geometry by shapely, stability by
the oracle (tests/oracle.py).

Shares nothing with ``planner``: the pusher body and its frame, the body motion, the pusher's
interpolation during a transit and the collision test are written out again here from the
README's definitions.
"""

from __future__ import annotations

import math

import numpy as np
import shapely
from scipy.linalg import expm

from oracle import Reference, guaranteed_stable

SAMPLE = 0.001  # metres any body point moves between replay samples
TURN = math.radians(1.0)  # and the most a transit's pusher turns between them


def pose_matrix(q) -> np.ndarray:
    x, y, th = q
    return np.array([[math.cos(th), -math.sin(th), x], [math.sin(th), math.cos(th), y], [0, 0, 1.0]])


def matrix_pose(m) -> np.ndarray:
    return np.array([m[0, 2], m[1, 2], math.atan2(m[1, 0], m[0, 0])])


def advance(q, twist, t) -> np.ndarray:
    """q * exp([twist] t) with the 3x3 matrix exponential."""
    vx, vy, w = twist
    xi = np.array([[0.0, -w, vx], [w, 0.0, vy], [0.0, 0.0, 0.0]])
    return matrix_pose(pose_matrix(q) @ expm(xi * t))


def wrap(angle) -> float:
    """``angle`` in [-pi, pi)."""
    return (angle + math.pi) % (2 * math.pi) - math.pi


def angle_diff(a, b) -> float:
    return abs(wrap(a - b))


def transform(points, q) -> np.ndarray:
    """Points given in the frame at pose ``q``, in the frame ``q`` is given in."""
    m = pose_matrix(q)
    return np.asarray(points, float) @ m[:2, :2].T + m[:2, 2]


def place(points, q) -> shapely.Polygon:
    return shapely.Polygon(transform(points, q))


def pusher_rectangle(width, depth) -> np.ndarray:
    """The pusher in its own frame (README): origin at the middle of the pushing face, x along the
    push direction, so the body is x in [-depth, 0], y in [-width/2, width/2]."""
    return np.array([[-depth, -width / 2], [0.0, -width / 2], [0.0, width / 2], [-depth, width / 2]])


def edge_pose(vertices, edge) -> np.ndarray:
    """Slider-frame pose of the pusher frame flush on ``edge``: origin at the edge's midpoint, x
    along the inward normal (found by probing which side of the midpoint is inside the polygon)."""
    v = np.asarray(vertices, float)
    a, b = v[edge], v[(edge + 1) % len(v)]
    d = (b - a) / np.linalg.norm(b - a)
    inward = np.array([-d[1], d[0]])  # left of the edge direction
    mid = (a + b) / 2
    if not shapely.Polygon(v).contains(shapely.Point(mid + inward * 1e-6)):
        inward = -inward
    return np.array([*mid, math.atan2(inward[1], inward[0])])


def compose(a, b) -> np.ndarray:
    """The pose ``b`` (given in the frame at ``a``) in the frame ``a`` is given in."""
    return matrix_pose(pose_matrix(a) @ pose_matrix(b))


def flush_pose(vertices, edge, part_pose) -> np.ndarray:
    """World pose of the pusher frame in contact with ``edge`` of the part at ``part_pose``."""
    return compose(part_pose, edge_pose(vertices, edge))


def pusher_body(vertices, edge, width, depth) -> np.ndarray:
    """The width x depth rectangle behind the face centred on the edge, outside the part (slider frame)."""
    return transform(pusher_rectangle(width, depth), edge_pose(vertices, edge))


def interpolate(p, q, s) -> np.ndarray:
    """The pose a fraction ``s`` of the way from ``p`` to ``q``: (x, y, theta) linearly, theta the
    shorter way round."""
    p, q = np.asarray(p, float), np.asarray(q, float)
    return p + s * np.array([q[0] - p[0], q[1] - p[1], wrap(q[2] - p[2])])


def max_point_speed(points, twist) -> float:
    vx, vy, w = twist
    p = np.asarray(points, float)
    return float(np.max(np.hypot(vx - w * p[:, 1], vy + w * p[:, 0])))


def obstacle_polygons(spec) -> list[shapely.Polygon]:
    out = []
    for o in spec.get("obstacles") or []:
        if "polygon" in o:
            out.append(shapely.Polygon(o["polygon"]))
        else:
            b = o["box"]
            (cx, cy), (w, h), a = b["center"], b["size"], math.radians(b.get("angle", 0.0))
            c, s = math.cos(a), math.sin(a)
            corners = [(-w / 2, -h / 2), (w / 2, -h / 2), (w / 2, h / 2), (-w / 2, h / 2)]
            out.append(shapely.Polygon([(cx + c * x - s * y, cy + s * x + c * y) for x, y in corners]))
    return out


def blocked_region(spec) -> shapely.Geometry:
    """The obstacles and everything outside the workspace, where no body may go."""
    lo, hi = spec["workspace"]["min"], spec["workspace"]["max"]
    walls = shapely.box(lo[0] - 1, lo[1] - 1, hi[0] + 1, hi[1] + 1).difference(shapely.box(*lo, *hi))
    return shapely.union_all([*obstacle_polygons(spec), walls])


def degrees_pose(p) -> np.ndarray:
    return np.array([p[0], p[1], math.radians(p[2])])


def replay_plan(spec: dict, plan: dict, goal=None) -> None:
    """Assert that ``plan`` (its JSON form) is a valid plan of the scene ``spec`` (its YAML form)
    to ``goal`` (radians; default: the scene's): each push starts where the part is, on the edge
    where the pusher is, stable for every support distribution (the oracle's LP and Theorem 4),
    collision-free on samples at most ``SAMPLE`` apart, and the last ends within tolerance; each
    transit passes :func:`replay_transit`."""
    verts = np.asarray(spec["slider"]["vertices"], float)
    cf = spec["slider"].get("cf", list(shapely.Polygon(verts).centroid.coords[0]))
    pusher = spec["pusher"]
    blocked = blocked_region(spec)
    tol = spec.get("tolerance", {})
    pose = degrees_pose(spec["start"])
    np.testing.assert_allclose(plan["start"][:2], pose[:2], atol=1e-9)
    assert angle_diff(plan["start"][2], pose[2]) < 1e-9  # the file's angles are in [-pi, pi)
    assert not plan["segments"] or plan["segments"][-1]["kind"] == "push", "a transit must lead to a push on its edge"
    edge = None  # the edge the pusher is on, once the plan has placed it
    for seg in plan["segments"]:
        if seg["kind"] == "transit":
            assert edge is None or seg["from_edge"] == edge, f"transit {seg} leaves from another edge than {edge}"
            replay_transit(spec, seg, pose, blocked)
            edge = seg["to_edge"]
            continue  # the part stands still: the next push must start from the same pose
        assert seg["kind"] == "push"
        assert edge is None or seg["edge"] == edge, f"push {seg} is not on edge {edge}, where the pusher is"
        edge = seg["edge"]
        np.testing.assert_allclose(seg["start"][:2], pose[:2], atol=1e-9)
        assert angle_diff(seg["start"][2], pose[2]) < 1e-9
        # Stability: sticking for every support distribution on the part (re-derived LP), and a
        # turn's centre beyond the part along the edge (Theorem 4).
        ref = Reference(verts, cf, edge, pusher["mu"], width=pusher["width"])
        np.testing.assert_allclose(sorted(map(tuple, seg["contact"])), sorted(map(tuple, [ref.eL, ref.eR])), atol=1e-12)
        assert guaranteed_stable(verts, cf, edge, pusher["mu"], pusher["width"], seg["twist"]), \
            f"push {seg} is not stable for every support distribution, or may pivot"
        # Motion: the end is start * exp(twist * duration); sample it densely against obstacles.
        body = [verts, pusher_body(verts, edge, pusher["width"], pusher["depth"])]
        speed = max(max_point_speed(b, seg["twist"]) for b in body)
        n = max(2, math.ceil(speed * seg["duration"] / SAMPLE) + 1)
        for t in np.linspace(0.0, seg["duration"], n):
            q = advance(pose, seg["twist"], t)
            placed = shapely.union_all([place(b, q) for b in body])
            # Samples <= SAMPLE apart and clear by more than SAMPLE/2: nothing is crossed between.
            assert placed.distance(blocked) > SAMPLE / 2, f"collision at {q} in push {seg}"
        end = advance(pose, seg["twist"], seg["duration"])
        np.testing.assert_allclose(seg["end"][:2], end[:2], atol=1e-9)
        assert angle_diff(seg["end"][2], end[2]) < 1e-9
        pose = end
    goal = degrees_pose(spec["goal"]) if goal is None else np.asarray(goal, float)
    assert math.dist(pose[:2], goal[:2]) <= tol.get("position", 0.01)
    assert angle_diff(pose[2], goal[2]) <= math.radians(tol.get("angle", 2.0))
    np.testing.assert_allclose(plan["final"][:2], pose[:2], atol=1e-9)


def replay_transit(spec: dict, seg: dict, part_pose: np.ndarray, blocked: shapely.Geometry) -> None:
    """Check a transit against the README with the part standing at ``part_pose``: a mode the scene
    allows, flush contact poses at both ends, every in-plane piece clear of obstacles, walls and
    the part (which it touches only at the two ends), and the duration at 1 m/s."""
    verts, pusher = spec["slider"]["vertices"], spec["pusher"]
    allowed = pusher.get("transit", "plane")
    assert allowed in ("plane", "lift"), f"transit {seg} in a scene whose pusher may not switch edges"
    path = np.asarray(seg["pusher_path"], float)
    assert seg["mode"] in ("plane", "lift") and len(path) >= 2
    if seg["mode"] == "lift":
        assert allowed == "lift", f"lift {seg} in a scene whose pusher stays on the table"
        assert len(path) == 4, "a lift is contact, retreat, approach, contact"
    for at, edge in ((path[0], seg["from_edge"]), (path[-1], seg["to_edge"])):
        flush = flush_pose(verts, edge, part_pose)
        np.testing.assert_allclose(at[:2], flush[:2], atol=1e-9, err_msg=f"transit {seg} not flush on edge {edge}")
        assert angle_diff(at[2], flush[2]) < 1e-9, f"transit {seg} not square to edge {edge}"
    duration = sweep_pusher(pusher, seg, blocked, {"part": place(verts, part_pose)}, "part", "part")
    assert abs(duration - seg["duration"]) <= 1e-9, f"transit {seg} takes {duration} s at 1 m/s"


def sweep_pusher(pusher: dict, seg: dict, blocked: shapely.Geometry, parts: dict, first: str, last: str) -> float:
    """Sweep the pusher along ``seg``'s ``pusher_path`` (a transit or transfer): every in-plane
    piece clear of ``blocked``, touching part ``first`` of ``parts`` at the first pose and part
    ``last`` at the last, and no part anywhere else; returns the path's duration at 1 m/s."""
    path = np.asarray(seg["pusher_path"], float)
    rectangle = pusher_rectangle(pusher["width"], pusher["depth"])
    reach = math.hypot(pusher["depth"], pusher["width"] / 2)  # the body point farthest from the face centre
    end = len(path) - 2
    duration = 0.0
    for k, (p, q) in enumerate(zip(path, path[1:])):
        shift, turn = math.dist(p[:2], q[:2]), angle_diff(p[2], q[2])
        duration += shift + reach * turn
        if seg["mode"] == "lift" and k == 1:
            continue  # airborne: over everything
        # Between samples no body point moves more than SAMPLE (and the body turns at most TURN);
        # clear by more than SAMPLE/2, nothing is crossed between them.
        n = max(1, math.ceil((shift + reach * turn) / SAMPLE), math.ceil(turn / TURN)) + 1
        for s in np.linspace(0.0, 1.0, n):
            q_s = interpolate(p, q, s)
            body = place(rectangle, q_s)
            assert body.distance(blocked) > SAMPLE / 2, f"pusher collides at {q_s} in {seg['kind']} {seg}"
            for name, part in parts.items():
                touching = (k, s) == (0, 0.0) and name == first or (k, s) == (end, 1.0) and name == last
                gap = body.distance(part)
                assert gap < 1e-9 if touching else gap > 0, f"pusher and part {name} at {q_s} in {seg['kind']} {seg}"
    return duration


def replay_parts_plan(spec: dict, plan: dict) -> None:
    """Assert that ``plan`` (a ``stablepush.plan/2`` JSON) is a valid plan of the multi-part scene
    ``spec`` (its YAML form): each move, the part's run of segments between transfers, replays as a
    one-part plan (:func:`replay_plan`) with the other parts as obstacles where they stand then;
    each transfer passes :func:`replay_transfer`; every part ends within tolerance of its goal."""
    parts = {p["name"]: p for p in spec["parts"]}
    poses = {n: degrees_pose(p["start"]) for n, p in parts.items()}
    edge_on = None  # (part, edge) the pusher is on
    segments = plan["segments"]
    k = 0
    while k < len(segments):
        seg = segments[k]
        if seg["kind"] == "transfer":
            assert edge_on is not None and seg["from_part"] == edge_on[0], f"transfer {k} leaves another part"
            replay_transfer(spec, seg, poses, edge_on[1])
            edge_on = (seg["to_part"], seg["to_edge"])
            k += 1
            continue
        name = seg["part"]
        assert edge_on is None or edge_on[0] == name, f"segment {k} pushes {name}, the pusher is on {edge_on[0]}"
        run = []
        while k < len(segments) and segments[k]["kind"] != "transfer":
            assert segments[k]["part"] == name, "a move pushes one part"
            run.append({key: v for key, v in segments[k].items() if key != "part"})
            k += 1
        first = run[0]["edge"] if run[0]["kind"] == "push" else run[0]["from_edge"]
        assert edge_on is None or edge_on[1] == first, f"the move of {name} starts on another edge than the transfer's"
        others = [place(parts[m]["vertices"], poses[m]) for m in parts if m != name]
        one = {"slider": {key: parts[name][key] for key in ("vertices", "cf") if key in parts[name]},
               "pusher": spec["pusher"], "workspace": spec["workspace"], "tolerance": spec.get("tolerance", {}),
               "obstacles": [*(spec.get("obstacles") or []),
                             *({"polygon": np.asarray(o.exterior.coords)[:-1].tolist()} for o in others)],
               "start": [*poses[name][:2], math.degrees(poses[name][2])]}
        end = np.asarray(run[-1]["end"], float)
        replay_plan(one, {"start": list(poses[name]), "segments": run, "final": list(end)}, goal=end)
        poses[name] = end
        edge_on = (name, run[-1]["edge"] if run[-1]["kind"] == "push" else run[-1]["to_edge"])
    tol = spec.get("tolerance", {})
    for n, p in parts.items():
        goal = degrees_pose(p["goal"])
        assert math.dist(poses[n][:2], goal[:2]) <= tol.get("position", 0.01), f"part {n} misses its goal"
        assert angle_diff(poses[n][2], goal[2]) <= math.radians(tol.get("angle", 2.0)), f"part {n} misses its heading"
        np.testing.assert_allclose(plan["parts"][n]["final"][:2], poses[n][:2], atol=1e-9)


def replay_transfer(spec: dict, seg: dict, poses: dict, from_edge: int) -> None:
    """Check a transfer with every part standing at ``poses``: flush on ``from_edge`` of the part it
    leaves at its first pose and on ``to_edge`` of the part it reaches at its last, every in-plane
    piece clear of obstacles, walls and every part (touching only those two, at the two ends), and
    the duration at 1 m/s."""
    parts = {p["name"]: p for p in spec["parts"]}
    pusher = spec["pusher"]
    path = np.asarray(seg["pusher_path"], float)
    assert seg["mode"] in ("plane", "lift") and len(path) >= 2
    if seg["mode"] == "lift":
        assert pusher.get("transit", "plane") == "lift" and len(path) == 4
    for at, part, edge in ((path[0], seg["from_part"], from_edge), (path[-1], seg["to_part"], seg["to_edge"])):
        flush = flush_pose(parts[part]["vertices"], edge, poses[part])
        np.testing.assert_allclose(at[:2], flush[:2], atol=1e-9, err_msg=f"transfer not flush on {part}'s edge {edge}")
        assert angle_diff(at[2], flush[2]) < 1e-9
    bodies = {n: place(p["vertices"], poses[n]) for n, p in parts.items()}
    duration = sweep_pusher(pusher, seg, blocked_region(spec), bodies, seg["from_part"], seg["to_part"])
    assert abs(duration - seg["duration"]) <= 1e-9
