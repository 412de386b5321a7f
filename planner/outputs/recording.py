"""Rerun recording of a plan of any number of parts: the scene, the search tree and the steps,
animated (the frames come from :mod:`planner.outputs.frames`, the pushed edge's mechanics from
:mod:`planner.outputs.analysis`, each part's colours from :mod:`planner.outputs.looks`).

:func:`write_recording` writes one ``.rrd`` file (application ``stablepush``, recording id
``<scene>-<planner>-seed<seed>``, no wall-clock timeline, so the same plan gives the same file).
Everything is in world coordinates, metres, z up; outlines are closed ``LineStrips3D`` in the
plane of the table (each kind at its own height of a few millimetres, ``_LAYER``, so that the
part is drawn over its path and everything over the search tree), points ``Points3D``. They are
3-D so that a view can show them the right way up (y up, as in the scene files and the README's
figures): rerun's 2-D views draw y downwards. A part's entities lie under ``<part>``: ``/world``
for the one part of a ``slider:`` scene (the paths a recording of one part has always had),
``/world/parts/<name>`` for each part of a ``parts:`` scene, whose labels then carry its name.
Entities:

Static (no timeline, always visible)

* ``/world/workspace`` -- the workspace bounds, one closed strip;
* ``/world/obstacles`` -- one strip per obstacle, labelled ``obstacle <k>`` in scene order;
* ``<part>/start``, ``<part>/goal`` -- the part's outline at its start and goal poses (ghosts),
  labelled ``start`` and ``goal`` (``<name> start``, ``<name> goal``);
* ``/world/tree`` -- one strip per search-tree edge (``Plan.tree``; empty after a one-step plan
  and for several parts, whose search keeps none);
* ``/world/transits`` -- the path of the pusher's face centre on each transit (edge switch),
  labelled ``transit <k>`` in plan order: one strip for a walk round the part, three for a lift,
  whose middle, airborne, strip is labelled ``transit <k> lifted`` and drawn thin and faint in
  the lifted pusher's colour (no strip for a plan without switches);
* ``/world/transfers`` -- the same for each transfer of the pusher from one part to the next,
  labelled ``transfer <k> to <name>`` (no strip for a plan of one part);
* ``/log`` -- ``TextLog``, the summary panel's rows (``WARN`` when not solved): what was solved
  with how many parts, moves, pushes, switches and transfers, the CF path length and the cost
  (length plus ``switch_cost`` per switch and per transfer), the push, transit and transfer
  times, the stability margin the plan was made for and the least its pushes keep
  (:mod:`planner.actions.margins`), and last, for several parts which were delivered, for one
  part the search tree's size.
  They are on both timelines at 0, not static: a text log view lists only rows of its timeline.

Animated, one row per frame on the timelines ``time`` (plan time in seconds, pushes, transits and
transfers alike: no body point moves faster than 1 m/s) and ``step`` (frame index), only for a
plan with a step. Frames are ``FRAMES_PER_RADIUS`` per radius of the smallest part of point
travel, at most ``MAX_FRAMES`` in all:

* ``<part>/slider`` -- the part's outline; it stands still but while it is pushed;
* ``/world/pusher`` -- the pusher's outline on the table: on the pushed edge during a push, and
  along the path (:func:`planner.actions.transit.transit_poses`) during a transit or transfer; no
  strip while it is lifted; during a push, labelled with the push's own certified margin
  (``push 2/5: margin friction -81 %, CF 1.2 mm``: how much lower the friction, and how far the
  CF, may be before it may slip) where the plan has its margins;
* ``/world/pusher_lifted`` -- the pusher's outline while it is in the air (the inside of a lift's
  middle piece), thin, faint and labelled ``lifted``; no strip on every other frame;
* ``<part>/cf_path`` -- the path of the part's centre of friction so far (thinned to about
  ``PATH_POINTS`` points, always through the steps' ends);
* ``/world/cor`` -- ``Points3D``, the current push's centre of rotation, labelled ``COR`` (no
  point for a translation, whose COR is at infinity, nor during a transit or transfer). The
  stable regions it lies in are drawn in the slider frame only (below): carried with the part in
  the world they were large outlines easily read as obstacles.

The first pushed edge's mechanics (Lynch 1992's figures 11 and 14 for the part first pushed),
static, in that part's frame, for a plan with a push:

* ``/analysis/part`` -- the part's outline at the origin of its frame, and ``/analysis/contact``
  the pushed contact segment;
* ``/analysis/stable/{ccw,cw}`` -- procedure STABLE's COR regions; ``/analysis/exact/{ccw,cw}``
  the exact regions (contain STABLE's; :mod:`mechanics.exact_region`);
* ``/analysis/sticking/{ccw,cw}/{P,U,I}`` -- the force status of sticking (both ends) for every
  COR of each sense (:func:`mechanics.force_status_regions`, ``ANALYSIS_RAYS`` rays), for every CF
  of the part's uncertainty disk;
* ``/analysis/cor`` -- ``Points3D``, the centres of rotation of the plan's pushes of that part on
  that edge inside the window (pushes on other edges belong with other regions).

All COR regions are clipped to a square of half-side 4 part radii about the CF.

The checks below are drawn for a plan of one part: their reports for several parts
(:mod:`planner.execution.parts_verify`, :mod:`planner.execution.parts_sim`) hold other records.
With a :class:`~planner.execution.verify.Verification` (``plan --verify``), also:

* ``/world/ghost`` -- the slider's outline as simulated under each push's worst support
  distribution (the run deviating most from the plan), from the push's planned start, at up to
  ``GHOST_SAMPLES`` frames per push (the viewer holds it in between, through transits too); it
  hides under ``/world/slider`` wherever the push sticks;
* ``/log/verify`` -- ``TextLog``, the verification's summary row (``WARN`` when it failed).

With a :class:`~planner.execution.mujoco_sim.Simulation` (``plan --simulate N``), also:

* ``/world/simulated`` -- the slider's outline as MuJoCo moved it in the run that strayed
  farthest from the planned path (:attr:`~planner.execution.mujoco_sim.Simulation.worst`), at
  every frame: the trajectory sample at the frame's plan time
  (:attr:`~planner.execution.trajectory.Trajectory.plan_time`), so the two outlines part where
  the run leaves the plan and one hides the other while it follows;
* ``/log/simulate`` -- ``TextLog``, the simulation's summary row (``WARN`` when it failed);
* ``/world/arm`` -- for a scene with a robot (any number of parts), the arm of that run as
  MuJoCo moved it, at every frame: a line through its bodies' origins from the base on, the
  flange and the pusher frame's origin, in 3-D over the table.

With a :class:`~planner.execution.closed_loop.ClosedLoop` (``plan --simulate N --closed-loop``),
also, per run ``k`` (from 1, as the output lines number them), on the ``time`` timeline but on
the run's own clock (seconds since its pusher began to move, its lead-in, the waits for the part
to settle and the re-plans' latencies included; not on ``step``), at :data:`RUN_FRAMES_HZ`:

* ``/world/closed_loop/<k>/part`` -- the part's outline where MuJoCo has it (started off the
  plan's start, knocked), labelled ``run <k>``;
* ``/world/closed_loop/<k>/pusher`` -- the pusher's outline where the loop moved it, and
  ``/world/closed_loop/<k>/pusher_path`` the path of its frame's origin so far;
* ``/world/closed_loop/<k>/replan/<j>`` -- from the ``j``-th re-plan's time on: the CF path of
  the new plan, and ``/world/closed_loop/<k>/replan/<j>/start`` a point at the CF of the
  observed pose it was planned from, labelled ``re-plan <j> at <t> s``;
* ``/log/closed_loop`` -- ``TextLog``: at 0 the loop's summary and the runs' lines (``WARN``
  when it failed), and a row at each re-plan's time saying what triggered it, and at each time
  the run went on with its plan for want of a re-plan, saying why; for a camera run, a row when
  it lost track of a part, saying why, and one when it saw it again.

A run observed through the camera (``--observe camera``) also has, at the times its images were
taken:

* ``/world/closed_loop/<k>/camera`` -- static, the camera's pose (``Transform3D``) and lens
  (``Pinhole``, of the images below), and ``/world/closed_loop/<k>/camera/depth`` the depth images
  kept (``DepthImage``, mm): about :data:`~planner.execution.closed_loop.DEPTH_HZ` a second, each
  the middle pixel of every square of :data:`~planner.execution.closed_loop.DEPTH_STEP` pixels, 0
  where no ray was cast (the estimator reads only round the parts); coloured over the table's
  depths and twice a part's height either side, so the table is mid-range, a part darker and the
  pixels not cast the light end. The default blueprint shows run 1's in a 2-D view of its own
  and leaves the cameras out of the world's view (there the images would be clouds of points
  hiding the outlines, and the frustum lines across the view);
* ``/world/closed_loop/<k>/seen/estimate`` -- each image's estimated outlines (none for a part
  lost), orange, labelled ``camera``, over ``/world/closed_loop/<k>/seen/truth``, the outlines
  where MuJoCo had the parts when the image was taken, drawn red and labelled ``lost track:
  <why>`` for a part lost.

(The re-plans' latencies are in the runs' clocks, so a closed loop's recording differs a little
from one run of it to the next.)

With a reachable-set map (``plan --reach N``; :mod:`planner.queries.reachable_set`), also:

* ``/world/reach`` -- ``Points3D``, static, one point per reachable cell centre, green for one
  push and amber for two.

Styles (colours, line widths in UI points) are logged statically on the animated entities: the
one part of a ``slider:`` scene blue, its goal green and its CF's path light blue; each part of a
``parts:`` scene, its goal and its path in its colour (:func:`~planner.outputs.looks.looks`). The
default blueprint shows ``/world`` and, beside it, ``/analysis`` each in a 3-D view looking
straight down (x to the right, y up; the world view framing the workspace), above the summary
panel, a text log view of ``/log``.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import rerun as rr
import rerun.blueprint as rrb
import shapely
from numpy.typing import ArrayLike

from mechanics import twist_to_cor

from ..actions.margins import smallest
from ..actions.region_cache import RegionCache
from ..actions.transit import transit_pieces
from ..model.bodies import place, pusher_frame_body
from ..model.files import write_atomic
from ..model.plan import Plan
from ..model.scene import Scene
from ..model.segments import Push, Transfer, Transit, path_length
from .analysis import STATUS, analysis
from .frames import Frames, frames, history
from .looks import Look, looks

if TYPE_CHECKING:  # the simulators behind them import scipy or MuJoCo: not needed to draw a plan
    from ..execution.closed_loop import ClosedLoop, Seen
    from ..execution.mujoco_sim import Simulation
    from ..execution.verify import Verification
    from ..queries.reachable_set import ReachableSet

__all__ = ["GHOST_SAMPLES", "RUN_FRAMES_HZ", "write_recording"]

#: Most frames per push at which the simulated ghost is drawn (each costs a simulation).
GHOST_SAMPLES = 10
#: Frames per second of a closed-loop run's clock.
RUN_FRAMES_HZ = 10.0

_THIN, _LINE, _BOLD, _DOT = (float(r) for r in rr.components.Radius.ui_points([0.5, 1.0, 2.0, 4.0]))
_GREY, _DARK, _RED = [150, 150, 150], [60, 60, 60], [200, 50, 50]
_SLIDER, _GOAL, _CF = (40, 110, 220), (40, 170, 70), (90, 160, 255)
_CCW, _CW, _COR, _GHOST, _SIMULATED = [20, 170, 150], [230, 130, 20], [210, 40, 190], [140, 60, 230], [235, 70, 120]
_CAMERA = [255, 150, 0]  # what the camera saw: orange, apart from MuJoCo's pink
_LIFTED = [110, 110, 110, 110]  # a faint, see-through grey: the pusher off the table, seen from above
_STATUS = dict(zip(STATUS, ([40, 170, 70], [230, 190, 40], [200, 50, 50])))
#: Height of the views' eye over the table, in half-widths of what it must show (the viewer's field of view).
_EYE = 1.7
#: Heights (m) at which each kind of drawing lies over the table: a view from straight above
#: sees them flat, and what lies higher is drawn over what lies lower (the part over its path,
#: everything over the search tree).
_LAYER = {"map": -0.002, "tree": -0.001, "scene": 0.0, "path": 0.001, "ghost": 0.0015, "part": 0.002,
          "marker": 0.003}


def _z(points: ArrayLike, layer: str = "scene") -> np.ndarray:
    """2-D points ``(..., 2)`` at the height of ``layer`` (:data:`_LAYER`) in the plane of the table.

    >>> _z([[1.0, 2.0]], "part").tolist()
    [[1.0, 2.0, 0.002]]
    """
    p = np.asarray(points, dtype=float)
    return np.concatenate([p, np.full((*p.shape[:-1], 1), _LAYER[layer])], axis=-1)


def _zs(strips, layer: str = "scene") -> list[np.ndarray]:
    """:func:`_z` of each strip of a list (strips may differ in length)."""
    return [_z(strip, layer) for strip in strips]


def _closed(points: ArrayLike) -> np.ndarray:
    """A polygon's vertices as a closed strip (the first vertex repeated at the end)."""
    p = np.asarray(points, dtype=float)
    return np.vstack([p, p[:1]])


