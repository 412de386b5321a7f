"""Contact synthesis: which edge to push for a desired motion (Lynch 1992, §5.2, fig. 14).

With a fence pusher and a polygonal slider the only stable contact is edge-edge. Each pushable
edge has its region of guaranteed-stable ``COR_p`` (§5.1, :mod:`.stable_pushing`); to move the
slider with a given twist, push an edge whose region holds it. Figure 14 draws the sticking P
regions ``P1..Pn`` of all edges (the paper's guaranteed-stable regions) and the motions that are I
for every edge: those no edge-edge push can produce.
"""

from __future__ import annotations

from dataclasses import dataclass

import shapely
from numpy.typing import ArrayLike

from .contacts import ContactConfiguration
from .force_status import force_status_regions
from .slider import Slider
from .stable_pushing import classify_goal
from .support import SupportModel
from .wrenches import contact_wrench_cone

__all__ = ["EdgeRegions", "edge_regions", "stable_edges"]


def stable_edges(
    slider: Slider, mu: float, twist: ArrayLike, support: SupportModel | None = None, width: float | None = None
) -> tuple[int, ...]:
    """The pushable edges for which ``twist`` is a guaranteed-stable push (Goal1 of §5.1).

    Examples
    --------
    A 2 x 1 block, mu = 0.5: translating up (through the CF) is pushing the bottom face; down is
    pushing the top face; a sideways pull along the bottom face is no edge's push.

    >>> block = Slider([[-1, 0], [1, 0], [1, 1], [-1, 1]])
    >>> stable_edges(block, 0.5, [0, 1, 0]), stable_edges(block, 0.5, [0, -1, 0])
    ((0,), (2,))
    """
    support = SupportModel.of_slider(slider) if support is None else support
    return tuple(e for e in slider.pushable_edges
                 if classify_goal(slider, e, mu, twist, support, width) == "guaranteed")


@dataclass(frozen=True)
class EdgeRegions:
    """Fig. 14's data: ``possible[edge][sense]``, the COR region where sticking on ``edge`` is P,
    and ``impossible[sense]``, the CORs that are I for every pushable edge."""

    possible: dict[int, dict[int, shapely.Geometry]]
    impossible: dict[int, shapely.Geometry]


def edge_regions(
    slider: Slider,
    mu: float,
    support: SupportModel | None = None,
    window: ArrayLike | None = None,
    rays: int = 24,
    steps: int = 10,
) -> EdgeRegions:
    """Sticking P regions of every pushable edge (whole-edge contact) and the common I region.

    ``window``, ``rays`` and ``steps`` are those of :func:`~.force_status.force_status_regions`.

    Examples
    --------
    The 2 x 1 block, mu = 0.5: pushing the bottom face can turn the block about points far to
    its left (CCW) or right (CW), and nothing is impossible for all four faces near the CF.

    >>> block = Slider([[-1, 0], [1, 0], [1, 1], [-1, 1]])
    >>> regions = edge_regions(block, 0.5, rays=8, steps=4)
    >>> sorted(regions.possible), regions.possible[0][1].contains(shapely.Point(-3, 0.5))
    ([0, 1, 2, 3], True)
    >>> regions.impossible[1].contains(shapely.Point(0, 0.5))
    False
    """
    support = SupportModel.of_slider(slider) if support is None else support
    status = {
        e: force_status_regions(contact_wrench_cone(ContactConfiguration.slider_edge(slider, e, mu), "ss"),
                                support, window, rays, steps)
        for e in slider.pushable_edges
    }
    return EdgeRegions(
        possible={e: {sense: regions[sense]["P"] for sense in (1, -1)} for e, regions in status.items()},
        impossible={sense: shapely.intersection_all([regions[sense]["I"] for regions in status.values()])
                    for sense in (1, -1)},
    )
