"""What a ``plan`` run costs before and around the search (issue 10).

A warm run imports only what planning and the recording need: scipy's optimize and linalg (a
third of a second) and matplotlib are left to the commands that use them. A cold run computes the
edges' exact regions side by side in forked processes (:func:`planner.actions.region_cache.compute_regions`);
sources of truth: the same regions computed one by one in this process, bit for bit, and the
process ids of the workers that computed them.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from pathlib import Path

import pytest
import shapely

from mechanics import Slider, exact_region
from planner.actions.region_cache import RegionCache, compute_regions, is_cached

ROOT = Path(__file__).resolve().parents[2]
#: The CF off the centre: no turn of the block carries one edge onto another, so each is computed.
BLOCK = Slider([[-0.05, 0.0], [0.05, 0.0], [0.05, 0.06], [-0.05, 0.06]], cf=[0.01, 0.03])
#: Imported only by what needs them: the controllability report, the simulator, the pictures and
#: the CAD readers (a plain scene loads none of these).
HEAVY = ("scipy.optimize", "scipy.linalg", "matplotlib", "ezdxf", "svgelements", "trimesh")
#: Left out by ``import planner`` until their public names are used: the controllability report
#: (scipy) and the quasi-static re-simulator.
ON_FIRST_USE = ("planner.queries.controllability", "planner.execution.verify", "mechanics.quasistatic")


def _fresh(script: str, **env: str) -> str:
    """What ``script`` prints, run in a fresh interpreter from the project's folder (with ``env``
    added to the environment)."""
    run = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, cwd=ROOT, timeout=120,
                         env={**os.environ, **env})
    assert run.returncode == 0, run.stderr
    return run.stdout


@pytest.fixture()
def empty_cache(tmp_path):
    return RegionCache(tmp_path / "cache")


def test_a_plan_run_imports_nothing_it_does_not_use(tmp_path):
    """The whole ``plan`` command in a fresh interpreter, then a look at what it imported; the
    public names that need scipy still work, importing it when called."""
    script = f"""
import json, sys
from planner.cli import main
code = main(["scenes/parking.yaml", "--out", {str(tmp_path / 'out')!r}])
loaded = sorted(m for m in sys.modules if m.startswith({HEAVY!r}))
from planner import controllability, load_scene
print(json.dumps([code, loaded, controllability(load_scene("scenes/parking.yaml")).stlc,
                  "scipy.optimize" in sys.modules]))
"""
    code, loaded, stlc, optimize = json.loads(_fresh(script).splitlines()[-1])
    assert code == 0 and (tmp_path / "out" / "parking.rrd").is_file()
    assert loaded == []
    assert stlc and optimize


def test_import_planner_leaves_the_rarely_used_parts_for_their_first_use():
    script = f"""
import json, sys
import planner
before = [m for m in {ON_FIRST_USE!r} if m in sys.modules]
from planner import SceneControllability, Verification, controllability, verify
from planner import *
print(json.dumps([before, [m for m in {ON_FIRST_USE!r} if m in sys.modules],
                  [name for name in planner.__all__ if name not in dir(planner) or name not in globals()]]))
"""
    before, after, missing = json.loads(_fresh(script).splitlines()[-1])
    assert before == [] and after == list(ON_FIRST_USE) and missing == []


def _noting_process(folder: Path, slider: Slider, edge: int, *args, **kwargs):
    """:func:`mechanics.exact_region`, leaving a file named by the edge and the process that computed it."""
    folder.mkdir(exist_ok=True)
    (folder / f"{edge}-{os.getpid()}").touch()
    return exact_region(slider, edge, *args, **kwargs)


def test_regions_computed_in_parallel_are_the_serial_ones(tmp_path):
    """Run where forking is safe (one thread, as the plan command sets it up): the regions come
    from worker processes, bit for bit the ones computed here."""
    script = f"""
