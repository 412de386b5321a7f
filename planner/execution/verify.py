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

Transits. While the pusher moves from one edge to another the part stands still, so there is
nothing to simulate; but each push is simulated from its own planned start with the pusher on its
own edge, which would not notice a plan that teleports the part or the pusher between pushes.
So before simulating, :func:`verify` checks that the plan hangs together: every segment starts
where the one before it left the part, every push is on the edge the pusher is on, and every
transit starts at the contact pose on that edge, ends at the contact pose on the next push's edge,
and uses a mode the scene allows (a lift only with ``pusher.transit: lift``). The drift treats a
transit as the identity. Whether a transit's path is collision-free is the planner's rule
(:mod:`planner.actions.transit`), not checked here; a plan read from a file is checked against its
scene, obstacles included, before it is verified (:mod:`planner.execution.fit`, which uses
:func:`check_chain`).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import shapely
from numpy.typing import ArrayLike

from mechanics import exp_twist, log_pose, transform_points, wrap_angle
from mechanics.quasistatic import (DEFAULT_STEPS, Contact, ContactMode, PushResult, SupportDistribution,
                                   dipod_supports, edge_contacts, grid_support, random_support, simulate_push,
                                   tripod_supports)

from ..model.fields import SceneError, pose_text
from ..model.plan import Plan
from ..model.segments import Push, Transit
from ..model.scene import Scene
from ..actions.transit import edge_contact_pose

__all__ = ["TOLERANCE", "PushCheck", "Verification", "check_chain", "distributions", "verify"]

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
    segment : Push
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

    segment: Push
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
    """Outcome of :func:`verify`: per push, and the plan's drift when pushes are chained.

    ``pushes`` holds one check per push segment, in order (transits have nothing to simulate);
    ``segments`` is the whole plan, so that :meth:`lines` can show where the pusher switched.
    """

    scene: Scene
    segments: tuple[Push | Transit, ...]
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
        """A line per segment, in plan order, numbered from 1 (``plan --verify`` prints them, then
        :meth:`summary`).

        A transit has nothing to simulate and :func:`verify` refuses a plan whose transits do not
        join up, so every transit it reports on is ``ok``; its line shows where the edge changes.
        """
        transits = [s for s in self.segments if s.kind == "transit"]
        numbered = {"push": iter(enumerate(self.pushes, 1)), "transit": iter(enumerate(transits, 1))}
        out = []
        for n, s in enumerate(self.segments, 1):  # the plan's own numbering, as --simulate and the CSV use
            k, item = next(numbered[s.kind])
            out.append(f"segment {n}/{len(self.segments)}: " + (
                self._push_line(k, item) if s.kind == "push" else
                f"transit {k}/{len(transits)} (edge {item.from_edge} -> {item.to_edge}, {item.mode}, "
                f"{item.duration:.3f} s): part still, flush on both edges: ok"))
        return out

    def _push_line(self, k: int, p: PushCheck) -> str:
        """The verdict on push ``k`` (from 1) and what its runs did."""
        runs = len(p.results)
        stuck = sum(r.sticks for r in p.results)
        stopped = {s: sum(r.status == s for r in p.results) for s in ("separated", "slid_off_edge", "no_solution")}
        notes = [f"{stuck}/{runs} stick"] + [f"{c} {s.replace('_', ' ')}" for s, c in stopped.items() if c]
        if (ambiguous := sum(r.ambiguous_steps > 0 for r in p.results)):
            notes.append(f"{ambiguous} ambiguous")
        if (modes := p.non_sticking_modes()):
            notes.append(f"modes {', '.join(modes)}")
        return (f"push {k}/{len(self.pushes)} (edge {p.segment.edge}, {p.segment.duration:.3f} s): "
                f"worst {p.position_error.max():.2e} m, {p.angle_error.max():.2e} rad "
                f"({self.kinds[p.worst]} run {p.worst}); {', '.join(notes)}: {'ok' if p.passed else 'SLIPS'}")

    def summary(self) -> str:
        """One line: the verdict, the distributions, the worst deviation and the chained drift."""
        mix = ", ".join(f"{self.kinds.count(k)} {k}" for k in dict.fromkeys(self.kinds))
        position, angle = self.worst
        return (f"verify: {'passed' if self.passed else 'FAILED'}: {len(self.pushes)} push{'' if len(self.pushes) == 1 else 'es'} x "
                f"{len(self.supports)} distributions ({mix}); worst deviation {position:.2e} m, {angle:.2e} rad; "
                f"chained drift {self.drift[0]:.2e} m, {self.drift[1]:.2e} rad "
                f"(tolerance {self.tolerance[0]:.1e} m, {self.tolerance[1]:.1e} rad)")


def _allowed_edge(scene: Scene, edge: int, field: str) -> None:
    """Refuse an edge the scene does not let the pusher push (a plan made for another scene)."""
    if edge not in scene.edges:
        raise SceneError(field, f"edge {edge} is not one the scene lets the pusher push "
                                f"(allowed: {', '.join(map(str, scene.edges))})")


