"""Which controllability a scene's stable pushes give (Lynch & Mason 1996, §2-3; docs/mechanics.md, "Controllability").

The controls are the extremal stable twists of each allowed edge (the corners of its region,
whose positive combinations hold the whole region, Prop. 3), decided by
:func:`mechanics.controllability`. Without switching (the ``transit`` option ``none``) a plan
keeps one edge, so each edge counts alone; otherwise the edges' twists are pooled.

One edge alone is never small-time locally controllable (the paper: it cannot pull back). Every
stable twist of an edge pushes the contact's midpoint ``m`` into the part, ``a(v) = (v_xy + omega
k x m) . n > 0`` with ``n`` the inward normal (:class:`mechanics.push_plane.PushPlane` has
``a = 1``), so ``a`` is positive on all of the edge's cone but zero at its apex: the cone holds no
line, let alone the great circle of Prop. 4.
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import combinations

import numpy as np

from mechanics import Controllability, controllability as twist_controllability

from ..model.fields import SceneError
from ..actions.controls import edge_controls
from ..model.margin import EXACT, Margin
from ..model.options import DEFAULT_REGIONS, DEFAULT_TRANSIT
from ..model.scene import Scene

__all__ = ["SceneControllability", "controllability"]


@dataclass(frozen=True)
class SceneControllability:
    """A scene's controllability by stable pushes.

    Attributes
    ----------
    per_edge : dict
        Each allowed edge with stable pushes mapped to its :class:`mechanics.Controllability` alone.
    empty : tuple of int
        The allowed edges without any stable push (left out).
    union : Controllability
        All of ``per_edge``'s twists together: what switching edges gives.
    stlc_edges : tuple of int
        Edges whose union is STLC: a pair if one is (the first in order), else an inclusion-minimal
        set; empty if even the union is not.
    switching : bool
        Whether the plan may change edge (the ``transit`` option is not ``'none'``).
    opposite : bool
        Whether ``stlc_edges`` are two parallel faces pushed from either side.
    """

    per_edge: dict[int, Controllability]
    empty: tuple[int, ...]
    union: Controllability
    stlc_edges: tuple[int, ...]
    switching: bool
    opposite: bool

    @property
    def alone(self) -> tuple[int, ...]:
        """The edges that each make the part controllable on their own."""
        return tuple(e for e, c in self.per_edge.items() if c.controllable)

    @property
    def controllable(self) -> bool:
        """Controllable in the obstacle-free plane with the pushes a plan may use (Prop. 2)."""
        return self.union.controllable if self.switching else bool(self.alone)

    @property
    def stlc(self) -> bool:
        """Small-time locally controllable with the pushes a plan may use (Prop. 4); never with
        one edge (module docstring)."""
        return self.switching and self.union.stlc

    def summary(self) -> str:
        """One line: what the part is, and with which edges.

        >>> from planner import load_scene
        >>> print(controllability(load_scene("scenes/battery.yaml")).summary())
        controllable (edge 3); not small-time locally controllable: one edge never is (it cannot pull back)
        """
        if not self.per_edge:
            return f"not accessible: no allowed edge has a stable push ({_edges(self.empty)})"
        if not self.controllable:
            line = "not accessible: " + (self.union.reason.removeprefix("not accessible: ") if self.switching
                                         else "no edge alone is (Prop. 1) and transit none keeps to one edge")
        else:
            line = (f"controllable ({_edges(self.alone)})" if self.alone
                    else f"controllable ({_edges(tuple(self.per_edge))} together)")
            if self.stlc:
                line += (f"; small-time locally controllable with {_edges(self.stlc_edges)}"
                         + (" (opposite faces)" if self.opposite else ""))
            elif len(self.per_edge) == 1:
                line += "; not small-time locally controllable: one edge never is (it cannot pull back)"
            elif not self.switching:
                line += ("; not small-time locally controllable: transit none keeps to one edge, which never is"
                         + (f" ({_edges(self.stlc_edges)} would be with switching)" if self.stlc_edges else ""))
            else:
                line += "; not small-time locally controllable (no union of edges positively spans a great circle)"
        if self.empty:
            line += f"; {_edges(self.empty)} {'has' if len(self.empty) == 1 else 'have'} no stable push"
        return line


def controllability(scene: Scene, *, regions: str = DEFAULT_REGIONS,
                    transit: str = DEFAULT_TRANSIT, margin: Margin = EXACT) -> SceneControllability:
    """The controllability the scene's allowed edges give by stable pushes.

    Parameters
    ----------
    scene : Scene
    regions : str
        The ``regions`` option: the stable pushes of ``'exact'`` regions or procedure ``'stable'``.
    transit : str
        The ``transit`` option: ``'none'`` keeps one edge per plan.
    margin : Margin
        The stability margin the pushes keep (the ``margin`` option; default: none).

    Returns
    -------
    SceneControllability

    Raises
    ------
    SceneError
        If procedure STABLE is asked for with an uncertain CF (:func:`planner.actions.controls.edge_controls`).

    Examples
    --------
    >>> from planner import load_scene
    >>> c = controllability(load_scene("scenes/parking.yaml"))
    >>> c.controllable, c.stlc, c.stlc_edges
    (True, True, (0, 2))
    >>> print(c.summary())
    controllable (edges 0, 1, 2, 3); small-time locally controllable with edges 0 and 2 (opposite faces)
    """
    scene.one_part("controllability")
    try:
        pushes = edge_controls(scene, regions=regions, margin=margin)
    except SceneError as err:
        if err.field == "planner.regions":  # a refused method, not a finding about the edges
            raise
        pushes = []  # no allowed edge has a stable push
    twists = {p.edge: p.region.extremal_twists() for p in pushes}
    per_edge = {e: twist_controllability(v) for e, v in twists.items()}
    union = twist_controllability(np.vstack([np.zeros((0, 3)), *twists.values()]))
    stlc_edges = _stlc_edges(twists) if union.stlc else ()
    normals = [scene.slider.inward_normal(e) for e in stlc_edges]
    opposite = len(normals) == 2 and float(normals[0] @ normals[1]) < -1.0 + 1e-9
    return SceneControllability(per_edge, tuple(e for e in scene.edges if e not in twists), union,
                                stlc_edges, transit != "none", opposite)


def _stlc_edges(twists: dict[int, np.ndarray]) -> tuple[int, ...]:
    """Edges whose union is STLC, given that all of them together are: the first pair that is,
    else all of them less each edge whose removal keeps it (STLC only grows with the set)."""
    def stlc(edges: tuple[int, ...]) -> bool:
        return twist_controllability(np.vstack([twists[e] for e in edges])).stlc

    pair = next((p for p in combinations(twists, 2) if stlc(p)), None)
    if pair is not None:
        return pair
    edges = tuple(twists)
    for e in twists:
        if stlc(trial := tuple(f for f in edges if f != e)):
            edges = trial
    return edges


def _edges(edges: tuple[int, ...]) -> str:
    """``edge 3``, ``edges 0 and 2``, ``edges 0, 1, 2, 3``."""
    if len(edges) == 1:
        return f"edge {edges[0]}"
    if len(edges) == 2:
        return f"edges {edges[0]} and {edges[1]}"
    return "edges " + ", ".join(map(str, edges))
