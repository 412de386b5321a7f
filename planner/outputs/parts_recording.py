"""Rerun recording of a multi-part plan: every part, coloured and labelled, moving on one timeline,
and the pusher's transits and transfers drawn.

:func:`write_parts_recording` writes one ``.rrd`` file as :func:`planner.outputs.recording.write_recording`
does (application ``stablepush``, the same views, heights and styles). Entities:

Static

* ``/world/workspace``, ``/world/obstacles`` -- as for one part;
* ``/world/starts``, ``/world/goals`` -- each part's outline at its start (grey) and at its goal
  (in its colour, thin), labelled ``<part> start`` and ``<part> goal``;
* ``/world/transfers`` -- the path of the pusher's face centre on each transfer, labelled
  ``transfer <k> to <part>``; a lift's airborne piece thin and faint, labelled ``... lifted``;
* ``/world/transits`` -- the same for the switches of edge within a move;
* ``/log`` -- the summary rows (``WARN`` when not solved): parts, moves, buffer moves, pushes,
  transfers, cost, and which parts were delivered.

Animated on the timelines ``time`` (plan time, s: pushes, transits and transfers alike, no point
of the pusher faster than 1 m/s) and ``step`` (frame index):

* ``/world/parts/<part>`` -- each part's outline in its colour, labelled with its name; a part
  stands still but while it is pushed;
* ``/world/pusher``, ``/world/pusher_lifted`` -- the pusher on the table and in the air.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import rerun as rr
import rerun.blueprint as rrb

from ..actions.transit import transit_poses
from ..model.bodies import place, pusher_frame_body
from ..model.files import write_atomic
from ..model.scene import Scene
from ..model.plan import Plan
from .frames import FRAMES_PER_RADIUS, MAX_FRAMES, sample
from .recording import (_BOLD, _DARK, _GREY, _LIFTED, _THIN, _closed, _log_pusher_paths, _log_table, _log_text,
                        _top_view, _z)

__all__ = ["PALETTE", "part_colours", "write_parts_recording"]

#: Colours of the parts, in scene order (repeated past the last).
PALETTE = ([40, 110, 220], [230, 130, 20], [20, 170, 150], [210, 40, 190], [140, 90, 40], [110, 60, 230],
           [200, 170, 20], [60, 160, 60], [235, 70, 120], [90, 160, 255])


def part_colours(scene: Scene) -> dict[str, list[int]]:
    """Each part's colour: :data:`PALETTE` in scene order."""
    return {n: PALETTE[k % len(PALETTE)] for k, n in enumerate(scene.names)}


def _summary(scene: Scene, plan: Plan) -> list[str]:
    head = f"{scene.name}: planner {plan.planner}, seed {plan.seed}"
    missing = [n for n in scene.names if n not in plan.delivered]
    delivered = (f"delivered: {len(plan.delivered)} of {len(scene.names)} parts"
                 + (f"; not delivered: {', '.join(missing)}" if missing else ""))
    if not plan.solved:
        return [f"{head}: not solved: {plan.reason}", delivered]
    return [f"{head}: solved with {plan.contents()}",
            f"CF path length {plan.length:.4f} m; cost {plan.cost:.4f} m (length + {plan.switch_cost:g} m per switch "
            "and per transfer)", delivered]


def _frames(scene: Scene, plan: Plan) -> tuple[np.ndarray, dict[str, np.ndarray], np.ndarray, np.ndarray]:
    """Times, each part's pose, the pusher's pose and its being lifted, frame by frame: no body
    point moves more than a twentieth of the smallest part's radius between frames, unless that
    would take more than :data:`~planner.outputs.frames.MAX_FRAMES` frames."""
    body = pusher_frame_body(scene.pusher.width, scene.pusher.depth)
    segments = plan.steps
    durations = np.array([s.duration for _, s in segments])
    step = min(p.slider.radius for p in scene.parts) / FRAMES_PER_RADIUS
    counts = np.maximum(np.ceil(durations / step), 1).astype(int)
    if counts.sum() > MAX_FRAMES - 1:
        counts = 1 + (max(MAX_FRAMES - 1 - len(segments), 0) * durations / durations.sum()).astype(int)
    at = {n: np.asarray(p, dtype=float) for n, p in plan.starts.items()}
    times, poses, pusher, lifted = [], {n: [] for n in at}, [], []
    clock = 0.0
    for (name, s), n in zip([*segments, segments[-1]], [*counts.tolist(), 1]):
        last = len(times) == len(segments)
        t = np.array([s.duration]) if last else np.arange(n) * (s.duration / n)
        if s.kind == "transfer":
            where, up = transit_poses(s, body, t)
            moving = np.tile(at[name], (len(t), 1))
        else:
            moving, where, up = sample(scene.part(name).slider, body, s, t)
        for other in at:
            poses[other].append(moving if other == name else np.tile(at[other], (len(t), 1)))
        pusher.append(where)
        lifted.append(up)
        times.append(clock + t if not last else np.array([clock]))
        if not last:
            clock += s.duration
            if s.kind != "transfer":
                at[name] = s.end
    return (np.concatenate(times), {n: np.concatenate(p) for n, p in poses.items()}, np.concatenate(pusher),
            np.concatenate(lifted))


