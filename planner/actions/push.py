"""One constant stable push between two poses, checked: the step every planner part is made of.

The displacement from ``start`` to ``goal`` is one body twist, ``COR_total = log(start^-1 goal)``
(turning by the smaller angle; Lynch 1992, §5.1). If it lies in an edge's stable region and the
motion keeps its clearance, pushing about that COR reaches the goal exactly (:func:`connect`).
:func:`free_push` checks any given push the same way, so every push a plan holds, whoever built
it (the goal region, the shortcuts, the Dubins curves), passed one test.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from mechanics import log_pose

from ..model.segments import Push
from ..world.validity import CollisionModel
from .controls import EdgeControls

__all__ = ["connect", "free_push"]


def free_push(controls: EdgeControls, model: CollisionModel, margin: float, start: ArrayLike, twist: ArrayLike,
              duration: float, *, stable: bool = False) -> Push | str:
    """The push of unit-speed ``twist`` for ``duration`` from ``start`` on ``controls.edge`` if
    it is stable (not checked again when the caller knows it is, ``stable=True``) and keeps
    ``margin`` from obstacles all the way, else why not."""
    if not stable and not controls.region.contains(twist):
        return "the twist is not a stable push"
    if not model.push_is_free(start, twist, duration, controls.edge, margin):
        return "the push collides"
    return controls.push(start, twist, duration)


def connect(start: ArrayLike, goal: ArrayLike, controls: EdgeControls, model: CollisionModel, margin: float, *,
            total: np.ndarray | None = None) -> Push | str:
    """The single stable push of ``controls.edge`` from ``start`` to ``goal`` keeping ``margin``
    from obstacles, or why there is none. A caller that has COR_total (``log_pose(start, goal)``)
    and has found it stable passes it as ``total``: it is not computed nor checked again.

    >>> from planner import load_scene
    >>> from planner.actions.controls import clearance_margin, edge_controls
    >>> scene = load_scene("scenes/battery.yaml")
    >>> [controls] = edge_controls(scene)
    >>> model = CollisionModel(scene, [controls.edge])
    >>> connect(scene.start, scene.start, controls, model, clearance_margin(scene))
    'the start is the goal'
    >>> push = connect(scene.start, scene.goal, controls, model, clearance_margin(scene))
    >>> bool(np.allclose(push.end, scene.goal)), push.edge
    (True, 3)
    """
    checked = total is not None
    total = log_pose(start, goal) if total is None else total
    speed = float(controls.speed(total))
    if speed == 0.0:
        return "the start is the goal"
    if not checked and not controls.region.contains(total):
        return "COR_total is not a stable push"
    return free_push(controls, model, margin, np.asarray(start, dtype=float), total / speed, speed, stable=True)
