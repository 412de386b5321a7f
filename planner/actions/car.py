"""An edge's stable pushes as a Dubins car: a heading and a turning radius for the centre of friction.

Lynch & Mason (1996, §4) note that pushing on one edge is a forward-only car and that shortest
paths were known only for cars (Dubins forward-only, Reeds-Shepp with reverse). This module picks,
for one edge, a car whose every motion is a guaranteed-stable push, so a shortest Dubins path is
a shortest path among those pushes:

* a *heading* ``h``: a unit direction in the slider frame along which the centre of friction (CF)
  moves when the car goes straight (a stable translation);
* a *curvature* ``kappa_max = 1 / R``: every motion with the CF moving along ``h`` at unit speed
  while the part turns at ``kappa`` in ``[-kappa_max, kappa_max]`` is stable; the Dubins car uses
  ``-kappa_max`` (right), ``0`` (straight) and ``+kappa_max`` (left), rotations about the points
  ``R`` to either side of the CF.

Why it is sound for any region. Those twists are ``V(kappa) = (h + kappa k x (O - cf), kappa)``,
affine in ``kappa``, so they form a straight segment of twists, and the push plane maps straight
segments to straight segments (:mod:`mechanics.push_plane`). The segment is accepted only if the
region's section, shrunk by a margin, *covers* it (shapely, exact for the polygon): convex or not,
every curvature in between, and hence every larger radius, is stable. ``kappa_max`` is the largest
such curvature (bisection), for the heading among the stable translations that allows the
tightest turns.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from weakref import WeakKeyDictionary

import numpy as np
import shapely
from numpy.typing import ArrayLike

from mechanics import ExactRegion, transform_points, wrap_angle

from .controls import EdgeControls

__all__ = ["EdgeCar", "edge_car"]

#: Headings tried across the edge's stable translations, then about the best of them.
_HEADINGS, _REFINE = 13, 4
#: Halvings of the curvature interval: the radius to about 1e-9 of itself.
_BISECTIONS = 32
#: The heading and radius of each car found (None, inf: none), by exact region and CF. Exact
#: regions come from the region cache, the same objects plan after plan, and are hashed by
#: identity; held weakly, a region's cars go when the cache drops it.
_found: WeakKeyDictionary[ExactRegion, dict[tuple[float, ...], tuple[np.ndarray | None, float]]] = WeakKeyDictionary()
#: Margin inside the region's section (push-plane units) that the segment of twists must keep.
_MARGIN = 1e-3


@dataclass(frozen=True)
class EdgeCar:
    """The Dubins car of one edge's pushes (module docstring).

    Attributes
    ----------
    push : EdgeControls
        The edge, its region and its body.
    cf : (2,) ndarray
        The centre of friction, slider frame: the car's reference point.
    heading : (2,) ndarray
        Unit direction of the CF's motion when going straight, slider frame.
    radius : float
        The least turning radius of the CF, ``1 / kappa_max``.
    """

    push: EdgeControls
    cf: np.ndarray
    heading: np.ndarray
    radius: float

    @property
    def heading_angle(self) -> float:
        """Angle of :attr:`heading` in the slider frame."""
        return math.atan2(self.heading[1], self.heading[0])

    def twist(self, kappa: ArrayLike) -> np.ndarray:
        """Slider-frame twists with the CF moving along the heading at unit speed, turning at ``kappa``.

        >>> car = EdgeCar(None, np.array([0.0, 1.0]), np.array([1.0, 0.0]), 0.5)
        >>> car.twist([0.0, 2.0]).tolist()   # straight; left about the point 0.5 to the CF's left
        [[1.0, 0.0, 0.0], [3.0, 0.0, 2.0]]
        """
        k = np.asarray(kappa, dtype=float)[..., None]
        h, c = self.heading, self.cf
        return np.concatenate([h + k * np.array([c[1], -c[0]]), k], axis=-1)

    def state(self, pose: ArrayLike) -> np.ndarray:
        """The car's state ``(x, y, psi)`` (CF position, heading) for a slider pose.

        >>> car = EdgeCar(None, np.array([0.1, 0.0]), np.array([0.0, 1.0]), 0.5)
        >>> car.state([1.0, 0.0, 0.0]).round(12).tolist()
        [1.1, 0.0, 1.570796326795]
        >>> car.pose(car.state([1.0, 2.0, 3.0])).round(12).tolist()
        [1.0, 2.0, 3.0]
        """
        return self.states(pose)[0]

    def states(self, poses: ArrayLike) -> np.ndarray:
        """:meth:`state` of each slider pose of ``poses`` ``(n, 3)``, as rows.

        >>> car = EdgeCar(None, np.array([0.1, 0.0]), np.array([0.0, 1.0]), 0.5)
        >>> car.states([[1.0, 0.0, 0.0], [0.0, 0.0, np.pi / 2]]).round(12).tolist()
        [[1.1, 0.0, 1.570796326795], [0.0, 0.1, -3.14159265359]]
        """
        q = np.asarray(poses, dtype=float).reshape(-1, 3)
        return np.column_stack([transform_points(self.cf, q), wrap_angle(q[:, 2] + self.heading_angle)])

    def pose(self, state: ArrayLike) -> np.ndarray:
        """The slider pose for a car state (inverse of :meth:`state`)."""
        x, y, psi = (float(v) for v in state)
        th = float(wrap_angle(psi - self.heading_angle))
        return np.array([*(np.array([x, y]) - transform_points(self.cf, [0.0, 0.0, th])), th])

    def reach(self) -> float:
        """Farthest point of the pushed body (part and pusher) from the CF: a body point moves at
        most ``1 + reach / radius`` times the CF's speed."""
        return float(max(np.linalg.norm(points - self.cf, axis=1).max() for points in self.push.outline))


