"""Whole plans run closed-loop in MuJoCo: the part observed, the plan tracked and re-planned.

The MuJoCo model and the perturbations are those of the open-loop runs
(:mod:`.mujoco_sim`): the part starts where ``start_error`` puts it, is knocked by the bumps, and
the pusher begins behind the first contact. Here the pusher follows a
:class:`~.tracker.Tracker`: every ``1 / OBSERVE_HZ`` seconds of simulated time the part's pose,
with Gaussian noise of the given deviations, is handed to it, and the pusher is set before every
step to where the tracker has it (stopped while the tracker waits for the part to settle, then
along the approach to the new plan's first contact and the new plan). While the tracker re-plans,
simulated time goes on as the wall clock did (the re-plan's latency), the pusher held still: the
new plan begins after it, as on a robot. So a run is repeatable up to those waits, which differ
from one run to the next by milliseconds with the part at rest.

A run ends when the tracker is done (the part observed at rest within the goal tolerance) or gives
up, or after :data:`PATIENCE` times the first plan's duration plus :data:`GRACE` seconds.
Whether it passed is judged on the part's true pose: in the goal, no collision, not given up.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike

from mechanics import wrap_angle

from ..model.plan import Plan
from ..model.scene import Scene
from ..queries.session import Planner
from .approach import lead_in_pose
from .mujoco_sim import SETTLE, TABLE_MU, Feet, Runs, World, feet, needs_mujoco, perturbations, write_mjcf
from .tracker import Replan, Tracker
from .trajectory import RATE, Trajectory

__all__ = ["GRACE", "OBSERVE_HZ", "PATIENCE", "ClosedLoop", "ClosedRun", "closed_loop"]

#: Observations per second of simulated time.
OBSERVE_HZ = 20.0
#: A run is stopped after this many times the first plan's duration plus this many seconds.
PATIENCE, GRACE = 3.0, 20.0


@dataclass(frozen=True)
class ClosedRun:
    """One closed-loop run on one foot set: the part's true final pose against the goal, the
    re-plans (:class:`~.tracker.Replan`) and the times it went on without one
    (:attr:`~.tracker.Tracker.carried`), why the tracker gave up (empty if it did not), samples
    of the part touching a wall or obstacle, wall and simulated seconds, the pusher's executed
    path (a :class:`~.trajectory.Trajectory` at :data:`~.trajectory.RATE` Hz) and the part's
    true pose at each of its samples."""

    feet: Feet
    goal_error: tuple[float, float]
    in_goal: bool
    replans: tuple[Replan, ...]
    reason: str
    collisions: int
    seconds: float
    simulated: float
    executed: Trajectory
    part: np.ndarray
    carried: tuple[tuple[float, str], ...] = ()

    @property
    def passed(self) -> bool:
        return self.in_goal and not self.collisions and not self.reason

    @property
    def latencies(self) -> list[float]:
        return [r.latency for r in self.replans]

    def line(self, k: int, n: int) -> str:
        faults = ([] if self.in_goal else ["misses the goal"]) + (
            [f"collides ({self.collisions} samples)"] if self.collisions else []) + (
            [f"gave up: {self.reason}"] if self.reason else [])
        latency = (f" (latency median {np.median(self.latencies) * 1e3:.0f} ms, max {max(self.latencies) * 1e3:.0f} ms;"
                   f" triggered by {'; '.join(_trigger(r) for r in self.replans)})" if self.replans else "")
        return (f"closed loop {k}/{n} ({self.feet.kind}, {len(self.feet.points)} feet): goal error "
                f"{self.goal_error[0]:.2e} m, {self.goal_error[1]:.2e} rad; {len(self.replans)} re-plans{latency}; "
                f"{_carried(self.carried)}"
                f"{self.seconds:.1f} s for {self.simulated:.1f} s: {', '.join(faults) if faults else 'ok'}")


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
    start: np.ndarray  # where the part was placed

    def summary(self) -> str:
        latencies = [x for r in self.runs for x in r.latencies]
        timing = (f", re-plan latency median {np.median(latencies) * 1e3:.0f} ms, max {max(latencies) * 1e3:.0f} ms"
                  if latencies else "")
        return (f"closed loop: {'passed' if self.passed else 'FAILED'}: {sum(r.passed for r in self.runs)}/"
                f"{len(self.runs)} runs in the goal without collision (MuJoCo, pusher mu {self.mu:g}, table mu "
                f"{TABLE_MU:g}); {sum(len(r.replans) for r in self.runs)} re-plans{timing}; worst goal error "
                f"{max(r.goal_error[0] for r in self.runs):.2e} m; the part started at ({self.start[0]:.17g}, "
                f"{self.start[1]:.17g}, {math.degrees(self.start[2]):.17g} deg); {sum(r.seconds for r in self.runs):.1f} s")

    def write_mjcf(self, path: str | Path, scene: Scene) -> None:
        """Write the first run's model, the part at its perturbed start (:func:`.mujoco_sim.mjcf`)."""
        name = scene.part().name
        write_mjcf(path, scene, {name: self.runs[0].feet}, self.mu, {name: self.start})

    def executed_files(self, name: str) -> list[str]:
        """The executed paths' file names, one per run: ``<name>.executed.csv`` for the first (the
        name scripts read), ``<name>.executed-<k>.csv`` for run ``k`` >= 2 (its number in :meth:`lines`)."""
        return [f"{name}.executed{'' if k == 1 else f'-{k}'}.csv" for k in range(1, len(self.runs) + 1)]

    def write_executed(self, folder: str | Path, name: str) -> None:
        """Write each run's executed pusher path as CSV into ``folder`` (the trajectory CSV's
        columns; :meth:`executed_files`)."""
        for run, file in zip(self.runs, self.executed_files(name)):
            run.executed.write_csv(Path(folder) / file)


