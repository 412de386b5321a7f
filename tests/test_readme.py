"""The README's promises: its two opening commands, CI running the same tests, the quick start's
commands and their output, the API examples, the CAD example."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from planner.model.extras import have

ROOT = Path(__file__).resolve().parent.parent
README = (ROOT / "README.md").read_text()


def opening_commands() -> list[str]:
    block = re.search(r"```bash\n(.*?)```", README, re.S).group(1)
    return [line.split("#")[0].strip() for line in block.strip().splitlines()]


def test_readme_opens_with_install_and_plan_then_tests():
    assert README.index("```bash") < 30
    install, tests = opening_commands()
    assert install.startswith("pip install -e . && plan scenes/")
    assert (ROOT / install.split("plan ")[1]).is_file()
    assert tests == "pip install -e '.[test]' && python -m pytest -q"


def test_the_opening_says_the_python_version_the_venv_and_where_regions_are_cached(monkeypatch):
    """Issue 41: a newcomer was told none of them. The version is the package's own, the folder
    the cache's default."""
    from planner.actions.region_cache import cache_folder

    opening = README[:README.index("## Quick start")]
    version = re.search(r'requires-python = ">=(\d+\.\d+)"', (ROOT / "pyproject.toml").read_text()).group(1)
    assert f"Python {version}+" in opening and "python3 -m venv .venv" in opening
    monkeypatch.delenv("STABLEPUSH_CACHE", raising=False)
    monkeypatch.delenv("XDG_CACHE_HOME", raising=False)
    assert f"`{str(cache_folder()).replace(str(Path.home()), '~')}`" in opening


def quick_start() -> str:
    start = README.index("## Quick start")
    return README[start:README.index("\n## ", start + 1) + 1]


def printed_as(lines: list[str]) -> re.Pattern:
    """What output matches the README's lines: ``...`` within a line stands for any text (times), a
    line of ``...`` alone for any lines."""
    return re.compile("".join(r"(?:.*\n)*?" if line == "..." else ".*".join(map(re.escape, line.split("..."))) + "\n"
                              for line in lines))


def test_the_quick_start_fills_the_first_60_lines_with_the_viewer_command():
    assert README[:README.index(quick_start()) + len(quick_start())].count("\n") <= 60
    assert "$ rerun logs/parking/parking.rrd" in quick_start()
    assert printed_as(["a ... s", "..."]).fullmatch("a 1.5 s\nmore\nlines\n")
    assert not printed_as(["a ... s"]).fullmatch("b 1.5 s\n")


def test_every_quick_start_command_runs_as_written_and_prints_what_it_says(tmp_path, monkeypatch, capsys):
    """Each ``$ command`` of the quick start, in a scratch folder holding the scenes, prints the lines
    under it; the viewer, which needs a screen, gets what it would open checked by ``rerun rrd
    verify`` instead. Then the Python example prints the block after it."""
    (tmp_path / "scenes").symlink_to(ROOT / "scenes")
    env = {**os.environ, "PATH": f"{Path(sys.executable).parent}{os.pathsep}{os.environ['PATH']}"}
    commands = [b for b in re.findall(r"```text\n(.*?)```", quick_start(), re.S) if b.startswith("$ ")]
    assert [c.split()[1] for c in commands] == ["plan", "rerun", "plan"]
    for block in commands:
        command, *printed = block.splitlines()
        if command.startswith("$ rerun "):
            command = f"rerun rrd verify {command.split()[2]}"
        elif "--simulate" in command and not have("mujoco"):
            continue  # CI installs it: this is a run without the extra
        run = subprocess.run(command.removeprefix("$ "), shell=True, cwd=tmp_path, env=env, capture_output=True,
                             text=True, timeout=300)
        assert run.returncode == 0, (command, run.stderr)
        assert command.startswith("rerun") or printed_as(printed).fullmatch(run.stdout), (printed, run.stdout)
    code = re.search(r"```python\n(.*?)```", quick_start(), re.S).group(1)
    printed = re.search(r"```python\n.*?```\n\n```text\n(.*?)```", quick_start(), re.S).group(1)
    monkeypatch.chdir(tmp_path)
    exec(compile(code, "README.md", "exec"), {})
    assert capsys.readouterr().out == printed
    assert shutil.which("rerun", path=env["PATH"])  # the viewer command is there to be run


def test_ci_runs_the_readme_test_command():
    ci = (ROOT / ".ci" / "run").read_text()
    test_command = opening_commands()[1].split("&& ")[1]
    assert test_command in ci.splitlines()


def test_python_api_example_prints_what_the_readme_says(monkeypatch, capsys):
    section = README[README.index("## Python API"):]
    code = re.search(r"```python\n(.*?)```", section, re.S).group(1)
    printed = re.search(r"```text\n(.*?)```", section, re.S).group(1)
    monkeypatch.chdir(ROOT)
    exec(compile(code, "README.md", "exec"), {})
    assert capsys.readouterr().out == printed


