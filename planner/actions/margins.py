"""Each push's own stability margin, and whether a plan's pushes keep the margin it was planned with.

A plan is planned to keep a :class:`~planner.model.margin.Margin` (the regions are those of the
friction and the CF disk it certifies, :func:`~planner.actions.controls.certified_for`). How much
each push keeps is its own: a push deep inside its region may hold for a friction half the
scene's, one near the boundary for the margin and little more. :func:`with_margins` certifies,
push by push, how much lower the friction may be (the CF as the scene states it) and how far the
CF may move (the friction as the scene states it) before the push may slip
(:func:`mechanics.push_margins`: certified lower bounds, not estimates), and :func:`keeps` says
whether each push lies in the regions of the margin its plan claims.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from mechanics import push_margins

from ..model.margin import EXACT, Margin, PushMargin, nominal_friction
from ..model.plan import Plan
from ..model.scene import Scene
from ..model.segments import Push
from .controls import certified_for
from .region_cache import edge_region

__all__ = ["keeps", "smallest", "with_margins"]


def _pushes(plan: Plan) -> list[tuple[str, Push]]:
    """``(part, push)`` for each push of the plan, in step order."""
    return [(part, s) for part, s in plan.steps if isinstance(s, Push)]


def _alone(scene: Scene, plan: Plan) -> dict[str, Scene]:
    """Each part's scene of its own (the stable regions are a part's, whatever stands about it)."""
    return {name: scene.move_scene(name, plan.starts, others=False) for name in plan.names}


def with_margins(scene: Scene, plan: Plan) -> Plan:
    """``plan`` with :attr:`~planner.model.plan.Plan.margins`: each push's own margin, certified
    against ``scene``'s friction and CFs (module docstring). The friction margin is a fraction of
    the scene's friction (the middle of an interval), found with the CF anywhere in the disk the
    plan's margin certifies (the part's ``cf_uncertainty`` for a plan without one); the CF margin
    is in metres, at the scene's friction.

    >>> from planner import load_scene, plan
    >>> scene = load_scene("scenes/battery.yaml")
    >>> [m] = with_margins(scene, plan(scene, seed=1)).margins
    >>> m.mu >= 0.1, m.cf >= 0.02 * scene.slider.radius
    (True, True)
    """
    if not plan.solved:
        return plan
    p, alone = scene.pusher, _alone(scene, plan)
    nominal = nominal_friction(p.mu, p.mu_high)
    pushes = _pushes(plan)
    found: list[PushMargin | None] = [None] * len(pushes)
    groups: dict[tuple[str, int], list[tuple[int, Push]]] = {}
    for k, (part, s) in enumerate(pushes):
        groups.setdefault((part, s.edge), []).append((k, s))
    for (name, edge), items in groups.items():
        one = alone[name]
        # The friction margin is found with the CF disk the plan was made for; that disk and that
        # friction are rungs of the searches, so a push certified for them says so exactly, not to
        # the ladders' step below.
        mu, rho = certified_for(one, plan.margin or EXACT)
        twists = np.array([s.twist for _, s in items])
        got = push_margins(one.slider, edge, twists, p.mu, p.width, cf_radius=rho, mu_rung=mu)
        for (k, _), low, radius in zip(items, got.mu_low, got.cf_radius):
            # Rounded: a friction certified at exactly 90 % of the scene's is a 10 % margin, not 9.99...
            found[k] = PushMargin(max(0.0, round(1.0 - float(low) / nominal, 12)) if np.isfinite(low) else 0.0,
                                  float(radius) if np.isfinite(radius) else 0.0)
    return replace(plan, margins=tuple(found))


def smallest(plan: Plan) -> PushMargin | None:
    """The smallest friction and CF margins over the plan's pushes (each on its own), or None
    without margins."""
    if not plan.margins:
        return None
    return PushMargin(min(m.mu for m in plan.margins), min(m.cf for m in plan.margins))


def keeps(scene: Scene, plan: Plan, margin: Margin, regions: str = "exact") -> list[bool]:
    """For each push of ``plan`` in step order, whether it lies in its edge's stable region of
    ``margin`` (the regions a plan with that margin is planned in; computed, or read from the cache)."""
    out, alone = [], _alone(scene, plan)
    for name, s in _pushes(plan):
        one = alone[name]
        mu, rho = certified_for(one, margin, regions)
        region = edge_region(one.slider, s.edge, mu, scene.pusher.width, regions, rho)
        out.append(bool(region.contains(s.twist)))
    return out
