"""A part's size against its pusher and workspace: far too small or far too large is a mistake of
units, refused in one line that says which units would fit, before anything is computed for it.

A part less than :data:`SMALLEST` of the pusher's width across is refused: a file drawn in metres
and declared in millimetres makes an 80 x 50 mm plate 80 x 50 um, and planning for it grew to
24 GB before the kernel ended it (the planner spaces its grids by the part's size, the
workspace by the pusher's). So is a part wider than the workspace's diagonal, which fits nowhere
in it (a file drawn in millimetres declared in metres). "Across" is the diameter of the smallest
circle holding the part, which no turn changes.
"""

from __future__ import annotations

import math

import numpy as np
import shapely

from .fields import SceneError

__all__ = ["SMALLEST", "check_scale", "length_text"]

#: The least size of a part, as a fraction of the pusher's width: a pusher a hundred times wider
#: than the part is no tool for it.
SMALLEST = 1 / 100


def check_scale(vertices: np.ndarray, pusher_width: float, workspace: tuple[float, float, float, float],
                field: str, units: str | None) -> None:
    """Refuse the part of ``vertices`` (metres) if it is less than :data:`SMALLEST` of
    ``pusher_width`` across or wider than ``workspace``'s diagonal, naming ``field`` and hinting
    at the units: ``units`` is the file's (None: vertices given in metres).

    >>> plate = np.array([[0, 0], [80e-6, 0], [80e-6, 50e-6], [0, 50e-6]])
    >>> check_scale(plate, 0.03, (-1, -1, 1, 1), "slider.units", "mm")
    Traceback (most recent call last):
    ...
    planner.model.fields.SceneError: slider.units: the part is 94.34 um across, less than 1/100 of the pusher's width (30 mm): is the file in metres? (units: mm)
    >>> check_scale(plate * 1e6, 0.03, (-1, -1, 1, 1), "slider.vertices", None)
    Traceback (most recent call last):
    ...
    planner.model.fields.SceneError: slider.vertices: the part is 94.34 m across, more than the workspace's diagonal (2.828 m): the vertices are in metres
    >>> check_scale(plate * 1e3, 0.03, (-1, -1, 1, 1), "slider.units", "mm")  # 80 x 50 mm: fine
    """
    across = 2 * shapely.minimum_bounding_radius(shapely.MultiPoint(vertices))
    diagonal = math.hypot(workspace[2] - workspace[0], workspace[3] - workspace[1])
    small = across < SMALLEST * pusher_width
    if small:
        problem = f"less than 1/{round(1 / SMALLEST)} of the pusher's width ({length_text(pusher_width)})"
    elif across > diagonal:
        problem = f"more than the workspace's diagonal ({length_text(diagonal)})"
    else:
        return
    unit, name = ("m", "metres") if small else ("mm", "millimetres")  # what the file was likely drawn in
    hint = ("the vertices are in metres" if units is None else
            f"is the file in {name}? (units: {units})" if units != unit else f"check the file's units (units: {units})")
    raise SceneError(field, f"the part is {length_text(across)} across, {problem}: {hint}")


def length_text(metres: float) -> str:
    """``metres`` in the unit that shows it best, to four digits (the workspace's diagonal, at
    most 2829 m, shows no exponent).

    >>> length_text(1999.998), length_text(2.82843), length_text(0.03), length_text(8e-5), length_text(3e-9)
    ('2000 m', '2.828 m', '30 mm', '80 um', '0.003 um')
    """
    for unit, size in (("m", 1.0), ("mm", 1e-3)):
        if metres >= size:
            return f"{metres / size:.4g} {unit}"
    return f"{metres / 1e-6:.4g} um"
