"""Whole plans run closed-loop in MuJoCo: the parts observed, the plan tracked and re-planned.

The MuJoCo model and the perturbations are those of the open-loop runs
(:mod:`.mujoco_sim`): the part moved first starts where ``start_error`` puts it, the bumps knock
parts, and the pusher begins behind the first contact. Here the pusher follows a
:class:`~.tracker.Tracker`: every ``1 / OBSERVE_HZ`` seconds of simulated time the part's pose,
with Gaussian noise of the given deviations, is handed to it, and the pusher is set before every
step to where the tracker has it (stopped while the tracker waits for the part to settle, then
along the approach to the new plan's first contact and the new plan). While the tracker re-plans,
simulated time goes on as the wall clock did (the re-plan's latency), the pusher held still: the
new plan begins after it, as on a robot. So a run is repeatable up to those waits, which differ
from one run to the next by milliseconds with the part at rest.

**Several parts.** A plan of several parts is followed move by move, each move tracked as a plan
of one part is: by a tracker on the move's one-part session (the part among the others where the
plan has them, :meth:`~planner.queries.session.Planner.move_session`), which takes the part to
the move's end (its goal, or the buffer pose it is left at for a later move). Every part is
observed, each with noise of its own. The moves left are re-planned when the move's tracker is
done or gives up, or when a part not being moved is observed off where the plan has it (beyond
the tracker's position and heading thresholds for that observation's noise,
:meth:`.tracker.Tracker.threshold_at`, on :data:`~.tracker.CONFIRM` observations in a row: it
was knocked or shoved): the pusher is held still, :data:`~.tracker.SETTLE` observations of every
part at rest are averaged (where a part is hidden, the pusher first backs off to look, and the
run gives up once a part has gone unseen for :data:`~.tracker.LOST_PATIENCE` s), and a fresh
session of the scene, every part's start at its mean (parts in their goals stay, as the search
leaves them), plans the moves left; the re-plan's latency runs on the
simulated clock as a tracker's does. The new plan's first move begins from where the pusher is:
from another part by a transfer as the planner makes them
(:class:`~planner.search.transfer.TransferPaths`, the parts where they are observed), from the
same part (or where no transfer is found) by the tracker's approach. Re-plans a move's end did
not ask for count against the tracker's :data:`~.tracker.BUDGET`.

**Observers.** The truth observer hands the loop MuJoCo's pose of every part with Gaussian noise,
:data:`OBSERVE_HZ` times a second. The camera observer (``observe='camera'``) never reads them: it
takes depth images with the scene's camera (its ``camera:`` block, or the default camera of the
workspace) at the camera's frame rate, finds the parts in them
(:class:`.camera_observer.CameraObserver`) and hands each image's estimates to the loop the
camera's latency after the image was taken, to be compared with the plan at the time it was
taken. A part not seen (a lost track) stops the pusher while the camera looks again
(:meth:`.tracker.Tracker.unseen`). MuJoCo's poses at the images' times are kept beside the
estimates, only to say how far off they were (:class:`Seen`) and to draw them in the recording
(:class:`Image`, with some of the depth images, downsampled).

A run ends when every part is observed at rest in its goal (one part: the tracker is done), when
it gives up (the tracker, for one part; no plan of the moves left, or the budget spent, for
several), or after :data:`PATIENCE` times the first plan's duration plus :data:`GRACE` seconds.
Whether it passed is judged on the parts' true poses: every part in its goal, no contact that
must not happen (:meth:`.mujoco_sim.World.faults`: a part against another part, a wall or an
obstacle, or the pusher against a part other than the one it moves and, on its way to that
one, the one it leaves), not given up.
"""

from __future__ import annotations

import math
import time
from collections import deque
from collections.abc import Collection, Mapping
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from mechanics import pose_error, wrap_angle

from ..actions.transit import edge_contact_pose
from ..model.camera import Camera, read_camera
from ..model.fields import SceneError, counted
from ..model.plan import Plan
from ..model.scene import Scene
from ..model.segments import Transit
from ..perception.estimation import Estimate
from ..queries.session import Planner
from .approach import first_edge, lead_in_pose
from .camera_observer import CameraObserver
from .mujoco_sim import (SETTLE, TABLE_MU, ByPart, Feet, Runs, World, _one, _worst, foot_sets, needs_mujoco,
                         perturbations, write_mjcf)
