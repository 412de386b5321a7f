"""The stability margin a plan keeps (``planner: {margin: ...}``, ``--margin``, :class:`Margin`).

A guaranteed-stable push is stable for the friction and the centre of friction (CF) the scene
states. Neither is known exactly: a friction measured with a spring scale is good to some 10 %,
and a CF is an estimate. A push on the boundary of its edge's exact region has no robustness at
all (a CF a millimetre off, or a friction a few per cent lower, and the part may rotate off the
pusher), so by default every push is planned to hold for a *certified* friction lower than the
scene's and for every CF in a disk about the scene's:

* friction: ``(1 - mu)`` times the scene's ``pusher.mu`` (for an interval ``[low, high]``, its
  middle), or the interval's low end where that is lower;
* CF: a disk of radius ``cf`` times the part's radius (:attr:`mechanics.Slider.radius`, the CF's
  distance to the farthest vertex), at least :data:`CF_FLOOR`, or the part's own
  ``cf_uncertainty`` where that is larger.

The regions are then computed for that friction and that disk (:mod:`mechanics.exact_region`),
so the margin holds for both at once. ``margin: 0`` plans at the exact limit.

>>> m = Margin()
>>> m.friction(0.5), m.friction(0.45, 0.55), m.friction(0.3, 0.9)
(0.45, 0.45, 0.3)
>>> m.cf_radius(0.2, 0.0), m.cf_radius(0.02, 0.0), m.cf_radius(0.2, 0.01)
(0.004, 0.001, 0.01)
>>> EXACT.friction(0.5), EXACT.cf_radius(0.2, 0.0)
(0.5, 0.0)
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from .fields import SceneError, number, shown

__all__ = ["CF_FLOOR", "DEFAULT_MARGIN", "EXACT", "Margin", "PushMargin", "check_margin", "nominal_friction"]

#: The smallest CF disk of a non-zero margin, m: a CF drawn or measured is rarely better than this.
CF_FLOOR = 0.001


@dataclass(frozen=True)
class Margin:
    """How much lower the pusher friction (``mu``, a fraction of the scene's) and how far the CF
    (``cf``, a fraction of the part's radius, at least :data:`CF_FLOOR`) may be off while every
    planned push still holds (module docstring)."""

    mu: float = 0.1
    cf: float = 0.02

    @property
    def exact(self) -> bool:
        """Whether this is no margin at all: the plan may use the regions' very boundary."""
        return self.mu == 0 and self.cf == 0

    def friction(self, mu: float, mu_high: float | None = None) -> float:
        """The friction the pushes are certified for, of a pusher of friction ``mu`` (or the
        interval ``[mu, mu_high]``)."""
        return min(mu, nominal_friction(mu, mu_high) * (1 - self.mu))

    def cf_radius(self, radius: float, cf_uncertainty: float = 0.0) -> float:
        """The radius of the CF disk the pushes are certified for, of a part of ``radius`` whose
        CF is known to within ``cf_uncertainty``."""
        return max(cf_uncertainty, max(self.cf * radius, CF_FLOOR) if self.cf > 0 else 0.0)

    def to_dict(self) -> dict[str, float]:
        return {"mu": self.mu, "cf": self.cf}

    def __str__(self) -> str:
        """The margin in words, as summaries print it.

        >>> str(Margin()), str(EXACT)
        ('friction -10 %, CF within 2 % of the part radius (>= 1 mm)', 'none (the exact limit)')
        """
        if self.exact:
            return "none (the exact limit)"
        return f"friction -{self.mu * 100:.3g} %, CF within {self.cf * 100:.3g} % of the part radius (>= 1 mm)"


@dataclass(frozen=True)
class PushMargin:
    """One push's own margin, certified: it holds for a pusher friction ``mu`` (a fraction) lower
    than the scene's, and for a CF anywhere within ``cf`` metres of the scene's (each with the
    other as the scene states it), before it may slip (:mod:`planner.actions.margins`)."""

    mu: float
    cf: float

    def to_dict(self) -> dict[str, float]:
        return {"mu": round(self.mu, 6), "cf": round(self.cf, 9)}

    def __str__(self) -> str:
        """The margin in words.

        >>> str(PushMargin(0.234, 0.0031))
        'friction -23 %, CF 3.1 mm'
        """
        return f"friction -{self.mu * 100:.0f} %, CF {self.cf * 1e3:.2g} mm"


def nominal_friction(mu: float, mu_high: float | None = None) -> float:
    """The friction a scene states, which a margin is a fraction of: ``mu``, or the middle of the
    interval ``[mu, mu_high]``.

    >>> nominal_friction(0.5), nominal_friction(0.4, 0.6)
    (0.5, 0.5)
    """
    return mu if mu_high is None else (mu + mu_high) / 2


#: The margin every plan keeps unless told otherwise.
DEFAULT_MARGIN = Margin()
#: No margin: the regions' exact limit.
EXACT = Margin(0.0, 0.0)


def check_margin(value: Any, name: str) -> Margin:
    """``value`` as a :class:`Margin`: one (checked again), ``0`` (none), a mapping with ``mu``
    and/or ``cf`` (the others the default's) or a pair ``[mu, cf]``; each a fraction in
    ``[0, 1)``. Else a :class:`SceneError` naming ``name``.

    >>> check_margin(0, "planner.margin"), check_margin({"mu": 0.2}, "planner.margin")
    (Margin(mu=0.0, cf=0.0), Margin(mu=0.2, cf=0.02))
    >>> check_margin([0.1, 1.5], "--margin")
    Traceback (most recent call last):
    ...
    planner.model.fields.SceneError: --margin: cf must be a fraction in [0, 1) of the part's radius, got 1.5
    >>> check_margin(0.1, "planner.margin")
    Traceback (most recent call last):
    ...
    planner.model.fields.SceneError: planner.margin: must be 0, {mu: M, cf: C} or [M, C], got 0.1
    """
    if isinstance(value, Margin):
        value = value.to_dict()
    if isinstance(value, Sequence) and not isinstance(value, str) and len(value) == 1:
        value = value[0]  # a flag's one value
    if isinstance(value, Mapping):
        unknown = [k for k in value if k not in ("mu", "cf")]
        if unknown:
            raise SceneError(name, f"has no key {shown(unknown[0])} (mu, cf)")
        parts = {**DEFAULT_MARGIN.to_dict(), **value}
    elif isinstance(value, Sequence) and not isinstance(value, str) and len(value) == 2:
        parts = dict(zip(("mu", "cf"), value))
    elif not isinstance(value, bool) and isinstance(value, (int, float)) and value == 0:
        return EXACT
    else:
        raise SceneError(name, f"must be 0, {{mu: M, cf: C}} or [M, C], got {shown(value)}")
    checked = {}
    for key, what in (("mu", "of the friction"), ("cf", "of the part's radius")):
        try:
            fraction = number(parts[key], name)
        except SceneError:
            fraction = math.nan
        if not 0 <= fraction < 1:
            raise SceneError(name, f"{key} must be a fraction in [0, 1) {what}, got {shown(parts[key])}")
        checked[key] = float(fraction) + 0.0  # -0.0 is 0
    return Margin(**checked)
