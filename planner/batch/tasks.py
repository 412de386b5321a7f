"""A batch's tasks: one scene, one seed, optionally another goal and option overrides; and how a
worker runs one (:func:`run_task`).

A task's plan depends on its scene, seed, goal and overrides only: a worker plans it with the
stable regions the run computed beforehand (:func:`shared_regions`), never with regions cut short
by the time limit, so the same task gives the same plan on any engine and any number of workers.

>>> parse_seeds("1:3"), parse_seeds("7"), parse_seeds("2,5,9")
(range(1, 4), [7], [2, 5, 9])
"""

from __future__ import annotations

import hashlib
import json
import math
import re
import socket
from collections.abc import Iterable, Iterator, Mapping, Sequence
from functools import cache
from importlib import metadata
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from mechanics import Slider

from ..actions.controls import certified_for, edge_controls
from ..actions.region_cache import default_cache, is_cached, regions_held
from ..model.fields import SceneError, number, shown
from ..model.margin import check_margin
from ..model.options import (PlannerOptions, check_optimize, check_planner, check_regions, check_seed,
                             check_switch_cost, check_time_limit, check_transit)
from ..model.scene import Scene
from ..model.scene_file import load_scene
from ..pipeline import run

__all__ = ["OVERRIDES", "Task", "TaskList", "make_tasks", "parse_seeds", "planner_version", "run_task", "shared_regions"]

#: What a task may change of its scene, and the check of each value.
OVERRIDES = {
    "planner": check_planner, "time_limit": check_time_limit, "transit": check_transit,
    "regions": check_regions, "switch_cost": check_switch_cost, "optimize": check_optimize,
    "mu": lambda value, name: number(value, name, positive=True),
    "cf_offset": lambda value, name: _pair(value, name),
    "margin": lambda value, name: check_margin(value, name).to_dict(),  # kept as plain data, as tasks are
}


#: The overrides that are planner options (:class:`~planner.model.options.PlannerOptions`;
#: ``planner`` is its ``name``).
_OPTIONS = ("planner", "time_limit", "transit", "regions", "switch_cost", "optimize", "margin")


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
    digest: str | None = None  # SHA-256 of the scene file's bytes (None for a Scene given as such)

    def planned(self) -> tuple[Scene, PlannerOptions]:
        """The scene as planned, the goal and the scene's overrides (``mu``, ``cf_offset``)
        applied, and the options it is planned with: the scene's own with the seed and the
        planner's overrides. A multi-part scene takes neither a goal, its parts have theirs, nor a
        CF offset, which is a part's."""
        scene, o = self.scene, self.overrides
        if len(scene.parts) > 1:
            for name, given in (("goal", self.goal), ("overrides.cf_offset", o.get("cf_offset"))):
                if given is not None:
                    raise SceneError(name, "is for one-part scenes: a scene with parts has a goal and a CF per part")
        if self.goal is not None:
            scene = scene.with_part(goal=self.goal)
        changes = {"name" if key == "planner" else key: o[key] for key in _OPTIONS if key in o}
        options = scene.options.merged({**changes, "seed": self.seed}, prefix="overrides.")
        if "mu" in o:
            scene = replace(scene, pusher=replace(scene.pusher, mu=o["mu"]))
        if "cf_offset" in o:
            slider = scene.slider
            try:
                scene = scene.with_part(slider=Slider(slider.vertices, slider.cf + np.asarray(o["cf_offset"])))
            except ValueError as err:
                raise SceneError("overrides.cf_offset", str(err)) from None
        return scene, options

    def record(self) -> dict[str, Any]:
        """What the results file says of the task itself: what it is, and what its plan depends
        on besides (the scene file's content and the planner's version), so that ``--resume``
        reuses a result only for the same task (:meth:`is_answered_by`)."""
        return {"id": self.id, "scene": self.scene.path or self.scene.name, "seed": self.seed,
                "goal": None if self.goal is None else [float(v) for v in self.goal],
                "overrides": dict(self.overrides), "scene_digest": self.digest, "version": planner_version()}

    def is_answered_by(self, record: Mapping[str, Any]) -> bool:
        """Whether the results line ``record`` is this task's: every field of :meth:`record` the
        same, as JSON gives them back (a Scene given as such, with no file, is never reused).

        >>> from planner import load_scene
        >>> task = make_tasks(["scenes/battery.yaml"], [3])[0]
        >>> task.is_answered_by(task.record()), task.is_answered_by(task.record() | {"scene_digest": "0" * 64})
        (True, False)
        >>> task.is_answered_by(task.record() | {"version": "0.1.0"}), task.is_answered_by(task.record() | {"seed": 4})
        (False, False)
        """
        mine = json.loads(json.dumps(self.record()))
        return self.digest is not None and all(record.get(k) == v for k, v in mine.items())


