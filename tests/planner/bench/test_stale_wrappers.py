"""A plan survives a thread that holds the planner's frames after they return, as
dask.distributed's sampling profiler does (docs/stack.md, "Stale state wrappers").

Before the callbacks dropped their state wrappers, every plan of this scene failed so
(``'CompoundState' object has no attribute 'value'`` in the goal's distance); the same plans
with no such thread never did.
"""

from __future__ import annotations

from pathlib import Path

from planner import load_scene, plan
from planner.bench.stale_stress import frames_held

SCENE = Path(__file__).resolve().parents[3] / "scenes" / "parking.yaml"


def test_plans_survive_frames_held_past_their_call():
    scene = load_scene(SCENE)
    with frames_held():  # about 10 ms of the main thread's frames, as a profiler keeps them
        plans = [plan(scene, seed=seed, time_limit=2.0) for seed in (1, 2, 3)]
    assert all(p.solved for p in plans)
