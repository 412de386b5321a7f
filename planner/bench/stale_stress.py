"""Stress: plans under a thread that holds the planner's frames past their calls, the condition
that made plans fail with ``'CompoundState' object has no attribute 'value'`` (a stale nanobind
wrapper of an OMPL state; docs/stack.md, "Stale state wrappers").

``python -m planner.bench.stale_stress --plans 200`` plans ``scenes/parking.yaml`` for seeds
1..200 on this machine's batch workers (:class:`planner.batch.LocalExecutor`), each plan with a
thread beside it that keeps the last ~10 ms of the main thread's frames, as dask.distributed's
sampling profiler does, and prints how many plans solved, did not, and failed with an error (by
type). ``--dask`` plans them instead in ``dask.distributed`` workers (``LocalCluster(n_workers=1,
threads_per_worker=1, processes=True)``, its profiler on), where the failure was first seen; dask
is not a dependency of the planner (``pip install 'dask[distributed]'``).
"""

from __future__ import annotations

import argparse
import sys
import threading
import time
from collections import Counter, deque
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

__all__ = ["frames_held", "main", "plan_with_frames_held"]

SCENE = Path(__file__).resolve().parents[2] / "scenes" / "parking.yaml"


@contextmanager
def frames_held() -> Iterator[None]:
    """Within the block, a thread keeps the last ~10 ms of the calling thread's frames (a sample
    every 0.5 ms, 20 kept), as a sampling profiler does; they are let go when it ends."""
    main, done = threading.get_ident(), threading.Event()
    held: deque = deque(maxlen=20)

    def sampler() -> None:
        while not done.is_set():
            frame, chain = sys._current_frames().get(main), []
            while frame is not None:
                chain.append(frame)
                frame = frame.f_back
            held.append(chain)
            time.sleep(0.0005)

    thread = threading.Thread(target=sampler, daemon=True)
    thread.start()
    try:
        yield
    finally:
        done.set()
        thread.join()
        held.clear()


def plan_with_frames_held(seed: int, time_limit: float = 2.0) -> str:
    """Plan the parking scene with ``seed`` while a thread holds the main thread's recent frames
    (:func:`frames_held`); ``'solved'``, ``'unsolved'`` or the error's type and first line."""
    from planner import load_scene, plan

    with frames_held():
        try:
            return "solved" if plan(load_scene(SCENE), seed=seed, time_limit=time_limit).solved else "unsolved"
        except Exception as err:
            return f"{type(err).__name__}: {str(err).splitlines()[0] if str(err) else ''}"


def _task(seed: int, shared: None) -> str:
    return plan_with_frames_held(seed)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m planner.bench.stale_stress", description=__doc__.splitlines()[0])
    p.add_argument("--plans", type=int, default=200, help="seeds 1..PLANS (default: %(default)s)")
    p.add_argument("--workers", type=int, default=2)
    p.add_argument("--dask", action="store_true", help="in dask.distributed workers instead")
    args = p.parse_args(argv)
    seeds = list(range(1, args.plans + 1))
    clock = time.perf_counter()
    if args.dask:
        from distributed import Client, LocalCluster

        with LocalCluster(n_workers=args.workers, threads_per_worker=1, processes=True, dashboard_address=None,
                          host="127.0.0.1") as cluster, Client(cluster) as client:
            outcomes = client.gather(client.map(plan_with_frames_held, seeds, pure=False))
        where = f"dask.distributed, {args.workers} worker processes (profiler on)"
    else:
        from ..batch import LocalExecutor

        with LocalExecutor(args.workers) as pool:
            outcomes = [o.value if not o.failed else f"worker: {o.error}" for _, o in pool.run(_task, seeds)]
        where = f"planner.batch local executor, {args.workers} workers, a frame-holding thread beside each plan"
    counts = Counter(outcomes)
    errors = {k: v for k, v in counts.items() if k not in ("solved", "unsolved")}
    print(f"{len(seeds)} plans of {SCENE.name} ({where}) in {time.perf_counter() - clock:.1f} s: "
          f"{counts['solved']} solved, {counts['unsolved']} unsolved, {sum(errors.values())} errors")
    for error, n in sorted(errors.items(), key=lambda kv: -kv[1]):
        print(f"  {n} x {error}")
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main())