def parse_seeds(text: str) -> Sequence[int]:
    """Seeds from ``A:B`` (A to B, both included: a range, however long, takes no memory), ``N``
    or ``A,B,C``.

    Raises
    ------
    SceneError
        Naming ``--seeds``.
    """
    try:
        if ":" in text:
            first, last = (int(v) for v in text.split(":"))
            seeds: Sequence[int] = range(first, last + 1)
        else:
            seeds = [int(v) for v in text.split(",")]
    except ValueError:
        raise SceneError("seeds", f"must be A:B, N or A,B,C (integers), got {shown(text)}") from None
    if not seeds:
        raise SceneError("seeds", f"{shown(text)} holds no seed (A:B needs A <= B)")
    if isinstance(seeds, range):
        check_seed(seeds[0], "seeds")
        check_seed(seeds[-1], "seeds")
        return seeds
    return [check_seed(s, "seeds") for s in seeds]


@cache
def planner_version() -> str:
    """The planner's version as each results line records it: the package's version and a digest
    of its source (the planner's and the mechanics' modules), since a plan depends on the code
    that made it and the package's version does not change with every edit.

    >>> planner_version().startswith(metadata.version("stablepush") + "+")
    True
    """
    try:
        version = metadata.version("stablepush")
    except metadata.PackageNotFoundError:
        version = "unknown"
    root = Path(__file__).resolve().parents[2]
    digest = hashlib.sha256()
    for path in sorted([*(root / "planner").rglob("*.py"), *(root / "mechanics").rglob("*.py")]):
        digest.update(path.relative_to(root).as_posix().encode() + b"\0" + path.read_bytes() + b"\0")
    return f"{version}+{digest.hexdigest()[:12]}"


#: A task id: the scene's name, the seed, and the goal's and the variant's numbers where there are several.
_ID = re.compile(r"(?P<name>.+)-s(?P<seed>[0-9]{1,10})(?:-g(?P<goal>[0-9]{1,9}))?(?:-o(?P<variant>[0-9]{1,9}))?")


