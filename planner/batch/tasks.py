"""A batch's tasks: one scene, one seed, optionally another goal and option overrides; and how a
worker runs one (:func:`run_task`).

A task's plan depends on its scene, seed, goal and overrides only: a worker plans it with the
stable regions the run computed beforehand (:func:`shared_regions`), never with regions cut short
by the time limit, so the same task gives the same plan on any engine and any number of workers.

>>> parse_seeds("1:3"), parse_seeds("7"), parse_seeds("2,5,9")
([1, 2, 3], [7], [2, 5, 9])
"""

from __future__ import annotations

import math
import socket
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from mechanics import Slider

from ..actions.controls import edge_controls
from ..actions.region_cache import default_cache, is_cached, regions_held
from ..model.fields import SceneError, number
from ..model.options import (check_optimize, check_planner, check_regions, check_seed, check_switch_cost,
                             check_time_limit, check_transit)
from ..model.plan_file import Plan
from ..model.scene import Scene, load_scene
from ..queries.reachability import certify_unreachable
from ..queries.session import plan

__all__ = ["OVERRIDES", "Task", "make_tasks", "parse_seeds", "run_task", "shared_regions"]

#: What a task may change of its scene, and the check of each value.
OVERRIDES = {
    "planner": check_planner, "time_limit": check_time_limit, "transit": check_transit,
    "regions": check_regions, "switch_cost": check_switch_cost, "optimize": check_optimize,
    "mu": lambda value, name: number(value, name, positive=True),
    "cf_offset": lambda value, name: _pair(value, name),
}


#: The overrides that are planner options (:class:`~planner.model.options.PlannerOptions`;
#: ``planner`` is its ``name``).
_OPTIONS = ("planner", "time_limit", "transit", "regions", "switch_cost", "optimize")


def _pair(value: Any, name: str) -> tuple[float, float]:
    if not isinstance(value, Sequence) or len(value) != 2:
        raise SceneError(name, f"must be a pair [dx, dy] in metres, got {value!r}")
    return (number(value[0], name), number(value[1], name))


@dataclass(frozen=True)
class Task:
    """One planning run of a batch: ``scene`` (read already) from its start to ``goal`` (default:
    the scene's), with ``seed`` and the ``overrides`` of :data:`OVERRIDES`. ``id`` names it in the
    results and its plan file (``<id>.json``)."""

    id: str
    scene: Scene
    seed: int
    goal: tuple[float, float, float] | None = None
    overrides: Mapping[str, Any] = field(default_factory=dict)

    def planned_scene(self) -> Scene:
        """The scene as planned: the goal and overrides applied."""
        scene, o = self.scene, self.overrides
        if self.goal is not None:
            scene = replace(scene, goal=np.asarray(self.goal, dtype=float))
        options = {"name" if key == "planner" else key: o[key] for key in _OPTIONS if key in o}
        scene = scene.with_options(scene.planner.merged({**options, "seed": self.seed}, prefix="overrides."))
        if "mu" in o:
            scene = replace(scene, pusher=replace(scene.pusher, mu=o["mu"]))
        if "cf_offset" in o:
            slider = scene.slider
            try:
                scene = replace(scene, slider=Slider(slider.vertices, slider.cf + np.asarray(o["cf_offset"])))
            except ValueError as err:
                raise SceneError("overrides.cf_offset", str(err)) from None
        return scene

    def record(self) -> dict[str, Any]:
        """What the results file says of the task itself."""
        return {"id": self.id, "scene": self.scene.path or self.scene.name, "seed": self.seed,
                "goal": None if self.goal is None else [float(v) for v in self.goal],
                "overrides": dict(self.overrides)}


def parse_seeds(text: str) -> list[int]:
    """Seeds from ``A:B`` (A to B, both included), ``N`` or ``A,B,C``.

    Raises
    ------
    SceneError
        Naming ``--seeds``.
    """
    try:
        if ":" in text:
            first, last = (int(v) for v in text.split(":"))
            seeds = list(range(first, last + 1))
        else:
            seeds = [int(v) for v in text.split(",")]
    except ValueError:
        raise SceneError("seeds", f"must be A:B, N or A,B,C (integers), got {text!r}") from None
    if not seeds:
        raise SceneError("seeds", f"{text!r} holds no seed (A:B needs A <= B)")
    return [check_seed(s, "seeds") for s in seeds]


