"""Check a plan with the independent quasi-static simulator (:mod:`mechanics.quasistatic`).

Each push of a plan claims the part stays stuck to the pusher *whatever* its support pressure
distribution. :func:`verify` tries to break that claim: it re-simulates every push, from the
push's planned start, under ``n`` support distributions over the part's footprint, all with their
centre at the CF (a uniform grid, random weights on random points, and the extreme two- and
three-point distributions), and compares each simulated end pose with the planned ``end``.

Deviation is measured by two numbers: the distance between the simulated and planned positions of
the centre of friction (m; the CF, not the frame origin, so the number does not depend on where
the scene put the slider frame) and the wrapped angle between them (rad).

Tolerance. A push that sticks is, in the simulator, one exact SE(2) exponential of the pusher's
twist, the same exponential the planner took, so it reproduces the plan to rounding (about
1e-16 relative). A run that slips for even one of its :data:`~mechanics.quasistatic.DEFAULT_STEPS`
steps moves the part relative to the pusher by the slip speed times a step. ``tolerance`` (default
:data:`TOLERANCE`, 1e-6) is relative: positions may deviate by ``tolerance`` slider radii and
angles by ``tolerance`` radians. It leaves ten orders of magnitude for rounding and still catches
a slip of a millionth of the part's size (so a plan file must carry full precision, as ``plan``
writes it; one rounded to micrometres fails). A run
*slips* when it deviates beyond the tolerance or stops early (the contact separated, a finger slid
off the edge, or no contact mode was consistent); a push passes when no run slips. Runs that
show a non-sticking or an ambiguous mode are counted and reported either way.

Chaining. Pushes are judged one by one, each from its planned start, so one bad push does not
hide or excuse another. The *drift* also reports where the part would end if each push started
from the previous push's simulated end (the pusher placed on the edge afresh for each push): the
simulator is invariant under moving the start pose, so this is each distribution's simulated
relative motions composed, without simulating again.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import shapely
from numpy.typing import ArrayLike

from mechanics import exp_twist, log_pose, wrap_angle
from mechanics.quasistatic import (DEFAULT_STEPS, Contact, ContactMode, PushResult, SupportDistribution,
                                   dipod_supports, edge_contacts, grid_support, random_support, simulate_push,
                                   tripod_supports)

from .bodies import transform_points
from .fields import SceneError
from .plan_file import Plan, Segment
from .scene import Scene

__all__ = ["TOLERANCE", "PushCheck", "Verification", "distributions", "verify"]

#: Default relative tolerance: positions in slider radii, angles in radians (module docstring).
TOLERANCE = 1e-6
#: Support points of the uniform grid and of each random distribution.
GRID_POINTS, RANDOM_POINTS = 100, 40


def distributions(scene: Scene, n: int, seed: int = 1) -> tuple[list[SupportDistribution], list[str]]:
    """``n`` support distributions of the scene's part with their centre at its CF, and their kinds.

    One uniform grid, then about a third each of extreme dipods (at evenly spaced angles), extreme
    tripods and random distributions; the tripods and the random ones are drawn from ``seed``.
    With ``slider.cf_uncertainty`` the centres move away from the CF: the dipods' and the tripods'
    round the rim of the uncertainty disk, the random ones anywhere in it (the grid stays at the CF).

    >>> from planner import load_scene
    >>> supports, kinds = distributions(load_scene("scenes/battery.yaml"), 7)
    >>> kinds
    ['grid', 'dipod', 'dipod', 'tripod', 'tripod', 'random', 'random']
    >>> bool(np.allclose([s.centre for s in supports], load_scene("scenes/battery.yaml").slider.cf))
    True
    """
    if n < 1:
        raise ValueError(f"need at least one distribution, got {n}")
    footprint, cf, rho = scene.slider.polygon, scene.slider.cf, scene.cf_uncertainty
    rng = np.random.default_rng(seed)
    extreme = (n - 1) // 3

    def centre(angle: float, reach: float = 1.0) -> np.ndarray:
        """A point of the uncertainty disk (the CF itself if that point is off the part)."""
        c = cf + rho * reach * np.array([np.cos(angle), np.sin(angle)])
        return c if footprint.contains(shapely.Point(c)) else cf

    if rho == 0:
        dipods, tripods = dipod_supports(footprint, cf, extreme), tripod_supports(footprint, cf, extreme, rng)
    else:  # the k-th line angle through the k-th centre round the rim
        dipods = [dipod_supports(footprint, centre(2 * np.pi * k / extreme), extreme)[k] for k in range(extreme)]
        tripods = [tripod_supports(footprint, centre(rng.uniform(0, 2 * np.pi)), 1, rng)[0] for _ in range(extreme)]
    randoms = n - 1 - 2 * extreme
    supports = ([grid_support(footprint, GRID_POINTS, cf=cf)] + dipods + tripods
                + [random_support(footprint, RANDOM_POINTS, rng,
                                  cf=centre(rng.uniform(0, 2 * np.pi), np.sqrt(rng.uniform())) if rho else cf)
                   for _ in range(randoms)])
    kinds = ["grid"] + ["dipod"] * extreme + ["tripod"] * extreme + ["random"] * randoms
    return supports, kinds


@dataclass(frozen=True, eq=False)
class PushCheck:
    """One push re-simulated under every distribution.

    Attributes
    ----------
    segment : Segment
        The push as planned.
    contacts : tuple of Contact
        The pusher's two end-point contacts (slider frame) the push was simulated with.
    results : tuple of PushResult
        One per distribution, in the order of :attr:`Verification.kinds`.
    position_error, angle_error : (n,) ndarray
        Per run: CF distance (m) and wrapped angle (rad) between the simulated and planned end.
    tolerance : (float, float)
        Position (m) and angle (rad) beyond which a run slips.
    """

    segment: Segment
    contacts: tuple[Contact, ...]
    results: tuple[PushResult, ...]
    position_error: np.ndarray
    angle_error: np.ndarray
    tolerance: tuple[float, float]

    @property
    def slipped(self) -> np.ndarray:
        """Per run: it stopped early or deviates beyond the tolerance."""
        stopped = np.array([r.status != "completed" for r in self.results])
        return stopped | (self.position_error > self.tolerance[0]) | (self.angle_error > self.tolerance[1])

    @property
    def passed(self) -> bool:
        return not self.slipped.any()

    @property
    def worst(self) -> int:
        """The run deviating most, both errors measured in tolerances."""
        return int(np.argmax(np.maximum(self.position_error / self.tolerance[0], self.angle_error / self.tolerance[1])))

    def non_sticking_modes(self) -> list[str]:
        """Every mode but all-stick seen in any run, as ``"stick/slide_left"`` (one word per contact)."""
        seen = {"/".join(m.value for m in mode) for r in self.results for mode in r.modes_seen
                if any(m is not ContactMode.STICK for m in mode)}
        return sorted(seen)


@dataclass(frozen=True, eq=False)
class Verification:
    """Outcome of :func:`verify`: per push, and the plan's drift when pushes are chained."""

    scene: Scene
    supports: tuple[SupportDistribution, ...]
    kinds: tuple[str, ...]
    pushes: tuple[PushCheck, ...]
    drift: tuple[float, float]  # worst CF distance (m) and angle (rad) of the chained end from the plan's
    tolerance: tuple[float, float]
    seconds: float

    @property
    def passed(self) -> bool:
        """No run of any push slipped."""
        return all(p.passed for p in self.pushes)

    @property
    def worst(self) -> tuple[float, float]:
        """Worst position (m) and angle (rad) deviation over all pushes and runs."""
        return (max((float(p.position_error.max()) for p in self.pushes), default=0.0),
                max((float(p.angle_error.max()) for p in self.pushes), default=0.0))

    def poses(self, push: int, times: ArrayLike, run: int | None = None) -> np.ndarray:
        """Poses ``(m, 3)`` of a run (default: the worst) of push ``push`` at push times ``times``.

        Each is the end of the same simulation cut short at that time, in steps no longer than the
        full push's, so the poses follow the verified run (exactly at its end, and wherever the
        part sticks); where the run stopped early they stay put. Costs a simulation per time (one
        step while the part sticks).
        """
        check = self.pushes[push]
        s, run = check.segment, check.worst if run is None else run
        dt = s.duration / DEFAULT_STEPS
        return np.array([simulate_push(self.supports[run], check.contacts, s.twist, t, dt=dt,
                                       footprint=self.scene.slider.polygon, start_pose=s.start).final_pose
                         if t > 0 else s.start for t in np.asarray(times, dtype=float)])

    def lines(self) -> list[str]:
        """A line per push (``plan --verify`` prints them, then :meth:`summary`)."""
        out = []
        for k, p in enumerate(self.pushes):
            runs = len(p.results)
            stuck = sum(r.sticks for r in p.results)
            stopped = {s: sum(r.status == s for r in p.results) for s in ("separated", "slid_off_edge", "no_solution")}
            notes = [f"{stuck}/{runs} stick"] + [f"{c} {s.replace('_', ' ')}" for s, c in stopped.items() if c]
            if (ambiguous := sum(r.ambiguous_steps > 0 for r in p.results)):
                notes.append(f"{ambiguous} ambiguous")
            if (modes := p.non_sticking_modes()):
                notes.append(f"modes {', '.join(modes)}")
            out.append(f"push {k + 1}/{len(self.pushes)} (edge {p.segment.edge}, {p.segment.duration:.3f} s): "
                       f"worst {p.position_error.max():.2e} m, {p.angle_error.max():.2e} rad "
                       f"({self.kinds[p.worst]} run {p.worst}); {', '.join(notes)}: {'ok' if p.passed else 'SLIPS'}")
        return out

    def summary(self) -> str:
        """One line: the verdict, the distributions, the worst deviation and the chained drift."""
        mix = ", ".join(f"{self.kinds.count(k)} {k}" for k in dict.fromkeys(self.kinds))
        position, angle = self.worst
        return (f"verify: {'passed' if self.passed else 'FAILED'}: {len(self.pushes)} pushes x "
                f"{len(self.supports)} distributions ({mix}); worst deviation {position:.2e} m, {angle:.2e} rad; "
                f"chained drift {self.drift[0]:.2e} m, {self.drift[1]:.2e} rad "
                f"(tolerance {self.tolerance[0]:.1e} m, {self.tolerance[1]:.1e} rad)")


