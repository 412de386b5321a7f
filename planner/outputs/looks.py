"""How the recording (:mod:`.recording`) and the pictures (:mod:`.picture`) tell a scene's parts
apart: each part's colours and the name its labels carry.

The one part of a ``slider:`` scene (:data:`~planner.model.scene.ONE_PART`) is drawn in the
drawer's own three colours: there, colour tells the part from its goal and from the path of its
centre of friction, and nothing needs its name. The parts of a ``parts:`` scene each take a colour
of :data:`PALETTE` in scene order, for the outline, the goal and the path alike, since there colour
must tell the parts apart, and their labels carry their names.

>>> from planner.model.scene_file import load_scene
>>> single = ((0, 0, 255), (0, 255, 0), (255, 0, 0))
>>> blue = looks(load_scene("scenes/parts/swap.yaml"), single)["blue"]  # the second part
>>> blue.part == blue.goal == blue.path == PALETTE[1], blue.label("goal")
(True, 'blue goal')
>>> looks(load_scene("scenes/battery.yaml"), single)["part"].label("goal")
'goal'
"""

from __future__ import annotations

from typing import NamedTuple

from ..model.scene import ONE_PART, Scene

__all__ = ["PALETTE", "Colour", "Look", "hex_colour", "looks"]

#: A colour: red, green, blue, 0 to 255.
Colour = tuple[int, int, int]

#: Colours of the parts of a ``parts:`` scene, in scene order (repeated past the last).
PALETTE: tuple[Colour, ...] = (
    (40, 110, 220), (230, 130, 20), (20, 170, 150), (210, 40, 190), (140, 90, 40), (110, 60, 230), (200, 170, 20),
    (60, 160, 60), (235, 70, 120), (90, 160, 255))


class Look(NamedTuple):
    """One part's colours (its outline, its goal, its CF's path) and its name, None for the one
    part of a ``slider:`` scene."""

    part: Colour
    goal: Colour
    path: Colour
    name: str | None

    def label(self, what: str) -> str:
        """``what`` said of this part: ``'goal'``, or ``'red goal'`` for a part named red."""
        return what if self.name is None else f"{self.name} {what}"


def looks(scene: Scene, single: tuple[Colour, Colour, Colour]) -> dict[str, Look]:
    """Each part's look (module docstring): ``single``'s colours (outline, goal, path) for the one
    part of a ``slider:`` scene, else each part's colour of :data:`PALETTE`."""
    if scene.names == (ONE_PART,):
        return {ONE_PART: Look(*single, None)}
    return {n: Look(*[PALETTE[k % len(PALETTE)]] * 3, n) for k, n in enumerate(scene.names)}


def hex_colour(colour: Colour) -> str:
    """``colour`` as matplotlib and HTML write it.

    >>> hex_colour((42, 111, 176))
    '#2a6fb0'
    """
    return "#%02x%02x%02x" % tuple(colour)
