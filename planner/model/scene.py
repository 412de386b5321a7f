"""Scenes: parts on a table among obstacles, each with a start and a goal, and one pusher.

A scene is what its file describes (:mod:`.scene_file` reads and writes it): :class:`Part` s,
the :class:`Pusher`, the obstacles, the workspace and the goal tolerance. A file with ``slider:``,
``start:`` and ``goal:`` is a scene of one part, named :data:`ONE_PART`; a file with ``parts:``
names its own. Everything that plans, checks or draws takes a scene of any number of parts.

How to plan is apart from the scene: the options the file asks for are kept as
:attr:`Scene.options`, the defaults of a :class:`planner.Planner` session, which resolves its own
options once and passes them down; what plans, checks or draws below it takes them as arguments.

Moving one part is a problem of one part: :meth:`Scene.move_scene` is the scene of that move,
every other part an obstacle where it stands. The search works on such scenes of one part, whose
:meth:`Scene.part` (and its shorthands :attr:`Scene.slider`, :attr:`Scene.start`,
:attr:`Scene.goal`, :attr:`Scene.edges`, :attr:`Scene.cf_uncertainty`) is the part moved.

>>> from planner.model.scene_file import parse_scene
>>> square = [[0, 0], [0.1, 0], [0.1, 0.1], [0, 0.1]]
>>> tray = parse_scene({"parts": [
...     {"name": "a", "vertices": square, "start": [0, 0, 0], "goal": [0.5, 0, 0]},
...     {"name": "b", "vertices": square, "start": [0, 0.3, 0], "goal": [0, 0.3, 0]}],
...     "pusher": {"width": 0.05, "depth": 0.01, "mu": 0.5}, "workspace": {"min": [-1, -1], "max": [1, 1]}})
>>> move = tray.move_scene("a", tray.starts)
>>> tray.names, move.names, [round(o.area, 3) for o in move.obstacles], move.goal.tolist()
(('a', 'b'), ('a',), [0.01], [0.5, 0.0, 0.0])
>>> tray.start
Traceback (most recent call last):
...
planner.model.fields.SceneError: part: the scene has 2 parts (a, b): name one
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
import shapely
from numpy.typing import ArrayLike

from mechanics import Slider, pose_error

from .bodies import slider_at
from .fields import SceneError, shown
from .options import PlannerOptions
from .camera import Camera
from .robot import Robot

__all__ = ["OBSTACLE_HEIGHT", "ONE_PART", "PART_HEIGHT", "Part", "Pusher", "Scene"]

#: The name of the part of a scene file with ``slider:`` (a scene of one part).
ONE_PART = "part"
#: An obstacle's height when its entry gives none (m): a fixture's wall, lower than either arm's
#: links come with a tool of 0.1 m or more (docs/arm.md).
OBSTACLE_HEIGHT = 0.05
#: How high a part stands above the table (m), as an obstacle to the arm: parts are flat.
PART_HEIGHT = 0.01


@dataclass(frozen=True)
class Pusher:
    """The flat pusher. ``mu`` is the friction the plan relies on: the scene's value, or the low
    end of its interval ``[mu, mu_high]`` (sticking at the lowest friction implies sticking at
    any higher one, :func:`mechanics.exact_region`)."""

    width: float
    depth: float
    mu: float
    mu_high: float | None = None  # top of the friction interval, if one was given


@dataclass(frozen=True)
class Part:
    """One part of a scene. Poses are ``(x, y, theta)`` in metres and radians."""

    name: str
    slider: Slider
    start: np.ndarray
    goal: np.ndarray
    edges: tuple[int, ...]  # the edges the pusher may push
    cf_uncertainty: float = 0.0  # radius of the disk about slider.cf holding the true CF (metres)


@dataclass(frozen=True)
class Scene:
    """A validated scene (module docstring). Poses are ``(x, y, theta)`` in metres and **radians**."""

    name: str
    parts: tuple[Part, ...]
    pusher: Pusher
    obstacles: tuple[shapely.Polygon, ...]
    workspace: tuple[float, float, float, float]  # xmin, ymin, xmax, ymax
    tolerance_position: float = 0.01
    tolerance_angle: float = math.radians(2.0)
    #: The options the file asks for (its ``planner:`` block and ``pusher.transit``): a session's
    #: defaults (:class:`planner.Planner`); nothing below the session reads them.
    options: PlannerOptions = field(default_factory=PlannerOptions)
    path: str | None = None  # the file it was read from
    notes: tuple[str, ...] = ()  # what was not read from the CAD files it names (text, open chains)
    robot: Robot | None = None  # the arm holding the pusher (None: a pusher that floats)
    camera: Camera | None = None  # the overhead depth camera (None: the file has no camera block)
    #: The first obstacles' heights above the table (m); those after them, the other parts that
    #: :meth:`move_scene` and the transfers stand in the way, are as high as a part
    #: (:data:`PART_HEIGHT`). Only an arm's links can meet an obstacle's top (planner.world.reach).
    heights: tuple[float, ...] = ()

    @property
    def obstacle_heights(self) -> tuple[float, ...]:
        """Each obstacle's height above the table (m), in :attr:`obstacles`' order."""
        return tuple(self.heights[:len(self.obstacles)]) + (PART_HEIGHT,) * (len(self.obstacles) - len(self.heights))

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(p.name for p in self.parts)

    @property
    def starts(self) -> dict[str, np.ndarray]:
        return {p.name: p.start.copy() for p in self.parts}

    @property
    def goals(self) -> dict[str, np.ndarray]:
        return {p.name: p.goal.copy() for p in self.parts}

    def part(self, name: str | None = None) -> Part:
        """The part named ``name``; without a name, the scene's one part (a scene of several
        parts must be told which)."""
        if name is None:
            if len(self.parts) != 1:
                raise SceneError("part", f"the scene has {len(self.parts)} parts ({', '.join(self.names)}): name one")
            return self.parts[0]
        for p in self.parts:
            if p.name == name:
                return p
        raise SceneError("part", f"no part is named {shown(name)} (the parts: {', '.join(self.names)})")

    def one_part(self, query: str) -> None:
        """Refuse this scene for ``query`` if it has several parts: ``query`` answers for one, and
        the message says how to ask for one.

        >>> from planner.model.scene_file import load_scene
        >>> load_scene("scenes/parts/swap.yaml").one_part("one_step")
        Traceback (most recent call last):
        ...
        planner.model.fields.SceneError: scene: has 2 parts; one_step answers for one part: pick one with scene.move_scene(name, scene.starts)
        """
        if len(self.parts) > 1:
            raise SceneError("scene", f"has {len(self.parts)} parts; {query} answers for one part: pick one with "
                                      "scene.move_scene(name, scene.starts)")

    @property
    def slider(self) -> Slider:
        """The one part's outline and CF."""
        return self.part().slider

    @property
    def start(self) -> np.ndarray:
        return self.part().start

    @property
    def goal(self) -> np.ndarray:
        return self.part().goal

    @property
    def edges(self) -> tuple[int, ...]:
        """The edges of the one part the pusher may push."""
        return self.part().edges

    @property
    def cf_uncertainty(self) -> float:
        return self.part().cf_uncertainty

    def with_part(self, **changes: Any) -> "Scene":
        """This scene with its one part's fields changed (``start``, ``goal``, ``slider``,
        ``edges``, ``cf_uncertainty``); poses are taken as float arrays."""
        for key in ("start", "goal"):
            if key in changes:
                changes[key] = np.asarray(changes[key], dtype=float)
        return replace(self, parts=(replace(self.part(), **changes),))

    def body(self, name: str, pose: ArrayLike) -> shapely.Polygon:
        """Part ``name``'s outline at ``pose`` (world)."""
        return slider_at(self.part(name).slider.polygon, pose)

    def bodies(self, poses: Mapping[str, ArrayLike], without: tuple[str, ...] = ()) -> tuple[shapely.Polygon, ...]:
        """The outlines of the parts at ``poses`` but those named in ``without``."""
        return tuple(self.body(n, poses[n]) for n in self.names if n not in without)

    def move_scene(self, name: str, poses: Mapping[str, ArrayLike], goal: ArrayLike | None = None,
                   others: bool = True) -> "Scene":
        """The one-part scene of pushing part ``name`` from ``poses[name]`` to ``goal`` (default:
        its own), every other part an obstacle at its pose in ``poses`` (with ``others``; without,
        the obstacles alone). The move scene of a one-part scene's part is the scene itself, but
        for its start and goal."""
        part = self.part(name)
        moved = replace(part, start=np.array(poses[name], dtype=float),
                        goal=np.array(part.goal if goal is None else goal, dtype=float))
        if len(self.parts) == 1:
            return replace(self, parts=(moved,))
        obstacles = self.obstacles + (self.bodies(poses, (name,)) if others else ())
        return replace(self, name=f"{self.name}.{name}", parts=(moved,), obstacles=obstacles, path=None)

    def within_tolerance(self, pose: ArrayLike, goal: ArrayLike | None = None) -> bool:
        """Whether ``pose`` ends the task: its origin within ``tolerance_position`` of ``goal``'s
        (default: the one part's goal) and its heading within ``tolerance_angle``. The one test of
        the tolerance: the search's goal test, the plan decoder and the certificates all use it.

        >>> from planner.model.scene_file import parse_scene
        >>> scene = parse_scene({"slider": {"vertices": [[0, 0], [0.1, 0], [0.1, 0.1], [0, 0.1]]},
        ...     "pusher": {"width": 0.05, "depth": 0.01, "mu": 0.5}, "workspace": {"min": [-1, -1], "max": [1, 1]},
        ...     "start": [0, 0, 0], "goal": [0.5, 0, 0]})
        >>> scene.within_tolerance([0.5, 0.01, 0.0]), scene.within_tolerance([0.5, 0.0101, 0.0])
        (True, False)
        >>> scene.within_tolerance([0.5, 0.0, math.radians(1.9)]), scene.within_tolerance([0.5, 0.0, math.radians(2.1)])
        (True, False)
        """
        distance, turn = pose_error(pose, self.goal if goal is None else goal)
        return distance <= self.tolerance_position and turn <= self.tolerance_angle

    def delivered(self, name: str, pose: ArrayLike) -> bool:
        """Whether part ``name`` at ``pose`` is within tolerance of its goal."""
        return self.within_tolerance(pose, self.part(name).goal)

    def tolerance_slack(self, reach: float) -> float:
        """How far a point ``reach`` from the slider frame's origin may end from where it is at
        the goal, for a pose within tolerance: ``tolerance_position + reach * tolerance_angle``
        (a turn by ``a`` moves it ``2 reach sin(a / 2) <= reach a``).

        >>> from planner.model.scene_file import parse_scene
        >>> scene = replace(parse_scene({"slider": {"vertices": [[0, 0], [1, 0], [1, 1], [0, 1]]},
        ...     "pusher": {"width": 0.5, "depth": 0.1, "mu": 0.5}, "workspace": {"min": [-3, -3], "max": [3, 3]},
        ...     "start": [0, 0, 0], "goal": [1, 0, 0]}), tolerance_angle=0.1)
        >>> round(scene.tolerance_slack(2.0), 12)  # 0.01 + 2 * 0.1
        0.21
        """
        return self.tolerance_position + reach * self.tolerance_angle
