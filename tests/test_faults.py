"""Faults a scheduler or a full disk brings: a `plan` run killed at any moment leaves no process
and no final output behind, and a write that fails is one error line with nothing in its place."""

from __future__ import annotations

import os
import resource
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
import yaml

from planner.model.files import remove_orphans

PLAN = Path(sys.executable).with_name("plan")
SCENES = Path(__file__).resolve().parents[1] / "scenes"
#: An irregular hexagon (no turn maps it onto itself, so every edge's region is computed cold) and a
#: goal in a ring of walls whose 62.1 mm gap its inscribed disk (61.4 mm) passes but the part (62.8 mm
#: at its narrowest) cannot: no certificate fires, and the search runs to its time limit.
SLOW = {
    "name": "slow",
    "slider": {"vertices": [[-0.04, -0.03], [0.035, -0.032], [0.045, 0.0], [0.03, 0.031], [-0.035, 0.028],
                            [-0.047, 0.002]]},
    "pusher": {"width": 0.04, "depth": 0.015, "mu": 0.5},
    "obstacles": [{"polygon": [[0.15, 0.15], [0.17, 0.15], [0.17, 0.21895], [0.15, 0.21895]]},
                  {"polygon": [[0.15, 0.28105], [0.17, 0.28105], [0.17, 0.35], [0.15, 0.35]]},
                  {"box": {"center": [0.34, 0.25], "size": [0.02, 0.20]}},
                  {"box": {"center": [0.25, 0.16], "size": [0.20, 0.02]}},
                  {"box": {"center": [0.25, 0.34], "size": [0.20, 0.02]}}],
    "workspace": {"min": [-0.5, -0.5], "max": [0.5, 0.5]},
    "start": [-0.35, -0.35, 0.0],
    "goal": [0.25, 0.25, 90.0],
}
EXIT = {signal.SIGKILL: -signal.SIGKILL, signal.SIGTERM: 143, signal.SIGINT: 130}


def alive_in_group(pgid: int) -> list[str]:
    """The processes of process group ``pgid`` that are not zombies, as ``pid (name)``."""
    found = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            text = stat.read_text()
        except OSError:
            continue
        name, rest = text[text.index("(") + 1:text.rindex(")")], text[text.rindex(")") + 2:].split()
        if int(rest[2]) == pgid and rest[0] not in "ZX":
            found.append(f"{stat.parent.name} ({name})")
    return found


def start(tmp_path: Path, *args: str, cache: Path, **kwargs) -> subprocess.Popen:
    """A `plan` run in its own session, so that all it starts shares its process group."""
    env = {**os.environ, "STABLEPUSH_CACHE": str(cache)}
    return subprocess.Popen([str(PLAN), *args], cwd=tmp_path, env=env, start_new_session=True,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, **kwargs)


@pytest.fixture
def slow_scene(tmp_path):
    (tmp_path / "slow.yaml").write_text(yaml.safe_dump(SLOW))
    return tmp_path


@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="reads processes from /proc")
@pytest.mark.parametrize("sig", [signal.SIGKILL, signal.SIGTERM, signal.SIGINT], ids=lambda s: s.name)
@pytest.mark.parametrize("after", [0.9, 2.5, 3.4], ids=["regions", "search", "recording"])
def test_a_killed_run_leaves_no_process_and_no_output(slow_scene, tmp_path, sig, after):
    # A cold cache: the first second goes to imports and the six edges' regions (side by side in
    # worker processes), then the search runs to the 3 s limit, then the recording is written.
    run = start(slow_scene, "slow.yaml", "--time-limit", "3", "--out", "out", cache=tmp_path / f"cache-{after}")
    time.sleep(after)
    os.kill(run.pid, sig)
    _, stderr = run.communicate(timeout=30)
    ended = time.monotonic()
    while (left := alive_in_group(run.pid)) and time.monotonic() < ended + 1.0:
        time.sleep(0.05)
    assert left == [], f"{sig.name} at {after} s left {left}"
    out = slow_scene / "out"
    if "plan: not solved:" in stderr:  # it had written everything (the signal came as it exited)
        assert {p.name for p in out.iterdir()} == {"slow.json", "slow.rrd"}
        return
    assert run.returncode == EXIT[sig], stderr
    assert stderr.strip().splitlines()[-1:] == {signal.SIGKILL: [], signal.SIGTERM: ["plan: terminated"],
                                               signal.SIGINT: ["plan: interrupted"]}[sig]
    finals = sorted(p.name for p in out.iterdir() if not p.name.endswith(".tmp")) if out.exists() else []
    assert finals == []
    # What a SIGKILL may leave (a temporary file half written) the next run into the folder removes.
    if out.exists():
        remove_orphans(out)
        assert list(out.iterdir()) == []


def _limit_file_size(limit: int):
    def apply() -> None:
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # a write past the limit fails with EFBIG instead
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))
    return apply


def test_a_write_that_fails_is_one_line_naming_the_file_and_leaves_nothing(tmp_path):
    # The plan of parking is 5 kB, its recording 400 kB: a 64 kB file size limit fails the recording.
    (tmp_path / "out").mkdir()
    (tmp_path / "out" / "parking.rrd").write_bytes(b"an older recording")
    run = start(tmp_path, str(SCENES / "parking.yaml"), "--out", "out", cache=tmp_path / "cache",
                preexec_fn=_limit_file_size(64_000))
    stdout, stderr = run.communicate(timeout=120)
    assert run.returncode == 4
    assert stderr == "plan: error: cannot write 'out/parking.rrd': File too large\n" and stdout == ""
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["parking.rrd"]
    assert (tmp_path / "out" / "parking.rrd").read_bytes() == b"an older recording"


def _mounted_tmpfs(folder: Path, options: str) -> bool:
    folder.mkdir()
    return shutil.which("mount") is not None and subprocess.run(
        ["mount", "-t", "tmpfs", "-o", options, "tmpfs", str(folder)], capture_output=True).returncode == 0


@pytest.mark.parametrize("case", ["full", "read-only"])
def test_a_full_or_read_only_folder_is_one_line_and_leaves_nothing(tmp_path, case):
    out = tmp_path / "out"
    if not _mounted_tmpfs(out, "size=48k" if case == "full" else "size=1m,ro"):
        pytest.skip("needs a tmpfs mount (root with CAP_SYS_ADMIN)")
    try:
        run = start(tmp_path, str(SCENES / "parking.yaml"), "--out", "out", cache=tmp_path / "cache")
        stdout, stderr = run.communicate(timeout=120)
        reason = "No space left on device" if case == "full" else "Read-only file system"
        assert run.returncode == 4
        assert stderr == f"plan: error: cannot write 'out/parking.rrd': {reason}\n" and stdout == ""
        assert list(out.iterdir()) == []
    finally:
        subprocess.run(["umount", str(out)], check=True)
