"""The MuJoCo model of a scene's arm (:func:`mjcf`), and a bound on how far it reaches (:func:`beyond_reach`).

The arms' kinematics and limits are :data:`planner.model.arms.ARMS`. From them :func:`mjcf`
writes a MuJoCo model of the arm: a body per link, a hinge per joint with its position limits, and
capsules between consecutive joint frames as the links' collision shapes (simple shapes, not the
makers' meshes: enough to keep the arm off the table and the obstacles). Inverse kinematics
(:mod:`.reach`) and the simulation run on that model.
"""

from __future__ import annotations

import math

import numpy as np

from ..model.arms import ARMS, Arm
from ..model.scene import Scene

__all__ = ["beyond_reach", "mjcf"]


def _quat_x(angle: float) -> str:
    """A rotation about x as MJCF's ``quat`` (w x y z)."""
    return f"{math.cos(angle / 2):.17g} {math.sin(angle / 2):.17g} 0 0"


def _rot_x(angle: float, v: np.ndarray) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([v[0], c * v[1] - s * v[2], s * v[1] + c * v[2]])


def _capsule(start: np.ndarray, end: np.ndarray, radius: float, name: str) -> str:
    """A link capsule between two points of a body's frame (nothing for a zero length)."""
    if np.linalg.norm(end - start) < 1e-9:
        return ""
    points = " ".join(f"{v:.17g}" for v in (*start, *end))
    return f'<geom name="{name}" type="capsule" fromto="{points}" size="{radius:.17g}" class="link"/>'


def mjcf(arm: Arm, tool_length: float, base: tuple[float, float, float] = (0.0, 0.0, 0.0), *,
         tool: str = "", attributes: str = "") -> str:
    """The MJCF ``<body>`` of ``arm`` (no ``<mujoco>`` around it), its base frame at ``base``
    ``(x, y, yaw)`` on the table (z = 0), with a site ``pusher`` ``tool_length`` beyond the flange
    along its z axis and a site ``flange`` at the flange. Joints are ``joint1`` ... and bodies
    ``link1`` ...; geoms use the default class ``link``, which the caller defines.

    The simulation adds to it: ``tool``, MJCF put in the body that carries the flange (in that
    body's frame, whose axes are the flange's), holds the pusher; ``attributes`` (with a leading
    space) are given to every body: gravity compensation, a default class for the joints.

    >>> xml = mjcf(ARMS["panda"], 0.12)
    >>> xml.count("<joint "), xml.count('name="pusher"'), xml.count('name="flange"')
    (7, 1, 1)
    """
    x, y, yaw = base
    out = [f'<body name="base" pos="{x:.17g} {y:.17g} 0" quat="{math.cos(yaw / 2):.17g} 0 0 {math.sin(yaw / 2):.17g}"{attributes}>']
    closing = ["</body>"]
    inertia = 0.4 * arm.radius ** 2  # per kg: a solid ball of the capsules' radius
    for k, (a, d, alpha) in enumerate(arm.dh, 1):
        held = (f'<inertial pos="0 0 0" mass="{arm.masses[k - 1]:.17g}" '
                f'diaginertia="{" ".join([f"{inertia * arm.masses[k - 1]:.17g}"] * 3)}"/>')
        if arm.convention == "modified":
            # Rx(alpha) Tx(a) Rz(q) Tz(d): the hinge turns about the z axis through Rx(alpha) Tx(a),
            # which Tz(d) only slides along, so the body sits at Rx(alpha) (a, 0, d).
            pos = _rot_x(alpha, np.array([a, 0.0, d]))
            out.append(_capsule(np.zeros(3), pos, arm.radius, f"shape{k}"))
            out.append(f'<body name="link{k}" pos="{" ".join(f"{v:.17g}" for v in pos)}" quat="{_quat_x(alpha)}"{attributes}>')
            out.append(f'<joint name="joint{k}" axis="0 0 1" range="{arm.lower[k - 1]:.17g} {arm.upper[k - 1]:.17g}"/>')
            out.append(held)
        else:
            # Rz(q) Tz(d) Tx(a) Rx(alpha): the hinge turns at the frame before; the next frame sits at (a, 0, d).
            out.append(f'<body name="link{k}"{attributes}>')
            out.append(f'<joint name="joint{k}" axis="0 0 1" range="{arm.lower[k - 1]:.17g} {arm.upper[k - 1]:.17g}"/>')
            out.append(held)
            end = np.array([a, 0.0, d])
            out.append(_capsule(np.zeros(3), np.array([0.0, 0.0, d]), arm.radius, f"shape{k}a"))
            out.append(_capsule(np.array([0.0, 0.0, d]), end, arm.radius, f"shape{k}b"))
            out.append(f'<body name="frame{k}" pos="{a:.17g} 0 {d:.17g}" quat="{_quat_x(alpha)}"{attributes}>')
            closing.append("</body>")
        closing.append("</body>")
    out.append(_capsule(np.zeros(3), np.array([0.0, 0.0, arm.flange]), arm.radius * 0.8, "shape_flange"))
    out.append(f'<site name="flange" pos="0 0 {arm.flange:.17g}"/>')
    out.append(f'<site name="pusher" pos="0 0 {arm.flange + tool_length:.17g}"/>')
    out.append(tool)
    return "\n".join(filter(None, out + closing))


def beyond_reach(scene: Scene, name: str, pose: np.ndarray, slack: float = 0.0) -> float:
    """How far (m) the scene's arm falls short of holding the pusher flush on any pushable edge of
    part ``name`` at ``pose``, if the part may be anywhere within ``slack`` of it: the least, over
    the edges, of the flange's distance from the shoulder beyond :attr:`Arm.span` (the flange is
    ``tool_length`` straight above the face's middle, ``push_height`` over the table). Positive:
    no posture of the arm holds the pusher on the part there, certainly; otherwise the bound
    says nothing (the inverse kinematics tells).

    >>> from dataclasses import replace
    >>> from planner.model.robot import Robot
    >>> from planner.model.scene_file import load_scene
    >>> scene = load_scene("scenes/parts/swap.yaml")
    >>> scene = replace(scene, robot=Robot("panda", np.array([0.0, -0.4, math.pi / 2]), 0.12))
    >>> beyond_reach(scene, "red", scene.part("red").start) < 0, beyond_reach(scene, "red", [2.0, 0.0, 0.0]) > 0
    (True, True)
    """
    robot, part = scene.robot, scene.part(name)
    arm = ARMS[robot.model]
    x, y, theta = (float(v) for v in pose)
    c, s = math.cos(theta), math.sin(theta)
    middles = np.array([part.slider.contact(e, scene.pusher.width).mean(axis=0) for e in part.edges])
    faces = np.c_[x + c * middles[:, 0] - s * middles[:, 1], y + s * middles[:, 0] + c * middles[:, 1]]
    flat = np.linalg.norm(faces - robot.base[:2], axis=1)
    rise = robot.push_height + robot.tool_length - arm.shoulder
    return float((np.hypot(flat, rise) - slack).min() - arm.span)