import functools, json, os, sys, shapely
from pathlib import Path
sys.path.insert(0, "tests/planner")
from test_startup import BLOCK, _noting_process
from planner.actions.region_cache import RegionCache, compute_regions
cache = RegionCache({str(tmp_path / "cache")!r}, compute=functools.partial(_noting_process, Path({str(tmp_path / "who")!r})))
heard = []
got = compute_regions(BLOCK, [0, 1, 2], 0.5, 0.08, progress=lambda k, n: heard.append((k, n)), workers=2, cache=cache)
print(json.dumps({{"heard": heard, "pid": os.getpid(), "polygons": {{e: shapely.to_wkb(r.polygon, hex=True) for e, r in got.items()}},
                   "centres": {{e: r.centre.tolist() for e, r in got.items()}}}}))
"""
    found = json.loads(_fresh(script, OPENBLAS_NUM_THREADS="1"))
    assert found["heard"] == [[1, 3], [2, 3], [3, 3]]
    who = [name.split("-") for name in os.listdir(tmp_path / "who")]
    assert sorted(int(e) for e, _ in who) == [0, 1, 2]
    assert all(int(pid) != found["pid"] for _, pid in who)
    cache = RegionCache(tmp_path / "cache", compute=_refuse)
    for e in (0, 1, 2):
        serial = exact_region(BLOCK, e, 0.5, 0.08)
        assert shapely.from_wkb(found["polygons"][str(e)]).equals_exact(serial.polygon, 0.0)
        assert found["centres"][str(e)] == serial.centre.tolist()
        assert is_cached(BLOCK, e, 0.5, 0.08, cache=cache)
    assert len(list(cache.folder.iterdir())) == 3  # written by that process, atomically: no temporary left


def _refuse(*args, **kwargs):
    raise AssertionError("computed again")


def test_parallel_regions_keep_the_deadline_and_raise_the_workers_errors(empty_cache):
    """A region of the block takes a tenth of a second or more: with 0.03 s, those begun (one per
    worker at most, if the workers start in time) are abandoned and the third is never begun."""
    heard = []
    start = time.perf_counter()
    assert compute_regions(BLOCK, [0, 1, 2], 0.5, 0.08, deadline=start + 0.03,
                           progress=lambda k, n: heard.append((k, n)), workers=2, cache=empty_cache) == {}
    assert time.perf_counter() - start < 0.5
    assert heard in ([], [(1, 3)], [(1, 3), (2, 3)]) and not empty_cache.folder.exists()
    with pytest.raises(ValueError, match="mu must be > 0"):
        compute_regions(BLOCK, [0, 1], -0.5, 0.08, workers=2, cache=empty_cache)


def test_the_recorder_writes_in_a_child_and_passes_its_errors_back(tmp_path):
    """In a fresh interpreter with one thread (rerun not imported, one BLAS thread, as the plan
    command sets it up), the recording is written by the forked child: the parent never imports
    rerun, the file verifies, and a failure to write comes back as the OSError it is. The child
    draws with the recorder's cache: given an empty one, it leaves there the pushed edge's region
    and analysis."""
    script = f"""
import sys
from planner import load_scene, plan
from planner.actions.region_cache import RegionCache
from planner.outputs.recorder import recorder
scene = load_scene("scenes/battery.yaml")
result = plan(scene, seed=1)
cache = RegionCache({str(tmp_path / "cache")!r})
with recorder(scene, cache) as write:
    write({str(tmp_path / "battery.rrd")!r}, scene, result)
try:
    with recorder(scene) as write:
        write({str(tmp_path / "missing" / "battery.rrd")!r}, scene, result)
except OSError as err:
    print(type(err).__name__, "rerun" in sys.modules)
"""
    assert _fresh(script, OPENBLAS_NUM_THREADS="1").split() == ["FileNotFoundError", "False"]
    assert sorted(p.name.split("-")[0] for p in (tmp_path / "cache").iterdir()) == ["analysis", "exact"]
    # With more threads (numpy's BLAS pool) a fork is not safe: the recording is written in process.
    assert _fresh(script, OPENBLAS_NUM_THREADS="2").split() == ["FileNotFoundError", "True"]
    rerun = Path(sys.executable).parent / "rerun"
    if rerun.exists():
        check = subprocess.run([str(rerun), "rrd", "verify", str(tmp_path / "battery.rrd")], capture_output=True,
                               text=True, timeout=120)
        assert check.returncode == 0, check.stderr

