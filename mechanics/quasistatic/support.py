"""Support friction of a part resting on weighted points: the exact point-support limit surface.

The part presses on the table at points ``x_i`` with weights ``w_i`` (normal force times support
friction coefficient, normalised to sum 1); their weighted centre is the centre of friction (CF,
Lynch & Mason 1996, §1.1). When the part moves with twist ``V``, the table's friction on support
point ``i`` is ``-w_i v_i/|v_i|``, ``v_i`` the point's velocity (Mason 1986). Quasi-statically the
pusher must supply the opposite wrench, the *load* ``W(V) = sum_i w_i (u_i, x_i x u_i)`` with
``u_i = v_i/|v_i|``. ``W`` is the gradient of the dissipated power ``D(V) = sum_i w_i |v_i|``, a
convex function; the loads ``W`` form the limit surface (docs/mechanics.md, "Limit surface").

Point supports give the limit surface flat facets: when the rotation centre (COR) sits on support
point ``k``, that point's friction is any force of norm at most ``w_k`` (it is not moving), so a
whole disk of loads produces the same rotation. :meth:`SupportDistribution.twist_for` handles the
facets exactly; :meth:`SupportDistribution.wrench` returns the facet's centre there.

Numerics are done in a *local* frame: origin at the CF, lengths divided by the support radius,
so forces are O(1), moments O(1) and one tolerance, :data:`TOL`, serves throughout.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import cached_property

import numpy as np
from numpy.typing import ArrayLike

from ..twist import point_velocity

__all__ = ["SupportDistribution", "TOL"]

#: Relative tolerance of the local frame (forces sum to 1, lengths at most 1): a support point is
#: at the COR, a velocity is zero, a force is in a cone, up to this.
TOL = 1e-9

#: Smoothing schedule of the limit-surface inversion (local units: speeds are O(1)); after each
#: stage an unsmoothed Newton polish is tried, which fails only near a kink.
_SMOOTHING = (1e-2, 1e-4, 1e-6, 1e-8, 1e-10, 1e-12)
_NEWTON_ITERATIONS = 50
_POLISH_ITERATIONS = 8


def cross2(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """z-component of the cross product of 2-vectors (last axis)."""
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


class SupportDistribution:
    """Weighted support points of a part; their weighted centre is its centre of friction.

    Parameters
    ----------
    points : (n, 2) array_like
        Distinct support points, slider frame, at least two.
    weights : (n,) array_like, optional
        Positive weights (pressure times support friction); normalised to sum 1. Default: equal.

    Raises
    ------
    ValueError
        With a one-line message if the points or weights are not acceptable.

    Examples
    --------
    A dipod: two points, the heavier one pulls the CF towards it.

    >>> s = SupportDistribution([[0.0, 0.0], [3.0, 0.0]], [2.0, 1.0])
    >>> s.centre.tolist(), s.weights.tolist(), s.radius
    ([1.0, 0.0], [0.6666666666666666, 0.3333333333333333], 2.0)

    A translation along +y needs a load of 1 along +y through the CF:

    >>> s.wrench([0.0, 1.0, 0.0]).round(12).tolist()
    [0.0, 1.0, 1.0]
    """

    def __init__(self, points: ArrayLike, weights: ArrayLike | None = None):
        x = np.asarray(points, dtype=float)
        if x.ndim != 2 or x.shape[1] != 2 or len(x) < 2:
            raise ValueError("support points must be a list of at least two [x, y] pairs")
        w = np.ones(len(x)) if weights is None else np.asarray(weights, dtype=float)
        if w.shape != (len(x),):
            raise ValueError(f"expected {len(x)} weights, got shape {w.shape}")
        if not (np.all(np.isfinite(x)) and np.all(np.isfinite(w))):
            raise ValueError("support points and weights must be finite")
        if np.any(w <= 0):
            raise ValueError("support weights must be positive")
        if len(np.unique(x, axis=0)) < len(x):
            raise ValueError("support points must be distinct")
        self.points: np.ndarray = x
        self.weights: np.ndarray = w / w.sum()
        self.centre: np.ndarray = self.weights @ x
        self.radius: float = float(np.max(np.linalg.norm(x - self.centre, axis=1)))
        # Local frame (module docstring): CF at the origin, unit radius.
        self.local_points: np.ndarray = (x - self.centre) / self.radius

    def __repr__(self) -> str:
        return f"SupportDistribution(n={len(self.points)}, centre={self.centre.tolist()})"

    # -- frames ----------------------------------------------------------------------------------

    def to_local_points(self, points: ArrayLike) -> np.ndarray:
        """Slider-frame points in the local frame."""
        return (np.asarray(points, dtype=float) - self.centre) / self.radius

    def to_local_twist(self, twist: ArrayLike) -> np.ndarray:
        """Slider-frame twist in the local frame: velocity of the CF over the radius, same omega."""
        v = np.asarray(twist, dtype=float)
        vc = point_velocity(v, self.centre)
        return np.concatenate([vc / self.radius, v[..., 2:]], axis=-1)

    def from_local_twist(self, twist: ArrayLike) -> np.ndarray:
        """Inverse of :meth:`to_local_twist`."""
        v = np.asarray(twist, dtype=float)
        w = v[..., 2]
        vc = v[..., :2] * self.radius
        # Velocity of the slider origin: v_c minus omega k x c.
        return np.stack([vc[..., 0] + w * self.centre[1], vc[..., 1] - w * self.centre[0], w], axis=-1)

    def to_local_wrench(self, wrench: ArrayLike) -> np.ndarray:
        """Slider-frame wrench (moment about the slider origin) in the local frame."""
        f = np.asarray(wrench, dtype=float)
        m = (f[..., 2] - cross2(self.centre, f[..., :2])) / self.radius
        return np.concatenate([f[..., :2], m[..., None]], axis=-1)

    def from_local_wrench(self, wrench: ArrayLike) -> np.ndarray:
        """Inverse of :meth:`to_local_wrench`."""
        f = np.asarray(wrench, dtype=float)
        m = f[..., 2] * self.radius + cross2(self.centre, f[..., :2])
        return np.concatenate([f[..., :2], m[..., None]], axis=-1)

    # -- the limit surface, slider frame ---------------------------------------------------------

    def dissipation(self, twist: ArrayLike) -> np.ndarray:
        """Power ``sum_i w_i |v_i|`` the support friction dissipates under ``twist``.

        >>> float(SupportDistribution([[-1.0, 0.0], [1.0, 0.0]]).dissipation([0.0, 0.0, 2.0]))
        2.0
        """
        v = point_velocity(np.asarray(twist, dtype=float)[..., None, :], self.points)
        return np.linalg.norm(v, axis=-1) @ self.weights

    def wrench(self, twist: ArrayLike) -> np.ndarray:
        """Load wrench ``W(V)`` the pusher must apply for the part to move with ``twist``.

        Vectorised over leading axes. A support point at the COR contributes nothing (the centre
        of its facet; any force of norm up to its weight would do).

        >>> s = SupportDistribution([[-1.0, 0.0], [1.0, 0.0]])
        >>> s.wrench([0.0, 0.0, 1.0]).round(12).tolist()   # spin about the CF: a pure moment
        [0.0, 0.0, 1.0]
        """
        local, _ = self.local_load(self.to_local_twist(twist))
        return self.from_local_wrench(local)

    def twist_for(self, wrench: ArrayLike) -> np.ndarray:
        """The motion a pushing ``wrench`` produces: the twist ``V`` with ``W(V)`` along ``wrench``.

        Scaled to unit dissipated power. Unique for support points that are not all on one line;
        on a facet the result is the rotation about that support point, exactly.

        Examples
        --------
        Three points, a heavy one at the CF: a small force with a moment turns the part about
        the heavy point (its friction absorbs the force).

        >>> s = SupportDistribution([[0.0, 0.0], [1.0, 0.0], [-1.0, 0.0]], [8.0, 1.0, 1.0])
        >>> (s.twist_for([0.05, 0.0, 0.3]).round(12) + 0.0).tolist()
        [0.0, 0.0, 5.0]

        A pure force through the CF translates the part along it (here the support is not on one
        line; for a dipod, a force across its line through the CF is a vertex of the limit
        surface and several twists answer it):

        >>> square = SupportDistribution([[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0], [0.0, -1.0]])
        >>> (square.twist_for([0.0, 2.0, 0.0]).round(9) + 0.0).tolist()
        [0.0, 1.0, 0.0]
        """
        local = self.local_twist_for(self.to_local_wrench(wrench))
        v = self.from_local_twist(local)
        return v / self.dissipation(v)

    # -- the limit surface, local frame (used by the contact solver) -----------------------------

    def local_load(self, twist: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """``(W, at_rest)`` for local twists (leading axes ``...``): the load with points at the
        COR left out, and the mask ``(..., n)`` of those points."""
        v = np.asarray(twist, dtype=float)
        vx, vy = self._velocities(v)
        speed = np.hypot(vx, vy)
        at_rest = speed <= TOL * np.linalg.norm(v, axis=-1)[..., None]
        inverse = np.where(at_rest, 0.0, 1.0 / np.where(at_rest, 1.0, speed))
        ux, uy = vx * inverse, vy * inverse
        x, y = self.local_points.T
        return np.stack([ux @ self.weights, uy @ self.weights, (x * uy - y * ux) @ self.weights], axis=-1), at_rest

    def _velocities(self, twist: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Velocity components ``(..., n)`` of the local support points under local twists
        ``(..., 3)`` (:func:`.point_velocity`, unrolled: this is the solver's inner loop)."""
        x, y = self.local_points.T
        return twist[..., 0, None] - twist[..., 2, None] * y, twist[..., 1, None] + twist[..., 2, None] * x

    @cached_property
    def _facets(self) -> tuple[np.ndarray, np.ndarray]:
        """For a CCW rotation about each support point ``k`` (local frame): the force and the
        moment about ``x_k`` of all the *other* points' friction, shapes ``(n, 2)``, ``(n,)``."""
        x = self.local_points
        d = x[None, :, :] - x[:, None, :]  # d[k, i] = x_i - x_k
        r = np.linalg.norm(d, axis=-1)
        safe = np.where(r > 0, r, 1.0)
        # CCW velocity direction of x_i about x_k is k x d / r; zero for i == k.
        u = np.stack([-d[..., 1], d[..., 0]], axis=-1) / safe[..., None]
        return u.transpose(0, 2, 1) @ self.weights, r @ self.weights

    def local_facet_twist(self, wrench: np.ndarray) -> np.ndarray | None:
        """Rotation about the support point whose facet the ray of local ``wrench`` hits, or None.

        For a rotation of sense ``s`` about ``x_k`` the load is ``s * rest_k`` plus any force of
        norm ``<= w_k`` through ``x_k``. Moments about ``x_k`` fix the scale ``lam`` of the ray,
        then the remaining force must fit in that disk.
        """
        g = np.asarray(wrench, dtype=float)
        x = self.local_points
        rest_force, rest_moment = self._facets
        moment = g[2] - cross2(x, g[:2])  # moment of g about each x_k
        with np.errstate(divide="ignore", invalid="ignore"):
            lam = rest_moment / np.abs(moment)
            sense = np.sign(moment)
            excess = np.linalg.norm(lam[:, None] * g[:2] - sense[:, None] * rest_force, axis=1) - self.weights
        excess = np.where(np.isfinite(excess), excess, np.inf)
        k = int(np.argmin(excess))
        if excess[k] > TOL:
            return None
        return sense[k] * np.array([x[k, 1], -x[k, 0], 1.0])

    def local_twist_for(self, wrench: ArrayLike) -> np.ndarray:
        """Local twist whose load is along local ``wrench`` (positive multiple), unnormalised.

        Off the facets this is the minimiser of ``D(V)`` on the plane ``g . V = 1`` (its optimality
        condition is ``W(V) = D g``): a convex problem, smooth at the minimiser but with a kink
        wherever the COR crosses a support point, where plain Newton stalls. So it is solved by
        damped Newton on ``sum_i w_i sqrt(|v_i|^2 + eps^2)`` for decreasing ``eps``, each stage
        followed by a try at ``eps = 0`` from there, started from the ellipsoidal limit
        surface's answer (docs/mechanics.md, "Ellipsoidal limit surface").
        """
        g = np.asarray(wrench, dtype=float)
        g = g / np.linalg.norm(g)
        facet = self.local_facet_twist(g)
        if facet is not None:
            return facet
        x, w = self.local_points, self.weights
        basis = np.linalg.svd(g[None, :])[2][1:].T  # (3, 2), orthonormal, perpendicular to g
        guess = np.array([g[0], g[1], g[2] / (w @ np.sum(x * x, axis=1))])
        z = basis.T @ guess / (g @ guess)
        for eps in _SMOOTHING:
            z, _ = self._newton(g, basis, z, eps, max(1e-13, 1e-3 * eps), _NEWTON_ITERATIONS)
            exact, converged = self._newton(g, basis, z, 0.0, 1e-13, _POLISH_ITERATIONS)
            if converged:
                return g + basis @ exact
        raise RuntimeError(f"limit-surface inversion did not converge for wrench {g.tolist()}")

    def _newton(self, origin: np.ndarray, basis: np.ndarray, z: np.ndarray, eps: float, tol: float,
                iterations: int) -> tuple[np.ndarray, bool]:
        """Minimise the ``eps``-smoothed dissipation over ``origin + basis z`` until the gradient
        is below ``tol``; (z, converged)."""

        def value(z: np.ndarray) -> float:
            vx, vy = self._velocities(origin + basis @ z)
            return float(self.weights @ np.sqrt(vx * vx + vy * vy + eps * eps))

        for _ in range(iterations):
            grad, hess = self._smoothed(origin + basis @ z, eps)
            grad, hess = basis.T @ grad, basis.T @ hess @ basis
            if np.linalg.norm(grad) <= tol:
                return z, True
            step = -np.linalg.solve(hess + 1e-14 * np.trace(hess) * np.eye(2), grad)
            z = z + _backtrack(value, z, step, grad @ step)
        return z, False

    def _smoothed(self, twist: np.ndarray, eps: float) -> tuple[np.ndarray, np.ndarray]:
        """Gradient and Hessian of ``sum_i w_i sqrt(|v_i|^2 + eps^2)`` at a local twist.

        With ``v_i = J_i V``, ``J_i = [[1, 0, -y_i], [0, 1, x_i]]``: the gradient is
        ``sum_i w_i J_i^T u_i`` and the Hessian ``sum_i J_i^T M_i J_i``, ``u_i = v_i/s_i``,
        ``M_i = w_i (I - u_i u_i^T)/s_i``, ``s_i = |(v_i, eps)|``; written out entry by entry.
        """
        x, y = self.local_points.T
        vx, vy = self._velocities(twist)
        size = np.maximum(np.sqrt(vx * vx + vy * vy + eps * eps), 1e-300)
        ux, uy = vx / size, vy / size
        c = self.weights / size
        m11, m12, m22 = c * (1 - ux * ux), -c * ux * uy, c * (1 - uy * uy)
        m13, m23 = x * m12 - y * m11, x * m22 - y * m12
        h = np.array([m11, m12, m13, m22, m23, x * m23 - y * m13]).sum(axis=1)
        hess = h[[0, 1, 2, 1, 3, 4, 2, 4, 5]].reshape(3, 3)
        grad = np.array([ux, uy, x * uy - y * ux]) @ self.weights
        return grad, hess


def _backtrack(f: Callable[[np.ndarray], float], z: np.ndarray, step: np.ndarray, slope: float) -> np.ndarray:
    """Armijo backtracking: the largest ``2^-k step`` that decreases convex ``f`` enough.

    Near the optimum the decrease (``~ |gradient|^2``) drops below the rounding of ``f``; the
    slack of a few ulps lets Newton's quadratic convergence finish on the gradient.
    """
    f0, t = f(z), 1.0
    slack = 4 * np.finfo(float).eps * abs(f0)
    while t > 1e-12 and f(z + t * step) > f0 + 1e-4 * t * slope + slack:
        t /= 2
    return t * step
