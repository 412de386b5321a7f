"""What a run does besides planning: the options of :func:`planner.pipeline.run`, apart from the
scene and from the planner's own options (:class:`~planner.model.options.PlannerOptions`).

Poses and angles are in metres and **radians** (the command's flags take degrees and convert).
:meth:`RunOptions.checked` finds every bad value before any work, each error naming the option
(the command names its flag instead, :data:`planner.cli.ARGUMENTS`):

>>> RunOptions(sim_mu=0.4).checked(None)
Traceback (most recent call last):
...
planner.model.fields.SceneError: sim_mu: only applies with simulate (a number of MuJoCo runs)
>>> RunOptions(simulate=2, pose_noise=(-0.0, 0.0)).checked(None).pose_noise
(0.0, 0.0)
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from pathlib import Path

from ..model.extras import have, needs
from ..model.fields import SceneError, shown
from ..model.scene import Scene
from ..model.scene_file import MU_RANGE

__all__ = ["MAX_NOISE", "RunOptions"]

#: The most observation noise a closed loop takes: standard deviations, m and rad (45 degrees).
MAX_NOISE = (0.1, math.pi / 4)

#: The options that only apply to a simulation.
_SIMULATION = ("sim_mu", "sim_cf_offset", "start_error", "bumps", "pose_noise", "closed_loop", "observe", "mjcf")


@dataclass(frozen=True)
class RunOptions:
    """What :func:`~planner.pipeline.run` does with a scene (module docstring); every field's
    default does nothing of it."""

    #: A plan file to check against the scene and run instead of planning (needs verify or simulate).
    plan_file: str | Path | None = None
    #: Re-simulate every push under this many support distributions (:func:`planner.verify`).
    verify: int | None = None
    #: Time the plan into the pusher's trajectory, written as ``<name>.trajectory.csv``.
    trajectory: bool = False
    #: Run the plan in MuJoCo on this many support distributions (:func:`planner.simulate`).
    simulate: int | None = None
    sim_mu: float | None = None  # the simulation's pusher friction (default: the scene's)
    sim_cf_offset: tuple[float, float] | None = None  # the supports' centre moved from the CF (slider frame, m)
    start_error: tuple[float, float, float] | None = None  # the part starts this far off (world frame; m, m, rad)
    bumps: tuple[tuple[float, float, float, float], ...] = ()  # (t s, dx m, dy m, dtheta rad): knocks
    pose_noise: tuple[float, float] | None = None  # the closed loop's observation noise (m, rad)
    closed_loop: bool = False  # observe the part and re-plan when it strays (planner.execution.tracker)
    observe: str | None = None  # the closed loop's observer: "truth" (the default) or "camera"
    mjcf: Path | None = None  # write the first run's MuJoCo model here
    #: Map the goal positions reachable in at most this many (1 or 2) stable pushes.
    reach: int | None = None
    #: The part whose reachable set is mapped, the others obstacles where they stand (a scene of several).
    part: str | None = None
    #: Where the plan, recording and other outputs are written (None: nothing is written).
    out: Path | None = None
    #: Write the scene as planned here, in the plain schema.
    export_scene: Path | None = None

    def checked(self, scene: Scene | None) -> "RunOptions":
        """These options, once every value is found good for ``scene`` (None: the values alone);
        ``-0.0`` noise is ``0.0``.

        Raises
        ------
        SceneError
            Naming the option at fault.
        """
        from ..execution.mujoco_sim import MAX_RUNS  # loads no MuJoCo, only its bounds
        from ..execution.verify import MAX_DISTRIBUTIONS

        for name, most in (("verify", MAX_DISTRIBUTIONS), ("simulate", MAX_RUNS)):
            if (value := getattr(self, name)) is not None and (isinstance(value, bool) or not isinstance(value, int)
                                                               or not 1 <= value <= most):
                raise SceneError(name, f"must be 1 to {most} distributions, got {shown(value)}")
        if self.plan_file is not None and self.verify is None and self.simulate is None:
            raise SceneError("plan_file", "needs verify or simulate: a plan file is only read to be checked")
        if self.simulate is None:
            for name in _SIMULATION:
                if getattr(self, name) not in (None, False, ()):
                    raise SceneError(name, "only applies with simulate (a number of MuJoCo runs)")
        if self.observe is not None and not self.closed_loop:
            raise SceneError("observe", "only applies with closed_loop (the open loop observes nothing)")
        if self.observe == "camera" and self.pose_noise is not None:
            raise SceneError("pose_noise", "is the truth observer's noise; a camera has its own (the scene's camera: "
                                           "block)")
        for name in ("start_error", "pose_noise", "sim_cf_offset"):
            if (values := getattr(self, name)) is not None and not all(abs(v) < math.inf for v in values):
                raise SceneError(name, f"must be finite, got {' '.join(map(str, values))}")
        for bump in self.bumps:
            if not all(abs(v) < math.inf for v in bump):
                raise SceneError("bump", f"must be finite, got {' '.join(map(str, bump))}")
            if bump[0] < 0:
                raise SceneError("bump", "a bump's time must be >= 0")
        # Physical ranges: beyond them MuJoCo's state blows up (a friction of 1e300, a knock of
        # 1e20 radians) or the perturbation means nothing (a knock of many turns is one of less
        # than half a turn; a pose seen 10 cm off is not a measurement).
        for name, turn in [("start_error", self.start_error), *(("bump", bump[1:]) for bump in self.bumps)]:
            if turn is not None and not abs(turn[2]) <= math.pi:
                raise SceneError(name, f"must turn the part by at most half a turn (180 degrees), got "
                                       f"{math.degrees(turn[2]):g} degrees")
        noise = self.pose_noise
        if noise is not None and min(noise) < 0:
            raise SceneError("pose_noise", f"standard deviations must be >= 0, got {' '.join(map(str, noise))}")
        if noise is not None and not (abs(noise[0]) <= MAX_NOISE[0] and abs(noise[1]) <= MAX_NOISE[1]):
            raise SceneError("pose_noise", f"must be at most {MAX_NOISE[0]:g} m and "
                                           f"{math.degrees(MAX_NOISE[1]):g} degrees, got {noise[0]:g} m and "
                                           f"{math.degrees(noise[1]):g} degrees")
        if self.sim_mu is not None and not MU_RANGE[0] <= self.sim_mu <= MU_RANGE[1]:
            raise SceneError("sim_mu", f"must be a friction coefficient in {MU_RANGE[0]:g}..{MU_RANGE[1]:g} (as "
                                       f"pusher.mu), got {self.sim_mu:g}")
        if self.reach is not None and self.reach not in (1, 2):
            raise SceneError("reach", f"must be 1 or 2 pushes, got {self.reach}")
        if self.reach is not None and not have("matplotlib"):  # found before the work, not after it
            raise SceneError("reach", f"the map's PNG {needs('matplotlib')}")
        if self.simulate is not None:
            from ..execution.mujoco_sim import needs_mujoco  # MuJoCo is only looked for here

            needs_mujoco()
        if scene is not None and scene.robot is not None:
            self._fit_arm()
        if scene is not None:
            self._fit(scene)
        return replace(self, pose_noise=None if noise is None else tuple(abs(v) for v in noise))

    def _fit_arm(self) -> None:
        """Refuse, before the work, what needs the arm's joints (written, or followed by the arm
        in the simulation, open or closed loop) without mink."""
        for name, asked in (("trajectory", self.trajectory), ("simulate", self.simulate is not None)):
            if asked and not have("mink"):
                raise SceneError(name, f"the arm's joints {needs('mink')}")

    def _fit(self, scene: Scene) -> None:
        """Refuse what ``scene`` does not take: a part it does not have, or one not named where
        it has several. (A start error of a scene of several parts moves the part the plan moves
        first, which only the plan knows: the simulation checks where it puts it.)"""
        if scene.robot is not None:
            from ..arm.arms import beyond_reach  # the arm's numbers, no inverse kinematics

            for k, part in enumerate(scene.parts):
                if (short := beyond_reach(scene, part.name, part.start)) > 0:
                    raise SceneError("start" if len(scene.parts) == 1 else f"parts[{k}].start",
                                     f"the {scene.robot.model} cannot hold the pusher on any allowed edge of the part "
                                     f"there: the nearest is {short * 1000:.0f} mm beyond the reach of its links")
        if self.part is not None:
            scene.part(self.part)
        elif self.reach is not None and len(scene.parts) > 1:
            raise SceneError("part", f"the reachable set is one part's: name one of {', '.join(scene.names)}")
        if self.sim_cf_offset is not None:
            from ..execution.mujoco_sim import support_centre

            for name in scene.names:
                support_centre(scene.move_scene(name, scene.starts), self.sim_cf_offset)
        if self.start_error is not None and len(scene.parts) == 1:
            from ..model.scene_file import placement_fault

            moved = scene.start + self.start_error
            if (fault := placement_fault(scene.slider, scene.obstacles, scene.workspace, moved)) is not None:
                raise SceneError("start_error", f"puts the part where it cannot be: {fault}")
