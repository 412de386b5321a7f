"""Can the part get to a goal at all? Certified answers: reachable (with a plan), unreachable
(with the certificate's reason) or unknown (the search ran out of time or of pushes).

Certificates of unreachability, run before any search. Each is *sufficient* for unreachability
and none is complete (a goal none of them catches may still be unreachable, and then the search
answers ``'unknown'``). A plan ends anywhere within the scene's tolerance of the goal
(``tolerance.position`` for the pose's origin, ``tolerance.angle``), so a point ``p`` of the part
(slider frame) may end up to ``tolerance.position + |p| tolerance.angle`` from where it is at the
goal; every certificate allows that much, which keeps it sound:

1. *collision*: no pose within tolerance of the goal has the part clear of the obstacles and
   inside the workspace by the push margin (every push keeps it all the way, the last one too:
   :func:`~planner.actions.controls.clearance_margin`). Shown at the goal's heading with the part shrunk by the most a turn
   within ``tolerance.angle`` moves its points (what is left lies inside the part however it is
   turned), by its configuration-space obstacles (:class:`~planner.world.room.Room`): no position
   within ``tolerance.position`` is free of them. Exact for thin walls, which a part may overlap
   by more than the tolerance on both sides;
2. *no pusher room*: for every allowed edge, the part with the pusher on that edge is so
   blocked. Every plan ends its last push with the pusher in contact on its edge, the body the
   push margin clear of everything;
3. *component*: the part always contains its largest inscribed disk, so that disk's centre
   travels in the workspace shrunk by its radius, outside the obstacles grown by it; the goal's
   centre is not within the tolerance of the connected piece of that region holding the start's.
   The radius is taken a millionth smaller, so a gap exactly as wide as the disk stays open;
4. *no stable push*: no allowed edge has a stable push, and the start is not within tolerance of
   the goal (this one needs the stable regions; 1-3 and 5 need only geometry);
5. *out of reach* (a scene with a ``robot:``): at every pose within tolerance of the goal, the
   pusher flush on any allowed edge would put the arm's flange farther from its shoulder than
   the arm's links reach end to end (:func:`planner.arm.arms.beyond_reach`). The last push ends
   with the arm holding the pusher there.

A start within tolerance of the goal is reachable by no push at all, and no certificate fires.

>>> from planner import load_scene
>>> scene = load_scene("scenes/unreachable/sealed.yaml")
>>> certify_unreachable(scene, regions=False).split(":")[0]
'component'
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import cached_property
from typing import TYPE_CHECKING

import numpy as np
import shapely
from numpy.typing import ArrayLike

from mechanics import transform_points
from .one_step import goal_verdicts
from ..model.plan import Plan
from ..model.segments import Push, Transit
from ..actions.controls import clearance_margin, controls_or_reason
from ..arm.arms import beyond_reach
from ..model.fields import poses
from ..model.options import PlannerOptions
from ..model.scene import Scene
from ..search import PlanningContext, solve_many
from ..world.free_space import ROUNDING_SHRINK, disk_free_space
from ..world.validity import CollisionModel

if TYPE_CHECKING:
    from .controllability import SceneControllability

__all__ = ["Certificates", "Reach", "answers", "certify_unreachable"]


@dataclass(frozen=True)
class Reach:
    """The answer for one goal.

    ``status`` is ``'reachable'`` (``plan`` reaches the goal; ``pushes`` is its number of
    pushes, 1 when one push does), ``'unreachable'`` (``reason`` names the certificate) or
    ``'unknown'`` (``reason`` says what ran out). ``verdicts`` (the one-step Goal1/2/3 label per
    allowed edge, :func:`planner.queries.one_step.goal_verdicts`) and ``controllability`` (the scene's
    with the ``options`` it was asked with, :func:`planner.controllability`) are computed when first
    read: each costs about 0.1 s, as much as finding most plans.
    """

    status: str
    plan: Plan | None
    reason: str
    pushes: int | None
    scene: Scene = field(repr=False, compare=False)
    goal: np.ndarray = field(repr=False, compare=False)
    options: PlannerOptions = field(repr=False, compare=False)  # the session's

    @cached_property
    def verdicts(self) -> dict[int, str]:
        return goal_verdicts(self.scene, self.scene.start, self.goal)

    @cached_property
    def controllability(self) -> SceneControllability:
        """What the scene's edges can do anywhere on an empty table (Lynch & Mason 1996, Props
        1-4): why an 'unknown' answer may still be reachable, or why a part goes nowhere.

        >>> from planner import load_scene, reachability
        >>> [answer] = reachability(load_scene("scenes/battery.yaml"))
        >>> answer.controllability.summary().split(";")[0]
        'controllable (edge 3)'
        """
        from .controllability import controllability  # its scipy is not needed for the answer

        return controllability(self.scene, regions=self.options.regions, transit=self.options.transit,
                               margin=self.options.margin)


class Certificates:
    """The geometric certificates 1-3 for one scene, its free space computed once for many goals
    (and starts)."""

    def __init__(self, scene: Scene, model: CollisionModel | None = None):
        self.scene = scene
        self.model = model or CollisionModel(scene, scene.edges)
        self.margin = clearance_margin(scene)
        circle = shapely.maximum_inscribed_circle(scene.slider.polygon)
        self.centre, self.radius = np.asarray(circle.coords[0]), circle.length
        # It contains the true free space of the disk (inscribed round corners), so it is only more
        # connected than the true one: sound.
        disk_free = disk_free_space(scene, self.radius * (1.0 - ROUNDING_SHRINK))
        self.pieces = list(getattr(disk_free, "geoms", [disk_free]))

    def _blocked(self, body: list[np.ndarray], goal: np.ndarray) -> bool:
        """Whether ``body`` (convex pieces, slider frame) has no room at any pose within tolerance
        of ``goal`` (:meth:`~planner.world.room.Room.blocked`)."""
        scene = self.scene
        return self.model.room.blocked(body, goal, scene.tolerance_position, scene.tolerance_angle, self.margin)

    def __call__(self, goal: np.ndarray, start: np.ndarray | None = None) -> str | None:
        """Why ``goal`` is certainly unreachable from ``start`` (default: the scene's), or None."""
        scene, model = self.scene, self.model
        start = scene.start if start is None else start
        if scene.within_tolerance(start, goal):
            return None
        if scene.robot is not None:
            far = float(np.linalg.norm(scene.slider.vertices, axis=1).max())  # no face middle is farther out
            if (short := beyond_reach(scene, scene.part().name, goal, scene.tolerance_slack(far))) > 0:
                return (f"out of reach: the {scene.robot.model} cannot hold the pusher on any allowed edge at the goal "
                        f"(the nearest is {short * 1000:.0f} mm beyond the reach of its links)")
        edges = scene.edges
        if not any(model.is_clear(goal, e, self.margin) for e in edges):  # else the goal itself has room
            room = f"with the push margin of {self.margin * 1000:.3g} mm"
            if self._blocked(model.part_pieces, goal):
                return f"collision: the part at the goal overlaps an obstacle or leaves the workspace ({room})"
            if all(self._blocked(model.body_pieces(e), goal) for e in edges):
                return (f"no pusher room: no allowed edge has room for the pusher at the goal, where the last push "
                        f"ends ({room})")
        start_c, goal_c = (shapely.Point(transform_points([self.centre], pose)[0]) for pose in (start, goal))
        near = [piece for piece in self.pieces if piece.distance(start_c) <= 1e-12]
        if near and near[0].distance(goal_c) > scene.tolerance_slack(float(np.linalg.norm(self.centre))) * (1 + 1e-9):
            return (f"component: the goal is cut off from the start for the part's inscribed disk "
                    f"(radius {self.radius:.4g} m)")
        return None


def certify_unreachable(scene: Scene, goal: ArrayLike | None = None, *, regions: bool = True) -> str | None:
    """The reason ``goal`` (default: the scene's, radians) is certainly unreachable from the
    scene's start, or None if no certificate shows it (see the module's list). With
    ``regions=False`` certificate 4, the only one needing the stable regions, is skipped. It is
    decided on the exact regions whatever the ``regions`` option: they are empty exactly where
    procedure STABLE's are (Prop. 6).

    >>> from planner import load_scene
    >>> scene = load_scene("scenes/parking.yaml")
    >>> certify_unreachable(scene) is None
    True
    >>> certify_unreachable(scene, [0.30, -0.15, 0.0]).split(" (")[0]  # inside the box in the way
    'collision: the part at the goal overlaps an obstacle or leaves the workspace'
    """
    scene.one_part("certify_unreachable")
    goal = scene.goal if goal is None else poses(goal, "goal")[0]
    reason = Certificates(scene)(goal)
    if reason is None and regions and not scene.within_tolerance(scene.start, goal):
        reason = _no_stable_push_reason(controls_or_reason(scene)[1])
    return reason


def _no_stable_push_reason(why: str | None) -> str | None:
    """Certificate 4's reason, given why no edge has a stable push (None: some edge has one)."""
    return None if why is None else f"no stable push: {why}"


def answers(scene: Scene, options: PlannerOptions, context: PlanningContext | None, reasons: list[str | None],
            goals: np.ndarray, pushes: int | None = None, timings: dict[str, float] | None = None,
            known: Mapping[tuple[float, ...], list[Push | Transit]] | None = None) -> list[Reach]:
    """One :class:`Reach` per goal (rows ``(x, y, theta)``, radians) from ``scene.start`` (the
    context's), given each goal's certificate (``reasons``, None where none fired), for a session
    with ``options``.

    The goals left get :func:`~planner.search.planning.solve_many`: first the one- and two-push
    connection from the start (so one stable push, when there is one, gives a 1-push plan), then
    one search tree grown towards all of them at once until the context's deadline. Their plans
    are as found, not shortened: they reach their goals and verify, and
    :meth:`planner.Planner.plan` gives a short one. ``pushes`` is a budget: a plan with more
    pushes is answered ``'unknown'``. Without a ``context`` (no edge has a stable push) every
    open goal is the start, reached by no push at all. ``timings`` and ``known`` as
    :func:`~planner.search.planning.solve_many`'s.
    """
    open_goals = [i for i, reason in enumerate(reasons) if reason is None]
    plans: dict[int, Plan] = {}
    if context is None:
        plans = {i: Plan.of_part(scene.part().name, scene.start, goals[i], [], scene=scene.path, solved=True,
                                 planner=options.name, seed=options.seed, planning_time_s=0.0)
                 for i in open_goals}
    elif open_goals:
        plans = dict(zip(open_goals, solve_many(context, goals[open_goals], shorten=False, timings=timings,
                                                          known=known)))
    out = []
    for i, goal in enumerate(goals):
        found = plans.get(i)
        if found is None:
            out.append(Reach("unreachable", None, reasons[i], None, scene, goal, options))
        elif not found.solved:
            out.append(Reach("unknown", found, found.reason, None, scene, goal, options))
        elif pushes is not None and found.pushes > pushes:
            out.append(Reach("unknown", found, f"the plan found has {found.pushes} pushes, more than the budget "
                                               f"of {pushes}", found.pushes, scene, goal, options))
        else:
            out.append(Reach("reachable", found, "", found.pushes, scene, goal, options))
    return out
