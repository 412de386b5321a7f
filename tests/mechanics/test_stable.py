"""Procedure STABLE (mechanics.stable) against independent reasoning.

Sources of truth, none of them the code under test:
* the hand-derived fixtures A-E and the membership table of docs/mechanics.md, "Fixtures", "Membership table";
* ``oracle.Reference``: the conditions re-written from docs/mechanics.md, "Procedure STABLE";
* ``oracle.LPOracle``: the exact V_F test of docs/mechanics.md, "Exact LP oracle" (linear programs over support distributions);
* invariances (mirror, rigid motion, scaling, winding) and monotonicity in mu.
"""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from scipy.optimize import nnls

import oracle as O
from mechanics import DEFAULT_TIP_FACTOR, Slider, cor_to_twist, stable_region

RECT = [[-1, 0], [1, 0], [1, 1], [-1, 1]]
# D and E: the contact is only part of the bottom edge, so extra collinear vertices make the pushed
# edge exactly [e_L, e_R] (the edge stays on the hull, so it is pushable).
D_VERTS = [(-2, 0), (-0.5, 0), (1, 0), (2, 0), (2, 1), (-2, 1)]
E_VERTS = [(-1, 0), (0.5, 0), (1, 0), (1, 1), (-1, 1)]

# docs/mechanics.md, "Fixtures" (values given to 4-5 significant digits there).
FIXTURES = {
    "A": dict(vertices=RECT, cf=(0, 0.5), edge=0, mu=0.5, contact=[(-1, 0), (1, 0)], r=1.1180,
              ccw=[(-2, 0.5)], cw=[(2, 0.5)], theta=26.565),
    "B": dict(vertices=RECT, cf=(0.4, 0.3), edge=0, mu=0.5, contact=[(-1, 0), (1, 0)], r=1.5652,
              ccw=[(-4.1111, -0.5556), (-3.2667, 1.1333)], cw=[(2.12, 0.44), (2.0968, 0.5484)], theta=26.565),
    "C": dict(vertices=RECT, cf=(0, 0.5), edge=0, mu=1.0, contact=[(-1, 0), (1, 0)], r=1.1180,
              ccw=[(-1.5, 0.5)], cw=[(1.5, 0.5)], theta=45.0),
    "D": dict(vertices=D_VERTS, cf=(0.6, 0.5), edge=1, mu=0.8, contact=[(-0.5, 0), (1, 0)], r=2.6476,
              ccw=[(-9.775, 6.22)], cw=[(9.4571, -4.9657), (5.8133, 3.0507)], theta=38.660),
    "E": dict(vertices=E_VERTS, cf=(0.8, 0.5), edge=0, mu=0.5, contact=[(-1, 0), (0.5, 0)], r=1.8682,
              ccw=[], cw=[], theta=None),
}


def fixture_region(name, tip_factor=1.0):
    f = FIXTURES[name]
    slider = Slider(f["vertices"], cf=f["cf"])
    return slider, stable_region(slider, f["edge"], f["mu"], tip_factor=tip_factor)


def fixture_reference(name, tip_factor=1.0):
    f = FIXTURES[name]
    return O.Reference(f["vertices"], f["cf"], f["edge"], f["mu"], None, tip_factor)


def build(g, tip_factor=DEFAULT_TIP_FACTOR, **over):
    """(region, reference) for a random-geometry dict (see oracle.random_geometry)."""
    g = {**g, **over}
    region = stable_region(Slider(g["vertices"], cf=g["cf"]), g["edge"], g["mu"], width=g["width"],
                           tip_factor=tip_factor)
    ref = O.Reference(g["vertices"], g["cf"], g["edge"], g["mu"], g["width"], tip_factor)
    return region, ref


def geometries(seed, count, nonempty=False, kind=None):
    rng = np.random.default_rng(seed)
    out = []
    while len(out) < count:
        g = O.random_geometry(rng, kind)
        if nonempty and O.Reference(g["vertices"], g["cf"], g["edge"], g["mu"], g["width"]).translation_interval() is None:
            continue
        out.append(g)
    return out


