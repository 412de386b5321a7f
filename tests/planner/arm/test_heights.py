"""Obstacles' heights (issue 39): an obstacle's ``height:`` is read, written back and, where it is
taller than the arm's links come down, kept out from under them; checked against the scene file's
numbers by hand and, for a whole plan, by the independent forward kinematics of test_joints: no
link capsule of the arm comes into a tall obstacle's prism on any row of the joints file."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yaml

pytest.importorskip("mink", reason="the arm extra is not installed: pip install 'stablepush[arm]'")

from planner.cli import main  # noqa: E402 (after the skip)
from planner.model.fields import SceneError  # noqa: E402
from planner.model.scene import OBSTACLE_HEIGHT  # noqa: E402
from planner.model.scene_file import parse_scene, plain_scene  # noqa: E402
from planner.world.validity import CollisionModel  # noqa: E402
from test_joints import ARMS, check_joints, frames, rows  # noqa: E402

ROOT = Path(__file__).resolve().parents[3]
AROUND = yaml.safe_load((ROOT / "scenes" / "arm" / "around.yaml").read_text())


def _around(*obstacles: dict) -> dict:
    return {**AROUND, "obstacles": list(obstacles)}


def test_heights_are_read_with_their_default_and_written_back():
    scene = parse_scene(_around({"box": {"center": [0.5, 0.3], "size": [0.04, 0.04]}, "height": 0.3},
                                {"polygon": [[-0.5, 0.3], [-0.45, 0.3], [-0.45, 0.35]]}))
    assert scene.obstacle_heights == (0.3, OBSTACLE_HEIGHT)
    again = parse_scene(plain_scene(scene))
    assert again.obstacle_heights == (0.3, OBSTACLE_HEIGHT) and again.obstacles == scene.obstacles


@pytest.mark.parametrize("height", [-0.1, 0, "tall", float("nan"), [0.1]])
def test_a_bad_height_is_one_line_naming_it(height):
    with pytest.raises(SceneError) as caught:
        parse_scene(_around({"box": {"center": [0.5, 0.3], "size": [0.04, 0.04]}, "height": height}))
    assert caught.value.field == "obstacles[0].height"


def test_a_tall_post_between_the_base_and_the_pusher_blocks_the_arm():
    """The pusher alone at (0, 0.1) facing +y, straight away from the Panda's base at (0, -0.5):
    the arm's links stand over the segment between them. A post 4 cm square at (0, -0.2) is under
    it: taller than the links come down (0.082 m: the flange, 0.13 m up, less its capsule's
    0.048 m) it blocks the pose, lower it does not; 20 cm to the side it does not either."""
    pose = (0.0, 0.1, math.pi / 2)
    for centre, height, blocked in (((0.0, -0.2), 0.3, True), ((0.0, -0.2), 0.07, False), ((0.2, -0.2), 0.3, False)):
        scene = parse_scene(_around({"box": {"center": list(centre), "size": [0.04, 0.04]}, "height": height}))
        assert (CollisionModel(scene, scene.edges).pusher_clearance(pose) <= 0) == blocked, (centre, height)


def test_a_start_under_which_the_arm_would_meet_a_tall_post_is_refused_saying_so(tmp_path, capsys):
    post = {"box": {"center": [-0.2, -0.42], "size": [0.04, 0.04]}, "height": 0.4}  # between the base and the start
    path = tmp_path / "post.yaml"
    path.write_text(yaml.safe_dump(_around(post)))
    assert main([str(path), "--out", str(tmp_path / "out")]) == 1
    err = capsys.readouterr().err
    assert err.startswith("plan: error: start: out of the panda arm's reach: its links would pass over an obstacle "
                          "taller than") and err.count("\n") == 1, err


def _capsule_clear(a: np.ndarray, b: np.ndarray, box: tuple[float, float, float, float, float], radius: float) -> bool:
    """Whether the segment ``a``-``b`` keeps ``radius`` from the prism ``(x0, y0, x1, y1, height)``
    standing on the table (sampled every millimetre)."""
    x0, y0, x1, y1, top = box
    n = max(2, int(np.linalg.norm(b - a) / 1e-3))
    points = a + np.linspace(0.0, 1.0, n)[:, None] * (b - a)
    nearest = np.clip(points, [x0, y0, 0.0], [x1, y1, top])
    return bool((np.linalg.norm(points - nearest, axis=1) >= radius).all())


def test_the_arm_keeps_its_links_clear_of_tall_posts_it_works_beside(tmp_path, capsys):
    """around with two posts 0.4 m tall: one just outside the sector the arm sweeps (left of the
    start, seen from the base), one beyond where the part goes. The plan is followed and, by
    forward kinematics from Franka's numbers, no link capsule (6 cm thick, test_joints' frames)
    comes into either post on any row."""
    posts = [(-0.55, -0.37, -0.49, -0.31), (-0.03, 0.25, 0.03, 0.31)]
    spec = _around(*({"box": {"center": [(x0 + x1) / 2, (y0 + y1) / 2], "size": [x1 - x0, y1 - y0]}, "height": 0.4}
                     for x0, y0, x1, y1 in posts))
    path = tmp_path / "posts.yaml"
    path.write_text(yaml.safe_dump(spec))
    assert main([str(path), "--trajectory", "--seed", "1", "--out", str(tmp_path / "out")]) == 0, capsys.readouterr()
    check_joints(path, tmp_path / "out")
    robot = spec["robot"]
    base = (robot["base"][0], robot["base"][1], math.radians(robot["base"][2]))
    [joints] = (tmp_path / "out").glob("*.joints.csv")
    for row in rows(joints):
        chain = frames(ARMS["panda"], base, [float(row[f"q{k}"]) for k in range(1, 8)])
        points = [f[:3, 3] for f in chain]
        for a, b in zip(points[1:-1], points[2:]):
            assert all(_capsule_clear(a, b, (*post, 0.4), 0.06) for post in posts), row["t"]