class TaskList(Sequence):
    """Every combination of ``scenes``, ``seeds`` (None: each scene's own), ``goals`` (None: each
    scene's own) and ``variants`` of the overrides, in that order, made only when asked for: its
    length, a task by its index and a task by its id (:meth:`find`) cost the same for a seed range
    of four billion as for one seed, and iterating makes one task at a time."""

    def __init__(self, scenes: Sequence[Scene], digests: Sequence[str | None], seeds: Sequence[int] | None,
                 goals: Sequence[tuple[float, float, float]] | None, variants: Sequence[dict[str, Any]]):
        self.scenes, self.digests, self.seeds, self.goals, self.variants = scenes, digests, seeds, goals, variants
        names = [s.name for s in scenes]
        self.names = [name if names.count(name) == 1 else f"{name}.{k}" for k, name in enumerate(names)]
        self._by_name = {name: k for k, name in enumerate(self.names)}
        self._shape = (len(scenes), 1 if seeds is None else len(seeds), 1 if goals is None else len(goals),
                       len(variants))
        self._seed_at = None if seeds is None or isinstance(seeds, range) else {s: i for i, s in enumerate(seeds)}

    def __len__(self) -> int:
        return math.prod(self._shape)

    def __getitem__(self, index):
        if isinstance(index, slice):
            return [self[i] for i in range(len(self))[index]]
        k, s, g, v = _unravel(range(len(self))[index], self._shape)
        scene = self.scenes[k]
        seed = scene.options.seed if self.seeds is None else self.seeds[s]
        tag = (f"{self.names[k]}-s{seed}{'' if self.goals is None else f'-g{g}'}"
               f"{'' if len(self.variants) == 1 else f'-o{v}'}")
        return Task(tag, scene, seed, None if self.goals is None else self.goals[g], self.variants[v], self.digests[k])

    def __iter__(self) -> Iterator[Task]:
        return (self[i] for i in range(len(self)))

    def find(self, task_id: str) -> Task | None:
        """The task whose id is ``task_id``, if it is one of these.

        >>> tasks = make_tasks(["scenes/battery.yaml"], range(1, 2**32))
        >>> tasks.find("battery-s4000000000").seed, tasks.find("battery-s0"), tasks.find("other-s1")
        (4000000000, None, None)
        """
        match = _ID.fullmatch(task_id) if isinstance(task_id, str) else None
        if match is None or match["name"] not in self._by_name:
            return None
        k, seed = self._by_name[match["name"]], int(match["seed"])
        if self.seeds is None:
            s = 0
        elif self._seed_at is None:
            s = seed - self.seeds.start if seed in self.seeds else None
        else:
            s = self._seed_at.get(seed)
        g = int(match["goal"]) if match["goal"] is not None else 0
        v = int(match["variant"]) if match["variant"] is not None else 0
        if s is None or not (g < self._shape[2] and v < self._shape[3]):
            return None
        task = self[((k * self._shape[1] + s) * self._shape[2] + g) * self._shape[3] + v]
        return task if task.id == task_id else None

    def setups(self) -> list[Task]:
        """A task of each scene and variant of the overrides: what the stable regions and the
        time limits depend on (not the seed nor the goal)."""
        return [self[(k * self._shape[1] * self._shape[2]) * self._shape[3] + v]
                for k in range(self._shape[0]) for v in range(self._shape[3])]


def _unravel(index: int, shape: tuple[int, ...]) -> tuple[int, ...]:
    """``index`` into a row-major array of ``shape`` as one index per axis (plain ints, any size).

    >>> _unravel(7, (2, 2, 2)), _unravel(2**40 + 1, (1, 2**41))
    ((1, 1, 1), (0, 1099511627777))
    """
    out = []
    for size in reversed(shape):
        index, rest = divmod(index, size)
        out.append(rest)
    return tuple(reversed(out))


def make_tasks(scenes: Iterable[str | Path | Scene], seeds: Sequence[int] | None = None,
               goals: Sequence[Sequence[float]] | None = None,
               overrides: Sequence[Mapping[str, Any]] | Mapping[str, Any] | None = None) -> TaskList:
    """Every combination of ``scenes`` (files are read now), ``seeds`` (default: each scene's
    own), ``goals`` (default: each scene's own) and ``overrides`` (one mapping, or several
    variants), in that order, with ids ``<scene>-s<seed>[-g<goal>][-o<variant>]``, as a
    :class:`TaskList` (each task made when it is needed).

    Raises
    ------
    SceneError
        For a scene file (the message names it) or override that is not valid.
    """
    loaded, digests = [], []
    for s in scenes:
        if isinstance(s, Scene):
            loaded.append(s)
            digests.append(None)
            continue
        try:
            loaded.append(load_scene(s))
        except SceneError as err:  # among several scene files, say which
            raise SceneError(str(s) if err.field == "scene" else f"{s}: {err.field}", err.problem) from None
        digests.append(_digest(s))
    variants = [overrides or {}] if overrides is None or isinstance(overrides, Mapping) else list(overrides)
    if isinstance(seeds, range) and seeds:  # the seeds between are within bounds if the ends are
        check_seed(seeds[0], "seed")
        check_seed(seeds[-1], "seed")
    elif not isinstance(seeds, range) and seeds is not None:
        seeds = [check_seed(s, "seed") for s in seeds]
    return TaskList(loaded, digests, seeds, None if goals is None else [_goal(g) for g in goals],
                    [_checked(v) for v in variants])


