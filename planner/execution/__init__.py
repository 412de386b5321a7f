"""Running a plan: re-simulation of its pushes under many support distributions
(:mod:`.verify`, the independent quasi-static simulator of :mod:`mechanics.quasistatic`), and the
pusher's time-parameterised trajectory a robot follows (:mod:`.trajectory`, jerk-limited time laws
from ruckig).

Allowed imports: :mod:`mechanics`, :mod:`planner.model`, :mod:`planner.world`,
:mod:`planner.actions` and this package (a plan is executed as it is, never searched again).
"""
