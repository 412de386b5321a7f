"""The pushes available on each edge, scaled for planning.

Each allowed edge with a non-empty stable region becomes an :class:`EdgePush`: its stable region
(procedure STABLE or the exact region, as the scene's ``planner.regions`` says; :mod:`.regions`),
the steering map from the unit control box onto it, and the body outline used to scale twists so
that no point of the slider or pusher moves faster than 1 m/s. With that scale, a push's
``duration`` bounds how far any point travels, which is what the collision rule of
:mod:`planner.validity` needs.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from mechanics import DeadlineExceeded, ExactRegion, StableRegion, StableSteering, point_velocity, stable_region

from .bodies import body_outline
from .regions import compute_regions, edge_region, is_cached
from .scene import Scene, SceneError

__all__ = ["EdgePush", "RegionTimeout", "clearance_margin", "edge_pushes", "resolution"]


def resolution(scene: Scene) -> float:
    """The search's propagation step: the largest distance any body point moves between two
    collision checks (a tenth of the part's radius about its CF)."""
    return scene.slider.radius / 10.0


def clearance_margin(scene: Scene) -> float:
    """The least clearance a whole push must keep (a fortieth of the part's radius): small enough
    to reach goals close to obstacles, large enough that near-tangent passes end quickly."""
    return scene.slider.radius / 40.0


@dataclass(frozen=True)
class EdgePush:
    edge: int
    region: StableRegion | ExactRegion
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


class RegionTimeout(Exception):
    """The deadline passed before every allowed edge's stable region was computed.

    ``pushes`` holds the :class:`EdgePush` of each other edge that has stable pushes (what
    :func:`edge_pushes` would return for those edges alone), ``pending`` the allowed edges not
    computed. Finished regions are cached (:mod:`.regions`), so a later run goes further.
    """

    def __init__(self, pushes: list[EdgePush], pending: tuple[int, ...]):
        self.pushes, self.pending = pushes, pending
        named = ", ".join(map(str, pending[:4])) + (f", ... ({len(pending)} in all)" if len(pending) > 4 else "")
        super().__init__(f"the stable regions of edge{'s' if len(pending) > 1 else ''} {named} were not computed "
                         f"within the time limit ({len(pushes)} edge{'' if len(pushes) == 1 else 's'} with stable "
                         "pushes ready)")


def edge_pushes(scene: Scene, deadline: float | None = None,
                progress: Callable[[int, int], None] | None = None) -> list[EdgePush]:
    """An :class:`EdgePush` for each allowed edge that has stable pushes.

    Parameters
    ----------
    scene : Scene
    deadline : float, optional
        A :func:`time.perf_counter` time by which the regions must be done: edges are begun in
        order, one per core at a time (:func:`~planner.regions.compute_regions`), those running at
        the deadline are abandoned and those not begun are skipped, but cached ones are still read.
    progress : callable, optional
        ``progress(k, n)`` is called before computing the ``k``-th (from 1) of the ``n`` regions
        that are not cached; regions read from the cache are not reported.

    Raises
    ------
    SceneError
        If no allowed edge has any (the friction cone of the contact cannot push through the CF, or
        not for every CF the scene's ``slider.cf_uncertainty`` allows), or if procedure STABLE is
        asked for with an uncertain CF. An edge on which procedure STABLE finds no push has no
        exact region to compute (Proposition 6), so such input fails at once.
    RegionTimeout
        If ``deadline`` passed first; it holds the pushes of the edges done.
    """
    p, slider = scene.pusher, scene.slider
    method, rho = scene.planner.regions, scene.cf_uncertainty
    todo = [e for e in p.edges if not is_cached(slider, e, p.mu, p.width, method, rho)]
    computed = compute_regions(slider, todo, p.mu, p.width, rho, deadline, progress)
    out, pending = [], []
    for e in p.edges:
        if e in todo and e not in computed:
            pending.append(e)
            continue
        try:  # read from the cache, or computed again if its file turned out unreadable
            region = edge_region(slider, e, p.mu, p.width, method, rho, deadline)
        except DeadlineExceeded:
            pending.append(e)
            continue
        if not region.is_empty:
            out.append(EdgePush(e, region, StableSteering(region), body_outline(slider, e, p.width, p.depth)))
    if pending:
        raise RegionTimeout(out, tuple(pending))
    if not out:
        raise _no_stable_push(scene)
    return out


def _no_stable_push(scene: Scene) -> SceneError:
    """Why no allowed edge has a stable push: the CF's uncertainty, if the CF known exactly would
    leave one (procedure STABLE's region, cheap and inside the exact one, has pushes), else the edges."""
    p = scene.pusher
    if scene.cf_uncertainty > 0 and any(not stable_region(scene.slider, e, p.mu, p.width).is_empty for e in p.edges):
        return SceneError("slider.cf_uncertainty", f"is too large: no allowed edge has a push stable for every CF "
                                                   f"within {scene.cf_uncertainty:g} m of the cf, though with the cf "
                                                   "known exactly some have")
    return SceneError("pusher.edges", "no allowed edge has a stable push (no contact force can pass through the cf)")
