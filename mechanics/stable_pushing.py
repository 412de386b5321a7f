"""Stable pushing and one-step goals (Lynch 1992, §5.1, example 1).

A push of an edge about ``COR_p`` is *guaranteed stable* when sticking (``ss...s``) is force
possible (P) for the slider moving with the pusher and every other contact mode is impossible
(§4): the contact is kept whatever the support pressure. One-step planning asks this of
``COR_total``, the one constant twist taking the start to the goal (:func:`~.se2.log_pose`); the
paper's three goals are the three answers of :func:`classify_goal`:

* **Goal1** ``'guaranteed'``: ``COR_total`` is a guaranteed-stable ``COR_p``, so pushing about it
  reaches the goal;
* **Goal2** ``'possible'``: sticking is not impossible but not guaranteed (U, or P with another
  mode possible): the push may or may not reach the goal;
* **Goal3** ``'impossible'``: sticking is force impossible (I), so the slider cannot follow the
  pusher about ``COR_total``.

Procedure STABLE (Lynch & Mason 1996, :mod:`.stable`) is a proven inner bound of the guaranteed
set, so a twist it accepts is Goal1 without the combined analysis; outside it the answer rests on
:func:`~.possible_motions.possible_motions`, whose "impossible" is a sampled one.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from .contacts import ContactConfiguration
from .force_status import force_status
from .possible_motions import possible_motions
from .slider import Slider
from .stable import procedure_stable
from .support import SupportModel
from .wrenches import contact_wrench_cone

__all__ = ["GOALS", "classify_goal"]

#: The paper's name for each answer of :func:`classify_goal` (its fig. 12).
GOALS = {"guaranteed": "goal1", "possible": "goal2", "impossible": "goal3"}


def classify_goal(
    slider: Slider,
    edge: int,
    mu: float,
    twist: ArrayLike,
    support: SupportModel | None = None,
    width: float | None = None,
) -> str:
    """``'guaranteed'``, ``'possible'`` or ``'impossible'``: pushing ``edge`` about ``twist``.

    ``twist`` is the pusher's (slider-frame) twist, e.g. ``COR_total``; ``support`` defaults to the
    slider's footprint (with a ``cf_radius``, the answer holds for every CF in that disk),
    ``width`` (the pusher's face) to the whole edge.

    Examples
    --------
    The 9 V battery (48.5 x 26.5 mm) pushed on its back face (edge 3, normal +x), mu = 1. A CW
    turn about a point 9 cm to the right of the face's foot is Goal1; turning about the CF is
    Goal2 (sticking is U); pulling the battery back is Goal3.

    >>> from mechanics import cor_to_twist
    >>> battery = Slider([[-0.02425, -0.01325], [0.02425, -0.01325], [0.02425, 0.01325], [-0.02425, 0.01325]])
    >>> [classify_goal(battery, 3, 1.0, v) for v in (cor_to_twist([0.0, -0.09], -1), cor_to_twist([0, 0], 1), [-1, 0, 0])]
    ['guaranteed', 'possible', 'impossible']
    """
    v = np.asarray(twist, dtype=float)
    support = SupportModel.of_slider(slider) if support is None else support
    # STABLE proves stability for the known CF only.
    if mu > 0 and support.cf_radius == 0 and procedure_stable(slider, edge, mu, width).contains(v):
        return "guaranteed"
    config = ContactConfiguration.slider_edge(slider, edge, mu, width)
    sticking = "s" * len(config)
    status = force_status(v, contact_wrench_cone(config, sticking), support).status
    if status == "I":
        return "impossible"
    if status == "P":
        others = [m for mode, m in possible_motions(config, v, support).items() if mode != sticking]
        if not any(m.can_occur for m in others):
            return "guaranteed"
    return "possible"