def test_the_whole_run_example_prints_what_the_readme_says(tmp_path, monkeypatch, capsys):
    """The pipeline's example (README, "The whole run"), run in a scratch folder holding the scenes."""
    section = README[README.index("### The whole run"):]
    code = re.search(r"```python\n(.*?)```", section, re.S).group(1)
    printed = re.search(r"```python\n.*?```\n\nIt prints:\n\n```text\n(.*?)```", section, re.S).group(1)
    (tmp_path / "scenes").symlink_to(ROOT / "scenes")
    monkeypatch.chdir(tmp_path)
    exec(compile(code, "README.md", "exec"), {})
    assert capsys.readouterr().out == printed
    assert sorted(p.name for p in (tmp_path / "logs" / "api").iterdir()) == ["junction.json", "junction.rrd",
                                                                             "junction.trajectory.csv"]


def test_reachability_example_prints_what_the_readme_says(tmp_path, monkeypatch, capsys):
    """The README's reachability example, run in a scratch folder (it writes a PNG under logs/, as
    every output goes): its output is the text block after it, and the map is a PNG."""
    section = README[README.index("## Reachability"):]
    code = re.search(r"```python\n(.*?)```", section, re.S).group(1)
    printed = re.search(r"```text\n(.*?)```", section, re.S).group(1)
    (tmp_path / "scenes").symlink_to(ROOT / "scenes")
    (tmp_path / "logs").mkdir()  # a checkout has it (its README is tracked)
    monkeypatch.chdir(tmp_path)
    exec(compile(code, "README.md", "exec"), {})
    assert capsys.readouterr().out == printed
    assert (tmp_path / "logs" / "parking-reach.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert {p.name for p in tmp_path.iterdir()} == {"scenes", "logs"}  # nothing beside logs/


def test_picture_of_a_plan(tmp_path):
    from planner import load_scene, plan
    from planner.outputs.picture import draw_plan

    scene = load_scene(ROOT / "scenes" / "battery.yaml")
    draw_plan(scene, plan(scene, seed=1), str(tmp_path / "battery.png"))
    assert (tmp_path / "battery.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_batch_example_saved_as_a_script_without_a_guard_solves_every_task(tmp_path):
    """The README's batch snippet as a user saves it: a script with no ``if __name__ ==
    "__main__":`` guard. Its workers must not run it again (two seeds here, not twenty)."""
    section = README[README.index("from planner.batch import executor"):]
    code = section[:section.index("```")]
    assert "range(1, 21)" in code
    code = code.replace("range(1, 21)", "range(1, 2)").replace('"scenes/', f'"{ROOT}/scenes/')
    (tmp_path / "mu.py").write_text(code + 'print(sorted(r["status"] for r in records))\n')
    run = subprocess.run([sys.executable, "mu.py"], cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert (run.returncode, run.stdout) == (0, "['solved', 'solved']\n"), run.stderr
    assert "Traceback" not in run.stderr and "Warning" not in run.stderr, run.stderr


def test_the_cad_example_is_the_shipped_scene_and_its_commands_write_under_logs(tmp_path):
    """The README's CAD scene is scenes/cad/bracket.yaml as shipped (beside the files it names), and
    its commands, run as written in a scratch folder holding the scenes, plan and verify it and
    write nothing but under logs/ (they used to leave out/ and bracket-plain.yaml beside scenes/)."""
    if not (have("ezdxf") and have("svgelements")):
        pytest.skip("the cad extra is not installed")
    section = README[README.index("### Parts and obstacles from CAD files"):README.index("### Several parts")]
    snippet = re.search(r"```yaml\n# (\S+)\n(.*?)```", section, re.S)
    shipped = ROOT / snippet.group(1)
    assert yaml.safe_load(snippet.group(2)) == yaml.safe_load(shipped.read_text())
    scene = yaml.safe_load(shipped.read_text())
    assert all((shipped.parent / spec["file"]).is_file() for spec in [scene["slider"], *scene["obstacles"]]
               if "file" in spec)
    (tmp_path / "scenes").symlink_to(ROOT / "scenes")
    (tmp_path / "logs").mkdir()  # a checkout has it (its README is tracked)
    env = {**os.environ, "PATH": f"{Path(sys.executable).parent}{os.pathsep}{os.environ['PATH']}"}
    commands = re.search(r"```text\n(\$ plan scenes/cad/.*?)```", section, re.S).group(1).splitlines()
    assert len(commands) == 2
    for command in commands:
        run = subprocess.run(command.removeprefix("$ "), shell=True, cwd=tmp_path, env=env, capture_output=True,
                             text=True, timeout=300)
        assert run.returncode == 0, (command, run.stderr)
    assert "verify: passed" in run.stdout
    assert {p.name for p in tmp_path.iterdir()} == {"scenes", "logs"}  # nothing beside logs/
