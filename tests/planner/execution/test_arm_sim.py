"""The arm pushes in MuJoCo (issue 39, build item 4): with a ``robot:`` block the pusher is a prism on
the arm's flange and the arm's servos follow the joint trajectory.

What is checked, each against something the simulation does not compute itself: the prism where the
trajectory has the pusher (its heading and its bottom on the table, from the trajectory's numbers);
a plan delivered by the arm (the scene's goal); a joint trajectory solved for targets moved 5 cm
fails the run, and the tracking error it reports is about those 5 cm; a link put on the table is
reported by name; the recording's arm starts at the robot's base.
"""

from __future__ import annotations

import math
import re
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import yaml

pytest.importorskip("mink", reason="the arm extra is not installed: pip install 'stablepush[arm]'")
pytest.importorskip("mujoco")

from planner import load_scene  # noqa: E402
from planner.arm.joints import joint_trajectory, joints_along  # noqa: E402
from planner.execution import mujoco_sim  # noqa: E402
from planner.arm.reach import ArmReach  # noqa: E402
from planner.execution.arm_sim import SimArm  # noqa: E402
from planner.model.robot import Robot  # noqa: E402
from planner.model.bodies import pusher_frame_body  # noqa: E402
from planner.queries.session import Planner  # noqa: E402
from robot_scenes import plan  # noqa: E402

ROOT = Path(__file__).resolve().parents[3]
AROUND = ROOT / "scenes" / "arm" / "around.yaml"


@pytest.fixture(scope="module")
def around():
    """The around scene, its plan, the run's set-up and the joints along its trajectory."""
    scene = load_scene(AROUND)
    plan = Planner(scene).plan()
    assert plan.solved
    setup = mujoco_sim.perturbations(scene, plan)
    return scene, plan, setup, joints_along(scene.robot, setup.motion)


@pytest.mark.parametrize("model, base", [("panda", (0.0, -0.5, math.pi / 2)), ("ur5e", (0.1, -0.45, 2.0))])
def test_the_pusher_prism_sits_on_the_flange_where_the_arm_holds_the_pusher(model, base):
    import mujoco

    scene = load_scene(AROUND)
    scene = replace(scene, robot=Robot(model, np.array(base), 0.12, 0.015))
    reach = ArmReach(scene.robot)
    poses = [(-0.3, -0.2, 0.4), (0.35, -0.3, -2.0), (0.1, 0.1, 2.5)]
    q = np.array([reach.first(pose)[0] for pose in poses])
    assert max(reach.pose_error(pose, row) for pose, row in zip(poses, q)) < 1e-4
    arm = SimArm(scene.robot, reach.mount, np.arange(len(q), dtype=float), q, np.zeros_like(q), None, {}, 0.001)
    world = mujoco_sim.World(scene, {scene.part().name: mujoco_sim.feet(scene, 1)[0]}, None, scene.starts, (), arm)
    geom = world.model.geom("pusher").id
    mesh = world.model.geom_dataid[geom]
    start, count = world.model.mesh_vertadr[mesh], world.model.mesh_vertnum[mesh]
    for (x, y, theta), row in zip(poses, q):
        world.data.qpos[world.model.joint("joint1").qposadr[0] + np.arange(arm.count)] = row
        mujoco.mj_forward(world.model, world.data)
        # The prism's corners in the world (MuJoCo keeps a mesh in its own inertial frame).
        corners = world.model.mesh_vert[start:start + count] @ world.data.geom_xmat[geom].reshape(3, 3).T \
            + world.data.geom_xpos[geom]
        # Where they should be: the pusher's outline at the trajectory's pose, from the table up.
        c, s = math.cos(theta), math.sin(theta)
        outline = pusher_frame_body(scene.pusher.width, scene.pusher.depth) @ np.array([[c, s], [-s, c]]) + [x, y]
        assert abs(corners[:, 2].min()) < 2e-4  # its bottom on the table (to the inverse kinematics' tolerance)
        for corner in corners:
            assert np.linalg.norm(outline - corner[:2], axis=1).min() < 1e-3, (corner, outline)
        for point in outline:
            assert np.linalg.norm(corners[:, :2] - point, axis=1).min() < 1e-3, (point, corners)


