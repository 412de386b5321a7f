"""StableSteering: the unit control box mapped onto an edge's stable twists.

Checked against independent reasoning: containment (the region and the oracle.Reference test),
the documented normalisation (contact midpoint advances at unit speed along the normal),
onto-ness by nearest-image search that must improve as the u-grid is refined, continuity,
symmetry of fixture A, degenerate and empty regions.
"""

from __future__ import annotations

import numpy as np
import pytest

import oracle as O
from mechanics import Slider, StableSteering, stable_region

RECT = [[-1, 0], [1, 0], [1, 1], [-1, 1]]


def cases(seed, count):
    rng = np.random.default_rng(seed)
    out = []
    while len(out) < count:
        g = O.random_geometry(rng)
        region = stable_region(Slider(g["vertices"], cf=g["cf"]), g["edge"], g["mu"], width=g["width"])
        if region.is_empty:
            continue
        ref = O.Reference(g["vertices"], g["cf"], g["edge"], g["mu"], g["width"], 1.02)
        out.append((g, region, ref))
    return out


CASES = cases(31, 24)


def u_grid(n):
    s = np.linspace(0, 1, n + 1)
    return np.stack(np.meshgrid(s, s, indexing="ij"), axis=-1)  # (n+1, n+1, 2): [i, j] = (s_i, s_j)


def directions(T, r):
    T = np.asarray(T, float) * np.array([1.0, 1.0, r])
    return T / np.linalg.norm(T, axis=-1, keepdims=True)


def test_fixture_a_straight_push_at_the_centre():
    """Fixture A is mirror-symmetric, so the centroid of the box's image is the straight push;
    scaled so the contact midpoint (0, 0) moves at unit speed along n = (0, 1)."""
    region = stable_region(Slider(RECT), 0, 0.5)
    steer = StableSteering(region)
    for u1 in (0.0, 0.3, 0.77, 1.0):
        np.testing.assert_allclose(steer.twist([u1, 0.0]), [0, 1, 0], atol=1e-12)


@pytest.mark.parametrize("k", range(4))
def test_every_image_is_stable(k):
    rng = np.random.default_rng(40 + k)
    for g, region, ref in CASES[k::4]:
        steer = StableSteering(region)
        u = np.vstack([u_grid(24).reshape(-1, 2), rng.random((500, 2))])
        T = steer.twist(u)
        assert T.shape == (len(u), 3)
        assert region.contains(T).all()
        margin, band = ref.twist_margin(T)  # the independent test agrees
        assert np.all(margin >= -band)
        # documented scale: the contact midpoint advances at unit speed along the normal
        m = (ref.eL + ref.eR) / 2
        np.testing.assert_allclose(O.velocity_at(T, m) @ ref.n, 1.0, atol=1e-9)


@pytest.mark.parametrize("k", range(4))
def test_onto(k):
    """Every stable direction is approached by images of a u-grid, better on finer grids."""
    rng = np.random.default_rng(50 + k)
    for g, region, ref in CASES[k::4]:
        steer = StableSteering(region)
        E = region.extremal_twists() * np.array([1, 1, ref.r])
        mixes = rng.dirichlet(np.full(len(E), 0.5), size=200) @ E / np.array([1, 1, ref.r])
        T = O.random_twists(rng, ref, 1500)
        targets = np.vstack([mixes, T[region.contains(T)], region.extremal_twists()])
        D = directions(targets, ref.r)
        errs = []
        for n in (12, 48):
            Im = directions(steer.twist(u_grid(n).reshape(-1, 2)), ref.r)
            errs.append(np.arccos(np.clip(D @ Im.T, -1, 1)).min(axis=1).max())
        assert errs[1] < 0.6 * errs[0] or errs[1] < 1e-3, errs
        assert errs[1] < 0.15, errs


def test_onto_fixture_corners_exactly_reached():
    """Fixture A: the four extremal directions are images of boundary controls (u2 = 1)."""
    region = stable_region(Slider(RECT), 0, 0.5)
    steer = StableSteering(region)
    u = np.column_stack([np.linspace(0, 1, 4001), np.ones(4001)])
    Im = directions(steer.twist(u), region.scale)
    D = directions(region.extremal_twists(), region.scale)
    assert np.arccos(np.clip(D @ Im.T, -1, 1)).min(axis=1).max() < 2e-3


@pytest.mark.parametrize("k", range(2))
def test_continuity(k):
    """Adjacent controls give nearby twists: the largest jump halves when the grid is refined;
    u1 = 0 and u1 = 1 are the same boundary point; u2 = 0 is a single point (the centre)."""
    for g, region, ref in CASES[k::6]:
        steer = StableSteering(region)
        jumps = []
        for n in (100, 200):
            D = directions(steer.twist(u_grid(n)), ref.r)
            d1 = np.arccos(np.clip(np.sum(D[1:] * D[:-1], -1), -1, 1)).max()
            d2 = np.arccos(np.clip(np.sum(D[:, 1:] * D[:, :-1], -1), -1, 1)).max()
            jumps.append(max(d1, d2))
        assert jumps[1] < 0.7 * jumps[0], jumps
        s = np.linspace(0, 1, 11)
        np.testing.assert_allclose(steer.twist(np.column_stack([np.zeros(11), s])),
                                   steer.twist(np.column_stack([np.ones(11), s])), atol=1e-9)
        centre = steer.twist(np.column_stack([s, np.zeros(11)]))
        np.testing.assert_allclose(centre, np.broadcast_to(centre[0], centre.shape), atol=1e-12)


def test_vectorised_shapes():
    steer = StableSteering(stable_region(Slider(RECT, cf=[0.4, 0.3]), 0, 0.5))
    u = np.random.default_rng(0).random((4, 5, 2))
    T = steer.twist(u)
    assert T.shape == (4, 5, 3)
    np.testing.assert_allclose(T[2, 3], steer.twist(u[2, 3]), atol=1e-14)


def test_empty_region_raises():
    off_centre = Slider(RECT, cf=[0.9, 0.5])
    with pytest.raises(ValueError):
        StableSteering(stable_region(off_centre, 0, 0.5, width=0.5))
    fixture_e = Slider([(-1, 0), (0.5, 0), (1, 0), (1, 1), (-1, 1)], cf=(0.8, 0.5))
    with pytest.raises(ValueError):
        StableSteering(stable_region(fixture_e, 0, 0.5, tip_factor=1.0))


def test_single_translation_region():
    """F holds exactly one pure force (CF at 0.25 right of e_R = (0.5, 0), h = 0.5, mu = 0.5):
    the only stable push is the translation tilted by -atan(0.5), i.e. velocity (1, 2)/sqrt(5)."""
    s = Slider([(-1, 0), (0.5, 0), (1, 0), (1, 1), (-1, 1)], cf=(0.75, 0.5))
    region = stable_region(s, 0, 0.5, tip_factor=1.0)
    steer = StableSteering(region)
    T = steer.twist(np.random.default_rng(1).random((50, 2)))
    np.testing.assert_allclose(T, np.broadcast_to([0.5, 1.0, 0.0], T.shape), atol=1e-12)
    assert region.contains(T).all()
