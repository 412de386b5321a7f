"""One-step planning (Lynch 1992, §5.1): reach the goal by one constant push.

The displacement from start to goal is one body twist, ``COR_total`` (turning by the smaller
angle). If that twist lies in an edge's stable region and the motion is collision-free, pushing
about ``COR_total`` reaches the goal exactly. The planner's goal region is built on it
(:mod:`planner.preimage`). Each allowed edge's goal is also labelled as the paper's fig. 12 does
(:func:`mechanics.classify_goal`): ``goal1`` guaranteed, ``goal2`` possible, ``goal3`` impossible,
collisions aside.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from mechanics import GOALS, SupportModel, classify_goal, exp_twist, log_pose, wrap_angle

from .plan_file import Segment
from .pushes import EdgePush, clearance_margin, edge_pushes
from .scene import Scene
from .validity import CollisionModel

__all__ = ["OneStep", "connect", "goal_verdicts", "one_step"]


def connect(start: ArrayLike, goal: ArrayLike, push: EdgePush, model: CollisionModel, margin: float, *,
            total: np.ndarray | None = None) -> Segment | str:
    """The single stable push of ``push.edge`` from ``start`` to ``goal`` keeping ``margin`` from
    obstacles, or why there is none. A caller that has COR_total (``log_pose(start, goal)``) and
    has found it stable passes it as ``total``: it is not computed nor checked again."""
    checked = total is not None
    total = log_pose(start, goal) if total is None else total
    speed = float(push.speed(total))
    if speed == 0.0:
        return "the start is the goal"
    if not checked and not push.region.contains(total):
        return "COR_total is not a stable push"
    twist, duration = total / speed, speed
    if not model.push_is_free(start, twist, duration, push.edge, margin):
        return "the push collides"
    end = exp_twist(start, twist, duration)
    end[2] = wrap_angle(end[2])
    return Segment(push.edge, push.region.contact, twist, duration, np.asarray(start, dtype=float), end)


@dataclass(frozen=True)
class OneStep:
    """Answer of :func:`one_step`: the push (``segment``) if reachable, else the ``reason``;
    ``verdicts`` labels ``COR_total`` per allowed edge ``'goal1'``, ``'goal2'`` or ``'goal3'``."""

    reachable: bool
    segment: Segment | None
    reason: str
    verdicts: dict[int, str] = field(default_factory=dict)

    @property
    def edge(self) -> int | None:
        return self.segment.edge if self.segment else None

    @property
    def twist(self) -> np.ndarray | None:
        return self.segment.twist if self.segment else None


def one_step(scene: Scene, start: ArrayLike | None = None, goal: ArrayLike | None = None) -> OneStep:
    """Is ``goal`` reachable from ``start`` (default: the scene's, radians) by one constant stable
    push about ``COR_total`` on some allowed edge, without collision?

    Edges are tried in the order the scene allows them; the first that works is returned.
    """
    start = scene.start if start is None else np.asarray(start, dtype=float)
    goal = scene.goal if goal is None else np.asarray(goal, dtype=float)
    pushes = edge_pushes(scene)
    model = CollisionModel(scene, [p.edge for p in pushes])
    verdicts = goal_verdicts(scene, start, goal)
    reasons = []
    for push in pushes:
        result = connect(start, goal, push, model, clearance_margin(scene))
        if isinstance(result, Segment):
            return OneStep(True, result, "", verdicts)
        reasons.append(f"edge {push.edge}: {result}")
    return OneStep(False, None, "; ".join(reasons), verdicts)


def goal_verdicts(scene: Scene, start: ArrayLike, goal: ArrayLike) -> dict[int, str]:
    """The paper's label of ``COR_total`` for each allowed edge (Lynch 1992, §5.1 and fig. 12)."""
    total = log_pose(start, goal)
    if not np.any(total):  # no motion: no COR to classify
        return {}
    p, support = scene.pusher, SupportModel.of_slider(scene.slider, cf_radius=scene.cf_uncertainty)
    return {e: GOALS[classify_goal(scene.slider, e, p.mu, total, support, p.width)] for e in p.edges}