from .tracker import BUDGET, CONFIRM, LOST_PATIENCE, BackOff, Replan, Tracker, look_back, mean_pose
from .tracker import SETTLE as AT_REST  # observations of the parts at rest (mujoco_sim's SETTLE is seconds)
from .trajectory import RATE, Trajectory

if TYPE_CHECKING:  # mink is loaded only for an arm
    from ..arm.reach import ArmReach
    from .arm_sim import SimArm

__all__ = ["DEPTH_HZ", "DEPTH_STEP", "GRACE", "OBSERVERS", "OBSERVE_HZ", "PATIENCE", "ClosedLoop", "ClosedRun", "Image",
           "Seen", "closed_loop"]

#: Observations per second of simulated time (the truth observer; a camera has its own rate).
OBSERVE_HZ = 20.0
#: What observes the parts: MuJoCo's poses with Gaussian noise, or the scene's camera.
OBSERVERS = ("truth", "camera")
#: A run is stopped after this many times the first plan's duration plus this many seconds.
PATIENCE, GRACE = 3.0, 20.0
#: The camera's depth images kept for the recording: about this many a second, and of each the
#: middle pixel of every square this many pixels a side (a sixteenth of the pixels, in whole
#: millimetres: 51 kB an image at 848 x 480), so that a minute's images take a few megabytes.
DEPTH_HZ, DEPTH_STEP = 2.0, 4


@dataclass(frozen=True)
class ClosedRun(ByPart):
    """One closed-loop run, each part on one foot set of its own: each part's true final pose
    against its goal (distance, angle) and whether it is within tolerance, the re-plans
    (:class:`~.tracker.Replan`: the trackers', and for several parts the re-plans of the moves
    left, whose ``start`` is the pose of the part that asked for it and ``plan`` the new plan of
    the scene) and the times it went on without one (:attr:`~.tracker.Tracker.carried`), why it
    gave up (empty if it did not), samples at which a contact that must not happen was on and
    those contacts in words with when each was first seen, wall and simulated seconds, the
    pusher's executed path (a :class:`~.trajectory.Trajectory` at :data:`~.trajectory.RATE` Hz)
    and each part's true pose at each of its samples.

    ``feet`` and ``part`` (the poses) are the one part's, for a run of one part; ``goal_error``
    the part's farthest off, for any run."""

    supports: dict[str, Feet]
    goal_errors: dict[str, tuple[float, float]]
    delivered: dict[str, bool]
    replans: tuple[Replan, ...]
    reason: str
    collisions: int
    seconds: float
    simulated: float
    executed: Trajectory
    tracks: dict[str, np.ndarray]
    carried: tuple[tuple[float, str], ...] = ()
    faults: tuple[tuple[float, str], ...] = ()
    seen: "Seen | None" = None  # how well the camera saw the parts (None: the truth observer)

    @property
    def part(self) -> np.ndarray:
        """:attr:`poses` (the one part's), as the recording reads them."""
        return self.poses

    @property
    def passed(self) -> bool:
        return self.in_goal and not self.collisions and not self.reason

    @property
    def latencies(self) -> list[float]:
        return [r.latency for r in self.replans]

    def line(self, k: int, n: int) -> str:
        """The run's line, numbered ``k`` of ``n``; with several parts it names the part its goal
        error is of, the parts that miss their goals and the first contacts that must not happen."""
        several = len(self.supports) > 1
        missed = ", ".join(name for name, ok in self.delivered.items() if not ok)
        touches = "; ".join(f"{what} at {t:.1f} s" for t, what in self.faults[:3])
        faults = ([] if self.in_goal else [f"misses the goal{': ' + missed if several else ''}"]) + (
            [f"collides ({self.collisions} samples{': ' + touches if several else ''})"] if self.collisions else []) + (
            [f"gave up: {self.reason}"] if self.reason else [])
        latency = (f" (latency median {np.median(self.latencies) * 1e3:.0f} ms, max {max(self.latencies) * 1e3:.0f} ms;"
                   f" triggered by {'; '.join(_trigger(r) for r in self.replans)})" if self.replans else "")
        kinds = ", ".join(sorted({f.kind for f in self.supports.values()}))
        worst = f" ({_worst(self.goal_errors)})" if several else ""
        return (f"closed loop {k}/{n} ({kinds}, {'+'.join(str(len(f.points)) for f in self.supports.values())} feet): "
                f"goal error {self.goal_error[0]:.2e} m, {self.goal_error[1]:.2e} rad{worst}; "
                f"{counted(len(self.replans), 're-plan')}{latency}; {_carried(self.carried)}"
                f"{'' if self.seen is None else self.seen.text() + '; '}"
                f"{self.seconds:.1f} s for {self.simulated:.1f} s: {', '.join(faults) if faults else 'ok'}")