def _off(scene: Scene, pose: ArrayLike, expected: ArrayLike) -> bool:
    """``pose`` is not ``expected`` to :data:`TOLERANCE` (in slider radii and radians): the same
    pose but for rounding, as in a plan file written with full precision."""
    gap = np.asarray(pose, dtype=float) - expected
    return bool(np.hypot(gap[0], gap[1]) > TOLERANCE * scene.slider.radius or abs(wrap_angle(gap[2])) > TOLERANCE)


def _contacts(scene: Scene, segment: Push, name: str) -> tuple[Contact, ...]:
    """The scene's flat pusher on ``segment``'s edge, after checking the segment is for this scene."""
    slider, pusher, edge = scene.slider, scene.pusher, segment.edge
    _allowed_edge(scene, edge, f"{name}.edge")
    expected = slider.contact(edge, pusher.width)
    miss = min(np.abs(segment.contact - expected).max(), np.abs(segment.contact[::-1] - expected).max())
    if miss > TOLERANCE * slider.radius:  # a plan made for another part or another pusher width
        raise SceneError(f"{name}.contact", f"is not where the scene's pusher touches edge {edge}: "
                                            f"{np.round(expected, 6).tolist()}")
    if segment.duration <= 0:
        raise SceneError(f"{name}.duration", "must be > 0 to be verified")
    return edge_contacts(slider, edge, pusher.mu, pusher.width)


def _check_transit(scene: Scene, transit: Transit, edge: int | None, name: str) -> None:
    """Refuse a transit the scene does not allow, or one that does not leave from ``edge`` (the
    edge the pusher is on; None at the plan's start) and reach its own ``to_edge`` flush."""
    allowed = scene.pusher.transit
    if allowed == "none" or (transit.mode == "lift" and allowed != "lift"):
        raise SceneError(f"{name}.mode", f"a {transit.mode} transit is not allowed: the scene's pusher.transit "
                                         f"is {allowed!r}")
    if edge is not None and transit.from_edge != edge:
        raise SceneError(f"{name}.from_edge", f"must be {edge}, the edge the pusher is on, got {transit.from_edge}")
    ends = (("from_edge", "starts", transit.from_edge, transit.pusher_path[0]),
            ("to_edge", "ends", transit.to_edge, transit.pusher_path[-1]))
    for field, verb, e, pose in ends:
        _allowed_edge(scene, e, f"{name}.{field}")
        flush = edge_contact_pose(scene.slider, e, transit.pose)
        if _off(scene, pose, flush):
            raise SceneError(f"{name}.pusher_path", f"{verb} at {pose_text(pose)}, not at the contact "
                                                    f"pose on edge {e}: {pose_text(flush)}")


def check_chain(scene: Scene, plan: Plan) -> list[tuple[Contact, ...]]:
    """The pusher's contacts for each push, after checking that every segment fits the scene and
    takes over where the one before left the part and the pusher (module docstring)."""
    pose, edge, after = plan.start, None, "the plan's start"
    contacts = []
    for k, segment in enumerate(plan.segments):
        name = f"plan.segments[{k}]"
        # A transit's pose is not in the file (it is the previous end), so only a plan built in
        # memory can get it wrong; then the segment as a whole is at fault.
        if _off(scene, segment.start, pose):
            raise SceneError(name if segment.kind == "transit" else f"{name}.start",
                             f"the part is at {pose_text(segment.start)}, not where {after} left it: "
                             f"{pose_text(pose)}")
        if segment.kind == "transit":
            _check_transit(scene, segment, edge, name)
        else:
            if edge is not None and segment.edge != edge:
                raise SceneError(f"{name}.edge", f"must be {edge}, the edge the pusher is on after {after} "
                                                 f"(a change of edge needs a transit), got {segment.edge}")
            contacts.append(_contacts(scene, segment, name))
        pose, edge, after = segment.end, segment.edge, name
    return contacts


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
        edge, a push of no duration, a lift where the pusher must stay on the table) or does not
        take over where the one before it left the part and the pusher (module docstring),
        naming the plan field.
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
    contacts = check_chain(scene, plan)
    clock = time.perf_counter()
    supports, kinds = distributions(scene, n, seed)
    limits = (tolerance * scene.slider.radius, tolerance)
    footprint = scene.slider.polygon
    checks = []
    chained = np.tile(plan.start, (n, 1))  # transits leave it be: the part stands still
    for segment, fingers in zip([s for s in plan.segments if s.kind == "push"], contacts):
        results = tuple(simulate_push(s, fingers, segment.twist, segment.duration, footprint=footprint,
                                      start_pose=segment.start) for s in supports)
        ends = np.array([r.final_pose for r in results])
        checks.append(PushCheck(segment, fingers, results, *_deviation(scene, ends, segment.end), limits))
        # chained * (start^-1 end): each run's own relative motion, from where it got to.
        chained = exp_twist(chained, log_pose(segment.start, ends))
    drift = _deviation(scene, chained, plan.final)
    return Verification(scene, tuple(plan.segments), tuple(supports), tuple(kinds), tuple(checks),
                        (float(drift[0].max()), float(drift[1].max())), limits, time.perf_counter() - clock)
