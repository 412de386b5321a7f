"""Time-parameterised pusher trajectories: the plan's pusher path with a jerk-limited time law.

A plan (:class:`~planner.model.plan.Plan`) says where the pusher goes, not when. Here the
pusher frame (:func:`planner.model.bodies.pusher_frame_body`: origin at the middle of the face,
x along the push) follows the planned path *exactly* and a time law ``s(t)`` says how fast:

* a push is a constant body twist, so the part's pose is ``start * exp(twist * s)`` for a path
  parameter ``s in [0, duration]``, and the pusher frame's pose is
  :func:`planner.actions.transit.edge_contact_pose` of that pose;
* each piece between two consecutive poses of a transit's ``pusher_path`` is the linear
  interpolation ``p0 + u (p1 - p0)`` of ``(x, y, theta)`` (theta the shorter way),
  ``u in [0, 1]``. A lift's airborne piece is flown at ``z = LIFT_HEIGHT``: the pusher rises
  straight up at the retreat pose, flies, and comes straight down at the approach pose, each a
  piece of its own. Rising while turning away would swing the face's ends into the part it
  just left (they are a standoff from it, and move ``width / 2`` per radian): in MuJoCo the
  narrow_junction lift nudged the part by 1.7 mm and 1.5 degrees that way.

**Rest to rest.** The pusher stops wherever the twist or the edge changes: every segment, and
every piece of a transit, begins and ends at rest. That is the simplest choice that is sound:
between pieces the path has a corner (a push's twist changes at once, a transit's polyline
bends), which a pusher at speed could follow only with an unbounded acceleration. Each piece's
time law is ruckig's time-optimal jerk-limited profile from ``s = 0`` to its length with zero
velocity and acceleration at both ends.

**Limits for every point of the pusher body.** A body point ``P(s)`` moves at ``dP/ds * s'``
and accelerates at ``dP/ds * s'' + d2P/ds2 * s'^2`` (tangential plus centripetal). Speeds and
accelerations are convex in the point, so the outline's corners bound the whole body. Per piece,
``speed`` is the largest ``|dP/ds|`` and ``bend`` the largest ``|d2P/ds2|`` over its corners (and
over ``s``): for a push turning at ``|omega|`` per unit ``s`` about a COR, ``speed`` is the
farthest corner's ``|omega| r`` (``|v|`` for a translation) and ``bend = |omega| speed``; for a
transit piece of step ``(dx, dy, dtheta)``, ``speed <= |dxy| + |dtheta| reach`` and ``bend =
dtheta^2 reach`` (``reach`` the farthest corner from the origin); a lift's rise or descent of
``H`` has ``speed = H`` and no bend. Then the 1-DOF limits on ``s`` (:func:`path_limits`)

* ``v = min(max_speed / speed, sqrt(max_accel / (2 bend)))``: the speed limit, and the
  centripetal part held to at most half the acceleration budget;
* ``a = (max_accel - bend v^2) / speed``: the rest of the budget, tangential (so that
  ``speed |s''| + bend s'^2 <= max_accel``, a bound on the sum, hence on the vector);
* ``j = max_jerk / speed``: the tangential jerk of the farthest corner (the centripetal
  term's rate of change is not bounded by it).

**Defaults** are slow enough for quasi-static pushing, the mechanics every plan relies on: the
part's inertial force ``m a`` must be negligible against the support friction ``mu m g``, i.e.
``a << mu g`` (about 3 m/s^2 for mu = 0.3); 0.5 m/s^2 is a sixth of that, and 0.05 m/s with
5 m/s^3 keeps the speed-up to a centimetre and a few tenths of a second.
"""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import NamedTuple

import numpy as np
import ruckig

from mechanics import Slider, compose, exp_twist, inverse, point_velocity, transform_points, wrap_angle

from ..actions.transit import AIRBORNE, edge_contact_pose, piece_times
from ..model.bodies import place, pusher_frame_body
from ..model.files import write_atomic
from ..model.plan import Plan
from ..model.segments import Push, Transfer, Transit
from ..model.scene import Pusher, Scene

