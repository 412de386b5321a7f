"""The pictures of Lynch (1992), redrawn from this package's computations.

``python -m mechanics.figures --out DIR`` writes PNGs in the spirit of the paper's figures:

* ``fig05_07_kinematics.png`` (figs. 5 and 7): the slider CORs of each contact mode for a given
  pusher COR, in the planes of CCW and CW rotation centres. The paper's contact configuration is
  not given; here it is an invented corner push: the bottom face of a unit square at
  ``(-0.5, 0)`` and its right face at ``(0.5, 0.5)``, mu = 0.3, pusher turning CW about
  ``(1.5, 2)`` (so that both contacts move into the part).
* ``fig10a_force_status.png`` / ``fig10b_force_status.png`` (fig. 10): the P, U and I CORs of two
  sticking contacts with parallel normals (up, at ``(-0.8, -1)`` and ``(-0.3, -1)`` below a unit
  support disk about the CF), mu = 0.5 and 0.2. With 0.2 no contact force passes through the CF:
  nothing is P and only CW rotations are possible.
* ``fig11_battery.png`` (fig. 11): the 9 V battery pushed on its back face, mu = 1, a CW pusher
  COR inside the sticking P region. (a) the modes' kinematic CW CORs; (b) sticking's CW P and U
  regions; (c), (d) the kinematic CORs of ``fr`` and ``sf`` and their U regions, which miss each
  other: neither mode can occur.
* ``fig14_contact_synthesis.png`` (fig. 14): the sticking P regions ``P1``-``P4`` of the four
  edges of an invented quadrilateral (``(0, 0), (3, 0), (2.5, 2), (0.5, 1.5)``, edges numbered
  from the bottom one counter-clockwise), mu = 0.5, and the CORs I for every edge.

Force regions come from the ray search of :func:`~.force_status.force_status_regions`; ``rays``
and ``steps`` trade detail for time. Needs matplotlib (``pip install -e '.[figures]'``).
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable
from pathlib import Path

try:
    import matplotlib
except ModuleNotFoundError:
    _NEEDS = "mechanics.figures needs matplotlib, which the figures extra installs: pip install -e '.[figures]'"
    if __name__ == "__main__":  # a command gets one line, not a traceback
        sys.exit(f"python -m {_NEEDS}")
    raise ModuleNotFoundError(_NEEDS, name="matplotlib") from None

import matplotlib.pyplot as plt
import numpy as np
import shapely
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from numpy.typing import ArrayLike

from .contact_synthesis import edge_regions
from .contacts import ContactConfiguration
from .force_status import force_status_regions
from .kinematics import kinematic_cone, kinematic_cones
from .slider import Slider
from .support import SupportModel
from .twist import cor_to_twist
from .wrenches import contact_wrench_cone

__all__ = ["FIGURES", "figure_5_7", "figure_10", "figure_11", "figure_14", "main", "write_figures"]

#: Colours of the force statuses (the paper shades P, hatches I and leaves U light).
STATUS_COLOURS = {"P": "tab:green", "U": "khaki", "I": "0.75"}
SENSES = {1: "CCW", -1: "CW"}
BATTERY = Slider([[-0.02425, -0.01325], [0.02425, -0.01325], [0.02425, 0.01325], [-0.02425, 0.01325]])
QUADRILATERAL = Slider([[0, 0], [3, 0], [2.5, 2], [0.5, 1.5]])


def _draw(ax: Axes, geometry: shapely.Geometry, colour: str, label: str | None = None, alpha: float = 0.6) -> None:
    """Fill polygons, stroke segments, dot points; parts of a collection one by one."""
    if geometry.is_empty:
        return
    if hasattr(geometry, "geoms"):
        for i, part in enumerate(geometry.geoms):
            _draw(ax, part, colour, label if i == 0 else None, alpha)
        return
    if isinstance(geometry, shapely.Polygon):
        ax.fill(*geometry.exterior.xy, color=colour, alpha=alpha, lw=0, label=label)
    elif isinstance(geometry, shapely.LineString):
        ax.plot(*geometry.xy, color=colour, lw=2.5, label=label)
    else:
        ax.plot(*geometry.xy, "o", color=colour, ms=5, label=label)


def _frame(ax: Axes, window: ArrayLike, title: str, outline: ArrayLike | None = None,
           contacts: ContactConfiguration | None = None) -> None:
    """Axes limits, title, the part's outline and the contact normals."""
    x0, y0, x1, y1 = window
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
    ax.set_aspect("equal")
    ax.set_title(title, fontsize=9)
    ax.tick_params(labelsize=7)
    if outline is not None:
        ring = np.vstack([outline, outline[:1]])
        ax.plot(ring[:, 0], ring[:, 1], "k-", lw=1)
    if contacts is not None:
        size = 0.08 * (x1 - x0)
        for p, n in zip(contacts.points, contacts.normals):
            ax.annotate("", p, p - size * n, arrowprops={"arrowstyle": "->", "color": "k"})


