"""Check a plan with the independent quasi-static simulator (:mod:`mechanics.quasistatic`).

Each push of a plan claims the part stays stuck to the pusher *whatever* its support pressure
distribution. :func:`verify` tries to break that claim: it re-simulates every push, from the
push's planned start, under ``n`` support distributions over the pushed part's footprint, all with
their centre at its CF (a uniform grid, random weights on random points, and the extreme two- and
three-point distributions), and compares each simulated end pose with the planned ``end``.

Deviation is measured by two numbers: the distance between the simulated and planned positions of
the centre of friction (m; the CF, not the frame origin, so the number does not depend on where
the scene put the slider frame) and the wrapped angle between them (rad).

Tolerance. A push that sticks is, in the simulator, one exact SE(2) exponential of the pusher's
twist, the same exponential the planner took, so it reproduces the plan to rounding (about
1e-16 relative). A run that slips for even one of its :data:`~mechanics.quasistatic.DEFAULT_STEPS`
steps moves the part relative to the pusher by the slip speed times a step. ``tolerance`` (default
:data:`TOLERANCE`, 1e-6) is relative: positions may deviate by ``tolerance`` radii of the part
pushed and angles by ``tolerance`` radians. It leaves ten orders of magnitude for rounding and
still catches a slip of a millionth of the part's size (so a plan file must carry full precision,
as ``plan`` writes it; one rounded to micrometres fails). A run
*slips* when it deviates beyond the tolerance or stops early (the contact separated, a finger slid
off the edge, or no contact mode was consistent); a push passes when no run slips. Runs that
show a non-sticking or an ambiguous mode are counted and reported either way.

Chaining. Pushes are judged one by one, each from its planned start, so one bad push does not
hide or excuse another. The *drift* also reports where the part would end its move if each push
started from the previous push's simulated end (the pusher placed on the edge afresh for each
push): the simulator is invariant under moving the start pose, so this is each distribution's
simulated relative motions composed, without simulating again.

Transits and transfers. While the pusher moves from one edge to another, or from one part to the
next, the parts stand still, so there is nothing to simulate; but each push is simulated from its
own planned start with the pusher on its own edge, which would not notice a plan that teleports a
part or the pusher between pushes. So before simulating, :func:`verify` checks that the plan
hangs together (:func:`check_chain`): its parts and their CFs are the scene's, every segment
starts where the one before it left its part, every push is on the edge the pusher is on, every
transit starts at the contact pose on that edge, ends at the contact pose on the next push's edge,
and uses a mode the ``transit`` option allows (a lift only with ``lift``), and every transfer
starts at the contact pose on the part it leaves and ends at the one on the edge it goes to. The
drift treats a transit as the identity. Whether a transit's path is clear of the obstacles is the
planner's rule (:mod:`planner.actions.transit`), not checked here; a plan read from a file is
checked against its scene, obstacles included, before it is verified (:mod:`planner.execution.fit`,
which uses :func:`check_chain`).

The pusher's own way between contacts is checked as written, not as the planner would have made
it: a transit or a transfer touches a part only at its ends (flush on an edge), so each of its
moves on the table (:func:`~planner.actions.transit.in_plane_moves`, by the segment's own
``mode``) is swept, by the planner's conservative advancement, against every part where it stands,
each shrunk by :data:`REACH_IN` of its radius; a segment whose pusher reaches deeper goes *through*
the part, and its move fails naming it. So a transit cut to its two contact poses, a lift
relabelled ``plane`` (its flight then on the table) or a transfer straight across the parts fails,
however well its pushes stick.

Several parts. A plan is a sequence of moves, each of one part with the others standing still, so
each move's pushes are verified as above under the distributions of that move's part. What the
simulation of one part cannot see is another part in the way: every push and every transit of a
move is swept against each other part where it stands then (:mod:`.sweep`), and a move that meets
one fails, naming the part it meets.
"""

from __future__ import annotations

import time
from collections import Counter
from collections.abc import Iterator
from dataclasses import dataclass, replace

import numpy as np
import shapely
from numpy.typing import ArrayLike

