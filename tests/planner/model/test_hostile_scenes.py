"""Issue 12: the hostile scene files a fuzz run found, each with the minimal scene of the issue.

Each bad scene must give exit code 1 and one printable line ``plan: error: <field>: <problem>`` of at
most 300 characters naming the real cause, with plain numbers, and write nothing (the contract of
tests/planner/test_cli.py). The limits tested are the README's (``Limits and YAML``).
"""

from __future__ import annotations

import json
import math
import re
import subprocess
import sys
import time

import numpy as np
import pytest
import yaml

from planner.cli import main
from planner.model.fields import SceneError
from planner.model.scene_file import _simple_polygon, load_scene
from test_cli import BATTERY_TEXT, VERTICES, assert_nothing_written, battery, error_field, nested, run_plan, write

#: An eight-pointed star: its vertices alternate between two radii, so no edge lies on its hull.
STAR = [[round((0.05 if k % 2 else 0.02) * math.cos(k * math.pi / 8), 6),
         round((0.05 if k % 2 else 0.02) * math.sin(k * math.pi / 8), 6)] for k in range(16)]


def scaled(points: list, factor: float) -> list:
    return [[x * factor for x in p] for p in points]


def alias_bomb(levels: int = 8, width: int = 8) -> str:
    """A YAML flow list of ``levels`` items, each an anchored list of ``width`` aliases of the item
    before it: ``width ** levels`` values (16.7 million for the issue's 8 x 8) from a few hundred bytes."""
    items = [f"&l0 [{', '.join(['x'] * width)}]"]
    items += [f"&l{i} [{', '.join([f'*l{i - 1}'] * width)}]" for i in range(1, levels)]
    return f"[{', '.join(items)}]"


def replaced(line: str, new: str) -> str:
    """The battery scene's text with the line starting ``line`` replaced by ``new``."""
    lines = BATTERY_TEXT.splitlines()
    (k,) = [i for i, text in enumerate(lines) if text.startswith(line)]
    return "\n".join([*lines[:k], new, *lines[k + 1:]]) + "\n"