def _mode_colours(modes: list[str]) -> dict[str, tuple]:
    cmap = plt.get_cmap("tab10")
    return {mode: cmap(i % 10) for i, mode in enumerate(modes)}


def _kinematic_panel(ax: Axes, config: ContactConfiguration, pusher_twist: np.ndarray, sense: int, window) -> None:
    """Every mode's kinematic CORs of ``sense``, coloured by mode, and the pusher's COR."""
    cones = kinematic_cones(config, pusher_twist)
    for mode, colour in _mode_colours(list(cones)).items():
        _draw(ax, cones[mode].cor_region(sense, window), colour, mode, alpha=0.5)
    if pusher_twist[2] * sense > 0:
        cor = np.array([-pusher_twist[1], pusher_twist[0]]) / pusher_twist[2]
        ax.plot(*cor, "k*", ms=9, label="COR$_p$")


def _status_panel(ax: Axes, regions: dict[str, shapely.Geometry], statuses: str = "IUP") -> None:
    for status in statuses:  # I first: it is the background the others stand out from
        _draw(ax, regions[status], STATUS_COLOURS[status], status)


def figure_5_7(window: ArrayLike = (-3, -3, 3, 3)) -> Figure:
    """Kinematically legal slider CORs and their contact modes for a CW pusher COR (figs. 5, 7)."""
    config = ContactConfiguration([[-0.5, 0.0], [0.5, 0.5]], [[0.0, 1.0], [-1.0, 0.0]], 0.3)
    pusher = cor_to_twist([1.5, 2.0], -1)  # both contacts move into the part
    square = np.array([[-0.5, 0.0], [0.5, 0.0], [0.5, 1.0], [-0.5, 1.0]])
    fig, axes = plt.subplots(1, 2, figsize=(8, 4))
    for ax, sense in zip(axes, (1, -1)):
        _kinematic_panel(ax, config, pusher, sense, window)
        _frame(ax, window, f"{SENSES[sense]} slider CORs by contact mode", square, config)
    axes[1].legend(fontsize=6, loc="lower left", ncol=2)
    return fig


def figure_10(mu: float, rays: int = 24, steps: int = 8) -> Figure:
    """P, U and I CORs of two sticking contacts with parallel normals on a unit disk (fig. 10)."""
    config = ContactConfiguration([[-0.8, -1.0], [-0.3, -1.0]], [[0.0, 1.0], [0.0, 1.0]], mu)
    window = (-4, -4, 4, 4)
    regions = force_status_regions(contact_wrench_cone(config, "ss"), SupportModel.disk([0, 0], 1.0), window, rays, steps)
    fig, axes = plt.subplots(1, 2, figsize=(8, 4))
    disk = np.stack([np.cos(np.linspace(0, 2 * np.pi, 65)), np.sin(np.linspace(0, 2 * np.pi, 65))], axis=1)
    for ax, sense in zip(axes, (1, -1)):
        _status_panel(ax, regions[sense])
        _frame(ax, window, f"{SENSES[sense]} CORs, mu = {mu:g}", disk[:-1], config)
    axes[0].legend(fontsize=7, loc="lower left")
    return fig


