"""One quasi-static step: every contact mode consistent with force balance (docs/mechanics.md, "Contact modes").

Problem. The pusher is kinematically driven with twist ``V_p``; the slider's twist ``V`` is
unknown. At each contact the relative velocity ``u = v_S(p) - v_P(p)`` and the contact force obey
Coulomb's law and complementarity (:mod:`.contact`), and quasi-statically the contact forces
balance the support friction: ``sum_j c_j = W(V)``, the load of :mod:`.support`.

Method: enumerate the ``4^m`` contact modes. A mode fixes

* kinematic equalities ``E (V - V_p) = 0`` (``u = 0`` when sticking, ``u . n = 0`` when sliding),
  so ``V`` lies on an affine family of dimension ``d = 3 - rank E``, plus strict inequalities
  (slip direction, separation);
* a polyhedral cone ``K`` of contact wrenches (friction cones of sticking contacts, the cone edge
  of sliding ones), spanned by ``k`` generators.

The mode is consistent when some ``V`` of the family has ``W(V)`` in ``K``. Generically
``d + k = 3`` (``k = 4`` for two sticking contacts), which leaves four small problems:

* ``d = 0`` (every contact sticks, ``V = V_p``): is ``W(V_p)`` in ``K``? Non-negative least
  squares; a linear program if the COR of ``V_p`` is on a support point (facet, below).
* ``d = 1``, ``k = 2`` (one contact sticks, or two slide): ``W(V)`` must lie in the plane of the
  two generators, one equation on a line of twists. Parametrise the line's directions by an angle
  ``phi``, scan the signed distance to the plane on a grid, refine sign changes with Brent's
  method, then check the load is in the cone (as for ``d = 0``).
* ``d = 2``, ``k = 1`` (one contact slides, the others separate): the load must be along the one
  generator ``g``; the twist is the limit surface's normal there
  (:meth:`.SupportDistribution.local_twist_for`), scaled to match the pusher's normal velocity.
* ``d = 3`` (all separate): only ``V = 0`` carries no load.

Then the strict kinematic inequalities select the consistent ones. All solutions are returned,
so an ambiguous step (several modes, or several twists of one mode) is visible.

Why enumerate modes rather than solve one program: Coulomb friction is not associative, so no
single convex program has exactly the quasi-static motions as its solutions, and a root finder
or complementarity solver would return one solution where several may exist. With ``m <= 2``
contacts the 16 modes are cheap, each reduces to at most a one-dimensional root or a smooth
two-dimensional convex minimisation, and the answer lists every solution. Everything is solved
in the support's local frame (:mod:`.support`); twists are returned in the slider frame.

Facets. Point supports make ``W`` set-valued when the COR is on a support point: that point's
friction is any force of norm at most its weight. In the ``d = 1`` scan ``W`` jumps there, and
Brent's method converges onto the jump if the sign changes across it; the cone check at a twist
whose COR is on support points is a linear program with each facet's disk replaced by an
inscribed 64-gon (a marginal balance is rejected rather than accepted). In the ``d = 2`` case the
facet test is exact (:meth:`.SupportDistribution.local_facet_twist`).

Limitations. Degenerate contact geometry raises ``ValueError``: a one-dimensional family whose
cone is not spanned by two independent wrenches, or a two-dimensional one with more than one
generator (e.g. a sticking contact on the normal line of a sliding one, coincident contacts,
two sliding contacts whose cone edges lie on one line). So does a pusher twist with zero normal
velocity at a contact (the slider could stay still under zero force: the speed of the
quasi-static motion is undetermined). Two roots of one mode closer than the scan's grid step
(pi/16 in ``phi``), or a root touching zero without a sign change, would be missed. With one
sticking contact the signed distance is monotone (the plane's normal is the family's direction
and ``W`` is the gradient of a convex function), so its root is unique; for two sliding contacts
no second root was found in thousands of random families, so the grid is a margin. For support
points all on one line the limit surface has vertices, and for a load exactly at a vertex
``d = 2`` returns one twist of a set.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from itertools import product

import numpy as np
from numpy.typing import ArrayLike
import scipy  # its linalg and optimize are imported where used: they take 0.3 s, and planning needs neither

from .contact import Contact, ContactMode
from ..wrenches import point_wrench
from .support import TOL, SupportDistribution

__all__ = ["Solution", "StepResult", "solve_step"]

_SCAN = 16  # grid cells over the half circle of twist directions of a d = 1 family
_FACET_SIDES = 64  # inscribed polygon of a facet disk in the d = 0 cone test

Mode = tuple[ContactMode, ...]


@dataclass(frozen=True, eq=False)
class Solution:
    """A consistent contact mode and the slider twist (slider frame) it gives."""

    mode: Mode
    twist: np.ndarray

    def __repr__(self) -> str:
        mode = ", ".join(m.value for m in self.mode)
        return f"Solution(mode=({mode}), twist={(self.twist.round(12) + 0.0).tolist()})"


@dataclass(frozen=True)
class StepResult:
    """All solutions of one quasi-static step, in mode-enumeration order (sticking first)."""

    solutions: tuple[Solution, ...]

    @property
    def modes(self) -> tuple[Mode, ...]:
        """The distinct consistent modes."""
        return tuple(dict.fromkeys(s.mode for s in self.solutions))

    @property
    def ambiguous(self) -> bool:
        """More than one solution: Coulomb friction does not decide the motion."""
        return len(self.solutions) > 1

    @property
    def sticks(self) -> bool:
        """The only solution is every contact sticking: the push is stable at this instant."""
        return len(self.solutions) == 1 and all(m is ContactMode.STICK for m in self.solutions[0].mode)


def solve_step(support: SupportDistribution, contacts: Sequence[Contact], pusher_twist: ArrayLike) -> StepResult:
    """Every contact mode and slider twist consistent with quasi-static force balance.

    Parameters
    ----------
    support : SupportDistribution
        The slider's support points, slider frame.
    contacts : sequence of Contact
        Current pusher contacts, slider frame (one for a point pusher, two for a flat one).
    pusher_twist : (3,) array_like
        The pusher's twist ``(vx, vy, omega)`` expressed in the slider frame.

    Raises
    ------
    ValueError
        If there is no contact, the pusher twist is zero or has zero normal velocity at a
        contact, or the contact geometry is degenerate (module docstring).

    Examples
    --------
    A 2 x 1 block on a 3 x 3 grid, pushed along its bottom edge's normal through the CF by a flat
    pusher: both ends stick, the block moves with the pusher.

    >>> from mechanics.quasistatic import Contact
    >>> grid = [[x, y] for x in (-2 / 3, 0, 2 / 3) for y in (1 / 6, 1 / 2, 5 / 6)]
    >>> support = SupportDistribution(grid)
    >>> line = [Contact([-1.0, 0.0], [0, 1], 0.5), Contact([1.0, 0.0], [0, 1], 0.5)]
    >>> step = solve_step(support, line, [0.0, 1.0, 0.0])
    >>> step.sticks, step.solutions[0].twist.tolist()
    (True, [0.0, 1.0, 0.0])

    Pushed at 45 degrees to the right, beyond the friction cone (mu = 0.5): the pusher slides to
    the right along the block at both ends, the block moves along the cone's right edge:

    >>> solve_step(support, line, [1.0, 1.0, 0.0]).solutions
    (Solution(mode=(slide_right, slide_right), twist=[0.5, 1.0, 0.0]),)
    """
    return StepResult(tuple(_Problem(support, contacts, pusher_twist).solve()))


class _Line:
    """The twists ``V_p + s N`` of a one-parameter family as ``size * (base + tan(phi) N)``,
    ``base`` the unit part of ``V_p`` orthogonal to ``N``, with their loads on a grid of ``phi``."""

    def __init__(self, support: SupportDistribution, pusher_twist: np.ndarray, direction: np.ndarray):
        base = pusher_twist - (pusher_twist @ direction) * direction
        self.size = float(np.linalg.norm(base))  # > 0: the pusher presses at every contact
        self.base, self.direction = base / self.size, direction
        self.phis = np.linspace(-np.pi / 2, np.pi / 2, _SCAN + 1)
        self.loads = support.local_load(self.unit(self.phis))[0]

    def unit(self, phi: ArrayLike) -> np.ndarray:
        """Unit twist directions at angle(s) ``phi``: ``cos(phi) base + sin(phi) N``."""
        phi = np.asarray(phi)[..., None]
        return np.cos(phi) * self.base + np.sin(phi) * self.direction

    def twist(self, phi: float) -> np.ndarray:
        return self.size * (self.base + np.tan(phi) * self.direction)


def _pattern(mode: Mode) -> tuple[str, ...]:
    """What a mode's kinematic equalities depend on: stick, slide (either way) or separate."""
    return tuple("slide" if m in (ContactMode.SLIDE_LEFT, ContactMode.SLIDE_RIGHT) else m.value for m in mode)


