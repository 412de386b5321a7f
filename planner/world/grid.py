"""Grids the planner lays over the table on its own (where to leave a part aside, where to switch
edges): their spacing is what the search wants, in part radii, but never so fine that the grid has
more than a number of cells the scene's size sets. A part of two microns on a table of a metre
would otherwise ask for some 10^11 cells (terabytes) where a part of centimetres asks for hundreds:
time and memory are bounded by the cells, not by how small a part is.

A grid the user sizes (:func:`planner.reachable_set`'s ``resolution``) is refused past its own
limit instead: there the spacing is the answer asked for.
"""

from __future__ import annotations

import math

__all__ = ["grid_spacing"]


def grid_spacing(width: float, height: float, wanted: float, cells: int) -> float:
    """The spacing of a grid over a ``width`` x ``height`` rectangle: ``wanted``, or coarser so
    that the grid has at most about ``2 * cells + 1`` points (``(width / s + 1) (height / s + 1)``
    for spacing ``s``, however long and thin the rectangle).

    >>> grid_spacing(1.0, 0.5, 0.1, 1000)                 # 11 x 6 points: as wanted
    0.1
    >>> round(grid_spacing(1.0, 0.5, 2e-6, 1000), 6)      # a 2 um part's spacing, held to the cells
    0.022361
    >>> grid_spacing(1000.0, 1e-6, 1e-3, 1000)            # a sliver: its length sets the spacing
    1.000000001
    """
    return max(wanted, math.sqrt(width * height / cells), (width + height) / cells)
