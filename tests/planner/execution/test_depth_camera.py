"""The simulated depth camera: its images against depths worked out by hand, its noise against
the sensor model it claims, and its occlusions."""

from __future__ import annotations

import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from planner.execution.depth_camera import PART_TOP
from staged import BOX, staged, table

ROOT = Path(__file__).resolve().parents[3]


def inside(scene, depth: np.ndarray) -> np.ndarray:
    """The pixels of ``depth`` that see the workspace (the default camera sees 5 % beyond it, where
    the workspace's walls, 3 cm high, stand)."""
    xmin, ymin, xmax, ymax = scene.workspace
    v, u = np.mgrid[0:depth.shape[0], 0:depth.shape[1]]
    rays = scene.camera.rays(np.stack([u, v], axis=-1).astype(float))
    xy = scene.camera.position[:2] + (-scene.camera.position[2] / rays[..., 2])[..., None] * rays[..., :2]
    return (xy[..., 0] > xmin) & (xy[..., 0] < xmax) & (xy[..., 1] > ymin) & (xy[..., 1] < ymax)


def test_a_camera_looking_straight_down_reads_its_height_everywhere_on_the_table():
    """z-depth, not ray length: the table is square to the optical axis, so every pixel's depth is
    the camera's height (0.947 m for the default camera of a 1 m table), at the workspace's corners
    too; beyond it the walls' tops read 3 cm less."""
    scene = table({"a": BOX})
    _, camera = staged(scene, {"a": [5.0, 5.0, 0.0]})  # the part off the table: only the table is seen
    depth = camera.exact()
    h = scene.camera.position[2]
    assert depth.shape == (480, 848)
    seen = inside(scene, depth)
    # The square workspace fills 1 / 1.05 of the image's height and as many pixels across.
    assert seen.mean() == pytest.approx(1 / 1.05 * 480 / 1.05 / 848, abs=0.005)
    assert np.abs(depth[seen] - h).max() < 1e-9
    assert np.isclose(depth[~seen], h - 0.03, atol=1e-9).any()


def test_a_tilted_camera_reads_the_slant_distance_at_its_centre_and_more_at_its_far_edge():
    """From (0, 0, 0.6) looking at (0.3, 0): the optical axis meets the table 0.6708 m away (the
    hypotenuse); the image's right (+x, yaw 0) looks further from straight down."""
    scene = table({"a": BOX}, camera={"position": [0, 0, 0.6], "look_at": [0.3, 0.0], "resolution": [101, 81],
                                      "fov": 40})
    _, camera = staged(scene, {"a": [5.0, 5.0, 0.0]})
    depth = camera.exact()
    assert depth[40, 50] == pytest.approx(math.hypot(0.6, 0.3), abs=1e-9)
    # The ray through the middle of the last column, 50 pixels right of the centre: the focal
    # length is 40.5 / tan 20 degrees (half the height over half the fov), so the ray is
    # atan(50 / focal) off the axis, whose angle of depression is atan(0.6 / 0.3); it meets the
    # table at the depression less that, and its z-depth is its length times the cosine of that.
    off = math.atan(50 / (40.5 / math.tan(math.radians(20.0))))
    down = math.atan2(0.6, 0.3) - off
    assert depth[40, 100] == pytest.approx(0.6 / math.sin(down) * math.cos(off), rel=1e-9)


def test_the_part_and_the_pusher_stand_out_of_the_table_by_their_heights():
    """Under the camera (straight down, height h) the part's top reads h - 6 mm and the pusher's
    top h - 16 mm (mujoco_sim: a 4 mm prism on 1 mm feet; the pusher 1 cm above that)."""
    scene = table({"a": BOX})
    h = scene.camera.position[2]
    _, camera = staged(scene, {"a": [0.0, 0.0, 0.3]}, pusher=(0.2, 0.0, 0.0, 0.0))
    depth = camera.exact()
    # The pusher's body lies behind its face, x from -1 cm to 0 in its frame: its middle at x = -5 mm.
    centre = np.round(scene.camera.pixels([[0.0, 0.0, 0.0], [0.195, 0.0, 0.0]])).astype(int)
    assert depth[centre[0, 1], centre[0, 0]] == pytest.approx(h - PART_TOP, abs=1e-9) == pytest.approx(h - 0.006)
    assert depth[centre[1, 1], centre[1, 0]] == pytest.approx(h - 0.016, abs=1e-9)


def test_the_pusher_hides_the_part_under_it():
    scene = table({"a": BOX})
    h = scene.camera.position[2]
    _, camera = staged(scene, {"a": [0.0, 0.0, 0.0]}, pusher=(0.0, 0.0, 0.007, 0.0))  # just over the part
    u, v = np.round(scene.camera.pixels([-0.005, 0.0, 0.0])).astype(int)
    assert camera.exact()[v, u] == pytest.approx(h - 0.007 - 0.016, abs=1e-9)


def test_the_noise_is_the_sensors_and_the_readings_are_quantised():
    """A flat table at 0.947 m: deviation noise * depth^2 (3.7 mm * 0.897 = 3.3 mm), mean the true
    depth, every reading a whole number of millimetres; the same seed gives the same image."""
    scene = table({"a": BOX})
    h = scene.camera.position[2]
    _, camera = staged(scene, {"a": [5.0, 5.0, 0.0]})
    image = camera.image(np.random.default_rng(7))
    table_only = image[inside(scene, image)]
    assert np.std(table_only) == pytest.approx(0.0037 * h ** 2, rel=0.02)
    assert np.mean(table_only) == pytest.approx(h, abs=1e-4)
    assert np.abs(image / 0.001 - np.round(image / 0.001)).max() < 1e-6
    assert np.array_equal(image, camera.image(np.random.default_rng(7)))


RENDERED = """
import numpy as np
from staged import BOX, staged, table
from planner.execution.depth_camera import RenderedDepthCamera
scene = table({"a": BOX}, camera={"look_at": [0.1, 0.05], "yaw": 20})
world, rays = staged(scene, {"a": [0.1, 0.1, 0.3]}, pusher=(0.0, 0.0, 0.0, 0.5))
try:
    rendered = RenderedDepthCamera(world, scene.camera)
except Exception as err:  # no EGL here
    print("no renderer:", type(err).__name__, err)
    raise SystemExit(0)
gap = np.abs(rendered.exact() - rays.exact())
print("near", float(np.mean(gap < 1e-4)), "far", float(np.mean(gap > 0.002)))
"""


def test_the_renderer_draws_the_depths_the_rays_find_where_egl_works():
    """MuJoCo's OpenGL renderer (EGL, in a fresh interpreter: MUJOCO_GL is read at import) gives
    the ray caster's depths but where an edge crosses a pixel (the depth buffer's pixel is not its
    centre's ray), and 0 where the rays meet nothing (a tilted view past the table's end)."""
    run = subprocess.run([sys.executable, "-c", RENDERED], capture_output=True, text=True, timeout=120,
                         env={**os.environ, "MUJOCO_GL": "egl", "PYTHONPATH": os.pathsep.join(
                             [str(ROOT), str(ROOT / "tests" / "planner" / "perception")])})
    assert run.returncode == 0, run.stderr
    if run.stdout.startswith("no renderer:"):
        pytest.skip(run.stdout.strip())
    near, far = (float(v) for v in run.stdout.split()[1::2])
    assert near > 0.99 and far < 0.005, run.stdout