def test_a_joint_trajectory_5_cm_off_fails_the_run_and_the_command_exits_3(tmp_path, monkeypatch, capsys):
    """(That the arm's own joints deliver the part: test_simulate_with_the_arm_from_the_command_line.)
    The command given, in place of the arm's joints, ones solved for the pusher's targets moved 5 cm
    along y, across the pushes: the run fails, and the command exits 3."""
    import planner.execution.arm_timing
    from planner.cli import main

    honest = planner.execution.arm_timing.arm_trajectory
    runs = []

    def doctored(scene, plan):
        motion, _ = honest(scene, plan)
        off = joint_trajectory(scene.robot, motion.t, np.c_[motion.x, motion.y + 0.05, motion.theta], motion.z,
                               motion.segment)
        return motion, off

    real = mujoco_sim.simulate
    monkeypatch.setattr(planner.execution.arm_timing, "arm_trajectory", doctored)
    monkeypatch.setattr(mujoco_sim, "simulate", lambda *a, **k: runs.append(real(*a, **k)) or runs[-1])
    code = main([str(AROUND), "--simulate", "1", "--seed", "1", "--out", str(tmp_path / "out")])
    out = capsys.readouterr().out
    assert code == 3, out
    (simulation,) = runs
    assert not simulation.passed and not simulation.runs[0].in_goal, out  # the run itself fails, not only the check
    assert 0.045 < simulation.runs[0].tracking < 0.06
    assert "simulate: FAILED" in out


@pytest.mark.slow
def test_a_link_on_the_table_is_reported_by_name(around):
    scene, plan, setup, joints = around
    motion = setup.motion
    # The pusher frame 12 cm lower: the flange (13 cm over the table) and its link go into the table.
    low = joint_trajectory(scene.robot, motion.t, np.c_[motion.x, motion.y, motion.theta], motion.z - 0.12,
                           motion.segment)
    run = mujoco_sim.simulate(scene, plan, 1, arm=(motion, low)).runs[0]
    assert not run.passed and any(what == "the arm's link7 touches the table" for _, what in run.faults), run.faults


def test_simulate_with_the_arm_from_the_command_line(tmp_path):
    from rerun.chunk import RrdReader

    run = plan(str(AROUND), "--simulate", "1", "--out", "out", "--mjcf", "out/model.xml", cwd=tmp_path)
    assert run.returncode == 0, run.stdout + run.stderr  # in the goal, no slip, no link touching
    assert "arm: follows" in run.stdout and "pusher held by the panda arm" in run.stdout
    tracking = float(run.stdout.split("worst tracking ")[1].split(" mm")[0])
    assert tracking < 2.0  # mm: the servos hold the pusher near the trajectory
    import mujoco

    model = mujoco.MjModel.from_xml_path(str(tmp_path / "out" / "model.xml"))
    assert model.nu == 7 and model.body("link7").id > 0
    strips = [chunk for chunk in RrdReader(str(tmp_path / "out" / "around.rrd")).store().stream()
              if chunk.entity_path == "/world/arm"]
    assert strips
    batch = strips[0].to_record_batch()
    first = batch.column(batch.schema.names.index("LineStrips3D:strips")).to_pylist()[0][0]
    base = yaml.safe_load(AROUND.read_text())["robot"]["base"]
    assert np.allclose(first[0], [base[0], base[1], 0.0], atol=1e-9)  # the arm drawn from its base
    assert abs(first[-1][2] - 0.01) < 0.003  # to the pusher frame, push_height over the table


@pytest.mark.slow
@pytest.mark.parametrize("scene, runs", [("arm/tray.yaml", "1"), ("arm/wrist.yaml", "2")],
                         ids=["arm/tray (shipped), ur5e", "arm/wrist (shipped), panda"])
def test_the_arm_delivers_other_scenes(tmp_path, scene, runs):
    """The tray's first run (the grid of feet) is the one whose wedge slipped 0.63 mm with a rigid
    tool integrated implicitly (arm_sim's docstring)."""
    path = ROOT / "scenes" / scene
    run = plan(str(path), "--simulate", runs, cwd=tmp_path)
    assert run.returncode == 0, run.stdout + run.stderr
    assert f"pusher held by the {yaml.safe_load(path.read_text())['robot']['model']} arm" in run.stdout


