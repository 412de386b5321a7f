"""Benchmark of the stable regions: ``python -m mechanics.bench``.

For every case of the stored reference regions (``tests/data/exact_regions_v2.json``: each shipped
scene's allowed edges, parts shared by several scenes once, and the fixtures of
``tests/mechanics/test_exact_region.py`` and ``tests/planner/queries/test_uncertainty.py``) it prints the per-edge cold CPU
time of procedure STABLE and of the exact region (a fresh computation, no cache), the exact
time the reference recorded for the previous algorithm, the area ratio of the new region to
the stored one, and the region's gap bound (how far the true boundary may lie beyond it, as a
fraction of the region's size, the square root of its area). Then the goals: median per-edge exact
time against 0.15 s (issue 33; issue 10's were 0.25 s and a largest of 0.6 s), and, measured in
subprocesses, ``plan scenes/parking.yaml`` with an empty
region cache against a warm one (goal <= 1.5) and the warm run against importing the
dependencies, ``python -c "import ompl, fcl, rerun, scipy"`` (goal <= 1.5).

``--plan-only`` skips the cases and prints the plan timings alone. ``--record FILE`` also writes
the same cases with the current algorithm's regions and times (and the plan timings): the
reference for the next change of the construction.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import shapely

from .exact_region import exact_region
from .slider import Slider
from .stable import procedure_stable

__all__ = ["main"]

ROOT = Path(__file__).resolve().parent.parent
REFERENCE = ROOT / "tests" / "data" / "exact_regions_v2.json"
#: Goals: per-edge cold exact time (median: issue 33; max: issue 10) and issue 10's two plan ratios.
GOALS = {"median": 0.15, "max": 0.6, "cold/warm": 1.5, "warm/imports": 1.5}


def _cpu(call, repeat: int = 1) -> float:
    """CPU seconds per call, the mean of ``repeat`` calls."""
    start = time.process_time()
    for _ in range(repeat):
        call()
    return (time.process_time() - start) / repeat


def measure(case: dict) -> tuple[float, float, shapely.Geometry, np.ndarray, float]:
    """``(stable s, exact s, polygon, centre, gap)`` of one stored case, computed cold."""
    slider = Slider(case["vertices"], cf=case["cf"])
    args = (slider, case["edge"], case["mu"], case["width"])
    stable = _cpu(lambda: procedure_stable(*args), repeat=200)
    found = {}
    exact = _cpu(lambda: found.setdefault("region", exact_region(*args, cf_radius=case["cf_radius"])))
    polygon, centre = found["region"].section()
    return stable, exact, polygon, np.asarray(centre, dtype=float), found["region"].gap


def _wall(command: list[str], env: dict[str, str]) -> float:
    start = time.perf_counter()
    subprocess.run(command, env=env, cwd=ROOT, check=True, capture_output=True)
    return time.perf_counter() - start


def plan_times(runs: int) -> dict[str, float]:
    """Median wall seconds of ``plan scenes/parking.yaml`` cold (an empty region cache) and warm,
    and of importing the dependencies."""
    plan = str(Path(sys.executable).parent / "plan")
    out: dict[str, list[float]] = {"cold": [], "warm": [], "imports": []}
    with tempfile.TemporaryDirectory() as tmp:
        for k in range(runs):
            env = {**os.environ, "STABLEPUSH_CACHE": str(Path(tmp) / f"cache-{k}")}
            command = [plan, "scenes/parking.yaml", "--out", str(Path(tmp) / f"out-{k}")]
            out["cold"].append(_wall(command, env))
            out["warm"].append(_wall(command, env))
            out["imports"].append(_wall([sys.executable, "-c", "import ompl, fcl, rerun, scipy"], env))
    return {k: statistics.median(v) for k, v in out.items()}


def _area_ratio(polygon: shapely.Geometry, stored: list) -> float:
    old = shapely.Polygon(stored) if stored else shapely.Polygon()
    if old.area == 0:
        return 1.0 if polygon.area == 0 else float("inf")
    return float(polygon.area / old.area)


def _regions(cases: list[dict], record: bool) -> None:
    """Print the table of the stored cases and the per-edge goals; with ``record``, store the
    current regions and times into ``cases``."""
    print(f"{'case':<22}{'STABLE[us]':>11}{'exact before[s]':>16}{'exact now[s]':>13}{'area new/old':>13}"
          f"{'gap/size':>9}  also")
    before = [c["exact_seconds"] for c in cases]
    now, ratios, gaps = [], [], []
    for case in cases:
        stable, exact, polygon, centre, gap = measure(case)
        ratio = _area_ratio(polygon, case["polygon"])
        now.append(exact)
        ratios.append(ratio)
        gaps.append(gap / np.sqrt(polygon.area) if polygon.area > 0 else 0.0)
        print(f"{case['name']:<22}{stable * 1e6:>11.0f}{case['exact_seconds']:>16.2f}{exact:>13.3f}{ratio:>13.4f}"
              f"{gaps[-1]:>9.3f}  {' '.join(case['also'])}", flush=True)
        if record:
            case.update(stable_seconds=stable, exact_seconds=exact, centre=centre.tolist(),
                        polygon=np.asarray(polygon.exterior.coords).tolist() if polygon.area > 0 else [])
    print(f"\nexact per edge, cold: median {statistics.median(now):.3f} s (goal <= {GOALS['median']}; before "
          f"{statistics.median(before):.2f} s), max {max(now):.3f} s (goal <= {GOALS['max']}; before {max(before):.2f} s)")
    print(f"area new/old: min {min(ratios):.4f} (goal >= 0.99), median {statistics.median(ratios):.4f}; "
          f"gap/size: median {statistics.median(gaps):.3f}, max {max(gaps):.3f}")


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m mechanics.bench", description=__doc__.splitlines()[0])
    p.add_argument("--reference", type=Path, default=REFERENCE, help="stored regions (default: %(default)s)")
    p.add_argument("--runs", type=int, default=3, help="plan runs of each kind (median; 0: skip the plan timings)")
    p.add_argument("--record", type=Path, metavar="FILE", help="write the current regions and times to FILE")
    p.add_argument("--plan-only", action="store_true", help="only the plan timings (not with --record)")
    args = p.parse_args(argv)
    if args.plan_only and args.record:
        p.error("--record needs the regions too: drop --plan-only")
    reference = json.loads(args.reference.read_text())
    if not args.plan_only:
        _regions(reference["cases"], args.record is not None)
    if args.runs > 0:
        was = reference["plan_seconds"]
        print(f"plan scenes/parking.yaml, wall medians of {args.runs} (before: {was['cold']:.2f} s, {was['warm']:.2f} s, "
              f"{was['imports']:.2f} s; ratios {was['cold'] / was['warm']:.2f}, {was['warm'] / was['imports']:.2f}):")
        t = plan_times(args.runs)
        print(f"  cold {t['cold']:.2f} s, warm {t['warm']:.2f} s, imports {t['imports']:.2f} s")
        print(f"  cold/warm {t['cold'] / t['warm']:.2f} (goal <= {GOALS['cold/warm']}), "
              f"warm/imports {t['warm'] / t['imports']:.2f} (goal <= {GOALS['warm/imports']})")
        if args.record:
            reference["plan_seconds"] = {k: round(v, 3) for k, v in t.items()}
    if args.record:
        args.record.write_text(json.dumps(reference, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
