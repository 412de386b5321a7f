"""Issue 40's knock case through the command line: a part knocked 2.5 cm and 12 degrees in the
middle of its push misses the goal open loop (exit 3) and is delivered by the closed loop that sees
it only through the camera (exit 0)."""

from __future__ import annotations

from pathlib import Path

from planner.cli import main

ROOT = Path(__file__).resolve().parents[3]
#: scenes/battery.yaml's run is a 0.8 s lead-in and a 1.8 s push: 1.5 s is 0.7 s into the push. The
#: knock is (15, -20) mm, 25 mm long, and 12 degrees.
KNOCK = ["--sim-bump", "1.5", "0.015", "-0.02", "12"]


def test_a_mid_push_knock_misses_open_loop_and_the_camera_loop_delivers(tmp_path, capsys):
    # A small, slow camera (212 x 120 pixels, 10 frames a second, 0.1 s late) keeps the run short.
    scene = tmp_path / "battery.yaml"
    scene.write_text((ROOT / "scenes" / "battery.yaml").read_text()
                     + "camera: {resolution: [212, 120], rate: 10, latency: 0.1}\n")
    assert main([str(scene), "--simulate", "1", *KNOCK, "--out", str(tmp_path / "open")]) == 3
    assert "misses the goal" in capsys.readouterr().out
    assert main([str(scene), "--simulate", "1", *KNOCK, "--closed-loop", "--observe", "camera",
                 "--out", str(tmp_path / "camera")]) == 0
    run = next(line for line in capsys.readouterr().out.splitlines() if line.startswith("closed loop 1/1"))
    # It saw the knock (a re-plan from the knocked pose), never lost the part, and ended in the goal.
    assert "1 re-plan" in run and "off the plan by 2" in run and "lost 0.0 s" in run and run.endswith(": ok"), run