def same_points(a, b, atol):
    a, b = np.asarray(a, float).reshape(-1, 2), np.asarray(b, float).reshape(-1, 2)
    if len(a) != len(b):
        return False
    return all(np.min(np.hypot(*(b - p).T)) <= atol for p in a) and all(
        np.min(np.hypot(*(a - p).T)) <= atol for p in b)


def unit_dirs(T, r):
    """Twist directions with omega scaled to a speed (scale-free angles)."""
    T = np.asarray(T, float) * np.array([1.0, 1.0, r])
    return T / np.linalg.norm(T, axis=-1, keepdims=True)


# ----------------------------------------------------------------------------------------------
# Fixtures A-E of docs/mechanics.md, "Fixtures" (tip_factor = 1.0)


def test_collinear_vertices_make_a_partial_contact_edge():
    """D's slider: 4 x 1 block whose bottom edge is split so that edge 1 is exactly the contact."""
    s = Slider(D_VERTS, cf=(0.6, 0.5))
    assert s.pushable_edges == tuple(range(6))  # collinear splits stay on the hull
    assert s.edge(1).tolist() == [[-0.5, 0.0], [1.0, 0.0]]
    assert s.inward_normal(1).tolist() == [0.0, 1.0]
    assert s.area == pytest.approx(4.0)


@pytest.mark.parametrize("name", "ABCDE")
def test_fixture_contact_and_radius(name):
    f = FIXTURES[name]
    slider, region = fixture_region(name)
    assert slider.radius == pytest.approx(f["r"], abs=1e-4)
    np.testing.assert_allclose(region.contact, f["contact"], atol=1e-12)  # ordered e_L, e_R
    np.testing.assert_allclose(region.normal, [0, 1], atol=1e-12)


@pytest.mark.parametrize("name", "ABCDE")
@pytest.mark.parametrize("sense", [1, -1])
def test_fixture_cor_vertices(name, sense):
    f = FIXTURES[name]
    _, region = fixture_region(name)
    got = region.cor_vertices(sense)
    want = f["ccw"] if sense > 0 else f["cw"]
    assert got.shape == (len(want), 2)
    assert same_points(got, want, atol=6e-4), (got, want)


def test_fixture_a_apex_exact():
    """Hand derivation: S1 is -x + 2y >= 3 (vertex (-1, 1)), S2 is x + 2y <= -1 (vertex (-1, 0))."""
    _, region = fixture_region("A")
    np.testing.assert_allclose(region.cor_vertices(1), [[-2.0, 0.5]], atol=1e-12)
    np.testing.assert_allclose(region.cor_vertices(-1), [[2.0, 0.5]], atol=1e-12)
    _, region_c = fixture_region("C")  # mu = 1: -x + y >= 2, x + y <= -1
    np.testing.assert_allclose(region_c.cor_vertices(1), [[-1.5, 0.5]], atol=1e-12)


@pytest.mark.parametrize("name", "ABCD")
def test_fixture_translation_range(name):
    f = FIXTURES[name]
    _, region = fixture_region(name)
    lo, hi = np.degrees(region.translation_range)
    assert lo == pytest.approx(-f["theta"], abs=1e-3)
    assert hi == pytest.approx(f["theta"], abs=1e-3)
    assert not region.is_empty