def _root(look: Look) -> str:
    """Where a part's entities lie (module docstring): ``world`` for the one part of a
    ``slider:`` scene, ``world/parts/<name>`` for a named part, the name escaped as one part of
    the path (a name may hold spaces or slashes, which rerun would otherwise warn of, or split on).

    >>> _root(Look((0, 0, 0), (0, 0, 0), (0, 0, 0), None)), _root(Look((0, 0, 0), (0, 0, 0), (0, 0, 0), "red"))
    ('world', 'world/parts/red')
    >>> print(_root(Look((0, 0, 0), (0, 0, 0), (0, 0, 0), "red part/2")))
    world/parts/red\\ part\\/2
    """
    return "world" if look.name is None else f"world/parts/{rr.escape_entity_path_part(look.name)}"


def _analysed(scene: Scene, plan: Plan) -> tuple[str, int | None]:
    """The part and edge ``/analysis`` shows: the first push's (for a plan without a push, the
    scene's first part and no edge)."""
    return next(((name, s.edge) for name, s in plan.steps if isinstance(s, Push)), (scene.names[0], None))


def _summary(scene: Scene, plan: Plan) -> list[str]:
    """The summary panel's rows; no planning time, so that the same plan always gives the same
    recording. Length and cost come from the scene's CFs and switch cost, which a plan made
    without them (:meth:`~planner.model.plan.Plan.of_part` without ``cf``) does not hold."""
    head = f"{scene.name}: planner {plan.planner}, seed {plan.seed}"
    # The last row: with several parts, which were delivered (a plan may deliver some and not
    # others); with one, the size of the search tree (the search of several parts keeps none).
    if len(scene.parts) > 1:
        missing = [n for n in scene.names if n not in plan.delivered]
        last = f"delivered: {len(plan.delivered)} of {len(scene.names)} parts" + (
            f"; not delivered: {', '.join(missing)}" if missing else "")
    else:
        last = f"search tree: {len(plan.tree)} edges"
    if not plan.solved:
        return [f"{head}: not solved: {plan.reason}", last]
    length = sum(path_length(m.segments, scene.part(m.part).slider.cf) for m in plan.moves)
    # The plan's own switch cost; a plan file may not give one, and then its cost is not known.
    per = "per switch" + (" and per transfer" if plan.transfers else "")
    cost = "" if plan.switch_cost is None else (
        f"; cost {length + (plan.switches + plan.transfers) * plan.switch_cost:.4f} m "
        f"(length + {plan.switch_cost:g} m {per})")
    times = [f"{word} time {sum(s.duration for s in plan.segments if isinstance(s, kind)):.4f} s"
             for word, kind in (("push", Push), ("transit", Transit), ("transfer", Transfer))
             if kind is Push or any(isinstance(s, kind) for s in plan.segments)]
    rows = [f"{head}: solved with {' and '.join(plan.contents().rsplit(', ', 1))}",
            f"CF path length {length:.4f} m{cost}",
            f"{', '.join(times)} (every point of the pusher at most 1 m/s)"]
    if plan.margin is not None or plan.margins:
        least = smallest(plan)
        rows.append("; ".join(([f"stability margin {plan.margin}"] if plan.margin is not None else [])
                              + ([f"least kept: {least}"] if least is not None else [])))
    return [*rows, last]


