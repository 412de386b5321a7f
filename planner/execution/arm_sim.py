"""The scene's arm in the MuJoCo runs of :mod:`.mujoco_sim`: it holds the pusher and pushes the parts.

With a ``robot:`` block the pusher is not the kinematic body of :mod:`.mujoco_sim` but a prism
on the arm's flange, and the arm's joints, not the pusher, follow the plan: they are driven along
the joint trajectory (:func:`planner.arm.joints.joints_along`) by servos, so the pusher goes where
the arm's dynamics, its servos' gains and torque limits and the contact forces take it. What
touches the part is the same prism with the same contacts as the free pusher's; what is added is
the arm's bodies, their servos, and contacts of the arm's links with the table, the walls, the
obstacles and the parts, which fail a run.

**The model** (:meth:`SimArm.body`). The arm's bodies on its base (:func:`planner.arm.arms.mjcf`),
each with gravity compensation (the runs' gravity is ten times Earth's; a real arm's controller
cancels its own weight too), its joints with an armature (the motors' rotor inertia seen through
the gears) of :data:`ARMATURE`. The pusher prism is on a body of its own at the pusher frame,
on the flange's body: its own frame has z up and x at the pusher's heading, so relative to the
flange it is turned by the mount about the flange's z axis and turned over; its bottom is
``push_height`` below the pusher frame's origin, on the table.

**The tool** is that body on a vertical slide with a spring (:data:`TOOL_STIFFNESS`, damped by
:data:`TOOL_DAMPING`), as a spring-loaded pusher is mounted. A joint servo gives way under the
push, and its give has a vertical part (the arm's stiffness in the world frame is not diagonal).
On a rigid tool the part's face would hold that vertical force by friction, and the friction
cone's share it takes is lost to the push: on the shipped UR5e tray, the wedge's longest push
loaded the face vertically with up to 0.45 times the horizontal force, the cone was full at every
contact, and the part slid 0.63 mm along the face where the free pusher's slides 0.07 mm. Sprung
at 200 N/m, a few tenths of a millimetre of vertical give cost the face a tenth of a newton: the
vertical share falls to 0.03, the cone's use to what the free pusher's is (0.5-0.8). A real cell
needs the same: a compliant mount, or a controller stiff only in the plane.

**The servos** (:meth:`SimArm.actuators`). One per joint, a PD law with a velocity feed-forward,
``tau = kp (q_ref - q) + kv (qd_ref - qd)``, clipped to the joint's torque limit
(:class:`planner.model.arms.Arm`); written as one affine actuator whose control is
``q_ref + kv / kp * qd_ref``, so that one force range bounds the joint's whole torque.

**Integration.** Explicit Euler, at a step shorter than the free pusher's (:attr:`SimArm.timestep`,
:func:`_timestep`): half the bound ``2 I / kv`` beyond which explicit Euler amplifies a damped
joint's motion, for the joint where it is least over the run's postures (a wrist joint: 0.5 ms
for the Panda, 0.67 ms for the UR5e on the shipped scenes). MuJoCo's implicit integrators take
the servos' damping into the step but not into the contact solver's friction forces (nor the
no-slip pass's), so a sticking contact creeps: 0.035 mm/s on the tray's wedge with the sprung
tool at 2 ms (`implicitfast`), 0.001-0.007 mm/s with explicit Euler at 0.5-1 ms.

**The reference** (:func:`sim_arm`). The joint trajectory of the plan's trajectory, and before it
the lead-in's: the pusher's approach to the first contact (:func:`.approach.lead_in_pose`),
reached backwards from the trajectory's first posture so that the two join; the velocities are
the joints' finite differences.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco
import numpy as np

from ..arm.arms import mjcf as arm_mjcf
from ..arm.joints import JointTrajectory, joint_trajectory, joints_along
from ..arm.reach import ArmReach
from ..model.arms import ARMS, Arm
from ..model.robot import Robot
from .trajectory import RATE, Trajectory

__all__ = ["ARMATURE", "TOOL_DAMPING", "TOOL_STIFFNESS", "SimArm", "sim_arm"]

#: Joint armature, kg m^2 (module docstring).
ARMATURE = 0.1
#: The tool's vertical spring, N/m, and its damping, N s/m (module docstring, "The tool").
TOOL_STIFFNESS, TOOL_DAMPING = 200.0, 5.0

#: Every this many rows of the reference, the arm's inertia is looked at for the step (:func:`_timestep`).
POSTURE_STRIDE = 25
#: Radius of the tool's shaft between the flange and the pusher prism, m (drawn, never touching).
SHAFT = 0.008


@dataclass(frozen=True, eq=False)
class SimArm:
    """The arm of one simulation: ``robot``, its ``mount`` (pusher heading minus flange x heading,
    :class:`planner.arm.reach.ArmReach`), the reference joint angles ``q`` and rates ``qd`` at
    times ``t`` of the run's clock (the lead-in, then the plan's trajectory), ``joints`` the plan
    trajectory's own joint trajectory, and the arm's link geoms that must not touch anything (by
    name: the link each belongs to)."""

    robot: Robot
    mount: float
    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    joints: JointTrajectory
    links: dict[str, str]
    #: The step its model is integrated with, s (module docstring, "Integration").
    timestep: float

    @property
    def arm(self) -> Arm:
        return ARMS[self.robot.model]

    @property
    def count(self) -> int:
        """The arm's number of joints."""
        return self.q.shape[1]

    def defaults(self) -> str:
        """The default classes :meth:`body` uses: ``arm`` (its joints' armature) and ``link``."""
        return (f'<default class="arm"><joint armature="{ARMATURE:g}"/>'
                '<default class="link"><geom rgba=".85 .85 .85 1"/></default></default>')

    def body(self, top: float) -> str:
        """The arm's bodies with the pusher prism (mesh ``pusher``, ``top`` high) on its flange
        and a shaft drawn from the flange to it (module docstring)."""
        arm, robot = self.arm, self.robot
        down = arm.flange + robot.tool_length + robot.push_height  # the table, along the flange's z axis
        half = self.mount / 2
        tool = (f'<body name="tool" pos="0 0 {down:.17g}" gravcomp="1">'
                f'<joint name="tool" type="slide" axis="0 0 1" stiffness="{TOOL_STIFFNESS:g}" damping="{TOOL_DAMPING:g}" armature="0"/>'
                f'<geom name="pusher" type="mesh" mesh="pusher" '
                f'quat="0 {math.cos(half):.17g} {-math.sin(half):.17g} 0" rgba=".1 .1 .1 1"/></body>'
                f'<geom name="shaft" type="cylinder" fromto="0 0 {arm.flange:.17g} 0 0 {down - top:.17g}" '
                f'size="{SHAFT:g}" rgba=".3 .3 .3 1"/>')
        return arm_mjcf(arm, robot.tool_length, tuple(float(v) for v in robot.base), tool=tool,
                        attributes=' childclass="arm" gravcomp="1"')

    def actuators(self) -> list[str]:
        """A servo per joint (module docstring)."""
        arm = self.arm
        return [f'<general name="servo{k}" joint="joint{k}" biastype="affine" gainprm="{kp:g}" '
                f'biasprm="0 {-kp:g} {-kv:g}" forcerange="{-limit:g} {limit:g}"/>'
                for k, (kp, kv, limit) in enumerate(zip(arm.kp, arm.kv, arm.torque), 1)]

    def controls(self, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
        """The servos' controls that ask for angles ``q`` and rates ``qd``."""
        arm = self.arm
        return q + np.asarray(arm.kv) / np.asarray(arm.kp) * qd

    def pairs(self, others: list[str]) -> list[str]:
        """Frictionless contacts of the arm's links with the geoms ``others`` (the table, walls,
        obstacles and parts): there to be seen, as the parts' with the walls are."""
        return [f'<pair geom1="{g}" geom2="{o}" condim="1"/>' for g in self.links for o in others]


def sim_arm(robot: Robot, lead: Trajectory, motion: Trajectory, joints: JointTrajectory | None = None) -> SimArm:
    """The arm of a run along ``lead`` then ``motion`` (module docstring, "The reference"):
    ``joints`` along ``motion`` (default: :func:`planner.arm.joints.joints_along` it)."""
    joints = joints_along(robot, motion) if joints is None else joints
    back = slice(None, None, -1)
    approach = joint_trajectory(robot, lead.t, np.c_[lead.x, lead.y, lead.theta][back], lead.z[back],
                                np.zeros(len(lead.t), dtype=int), start=joints.q[0]).q[back]
    t = np.concatenate([lead.t[:-1], lead.duration + motion.t])
    q = np.vstack([approach[:-1], joints.q])
    qd = np.gradient(q, t, axis=0) if len(t) > 1 else np.zeros_like(q)
    reach = ArmReach(robot)
    return SimArm(robot, reach.mount, t, q, qd, joints, _links(reach.model), _timestep(reach.model, ARMS[robot.model], q))


def _timestep(model, arm: Arm, q: np.ndarray) -> float:
    """Half explicit Euler's stability bound ``2 I / kv`` of the stiffest-damped joint for its
    inertia, over the postures ``q`` (every :data:`POSTURE_STRIDE`-th, and the last): ``I`` the
    joint's inertia in ``model`` (the arm's, without armature) plus the armature; shortened to
    divide the trajectory's sample interval (module docstring, "Integration")."""
    data = mujoco.MjData(model)
    inertia = np.zeros((model.nv, model.nv))
    least = np.full(arm.joints, np.inf)
    for row in np.vstack([q[::POSTURE_STRIDE], q[-1:]]):
        data.qpos[:arm.joints] = row
        mujoco.mj_forward(model, data)
        mujoco.mj_fullM(model, data, inertia)
        least = np.minimum(least, np.diag(inertia)[:arm.joints])
    bound = float(np.min((least + ARMATURE) / np.asarray(arm.kv)))
    return 1.0 / (RATE * math.ceil(1.0 / (RATE * bound)))


def _links(model) -> dict[str, str]:
    """The arm's geoms that may touch nothing, by name, each with the link it belongs to: those
    of joint 2's body and what it carries (joint 1's body and the base stand on the table)."""
    out = {}
    for g in range(model.ngeom):
        chain, body = [], int(model.geom_bodyid[g])
        while body > 0:
            chain.append(model.body(body).name)
            body = int(model.body_parentid[body])
        if "link2" in chain:
            out[model.geom(g).name] = next(name for name in chain if name.startswith("link"))
    return out
