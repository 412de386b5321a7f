"""Reachable-set maps: where can the part get from its start in one or two stable pushes?

:func:`reachable_set` lays a grid over the workspace and, for each cell, asks whether the part can
be pushed from ``scene.start`` to the goal pose ``(x, y, theta)`` whose **position (the slider
frame's origin, as for ``scene.goal``) is the cell's centre** -- the same pose a scene's ``goal:``
names, so a cell agrees exactly with :func:`planner.queries.one_step.one_step` for that goal. ``theta``
is the given final ``heading`` (radians, like every pose of :class:`~planner.model.scene.Scene`), or,
with ``heading=None``, each of ``headings`` evenly spaced headings, the cell keeping the fewest
pushes over all of them.

The answers use the planner's own machinery, so they agree with it:

* one push: :func:`planner.actions.push.connect` on each allowed edge (``COR_total`` a stable push
  and the push collision-free, keeping :func:`~planner.actions.controls.clearance_margin`). A vectorised
  screen (``log_pose`` and the stable regions' ``contains``) picks the cells worth the collision
  check; ``connect`` itself decides them;
* two pushes: :meth:`planner.search.goal_region.GoalRegion.pushes_to` for the cells' goals (those of a
  heading at once) on each edge (the planner's goal region: one push, or two through one of its
  fixed waypoints). This is
  *sufficient*, not complete: a cell at 0 may still be reachable in two pushes through some other
  waypoint, or in more pushes.

A push ends exactly at the cell's pose, not within the scene's tolerance, and moves the part: the
start itself needs no push and is not marked (the cell holding it is marked only if a push
reaches that cell's centre). Cells where the part at the goal overlaps an obstacle or leaves the
workspace (a cheap shapely test) are 0 without any push being tried (``blocked``): no
collision-free push can end there. Pushes on one edge only: a two-push answer never switches edge.

>>> from planner import load_scene
>>> scene = load_scene("scenes/parking.yaml")
>>> reach = reachable_set(scene, pushes=1, heading=scene.start[2], resolution=0.1)
>>> reach.count.shape, int(reach.count.max())
((10, 10), 1)
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import shapely

from mechanics import log_pose, wrap_angle

from ..actions.push import connect
from ..model.extras import pyplot
from ..model.fields import SceneError, number
from ..model.segments import Push
from ..search.goal_region import GoalRegion
from ..actions.controls import EdgeControls, clearance_margin, controls_or_reason
from ..model.margin import EXACT, Margin
from ..model.options import DEFAULT_REGIONS
from ..model.scene import Scene
from ..world.validity import CollisionModel

__all__ = ["HEADINGS", "MAX_CELLS", "ReachableSet", "reachable_set", "reach_points", "write_png"]

#: Headings tried (evenly spaced from 0) when the map is for any final heading.
HEADINGS = 24
#: Default cells along the workspace diagonal.
CELLS_PER_DIAGONAL = 60
#: Most cells of a map (1000 x 1000): each is collision-checked per heading, so the work and the
#: memory of a map grow with them; the default grid has some 1,800.
MAX_CELLS = 1_000_000
#: Colours of cells reached in 1 and 2 pushes (PNG and rerun alike).
COLOURS = {1: "#2e9e5b", 2: "#f0b429"}
#: Colour of cells where the part at the goal collides.
BLOCKED = "#dddddd"


@dataclass(frozen=True)
class ReachableSet:
    """A reachable-set map.

    ``count[j, i]`` is the fewest pushes (1 or 2) found from ``scene.start`` to the goal at cell
    centre ``(xs[i], ys[j])``, 0 where none within ``pushes``. ``heading`` is the final heading
    asked for (radians), or None for any heading; then ``theta[j, i]`` is a heading reaching the
    cell in ``count[j, i]`` pushes (radians; NaN where 0), and ``headings`` those tried.
    ``blocked`` marks cells where the part at the goal collides (at every heading tried).
    ``seconds`` is the time the map took.
    """

    extent: tuple[float, float, float, float]  # xmin, ymin, xmax, ymax: the workspace
    cell: tuple[float, float]  # cell width and height, metres
    pushes: int
    heading: float | None
    headings: np.ndarray
    count: np.ndarray  # (ny, nx) int8
    theta: np.ndarray  # (ny, nx) float
    blocked: np.ndarray  # (ny, nx) bool
    seconds: float

    @property
    def xs(self) -> np.ndarray:
        return self.extent[0] + (np.arange(self.count.shape[1]) + 0.5) * self.cell[0]

    @property
    def ys(self) -> np.ndarray:
        return self.extent[1] + (np.arange(self.count.shape[0]) + 0.5) * self.cell[1]

    def centres(self) -> np.ndarray:
        """(ny, nx, 2) cell centres."""
        x, y = np.meshgrid(self.xs, self.ys)
        return np.stack([x, y], axis=-1)

    def cell_of(self, x: float, y: float) -> tuple[int, int]:
        """``(j, i)``: the row and column of the cell holding point ``(x, y)``."""
        i = int(np.clip((x - self.extent[0]) // self.cell[0], 0, self.count.shape[1] - 1))
        j = int(np.clip((y - self.extent[1]) // self.cell[1], 0, self.count.shape[0] - 1))
        return j, i


def reachable_set(scene: Scene, pushes: int = 1, heading: float | None = None, resolution: float | None = None,
                  *, headings: int = HEADINGS, among: slice | None = None,
                  controls: list[EdgeControls] | None = None, regions: str = DEFAULT_REGIONS,
                  margin: Margin = EXACT) -> ReachableSet:
    """The map of goal positions reachable from ``scene.start`` in at most ``pushes`` (1 or 2)
    constant stable collision-free pushes (module docstring).

    Parameters
    ----------
    scene : Scene
    pushes : 1 or 2
    heading : float, optional
        The goal's final heading in **radians**; None: any heading (``headings`` tried).
    resolution : float, optional
        Cell size in metres (default: the workspace diagonal / 60); the workspace is split into
        whole cells, each side rounded to the nearest number of cells, so cells may be slightly
        non-square.
    headings : int
        Headings tried when ``heading`` is None.
    among : slice, optional
        With ``heading`` None, only these of the ``headings`` (a part of the map, which
        :func:`planner.batch.reach.reachable_set_on` computes on another worker).
    controls : the allowed edges' controls, where the caller has them (a session)
    regions : the ``regions`` option the controls are computed with where not given (``'exact'`` or ``'stable'``)
    margin : the stability margin they keep (the ``margin`` option; default: none)
    """
    import time

    clock = time.perf_counter()
    scene.one_part("reachable_set")
    if pushes not in (1, 2):
        raise SceneError("pushes", f"must be 1 or 2, got {pushes!r}")
    if heading is not None:
        heading = number(heading, "heading")
    xmin, ymin, xmax, ymax = scene.workspace
    w, h = xmax - xmin, ymax - ymin
    res = math.hypot(w, h) / CELLS_PER_DIAGONAL if resolution is None else number(resolution, "resolution", positive=True)
    nx, ny = max(1, round(w / res)), max(1, round(h / res))
    if nx * ny > MAX_CELLS:  # each cell is collision-checked per heading: the work and memory grow with them
        raise SceneError("resolution", f"{res:g} m makes {nx * ny} cells of the workspace, more than {MAX_CELLS}: "
                                       f"at least {math.sqrt(w * h / MAX_CELLS):.3g} m")
    dx, dy = w / nx, h / ny
    x, y = np.meshgrid(xmin + (np.arange(nx) + 0.5) * dx, ymin + (np.arange(ny) + 0.5) * dy)
    xy = np.stack([x.ravel(), y.ravel()], axis=-1)
    thetas = (np.array([wrap_angle(heading)]) if heading is not None
              else wrap_angle(np.arange(headings) * 2 * np.pi / headings)[among or slice(None)])
    count = np.zeros(nx * ny, dtype=np.int8)
    theta = np.full(nx * ny, np.nan)
    blocked = np.ones(nx * ny, dtype=bool)

    edges = controls if controls is not None else controls_or_reason(scene, regions, margin)[0]
    if edges is not None:
        model = CollisionModel(scene, [p.edge for p in edges])
        clearance = clearance_margin(scene)
        start = np.asarray(scene.start, dtype=float)
        free = []  # per heading: the cells where the part fits
        for th in thetas:
            ok = ~_collides(scene, xy, th)
            blocked &= ~ok
            free.append(ok)
        for th, ok in zip(thetas, free):  # one push, every heading first: a 1 beats any 2
            todo = np.flatnonzero(ok & (count == 0))
            goals = np.column_stack([xy[todo], np.full(todo.size, th)])
            hit = _one_push(start, goals, edges, model, clearance)
            count[todo[hit]], theta[todo[hit]] = 1, th
        if pushes == 2:
            for th, ok in zip(thetas, free):  # the cells of a heading as the goals of one region
                todo = np.flatnonzero(ok & (count == 0))
                region = GoalRegion(scene, np.column_stack([xy[todo], np.full(todo.size, th)]), edges, model, clearance,
                                    aim=False)
                hit: set[int] = set()
                for k in range(len(edges)):
                    hit |= region.pushes_to(start, k, [i for i in range(todo.size) if i not in hit]).keys()
                hit_cells = todo[sorted(hit)]
                count[hit_cells], theta[hit_cells] = 2, th
    return ReachableSet((xmin, ymin, xmax, ymax), (dx, dy), pushes, None if heading is None else float(thetas[0]),
                        thetas, count.reshape(ny, nx), theta.reshape(ny, nx), blocked.reshape(ny, nx),
                        time.perf_counter() - clock)


def _collides(scene: Scene, xy: np.ndarray, theta: float) -> np.ndarray:
    """For each position, whether the part there at ``theta`` overlaps an obstacle or leaves the workspace."""
    c, s = math.cos(theta), math.sin(theta)
    v = scene.slider.vertices @ np.array([[c, s], [-s, c]])
    parts = shapely.polygons(xy[:, None, :] + v[None])
    room = shapely.box(*scene.workspace)
    out = ~shapely.within(parts, room)
    if scene.obstacles:
        obstacles = shapely.union_all(scene.obstacles)
        shapely.prepare(obstacles)
        out |= shapely.intersects(obstacles, parts)
    return out


def _one_push(start: np.ndarray, goals: np.ndarray, edges: list[EdgeControls], model: CollisionModel,
              margin: float) -> np.ndarray:
    """Which ``goals`` one push of some edge reaches: a vectorised screen of ``COR_total`` against
    each stable region, then :func:`planner.actions.push.connect` on the cells that pass."""
    hit = np.zeros(len(goals), dtype=bool)
    if not len(goals):
        return hit
    total = log_pose(start, goals)
    moving = np.any(total != 0.0, axis=-1)
    for push in edges:
        for c in np.flatnonzero(~hit & moving & np.asarray(push.region.contains(total), dtype=bool)):
            hit[c] = isinstance(connect(start, goals[c], push, model, margin), Push)
    return hit


def reach_points(reach: ReachableSet) -> tuple[np.ndarray, np.ndarray]:
    """``(centres, counts)``: the (n, 2) centres of the reachable cells and their (n,) counts, for
    plotting elsewhere (the rerun layer ``/world/reach``)."""
    mask = reach.count > 0
    return reach.centres()[mask], reach.count[mask].astype(int)


def write_png(reach: ReachableSet, scene: Scene, path: str) -> None:
    """Write a PNG of the map to ``path``: the workspace, cells coloured by the fewest pushes, cells
    where the part collides in light grey, the obstacles, the start's outline and the scene's goal."""
    plt = pyplot()  # first: without matplotlib, one line naming the extra
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Patch

    from mechanics import transform_points

    xmin, ymin, xmax, ymax = reach.extent
    fig, ax = plt.subplots(figsize=(6, 6 * (ymax - ymin) / (xmax - xmin)), dpi=110)
    shown = np.ma.masked_equal(reach.count, 0)
    cmap = ListedColormap([COLOURS[1], COLOURS[2]])
    ax.imshow(shown, origin="lower", extent=(xmin, xmax, ymin, ymax), cmap=cmap, vmin=0.5, vmax=2.5,
              alpha=0.75, interpolation="nearest", zorder=1)
    ax.imshow(np.ma.masked_equal(reach.blocked.astype(int), 0), origin="lower", extent=(xmin, xmax, ymin, ymax),
              cmap=ListedColormap([BLOCKED]), vmin=0.5, vmax=1.5, interpolation="nearest", zorder=1)
    ax.add_patch(plt.Rectangle((xmin, ymin), xmax - xmin, ymax - ymin, fill=False, lw=1.5, color="0.3"))
    for obstacle in scene.obstacles:
        ax.fill(*obstacle.exterior.xy, color="#c8504b", alpha=0.85, lw=0, zorder=2)
    outline = np.vstack([scene.slider.vertices, scene.slider.vertices[:1]])
    ax.plot(*transform_points(outline, scene.start).T, color="#2a6fb0", lw=1.8, zorder=3)
    ax.plot(*transform_points(outline, scene.goal).T, "--", color="0.2", lw=1.2, zorder=3)
    legend = [Patch(color=COLOURS[1], alpha=0.75, label="1 push")]
    if reach.pushes == 2:
        legend.append(Patch(color=COLOURS[2], alpha=0.75, label="2 pushes"))
    legend += [Patch(color=BLOCKED, label="part collides"),
               plt.Line2D([], [], color="#2a6fb0", lw=1.8, label="start"),
               plt.Line2D([], [], color="0.2", ls="--", lw=1.2, label="scene goal")]
    ax.legend(handles=legend, loc="upper right", fontsize=8, framealpha=0.9)
    what = ("any heading" if reach.heading is None
            else f"heading {math.degrees(reach.heading):.0f}\N{DEGREE SIGN}")
    ax.set_title(f"{scene.name}: reachable in \N{LESS-THAN OR EQUAL TO} {reach.pushes} "
                 f"push{'es' if reach.pushes > 1 else ''} ({what}; cell origin = part pose)", fontsize=9)
    ax.set_xlim(xmin, xmax), ax.set_ylim(ymin, ymax)
    ax.set_aspect("equal")
    fig.tight_layout()
    fig.savefig(path, format="png")
    plt.close(fig)
