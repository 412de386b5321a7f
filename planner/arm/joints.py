"""The arm's joint trajectory along the pusher's (:func:`joint_trajectory`), and whether the arm can run it.

Each sample of the pusher's trajectory (:mod:`planner.execution.trajectory`: a table pose and a
height above the table, 100 a second) is reached from the posture of the sample before
(:class:`~planner.arm.reach.ArmReach`), the first from the arm's ready posture turned towards it.
So the joints move continuously and stay on one branch; a pose the arm cannot hold from there, a
wrist that would turn past its stop included, is missed rather than reached by a jump. The arm
*follows* the trajectory when every sample is reached to :data:`HELD` (m, of the pusher frame's
origin; its heading to :data:`HELD` rad), no joint moves faster than its speed limit between two
samples, and every joint frame stays above the table.

>>> import numpy as np
>>> from planner.model.robot import Robot
>>> robot = Robot("panda", np.array([0.0, 0.0, 0.0]), 0.12)
>>> t = np.linspace(0.0, 2.0, 201)  # 10 cm straight away from the base in 2 s
>>> poses = np.c_[0.45 + 0.05 * t, np.zeros_like(t), np.zeros_like(t)]
>>> run = joint_trajectory(robot, t, poses, np.zeros_like(t), np.zeros(len(t), dtype=int))
>>> run.follows, run.summary().startswith("arm: follows: 201 samples")
(True, True)
"""

from __future__ import annotations

import csv
import io
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from ..model.files import write_atomic
from ..model.robot import Robot
from .reach import ArmReach

__all__ = ["HELD", "JointTrajectory", "joint_trajectory", "joints_along"]

#: Farthest a reached sample may leave the pusher frame from where the trajectory has it: m for
#: its origin, rad for its axes (the check the joints file must pass asks for 1 mm).
HELD = 5e-4


@dataclass(frozen=True, eq=False)
class JointTrajectory:
    """Joint angles per sample of a pusher trajectory, and what the arm could not do.

    ``q`` is ``(n, joints)`` (rad); ``t`` and ``segment`` (from 0) are the pusher trajectory's,
    ``part`` too for a plan of several parts; ``miss`` is each sample's pusher frame error (m of
    its origin, rad of its axes, the larger); ``speed`` each joint's largest speed as a share of
    its limit; ``lowest`` the lowest joint frame's height above the table (m).
    """

    robot: Robot
    t: np.ndarray
    q: np.ndarray
    segment: np.ndarray
    miss: np.ndarray
    speed: np.ndarray
    lowest: float
    part: np.ndarray | None = None
    slowed: float = 1.0  # how many times slower than the pusher's own time law the trajectory was timed

    @property
    def too_fast(self) -> bool:
        """Whether the arm holds every sample and stays above the table but some joint would
        move faster than its limit: a trajectory timed slower is followed."""
        return bool(self.miss.max(initial=0.0) <= HELD and self.lowest > 0.0 and self.speed.max(initial=0.0) > 1.0)

    @property
    def follows(self) -> bool:
        return bool(self.miss.max(initial=0.0) <= HELD and self.speed.max(initial=0.0) <= 1.0 and self.lowest > 0.0)

    @property
    def passed(self) -> bool:
        """As the pipeline's other checks say it: the arm follows the trajectory."""
        return self.follows

    def lines(self) -> list[str]:
        """Where the arm cannot follow: the first sample missed, the fastest joint over its limit."""
        out = []
        if (missed := np.flatnonzero(self.miss > HELD)).size:
            k = int(missed[0])
            out.append(f"arm: cannot hold the pusher at t = {self.t[k]:.2f} s (segment {self.segment[k] + 1}): "
                       f"{self.miss[k] * 1e3:.1f} mm off, {missed.size} of {len(self.t)} samples missed")
        if self.speed[fast := int(np.argmax(self.speed))] > 1.0:
            out.append(f"arm: joint {fast + 1} would move at {self.speed[fast]:.2f} times its speed limit")
        if self.lowest <= 0.0:
            out.append(f"arm: a joint frame goes {-self.lowest * 1e3:.1f} mm below the table")
        return out

    def summary(self) -> str:
        verdict = "follows" if self.follows else "CANNOT FOLLOW"
        slowed = f", the trajectory timed {self.slowed:.2f} times slower for its joints" if self.slowed > 1.0 else ""
        return (f"arm: {verdict}: {len(self.t)} samples, {self.robot.model} ({self.q.shape[1]} joints){slowed}; worst "
                f"{self.miss.max(initial=0.0) * 1e3:.3f} mm off, joints at most {self.speed.max(initial=0.0):.0%} "
                f"of their speed limits, lowest joint frame {self.lowest:.3f} m above the table")

    def to_csv(self) -> str:
        """``t,q1,...,qn,segment`` (and ``part``), a row per sample; segments numbered from 1;
        floats round-trip (17 digits), as the trajectory's CSV has them."""
        text = io.StringIO()
        rows = csv.writer(text, lineterminator="\n")  # a part's name may hold a comma or a quote
        joints = self.q.shape[1]
        rows.writerow(["t", *(f"q{k}" for k in range(1, joints + 1)), "segment"] + (["part"] if self.part is not None else []))
        for k in range(len(self.t)):
            rows.writerow([f"{self.t[k]:.17g}", *(f"{v + 0.0:.17g}" for v in self.q[k]), int(self.segment[k]) + 1]
                          + ([str(self.part[k])] if self.part is not None else []))
        return text.getvalue()

    def write_csv(self, path) -> None:
        write_atomic(path, self.to_csv())