from mechanics import Slider, exp_twist, log_pose, transform_points, wrap_angle
from mechanics.quasistatic import (DEFAULT_STEPS, Contact, ContactMode, PushResult, SupportDistribution,
                                   dipod_supports, edge_contacts, grid_support, random_support, simulate_push,
                                   tripod_supports)

from ..actions.margins import keeps, with_margins
from ..actions.transit import edge_contact_pose, in_plane_moves
from ..model.fields import SceneError, counted, pose_text
from ..model.margin import Margin, PushMargin
from ..model.options import DEFAULT_REGIONS, DEFAULT_TRANSIT
from ..model.plan import Move, Plan
from ..model.plan_file import part_field
from ..model.scene import Part, Pusher, Scene
from ..model.segments import Push, Transfer, Transit
from ..world.validity import CollisionModel
from .sweep import collision_model, is_clear

__all__ = ["MAX_DISTRIBUTIONS", "REACH_IN", "TOLERANCE", "MoveCheck", "PushCheck", "Verification", "check_chain", "check_solved", "distributions",
           "placed_moves", "verify"]

#: Default relative tolerance: positions in part radii, angles in radians (module docstring).
TOLERANCE = 1e-6
#: Most support distributions a verification takes: each re-simulates every push (some ms each),
#: so the cap bounds the work at minutes, not at what a number typed by mistake asks for.
MAX_DISTRIBUTIONS = 10_000
#: Support points of the uniform grid and of each random distribution.
GRID_POINTS, RANDOM_POINTS = 100, 40
#: How deep (in part radii) the pusher may reach into a part on a transit or a transfer: it touches
#: a part only at the segment's ends, flush, so this is room for rounding at the contacts, a
#: thousand times less than any path through the part (module docstring).
REACH_IN = 1e-3


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
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or not 1 <= n <= MAX_DISTRIBUTIONS:
        raise SceneError("verify", f"must be 1 to {MAX_DISTRIBUTIONS} distributions, got {n!r}")
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
    part : str
        The part pushed.
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
    part: str
    contacts: tuple[Contact, ...]
    results: tuple[PushResult, ...]
    position_error: np.ndarray
    angle_error: np.ndarray
    tolerance: tuple[float, float]
    margin: PushMargin | None = None  # the push's own, certified (planner.actions.margins)
    keeps: bool | None = None  # whether it lies in the regions of its plan's margin (None: the plan claims none)

    @property
    def slipped(self) -> np.ndarray:
        """Per run: it stopped early or deviates beyond the tolerance."""
        stopped = np.array([r.status != "completed" for r in self.results])
        return stopped | (self.position_error > self.tolerance[0]) | (self.angle_error > self.tolerance[1])

    @property
    def passed(self) -> bool:
        return not self.slipped.any() and self.keeps is not False

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
class MoveCheck:
    """One move of a plan verified: a check per push, in order, the worst CF distance (m) and
    angle (rad) of its chained end from the move's, the other parts it meets (none: clear), and per
    segment (as :attr:`segments` numbers them) the parts its pusher goes through on the way between
    contacts (none for a push; module docstring)."""

    move: Move
    pushes: tuple[PushCheck, ...]
    drift: tuple[float, float]
    met: tuple[str, ...]
    crossed: tuple[tuple[str, ...], ...]

    @property
    def segments(self) -> list[Push | Transit | Transfer]:
        """The move's segments as the plan numbers them: its transfer first, if it has one."""
        return [self.move.transfer] * (self.move.transfer is not None) + list(self.move.segments)

    @property
    def passed(self) -> bool:
        return all(p.passed for p in self.pushes) and not self.met and not any(self.crossed)