__all__ = ["COLUMNS", "LIFT_HEIGHT", "MAX_ACCEL", "MAX_JERK", "MAX_SPEED", "RATE", "Trajectory", "path_limits",
           "planned_part", "trajectory"]

#: Default limits for every point of the pusher body: m/s, m/s^2, m/s^3 (quasi-static, above).
MAX_SPEED, MAX_ACCEL, MAX_JERK = 0.05, 0.5, 5.0
#: Default sampling rate, Hz.
RATE = 100.0
#: Top of a lift's flight above the table, m: the scene gives no heights; 5 cm clears a flat part.
LIFT_HEIGHT = 0.05
#: The CSV file's header.
COLUMNS = ("t", "x", "y", "theta", "vx", "vy", "omega", "z", "contact", "segment")


@dataclass(frozen=True)
class Trajectory:
    """Samples of the pusher frame's world pose and velocity, one row per sample (columns of
    :data:`COLUMNS`): time (s), pose (m, rad, theta in ``[-pi, pi)``), velocity of the frame's
    origin and angular velocity, height above the table, 1 while pushing, the plan segment's index
    (from 0; the CSV numbers segments from 1, as every line on screen does).
    ``plan_time`` (not a CSV column; None where no plan made the samples) is where each sample is
    on the plan's own clock, the plan file's durations at 1 m/s and the recording's ``time``
    timeline: a push's path parameter, a transit's share of its duration (none for a lift's rise
    or descent, which the plan does not model).

    >>> one = Trajectory(*(np.zeros(1) for _ in COLUMNS))
    >>> one.to_csv().splitlines()
    ['t,x,y,theta,vx,vy,omega,z,contact,segment', '0,0,0,0,0,0,0,0,0,1']
    """

    t: np.ndarray
    x: np.ndarray
    y: np.ndarray
    theta: np.ndarray
    vx: np.ndarray
    vy: np.ndarray
    omega: np.ndarray
    z: np.ndarray
    contact: np.ndarray
    segment: np.ndarray
    plan_time: np.ndarray | None = field(default=None, compare=False, repr=False)
    #: Of a plan of several parts: the part each sample's segment moves, a CSV column.
    part: np.ndarray | None = field(default=None, compare=False, repr=False)

    @property
    def duration(self) -> float:
        return float(self.t[-1]) if len(self.t) else 0.0

    def to_csv(self) -> str:
        """The samples as CSV with a header row; floats round-trip (17 digits); the plan's segments
        numbered from 1, as on screen (``simulate ...: slip ... (segment 7)``)."""
        text = io.StringIO()
        columns = [self.segment + 1 if c == "segment" else getattr(self, c) for c in COLUMNS]
        table = np.column_stack(columns) if len(self.t) else np.zeros((0, len(COLUMNS)))
        table = table + 0.0  # -0.0 written as 0
        header = ",".join(COLUMNS + (("part",) if self.part is not None else ()))
        np.savetxt(text, table, fmt=["%.17g"] * 8 + ["%d"] * 2, delimiter=",", header=header, comments="")
        if self.part is None:
            return text.getvalue()
        # A part's name is a plain printable name (planner.model.scene_file), but it may hold a comma or a quote.
        lines = text.getvalue().splitlines()
        rows = io.StringIO()
        csv.writer(rows, lineterminator="\n").writerows([line.split(",") + [name] for line, name in zip(lines[1:], self.part)])
        return f"{lines[0]}\n{rows.getvalue()}"

    def write_csv(self, path: str | Path) -> None:
        """Write :meth:`to_csv` to ``path`` atomically (:func:`planner.model.files.write_atomic`)."""
        write_atomic(path, self.to_csv())