@dataclass(frozen=True)
class Image:
    """One image of a run's camera, as the recording shows it: when it was taken (``taken``, s on
    the run's clock), each part's estimate from it and MuJoCo's pose of the part then (``truth``),
    and, for about :data:`DEPTH_HZ` images a second, the depth image at the middle pixel of each
    square of :data:`DEPTH_STEP` pixels, in mm (``depth``; 0: no return or no ray cast; None for the
    other images)."""

    taken: float
    estimates: dict[str, Estimate]
    truth: dict[str, np.ndarray]
    depth: np.ndarray | None = None


@dataclass(frozen=True)
class Seen:
    """How well a camera saw the parts in a run: each estimate's distance (m) and heading difference
    (rad) from MuJoCo's pose at the time its image was taken (``errors``, ``(n, 2)``), the seconds
    of images in which some part was lost (``lost``), and every image taken (``images``), with
    the ``camera`` that took them."""

    errors: np.ndarray
    lost: float
    camera: Camera | None = None
    images: tuple[Image, ...] = ()

    def text(self) -> str:
        """The camera's part of a run's line: the errors' median, 95th percentile and worst."""
        if not len(self.errors):
            return f"camera: no estimate, lost {self.lost:.1f} s"
        mm, deg = self.errors[:, 0] * 1e3, np.degrees(self.errors[:, 1])
        return (f"camera: {len(self.errors)} estimates off by {np.median(mm):.2f}/{np.percentile(mm, 95):.2f}/"
                f"{mm.max():.2f} mm, {np.median(deg):.2f}/{np.percentile(deg, 95):.2f}/{deg.max():.2f} deg "
                f"(median/p95/worst), lost {self.lost:.1f} s")


def _carried(carried: tuple[tuple[float, str], ...]) -> str:
    """The times the loop went on with its plan for want of a new one, if any."""
    if not carried:
        return ""
    return f"went on with the plan {len(carried)} time{'s' if len(carried) > 1 else ''} for want of a re-plan (first at t={carried[0][0]:.2f} s: {carried[0][1]}); "


def _trigger(replan: Replan) -> str:
    x, y, theta = replan.trigger
    return f"t={replan.time:.2f} s part at ({x:.4f}, {y:.4f}, {math.degrees(theta):.1f} deg): {replan.why}"


