"""A scene's ``camera:`` block: its defaults, its geometry, its round trip and its one-line errors
(through the command line: ``plan scene.yaml`` exits 1 before planning)."""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml

from planner.cli import main
from planner.model.camera import read_camera
from planner.model.scene_file import load_scene, parse_scene, plain_scene

ROOT = Path(__file__).resolve().parents[3]
SCENES = ROOT / "scenes"


def with_camera(tmp_path: Path, scene: str, camera) -> Path:
    spec = yaml.safe_load((SCENES / scene).read_text())
    spec["camera"] = camera
    path = tmp_path / Path(scene).name
    path.write_text(yaml.safe_dump(spec))
    return path


def test_the_default_camera_looks_straight_down_and_sees_the_whole_workspace():
    """Every workspace corner projects inside the image, and one side of the image is nearly filled
    (the 5 % margin): the camera is no higher than it must be."""
    workspace = (-0.55, -0.10, 0.55, 0.40)
    camera = read_camera(None, workspace)
    assert camera.position[:2] == pytest.approx([0.0, 0.15]) and camera.look_at == pytest.approx([0.0, 0.15])
    corners = np.array([[x, y, 0.0] for x in workspace[::2] for y in workspace[1::2]])
    local = (corners - camera.position) @ camera.T_world_camera[:3, :3]
    pixels = local[:, :2] / local[:, 2:] * camera.focal + (np.array(camera.resolution) - 1) / 2
    width, height = camera.resolution
    assert (pixels >= 0).all() and (pixels[:, 0] <= width - 1).all() and (pixels[:, 1] <= height - 1).all()
    # The x extent (1.1 m) is the tighter one at 848 x 480: it spans 848 / 1.05 pixels.
    assert np.ptp(pixels[:, 0]) == pytest.approx(848 / 1.05, abs=1.0)


def test_a_ray_through_the_image_centre_meets_the_table_at_look_at():
    camera = read_camera({"position": [0.1, -0.2, 0.8], "look_at": [0.3, 0.0], "yaw": 30}, (-1, -1, 1, 1))
    centre = (np.array(camera.resolution) - 1) / 2
    ray = camera.rays(centre)
    hit = camera.position + (-camera.position[2] / ray[2]) * ray
    assert hit[:2] == pytest.approx([0.3, 0.0], abs=1e-12)
    # Unit z-depth: the ray's component along the optical axis is 1.
    assert ray @ camera.T_world_camera[:3, 2] == pytest.approx(1.0)


def test_moved_shifts_the_camera_and_tilts_its_view_by_the_angle_asked():
    camera = read_camera({}, (-0.5, -0.5, 0.5, 0.5))
    tilted = camera.moved(shift=[0.01, 0.0, 0.0], tilt=math.radians(1.0))
    assert tilted.position.tolist() == pytest.approx((camera.position + [0.01, 0, 0]).tolist())
    cos = camera.T_world_camera[:3, 2] @ tilted.T_world_camera[:3, 2]
    assert math.degrees(math.acos(min(1.0, cos))) == pytest.approx(1.0, abs=1e-9)


def test_the_camera_block_is_written_back_as_read(tmp_path):
    path = with_camera(tmp_path, "parts/swap.yaml", {"position": [0.1, 0.0, 1.2], "look_at": [0.0, 0.05], "yaw": 20,
                                                     "resolution": [320, 240], "fov": 45, "noise": 0.002,
                                                     "quantisation": 0.0005, "rate": 15, "latency": 0.1})
    camera = load_scene(path).camera
    again = parse_scene(plain_scene(load_scene(path))).camera
    for c in (camera, again):
        assert (c.resolution, c.noise, c.quantisation, c.rate, c.latency) == ((320, 240), 0.002, 0.0005, 15.0, 0.1)
        assert math.degrees(c.fov) == pytest.approx(45) and math.degrees(c.yaw) == pytest.approx(20)
        assert np.allclose(c.T_world_camera, camera.T_world_camera)
    assert load_scene(SCENES / "parts" / "swap.yaml").camera is None  # no block, no camera


def test_a_bare_camera_key_is_the_default_camera(tmp_path):
    camera = load_scene(with_camera(tmp_path, "junction.yaml", None)).camera
    assert camera.resolution == (848, 480) and camera.noise == 0.0037 and camera.rate == 30.0


@pytest.mark.parametrize("camera, line", [
    ({"position": [0, 0, 0]}, "camera.position: must be above the table (z > 0), got z = 0"),
    ({"position": [0, 0, -0.5]}, "camera.position: must be above the table (z > 0), got z = -0.5"),
    ({"fov": 0}, "camera.fov: must be between 0 and 180 degrees (the vertical field of view), got 0"),
    ({"fov": 180}, "camera.fov: must be between 0 and 180 degrees (the vertical field of view), got 180"),
    ({"noise": -0.001}, "camera.noise: must be >= 0, got -0.001"),
    ({"quantisation": -1}, "camera.quantisation: must be >= 0, got -1"),
    ({"latency": -0.1}, "camera.latency: must be >= 0, got -0.1"),
    ({"rate": 0}, "camera.rate: must be > 0, got 0"),
    ({"resolution": [0, 480]}, "camera.resolution: must be 1 to 4096 pixels a side, got [0, 480]"),
    ({"resolution": [640]}, "camera.resolution: must be [width, height] in pixels, got [640]"),
    ({"resolution": [640.5, 480]}, "camera.resolution[0]: must be an integer, got 640.5"),
    ({"noise": float("nan")}, "camera.noise: must be a finite number, got nan"),
    ({"position": [0, float("nan"), 1]}, "camera.position[1]: must be a finite number, got nan"),
    ({"position": [0, 0, 0.1], "look_at": [1.0, 0]}, "camera.look_at: tilts the view 84.3 degrees from straight down "
                                                     "(at most 80: the camera must look at the table)"),
    ({"zoom": 2}, "camera.zoom: unknown key (known: position, look_at, yaw, resolution, fov, noise, quantisation, "
                  "rate, latency)"),
    ([1, 2], "camera: must be a mapping with keys position, look_at, yaw, resolution, fov, noise, quantisation, rate, "
             "latency"),
])
def test_a_camera_that_makes_no_sense_is_one_line_exit_1(tmp_path, capsys, camera, line):
    for scene in ("junction.yaml", "parts/swap.yaml"):  # both forms of scene
        path = with_camera(tmp_path, scene, camera)
        assert main([str(path), "--out", str(tmp_path / "out")]) == 1
        assert capsys.readouterr().err == f"plan: error: {line}\n"
        assert not (tmp_path / "out").exists()


def test_the_command_prints_no_traceback_for_a_camera_under_the_table(tmp_path):
    path = with_camera(tmp_path, "junction.yaml", {"position": [0.0, 0.0, -1.0]})
    run = subprocess.run([sys.executable, "-m", "planner.cli", str(path), "--out", "out"], capture_output=True,
                         text=True, cwd=tmp_path, timeout=120, env={"PYTHONPATH": str(ROOT), "PATH": "/usr/bin:/bin"})
    assert (run.returncode, run.stdout) == (1, "")
    assert run.stderr == "plan: error: camera.position: must be above the table (z > 0), got z = -1\n"
