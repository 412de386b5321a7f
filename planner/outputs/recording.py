"""Rerun recording of a plan: the scene, the search tree and the pushes, animated (the frames come
from :mod:`planner.outputs.frames`, the pushed edge's mechanics from :mod:`planner.outputs.analysis`).

:func:`write_recording` writes one ``.rrd`` file (application ``stablepush``, recording id
``<scene>-<planner>-seed<seed>``, no wall-clock timeline, so the same plan gives the same file).
Everything is in world coordinates, metres; outlines are closed ``LineStrips2D``. Entities:

Static (no timeline, always visible)

* ``/world/workspace`` -- ``Boxes2D``, the workspace bounds;
* ``/world/obstacles`` -- one strip per obstacle, labelled ``obstacle <k>`` in scene order;
* ``/world/start``, ``/world/goal`` -- the slider's outline at the start and goal poses (ghosts);
* ``/world/tree`` -- one strip per search-tree edge (``Plan.tree``; empty after a one-step plan);
* ``/world/transits`` -- the path of the pusher's face centre on each transit (edge switch),
  labelled ``transit <k>`` in plan order: one strip for a walk round the part, three for a lift,
  whose middle, airborne, strip is labelled ``transit <k> lifted`` and drawn thin and faint in
  the lifted pusher's colour (no strip for a plan without switches);
* ``/log`` -- ``TextLog``, one summary line (``WARN`` when not solved).

Animated, one row per frame on the timelines ``time`` (plan time in seconds, pushes and transits
alike: no body point moves faster than 1 m/s) and ``step`` (frame index), only for a plan with
segments. Frames are ``FRAMES_PER_RADIUS`` per slider radius of point travel, at most
``MAX_FRAMES`` in all:

* ``/world/slider`` -- the slider's outline; it stands still during a transit;
* ``/world/pusher`` -- the pusher's outline on the table: on the pushed edge during a push, and
  along the transit's path (:func:`planner.actions.transit.transit_poses`) during a transit; no strip while it is lifted;
* ``/world/pusher_lifted`` -- the pusher's outline while it is in the air (the inside of a lift's
  middle piece), thin, faint and labelled ``lifted``; no strip on every other frame;
* ``/world/cf_path`` -- the path of the centre of friction so far (thinned to about
  ``PATH_POINTS`` points, always through the segments' ends);
* ``/world/cor`` -- ``Points2D``, the current push's centre of rotation (no point for a
  translation, whose COR is at infinity, nor during a transit);
* ``/world/stable/ccw``, ``/world/stable/cw`` -- the pushed edge's stable COR regions, clipped to
  a square of half-side 4 slider radii about the CF and carried with the slider (no strip where
  a region is empty, nor during a transit: no edge is pushed then, and the regions of the edge
  being left would suggest one is).

The first pushed edge's mechanics (Lynch 1992's figures 11 and 14 for this part), static, in the
slider frame, for a plan with a push:

* ``/analysis/part`` -- the slider's outline at the origin of its frame, and ``/analysis/contact``
  the pushed contact segment;
* ``/analysis/stable/{ccw,cw}`` -- procedure STABLE's COR regions; ``/analysis/exact/{ccw,cw}``
  the exact regions (contain STABLE's; :mod:`mechanics.exact_region`);
* ``/analysis/sticking/{ccw,cw}/{P,U,I}`` -- the force status of sticking (both ends) for every
  COR of each sense (:func:`mechanics.force_status_regions`, ``ANALYSIS_RAYS`` rays), for every CF
  of the scene's uncertainty disk;
* ``/analysis/cor`` -- ``Points2D``, the centres of rotation of the plan's pushes on that edge
  inside the window (pushes on other edges belong with other regions).

All COR regions are clipped to a square of half-side 4 slider radii about the CF.

With a :class:`~planner.execution.verify.Verification` (``plan --verify``), also:

* ``/world/ghost`` -- the slider's outline as simulated under each push's worst support
  distribution (the run deviating most from the plan), from the push's planned start, at up to
  ``GHOST_SAMPLES`` frames per push (the viewer holds it in between, through transits too); it
  hides under ``/world/slider`` wherever the push sticks;
* ``/log/verify`` -- ``TextLog``, the verification's summary line (``WARN`` when it failed).

With a :class:`~planner.execution.mujoco_sim.Simulation` (``plan --simulate N``), also:

* ``/world/simulated`` -- the slider's outline as MuJoCo moved it in the run that strayed
  farthest from the planned path (:attr:`~planner.execution.mujoco_sim.Simulation.worst`), at
  every frame: the trajectory sample at the frame's plan time
  (:attr:`~planner.execution.trajectory.Trajectory.plan_time`), so the two outlines part where
  the run leaves the plan and one hides the other while it follows;
* ``/log/simulate`` -- ``TextLog``, the simulation's summary line (``WARN`` when it failed).

With a reachable-set map (``plan --reach N``; :mod:`planner.queries.reachable_set`), also:

* ``/world/reach`` -- ``Points2D``, static, one point per reachable cell centre, green for one
  push and amber for two.

Styles (colours, line widths in UI points) are logged statically on the animated entities. The
default blueprint shows ``/world`` in a 2-D view bounded by the workspace beside ``/analysis``,
above the text log.
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

from ..actions.region_cache import RegionCache, edge_region
from ..actions.transit import transit_pieces
from ..model.bodies import place, pusher_frame_body
from ..model.files import write_atomic
from ..model.plan_file import Plan
from ..model.scene import Scene
from .analysis import STATUS, analysis
from .frames import FRAMES_PER_RADIUS, frames, history

if TYPE_CHECKING:  # the simulators behind them import scipy or MuJoCo: not needed to draw a plan
    from ..execution.mujoco_sim import Simulation
    from ..execution.verify import Verification
    from ..queries.reachable_set import ReachableSet

__all__ = ["GHOST_SAMPLES", "write_recording"]

#: Most frames per push at which the simulated ghost is drawn (each costs a simulation).
GHOST_SAMPLES = 10

_THIN, _LINE, _BOLD, _DOT = (float(r) for r in rr.components.Radius.ui_points([0.5, 1.0, 2.0, 4.0]))
_GREY, _DARK, _RED = [150, 150, 150], [60, 60, 60], [200, 50, 50]
_SLIDER, _GOAL, _CF = [40, 110, 220], [40, 170, 70], [90, 160, 255]
_CCW, _CW, _COR, _GHOST, _SIMULATED = [20, 170, 150], [230, 130, 20], [210, 40, 190], [140, 60, 230], [235, 70, 120]
_LIFTED = [110, 110, 110, 110]  # a faint, see-through grey: the pusher off the table, seen from above
_STATUS = dict(zip(STATUS, ([40, 170, 70], [230, 190, 40], [200, 50, 50])))


def _closed(points: ArrayLike) -> np.ndarray:
    """A polygon's vertices as a closed strip (the first vertex repeated at the end)."""
    p = np.asarray(points, dtype=float)
    return np.vstack([p, p[:1]])


