"""Batch runs on this machine (planner.batch): a batch of scenes and seeds through the ``plan``
command, the same results for any number of workers, a worker killed mid-task, SIGTERM then
``--resume``, bad input as one line. The Ray engine is tested in tests/planner/batch/test_batch_ray.py."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from ctrl_c import sigint_default
from planner import load_scene
from planner.batch import BatchFailed, LocalExecutor, Outcome, make_tasks, run_batch
from planner.batch.reach import reachable_set_on
from planner.batch.results import COLUMNS, STATUSES
from planner.cli import main
from planner.queries.reachable_set import reachable_set

PLAN = Path(sys.executable).with_name("plan")
ROOT = Path(__file__).resolve().parents[3]
SCENES = [str(ROOT / "scenes" / "battery.yaml"), str(ROOT / "scenes" / "cluttered.yaml")]
#: What may differ between two runs of the same tasks: when they ran, where, and how often.
VARYING = {"planning_time_s", "task_s", "host", "attempts"}


def comparable(out: Path) -> dict[str, tuple]:
    """Each task's results line and plan file of a batch in ``out``, less what may vary between runs."""
    found = {}
    for line in (out / "results.jsonl").read_text().splitlines():
        record = json.loads(line)
        plan = json.loads((out / record["plan"]).read_text()) if record["plan"] else None
        if plan:  # when each plan was found varies, not what it costs
            plan.pop("planning_time_s")
            plan["improvements"] = [row[1:] for row in plan["improvements"]]
        found[record["id"]] = ({k: v for k, v in record.items() if k not in VARYING}, plan)
    return found


def batch(out: Path, *args: str, jobs: int = 2, **kwargs) -> subprocess.CompletedProcess:
    return subprocess.run([str(PLAN), *SCENES, "--seeds", "1:20", "--time-limit", "2", "--jobs", str(jobs),
                           "--out", str(out), *args], capture_output=True, text=True, timeout=300, **kwargs)


def test_a_batch_of_two_scenes_and_twenty_seeds_gives_the_same_results_on_one_worker_or_two(tmp_path):
    one, two = batch(tmp_path / "one", jobs=1), batch(tmp_path / "two", jobs=2)
    assert (one.returncode, two.returncode) == (0, 0), one.stderr + two.stderr
    records = [json.loads(line) for line in (tmp_path / "two" / "results.jsonl").read_text().splitlines()]
    assert len(records) == 40 and {r["id"] for r in records} == {f"{s}-s{k}" for s in ("battery", "cluttered")
                                                                 for k in range(1, 21)}
    assert all(list(r) == list(COLUMNS) and r["status"] in STATUSES for r in records)
    assert all(r["status"] == "solved" and r["regions_computed"] == 0 for r in records)  # the shared regions served
    assert comparable(tmp_path / "one") == comparable(tmp_path / "two")
    # The summary: a row per scene with its 20 tasks, all solved.
    rows = [line.split() for line in two.stdout.splitlines() if line.startswith(("battery.yaml", "cluttered.yaml"))]
    assert [row[:3] for row in rows] == [["battery.yaml", "20", "20"], ["cluttered.yaml", "20", "20"]]
    assert "40 tasks, 0 failed" in two.stdout


def _pid_then_sleep(path: str, shared) -> int:
    """A call that notes its worker's pid in a file, then waits to be killed (the first time)."""
    Path(path).write_text(str(os.getpid()))
    if not Path(path + ".killed").exists():
        time.sleep(60)
    return os.getpid()


def kill_mid_task(pool, folder: Path) -> tuple[dict, int]:
    """Run four calls on ``pool``, kill the worker of the first once it is under way, and return
    every call's outcome by index and the pid killed."""
    marker = str(folder / "pid")
    items = [marker] + [str(folder / f"other{k}") for k in range(3)]
    for item in items[1:]:
        Path(item + ".killed").touch()  # these return at once
    answered = {}
    runs = pool.run(_pid_then_sleep, items)
    while len(answered) < 3:  # the three others
        index, outcome = next(runs)
        answered[index] = outcome
    while not Path(marker).exists():  # the first, begun and waiting
        time.sleep(0.01)
    killed = int(Path(marker).read_text())
    Path(marker + ".killed").touch()
    os.kill(killed, signal.SIGKILL)
    answered |= dict(runs)
    assert sorted(answered) == [0, 1, 2, 3] and not any(o.failed for o in answered.values())
    assert answered[0].attempts == 2 and answered[0].value != killed
    return answered, killed


def test_a_worker_killed_mid_task_is_replaced_and_its_task_run_again(tmp_path):
    with LocalExecutor(2) as pool:
        answered, killed = kill_mid_task(pool, tmp_path)
    workers = {o.value for o in answered.values()} | {killed}
    assert [pid for pid in workers if Path(f"/proc/{pid}").exists()] == []  # every worker stopped and reaped