def path_limits(speed: float, bend: float, max_speed: float, max_accel: float,
                max_jerk: float) -> tuple[float, float, float]:
    """Velocity, acceleration and jerk limits on a piece's path parameter ``s`` such that no body
    point faster than ``max_speed`` or accelerating more than ``max_accel``, for a piece whose
    corners move at most ``speed`` per unit ``ds/dt`` and bend at most ``bend`` (module docstring).

    Examples
    --------
    A straight push at 1 m/s per unit ``s`` (every point alike): the body's limits themselves.

    >>> path_limits(1.0, 0.0, 0.05, 0.5, 5.0)
    (0.05, 0.5, 5.0)

    A turn about a COR 5 mm from the farthest corner (``speed = bend = 0.005`` per radian): at
    the speed limit, 10 rad/s, its centripetal acceleration would be ``0.005 * 10^2 = 0.5``, the
    whole budget; so the turn is capped at ``sqrt(0.5 / 0.01) = 7.07`` rad/s (0.035 m/s), whose
    centripetal 0.25 m/s^2 leaves 0.25 m/s^2 tangential: 50 rad/s^2.

    >>> [round(x, 3) for x in path_limits(0.005, 0.005, 0.05, 0.5, 5.0)]
    [7.071, 50.0, 1000.0]
    """
    v = max_speed / speed
    if bend > 0:
        v = min(v, math.sqrt(max_accel / (2 * bend)))
    return v, (max_accel - bend * v * v) / speed, max_jerk / speed


class _Piece(NamedTuple):
    """A stretch of the pusher's path between two rests, with ``s in [0, length]``."""

    segment: int
    pushing: bool
    length: float
    speed: float  # largest corner |dP/ds|
    bend: float  # largest corner |d2P/ds2|
    clock: float  # plan time at s = 0
    pace: float  # plan time per unit s
    at: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray, np.ndarray]]  # s -> pose, dpose/ds, z