def _log_text(rec: rr.RecordingStream, entity: str, lines: list[str], level: str) -> None:
    """Rows of the summary panel, at the start of both timelines: a text log shows the rows of
    its timeline up to the current time, and none logged without one (static;
    docs/stack.md, "What the viewer shows")."""
    zero = [0] * len(lines)
    rec.send_columns(entity, indexes=[rr.TimeColumn("step", sequence=zero), rr.TimeColumn("time", duration=zero)],
                     columns=rr.TextLog.columns(text=lines, level=[level] * len(lines)))


def _log_table(rec: rr.RecordingStream, scene: Scene) -> None:
    """The world's axes, ``/world/workspace`` and ``/world/obstacles``, static."""
    xmin, ymin, xmax, ymax = scene.workspace
    rec.log("world", rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)
    box = _closed([[xmin, ymin], [xmax, ymin], [xmax, ymax], [xmin, ymax]])
    rec.log("world/workspace", rr.LineStrips3D([_z(box)], colors=_DARK, radii=_LINE), static=True)
    rec.log("world/obstacles", rr.LineStrips3D(
        _zs(_closed(o.exterior.coords[:-1]) for o in scene.obstacles), colors=_RED, radii=_BOLD,
        labels=[f"obstacle {k}" for k in range(len(scene.obstacles))]), static=True)


