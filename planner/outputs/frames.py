"""The animation of a plan, frame by frame: where the part and the pusher are, and when.

What the recording (:mod:`planner.outputs.recording`) draws at each frame, computed apart from
drawing it: each segment is sampled so that no body point moves more than a step between frames
(:func:`frames`), and the centre of friction's path so far is thinned for each frame
(:func:`history`).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from mechanics import Slider, exp_twist

from ..actions.transit import edge_contact_pose, transit_poses
from ..model.bodies import place, pusher_frame_body
from ..model.plan import Plan
from ..model.segments import Push, Transit
from ..model.scene import Scene

__all__ = ["FRAMES_PER_RADIUS", "MAX_FRAMES", "PATH_POINTS", "Frames", "frames", "history", "pusher_on", "sample"]

#: Animation frames while a body point travels one slider radius (fewer if that exceeds MAX_FRAMES).
FRAMES_PER_RADIUS = 20
#: Most animation frames a recording holds (for plans of fewer than ``MAX_FRAMES - 1`` pushes).
MAX_FRAMES = 600
#: About the most points of the CF path drawn in one frame (it is redrawn every frame).
PATH_POINTS = 100


class Frames(NamedTuple):
    """The animation, one item per frame."""

    index: np.ndarray  # the segment shown
    times: np.ndarray  # plan time, s
    part: np.ndarray  # the part's pose
    pusher: np.ndarray  # the pusher frame's world pose (planner.model.bodies.pusher_frame_body)
    lifted: np.ndarray  # whether the pusher is in the air


def pusher_on(slider: Slider, edge: int) -> np.ndarray:
    """The pusher frame's pose in the slider frame while it pushes ``edge``: face centred on the
    edge's midpoint (:func:`planner.model.bodies.pusher_polygon`), facing the part."""
    return edge_contact_pose(slider, edge, np.zeros(3))


def sample(slider: Slider, body: np.ndarray, segment: Push | Transit,
            t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The part's and the pusher's poses and the pusher's being airborne, ``t`` into ``segment``."""
    if isinstance(segment, Transit):
        pusher, lifted = transit_poses(segment, body, t)
        return np.tile(segment.pose, (len(t), 1)), pusher, lifted
    part = exp_twist(segment.start, segment.twist, t)
    local = pusher_on(slider, segment.edge)
    pusher = np.column_stack([place(local[None, :2], part)[:, 0], part[:, 2] + local[2]])
    return part, pusher, np.zeros(len(t), dtype=bool)


def frames(scene: Scene, plan: Plan, step: float) -> Frames:
    """Every animation frame.

    No body point moves more than ``step`` between frames (pushes and transits alike, duration
    bounds point travel), unless that would take more than ``MAX_FRAMES``: then frames are
    shared out in proportion to the segments' durations. Every segment gets at least its first
    frame, and a last frame shows the end of the last, so there are at most
    ``max(MAX_FRAMES, segments + 1)`` frames.
    """
    segments = plan.segments
    body = pusher_frame_body(scene.pusher.width, scene.pusher.depth)
    durations = np.array([s.duration for s in segments])
    counts = np.maximum(np.ceil(durations / step), 1).astype(int)
    if counts.sum() > MAX_FRAMES - 1:
        budget = max(MAX_FRAMES - 1 - len(segments), 0)
        counts = 1 + (budget * durations / durations.sum()).astype(int)
    index, times, samples = [], [], []
    clock = 0.0
    for k, (s, n) in enumerate(zip(segments, counts)):
        t = np.arange(n) * (s.duration / n)
        index.append(np.full(n, k))
        times.append(clock + t)
        samples.append(sample(scene.slider, body, s, t))
        clock += s.duration
    index.append([len(segments) - 1])
    times.append([clock])
    samples.append(sample(scene.slider, body, segments[-1], np.array([segments[-1].duration])))
    return Frames(np.concatenate(index), np.concatenate(times), *map(np.concatenate, zip(*samples)))


def history(points: np.ndarray, index: np.ndarray) -> list[np.ndarray]:
    """For each frame, the path of ``points`` (one per frame) so far, thinned to at most about
    ``PATH_POINTS`` points: every few frames plus the first frame of each segment (where the path
    may turn sharply) and the current one."""
    keep = np.zeros(len(points), dtype=bool)
    keep[:: -(-len(points) // PATH_POINTS)] = True
    keep[np.flatnonzero(np.diff(index, prepend=-1))] = True
    kept = np.flatnonzero(keep)
    return [points[np.r_[kept[: np.searchsorted(kept, i)], i]] for i in range(len(points))]