def test_translation_range_limited_by_contact_end_and_sign_convention():
    """4 x 1 block, CF (0.6, 0.5), mu 0.8, a pusher of width 1.5 centred on the bottom edge.

    Contact [-0.75, 0.75]. The force line through the CF along a push tilted by theta towards -t
    meets the contact line at x = 0.6 + 0.5 tan(theta), which must stay <= 0.75: tan <= 0.3.
    On the other side friction limits: theta >= -atan(0.8).
    """
    s = Slider([[-2, 0], [2, 0], [2, 1], [-2, 1]], cf=(0.6, 0.5))
    region = stable_region(s, 0, 0.8, width=1.5, tip_factor=1.0)
    np.testing.assert_allclose(region.contact, [[-0.75, 0], [0.75, 0]], atol=1e-12)
    lo, hi = region.translation_range
    assert lo == pytest.approx(-np.arctan(0.8), abs=1e-12)
    assert hi == pytest.approx(np.arctan(0.3), abs=1e-12)
    # theta > 0 is tilted towards -t: the push (-sin a, cos a) has theta = a, (sin a, cos a) has -a.
    a = 0.35
    assert not region.contains([-np.sin(a), np.cos(a), 0.0])
    assert region.contains([np.sin(a), np.cos(a), 0.0])
    assert region.contains([-np.sin(0.28), np.cos(0.28), 0.0])


def test_fixture_e_is_empty():
    slider, region = fixture_region("E")
    assert region.is_empty
    assert region.translation_range is None
    assert region.cor_vertices(1).shape == (0, 2) and region.cor_vertices(-1).shape == (0, 2)
    assert region.extremal_twists().shape == (0, 3)
    ref = fixture_reference("E")
    assert ref.translation_interval() is None  # no pure force in F (Prop. 6)
    rng = np.random.default_rng(0)
    T = O.random_twists(rng, ref, 4000)
    assert not region.contains(T).any()
    assert not (ref.twist_margin(T)[0] >= 0).any()  # the reference agrees: nothing at all
    polys = region.cor_polygons()
    assert polys[1].is_empty and polys[-1].is_empty


# docs/mechanics.md, "Membership table": (case, COR, sense, STABLE, exact V_F)
TABLE = [
    ("A", (-3, 0.5), 1, True, True),
    ("A", (-3, 1.2), 1, False, True),
    ("A", (-1.5, 0.5), 1, False, True),
    ("A", (-3, 0.5), -1, False, False),
    ("A", (10, 0.5), -1, True, True),
    ("B", (-5, 0.3), 1, True, True),
    ("B", (-3.5, 0.3), 1, False, True),
    ("B", (2.05, 0.5), -1, False, True),
    ("B", (6, -1), -1, True, True),
    ("D", (-12, 6), 1, True, True),
    ("D", (-12, 3), 1, False, True),
    ("D", (5.5, 3), -1, False, True),
]


@pytest.mark.parametrize("name, cor, sense, stable, exact", TABLE)
def test_membership_table(name, cor, sense, stable, exact):
    _, region = fixture_region(name)
    assert bool(region.contains(cor_to_twist(cor, sense))) is stable
    # the independent reference agrees, and the LP oracle reproduces the "exact" column
    ref = fixture_reference(name)
    assert bool(ref.cor_is_stable(np.array(cor, float), sense)) is stable
    lp = O.LPOracle(ref, O.support_samples(FIXTURES[name]["vertices"], 14))
    assert (lp.max_violation(O.twist_of_cor(np.array(cor, float), sense)) <= 1e-9) is exact


def test_contains_is_scale_free_and_rejects_zero():
    _, region = fixture_region("A")
    V = np.array([[0, 3, 1], [0, 1, 0], [0.2, 1, 0]])
    np.testing.assert_array_equal(region.contains(V), region.contains(V * 1e-6))
    np.testing.assert_array_equal(region.contains(V), region.contains(V * 1e6))
    assert not region.contains([0.0, 0.0, 0.0])
    assert not region.contains([0, -1, 0])  # pulling
    assert region.contains(np.zeros((2, 5, 3))).shape == (2, 5)


# ----------------------------------------------------------------------------------------------
# Agreement with the independent reference on random geometries


