"""Can the part get to a goal at all? Certified answers: reachable (with a plan), unreachable
(with the certificate's reason) or unknown (the search ran out of time or of pushes).

Certificates of unreachability, run before any search. Each is *sufficient* for unreachability
and none is complete (a goal none of them catches may still be unreachable, and then the search
answers ``'unknown'``). A plan ends anywhere within the scene's tolerance of the goal
(``tolerance.position`` for the pose's origin, ``tolerance.angle``), so a point ``p`` of the part
(slider frame) may end up to ``tolerance.position + |p| tolerance.angle`` from where it is at the
goal; every certificate allows that much, which keeps it sound:

1. *collision*: the part at the goal reaches further into an obstacle or beyond the workspace
   than the tolerance can undo;
2. *no pusher room*: for every allowed edge, the part with the pusher on that edge does so. Every
   plan ends with the pusher in contact on an edge (after its last push, or a transit to another
   edge), its body at least the push margin clear of everything;
3. *component*: the part always contains its largest inscribed disk, so that disk's centre
   travels in the workspace shrunk by its radius, outside the obstacles grown by it; the goal's
   centre is not within the tolerance of the connected piece of that region holding the start's.
   The radius is taken a millionth smaller, so a gap exactly as wide as the disk stays open;
4. *no stable push*: no allowed edge has a stable push, and the start is not within tolerance of
   the goal (this one needs the stable regions; 1-3 need only geometry).

A start within tolerance of the goal is reachable by no push at all, and no certificate fires.

>>> from planner import load_scene
>>> scene = load_scene("scenes/unreachable/sealed.yaml")
>>> certify_unreachable(scene, regions=False).split(":")[0]
'component'
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property
from typing import TYPE_CHECKING

import numpy as np
import shapely
from numpy.typing import ArrayLike

from mechanics import wrap_angle

from ..model.bodies import pusher_polygon, slider_at, transform_points
from .one_step import goal_verdicts
from ..model.plan_file import Plan
from ..actions.controls import controls_or_reason
from ..model.fields import SceneError
from ..model.scene import Scene
from ..search import plan_batch
from ..world.free_space import ROUNDING_SHRINK, cover, disk_free_space
from ..world.validity import CollisionModel

if TYPE_CHECKING:
    from .controllability import SceneControllability

__all__ = ["Reach", "certify_unreachable", "reachability"]


@dataclass(frozen=True)
class Reach:
    """The answer for one goal.

    ``status`` is ``'reachable'`` (``plan`` reaches the goal; ``pushes`` is its number of
    pushes, 1 when one push does), ``'unreachable'`` (``reason`` names the certificate) or
    ``'unknown'`` (``reason`` says what ran out). ``verdicts`` (the one-step Goal1/2/3 label per
    allowed edge, :func:`planner.queries.one_step.goal_verdicts`) and ``controllability`` (the scene's,
    :func:`planner.controllability`) are computed when first read: each costs about 0.1 s, as
    much as finding most plans.
    """

    status: str
    plan: Plan | None
    reason: str
    pushes: int | None
    scene: Scene = field(repr=False, compare=False)
    goal: np.ndarray = field(repr=False, compare=False)

    @cached_property
    def verdicts(self) -> dict[int, str]:
        return goal_verdicts(self.scene, self.scene.start, self.goal)

    @cached_property
    def controllability(self) -> SceneControllability:
        """What the scene's edges can do anywhere on an empty table (Lynch & Mason 1996, Props
        1-4): why an 'unknown' answer may still be reachable, or why a part goes nowhere.

        >>> from planner import load_scene
        >>> [answer] = reachability(load_scene("scenes/battery.yaml"))
        >>> answer.controllability.summary().split(";")[0]
        'controllable (edge 3)'
        """
        from .controllability import controllability  # its scipy is not needed for the answer

        return controllability(self.scene)


class _Certificates:
    """The geometric certificates 1-3 for one scene, its free space computed once for many goals."""

    def __init__(self, scene: Scene):
        self.scene = scene
        self.free = shapely.box(*scene.workspace).difference(shapely.union_all(scene.obstacles))
        self._grown: dict[float, shapely.Geometry] = {}
        circle = shapely.maximum_inscribed_circle(scene.slider.polygon)
        self.centre, self.radius = np.asarray(circle.coords[0]), circle.length
        # It contains the true free space of the disk (inscribed round corners), so it is only more
        # connected than the true one: sound.
        disk_free = disk_free_space(scene, self.radius * (1.0 - ROUNDING_SHRINK))
        self.pieces = list(getattr(disk_free, "geoms", [disk_free]))

    def _slack(self, points: ArrayLike) -> float:
        """How far any of these slider-frame points may end from where it is at the goal."""
        return self.scene.tolerance_slack(float(np.linalg.norm(np.asarray(points, dtype=float), axis=-1).max()))

    def _stuck(self, body: shapely.Polygon, slack: float) -> bool:
        """True if some point of ``body`` (world) is further than ``slack`` from the free space."""
        if slack not in self._grown:
            self._grown[slack] = cover(self.free, slack)
        return not body.within(self._grown[slack])

    def __call__(self, goal: np.ndarray) -> str | None:
        scene = self.scene
        if scene.within_tolerance(scene.start, goal):
            return None
        part = scene.slider.polygon
        if self._stuck(slider_at(part, goal), self._slack(scene.slider.vertices)):
            return "collision: the part at the goal overlaps an obstacle or leaves the workspace"
        p = scene.pusher
        bodies = [part.union(pusher_polygon(scene.slider, e, p.width, p.depth)) for e in p.edges]
        # A union can come out as two polygons that touch along the face: place it as a geometry.
        if all(self._stuck(shapely.transform(b, lambda xy: transform_points(xy, goal)),
                           self._slack(shapely.get_coordinates(b))) for b in bodies):
            return "no pusher room: no allowed edge has room for the pusher at the goal, where the last push ends"
        start_c, goal_c = (shapely.Point(transform_points([self.centre], pose)[0]) for pose in (scene.start, goal))
        near = [piece for piece in self.pieces if piece.distance(start_c) <= 1e-12]
        if near and near[0].distance(goal_c) > self._slack([self.centre]) * (1 + 1e-9):
            return (f"component: the goal is cut off from the start for the part's inscribed disk "
                    f"(radius {self.radius:.4g} m)")
        return None


def certify_unreachable(scene: Scene, goal: ArrayLike | None = None, *, regions: bool = True) -> str | None:
    """The reason ``goal`` (default: the scene's, radians) is certainly unreachable from the
    scene's start, or None if no certificate shows it (see the module's list). With
    ``regions=False`` certificate 4, the only one needing the stable regions, is skipped.

    >>> from planner import load_scene
    >>> scene = load_scene("scenes/parking.yaml")
    >>> certify_unreachable(scene) is None
    True
    >>> certify_unreachable(scene, [0.30, -0.15, 0.0])  # inside the box in the way
    'collision: the part at the goal overlaps an obstacle or leaves the workspace'
    """
    goal = _goal(scene.goal if goal is None else goal)
    reason = _Certificates(scene)(goal)
    if reason is None and regions and not scene.within_tolerance(scene.start, goal):
        reason = _no_stable_push_reason(controls_or_reason(scene)[1])
    return reason


def _no_stable_push_reason(why: str | None) -> str | None:
    """Certificate 4's reason, given why no edge has a stable push (None: some edge has one)."""
    return None if why is None else f"no stable push: {why}"


