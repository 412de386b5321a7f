"""Inverse kinematics of a scene's arm: the joint angles that hold the pusher at a pose on the table.

The pusher frame at a table pose ``(x, y, heading)`` is at height ``push_height`` with its z axis
down (the flange's, :mod:`planner.model.robot`), and its x axis at ``heading - mount`` where the
*mount* is the constant angle between the pusher's heading and the flange's x axis. The mount is
fixed per arm so that pushing straight away from the base leaves the last joint at the middle of
its range: the wrist then turns as far either way before its stop.

:class:`ArmReach` solves with mink (differential inverse kinematics on the MuJoCo model of
:func:`planner.arm.arms.mjcf`, a quadratic program per step that keeps every joint within its
position limits), from a given posture: along a path, each pose from the posture of the one
before, so the arm follows the path continuously, on one branch, and a wrist that would have to
turn past its stop fails to reach rather than jumping.

>>> from planner.model.robot import Robot
>>> reach = ArmReach(Robot("panda", np.array([0.0, 0.0, 0.0]), 0.12))
>>> q, miss = reach.solve([0.45, 0.1, 0.3], reach.ready)
>>> bool(miss < 1e-4), bool(np.all((reach.arm.lower <= q) & (q <= reach.arm.upper)))
(True, True)
"""

from __future__ import annotations

import math
from dataclasses import replace

import mink
import mujoco
import numpy as np
from numpy.typing import ArrayLike

from ..model.robot import Robot
from ..world.reach import family_posture
from ..model.arms import ARMS, Arm
from .arms import mjcf

__all__ = ["ArmReach", "FOLLOW_STEPS", "REACHED", "SPEED_SHARE", "arm_model"]

#: Largest pose error (m, and rad times the part of a metre it counts as) of a pose reached.
REACHED = 1e-4
_DT = 0.05  # the step mink's velocities are integrated over; a pose is reached in some tens of them
_STEPS = 200  # most steps towards one pose from a far posture (a path's first)
#: Most steps towards a path's next pose from the last one's posture: it needs a few (100 a second
#: of a slow pusher), and one it cannot reach in these would need a jump, missed either way.
FOLLOW_STEPS = 20
_SETTLED = 1e-6  # rad a step: a settling posture that moves less has stopped
#: The share of each joint's speed limit a path is followed within (the rest is the check's margin).
SPEED_SHARE = 0.95
_WRISTS = 7  # places of the last joint a path's first pose is tried from
_DOWN = np.array([[1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, -1.0]])  # x kept, z down


def arm_model(robot: Robot, extra: str = "") -> str:
    """A MuJoCo model (MJCF text) of ``robot``'s arm on its base, with ``extra`` bodies in the
    world (the simulation's table and parts); the links' capsules collide with the world's geoms
    but not with each other."""
    arm = ARMS[robot.model]
    return (f'<mujoco model="{robot.model}"><compiler angle="radian"/>'
            '<default><default class="link"><geom contype="2" conaffinity="1" rgba="0.9 0.9 0.9 1"/></default></default>'
            f'<worldbody>{mjcf(arm, robot.tool_length, tuple(float(v) for v in robot.base))}{extra}</worldbody></mujoco>')