def figure_11(rays: int = 24, steps: int = 8, pusher_cor: ArrayLike = (0.0, -0.09)) -> Figure:
    """The battery pushed about a CW COR in the sticking P region: only ``ss`` can occur (fig. 11)."""
    config = ContactConfiguration.slider_edge(BATTERY, 3, 1.0)
    support = SupportModel.of_slider(BATTERY)
    pusher = cor_to_twist(pusher_cor, -1)
    window = (-0.12, -0.14, 0.12, 0.1)
    fig, axes = plt.subplots(2, 2, figsize=(8, 8))
    (a, b), (c, d) = axes
    _kinematic_panel(a, config, pusher, -1, window)
    a.legend(fontsize=6, loc="upper right", ncol=2)
    _frame(a, window, "(a) kinematic CW CORs by mode", BATTERY.vertices, config)
    _status_panel(b, force_status_regions(contact_wrench_cone(config, "ss"), support, window, rays, steps)[-1], "UP")
    b.plot(*pusher_cor, "k*", ms=9, label="COR$_p$")
    b.legend(fontsize=7, loc="upper right")
    _frame(b, window, "(b) ss: CW P and U regions", BATTERY.vertices, config)
    for ax, mode, tag in ((c, "fr", "c"), (d, "sf", "d")):
        _draw(ax, force_status_regions(contact_wrench_cone(config, mode), support, window, rays, steps)[-1]["U"],
              STATUS_COLOURS["U"], "force U")
        _draw(ax, kinematic_cone(config, mode, pusher).cor_region(-1, window), "tab:blue", "kinematic")
        ax.legend(fontsize=7, loc="upper right")
        _frame(ax, window, f"({tag}) {mode}: kinematic and U CW CORs miss", BATTERY.vertices, config)
    return fig


def figure_14(rays: int = 24, steps: int = 8) -> Figure:
    """Guaranteed-stable CORs ``P1``-``P4`` of each edge of a quadrilateral, mu = 0.5 (fig. 14)."""
    part = QUADRILATERAL
    window = (*(part.cf - 6), *(part.cf + 6))
    regions = edge_regions(part, 0.5, window=window, rays=rays, steps=steps)
    colours = _mode_colours([f"P{e + 1}" for e in regions.possible])
    fig, axes = plt.subplots(1, 2, figsize=(8, 4))
    for ax, sense in zip(axes, (1, -1)):
        _draw(ax, regions.impossible[sense], STATUS_COLOURS["I"], "I (every edge)")
        for e, per_sense in regions.possible.items():
            _draw(ax, per_sense[sense], colours[f"P{e + 1}"], f"P{e + 1}")
        _frame(ax, window, f"{SENSES[sense]} CORs, mu = 0.5", part.vertices)
    axes[0].legend(fontsize=7, loc="lower left")
    return fig


#: File stem -> figure maker taking ``(rays, steps)``.
FIGURES: dict[str, Callable[[int, int], Figure]] = {
    "fig05_07_kinematics": lambda rays, steps: figure_5_7(),
    "fig10a_force_status": lambda rays, steps: figure_10(0.5, rays, steps),
    "fig10b_force_status": lambda rays, steps: figure_10(0.2, rays, steps),
    "fig11_battery": figure_11,
    "fig14_contact_synthesis": figure_14,
}


def write_figures(out: Path | str, rays: int = 24, steps: int = 8, dpi: int = 100,
                  names: list[str] | None = None) -> list[Path]:
    """Write the figures ``names`` (default: all of :data:`FIGURES`) as PNGs into ``out``."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    written = []
    for name in names or list(FIGURES):
        fig = FIGURES[name](rays, steps)
        fig.tight_layout()
        path = out / f"{name}.png"
        fig.savefig(path, dpi=dpi)
        plt.close(fig)
        written.append(path)
    return written


def main(argv: list[str] | None = None) -> None:
    matplotlib.use("Agg")  # the command draws files only; an importer keeps its own backend
    parser = argparse.ArgumentParser(description="Redraw the figures of Lynch (1992) as PNGs.")
    parser.add_argument("--out", default="docs/figures", help="output directory (default: docs/figures)")
    parser.add_argument("--rays", type=int, default=24, help="rays per sense of the force ray search")
    parser.add_argument("--steps", type=int, default=8, help="bisection steps per ray")
    parser.add_argument("--dpi", type=int, default=100)
    args = parser.parse_args(argv)
    for path in write_figures(args.out, args.rays, args.steps, args.dpi):
        print(path)


if __name__ == "__main__":
    main()
