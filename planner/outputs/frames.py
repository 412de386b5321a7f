"""The animation of a plan, frame by frame: where every part and the pusher are, and when.

What the recording (:mod:`planner.outputs.recording`) draws at each frame, computed apart from
drawing it: each step of the plan (:attr:`~planner.model.plan.Plan.steps`: pushes, transits and
transfers) is sampled so that no body point moves more than a step between frames
(:func:`frames`), and a point's path so far is thinned for each frame (:func:`history`).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from mechanics import Slider, exp_twist

from ..actions.transit import edge_contact_pose, transit_poses
from ..model.bodies import place, pusher_frame_body
from ..model.plan import Plan
from ..model.segments import Push, Transfer, Transit
from ..model.scene import Scene

__all__ = ["FRAMES_PER_RADIUS", "MAX_FRAMES", "PATH_POINTS", "Frames", "frames", "history", "pusher_on"]

#: Animation frames while a body point travels the radius of the scene's smallest part (fewer if
#: that exceeds MAX_FRAMES).
FRAMES_PER_RADIUS = 20
#: Most animation frames a recording holds (for plans of fewer than ``MAX_FRAMES - 1`` steps).
MAX_FRAMES = 600
#: About the most points of the CF path drawn in one frame (it is redrawn every frame).
PATH_POINTS = 100


class Frames(NamedTuple):
    """The animation, one item per frame."""

    index: np.ndarray  # the step shown (an index into Plan.steps)
    times: np.ndarray  # plan time, s
    parts: dict[str, np.ndarray]  # each part's pose
    pusher: np.ndarray  # the pusher frame's world pose (planner.model.bodies.pusher_frame_body)
    lifted: np.ndarray  # whether the pusher is in the air


def pusher_on(slider: Slider, edge: int) -> np.ndarray:
    """The pusher frame's pose in the slider frame while it pushes ``edge``: face centred on the
    edge's midpoint (:func:`planner.model.bodies.pusher_polygon`), facing the part."""
    return edge_contact_pose(slider, edge, np.zeros(3))


def _sample(slider: Slider, body: np.ndarray, segment: Push | Transit | Transfer, t: np.ndarray,
            pose: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The poses of the part ``segment`` concerns (``slider``, at ``pose`` as it begins), of the
    pusher, and the pusher's being airborne, ``t`` into ``segment``."""
    if not isinstance(segment, Push):  # a transit or a transfer: the pusher follows its path, the part stands
        pusher, lifted = transit_poses(segment, body, t)
        return np.tile(pose, (len(t), 1)), pusher, lifted
    part = exp_twist(segment.start, segment.twist, t)
    local = pusher_on(slider, segment.edge)
    pusher = np.column_stack([place(local[None, :2], part)[:, 0], part[:, 2] + local[2]])
    return part, pusher, np.zeros(len(t), dtype=bool)


def frames(scene: Scene, plan: Plan) -> Frames:
    """Every animation frame of ``plan`` (which has a step) for ``scene``.

    No body point moves more than the smallest part's radius over ``FRAMES_PER_RADIUS`` between
    frames (pushes, transits and transfers alike: duration bounds point travel), unless that would
    take more than ``MAX_FRAMES``: then frames are shared out in proportion to the steps'
    durations. Every step gets at least its first frame, and a last frame shows the end of the
    last, so there are at most ``max(MAX_FRAMES, steps + 1)`` frames. A part stands where its
    last step left it (at first, the plan's start) while another part is pushed.
    """
    steps = plan.steps
    body = pusher_frame_body(scene.pusher.width, scene.pusher.depth)
    durations = np.array([s.duration for _, s in steps])
    counts = np.maximum(np.ceil(durations / (min(p.slider.radius for p in scene.parts) / FRAMES_PER_RADIUS)),
                        1).astype(int)
    if counts.sum() > MAX_FRAMES - 1:
        budget = max(MAX_FRAMES - 1 - len(steps), 0)
        counts = 1 + (budget * durations / durations.sum()).astype(int)
    at = {n: np.asarray(p, dtype=float) for n, p in plan.starts.items()}
    index, times, parts, pusher, lifted = [], [], {n: [] for n in at}, [], []
    clock = 0.0
    for k, ((name, s), n) in enumerate(zip(steps, counts)):
        t = np.arange(n) * (s.duration / n)
        # Sampled at its end too: where the step leaves the part, and the last frame if it is the last.
        moving, where, up = _sample(scene.part(name).slider, body, s, np.append(t, s.duration), at[name])
        for other, poses in parts.items():
            poses.append(moving[:-1] if other == name else np.tile(at[other], (n, 1)))
        index.append(np.full(n, k))
        times.append(clock + t)
        pusher.append(where[:-1])
        lifted.append(up[:-1])
        clock += s.duration
        at[name] = moving[-1]
    index.append([len(steps) - 1])
    times.append([clock])
    for other, poses in parts.items():
        poses.append(at[other][None])
    pusher.append(where[-1:])
    lifted.append(up[-1:])
    return Frames(np.concatenate(index), np.concatenate(times), {n: np.concatenate(p) for n, p in parts.items()},
                  np.concatenate(pusher), np.concatenate(lifted))


def history(points: np.ndarray, index: np.ndarray) -> list[np.ndarray]:
    """For each frame, the path of ``points`` (one per frame) so far, thinned to at most about
    ``PATH_POINTS`` points: every few frames plus the first frame of each step (where the path
    may turn sharply) and the current one."""
    keep = np.zeros(len(points), dtype=bool)
    keep[:: -(-len(points) // PATH_POINTS)] = True
    keep[np.flatnonzero(np.diff(index, prepend=-1))] = True
    kept = np.flatnonzero(keep)
    return [points[np.r_[kept[: np.searchsorted(kept, i)], i]] for i in range(len(points))]