def _summary(scene: Scene, plan: Plan) -> str:
    """One line; no planning time, so that the same plan always gives the same recording."""
    head = f"{scene.name}: planner {plan.planner}, seed {plan.seed}"
    if not plan.solved:
        return f"{head}: not solved: {plan.reason}; {len(plan.tree)} tree edges"
    made = plan.contents(" and ")
    timing = f"push time {sum(s.duration for s in plan.segments if s.kind == 'push'):.4f} s"
    if plan.switches:
        timing += f", transit time {sum(s.duration for s in plan.segments if s.kind == 'transit'):.4f} s"
    return (f"{head}: solved with {made}, CF path {plan.path_length(scene.slider.cf):.4f} m, {timing}; "
            f"{len(plan.tree)} tree edges")


def _log_static(rec: rr.RecordingStream, scene: Scene, plan: Plan) -> None:
    xmin, ymin, xmax, ymax = scene.workspace
    outline = _closed(scene.slider.vertices)
    ghosts = place(outline, np.array([scene.start, scene.goal]))
    rec.log("world/workspace", rr.Boxes2D(mins=[xmin, ymin], sizes=[xmax - xmin, ymax - ymin],
                                          colors=_DARK, radii=_LINE), static=True)
    rec.log("world/obstacles", rr.LineStrips2D(
        [_closed(o.exterior.coords[:-1]) for o in scene.obstacles], colors=_RED, radii=_BOLD,
        labels=[f"obstacle {k}" for k in range(len(scene.obstacles))]), static=True)
    rec.log("world/start", rr.LineStrips2D(ghosts[:1], colors=_GREY, radii=_LINE, labels="start"), static=True)
    rec.log("world/goal", rr.LineStrips2D(ghosts[1:], colors=_GOAL, radii=_LINE, labels="goal"), static=True)
    rec.log("world/tree", rr.LineStrips2D(np.asarray(plan.tree, dtype=float).reshape(-1, 2, 2),
                                          colors=_GREY, radii=_THIN, draw_order=-1.0), static=True)
    pieces = [(k, xy, up) for k, t in enumerate(s for s in plan.segments if s.kind == "transit")
              for xy, up in transit_pieces(t)]
    rec.log("world/transits", rr.LineStrips2D(
        [xy for _, xy, _ in pieces], colors=[_LIFTED if up else _DARK for *_, up in pieces],
        radii=[_THIN if up else _LINE for *_, up in pieces],
        labels=[f"transit {k + 1}{' lifted' if up else ''}" for k, _, up in pieces]), static=True)
    rec.log("log", rr.TextLog(_summary(scene, plan), level="INFO" if plan.solved else "WARN"), static=True)