def _contacts(scene: Scene, segment: Segment, name: str) -> tuple[Contact, ...]:
    """The scene's flat pusher on ``segment``'s edge, after checking the segment is for this scene."""
    slider, pusher, edge = scene.slider, scene.pusher, segment.edge
    if edge not in pusher.edges:
        raise SceneError(f"{name}.edge", f"edge {edge} is not one the scene lets the pusher push "
                                         f"(allowed: {', '.join(map(str, pusher.edges))})")
    expected = slider.contact(edge, pusher.width)
    miss = min(np.abs(segment.contact - expected).max(), np.abs(segment.contact[::-1] - expected).max())
    if miss > TOLERANCE * slider.radius:  # a plan made for another part or another pusher width
        raise SceneError(f"{name}.contact", f"is not where the scene's pusher touches edge {edge}: "
                                            f"{np.round(expected, 6).tolist()}")
    if segment.duration <= 0:
        raise SceneError(f"{name}.duration", "must be > 0 to be verified")
    return edge_contacts(slider, edge, pusher.mu, pusher.width)


def _deviation(scene: Scene, simulated: np.ndarray, planned: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """CF distance and wrapped angle between simulated poses ``(n, 3)`` and a planned pose."""
    cf = scene.slider.cf[None]
    gap = np.array([transform_points(cf, q)[0] for q in simulated]) - transform_points(cf, planned)[0]
    return np.linalg.norm(gap, axis=1), np.abs(wrap_angle(simulated[:, 2] - planned[2]))


def verify(scene: Scene, plan: Plan, n: int = 200, seed: int = 1, tolerance: float = TOLERANCE) -> Verification:
    """Re-simulate every push of ``plan`` under ``n`` support distributions (module docstring).

    Parameters
    ----------
    scene : Scene
        The scene the plan is for: part, CF, pusher width and friction.
    plan : Plan
        The plan, from :func:`planner.plan` or :func:`planner.load_plan`.
    n : int
        Number of support distributions (see :func:`distributions`), >= 1.
    seed : int
        Seed of the random distributions.
    tolerance : float
        Relative tolerance: positions in slider radii, angles in radians.

    Returns
    -------
    Verification

    Raises
    ------
    SceneError
        If a segment does not fit the scene (an edge the scene does not allow, a contact off its
        edge, a push of no duration), naming the plan field.
    ValueError
        If ``n < 1``.

    Examples
    --------
    >>> from planner import load_scene, plan
    >>> scene = load_scene("scenes/battery.yaml")
    >>> check = verify(scene, plan(scene, seed=1), n=4)
    >>> check.passed, len(check.pushes), check.worst[0] < 1e-12
    (True, 1, True)
    """
    contacts = [_contacts(scene, s, f"plan.segments[{k}]") for k, s in enumerate(plan.segments)]
    clock = time.perf_counter()
    supports, kinds = distributions(scene, n, seed)
    limits = (tolerance * scene.slider.radius, tolerance)
    footprint = scene.slider.polygon
    checks = []
    chained = np.tile(plan.segments[0].start if plan.segments else plan.start, (n, 1))
    for segment, fingers in zip(plan.segments, contacts):
        results = tuple(simulate_push(s, fingers, segment.twist, segment.duration, footprint=footprint,
                                      start_pose=segment.start) for s in supports)
        ends = np.array([r.final_pose for r in results])
        checks.append(PushCheck(segment, fingers, results, *_deviation(scene, ends, segment.end), limits))
        # chained * (start^-1 end): each run's own relative motion, from where it got to.
        chained = exp_twist(chained, log_pose(segment.start, ends))
    drift = _deviation(scene, chained, plan.final)
    return Verification(scene, tuple(supports), tuple(kinds), tuple(checks),
                        (float(drift[0].max()), float(drift[1].max())), limits, time.perf_counter() - clock)