def test_a_worker_killed_while_idle_is_replaced_before_its_next_call():
    with LocalExecutor(1) as pool:
        runs = pool.run(_pid, [0, 1])
        _, first = next(runs)
        os.kill(first.value, signal.SIGKILL)  # between its calls
        time.sleep(0.2)
        _, second = next(runs)
    assert not second.failed and second.value != first.value and second.attempts == 1


def _pid(item, shared) -> int:
    return os.getpid()


def _dies(item, shared):
    os.kill(os.getpid(), signal.SIGKILL)


def _late(item, shared):
    time.sleep(30)


def test_a_task_that_always_kills_its_worker_fails_after_two_retries_and_a_late_one_is_stopped():
    with LocalExecutor(2) as pool:
        died = dict(pool.run(_dies, [0]))[0]
        late = dict(pool.run(_late, [0], timeout=0.5))[0]
    assert (died.attempts, died.error) == (3, "its worker died (signal 9), 3 times")
    assert (late.attempts, late.error) == (1, "stopped after 0.5 s, past its time limit")


def test_sigterm_stops_a_batch_keeping_its_results_and_resume_runs_only_the_rest(tmp_path):
    out = tmp_path / "out"
    run = subprocess.Popen([str(PLAN), *SCENES, "--seeds", "1:20", "--time-limit", "2", "--jobs", "2",
                            "--out", str(out)], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                           start_new_session=True)
    results = out / "results.jsonl"
    while run.poll() is None and (not results.exists() or len(results.read_text().splitlines()) < 5):
        time.sleep(0.01)
    group = [p.name for p in Path("/proc").glob("[0-9]*") if _group_of(p) == run.pid]
    run.send_signal(signal.SIGTERM)
    _, stderr = run.communicate(timeout=60)
    assert run.returncode == 143, stderr
    assert stderr.strip().splitlines()[-1] == "plan: terminated"
    time.sleep(0.2)
    assert [pid for pid in group if _alive(pid)] == []  # the workers went with it
    done = len(results.read_text().splitlines())
    assert 5 <= done < 40
    again = batch(out, "--resume")
    assert again.returncode == 0, again.stderr
    ran = [line for line in again.stderr.splitlines() if line.startswith("[")]
    assert len(ran) == 40 - done and ran[0].startswith(f"[{done + 1}/40]")
    lines = results.read_text().splitlines()
    assert len(lines) == 40 and len({json.loads(line)["id"] for line in lines}) == 40


def _group_of(proc: Path) -> int | None:
    try:
        text = (proc / "stat").read_text()
    except OSError:
        return None
    return int(text[text.rindex(")") + 2:].split()[2])


def _alive(pid: int | str) -> bool:
    try:
        text = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return False
    return text[text.rindex(")") + 2] not in "ZX"


def test_a_batch_without_resume_refuses_a_folder_holding_results(tmp_path, capsys):
    out = tmp_path / "out"
    tasks = make_tasks([SCENES[0]], [1, 2])
    with LocalExecutor(1) as pool:
        assert len(run_batch(tasks, out, pool, stream=open(os.devnull, "w"))) == 2
    assert main([*SCENES, "--seeds", "1:2", "--out", str(out)]) == 1
    assert capsys.readouterr().err.startswith("plan: error: --out: ")


@pytest.mark.parametrize("args, field", [
    (["--seeds", "5:1"], "--seeds"), (["--seeds", "1:x"], "--seeds"), (["--verify", "3"], "--verify"),
    (["--trajectory"], "--trajectory"), (["--jobs", "0"], "--jobs"), (["--address", "127.0.0.1:1"], "--address"),
    (["--resume"], "--resume"),
])
def test_bad_batch_input_is_one_line_naming_the_flag(args, field, capsys, tmp_path):
    out = [] if args == ["--resume"] else ["--out", str(tmp_path / "out")]
    assert main([*SCENES, *args, *out]) == 1
    err = capsys.readouterr().err
    assert err.startswith(f"plan: error: {field}: ") and err.count("\n") == 1, err
    assert not (tmp_path / "out").exists()


def test_without_ray_the_ray_engine_is_one_line(monkeypatch, capsys, tmp_path):
    monkeypatch.setitem(sys.modules, "ray", None)  # import ray raises ImportError
    assert main([*SCENES, "--engine", "ray", "--out", str(tmp_path / "out")]) == 1
    assert capsys.readouterr().err == "plan: error: --engine: ray is not installed: pip install 'stablepush[ray]'\n"


