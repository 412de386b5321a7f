"""An independent quasi-static pushing simulator with the exact point-support limit surface.

It checks pushes without any of the stable-region code (:mod:`mechanics.stable`,
:mod:`mechanics.steering`): it solves the contact problem of every step from first principles.

* :mod:`.support`: weighted support points and their limit surface (load of a twist, twist of a
  load, facets where the rotation centre sits on a support point);
* :mod:`.sampling`: distributions over a footprint (grid, random, extreme dipods and tripods);
* :mod:`.contact`: pusher contacts with Coulomb friction and their modes;
* :mod:`.step`: one quasi-static step, every consistent contact mode (:func:`solve_step`);
* :mod:`.push`: a push integrated over its duration (:func:`simulate_push`).

``python -m mechanics.quasistatic`` prints the simulator's speed.
"""

from .contact import Contact, ContactMode, edge_contacts
from .push import DEFAULT_STEPS, PushResult, adjoint, simulate_push
from .sampling import dipod_supports, grid_support, random_support, tripod_supports
from .step import Solution, StepResult, solve_step
from .support import SupportDistribution

__all__ = [
    "DEFAULT_STEPS",
    "Contact",
    "ContactMode",
    "PushResult",
    "Solution",
    "StepResult",
    "SupportDistribution",
    "adjoint",
    "dipod_supports",
    "edge_contacts",
    "grid_support",
    "random_support",
    "simulate_push",
    "solve_step",
    "tripod_supports",
]
