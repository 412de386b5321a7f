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

from mechanics import DeadlineExceeded, PushRegion, StableSteering, point_velocity, stable_region

from ..model.bodies import body_outline
from ..model.segments import Push
from .region_cache import RegionCache, compute_regions, edge_region, is_cached
from ..model.fields import SceneError
from ..model.options import DEFAULT_REGIONS
from ..model.scene import Scene

__all__ = ["EdgeControls", "NoStablePush", "RegionTimeout", "clearance_margin", "controls_or_reason", "edge_controls",
           "step_length"]


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
    outline: np.ndarray  # slider + pusher vertices, slider frame

    def speed(self, twist: ArrayLike) -> np.ndarray:
        """Largest point speed of the body under ``twist`` (attained at an outline vertex)."""
        v = np.asarray(twist, dtype=float)
        return np.linalg.norm(point_velocity(v[..., None, :], self.outline), axis=-1).max(axis=-1)

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
                  cache: RegionCache | None = None, *, regions: str = DEFAULT_REGIONS) -> list[EdgeControls]:
    """An :class:`EdgeControls` for each allowed edge that has stable pushes.

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
    method, rho = regions, scene.cf_uncertainty
    todo = [e for e in scene.edges if not is_cached(slider, e, p.mu, p.width, method, rho, cache)]
    computed = compute_regions(slider, todo, p.mu, p.width, rho, deadline, progress, cache=cache)
    out, pending = [], []
    for e in scene.edges:
        if e in todo and e not in computed:
            pending.append(e)
            continue
        try:  # read from the cache, or computed again if its file turned out unreadable
            region = edge_region(slider, e, p.mu, p.width, method, rho, deadline, cache)
        except DeadlineExceeded:
            pending.append(e)
            continue
        if not region.is_empty:
            out.append(EdgeControls(e, region, StableSteering(region), body_outline(slider, e, p.width, p.depth)))
    if pending:
        raise RegionTimeout(out, tuple(pending))
    if not out:
        raise NoStablePush(scene)
    return out


class NoStablePush(SceneError):
    """No allowed edge of ``scene`` has a stable push. The field blamed is the CF's uncertainty if
    the CF known exactly would leave one (procedure STABLE's region, cheap and inside the exact
    one, has pushes), else the edges."""

    def __init__(self, scene: Scene):
        p = scene.pusher
        if scene.cf_uncertainty > 0 and any(not stable_region(scene.slider, e, p.mu, p.width).is_empty
                                            for e in scene.edges):
            super().__init__("slider.cf_uncertainty", f"is too large: no allowed edge has a push stable for every CF "
                                                      f"within {scene.cf_uncertainty:g} m of the cf, though with the "
                                                      "cf known exactly some have")
        else:
            super().__init__("pusher.edges", "no allowed edge has a stable push (no contact force can pass through "
                                             "the cf)")


def controls_or_reason(scene: Scene, regions: str = DEFAULT_REGIONS) -> tuple[list[EdgeControls] | None, str | None]:
    """``(edge_controls(scene, regions=regions), None)``, or ``(None, why)`` when no allowed edge
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
        return edge_controls(scene, regions=regions), None
    except NoStablePush as err:
        return None, err.problem