@pytest.mark.parametrize("seed", range(8))
def test_contains_matches_reference(seed):
    rng = np.random.default_rng(100 + seed)
    n_stable = n_total = 0
    for g in geometries(1000 + seed, 25):
        region, ref = build(g, tip_factor=1.02)
        T = O.random_twists(rng, ref, 1200)
        margin, band = ref.twist_margin(T)
        got = region.contains(T)
        bad = (got != (margin >= 0)) & (np.abs(margin) > band)
        assert not bad.any(), (g, T[bad][:5], margin[bad][:5], got[bad][:5])
        n_stable += int((margin >= 0).sum())
        n_total += len(T)
        # the translation interval and emptiness agree too
        want = ref.translation_interval()
        if want is None:
            assert region.is_empty
        else:
            np.testing.assert_allclose(region.translation_range, want, atol=1e-12)
    assert 0.05 < n_stable / n_total < 0.6  # the sample probes both sides of the boundary


@pytest.mark.parametrize("seed", range(4))
def test_cor_vertices_match_brute_force(seed):
    """Corners = pairwise intersections of the four lines that satisfy all four conditions."""
    for g in geometries(2000 + seed, 20):
        region, ref = build(g)
        for sense in (1, -1):
            want = ref.corners(sense)
            got = region.cor_vertices(sense)
            assert same_points(got, want, atol=1e-7 * (1 + np.abs(want).max(initial=0))), (g, sense, got, want)


def test_translations_are_the_limit_of_far_cors():
    """docs/mechanics.md, "Translations and extremal twists": a CCW COR at cf + R rho (CW: cf - R rho), R -> inf, gives the
    translation (rho_y, -rho_x)."""
    for g in geometries(77, 15, nonempty=True):
        region, ref = build(g)
        lo, hi = region.translation_range
        if hi - lo < 1e-3:
            continue
        thetas = np.r_[np.linspace(lo, hi, 7)[1:-1], lo - 0.05 * (hi - lo), hi + 0.05 * (hi - lo)]
        inside = np.r_[np.ones(5, bool), False, False]
        v = ref.translation(thetas)[:, :2]
        rho = np.column_stack([-v[:, 1], v[:, 0]])
        R = 1e5 * ref.r
        np.testing.assert_array_equal(region.contains(np.column_stack([v, np.zeros(len(v))])), inside)
        for sense, c in ((1, ref.cf + R * rho), (-1, ref.cf - R * rho)):
            far = region.contains(cor_to_twist(c, sense))
            np.testing.assert_array_equal(far, inside)
            np.testing.assert_array_equal(ref.cor_is_stable(c, sense), far)


# ----------------------------------------------------------------------------------------------
# Invariances and monotonicity


def check_same_region(region_a, region_b, T_a, T_b, ref_a):
    """contains agrees on corresponding twists, except within the boundary band."""
    margin, band = ref_a.twist_margin(T_a)
    far = np.abs(margin) > band
    np.testing.assert_array_equal(region_a.contains(T_a)[far], region_b.contains(T_b)[far])
    assert region_a.contains(T_a)[far].any()  # non-vacuous


@pytest.mark.parametrize("seed", range(3))
def test_mirror_symmetry_swaps_senses(seed):
    """Reflect across the normal line through the edge midpoint: CCW <-> CW, theta -> -theta."""
    rng = np.random.default_rng(300 + seed)
    for g in geometries(3000 + seed, 12, nonempty=True):
        region, ref = build(g)
        V = g["vertices"]
        a, b = V[g["edge"]], V[(g["edge"] + 1) % len(V)]
        m, t = (a + b) / 2, ref.t
        M = np.eye(2) - 2 * np.outer(t, t)
        off = m - M @ m
        gm = {**g, "vertices": V @ M.T + off, "cf": M @ g["cf"] + off}
        region_m, _ = build(gm)
        T = O.random_twists(rng, ref, 800)
        check_same_region(region, region_m, T, O.transform_twist(T, 1.0, M, off), ref)
        for sense in (1, -1):
            assert same_points(region.cor_vertices(sense) @ M.T + off, region_m.cor_vertices(-sense), 1e-8)
        lo, hi = region.translation_range
        np.testing.assert_allclose(region_m.translation_range, (-hi, -lo), atol=1e-12)
        np.testing.assert_allclose(region_m.contact, (region.contact @ M.T + off)[::-1], atol=1e-12)


