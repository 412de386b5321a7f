"""Closing the loop: a plan followed against timed observations of the part, re-planned when the
part is not where the plan expects it.

A :class:`Tracker` is what a robot program runs beside its perception: it holds the plan being
executed as a trajectory of the pusher (:func:`.trajectory.trajectory`, with the approach to the
first contact in front, :func:`.approach.approach`) and the part's planned pose along it
(:func:`.trajectory.planned_part`). :meth:`Tracker.pusher_at` says where the pusher should be at
any time; :meth:`Tracker.observe` takes an observed part pose and says what to do.

**When to re-plan.** The part's observed pose is compared with the planned one at the same time:
the distance ``e`` of the slider frame's origins and the wrapped heading difference ``phi``. A lost
contact shows the same way (the part stays behind while the plan moves on). It is off the plan
when one of three thresholds (:meth:`Tracker.threshold_at`) is passed:

* ``e`` or ``|phi|`` beyond half the goal tolerance: a stable push funnels smaller errors away
  (open loop in MuJoCo, parts started up to a centimetre off mostly end inside the 1 cm
  tolerance, ``python -m planner.bench.closed_loop``), and a plan joined from the observed pose
  is only as good as that observation;
* the *sweep* ``e + R |phi|`` (``R`` the part's farthest point from its origin: no point of the
  part is farther than that from where the plan has it) beyond :data:`ROOM` of the room ahead:
  the least clearance the planned part keeps from the walls, the obstacles and the other parts
  (:meth:`~planner.world.validity.CollisionModel.part_clearance`) from now until it has swept
  ``R`` further. Ahead, because a deviation is carried along by the pushes into the tight places
  that follow: caught while the part still has room (as the pusher lifts over to another face),
  it is re-planned from; caught in the tight place, there may be no plan from there (the pusher
  needs room flush on a face) and the pusher can only go on. Where the plan keeps more than
  ``(e + R |phi|) / ROOM`` at half the tolerance (1.2 cm for narrow_junction's block) the first
  rule is the stricter. The rest of the room is for what the part strays while the deviation
  is confirmed (below) and the pusher stops: two observation periods (0.1 s at 20 Hz; a
  camera's two frames and its latency, about 0.12 s at 30 Hz and 50 ms). A plan keeps at least a
  fortieth of the part's radius (:func:`~planner.actions.controls.clearance_margin`), so the
  sweep's threshold is never below an eightieth of it, 0.73 mm for narrow_junction's 10 x 6 cm
  block, twenty times what an unperturbed run strays from its plan in MuJoCo (0.03 mm), and the
  other half is as much: in narrow_junction's runs with half the friction or the centre of
  pressure 5 mm off, the sweep grew by at most 3.4 mm/s, 0.4 mm in 0.12 s. The pusher is not
  counted: it follows the plan whatever the part does;
* each never below :data:`SIGMAS` standard deviations of the observation (the sweep's: the
  position's plus ``R`` times the heading's), from the observer's configured noise (the truth
  observer) or from each estimate's covariance (a camera; the position's along its worst axis):
  a tight corridor must not make the loop chase noise. Noise alone passes 3 sigma in one
  observation with probability 0.011 for the position (Rayleigh, ``exp(-9/2)``) and 0.0027 for
  the heading, and the sweep only where one of them does (0.014 in all); :data:`CONFIRM` (3)
  observations in a row, independent, with probability 3e-6: about one stop for nothing in 300
  runs of a minute at 20 Hz, and such a stop costs a re-plan of tens of milliseconds, not the
  run. (A camera's covariance is on the safe side: ``docs/camera.md``, "Accuracy".)

An observation beyond them counts only when :data:`CONFIRM` consecutive ones are (a debounce:
one outlier of the perception does not stop the robot). Then the pusher stops where it is
(``'stop'`` commands) and the tracker takes :data:`SETTLE` more observations of the part at rest;
their mean (the noise down by ``sqrt(SETTLE)``) is where it re-plans from, with the planner
session, which joins that pose to the plan it remembers for the goal in milliseconds
(:meth:`planner.Planner.plan`). At the plan's end the same mean decides: in the goal tolerance,
``'done'``; else a re-plan.

**Re-planning** asks first for a plan whose first push is on the edge the pusher is at (if it
can come back to it), then for one beginning on an edge it has a free approach to; from the
observed pose, the pusher needs only the room every push keeps
(``Planner.plan(observed=True)``). The new plan begins when the planning is done (the
observation's time plus the planning's wall-clock time, :attr:`Replan.latency`): a robot that
gets it that much later finds the pusher at its beginning, held still until then.

**Friction.** A push that does not stick is what a pusher with less friction than planned
shows: the part drifts off the plan while it is pushed, still against the pusher's face. So a
deviation confirmed while the plan pushes, with the part within the position threshold of the
pusher's body, that grew gradually (no observation's error differs from the one before by as
much as the thresholds, as a knock's does), is taken for slip: the re-plan, and those after it,
assume :data:`FRICTION_STEP` times the friction the last plan assumed (a session of its own), down
to :data:`FRICTION_FLOOR` times the planned. Sticking at a lower friction implies sticking at any
higher one, so a plan for too low a friction still holds; it is only more cautious.

**Squaring.** When the planner finds no plan from the observed pose, or the pusher has no free
approach to any edge, the part is often turned off the plan in a narrow corridor: it leaves no
room for the pusher flush on any face, or for the margin a plan keeps from the walls. A flat
pusher that meets a part askew turns it flush against itself, and pushing one face moves it
towards the wall while it turns, the opposite face away from it (:mod:`.squaring`). So where the
part is turned off the plan's heading (where the pusher stopped) by more than the heading
threshold, the pusher is driven straight, at that heading, to the contact of the part as
:func:`.squaring.squared` predicts it once flush, on the face that leaves it most room (its
sweep and the pusher flush at the end keeping the margin a push keeps, and the way there free,
:func:`.approach.approach`); deviations are not counted on the way; at the end the part is
observed at rest and re-planned from as after a deviation. It counts as a re-plan (a plan of one
transit, planner ``'squaring'``).

**Going on.** Where no face can be squared either, the pusher goes on with the plan it has, from
where it stopped: a flat pusher that meets a part askew turns it flush and funnels its error
(open loop in MuJoCo), after which a plan may exist. Deviations are not looked at until the
pusher has moved the part's radius on along the plan (or the plan ends); then the loop looks
again. Each time counts against the budget.

**Lost track.** A camera may not see the part (the pusher or the arm hides it, or it left the
view): the perception then says so (:meth:`Tracker.unseen`) instead of giving a pose. Where the
part is *hidden* (some of its outline is seen where it was expected, too little to fix its pose)
and was last seen on the plan (within the thresholds), the pusher goes on blind: a stable push
carries the part whatever its support and friction (that is what the plan was chosen for), a part
waiting for the pusher stays where it is, and the part is judged again at the next observation,
or when the plan ends (whether it is in its goal needs it seen). A single observation beyond the
thresholds does not stop that (the debounce: only :data:`CONFIRM` in a row make a deviation).
Otherwise (not seen at all, or a deviation confirmed) the pusher stops and the tracker looks
again; where the part is hidden it stops backed off along its own -x by up to :data:`LOOK_BACK`
(as far as the walls and obstacles let it, at the pusher's cruising speed), so that what hides
the part (the pusher, the arm's hand over it) moves out of the way; once the part is seen again it is observed at rest as after a deviation and
re-planned from, since it may have moved while unseen. Seen by no observation for
:data:`LOST_PATIENCE` seconds while stopped, the tracker gives up. (An arm between an overhead
camera and the part hides it for most of a push and of the approach to it: holding still does
not help there, going on does.)

**Giving up.** When the goal is certified unreachable from the observed pose
(:meth:`planner.Planner.certify_unreachable`), when no plan is found from where the plan has
ended, or when the re-plans and the goings-on exceed the budget, the tracker gives up with the
reason and holds the pusher where it is.

Times are the caller's clock (seconds, increasing); poses ``(x, y, theta)`` in metres and radians.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace
from enum import StrEnum

import numpy as np
import shapely
from numpy.typing import ArrayLike

from mechanics import pose_error, wrap_angle

from ..actions.controls import clearance_margin
from ..actions.transit import backed_off
from ..model.bodies import pusher_frame_body, slider_at
from ..model.fields import SceneError, poses
from ..model.plan import Plan
from ..model.scene import Scene
from ..model.segments import Transit
from ..queries.session import Planner
from ..world.validity import CollisionModel
from .approach import approach, first_edge, free_back_off
from .squaring import squared
from .trajectory import LIFT_HEIGHT, MAX_SPEED, Trajectory, planned_part, trajectory

__all__ = ["BUDGET", "CONFIRM", "FRICTION_FLOOR", "FRICTION_STEP", "LOOK_BACK", "LOST_PATIENCE", "REPLAN_LIMIT", "FRACTION",
           "ROOM", "SETTLE", "SIGMAS",
           "Action", "BackOff", "Command", "Replan", "Tracker", "look_back", "mean_pose"]

#: Thresholds: this fraction of the goal tolerance, and at least this many deviations of the
#: observation (module docstring, "When to re-plan").
FRACTION, SIGMAS = 0.5, 3.0
#: The share of the planned part's clearance a deviation may sweep before it counts (module docstring).
ROOM = 0.5
#: Consecutive observations beyond the thresholds that make a deviation (the debounce).
CONFIRM = 3
#: Observations of the part at rest averaged before a re-plan or the final check.
SETTLE = 5
#: Longest time, s, the part may go unseen before the tracker gives up (module docstring, "Lost track").
LOST_PATIENCE = 3.0
#: How far the pusher backs off to look at a part hidden when it stops, m (module docstring,
#: "Lost track"): beyond the arm's hand over the pusher from an overhead camera's view.
LOOK_BACK = 0.1
#: Re-plans allowed in one run.
BUDGET = 8
#: Default time limit of a re-plan's search, s: a robot waits that long at most (a join to the
#: remembered plan takes tens of milliseconds; a search on the shipped scenes well under a second).
REPLAN_LIMIT = 2.0
#: After slip, a re-plan assumes this times the friction the last plan assumed, and never less
#: than the floor times the planned (three halvings).
FRICTION_STEP, FRICTION_FLOOR = 0.5, 0.125


class Action(StrEnum):
    """What a :class:`Command` tells the pusher to do (a string too: ``Action.STOP == 'stop'``)."""

    FOLLOW = "follow"  # go on along the plan
    STOP = "stop"  # hold still while the part is observed at rest
    REPLAN = "replan"  # the command's plan is the new plan: the pusher now approaches its first contact
    DONE = "done"  # the part is in the goal
    GIVE_UP = "give_up"  # the command's reason says why

    @property
    def ended(self) -> bool:
        """No command will follow this one but itself."""
        return self in (Action.DONE, Action.GIVE_UP)


@dataclass(frozen=True)
class Command:
    """What the pusher should do after an observation.

    ``kind``: an :class:`Action`.
    ``pusher`` is where the pusher frame should be now ``(x, y, theta)``, ``height`` its height
    above the table (a lift's flight), ``contact`` whether it should be pushing, ``error`` the
    observed part's distance (m) and heading difference (rad) from its planned pose."""

    kind: Action
    pusher: np.ndarray
    height: float
    contact: bool
    error: tuple[float, float]
    plan: Plan | None = None
    reason: str = ""


@dataclass(frozen=True)
class Replan:
    """One re-plan: when (the caller's clock), from which observed pose (the mean of the settled
    observations), what triggered it (``trigger``: the observation that confirmed the deviation,
    and its error), how long the planning took (s), what it gave and the pusher friction it
    assumed."""

    time: float
    start: np.ndarray
    trigger: np.ndarray
    error: tuple[float, float]
    why: str
    latency: float
    plan: Plan
    mu: float


@dataclass(frozen=True)
class BackOff:
    """The pusher backing straight off to look at a part it hides (:func:`look_back`): from
    ``start`` at time ``began`` (the caller's clock) to ``end`` in ``duration`` seconds, a half
    cosine in time, at rest at both ends, at most pi / 2 times the mean speed on the way.

    Half way through 10 cm in 2 s: 5 cm on, at pi / 2 times 5 cm/s:

    >>> move = BackOff(0.0, np.zeros(3), np.array([0.1, 0.0, 0.0]), 2.0)
    >>> pose, rate = move.at(1.0)
    >>> pose.round(12).tolist(), rate.round(12).tolist()
    ([0.05, 0.0, 0.0], [0.07853981634, 0.0, 0.0, 0.0])
    """

    began: float
    start: np.ndarray
    end: np.ndarray
    duration: float

    def moving(self, now: float) -> bool:
        """Whether the pusher is still on its way at ``now``: the look begins when it stops."""
        return now < self.began + self.duration

    def at(self, now: float) -> tuple[np.ndarray, np.ndarray]:
        """The pusher's pose and velocity ``(vx, vy, omega, vz)`` at ``now``."""
        phase = math.pi * min(max((now - self.began) / self.duration, 0.0), 1.0)
        share, pace = (1 - math.cos(phase)) / 2, math.pi * math.sin(phase) / (2 * self.duration)
        way = self.end - self.start
        return self.start + share * way, np.array([*(pace * way[:2]), pace * way[2], 0.0])


def look_back(scene: Scene, model: CollisionModel, pose: np.ndarray, now: float) -> BackOff | None:
    """The pusher stopped at ``pose`` backing off from ``now`` to look at a part it hides: along its
    own -x, up to :data:`LOOK_BACK` where the way is free (halving down to the transits' standoff,
    :func:`.approach.free_back_off`), at the pusher's cruising speed; None if it cannot back off."""
    distance = free_back_off(scene, model, pose, LOOK_BACK)
    return None if distance is None else BackOff(now, pose, backed_off(pose, distance), 2 * distance / MAX_SPEED)


def mean_pose(rows: ArrayLike) -> np.ndarray:
    """The mean of poses ``(x, y, theta)``: positions averaged, headings by their unit vectors.

    >>> mean_pose([[0.0, 0.0, math.pi - 0.1], [1.0, 2.0, -math.pi + 0.1]]).round(12).tolist()
    [0.5, 1.0, -3.14159265359]
    """
    rows = np.asarray(rows, dtype=float)
    heading = math.atan2(float(np.sin(rows[:, 2]).mean()), float(np.cos(rows[:, 2]).mean()))
    return np.array([*rows[:, :2].mean(axis=0), float(wrap_angle(heading))])


class Tracker:
    """Follows ``plan`` (solved, for ``session``'s scene) against observations of the part
    (module docstring).

    Parameters
    ----------
    session : Planner
        The planning session of the scene: re-plans and certificates come from it.
    plan : Plan
        The plan to execute, from where the part is believed to be.
    pusher : (3,) array_like
        Where the pusher frame is when the run begins (the tracker approaches the first contact
        from there); default: on the first contact.
    time : float
        The caller's clock when the run begins.
    noise : (float, float)
        Standard deviations of the observations: position (m, per axis) and heading (rad), where
        an observation comes without a covariance (:meth:`observe`).
    confirm, settle, budget : int
        :data:`CONFIRM`, :data:`SETTLE`, :data:`BUDGET`.
    seed : int, optional
        The re-plans' seed (default: the session's).
    time_limit : float
        Each re-plan's search time limit, s (:data:`REPLAN_LIMIT`).
    goal : (3,) array_like, optional
        Where the part is taken (default: the scene's goal): a move of a scene of several parts
        may leave its part aside, at a buffer pose, for a later move.
    height : float
        How high above the table the pusher is at ``pusher`` (> 0: stopped on a lift's flight, it
        is brought down at the standoff pose, not where it is).

    Raises
    ------
    SceneError
        Naming the argument at fault.

    Examples
    --------
    >>> from planner import load_scene
    >>> session = Planner(load_scene("scenes/battery.yaml"))
    >>> tracker = Tracker(session, session.plan(seed=1))
    >>> str(tracker.observe(0.0, session.scene.start).kind), tracker.replans
    ('follow', [])
    """

    def __init__(self, session: Planner, plan: Plan, *, pusher: ArrayLike | None = None, time: float = 0.0,
                 noise: tuple[float, float] = (0.0, 0.0), confirm: int = CONFIRM, settle: int = SETTLE,
                 budget: int = BUDGET, seed: int | None = None, time_limit: float = REPLAN_LIMIT,
                 goal: ArrayLike | None = None, height: float = 0.0):
        if not isinstance(session, Planner):
            raise SceneError("session", f"must be a Planner, got {type(session).__name__}")
        if not (isinstance(plan, Plan) and plan.solved and plan.segments):
            raise SceneError("plan", "must be a solved plan with at least one segment")
        if not (len(noise) == 2 and all(0 <= float(v) < math.inf for v in noise)):
            raise SceneError("noise", f"must be two finite standard deviations >= 0, got {noise}")
        for name, value in (("confirm", confirm), ("settle", settle), ("budget", budget)):
            if not (isinstance(value, int) and value >= (0 if name == "budget" else 1)):
                raise SceneError(name, f"must be an integer >= {0 if name == 'budget' else 1}, got {value!r}")
        self.session, self.scene = session, session.scene
        scene = self.scene
        self.noise = (float(noise[0]), float(noise[1]))
        self._reach = float(np.linalg.norm(scene.slider.hull, axis=1).max())  # R of the module docstring
        #: Position (m) and heading (rad) thresholds for the configured noise (:meth:`threshold_at`;
        #: near walls the sweep's is stricter).
        self.threshold = self._raised(self.noise)
        if not 0 < float(time_limit) < math.inf:
            raise SceneError("time_limit", f"must be a positive number of seconds, got {time_limit}")
        self.confirm, self.settle, self.budget, self.seed = confirm, settle, budget, seed
        #: Where the part is taken; None: the scene's goal (the session's plans and certificates default to it).
        self.goal = None if goal is None else self._pose(goal, "goal")
        self.time_limit = min(float(time_limit), session.options.time_limit)
        #: The re-plans so far.
        self.replans: list[Replan] = []
        #: When no plan was found and the pusher went on with the one it had, and why: ``(time, reason)``.
        self.carried: list[tuple[float, str]] = []
        self.reason = ""  # why the tracker gave up
        self.done = False
        self._strikes, self._jump, self._last = 0, 0.0, None
        self._unseen: float | None = None  # since when the part has not been seen
        self._body = shapely.Polygon(pusher_frame_body(scene.pusher.width, scene.pusher.depth))
        self._trigger: tuple[np.ndarray, tuple[float, float], str, bool] | None = None
        self._window: list[np.ndarray] = []  # the observations since the pusher stopped
        self._held: tuple[np.ndarray, float] | None = None  # where the pusher holds still (pose, height)
        self._backing: BackOff | None = None  # backing off to look before holding there
        self._stopped = 0.0  # where on the plan's clock the pusher stopped
        self._edge = -1  # the edge the pusher was on when it stopped
        # The plan followed, from _begin: its segments (the approach first), the pusher's timed
        # motion, the part's pose expected at each sample, the pusher's heading unwrapped along
        # it, when it began on the caller's clock and until when a deviation is not counted.
        self.plan = plan
        self._segments: list = []
        self.motion: Trajectory | None = None
        self.expected = np.zeros((0, 3))
        self.ahead = np.zeros(0)  # the room ahead of each sample, m (_room_ahead)
        self._theta = np.zeros(0)
        self._since, self._quiet = float(time), 0.0
        start = self._pose(plan.start, "plan.start")
        first = self._begin(plan, self._pose(pusher, "pusher") if pusher is not None else None, start, float(time),
                            float(height))
        if first:
            raise SceneError("pusher", first)

    @staticmethod
    def _pose(value: ArrayLike, name: str) -> np.ndarray:
        rows = poses(value, name)
        if len(rows) != 1:
            raise SceneError(name, f"must be one pose (x, y, theta), got {len(rows)}")
        return rows[0]

    def _begin(self, plan: Plan, pusher: np.ndarray | None, part: np.ndarray, now: float, height: float = 0.0) -> str:
        """Follow ``plan`` from ``now``, the pusher first approaching its first contact from
        ``pusher`` (if given), ``height`` above the table; the reason if there is no free approach."""
        segments = list(plan.segments)
        if pusher is not None:
            way = self._approach(pusher, part, first_edge(plan), height)
            if way is None:
                return "no free approach from the pusher to the plan's first contact"
            segments.insert(0, way)
        self.plan, self._segments = plan, segments
        led = plan.with_segments(segments)
        self.motion = trajectory(self.scene, led)
        up = self.motion.z >= LIFT_HEIGHT - 1e-12
        if height > 0 and up.any():  # stopped in the air: it stays up until its approach's flight (approach, airborne)
            top, z = int(np.argmax(up)), self.motion.z.copy()
            z[:top] = np.maximum(z[:top], height)
            self.motion = replace(self.motion, z=z)
        self.expected = planned_part(self.scene, led, self.motion)
        self.ahead = self._room_ahead()
        self._theta = np.unwrap(self.motion.theta)
        self._since, self._quiet = now, 0.0
        self._strikes, self._held, self._last = 0, None, None
        return ""

    def _room_ahead(self) -> np.ndarray:
        """At each sample of the plan, the least clearance the planned part keeps from there until
        it has swept ``R`` further (module docstring, "When to re-plan"), m."""
        # Beyond this clearance the sweep's threshold is looser than the position's and the
        # heading's together (threshold_at): it is not worked out farther, far from everything.
        wide = FRACTION * (self.scene.tolerance_position + self._reach * self.scene.tolerance_angle) / ROOM
        model = self.session.model
        here = np.array([model.part_clearance(pose, wide) for pose in self.expected])
        step = np.diff(self.expected[:, :2], axis=0)
        swept = np.hypot(step[:, 0], step[:, 1]) + self._reach * np.abs(np.diff(np.unwrap(self.expected[:, 2])))
        travel = np.concatenate([[0.0], np.cumsum(swept)])
        ends = np.searchsorted(travel, travel + self._reach, side="right")
        return np.array([here[k:j].min() for k, j in enumerate(ends)])

    def _approach(self, pusher: np.ndarray, part: np.ndarray, edge: int, height: float = 0.0, **squaring) -> Transit | None:
        """:func:`.approach.approach` from ``pusher``, ``height`` above the table (> 0: on a lift's flight)."""
        return approach(self.scene, self.session.model, self.session.transits, pusher, part, edge,
                        list(self.session.stable_edges), airborne=height > 0, **squaring)

    def pusher_at(self, now: float) -> tuple[np.ndarray, float, np.ndarray, bool]:
        """Where the pusher frame should be at ``now``: pose ``(x, y, theta)`` (theta unwrapped along
        the plan), height, velocity ``(vx, vy, omega, vz)`` and whether it should be pushing."""
        if self._held is not None:
            pose, height = self._held
            if self._still_backing(now):
                moving, rate = self._backing.at(now)
                return moving, height, rate, False
            return pose.copy(), height, np.zeros(4), False
        m, u = self.motion, max(now - self._since, 0.0)  # before a re-plan's start: at its first sample, at rest
        column = [np.interp(u, m.t, c) for c in (m.x, m.y, self._theta, m.z, m.vx, m.vy, m.omega)]
        k = self._sample(now)
        rise = np.interp(u, m.t, np.gradient(m.z, m.t)) if len(m.t) > 1 else 0.0
        return np.array(column[:3]), float(column[3]), np.array([*column[4:], rise]), bool(m.contact[k])

    def _command(self, kind: Action, now: float, error: tuple[float, float], plan: Plan | None = None) -> Command:
        pose, height, _, contact = self.pusher_at(now)
        return Command(kind, pose, height, contact, error, plan, self.reason)

    def _stop(self, now: float) -> None:
        pose, height, _, _ = self.pusher_at(now)
        self._stopped = min(max(now - self._since, 0.0), self.motion.duration)  # on the plan's clock
        k = self._sample(now)
        self._edge = self._segments[int(self.motion.segment[k])].edge
        self._held, self._window, self._backing = (pose, height), [], None

    def _look_back(self, now: float) -> bool:
        """Back the held pusher off to look (:func:`look_back`), before holding there (module
        docstring, "Lost track"); whether it does."""
        pose, height = self._held
        self._backing = look_back(self.scene, self.session.model, pose, now)
        if self._backing is None:
            return False
        self._held = (self._backing.end, height)
        return True

    def _still_backing(self, now: float) -> bool:
        """Whether the pusher is backing off to look (:meth:`_look_back`)."""
        return self._backing is not None and self._backing.moving(now)

    def planned(self, now: float) -> np.ndarray:
        """The part's planned pose at ``now``."""
        return self.expected[self._sample(now)].copy()

    def _sample(self, now: float) -> int:
        """The plan's sample at ``now`` (the caller's clock)."""
        return self._row(now - self._since)

    def _row(self, u: float) -> int:
        """The plan's sample at ``u`` seconds on the plan's own clock."""
        return min(int(np.searchsorted(self.motion.t, u)), len(self.motion.t) - 1)

    def threshold_at(self, now: float, covariance: ArrayLike | None = None) -> tuple[float, float, float]:
        """The thresholds at ``now`` on the plan of an observation of ``covariance`` (3 x 3, m and
        rad; default: the configured noise): position (m), heading (rad) and sweep (m), module
        docstring, "When to re-plan"."""
        if covariance is None:
            sigma = self.noise
        else:
            c = np.asarray(covariance, dtype=float)
            worst = float(np.linalg.eigvalsh(c[:2, :2])[-1])  # the position's variance along its worst axis
            sigma = (math.sqrt(max(worst, 0.0)), math.sqrt(max(float(c[2, 2]), 0.0)))
        room = ROOM * float(self.ahead[self._sample(now)])
        return (*self._raised(sigma), max(room, SIGMAS * (sigma[0] + self._reach * sigma[1])))

    def _raised(self, sigma: tuple[float, float]) -> tuple[float, float]:
        """The position (m) and heading (rad) thresholds for deviations ``sigma``: half the
        tolerance, or :data:`SIGMAS` deviations."""
        return (max(FRACTION * self.scene.tolerance_position, SIGMAS * sigma[0]),
                max(FRACTION * self.scene.tolerance_angle, SIGMAS * sigma[1]))

    def error(self, now: float, pose: np.ndarray) -> tuple[float, float]:
        """The distance (m) and heading difference (rad) of ``pose`` from the part's planned pose at ``now``."""
        return pose_error(pose, self.planned(now))

    def observe(self, now: float, pose: ArrayLike, seen_at: float | None = None,
                covariance: ArrayLike | None = None) -> Command:
        """Take the part's observed pose at ``now`` and say what the pusher does (module docstring).
        ``seen_at`` is when the part was where ``pose`` says (default: ``now``): a camera's image
        is in hand its latency after it was taken, and it is compared with the plan at that time.
        ``covariance`` is the observation's (3 x 3; default: the configured noise's), which
        bounds the thresholds below (:meth:`threshold_at`).

        Raises
        ------
        SceneError
            If ``pose`` is not one finite pose.
        """
        pose = self._pose(pose, "pose")
        now = float(now)
        self._unseen = None
        seen = now if seen_at is None else float(seen_at)
        error = self.error(seen, pose)
        if self.done or self.reason:
            return self._command(Action.DONE if self.done else Action.GIVE_UP, now, error)
        if self._still_backing(now):  # the part at rest is observed once the pusher is
            return self._command(Action.STOP, now, error)
        if self._held is not None:
            self._window.append(pose)
            if len(self._window) < self.settle:
                return self._command(Action.STOP, now, error)
            return self._settled(now, mean_pose(self._window), error)
        limit = self.threshold_at(seen, covariance)
        sweep = error[0] + self._reach * error[1]
        off = error[0] > limit[0] or error[1] > limit[1] or sweep > limit[2]
        beyond = off and now - self._since >= self._quiet
        step = 0.0 if self._last is None else max(abs(a - b) / t for a, b, t in zip(error, self._last, self.threshold))
        self._strikes, self._last = self._strikes + 1 if beyond else 0, error
        self._jump = max(self._jump, step) if beyond else 0.0  # from the last observation within the thresholds on
        ended = now - self._since >= self.motion.duration
        if self._strikes >= self.confirm or ended:
            why = "the plan ended" if ended and self._strikes < self.confirm else (
                f"off the plan by {error[0] * 1000:.1f} mm, {math.degrees(error[1]):.1f} deg"
                f" (thresholds {limit[0] * 1000:.1f} mm, {math.degrees(limit[1]):.1f} deg, sweep"
                f" {sweep * 1000:.1f} of {limit[2] * 1000:.1f} mm)")
            self._trigger = (pose, error, why, self._strikes >= self.confirm and self._slid(now, pose))
            self._stop(now)
            return self._command(Action.STOP, now, error)
        return self._command(Action.FOLLOW, now, error)

    def unseen(self, now: float, why: str, hidden: bool = False) -> Command:
        """The part was not seen at ``now`` (``why``; ``hidden``: partly seen where it was expected):
        a hidden part last seen on the plan is followed blind; else the pusher stops where it is
        and the tracker looks again, giving up after :data:`LOST_PATIENCE` s unseen (module
        docstring, "Lost track")."""
        now, error = float(now), (math.nan, math.nan)
        if self.done or self.reason:
            return self._command(Action.DONE if self.done else Action.GIVE_UP, now, error)
        if (hidden and self._held is None and self._last is not None and self._strikes < self.confirm
                and now - self._since < self.motion.duration):  # the plan's end needs the part seen
            return self._command(Action.FOLLOW, now, error)  # blind (module docstring, "Lost track")
        if self._still_backing(now):
            return self._command(Action.STOP, now, error)
        self._unseen = now if self._unseen is None else self._unseen
        if now - self._unseen >= LOST_PATIENCE:
            return self._give_up(now, error, f"lost track of the part for {now - self._unseen:.1f} s: {why}")
        if self._held is None:
            self._trigger = (self.planned(now), error, f"lost track: {why}", False)
            self._stop(now)
        if hidden and self._backing is None and self._look_back(now):
            self._unseen = None  # the patience runs from the end of the backing off
        self._window = []  # the part at rest is observed anew once seen
        return self._command(Action.STOP, now, error)

    def _slid(self, now: float, pose: np.ndarray) -> bool:
        """Whether the part, observed at ``pose``, strayed as a push that does not stick makes it:
        while pushed, gradually, still against the pusher (module docstring, "Friction")."""
        pusher, _, _, contact = self.pusher_at(now)
        if not contact or self._jump >= 1.0:
            return False
        return slider_at(self.scene.slider.polygon, pose).distance(slider_at(self._body, pusher)) < self.threshold[0]

    def _lower_friction(self) -> str:
        """Re-plan from now on for less friction (module docstring, "Friction"); what to say of it."""
        mu = self.session.scene.pusher.mu * FRICTION_STEP
        if mu < FRICTION_FLOOR * self.scene.pusher.mu * (1 - 1e-9):
            return ""
        lower = self.session.with_friction(mu)
        if lower is None:  # no stable push at that friction (or no region in time): plan as before
            return ""
        self.session = lower
        return f"; it slid on the pusher: planned for pusher mu {mu:g}"

    def _settled(self, now: float, part: np.ndarray, error: tuple[float, float]) -> Command:
        """The part observed at rest at ``part`` (the mean): done, re-planned, or given up."""
        if self.scene.within_tolerance(part, self.goal):
            self.done = True
            return self._command(Action.DONE, now, error)
        if len(self.replans) + len(self.carried) >= self.budget:
            return self._give_up(now, error, f"the re-plan budget ({self.budget}) is spent")
        clock = time.perf_counter()
        trigger, trigger_error, why, slid = self._trigger
        if slid:
            why += self._lower_friction()
        certificate = self.session.certify_unreachable(self.goal, start=part)
        if certificate:
            return self._give_up(now, error, f"the goal is unreachable from the observed pose: {certificate}")
        pusher, height = self._held
        try:
            # First a plan that begins on the edge the pusher is at, so that it only has to come
            # back to the part; then one that begins on an edge the pusher can get to from there.
            found = None
            if self._approach(pusher, part, self._edge, height) is not None:
                found = self.session.plan(start=part, goal=self.goal, seed=self.seed, time_limit=self.time_limit,
                                          edges=[self._edge], observed=True)
            if found is None or not found.solved:
                others = [e for e in self.session.stable_edges if e != self._edge]
                reached = [e for e in others if self._approach(pusher, part, e, height) is not None]
                if not reached and found is None:
                    return self._carry_on(now, part, error, "no free approach from the pusher to any edge of the part", clock)
                if reached:
                    found = self.session.plan(start=part, goal=self.goal, seed=self.seed, time_limit=self.time_limit,
                                              edges=reached, observed=True)
        except SceneError as err:  # the pusher has no room at the observed pose
            return self._carry_on(now, part, error, f"no plan from the observed pose: {err.problem}", clock)
        if not found.solved or not found.segments:
            return self._carry_on(now, part, error, f"no plan from the observed pose: {found.reason or 'no segments'}", clock)
        latency = time.perf_counter() - clock
        # The new plan begins when it is there: the pusher held still until then.
        problem = self._begin(found, pusher, part, now + latency, height)
        if problem:
            self._held = (pusher, height)
            return self._give_up(now, error, problem)
        self.replans.append(Replan(now, part, trigger, trigger_error, why, latency, found, self.session.scene.pusher.mu))
        return self._command(Action.REPLAN, now, error, found)

    def _carry_on(self, now: float, part: np.ndarray, error: tuple[float, float], reason: str,
                  clock: float) -> Command:
        """No plan from where the part is, observed at ``part`` (``reason``): square it if it is
        askew (:meth:`_square`), else go on with the plan from where the pusher stopped, deaf to
        deviations until it has moved the part's radius on (module docstring, "Going on"); give
        up if the plan had ended or the budget is spent."""
        if len(self.replans) + len(self.carried) < self.budget and (squaring := self._square(now, part, reason, clock)):
            return squaring
        if self._stopped >= self.motion.duration or len(self.replans) + len(self.carried) >= self.budget:
            return self._give_up(now, error, reason)
        self.carried.append((now, reason))
        m = self.motion
        travel = np.concatenate([[0.0], np.cumsum(np.hypot(np.diff(m.x), np.diff(m.y)))])
        on = np.interp(self._stopped, m.t, travel) + self.scene.slider.radius
        self._quiet = float(np.interp(on, travel, m.t)) if on < travel[-1] else m.duration
        # It goes on once this was decided, from where it stopped.
        self._since = now + (time.perf_counter() - clock) - self._stopped
        self._held, self._strikes, self._last = None, 0, None
        return self._command(Action.FOLLOW, now, error)

    def _square(self, now: float, part: np.ndarray, reason: str, clock: float) -> Command | None:
        """Square the part observed at ``part`` turned off the plan's heading where the pusher
        stopped (module docstring, "Squaring"): drive the pusher straight at the face whose
        squared part (:func:`.squaring.squared`) keeps most room from the walls, obstacles and
        other parts, to that part's contact, deaf to deviations on the way, then observe it at
        rest and re-plan. None where the part is not turned beyond the heading threshold, or no
        face has a squared part with room for it and for the pusher flush, and a free way there."""
        heading = float(self.expected[self._row(self._stopped), 2])
        turn = abs(float(wrap_angle(part[2] - heading)))
        if turn <= self.threshold[1]:
            return None
        model, room = self.session.model, clearance_margin(self.scene)
        (pusher, height), best = self._held, None
        back = float(wrap_angle(heading - part[2]))
        for edge in self.session.stable_edges:
            square, advance = squared(self.scene.slider, part, edge, heading)
            # The part swept while it turns, and its pusher flush once square, keep the room a push keeps.
            sweep = [squared(self.scene.slider, part, edge, part[2] + u * back)[0] for u in (0.25, 0.5, 0.75)]
            if not (model.is_clear(square, edge, room) and all(model.part_clearance(p, room) > room for p in sweep)):
                continue
            way = self._approach(pusher, square, edge, height, behind=advance, actual=part)
            if way is not None:
                clear = model.part_clearance(square)
                if best is None or clear > best[0]:
                    best = (clear, edge, square, way)
        if best is None:
            return None
        _, edge, square, way = best
        latency = time.perf_counter() - clock
        plan = Plan.of_part(self.plan.part, part, square, [way], solved=True, scene=self.plan.scene,
                            planner="squaring", seed=self.seed or 0, planning_time_s=latency)
        self._begin(plan, None, part, now + latency, height)
        self._quiet = self.motion.duration  # the part turns against the pusher on the way: judged once square
        why = f"{reason}; squaring the part, {math.degrees(turn):.1f} deg askew, against edge {edge}"
        trigger, trigger_error, _, _ = self._trigger
        self.replans.append(Replan(now, part, trigger, trigger_error, why, latency, plan, self.session.scene.pusher.mu))
        return self._command(Action.REPLAN, now, (math.nan, math.nan), plan)

    def _give_up(self, now: float, error: tuple[float, float], reason: str) -> Command:
        self.reason = reason
        return self._command(Action.GIVE_UP, now, error)
