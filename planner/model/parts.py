"""Multi-part scenes: several parts on one table, each with its start and goal, and one pusher.

A scene file with ``parts:`` instead of ``slider``/``start``/``goal`` (README, "Several parts")
describes a transfer: every part is to be pushed to its goal, and while one part moves the others
are obstacles where they stand. :meth:`PartsScene.move_scene` is the one-part
:class:`~planner.model.scene.Scene` of such a move, which the one-part planner plans as any other.

>>> scene = parse_parts_scene({"parts": [
...     {"name": "a", "vertices": [[0, 0], [0.1, 0], [0.1, 0.1], [0, 0.1]], "start": [0, 0, 0], "goal": [0.5, 0, 0]},
...     {"name": "b", "vertices": [[0, 0], [0.1, 0], [0.1, 0.1], [0, 0.1]], "start": [0, 0.3, 0], "goal": [0, 0.3, 0]}],
...     "pusher": {"width": 0.05, "depth": 0.01, "mu": 0.5}, "workspace": {"min": [-1, -1], "max": [1, 1]}})
>>> scene.names, [round(o.area, 3) for o in scene.move_scene("a", scene.starts).obstacles]
(('a', 'b'), [0.01])
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np
import shapely
from numpy.typing import ArrayLike

from mechanics import Slider, wrap_angle

from .bodies import slider_at
from .fields import SceneError, keys, shown
from .options import PlannerOptions
from .scene import (Pusher, Scene, read_cf_uncertainty, read_edges, read_name, read_pose, read_pusher, read_slider,
                    read_table)

__all__ = ["Part", "PartsScene", "parse_parts_scene"]

#: The keys of one part of ``parts:``: those of ``slider`` (or a CAD file's) and these.
_PART_KEYS = ("name", "start", "goal", "edges")


@dataclass(frozen=True)
class Part:
    """One part of a multi-part scene. Poses are ``(x, y, theta)`` in metres and radians."""

    name: str
    slider: Slider
    start: np.ndarray
    goal: np.ndarray
    edges: tuple[int, ...]  # the edges the pusher may push
    cf_uncertainty: float = 0.0


@dataclass(frozen=True)
class PartsScene:
    """A validated multi-part scene: :class:`Part` s, one pusher (its ``edges`` empty: each part
    has its own), and the table of a one-part :class:`~planner.model.scene.Scene`."""

    name: str
    parts: tuple[Part, ...]
    pusher: Pusher
    obstacles: tuple[shapely.Polygon, ...]
    workspace: tuple[float, float, float, float]
    tolerance_position: float = 0.01
    tolerance_angle: float = math.radians(2.0)
    planner: PlannerOptions = field(default_factory=PlannerOptions)
    path: str | None = None
    notes: tuple[str, ...] = ()

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(p.name for p in self.parts)

    @property
    def starts(self) -> dict[str, np.ndarray]:
        return {p.name: p.start.copy() for p in self.parts}

    @property
    def goals(self) -> dict[str, np.ndarray]:
        return {p.name: p.goal.copy() for p in self.parts}

    def part(self, name: str) -> Part:
        for p in self.parts:
            if p.name == name:
                return p
        raise SceneError("part", f"no part is named {shown(name)} (the parts: {', '.join(self.names)})")

    def with_options(self, options: PlannerOptions) -> "PartsScene":
        """As :meth:`Scene.with_options <planner.model.scene.Scene.with_options>`."""
        pusher = self.pusher if options.transit is None else replace(self.pusher, transit=options.transit)
        return replace(self, planner=options, pusher=pusher)

    def body(self, name: str, pose: ArrayLike) -> shapely.Polygon:
        """Part ``name``'s outline at ``pose`` (world)."""
        return slider_at(self.part(name).slider.polygon, pose)

    def bodies(self, poses: Mapping[str, ArrayLike], without: tuple[str, ...] = ()) -> tuple[shapely.Polygon, ...]:
        """The outlines of the parts at ``poses`` but those named in ``without``."""
        return tuple(self.body(n, poses[n]) for n in self.names if n not in without)

    def move_scene(self, name: str, poses: Mapping[str, ArrayLike], goal: ArrayLike | None = None) -> Scene:
        """The one-part scene of pushing part ``name`` from ``poses[name]`` to ``goal`` (default:
        its own) with every other part an obstacle at its pose in ``poses``."""
        part = self.part(name)
        return Scene(f"{self.name}.{name}", part.slider, replace(self.pusher, edges=part.edges),
                     self.obstacles + self.bodies(poses, (name,)), self.workspace,
                     np.array(poses[name], dtype=float), np.array(part.goal if goal is None else goal, dtype=float),
                     self.tolerance_position, self.tolerance_angle, self.planner, None, part.cf_uncertainty,
                     self.notes)

    def within_tolerance(self, name: str, pose: ArrayLike) -> bool:
        """Whether part ``name`` at ``pose`` is at its goal (:meth:`Scene.within_tolerance
        <planner.model.scene.Scene.within_tolerance>`)."""
        goal = self.part(name).goal
        return (math.hypot(pose[0] - goal[0], pose[1] - goal[1]) <= self.tolerance_position
                and abs(float(wrap_angle(pose[2] - goal[2]))) <= self.tolerance_angle)


