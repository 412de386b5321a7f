"""Multi-part plans run open-loop in MuJoCo: every part a body on its own feet, the pusher following
the whole sequence of moves and transfers blindly.

The model is :func:`planner.execution.mujoco_sim.mjcf`'s, with every part in it (each a rigid body
on the feet of its own support distribution, moving in the plane) and the contacts that can tell
a bad plan from a good one: the pusher against every part, every part against every other part
(with the table's friction: a part shoved by another moves as it would), and every part against
the walls and obstacles. A run fails if any part ends outside its goal tolerance, if the pusher
slips on the part it pushes (:data:`~planner.execution.mujoco_sim.SLIP`, measured per push as for
one part), or if any part ever touches another part, a wall or an obstacle, or the pusher touches
a part other than the one it moves (or, on a transfer, leaves): a push that shoves a second part
is caught.

Run ``k`` gives each part the ``k``-th foot set of :func:`~planner.execution.mujoco_sim.feet` for
that part, and begins with the pusher behind the first move's first contact, moving in.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike

from mechanics import relative_pose

from ..model.bodies import convex_pieces
from ..model.files import write_atomic
from ..model.scene import Scene
from ..model.plan import Plan
from ..world.validity import CollisionModel
from .mujoco_sim import (SETTLE, SLIP, TABLE_MU, TIMESTEP, Feet, Runs, _error, _follower, _lead_in, _numbers, document,
                         feet, needs_mujoco, part_body, part_pairs, table)
from .trajectory import Trajectory, trajectory

__all__ = ["PartsRun", "PartsSimulation", "parts_mjcf", "simulate_parts"]


def parts_mjcf(scene: Scene, supports: dict[str, Feet], mu: float | None = None,
               starts: dict[str, ArrayLike] | None = None) -> str:
    """The MuJoCo model of ``scene`` with each part on its ``supports`` feet at ``starts``
    (default: the scene's), pusher-part friction ``mu`` (default: the planned ``pusher.mu``).
    Part ``k`` (scene order) is the body ``part<k>`` of geoms ``part<k>_<j>``."""
    mu = scene.pusher.mu if mu is None else mu
    starts = scene.starts if starts is None else starts
    assets, world, blocks = table(scene)
    bodies, pairs, geoms, qpos = [], [], [], []
    for k, part in enumerate(scene.parts):
        more, body, own, feet_pairs = part_body(f"part{k}", f"part{k}_", part.slider, supports[part.name])
        assets += more
        bodies.append(body)
        geoms.append(own)
        pairs += feet_pairs
        qpos += [*np.asarray(starts[part.name], dtype=float), *np.zeros(len(supports[part.name].points))]
    for k, own in enumerate(geoms):
        pairs += part_pairs(own, blocks, mu)
        # Parts against parts, with the table's friction: a part shoved by another moves as it would.
        pairs += [f'<pair geom1="{g}" geom2="{h}" condim="3" friction="{TABLE_MU} {TABLE_MU} 0 0 0"/>'
                  for g in own for other in geoms[k + 1:] for h in other]
    return document(scene, assets, world, bodies, pairs, [f'<key name="start" qpos="{_numbers([*qpos, 0, 0, 0, 0])}"/>'])


@dataclass(frozen=True)
class PartsRun:
    """One open-loop run of a multi-part plan: each part's final error against its goal (m,
    rad), the worst slip of a push (m), and the faults met: contacts that must not happen, as
    ``(first time s, what)``; a fault is reported once, at its first sample."""

    supports: dict[str, Feet]  # each part's feet
    goal_errors: dict[str, tuple[float, float]]
    in_goal: dict[str, bool]
    slip: float
    slip_segment: int  # where the worst slip was (a segment of Plan.segments, from 0), -1 if none
    faults: tuple[tuple[float, str], ...]
    seconds: float
    simulated: float
    poses: dict[str, np.ndarray]  # each part's simulated pose at every trajectory sample

    @property
    def passed(self) -> bool:
        return all(self.in_goal.values()) and self.slip <= SLIP and not self.faults

    def line(self, k: int, n: int) -> str:
        worst = max(self.goal_errors, key=lambda name: self.goal_errors[name][0])
        missed = [name for name, ok in self.in_goal.items() if not ok]
        faults = ([f"misses the goal: {', '.join(missed)}"] if missed else []) + (
            [f"SLIPS (segment {self.slip_segment + 1})"] if self.slip > SLIP else []) + [
            f"{what} at {t:.1f} s" for t, what in self.faults[:3]] + (
            [f"{len(self.faults) - 3} more faults"] if len(self.faults) > 3 else [])
        return (f"simulate {k}/{n} ({', '.join(sorted({f.kind for f in self.supports.values()}))} feet): worst goal error "
                f"{self.goal_errors[worst][0]:.2e} m ({worst}); slip {self.slip:.2e} m; {self.seconds:.1f} s for "
                f"{self.simulated:.1f} s: {'; '.join(faults) if faults else 'ok'}")


@dataclass(frozen=True)
class PartsSimulation(Runs):
    """Outcome of :func:`simulate_parts`: a :class:`PartsRun` per foot set."""

    runs: tuple[PartsRun, ...]
    mu: float
    motion: Trajectory

    def write_mjcf(self, path: str | Path, scene: Scene) -> None:
        """Write the first run's model (:func:`parts_mjcf`) to ``path`` atomically."""
        write_atomic(path, parts_mjcf(scene, self.runs[0].supports, self.mu))

    def summary(self) -> str:
        delivered = min(sum(r.in_goal.values()) for r in self.runs)
        parts = len(self.runs[0].in_goal)
        return (f"simulate: {'passed' if self.passed else 'FAILED'}: {sum(r.passed for r in self.runs)}/{len(self.runs)} "
                f"runs with every part in its goal, without slip or a touch (MuJoCo, pusher mu {self.mu:g}, table mu "
                f"{TABLE_MU:g}); at least {delivered}/{parts} parts delivered in every run; worst slip "
                f"{max(r.slip for r in self.runs):.2e} m, {sum(r.seconds for r in self.runs):.1f} s")


