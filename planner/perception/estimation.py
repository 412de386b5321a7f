"""Each known part's pose from a depth image, or a lost track: never a wrong pose given as good.

For each part (its outline, in its own frame, and a *prior*: the pose it was last estimated at,
or where the plan has it) the edge points of the image (:mod:`.silhouette`) nearest its outline
at the prior (within :data:`GATE` of it, and nearer it than any other part's) are its points. Its
outline is registered to them (:mod:`.registration`) from the prior and from the prior moved onto
the points' centre, and the better fit kept. Then the points are shared again, by the fitted
outlines, and each part fitted again: a
prior a few millimetres off can hand a neighbour's edge to a part, a fit cannot. A part whose outline looks the same turned (a square:
four poses alike, :attr:`mechanics.Slider.turns` about its centroid) is then given the look-alike
pose nearest the prior: continuity decides what the image cannot.

Only the pixels round the parts' priors are read: for each part, the image's rectangle round its
outline at the prior widened by :data:`GATE`, so every edge point the gate lets through is in it,
with the pixels its smoothed height depends on (:data:`PAD`); and a sparse lattice over the whole
image that fits the table plane (:mod:`.table_view`). :func:`sight` says which pixels these are:
a camera need cast no ray elsewhere, since what it would see there is never used.

The estimate is checked before it is given (:class:`Estimate`): the track is *lost* if the part
stands too little out of the depth noise where it is (half its height less than :data:`CONTRAST`
deviations of the smoothed heights: then enough pixels of the table pass for the part, and of
the part for the table, to shape a wrong outline), if too few points were found (the part is out
of view or hidden), if less than :data:`MIN_VISIBLE` of the
outline was seen, if the points lie off the outline (their median distance beyond a pixel's
footprint), if the pose is poorly fixed (its deviation beyond :data:`MAX_SIGMA`, as when only one
straight side is seen), or if the camera sees the table inside the outline at the pose found
(beyond :data:`TABLE_INSIDE` of its pixels): then the part is not where the fit put it.

A lost track is *hidden* (:attr:`Estimate.hidden`) when it is lost for want of sight alone: too
little of the outline seen (under :data:`MIN_VISIBLE`) where the points fit it, or too few points
where something taller than the parts (the pusher, the arm) stands over at least :data:`HIDDEN`
of the area where the part was. The part is then likely still there, under it; a part out of view,
or gone from where the table now shows, is not hidden. The closed loop goes on blind through a
hidden part's push (:mod:`planner.execution.tracker`, "Lost track").

The covariance has two terms. The noise's is the Gauss-Newton one, the inverse of ``J^T J`` (``J``
the Jacobian of the inlying points' distances across their edges, the points at corners left out:
:class:`.registration.Fit`) times their mean square distance, times
:data:`CORRELATED`: the smoothing of the heights makes neighbouring edge points share their
noise, so they are worth fewer independent measurements than their count; the pose is poorly
fixed if this term's deviations pass :data:`MAX_SIGMA`. The other is what is left when the noise
is gone, :data:`SYSTEMATIC` of a pixel's footprint in position and that over the part's radius
in heading: the silhouette's model (the smoothed corners, the walls cut at half height) is good
to about that (``docs/camera.md``, "Accuracy").
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
import shapely
from numpy.typing import ArrayLike

from mechanics import Slider, transform_points, wrap_angle

from ..model.bodies import slider_at
from ..model.camera import Camera
from .registration import Fit, distances, register
from .silhouette import GUARD, Silhouette, silhouette
from .table_view import SMOOTHING, plane_pixels, smoothed_noise, table_view

__all__ = ["AS_WELL", "CONTRAST", "CORRELATED", "GATE", "HIDDEN", "MAX_SIGMA", "MIN_POINTS", "MIN_VISIBLE", "PAD", "SYSTEMATIC",
           "TABLE_INSIDE", "Estimate", "estimate_poses", "sight"]

#: Farthest an edge point may be from a part's outline at its prior and still be the part's, m:
#: how far a part may move between two images (a knock of 2.5 cm and 12 degrees moves a 5 cm
#: part's far corner by about 3 cm).
GATE = 0.04
#: Pixels round each part's rectangle of :func:`sight`: the smoothing's reach (three deviations), the
#: guard round tall things (:data:`.silhouette.GUARD`), and the table pixel next to an edge's part pixel.
PAD = 3 * round(SMOOTHING) + GUARD + 1
#: Least ratio of half a part's height to the deviation of the smoothed heights there.
CONTRAST = 3.0
#: Fewest edge points of a part seen.
MIN_POINTS = 20
#: Least fraction of the outline seen (within two pixels' footprint of an inlying edge point).
MIN_VISIBLE = 0.3
#: Least share of where a part was, by area, that something taller must stand over for a part not
#: seen at all to be hidden rather than gone (:class:`Estimate`).
HIDDEN = 0.5
#: Largest deviation of a good estimate's noise: m in position, radians in heading.
MAX_SIGMA = (0.002, np.radians(2.0))
#: Largest fraction of the pixels inside a part's outline (shrunk by two pixels) that may be table.
TABLE_INSIDE = 0.02
#: Neighbouring edge points share their noise (the smoothing): the covariance is inflated by this.
CORRELATED = 4.0
#: The deviation left without noise, in pixels' footprints (module docstring).
SYSTEMATIC = 0.25
#: Two registrations fit the points as well when one's cost is within this factor of the other's
#: (:func:`_fit`): far below what a fit caught a centimetre off costs (points a centimetre off, eight
#: pixels' footprints, cost over a hundred times those on the outline).
AS_WELL = 1.5


@dataclass(frozen=True)
class Estimate:
    """A part's pose as the camera sees it: ``pose`` (world ``(x, y, theta)``) and its 3 x 3
    ``covariance`` (m, m, rad), the median distance of its points to the outline there
    (``residual``, m), the fraction of the outline seen (``visible``) and the number of edge points
    (``points``); ``lost`` says why the track is lost (then ``pose`` and ``covariance`` are None),
    empty if it is not, and ``hidden`` whether it is lost for want of sight alone: something taller
    stands between the camera and where the part was, and what is seen of it does not say it left
    (module docstring)."""

    pose: np.ndarray | None
    covariance: np.ndarray | None
    residual: float
    visible: float
    points: int
    lost: str = ""
    hidden: bool = False

    @property
    def tracked(self) -> bool:
        return not self.lost


def estimate_poses(depth: np.ndarray, camera: Camera, outlines: Mapping[str, ArrayLike], top: float,
                   priors: Mapping[str, ArrayLike]) -> dict[str, Estimate]:
    """Each part's :class:`Estimate` from ``depth`` (z-depths, m; 0: no return) taken by ``camera``
    (its calibration): ``outlines`` are the parts' polygons (their own frames), ``top`` the height
    of their tops over the table (m), ``priors`` their last known poses (module docstring)."""
    seen = silhouette(table_view(depth, camera, _window(_rectangles(camera, outlines, top, priors))), top)
    shapes = {name: np.asarray(outline, dtype=float) for name, outline in outlines.items()}
    priors = {name: np.asarray(priors[name], dtype=float) for name in shapes}
    pixels = {name: _footprint(camera, priors[name], top) for name in shapes}
    first = {name: _fit(points, shapes[name], priors[name], pixels[name])
             for name, points in _shares(seen.points, shapes, priors, GATE).items()}
    # The points again, each to the part whose fitted outline it is nearest: the priors' outlines
    # may have handed a neighbour's edge to a part.
    found = {name: priors[name] if fit is None else fit.pose for name, fit in first.items()}
    estimates = {}
    for name, points in _shares(seen.points, shapes, found, GATE).items():
        # The deviation of the smoothed heights there: the depth is the pixel's footprint times the focal length.
        noise = smoothed_noise(camera.noise * (pixels[name] * camera.focal) ** 2)
        if top / 2 < CONTRAST * noise:
            estimates[name] = Estimate(None, None, np.nan, 0.0, len(points), f"too thin for the camera here: "
                                       f"{top * 1e3:.1f} mm high in depth noise of {noise * 1e3:.1f} mm (smoothed)")
        else:
            refit = None if first[name] is None else _fit(points, shapes[name], found[name], pixels[name])
            estimates[name] = _judge(seen, shapes[name], priors[name], points, pixels[name], refit)
    return estimates


def sight(camera: Camera, outlines: Mapping[str, ArrayLike], top: float, priors: Mapping[str, ArrayLike]) -> np.ndarray:
    """The pixels :func:`estimate_poses` reads of ``camera``'s images, a mask of the image, for parts of
    ``outlines`` at ``priors`` whose tops are ``top`` over the table (module docstring): the
    rectangles round the parts (:func:`_rectangles`) and the lattice that fits the table plane
    (:func:`.table_view.plane_pixels`)."""
    width, height = camera.resolution
    mask = plane_pixels((height, width))
    for rows, columns in _rectangles(camera, outlines, top, priors):
        mask[rows, columns] = True
    return mask


def _rectangles(camera: Camera, outlines: Mapping[str, ArrayLike], top: float,
                priors: Mapping[str, ArrayLike]) -> list[tuple[slice, slice]]:
    """For each part (``outlines`` at ``priors``, their tops ``top`` over the table), the rectangle
    of the image (rows, columns) round its outline widened by :data:`GATE`, on the table and at
    ``top``, and :data:`PAD` pixels more (empty where it is out of view); the whole image if some of
    that is behind the camera."""
    width, height = camera.resolution
    found = []
    for name, outline in outlines.items():
        ring = np.asarray(slider_at(shapely.Polygon(outline), np.asarray(priors[name], dtype=float)).buffer(GATE)
                          .exterior.coords)
        points = np.vstack([np.column_stack([ring, np.full(len(ring), z)]) for z in (0.0, top)])
        if ((points - camera.position) @ camera.T_world_camera[:3, 2] <= 0).any():
            return [(slice(0, height), slice(0, width))]
        pixels = camera.pixels(points)
        (u0, v0), (u1, v1) = np.floor(pixels.min(axis=0)) - PAD, np.ceil(pixels.max(axis=0)) + PAD + 1
        found.append((slice(int(np.clip(v0, 0, height)), int(np.clip(v1, 0, height))),
                      slice(int(np.clip(u0, 0, width)), int(np.clip(u1, 0, width)))))
    return found


def _window(rectangles: list[tuple[slice, slice]]) -> tuple[slice, slice]:
    """The smallest rectangle of the image holding all of ``rectangles`` (those not empty)."""
    full = [(r, c) for r, c in rectangles if r.stop > r.start and c.stop > c.start]
    if not full:
        return slice(0, 0), slice(0, 0)
    return (slice(min(r.start for r, _ in full), max(r.stop for r, _ in full)),
            slice(min(c.start for _, c in full), max(c.stop for _, c in full)))


def _shares(points: np.ndarray, shapes: dict[str, np.ndarray], poses: dict[str, np.ndarray],
            reach: float) -> dict[str, np.ndarray]:
    """Each part's share of ``points``: those nearer its outline at its pose than any other's, and
    within ``reach`` of it."""
    names = list(shapes)
    if not len(points):
        return {name: points for name in names}
    near = np.array([distances(points, shapes[n], poses[n]) for n in names])
    owner = near.argmin(axis=0)
    return {name: points[(owner == k) & (near[k] <= reach)] for k, name in enumerate(names)}


def _footprint(camera: Camera, pose: np.ndarray, top: float) -> float:
    """The size (m) of a pixel's footprint at the part's top where ``pose`` puts it."""
    depth = (np.array([*pose[:2], top]) - camera.position) @ camera.T_world_camera[:3, 2]
    return float(depth / camera.focal)


def _fit(points: np.ndarray, outline: np.ndarray, start: np.ndarray, pixel: float) -> Fit | None:
    """The better registration of ``outline`` to ``points`` from ``start`` and from ``start`` moved
    onto the points' centre; where both fit as well (the cost within :data:`AS_WELL` times the
    other's), the one from ``start`` (None if there are fewer than :data:`MIN_POINTS`).

    Two fits as good are two poses the points cannot tell apart: a corner seen with parts of its
    two edges, the rest hidden, fits the outline's other corners too, turned a quarter. Continuity
    decides, as for look-alikes (module docstring)."""
    if len(points) < MIN_POINTS:
        return None
    ring = np.vstack([outline, outline[:1]])
    centre = shapely.LinearRing(ring).centroid  # where the points' centre is when all of it is seen
    moved = np.array([*(points.mean(axis=0) - transform_points([centre.x, centre.y], start) + start[:2]), start[2]])
    near, other = (register(points, outline, s, pixel) for s in (start, moved))
    return near if near.cost(pixel) <= AS_WELL * other.cost(pixel) else other


def _judge(seen: Silhouette, outline: np.ndarray, prior: np.ndarray, points: np.ndarray, pixel: float,
           fit: Fit | None) -> Estimate:
    """The estimate of ``fit`` of ``points`` (a part of ``outline`` last at ``prior``), or a lost
    track if it fails a check (module docstring); ``pixel`` is a pixel's footprint there (m)."""
    if fit is None or len(points) < MIN_POINTS:
        where = slider_at(shapely.Polygon(outline), prior)
        covered = seen.occluded_inside(where) / max(where.area / pixel ** 2, 1.0)
        if covered >= HIDDEN:
            return Estimate(None, None, np.nan, 0.0, len(points),
                            f"hidden: something taller stands over {min(covered, 1.0):.0%} of where it was", hidden=True)
        return Estimate(None, None, np.nan, 0.0, len(points), "not seen: the part is out of view or hidden")
    fit = _nearest_alike(fit, outline, prior)
    inlying = fit.distance <= 2 * pixel
    residual = float(np.median(fit.distance))
    visible = _visible(outline, fit.pose, points[inlying], 2 * pixel)
    noise = _covariance(fit, inlying)
    sigma = np.sqrt(np.diag(noise)) if noise is not None else np.full(3, np.inf)
    inner = slider_at(shapely.Polygon(outline), fit.pose).buffer(-2 * pixel)
    table = seen.table_inside(inner) / max(inner.area / pixel ** 2, 1.0) if not inner.is_empty else 0.0
    why = ("too occluded: {:.0%} of the outline seen".format(visible) if visible < MIN_VISIBLE else
           f"poor fit: the points lie {residual * 1e3:.1f} mm off the outline" if residual > pixel else
           "ambiguous: the points do not fix the pose" if max(sigma[:2]) > MAX_SIGMA[0] or sigma[2] > MAX_SIGMA[1] else
           f"the table is seen where the part would be ({table:.0%} of it)" if table > TABLE_INSIDE else "")
    if why:
        return Estimate(None, None, residual, visible, len(points), why, hidden=visible < MIN_VISIBLE)
    floor = SYSTEMATIC * pixel
    covariance = noise + np.diag([floor ** 2, floor ** 2, (floor / Slider(outline).radius) ** 2])
    return Estimate(fit.pose, covariance, residual, visible, len(points))