def _log_pusher_paths(rec: rr.RecordingStream, entity: str, moves: list[tuple[str, Transit | Transfer]]) -> None:
    """The path of the pusher's face centre on each of ``moves`` (label, transit or transfer),
    static: one strip per piece, a lift's airborne piece thin and faint, labelled ``... lifted``."""
    pieces = [(label, xy, up) for label, move in moves for xy, up in transit_pieces(move)]
    rec.log(entity, rr.LineStrips3D(
        [_z(xy, "path") for _, xy, _ in pieces], colors=[_LIFTED if up else _DARK for *_, up in pieces],
        radii=[_THIN if up else _LINE for *_, up in pieces],
        labels=[f"{label}{' lifted' if up else ''}" for label, _, up in pieces]), static=True)


def _log_static(rec: rr.RecordingStream, scene: Scene, plan: Plan, look: dict[str, Look]) -> None:
    """The table, each part's start and goal, the search tree, the pusher's paths between
    contacts and the summary (module docstring)."""
    _log_table(rec, scene)
    for part in scene.parts:
        ghosts = place(_closed(part.slider.vertices), np.array([part.start, part.goal]))
        mine, root = look[part.name], _root(look[part.name])
        rec.log(f"{root}/start", rr.LineStrips3D(_z(ghosts[:1]), colors=_GREY, radii=_LINE, labels=mine.label("start")),
                static=True)
        rec.log(f"{root}/goal", rr.LineStrips3D(_z(ghosts[1:]), colors=mine.goal, radii=_LINE, labels=mine.label("goal")),
                static=True)
    rec.log("world/tree", rr.LineStrips3D(_z(np.asarray(plan.tree, dtype=float).reshape(-1, 2, 2), "tree"),
                                          colors=_GREY, radii=_THIN), static=True)
    _log_pusher_paths(rec, "world/transits", [(f"transit {k + 1}", t) for k, t in
                                              enumerate(s for s in plan.segments if isinstance(s, Transit))])
    _log_pusher_paths(rec, "world/transfers", [(f"transfer {k + 1} to {name}", t) for k, (name, t) in
                                               enumerate((n, s) for n, s in plan.steps if isinstance(s, Transfer))])
    _log_text(rec, "log", _summary(scene, plan), "INFO" if plan.solved else "WARN")


def _rings(geometry: shapely.Geometry) -> list[np.ndarray]:
    """Closed outer rings of every polygon of ``geometry`` with area."""
    parts = getattr(geometry, "geoms", [geometry])
    return [np.asarray(g.exterior.coords) for g in parts if isinstance(g, shapely.Polygon) and g.area > 0]