def make_tasks(scenes: Iterable[str | Path | Scene], seeds: Iterable[int] | None = None,
               goals: Sequence[Sequence[float]] | None = None,
               overrides: Sequence[Mapping[str, Any]] | Mapping[str, Any] | None = None) -> list[Task]:
    """Every combination of ``scenes`` (files are read now), ``seeds`` (default: each scene's
    own), ``goals`` (default: each scene's own) and ``overrides`` (one mapping, or several
    variants), in that order, with ids ``<scene>-s<seed>[-g<goal>][-o<variant>]``.

    Raises
    ------
    SceneError
        For a scene file or override that is not valid.
    """
    loaded = [s if isinstance(s, Scene) else load_scene(s) for s in scenes]
    variants = [overrides or {}] if overrides is None or isinstance(overrides, Mapping) else list(overrides)
    variants = [_checked(v) for v in variants]
    names = [s.name for s in loaded]
    tasks = []
    for k, scene in enumerate(loaded):
        name = scene.name if names.count(scene.name) == 1 else f"{scene.name}.{k}"
        for seed in (list(seeds) if seeds is not None else [scene.planner.seed]):
            for g, goal in enumerate(goals if goals is not None else [None]):
                for v, variant in enumerate(variants):
                    tag = f"{name}-s{seed}{'' if goals is None else f'-g{g}'}{'' if len(variants) == 1 else f'-o{v}'}"
                    tasks.append(Task(tag, scene, check_seed(seed, "seed"), None if goal is None else _goal(goal),
                                      variant))
    return tasks


def _goal(goal: Sequence[float]) -> tuple[float, float, float]:
    if len(goal) != 3 or not all(math.isfinite(float(v)) for v in goal):
        raise SceneError("goal", f"must be [x, y, theta], finite, got {list(goal)!r}")
    return tuple(float(v) for v in goal)


def _checked(variant: Mapping[str, Any]) -> dict[str, Any]:
    unknown = sorted(set(variant) - set(OVERRIDES))
    if unknown:
        raise SceneError(f"overrides.{unknown[0]}", f"is not an option a task may change ({', '.join(OVERRIDES)})")
    return {key: OVERRIDES[key](value, f"overrides.{key}") for key, value in variant.items()}


def _region_keys(scene: Scene) -> tuple:
    """What a scene's exact regions depend on, to compute them once for all tasks alike."""
    p = scene.pusher
    return (scene.slider.vertices.tobytes(), scene.slider.cf.tobytes(), tuple(p.edges), p.mu, p.width, scene.cf_uncertainty, scene.planner.regions)


def shared_regions(tasks: Iterable[Task]) -> dict[str, Any]:
    """Compute (or read from the cache) the exact regions of every part, friction and edge the
    tasks plan with, once for the whole batch, and return them by cache key
    (:func:`~planner.actions.region_cache.regions_held`): each worker is sent them once. A scene
    whose regions fail (no stable push) is left to its tasks, which report it."""
    shared: dict[str, Any] = {}
    seen = set()
    for task in tasks:
        scene = task.planned_scene()
        if _region_keys(scene) in seen:
            continue
        seen.add(_region_keys(scene))
        try:
            edge_controls(scene)
        except SceneError:
            continue
        p = scene.pusher
        shared |= regions_held(scene.slider, p.edges, p.mu, p.width, scene.cf_uncertainty)
    return shared


def run_task(task: Task, shared: Mapping[str, Any] | None) -> dict[str, Any]:
    """Plan ``task`` in this (worker) process, with the ``shared`` regions (:func:`shared_regions`)
    put into its cache first: its status (``solved``, ``unreachable``: certified so at once,
    ``unknown``: not solved in time), cost, length, pushes, switches, planning time, the exact
    regions it had to compute itself (0 when the shared ones covered it), its host, and the plan
    file's text."""
    cache = default_cache()
    for key, region in (shared or {}).items():
        if cache.get(key) is None:
            cache.put(key, region)
    scene = task.planned_scene()
    p = scene.pusher
    missing = sum(not is_cached(scene.slider, e, p.mu, p.width, scene.planner.regions, scene.cf_uncertainty)
                  for e in p.edges)
    unreachable = certify_unreachable(scene, regions=False)
    if unreachable:
        result = Plan(scene.path, False, scene.planner.name, task.seed, 0.0, scene.start.copy(), scene.goal.copy(),
                      reason=unreachable)
    else:
        result = plan(scene, seed=task.seed)
    status = "solved" if result.solved else "unreachable" if unreachable else "unknown"
    return {"status": status, "cost": result.cost if result.solved else None,
            "length": result.length if result.solved else None,
            "pushes": result.pushes, "switches": result.switches, "planning_time_s": result.planning_time_s,
            "reason": result.reason, "regions_computed": missing, "host": socket.gethostname(),
            "plan": result.to_json()}
