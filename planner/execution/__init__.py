"""Running a plan: re-simulation of its pushes under many support distributions
(:mod:`.verify`, the independent quasi-static simulator of :mod:`mechanics.quasistatic`), the
pusher's time-parameterised trajectory a robot follows (:mod:`.trajectory`, jerk-limited time laws
from ruckig), and the whole plan run open-loop along that trajectory in MuJoCo
(:mod:`.mujoco_sim`; MuJoCo is imported only when a simulation runs), with a scene's arm holding
the pusher (:mod:`.arm_sim`).

Allowed imports: :mod:`mechanics`, :mod:`planner.model`, :mod:`planner.world`,
:mod:`planner.arm` (the arm's model and joints, for a scene with a robot), :mod:`planner.actions`
and this package (a plan is executed as it is, never searched again).
"""
