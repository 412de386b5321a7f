"""The batched support LPs (mechanics.support.LoadBatch, mechanics.simplex.batched_simplex) against HiGHS.

Until issue 10 every support value of a certification was one HiGHS linear programme (or a Qhull
hull) per twist and direction, and every impossibility proof one more (the minimax LP); now a
whole batch is solved at once by a small simplex method in numpy. Sources of truth, none of them
the code under test:

* scipy's HiGHS on the same discrete LPs, written out here from their definition: the primal over
  distributions on the samples (centroid at the CF, or anywhere in the 32-gon of centres with an
  uncertain CF) and its dual, whose multiplier feeds the certificate as the old code's did, and
  the minimax LP as the old code posed it;
* the independent LP oracle over explicit distributions (tests/oracle.py) for every P verdict on
  which the two computations disagree.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import linprog

import brute_force as B
import oracle as O
from mechanics import (
    ContactConfiguration,
    Slider,
    SupportModel,
    contact_wrench_cone,
    cor_to_twist,
    force_possible,
    force_status,
    procedure_stable,
)
from mechanics.simplex import batched_simplex
from mechanics.support import CF_DIRECTIONS

TRAPEZOID = Slider([[-1.2, 0], [1.0, 0], [0.6, 0.9], [-0.5, 1.1]], cf=(-0.1, 0.45))
BLOCK = Slider([[-1, 0], [1, 0], [1, 1], [-1, 1]], cf=(0.3, 0.4))
CENTRES = np.stack([np.cos(a := 2 * np.pi * np.arange(CF_DIRECTIONS) / CF_DIRECTIONS), np.sin(a)], axis=1)
REFERENCE = json.loads((Path(__file__).resolve().parents[1] / "data" / "exact_regions_v2.json").read_text())
#: HiGHS's default feasibility tolerances (1e-7) leave its optima off by 1e-8: ask for the digits.
TIGHT = {"primal_feasibility_tolerance": 1e-10, "dual_feasibility_tolerance": 1e-10}


def highs_primal(h, x, cf, rho):
    """max sum s_i h_i over s >= 0, sum s = 1, sum s_i (x_i - cf) = rho sum nu_j e_j, nu >= 0, sum nu = 1."""
    n = len(x)
    a_eq = np.block([[np.ones((1, n)), np.zeros((1, CF_DIRECTIONS))],
                     [(x - cf).T, -rho * CENTRES.T],
                     [np.zeros((1, n)), np.ones((1, CF_DIRECTIONS))]])
    res = linprog(np.r_[-h, np.zeros(CF_DIRECTIONS)], A_eq=a_eq, b_eq=[1.0, 0, 0, 1.0], bounds=(0, None), method="highs",
                  options=TIGHT)
    assert res.status == 0, res.message
    return -res.fun


def highs_dual(h, x, cf, rho):
    """min t + rho u over t >= h_i + lam . (x_i - cf), u >= -lam . e_j: ``(value, lam)``."""
    n = len(x)
    a_ub = np.r_[np.c_[-np.ones(n), x - cf, np.zeros(n)], np.c_[np.zeros(CF_DIRECTIONS), -CENTRES, -np.ones(CF_DIRECTIONS)]]
    res = linprog([1.0, 0.0, 0.0, rho], A_ub=a_ub, b_ub=np.r_[-h, np.zeros(CF_DIRECTIONS)],
                  bounds=[(None, None)] * 3 + [(0, None)], method="highs", options=TIGHT)
    assert res.status == 0, res.message
    return res.x[0] + rho * res.x[3], res.x[1:3]


def twists_about(rng, support, n):
    """CORs from inside the support to far away, both senses, and some translations."""
    c = support.cf + support.radius * rng.normal(size=(n, 2)) * rng.choice([0.5, 1.5, 4.0], (n, 1))
    angle = rng.uniform(0, 2 * np.pi, n // 4)
    return np.vstack([cor_to_twist(c, rng.choice([-1, 1], n)), np.c_[np.cos(angle), np.sin(angle), np.zeros(n // 4)]])


@pytest.mark.parametrize("rho", [0.0, 0.05])
@pytest.mark.parametrize("kind", ["disk", "footprint"])
@pytest.mark.parametrize("level", [0, 1])
def test_support_values_and_multipliers_match_highs(kind, rho, level):
    """One batch of twists and directions: every value is HiGHS's optimum of the discrete LP, and
    every multiplier certifies it (the sample loads lie under ``value - rho |lam|_32`` after the
    centroid term), as HiGHS's dual does. A COR inside the support adds a sample there whose
    friction points the best way, so the value can only be higher than without it."""
    rng = np.random.default_rng(int(10 * rho) + 2 * level + (kind == "disk"))
    support = SupportModel.of_slider(TRAPEZOID, kind, cf_radius=rho)
    twists = twists_about(rng, support, 24)
    cone = contact_wrench_cone(ContactConfiguration.slider_edge(TRAPEZOID, 0, 0.6), "ss")
    ys = np.vstack([-cone.rows, rng.normal(size=(4, 3))])
    batch = support.batch(twists, level)
    values, lams = batch.sample_support(ys)
    x = support.cells(level).points
    for k, twist in enumerate(twists):
        g = B.loads(twist, x)
        for r, y in enumerate(ys):
            h = g @ y
            reference = highs_primal(h, x, support.cf, rho)
            if batch.cor_in_region[k]:
                assert values[k, r] >= reference - 1e-9
                continue
            assert values[k, r] == pytest.approx(reference, abs=1e-9 * (1 + abs(reference)))
            lam = lams[k, r]
            certified = np.max(h + (x - support.cf) @ lam) + rho * np.max(-CENTRES @ lam)
            assert certified == pytest.approx(values[k, r], abs=1e-9 * (1 + abs(reference)))


def highs_minimax(twist, rows, x, cf, rho):
    """The minimax LP as the old code gave it to HiGHS: over convex weights beta of ``rows``, a
    centroid multiplier lam and t (u >= 0 for the centre's 32-gon), minimise t + rho u subject to
    (beta . rows) . g(x_i) + lam . (x_i - cf) <= t and u >= -lam . e_j. ``(beta, lam, value)``."""
    k, n = len(rows), len(x)
    a_ub = np.r_[np.c_[B.loads(twist, x) @ rows.T, x - cf, -np.ones(n), np.zeros(n)],
                 np.c_[np.zeros((CF_DIRECTIONS, k)), -CENTRES, np.zeros(CF_DIRECTIONS), -np.ones(CF_DIRECTIONS)]]
    res = linprog(np.r_[np.zeros(k + 2), 1.0, rho], A_ub=a_ub, b_ub=np.zeros(len(a_ub)),
                  A_eq=np.r_[np.ones(k), np.zeros(4)][None], b_eq=[1.0],
                  bounds=[(0, None)] * k + [(None, None)] * 3 + [(0, None)], method="highs", options=TIGHT)
    assert res.status == 0, res.message
    return res.x[:k], res.x[k:k + 2], res.fun


@pytest.mark.parametrize("rho", [0.0, 0.05])
@pytest.mark.parametrize("kind", ["disk", "footprint"])
@pytest.mark.parametrize("mode", ["ss", "sf", "rr"])
def test_minimax_matches_highs(mode, kind, rho):
    """The separating-hyperplane LP of the I proofs, batched: HiGHS's optimum for every twist,
    with weights on the simplex and a multiplier that certifies the value. CORs inside the
    support are left out here (the sample there is a fan of friction directions on one side, a
    point on the other); the verdicts below cover them."""
    rng = np.random.default_rng(len(mode) + int(100 * rho) + (kind == "disk"))
    support = SupportModel.of_slider(BLOCK, kind, cf_radius=rho)
    twists = twists_about(rng, support, 30)
    rows = contact_wrench_cone(ContactConfiguration.slider_edge(BLOCK, 0, 0.6), mode).rows
    batch = support.batch(twists, 0)
    beta, lam, value = batch.minimax(rows)
    x = support.cells(0).points
    assert np.all(beta[~batch.cor_in_region] >= -1e-9) and np.allclose(beta[~batch.cor_in_region].sum(axis=1), 1.0)
    for k in np.flatnonzero(~batch.cor_in_region):
        _, _, reference = highs_minimax(twists[k], rows, x, support.cf, rho)
        assert value[k] == pytest.approx(reference, abs=1e-9 * (1 + abs(reference)))
        psi = B.loads(twists[k], x) @ (beta[k] @ rows) + (x - support.cf) @ lam[k]
        assert psi.max() + rho * np.max(-CENTRES @ lam[k]) == pytest.approx(value[k], abs=1e-9 * (1 + abs(reference)))


@pytest.mark.parametrize("kind", ["disk", "footprint"])
def test_verdicts_match_those_from_highs_lps(kind):
    """Full P / U / I verdicts (force_status) against the old computation rebuilt from HiGHS: each
    row's support LP refuting P or, through its multiplier, certifying it; the minimax LP's
    weights and multiplier proving I. CORs are drawn from inside the support to far away, so
    both models meet CORs among their samples. A degenerate LP may yield another optimal
    multiplier, so a verdict may differ rarely, but only between a proof and U."""
    rng = np.random.default_rng(12)
    support = SupportModel.of_slider(TRAPEZOID, kind)
    cone = contact_wrench_cone(ContactConfiguration.slider_edge(TRAPEZOID, 0, 0.6), "ss")
    tol = 1e-9 * (1.0 + np.linalg.norm(support.cf) + support.radius)
    twists = twists_about(rng, support, 80)
    twists = twists[twists[:, 2] != 0]  # translations need no LP

    def old_verdict(twist):
        consistent = {"P", "U", "I"}
        for level in (0, 1):
            loads = support.loads(twist, level)
            x = loads.batch.cells.points
            if loads.batch.cor_in_region[0]:  # the old samples' fan of friction directions at the COR
                cor = np.array([-twist[1], twist[0]]) / twist[2]
                fan = 2 * np.pi * np.arange(32) / 32
                x = np.vstack([x, cor + 1e-12 * np.c_[np.cos(fan), np.sin(fan)]])
            g = B.loads(twist, x)
            answers = [highs_dual(g @ -a, x, support.cf, 0.0) for a in cone.rows]
            refuted = any(value > tol for value, _ in answers)
            if not refuted and all(loads.upper_bound(-a, lam) <= 0 for a, (_, lam) in zip(cone.rows, answers)):
                return "P"
            beta, lam, value = highs_minimax(twist, cone.rows, x, support.cf, 0.0)
            if value < -tol and loads.is_negative(beta @ cone.rows, lam, tol):
                return "I"
            consistent -= {"P"} if refuted or value < -tol else set()
            consistent -= {"I"} if value >= -tol else set()
            if len(consistent) == 1:
                break
        return "U" if len(consistent) > 1 else consistent.pop()

    new = np.array([force_status(v, cone, support).status for v in twists])
    old = np.array([old_verdict(v) for v in twists])
    assert set(new) == {"P", "U", "I"}
    assert np.mean(new == old) >= 0.97, list(zip(new, old))
    assert all("U" in pair for pair in zip(new[new != old], old[new != old]))


def near_boundary(case, rng, count):
    """Push-plane points of a stored region scaled about its centre by 0.85 to 1.15: twists on
    both sides of its boundary, where certificates are tight."""
    ring = np.asarray(case["polygon"])[:-1]
    pick = ring[rng.integers(len(ring), size=count)]
    return np.asarray(case["centre"]) + rng.uniform(0.85, 1.15, (count, 1)) * (pick - case["centre"])


@pytest.mark.parametrize("name", ["A", "L", "junction:3", "nonconvex:1", "B-rho0.05", "corridor:3-rho0.004"])
def test_sticking_verdicts_match_those_from_highs_multipliers(name):
    """P (certified sticking) per twist near the region's boundary: the batched LPs' verdicts
    against the old computation's, each row's HiGHS value refuting and its HiGHS multiplier
    certifying at refinement levels 0 then 1. A degenerate LP has many optimal multipliers and
    the two may pick different ones, so a rare disagreement is allowed, but whichever says P must
    be right by the independent oracle."""
    case = next(c for c in REFERENCE["cases"] if c["name"] == name)
    slider = Slider(case["vertices"], cf=case["cf"])
    stable = procedure_stable(slider, case["edge"], case["mu"], case["width"])
    cone = contact_wrench_cone(ContactConfiguration.slider_edge(slider, case["edge"], case["mu"], case["width"]), "ss")
    support = SupportModel.of_slider(slider, "footprint", cf_radius=case["cf_radius"])
    twists = stable.plane.twists(near_boundary(case, np.random.default_rng(7), 60))
    tol = 1e-9 * (1.0 + np.linalg.norm(support.cf) + support.radius)

    def old_verdict(twist):
        for level in (0, 1):
            loads = support.loads(twist, level)
            x = loads.batch.cells.points
            g = B.loads(twist, x)
            answers = [highs_dual(g @ -a, x, support.cf, support.cf_radius) for a in cone.rows]
            if any(value > tol for value, _ in answers):
                return False
            if all(loads.upper_bound(-a, lam) <= 0 for a, (_, lam) in zip(cone.rows, answers)):
                return True
        return False

    new = force_possible(twists, cone, support)
    old = np.array([old_verdict(v) for v in twists])
    assert 0 < old.sum() < len(old)  # both sides of the boundary
    assert np.mean(new == old) >= 0.98, (new.astype(int), old.astype(int))
    differ = np.flatnonzero(new != old)
    cfs = [np.asarray(case["cf"]) + case["cf_radius"] * e for e in np.r_[np.zeros((1, 2)), CENTRES[::4]]]
    oracles = [O.LPOracle(O.Reference(np.asarray(case["vertices"]), cf, case["edge"], case["mu"], case["width"]),
                          O.support_samples(case["vertices"], 12)) for cf in cfs]
    for k in differ:
        assert max(lp.max_violation(twists[k]) for lp in oracles) <= 1e-9, twists[k]


def configurations():
    edge = ContactConfiguration.slider_edge(BLOCK, 0, 0.6)
    corner = ContactConfiguration([[0.4, 0.0], [-1.0, 0.7]], [[0, 1], [1, 0]], 0.4)
    return [(edge, "ss"), (edge, "sf"), (edge, "rr"), (corner, "ss"), (corner, "ls"), (edge, "ff")]


@pytest.mark.parametrize("rho", [0.0, 0.05])
@pytest.mark.parametrize("kind", ["disk", "footprint"])
def test_force_possible_is_force_status_p(kind, rho):
    """The batched verdict is the per-twist one (``force_status(...).status == 'P'``) for every
    twist of a batch: rotations, translations, CORs inside the support, and modes whose cone is
    a wedge, a plane or empty."""
    rng = np.random.default_rng(4)
    support = SupportModel.of_slider(BLOCK, kind, cf_radius=rho)
    twists = np.vstack([twists_about(rng, support, 40), procedure_stable(BLOCK, 0, 0.6).extremal_twists()])
    for config, mode in configurations():
        cone = contact_wrench_cone(config, mode)
        batched = force_possible(twists, cone, support)
        single = [force_status(v, cone, support).status == "P" for v in twists]
        assert batched.tolist() == single, mode
        assert force_possible(twists.reshape(-1, 2, 3), cone, support).shape == (len(twists) // 2, 2)


def test_degenerate_lps_converge_without_highs(monkeypatch):
    """The footprint grid runs through the CF, so the LPs are degenerate (a sample at the CF and
    others in line with it) and Dantzig's rule alone can cycle; with Bland's rule after a while
    every LP of a whole exact-region trace converges in the simplex, HiGHS never called."""
    import scipy.optimize

    from mechanics import exact_region

    def refuse(*args, **kwargs):
        raise AssertionError("HiGHS called")

    monkeypatch.setattr(scipy.optimize, "linprog", refuse)
    for name in ("corridor:0", "corridor:2", "cluttered:0", "B-rho0.05"):
        case = next(c for c in REFERENCE["cases"] if c["name"] == name)
        slider = Slider(case["vertices"], cf=case["cf"])
        assert exact_region(slider, case["edge"], case["mu"], case["width"], cf_radius=case["cf_radius"]).polygon.area > 0


def test_simplex_on_random_degenerate_lps():
    """Points of a small integer grid through the origin, integer costs (ties everywhere): the
    batched simplex finds HiGHS's optimum of every LP, and its duals are feasible."""
    rng = np.random.default_rng(9)
    x = np.array([(i, j) for i in range(-2, 3) for j in range(-2, 3)], dtype=float)
    columns = np.vstack([np.ones(len(x)), x.T])
    costs = rng.integers(-3, 4, size=(200, len(x))).astype(float)
    start = np.array([[i for i, p in enumerate(x.tolist()) if p in ([-2, -2], [2, -2], [0, 2])]] * 200)
    duals, unbounded, _ = batched_simplex(costs, columns, np.array([1.0, 0.0, 0.0]), start)
    assert not unbounded.any()
    for c, pi in zip(costs, duals):
        res = linprog(-c, A_eq=columns, b_eq=[1.0, 0.0, 0.0], bounds=(0, None), method="highs", options=TIGHT)
        assert pi[0] == pytest.approx(-res.fun, abs=1e-9)
        assert np.all(pi @ columns >= c - 1e-9)


@pytest.mark.parametrize("rho", [0.0, 0.05])
def test_warm_started_support_lps_find_highs_optimum(rho):
    """A model that has solved some twists starts the LPs of others from the optimal basis of the
    nearest one it kept, at the same level or lifted from the level below (whose samples are among
    this level's): the values are still HiGHS's optima of each discrete LP, for twists near and far
    from those solved before, a level finer too, and a degenerate start (a sample at the CF, where
    Dantzig's rule can cycle) still ends at the optimum."""
    rng = np.random.default_rng(33 + int(100 * rho))
    support = SupportModel.of_slider(TRAPEZOID, "footprint", cf_radius=rho)
    cone = contact_wrench_cone(ContactConfiguration.slider_edge(TRAPEZOID, 0, 0.6), "ss")
    ys = -cone.rows
    first = twists_about(rng, support, 8)
    support.batch(first, 1).sample_support(ys)  # kept for the warm starts below
    nearby = first + 0.01 * rng.normal(size=first.shape)
    for twists, level in ((nearby, 1), (twists_about(rng, support, 4), 1), (nearby, 2)):
        batch = support.batch(twists, level)
        values, _ = batch.sample_support(ys)
        x = support.cells(level).points
        for k in np.flatnonzero(~batch.cor_in_region):
            h = B.loads(twists[k], x) @ ys.T
            assert values[k] == pytest.approx([highs_primal(h[:, r], x, support.cf, rho) for r in range(len(ys))],
                                              abs=1e-9)


def test_a_warm_start_that_stalls_starts_again_cold(monkeypatch):
    """Points of an integer grid with one at the CF, costs that make the point mass at the CF
    optimal (a degenerate vertex): from three far corners one pivot does not reach the optimum,
    and the LP would go to HiGHS (here made to fail); with a restart from three points about the
    CF it reaches the optimum, 0, with feasible duals, in numpy alone."""
    import scipy.optimize

    def no_highs(*args, **kwargs):
        raise AssertionError("went to HiGHS")

    monkeypatch.setattr(scipy.optimize, "linprog", no_highs)
    x = np.array([(i, j) for i in range(-2, 3) for j in range(-2, 3)], dtype=float)
    columns = np.vstack([np.ones(len(x)), x.T])
    costs = -np.abs(x).sum(axis=1)[None]  # concave: all the weight at the CF (0, 0) is best, value 0
    far = np.array([[i for i, p in enumerate(x.tolist()) if p in ([-2, -2], [2, -2], [0, 2])]])
    near = np.array([[i for i, p in enumerate(x.tolist()) if p in ([-1, -1], [1, -1], [0, 1])]])
    rhs = np.array([1.0, 0.0, 0.0])
    with pytest.raises(AssertionError, match="HiGHS"):
        batched_simplex(costs, columns, rhs, far, limit=1)
    duals, _, _ = batched_simplex(costs, columns, rhs, far, limit=1, restart=near)
    assert duals[0] @ rhs == pytest.approx(0.0, abs=1e-12)
    assert np.all(duals[0] @ columns >= costs[0] - 1e-9)