@dataclass(frozen=True)
class ClosedLoop(Runs):
    """Outcome of :func:`closed_loop`: one :class:`ClosedRun` per foot set."""

    runs: tuple[ClosedRun, ...]
    mu: float
    starts: dict[str, np.ndarray]  # where the parts were placed: the first moved by any start error
    arm: "SimArm | None" = None  # the arm that held the pusher (arm_sim), for a scene with a robot

    @property
    def start(self) -> np.ndarray:
        """Where the one part was placed, for a run of one part."""
        return _one(self.starts)

    def summary(self) -> str:
        latencies = [x for r in self.runs for x in r.latencies]
        timing = (f", re-plan latency median {np.median(latencies) * 1e3:.0f} ms, max {max(latencies) * 1e3:.0f} ms"
                  if latencies else "")
        # Rounded to what a perturbation is given to (0.1 mm, 0.01 degree): not float noise.
        placed = "; ".join(f"{'the part' if len(self.starts) == 1 else name} started at ({pose[0]:.4f}, "
                           f"{pose[1]:.4f}, {math.degrees(pose[2]):.2f} deg)" for name, pose in self.starts.items())
        goal = "in the goal" if len(self.starts) == 1 else "with every part in its goal"
        return (f"closed loop: {'passed' if self.passed else 'FAILED'}: {sum(r.passed for r in self.runs)}/"
                f"{len(self.runs)} runs {goal} without collision (MuJoCo, pusher mu {self.mu:g}, table mu "
                f"{TABLE_MU:g}); {counted(sum(len(r.replans) for r in self.runs), 're-plan')}{timing}; worst goal error "
                f"{max(r.goal_error[0] for r in self.runs):.2e} m; {placed}; {sum(r.seconds for r in self.runs):.1f} s")

    def write_mjcf(self, path: str | Path, scene: Scene) -> None:
        """Write the first run's model, the parts where they were placed (:func:`.mujoco_sim.mjcf`)."""
        write_mjcf(path, scene, self.runs[0].supports, self.mu, self.starts, arm=self.arm)

    def executed_files(self, name: str) -> list[str]:
        """The executed paths' file names, one per run: ``<name>.executed.csv`` for the first (the
        name scripts read), ``<name>.executed-<k>.csv`` for run ``k`` >= 2 (its number in :meth:`lines`)."""
        return [f"{name}.executed{'' if k == 1 else f'-{k}'}.csv" for k in range(1, len(self.runs) + 1)]

    def write_executed(self, folder: str | Path, name: str) -> None:
        """Write each run's executed pusher path as CSV into ``folder`` (the trajectory CSV's
        columns; :meth:`executed_files`)."""
        for run, file in zip(self.runs, self.executed_files(name)):
            run.executed.write_csv(Path(folder) / file)