def write_parts_recording(path: str | Path, scene: Scene, plan: Plan) -> None:
    """Write a rerun recording of ``plan`` for ``scene`` to ``path`` (module docstring), atomically.

    Raises
    ------
    OSError
        If the file cannot be written whole, naming ``path``.
    """
    xmin, ymin, xmax, ymax = scene.workspace
    blueprint = rrb.Blueprint(rrb.Vertical(
        _top_view("/world", scene.name, (xmin + xmax) / 2, (ymin + ymax) / 2, max(xmax - xmin, ymax - ymin) / 2),
        rrb.TextLogView(origin="/log", name="summary"), row_shares=[3, 1]))
    rec = rr.RecordingStream("stablepush", recording_id=f"{scene.name}-{plan.planner}-seed{plan.seed}")
    rec.set_log_time_enabled(False)
    stream = rec.binary_stream()
    colours = part_colours(scene)
    try:
        rec.send_blueprint(blueprint, make_active=True, make_default=True)
        _log_table(rec, scene)
        for entity, which, colour in (("world/starts", "start", None), ("world/goals", "goal", True)):
            strips = [_z(place(_closed(p.slider.vertices), getattr(p, which)[None])[0], "ghost") for p in scene.parts]
            rec.log(entity, rr.LineStrips3D(strips, colors=[colours[p.name] if colour else _GREY for p in scene.parts],
                                            radii=_THIN, labels=[f"{p.name} {which}" for p in scene.parts]), static=True)
        hops = [m for m in plan.moves if m.transfer is not None]
        _log_pusher_paths(rec, "world/transfers", [(f"transfer {k + 1} to {m.part}", m.transfer) for k, m in enumerate(hops)])
        _log_pusher_paths(rec, "world/transits", [(f"transit {k + 1}", t) for k, t in enumerate(
            s for m in plan.moves for s in m.segments if s.kind == "transit")])
        _log_text(rec, "log", _summary(scene, plan), "INFO" if plan.solved else "WARN")
        if plan.moves:
            times, poses, pusher, lifted = _frames(scene, plan)
            steps = [rr.TimeColumn("step", sequence=np.arange(len(times))), rr.TimeColumn("time", duration=times)]
            for p in scene.parts:
                entity = f"world/parts/{p.name}"
                rec.send_columns(entity, indexes=steps, columns=rr.LineStrips3D.columns(
                    strips=_z(place(_closed(p.slider.vertices), poses[p.name]), "part")))
                rec.log(entity, rr.LineStrips3D.from_fields(colors=colours[p.name], radii=_BOLD, labels=[p.name]),
                        static=True)
            outline = _z(place(_closed(pusher_frame_body(scene.pusher.width, scene.pusher.depth)), pusher), "part")
            for entity, where in (("world/pusher", ~lifted), ("world/pusher_lifted", lifted)):
                rec.send_columns(entity, indexes=steps,
                                 columns=rr.LineStrips3D.columns(strips=outline[where]).partition(where.astype(int)))
            rec.log("world/pusher", rr.LineStrips3D.from_fields(colors=_DARK, radii=_BOLD), static=True)
            rec.log("world/pusher_lifted", rr.LineStrips3D.from_fields(colors=_LIFTED, radii=_THIN, labels=["lifted"]),
                    static=True)
        data = stream.read(flush=True)
    finally:
        rec.disconnect()
    write_atomic(path, data)
