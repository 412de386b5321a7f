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

from importlib import import_module
from typing import TYPE_CHECKING, Any

from .model.fields import SceneError
from .model.options import DEFAULT_PLANNER
from .model.plan_file import Plan, Push, Transit, load_plan
from .model.scene import Scene, load_scene, parse_scene
from .queries.one_step import OneStep, one_step
from .queries.reachability import Reach, certify_unreachable, reachability
from .search import plan

if TYPE_CHECKING:
    from .execution.verify import Verification, verify
    from .queries.controllability import SceneControllability, controllability

__all__ = ["DEFAULT_PLANNER", "OneStep", "Plan", "Reach", "Scene", "SceneError", "Push", "Transit",
           "certify_unreachable", "load_plan", "load_scene", "one_step", "parse_scene", "plan", "reachability",
           "Verification", "verify", "SceneControllability", "controllability"]

#: Public names imported on first use, by module: the controllability report needs scipy and
#: the re-simulator its own mechanics, which a plan run does not (tests/test_startup.py).
_ON_FIRST_USE = {"SceneControllability": ".queries.controllability", "controllability": ".queries.controllability",
                 "Verification": ".execution.verify", "verify": ".execution.verify"}


def __getattr__(name: str) -> Any:
    if name not in _ON_FIRST_USE:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(import_module(_ON_FIRST_USE[name], __name__), name)
    globals()[name] = value  # later look-ups find it without coming here
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *_ON_FIRST_USE})