def parse_parts_scene(data: dict, default_name: str = "scene", path: str | None = None) -> PartsScene:
    """Validate a multi-part scene given as the parsed YAML mapping (:func:`planner.model.scene_file.parse_scene`
    sends those with ``parts:`` here)."""
    for key in ("slider", "start", "goal"):
        if key in data:
            raise SceneError(key, "a scene has parts: (each with its own start and goal) or slider, start and goal, "
                                  "not both")
    spec = keys(data, "scene", ("parts", "pusher", "workspace"), ("name", "obstacles", "tolerance", "planner"))
    name = read_name(spec.get("name", default_name))
    folder, notes = Path(path).parent if path else Path(), []
    pusher = read_pusher(spec["pusher"], None)
    table = read_table(spec, folder, notes)
    listed = spec["parts"]
    if not isinstance(listed, list) or not listed:
        raise SceneError("parts", "must be a non-empty list of parts, each with name, vertices, start and goal")
    parts: list[Part] = []
    for i, item in enumerate(listed):
        field_name = f"parts[{i}]"
        slider = read_slider(item, folder, notes, field_name, _PART_KEYS)
        for key in ("name", "start", "goal"):
            if key not in item:
                raise SceneError(f"{field_name}.{key}", "missing")
        part_name = _part_name(item["name"], f"{field_name}.name")
        if part_name in (p.name for p in parts):
            raise SceneError(f"{field_name}.name", f"part {shown(part_name)} is named twice")
        poses = [read_pose(item[k], f"{field_name}.{k}", slider, table.obstacles, table.workspace) for k in ("start", "goal")]
        parts.append(Part(part_name, slider, *poses, read_edges(item.get("edges"), slider, f"{field_name}.edges"),
                          read_cf_uncertainty(item, slider, field_name)))
    for which in ("start", "goal"):
        _apart(parts, which)
    return PartsScene(name, tuple(parts), pusher, table.obstacles, table.workspace, table.tolerance_position,
                      table.tolerance_angle, table.planner, path, tuple(notes))


def _part_name(value: Any, field_name: str) -> str:
    """A part's name: what names a scene (it may name files) and no longer than a label."""
    try:
        return read_name(value)
    except SceneError as err:
        raise SceneError(field_name, err.problem) from None


def _apart(parts: list[Part], which: str) -> None:
    """Refuse two parts that touch or overlap at their ``which`` poses (``'start'`` or ``'goal'``),
    naming both."""
    bodies = [slider_at(p.slider.polygon, getattr(p, which)) for p in parts]
    i, j = shapely.STRtree(bodies).query(bodies, predicate="intersects")
    for a, b in zip(i.tolist(), j.tolist()):
        if a < b:
            raise SceneError(f"parts[{b}].{which}", f"part {shown(parts[b].name)} overlaps part "
                                                    f"{shown(parts[a].name)} at their {which}s")