def _goal(pose: ArrayLike) -> np.ndarray:
    g = np.array(pose, dtype=float)
    g[2] = wrap_angle(g[2])
    return g


def reachability(scene: Scene, goals: ArrayLike | None = None, *, pushes: int | None = None,
                 time_limit: float | None = None, seed: int | None = None) -> list[Reach]:
    """One :class:`Reach` per goal (rows ``(x, y, theta)``, radians; default: the scene's goal).

    Each goal gets the certificates; the goals left get :func:`planner.search.plan_batch`: first
    the one- and two-push connection from the start (so one stable push, when there is one, gives
    a 1-push plan), then one search tree grown towards all of them at once, for at most
    ``time_limit`` seconds in all (default: the scene's), seeded by ``seed`` (default: the
    scene's). ``pushes`` is a budget: a plan with more pushes is answered ``'unknown'``. The goals
    share the stable regions (computed in full first, and cached per part), the collision model,
    the free-space geometry and the search tree, so a batch costs far less than a :func:`plan`
    per goal (``python -m planner.bench.reach`` measures it).

    >>> from planner import load_scene
    >>> scene = load_scene("scenes/battery.yaml")
    >>> [(r.status, r.pushes) for r in reachability(scene, [scene.goal, [9.0, 9.0, 0.0]])]
    [('reachable', 1), ('unreachable', None)]

    Raises
    ------
    SceneError
        If ``goals`` is not a list of poses, or as :func:`planner.plan` does.
    """
    rows = np.atleast_2d(np.asarray(scene.goal if goals is None else goals, dtype=float))
    if rows.ndim != 2 or rows.shape[1] != 3 or not np.all(np.isfinite(rows)):
        raise SceneError("goals", f"must be finite (x, y, theta) rows, got an array of shape {rows.shape}")
    certificates = _Certificates(scene)
    edge_set, why = controls_or_reason(scene)
    no_push = _no_stable_push_reason(why)
    goals = [_goal(row) for row in rows]
    reasons = [certificates(goal) or (no_push if not scene.within_tolerance(scene.start, goal) else None)
               for goal in goals]
    open_goals = [i for i, reason in enumerate(reasons) if reason is None]
    plans: dict[int, Plan] = {}
    if edge_set is None:  # every open goal is the start, and nothing can be pushed: no push needed
        plans = {i: Plan(scene.path, True, scene.planner.name, scene.planner.seed if seed is None else seed, 0.0,
                         scene.start.copy(), goals[i]) for i in open_goals}
    elif open_goals:
        model = CollisionModel(scene, scene.pusher.edges)
        found = plan_batch(scene, [goals[i] for i in open_goals], seed=seed, time_limit=time_limit,
                           prebuilt=(edge_set, model))
        plans = dict(zip(open_goals, found))
    answers = []
    for i, goal in enumerate(goals):
        found = plans.get(i)
        if found is None:
            answers.append(Reach("unreachable", None, reasons[i], None, scene, goal))
        elif not found.solved:
            answers.append(Reach("unknown", found, found.reason, None, scene, goal))
        elif pushes is not None and found.pushes > pushes:
            answers.append(Reach("unknown", found, f"the plan found has {found.pushes} pushes, more than the budget "
                                                   f"of {pushes}", found.pushes, scene, goal))
        else:
            answers.append(Reach("reachable", found, "", found.pushes, scene, goal))
    return answers
