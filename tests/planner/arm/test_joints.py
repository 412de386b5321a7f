"""The arm's joint trajectory (issue 39, first part), checked by forward kinematics written here from
the makers' published Denavit-Hartenberg parameters: no code shared with planner.arm, whose model
is MuJoCo's and whose inverse kinematics is mink's.

What a joints file must be: per row of the trajectory CSV, the same ``t``; the pusher frame within
1 mm of the trajectory's pose and height; while pushing, the flange's z axis within 1 degree of
straight down; the pusher's heading minus the flange x axis's heading one constant (spread at most
0.5 degree); every joint within its position limits and, between rows, its speed limit; every joint
frame past the first above the table.
"""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path

import numpy as np
import pytest
import yaml

pytest.importorskip("mink", reason="the arm extra is not installed: pip install 'stablepush[arm]'")

from robot_scenes import plan, with_robot  # noqa: E402

ROOT = Path(__file__).resolve().parents[3]

# Franka Emika Panda: Craig's convention, rows (a, d, alpha) of joints 1-7; the flange 0.107 m on.
PANDA = dict(modified=True, flange=0.107,
             dh=[(0, 0.333, 0), (0, 0, -math.pi / 2), (0, 0.316, math.pi / 2), (0.0825, 0, math.pi / 2),
                 (-0.0825, 0.384, -math.pi / 2), (0, 0, math.pi / 2), (0.088, 0, math.pi / 2)],
             lower=[-2.8973, -1.7628, -2.8973, -3.0718, -2.8973, -0.0175, -2.8973],
             upper=[2.8973, 1.7628, 2.8973, -0.0698, 2.8973, 3.7525, 2.8973],
             speed=[2.175] * 4 + [2.61] * 3)
# Universal Robots UR5e: the standard convention, rows (a, d, alpha) of joints 1-6; the flange is frame 6.
UR5E = dict(modified=False, flange=0.0,
            dh=[(0, 0.1625, math.pi / 2), (-0.425, 0, 0), (-0.3922, 0, 0), (0, 0.1333, math.pi / 2),
                (0, 0.0997, -math.pi / 2), (0, 0.0996, 0)],
            lower=[-2 * math.pi] * 6, upper=[2 * math.pi] * 6, speed=[math.pi] * 6)
ARMS = {"panda": PANDA, "ur5e": UR5E}