def edge_car(push: EdgeControls, cf: ArrayLike) -> EdgeCar | None:
    """The car with the tightest turns among the edge's stable pushes, or None if it has no
    stable translation with room to turn.

    Examples
    --------
    The long face of a 10 x 6 cm block (mu 0.6): straight ahead, turning no tighter than about
    8.4 cm; every curvature up to that is a stable push.

    >>> from planner import load_scene
    >>> from planner.actions.controls import edge_controls
    >>> scene = load_scene("scenes/parking.yaml")
    >>> car = edge_car(edge_controls(scene)[0], scene.slider.cf)
    >>> (car.heading.round(6) + 0.0).tolist(), round(car.radius, 3)
    ([0.0, 1.0], 0.084)
    >>> bool(car.push.region.contains(car.twist(np.linspace(-1, 1, 201) / car.radius)).all())
    True
    """
    region, cf = push.region, np.asarray(cf, dtype=float)
    if not isinstance(region, ExactRegion):  # STABLE's regions are made afresh for each plan: nothing to reuse
        return _tightest(push, cf)
    cars = _found.setdefault(region, {})
    key = tuple(cf.tolist())
    if key not in cars:
        car = _tightest(push, cf)
        cars[key] = (None, math.inf) if car is None else (car.heading, car.radius)
    heading, radius = cars[key]
    return None if heading is None else EdgeCar(push, cf, heading, radius)


def _tightest(push: EdgeControls, cf: np.ndarray) -> EdgeCar | None:
    """The search behind :func:`edge_car`, all headings of a sweep at once."""
    region = push.region
    span = region.translation_range
    if span is None:
        return None
    polygon, _ = region.section()
    inner = polygon.buffer(-_MARGIN)
    shapely.prepare(inner)
    n = region.normal
    t = np.array([n[1], -n[0]])
    arm = np.array([cf[1], -cf[0]])  # EdgeCar.twist: V(kappa) = (h + kappa arm, kappa)

    def covered(h: np.ndarray, kappa: np.ndarray) -> np.ndarray:
        """Whether each heading's segment of twists from -kappa to kappa lies in the region."""
        k = kappa[:, None]
        ends = region.plane.points(np.stack([np.c_[h - k * arm, -k], np.c_[h + k * arm, k]], axis=1))
        finite = np.isfinite(ends).all(axis=(1, 2))
        return finite & shapely.covers(inner, shapely.linestrings(np.where(finite[:, None, None], ends, 0.0)))

    def radii(angles: np.ndarray) -> np.ndarray:
        """The least radius of the car heading at each angle from the normal (inf if none)."""
        h = np.cos(angles)[:, None] * n - np.sin(angles)[:, None] * t
        straight = covered(h, np.zeros(len(angles)))
        low, high = np.zeros(len(angles)), np.full(len(angles), 1.0 / push.region.scale)
        growing = np.flatnonzero(straight)
        while growing.size:  # double until a curvature is not covered
            more = covered(h[growing], high[growing])
            growing = growing[more]
            low[growing], high[growing] = high[growing], 2.0 * high[growing]
        for _ in range(_BISECTIONS):
            mid = 0.5 * (low + high)
            ok = covered(h, mid)
            low, high = np.where(ok, mid, low), np.where(ok, high, mid)
        with np.errstate(divide="ignore"):
            return np.where(straight & (low > 0), 1.0 / low, math.inf)

    # A coarse sweep of the headings, then a finer one about the best: the radius varies smoothly
    # with the heading, and this costs a fifth of a fine sweep.
    grid = np.linspace(span[0], span[1], _HEADINGS)[1:-1]  # the ends lie on the boundary
    k = int(np.argmin(radii(grid)))
    step = grid[1] - grid[0] if len(grid) > 1 else 0.0
    fine = np.linspace(grid[k] - step, grid[k] + step, 2 * _REFINE + 1)
    fine = fine[(fine > span[0]) & (fine < span[1])]
    radii_fine = radii(fine)
    j = int(np.argmin(radii_fine))
    if not math.isfinite(radii_fine[j]):
        return None
    angle = fine[j]
    return EdgeCar(push, cf, math.cos(angle) * n - math.sin(angle) * t, float(radii_fine[j]))