def _push_piece(slider: Slider, index: int, push: Push, corners: np.ndarray, clock: float) -> _Piece:
    local = edge_contact_pose(slider, push.edge, np.zeros(3))  # pusher frame in the slider frame
    twist = np.asarray(push.twist, dtype=float)
    speed = float(np.linalg.norm(point_velocity(twist, transform_points(corners, local)), axis=1).max())
    origin = point_velocity(twist, local[:2])  # the pusher origin's velocity per unit s, slider frame

    def at(s: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        part = exp_twist(push.start, twist, s)
        turned = np.column_stack([np.zeros((len(s), 2)), part[:, 2]])  # the part's heading alone
        rate = np.column_stack([place(origin[None], turned)[:, 0], np.full(len(s), twist[2])])
        return compose(part, local), rate, np.zeros(len(s))

    return _Piece(index, True, float(push.duration), speed, abs(float(twist[2])) * speed, clock, 1.0, at)


def _transit_pieces(index: int, transit: Transit | Transfer, reach: float, clock: float) -> list[_Piece]:
    path = np.asarray(transit.pusher_path, dtype=float)
    # The plan's clock runs through the pieces as transit_poses has it, stretched to the duration.
    times = piece_times(path, reach)
    times *= transit.duration / times.sum() if times.sum() > 0 else 0.0
    starts = clock + np.concatenate([[0.0], np.cumsum(times)])
    pieces = []
    for k in range(len(path) - 1):
        p0, step = path[k], path[k + 1] - path[k]
        step[2] = wrap_angle(step[2])
        lifted = transit.mode == "lift" and k == AIRBORNE
        height = LIFT_HEIGHT if lifted else 0.0
        if lifted:
            pieces.append(_vertical_piece(index, p0, 0.0, LIFT_HEIGHT, starts[k]))
        speed = math.hypot(step[0], step[1]) + abs(step[2]) * reach

        def at(u: np.ndarray, p0=p0, step=step, height=height) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
            pose = p0 + u[:, None] * step
            pose[:, 2] = wrap_angle(pose[:, 2])
            return pose, np.tile(step, (len(u), 1)), np.full(len(u), height)

        pieces.append(_Piece(index, False, 1.0, speed, step[2] ** 2 * reach, starts[k], times[k], at))
        if lifted:
            pieces.append(_vertical_piece(index, path[k + 1], LIFT_HEIGHT, 0.0, starts[k + 1]))
    return pieces


def _vertical_piece(index: int, pose: np.ndarray, bottom: float, top: float, clock: float) -> _Piece:
    """The pusher rising (or sinking) straight from height ``bottom`` to ``top`` at ``pose``."""

    def at(u: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        return np.tile(pose, (len(u), 1)), np.zeros((len(u), 3)), bottom + u * (top - bottom)

    return _Piece(index, False, 1.0, abs(top - bottom), 0.0, clock, 0.0, at)


def _time_law(piece: _Piece, max_speed: float, max_accel: float, max_jerk: float) -> ruckig.Trajectory | None:
    """Ruckig's time-optimal rest-to-rest profile of ``s`` over the piece, or None if it does not move."""
    if piece.length <= 0 or piece.speed <= 0:
        return None
    v, a, j = path_limits(piece.speed, piece.bend, max_speed, max_accel, max_jerk)
    inp = ruckig.InputParameter(1)
    inp.current_position, inp.current_velocity, inp.current_acceleration = [0.0], [0.0], [0.0]
    inp.target_position, inp.target_velocity, inp.target_acceleration = [piece.length], [0.0], [0.0]
    inp.max_velocity, inp.max_acceleration, inp.max_jerk = [v], [a], [j]
    law = ruckig.Trajectory(1)
    result = ruckig.Ruckig(1).calculate(inp, law)
    if result not in (ruckig.Result.Working, ruckig.Result.Finished):
        raise RuntimeError(f"ruckig found no profile for a piece of segment {piece.segment}: {result}")
    return law if law.duration > 0 else None


def trajectory(scene: Scene, plan: Plan, max_speed: float = MAX_SPEED, max_accel: float = MAX_ACCEL,
               max_jerk: float = MAX_JERK, rate: float = RATE) -> Trajectory:
    """The pusher's trajectory along ``plan``, sampled at ``rate`` Hz from ``t = 0``, with a last
    sample at the end; no point of the pusher body faster than ``max_speed`` (m/s) or accelerating
    more than ``max_accel`` (m/s^2), its tangential jerk at most ``max_jerk`` (m/s^3); at rest at
    the start and end of every segment and of every piece of a transit (module docstring).
    A plan without segments has no pusher pose: no samples. The pusher follows every move and
    every transfer in order (a transfer is followed as a transit is, rest to rest on each piece);
    for a plan of several parts, :attr:`Trajectory.part` names the part each sample's segment
    belongs to (a transfer's: the part it goes to).

    >>> from planner.model.scene_file import load_scene
    >>> scene = load_scene("scenes/junction.yaml")
    >>> push = Push.along(0, np.zeros((2, 2)), [0.0, 1.0, 0.0], 0.3, scene.start)  # 0.3 m straight
    >>> run = trajectory(scene, Plan.of_part("part", scene.start, scene.goal, [push],
    ...                                      scene=None, solved=True, planner="rrt", seed=1, planning_time_s=0.0))
    >>> run.duration, len(run.t), float(run.vy.max()), float(run.vx.max())  # 0.3/0.05 + 0.05/0.5 + 0.5/5
    (6.2, 621, 0.05, 0.0)
    >>> from planner.queries.session import Planner
    >>> tray = load_scene("scenes/parts/swap.yaml")
    >>> run = trajectory(tray, Planner(tray).plan())
    >>> run.to_csv().splitlines()[0], sorted(set(run.part.tolist()))
    ('t,x,y,theta,vx,vy,omega,z,contact,segment,part', ['blue', 'red'])
    """
    steps = plan.steps
    motion = _timed(scene.pusher, [(scene.part(name).slider, s) for name, s in steps], max_speed, max_accel,
                    max_jerk, rate)
    if len(plan.names) == 1:
        return motion
    names = np.array([name for name, _ in steps] or [""])
    return replace(motion, part=names[motion.segment] if len(motion.t) else np.zeros(0, dtype=str))


def _timed(pusher: Pusher, segments: list[tuple[Slider, Push | Transit | Transfer]], max_speed: float,
           max_accel: float, max_jerk: float, rate: float) -> Trajectory:
    """The trajectory along ``segments``, each with the part it moves (module docstring)."""
    if not all(0 < value < math.inf for value in (max_speed, max_accel, max_jerk, rate)):
        raise ValueError("limits and rate must be positive and finite")
    if not segments:
        return Trajectory(*(np.zeros(0) for _ in COLUMNS), np.zeros(0))
    corners = pusher_frame_body(pusher.width, pusher.depth)
    reach = float(np.linalg.norm(corners, axis=1).max())
    pieces: list[_Piece] = []
    clock = 0.0
    for i, (slider, segment) in enumerate(segments):
        pieces += ([_push_piece(slider, i, segment, corners, clock)] if isinstance(segment, Push)
                   else _transit_pieces(i, segment, reach, clock))
        clock += segment.duration
    laws = [_time_law(p, max_speed, max_accel, max_jerk) for p in pieces]
    moving = [(p, law) for p, law in zip(pieces, laws) if law is not None] or [(pieces[0], None)]
    durations = np.array([law.duration if law else 0.0 for _, law in moving])
    ends = np.cumsum(durations)
    total = float(ends[-1])
    t = np.append(np.arange(math.ceil(total * rate - 1e-9)) / rate, total)
    which = np.minimum(np.searchsorted(ends, t, side="right"), len(moving) - 1)
    local = t - (ends[which] - durations[which])
    out = np.zeros((len(t), len(COLUMNS)))
    out[:, 0] = t
    progress = np.zeros(len(t))
    for k, (piece, law) in enumerate(moving):
        rows = np.flatnonzero(which == k)
        if not len(rows):
            continue
        s, ds = np.zeros(len(rows)), np.zeros(len(rows))
        if law is not None:
            for n, r in enumerate(rows):
                position, velocity, _ = law.at_time(min(local[r], law.duration))
                s[n], ds[n] = position[0], velocity[0]
            s = np.clip(s, 0.0, piece.length)
        pose, rate_of, z = piece.at(s)
        out[rows, 1:4] = pose
        out[rows, 4:7] = rate_of * ds[:, None]
        out[rows, 7] = z
        out[rows, 8] = piece.pushing
        out[rows, 9] = piece.segment
        progress[rows] = piece.clock + piece.pace * s
    return Trajectory(*out[:, :8].T, out[:, 8].astype(int), out[:, 9].astype(int), progress)


def planned_part(scene: Scene, plan: Plan, motion: Trajectory, name: str | None = None) -> np.ndarray:
    """Part ``name``'s (default: the plan's one part's) planned pose at each sample of ``motion``
    (``plan``'s trajectory): during a push of it, the pusher frame's pose times the inverse of the
    contact pose; in a transit of it, where the part was left; while another part moves or the
    pusher travels between parts, where its last segment left it (its start before its first)."""
    name = plan.part if name is None else name
    slider = scene.part(name).slider
    out = np.empty((len(motion.t), 3))
    pusher = np.column_stack([motion.x, motion.y, motion.theta])
    left = plan.starts[name]
    for k, (part, segment) in enumerate(plan.steps):
        rows = motion.segment == k
        if part != name or isinstance(segment, Transfer):
            out[rows] = left
            continue
        left = segment.end
        if isinstance(segment, Transit):
            out[rows] = segment.start
            continue
        local = edge_contact_pose(slider, segment.edge, np.zeros(3))  # pusher frame in the slider frame
        out[rows] = compose(pusher[rows], inverse(local))  # the slider frame in the world
    return out