@dataclass(frozen=True, eq=False)
class Verification:
    """Outcome of :func:`verify`: per move, its pushes' checks, its drift and the parts it meets.

    ``pushes`` holds one check per push of the plan, in order (transits and transfers have nothing
    to simulate); ``segments`` is the whole plan, so that :meth:`lines` can show where the pusher
    switched. ``supports`` and ``tolerance`` are those of the one part of a plan of one part.
    """

    scene: Scene
    moves: tuple[MoveCheck, ...]
    supports_of: dict[str, tuple[SupportDistribution, ...]]  # each part's, in the order of kinds
    kinds: tuple[str, ...]
    relative_tolerance: float  # positions in part radii, angles in radians
    seconds: float
    margin: Margin | None = None  # the margin the plan claims to keep

    @property
    def pushes(self) -> tuple[PushCheck, ...]:
        return tuple(p for m in self.moves for p in m.pushes)

    @property
    def segments(self) -> tuple[Push | Transit | Transfer, ...]:
        return tuple(s for m in self.moves for s in m.segments)

    @property
    def supports(self) -> tuple[SupportDistribution, ...]:
        """The one part's distributions."""
        return self.supports_of[self.scene.part().name]

    @property
    def tolerance(self) -> tuple[float, float]:
        """Position (m) and angle (rad) beyond which a run of the one part slips."""
        return self.relative_tolerance * self.scene.slider.radius, self.relative_tolerance

    @property
    def drift(self) -> tuple[float, float]:
        """Worst CF distance (m) and angle (rad) of a move's chained end from the plan's."""
        return (max((m.drift[0] for m in self.moves), default=0.0), max((m.drift[1] for m in self.moves), default=0.0))

    @property
    def passed(self) -> bool:
        """No run of any push slipped, no move meets another part, and no pusher goes through a part."""
        return all(m.passed for m in self.moves)

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
        footprint = self.scene.part(check.part).slider.polygon
        return np.array([simulate_push(self.supports_of[check.part][run], check.contacts, s.twist, t, dt=dt,
                                       footprint=footprint, start_pose=s.start).final_pose
                         if t > 0 else s.start for t in np.asarray(times, dtype=float)])

    def lines(self) -> list[str]:
        """A line per segment, in plan order, numbered from 1 (``plan --verify`` prints them, then
        :meth:`summary`); with several parts, each move's segments after a line on the move.

        A transit or a transfer has nothing to simulate and :func:`verify` refuses a plan whose
        transits and transfers do not join up; its line shows where the pusher goes, and whether it
        goes through a part on the way.
        """
        segments, pushes = self.segments, iter(self.pushes)
        totals, seen = Counter(map(type, segments)), Counter()
        out = []
        for k, move in enumerate(self.moves, 1):
            if len(self.scene.parts) > 1:  # a part alone has no other part to meet
                clear = f"meets {', '.join(move.met)}: FAILED" if move.met else "clear of the other parts"
                out.append(f"move {k}/{len(self.moves)} ({move.move.part}): {clear}")
            for s, crossed in zip(move.segments, move.crossed):
                seen[type(s)] += 1
                count = f"{seen[type(s)]}/{totals[type(s)]}"
                way = f"the pusher goes through {self._parts(crossed)}: FAILED" if crossed else "ok"
                if isinstance(s, Push):
                    text = self._push_line(count, next(pushes))
                elif isinstance(s, Transit):
                    text = (f"transit {count} (edge {s.from_edge} -> {s.to_edge}, {s.mode}, {s.duration:.3f} s): "
                            f"part still, flush on both edges: {way}")
                else:
                    text = (f"transfer {count} ({s.from_part} -> {s.to_part} edge {s.to_edge}, {s.mode}, "
                            f"{s.duration:.3f} s): parts still, flush on both: {way}")
                # The plan's own numbering, as --simulate and the CSV use.
                out.append(f"segment {sum(seen.values())}/{len(segments)}: {text}")
        return out

    def _parts(self, names: tuple[str, ...]) -> str:
        """How a line names parts: "the part" when the scene has one."""
        return "the part" if len(self.scene.parts) == 1 else ", ".join(names)

    def _push_line(self, count: str, p: PushCheck) -> str:
        """The verdict on push ``count`` (``k/n``) and what its runs did."""
        runs = len(p.results)
        stuck = sum(r.sticks for r in p.results)
        stopped = {s: sum(r.status == s for r in p.results) for s in ("separated", "slid_off_edge", "no_solution")}
        notes = [f"{stuck}/{runs} stick"] + [f"{c} {s.replace('_', ' ')}" for s, c in stopped.items() if c]
        if (ambiguous := sum(r.ambiguous_steps > 0 for r in p.results)):
            notes.append(f"{ambiguous} ambiguous")
        if (modes := p.non_sticking_modes()):
            notes.append(f"modes {', '.join(modes)}")
        if p.margin is not None:
            notes.append(f"margin {p.margin}")
        verdict = "ok" if p.passed else "SLIPS" if p.slipped.any() else "BELOW THE PLAN'S MARGIN"
        return (f"push {count} (edge {p.segment.edge}, {p.segment.duration:.3f} s): "
                f"worst {p.position_error.max():.2e} m, {p.angle_error.max():.2e} rad "
                f"({self.kinds[p.worst]} run {p.worst}); {', '.join(notes)}: {verdict}")

    def summary(self) -> str:
        """One line: the verdict, the distributions, the worst deviation and the chained drift; with
        several parts, the moves and the parts they meet."""
        mix = ", ".join(f"{self.kinds.count(k)} {k}" for k in dict.fromkeys(self.kinds))
        position, angle = self.worst
        pushes = f"{len(self.pushes)} push{'' if len(self.pushes) == 1 else 'es'}"
        if len(self.scene.parts) == 1:
            limits, met = f"{self.tolerance[0]:.1e} m", ""
        else:  # one tolerance in metres per part: said relative to the part
            parts = sorted({p for m in self.moves for p in m.met})
            pushes += f" of {len(self.moves)} move{'' if len(self.moves) == 1 else 's'}"
            limits = f"{self.relative_tolerance:.1e} part radii"
            met = "; " + (f"parts met: {', '.join(parts)}" if parts else "every move clear of the other parts")
        margins = [p.margin for p in self.pushes if p.margin is not None]
        least = "" if not margins else (f"; smallest margin friction -{min(m.mu for m in margins) * 100:.0f} %, "
                                        f"CF {min(m.cf for m in margins) * 1e3:.2g} mm")
        if (below := sum(p.keeps is False for p in self.pushes)):
            least += f" ({counted(below, 'push')} below the plan's margin, {self.margin})"
        elif self.margin is not None:
            least += f" (planned: {self.margin})"
        if (through := sum(map(bool, (c for m in self.moves for c in m.crossed)))):
            least += f"; the pusher goes through {'the' if len(self.scene.parts) == 1 else 'a'} part on {counted(through, 'segment')}"
        return (f"verify: {'passed' if self.passed else 'FAILED'}: {pushes} x "
                f"{len(self.kinds)} distributions ({mix}); worst deviation {position:.2e} m, {angle:.2e} rad; "
                f"chained drift {self.drift[0]:.2e} m, {self.drift[1]:.2e} rad "
                f"(tolerance {limits}, {self.relative_tolerance:.1e} rad){least}{met}")


