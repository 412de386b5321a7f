"""Reachable-set maps on an executor: the headings of a map for any final heading
(:func:`planner.queries.reachable_set.reachable_set`) split into one run of headings per worker,
the maps merged into the map one process would make.

A cell's answer at one heading does not depend on the other headings (each heading's cells are
tried with that heading alone), so the merge is exact: a cell takes the fewest pushes over the
parts, from the first part (in heading order) that has them, and is blocked where every part is.
"""

from __future__ import annotations

import time
from dataclasses import replace

import numpy as np

from ..model.margin import EXACT, Margin
from ..model.options import DEFAULT_REGIONS
from ..model.scene import Scene
from ..queries.reachable_set import HEADINGS, ReachableSet, reachable_set
from .engines import map_ordered
from ..model.processes import cores

__all__ = ["merge", "reachable_set_on"]


def _part(job: tuple[Scene, int, float | None, int, slice, str, Margin], shared: None) -> ReachableSet:
    scene, pushes, resolution, headings, among, regions, margin = job
    return reachable_set(scene, pushes, None, resolution, headings=headings, among=among, regions=regions,
                         margin=margin)


def merge(maps: list[ReachableSet], seconds: float) -> ReachableSet:
    """One map for any heading from ``maps``, parts of it over successive runs of headings."""
    first = maps[0]
    counts = np.stack([m.count for m in maps])
    reached = np.where(counts > 0, counts, np.iinfo(counts.dtype).max)
    best = reached.argmin(axis=0)  # the first heading with the fewest pushes
    count = np.take_along_axis(counts, best[None], axis=0)[0]
    theta = np.take_along_axis(np.stack([m.theta for m in maps]), best[None], axis=0)[0]
    blocked = np.logical_and.reduce([m.blocked for m in maps])
    return replace(first, headings=np.concatenate([m.headings for m in maps]), count=count, theta=theta, blocked=blocked, seconds=seconds)


def reachable_set_on(scene: Scene, pushes: int = 1, engine: str = "local", workers: int | None = None,
                     address: str | None = None, resolution: float | None = None, *,
                     headings: int = HEADINGS, regions: str = DEFAULT_REGIONS, margin: Margin = EXACT) -> ReachableSet:
    """:func:`~planner.queries.reachable_set.reachable_set` of ``scene`` for any final heading
    with the stable pushes of the ``regions`` option keeping ``margin``, its ``headings`` computed on the ``engine``
    executor (:func:`planner.batch.executor`).

    The headings are cut into one run per worker (``workers``, default: this machine's cores):
    each run builds the collision model and the goal regions once.

    Raises
    ------
    RuntimeError
        If a part of the map failed (its worker died more often than retried, say).
    """
    clock = time.perf_counter()
    parts = min(workers or cores(), headings)
    cuts = np.linspace(0, headings, parts + 1).round().astype(int)
    jobs = [(scene, pushes, resolution, headings, slice(a, b), regions, margin) for a, b in zip(cuts[:-1], cuts[1:])]
    maps = map_ordered(_part, jobs, workers, engine, address)
    return merge(maps, time.perf_counter() - clock)