def _log_analysis(rec: rr.RecordingStream, scene: Scene, plan: Plan, edge: int, cache: RegionCache | None) -> None:
    """``/analysis``: ``edge``'s regions in the frame of ``scene``'s part (module docstring);
    ``scene`` is the problem of that part alone (:meth:`~planner.model.scene.Scene.move_scene`)."""
    name, slider = scene.names[0], scene.slider
    window, contact, polygons = analysis(scene, edge, cache)
    rec.log("analysis", rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)
    rec.log("analysis/part", rr.LineStrips3D([_z(_closed(slider.vertices), "part")], colors=_SLIDER,
                                             radii=_BOLD), static=True)
    rec.log("analysis/contact", rr.LineStrips3D([_z(contact, "part")], colors=_DARK, radii=_BOLD), static=True)
    for kind, width in (("stable", _BOLD), ("exact", _LINE)):
        for side, colour in (("ccw", _CCW), ("cw", _CW)):
            rings = _rings(polygons[kind][1 if side == "ccw" else -1])
            rec.log(f"analysis/{kind}/{side}", rr.LineStrips3D(_zs(rings, "path"), colors=colour, radii=width),
                    static=True)
    for side, sense in (("ccw", 1), ("cw", -1)):
        for label, colour in _STATUS.items():
            rings = _rings(polygons[label][sense])
            rec.log(f"analysis/sticking/{side}/{label}", rr.LineStrips3D(_zs(rings), colors=colour, radii=_THIN),
                    static=True)
    pushes = (s for n, s in plan.steps if n == name and isinstance(s, Push) and s.edge == edge)
    cors = [c for c, sense in map(twist_to_cor, (s.twist for s in pushes)) if sense != 0]
    inside = [c for c in cors if shapely.box(*window).contains(shapely.Point(c))]  # far ones would zoom the view out
    rec.log("analysis/cor", rr.Points3D(_z(inside or np.zeros((0, 2)), "marker"), colors=_COR, radii=_DOT),
            static=True)


def _log_ghost(rec: rr.RecordingStream, plan: Plan, verification: Verification, shown: Frames) -> None:
    """``/world/ghost`` at up to ``GHOST_SAMPLES`` of each push's frames, and ``/log/verify``.

    The verification checks pushes only, in plan order: its ``i``-th is the plan's ``i``-th push,
    whose frames are found by that push's segment index."""
    index, times = shown.index, shown.times
    frames, poses = [], []
    segment_of = [k for k, s in enumerate(plan.segments) if isinstance(s, Push)]
    for i in range(len(verification.pushes)):
        mine = np.flatnonzero(index == segment_of[i])  # the last segment's frames include the final one
        mine = mine[np.unique(np.linspace(0, len(mine) - 1, min(GHOST_SAMPLES, len(mine))).round().astype(int))]
        frames.append(mine)
        poses.append(verification.poses(i, times[mine] - times[mine[0]]))
    frames = np.concatenate(frames)
    outline = _closed(verification.scene.slider.vertices)
    rec.send_columns("world/ghost", indexes=[rr.TimeColumn("step", sequence=frames),
                                             rr.TimeColumn("time", duration=times[frames])],
                     columns=rr.LineStrips3D.columns(strips=_z(place(outline, np.concatenate(poses)), "ghost")))
    rec.log("world/ghost", rr.LineStrips3D.from_fields(colors=_GHOST, radii=_LINE), static=True)
    _log_text(rec, "log/verify", [verification.summary()], "INFO" if verification.passed else "WARN")


def _log_simulated(rec: rr.RecordingStream, scene: Scene, simulation: Simulation, times: np.ndarray) -> None:
    """``/world/simulated`` at every frame, and ``/log/simulate`` (module docstring)."""
    clock = simulation.motion.plan_time
    samples = np.clip(np.searchsorted(clock, times + 1e-12, side="right") - 1, 0, len(clock) - 1)
    strips = place(_closed(scene.slider.vertices), simulation.worst.poses[samples])
    rec.send_columns("world/simulated", indexes=[rr.TimeColumn("step", sequence=np.arange(len(times))),
                                                 rr.TimeColumn("time", duration=times)],
                     columns=rr.LineStrips3D.columns(strips=_z(strips, "ghost")))
    rec.log("world/simulated", rr.LineStrips3D.from_fields(colors=_SIMULATED, radii=_LINE, labels=["MuJoCo"]),
            static=True)
    _log_text(rec, "log/simulate", [simulation.summary()], "INFO" if simulation.passed else "WARN")


def _log_arm(rec: rr.RecordingStream, simulation: Simulation, times: np.ndarray) -> None:
    """``/world/arm`` at every frame (module docstring)."""
    clock = simulation.motion.plan_time
    samples = np.clip(np.searchsorted(clock, times + 1e-12, side="right") - 1, 0, len(clock) - 1)
    rec.send_columns("world/arm", indexes=[rr.TimeColumn("step", sequence=np.arange(len(times))),
                                           rr.TimeColumn("time", duration=times)],
                     columns=rr.LineStrips3D.columns(strips=simulation.worst.arm[samples]))
    rec.log("world/arm", rr.LineStrips3D.from_fields(colors=_SIMULATED, radii=_BOLD,
                                                     labels=[f"{simulation.arm.robot.model} (MuJoCo)"]), static=True)