class _Loop:
    """What a run's pusher follows (module docstring): the tracker of the move under way, and for
    a scene of several parts the re-plans of the moves left.

    ``session`` is the session of the scene run, ``plan`` its plan; the first move begins with
    the pusher behind its first contact (:func:`.approach.lead_in_pose`). :meth:`pusher_at` says
    where the pusher is at any time, :meth:`observe` takes every part's observed pose."""

    def __init__(self, session: Planner, plan: Plan, noise: tuple[float, float], seed: int | None):
        self.session, self.plan, self.scene = session, plan, session.scene
        self.noise, self.seed = noise, seed
        self.reason, self.done = "", False
        self._past: list[Replan] = []  # the re-plans of the trackers before this one, and of the moves left
        self._carried: list[tuple[float, str]] = []
        self._spent = 0  # re-plans of the moves left that no move's end asked for
        self._held: tuple[np.ndarray, float] | None = None  # the pusher held still while the moves left are re-planned
        self._looking: BackOff | None = None  # backing off to look at a part hidden while held
        self._unseen: float | None = None  # since when some part has not been seen while held
        self._window: list[dict[str, np.ndarray]] = []  # every part's observations since
        self._trigger: tuple[str, np.ndarray, tuple[float, float], str, bool] | None = None
        self._strikes: dict[str, int] = {}
        self._left: str | None = None  # the part the pusher leaves for this move's, until it pushes
        session, lone, goal = self._move()
        self._seen = lone.start  # the moving part's last observed pose
        self.tracker = Tracker(session, lone, pusher=lead_in_pose(session.scene, session.model, lone), noise=noise,
                               seed=seed, goal=goal)

    @property
    def moving(self) -> str:
        """The part of the move under way."""
        return self.tracker.plan.part

    @property
    def replans(self) -> list[Replan]:
        return [*self._past, *self.tracker.replans]

    @property
    def carried(self) -> list[tuple[float, str]]:
        return [*self._carried, *self.tracker.carried]

    @property
    def allowed(self) -> set[str]:
        """The parts the pusher may touch now."""
        return {self.moving} if self._left is None else {self.moving, self._left}

    def _move(self) -> tuple[Planner, Plan, np.ndarray | None]:
        """The session the plan's first move is tracked on, the move as a plan of its part, and the
        pose it takes the part to where that is not the part's goal (a buffer). A plan of one part
        is its own move, on the session given."""
        if len(self.scene.parts) == 1:
            return self.session, self.plan, None
        lone = self.plan.move_plan()
        goal = None if self.scene.delivered(lone.part, lone.final) else lone.final
        return self.session.move_session(lone.part, self.plan.starts), lone, goal

    def pusher_at(self, now: float) -> tuple[np.ndarray, float, np.ndarray, bool]:
        """:meth:`.tracker.Tracker.pusher_at` of the tracker, or the pusher held still."""
        if self._held is not None:
            pose, height = self._held
            if self._backing_off(now):
                moving, rate = self._looking.at(now)
                return moving, height, rate, False
            return pose.copy(), height, np.zeros(4), False
        return self.tracker.pusher_at(now)

    def _backing_off(self, now: float) -> bool:
        return self._looking is not None and self._looking.moving(now)

    def observe(self, now: float, seen: dict[str, np.ndarray], taken: float | None = None,
                lost: Mapping[str, str] | None = None, hidden: Collection[str] = (),
                covariances: Mapping[str, np.ndarray] | None = None) -> bool:
        """Take every part's observed pose at ``now``, of the parts as they were at ``taken``
        (default: ``now``; a camera's latency before), with their ``covariances`` (a camera's
        estimates'; default: the configured noise's), and the parts not seen with why (``lost``,
        those of them ``hidden`` partly seen: :meth:`.tracker.Tracker.unseen`; a part not seen is
        not judged); whether the run has ended."""
        lost = lost or {}
        if self._held is not None:
            return self._at_rest(now, seen, lost, hidden)
        if self.moving in lost:
            command = self.tracker.unseen(now, lost[self.moving], self.moving in hidden)
        else:
            command = self.tracker.observe(now, seen[self.moving], taken, (covariances or {}).get(self.moving))
            self._seen = seen[self.moving]
        if command.contact:
            self._left = None
        if command.kind.ended:
            if len(self.scene.parts) == 1:  # the tracker's end is the run's
                self.done, self.reason = self.tracker.done, self.tracker.reason
                return True
            done = self.tracker.done
            why = f"{self.moving}'s move is done" if done else f"gave up on {self.moving}: {self.tracker.reason}"
            self._hold(now, self.moving, self._seen, command.error, why, not done)
            return False
        for name, pose in seen.items():
            if name == self.moving:
                continue
            planned = self.plan.starts[name]  # where the plan has it until it is moved
            error = pose_error(pose, planned)
            limit = self.tracker.threshold_at(now, (covariances or {}).get(name))  # the estimate's own noise too
            beyond = error[0] > limit[0] or error[1] > limit[1]
            self._strikes[name] = self._strikes.get(name, 0) + 1 if beyond else 0
            if self._strikes[name] >= CONFIRM:
                why = f"{name} is off the plan by {error[0] * 1000:.1f} mm, {math.degrees(error[1]):.1f} deg"
                self._hold(now, name, pose, error, why, True)
                break
        return False

    def _hold(self, now: float, name: str, pose: np.ndarray, error: tuple[float, float], why: str,
              counted: bool) -> None:
        """Hold the pusher where it is and observe the parts at rest before re-planning the moves
        left, because of part ``name`` observed at ``pose`` (``counted`` against the budget)."""
        pusher, height, _, _ = self.tracker.pusher_at(now)
        self._held, self._window, self._looking, self._unseen = (pusher, height), [], None, None
        self._trigger = (name, pose, error, why, counted)

    def _at_rest(self, now: float, seen: dict[str, np.ndarray], lost: Mapping[str, str], hidden: Collection[str]) -> bool:
        """Observe the parts at rest while held (:meth:`_hold`), then re-plan; whether the run has
        ended. The mean needs every part seen: where one is hidden (under the arm's hand, say),
        the pusher first backs off to look, as a tracker does (:func:`.tracker.look_back`), and
        the run gives up once a part has not been seen for :data:`~.tracker.LOST_PATIENCE` s."""
        if self._backing_off(now):
            return False
        if not lost:
            self._unseen = None
            self._window.append(seen)
            if len(self._window) >= AT_REST:
                self._replan(now)
            return self.done or bool(self.reason)
        self._window = []
        if self._looking is None and set(lost) & set(hidden):
            pose, height = self._held
            self._looking = look_back(self.tracker.scene, self.tracker.session.model, pose, now)
            if self._looking is not None:
                self._held, self._unseen = (self._looking.end, height), None
                return False
        self._unseen = now if self._unseen is None else self._unseen
        if now - self._unseen >= LOST_PATIENCE:
            self.reason = (f"lost track of {', '.join(sorted(lost))} for {now - self._unseen:.1f} s while re-planning "
                           f"the moves left: {'; '.join(lost[n] for n in sorted(lost))}")
            return True
        return False

    def _replan(self, now: float) -> None:
        """Re-plan the moves left from the parts' mean poses and begin the new plan's first move
        (module docstring); or end the run: every part in its goal, or given up."""
        clock = time.perf_counter()
        means = {name: mean_pose([seen[name] for seen in self._window]) for name in self.scene.names}
        name, trigger, error, why, counted = self._trigger
        if all(self.scene.delivered(n, pose) for n, pose in means.items()):
            self.done = True
            return
        self._spent += counted
        if self._spent > BUDGET:
            self.reason = f"the re-plan budget ({BUDGET}) is spent: {why}"
            return
        observed = replace(self.scene, parts=tuple(replace(p, start=means[p.name]) for p in self.scene.parts))
        session = Planner(observed, self.session.options)
        found = session.plan(seed=self.seed)
        if not found.solved:
            self.reason = f"no plan of the moves left ({why}): {found.reason}"
            return
        left, pusher = self.moving, self._held[0]
        self.session, self.plan = session, found
        mover, lone, goal = self._move()
        way = None
        if lone.part != left:
            edge = first_edge(lone)
            reach = edge_contact_pose(observed.part(lone.part).slider, edge, lone.start)
            way = session.paths.find(means, left, pusher, lone.part, edge, reach, self.seed)
        latency = time.perf_counter() - clock  # the plan and its transfer: the pusher waits for both
        if way is not None:
            # The transfer as the new plan's way in: the tracker follows it as it does its approaches.
            lone = lone.with_segments([Transit(way.to_edge, way.to_edge, way.mode, way.pusher_path, way.duration,
                                               lone.start), *lone.segments])
        try:
            tracker = Tracker(mover, lone, pusher=None if way is not None else pusher, time=now + latency,
                              noise=self.noise, seed=self.seed, goal=goal, height=0.0 if way is not None else self._held[1])
        except SceneError as err:
            self.reason = f"no way for the pusher from {left} to {lone.part}: {err.problem}"
            return
        self._past += [*self.tracker.replans, Replan(now, means[name], trigger, error, why, latency, found,
                                                     observed.pusher.mu)]
        self._carried += self.tracker.carried
        self.tracker, self._held, self._strikes, self._seen, self._looking = tracker, None, {}, lone.start, None
        self._left = left if lone.part != left else None