def test_mirror_symmetric_fixture_is_symmetric():
    _, region = fixture_region("A")
    for c in ([-3, 0.5], [-2.5, 0.2], [-5, 2], [-2.1, 0.5], [-1.9, 0.5]):
        assert region.contains(cor_to_twist(c, 1)) == region.contains(cor_to_twist([-c[0], c[1]], -1))


@pytest.mark.parametrize("seed", range(3))
def test_rigid_motion_invariance(seed):
    rng = np.random.default_rng(400 + seed)
    for g in geometries(4000 + seed, 12):
        region, ref = build(g)
        R = O.rot(rng.uniform(0, 2 * np.pi))
        b = rng.uniform(-10, 10, size=2)
        region_w, _ = build({**g, "vertices": g["vertices"] @ R.T + b, "cf": R @ g["cf"] + b})
        if ref.translation_interval() is None:
            assert region_w.is_empty
            continue
        T = O.random_twists(rng, ref, 800)
        check_same_region(region, region_w, T, O.transform_twist(T, 1.0, R, b), ref)
        for sense in (1, -1):
            assert same_points(region.cor_vertices(sense) @ R.T + b, region_w.cor_vertices(sense), 1e-8)
        np.testing.assert_allclose(region_w.translation_range, region.translation_range, atol=1e-12)
        np.testing.assert_allclose(region_w.normal, R @ region.normal, atol=1e-12)


@pytest.mark.parametrize("s", [0.01, 0.25, 7.0, 1000.0])
def test_scaling_invariance(s):
    """Scaling the part by s scales every COR by s; translations are unchanged."""
    rng = np.random.default_rng(int(s * 100) + 5)
    for g in geometries(5000, 12, nonempty=True):
        region, ref = build(g)
        w = None if g["width"] is None else g["width"] * s
        region_s, _ = build({**g, "vertices": g["vertices"] * s, "cf": g["cf"] * s, "width": w})
        T = O.random_twists(rng, ref, 800)
        check_same_region(region, region_s, T, O.transform_twist(T, s, np.eye(2), np.zeros(2)), ref)
        for sense in (1, -1):
            assert same_points(region.cor_vertices(sense) * s, region_s.cor_vertices(sense), 1e-9 * s * 100)
        np.testing.assert_allclose(region_s.translation_range, region.translation_range, atol=1e-12)


def test_extremal_twists_contained_for_large_parts():
    for s in (1.0, 1e3):
        for g in geometries(5100, 10, nonempty=True):
            region, _ = build({**g, "vertices": g["vertices"] * s, "cf": g["cf"] * s,
                               "width": None if g["width"] is None else g["width"] * s})
            assert region.contains(region.extremal_twists()).all()


def test_extremal_twists_contained_for_millimetre_block():
    """Fixture B scaled to a 2 mm x 1 mm block (metres): its corners must still be contained."""
    s = 1e-3
    slider = Slider(np.array(RECT, float) * s, cf=np.array([0.4, 0.3]) * s)
    region = stable_region(slider, 0, 0.5, tip_factor=1.0)
    assert region.contains(region.extremal_twists()).all()


def test_extremal_twists_contained_for_centimetre_parts():
    """Random parts of 1-5 cm, in metres (the paper's objects are ~30 mm)."""
    bad = 0
    for g in geometries(5000, 12, nonempty=True):
        s = 0.01
        region, _ = build({**g, "vertices": g["vertices"] * s, "cf": g["cf"] * s,
                           "width": None if g["width"] is None else g["width"] * s})
        bad += not region.contains(region.extremal_twists()).all()
    assert bad == 0


