"""Pusher-slider contact configurations (Lynch 1992, §1.1 and fig. 2).

A contact configuration is a finite set of point contacts, each a point on the slider's boundary
with the *inward* normal (the direction the pusher pushes the slider there), and one friction
coefficient ``mu`` between pusher and slider. An edge-edge contact is its two end points.

Each contact has a tangent ``t = (n_y, -n_x)``: looking from the pusher into the slider along
``n``, ``t`` points to the right (docs/mechanics.md, "Conventions"). Slider motions are twists in the slider frame
(:mod:`mechanics.twist`): a signed COR ``(c, s)`` is the twist ``cor_to_twist(c, s)`` and a
translation (a COR at infinity) is ``(vx, vy, 0)``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from .slider import Slider

__all__ = ["ContactConfiguration"]


@dataclass(frozen=True)
class ContactConfiguration:
    """Point contacts ``points`` (k, 2) with unit inward ``normals`` (k, 2) and friction ``mu``.

    Examples
    --------
    The bottom face of a 2 x 1 block pushed up, as its two end points:

    >>> edge = ContactConfiguration.edge([-1, 0], [1, 0], [0, 2], mu=0.5)
    >>> edge.points.tolist(), edge.normals.tolist(), edge.tangents.tolist()
    ([[-1.0, 0.0], [1.0, 0.0]], [[0.0, 1.0], [0.0, 1.0]], [[1.0, 0.0], [1.0, 0.0]])
    >>> len(edge)
    2
    """

    points: np.ndarray
    normals: np.ndarray
    mu: float

    def __post_init__(self):
        p = np.asarray(self.points, dtype=float).reshape(-1, 2)
        n = np.asarray(self.normals, dtype=float).reshape(-1, 2)
        if len(p) == 0 or p.shape != n.shape:
            raise ValueError("need one normal per contact point, and at least one contact")
        length = np.linalg.norm(n, axis=1)
        if not (np.all(np.isfinite(p)) and np.all(length > 0)):
            raise ValueError("contact points must be finite and normals non-zero")
        if not self.mu >= 0:
            raise ValueError(f"mu must be >= 0, got {self.mu}")
        object.__setattr__(self, "points", p)
        object.__setattr__(self, "normals", n / length[:, None])
        object.__setattr__(self, "mu", float(self.mu))

    def __len__(self) -> int:
        return len(self.points)

    @property
    def tangents(self) -> np.ndarray:
        """``t = (n_y, -n_x)`` per contact: "right" seen from the pusher (sliding label ``r``)."""
        return np.stack([self.normals[:, 1], -self.normals[:, 0]], axis=1) + 0.0  # no -0.0

    def check_mode(self, mode: str) -> str:
        """``mode`` if it has one label ``s``, ``r``, ``l`` or ``f`` per contact, else ``ValueError``.

        >>> ContactConfiguration([[0, 0]], [[0, 1]], 0.5).check_mode("r")
        'r'
        """
        if len(mode) != len(self) or set(mode) - set("srlf"):
            raise ValueError(f"mode {mode!r} needs one of s, r, l, f for each of the {len(self)} contacts")
        return mode

    @classmethod
    def edge(cls, a: ArrayLike, b: ArrayLike, normal: ArrayLike, mu: float) -> ContactConfiguration:
        """Edge-edge contact along the segment ``a``-``b``: its two end points, one normal."""
        return cls(np.array([a, b], dtype=float), np.array([normal, normal], dtype=float), mu)

    @classmethod
    def slider_edge(cls, slider: Slider, edge: int, mu: float, width: float | None = None) -> ContactConfiguration:
        """A flat pusher of ``width`` centred on ``edge`` of ``slider`` (see :meth:`Slider.contact`).

        >>> block = Slider([[-1, 0], [1, 0], [1, 1], [-1, 1]])
        >>> ContactConfiguration.slider_edge(block, 0, 0.5, width=1.0).points.tolist()
        [[-0.5, 0.0], [0.5, 0.0]]
        """
        a, b = slider.contact(edge, width)
        return cls.edge(a, b, slider.inward_normal(edge), mu)