def _outline(region: shapely.Geometry) -> np.ndarray | None:
    """Closed outline of a convex COR region, or None if it is empty or has no area."""
    return np.asarray(region.exterior.coords) if isinstance(region, shapely.Polygon) and region.area > 0 else None


def _rings(geometry: shapely.Geometry) -> list[np.ndarray]:
    """Closed outer rings of every polygon of ``geometry`` with area."""
    parts = getattr(geometry, "geoms", [geometry])
    return [np.asarray(g.exterior.coords) for g in parts if isinstance(g, shapely.Polygon) and g.area > 0]


def _log_analysis(rec: rr.RecordingStream, scene: Scene, plan: Plan, cache: RegionCache | None) -> None:
    """``/analysis``: the first pushed edge's regions in the slider frame (module docstring)."""
    pushes = [s for s in plan.segments if s.kind == "push"]
    edge = pushes[0].edge
    window, contact, polygons = analysis(scene, edge, cache)
    rec.log("analysis/part", rr.LineStrips2D([_closed(scene.slider.vertices)], colors=_SLIDER, radii=_BOLD),
            static=True)
    rec.log("analysis/contact", rr.LineStrips2D([contact], colors=_DARK, radii=_BOLD), static=True)
    for name, width in (("stable", _BOLD), ("exact", _LINE)):
        for side, colour in (("ccw", _CCW), ("cw", _CW)):
            rings = _rings(polygons[name][1 if side == "ccw" else -1])
            rec.log(f"analysis/{name}/{side}", rr.LineStrips2D(rings, colors=colour, radii=width), static=True)
    for side, sense in (("ccw", 1), ("cw", -1)):
        for label, colour in _STATUS.items():
            rings = _rings(polygons[label][sense])
            rec.log(f"analysis/sticking/{side}/{label}", rr.LineStrips2D(rings, colors=colour, radii=_THIN), static=True)
    cors = [c for c, sense in map(twist_to_cor, (s.twist for s in pushes if s.edge == edge)) if sense != 0]
    inside = [c for c in cors if shapely.box(*window).contains(shapely.Point(c))]  # far ones would zoom the view out
    rec.log("analysis/cor", rr.Points2D(inside or np.zeros((0, 2)), colors=_COR, radii=_DOT), static=True)


def _log_ghost(rec: rr.RecordingStream, plan: Plan, verification: Verification, index: np.ndarray,
               times: np.ndarray) -> None:
    """``/world/ghost`` at up to ``GHOST_SAMPLES`` of each push's frames, and ``/log/verify``.

    The verification checks pushes only, in plan order: its ``i``-th is the plan's ``i``-th push,
    whose frames are found by that push's segment index."""
    frames, poses = [], []
    segment_of = [k for k, s in enumerate(plan.segments) if s.kind == "push"]
    for i in range(len(verification.pushes)):
        mine = np.flatnonzero(index == segment_of[i])  # the last segment's frames include the final one
        mine = mine[np.unique(np.linspace(0, len(mine) - 1, min(GHOST_SAMPLES, len(mine))).round().astype(int))]
        frames.append(mine)
        poses.append(verification.poses(i, times[mine] - times[mine[0]]))
    frames = np.concatenate(frames)
    outline = _closed(verification.scene.slider.vertices)
    rec.send_columns("world/ghost", indexes=[rr.TimeColumn("step", sequence=frames),
                                             rr.TimeColumn("time", duration=times[frames])],
                     columns=rr.LineStrips2D.columns(strips=place(outline, np.concatenate(poses))))
    rec.log("world/ghost", rr.LineStrips2D.from_fields(colors=_GHOST, radii=_LINE), static=True)
    rec.log("log/verify", rr.TextLog(verification.summary(), level="INFO" if verification.passed else "WARN"),
            static=True)