@pytest.mark.parametrize("seed", range(3))
def test_monotone_in_mu(seed):
    rng = np.random.default_rng(600 + seed)
    for g in geometries(6000 + seed, 12):
        mu1 = g["mu"]
        mu2 = mu1 * rng.uniform(1.05, 3.0)
        region1, ref1 = build(g)
        region2, _ = build(g, mu=mu2)
        T = O.random_twists(rng, ref1, 1000)
        margin, band = ref1.twist_margin(T)
        in1 = region1.contains(T) & (margin > band)
        assert region2.contains(T[in1]).all()
    # strict growth in fixture A -> C (mu 0.5 -> 1.0): the apex moves from (-2, .5) to (-1.5, .5)
    _, a = fixture_region("A")
    _, c = fixture_region("C")
    probe = cor_to_twist([[-1.7, 0.5], [1.7, 0.5]], [1, -1])
    assert not a.contains(probe).any() and c.contains(probe).all()
    assert c.contains([np.sin(0.7), np.cos(0.7), 0]) and not a.contains([np.sin(0.7), np.cos(0.7), 0])


@pytest.mark.parametrize("seed", range(2))
def test_winding_invariance(seed):
    """Reversed vertex order: the physical edge (v_i, v_i+1) becomes edge n - 2 - i (mod n)."""
    rng = np.random.default_rng(700 + seed)
    for g in geometries(7000 + seed, 15):
        region, ref = build(g)
        n = len(g["vertices"])
        region_r, _ = build({**g, "vertices": g["vertices"][::-1], "edge": (n - 2 - g["edge"]) % n})
        np.testing.assert_allclose(region_r.normal, region.normal, atol=1e-12)
        np.testing.assert_allclose(region_r.contact, region.contact, atol=1e-12)
        if region.is_empty:
            assert region_r.is_empty
            continue
        T = O.random_twists(rng, ref, 600)
        np.testing.assert_array_equal(region.contains(T), region_r.contains(T))
        for sense in (1, -1):
            assert same_points(region.cor_vertices(sense), region_r.cor_vertices(sense), 1e-9)
        np.testing.assert_allclose(region_r.translation_range, region.translation_range, atol=1e-14)


# ----------------------------------------------------------------------------------------------
# Soundness against the exact LP oracle (docs/mechanics.md, "Exact LP oracle") and Theorem 4


def soundness_cases():
    cases = {
        "A": dict(vertices=np.array(RECT, float), cf=np.array([0, 0.5]), edge=0, mu=0.5, width=None),
        "B": dict(vertices=np.array(RECT, float), cf=np.array([0.4, 0.3]), edge=0, mu=0.5, width=None),
    }
    cases["L"] = geometries(11, 1, nonempty=True, kind="L")[0]
    cases["L-short-edge"] = {**O.random_geometry(np.random.default_rng(3), "L"), "edge": 5, "mu": 1.2}  # w 0.16
    cases["convex"] = geometries(12, 1, nonempty=True, kind="convex")[0]
    return cases


SOUNDNESS = soundness_cases()


@pytest.mark.parametrize("name", list(SOUNDNESS))
def test_accepted_twists_are_sound(name):
    g = SOUNDNESS[name]
    region, ref = build(g, tip_factor=DEFAULT_TIP_FACTOR)
    assert not region.is_empty
    far = [np.abs(ref.corners(s) - ref.cf).max(initial=0) for s in (1, -1)]
    w = max(6 * ref.r, 1.3 * max(far))
    xs = np.linspace(ref.cf[0] - w, ref.cf[0] + w, 25)
    ys = np.linspace(ref.cf[1] - w, ref.cf[1] + w, 25)
    C = np.array([(x, y) for x in xs for y in ys])
    grid = [cor_to_twist(C, 1), cor_to_twist(C, -1)]
    for sense in (1, -1):  # a finer grid around each COR region's corners
        K = ref.corners(sense)
        if len(K):
            lo, hi = K.min(axis=0) - 2 * ref.r, K.max(axis=0) + 2 * ref.r
            C2 = np.array([(x, y) for x in np.linspace(lo[0], hi[0], 15) for y in np.linspace(lo[1], hi[1], 15)])
            grid.append(cor_to_twist(C2, sense))
    grid = np.vstack(grid)
    accepted = grid[region.contains(grid)]
    assert len(accepted) >= 10
    # Theorem 4: accepted CORs lie beyond the part's extent along t (CCW left, CW right)
    tV = g["vertices"] @ ref.t
    ccw, cw = accepted[accepted[:, 2] > 0], accepted[accepted[:, 2] < 0]
    assert len(ccw) and len(cw)
    assert np.all(np.column_stack([-ccw[:, 1], ccw[:, 0]]) / ccw[:, 2:] @ ref.t <= tV.min() + 1e-9)
    assert np.all(np.column_stack([-cw[:, 1], cw[:, 0]]) / cw[:, 2:] @ ref.t >= tV.max() - 1e-9)
    # boundary twists: corners, translations across the interval, pairwise mixtures of corners
    E = region.extremal_twists()
    lo, hi = region.translation_range
    pairs = [(1 - a) * E[i] + a * E[j] for i in range(len(E)) for j in range(i + 1, len(E)) for a in (0.25, 0.5)]
    mixes = np.random.default_rng(0).dirichlet(np.ones(len(E)), size=30) @ E
    twists = np.vstack([accepted, E, ref.translation(np.linspace(lo, hi, 9)), pairs, mixes])
    assert region.contains(twists).all()
    lp = O.LPOracle(ref, O.support_samples(g["vertices"], 12))
    assert len(lp.facets) == 4
    worst = np.array([lp.max_violation(v) for v in twists])
    assert worst.max() <= 1e-9, (twists[np.argmax(worst)], worst.max())


