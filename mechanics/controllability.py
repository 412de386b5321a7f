"""Controllability of a part pushed with a finite set of twists (Lynch & Mason 1996, §2; docs/mechanics.md, "Controllability").

Each control is a constant body twist ``v = (v_x, v_y, omega)``; only its direction matters, so
the controls are points of the velocity sphere. With ``X_i`` the vector field of twist ``i``,
``det(X_i, X_j, [X_i, X_j])`` is the squared length of the first two components of ``v_i x v_j``
(docs/mechanics.md, "Controllability"), zero just when the two twists are parallel or both translations:

- **Prop. 1** the part is (small-time) accessible iff some pair has a nonzero determinant;
- **Prop. 2** then it is also controllable in the obstacle-free plane (the system has no drift);
- **Prop. 4** it is small-time locally controllable (STLC) iff the twists *positively span* a
  great circle other than the translations' ``omega = 0``: the convex cone of nonnegative
  combinations of the twists contains a plane through the origin other than ``omega = 0``.

The planes inside a cone all lie in its *lineality space* ``L``, the largest linear subspace it
contains, so Prop. 4 reads: ``dim L = 3`` (zero inside the twists' convex hull, Sussmann's
Thm. 1), or ``dim L = 2`` with ``L`` not the translation plane. ``L`` is the span of the twists
``v_i`` whose opposite ``-v_i`` is a nonnegative combination of the twists (if
``x = sum lambda_j v_j`` and ``-x`` both lie in the cone, so does every ``-v_j`` with
``lambda_j > 0``); each such test is a linear programme.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

__all__ = ["Controllability", "controllability"]

TOL = 1e-7  # HiGHS's feasibility tolerance: finer distinctions between unit twists are noise


@dataclass(frozen=True)
class Controllability:
    """What a set of twists can do (Lynch & Mason 1996, Props. 1, 2 and 4).

    Attributes
    ----------
    accessible : bool
        Small-time accessible, hence accessible (Prop. 1).
    stlc : bool
        Small-time locally controllable (Prop. 4).
    pair : tuple of int, or None
        Two twists (row indices) that make the part accessible on their own (Cor. 1): the pair
        with the largest ``det(X_i, X_j, [X_i, X_j])`` of the unit twists; ``None`` if none does.
    spanning : tuple of int
        When STLC, an inclusion-minimal set of twists whose positive span contains a great circle
        off ``omega = 0`` (three or four in the paper's examples, Cor. 2); else empty.
    lineality : int
        Dimension of the largest linear subspace inside the twists' cone (0 to 3).
    reason : str
        One sentence saying why, naming the proposition.
    """

    accessible: bool
    stlc: bool
    pair: tuple[int, int] | None
    spanning: tuple[int, ...]
    lineality: int
    reason: str

    @property
    def controllable(self) -> bool:
        """Controllable in the obstacle-free plane: the same condition as accessibility (Prop. 2)."""
        return self.accessible


def controllability(twists: ArrayLike, tol: float = TOL) -> Controllability:
    """Decide accessibility, controllability and STLC for the controls ``twists``.

    Parameters
    ----------
    twists : (n, 3) array_like
        Body twists ``(v_x, v_y, omega)``, e.g. the union of edges'
        :meth:`~mechanics.ExactRegion.extremal_twists`. Only directions count: each row is scaled
        to unit length, and zero rows (no motion) are ignored.
    tol : float
        Below this, a unit twist's component, a determinant's square root or a singular value
        counts as zero.

    Returns
    -------
    Controllability

    Examples
    --------
    A counter-clockwise rotation about ``c`` is the twist ``(c_y, -c_x, 1)``, a clockwise one
    ``(-c_y, c_x, -1)`` (docs/mechanics.md, "Conventions"). Two rotations about distinct centres, ``(0, 0)`` and
    ``(1, 0)``: controllable (Fig. 5), but every combination turns counter-clockwise, so no
    neighbourhood is reachable in small time:

    >>> c = controllability([[0, 0, 1], [0, -1, 1]])
    >>> c.accessible, c.controllable, c.stlc, c.pair, c.lineality
    (True, True, False, (0, 1), 0)

    A rotation and a translation (Fig. 4: rotate, translate, rotate back the long way round):

    >>> controllability([[0, 0, 1], [1, 0, 0]]).controllable
    True

    Translations alone never turn the part, even both ways along both axes:

    >>> c = controllability([[1, 0, 0], [0, 1, 0], [-1, 0, 0], [0, -1, 0]])
    >>> c.accessible, c.lineality
    (False, 2)
    >>> c.reason
    'not accessible: the twists are all translations (Prop. 1)'

    Adding a rotation makes it controllable, but the only great circle the twists positively span
    is the translations', which cannot undo the rotation (the boundary case of Prop. 4):

    >>> c = controllability([[1, 0, 0], [0, 1, 0], [-1, 0, 0], [0, -1, 0], [0, 0, 1]])
    >>> c.controllable, c.stlc
    (True, False)

    Fig. 7: a counter-clockwise rotation about ``(0, 1)``, a clockwise one about ``(0, -1)`` and the
    translations both ways across their line ``x = 0``. The first two sum to ``(2, 0, 0)``, and each
    rotation's opposite is the other rotation plus twice ``(-1, 0, 0)``: the twists positively span
    the great circle ``v_y = 0`` (every centre on the line, both senses), and three suffice:

    >>> c = controllability([[1, 0, 1], [1, 0, -1], [1, 0, 0], [-1, 0, 0]])
    >>> c.stlc, c.lineality, c.spanning
    (True, 2, (0, 1, 3))
    >>> c.reason
    'small-time locally controllable: twists 0, 1, 3 positively span a great circle off omega = 0 (Prop. 4)'
    """
    v = np.asarray(twists, dtype=float).reshape(-1, 3)
    if not np.all(np.isfinite(v)):
        raise ValueError("twists must be finite")
    norms = np.linalg.norm(v, axis=1)
    index = np.flatnonzero(norms > tol)  # rows kept, as indices of the caller's array
    unit = v[index] / norms[index, None]
    pair = _best_pair(unit, tol)
    in_l = _lineality_generators(unit, tol)
    dim = _rank(unit[in_l], tol)
    if pair is None:
        what = ("there are no twists" if len(unit) == 0 else "the twists are all translations"
                if np.all(np.abs(unit[:, 2]) <= tol) else "the twists all lie on one line")
        return Controllability(False, False, None, (), dim, f"not accessible: {what} (Prop. 1)")
    pair = (int(index[pair[0]]), int(index[pair[1]]))
    if not _stlc(unit[in_l], tol):
        why = ("the only great circle they positively span is the translations' (omega = 0)" if dim == 2
               else "they positively span no great circle")
        return Controllability(True, False, pair, (), dim, "controllable, not small-time locally controllable: "
                                                           f"{why} (Props. 2, 4)")
    spanning = tuple(int(i) for i in index[_minimal_spanning(unit, np.flatnonzero(in_l), tol)])
    named = ", ".join(map(str, spanning))
    return Controllability(True, True, pair, spanning, dim, f"small-time locally controllable: twists {named} "
                                                            "positively span a great circle off omega = 0 (Prop. 4)")


def _best_pair(unit: np.ndarray, tol: float) -> tuple[int, int] | None:
    """The pair of rows with the largest ``det(X_i, X_j, [X_i, X_j])``, if it is not zero."""
    if len(unit) < 2:
        return None
    cross = np.cross(unit[:, None, :], unit[None, :, :])
    det = np.hypot(cross[..., 0], cross[..., 1])  # square root of the determinant
    i, j = np.unravel_index(np.argmax(np.triu(det, 1)), det.shape)
    return (int(i), int(j)) if det[i, j] > tol else None


def _in_cone(unit: np.ndarray, target: np.ndarray) -> np.ndarray | None:
    """Nonnegative weights of the rows of ``unit`` summing to ``target`` (a vertex of the LP, so
    at most three are nonzero), or ``None`` if there are none."""
    # scipy.optimize takes a third of a second to import, and planning never asks for controllability.
    from scipy.optimize import linprog

    res = linprog(np.zeros(len(unit)), A_eq=unit.T, b_eq=target, bounds=(0, None), method="highs")
    return res.x if res.status == 0 else None


def _lineality_generators(unit: np.ndarray, tol: float) -> np.ndarray:
    """Mask of the rows lying in the lineality space of their cone (``-v_i`` in the cone)."""
    mask = np.zeros(len(unit), dtype=bool)
    for i in range(len(unit)):
        if not mask[i]:
            weights = _in_cone(unit, -unit[i])
            if weights is not None:
                # Every row used for -v_i is in the lineality space too (module docstring).
                mask |= weights > tol
                mask[i] = True
    return mask


def _rank(rows: np.ndarray, tol: float) -> int:
    return int(np.sum(np.linalg.svd(rows, compute_uv=False) > tol)) if len(rows) else 0


def _stlc(generators: np.ndarray, tol: float) -> bool:
    """Prop. 4 for the generators of a lineality space: a plane in it other than ``omega = 0``."""
    dim = _rank(generators, tol)
    return dim == 3 or (dim == 2 and bool(np.any(np.abs(generators[:, 2]) > tol)))


def _minimal_spanning(unit: np.ndarray, in_l: np.ndarray, tol: float) -> list[int]:
    """An inclusion-minimal subset of rows ``in_l`` (the lineality generators, STLC together)
    whose cone still holds a plane off ``omega = 0``.

    Two generators spanning such a plane and the few rows that make up their opposites hold that
    plane (at most eight rows); dropping rows one at a time while STLC lasts leaves a minimal set
    (STLC only grows with the set), without testing subsets of all ``n`` rows.
    """
    a, b = (in_l[k] for k in _best_pair(unit[in_l], tol))
    keep = {int(a), int(b)}
    for k in (a, b):
        keep |= set(np.flatnonzero(_in_cone(unit, -unit[k]) > tol).tolist())
    rows = sorted(keep)
    for k in list(rows):
        trial = [r for r in rows if r != k]
        sub = unit[trial]
        if _stlc(sub[_lineality_generators(sub, tol)], tol):
            rows = trial
    return rows