def _rot(axis: str, angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    m = np.eye(4)
    i, j = (1, 2) if axis == "x" else (0, 1)
    m[i, i], m[i, j], m[j, i], m[j, j] = c, -s, s, c
    return m


def _move(x: float, y: float, z: float) -> np.ndarray:
    m = np.eye(4)
    m[:3, 3] = x, y, z
    return m


def frames(arm: dict, base, q) -> list[np.ndarray]:
    """World transforms of every joint frame, then the flange's, at joint angles ``q``."""
    x, y, yaw = base
    pose = _move(x, y, 0.0) @ _rot("z", yaw)
    out = []
    for (a, d, alpha), angle in zip(arm["dh"], q):
        step = (_rot("x", alpha) @ _move(a, 0, 0) @ _rot("z", angle) @ _move(0, 0, d) if arm["modified"]
                else _rot("z", angle) @ _move(0, 0, d) @ _move(a, 0, 0) @ _rot("x", alpha))
        pose = pose @ step
        out.append(pose)
    return out + [pose @ _move(0, 0, arm["flange"])]


def rows(path: Path) -> list[dict]:
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def check_joints(scene_file: Path, out: Path) -> dict:
    """The checks of the module docstring on ``out``'s files for ``scene_file``; the numbers found."""
    spec = yaml.safe_load(scene_file.read_text())["robot"]
    arm, tool, height = ARMS[spec["model"]], spec["tool_length"], spec.get("push_height", 0.01)
    base = (spec["base"][0], spec["base"][1], math.radians(spec["base"][2]))
    [motion_file] = out.glob("*.trajectory.csv")
    [joints_file] = out.glob("*.joints.csv")
    motion, joints = rows(motion_file), rows(joints_file)
    n = len(arm["dh"])
    assert list(joints[0]) == ["t", *(f"q{k}" for k in range(1, n + 1)), "segment"] + (["part"] if "part" in motion[0] else [])
    assert len(motion) == len(joints)
    q = np.array([[float(r[f"q{k}"]) for k in range(1, n + 1)] for r in joints])
    t = np.array([float(r["t"]) for r in joints])
    assert t.tolist() == [float(r["t"]) for r in motion]
    assert [r["segment"] for r in joints] == [r["segment"] for r in motion]
    assert (q >= np.array(arm["lower"]) - 1e-9).all() and (q <= np.array(arm["upper"]) + 1e-9).all()
    speeds = np.abs(np.diff(q, axis=0)) / np.diff(t)[:, None]
    assert (speeds <= np.array(arm["speed"])).all(), speeds.max(axis=0)
    worst, tilt, offsets, lowest = 0.0, 0.0, [], math.inf
    for row, angles in zip(motion, q):
        chain = frames(arm, base, angles)
        flange = chain[-1]
        pusher = flange[:3, 3] + tool * flange[:3, 2]
        wanted = np.array([float(row["x"]), float(row["y"]), height + float(row["z"])])
        worst = max(worst, float(np.linalg.norm(pusher - wanted)))
        lowest = min(lowest, min(f[2, 3] for f in chain[1:-1]))
        if row["contact"] == "1":
            tilt = max(tilt, math.degrees(math.acos(min(1.0, -flange[2, 2]))))
            offsets.append(math.remainder(float(row["theta"]) - math.atan2(flange[1, 0], flange[0, 0]), 2 * math.pi))
    offsets = np.unwrap(offsets)
    found = dict(worst=worst, tilt=tilt, spread=math.degrees(offsets.max() - offsets.min()), lowest=lowest,
                 speed=float((speeds / np.array(arm["speed"])).max()))
    assert worst <= 1e-3 and tilt <= 1.0 and found["spread"] <= 0.5 and lowest > 0.0, found
    return found


CASES = {
    "arm/tray (shipped, a tray), ur5e": ("arm/tray.yaml", None),
}


@pytest.mark.parametrize("scene, robot", CASES.values(), ids=CASES.keys())
def test_the_joints_file_holds_the_pusher_where_the_trajectory_has_it(tmp_path, scene, robot):
    path = ROOT / "scenes" / scene if robot is None else with_robot(tmp_path, scene, robot)
    run = plan(str(path), "--trajectory", "--seed", "1", "--out", "out", cwd=tmp_path)
    assert run.returncode == 0, run.stdout + run.stderr
    assert "arm: follows:" in run.stdout
    check_joints(path, tmp_path / "out")


def test_the_independent_check_sees_a_joints_file_that_is_off(tmp_path):
    """The check above is not blind: a joints file with one joint turned 0.01 rad fails it."""
    path = ROOT / "scenes" / "arm" / "around.yaml"
    assert plan(str(path), "--trajectory", "--seed", "1", "--out", "out", cwd=tmp_path).returncode == 0
    check_joints(path, tmp_path / "out")  # as planned it passes
    [joints] = (tmp_path / "out").glob("*.joints.csv")
    lines = joints.read_text().splitlines()
    cells = lines[500].split(",")
    cells[2] = repr(float(cells[2]) + 0.01)
    joints.write_text("\n".join(lines[:500] + [",".join(cells)] + lines[501:]) + "\n")
    with pytest.raises(AssertionError):
        check_joints(path, tmp_path / "out")


def test_a_start_out_of_the_reach_zone_is_bad_input(tmp_path):
    """cluttered's start is at the far corner from a Panda in the middle of the opposite side:
    within the bound of its links end to end, but outside where it holds the pusher flange-down."""
    path = with_robot(tmp_path, "cluttered.yaml", {"model": "panda", "base": [0.0, 0.5, -90], "tool_length": 0.1,
                                                   "push_height": 0.02})
    run = plan(str(path), "--trajectory", "--seed", "1", "--out", "out", cwd=tmp_path)
    assert run.returncode == 1 and run.stdout == "" and not (tmp_path / "out").exists()
    assert run.stderr.startswith("plan: error: start: out of the panda arm's reach: its reach zone is ") and \
        run.stderr.count("\n") == 1, run.stderr


def test_a_plan_the_arm_cannot_follow_exits_3_with_its_files_written(tmp_path, monkeypatch, capsys):
    """With the reach zone widened 30 cm past the arm's reach (as a zone drawn wrong would be),
    around's plan goes where the arm cannot hold the pusher: the joints check catches it."""
    import planner.world.reach

    from planner.cli import main

    monkeypatch.setattr(planner.world.reach, "RING_MARGIN", -0.3)
    code = main([str(ROOT / "scenes" / "arm" / "around.yaml"), "--trajectory", "--seed", "1", "--out", str(tmp_path / "out")])
    out = capsys.readouterr().out
    assert code == 3, out
    assert "arm: CANNOT FOLLOW:" in out and "arm: cannot hold the pusher at t = " in out
    assert (tmp_path / "out" / "around.joints.csv").exists()  # written, to be looked at


def _free_plan_joints(tmp_path: Path, path: Path):
    """The joints of ``path``'s arm along the trajectory of the plan of ``path``'s scene for a
    free pusher (its robot block taken out; the plan written under ``free``)."""
    from planner.arm.joints import joints_along
    from planner.execution.trajectory import trajectory
    from planner.model.plan_file import read_plan
    from planner.model.scene_file import load_scene

    spec = yaml.safe_load(path.read_text())
    del spec["robot"]
    free = tmp_path / f"free_{path.name}"
    free.write_text(yaml.safe_dump(spec))
    run = plan(str(free), "--seed", "1", "--out", "free", cwd=tmp_path)
    assert run.returncode == 0, run.stdout + run.stderr
    scene = load_scene(free)
    found = read_plan(json.loads((tmp_path / "free" / f"{spec['name']}.json").read_text()))
    return joints_along(load_scene(path).robot, trajectory(scene, found))


ARM_AWARE = {
    # Straight across passes 15 cm from the base: too near for the flange to point down.
    "around: the free plan passes too near the base": ROOT / "scenes" / "arm" / "around.yaml",
    # The free plan walks the pusher round the part, turning it past pushing straight at the base.
    "wrist: the free plan winds the wrist": ROOT / "scenes" / "arm" / "wrist.yaml",
}


@pytest.mark.parametrize("path", ARM_AWARE.values(), ids=ARM_AWARE.keys())
def test_where_the_free_plan_fails_the_arm_the_arm_aware_plan_is_followed(tmp_path, path):
    free = _free_plan_joints(tmp_path, path)
    assert not free.follows and any(line.startswith("arm: cannot hold the pusher") for line in free.lines())
    refused = plan(str(path), "--plan", str(next((tmp_path / "free").glob("*.json"))), "--verify", "1", "--out", "v",
                   cwd=tmp_path)
    assert refused.returncode == 1 and "leaves the panda arm's reach zone" in refused.stderr, refused.stderr
    run = plan(str(path), "--trajectory", "--seed", "1", "--out", "out", cwd=tmp_path)
    assert run.returncode == 0 and "arm: follows:" in run.stdout, run.stdout + run.stderr
    check_joints(path, tmp_path / "out")


def test_a_start_out_of_reach_is_bad_input_and_a_goal_out_of_reach_is_certified_unreachable(tmp_path):
    """corridor's start and goal are at opposite corners of a 1 m table: a Panda at the goal's corner
    reaches the goal but not the start (1.1 m away); one at the start's corner, the other way round.
    The reach is the arm's links end to end (0.986 m from the shoulder), a bound no posture beats."""
    robot = {"model": "panda", "base": [0.5, 0.5, -135], "tool_length": 0.12}
    run = plan(str(with_robot(tmp_path, "corridor.yaml", robot)), "--out", "out", cwd=tmp_path)
    assert run.returncode == 1 and run.stdout == "" and not (tmp_path / "out").exists()
    assert run.stderr.startswith("plan: error: start: the panda cannot hold the pusher on any allowed edge") and \
        run.stderr.count("\n") == 1, run.stderr
    robot["base"] = [-0.5, -0.5, 45]
    run = plan(str(with_robot(tmp_path, "corridor.yaml", robot)), "--out", "out", cwd=tmp_path)
    assert run.returncode == 2, run.stdout + run.stderr
    assert "unreachable: out of reach: the panda cannot hold the pusher on any allowed edge at the goal" in run.stdout + run.stderr


def test_the_robot_block_is_written_back_as_read(tmp_path):
    """--export-scene (plain_scene) writes the block so that reading it gives the same robot."""
    from planner.model.scene_file import load_scene, parse_scene, plain_scene

    path = with_robot(tmp_path, "parts/swap.yaml", {"model": "ur5e", "base": [0.1, -0.4, 120], "tool_length": 0.15,
                                                    "push_height": 0.02})
    robot = load_scene(path).robot
    again = parse_scene(plain_scene(load_scene(path))).robot
    assert (again.model, again.tool_length, again.push_height) == (robot.model, robot.tool_length, robot.push_height) == ("ur5e", 0.15, 0.02)
    assert np.allclose(again.base, robot.base) and np.allclose(robot.base, [0.1, -0.4, math.radians(120)])


@pytest.mark.parametrize("change, field", [
    ({"model": "kuka"}, "robot.model"),
    ({"base": [2.0, 0.0, 0]}, "robot.base"),
    ({"base": [0.0, 0.0]}, "robot.base"),
    ({"tool_length": 0}, "robot.tool_length"),
    ({"tool_length": float("nan")}, "robot.tool_length"),
    ({"tool_length": 5.0}, "robot.tool_length"),
    ({"push_height": -0.01}, "robot.push_height"),
    ({"reach": 1}, "robot.reach"),
])
def test_a_bad_robot_block_is_one_line_exit_1(tmp_path, change, field):
    path = with_robot(tmp_path, "parking.yaml", {"model": "panda", "base": [0.0, -0.4, 90], "tool_length": 0.12} | change)
    run = plan(str(path), "--out", "out", cwd=tmp_path)
    assert run.returncode == 1 and run.stdout == ""
    assert run.stderr.startswith(f"plan: error: {field}: ") and run.stderr.count("\n") == 1, run.stderr
    assert not (tmp_path / "out").exists()


def test_a_trajectory_too_fast_for_a_joint_is_timed_slower_for_the_arm(tmp_path):
    """A random scene's plan (test_unseen_scenes found it) passes the Panda's elbow near straight,
    where the pusher's own time law asked joint 3 for 1.74 times its speed limit: the trajectory is
    timed slower, the same path in more time, and its joints pass the independent check."""
    spec = {"name": "elbow", "slider": {"vertices": [[-0.0304, -0.0351], [0.0304, -0.0351], [0.0304, 0.0351],
                                                     [-0.0304, 0.0351]]},
            "pusher": {"width": 0.03, "depth": 0.015, "mu": 0.6848},
            "obstacles": [{"box": {"center": [0.3985, 0.5088], "size": [0.0996, 0.1079]}}],
            "workspace": {"min": [-0.4752, -0.45], "max": [0.4752, 0.5148]},
            "start": [-0.3726, -0.3650, 179.0], "goal": [0.3897, -0.2361, 165.8],
            "robot": {"model": "panda", "base": [0.0, -0.45, 90.0], "tool_length": 0.1847, "push_height": 0.0178}}
    path = tmp_path / "elbow.yaml"
    path.write_text(yaml.safe_dump(spec))
    run = plan(str(path), "--trajectory", "--seed", "1", "--out", "out", cwd=tmp_path)
    assert run.returncode == 0, run.stdout + run.stderr
    assert "arm: follows: " in run.stdout and " times slower for its joints; " in run.stdout, run.stdout
    found = check_joints(path, tmp_path / "out")
    assert found["speed"] <= 1.0