def _allowed_edge(part: Part, edge: int, field: str) -> None:
    """Refuse an edge the scene does not let the pusher push (a plan made for another scene)."""
    if edge not in part.edges:
        raise SceneError(field, f"edge {edge} is not one the scene lets the pusher push "
                                f"(allowed: {', '.join(map(str, part.edges))})")


def _off(part: Part, pose: ArrayLike, expected: ArrayLike) -> bool:
    """``pose`` is not ``expected`` to :data:`TOLERANCE` (in part radii and radians): the same
    pose but for rounding, as in a plan file written with full precision."""
    gap = np.asarray(pose, dtype=float) - expected
    return bool(np.hypot(gap[0], gap[1]) > TOLERANCE * part.slider.radius or abs(wrap_angle(gap[2])) > TOLERANCE)


def _contacts(part: Part, pusher: Pusher, segment: Push, name: str) -> tuple[Contact, ...]:
    """The scene's flat pusher on ``segment``'s edge, after checking the segment is for this part."""
    slider, edge = part.slider, segment.edge
    _allowed_edge(part, edge, f"{name}.edge")
    expected = slider.contact(edge, pusher.width)
    miss = min(np.abs(segment.contact - expected).max(), np.abs(segment.contact[::-1] - expected).max())
    if miss > TOLERANCE * slider.radius:  # a plan made for another part or another pusher width
        raise SceneError(f"{name}.contact", f"is not where the scene's pusher touches edge {edge}: "
                                            f"{np.round(expected, 6).tolist()}")
    if segment.duration <= 0:
        raise SceneError(f"{name}.duration", "must be > 0 to be verified")
    return edge_contacts(slider, edge, pusher.mu, pusher.width)


