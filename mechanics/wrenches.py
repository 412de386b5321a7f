"""Pusher contact forces of a contact mode (Lynch 1992, §3.1; docs/mechanics.md, "Contact modes", "Moment labelling").

At a sticking contact (``s``) the force on the slider may lie anywhere in the friction cone; at a
sliding contact it lies on the cone edge opposite the slider's motion relative to the pusher
(``r``: slider moving right, so the left edge ``n - mu t``; ``l``: the right edge ``n + mu t``); a
breaking contact (``f``) carries nothing. The total is any non-negative combination: the mode's
*composite wrench cone* (Erdmann's composite friction cone). Wrenches are ``(fx, fy, m)`` with
the moment about the slider frame's origin.
"""

from __future__ import annotations

import numpy as np
import shapely
from numpy.typing import ArrayLike

from .cones import Cone
from .contacts import ContactConfiguration

__all__ = ["contact_wrench_cone", "friction_cone_edges", "moment_labels", "point_wrench"]


def point_wrench(points: ArrayLike, forces: ArrayLike) -> np.ndarray:
    """Wrench ``(fx, fy, p x f)`` of forces applied at points (broadcasting, shape ``(..., 3)``).

    >>> point_wrench([1.0, 0.0], [0.0, 2.0]).tolist()
    [0.0, 2.0, 2.0]
    """
    p = np.asarray(points, dtype=float)
    f = np.asarray(forces, dtype=float)
    p, f = np.broadcast_arrays(p, f)
    return np.concatenate([f, (p[..., 0] * f[..., 1] - p[..., 1] * f[..., 0])[..., None]], axis=-1)


def friction_cone_edges(config: ContactConfiguration) -> np.ndarray:
    """Unit force directions ``(k, 2, 2)``: per contact its left edge ``n - mu t`` and right edge ``n + mu t``.

    >>> edge = ContactConfiguration.edge([-1, 0], [1, 0], [0, 1], mu=1.0)
    >>> (friction_cone_edges(edge)[0] * np.sqrt(2)).round(12).tolist()
    [[-1.0, 1.0], [1.0, 1.0]]
    """
    n, t = config.normals, config.tangents
    edges = np.stack([n - config.mu * t, n + config.mu * t], axis=1)
    return edges / np.sqrt(1 + config.mu**2)


def contact_wrench_cone(config: ContactConfiguration, mode: str) -> Cone:
    """Composite wrench cone of ``mode`` (one label ``s``, ``r``, ``l`` or ``f`` per contact).

    Examples
    --------
    Fig. 8's mode ``sf`` for the bottom face of a block, mu = 1: only the friction cone at
    ``(-1, 0)``, edges ``(-1, 1)`` and ``(1, 1)``, both passing left of the origin (moment -1 per
    unit of upward force). Generators are unit vectors; scaled to ``fy = 1``:

    >>> edge = ContactConfiguration.edge([-1, 0], [1, 0], [0, 1], mu=1.0)
    >>> g = contact_wrench_cone(edge, "sf").generators
    >>> (g / g[:, 1:2]).round(12).tolist()
    [[-1.0, 1.0, -1.0], [1.0, 1.0, -1.0]]
    >>> contact_wrench_cone(edge, "ff").dimension
    0
    """
    edges = friction_cone_edges(config)
    label = np.array(list(config.check_mode(mode)))
    # Which cone edges (left, right) act at each contact under its label.
    use = np.stack([np.isin(label, ["s", "r"]), np.isin(label, ["s", "l"])], axis=1)
    points = np.broadcast_to(config.points[:, None, :], edges.shape)
    return Cone.from_generators(point_wrench(points[use], edges[use]))


def moment_labels(cone: Cone, window: ArrayLike) -> dict[int, shapely.Geometry]:
    """Moment-labelling regions of a wrench cone: ``{+1: P+, -1: P-}`` clipped to ``window``.

    ``P+`` holds the points about which every wrench of the cone has a moment ``>= 0``, ``P-``
    those with moment ``<= 0`` (docs/mechanics.md, "Moment labelling"). They are the CCW and CW rotation centres of the
    dual cone, since the moment about ``q`` is the power on a unit CCW rotation about ``q``.

    Examples
    --------
    One upward force along ``x = 1``: ``P+`` is the half-plane to its left, ``P-`` to its right.

    >>> labels = moment_labels(Cone.from_generators([point_wrench([1, 0], [0, 1])]), (-3, -3, 3, 3))
    >>> labels[1].bounds, labels[-1].bounds
    ((-3.0, -3.0, 1.0, 3.0), (1.0, -3.0, 3.0, 3.0))
    """
    dual = cone.dual()
    return {sense: dual.cor_region(sense, window) for sense in (1, -1)}
