"""A plan's trajectory timed for the arm that runs it (:func:`arm_trajectory`).

The pusher's time law (:func:`.trajectory.trajectory`) bounds the pusher's speed, acceleration
and jerk, not the arm's joints: near a singular posture (the Panda's elbow straight, its wrist
over its shoulder) a slow pusher can ask a joint for more than its speed limit. Where the arm
holds every sample but a joint would go too fast, the whole trajectory is timed slower, by the
factor the fastest joint needs plus :data:`SLACK`, and the joints followed again: the path is the
same, every limit of the time law divided by that factor (speed), its square (acceleration) and
its cube (jerk), so the time law is the same, stretched. Slowing down cannot help a pose the arm
misses or a joint frame under the table: those are left to the joints check to report.
"""

from __future__ import annotations

from dataclasses import replace

from ..arm.joints import JointTrajectory, joints_along
from ..model.plan import Plan
from ..model.scene import Scene
from .trajectory import MAX_ACCEL, MAX_JERK, MAX_SPEED, Trajectory, trajectory

__all__ = ["SLACK", "SLOWINGS", "arm_trajectory"]

#: Beyond the factor the fastest joint needs: the joints are followed again, and a slower law
#: moves them a little differently.
SLACK = 1.1
#: Times the trajectory is slowed at most before the joints check reports what is left.
SLOWINGS = 3


def arm_trajectory(scene: Scene, plan: Plan) -> tuple[Trajectory, JointTrajectory]:
    """The trajectory of ``plan`` and the joints of ``scene``'s arm along it, slowed (module
    docstring) until no joint is too fast, at most :data:`SLOWINGS` times."""
    motion = trajectory(scene, plan)
    joints = joints_along(scene.robot, motion)
    slowed = 1.0
    for _ in range(SLOWINGS):
        if not joints.too_fast:
            break
        slowed *= SLACK * float(joints.speed.max())
        motion = trajectory(scene, plan, MAX_SPEED / slowed, MAX_ACCEL / slowed ** 2, MAX_JERK / slowed ** 3)
        joints = joints_along(scene.robot, motion)
    return motion, replace(joints, slowed=slowed)
