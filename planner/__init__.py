"""Planning guaranteed-stable pushes among obstacles (Lynch & Mason 1996, §4).

:func:`load_scene` reads a YAML scene, :func:`plan` searches with OMPL, :func:`one_step` answers
the paper's one-step question, :func:`reachability` answers reachable / unreachable (certified) /
unknown for many goals, :func:`controllability` says what the stable pushes can reach (1996 §2-3),
:func:`verify` re-simulates a plan (or one read by :func:`load_plan`)
under many support distributions. Modules: :mod:`.scene` (file format), :mod:`.bodies` (slider +
pusher geometry), :mod:`.validity` (fcl collision rule), :mod:`.pushes` (stable pushes per edge),
:mod:`.one_step`, :mod:`.search` (OMPL), :mod:`.plan_file` (JSON), :mod:`.verify` (re-simulation),
:mod:`.recording` (rerun) and :mod:`.recorder` (written beside the search), :mod:`.cli` (the ``plan``
command), :mod:`.geodesic` (a lower bound on any plan's length), and the benchmarks :mod:`.bench`,
:mod:`.quality` and :mod:`.reach_bench`.
"""

from .queries.controllability import SceneControllability, controllability
from .queries.one_step import OneStep, one_step
from .model.plan_file import Plan, Push, Transit, load_plan
from .queries.reachability import Reach, certify_unreachable, reachability
from .model.scene import DEFAULT_PLANNER, Scene, SceneError, load_scene, parse_scene
from .search import plan
from .execution.verify import Verification, verify

__all__ = ["DEFAULT_PLANNER", "OneStep", "Plan", "Reach", "Scene", "SceneError", "Push", "Transit",
           "certify_unreachable", "load_plan", "load_scene", "one_step", "parse_scene", "plan", "reachability",
           "Verification", "verify", "SceneControllability", "controllability"]