def _nearest_alike(fit: Fit, outline: np.ndarray, prior: np.ndarray) -> Fit:
    """``fit`` with its pose replaced by the look-alike pose (the outline turned onto itself about
    its centroid) nearest ``prior``; distances and Jacobian are the same at every look-alike."""
    part = Slider(outline)
    radius = part.radius
    alike = [fit.pose] + [_turned(fit.pose, part.cf, part.turn_angle(r)) for r in part.turns]

    def gap(pose: np.ndarray) -> float:
        return float(np.hypot(*(pose[:2] - prior[:2])) + radius * abs(wrap_angle(pose[2] - prior[2])))

    return Fit(min(alike, key=gap), fit.distance, fit.jacobian)


def _turned(pose: np.ndarray, centre: np.ndarray, angle: float) -> np.ndarray:
    """The pose at which the outline, turned by ``angle`` about its own ``centre``, lies where it lies at ``pose``."""
    c, s = np.cos(angle), np.sin(angle)
    # The frame turned by -angle about the centre: a point p of the outline then lands where R(angle) p lands now.
    shift = centre - np.array([[c, s], [-s, c]]) @ centre
    return np.array([*transform_points(shift, pose), float(wrap_angle(pose[2] - angle))])


def _visible(outline: np.ndarray, pose: np.ndarray, points: np.ndarray, reach: float) -> float:
    """The fraction of ``outline``'s length at ``pose`` within ``reach`` of some of ``points``."""
    ring = np.vstack([outline, outline[:1]])
    line = shapely.LineString(transform_points(ring, pose))
    samples = np.array([line.interpolate(d).coords[0] for d in np.arange(0.0, line.length, reach / 2)])
    if not len(points):
        return 0.0
    gap = np.linalg.norm(samples[:, None, :] - points[None, :, :], axis=-1).min(axis=1)
    return float(np.mean(gap <= reach))


def _covariance(fit: Fit, inlying: np.ndarray) -> np.ndarray | None:
    """The pose's covariance from the inlying points (module docstring); None if they do not fix it."""
    J, d = fit.jacobian[inlying], fit.distance[inlying]
    if len(d) <= 3:
        return None
    normal = J.T @ J
    if np.linalg.cond(normal) > 1e12:
        return None
    return CORRELATED * float(d @ d) / (len(d) - 3) * np.linalg.inv(normal)