class ArmReach:
    """Inverse kinematics of ``robot``'s arm for pusher poses on the table (module docstring)."""

    def __init__(self, robot: Robot):
        self.robot, self.arm = robot, _limits(ARMS[robot.model])
        self.model = mujoco.MjModel.from_xml_string(arm_model(robot))
        self.configuration = mink.Configuration(self.model)
        self.task = mink.FrameTask("pusher", "site", position_cost=1.0, orientation_cost=1.0)
        self.posture = mink.PostureTask(self.model, cost=1e-3)
        self.ready = np.array(self.arm.ready, dtype=float)
        self.posture.set_target(self.ready)
        self.limits = [mink.ConfigurationLimit(self.model)]
        self.speeds = mink.VelocityLimit(self.model, {f"joint{k}": SPEED_SHARE * v for k, v in enumerate(self.arm.speed, 1)})
        self.mount = self._mount()
        # The joint frames that can come near the table: every link's but the first, on the base.
        self._links = [self.model.body(f"link{k}").id for k in range(2, self.arm.joints + 1)]

    def _mount(self) -> float:
        """Pusher heading minus flange x heading, so that the ready posture with its last joint at
        the middle of its range pushes straight away from the base."""
        middle = self.ready.copy()
        middle[-1] = (self.arm.lower[-1] + self.arm.upper[-1]) / 2
        rotation = self.pusher_frame(middle)[1]
        return math.remainder(float(self.robot.base[2]) - math.atan2(rotation[1, 0], rotation[0, 0]), 2 * math.pi)

    def pusher_frame(self, q: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """The pusher frame's origin (world, m) and rotation matrix at joint angles ``q``."""
        self.configuration.update(np.asarray(q, dtype=float))
        site = self.configuration.data.site("pusher")
        return site.xpos.copy(), site.xmat.reshape(3, 3).copy()

    def target(self, pose: ArrayLike, height: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
        """The pusher frame's origin and rotation holding the pusher at table pose ``pose``,
        ``height`` above where it pushes (module docstring)."""
        x, y, heading = (float(v) for v in pose)
        yaw = heading - self.mount
        turn = np.array([[math.cos(yaw), -math.sin(yaw), 0.0], [math.sin(yaw), math.cos(yaw), 0.0], [0.0, 0.0, 1.0]])
        return np.array([x, y, self.robot.push_height + height]), turn @ _DOWN

    def pose_error(self, pose: ArrayLike, q: ArrayLike, height: float = 0.0) -> float:
        """How far joint angles ``q`` leave the pusher frame from holding the pusher at ``pose``:
        the larger of its origin's distance (m) and its rotation's angle (rad)."""
        (origin, rotation), (at, turned) = self.target(pose, height), self.pusher_frame(q)
        cos = (np.trace(rotation.T @ turned) - 1.0) / 2.0
        return max(float(np.linalg.norm(at - origin)), math.acos(min(1.0, max(-1.0, cos))))

    def first(self, pose: ArrayLike, height: float = 0.0) -> tuple[np.ndarray, float]:
        """Joint angles holding the pusher at a path's first pose, and how far from it they
        leave it (as :meth:`solve`). The arm starts on its own family of postures, the one the
        planner's reach zone is drawn on (:func:`planner.world.reach.family_posture`) at the
        pose's distance from the base, turned about the first joint to face ``pose``, its last
        joint turned to the pusher's heading (within its stops). Where that is not reached, the last joint is tried at :data:`_WRISTS`
        places over its range, keeping the reached posture whose other joints are nearest the
        facing one (else the nearest miss): a reach that swings the whole arm round to spare the
        wrist leaves joints near their stops, where the path soon cannot be followed."""
        x, y, _ = (float(v) for v in self.robot.base)
        low, high = self.arm.lower, self.arm.upper
        middle = (low[-1] + high[-1]) / 2
        facing = family_posture(self.robot, math.hypot(pose[0] - x, pose[1] - y))
        facing[-1] = middle
        at, _ = self.pusher_frame(facing)
        turn = math.atan2(pose[1] - y, pose[0] - x) - math.atan2(at[1] - y, at[0] - x)
        facing[0] = float(np.clip(facing[0] + math.remainder(turn, 2 * math.pi), low[0], high[0]))
        # The flange points down, so the last joint turns the pusher's heading the other way.
        at = self.pusher_frame(facing)[1]
        off = math.remainder(float(pose[2]) - self.mount - math.atan2(at[1, 0], at[0, 0]), 2 * math.pi)
        wrist = facing[-1] - off
        # A last joint of more than a turn (the UR5e's) holds the heading on several branches: the
        # one where pushing straight away from the base (psi = 0, planner.world.reach) would put
        # it nearest the middle of its range, so that the psi the planner allows either way fits.
        psi = math.remainder(float(pose[2]) - math.atan2(pose[1] - y, pose[0] - x), 2 * math.pi)
        branches = [wrist + k * 2 * math.pi for k in (-1, 0, 1) if low[-1] <= wrist + k * 2 * math.pi <= high[-1]]
        facing[-1] = min(branches, key=lambda q: abs(q + psi - middle)) if branches else float(np.clip(wrist, low[-1], high[-1]))
        q, miss = self.solve(pose, facing, height=height, settle=True)
        if miss < REACHED:
            return q, miss
        tried = []
        for wrist in np.linspace(low[-1], high[-1], _WRISTS + 2)[1:-1]:
            facing[-1] = wrist
            tried.append(self.solve(pose, facing, height=height, settle=True))
        return min(tried, key=lambda t: (t[1] >= REACHED,
                                         float(np.linalg.norm(t[0][:-1] - facing[:-1])) if t[1] < REACHED else t[1]))

    def lowest_frame(self, q: ArrayLike) -> float:
        """The height above the table of the lowest joint frame but the first (which stands on
        the table) at joint angles ``q``."""
        self.configuration.update(np.asarray(q, dtype=float))
        return float(self.configuration.data.xpos[self._links, 2].min())

    def follow(self, pose: ArrayLike, q: ArrayLike, height: float, gap: float) -> tuple[np.ndarray, float]:
        """A path's next pose, ``gap`` seconds after the one the arm holds at ``q``: :meth:`solve`
        within that time (the joints file's rule, :mod:`planner.arm.joints`, and the closed loop's)."""
        return self.solve(pose, q, steps=FOLLOW_STEPS, height=height, within=gap if gap > 0 else None)

    def solve(self, pose: ArrayLike, q: ArrayLike, steps: int = _STEPS, height: float = 0.0,
              settle: bool = False, within: float | None = None) -> tuple[np.ndarray, float]:
        """Joint angles holding the pusher at ``pose`` (``height`` above where it pushes), reached
        from ``q``, and how far from it they leave the pusher frame (the norm of its twist error:
        m, and rad); within :data:`REACHED` it is reached. With ``settle``, the steps go on once
        it is reached until the joints stop moving: the arm's redundant joints come to where the
        posture task holds them, so that the next pose's steps move them no more than the pose
        asks (else the first step after a path's first pose swings them there at once). With
        ``within`` (s), each step moves the joints over that time no faster than :data:`SPEED_SHARE`
        of their speed limits (mink's velocity limit) and as little as the pose asks: a path's next
        pose, reached as the arm would reach it."""
        self.configuration.update(np.asarray(q, dtype=float))
        origin, rotation = self.target(pose, height)
        self.task.set_target(mink.SE3.from_rotation_and_translation(mink.SO3.from_matrix(rotation), origin))
        # Along a path: one step over the whole interval reaches a near pose exactly (to second
        # order), within the arm's speeds; and no posture task, so the redundant joints move as
        # little as the pose asks (the least joint motion, the solver's damping) and never swing
        # to where the posture task's optimum jumps (joint 5 once went at 44 times its limit).
        dt, limits, tasks = ((_DT, self.limits, [self.task, self.posture]) if within is None
                             else (within, self.limits + [self.speeds], [self.task]))
        miss = math.inf
        for step in range(steps):
            miss = float(np.linalg.norm(self.task.compute_error(self.configuration)))
            # Along a path every sample takes its step, however near: a posture left where it
            # was while the pose creeps until it is REACHED away, then caught up, would shake the
            # arm's pusher by that much a sample (slip in the simulation).
            if miss < REACHED and not settle and (within is None or step > 0):
                break
            velocity = mink.solve_ik(self.configuration, tasks, dt, "daqp", damping=1e-6, limits=limits)
            if miss < REACHED and float(np.abs(velocity).max()) * dt < _SETTLED:
                break
            self.configuration.integrate_inplace(velocity, dt)
        return self.configuration.q.copy(), float(np.linalg.norm(self.task.compute_error(self.configuration)))


def _limits(arm: Arm) -> Arm:
    """``arm`` with its limits as arrays (for vectorised checks)."""
    return replace(arm, lower=np.array(arm.lower), upper=np.array(arm.upper), speed=np.array(arm.speed))
