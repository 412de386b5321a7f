"""Batch runs on Ray (planner.batch.ray_engine), on one local Ray cluster of 2 CPUs bound to
127.0.0.1 shared by the module's tests, stopped by pid at the end: the same results as on this
machine's workers, a Ray worker killed mid-task, reachable-set maps."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from planner.batch.ray_cluster import ENVIRONMENT, LocalRayCluster

# This process connects to the cluster as a driver, and Ray reads the mode when it is imported.
os.environ.update(ENVIRONMENT)
ray = pytest.importorskip("ray")

from planner import load_scene  # noqa: E402 (after the skip)
from planner.batch.ray_engine import RayExecutor  # noqa: E402
from planner.batch.reach import reachable_set_on  # noqa: E402
from planner.queries.reachable_set import reachable_set  # noqa: E402

import test_batch  # noqa: E402 (tests/ is on the path)
from test_batch import PLAN, ROOT, SCENES, _alive, batch, comparable, kill_mid_task  # noqa: E402


def test_sigterm_stops_a_batch_on_a_ray_cluster_of_its_own_leaving_no_process_and_local_resume_ends_it(tmp_path):
    # First in the module, before the shared cluster starts: one Ray cluster at a time.
    before, out = _ray_processes(), tmp_path / "out"
    run = subprocess.Popen([str(PLAN), *SCENES, "--seeds", "1:20", "--time-limit", "2", "--engine", "ray",
                            "--jobs", "2", "--out", str(out)], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                           text=True)
    results = out / "results.jsonl"
    while run.poll() is None and (not results.exists() or len(results.read_text().splitlines()) < 3):
        time.sleep(0.01)
    assert _ray_processes() - before  # its cluster is running
    run.send_signal(signal.SIGTERM)
    _, stderr = run.communicate(timeout=120)
    assert run.returncode == 143, stderr
    time.sleep(0.5)
    assert _ray_processes() - before == set()
    done = len(results.read_text().splitlines())
    again = batch(out, "--resume")  # on local workers: the same tasks, the same results
    assert again.returncode == 0, again.stderr
    assert len([line for line in again.stderr.splitlines() if line.startswith("[")]) == 40 - done
    assert len(comparable(out)) == 40


@pytest.fixture(scope="module")
def cluster():
    with LocalRayCluster((2,)) as running:
        yield running
    assert running.pids() == set()


def test_forty_tasks_give_the_same_results_on_ray_as_on_local_workers(cluster, tmp_path):
    local, on_ray = batch(tmp_path / "local"), batch(tmp_path / "ray", "--engine", "ray", "--address", cluster.address)
    assert (local.returncode, on_ray.returncode) == (0, 0), local.stderr + on_ray.stderr
    assert len(comparable(tmp_path / "ray")) == 40
    assert comparable(tmp_path / "local") == comparable(tmp_path / "ray")


def test_a_ray_worker_killed_mid_task_is_replaced_and_its_task_run_again(cluster, tmp_path):
    ray.cloudpickle.register_pickle_by_value(test_batch)  # Ray's workers cannot import the tests
    with RayExecutor(address=cluster.address) as pool:
        _, killed = kill_mid_task(pool, tmp_path)
    time.sleep(0.2)
    assert not _alive(killed)


def test_a_reachable_set_map_on_ray_is_the_map_of_one_process(cluster, tmp_path):
    scene = load_scene(ROOT / "scenes" / "parking.yaml")
    alone = reachable_set(scene, 1, resolution=0.08, headings=8)
    split = reachable_set_on(scene, 1, "ray", address=cluster.address, resolution=0.08, headings=8)
    assert np.array_equal(alone.count, split.count) and np.array_equal(alone.theta, split.theta, equal_nan=True)
    run = subprocess.run([str(PLAN), str(ROOT / "scenes" / "parking.yaml"), "--reach", "1", "--engine", "ray",
                          "--address", cluster.address, "--out", str(tmp_path / "out")],
                         capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    assert (tmp_path / "out" / "parking-reach.png").stat().st_size > 0


def _ray_processes() -> set[int]:
    """Live processes running Ray's programs."""
    found = set()
    for proc in Path("/proc").glob("[0-9]*"):
        try:
            cmdline = (proc / "cmdline").read_bytes()
        except OSError:
            continue
        if b"ray" in cmdline and (b"raylet" in cmdline or b"gcs_server" in cmdline or cmdline.startswith(b"ray::")):
            found.add(int(proc.name))
    return found


assert sys.platform.startswith("linux")  # the cluster is found and stopped through /proc