HOSTILE = {
    # (scene, the field the message must name, words the line must hold)
    # 1. Huge numbers: beyond the README's limits, one line naming the number at fault.
    "part near 1e154": (nested("slider.vertices", scaled(VERTICES, 1e154 / 0.02425)), "slider.vertices[0][0]",
                        ["at most 1000 m", "-1e+154"]),
    "part near 1e160 (was an OverflowError)": (nested("slider.vertices", scaled(VERTICES, 1e160)),
                                               "slider.vertices[0][0]", ["at most 1000 m"]),
    "obstacle polygon at 1e160": (battery(obstacles=[{"polygon": [[0.1, 0.1], [1e160, 0.1], [0.1, 1e160]]}]),
                                  "obstacles[0].polygon[1][0]", ["at most 1000 m"]),
    "workspace of +-1e200": (battery(workspace={"min": [-1e200, -1e200], "max": [1e200, 1e200]}), "workspace.min[0]",
                             ["at most 1000 m", "-1e+200"]),
    "box at 1e300": (nested("obstacles.0.box.center", [1e300, 1e300]), "obstacles[0].box.center[0]",
                     ["at most 1000 m"]),
    "goal angle of 1e300 degrees": (battery(goal=[0.05798, 0.02116, 1e300]), "goal[2]", ["at most 1e+06 degrees"]),
    "workspace just beyond 1000 m": (battery(workspace={"min": [-0.12, -0.12], "max": [1000.001, 0.15]}),
                                     "workspace.max[0]", ["1000.001"]),
    "box angle beyond 1e6 degrees": (nested("obstacles.0.box.angle", -1.5e6), "obstacles[0].box.angle", ["degrees"]),
    "pusher thinner than a micron": (nested("pusher.depth", 9e-7), "pusher.depth", ["at least 1e-06 m", "9e-07"]),
    "edge of 1e-300 m (was a division by zero)": (
        nested("slider.vertices", [[-0.02425, -0.01325], [0.02425, -0.01325], [0.02425, 0.0], [0.02425, 1e-300],
                                   [0.02425, 0.01325], [-0.02425, 0.01325]]), "slider.vertices",
        ["vertices 2 and 3 coincide (closer than 1e-06 m)"]),
    "box thinner than a micron": (nested("obstacles.0.box.size", [0.04, 1e-9]), "obstacles[0].box.size",
                                  ["at least 1e-06 m"]),
    "mu of 1e300 (was an OverflowError)": (nested("pusher.mu", 1e300), "pusher.mu", ["from 0.001 to 1000"]),
    "mu interval reaching 1e-300": (nested("pusher.mu", [1e-300, 0.5]), "pusher.mu", ["from 0.001 to 1000"]),
    "switch cost of 1e300 metres": (battery(planner={"switch_cost": 1e300}), "planner.switch_cost", ["1000 m"]),
    # 2. Aliases: the bomb through each field it named; long values quoted short.
    "alias bomb in name": (replaced("name:", f"name: {alias_bomb()}"), "scene", ["aliases"]),
    "alias bomb in planner.name": (BATTERY_TEXT + f"planner: {{name: {alias_bomb()}}}\n", "scene", ["aliases"]),
    "alias bomb in slider.vertices": (replaced("  vertices:", f"  vertices: {alias_bomb()}"), "scene", ["aliases"]),
    "alias of itself": (replaced("name:", "name: &a [*a]"), "scene", ["alias *a"]),
    "a name of 99000 values": (replaced("name:", f"name: [{', '.join(['0'] * 99_000)}]"), "name",
                               ["[0, 0, 0, 0, 0, 0, 0, 0, ...]"]),
    "a transit of 10000 characters": (nested("pusher.transit", "t" * 10_000), "pusher.transit", ["must be one of"]),
    "a file over a megabyte": (BATTERY_TEXT + "#" * 1_000_000, "scene", ["larger than 1000000 bytes"]),
    "nested 17 deep": (battery(name=[[[[[[[[[[[[[[[[[0]]]]]]]]]]]]]]]]]), "scene", ["nest more than 16 deep"]),
    # 3. Control characters are escaped, in keys and in values.
    "key 'a\\nb'": (battery(**{"a\nb": 1}), "'a\\nb'", ["unknown key"]),
    "nested key with a tab": (nested("pusher.a\tb", 1), "pusher.'a\\tb'", ["unknown key"]),
    "name with a line separator": (battery(name="a\u2028b"), "name", ["'a\\u2028b'"]),
    "transit with an escape sequence": (nested("pusher.transit", "\x1b[2Jplane"), "pusher.transit", ["\\x1b"]),
    # 4. YAML 1.2, not 1.1: 1:30 is a string, and a key given twice is an error naming it.
    "mu 1:30 (was 90)": (BATTERY_TEXT.replace("mu: 1.0", "mu: 1:30"), "pusher.mu", ["number", "'1:30'"]),
    "tolerance yes (was true)": (BATTERY_TEXT.replace("angle: 1.0}", "angle: yes}"), "tolerance.angle", ["'yes'"]),
    "duplicate top-level key": (BATTERY_TEXT + "start: [0.0, 0.0, 90.0]\n", "start", ["duplicate key", "line 15"]),
    "duplicate key in a mapping": (BATTERY_TEXT.replace("mu: 1.0", "mu: 1.0\n  mu: 0.2"), "pusher.mu",
                                   ["duplicate key", "line 10", "line 11"]),
    "duplicate key in a list's mapping": (BATTERY_TEXT.replace("angle: 15}", "angle: 15, angle: 0}"),
                                          "obstacles[0].box.angle", ["duplicate key"]),
    "a tag of YAML 1.1": (BATTERY_TEXT.replace("depth: 0.01", "depth: !!float 1:30"), "scene", ["'1:30'"]),
    # 5. The real cause, in plain numbers.
    "an eight-pointed star": (battery(slider={"vertices": STAR}, pusher={"width": 0.02, "depth": 0.01, "mu": 0.5}),
                              "slider.vertices", ["no edge lies on the part's convex hull"]),
    "negative box size": (nested("obstacles.0.box.size", [-0.1, 0.1]), "obstacles[0].box.size",
                          ["must be positive, got [-0.1, 0.1]"]),
}