def _check_flush(part: Part, edge: int, where: ArrayLike, pose: ArrayLike, name: str, verb: str, edge_text: str) -> None:
    """Refuse a pusher ``pose`` (``verb``: how it is on segment ``name``'s path) that is not the
    contact pose on ``part``'s ``edge`` (in words: ``edge_text``) with the part at ``where``."""
    flush = edge_contact_pose(part.slider, edge, where)
    if _off(part, pose, flush):
        raise SceneError(f"{name}.pusher_path", f"{verb} at {pose_text(pose)}, not at the contact pose on "
                                                f"{edge_text}: {pose_text(flush)}")


def _check_transit(part: Part, transit: Transit, edge: int | None, name: str, allowed: str) -> None:
    """Refuse a transit the ``transit`` option ``allowed`` does not allow, or one that does not
    leave from ``edge`` (the edge the pusher is on; None at the plan's start) and reach its own
    ``to_edge`` flush."""
    if allowed == "none" or (transit.mode == "lift" and allowed != "lift"):
        raise SceneError(f"{name}.mode", f"a {transit.mode} transit is not allowed: the transit option is {allowed!r}")
    if edge is not None and transit.from_edge != edge:
        raise SceneError(f"{name}.from_edge", f"must be {edge}, the edge the pusher is on, got {transit.from_edge}")
    for field, verb, e, pose in (("from_edge", "starts", transit.from_edge, transit.pusher_path[0]),
                                 ("to_edge", "ends", transit.to_edge, transit.pusher_path[-1])):
        _allowed_edge(part, e, f"{name}.{field}")
        _check_flush(part, e, transit.pose, pose, name, verb, f"edge {e}")


def check_solved(plan: Plan) -> None:
    """Refuse a plan that is not solved: it holds no way to the goals to check or run."""
    if not plan.solved:
        raise SceneError("plan.solved", f"is false: the plan holds no way to the goal{'s' * (len(plan.names) > 1)} "
                                        "to check or run"
                                        + (f" ({plan.reason})" if plan.reason else ""))


def placed_moves(plan: Plan) -> Iterator[tuple[Move, dict[str, np.ndarray], int]]:
    """Each move of ``plan`` with where every part stands as it begins (its start, or where its
    last move left it) and the index in :attr:`Plan.segments` of the move's first segment (after
    its transfer)."""
    poses = {n: np.asarray(p, dtype=float) for n, p in plan.starts.items()}
    first = 0
    for move in plan.moves:
        first += move.transfer is not None
        yield move, dict(poses), first
        first += len(move.segments)
        poses[move.part] = move.end


def check_chain(scene: Scene, plan: Plan, transit: str) -> list[list[tuple[Push, tuple[Contact, ...]]]]:
    """Per move, each of its pushes with the pusher's contacts for it, after checking that the
    plan's parts are the scene's and that every segment fits the scene and the ``transit`` option
    and takes over where the one before left its part and the pusher (module docstring). Errors
    name the plan's fields as its
    file does (:func:`~planner.model.plan_file.part_field`), segments by their index in
    :attr:`Plan.segments`."""
    if sorted(plan.names) != sorted(scene.names):
        raise SceneError("plan.parts", f"are {', '.join(plan.names)}, but the scene's parts are {', '.join(scene.names)}")
    for part in scene.parts:
        cf = plan.cfs.get(part.name)
        if cf is not None and np.abs(cf - part.slider.cf).max() > TOLERANCE * part.slider.radius:
            raise SceneError(part_field(plan, part.name, "cf"), f"is {np.round(cf, 6).tolist()}, but the scene's part "
                                                                f"has its CF at {np.round(part.slider.cf, 6).tolist()}: "
                                                                "a plan for another part")
    out = []
    for k, (move, poses, first) in enumerate(placed_moves(plan)):
        part, edge, after = scene.part(move.part), None, "the plan's start"
        if move.transfer is not None:
            after = f"plan.segments[{first - 1}]"
            if k == 0:
                raise SceneError(after, "a transfer must come between two parts' segments")
            before, to = plan.moves[k - 1], move.transfer.to_edge
            last = before.segments[-1].edge
            _check_flush(scene.part(before.part), last, poses[before.part], move.transfer.pusher_path[0], after,
                         "starts", f"part {before.part}'s edge {last}")
            _check_flush(part, to, poses[move.part], move.transfer.pusher_path[-1], after, "ends",
                         f"part {move.part}'s edge {to}")
            edge = to
        out.append(_check_move(part, scene.pusher, move.segments, poses[move.part], edge, first, after, transit))
    return out