def _digest(path: str | Path) -> str | None:
    """SHA-256 of the file's bytes (it was just read as a scene: a regular file of at most a megabyte)."""
    try:
        return hashlib.sha256(Path(path).read_bytes()).hexdigest()
    except OSError:
        return None


def _goal(goal: Sequence[float]) -> tuple[float, float, float]:
    if len(goal) != 3 or not all(math.isfinite(float(v)) for v in goal):
        raise SceneError("goal", f"must be [x, y, theta], finite, got {list(goal)!r}")
    return tuple(float(v) for v in goal)


def _checked(variant: Mapping[str, Any]) -> dict[str, Any]:
    unknown = sorted(set(variant) - set(OVERRIDES))
    if unknown:
        raise SceneError(f"overrides.{unknown[0]}", f"is not an option a task may change ({', '.join(OVERRIDES)})")
    return {key: OVERRIDES[key](value, f"overrides.{key}") for key, value in variant.items()}


def _one_part(scene: Scene) -> list[Scene]:
    """The one-part scenes whose regions ``scene`` plans with: each of its parts' moves."""
    return [scene.move_scene(name, scene.starts) for name in scene.names]


def _region_keys(scene: Scene, options: PlannerOptions) -> tuple:
    """What a scene's regions of ``options`` depend on, to compute them once for all tasks alike."""
    p = scene.pusher
    return (scene.slider.vertices.tobytes(), scene.slider.cf.tobytes(), tuple(scene.edges), p.width,
            certified_for(scene, options.margin, options.regions), options.regions)


def shared_regions(tasks: Iterable[Task] | TaskList) -> dict[str, Any]:
    """Compute (or read from the cache) the exact regions of every part, friction and edge the
    tasks plan with, once for the whole batch, and return them by cache key
    (:func:`~planner.actions.region_cache.regions_held`): each worker is sent them once. A scene
    whose regions fail (no stable push) is left to its tasks, which report it."""
    shared: dict[str, Any] = {}
    seen = set()
    for task in tasks.setups() if isinstance(tasks, TaskList) else tasks:
        planned, options = task.planned()
        for scene in _one_part(planned):
            if (key := _region_keys(scene, options)) in seen:
                continue
            seen.add(key)
            try:
                edge_controls(scene, regions=options.regions, margin=options.margin)
            except SceneError:
                continue
            mu, rho = certified_for(scene, options.margin, options.regions)
            shared |= regions_held(scene.slider, scene.edges, mu, scene.pusher.width, rho)
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
    scene, options = task.planned()
    missing = sum(not is_cached(one.slider, e, mu, one.pusher.width, options.regions, rho)
                  for one in _one_part(scene) for e in one.edges
                  for mu, rho in [certified_for(one, options.margin, options.regions)])
    # The command's pipeline, writing nothing: the certificates, else the plan.
    outcome = run(scene, planner_options=options)
    result = outcome.plan
    status = "solved" if result.solved else "unreachable" if outcome.unreachable else "unknown"
    return {"status": status, "cost": result.cost if result.solved else None,
            "length": result.length if result.solved else None,
            "pushes": result.pushes, "switches": result.switches, "planning_time_s": result.planning_time_s,
            "reason": result.reason, "regions_computed": missing, "host": socket.gethostname(),
            "plan": result.to_json()}