@pytest.mark.slow
def test_simulate_with_an_arm_that_cannot_follow_says_so_and_exits_3(tmp_path, monkeypatch, capsys):
    """--simulate without --trajectory checks the joints itself: with the reach zone widened 30 cm
    past the arm's reach (as in test_joints.py), around's plan goes where the arm cannot hold the
    pusher, and the run is not passed off as the arm's success."""
    import planner.world.reach
    from planner.cli import main

    monkeypatch.setattr(planner.world.reach, "RING_MARGIN", -0.3)
    code = main([str(AROUND), "--simulate", "1", "--seed", "1", "--out", str(tmp_path / "out")])
    out = capsys.readouterr().out
    assert code == 3, out
    assert "arm: CANNOT FOLLOW:" in out and "simulate 1/1" in out


@pytest.mark.slow
def test_the_closed_loop_with_the_arm_delivers_a_part_the_open_loop_misses(tmp_path, capsys):
    """around's part started 15 mm, -10 mm and 8 degrees off: the arm run open loop misses the goal
    (exit 3); closed loop, the arm's servos following the re-planned pusher as the loop goes, it is
    delivered (exit 0), no link touching anything."""
    from planner.cli import main

    error = ["--sim-start-error", "0.015", "-0.01", "8", "--seed", "1"]
    assert main([str(AROUND), "--simulate", "1", *error, "--out", str(tmp_path / "open")]) == 3
    assert "pusher held by the panda arm" in capsys.readouterr().out
    assert main([str(AROUND), "--simulate", "1", "--closed-loop", *error, "--out", str(tmp_path / "closed")]) == 0, \
        capsys.readouterr().out


@pytest.mark.slow
def test_the_closed_loop_with_the_arm_delivers_through_the_overhead_camera(tmp_path, capsys):
    """The same start seen through the default overhead camera: the Panda's forearm and hand hide
    the part for about half of the run (it is pushed on blind and looked for where the plan has
    it), and it is delivered (exit 0), no estimate more than 10 degrees off. A corner of it seen
    alone fitted the outline a quarter turn off as well as the right way, in every run before the
    estimator kept, of two fits as good, the one nearer the prior (93 degrees off at worst; the loop
    then lost the part in 3 of 6 runs); tests/planner/perception/test_estimation.py."""
    from planner.cli import main

    error = ["--sim-start-error", "0.015", "-0.01", "8", "--seed", "1"]
    code = main([str(AROUND), "--simulate", "1", "--closed-loop", "--observe", "camera", *error,
                 "--out", str(tmp_path / "camera")])
    out = capsys.readouterr().out
    assert code == 0, out
    lost = float(re.search(r"lost (\d+\.\d) s", out).group(1))
    worst = float(re.search(r"mm, [\d.]+/[\d.]+/([\d.]+) deg \(median/p95/worst\)", out).group(1))
    assert lost > 5.0 and worst < 10.0, out


def test_the_depth_camera_sees_the_arm_over_the_table():
    """The default overhead camera over around, the arm at its first posture of the plan: the pixel
    through the flange's origin reads at most that point's z-depth (the flange's link is round it),
    and well short of the table behind it."""
    from planner.execution.arm_sim import sim_arm
    from planner.execution.depth_camera import DepthCamera
    from planner.model.camera import read_camera

    scene = load_scene(AROUND)
    plan_ = Planner(scene).plan()
    setup = mujoco_sim.perturbations(scene, plan_)
    arm = sim_arm(scene.robot, setup.lead, setup.motion, joints_along(scene.robot, setup.motion))
    world = mujoco_sim.World(scene, {scene.part().name: mujoco_sim.feet(scene, 1)[0]}, None, scene.starts, (), arm)
    camera = read_camera(None, scene.workspace)
    depth = DepthCamera(world, camera).exact()
    flange = world.data.site_xpos[world.flange].copy()
    u, v = np.round(camera.pixels(flange)).astype(int)
    along = (flange - camera.position) @ camera.T_world_camera[:3, 2]
    behind = (np.array([*flange[:2], 0.0]) - camera.position) @ camera.T_world_camera[:3, 2]
    assert 0 < depth[v, u] <= along + 1e-3 and depth[v, u] < behind - 0.1
