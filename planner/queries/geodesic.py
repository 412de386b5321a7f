"""The free-space geodesic of the centre of friction: a sound lower bound on any plan's path length.

Let ``rho`` be the distance from the centre of friction (CF) to the part's boundary. The disk of
radius ``rho`` about the CF lies inside the part (convex or not: the CF is strictly inside it), and
the part never overlaps an obstacle nor leaves the workspace, so at every instant of every plan
(pushes, switches, crabbing alike) the CF is at least ``rho`` from every obstacle and from the
workspace's walls: it stays in the free space ``F`` of the disk, the workspace shrunk by ``rho``
minus the obstacles grown by it (:func:`~planner.world.free_space.disk_free_space`). The CF's path is therefore at least as
long as the shortest path in ``F`` from the CF's start to where it ends.

A plan ends anywhere within the scene's tolerance of the goal: the pose's origin within
``tolerance.position`` and the heading within ``tolerance.angle``, so the CF ends within
``slack = tolerance.position + |cf| tolerance.angle`` of its goal position ``g`` (a rotation by
``a`` moves it ``2 |cf| sin(a / 2) <= |cf| a``). Any such path, followed by the straight segment
from its end to ``g`` (at most ``slack`` long, inside the disk ``D`` of radius ``slack`` about
``g``), is a path in ``F`` united with ``D``; so the CF travels at least the shortest path from
start to ``g`` in that union, less ``slack`` (:func:`geodesic_bound`). The shortest path is found
on the visibility graph of the region's vertices (:func:`shortest_path_length`).

Worked example, to check by hand: a 1 x 1 m table with a wall 0.1 m thick rising 0.6 m from its
bottom edge (``x`` in ``[-0.05, 0.05]``, ``y`` up to 0.1), and a 0.1 m square part with its CF at
its centre (``rho = 0.05``, ``|cf| = 0``, so ``slack`` is the position tolerance, 0.01 m), from CF
``(-0.15, 0.1)`` to CF ``(0.15, 0.1)``, on either side of the wall's top. The grown wall ends in
two quarter circles of radius 0.05 about ``(-0.05, 0.1)`` and ``(0.05, 0.1)``, joined by a flat top
at ``y = 0.15``; the wall runs off the table, so the path goes over it. The start is ``2 rho`` from
the first circle's centre, so its tangent to the circle is ``rho sqrt(3)`` long and touches it 60
degrees up from the start's side: 30 degrees of arc up to the flat top, 0.1 m across, and the
mirror image down. With :data:`~planner.world.free_space.QUAD_SEGS` = 6 the arcs are chords of 15 degrees, ``2 rho sin(pi /
24)`` each, and the tangent points are vertices, so the bound is ``2 rho sqrt(3) + 4 * 2 rho
sin(pi / 24) + 0.1 - 0.01``; the true geodesic has ``rho pi / 3`` of arcs instead of the chords:

>>> import math
>>> from planner.model.scene_file import parse_scene
>>> scene = parse_scene({
...     "slider": {"vertices": [[-0.05, -0.05], [0.05, -0.05], [0.05, 0.05], [-0.05, 0.05]]},
...     "pusher": {"width": 0.05, "depth": 0.01, "mu": 0.5},
...     "obstacles": [{"box": {"center": [0.0, -0.2], "size": [0.1, 0.6]}}],
...     "workspace": {"min": [-0.5, -0.5], "max": [0.5, 0.5]},
...     "start": [-0.15, 0.1, 0.0], "goal": [0.15, 0.1, 0.0]})
>>> by_hand = 0.1 * math.sqrt(3) + 0.4 * math.sin(math.pi / 24) + 0.1 - 0.01
>>> round(by_hand, 5), round(geodesic_bound(scene), 5)
(0.31542, 0.31542)
>>> round(0.1 * math.sqrt(3) + 0.05 * math.pi / 3 + 0.1 - 0.01, 5)  # true geodesic less slack: a little more
0.31556
"""

from __future__ import annotations

import numpy as np
import shapely
from numpy.typing import ArrayLike

from mechanics import transform_points
from ..model.scene import Scene
from ..world.free_space import ROUNDING_SHRINK, cover, disk_free_space

__all__ = ["geodesic_bound", "shortest_path_length"]

def shortest_path_length(region: shapely.Geometry, a: ArrayLike, b: ArrayLike) -> float:
    """Length of the shortest path from ``a`` to ``b`` inside the closed polygonal ``region``.

    A shortest path in a polygonal region is a polyline bending only at the region's vertices, so
    it is the shortest path from ``a`` to ``b`` in the graph of the vertices, ``a`` and ``b``
    joined wherever the straight segment between two lies in the region.

    Returns
    -------
    float
        ``inf`` if no path in the region joins them (in particular if ``a`` or ``b`` is outside
        it, unless they are the same point).

    >>> room = shapely.box(0, 0, 7, 5).difference(shapely.box(3, 0, 4, 4))  # a wall up from the floor
    >>> shortest_path_length(room, (0, 0), (7, 0))  # to its top-left corner (3, 4), across, and down
    11.0
    >>> shortest_path_length(shapely.box(0, 0, 7, 5).difference(shapely.box(3, 0, 4, 5)), (0, 0), (7, 0))
    inf
    """
    # Imported here: the plan command uses disk_free_space (reachability's certificates) and
    # should not pay for scipy's import.
    from scipy.sparse import csr_array
    from scipy.sparse.csgraph import dijkstra

    points = np.vstack([np.reshape(a, (1, 2)), np.reshape(b, (1, 2)), shapely.get_coordinates(region)])
    # One node per distinct point: a or b on a vertex, and each ring's closing repeat, merge.
    nodes, index = np.unique(points, axis=0, return_inverse=True)
    i, j = np.triu_indices(len(nodes), k=1)
    shapely.prepare(region)
    seen = shapely.covers(region, shapely.linestrings(np.stack([nodes[i], nodes[j]], axis=1)))
    lengths = np.linalg.norm(nodes[i[seen]] - nodes[j[seen]], axis=1)
    graph = csr_array((lengths, (i[seen], j[seen])), shape=(len(nodes), len(nodes)))
    return float(dijkstra(graph, directed=False, indices=index[0])[index[1]])


def geodesic_bound(scene: Scene) -> float:
    """A lower bound on the length of the centre of friction's path of any plan for ``scene``.

    The shortest path of the CF in the free space of its inscribed disk, less the goal
    tolerance's slack (module docstring). On an empty table it is the straight line less the
    slack; it is ``inf`` when the goal is walled off from the start.
    """
    cf = scene.slider.cf
    start, goal = (transform_points([cf], pose)[0] for pose in (scene.start, scene.goal))
    slack = scene.tolerance_slack(float(np.linalg.norm(cf)))
    straight = float(np.linalg.norm(goal - start)) - slack
    if straight <= 0.0:  # the start is within the tolerance's reach of the goal
        return 0.0
    rho = scene.slider.cf_depth * (1.0 - ROUNDING_SHRINK)
    # The disk of the slack about the goal, as a polygon covering it, so that every end of the CF's
    # path lies in it.
    free = disk_free_space(scene, rho).union(cover(shapely.Point(goal), slack))
    if not free.covers(shapely.Point(start)):
        # Only rounding can put the true start outside; the straight line is sound for any path.
        return straight
    return shortest_path_length(free, start, goal) - slack