def test_a_reachable_set_map_split_between_workers_is_the_map_of_one_process():
    scene = load_scene(ROOT / "scenes" / "parking.yaml")
    alone = reachable_set(scene, 2, resolution=0.08, headings=8)
    split = reachable_set_on(scene, 2, "local", 2, resolution=0.08, headings=8)
    assert np.array_equal(alone.count, split.count) and np.array_equal(alone.blocked, split.blocked)
    assert np.array_equal(alone.theta, split.theta, equal_nan=True) and np.array_equal(alone.headings, split.headings)
    assert set(np.unique(alone.count)) == {0, 1, 2}  # a map with something to merge


# -- streaming, resuming only the same task, bad input named (issue 31) ---------------------------------

BATTERY = SCENES[0]


def test_four_billion_seeds_stream_their_first_result_at_once_and_sigterm_ends_them_cleanly(tmp_path):
    """The tasks are made as workers free up: no list of seeds, no option planned per task."""
    out = tmp_path / "out"
    run = subprocess.Popen([str(PLAN), BATTERY, "--seeds", "1:4294967295", "--jobs", "2", "--out", str(out)],
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True)
    results, began = out / "results.jsonl", time.monotonic()
    while run.poll() is None and not (results.exists() and results.read_text().count("\n")) \
            and time.monotonic() - began < 30:
        time.sleep(0.05)
    first = time.monotonic() - began
    run.send_signal(signal.SIGTERM)
    stdout, stderr = run.communicate(timeout=60)
    assert first < 30 and results.read_text().count("\n") >= 1, stderr
    assert run.returncode == 143 and "Traceback" not in stderr and stderr.splitlines()[-1] == "plan: terminated"
    assert json.loads(results.read_text().splitlines()[0])["id"].startswith("battery-s")


def test_more_jobs_than_tasks_start_a_worker_a_task_and_say_so(tmp_path, capsys, monkeypatch):
    from planner.batch import command, executors

    started = []
    monkeypatch.setattr(executors._Worker, "__init__", _counted(executors._Worker.__init__, started))
    monkeypatch.setattr(command, "cores", lambda: 1)  # as on a machine of one core
    assert main([BATTERY, "--seeds", "1:2", "--jobs", "64", "--out", str(tmp_path / "out")]) == 0
    assert len(started) <= 2
    assert ("plan: note: --jobs 64: 2 workers, one per task; more than the 1 core: the tasks share them, each "
            "running slower\n") in capsys.readouterr().err


def _counted(init, started: list):
    def counting(self, *args, **kwargs):
        started.append(1)
        init(self, *args, **kwargs)
    return counting


def _lines(out: Path) -> list[dict]:
    return [json.loads(line) for line in (out / "results.jsonl").read_text().splitlines()]


def test_resume_runs_again_the_tasks_whose_lines_are_not_whole_records(tmp_path, capsys):
    out = tmp_path / "out"
    assert main([BATTERY, "--seeds", "1:3", "--jobs", "1", "--out", str(out)]) == 0
    whole = _lines(out)
    cut = dict(whole[2])
    del cut["cost"]
    (out / "results.jsonl").write_text("\n".join([json.dumps(whole[0]), json.dumps({"id": "battery-s2"}),
                                                   json.dumps(cut), "[" * 5000]) + "\n")
    capsys.readouterr()
    assert main([BATTERY, "--seeds", "1:3", "--jobs", "1", "--out", str(out), "--resume"]) == 0
    err = capsys.readouterr().err
    assert "plan: warning: 3 lines of " in err and "Traceback" not in err
    assert [line.split(":")[0] for line in err.splitlines() if line.startswith("[")] == ["[2/3] battery-s2", "[3/3] battery-s3"]
    again = {r["id"]: r for r in map(json.loads, (out / "results.jsonl").read_text().splitlines()[4:])}
    assert sorted(again) == ["battery-s2", "battery-s3"] and again["battery-s3"]["cost"] == whole[2]["cost"]


def test_resume_with_a_changed_scene_file_runs_its_tasks_again(tmp_path, capsys):
    """The same file name with another goal: its results are another task's, not reused."""
    scene, out = tmp_path / "battery.yaml", tmp_path / "out"
    scene.write_text(Path(BATTERY).read_text())
    assert main([str(scene), "--seeds", "1:2", "--jobs", "1", "--out", str(out)]) == 0
    scene.write_text(Path(BATTERY).read_text().replace("goal: [0.05798, 0.02116, 40.107]", "goal: [0.05, 0.0, 0.0]"))
    capsys.readouterr()
    assert main([str(scene), "--seeds", "1:2", "--jobs", "1", "--out", str(out), "--resume"]) == 0
    assert "plan: warning: 2 lines of " in capsys.readouterr().err
    first, second = _lines(out)[:2], _lines(out)[2:]
    assert [r["id"] for r in second] == ["battery-s1", "battery-s2"]
    assert {r["scene_digest"] for r in first}.isdisjoint({r["scene_digest"] for r in second})
    assert json.loads((out / "battery-s1.json").read_text())["goal"][:2] == [0.05, 0.0]
    # Resumed again, unchanged: nothing runs, no warning.
    assert main([str(scene), "--seeds", "1:2", "--jobs", "1", "--out", str(out), "--resume"]) == 0
    assert "warning" not in capsys.readouterr().err and len(_lines(out)) == 4