@pytest.mark.parametrize("case", HOSTILE, ids=str)
def test_hostile_scene_exits_1_with_one_short_line_naming_the_field(case, tmp_path, monkeypatch, capsys):
    scene, field, words = HOSTILE[case]
    write(tmp_path, scene)
    monkeypatch.chdir(tmp_path)
    clock = time.perf_counter()
    assert main(["scene.yaml"]) == 1
    assert time.perf_counter() - clock < 3.0  # the alias bomb took 11 s and 1.5 GB
    captured = capsys.readouterr()
    assert captured.out == ""
    assert error_field(captured.err) == field
    line = captured.err.rstrip("\n")
    assert line.isprintable() and len(line) <= 300 and "np.float64" not in line, line
    for word in words:
        assert word in line
    assert_nothing_written(tmp_path, {"scene.yaml"})


def test_cf_uncertainty_too_large_for_any_stable_push_is_named(tmp_path, monkeypatch, capsys):
    # Half the battery's radius (0.0276 m): the exact regions for every CF in the disk are empty,
    # though with the CF known the edge has stable pushes. It used to blame pusher.edges.
    write(tmp_path, nested("slider.cf_uncertainty", 0.0139))
    monkeypatch.chdir(tmp_path)
    assert main(["scene.yaml", "--out", "out"]) == 1
    captured = capsys.readouterr()
    assert error_field(captured.err) == "slider.cf_uncertainty" and "too large" in captured.err
    assert_nothing_written(tmp_path, {"scene.yaml"})


@pytest.mark.parametrize("case", ["box at 1e300", "alias bomb in name"])
def test_command_prints_no_warning_and_no_traceback(case, tmp_path):
    # The box at 1e300 used to be planned, and the recording printed an overflow warning.
    write(tmp_path, HOSTILE[case][0])
    run = run_plan("scene.yaml", cwd=tmp_path)
    assert run.returncode == 1 and run.stdout == ""
    assert error_field(run.stderr) == HOSTILE[case][1]
    assert_nothing_written(tmp_path, {"scene.yaml"})


# --- what the limits still accept --------------------------------------------------------------------

def test_scenes_at_the_limits_are_read(tmp_path):
    spec = battery(workspace={"min": [-1000.0, -0.12], "max": [0.18, 1000]}, goal=[0.05798, 0.02116, 1e6],
                   tolerance={"position": 1e-6, "angle": 6e-8})  # the least a 1 km table resolves (MIN_TOLERANCE)
    spec["pusher"] |= {"width": 1e-6, "depth": 1000, "mu": [0.001, 1000]}
    spec["obstacles"][0]["box"] |= {"size": [1e-6, 0.03], "angle": -1e6}
    scene = load_scene(write(tmp_path, spec))
    assert scene.workspace == (-1000.0, -0.12, 0.18, 1000.0)
    assert (scene.pusher.width, scene.pusher.mu, scene.pusher.mu_high) == (1e-6, 0.001, 1000.0)
    assert scene.goal[2] == pytest.approx(math.radians(1e6 - 2778 * 360))  # -80 degrees, within 1e-9 rad


def test_aliases_a_yaml_writer_makes_for_shared_values_are_read(tmp_path):
    spec = battery()
    spec["goal"] = spec["start"] = [0.01, 0.0, 0.0]  # one list in two places: the dump aliases it
    text = yaml.safe_dump(spec)
    assert "&id" in text and "*id" in text
    scene = load_scene(write(tmp_path, text))
    np.testing.assert_array_equal(scene.start, scene.goal)