def _run(session: Planner, plan: Plan, support: Feet, mu: float | None, starts: dict[str, np.ndarray], bumps: tuple,
         noise: np.ndarray, rng: np.random.Generator, lead: np.ndarray, seed: int | None) -> ClosedRun:
    scene = session.scene
    clock = time.perf_counter()
    world = World(scene, {scene.part().name: support}, mu, starts, bumps)
    tracker = Tracker(session, plan, pusher=lead, noise=(float(noise[0]), float(noise[1])), seed=seed)
    limit = PATIENCE * tracker.motion.duration + GRACE

    def pusher(u: float):
        pose, height, rate, _ = tracker.pusher_at(u)
        return [pose[0], pose[1], height, pose[2]], [rate[0], rate[1], rate[3], rate[2]]

    every = max(1, round(RATE / OBSERVE_HZ))
    rows, collisions, k = [], 0, 0
    while True:
        u = k / RATE
        world.step_to(SETTLE + u, pusher)
        pose, height, rate, contact = tracker.pusher_at(u)
        rows.append([u, *pose, *rate[:3], height, contact, len(tracker.replans), *world.pose()])
        collisions += bool(world.faults(scene.names))  # the pusher may touch the one part at any time
        if k % every == 0:
            seen = world.pose() + rng.normal(0.0, [noise[0], noise[0], noise[1]])
            if tracker.observe(u, seen).kind.ended or u > limit:
                break
        k += 1
    table = np.array(rows)
    table[:, 3] = wrap_angle(table[:, 3])
    executed = Trajectory(*table[:, :8].T, table[:, 8].astype(int), table[:, 9].astype(int))
    part = table[:, 10:13]
    end = world.pose()
    error = (math.hypot(*(end[:2] - scene.goal[:2])), abs(float(wrap_angle(end[2] - scene.goal[2]))))
    reason = tracker.reason or ("" if tracker.done else f"not done after {limit:.0f} s")
    return ClosedRun(support, error, scene.within_tolerance(end), tuple(tracker.replans), reason, collisions,
                     time.perf_counter() - clock, float(table[-1, 0]), executed, part, tuple(tracker.carried))


def closed_loop(session: Planner, plan: Plan, n: int = 3, seed: int = 1, mu: float | None = None,
                cf_offset: ArrayLike = (0.0, 0.0), start_error: ArrayLike = (0.0, 0.0, 0.0), bumps: ArrayLike = (),
                noise: ArrayLike = (0.0, 0.0)) -> ClosedLoop:
    """Run ``plan`` closed-loop in MuJoCo once per foot set of :func:`.mujoco_sim.feet`
    (module docstring), re-planning with ``session`` (its scene is the one run).

    ``seed`` draws the foot sets, the observation noise and the re-plans; the perturbations are
    :func:`.mujoco_sim.perturbations`' (``noise``: ``(sigma_m, sigma_rad)``).

    Raises
    ------
    SceneError
        As :func:`.mujoco_sim.simulate`, and naming ``pose_noise``.
    """
    needs_mujoco()
    scene = session.scene
    supports = feet(scene, n, seed, cf_offset)
    setup = perturbations(scene, plan, session.model, start_error, bumps, noise)
    lead = lead_in_pose(scene, session.model, plan)
    rng = np.random.default_rng(seed)
    sigma = np.asarray(noise, dtype=float)
    runs = tuple(_run(session, plan, s, mu, setup.starts, setup.bumps, sigma, rng, lead, seed) for s in supports)
    return ClosedLoop(runs, scene.pusher.mu if mu is None else mu, setup.starts[scene.part().name])
