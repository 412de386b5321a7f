"""A plan survives a thread that holds the planner's frames after they return, as
dask.distributed's sampling profiler does (docs/stack.md, "Stale state wrappers").

Before the callbacks dropped their state wrappers, every plan of this scene failed so
(``'CompoundState' object has no attribute 'value'`` in the goal's distance); the same plans
with no such thread never did.
"""

from __future__ import annotations

import sys
import threading
import time
from collections import deque
from pathlib import Path

from planner import load_scene, plan

SCENE = Path(__file__).resolve().parent.parent / "scenes" / "parking.yaml"


def test_plans_survive_frames_held_past_their_call():
    main = threading.get_ident()
    held: deque = deque(maxlen=20)  # about 10 ms of samples, as a profiler keeps them
    done = threading.Event()

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
        scene = load_scene(SCENE)
        plans = [plan(scene, seed=seed, time_limit=2.0) for seed in (1, 2, 3)]
    finally:
        done.set()
        thread.join()
        held.clear()
    assert all(p.solved for p in plans)