def simulate_parts(scene: Scene, plan: Plan, n: int = 3, seed: int = 1, mu: float | None = None,
                   cf_offset: ArrayLike = (0.0, 0.0)) -> PartsSimulation:
    """Run ``plan`` open-loop in MuJoCo once per foot set (module docstring).

    Raises
    ------
    SceneError
        If MuJoCo is missing, or ``cf_offset`` puts a part's centre of pressure off it.
    """
    needs_mujoco()
    first = plan.moves[0]
    lead_scene = scene.move_scene(first.part, scene.starts)
    lead_plan = Plan.of_part(first.part, first.start, first.end, first.segments,
                             scene=None, solved=True, planner=plan.planner, seed=plan.seed, planning_time_s=0.0)
    lead = _lead_in(lead_scene, lead_plan, CollisionModel(lead_scene, lead_scene.edges))
    motion = trajectory(scene, plan)
    sets = {p.name: feet(scene.move_scene(p.name, scene.starts), n, seed, cf_offset) for p in scene.parts}
    runs = tuple(_run(scene, plan, motion, lead, {name: s[k] for name, s in sets.items()}, mu) for k in range(n))
    return PartsSimulation(runs, scene.pusher.mu if mu is None else mu, motion)


def _run(scene: Scene, plan: Plan, motion: Trajectory, lead: Trajectory, supports: dict[str, Feet],
         mu: float | None) -> PartsRun:
    import mujoco  # only when simulating

    clock = time.perf_counter()
    model = mujoco.MjModel.from_xml_string(parts_mjcf(scene, supports, mu))
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key("start").id)
    names = scene.names
    slots = {n: model.joint(f"part{k}_x").qposadr[0] + np.arange(3) for k, n in enumerate(names)}
    owner = {model.geom(f"part{k}_{j}").id: n for k, n in enumerate(names)
             for j in range(len(convex_pieces(scene.part(n).slider.polygon)))}
    blocks = {model.geom(i).id for i in range(model.ngeom) if model.geom(i).name.startswith(("wall", "obstacle"))}
    pusher_geom = model.geom("pusher").id
    qpos = model.joint("pusher_x").qposadr[0] + np.arange(4)
    qvel = model.joint("pusher_x").dofadr[0] + np.arange(4)
    led, follow = _follower(lead), _follower(motion)
    pushed = [name for name, _ in plan.steps]
    # The pusher may touch the part of its segment, and on a transfer the part it leaves: a transit
    # or a transfer begins (and ends) in contact.
    allowed = [{name, s.from_part} if s.kind == "transfer" else {name} for name, s in plan.steps]

    def step_to(t: float) -> None:
        while data.time < t - TIMESTEP / 2:
            u = data.time - SETTLE
            pose, rate = led(max(u, 0.0)) if u < lead.duration else follow(u - lead.duration)
            data.qpos[qpos] = pose
            data.qvel[qvel] = rate if u >= 0 else 0.0
            mujoco.mj_step(model, data)

    times = motion.t + SETTLE + lead.duration
    poses = {n: np.empty((len(times), 3)) for n in names}
    slips, starts, faults, seen = np.zeros(len(plan.segments)), {}, [], set()
    step_to(SETTLE + lead.duration)
    for row, t in enumerate(times):
        step_to(t)
        for n in names:
            poses[n][row] = data.qpos[slots[n]]
        k = int(motion.segment[row])
        for c in data.contact[:data.ncon]:
            if c.dist >= 0:
                continue
            pair = {c.geom1, c.geom2}
            touched = sorted({owner[g] for g in pair if g in owner})
            if len(touched) == 2:
                fault = f"{touched[0]} touches {touched[1]}"
            elif touched and pair & blocks:
                fault = f"{touched[0]} touches a wall or obstacle"
            elif touched and pusher_geom in pair and touched[0] not in allowed[k]:
                fault = f"the pusher touches {touched[0]}"
            else:
                continue
            if fault not in seen:
                seen.add(fault)
                faults.append((float(motion.t[row]), fault))
        if motion.contact[row]:
            face = relative_pose(poses[pushed[k]][row], [motion.x[row], motion.y[row], motion.theta[row]])[:2]
            first = starts.setdefault(k, face)
            slips[k] = max(slips[k], float(np.linalg.norm(face - first)))
    errors = {n: _error(poses[n][-1], scene.part(n).goal) for n in names}
    worst = int(np.argmax(slips)) if len(slips) and slips.max() > 0 else -1
    return PartsRun(supports, errors,
                    {n: scene.delivered(n, poses[n][-1]) for n in names}, float(slips.max(initial=0.0)), worst,
                    tuple(faults), time.perf_counter() - clock, float(motion.duration + lead.duration), poses)

