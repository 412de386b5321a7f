"""Test-only oracles for the stable-pushing mechanics (docs/mechanics.md, "Procedure STABLE", "Exact LP oracle").

Nothing here imports ``mechanics``: the edge frame, the conditions S1-S4 / S1'-S4', the
translation test, the composite friction cone and the exact LP oracle are written out again from
the note, so a test comparing them with ``mechanics.stable`` compares two independent derivations.

Conventions (docs/mechanics.md, "Conventions"): twist ``(vx, vy, omega)``; the velocity of a point ``x`` is
``(vx - omega y, vy + omega x)``; the COR of a rotation is ``(-vy, vx) / omega``; ``n`` is the
inward normal of the pushed edge, ``t = (n_y, -n_x)``, ``t.e_L < t.e_R``.
"""

from __future__ import annotations

import numpy as np
import shapely
from scipy.optimize import linprog

# ----------------------------------------------------------------------------------------------
# Plane geometry


def cross2(a, b):
    """z-component of the cross product of 2-vectors (broadcasting)."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def shoelace(vertices) -> float:
    """Signed area: > 0 for counter-clockwise vertices."""
    v = np.asarray(vertices, float)
    return 0.5 * float(np.sum(cross2(v, np.roll(v, -1, axis=0))))


def rot(angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s], [s, c]])


def edge_frame(vertices, i: int, width=None) -> dict:
    """Inward normal, tangent and contact end points of edge ``i`` (vertex i -> vertex i+1).

    The contact is the central ``min(width, length)`` of the edge.
    """
    v = np.asarray(vertices, float)
    a, b = v[i], v[(i + 1) % len(v)]
    length = float(np.hypot(*(b - a)))
    d = (b - a) / length
    left = np.array([-d[1], d[0]])  # left of the edge direction: inside for a CCW polygon
    n = left if shoelace(v) > 0 else -left
    t = np.array([n[1], -n[0]])
    if width is not None and width < length:
        mid = (a + b) / 2
        a, b = mid - d * width / 2, mid + d * width / 2
    e_l, e_r = (a, b) if t @ a < t @ b else (b, a)
    return dict(n=n, t=t, eL=np.array(e_l, float), eR=np.array(e_r, float))


def twist_of_cor(c, sense) -> np.ndarray:
    """Rotation about ``c`` with ``sense`` (+1 CCW / -1 CW), |omega| = 1 (docs/mechanics.md, "Conventions")."""
    c = np.asarray(c, float)
    s = np.broadcast_to(np.asarray(sense, float), c.shape[:-1])
    return np.stack([s * c[..., 1], -s * c[..., 0], s], axis=-1)


def velocity_at(twist, x) -> np.ndarray:
    v, x = np.asarray(twist, float), np.asarray(x, float)
    return np.stack([v[..., 0] - v[..., 2] * x[..., 1], v[..., 1] + v[..., 2] * x[..., 0]], axis=-1)


def transform_twist(twist, s: float, A, b) -> np.ndarray:
    """Twist of the same motion after the similarity ``x' = s A x + b`` (A orthogonal).

    v'(x') = s A v(x) with x = A^T (x' - b) / s gives omega' = det(A) omega and
    v0' = s A v0 - omega' J b (J = rotation by +90 deg), since A J A^T = det(A) J.
    """
    v = np.asarray(twist, float)
    A = np.asarray(A, float)
    w2 = np.linalg.det(A) * v[..., 2]
    v0 = s * v[..., :2] @ A.T
    jb = np.array([-b[1], b[0]])
    return np.concatenate([v0 - w2[..., None] * jb, w2[..., None]], axis=-1)


def angle_between(a, b) -> np.ndarray:
    """Angle between the directions of a and b (last axis)."""
    a = np.asarray(a, float) / np.linalg.norm(a, axis=-1, keepdims=True)
    b = np.asarray(b, float) / np.linalg.norm(b, axis=-1, keepdims=True)
    return np.arccos(np.clip(np.sum(a * b, axis=-1), -1.0, 1.0))


# ----------------------------------------------------------------------------------------------
# Procedure STABLE, re-derived from docs/mechanics.md, "Procedure STABLE" (vectorised)


class Reference:
    """STABLE for one edge, from the vertices only (no ``Slider``)."""

    def __init__(self, vertices, cf, edge, mu, width=None, tip_factor=1.0):
        V = np.asarray(vertices, float)
        self.V, self.cf, self.mu, self.tip = V, np.asarray(cf, float), float(mu), float(tip_factor)
        f = edge_frame(V, edge, width)
        self.n, self.t, self.eL, self.eR = f["n"], f["t"], f["eL"], f["eR"]
        a = np.arctan(mu)
        self.alpha = a
        self.dL = np.cos(a) * self.n - np.sin(a) * self.t
        self.dR = np.cos(a) * self.n + np.sin(a) * self.t
        self.r = float(np.max(np.hypot(*(V - self.cf).T)))
        self.pL = float(np.hypot(*(self.eL - self.cf)))
        self.pR = float(np.hypot(*(self.eR - self.cf)))
        self.uL, self.uR = (self.eL - self.cf) / self.pL, (self.eR - self.cf) / self.pR
        self.hiL, self.loL = (V @ self.dL).max(), (V @ self.dL).min()
        self.hiR, self.loR = (V @ self.dR).max(), (V @ self.dR).min()
        self.h = float(self.n @ (self.cf - self.eL))

    # -- rotations
    def cor_margins(self, c, sense: int) -> np.ndarray:
        """Slack of the four conditions (length units, >= 0 means satisfied), shape (..., 4)."""
        c = np.asarray(c, float)
        d = c - self.cf
        k = self.tip * self.r**2
        if sense > 0:  # S1..S4
            m = [c @ self.dL - self.hiL, self.loR - c @ self.dR,
                 d @ self.uL - self.pL / 2, -k / self.pR - d @ self.uR]
        else:  # S1'..S4'
            m = [c @ self.dR - self.hiR, self.loL - c @ self.dL,
                 d @ self.uR - self.pR / 2, -k / self.pL - d @ self.uL]
        return np.stack(m, axis=-1)

    def cor_is_stable(self, c, sense: int) -> np.ndarray:
        return np.all(self.cor_margins(c, sense) >= 0, axis=-1)

    # -- translations
    def translation_margins(self, theta) -> np.ndarray:
        """Slack of |theta| <= alpha (radians) and of the line-through-CF test (length units)."""
        theta = np.asarray(theta, float)
        x = self.t @ self.cf + self.h * np.tan(np.clip(theta, -1.5, 1.5))
        return np.stack([self.alpha - np.abs(theta), x - self.t @ self.eL, self.t @ self.eR - x], axis=-1)

    def translation_is_stable(self, theta) -> np.ndarray:
        return np.all(self.translation_margins(theta) >= 0, axis=-1)

    def translation(self, theta) -> np.ndarray:
        """Unit translation twist cos(theta) n - sin(theta) t."""
        theta = np.asarray(theta, float)[..., None]
        return np.concatenate([np.cos(theta) * self.n - np.sin(theta) * self.t, 0 * theta], axis=-1)

    def theta_of(self, v) -> np.ndarray:
        v = np.asarray(v, float)
        return np.arctan2(-(v @ self.t), v @ self.n)

    # -- any twist
    def twist_margin(self, twist) -> tuple[np.ndarray, np.ndarray]:
        """(min slack, boundary band): the twist is stable iff the slack is >= 0.

        A disagreement with the code under test is excused only when |slack| < band, i.e. the
        twist lies within ~1e-8 (relative) of a boundary of the region.
        """
        v = np.atleast_2d(np.asarray(twist, float))
        w = v[:, 2]
        out = np.full(len(v), -np.inf)
        band = np.zeros(len(v))
        rot_ = w != 0
        if rot_.any():
            c = np.stack([-v[rot_, 1], v[rot_, 0]], axis=-1) / w[rot_, None]
            sense = np.sign(w[rot_])
            m = np.where(sense[:, None] > 0, self.cor_margins(c, 1), self.cor_margins(c, -1))
            out[rot_] = m.min(axis=1)
            band[rot_] = 1e-8 * (self.r + np.hypot(*(c - self.cf).T)) * max(1.0, self.r)
        tr = ~rot_
        if tr.any():
            th = self.theta_of(v[tr, :2])
            m = self.translation_margins(th)
            forward = np.abs(th) < np.pi / 2
            out[tr] = np.where(forward, m.min(axis=1), m[:, 0])
            band[tr] = 1e-8 * max(1.0, self.r)
        return out, band

    # -- corners, by brute force over pairs of lines
    def lines(self, sense: int):
        """Each condition as (d, off): d . c >= off."""
        k = self.tip * self.r**2
        cf = self.cf
        if sense > 0:
            return [(self.dL, self.hiL), (-self.dR, -self.loR),
                    (self.uL, cf @ self.uL + self.pL / 2), (-self.uR, -(cf @ self.uR) + k / self.pR)]
        return [(self.dR, self.hiR), (-self.dL, -self.loL),
                (self.uR, cf @ self.uR + self.pR / 2), (-self.uL, -(cf @ self.uL) + k / self.pL)]

    def corners(self, sense: int, tol=1e-9) -> np.ndarray:
        L = self.lines(sense)
        out = []
        for i in range(4):
            for j in range(i + 1, 4):
                M = np.array([L[i][0], L[j][0]])
                if abs(np.linalg.det(M)) < 1e-12:
                    continue
                c = np.linalg.solve(M, [L[i][1], L[j][1]])
                if np.all(self.cor_margins(c, sense) >= -tol * (1 + np.hypot(*c))):
                    out.append(c)
        if not out:
            return np.zeros((0, 2))
        out = np.array(out)
        keep = [k for k in range(len(out)) if all(np.hypot(*(out[k] - out[j])) > 1e-9 for j in range(k))]
        return out[keep]

    def extremal(self) -> np.ndarray:
        """Corner twists of the region: CCW corners, end translations, CW corners (maybe empty)."""
        iv = self.translation_interval()
        parts = [twist_of_cor(self.corners(1), 1).reshape(-1, 3),
                 self.translation(np.unique(iv)) if iv is not None else np.zeros((0, 3)),
                 twist_of_cor(self.corners(-1), -1).reshape(-1, 3)]
        return np.vstack(parts)

    def translation_interval(self):
        lo = max(-self.alpha, np.arctan(self.t @ (self.eL - self.cf) / self.h))
        hi = min(self.alpha, np.arctan(self.t @ (self.eR - self.cf) / self.h))
        return (lo, hi) if lo <= hi else None


# ----------------------------------------------------------------------------------------------
# Exact V_F oracle (docs/mechanics.md, "Exact LP oracle")


def composite_cone_facets(ref: Reference) -> np.ndarray:
    """Outward unit facet normals a_j of F = cone of the 4 edge wrenches (f, (e - cf) x f).

    A wrench w is in F iff a_j . w <= 0 for all j. Moments are divided by r (same for the
    support wrenches in :func:`lp_max_violation`), so both entries have force units.
    """
    gens = []
    for e in (ref.eL, ref.eR):
        for d in (ref.dL, ref.dR):
            gens.append(np.r_[d, cross2(e - ref.cf, d) / ref.r])
    G = np.array(gens)
    facets = []
    for i in range(4):
        for j in range(i + 1, 4):
            a = np.cross(G[i], G[j])
            if np.linalg.norm(a) < 1e-12:
                continue
            a = a / np.linalg.norm(a)
            s = G @ a
            if np.all(s <= 1e-12):
                facets.append(a)
            elif np.all(s >= -1e-12):
                facets.append(-a)
    facets = np.array(facets)
    # deduplicate
    keep = [k for k in range(len(facets)) if all(np.linalg.norm(facets[k] - facets[j]) > 1e-9 for j in range(k))]
    return facets[keep]


def support_samples(vertices, n_grid=14) -> np.ndarray:
    """Grid points strictly inside the polygon, plus its vertices."""
    V = np.asarray(vertices, float)
    poly = shapely.Polygon(V)
    lo, hi = V.min(axis=0), V.max(axis=0)
    xs = np.linspace(lo[0], hi[0], n_grid + 2)[1:-1]
    ys = np.linspace(lo[1], hi[1], n_grid + 2)[1:-1]
    P = np.array([(x, y) for x in xs for y in ys])
    P = P[shapely.contains_xy(poly, P[:, 0], P[:, 1])]
    return np.vstack([P, V])


class LPOracle:
    """max over support distributions (centre at CF) of a_j . (pusher wrench), per facet a_j."""

    def __init__(self, ref: Reference, samples: np.ndarray):
        self.ref, self.x = ref, np.asarray(samples, float)
        self.rel = self.x - ref.cf
        self.facets = composite_cone_facets(ref)
        self.A_eq = np.vstack([np.ones(len(self.x)), self.rel.T])
        self.b_eq = np.array([1.0, 0.0, 0.0])

    def wrenches(self, twist) -> np.ndarray:
        """g_i = (v_i, (x_i - cf) x v_i / r), v_i the unit velocity of support point x_i."""
        vel = velocity_at(twist, self.x)
        speed = np.hypot(*vel.T)
        vhat = vel / np.where(speed > 0, speed, 1.0)[:, None]
        vhat[speed <= 1e-14 * max(1.0, speed.max())] = 0.0  # the COR itself feels no friction force
        return np.column_stack([vhat, cross2(self.rel, vhat) / self.ref.r])

    def max_violation(self, twist) -> float:
        """Largest a_j . w over distributions and facets (<= 0: stuck for every distribution)."""
        g = self.wrenches(twist)
        best = -np.inf
        for a in self.facets:
            res = linprog(-(g @ a), A_eq=self.A_eq, b_eq=self.b_eq, bounds=(0, None), method="highs")
            assert res.status == 0, res.message
            best = max(best, -res.fun)
        return best


# ----------------------------------------------------------------------------------------------
# Random geometries


def random_convex_polygon(rng) -> np.ndarray:
    """CCW convex polygon (hull of 6-20 random points), diameter ~1..4, random pose."""
    while True:
        pts = rng.normal(size=(int(rng.integers(6, 21)), 2)) * rng.uniform(0.4, 1.2, size=2)
        hull = shapely.MultiPoint(pts).convex_hull
        if isinstance(hull, shapely.Polygon) and hull.area > 0.2:
            V = np.asarray(hull.simplify(0.0).exterior.coords)[:-1]
            if shoelace(V) < 0:
                V = V[::-1]
            return V @ rot(rng.uniform(0, 2 * np.pi)).T + rng.uniform(-3, 3, size=2)


def random_rectangle(rng) -> np.ndarray:
    w, h = rng.uniform(0.4, 3.0, size=2)
    V = np.array([[0, 0], [w, 0], [w, h], [0, h]]) - [w / 2, h / 2]
    return V @ rot(rng.uniform(0, 2 * np.pi)).T + rng.uniform(-3, 3, size=2)


def l_shape(rng=None) -> np.ndarray:
    """Non-convex L (CCW); its edges 0, 1, 4, 5 lie on the convex hull."""
    V = np.array([[0, 0], [2.0, 0], [2.0, 0.6], [0.7, 0.6], [0.7, 1.5], [0, 1.5]])
    if rng is not None:
        V = V @ rot(rng.uniform(0, 2 * np.pi)).T + rng.uniform(-2, 2, size=2)
    return V


def random_point_inside(rng, V, margin=0.02) -> np.ndarray:
    poly = shapely.Polygon(V)
    inner = poly.buffer(-margin * np.sqrt(poly.area))
    lo, hi = np.asarray(V).min(axis=0), np.asarray(V).max(axis=0)
    while True:
        p = rng.uniform(lo, hi)
        if inner.contains(shapely.Point(p)):
            return p


def hull_edges(V) -> list[int]:
    """Edges with every vertex on the inner side (independent of Slider.is_pushable)."""
    V = np.asarray(V, float)
    out = []
    for i in range(len(V)):
        f = edge_frame(V, i)
        depth = (V - V[i]) @ f["n"]
        if np.all(depth >= -1e-9):
            out.append(i)
    return out


def random_geometry(rng, kind=None) -> dict:
    """A random (vertices, cf, edge, mu, width) case. ``width`` is None half of the time."""
    kind = kind or rng.choice(["convex", "rect", "L"])
    V = {"convex": random_convex_polygon, "rect": random_rectangle, "L": l_shape}[kind](rng)
    cf = random_point_inside(rng, V)
    edge = int(rng.choice(hull_edges(V)))
    a, b = V[edge], V[(edge + 1) % len(V)]
    length = float(np.hypot(*(b - a)))
    width = None if rng.random() < 0.5 else float(rng.uniform(0.15, 1.2) * length)
    return dict(vertices=np.asarray(V, float), cf=cf, edge=edge, mu=float(rng.uniform(0.2, 2.0)), width=width,
                kind=str(kind))


def random_twists(rng, ref: Reference, n: int) -> np.ndarray:
    """Twists that probe the region: CORs near the part and far out, both senses, translations."""
    k = n // 5
    scale = ref.r
    c1 = ref.cf + rng.normal(size=(k, 2)) * 3 * scale
    c2 = ref.cf + rng.normal(size=(k, 2)) * 15 * scale
    cors = np.vstack([c1, c2])
    sense = rng.choice([-1.0, 1.0], size=len(cors))
    rots = twist_of_cor(cors, sense) * rng.uniform(0.1, 10, size=(len(cors), 1))
    phi = rng.uniform(-np.pi, np.pi, size=k)
    trans = np.column_stack([np.cos(phi), np.sin(phi), np.zeros(k)])
    th = rng.uniform(-1.2 * ref.alpha - 0.1, 1.2 * ref.alpha + 0.1, size=k)
    near = ref.translation(th)
    E = ref.extremal() * np.array([1.0, 1.0, scale])
    if len(E):  # mixtures of the corners: inside the region (and on its faces for 2-sparse weights)
        w = rng.dirichlet(np.full(len(E), 0.5), size=n - 4 * k)
        mix = (w @ E) / np.array([1.0, 1.0, scale])
    else:
        mix = np.zeros((0, 3))
    return np.vstack([rots, trans, near, mix])


def guaranteed_stable(vertices, cf, edge: int, mu: float, width, twist) -> bool:
    """Sticking for every support distribution on the part (the LP oracle) and, for a turn, its
    centre beyond the part along the edge (Theorem 4): the push is guaranteed stable."""
    verts = np.asarray(vertices, float)
    ref = Reference(verts, cf, edge, mu, width=width)
    v = np.asarray(twist, float)
    if LPOracle(ref, support_samples(verts, 12)).max_violation(v) > 1e-9:
        return False
    if v[2] == 0:
        return True
    along = verts @ ref.t
    c_t = np.array([-v[1], v[0]]) / v[2] @ ref.t
    return bool(c_t <= along.min()) if v[2] > 0 else bool(c_t >= along.max())


# ----------------------------------------------------------------------------------------------
# Test parts shared by the mechanics tests: fixtures A, B, D (docs/mechanics.md, "Fixtures"), an
# L-shaped part and a random convex one.

RECT = [[-1, 0], [1, 0], [1, 1], [-1, 1]]
D_VERTS = [(-2, 0), (-0.5, 0), (1, 0), (2, 0), (2, 1), (-2, 1)]
PARTS = {
    "A": dict(vertices=np.array(RECT, float), cf=np.array([0.0, 0.5]), edge=0, mu=0.5, width=None),
    "B": dict(vertices=np.array(RECT, float), cf=np.array([0.4, 0.3]), edge=0, mu=0.5, width=None),
    "D": dict(vertices=np.array(D_VERTS, float), cf=np.array([0.6, 0.5]), edge=1, mu=0.8, width=None),
    "L": {**random_geometry(np.random.default_rng(11), "L"), "mu": 0.7, "width": None},
    "convex": {**random_geometry(np.random.default_rng(5), "convex"), "width": None},
}