def _check_move(part: Part, pusher: Pusher, segments: list[Push | Transit], pose: np.ndarray, edge: int | None,
                first: int, after: str, transit: str) -> list[tuple[Push, tuple[Contact, ...]]]:
    """:func:`check_chain` of one move's ``segments`` (plan segments ``first`` on), ``part`` at
    ``pose`` and the pusher on ``edge`` (None: anywhere) as ``after`` left them, with the
    ``transit`` option."""
    out = []
    for k, segment in enumerate(segments, first):
        name = f"plan.segments[{k}]"
        # A transit's pose is not in the file (it is the previous end), so only a plan built in
        # memory can get it wrong; then the segment as a whole is at fault.
        if _off(part, segment.start, pose):
            raise SceneError(name if isinstance(segment, Transit) else f"{name}.start",
                             f"the part is at {pose_text(segment.start)}, not where {after} left it: "
                             f"{pose_text(pose)}")
        if isinstance(segment, Transit):
            _check_transit(part, segment, edge, name, transit)
        else:
            if edge is not None and segment.edge != edge:
                raise SceneError(f"{name}.edge", f"must be {edge}, the edge the pusher is on after {after} "
                                                 f"(a change of edge needs a transit), got {segment.edge}")
            out.append((segment, _contacts(part, pusher, segment, name)))
        pose, edge, after = segment.end, segment.edge, name
    return out