class _ArmDriver:
    """The arm's servos' reference in a closed loop (module docstring, "With a robot"): at each
    sample, the pose the loop asks of the pusher, reached from the posture of the sample before
    (:meth:`planner.arm.reach.ArmReach.follow`, as the joints file's samples are); linear in between,
    at the rate that gets it there."""

    def __init__(self, reach: "ArmReach", start: np.ndarray):
        self.reach = reach
        self.times, self.postures = (0.0, 0.0), (start, start)
        self.rate = np.zeros_like(start)

    def advance(self, u: float, pose: np.ndarray, height: float) -> None:
        """Reach the pusher's pose ``pose`` at ``height`` for time ``u``, the next sample's."""
        before, now = self.postures[1], self.times[1]
        posture, _ = self.reach.follow(pose, before, height, u - now)
        self.times, self.postures, self.rate = (now, u), (before, posture), (posture - before) / (u - now)

    def __call__(self, u: float) -> tuple[np.ndarray, np.ndarray]:
        (t0, t1), (q0, q1) = self.times, self.postures
        share = 1.0 if t1 <= t0 else min(max((u - t0) / (t1 - t0), 0.0), 1.0)
        return q0 + share * (q1 - q0), self.rate


def _after_first_move(plan: Plan, motion: Trajectory) -> float:
    """Seconds of ``motion``, the trajectory of ``plan``, after its first move (the later moves,
    with their transfers): 0 for a plan of one move."""
    later = motion.segment >= len(plan.moves[0].segments)  # the first move has no transfer
    return motion.duration - float(motion.t[later][0]) if later.any() else 0.0


