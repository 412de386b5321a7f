"""Steering by stable pushes: the unit control box mapped onto an edge's stable twists.

A sampling planner draws controls from a box. To make *every* sampled control a guaranteed-stable
push, the box is mapped onto the stable cone of :func:`mechanics.stable_region`, and the map is
onto, so no stable push is out of reach (Lynch & Mason 1996, Prop. 3: the convex hull of the
extremal pushes is what a planner can follow).

Construction. The region's cross-section in the push plane (:mod:`.push_plane`) is a polygon
that is star-shaped about a centre ``C`` (convex for procedure STABLE, the hull of the extremal
twists). ``u1`` picks a point ``B`` on its boundary by arc length, ``u2`` the point
``C + u2 (B - C)`` on the segment from the centre: a continuous map onto the polygon.
"""

from __future__ import annotations

import numpy as np
import shapely
from numpy.typing import ArrayLike

from .stable import StableRegion

__all__ = ["StableSteering"]


class StableSteering:
    """Map ``u in [0, 1]^2`` onto the stable twists of ``region``.

    Twists come scaled so that the contact midpoint advances at unit speed along the normal.

    Examples
    --------
    Fixture A (2 x 1 block, mu = 0.5): the centre of the box is a push near straight ahead, the
    corners of the box land on the region's boundary, and every image is stable.

    >>> from mechanics import Slider, stable_region
    >>> region = stable_region(Slider([[-1, 0], [1, 0], [1, 1], [-1, 1]]), 0, 0.5)
    >>> steer = StableSteering(region)
    >>> steer.twist([0.5, 0.0]).round(6).tolist()
    [0.0, 1.0, 0.0]
    >>> twists = steer.twist(np.random.default_rng(0).random((1000, 2)))
    >>> bool(region.contains(twists).all())
    True
    """

    def __init__(self, region: StableRegion):
        if region.is_empty:
            raise ValueError(f"edge {region.edge} has no stable pushes")
        self.region = region
        polygon, centre = region.section()
        self._plane = region.plane
        self._centre = np.asarray(centre, dtype=float)
        # A region of one translation is a point; of translations only, a segment.
        self._boundary = {"Polygon": getattr(polygon, "exterior", None), "LineString": polygon}.get(polygon.geom_type)

    def twist(self, u: ArrayLike) -> np.ndarray:
        """Stable twist(s) for control(s) ``u`` of shape ``(..., 2)`` in the unit box."""
        u = np.clip(np.asarray(u, dtype=float), 0.0, 1.0)
        if self._boundary is None:
            b = np.broadcast_to(self._centre, u.shape).copy()
        else:
            pts = shapely.line_interpolate_point(self._boundary, u[..., 0], normalized=True)
            b = shapely.get_coordinates(pts).reshape(u.shape)
        return self._plane.twists(self._centre + u[..., 1:2] * (b - self._centre))
