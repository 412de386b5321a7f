"""A whole push: quasi-static steps integrated over its duration.

The pusher moves with a constant body twist ``V_p`` (constant in its own frame, as a control of
Lynch & Mason 1996, §1.1), its frame coinciding with the slider's at the start, so a push that
sticks throughout moves the slider by ``exp(V_p T)``. Each step solves :func:`.solve_step` in the
current slider frame and moves both bodies for ``dt`` with their twists (explicit Euler on SE(2),
first order). Once the slider moves with the pusher (every contact sticking, ``V = V_p``) the
relative configuration, hence the step, stays the same to the end, so the rest of the push is
one exact exponential: a stable push is solved once and is exact for any ``dt``.

Contact geometry. Each contact is a *finger*: a point fixed on the pusher, touching a straight
edge of the slider whose normal is fixed on the slider. While sticking the finger stays put on
the slider; while sliding it moves along the edge (its position is recomputed from the two poses
and projected on the edge's line, so the ``O(dt^2)`` gap or overlap a step leaves is not carried
into the contact geometry). A flat
pusher is two fingers at the ends of the touching segment: exact while the face stays flush
(sticking, or both ends sliding along the edge).

The simulation stops, and says why, when

* a contact separates (``"separated"``): without collision geometry the fingers cannot tell when
  they would touch again, and a flat pusher pivoting on one end no longer touches at its fingers;
* a sliding finger leaves the footprint's boundary (``"slid_off_edge"``, needs ``footprint``);
* no mode is consistent (``"no_solution"``; not expected for a pressing pusher).

When several solutions are consistent the step follows the first (enumeration order: sticking
first) and counts the step as ambiguous: ambiguity is reported, never resolved silently.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np
import shapely
from numpy.typing import ArrayLike

from ..se2 import exp_twist, relative_pose
from .contact import Contact, ContactMode
from .step import Mode, solve_step
from .support import TOL, SupportDistribution

__all__ = ["DEFAULT_STEPS", "PushResult", "adjoint", "simulate_push"]

#: Steps of a push when ``dt`` is not given.
DEFAULT_STEPS = 200

Status = Literal["completed", "separated", "slid_off_edge", "no_solution"]


@dataclass(frozen=True, eq=False)
class PushResult:
    """Outcome of :func:`simulate_push`.

    Attributes
    ----------
    final_pose : (3,) ndarray
        Slider pose at the end (world frame, from ``start_pose``).
    pusher_pose : (3,) ndarray
        Pusher frame pose at the end (it coincided with the slider's at the start).
    modes_seen : tuple of mode tuples
        Every consistent mode of every step taken, in order of first appearance.
    ambiguous_steps : int
        Steps with more than one solution (the step that stopped the simulation included).
    steps : int
        Steps integrated (all of them when completed).
    time : float
        Simulated time reached.
    status : str
        ``"completed"``, ``"separated"``, ``"slid_off_edge"`` or ``"no_solution"``.
    """

    final_pose: np.ndarray
    pusher_pose: np.ndarray
    modes_seen: tuple[Mode, ...]
    ambiguous_steps: int
    steps: int
    time: float
    status: Status

    @property
    def sticks(self) -> bool:
        """The push completed with every contact sticking at every step, unambiguously."""
        return (self.status == "completed" and self.ambiguous_steps == 0
                and all(m is ContactMode.STICK for mode in self.modes_seen for m in mode))


def adjoint(pose: ArrayLike, twist: ArrayLike) -> np.ndarray:
    """A body twist of a frame at ``pose`` expressed in the reference frame of ``pose``.

    >>> adjoint([1.0, 0.0, np.pi / 2], [1.0, 0.0, 1.0]).round(12).tolist()
    [0.0, 0.0, 1.0]
    """
    x, y, theta = np.asarray(pose, dtype=float)
    vx, vy, w = np.asarray(twist, dtype=float)
    c, s = math.cos(theta), math.sin(theta)
    return np.array([c * vx - s * vy + w * y, s * vx + c * vy - w * x, w])


def simulate_push(support: SupportDistribution, contacts: Sequence[Contact], pusher_twist: ArrayLike,
                  duration: float, dt: float | None = None, footprint: shapely.Polygon | None = None,
                  start_pose: ArrayLike = (0.0, 0.0, 0.0)) -> PushResult:
    """Integrate a push of constant pusher body twist over ``duration``.

    Parameters
    ----------
    support : SupportDistribution
        The slider's support, slider frame.
    contacts : sequence of Contact
        Pusher fingers at the start, slider frame (module docstring).
    pusher_twist : (3,) array_like
        Pusher body twist; at the start the pusher frame is the slider frame.
    duration : float
        Push time, > 0.
    dt : float, optional
        Largest step; the push is cut into ``ceil(duration/dt)`` equal steps. Default:
        ``duration / DEFAULT_STEPS``.
    footprint : shapely.Polygon, optional
        The slider's outline; if given, a finger sliding off it ends the simulation.
    start_pose : (3,) array_like
        World pose of the slider (and pusher) frame at the start.

    Examples
    --------
    A 2 x 1 block pushed 2 m along its bottom edge's normal by a flat pusher: it sticks.

    >>> from mechanics.quasistatic import Contact, grid_support
    >>> block = shapely.box(-1, 0, 1, 1)
    >>> line = [Contact([-1.0, 0.0], [0, 1], 0.5), Contact([1.0, 0.0], [0, 1], 0.5)]
    >>> push = simulate_push(grid_support(block, 9), line, [0.0, 1.0, 0.0], 2.0, footprint=block)
    >>> push.sticks, push.final_pose.round(12).tolist(), push.steps
    (True, [0.0, 2.0, 0.0], 200)
    """
    if not (np.isfinite(duration) and duration > 0):
        raise ValueError(f"duration must be > 0, got {duration}")
    if dt is not None and not (np.isfinite(dt) and dt > 0):
        raise ValueError(f"dt must be > 0, got {dt}")
    slider = pusher = np.asarray(start_pose, dtype=float)
    if slider.shape != (3,) or not np.all(np.isfinite(slider)):
        raise ValueError("start_pose must be three finite numbers (x, y, theta)")
    steps = DEFAULT_STEPS if dt is None else max(1, math.ceil(duration / dt - 1e-9))
    h = duration / steps
    fingers = _Fingers(contacts, footprint, support.radius)
    vp = np.asarray(pusher_twist, dtype=float)
    seen: dict[Mode, None] = {}
    ambiguous, step = 0, 0
    while step < steps:
        relative = relative_pose(slider, pusher)
        current = fingers.place(relative)
        if current is None:
            return PushResult(slider, pusher, tuple(seen), ambiguous, step, step * h, "slid_off_edge")
        local = adjoint(relative, vp)
        result = solve_step(support, current, local)
        seen.update(dict.fromkeys(result.modes))
        ambiguous += result.ambiguous
        if not result.solutions:
            return PushResult(slider, pusher, tuple(seen), ambiguous, step, step * h, "no_solution")
        chosen = result.solutions[0]
        if ContactMode.SEPARATE in chosen.mode:
            return PushResult(slider, pusher, tuple(seen), ambiguous, step, step * h, "separated")
        # A slider moving with the pusher keeps the relative configuration, hence this very step,
        # to the end of the push: take the remaining steps at once (the exponential is exact).
        repeat = steps - step if np.array_equal(chosen.twist, local) else 1
        ambiguous += (repeat - 1) * result.ambiguous
        slider, pusher = exp_twist(slider, chosen.twist, repeat * h), exp_twist(pusher, vp, repeat * h)
        step += repeat
    return PushResult(slider, pusher, tuple(seen), ambiguous, steps, duration, "completed")


class _Fingers:
    """Pusher-fixed contact points on slider-fixed edges (module docstring)."""

    def __init__(self, contacts: Sequence[Contact], footprint: shapely.Polygon | None, size: float):
        self.contacts = tuple(contacts)
        self.tips = np.array([c.point for c in contacts])  # pusher frame = slider frame at the start
        self.boundary = None if footprint is None else footprint.exterior
        self.tolerance = TOL * size

    def place(self, relative: np.ndarray) -> list[Contact] | None:
        """Contacts for the pusher at ``relative`` (its pose in the slider frame); None if a finger
        left the footprint."""
        c, s = math.cos(relative[2]), math.sin(relative[2])
        tips = self.tips @ np.array([[c, s], [-s, c]]) + relative[:2]
        out = []
        for contact, tip in zip(self.contacts, tips):
            point = tip - ((tip - contact.point) @ contact.normal) * contact.normal  # onto the edge's line
            if self.boundary is not None and self.boundary.distance(shapely.Point(point)) > self.tolerance:
                return None
            out.append(contact.moved(point))
        return out
