"""A batched revised simplex method: many small linear programmes in standard form at once, in numpy.

It knows nothing of pushing: :mod:`.support` poses its LPs to it, a handful of constraints each
and thousands at a time (many twists, many directions), where a HiGHS call per LP would cost far
more than the LP itself.
"""

from __future__ import annotations

import numpy as np

__all__ = ["batched_simplex"]


def batched_simplex(costs: np.ndarray, columns: np.ndarray, rhs: np.ndarray, basis: np.ndarray,
                    limit: int = 100, restart: np.ndarray | None = None,
                    restart_limit: int = 100) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Optimal duals of the LPs ``max costs[p] . s`` s.t. ``columns s = rhs``, ``s >= 0``, one per
    row of ``costs``, which LPs are unbounded, and the final bases.

    Parameters
    ----------
    costs : (P, n) ndarray
        One LP per row; a cost of ``-inf`` keeps that column out of its LP.
    columns : (m, n) or (P, m, n) ndarray
        The constraint matrix, shared by all LPs or one per LP.
    rhs : (m,) ndarray
        The right-hand side, shared.
    basis : (P, m) int ndarray
        A feasible basis of each LP to start from: ``m`` column indices whose columns solve
        ``columns[:, basis] s_B = rhs`` with ``s_B >= 0``.
    limit : int
        Most pivots before the LPs still open go to HiGHS.
    restart : (P, m) int ndarray, optional
        Other feasible bases: an LP still open after ``limit`` pivots starts again from its own
        (``restart_limit`` more pivots) before it goes to HiGHS. A warm start (``basis`` the
        optimum of a similar LP) can lead into a degenerate vertex that the cold start avoids.

    Returns
    -------
    duals : (P, m) ndarray
        Optimal duals ``pi``: ``pi . column >= cost`` for every column (to rounding), and
        ``pi . rhs`` is the optimum. Meaningless for an unbounded LP.
    unbounded : (P,) bool ndarray
        Which LPs have no finite optimum.
    basis : (P, m) int ndarray
        Each LP's last basis: optimal unless the LP is unbounded or went to HiGHS (then its
        starting basis), and feasible in any case. The constraints do not depend on the costs, so
        with shared columns it is a feasible start for any other costs: the optimal basis of a
        similar LP starts the next one a pivot or two from its optimum.

    Notes
    -----
    The revised simplex method on all problems at once: each pivot costs one product of the duals
    with the columns. Pivots follow Dantzig's rule (the largest reduced cost), which converges in
    a few pivots but can cycle on degenerate vertices (a basic weight of 0: :mod:`.support`'s grids
    through the CF make them, a sample at the CF, others in line with it); after ``limit // 4``
    pivots the open problems follow Bland's rule (lowest indices), which cannot cycle. One still
    open after ``limit`` (rounding) goes to HiGHS.

    Examples
    --------
    Weights on the points 0, 1 and 3 of a line (columns ``(1, x - 1)``) with total 1 and mean 1:
    the best of costs 0, 2 and 9 puts 2/3 on 0 and 1/3 on 3, for 3; the duals ``(3, 3)`` are the
    line ``3 + 3 (x - 1)``, on or above every point's cost (0, 3 and 9):

    >>> pi, unbounded, _ = batched_simplex(np.array([[0.0, 2.0, 9.0]]), np.array([[1.0, 1, 1], [-1, 0, 2]]),
    ...                                 np.array([1.0, 0]), np.array([[0, 1]]))
    >>> pi.round(12).tolist(), unbounded.tolist()
    ([[3.0, 3.0]], [False])

    Degenerate: points -1, 0, -2 and 1 about the mean 0, costs 0, 1, 2 and 3, from the start
    all the weight at 0 (the basis also holds -1, at weight 0). The first pivot brings -2 in at
    weight 0, so the value stays 1; the next finds the optimum, 1/3 on -2 and 2/3 on 1, for 8/3:

    >>> pi, unbounded, _ = batched_simplex(np.array([[0.0, 1.0, 2.0, 3.0]]),
    ...                                 np.array([[1.0, 1, 1, 1], [-1, 0, -2, 1]]), np.array([1.0, 0]),
    ...                                 np.array([[0, 1]]))
    >>> (pi @ [1.0, 0]).round(12).tolist(), unbounded.tolist()
    ([2.666666666667], [False])

    A singular basis (two columns alike; rounding can make one of a nearly degenerate part) is
    not pivoted from: that LP goes to HiGHS, which finds the optimum 2 (3/4 at the second point 0,
    1/4 at 2, for costs 1 and 5):

    >>> pi, unbounded, _ = batched_simplex(np.array([[0.0, 1.0, 5.0]]), np.array([[1.0, 1, 1], [0, 0, 2]]),
    ...                                 np.array([1.0, 0.5]), np.array([[0, 1]]))
    >>> (pi @ [1.0, 0.5]).round(9).tolist(), unbounded.tolist()
    ([2.0], [False])

    Unbounded: ``max s_1`` s.t. ``s_0 - s_1 = 1`` lets ``s_1`` grow without end:

    >>> batched_simplex(np.array([[0.0, 1.0]]), np.array([[1.0, -1.0]]), np.array([1.0]), np.array([[0]]))[1]
    array([ True])
    """
    problems, m = basis.shape
    start, basis = basis, np.array(basis)
    duals = np.zeros((problems, m))
    unbounded = np.zeros(problems, dtype=bool)
    tol = 1e-12 * (1.0 + np.max(np.abs(np.where(np.isfinite(costs), costs, 0.0)), axis=1))
    open_, handed = _pivots(costs, columns, rhs, basis, duals, unbounded, tol, np.arange(problems), limit)
    if restart is not None and len(open_):
        basis[open_] = restart[open_]
        open_, more = _pivots(costs, columns, rhs, basis, duals, unbounded, tol, open_, restart_limit)
        handed += more
    basis[handed] = start[handed]
    if not len(open_) and not handed:
        return duals, unbounded, basis
    shared = columns.ndim == 2
    from scipy.optimize import linprog  # rarely needed: scipy.optimize takes a third of a second to import

    for p in [*open_.tolist(), *handed]:
        a = columns if shared else columns[p]
        keep = np.isfinite(costs[p])
        res = linprog(rhs, A_ub=-a[:, keep].T, b_ub=-costs[p, keep], bounds=[(None, None)] * m, method="highs")
        if res.status == 2:  # no feasible duals: the LP itself is unbounded
            unbounded[p] = True
        elif res.status != 0:
            raise RuntimeError(f"support LP failed: {res.message}")
        else:
            duals[p] = res.x
    return duals, unbounded, basis


def _pivots(costs: np.ndarray, columns: np.ndarray, rhs: np.ndarray, basis: np.ndarray, duals: np.ndarray,
            unbounded: np.ndarray, tol: np.ndarray, open_: np.ndarray, limit: int) -> tuple[np.ndarray, list[int]]:
    """Up to ``limit`` pivots of the LPs ``open_`` of :func:`batched_simplex` (``basis``, ``duals`` and
    ``unbounded`` updated in place): those still open, and those whose basis turned singular."""
    m = basis.shape[1]
    shared = columns.ndim == 2
    handed: list[int] = []
    for pivot in range(limit):
        bland = pivot >= limit // 4
        a = columns if shared else columns[open_]
        cols = (a[:, basis[open_]].transpose(1, 0, 2) if shared
                else np.take_along_axis(a, basis[open_][:, None, :], axis=2))
        c = costs[open_]
        pi, singular = _solved(np.swapaxes(cols, 1, 2), np.take_along_axis(c, basis[open_], axis=1))
        if singular.any():  # a basis rounding made singular: that LP goes to HiGHS
            handed.extend(open_[singular].tolist())
            keep = ~singular
            open_, cols, c, pi = open_[keep], cols[keep], c[keep], pi[keep]
            a = columns if shared else columns[open_]
        duals[open_] = pi
        reduced = c - (pi @ a if shared else np.einsum("pm,pmn->pn", pi, a))
        improving = reduced > tol[open_, None]
        going = improving.any(axis=1)
        if not going.any():
            return np.arange(0), handed
        enter = np.argmax(improving if bland else reduced, axis=1)[going]
        open_, cols = open_[going], cols[going]
        entering = a[:, enter].T if shared else a[going][np.arange(len(open_)), :, enter]
        weights = np.linalg.solve(cols, np.broadcast_to(rhs, (len(open_), m))[..., None])[..., 0]
        step = np.linalg.solve(cols, entering[..., None])[..., 0]
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = np.where(step > 1e-11, np.maximum(weights, 0.0) / step, np.inf)
        bounded = np.isfinite(ratio).any(axis=1)  # else the entering column grows without end
        unbounded[open_[~bounded]] = True
        open_, enter, ratio = open_[bounded], enter[bounded], ratio[bounded]
        if bland:  # of the tied leaving columns, the lowest
            ratio = np.where(ratio <= ratio.min(axis=1, keepdims=True), basis[open_], np.inf)
        basis[open_, np.argmin(ratio, axis=1)] = enter
    return open_, handed


def _solved(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``x`` with ``a[p] x[p] = b[p]`` for each problem ``p``, and which ``a[p]`` are singular
    (their ``x`` is left 0)."""
    try:
        return np.linalg.solve(a, b[..., None])[..., 0], np.zeros(len(a), dtype=bool)
    except np.linalg.LinAlgError:  # one singular matrix fails the whole batch: solve them apart
        x, singular = np.zeros(b.shape), np.zeros(len(a), dtype=bool)
        for p in range(len(a)):
            try:
                x[p] = np.linalg.solve(a[p], b[p])
            except np.linalg.LinAlgError:
                singular[p] = True
        return x, singular
