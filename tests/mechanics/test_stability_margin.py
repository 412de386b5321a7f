"""Certified stability margins (mechanics.stability_margin) against independent reasoning.

Sources of truth, none of them the code under test:
* ``oracle.guaranteed_stable`` / ``oracle.LPOracle``: linear programmes over explicit support
  distributions on a grid of the part, and Theorem 4 re-derived (tests/oracle.py imports nothing
  of ``mechanics``). The oracle takes one CF, so a disk of CFs is sampled on its rim and centre;
* similarity and mirror invariance of the mechanics;
* the exact region's boundary, where some margin must run out.
"""

from __future__ import annotations

import numpy as np
import pytest
import shapely

import oracle as O
from mechanics import Slider, exact_region, procedure_stable, push_margins

PARTS = O.PARTS  # fixtures A, B, D, an L and a random convex part (tests/oracle.py)


def slider(g: dict) -> Slider:
    return Slider(g["vertices"], cf=g["cf"])


def probes(g: dict) -> np.ndarray:
    """STABLE's centroid (deep inside the stable set) and points a fifth beyond three of STABLE's
    vertices from it (STABLE is an inner bound: some of these are stable, some not)."""
    region = procedure_stable(slider(g), g["edge"], g["mu"], g["width"])
    polygon, centre = region.section()
    ring = np.asarray(polygon.exterior.coords)[:-1]
    picks = ring[:: max(1, len(ring) // 3)][:3]
    return region.plane.twists(np.vstack([centre, centre + 1.2 * (picks - centre)]))


CACHE: dict[tuple[str, float], tuple] = {}


def margins(name: str, rho: float = 0.0):
    if (name, rho) not in CACHE:
        g = PARTS[name]
        twists = probes(g)
        CACHE[name, rho] = twists, push_margins(slider(g), g["edge"], twists, g["mu"], g["width"], cf_radius=rho)
    return CACHE[name, rho]


def rim(cf: np.ndarray, radius: float, count: int) -> np.ndarray:
    angle = 2 * np.pi * np.arange(count) / count
    return np.asarray(cf, float) + radius * np.stack([np.cos(angle), np.sin(angle)], axis=1)


def stable_at(g: dict, cf: np.ndarray, mu: float, twist: np.ndarray) -> bool:
    return O.guaranteed_stable(g["vertices"], cf, g["edge"], mu, g["width"], twist)


def violation(g: dict, cf: np.ndarray, mu: float, twist: np.ndarray) -> float:
    """The oracle's worst sticking violation over distributions on a finer grid (> 0: slips)."""
    ref = O.Reference(g["vertices"], cf, g["edge"], mu, width=g["width"])
    return O.LPOracle(ref, O.support_samples(g["vertices"], 20)).max_violation(twist)


@pytest.mark.parametrize("name, rho", [(n, 0.0) for n in PARTS] + [("A", 0.1), ("B", 0.05)])
def test_margins_hold_in_the_lp_oracle(name, rho):
    """At friction ``mu_low`` every CF of the scene's disk (its rim and centre) sticks; at the
    nominal friction every CF of the reported disk does; and the pushes keep to Theorem 4's strip."""
    g = PARTS[name]
    twists, m = margins(name, rho)
    certified = np.flatnonzero(~np.isnan(m.mu_low))
    assert 0 in certified and len(certified) >= 2, m  # the centroid, and some beyond STABLE
    part = shapely.Polygon(g["vertices"])
    for k in certified:
        scene = [g["cf"], *(rim(g["cf"], rho, 8) if rho else [])]
        assert all(stable_at(g, cf, m.mu_low[k], twists[k]) for cf in scene), (k, m.mu_low[k])
        disk = [g["cf"], *rim(g["cf"], m.cf_radius[k], 8)]
        # The reported radius never exceeds the CF's depth in the part: its rim lies in the part.
        assert shapely.contains_xy(part.buffer(1e-9), *np.transpose(disk)).all()
        assert all(stable_at(g, cf, g["mu"], twists[k]) for cf in disk), (k, m.cf_radius[k])


@pytest.mark.parametrize("name", list(PARTS))
def test_a_push_deep_inside_has_substantial_margins(name):
    """STABLE's centroid keeps at least half the friction and a disk of at least half the CF's
    depth in the part: the margins are not trivially small."""
    _, m = margins(name)
    assert m.friction_margin[0] >= 0.5, m.mu_low[0]
    assert m.cf_radius[0] >= 0.5 * slider(PARTS[name]).cf_depth, m.cf_radius[0]


@pytest.mark.parametrize("name", list(PARTS))
def test_margins_are_close_to_where_the_oracle_slips(name):
    """A fifth below ``mu_low`` (where it is more than two rungs), and on the rim two rungs beyond
    the reported radius (where the search stopped short of the CF's depth in the part, and that
    rim lies mostly in the part), the oracle finds a distribution that breaks sticking: the bounds
    are not loose."""
    g = PARTS[name]
    twists, m = margins(name)
    part = shapely.Polygon(g["vertices"])
    depth = slider(g).cf_depth
    tested = 0
    for k in np.flatnonzero(~np.isnan(m.mu_low)):
        if m.mu_low[k] > 2 * m.mu_step:
            assert violation(g, g["cf"], 0.8 * m.mu_low[k], twists[k]) > 1e-9, (k, m.mu_low[k])
            tested += 1
        beyond = rim(g["cf"], m.cf_radius[k] + 2 * m.radius_step, 12)
        beyond = beyond[shapely.contains_xy(part, *beyond.T)]
        if m.cf_radius[k] < depth and len(beyond) >= 6:
            assert max(violation(g, cf, g["mu"], twists[k]) for cf in beyond) > 1e-9, (k, m.cf_radius[k])
            tested += 1
    assert tested >= 2


def test_invariant_under_scaling_and_shifting():
    """Scaling the part scales the CF margin and leaves the friction margin (the support grids
    scale with the part); shifting it changes nothing (they are anchored at the CF)."""
    g = PARTS["D"]
    twists, m = margins("D")
    scale, shift = 0.02, np.array([3.0, -2.0])
    moved = Slider(scale * g["vertices"] + shift, cf=scale * g["cf"] + shift)
    there = push_margins(moved, g["edge"], O.transform_twist(twists, scale, np.eye(2), shift), g["mu"])
    np.testing.assert_allclose(there.mu_low, m.mu_low, rtol=1e-12)
    np.testing.assert_allclose(there.cf_radius, scale * m.cf_radius, rtol=1e-9)
    assert np.isnan(m.mu_low).any() and not np.isnan(m.mu_low).all()  # both kinds of probe were compared


def test_mirror_symmetry():
    """The mirror image of a part pushed with the mirror image of a twist has the same margins."""
    g = PARTS["B"]
    twists, m = margins("B")
    flip = np.diag([-1.0, 1.0])
    mirrored = Slider(g["vertices"] @ flip, cf=g["cf"] @ flip)
    there = push_margins(mirrored, g["edge"], O.transform_twist(twists, 1.0, flip, np.zeros(2)), g["mu"])
    np.testing.assert_allclose(there.mu_low, m.mu_low, rtol=1e-12)
    np.testing.assert_allclose(there.cf_radius, m.cf_radius, rtol=1e-12)


@pytest.mark.parametrize("name, rho", [("A", 0.0), ("B", 0.0), ("B", 0.05)])
def test_the_exact_regions_boundary_has_no_margin_left(name, rho):
    """Every vertex of the exact region at ``(mu, rho)`` is certified there (its margins reach
    ``mu`` and ``rho``) and lies on the boundary of what friction or CF uncertainty allows: within
    two rungs of losing one or the other (a friction-limited vertex may keep a wide CF margin,
    and the other way round)."""
    g = PARTS[name]
    part = slider(g)
    region = exact_region(part, g["edge"], g["mu"], g["width"], cf_radius=rho, rays=16)
    polygon, _ = region.section()
    twists = region.plane.twists(np.asarray(polygon.exterior.coords)[:-1])
    m = push_margins(part, g["edge"], twists, g["mu"], g["width"], cf_radius=rho)
    assert len(twists) >= 16
    assert np.all(m.mu_low <= g["mu"]) and np.all(m.cf_radius >= rho)  # NaN fails both
    left = np.minimum(m.friction_margin, (m.cf_radius - rho) / part.radius)
    assert np.all(left <= 2 / 64), left


def test_rejects_bad_arguments():
    part = slider(PARTS["A"])
    for kwargs, message in [(dict(mu=0.0), "mu"), (dict(mu=0.5, cf_radius=-0.1), "cf_radius"),
                            (dict(mu=0.5, rungs=0), "rungs")]:
        with pytest.raises(ValueError, match=message):
            push_margins(part, 0, [[0, 1, 0]], **kwargs)


def test_a_friction_rung_of_its_own_is_reported_exactly_where_it_is_certified():
    """A push tilted by tan = 0.2 on the square's face needs mu >= 0.2 (its load, a force along
    the motion, leaves the cone below): an extra rung at 0.201 is certified and reported, one at
    0.199 is not, and the ladder's own rung above (26/128) is."""
    from mechanics import Slider, push_margins

    square = Slider([[-1, 0], [1, 0], [1, 2], [-1, 2]])
    tilted = [[-0.2, 1, 0]]
    assert push_margins(square, 0, tilted, 0.5, width=0.5, mu_rung=0.201).mu_low.tolist() == [0.201]
    assert push_margins(square, 0, tilted, 0.5, width=0.5, mu_rung=0.199).mu_low.tolist() == [26 / 128]
    with pytest.raises(ValueError):
        push_margins(square, 0, tilted, 0.5, mu_rung=0.6)