def _deviation(slider: Slider, simulated: np.ndarray, planned: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """CF distance and wrapped angle between simulated poses ``(n, 3)`` and a planned pose."""
    cf = slider.cf[None]
    gap = np.array([transform_points(cf, q)[0] for q in simulated]) - transform_points(cf, planned)[0]
    return np.linalg.norm(gap, axis=1), np.abs(wrap_angle(simulated[:, 2] - planned[2]))


def _meets(scene: Scene, move: Move, poses: dict[str, np.ndarray], other: str) -> bool:
    """Whether a push or transit of ``move`` is not clear of part ``other`` at its pose in ``poses``."""
    # The part alone in the way, and no arm: the arm's reach is fit's business.
    only = replace(scene.move_scene(move.part, poses, others=False), obstacles=(scene.body(other, poses[other]),),
                   robot=None, heights=())
    model = collision_model(only, move.segments)
    return not all(is_clear(only, model, s) for s in move.segments)


def _goes_through(scene: Scene, segment: Transit | Transfer, name: str, pose: np.ndarray) -> bool:
    """Whether ``segment``'s pusher, on the table, reaches deeper than :data:`REACH_IN` of its
    radius into part ``name`` standing at ``pose`` (module docstring)."""
    part = scene.part(name)
    depth = REACH_IN * part.slider.radius
    inner = scene.body(name, pose).buffer(-depth)
    if inner.is_empty:  # a part thinner than the room left for rounding: nothing to go through
        return False
    # Walls are the file check's business (planner.execution.fit): kept far off, they cannot be
    # mistaken for the part.
    path = np.asarray(segment.pusher_path, dtype=float)[:, :2]
    low, high = np.minimum(path.min(axis=0), inner.bounds[:2]), np.maximum(path.max(axis=0), inner.bounds[2:])
    room = 1.0 + scene.pusher.width + scene.pusher.depth
    alone = replace(scene.move_scene(name, {**scene.starts, name: pose}, others=False),
                    obstacles=tuple(getattr(inner, "geoms", (inner,))), robot=None, heights=(),
                    workspace=tuple(float(v) for v in (*(low - room), *(high + room))))
    model = CollisionModel(alone, [])
    return not all(model.pusher_move_is_free(a, b, depth / 2) for a, b in in_plane_moves(segment))


def _crossings(scene: Scene, move: Move, poses: dict[str, np.ndarray]) -> tuple[tuple[str, ...], ...]:
    """Per segment of ``move`` (its transfer first), the parts its pusher goes through, every part
    where it stands then: ``poses`` as the move begins, its own part where each transit has it."""
    out, standing = [], dict(poses)
    for segment in [move.transfer] * (move.transfer is not None) + list(move.segments):
        if isinstance(segment, Transit):
            standing[move.part] = segment.pose
        out.append(() if isinstance(segment, Push) else
                   tuple(n for n in scene.names if _goes_through(scene, segment, n, standing[n])))
    return tuple(out)


def verify(scene: Scene, plan: Plan, n: int = 200, seed: int = 1, tolerance: float = TOLERANCE, *,
           transit: str = DEFAULT_TRANSIT, regions: str = DEFAULT_REGIONS) -> Verification:
    """Re-simulate every push of ``plan`` under ``n`` support distributions of its part, and sweep
    every move against the other parts (module docstring); certify each push's own stability
    margin, and check that it lies in the ``regions`` of the margin the plan claims
    (:mod:`planner.actions.margins`).

    Parameters
    ----------
    scene : Scene
        The scene the plan is for: parts, CFs, pusher width and friction.
    plan : Plan
        The plan, from :func:`planner.plan` or :func:`planner.load_plan`, of any number of parts.
    n : int
        Number of support distributions of each part (see :func:`distributions`), >= 1.
    seed : int
        Seed of the random distributions.
    tolerance : float
        Relative tolerance: positions in part radii, angles in radians.
    transit : str
        The ``transit`` option the plan was made with: the modes its transits may use.
    regions : str
        The ``regions`` option it was made with (``'exact'`` or ``'stable'``).

    Returns
    -------
    Verification

    Raises
    ------
    SceneError
        If the plan is not solved, or is for other parts, or a segment does not fit the scene (an
        edge the scene does not allow, a contact off its edge, a push of no duration, a lift where
        ``transit`` keeps the pusher on the table) or does not take over where the one before it
        left its part and the pusher (module docstring), naming the plan field.
    SceneError
        If ``n`` is not 1 to :data:`MAX_DISTRIBUTIONS` (naming ``verify``).

    Examples
    --------
    >>> from planner import load_scene, plan
    >>> scene = load_scene("scenes/battery.yaml")
    >>> check = verify(scene, plan(scene, seed=1), n=4)
    >>> check.passed, len(check.pushes), check.worst[0] < 1e-12
    (True, 1, True)
    """
    check_solved(plan)
    contacts = check_chain(scene, plan, transit)
    clock = time.perf_counter()
    own = iter((plan if plan.margins else with_margins(scene, plan)).margins)
    claimed = plan.margin is not None and not plan.margin.exact
    kept = iter(keeps(scene, plan, plan.margin, regions) if claimed else [])
    supports_of, kinds = {}, []
    for part in scene.names:
        supports, kinds = distributions(scene.move_scene(part, scene.starts, others=False), n, seed)
        supports_of[part] = tuple(supports)
    moves = []
    for (move, poses, _), pushes in zip(placed_moves(plan), contacts):
        part = scene.part(move.part)
        limits = (tolerance * part.slider.radius, tolerance)
        checks = []
        chained = np.tile(move.start, (n, 1))  # transits leave it be: the part stands still
        for segment, fingers in pushes:
            results = tuple(simulate_push(s, fingers, segment.twist, segment.duration, footprint=part.slider.polygon,
                                          start_pose=segment.start) for s in supports_of[move.part])
            ends = np.array([r.final_pose for r in results])
            checks.append(PushCheck(segment, move.part, fingers, results, *_deviation(part.slider, ends, segment.end),
                                    limits, next(own), next(kept) if claimed else None))
            # chained * (start^-1 end): each run's own relative motion, from where it got to.
            chained = exp_twist(chained, log_pose(segment.start, ends))
        drift = _deviation(part.slider, chained, move.end)
        met = tuple(other for other in scene.names if other != move.part and _meets(scene, move, poses, other))
        moves.append(MoveCheck(move, tuple(checks), (float(drift[0].max()), float(drift[1].max())), met,
                               _crossings(scene, move, poses)))
    return Verification(scene, tuple(moves), supports_of, tuple(kinds), tolerance, time.perf_counter() - clock,
                        plan.margin)
