"""Combined analysis: the possible slider motions of each contact mode (Lynch 1992, §4).

For a pusher moving with twist ``V_p`` (its COR, ``COR_p``), a contact mode can occur only with a
slider twist that is both *kinematically* legal for the mode (:func:`~.kinematics.kinematic_cone`,
§2) and not *force* impossible (status P or U, :func:`~.force_status.force_status`, §3). The
intersection of the two is guaranteed to hold the slider's actual motion; a mode whose
intersection is empty cannot occur.

Whether the intersection is empty is decided here by *sampling* the kinematic cone: random strictly
positive combinations of its generators (the open cone of §2.3), each given a certified force
status. A sample that is P or U proves the mode can occur (a U still open after refinement is
counted too: never wrongly impossible); none does not prove the opposite,
though the samples are spread over every scale of the generators (docs/mechanics.md, "Exact edge region": no
counterexample was found to the paper's claim that a stable push excludes all other modes). The
pointwise question, :func:`mode_possible`, has no such caveat.

The COR regions of a mode (for pictures like the paper's fig. 11) are its kinematic COR region
intersected with the P and U regions of the ray search (:func:`~.force_status.force_status_regions`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import shapely
from numpy.typing import ArrayLike

from .cones import Cone
from .contacts import ContactConfiguration
from .force_status import force_status, force_status_regions
from .kinematics import contact_modes, kinematic_cone, kinematic_cones
from .support import SupportModel
from .wrenches import contact_wrench_cone

__all__ = ["ModeMotions", "mode_possible", "possible_motions"]

#: Default number of sampled slider twists per contact mode.
DEFAULT_SAMPLES = 48

#: Extra sample levels for a twist whose status the default level left open: near the pusher's
#: contacts, samples with a COR on the slider's boundary need a finer support grid to be settled.
REFINEMENTS = 3


@dataclass(frozen=True)
class ModeMotions:
    """The possible slider motions of one contact ``mode`` for a given pusher twist.

    ``kinematic`` is the mode's closed kinematic cone (its motions are the relative interior),
    ``wrenches`` its composite wrench cone. ``can_occur`` is True when ``witness``, a sampled
    kinematically legal twist, is not force impossible; ``status`` is the witness's status
    (``'P'`` or ``'U'``), ``None`` with the witness when no sample qualified.
    """

    mode: str
    kinematic: Cone
    wrenches: Cone
    can_occur: bool
    witness: np.ndarray | None
    status: str | None

    def regions(
        self, support: SupportModel, window: ArrayLike, rays: int = 24, steps: int = 10
    ) -> dict[int, dict[str, shapely.Geometry]]:
        """Kinematic COR region per sense, split by force status: ``{sense: {'P': ..., 'U': ...}}``.

        Polygons for a full-dimensional kinematic cone, segments or points for a thin one; the
        force regions come from ``rays`` rays of ``steps`` bisection steps each.
        """
        kinematic = {sense: self.kinematic.cor_region(sense, window) for sense in (1, -1)}
        if all(region.is_empty for region in kinematic.values()):  # nothing to draw: skip the search
            return {sense: {"P": shapely.Polygon(), "U": shapely.Polygon()} for sense in (1, -1)}
        force = force_status_regions(self.wrenches, support, window, rays, steps)
        return {sense: {s: kinematic[sense].intersection(force[sense][s]) for s in "PU"} for sense in (1, -1)}


def _interior_samples(cone: Cone, samples: int, rng: np.random.Generator) -> np.ndarray:
    """Twists in the relative interior of ``cone``: every generator with a positive weight.

    Log-uniform weights over six decades reach close to every edge and facet of the cone.
    """
    g = cone.generators
    if len(g) <= 1:  # a ray (or the zero cone): its one direction is the whole interior
        return g
    weights = np.exp(rng.uniform(-7.0, 7.0, size=(samples, len(g))))
    return np.vstack([g.sum(axis=0), weights @ g])


def mode_possible(
    config: ContactConfiguration, mode: str, pusher_twist: ArrayLike, slider_twist: ArrayLike, support: SupportModel
) -> bool:
    """Whether the slider can move with ``slider_twist`` under ``mode`` when the pusher moves with
    ``pusher_twist``: kinematically legal for the mode and force P or U.

    Examples
    --------
    The 2 x 1 block's bottom face pushed straight up, mu = 0.5. Moving with the pusher is sticking
    (``ss``) and force possible; pivoting about the left end (CCW about ``(-2, 0)``, mode ``sf``)
    is kinematically legal but needs a load the one friction cone cannot give; sliding right
    along the face (``rr``) cannot give a pure pivot at all.

    >>> from mechanics import Slider, cor_to_twist
    >>> block = Slider([[-1, 0], [1, 0], [1, 1], [-1, 1]])
    >>> face = ContactConfiguration.slider_edge(block, 0, 0.5)
    >>> support = SupportModel.of_slider(block)
    >>> mode_possible(face, "ss", [0, 1, 0], [0, 1, 0], support)
    True
    >>> pivot = cor_to_twist([-2, 0], 1)
    >>> mode_possible(face, "sf", [0, 1, 0], pivot, support), mode_possible(face, "rr", [0, 1, 0], pivot, support)
    (False, False)
    """
    v = np.asarray(slider_twist, dtype=float)
    if mode not in contact_modes(config) or not kinematic_cone(config, mode, pusher_twist).contains(v, interior=True):
        return False
    return force_status(v, contact_wrench_cone(config, mode), support).status != "I"


def possible_motions(
    config: ContactConfiguration,
    pusher_twist: ArrayLike,
    support: SupportModel,
    samples: int = DEFAULT_SAMPLES,
    seed: int = 0,
) -> dict[str, ModeMotions]:
    """The combined analysis of every force-carrying contact mode, by mode (§4).

    Each mode's kinematic cone is sampled with ``samples`` twists (a fixed ``seed``: the answer
    is reproducible); see the module's note on what ``can_occur = False`` means.

    Examples
    --------
    The 2 x 1 block's bottom face, mu = 0.5, pushed by a CCW rotation about ``(-3, 0.5)``, a
    guaranteed-stable push (docs/mechanics.md, "Fixtures", fixture A): the slider moves with the pusher,
    sticking, and no other contact mode can occur.

    >>> from mechanics import Slider, cor_to_twist
    >>> block = Slider([[-1, 0], [1, 0], [1, 1], [-1, 1]])
    >>> face = ContactConfiguration.slider_edge(block, 0, 0.5)
    >>> motions = possible_motions(face, cor_to_twist([-3, 0.5], 1), SupportModel.of_slider(block))
    >>> [mode for mode, m in motions.items() if m.can_occur], motions["ss"].status
    (['ss'], 'P')

    Pushed about the CF instead, sticking is only U and nothing can be ruled out: every mode can
    occur, depending on the unknown support pressure.

    >>> motions = possible_motions(face, cor_to_twist([0, 0.5], 1), SupportModel.of_slider(block))
    >>> motions["ss"].status, all(m.can_occur for m in motions.values()), len(motions)
    ('U', True, 9)
    """
    rng = np.random.default_rng(seed)
    out = {}
    for mode, cone in kinematic_cones(config, pusher_twist).items():
        wrenches = contact_wrench_cone(config, mode)
        witness, status = None, None
        for twist in _interior_samples(cone, samples, rng):
            verdict = force_status(twist, wrenches, support)
            if verdict.status == "U" and not verdict.exact:  # open: refine before believing it
                verdict = force_status(twist, wrenches, support, REFINEMENTS)
            if verdict.status != "I":
                witness, status = twist, verdict.status
                break
        out[mode] = ModeMotions(mode, cone, wrenches, witness is not None, witness, status)
    return out
