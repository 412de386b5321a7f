"""The pipeline: what the ``plan`` command does, as one library call.

:func:`run` takes a scene (of one part or several), :class:`RunOptions` and the planner's options
(:class:`~planner.model.options.PlannerOptions`, default: the scene's own) and does, in order,
what they ask: certify the goal unreachable or plan it (or fit a plan read from a file), verify
the plan under many support distributions, time it into a trajectory, run it in MuJoCo open loop
or closed loop, map the reachable set, and write the outputs. It returns an :class:`Outcome`
holding every result and the lines the command prints. The command (:mod:`planner.cli`) parses
its flags into these options, calls :func:`run`, prints and exits; batch workers call the same.

>>> from planner import load_scene, run, RunOptions
>>> outcome = run(load_scene("scenes/battery.yaml"), RunOptions(verify=2))
>>> outcome.plan.headline(), outcome.verification.passed, outcome.code
('1 push, cost 0.063 m, length 0.063 m', True, 0)

Allowed imports: :mod:`mechanics`, every package below it (:mod:`planner.model` to
:mod:`planner.outputs`) and this one.
"""

from .options import RunOptions
from .outcome import Outcome, OutputError
from .run import run

__all__ = ["Outcome", "OutputError", "RunOptions", "run"]