def test_yaml_1_2_integers(tmp_path):
    # YAML 1.1 read 017 as octal 15; YAML 1.2 reads it as 17 and writes octal as 0o17.
    scene = load_scene(write(tmp_path, BATTERY_TEXT + "planner: {seed: 017, time_limit: 0o17}\n"))
    assert (scene.options.seed, scene.options.time_limit) == (17, 15.0)


@pytest.mark.filterwarnings("ignore:overflow encountered in is_simple:RuntimeWarning")  # GEOS's own products
def test_the_zero_area_check_survives_squares_beyond_a_float():
    # np.ptp(points) ** 2 raised OverflowError from about 1e154 on. The limits now refuse such
    # scenes first (GEOS overflows there too), but the check itself must hold for any finite polygon.
    assert _simple_polygon(np.array([[0.0, 0.0], [1e200, 0.0], [0.0, 1e200]]), "p").area > 0
    with pytest.raises(SceneError, match="zero area"):
        _simple_polygon(np.array([[0.0, 0.0], [1e200, 0.0], [2e200, 0.0]]), "p")


# --- first-hour papercuts ----------------------------------------------------------------------------

@pytest.mark.parametrize("degrees, expected", [(180.0, -180.0), (540.0, -180.0), (-180.0, -180.0), (179.5, 179.5),
                                               (-900.0, -180.0), (270.0, -90.0)])
def test_scene_angles_are_wrapped_like_the_plans(degrees, expected, tmp_path):
    scene = load_scene(write(tmp_path, battery(start=[0.0, 0.0, degrees])))
    assert scene.start[2] == pytest.approx(math.radians(expected), abs=1e-12)


def test_plan_start_and_its_first_segment_agree_on_the_angle(tmp_path, monkeypatch, capsys):
    # The battery scene turned by 180 degrees about the origin: its start heading is 180 degrees,
    # which the plan wrote as 3.14159 while its first segment started at -3.14159.
    turned = battery(start=[0.0, 0.0, 180.0], goal=[-0.05798, -0.02116, 220.107],
                     obstacles=[{"box": {"center": [-0.10, 0.06], "size": [0.04, 0.03], "angle": 195}}],
                     workspace={"min": [-0.18, -0.15], "max": [0.12, 0.12]})
    write(tmp_path, turned)
    monkeypatch.chdir(tmp_path)
    assert main(["scene.yaml", "--out", "out"]) == 0
    capsys.readouterr()
    data = json.loads((tmp_path / "out" / "battery.json").read_text())
    assert data["start"][2] == data["segments"][0]["start"][2] == pytest.approx(-math.pi)
    assert data["goal"][2] == pytest.approx(math.radians(220.107 - 360))


def test_figures_without_matplotlib_say_which_extra_to_install():
    hide = ("import runpy, sys; sys.modules['matplotlib'] = None; "  # None: `import matplotlib` fails
            "runpy.run_module('mechanics.figures', run_name='__main__', alter_sys=True)")
    run = subprocess.run([sys.executable, "-c", hide], capture_output=True, text=True, timeout=60)
    assert run.returncode == 1 and run.stdout == ""
    assert run.stderr.splitlines() == [
        "python -m mechanics.figures needs matplotlib, which the figures extra installs: pip install -e '.[figures]'"]


def test_bench_help_describes_every_argument(capsys):
    from planner.bench.planners import main as bench

    with pytest.raises(SystemExit) as exit_:
        bench(["--help"])
    assert exit_.value.code == 0
    text = capsys.readouterr().out
    arguments = text[text.index("positional arguments:"):text.index("Columns:")]
    # An argument's entry starts two spaces in: its name (and metavar), then, two spaces on or on
    # the next lines, what it means.
    entries = [entry.strip().partition("  ") for entry in re.split(r"\n  (?=\S)", arguments)[1:]]
    names = [name.split()[0].rstrip(",") for name, _, _ in entries]
    assert names == ["SCENE", "-h", "--runs", "--planners", "--time-limit", "--transit", "--workers", "--engine",
                     "--address", "--quality", "--ompl-log"]
    for name, _, meaning in entries:
        assert len(meaning.split()) >= 4, f"{name} is not described"
