"""Pusher-slider point contacts with Coulomb friction and their contact modes (docs/mechanics.md, "Contact modes").

A contact is a point ``p`` on the slider's boundary with the unit normal ``n`` pointing *into* the
slider (the direction the pusher pushes) and a friction coefficient ``mu``. Its tangent is
``t = (n_y, -n_x)`` (docs/mechanics.md, "Conventions": ``(t, n)`` is right-handed; "left" is the ``-t`` side).
A flat pusher on an edge is the two point contacts at the ends of the touching segment (Lynch &
Mason 1996, §3.3.1).

Contact modes, in terms of the slider's velocity relative to the pusher at ``p``, ``u``:

* ``STICK``: ``u = 0``; the force is anywhere in the friction cone.
* ``SLIDE_LEFT``: the pusher slides to the left along the slider (``u . n = 0``, ``u . t > 0``);
  friction opposes the slider's relative motion, so the force is the left cone edge ``n - mu t``.
* ``SLIDE_RIGHT``: mirror image (``u . t < 0``, force ``n + mu t``).
* ``SEPARATE``: the slider leaves the pusher (``u . n > 0``); no force.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum

import numpy as np
from numpy.typing import ArrayLike

from ..slider import Slider

__all__ = ["Contact", "ContactMode", "edge_contacts"]


class ContactMode(Enum):
    """State of one contact (module docstring)."""

    STICK = "stick"
    SLIDE_LEFT = "slide_left"
    SLIDE_RIGHT = "slide_right"
    SEPARATE = "separate"

    def mirrored(self) -> ContactMode:
        """The mode seen in a mirror: left and right swap.

        >>> ContactMode.SLIDE_LEFT.mirrored(), ContactMode.STICK.mirrored()
        (<ContactMode.SLIDE_RIGHT: 'slide_right'>, <ContactMode.STICK: 'stick'>)
        """
        swap = {ContactMode.SLIDE_LEFT: ContactMode.SLIDE_RIGHT, ContactMode.SLIDE_RIGHT: ContactMode.SLIDE_LEFT}
        return swap.get(self, self)


@dataclass(frozen=True, eq=False)
class Contact:
    """A point contact on the slider, slider frame.

    Parameters
    ----------
    point : (2,) array_like
        Contact point on the slider's boundary.
    normal : (2,) array_like
        Normal into the slider (normalised here).
    mu : float
        Pusher-slider friction coefficient, > 0 (with ``mu = 0`` sticking and sliding carry the
        same force and the mode is not defined).

    Examples
    --------
    >>> c = Contact([0.0, -1.0], [0.0, 2.0], 0.5)
    >>> c.normal.tolist(), c.tangent.tolist()
    ([0.0, 1.0], [1.0, -0.0])
    >>> np.round(c.force_directions(ContactMode.SLIDE_LEFT), 12).tolist()
    [[-0.5, 1.0]]
    """

    point: np.ndarray
    normal: np.ndarray
    mu: float

    def __post_init__(self) -> None:
        p = np.asarray(self.point, dtype=float)
        n = np.asarray(self.normal, dtype=float)
        if p.shape != (2,) or n.shape != (2,) or not (np.all(np.isfinite(p)) and np.all(np.isfinite(n))):
            raise ValueError("contact point and normal must be finite pairs [x, y]")
        length = float(np.linalg.norm(n))
        if length == 0:
            raise ValueError("contact normal must be non-zero")
        if not (np.isfinite(self.mu) and self.mu > 0):
            raise ValueError(f"friction coefficient must be > 0, got {self.mu}")
        object.__setattr__(self, "point", p)
        object.__setattr__(self, "normal", n / length)
        object.__setattr__(self, "mu", float(self.mu))

    def __repr__(self) -> str:
        return f"Contact(point={self.point.tolist()}, normal={self.normal.tolist()}, mu={self.mu})"

    @property
    def tangent(self) -> np.ndarray:
        """``t = (n_y, -n_x)``: ``(t, n)`` is right-handed."""
        return np.array([self.normal[1], -self.normal[0]])

    def force_directions(self, mode: ContactMode) -> np.ndarray:
        """Generators ``(k, 2)`` of the forces the contact can apply on the slider in ``mode``."""
        left, right = self.normal - self.mu * self.tangent, self.normal + self.mu * self.tangent
        return {
            ContactMode.STICK: np.array([left, right]),
            ContactMode.SLIDE_LEFT: left[None, :],
            ContactMode.SLIDE_RIGHT: right[None, :],
            ContactMode.SEPARATE: np.empty((0, 2)),
        }[mode]

    def moved(self, point: ArrayLike) -> Contact:
        """The same contact (normal, friction) at another point of the same edge."""
        return Contact(point, self.normal, self.mu)


def edge_contacts(slider: Slider, edge: int, mu: float, width: float | None = None) -> tuple[Contact, Contact]:
    """The two end-point contacts of a flat pusher on ``edge`` (see :meth:`Slider.contact`).

    >>> s = Slider([[-1, 0], [1, 0], [1, 1], [-1, 1]])
    >>> [c.point.tolist() for c in edge_contacts(s, 0, 0.5, width=1.0)]
    [[-0.5, 0.0], [0.5, 0.0]]
    """
    a, b = slider.contact(edge, width)
    n = slider.inward_normal(edge)
    return Contact(a, n, mu), Contact(b, n, mu)
