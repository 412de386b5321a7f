"""The pushes available on each edge, scaled for planning.

Each allowed edge with a non-empty stable region becomes an :class:`EdgeControls`: its stable region
(procedure STABLE or the exact region, as the ``regions`` option says; :mod:`.region_cache`),
the steering map from the unit control box onto it, and the body outline used to scale twists so
that no point of the slider or pusher moves faster than 1 m/s. With that scale, a push's
``duration`` bounds how far any point travels, which is what the collision rule of
:mod:`planner.world.validity` needs.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from mechanics import DeadlineExceeded, PushRegion, StableSteering, stable_region

from ..model.bodies import body_outline, top_speed
from ..model.segments import Push
from .region_cache import RegionCache, compute_regions, edge_region, is_cached
from ..model.fields import SceneError
from ..model.margin import EXACT, Margin
from ..model.options import DEFAULT_REGIONS
from ..model.scene import Scene

__all__ = ["EdgeControls", "NoStablePush", "RegionTimeout", "certified_for", "clearance_margin", "controls_or_reason",
           "edge_controls", "step_length"]


def step_length(scene: Scene) -> float:
    """The search's propagation step: the largest distance any body point moves between two
    collision checks (a tenth of the part's radius about its CF)."""
    return scene.slider.radius / 10.0


def clearance_margin(scene: Scene) -> float:
    """The least clearance a whole push must keep (a fortieth of the part's radius): small enough
    to reach goals close to obstacles, large enough that near-tangent passes end quickly."""
    return scene.slider.radius / 40.0


@dataclass(frozen=True)
class EdgeControls:
    """What the search may do on one edge: its stable region, the steering map from the unit
    control box onto it, and the outline of the body (slider and pusher) that sets the speed
    scale of its twists."""

    edge: int
    region: PushRegion
    steering: StableSteering
    outline: tuple[np.ndarray, np.ndarray]  # the body's outline, slider frame (planner.model.bodies.body_outline)

    def speed(self, twist: ArrayLike) -> np.ndarray:
        """Largest point speed of the body under ``twist`` (attained at an outline vertex)."""
        return top_speed(self.outline, twist)

    def control_twist(self, u: ArrayLike) -> np.ndarray:
        """The unit-speed stable twist for control ``u`` in ``[0, 1]^2``."""
        v = self.steering.twist(u)
        return v / self.speed(v)[..., None]

    def push(self, start: ArrayLike, twist: ArrayLike, duration: float) -> Push:
        """The push of ``twist`` for ``duration`` from ``start`` on this edge (unchecked)."""
        return Push.along(self.edge, self.region.contact, twist, duration, start)


class RegionTimeout(Exception):
    """The deadline passed before every allowed edge's stable region was computed.

    ``controls`` holds the :class:`EdgeControls` of each other edge that has stable pushes (what
    :func:`edge_controls` would return for those edges alone), ``pending`` the allowed edges not
    computed. Finished regions are cached (:mod:`.region_cache`), so a later run goes further.
    """

    def __init__(self, controls: list[EdgeControls], pending: tuple[int, ...]):
        self.controls, self.pending = controls, pending
        named = ", ".join(map(str, pending[:4])) + (f", ... ({len(pending)} in all)" if len(pending) > 4 else "")
        super().__init__(f"the stable regions of edge{'s' if len(pending) > 1 else ''} {named} were not computed "
                         f"within the time limit ({len(controls)} edge{'' if len(controls) == 1 else 's'} with stable "
                         "pushes ready)")


def edge_controls(scene: Scene, deadline: float | None = None, progress: Callable[[int, int], None] | None = None,
                  cache: RegionCache | None = None, *, regions: str = DEFAULT_REGIONS,
                  margin: Margin = EXACT) -> list[EdgeControls]:
    """An :class:`EdgeControls` for each allowed edge that has stable pushes, stable with
    ``margin`` to spare (:func:`certified_for`).

    Parameters
    ----------
    scene : Scene
    deadline : float, optional
        A :func:`time.perf_counter` time by which the regions must be done: edges are begun in
        order, one per core at a time (:func:`~planner.actions.region_cache.compute_regions`), those running at
        the deadline are abandoned and those not begun are skipped, but cached ones are still read.
    progress : callable, optional
        ``progress(k, n)`` is called before computing the ``k``-th (from 1) of the ``n`` regions
        that are not cached; regions read from the cache are not reported.
    cache : RegionCache, optional
        Where the exact regions are kept and what computes them
        (default: :func:`~planner.actions.region_cache.default_cache`).
    regions : str
        The ``regions`` option: ``'exact'`` (the default) or ``'stable'`` (procedure STABLE).

    Raises
    ------
    NoStablePush
        If no allowed edge has any (the friction cone of the contact cannot push through the CF, or
        not for every CF the scene's ``slider.cf_uncertainty`` allows). An edge on which procedure
        STABLE finds no push has no exact region to compute (Proposition 6), so such input fails
        at once.
    SceneError
        If procedure STABLE is asked for with an uncertain CF.
    RegionTimeout
        If ``deadline`` passed first; it holds the pushes of the edges done.
    """
    p, slider = scene.pusher, scene.slider
    method, (mu, rho) = regions, certified_for(scene, margin, regions)
    todo = [e for e in scene.edges if not is_cached(slider, e, mu, p.width, method, rho, cache)]
    computed = compute_regions(slider, todo, mu, p.width, rho, deadline, progress, cache=cache)
    out, pending, uncomputed = [], [], set(todo) - set(computed)
    for e in scene.edges:
        if e in uncomputed:
            pending.append(e)
            continue
        try:  # read from the cache, or computed again if its file turned out unreadable
            region = edge_region(slider, e, mu, p.width, method, rho, deadline, cache)
        except DeadlineExceeded:
            pending.append(e)
            continue
        if not region.is_empty:
            out.append(EdgeControls(e, region, StableSteering(region), body_outline(slider, e, p.width, p.depth)))
    if pending:
        raise RegionTimeout(out, tuple(pending))
    if not out:
        raise NoStablePush(scene, margin, regions)
    return out


def certified_for(scene: Scene, margin: Margin, regions: str = DEFAULT_REGIONS) -> tuple[float, float]:
    """The friction and the CF disk's radius that the pushes of ``scene``'s part are certified
    for with ``margin`` (:mod:`planner.model.margin`). Procedure STABLE knows one CF only, so with
    ``regions='stable'`` the margin's CF disk is left out (its friction is kept).

    >>> from planner import load_scene
    >>> scene = load_scene("scenes/battery.yaml")
    >>> certified_for(scene, EXACT) == (scene.pusher.mu, 0.0)
    True
    >>> mu, rho = certified_for(scene, Margin(0.1, 0.02))  # 2 % of the part's 28 mm is less than the 1 mm floor
    >>> round(mu / scene.pusher.mu, 12), round(rho, 12), round(scene.slider.radius, 4)
    (0.9, 0.001, 0.0276)
    """
    p = scene.pusher
    applied = margin if regions == "exact" else Margin(margin.mu, 0.0)
    return applied.friction(p.mu, p.mu_high), applied.cf_radius(scene.slider.radius, scene.cf_uncertainty)


class NoStablePush(SceneError):
    """No allowed edge of ``scene`` has a stable push with ``margin``. The field blamed is the
    margin if the exact limit would leave one, the CF's uncertainty if the CF known exactly would
    (procedure STABLE's region, cheap and inside the exact one, has pushes), else the edges."""

    def __init__(self, scene: Scene, margin: Margin = EXACT, regions: str = DEFAULT_REGIONS):
        p = scene.pusher
        mu, rho = certified_for(scene, margin, regions)
        some = any(not stable_region(scene.slider, e, p.mu, p.width).is_empty for e in scene.edges)
        if (mu, rho) != certified_for(scene, EXACT, regions) and some and scene.cf_uncertainty == 0:
            super().__init__("planner.margin", f"no allowed edge has a push stable with the margin ({margin}: "
                                               f"friction {mu:.4g}, CF within {rho * 1e3:.3g} mm), though at the "
                                               "exact limit (margin 0) some have")
        elif scene.cf_uncertainty > 0 and some:
            super().__init__("slider.cf_uncertainty", f"is too large: no allowed edge has a push stable for every CF "
                                                      f"within {scene.cf_uncertainty:g} m of the cf, though with the "
                                                      "cf known exactly some have")
        else:
            super().__init__("pusher.edges", "no allowed edge has a stable push (no contact force can pass through "
                                             "the cf)")


def controls_or_reason(scene: Scene, regions: str = DEFAULT_REGIONS,
                       margin: Margin = EXACT) -> tuple[list[EdgeControls] | None, str | None]:
    """``(edge_controls(scene, regions=regions, margin=margin), None)``, or ``(None, why)`` when no allowed edge
    has a stable push (the problem of the :class:`NoStablePush` it raised); other errors pass
    through.

    A CF beyond the end of edge 0, which no force in the contact's friction cone passes through:

    >>> from planner.model.scene_file import parse_scene
    >>> scene = parse_scene({"slider": {"vertices": [[-0.1, 0], [0.05, 0], [0.1, 0], [0.1, 0.1], [-0.1, 0.1]],
    ...                                 "cf": [0.08, 0.05]},
    ...     "pusher": {"width": 0.01, "depth": 0.01, "mu": 0.5, "edges": [0]},
    ...     "workspace": {"min": [-1, -1], "max": [1, 1]}, "start": [0, 0, 0], "goal": [0.5, 0, 0]})
    >>> controls_or_reason(scene)
    (None, 'no allowed edge has a stable push (no contact force can pass through the cf)')
    """
    try:
        return edge_controls(scene, regions=regions, margin=margin), None
    except NoStablePush as err:
        return None, err.problem
