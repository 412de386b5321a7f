"""One-step planning (Lynch 1992, §5.1): reach the goal by one constant push.

The displacement from start to goal is one body twist, ``COR_total`` (turning by the smaller
angle). If that twist lies in an edge's stable region and the motion is collision-free, pushing
about ``COR_total`` reaches the goal exactly. The planner's goal region is built on it
(:mod:`planner.search.goal_region`). Each allowed edge's goal is also labelled as the paper's fig. 12 does
(:func:`mechanics.classify_goal`): ``goal1`` guaranteed, ``goal2`` possible, ``goal3`` impossible,
collisions aside.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from mechanics import GOALS, SupportModel, classify_goal, log_pose

from ..model.fields import pose
from ..model.segments import Push
from ..actions.controls import clearance_margin, edge_controls
from ..model.margin import EXACT, Margin
from ..actions.push import connect
from ..model.options import DEFAULT_REGIONS
from ..model.scene import Scene
from ..world.validity import CollisionModel

__all__ = ["OneStep", "goal_verdicts", "one_step"]


@dataclass(frozen=True)
class OneStep:
    """Answer of :func:`one_step`: the push (``segment``) if reachable, else the ``reason``;
    ``verdicts`` labels ``COR_total`` per allowed edge ``'goal1'``, ``'goal2'`` or ``'goal3'``."""

    reachable: bool
    segment: Push | None
    reason: str
    verdicts: dict[int, str] = field(default_factory=dict)

    @property
    def edge(self) -> int | None:
        return self.segment.edge if self.segment else None

    @property
    def twist(self) -> np.ndarray | None:
        return self.segment.twist if self.segment else None


def one_step(scene: Scene, start: ArrayLike | None = None, goal: ArrayLike | None = None, *,
             regions: str = DEFAULT_REGIONS, margin: Margin = EXACT) -> OneStep:
    """Is ``goal`` reachable from ``start`` (default: the scene's, radians) by one constant stable
    push about ``COR_total`` on some allowed edge, without collision? The stable pushes are the
    ``regions`` option's (``'exact'`` or ``'stable'``), with ``margin`` to spare (default: none).

    Edges are tried in the order the scene allows them; the first that works is returned.
    """
    scene.one_part("one_step")
    start = scene.start if start is None else pose(start, "start")
    goal = scene.goal if goal is None else pose(goal, "goal")
    pushes = edge_controls(scene, regions=regions, margin=margin)
    model = CollisionModel(scene, [p.edge for p in pushes])
    verdicts = goal_verdicts(scene, start, goal)
    reasons = []
    for push in pushes:
        result = connect(start, goal, push, model, clearance_margin(scene))
        if isinstance(result, Push):
            return OneStep(True, result, "", verdicts)
        reasons.append(f"edge {push.edge}: {result}")
    return OneStep(False, None, "; ".join(reasons), verdicts)


def goal_verdicts(scene: Scene, start: ArrayLike, goal: ArrayLike) -> dict[int, str]:
    """The paper's label of ``COR_total`` for each allowed edge (Lynch 1992, §5.1 and fig. 12)."""
    total = log_pose(start, goal)
    if not np.any(total):  # no motion: no COR to classify
        return {}
    p, support = scene.pusher, SupportModel.of_slider(scene.slider, cf_radius=scene.cf_uncertainty)
    return {e: GOALS[classify_goal(scene.slider, e, p.mu, total, support, p.width)] for e in scene.edges}