def _log_simulated(rec: rr.RecordingStream, scene: Scene, simulation: Simulation, times: np.ndarray) -> None:
    """``/world/simulated`` at every frame, and ``/log/simulate`` (module docstring)."""
    clock = simulation.motion.plan_time
    samples = np.clip(np.searchsorted(clock, times + 1e-12, side="right") - 1, 0, len(clock) - 1)
    strips = place(_closed(scene.slider.vertices), simulation.worst.poses[samples])
    rec.send_columns("world/simulated", indexes=[rr.TimeColumn("step", sequence=np.arange(len(times))),
                                                 rr.TimeColumn("time", duration=times)],
                     columns=rr.LineStrips2D.columns(strips=strips))
    rec.log("world/simulated", rr.LineStrips2D.from_fields(colors=_SIMULATED, radii=_LINE, labels=["MuJoCo"]),
            static=True)
    rec.log("log/simulate", rr.TextLog(simulation.summary(), level="INFO" if simulation.passed else "WARN"),
            static=True)


def _log_motion(rec: rr.RecordingStream, scene: Scene, plan: Plan,
                cache: RegionCache | None) -> tuple[np.ndarray, np.ndarray]:
    """The animated entities; returns the frames' segment indices and times."""
    shown = frames(scene, plan, scene.slider.radius / FRAMES_PER_RADIUS)
    index, times, poses = shown.index, shown.times, shown.part
    steps = [rr.TimeColumn("step", sequence=np.arange(len(times))), rr.TimeColumn("time", duration=times)]
    slider = scene.slider
    window = (*(slider.cf - 4 * slider.radius), *(slider.cf + 4 * slider.radius))
    # Only the pushed edges' regions: they are cached, the plan used them (others may not be done).
    p = scene.pusher
    regions = {e: {sense: _outline(poly) for sense, poly in edge_region(
        slider, e, p.mu, p.width, scene.planner.regions, scene.cf_uncertainty,
        cache=cache).cor_polygons(window).items()} for e in {s.edge for s in plan.segments if s.kind == "push"}}
    # Per frame: the COR and the regions' outlines, none or one each.
    cor: list[np.ndarray] = []
    stable: dict[int, list[np.ndarray]] = {1: [], -1: []}
    for k, s in enumerate(plan.segments):
        at = poses[index == k]
        centre, sense = twist_to_cor(s.twist)  # a transit's twist is zero: no COR
        cor += list(place(centre[None], at)) if sense != 0 else [np.zeros((0, 2))] * len(at)
        outlines = regions[s.edge] if s.kind == "push" else dict.fromkeys(stable)  # nothing is pushed
        for side, outline in outlines.items():
            empty = [np.zeros((0, 0, 2))] * len(at)
            stable[side] += empty if outline is None else list(place(outline, at)[:, None])

    def send(entity: str, columns: rr.ComponentColumnList, lengths: ArrayLike | None = None) -> None:
        """One row per frame; ``lengths`` (how many items each frame has) splits ``columns`` into them."""
        rec.send_columns(entity, indexes=steps, columns=columns if lengths is None else columns.partition(lengths))

    send("world/slider", rr.LineStrips2D.columns(strips=place(_closed(slider.vertices), poses)))
    pusher = place(_closed(pusher_frame_body(scene.pusher.width, scene.pusher.depth)), shown.pusher)
    for entity, where in (("world/pusher", ~shown.lifted), ("world/pusher_lifted", shown.lifted)):
        send(entity, rr.LineStrips2D.columns(strips=pusher[where]), where.astype(int))
    send("world/cf_path", rr.LineStrips2D.columns(strips=history(place(slider.cf[None], poses)[:, 0], index)))
    send("world/cor", rr.Points2D.columns(positions=np.concatenate(cor)), [len(c) for c in cor])
    for name, side in (("ccw", 1), ("cw", -1)):
        send(f"world/stable/{name}", rr.LineStrips2D.columns(strips=[o for row in stable[side] for o in row]),
             [len(row) for row in stable[side]])
    for entity, color, radius in (("world/slider", _SLIDER, _BOLD), ("world/pusher", _DARK, _BOLD),
                                  ("world/cf_path", _CF, _LINE), ("world/stable/ccw", _CCW, _LINE),
                                  ("world/stable/cw", _CW, _LINE)):
        rec.log(entity, rr.LineStrips2D.from_fields(colors=color, radii=radius), static=True)
    rec.log("world/pusher_lifted", rr.LineStrips2D.from_fields(colors=_LIFTED, radii=_THIN, labels=["lifted"]),
            static=True)
    rec.log("world/cor", rr.Points2D.from_fields(colors=_COR, radii=_DOT), static=True)
    return index, times