class _Problem:
    """One step in the support's local frame (see :mod:`.support`)."""

    def __init__(self, support: SupportDistribution, contacts: Sequence[Contact], pusher_twist: ArrayLike):
        if len(contacts) == 0:
            raise ValueError("need at least one contact")
        self.support = support
        self.contacts = tuple(contacts)
        self.pusher_twist = np.array(pusher_twist, dtype=float)
        if self.pusher_twist.shape != (3,) or not np.all(np.isfinite(self.pusher_twist)):
            raise ValueError("pusher twist must be three finite numbers (vx, vy, omega)")
        points = support.to_local_points([c.point for c in contacts])
        self.normal_rows = point_wrench(points, [c.normal for c in contacts])  # u . n = row . (V - V_p)
        self.tangent_rows = point_wrench(points, [c.tangent for c in contacts])
        self.cones = [{m: point_wrench(p, c.force_directions(m)) for m in ContactMode}
                      for p, c in zip(points, contacts)]
        self.vp = support.to_local_twist(self.pusher_twist)
        self.speed = float(np.linalg.norm(self.vp))
        pressing = self.normal_rows @ self.vp
        if self.speed == 0 or np.any(np.abs(pressing) <= TOL * self.speed):
            raise ValueError("the pusher twist must move every contact point along its normal")
        self._families: dict[tuple[str, ...], np.ndarray] = {}
        self._lines: dict[tuple[str, ...], _Line] = {}

    # -- modes -----------------------------------------------------------------------------------

    def solve(self) -> list[Solution]:
        out = []
        for mode in product(ContactMode, repeat=len(self.contacts)):
            out += [Solution(mode, v) for v in self._solve_mode(mode)]
        return out

    def _family(self, mode: Mode) -> np.ndarray:
        """Orthonormal basis ``(3, d)`` of the relative twists ``V - V_p`` meeting the mode's
        kinematic equalities; shared by the modes that differ only in slip directions."""
        key = _pattern(mode)
        if key not in self._families:
            rows = []
            for j, m in enumerate(mode):
                if m is not ContactMode.SEPARATE:
                    rows.append(self.normal_rows[j])
                if m is ContactMode.STICK:
                    rows.append(self.tangent_rows[j])
            self._families[key] = scipy.linalg.null_space(np.array(rows).reshape(-1, 3), rcond=TOL)
        return self._families[key]

    def _solve_mode(self, mode: Mode) -> list[np.ndarray]:
        """Slider twists (slider frame) consistent with ``mode``."""
        family = self._family(mode)
        generators = np.concatenate([cone[m] for cone, m in zip(self.cones, mode)]).T  # (3, k)
        d, k = family.shape[1], generators.shape[1]
        if d == 0:
            # V = V_p: nothing slides or separates, so only all-stick can hold; return the
            # pusher's twist itself (no round trip through the local frame).
            stick = all(m is ContactMode.STICK for m in mode)
            return [self.pusher_twist.copy()] if stick and self._in_cone(generators, self.vp) else []
        if d == 3:
            candidates = [np.zeros(3)]  # no contact force: only a motionless slider balances
        elif d == 1 and k == 2:
            candidates = self._line_roots(mode, generators)
        elif d == 2 and k == 1:
            candidates = self._ray_twist(mode, generators[:, 0])
        else:
            raise ValueError(f"degenerate contact geometry for mode {[m.value for m in mode]} (d={d}, k={k})")
        return [self.support.from_local_twist(v) for v in candidates if self._kinematics_hold(mode, v)]

    def _kinematics_hold(self, mode: Mode, twist: np.ndarray) -> bool:
        """The strict inequalities of ``mode`` (its equalities hold by construction)."""
        rel = twist - self.vp
        normal, tangent = self.normal_rows @ rel, self.tangent_rows @ rel
        tol = TOL * max(self.speed, float(np.linalg.norm(twist)))
        holds = {ContactMode.SLIDE_LEFT: tangent > tol, ContactMode.SLIDE_RIGHT: tangent < -tol,
                 ContactMode.SEPARATE: normal > tol}
        return all(holds[m][j] for j, m in enumerate(mode) if m is not ContactMode.STICK)

    # -- force balance at a known twist ----------------------------------------------------------

    def _in_cone(self, generators: np.ndarray, twist: np.ndarray) -> bool:
        """Is some load of local ``twist`` a non-negative combination of ``generators``?"""
        load, at_rest = self.support.local_load(twist)
        if not at_rest.any():
            return scipy.optimize.nnls(generators, load)[1] <= TOL
        # COR on support point(s): each adds any force of norm <= w_k through it (inscribed polygon).
        angles = 2 * np.pi * np.arange(_FACET_SIDES) / _FACET_SIDES
        circle = np.stack([np.cos(angles), np.sin(angles)], axis=1)
        facets = [-w * point_wrench(x, circle).T for x, w in
                  zip(self.support.local_points[at_rest], self.support.weights[at_rest])]
        k, n_f = generators.shape[1], len(facets)
        a_eq = np.hstack([generators, *facets])
        a_ub = np.zeros((n_f, a_eq.shape[1]))
        for i in range(n_f):
            a_ub[i, k + i * _FACET_SIDES: k + (i + 1) * _FACET_SIDES] = 1.0  # convex combination
        result = scipy.optimize.linprog(np.zeros(a_eq.shape[1]), A_ub=a_ub, b_ub=np.ones(n_f), A_eq=a_eq, b_eq=load,
                         bounds=(0, None), method="highs")
        return result.status == 0

    # -- d = 1: a line of twists, the load on a plane --------------------------------------------

    def _line_roots(self, mode: Mode, generators: np.ndarray) -> list[np.ndarray]:
        """Twists of the mode's line whose load is a non-negative combination of the two
        generators (module docstring)."""
        normal = np.cross(generators[:, 0], generators[:, 1])
        if np.linalg.norm(normal) <= TOL:
            raise ValueError("degenerate contact geometry: parallel contact wrenches")
        normal /= np.linalg.norm(normal)
        line = self._line(mode)

        def side(phi: float) -> float:
            return float(self.support.local_load(line.unit(phi))[0] @ normal)

        h = line.loads @ normal
        out = []
        for i in np.flatnonzero((h[:-1] > 0) != (h[1:] > 0)):
            a, b = line.phis[i], line.phis[i + 1]
            ha, hb = side(a), side(b)
            # The scan's loads are batched, so a root on a grid point may have lost its sign here.
            phi = scipy.optimize.brentq(side, a, b, xtol=1e-14) if ha * hb < 0 else (a if abs(ha) <= abs(hb) else b)
            if np.cos(phi) <= TOL:
                continue  # the twist would be infinite
            twist = line.twist(phi)
            if self._in_cone(generators, twist):
                out.append(twist)
        return out

    def _line(self, mode: Mode) -> _Line:
        """The mode's line of twists with the loads on the scan grid; shared like :meth:`_family`."""
        key = _pattern(mode)
        if key not in self._lines:
            self._lines[key] = _Line(self.support, self.vp, self._family(mode)[:, 0])
        return self._lines[key]

    # -- d = 2: one sliding contact --------------------------------------------------------------

    def _ray_twist(self, mode: Mode, generator: np.ndarray) -> list[np.ndarray]:
        """The twist whose load is along ``generator``, scaled so the sliding contact keeps the
        pusher's normal velocity (a positive scale: the load's sign is fixed)."""
        j = next(j for j, m in enumerate(mode) if m is not ContactMode.SEPARATE)
        twist = self.support.local_twist_for(generator)
        moved, pushed = self.normal_rows[j] @ twist, self.normal_rows[j] @ self.vp
        if moved * pushed <= 0 or abs(moved) <= TOL * np.linalg.norm(twist):
            return []
        return [pushed / moved * twist]