def _log_closed_loop(rec: rr.RecordingStream, scene: Scene, loop: ClosedLoop) -> None:
    """Each closed-loop run's part, pusher, executed path and re-plans, and ``/log/closed_loop``
    (module docstring)."""
    outline, body = _closed(scene.slider.vertices), _closed(pusher_frame_body(scene.pusher.width, scene.pusher.depth))
    for k, run in enumerate(loop.runs, 1):
        root, t = f"world/closed_loop/{k}", run.executed.t
        rows = np.unique(np.append(np.searchsorted(t, np.arange(0.0, t[-1], 1.0 / RUN_FRAMES_HZ)), len(t) - 1))
        clock = [rr.TimeColumn("time", duration=t[rows])]
        pusher = np.column_stack([run.executed.x, run.executed.y, run.executed.theta])[rows]
        for entity, strips in ((f"{root}/part", place(outline, run.part[rows])), (f"{root}/pusher", place(body, pusher))):
            rec.send_columns(entity, indexes=clock, columns=rr.LineStrips3D.columns(strips=_z(strips, "ghost")))
        rec.send_columns(f"{root}/pusher_path", indexes=clock, columns=rr.LineStrips3D.columns(
            strips=_zs(history(pusher[:, :2], np.zeros(len(rows), dtype=int)), "path")))
        rec.log(f"{root}/part", rr.LineStrips3D.from_fields(colors=_SIMULATED, radii=_BOLD, labels=[f"run {k}"]),
                static=True)
        rec.log(f"{root}/pusher", rr.LineStrips3D.from_fields(colors=_DARK, radii=_LINE), static=True)
        rec.log(f"{root}/pusher_path", rr.LineStrips3D.from_fields(colors=_DARK, radii=_THIN), static=True)
        for j, replan in enumerate(run.replans, 1):
            rec.set_time("time", duration=replan.time)
            shown = frames(scene, replan.plan).parts[replan.plan.part]
            rec.log(f"{root}/replan/{j}", rr.LineStrips3D([_z(place(scene.slider.cf[None], shown)[:, 0], "path")],
                                                          colors=_COR, radii=_LINE))
            rec.log(f"{root}/replan/{j}/start", rr.Points3D(
                _z(place(scene.slider.cf[None], replan.start[None])[0], "marker"), colors=_COR, radii=_DOT,
                labels=[f"re-plan {j} at {replan.time:.2f} s"]))
            rec.log("log/closed_loop", rr.TextLog(f"run {k}, re-plan {j} at {replan.time:.2f} s: {replan.why} "
                                                  f"({replan.latency * 1e3:.0f} ms)", level="INFO"))
        for when, reason in run.carried:
            rec.set_time("time", duration=when)
            rec.log("log/closed_loop", rr.TextLog(f"run {k} went on with its plan at {when:.2f} s: {reason}",
                                                  level="WARN"))
        rec.reset_time()
        if run.seen is not None and run.seen.images:
            _log_camera(rec, scene, root, k, run.seen)
    _log_text(rec, "log/closed_loop", [loop.summary(), *loop.lines()], "INFO" if loop.passed else "WARN")


