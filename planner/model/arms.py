"""The arms a scene's ``robot:`` block may name, from their makers' published kinematics and limits.

Each arm is a chain of revolute joints given by Denavit-Hartenberg rows, in the convention its
maker publishes them in:

* the Franka Emika Panda (and FR3, the same kinematics) in Craig's *modified* convention, each
  link frame ``Rx(alpha) Tx(a) Rz(q) Tz(d)`` from the one before; the flange is 0.107 m beyond
  joint 7's frame along its z axis;
* the Universal Robots UR5e in the *standard* convention, ``Rz(q) Tz(d) Tx(a) Rx(alpha)``; the
  flange (``tool0``) is frame 6.

The numbers, limits included, are in ``docs/arm.md`` with where they come from. They are part of
the problem a plan answers (where the pusher can be), so they live with the scene's model: the
table's reach zone (:mod:`planner.world.reach`) is drawn from them, and the arm package
(:mod:`planner.arm`) builds its MuJoCo model and inverse kinematics on them.

>>> ARMS["panda"].joints, ARMS["ur5e"].joints
(7, 6)
>>> ARMS["panda"].lower[3], ARMS["panda"].upper[3]
(-3.0718, -0.0698)
"""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ["ARMS", "Arm"]


@dataclass(frozen=True)
class Arm:
    """An arm's kinematics and limits.

    ``dh`` holds a row ``(a, d, alpha)`` per joint (m, m, rad) in ``convention`` ``'modified'``
    or ``'standard'``; ``flange`` is the flange frame's offset along the last frame's z axis (m).
    ``lower``, ``upper`` and ``speed`` are per joint (rad, rad/s). ``ready`` is a posture with
    the flange pointing down over the table in front of the arm, where inverse kinematics starts.
    ``radius`` is the links' capsule radius (m); ``masses`` the links' masses (kg), each held at
    its joint's frame in the model (its inertia a solid ball of the capsule's radius): the position
    actuators of the simulation need loads of the right size, not the exact distribution.
    ``kp`` and ``kv`` are the simulation's joint servo gains (N m/rad, N m s/rad) and ``torque``
    the joints' torque limits (N m), per joint (``docs/arm.md``, "The arm in the simulation").
    """

    name: str
    convention: str
    dh: tuple[tuple[float, float, float], ...]
    flange: float
    lower: tuple[float, ...]
    upper: tuple[float, ...]
    speed: tuple[float, ...]
    ready: tuple[float, ...]
    radius: float
    masses: tuple[float, ...]
    kp: tuple[float, ...]
    kv: tuple[float, ...]
    torque: tuple[float, ...]

    @property
    def joints(self) -> int:
        return len(self.dh)

    @property
    def shoulder(self) -> float:
        """Height (m) above the base frame of the point the rest of the arm swings about: joint
        1's frame origin, on joint 2's axis (the Panda's 0.333 m, the UR5e's 0.1625 m)."""
        return self.dh[0][1]

    @property
    def span(self) -> float:
        """The farthest (m) the flange can be from the shoulder: the lengths between consecutive
        joint frames past the first, and the flange's offset (triangle inequality: no posture
        reaches farther). The Panda's is 0.316 + 0.0825 + 0.3928 + 0.088 + 0.107.

        >>> round(ARMS["panda"].span, 4), round(ARMS["ur5e"].span, 4)
        (0.9863, 1.1498)
        """
        return sum(math.hypot(a, d) for a, d, _ in self.dh[1:]) + self.flange


_PI = math.pi
ARMS = {
    "panda": Arm(
        "panda", "modified",
        ((0.0, 0.333, 0.0), (0.0, 0.0, -_PI / 2), (0.0, 0.316, _PI / 2), (0.0825, 0.0, _PI / 2),
         (-0.0825, 0.384, -_PI / 2), (0.0, 0.0, _PI / 2), (0.088, 0.0, _PI / 2)),
        0.107,
        (-2.8973, -1.7628, -2.8973, -3.0718, -2.8973, -0.0175, -2.8973),
        (2.8973, 1.7628, 2.8973, -0.0698, 2.8973, 3.7525, 2.8973),
        (2.175, 2.175, 2.175, 2.175, 2.61, 2.61, 2.61),
        (0.0, -_PI / 4, 0.0, -3 * _PI / 4, 0.0, _PI / 2, _PI / 4),
        0.06,
        (4.971, 0.647, 3.229, 3.588, 1.226, 1.667, 0.736),
        (4500.0, 4500.0, 3500.0, 3500.0, 2000.0, 2000.0, 2000.0),
        (450.0, 450.0, 350.0, 350.0, 200.0, 200.0, 200.0),
        (87.0, 87.0, 87.0, 87.0, 12.0, 12.0, 12.0)),
    "ur5e": Arm(
        "ur5e", "standard",
        ((0.0, 0.1625, _PI / 2), (-0.425, 0.0, 0.0), (-0.3922, 0.0, 0.0), (0.0, 0.1333, _PI / 2),
         (0.0, 0.0997, -_PI / 2), (0.0, 0.0996, 0.0)),
        0.0,
        (-2 * _PI,) * 6,
        (2 * _PI,) * 6,
        (_PI,) * 6,
        (0.0, -_PI / 2, _PI / 2, -_PI / 2, -_PI / 2, 0.0),
        0.05,
        (3.761, 8.058, 2.846, 1.37, 1.3, 0.365),
        (2000.0, 2000.0, 2000.0, 500.0, 500.0, 500.0),
        (400.0, 400.0, 400.0, 100.0, 100.0, 100.0),
        (150.0, 150.0, 150.0, 28.0, 28.0, 28.0)),
}
