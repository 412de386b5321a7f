"""Procedure STABLE: guaranteed-stable pushes for a line contact (Lynch & Mason 1996, §3.3.1).

A flat pusher in contact with a slider edge pushes it *stably* when the slider stays stuck to the
pusher whatever the support pressure distribution (inside the part, centre at the CF). STABLE
returns a conservative set of such pushes: two convex regions of rotation centres, one per
rotation sense, joined by an interval of translations. As twists, the set is a convex polyhedral
cone, so every condition below is a linear inequality on the twist (docs/mechanics.md, "Procedure STABLE").

Notation (docs/mechanics.md, "Conventions"): ``n`` is the edge's inward normal (push direction), ``t = (n_y,
-n_x)``, ``e_L``/``e_R`` the contact end points with ``t.e_L < t.e_R``, ``d_L``/``d_R`` the friction
cone edges tilted left/right by ``alpha = atan(mu)``, ``r`` the CF's distance to the farthest
point of the part and ``p_L``, ``p_R`` its distances to the end points.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
import shapely
from numpy.typing import ArrayLike

from .push_plane import PushPlane
from .slider import Slider
from .twist import cor_to_twist

__all__ = ["StableRegion", "procedure_stable", "DEFAULT_TIP_FACTOR"]

#: Peshkin & Sanderson's tip line lies slightly beyond r^2/p; docs/mechanics.md, "Checks of STABLE" found violations
#: 0.5 % inside it, so the line is moved out by 2 %.
DEFAULT_TIP_FACTOR = 1.02


def _halfplane_row(d: np.ndarray, offset: float, sense: int) -> np.ndarray:
    """Row ``a`` with ``a . V >= 0`` iff the COR ``c`` of twist ``V`` (of ``sense``) has ``c.d >= offset``.

    With ``c = (-vy, vx)/omega``, multiplying by ``sense * omega > 0`` keeps the inequality.
    """
    return sense * np.array([d[1], -d[0], -offset])


@dataclass(frozen=True)
class StableRegion:
    """The stable pushes of one edge: a convex cone of slider-frame twists.

    Build it with :func:`procedure_stable`. A twist ``V`` of sense ``s`` (``s = sign(omega)``) is in
    the region iff ``s * omega >= 0`` and ``rows[s] @ V >= 0``; translations belong to both.
    """

    edge: int
    contact: np.ndarray  # [e_L, e_R], slider frame
    normal: np.ndarray  # inward normal n
    mu: float
    cf: np.ndarray
    translation_range: tuple[float, float] | None  # angles from n, positive tilted towards -t
    rows: dict[int, np.ndarray] = field(repr=False)  # sense -> (4, 3) inequality rows
    scale: float = field(repr=False)  # the part's radius: converts omega to a speed

    @property
    def is_empty(self) -> bool:
        """True when no push of this edge is guaranteed stable (Proposition 6)."""
        return self.translation_range is None

    def contains(self, twist: ArrayLike, tol: float = 1e-9) -> np.ndarray:
        """Whether each slider-frame twist (shape ``(..., 3)``, any positive scale) is stable.

        ``tol`` is a relative tolerance on the inequalities (in units of the twist's speed).
        """
        v = np.asarray(twist, dtype=float)
        if self.is_empty:
            return np.zeros(v.shape[:-1], dtype=bool)
        size = np.linalg.norm(v[..., :2], axis=-1) + np.abs(v[..., 2]) * self.scale
        eps = tol * size
        # Each row . V is a speed (unit direction . velocity - offset * omega): compare with eps.
        inside = {
            s: (s * v[..., 2] >= -eps / self.scale) & np.all(v @ self.rows[s].T >= -eps[..., None], axis=-1)
            for s in (1, -1)
        }
        return (inside[1] | inside[-1]) & (size > 0)

    def cor_vertices(self, sense: int) -> np.ndarray:
        """Finite corners (shape ``(k, 2)``) of the COR region of ``sense`` (+1 CCW, -1 CW)."""
        if self.is_empty:
            return np.zeros((0, 2))
        rows = self.rows[sense] * sense  # a . (c, 1)-form: [d_y, -d_x, -off] . (c_y, -c_x, 1)
        corners = []
        for i in range(4):
            for j in range(i + 1, 4):
                # Row a means d.c >= off with d = (-a_1, a_0), off = -a_2.
                m = np.array([[-rows[i, 1], rows[i, 0]], [-rows[j, 1], rows[j, 0]]])
                if abs(np.linalg.det(m)) < 1e-12:
                    continue
                c = np.linalg.solve(m, [-rows[i, 2], -rows[j, 2]])
                same = any(np.linalg.norm(c - k) <= 1e-9 * (self.scale + np.linalg.norm(k)) for k in corners)
                if not same and self.contains(cor_to_twist(c, sense), tol=1e-7):
                    corners.append(c)
        return np.array(corners).reshape(-1, 2)

    def extremal_twists(self) -> np.ndarray:
        """Corners of the region (shape ``(k, 3)``): the controls of the 1996 planner.

        Rotations are scaled to ``|omega| = 1`` and translations to unit speed; rows are ordered
        CCW corners, the two end translations, CW corners (docs/mechanics.md, "Translations and extremal twists").
        """
        if self.is_empty:
            return np.zeros((0, 3))
        n = self.normal
        t = np.array([n[1], -n[0]])
        lo, hi = self.translation_range
        trans = [np.r_[np.cos(a) * n - np.sin(a) * t, 0.0] for a in sorted({lo, hi})]
        parts = [cor_to_twist(self.cor_vertices(1), 1), np.array(trans), cor_to_twist(self.cor_vertices(-1), -1)]
        return np.vstack([p.reshape(-1, 3) for p in parts])

    @cached_property
    def plane(self) -> PushPlane:
        """The chart of this edge's pushes (:mod:`.push_plane`)."""
        return PushPlane(self.normal, self.contact, self.scale)

    def section(self) -> tuple[shapely.Geometry, np.ndarray]:
        """The region in the push plane and a centre it is star-shaped about.

        STABLE's region is convex: the hull of the extremal twists, with its centroid.

        >>> block = Slider([[-1, 0], [1, 0], [1, 1], [-1, 1]])
        >>> polygon, centre = procedure_stable(block, 0, 0.5, tip_factor=1.0).section()
        >>> np.round(polygon.bounds, 6).tolist(), (np.round(centre, 12) + 0.0).tolist()
        ([-0.5, -0.559017, 0.5, 0.559017], [0.0, 0.0])
        """
        hull = shapely.MultiPoint(self.plane.points(self.extremal_twists())).convex_hull
        return hull, np.asarray(hull.centroid.coords[0])

    def cor_polygons(self, window: ArrayLike | None = None) -> dict[int, shapely.Polygon]:
        """COR regions per sense clipped to ``window = (xmin, ymin, xmax, ymax)`` (for drawing).

        The default window is a square of half-side ``4 r`` about the CF.
        """
        if window is None:
            window = (*(self.cf - 4 * self.scale), *(self.cf + 4 * self.scale))
        box = shapely.box(*window)
        if self.is_empty:
            return {1: shapely.Polygon(), -1: shapely.Polygon()}
        big = 10.0 * float(np.hypot(window[2] - window[0], window[3] - window[1]))
        centre = np.asarray(box.centroid.coords[0])
        out = {}
        for sense in (1, -1):
            region = box
            for a in self.rows[sense] * sense:
                d, off = np.array([-a[1], a[0]]), -a[2]
                d, off = d / np.linalg.norm(d), off / np.linalg.norm(d)
                along = np.array([-d[1], d[0]])
                base = d * off + along * (along @ centre)  # on the line, abreast of the window
                span = along * big
                region = region.intersection(
                    shapely.Polygon([base - span, base + span, base + span + d * big, base - span + d * big])
                )
            out[sense] = region
        return out


def procedure_stable(
    slider: Slider,
    edge: int,
    mu: float,
    width: float | None = None,
    tip_factor: float = DEFAULT_TIP_FACTOR,
) -> StableRegion:
    """Procedure STABLE for a flat pusher of ``width`` centred on ``edge`` with friction ``mu``.

    :func:`mechanics.stable_region` chooses between this and the exact region.

    Parameters
    ----------
    slider : Slider
    edge : int
        A pushable edge (on the convex hull).
    mu : float
        Pusher-slider friction coefficient, > 0.
    width : float, optional
        Length of the pusher face; the contact is the central ``min(width, edge length)`` of the
        edge. Default: the whole edge.
    tip_factor : float
        Moves the tip line of step 2 from ``r^2/p`` to ``tip_factor * r^2/p`` (>= 1 is safer).

    Examples
    --------
    Fixture A of docs/mechanics.md, "Fixtures": a 2 x 1 block pushed on its whole bottom face, mu = 0.5.
    The CCW region is the wedge with apex (-2, 0.5), the CW one its mirror image, and the
    translations are those within atan(0.5) = 26.565 deg of the normal:

    >>> block = Slider([[-1, 0], [1, 0], [1, 1], [-1, 1]])
    >>> region = procedure_stable(block, 0, 0.5, tip_factor=1.0)
    >>> region.cor_vertices(1).round(12).tolist(), region.cor_vertices(-1).round(12).tolist()
    ([[-2.0, 0.5]], [[2.0, 0.5]])
    >>> np.degrees(region.translation_range).round(3).tolist()
    [-26.565, 26.565]
    >>> region.contains([[0, 1, 0], [0, 3, 1], [0, 1, 1], [1, 0, 0]]).tolist()
    [True, True, False, False]

    A short pusher whose friction cone cannot reach a force through the CF pushes nothing
    stably (Proposition 6):

    >>> off_centre = Slider([[-1, 0], [1, 0], [1, 1], [-1, 1]], cf=[0.9, 0.5])
    >>> procedure_stable(off_centre, 0, 0.5, width=0.5).is_empty
    True
    """
    if not mu > 0:
        raise ValueError(f"mu must be > 0, got {mu}")
    if not slider.is_pushable(edge):
        raise ValueError(f"edge {edge} is not on the convex hull, so a flat pusher cannot push it")
    n = slider.inward_normal(edge)
    t = np.array([n[1], -n[0]])
    e_l, e_r = sorted(slider.contact(edge, width), key=lambda e: float(e @ t))
    c0 = slider.cf
    alpha = np.arctan(mu)
    d_l = np.cos(alpha) * n - np.sin(alpha) * t
    d_r = np.cos(alpha) * n + np.sin(alpha) * t
    k = tip_factor * slider.radius**2
    p_l, p_r = np.linalg.norm(e_l - c0), np.linalg.norm(e_r - c0)
    u_l, u_r = (e_l - c0) / p_l, (e_r - c0) / p_r

    reach_l, reach_r, back_l, back_r = slider.extent([d_l, d_r, -d_l, -d_r])  # how far the part reaches along each

    def sense_rows(sense: int, d_near, reach_near, d_far, back_far, u_near, p_near, u_far, p_far) -> np.ndarray:
        # Steps 1 and 2 of STABLE, as read in docs/mechanics.md, "Procedure STABLE" (S1-S4; S1'-S4' mirrored).
        return np.array([
            _halfplane_row(d_near, reach_near, sense),
            _halfplane_row(-d_far, back_far, sense),
            _halfplane_row(u_near, c0 @ u_near + p_near / 2, sense),
            _halfplane_row(-u_far, -(c0 @ u_far) + k / p_far, sense),
        ])

    rows = {1: sense_rows(1, d_l, reach_l, d_r, back_r, u_l, p_l, u_r, p_r),
            -1: sense_rows(-1, d_r, reach_r, d_l, back_l, u_r, p_r, u_l, p_l)}
    # Translations: the line through the CF along the push meets the contact, within the cone.
    h = float(n @ (c0 - e_l))
    lo = max(-mu, float(t @ (e_l - c0)) / h)
    hi = min(mu, float(t @ (e_r - c0)) / h)
    translation_range = (float(np.arctan(lo)), float(np.arctan(hi))) if lo <= hi else None
    return StableRegion(
        edge=int(edge), contact=np.array([e_l, e_r]), normal=n, mu=float(mu), cf=c0.copy(),
        translation_range=translation_range, rows=rows, scale=slider.radius,
    )
