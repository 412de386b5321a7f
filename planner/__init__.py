"""Planning guaranteed-stable pushes among obstacles (Lynch & Mason 1996, §4).

A :class:`Planner` session sets a scene up once (its edges' stable regions, the collision model,
the transits between edges) and then answers many plans, re-plans and reachability queries;
poses are ``(x, y, theta)`` in metres and **radians** (a scene file's are in degrees):

>>> from planner import Planner, load_scene
>>> session = Planner(load_scene("scenes/parking.yaml"), {"seed": 1})
>>> first = session.plan()                        # from the scene's start to its goal
>>> first.solved, first.cost < 1.0                # metres of the part's path, plus each switch's cost
(True, True)
>>> moved = session.plan(start=session.scene.start + [0.005, 0.0, 0.02])  # re-plan: joins the first
>>> moved.solved
True
>>> [a.status for a in session.reachability([[0.3, 0.3, 0.0], [0.0, -0.04, 0.0]])]  # the 2nd is in a wall
['reachable', 'unreachable']

:func:`plan` and :func:`reachability` are the same asked once of a fresh session. A scene of
several parts (``parts:``) is planned as a whole: the plan moves every part to its goal in an
order the session searches for, pushing parts aside where it must:

>>> tray = Planner(load_scene("scenes/parts/swap.yaml")).plan()     # two blocks trade places
>>> tray.solved, [m.part for m in tray.moves]
(True, ['red', 'blue', 'red'])

:func:`load_scene` reads a YAML scene, :func:`plan` searches with OMPL, :func:`one_step` answers
the paper's one-step question, :func:`reachability` answers reachable / unreachable (certified) /
unknown for many goals, :func:`controllability` says what the stable pushes can reach (1996 §2-3),
:func:`verify` re-simulates a plan (or one read by :func:`load_plan`, checked against its scene
by :func:`fit_plan`) under many support distributions, and :func:`run` does all the ``plan``
command does (certify or plan, verify, simulate, map, write) as one call returning an
:class:`Outcome`. The subpackages, lowest first (each imports only from those before it):
:mod:`.model` (scenes, plans and their files), :mod:`.world` (collisions, free space),
:mod:`.actions` (stable pushes, transits, shortcuts), :mod:`.search` (OMPL), :mod:`.queries`
(sessions, one step, reachability, controllability, bounds), :mod:`.execution` (re-simulation,
trajectories, MuJoCo, the closed loop), :mod:`.outputs` (recording, pictures), :mod:`.pipeline`
(:func:`run`), :mod:`.batch` (many tasks on local workers or Ray) and :mod:`.bench`;
:mod:`.cli` is the ``plan`` command, over its flags (:mod:`.flags`).
"""

from importlib import import_module
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from .execution.fit import fit_plan
    from .execution.mujoco_sim import Simulation, simulate
    from .execution.trajectory import Trajectory, trajectory
    from .execution.verify import Verification, verify
    from .model.fields import SceneError
    from .model.options import DEFAULT_PLANNER, PlannerOptions
    from .model.plan import Move, Plan
    from .model.plan_file import load_plan
    from .model.scene import Part, Scene
    from .model.scene_file import load_scene, parse_scene
    from .model.segments import Push, Transfer, Transit
    from .queries.controllability import SceneControllability, controllability
    from .queries.one_step import OneStep, one_step
    from .queries.reachability import Reach, certify_unreachable
    from .queries.reachable_set import ReachableSet, reachable_set
    from .queries.session import Planner, plan, reachability
    from .pipeline import Outcome, RunOptions, run

__all__ = ["DEFAULT_PLANNER", "OneStep", "Plan", "Planner", "PlannerOptions", "Reach", "Scene", "SceneError", "Push", "Transit",
           "certify_unreachable", "load_plan", "load_scene", "one_step", "parse_scene", "plan", "reachability",
           "Verification", "verify", "fit_plan", "SceneControllability", "controllability", "ReachableSet",
           "reachable_set", "Trajectory", "trajectory", "Simulation", "simulate", "Part", "Move", "Transfer", "Outcome", "RunOptions", "run"]

#: Every public name is imported on first use, from its module: ``import planner`` itself loads
#: nothing (the ``plan`` command sets up the process before numpy is loaded, planner.cli), and the
#: controllability report (scipy) and the re-simulator are loaded only where used
#: (tests/planner/test_startup.py).
_ON_FIRST_USE = {
    "SceneError": ".model.fields", "DEFAULT_PLANNER": ".model.options", "PlannerOptions": ".model.options",
    "Planner": ".queries.session", "Plan": ".model.plan", "Move": ".model.plan", "Push": ".model.segments",
    "Transit": ".model.segments", "Transfer": ".model.segments", "load_plan": ".model.plan_file",
    "Scene": ".model.scene", "Part": ".model.scene", "load_scene": ".model.scene_file",
    "parse_scene": ".model.scene_file", "OneStep": ".queries.one_step", "one_step": ".queries.one_step",
    "Reach": ".queries.reachability", "certify_unreachable": ".queries.reachability",
    "reachability": ".queries.session", "plan": ".queries.session",
    "SceneControllability": ".queries.controllability", "controllability": ".queries.controllability",
    "Verification": ".execution.verify", "verify": ".execution.verify", "fit_plan": ".execution.fit",
    "ReachableSet": ".queries.reachable_set", "reachable_set": ".queries.reachable_set",
    "Trajectory": ".execution.trajectory", "trajectory": ".execution.trajectory",
    "Simulation": ".execution.mujoco_sim", "simulate": ".execution.mujoco_sim",
    "Outcome": ".pipeline", "RunOptions": ".pipeline", "run": ".pipeline",
}


def __getattr__(name: str) -> Any:
    if name not in _ON_FIRST_USE:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(import_module(_ON_FIRST_USE[name], __name__), name)
    globals()[name] = value  # later look-ups find it without coming here
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *_ON_FIRST_USE})