def _log_reach(rec: rr.RecordingStream, reach: ReachableSet) -> None:
    """The reachable-set map, static: a point per reachable cell, coloured by its fewest pushes."""
    from ..queries.reachable_set import COLOURS, reach_points

    centres, counts = reach_points(reach)
    colours = {k: [int(c[i:i + 2], 16) for i in (1, 3, 5)] for k, c in COLOURS.items()}
    rec.log("world/reach", rr.Points2D(centres, colors=[colours[int(k)] for k in counts],
                                       radii=0.35 * min(reach.cell), draw_order=-2.0), static=True)


def write_recording(path: str | Path, scene: Scene, plan: Plan, verification: Verification | None = None,
                    reach: ReachableSet | None = None, simulation: Simulation | None = None,
                    cache: RegionCache | None = None) -> None:
    """Write a rerun recording of ``plan`` for ``scene`` to ``path`` (layout: module docstring).

    The recording is made in memory (footer included) and written with
    :func:`~planner.model.files.write_atomic`: readers see the old file or the whole new one, and
    a failed write leaves any previous file untouched and no temporary file behind.

    Parameters
    ----------
    path : str or Path
        The ``.rrd`` file to write; its folder must exist.
    scene : Scene
        The scene that was planned.
    plan : Plan
        The planner's result, solved or not (an unsolved plan gives the static scene only).
    verification : Verification, optional
        :func:`planner.verify` of ``plan``: adds the simulated ghost and the verdict.
    reach : ReachableSet, optional
        :func:`planner.queries.reachable_set.reachable_set` from the scene's start: adds ``/world/reach``.
    simulation : Simulation, optional
        :func:`planner.execution.mujoco_sim.simulate` of ``plan``: adds the simulated part and the verdict.
    cache : RegionCache, optional
        Where the plan's regions and the analysis are found, or kept once computed (default:
        :func:`~planner.actions.region_cache.default_cache`); :func:`~planner.outputs.analysis.prepare` may have filled it.

    Raises
    ------
    OSError
        If the file cannot be written whole (a full disk, say), naming ``path``.
    """
    xmin, ymin, xmax, ymax = scene.workspace
    blueprint = rrb.Blueprint(rrb.Vertical(
        rrb.Horizontal(
            rrb.Spatial2DView(origin="/world", name=scene.name,
                              visual_bounds=rrb.VisualBounds2D(x_range=[xmin, xmax], y_range=[ymin, ymax])),
            rrb.Spatial2DView(origin="/analysis", name="pushed edge (slider frame)"),
            column_shares=[3, 2]),
        rrb.TextLogView(origin="/log", name="summary"),
        row_shares=[6, 1]))
    rec = rr.RecordingStream("stablepush", recording_id=f"{scene.name}-{plan.planner}-seed{plan.seed}")
    rec.set_log_time_enabled(False)
    # Into memory, then written by this process: rerun's own file sink reports a failed write
    # (a full disk) only in its log, and the caller would take a truncated file for a good one.
    stream = rec.binary_stream()
    try:
        # Active, not only default: in a stream the data comes first, and the viewer would keep the
        # layout it makes up for it (seen in the web viewer; tests/test_recording.py checks the file).
        rec.send_blueprint(blueprint, make_active=True, make_default=True)
        _log_static(rec, scene, plan)
        if plan.segments:
            index, times = _log_motion(rec, scene, plan, cache)
            if plan.pushes:
                _log_analysis(rec, scene, plan, cache)
            if verification is not None:
                _log_ghost(rec, plan, verification, index, times)
            if simulation is not None:
                _log_simulated(rec, scene, simulation, times)
        if reach is not None:
            _log_reach(rec, reach)
        data = stream.read(flush=True)  # the whole recording, footer included
    finally:
        rec.disconnect()
    write_atomic(path, data)
