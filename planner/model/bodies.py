"""The moving body during a push: the slider and the pusher stuck to it, in the slider frame.

The pusher face is centred on the pushed edge's midpoint; its body is the ``width x depth``
rectangle behind the face, outside the part (the edge lies on the convex hull, so it cannot
overlap the part).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import shapely
from numpy.typing import ArrayLike

from mechanics import Slider, point_velocity, transform_points

__all__ = ["body_outline", "cf_poses", "edge_frame", "place", "pusher_frame_body", "pusher_polygon", "convex_pieces", "slider_at",
           "top_speed"]


def place(points: np.ndarray, poses: np.ndarray) -> np.ndarray:
    """Slider-frame ``points`` (shape ``(m, 2)``) placed at each of ``poses`` (shape ``(f, 3)``): ``(f, m, 2)``.

    >>> place(np.array([[1.0, 0.0]]), np.array([[0.0, 1.0, np.pi / 2]])).round(12).tolist()
    [[[0.0, 2.0]]]
    """
    return transform_points(np.asarray(points, dtype=float)[None], np.asarray(poses, dtype=float)[:, None])


def cf_poses(cf: ArrayLike, xy: ArrayLike, theta: ArrayLike) -> np.ndarray:
    """Slider poses ``(n, 3)`` that put the slider-frame point ``cf`` at world points ``xy``
    ``(n, 2)`` with headings ``theta`` ``(n,)``: the inverse of :func:`place` for one point.

    >>> poses = cf_poses([0.1, 0.0], [[1.0, 1.0]], [np.pi / 2])
    >>> poses.round(12).tolist(), place(np.array([[0.1, 0.0]]), poses)[:, 0].round(12).tolist()
    ([[1.0, 0.9, 1.570796326795]], [[1.0, 1.0]])
    """
    xy, theta = np.asarray(xy, dtype=float).reshape(-1, 2), np.asarray(theta, dtype=float).reshape(-1)
    turned = transform_points(cf, np.column_stack([np.zeros((len(theta), 2)), theta]))  # cf turned by each theta
    return np.column_stack([xy - turned, theta])


def slider_at(polygon: shapely.Polygon, pose: ArrayLike) -> shapely.Polygon:
    """``polygon`` (slider frame) placed at ``pose`` in the world."""
    return shapely.Polygon(transform_points(np.asarray(polygon.exterior.coords), pose))


def pusher_polygon(slider: Slider, edge: int, width: float, depth: float) -> shapely.Polygon:
    """The pusher's ``width x depth`` body behind edge ``edge``, in the slider frame.

    >>> block = Slider([[-1, 0], [1, 0], [1, 1], [-1, 1]])
    >>> sorted(map(tuple, np.asarray(pusher_polygon(block, 0, 0.5, 0.1).exterior.coords)[:4].round(12).tolist()))
    [(-0.25, -0.1), (-0.25, 0.0), (0.25, -0.1), (0.25, 0.0)]
    """
    a, b = slider.edge(edge)
    mid, along = (a + b) / 2, (b - a) / np.linalg.norm(b - a)
    back = -slider.inward_normal(edge) * depth
    half = along * width / 2
    return shapely.Polygon([mid - half, mid + half, mid + half + back, mid - half + back])


def edge_frame(slider: Slider, edge: int) -> np.ndarray:
    """The pusher frame's pose in the slider frame while it pushes ``edge``: its face centred on
    the edge's midpoint and flush with it, its x axis along the edge's inward normal.

    >>> edge_frame(Slider([[-1, 0], [1, 0], [1, 1], [-1, 1]]), 0).round(12).tolist()
    [0.0, 0.0, 1.570796326795]
    """
    a, b = slider.edge(edge)
    inward = slider.inward_normal(edge)
    return np.array([*((a + b) / 2), math.atan2(inward[1], inward[0])])


def pusher_frame_body(width: float, depth: float) -> np.ndarray:
    """The pusher's rectangle in its own frame: origin at the middle of the pushing face, x along
    the push direction, so the body is ``x in [-depth, 0]``, ``y in [-width/2, width/2]`` (CCW).

    >>> pusher_frame_body(0.06, 0.02).tolist()
    [[-0.02, -0.03], [0.0, -0.03], [0.0, 0.03], [-0.02, 0.03]]
    """
    w = width / 2
    return np.array([[-depth, -w], [0.0, -w], [0.0, w], [-depth, w]])


def convex_pieces(polygon: shapely.Polygon) -> list[np.ndarray]:
    """Counter-clockwise convex pieces covering ``polygon``: itself if convex, else triangles.

    >>> [len(p) for p in convex_pieces(shapely.box(0, 0, 1, 1))]
    [4]
    >>> len(convex_pieces(shapely.Polygon([[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]])))
    4
    """
    if polygon.convex_hull.area - polygon.area <= 1e-12 * polygon.area:
        pieces = [polygon]
    else:
        pieces = list(shapely.constrained_delaunay_triangles(polygon).geoms)
    return [np.asarray(shapely.orient_polygons(p).exterior.coords)[:-1] for p in pieces]


def body_outline(slider: Slider, edge: int, width: float, depth: float) -> tuple[np.ndarray, np.ndarray]:
    """The points of the slider and of the pusher on ``edge`` (slider frame) where any convex
    function of position, such as a point's speed or its distance to a wall, peaks: the part's
    hull vertices (one array, :attr:`mechanics.Slider.hull`, shared by every edge: a part of a
    hundred thousand edges would otherwise hold as many copies) and the pusher's four corners.

    >>> block = Slider([[-1, 0], [1, 0], [0.5, 0.5], [1, 1], [-1, 1]])
    >>> part, pusher = body_outline(block, 0, 0.5, 0.1)
    >>> len(part), part is body_outline(block, 4, 0.5, 0.1)[0], len(pusher)
    (4, True, 4)
    """
    return slider.hull, np.asarray(pusher_polygon(slider, edge, width, depth).exterior.coords)[:-1]


def top_speed(outline: Sequence[np.ndarray], twist: ArrayLike) -> np.ndarray:
    """The largest speed of any point of a body under each of ``twist`` (shape ``(..., 3)``),
    ``outline`` being its :func:`body_outline`.

    >>> block = Slider([[-1, 0], [1, 0], [1, 1], [-1, 1]])
    >>> top_speed(body_outline(block, 0, 0.5, 0.1), [[0.0, 0.0, 1.0], [0.0, 2.0, 0.0]]).round(6).tolist()
    [1.414214, 2.0]
    """
    points = np.concatenate(outline)  # for each call: holding it for every edge is what the pair saves
    return np.linalg.norm(point_velocity(np.asarray(twist, dtype=float)[..., None, :], points), axis=-1).max(axis=-1)