def joint_trajectory(robot: Robot, t: ArrayLike, poses: ArrayLike, heights: ArrayLike, segments: ArrayLike,
                     parts: ArrayLike | None = None, start: ArrayLike | None = None) -> JointTrajectory:
    """The joint angles of ``robot``'s arm along pusher table poses ``poses`` ``(n, 3)`` at
    heights ``heights`` above the table and times ``t`` (module docstring); the first sample
    reached from the posture ``start`` if given (a path that must join one the arm is on), else
    from :meth:`ArmReach.first`'s."""
    t, poses, heights = np.asarray(t, dtype=float), np.asarray(poses, dtype=float), np.asarray(heights, dtype=float)
    reach = ArmReach(robot)
    q = np.zeros((len(t), reach.arm.joints))
    miss = np.zeros(len(t))
    posture = reach.ready
    for k in range(len(t)):
        if k == 0 and start is None:
            posture, _ = reach.first(poses[k], height=float(heights[k]))
        elif k == 0:
            posture, _ = reach.solve(poses[k], start, height=float(heights[k]))
        else:
            # Within the samples' interval, as the arm would move (the speed check then has the rest).
            posture, _ = reach.follow(poses[k], posture, float(heights[k]), float(t[k] - t[k - 1]))
        q[k] = posture
        miss[k] = reach.pose_error(poses[k], posture, float(heights[k]))
    dt = np.diff(t)
    speed = (np.abs(np.diff(q, axis=0)) / np.where(dt > 0, dt, np.inf)[:, None]).max(axis=0, initial=0.0) / reach.arm.speed \
        if len(t) > 1 else np.zeros(reach.arm.joints)
    lowest = min((reach.lowest_frame(row) for row in q), default=math.inf)
    return JointTrajectory(robot, t, q, np.asarray(segments, dtype=int), miss, speed, lowest,
                           None if parts is None else np.asarray(parts))


def joints_along(robot: Robot, motion) -> JointTrajectory:
    """:func:`joint_trajectory` along a pusher trajectory ``motion`` (a
    :class:`planner.execution.trajectory.Trajectory`: its samples' times, poses, heights,
    segments and, of a tray, parts)."""
    return joint_trajectory(robot, motion.t, np.c_[motion.x, motion.y, motion.theta], motion.z, motion.segment,
                            motion.part)