def test_lp_oracle_has_teeth():
    """The oracle rejects twists outside V_F: it can fail.

    (1) Translations just outside the friction cone: the wrench is the pure force along the push,
    outside F for every distribution. (2) Fixture B (docs/mechanics.md, "Checks of STABLE"): CORs violating only S1, or
    only S2, on a grid: a good part of them have a distribution pushing the wrench out of F.
    (Note: CORs *just* outside S1/S2 are still in the exact V_F; the exact boundary lies ~0.35-1.2
    beyond S1/S2 in B, so the points are taken on a grid, as in the note.)
    """
    ref = fixture_reference("A")
    lp = O.LPOracle(ref, O.support_samples(RECT, 12))
    for th in (ref.alpha + 0.02, -ref.alpha - 0.02):
        assert lp.max_violation(ref.translation(th)) > 1e-3
    assert lp.max_violation(ref.translation(ref.alpha - 0.02)) <= 1e-9

    ref = fixture_reference("B")
    _, region = fixture_region("B")
    lp = O.LPOracle(ref, O.support_samples(RECT, 12))
    C = np.array([(x, y) for x in np.linspace(-8, 8, 17) for y in np.linspace(-6, 6, 13)])
    for sense in (1, -1):
        m = ref.cor_margins(C, sense)
        for k in (0, 1):  # S1 only / S2 only (primed for CW)
            only = (m[:, k] < 0) & np.all(np.delete(m, k, axis=1) >= 0, axis=1)
            pts = C[only][:: max(1, only.sum() // 6)][:6]
            assert len(pts) >= 4
            assert not region.contains(cor_to_twist(pts, sense)).any()
            viol = [lp.max_violation(O.twist_of_cor(c, sense)) for c in pts]
            assert max(viol) > 1e-4, (sense, k, pts, viol)


# ----------------------------------------------------------------------------------------------
# Extremal twists


def test_extremal_twists_fixture_a():
    _, region = fixture_region("A")
    E = region.extremal_twists()
    a = np.arctan(0.5)
    want = np.array([[0, 2, 1], [np.sin(a), np.cos(a), 0], [-np.sin(a), np.cos(a), 0], [0, 2, -1]])
    assert E.shape == (4, 3)
    # documented order: CCW corners, the two end translations, CW corners
    assert E[0, 2] > 0 and E[1, 2] == 0 and E[2, 2] == 0 and E[3, 2] < 0
    # MECHANICS gives them CF-relative (CF at the origin): move the twists' reference point to the CF
    E_cf = O.transform_twist(E, 1.0, np.eye(2), -np.array(FIXTURES["A"]["cf"], float))
    ang = O.angle_between(E_cf[:, None, :], want[None, :, :])
    assert np.all(ang.min(axis=1) < 1e-7) and np.all(ang.min(axis=0) < 1e-7)
    # scaling: |omega| = 1 for rotations, unit speed for translations
    np.testing.assert_allclose(np.abs(E[[0, 3], 2]), 1.0)
    np.testing.assert_allclose(np.linalg.norm(E[[1, 2], :2], axis=1), 1.0)


@pytest.mark.parametrize("seed", range(3))
def test_extremal_twists_generate_the_region(seed):
    rng = np.random.default_rng(800 + seed)
    for g in geometries(8000 + seed, 12, nonempty=True):
        region, ref = build(g)
        E = region.extremal_twists()
        assert region.contains(E).all()
        # same set as the brute-force corners plus the translation interval's ends
        lo, hi = ref.translation_interval()
        want = np.vstack([O.twist_of_cor(ref.corners(1), 1).reshape(-1, 3),
                          ref.translation(np.unique([lo, hi])),
                          O.twist_of_cor(ref.corners(-1), -1).reshape(-1, 3)])
        assert len(E) == len(want)
        ang = O.angle_between(unit_dirs(E, ref.r)[:, None], unit_dirs(want, ref.r)[None])
        assert np.all(ang.min(axis=1) < 1e-7) and np.all(ang.min(axis=0) < 1e-7)
        # every contained twist is a non-negative combination of the extremal twists
        T = O.random_twists(rng, ref, 1500)
        T = T[region.contains(T)]
        assert len(T) > 20
        Es = E * np.array([1, 1, ref.r])
        for v in T * np.array([1, 1, ref.r]):
            _, res = nnls(Es.T, v)
            assert res <= 1e-8 * np.linalg.norm(v)
        # and every non-negative combination is contained (the region is a convex cone)
        mix = rng.dirichlet(np.ones(len(E)), size=200) @ E
        assert region.contains(mix).all()
        # each extremal twist is a genuine corner: not a combination of the others
        if len(E) > 1:
            for i in range(len(E)):
                others = np.delete(Es, i, axis=0)
                _, res = nnls(others.T, Es[i])
                assert res > 1e-6 * np.linalg.norm(Es[i])


# ----------------------------------------------------------------------------------------------
# COR polygons


@pytest.mark.parametrize("case", ["A", "B", "D", "random"])
def test_cor_polygons(case):
    rng = np.random.default_rng(9)
    if case == "random":
        items = [build(g) for g in geometries(9000, 6, nonempty=True)]
    else:
        items = [(fixture_region(case, DEFAULT_TIP_FACTOR)[1], fixture_reference(case, DEFAULT_TIP_FACTOR))]
    n_in = 0
    for region, ref in items:
        c, w = ref.cf, 8 * ref.r
        window = (c[0] - w, c[1] - w, c[0] + w, c[1] + 0.8 * w)
        polys = region.cor_polygons(window)
        P = rng.uniform(window[:2], window[2:], size=(3000, 2))
        box = shapely.box(*window)
        for sense in (1, -1):
            poly = polys[sense]
            if case != "random":
                assert poly.area > 0
            assert poly.is_empty or box.buffer(1e-9).contains(poly)
            inside = shapely.contains_xy(poly, P[:, 0], P[:, 1])
            dist = shapely.distance(poly.boundary, shapely.points(P))
            clear = dist > 1e-7 * ref.r
            got = region.contains(cor_to_twist(P, sense))
            np.testing.assert_array_equal(got[clear], inside[clear])
            np.testing.assert_array_equal(ref.cor_is_stable(P, sense)[clear], inside[clear])
            assert case == "random" or inside[clear].sum() > 10
            n_in += int(inside[clear].sum())
    assert n_in > 100
    # default window: square of half-side 4 r about the CF
    _, region = fixture_region("A")
    r = np.hypot(1, 0.5)
    assert region.cor_polygons()[1].bounds[0] == pytest.approx(-4 * r)