def _log_camera(rec: rr.RecordingStream, scene: Scene, root: str, k: int, seen: Seen) -> None:
    """What run ``k``'s camera saw (module docstring): its pose and lens, the depth images kept,
    each image's estimated outlines and MuJoCo's at the same time, and where it lost a part."""
    from ..execution.closed_loop import DEPTH_STEP  # a camera run was made: the simulator is there
    from ..execution.depth_camera import PART_TOP

    camera, images = seen.camera, seen.images
    width, height = camera.resolution
    # Pixel i of a kept image is pixel DEPTH_STEP i + DEPTH_STEP // 2 of the camera's; rerun puts (0, 0)
    # at the first pixel's corner, the camera model (Camera.K) at its centre.
    lens = camera.K / DEPTH_STEP
    lens[:2, 2] = (camera.K[:2, 2] - DEPTH_STEP // 2) / DEPTH_STEP + 0.5
    lens[2, 2] = 1.0
    rec.log(f"{root}/camera", rr.Transform3D(translation=camera.position, mat3x3=camera.T_world_camera[:3, :3]),
            rr.Pinhole(image_from_camera=lens, resolution=[-(-width // DEPTH_STEP), -(-height // DEPTH_STEP)],
                       camera_xyz=rr.ViewCoordinates.RDF, image_plane_distance=0.05), static=True)
    kept = [image for image in images if image.depth is not None]
    returns = np.concatenate([image.depth[image.depth > 0] for image in kept])
    # Coloured over the table's depths and twice a part's height either side: a part stands out by
    # colour, and the table is not drawn in the colour of the end of the range, where the viewer draws
    # the pixels of no return, most of them those where no ray was cast.
    margin = 2e3 * PART_TOP
    span = ([float(np.percentile(returns, 2)) - margin, float(np.percentile(returns, 98)) + margin] if len(returns)
            else None)
    for image in kept:
        rec.set_time("time", duration=image.taken)
        rec.log(f"{root}/camera/depth", rr.DepthImage(image.depth, meter=1000.0, depth_range=span, colormap="Magma"))
    rec.reset_time()
    outlines = {part.name: _closed(part.slider.vertices) for part in scene.parts}
    clock = [rr.TimeColumn("time", duration=[image.taken for image in images])]
    estimates = [[place(outlines[n], e.pose[None])[0] for n, e in image.estimates.items() if e.tracked]
                 for image in images]
    rec.send_columns(f"{root}/seen/estimate", indexes=clock, columns=rr.LineStrips3D.columns(
        strips=_zs([s for row in estimates for s in row], "part")).partition([len(row) for row in estimates]))
    rec.log(f"{root}/seen/estimate", rr.LineStrips3D.from_fields(colors=_CAMERA, radii=_LINE, labels=["camera"]),
            static=True)
    lost = [[image.estimates[n].lost for n in image.truth] for image in images]
    truth = [place(outlines[n], pose[None])[0] for image in images for n, pose in image.truth.items()]
    why = [w for row in lost for w in row]
    rec.send_columns(f"{root}/seen/truth", indexes=clock, columns=rr.LineStrips3D.columns(
        strips=_zs(truth, "ghost"), colors=[_RED if w else _SIMULATED for w in why],
        labels=[f"lost track: {w}" if w else "" for w in why]).partition([len(row) for row in lost]))
    rec.log(f"{root}/seen/truth", rr.LineStrips3D.from_fields(radii=_LINE), static=True)
    was: set[str] = set()
    for image, row in zip(images, lost):
        now = {n for n, w in zip(image.truth, row) if w}
        rec.set_time("time", duration=image.taken)
        for name in sorted(now - was):
            rec.log("log/closed_loop", rr.TextLog(f"run {k} lost track of {name} at {image.taken:.2f} s: "
                                                  f"{image.estimates[name].lost}", level="WARN"))
        for name in sorted(was - now):
            rec.log("log/closed_loop", rr.TextLog(f"run {k} sees {name} again at {image.taken:.2f} s", level="INFO"))
        was = now
    rec.reset_time()


def _log_motion(rec: rr.RecordingStream, scene: Scene, plan: Plan, look: dict[str, Look]) -> Frames:
    """The animated entities; returns the frames."""
    shown = frames(scene, plan)
    steps = [rr.TimeColumn("step", sequence=np.arange(len(shown.times))), rr.TimeColumn("time", duration=shown.times)]
    # Per frame: the current push's COR, none or one (a transit or a transfer turns nothing: no COR).
    cor: list[np.ndarray] = []
    for k, (name, s) in enumerate(plan.steps):
        at = shown.parts[name][shown.index == k]
        centre, sense = twist_to_cor(s.twist) if isinstance(s, Push) else (None, 0)
        cor += list(place(centre[None], at)) if sense != 0 else [np.zeros((0, 2))] * len(at)

    def send(entity: str, columns: rr.ComponentColumnList, lengths: ArrayLike | None = None) -> None:
        """One row per frame; ``lengths`` (how many items each frame has) splits ``columns`` into them."""
        rec.send_columns(entity, indexes=steps, columns=columns if lengths is None else columns.partition(lengths))

    for part in scene.parts:
        poses, mine, root = shown.parts[part.name], look[part.name], _root(look[part.name])
        send(f"{root}/slider", rr.LineStrips3D.columns(strips=_z(place(_closed(part.slider.vertices), poses), "part")))
        send(f"{root}/cf_path", rr.LineStrips3D.columns(
            strips=_zs(history(place(part.slider.cf[None], poses)[:, 0], shown.index), "path")))
        rec.log(f"{root}/slider", rr.LineStrips3D.from_fields(
            colors=mine.part, radii=_BOLD, labels=None if mine.name is None else [mine.name]), static=True)
        rec.log(f"{root}/cf_path", rr.LineStrips3D.from_fields(colors=mine.path, radii=_LINE), static=True)
    pusher = _z(place(_closed(pusher_frame_body(scene.pusher.width, scene.pusher.depth)), shown.pusher), "part")
    send("world/pusher", rr.LineStrips3D.columns(strips=pusher[~shown.lifted],
                                                 labels=_margin_labels(plan, shown)[~shown.lifted]),
         (~shown.lifted).astype(int))
    send("world/pusher_lifted", rr.LineStrips3D.columns(strips=pusher[shown.lifted]), shown.lifted.astype(int))
    send("world/cor", rr.Points3D.columns(positions=_z(np.concatenate(cor), "marker")), [len(c) for c in cor])
    rec.log("world/pusher", rr.LineStrips3D.from_fields(colors=_DARK, radii=_BOLD), static=True)
    rec.log("world/pusher_lifted", rr.LineStrips3D.from_fields(colors=_LIFTED, radii=_THIN, labels=["lifted"]),
            static=True)
    rec.log("world/cor", rr.Points3D.from_fields(colors=_COR, radii=_DOT, labels=["COR"]), static=True)
    return shown


def _margin_labels(plan: Plan, shown: Frames) -> np.ndarray:
    """The pusher's label at each frame: during a push, the push and its own certified margin
    (``push 2/5: margin friction -81 %, CF 1.2 mm``); else none (an empty label)."""
    pushes = [k for k, (_, s) in enumerate(plan.steps) if isinstance(s, Push)]
    text = {k: f"push {j}/{len(pushes)}: margin {m}" for j, (k, m) in enumerate(zip(pushes, plan.margins), 1)}
    return np.array([text.get(int(k), "") for k in shown.index], dtype=object)


def _log_reach(rec: rr.RecordingStream, reach: ReachableSet) -> None:
    """The reachable-set map, static: a point per reachable cell, coloured by its fewest pushes."""
    from ..queries.reachable_set import COLOURS, reach_points

    centres, counts = reach_points(reach)
    colours = {k: [int(c[i:i + 2], 16) for i in (1, 3, 5)] for k, c in COLOURS.items()}
    rec.log("world/reach", rr.Points3D(_z(centres, "map"), colors=[colours[int(k)] for k in counts],
                                       radii=0.35 * min(reach.cell)), static=True)


def _top_view(origin: str, name: str, x: float, y: float, half: float, hidden: tuple[str, ...] = ()) -> rrb.Spatial3DView:
    """A 3-D view looking straight down at ``(x, y)`` from high enough to see ``half`` round it, x
    to the right and y up, showing what is under ``origin`` but the entities ``hidden``: rerun's 2-D
    views draw y downwards whatever the view coordinates say (its issue #1387), and a pushing plan
    drawn upside down reads wrongly (a left turn looks right; docs/stack.md, "What the viewer shows")."""
    return rrb.Spatial3DView(origin=origin, name=name, line_grid=False, eye_controls=rrb.EyeControls3D(
        kind=rrb.Eye3DKind.Orbital, position=[x, y, _EYE * half], look_target=[x, y, 0.0], eye_up=[0.0, 1.0, 0.0]),
        contents=["+ $origin/**", *(f"- {entity}" for entity in hidden)])


def write_recording(path: str | Path, scene: Scene, plan: Plan, verification: Verification | None = None,
                    reach: ReachableSet | None = None, simulation: Simulation | None = None,
                    closed_loop: ClosedLoop | None = None, cache: RegionCache | None = None) -> None:
    """Write a rerun recording of ``plan`` for ``scene`` to ``path`` (layout: module docstring).

    The recording is made in memory (footer included) and written with
    :func:`~planner.model.files.write_atomic`: readers see the old file or the whole new one, and
    a failed write leaves any previous file untouched and no temporary file behind.

    Parameters
    ----------
    path : str or Path
        The ``.rrd`` file to write; its folder must exist.
    scene : Scene
        The scene that was planned, of any number of parts.
    plan : Plan
        The planner's result, solved or not (a plan without a move, as an unsolved plan of one part
        is, gives the static scene only).
    verification : Verification, optional
        :func:`planner.verify` of ``plan``, a plan of one part: adds the simulated ghost and the
        verdict (the checks are drawn for one part only, as the module docstring says).
    reach : ReachableSet, optional
        :func:`planner.queries.reachable_set.reachable_set` from the scene's start: adds ``/world/reach``.
    simulation : Simulation, optional
        :func:`planner.execution.mujoco_sim.simulate` of ``plan``, a plan of one part: adds the
        simulated part and the verdict.
    closed_loop : ClosedLoop, optional
        :func:`planner.execution.closed_loop.closed_loop` of ``plan``, a plan of one part: adds its
        runs and re-plans.
    cache : RegionCache, optional
        Where the plan's regions and the analysis are found, or kept once computed (default:
        :func:`~planner.actions.region_cache.default_cache`); :func:`~planner.outputs.analysis.prepare` may have filled it.

    Raises
    ------
    OSError
        If the file cannot be written whole (a full disk, say), naming ``path``.
    """
    xmin, ymin, xmax, ymax = scene.workspace
    look = looks(scene, (_SLIDER, _GOAL, _CF))
    name, edge = _analysed(scene, plan)
    first = scene.part(name).slider
    # A camera run's depth images in a view of their own: in the world's, the viewer draws each as a
    # cloud of fat points over the table, which hides the outlines, and the camera's frustum, near
    # the view's eye, as lines across it.
    cameras = closed_loop is not None and len(scene.parts) == 1 and closed_loop.runs[0].seen is not None
    depths = tuple(f"/world/closed_loop/{k}/camera/**" for k in range(1, len(closed_loop.runs) + 1)) if cameras else ()
    views = [_top_view("/world", scene.name, (xmin + xmax) / 2, (ymin + ymax) / 2, max(xmax - xmin, ymax - ymin) / 2,
                       depths),
             _top_view("/analysis", f"{look[name].label('pushed edge')} (slider frame)", *first.cf, 6 * first.radius)]
    if cameras:
        views.append(rrb.Spatial2DView(origin="/world/closed_loop/1/camera", name="depth camera, run 1"))
    blueprint = rrb.Blueprint(rrb.Vertical(
        rrb.Horizontal(*views, column_shares=[3, 2, 2][:len(views)]),
        rrb.TextLogView(origin="/log", name="summary"),
        row_shares=[3, 1]))
    rec = rr.RecordingStream("stablepush", recording_id=f"{scene.name}-{plan.planner}-seed{plan.seed}")
    rec.set_log_time_enabled(False)
    # Into memory, then written by this process: rerun's own file sink reports a failed write
    # (a full disk) only in its log, and the caller would take a truncated file for a good one.
    stream = rec.binary_stream()
    try:
        # Active, not only default: in a stream the data comes first, and the viewer would keep the
        # layout it makes up for it (seen in the web viewer; tests/planner/outputs/test_recording.py checks the file).
        rec.send_blueprint(blueprint, make_active=True, make_default=True)
        _log_static(rec, scene, plan, look)
        if plan.moves:
            shown = _log_motion(rec, scene, plan, look)
            if edge is not None:
                _log_analysis(rec, scene.move_scene(name, scene.starts, others=False), plan, edge, cache)
            one = len(scene.parts) == 1  # the checks' reports of one part (module docstring)
            if verification is not None and one:
                _log_ghost(rec, plan, verification, shown)
            if simulation is not None and one:
                _log_simulated(rec, scene, simulation, shown.times)
            if simulation is not None and simulation.arm is not None:
                _log_arm(rec, simulation, shown.times)
            if closed_loop is not None and one:
                _log_closed_loop(rec, scene, closed_loop)
        if reach is not None:
            _log_reach(rec, reach)
        data = stream.read(flush=True)  # the whole recording, footer included
    finally:
        rec.disconnect()
    write_atomic(path, data)