def _run(session: Planner, plan: Plan, supports: dict[str, Feet], mu: float | None, starts: dict[str, np.ndarray],
         bumps: tuple, noise: np.ndarray, rng: np.random.Generator, seed: int | None, later: float,
         camera: Camera | None = None, arm: "SimArm | None" = None) -> ClosedRun:
    """One run of :func:`closed_loop`, each part on its ``supports`` and placed at ``starts``;
    ``later`` is how long the plan runs after its first move (:func:`_after_first_move`). With
    ``camera``, the parts are observed through it (:class:`.camera_observer.CameraObserver`, at
    its frame rate, each image in hand its latency after it was taken); else as MuJoCo has them,
    with Gaussian ``noise``. With ``arm`` (a scene with a robot), the arm holds the pusher and
    follows the loop's pusher (:class:`_ArmDriver`)."""
    scene = session.scene
    clock = time.perf_counter()
    world = World(scene, supports, mu, starts, bumps, arm)
    loop = _Loop(session, plan, (float(noise[0]), float(noise[1])), seed)
    limit = PATIENCE * (loop.tracker.motion.duration + later) + GRACE

    def free(u: float) -> tuple[list[float], list[float]]:
        pose, height, rate, _ = loop.pusher_at(u)
        return [pose[0], pose[1], height, pose[2]], [rate[0], rate[1], rate[3], rate[2]]

    if arm is None:
        pusher, joints = free, None
    else:
        from ..arm.reach import ArmReach  # loads mink: only for an arm

        pusher = joints = _ArmDriver(ArmReach(scene.robot), arm.q[0])

    eye = None if camera is None else CameraObserver(world, scene, camera, plan.starts, rng)
    every = max(1, round(RATE / OBSERVE_HZ))
    frames: deque[tuple[float, Image]] = deque()  # the camera's images taken and not yet in hand, and when they will be
    images: list[Image] = []
    keep = max(1, round(camera.rate / DEPTH_HZ)) if camera is not None else 1  # the images whose depth is kept
    shots, errors, lost_time = 0, [], 0.0  # images taken; the k-th at the first sample at or after k / rate
    rows, moving, collisions, faults, k = [], [], 0, {}, 0
    while True:
        u = k / RATE
        # Where the loop has the pusher at the sample: the loop changes only when it observes, below.
        pose, height, rate, contact = loop.pusher_at(u)
        if joints is not None and k > 0:
            joints.advance(u, pose, height)
        world.step_to(SETTLE + u, pusher)
        parts = np.ravel([world.pose(n) for n in scene.names])
        rows.append([u, *pose, *rate[:3], height, contact, len(loop.replans), *parts])
        moving.append(loop.moving)
        now = world.faults(loop.allowed)
        collisions += bool(now)
        for fault in now:
            faults.setdefault(fault, u)
        if world.diverged:  # nothing real is left to observe: the run fails, saying why
            break
        ended = False
        if eye is None and k % every == 0:
            seen = {n: world.pose(n) + rng.normal(0.0, [noise[0], noise[0], noise[1]]) for n in scene.names}
            ended = loop.observe(u, seen)
        if eye is not None and u >= shots / camera.rate - 1e-9:
            found = eye.look()
            # The middle pixel of each square of DEPTH_STEP: never one of the table plane's lattice, which would
            # speckle the picture.
            middle = slice(DEPTH_STEP // 2, None, DEPTH_STEP)
            depth = np.round(eye.image[middle, middle] * 1e3).astype(np.uint16) if shots % keep == 0 else None
            # The truth is kept beside the estimates to judge them, never handed to the loop.
            images.append(Image(u, found, {n: world.pose(n) for n in scene.names}, depth))
            frames.append((u + camera.latency, images[-1]))
            shots += 1
        while frames and frames[0][0] <= u + 1e-9 and not ended:
            _, image = frames.popleft()
            found = image.estimates
            tracked = {n: e for n, e in found.items() if e.tracked}
            errors += [pose_error(e.pose, image.truth[n]) for n, e in tracked.items()]
            lost = {n: e.lost for n, e in found.items() if not e.tracked}
            lost_time += 1 / camera.rate if lost else 0.0
            hidden = {n for n, e in found.items() if e.hidden}
            ended = loop.observe(u, {n: e.pose for n, e in tracked.items()}, image.taken, lost, hidden,
                                 {n: e.covariance for n, e in tracked.items()})
            if loop.moving in hidden:  # pushed blind: it is looked for where the plan has it next
                eye.priors[loop.moving] = loop.tracker.planned(u)
        if ended or u > limit:
            break
        k += 1
    table = np.array(rows)
    table[:, 3] = wrap_angle(table[:, 3])
    executed = Trajectory(*table[:, :8].T, table[:, 8].astype(int), table[:, 9].astype(int),
                          part=np.array(moving) if len(scene.parts) > 1 else None)
    tracks = {n: table[:, 10 + 3 * j:13 + 3 * j] for j, n in enumerate(scene.names)}
    ends = {n: world.pose(n) for n in scene.names}
    reason = world.diverged or loop.reason or ("" if loop.done else f"not done after {limit:.0f} s")
    seen = None if camera is None else Seen(np.array(errors).reshape(-1, 2), lost_time, camera, tuple(images))
    return ClosedRun(dict(supports), {n: pose_error(end, scene.part(n).goal) for n, end in ends.items()},
                     {n: scene.delivered(n, end) for n, end in ends.items()}, tuple(loop.replans), reason, collisions,
                     time.perf_counter() - clock, float(table[-1, 0]), executed, tracks, tuple(loop.carried),
                     tuple((t, what) for what, t in faults.items()), seen)


def closed_loop(session: Planner, plan: Plan, n: int = 3, seed: int = 1, mu: float | None = None,
                cf_offset: ArrayLike = (0.0, 0.0), start_error: ArrayLike = (0.0, 0.0, 0.0), bumps: ArrayLike = (),
                noise: ArrayLike = (0.0, 0.0), observe: str = "truth") -> ClosedLoop:
    """Run ``plan``, of one part or several, closed-loop in MuJoCo once per foot set: run ``k``
    puts every part on the ``k``-th of its own :func:`.mujoco_sim.feet` (module docstring),
    re-planning with ``session`` (its scene is the one run; for several parts, its move sessions
    track the first plan's first move).

    ``seed`` draws the foot sets, the observation noise and the re-plans; the perturbations are
    :func:`.mujoco_sim.perturbations`' (``noise``: ``(sigma_m, sigma_rad)``). ``observe`` is
    ``'truth'`` (MuJoCo's poses with that noise) or ``'camera'`` (the scene's camera, or the
    default camera of its workspace, and the pose estimator: module docstring, "Observers").

    Raises
    ------
    SceneError
        As :func:`.mujoco_sim.simulate`, and naming ``pose_noise`` or ``observe``.
    """
    needs_mujoco()
    scene = session.scene
    if observe not in OBSERVERS:
        raise SceneError("observe", f"must be one of {', '.join(OBSERVERS)}, got {observe!r}")
    camera = None if observe == "truth" else scene.camera or read_camera(None, scene.workspace)
    sets = foot_sets(scene, n, seed, cf_offset)
    held = None
    if scene.robot is None:
        setup = perturbations(scene, plan, session.model, start_error, bumps, noise)
    else:
        from .arm_sim import sim_arm  # loads mink: only for an arm
        from .arm_timing import arm_trajectory

        motion, joints = arm_trajectory(scene, plan)
        setup = perturbations(scene, plan, session.model, start_error, bumps, noise, motion=motion)
        held = sim_arm(scene.robot, setup.lead, setup.motion, joints)
    rng = np.random.default_rng(seed)
    sigma = np.asarray(noise, dtype=float)
    later = _after_first_move(plan, setup.motion)
    runs = tuple(_run(session, plan, s, mu, setup.starts, setup.bumps, sigma, rng, seed, later, camera, held)
                 for s in sets)
    return ClosedLoop(runs, scene.pusher.mu if mu is None else mu, setup.starts, held)
