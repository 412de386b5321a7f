"""Joining a new start to plans found before (:func:`join`): a re-plan in milliseconds.

A robot re-planning from where the part really is, near a plan it already has for the same goal,
needs no new search: one or two stable pushes (and a switch where the edges differ) onto a pose
along that plan, then the rest of it. :func:`join` tries the poses along the latest plans (each
push's start and points part way along it, :data:`ALONG`) cheapest first by a lower bound, and
keeps the cheapest join found.
"""

from __future__ import annotations

import numpy as np

from mechanics import exp_twist, transform_points

from ..model.plan import Plan
from ..model.segments import Push, Transit, rechain
from .context import PlanningContext, SearchWorld, cost

__all__ = ["ALONG", "JOINED_PLANS", "JOIN_SLACK", "join"]

#: How many of the latest plans for a goal a new start is joined to.
JOINED_PLANS = 2
#: A join is taken once no pose left could make one cheaper by more than this share: the lower
#: bound (the straight line) is loose, and each pose tried costs collision checks.
JOIN_SLACK = 0.05
#: Poses along a plan that a new start may be joined to: each push's start and these fractions of it.
ALONG = (0.0, 0.25, 0.5, 0.75)


def join(world: SearchWorld, context: PlanningContext, goal: np.ndarray, known: list[Plan]) -> Plan | None:
    """A plan from ``context.start`` joined by one or two pushes (and a switch where the edges
    differ) to a pose along one of the :data:`JOINED_PLANS` latest ``known`` plans for
    ``goal``, the rest of that plan after it: the cheapest found, or None.

    Poses are tried cheapest first by a lower bound (the straight line from the start's CF to
    theirs, plus the rest of their plan), until no pose left can beat the best join by more
    than :data:`JOIN_SLACK`."""
    scene, switch_cost = world.scene, world.options.switch_cost
    anchors = [a for p in known[:JOINED_PLANS] for a in _anchors(p.segments)]
    if not anchors:
        return None
    region = world.goal_region([pose for pose, _, _ in anchors], aim=False)
    cf = scene.slider.cf
    here, there = transform_points(cf, context.start), transform_points(cf, np.array([a[0] for a in anchors]))
    bounds = np.linalg.norm(there - here, axis=1) + [cost(scene, rest, switch_cost) for _, _, rest in anchors]
    best, best_cost = None, np.inf
    for a in np.argsort(bounds, kind="stable").tolist():
        if bounds[a] * (1.0 + JOIN_SLACK) >= best_cost:
            break
        pose, edge, rest = anchors[a]
        for k in context.starts:
            lead = region.pushes_to(context.start, k, [a]).get(a)
            if lead is None:
                continue
            joint: list[Push | Transit] = list(lead)
            if edge != world.controls[k].edge:
                transit = world.transits.find(pose, world.controls[k].edge, edge) if world.transits else None
                if transit is None:
                    continue
                joint.append(transit)
            candidate = rechain(joint + rest)
            if (c := cost(scene, candidate, switch_cost)) < best_cost:
                best, best_cost = candidate, c
    if best is None:
        return None
    return context.result(goal, world.shortcut_cheaply(best))


def _anchors(segments: list[Push | Transit]) -> list[tuple[np.ndarray, int, list[Push | Transit]]]:
    """Poses along a plan that a new start may join: per push, its start and points along it
    (:data:`ALONG`), each with the push's edge and the plan's segments from there on."""
    out = []
    for i, s in enumerate(segments):
        if not isinstance(s, Push):
            continue
        for f in ALONG:
            if f == 0.0:
                out.append((s.start, s.edge, segments[i:]))
            else:
                pose = exp_twist(s.start, s.twist, f * s.duration)
                rest = Push.along(s.edge, s.contact, s.twist, (1.0 - f) * s.duration, pose)
                out.append((rest.start, s.edge, [rest, *segments[i + 1:]]))
    return out
