"""The pushes available on each edge, scaled for planning.

Each allowed edge with a non-empty stable region becomes an :class:`EdgePush`: its stable region
(procedure STABLE or the exact region, as the scene's ``planner.regions`` says; :mod:`.regions`),
the steering map from the unit control box onto it, and the body outline used to scale twists so
that no point of the slider or pusher moves faster than 1 m/s. With that scale, a push's
``duration`` bounds how far any point travels, which is what the collision rule of
:mod:`planner.validity` needs.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from mechanics import ExactRegion, StableRegion, StableSteering, point_velocity

from .bodies import body_outline
from .regions import edge_region
from .scene import Scene, SceneError

__all__ = ["EdgePush", "clearance_margin", "edge_pushes", "resolution"]


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


def edge_pushes(scene: Scene) -> list[EdgePush]:
    """An :class:`EdgePush` for each allowed edge that has stable pushes.

    Raises
    ------
    SceneError
        If no allowed edge has any (the friction cone of the contact cannot push through the CF), or
        if procedure STABLE is asked for with an uncertain CF.
    """
    p = scene.pusher
    out = []
    for e in p.edges:
        region = edge_region(scene.slider, e, p.mu, p.width, scene.planner.regions, scene.cf_uncertainty)
        if not region.is_empty:
            out.append(EdgePush(e, region, StableSteering(region), body_outline(scene.slider, e, p.width, p.depth)))
    if not out:
        raise SceneError("pusher.edges", "no allowed edge has a stable push (no contact force can pass through the cf)")
    return out
