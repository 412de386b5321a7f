"""The arm that holds the pusher: a scene's ``robot:`` block (:class:`Robot`, read by :func:`read_robot`).

Frames. The arm's *base frame* lies on the table top (z = 0) at ``base`` = ``(x, y, yaw)`` of the
scene frame; for the Panda it is Franka's frame 0, where joint 1's axis meets the mounting
surface. The *pusher frame*'s origin is the middle of the pushing face, ``tool_length`` beyond
the flange along the flange's z axis, ``push_height`` above the table while the pusher is on it;
there the flange's z axis points straight down and the pusher's heading is the flange x axis's
heading plus a constant of the mount (:mod:`planner.arm`).

>>> robot = read_robot({"model": "panda", "base": [0.0, -0.4, 90], "tool_length": 0.12}, (-1, -1, 1, 1))
>>> robot.model, robot.base.round(4).tolist(), robot.push_height
('panda', [0.0, -0.4, 1.5708], 0.01)
>>> read_robot({"model": "kuka", "base": [0, 0, 0], "tool_length": 0.1}, (-1, -1, 1, 1))
Traceback (most recent call last):
...
planner.model.fields.SceneError: robot.model: must be one of panda, ur5e, got 'kuka'
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from .arms import ARMS
from .fields import SceneError, keys, number, shown, vector

__all__ = ["MAX_TOOL", "ROBOT_MODELS", "Robot", "read_robot"]

#: The arms a scene may name (their kinematics: :data:`planner.model.arms.ARMS`).
ROBOT_MODELS = tuple(ARMS)
#: Longest tool and highest push (m): beyond an arm's reach, so a number typed wrong, not a tool.
MAX_TOOL = 1.0


@dataclass(frozen=True, eq=False)
class Robot:
    """An arm holding the pusher (module docstring); ``base`` is ``(x, y, yaw)`` in m, m, rad."""

    model: str
    base: np.ndarray
    tool_length: float
    push_height: float = 0.01

    def to_dict(self) -> dict:
        """The block as a scene file writes it (yaw in degrees)."""
        x, y, yaw = (float(v) for v in self.base)
        return {"model": self.model, "base": [x, y, math.degrees(yaw)], "tool_length": self.tool_length,
                "push_height": self.push_height}


def read_robot(value: Any, workspace: tuple[float, float, float, float]) -> Robot:
    """The ``robot:`` block ``value``, checked: a known model, a base on the table (inside
    ``workspace``) with its yaw in degrees, a tool length and a push height each positive and at
    most :data:`MAX_TOOL`."""
    spec = keys(value, "robot", ("model", "base", "tool_length"), ("push_height",))
    if spec["model"] not in ROBOT_MODELS:
        raise SceneError("robot.model", f"must be one of {', '.join(ROBOT_MODELS)}, got {shown(spec['model'])}")
    x, y, yaw = vector(spec["base"], "robot.base", 3)
    xmin, ymin, xmax, ymax = workspace
    if not (xmin <= x <= xmax and ymin <= y <= ymax):
        raise SceneError("robot.base", f"({x:g}, {y:g}) is off the table (the workspace, x {xmin:g} to {xmax:g}, "
                                       f"y {ymin:g} to {ymax:g})")
    tool = number(spec["tool_length"], "robot.tool_length", positive=True)
    height = number(spec.get("push_height", 0.01), "robot.push_height", positive=True)
    for key, v in (("tool_length", tool), ("push_height", height)):
        if v > MAX_TOOL:
            raise SceneError(f"robot.{key}", f"must be at most {MAX_TOOL:g} m, got {v:g}")
    return Robot(spec["model"], np.array([x, y, math.remainder(math.radians(yaw), 2 * math.pi)]), float(tool),
                 float(height))
