"""The stable pushes of an edge by either method: procedure STABLE or the exact region.

:mod:`.stable` (procedure STABLE, Lynch & Mason 1996, §3.3.1) is a closed form;
:mod:`.exact_region` traces the exact set and starts from STABLE's region, so it depends on
:mod:`.stable`. This module chooses between them, above both, so that the dependency runs one way.
"""

from __future__ import annotations

from typing import Protocol

import numpy as np
import shapely
from numpy.typing import ArrayLike

from .exact_region import ExactRegion, exact_region
from .push_plane import PushPlane
from .slider import Slider
from .stable import DEFAULT_TIP_FACTOR, StableRegion, procedure_stable

__all__ = ["METHODS", "PushRegion", "stable_region"]


class PushRegion(Protocol):
    """What every edge's set of stable pushes offers, by either method (:class:`StableRegion`,
    :class:`ExactRegion`): the planner relies on this and on nothing else of them."""

    edge: int
    contact: np.ndarray  # [e_L, e_R], slider frame
    normal: np.ndarray
    mu: float
    cf: np.ndarray
    scale: float

    @property
    def is_empty(self) -> bool: ...
    @property
    def plane(self) -> PushPlane: ...
    @property
    def translation_range(self) -> tuple[float, float] | None: ...
    def contains(self, twist: ArrayLike, tol: float = 1e-9) -> np.ndarray: ...
    def extremal_twists(self) -> np.ndarray: ...
    def section(self) -> tuple[shapely.Geometry, np.ndarray]: ...
    def cor_polygons(self, window: ArrayLike | None = None) -> dict[int, shapely.Polygon]: ...

#: The ways of finding an edge's stable pushes.
METHODS = ("stable", "exact")


def stable_region(
    slider: Slider,
    edge: int,
    mu: float,
    width: float | None = None,
    tip_factor: float = DEFAULT_TIP_FACTOR,
    method: str = "stable",
    cf_radius: float = 0.0,
) -> PushRegion:
    """The stable pushes of a flat pusher of ``width`` centred on ``edge`` with friction ``mu``.

    Parameters
    ----------
    slider, edge, mu, width
        As for :func:`~.stable.procedure_stable`; for the exact region ``mu`` may be an interval
        (:func:`~.exact_region.exact_region`).
    tip_factor : float
        Procedure STABLE's tip-line factor (its default is the only one the exact region uses).
    method : {"stable", "exact"}
        Procedure STABLE (:class:`~.stable.StableRegion`, closed form) or the exact region
        (:class:`~.exact_region.ExactRegion`, traced by certified force status; it contains STABLE's).
    cf_radius : float
        The exact region's CF uncertainty; procedure STABLE assumes a known CF.

    Examples
    --------
    Fixture A of docs/mechanics.md, "Fixtures" (a 2 x 1 block pushed on its whole bottom face, mu = 0.5):
    turning CCW about (-3, 1.2) is stable, but only the exact region knows it.

    >>> from mechanics import cor_to_twist
    >>> block = Slider([[-1, 0], [1, 0], [1, 1], [-1, 1]])
    >>> turn = cor_to_twist([-3, 1.2], 1)
    >>> [bool(stable_region(block, 0, 0.5, method=m).contains(turn)) for m in METHODS]
    [False, True]
    >>> stable_region(block, 0, 0.5, method="exact", tip_factor=1.0)
    Traceback (most recent call last):
    ...
    ValueError: tip_factor is procedure STABLE's; the exact region starts from its default
    """
    if method == "stable":
        if cf_radius > 0:
            raise ValueError("procedure STABLE assumes a known CF (cf_radius 0)")
        return procedure_stable(slider, edge, mu, width, tip_factor)
    if method == "exact":
        if tip_factor != DEFAULT_TIP_FACTOR:
            raise ValueError("tip_factor is procedure STABLE's; the exact region starts from its default")
        return exact_region(slider, edge, mu, width, cf_radius=cf_radius)
    raise ValueError(f"method must be one of {', '.join(map(repr, METHODS))}, got {method!r}")