def test_a_bad_scene_among_several_is_named(tmp_path, capsys):
    bad = tmp_path / "bad.yaml"
    bad.write_text(Path(BATTERY).read_text().replace("mu: 1.0", "mu: -1.0"))
    assert main([BATTERY, str(bad), "--seeds", "1", "--out", str(tmp_path / "out")]) == 1
    err = capsys.readouterr().err
    assert err.startswith(f"plan: error: {bad}: pusher.mu: ") and err.count("\n") == 1
    assert not (tmp_path / "out").exists()


def test_a_results_file_that_is_a_pipe_is_one_line_before_any_task(tmp_path, capsys):
    (tmp_path / "out").mkdir()
    os.mkfifo(tmp_path / "out" / "results.jsonl")
    assert main([BATTERY, "--seeds", "1", "--out", str(tmp_path / "out"), "--resume"]) == 1
    assert capsys.readouterr().err == (f"plan: error: --out: cannot use {str(tmp_path / 'out' / 'results.jsonl')!r}: "
                                       "not a regular file\n")


def test_ctrl_c_while_the_workers_start_is_one_line(tmp_path):
    """Ctrl-C reaches the whole process group, the batch's workers too, which import the
    planner for a second or so: they start with it ignored, so only the command speaks."""
    runs = [subprocess.Popen(sigint_default([str(PLAN), *SCENES, "--seeds", "1:20", "--jobs", "2", "--out",
                                             str(tmp_path / f"o{k}")]),
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True,
                             env={**os.environ, "STABLEPUSH_CACHE": str(tmp_path / f"cache{k}")}) for k in range(2)]
    began = time.monotonic()
    for after, run in zip((0.8, 1.4), runs):
        time.sleep(max(0.0, began + after - time.monotonic()))
        os.killpg(run.pid, signal.SIGINT)
    for run in runs:
        _, stderr = run.communicate(timeout=60)
        assert run.returncode == 130 and "Traceback" not in stderr, stderr
        assert [line for line in stderr.splitlines() if not line.startswith("[")] == ["plan: interrupted"], stderr


class _Failing:
    """An executor whose every call fails, as when a worker cannot run the tasks at all."""

    workers = 1

    def run(self, fn, items, shared=None, **kwargs):
        for index, _ in enumerate(items):
            yield index, Outcome(error="OSError: no room left")

    def close(self) -> None:
        pass

    def __enter__(self):
        return self

    def __exit__(self, *exc) -> None:
        pass


def test_a_batch_whose_every_task_fails_raises_and_the_command_exits_2(tmp_path, monkeypatch, capsys):
    with pytest.raises(BatchFailed, match=r"every task of the batch failed \(2\); battery-s1: OSError: no room"):
        run_batch(make_tasks([SCENES[0]], [1, 2]), tmp_path / "api", _Failing(), stream=open(os.devnull, "w"))
    assert len((tmp_path / "api" / "results.jsonl").read_text().splitlines()) == 2  # recorded all the same
    monkeypatch.setattr("planner.batch.command.executor", lambda *args: _Failing())
    assert main([SCENES[0], "--seeds", "1:2", "--out", str(tmp_path / "cli")]) == 2
    out, err = capsys.readouterr()
    assert "2 tasks, 2 failed" in out
    assert err.splitlines()[-1] == "plan: every task of the batch failed (2); battery-s1: OSError: no room left"


_RUNS_ITSELF = '''
import os
from planner.batch import LocalExecutor

def square(item, shared):
    return item * item

if __name__ == "__main__":
    with LocalExecutor(2) as pool:
        print(sorted(o.value for _, o in pool.run(square, [2, 3])))
'''


def test_a_function_of_a_module_run_with_dash_m_reaches_the_workers_and_one_of_a_script_is_one_line(tmp_path):
    (tmp_path / "squares.py").write_text(_RUNS_ITSELF)
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")])}
    module = subprocess.run([sys.executable, "-m", "squares"], cwd=tmp_path, env=env, capture_output=True, text=True,
                            timeout=120)
    assert (module.returncode, module.stdout) == (0, "[4, 9]\n"), module.stderr
    script = subprocess.run([sys.executable, "squares.py"], cwd=tmp_path, env=env, capture_output=True, text=True,
                            timeout=120)
    assert script.returncode == 1 and script.stderr.splitlines()[-1] == (
        f"TypeError: square is defined in the script being run ({tmp_path / 'squares.py'}), which batch workers "
        "do not run: define it in a module they can import"), script.stderr
