"""The arm benchmark (planner.bench.arm) runs and prints a row a scene, with numbers in every cell."""

from __future__ import annotations

from pathlib import Path

import pytest

pytest.importorskip("mink", reason="the arm extra is not installed: pip install 'stablepush[arm]'")

ROOT = Path(__file__).resolve().parents[3]


def test_the_arm_benchmark_prints_a_row_per_scene(capsys):
    from planner.bench.arm import HEADER, main

    assert main([str(ROOT / "scenes" / "parts" / "swap.yaml"), "--robot", "panda", "0", "-0.4", "90", "--seeds", "1"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[:2] == HEADER.splitlines() and len(lines) == 3
    cells = [c.strip() for c in lines[2].strip("|").split("|")]
    assert cells[:2] == ["swap", "panda"] and cells[7] == "follows"
    assert all(c for c in cells) and int(cells[8]) > 0 and float(cells[10].replace(",", "")) > 0


def test_a_scene_without_a_robot_needs_the_flag(capsys):
    from planner.bench.arm import main

    with pytest.raises(SystemExit) as exit:
        main([str(ROOT / "scenes" / "parts" / "swap.yaml")])
    assert exit.value.code == 1 and "has no robot block: give one with --robot" in capsys.readouterr().err
