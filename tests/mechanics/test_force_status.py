"""Support friction and force status P / U / I (Lynch 1992, §3.2-3.4).

Sources of truth, none of them the code under test:
* the paper's statements (fig. 10b, a single line of force, translations never U, the four ray
  patterns, the disk model being looser than the footprint);
* the exact V_F column of docs/mechanics.md, "Membership table" for fixtures A, B, D, and procedure STABLE (already
  tested against it), whose pushes must all be P;
* explicit random support distributions and dense-point linear programmes (``brute_force``),
  for the soundness of every P and I verdict and of the bounds behind them;
* invariances: rigid motions, reflection, mu.
"""

from __future__ import annotations

import zlib

import numpy as np
import pytest
import shapely

import brute_force as B
from mechanics import (
    ContactConfiguration,
    Slider,
    SupportModel,
    contact_wrench_cone,
    cor_to_twist,
    effective_cf,
    force_status,
    force_status_regions,
    ray_twist,
    stable_region,
    support_friction,
    unit_loads,
)

RECT = [[-1, 0], [1, 0], [1, 1], [-1, 1]]
D_VERTS = [(-2, 0), (-0.5, 0), (1, 0), (2, 0), (2, 1), (-2, 1)]
BLOCK = Slider(RECT, cf=(0.3, 0.4))
TRAPEZOID = Slider([[-1.2, 0], [1.0, 0], [0.6, 0.9], [-0.5, 1.1]], cf=(-0.1, 0.45))


def region_of(support):
    return B.disk_region(support.cf, support.radius) if support.kind == "disk" else support.polygon


def random_cor_twists(rng, support, n):
    """Twists whose CORs are spread from inside the support to far away, both senses."""
    c = support.cf + support.radius * rng.normal(size=(n, 2)) * rng.choice([0.5, 1.5, 4.0], (n, 1))
    return cor_to_twist(c, rng.choice([-1, 1], n))


def near_possible_translations(rng, support, generators, n):
    """Twists close to translations whose load (through the CF) is a possible contact force: where
    P regions are (their CORs are far away, on either side)."""
    angle = np.linspace(0, 2 * np.pi, 360, endpoint=False)
    t = np.stack([np.cos(angle), np.sin(angle)], 1)
    good = t[[B.in_cone(B.wrench(support.cf, ti), generators, tol=1e-9) for ti in t]]
    if len(good) == 0:
        return np.zeros((0, 3))
    pick = good[rng.integers(len(good), size=n)]
    omega = rng.uniform(-0.4, 0.4, n) / support.radius  # the CF moves along t: COR >= 2.5 r away
    spin = np.array([-support.cf[1], support.cf[0]])
    return np.c_[pick - omega[:, None] * spin, omega]


# ----------------------------------------------------------------------------------------------
# Support friction, eqs. (1)-(6)


def test_friction_of_one_point_by_hand():
    """CW about (1, 1), unit weight at (1, 0): the point moves left with speed 1, friction pushes
    it right; moment about the COR = +mu_s * 1 (eq. 2, opposing the CW turn)."""
    w = support_friction(cor_to_twist([1, 1], -1), [[1.0, 0.0]], [1.0], mu_s=0.3)
    force, moment_about_cor = w[:2], w[2] - B.cross([1, 1], w[:2])
    np.testing.assert_allclose(force, [0.3, 0.0], atol=1e-15)
    assert moment_about_cor == pytest.approx(0.3)


@pytest.mark.parametrize("seed", range(5))
def test_effective_cf(seed):
    """Eqs. (3)-(6): the friction equals that of one point at CF_eff with weight |d|; CF_eff is at
    least as far from the COR as the CF; it depends neither on mu_s nor on the sense."""
    rng = np.random.default_rng(seed)
    x, w = rng.normal(size=(7, 2)), rng.random(7)
    c = rng.normal(size=2) * 2
    for sense in (1, -1):
        twist = cor_to_twist(c, sense)
        q = effective_cf(twist, x, w)
        rel = x - c
        d = np.linalg.norm(w @ (rel / np.linalg.norm(rel, axis=1, keepdims=True)))
        np.testing.assert_allclose(d * B.loads(twist, q[None])[0], w @ B.loads(twist, x), atol=1e-12)
        np.testing.assert_allclose(support_friction(twist, x, w, 0.7), -0.7 * w @ B.loads(twist, x), atol=1e-12)
        np.testing.assert_allclose(q, effective_cf(cor_to_twist(c, -sense), x, w), atol=1e-12)
        cf = w @ x / w.sum()
        assert np.linalg.norm(q - c) >= np.linalg.norm(cf - c) - 1e-12
    # A translation: the friction acts through the CF (Mason), so CF_eff = CF.
    np.testing.assert_allclose(effective_cf([1.0, 2.0, 0.0], x, w), w @ x / w.sum())


def test_unit_loads_match_the_written_out_loads():
    rng = np.random.default_rng(0)
    x = rng.normal(size=(50, 2))
    for twist in ([0.3, -1.0, 0.7], [1.0, 2.0, 0.0]):
        np.testing.assert_allclose(unit_loads(twist, x), B.loads(twist, x), atol=1e-14)


@pytest.mark.parametrize("kind", ["disk", "footprint"])
def test_cells_cover_the_region_and_samples_lie_in_it(kind):
    support = SupportModel.of_slider(TRAPEZOID, kind)
    for level in (0, 1):
        cells = support.cells(level)
        union = shapely.union_all([shapely.Polygon(cells.nodes[c]).convex_hull for c in cells.cells])
        assert union.buffer(1e-9).covers(region_of(support))
        assert np.all(support.covers(cells.points))


def test_hessian_bound_of_the_direction_term():
    """The curvature margin: the Hessian of w . (x - c)/|x - c| is >= -1.5 |w| / |x - c|^2."""
    rng = np.random.default_rng(1)
    worst = 0.0
    for _ in range(2000):
        w, z = rng.normal(size=2), rng.normal(size=2)
        r = np.linalg.norm(z)
        zh = z / r
        h = (-(np.outer(w, zh) + np.outer(zh, w)) - (w @ zh) * (np.eye(2) - 3 * np.outer(zh, zh))) / r**2
        f = lambda p: w @ p / np.linalg.norm(p)  # noqa: E731
        e = 1e-3 * r  # central second differences
        num = np.array([[(f(z + e * (a + b)) - f(z + e * (a - b)) - f(z - e * (a - b)) + f(z - e * (a + b))) / (4 * e * e)
                         for b in np.eye(2)] for a in np.eye(2)])
        np.testing.assert_allclose(h, num, atol=1e-4 * np.abs(h).max())
        worst = min(worst, np.linalg.eigvalsh(h).min() * r**2 / np.linalg.norm(w))
    assert -1.5 < worst < -1.1  # the bound holds, and is not slack by much


@pytest.mark.parametrize("kind", ["disk", "footprint"])
def test_upper_bound_is_sound_for_any_multiplier(kind):
    """The certificate behind every P and I: for any y and lam, ``upper_bound`` is at least
    y . g(x) + lam . (x - CF) at every point of the region, and at least y . L for every explicit
    distribution; ``is_negative`` only when that function is negative on a dense point set."""
    rng = np.random.default_rng(2)
    support = SupportModel.of_slider(TRAPEZOID, kind)
    dense = B.points_in_region(rng, region_of(support), 4000, boundary=1000)
    for twist in random_cor_twists(rng, support, 25):
        loads = support.loads(twist)
        for _ in range(4):
            y, lam = rng.normal(size=3), rng.normal(size=2)
            psi = B.loads(twist, dense) @ y + (dense - support.cf) @ lam
            bound = loads.upper_bound(y, lam)
            assert bound >= psi.max() - 1e-12
            if loads.is_negative(y, lam):
                assert psi.max() < 0
        # Discrete value <= a much finer discretisation <= the bound from the LP's multiplier. Near
        # a COR inside the region the fine set needs points all around it (any friction direction).
        y = rng.normal(size=3)
        value, lam = loads.sample_support(y)
        cor = np.array([-twist[1], twist[0]]) / twist[2]
        angle = np.linspace(0, 2 * np.pi, 256)
        ring = cor + 1e-7 * np.stack([np.cos(angle), np.sin(angle)], 1)
        fine = np.vstack([dense, ring[support.covers(ring)]])
        best = B.dense_support_max(twist, fine, support.cf, y)
        assert value <= best + 1e-6 <= loads.upper_bound(y, lam) + 1e-6 + 1e-9


# ----------------------------------------------------------------------------------------------
# Force status: fixtures and cross-checks


FIXTURE_TABLE = [  # docs/mechanics.md, "Membership table": (vertices, cf, edge, mu, COR, sense, exact V_F)
    (RECT, (0, 0.5), 0, 0.5, (-3, 0.5), 1, True),
    (RECT, (0, 0.5), 0, 0.5, (-3, 1.2), 1, True),
    (RECT, (0, 0.5), 0, 0.5, (-1.5, 0.5), 1, True),
    (RECT, (0, 0.5), 0, 0.5, (-3, 0.5), -1, False),
    (RECT, (0, 0.5), 0, 0.5, (10, 0.5), -1, True),
    (RECT, (0.4, 0.3), 0, 0.5, (-5, 0.3), 1, True),
    (RECT, (0.4, 0.3), 0, 0.5, (-3.5, 0.3), 1, True),
    (RECT, (0.4, 0.3), 0, 0.5, (2.05, 0.5), -1, True),
    (RECT, (0.4, 0.3), 0, 0.5, (6, -1), -1, True),
    (D_VERTS, (0.6, 0.5), 1, 0.8, (-12, 6), 1, True),
    (D_VERTS, (0.6, 0.5), 1, 0.8, (-12, 3), 1, True),
    (D_VERTS, (0.6, 0.5), 1, 0.8, (5.5, 3), -1, True),
]


@pytest.mark.parametrize("vertices, cf, edge, mu, cor, sense, want", FIXTURE_TABLE)
def test_sticking_edge_matches_the_exact_oracle_table(vertices, cf, edge, mu, cor, sense, want):
    """ss with the footprint model is the exact V_F (docs/mechanics.md, "Exact LP oracle", "Membership table")."""
    slider = Slider(vertices, cf=cf)
    cone = contact_wrench_cone(ContactConfiguration.slider_edge(slider, edge, mu), "ss")
    verdict = force_status(cor_to_twist(cor, sense), cone, SupportModel.of_slider(slider, "footprint"))
    assert (verdict.status == "P") == want
    assert verdict.exact


@pytest.mark.parametrize("slider", [BLOCK, TRAPEZOID], ids=["block", "trapezoid"])
def test_procedure_stable_pushes_are_all_possible(slider):
    """STABLE (Lynch & Mason 1996) is a conservative V_F: each of its pushes is P for ss."""
    rng = np.random.default_rng(5)
    region = stable_region(slider, 0, 0.6)
    cone = contact_wrench_cone(ContactConfiguration.slider_edge(slider, 0, 0.6), "ss")
    support = SupportModel.of_slider(slider, "footprint")
    twists = np.vstack([region.extremal_twists(), random_cor_twists(rng, support, 400)])
    stable = twists[region.contains(twists)]
    assert len(stable) >= 10
    for twist in stable:
        assert "P" in force_status(twist, cone, support).consistent


def configurations():
    """(name, contact configuration, mode, slider) cases for the property tests."""
    edge = ContactConfiguration.slider_edge(BLOCK, 0, 0.6)
    corner = ContactConfiguration([[0.4, 0.0], [-1.0, 0.7]], [[0, 1], [1, 0]], 0.4)
    slanted = ContactConfiguration.slider_edge(TRAPEZOID, 1, 0.5)
    return [("edge-ss", edge, "ss", BLOCK), ("edge-sf", edge, "sf", BLOCK), ("edge-rr", edge, "rr", BLOCK),
            ("corner-ss", corner, "ss", BLOCK), ("corner-ls", corner, "ls", BLOCK), ("slanted-ss", slanted, "ss", TRAPEZOID)]


CASES = configurations()


@pytest.mark.parametrize("name, config, mode, slider", CASES, ids=[c[0] for c in CASES])
@pytest.mark.parametrize("kind", ["disk", "footprint"])
def test_verdicts_against_explicit_distributions(name, config, mode, slider, kind):
    """Brute force: for P every random distribution's load lies in the cone (generators + NNLS),
    for I none does; and a much finer discretisation (dense-point LPs) finds no counter-example."""
    rng = np.random.default_rng(zlib.crc32((name + kind).encode()))  # hash() is salted per process
    support = SupportModel.of_slider(slider, kind)
    region = region_of(support)
    cone = contact_wrench_cone(config, mode)
    gens = B.friction_generators(config.points, config.normals, config.mu, mode)
    dists = B.random_distributions(rng, region, support.cf, 25)
    dense = B.points_in_region(rng, region, 1000, boundary=300)
    seen = {"P": 0, "I": 0}
    for twist in np.vstack([random_cor_twists(rng, support, 14), near_possible_translations(rng, support, gens, 10)]):
        verdict = force_status(twist, cone, support, refinements=0)
        if verdict.status == "U":
            continue
        seen[verdict.status] += 1
        inside = [B.in_cone(B.load_of(twist, x, w), gens, tol=1e-6) for x, w in dists]
        assert all(inside) if verdict.status == "P" else not any(inside), (twist, verdict)
        if verdict.status == "P":
            assert max(B.dense_support_max(twist, dense, support.cf, -a) for a in cone.rows) <= 1e-9
        else:
            assert not B.dense_some_in_cone(twist, dense, support.cf, gens)
    assert seen["I"] > 0 and (seen["P"] > 0 or mode in ("sf", "rr"))


@pytest.mark.parametrize("kind", ["disk", "footprint"])
def test_translation_is_never_undetermined(kind):
    """§3.4: at infinity {CF_eff} is the CF, so a translation is P or I; and exactly P when the
    force along it through the CF is a possible contact force."""
    rng = np.random.default_rng(6)
    for _, config, mode, slider in CASES:
        support = SupportModel.of_slider(slider, kind)
        cone = contact_wrench_cone(config, mode)
        gens = B.friction_generators(config.points, config.normals, config.mu, mode)
        for a in rng.uniform(0, 2 * np.pi, 12):
            t = np.array([np.cos(a), np.sin(a)])
            verdict = force_status(np.r_[t, 0.0], cone, support)
            assert verdict.status in "PI" and verdict.exact
            assert (verdict.status == "P") == B.in_cone(B.wrench(support.cf, t), gens, tol=1e-9)


# ----------------------------------------------------------------------------------------------
# The paper's examples


FIG10_SLIDER = Slider([[-1.5, -1], [1.5, -1], [1.5, 1], [-1.5, 1]], cf=(0, 0))


@pytest.mark.parametrize("kind", ["disk", "footprint"])
def test_fig10b_two_sticking_contacts_with_mu_02(kind):
    """Fig. 10b: two sticking contacts with parallel normals, mu = 0.2, all forces passing left of
    the CF. No translation is possible, so nothing is P, and the slider can only turn clockwise."""
    config = ContactConfiguration.edge([-1.2, -1], [-0.6, -1], [0, 1], 0.2)
    cone = contact_wrench_cone(config, "ss")
    support = SupportModel.of_slider(FIG10_SLIDER, kind)
    rng = np.random.default_rng(10)
    for a in np.linspace(0, 2 * np.pi, 24, endpoint=False):
        assert force_status([np.cos(a), np.sin(a), 0.0], cone, support).status == "I"
    statuses = {1: set(), -1: set()}
    for twist in random_cor_twists(rng, support, 80):
        verdict = force_status(twist, cone, support)
        assert verdict.status != "P"
        statuses[int(np.sign(twist[2]))].add(verdict.status)
    assert statuses[1] == {"I"}  # never counter-clockwise
    assert "U" in statuses[-1]
    regions = force_status_regions(cone, support, rays=12, steps=6)
    assert regions[1]["P"].is_empty and regions[-1]["P"].is_empty and regions[1]["U"].is_empty
    assert regions[-1]["U"].area > 0


def test_a_wider_friction_cone_gives_a_p_region():
    """Fig. 10a's situation: when a contact force through the CF exists, some motions are P."""
    config = ContactConfiguration.edge([-1.2, -1], [0.6, -1], [0, 1], 0.5)
    regions = force_status_regions(contact_wrench_cone(config, "ss"), SupportModel.of_slider(FIG10_SLIDER, "disk"), rays=12, steps=6)
    assert regions[1]["P"].area > 0 and regions[-1]["P"].area > 0


@pytest.mark.parametrize("d", [0.5, 0.0])
def test_single_line_of_force_is_peshkins_cor_locus(d):
    """One line of force (up along x = d) on the unit disk: the U region is the COR locus, P is
    empty (except the translation along a force through the CF, for d = 0), and
    * every translation but that one is I;
    * the load's moment about the CF has the sense of rotation, so for d > 0 all CW CORs are I;
    * a CCW COR at (-s, 0) is produced by the dipod (0, +-rho) with s = rho^2 / d, rho <= 1: U for
      s <= 1/d, and beyond the tip I."""
    line = contact_wrench_cone(ContactConfiguration([[d, -1]], [[0, 1]], 0.0), "s")
    support = SupportModel.disk([0, 0], 1.0)
    for a in np.linspace(0, 2 * np.pi, 16, endpoint=False):
        t = np.array([np.cos(a), np.sin(a)])
        want = "P" if d == 0 and abs(a - np.pi / 2) < 1e-9 else "I"
        assert force_status(np.r_[t, 0.0], line, support).status == want
    rng = np.random.default_rng(11)
    for twist in random_cor_twists(rng, support, 40):
        verdict = force_status(twist, line, support)
        assert verdict.status != "P"
        if d > 0 and twist[2] < 0:
            assert verdict.status == "I"
    if d > 0:
        for s in (0.2, 0.6, 1.0, 1.6, 1.9):
            rho = np.sqrt(s * d)
            dipod = B.load_of(cor_to_twist([-s, 0], 1), np.array([[0, rho], [0, -rho]]), np.array([0.5, 0.5]))
            assert dipod[0] == pytest.approx(0) and dipod[2] / dipod[1] == pytest.approx(d)  # on the line
            assert force_status(cor_to_twist([-s, 0], 1), line, support).status == "U"
        for s in (2.2, 3.0, 6.0):
            assert force_status(cor_to_twist([-s, 0], 1), line, support).status == "I"
    regions = force_status_regions(line, support, rays=12, steps=6)
    assert regions[1]["P"].is_empty and regions[-1]["P"].is_empty


# ----------------------------------------------------------------------------------------------
# Structure: rays, models, mu, symmetry


def matches_a_pattern(consistent):
    """Whether statuses along a ray (sets of possible ones) fit I, U->I, P or U->P (§3.4)."""
    for end in "IP":
        for split in range(len(consistent) + 1):
            if all("U" in c for c in consistent[:split]) and all(end in c for c in consistent[split:]):
                return True
    return False


@pytest.mark.parametrize("kind", ["disk", "footprint"])
@pytest.mark.parametrize("mode", ["ss", "sf"])
def test_status_along_rays_follows_the_four_patterns(kind, mode):
    config = ContactConfiguration.slider_edge(BLOCK, 0, 0.6)
    cone = contact_wrench_cone(config, mode)
    support = SupportModel.of_slider(BLOCK, kind)
    taus = np.linspace(0, 1, 13)
    for angle in np.linspace(0, 2 * np.pi, 6, endpoint=False):
        for sense in (1, -1):
            twists = ray_twist(support.cf, angle, taus, sense, support.radius)
            along = [force_status(v, cone, support).consistent for v in twists]
            assert matches_a_pattern(along), (angle, sense, along)


@pytest.mark.parametrize("name, config, mode, slider", CASES[:4], ids=[c[0] for c in CASES[:4]])
def test_disk_model_is_more_conservative_than_the_footprint(name, config, mode, slider):
    """The footprint's distributions are among the disk's: P_disk within P_footprint, I_disk
    within I_footprint."""
    cone = contact_wrench_cone(config, mode)
    disk, foot = (SupportModel.of_slider(slider, k) for k in ("disk", "footprint"))
    rng = np.random.default_rng(12)
    gens = B.friction_generators(config.points, config.normals, config.mu, mode)
    for twist in np.vstack([random_cor_twists(rng, disk, 25), near_possible_translations(rng, disk, gens, 10)]):
        d, f = force_status(twist, cone, disk), force_status(twist, cone, foot)
        if d.status in "PI":
            assert d.status in f.consistent, (twist, d, f)


def test_monotonic_in_mu():
    """For sticking contacts a larger mu only enlarges the cone: P stays P, I was I."""
    rng = np.random.default_rng(13)
    support = SupportModel.of_slider(BLOCK, "footprint")
    configs = [ContactConfiguration.slider_edge(BLOCK, 0, mu) for mu in (0.3, 0.6, 1.0)]
    cones = [contact_wrench_cone(config, "ss") for config in configs]
    gens = B.friction_generators(configs[1].points, configs[1].normals, configs[1].mu, "ss")
    for twist in np.vstack([random_cor_twists(rng, support, 25), near_possible_translations(rng, support, gens, 15)]):
        verdicts = [force_status(twist, cone, support) for cone in cones]
        for lo, hi in zip(verdicts, verdicts[1:]):
            if lo.status == "P":
                assert "P" in hi.consistent
            if hi.status == "I":
                assert "I" in lo.consistent


@pytest.mark.parametrize("mirror", [False, True], ids=["rigid", "mirror"])
@pytest.mark.parametrize("kind", ["disk", "footprint"])
def test_invariant_under_rigid_motions_and_reflection(kind, mirror):
    """Moving everything by an isometry maps verdicts onto verdicts; a reflection swaps the
    rotation sense and the sliding labels r and l."""
    a, b = B.isometry(0.7, (2.0, -1.0), mirror)
    config = ContactConfiguration([[0.4, 0.0], [-1.0, 0.7]], [[0, 1], [1, 0]], 0.4)
    moved = ContactConfiguration(B.move_points(config.points, a, b), config.normals @ a.T, config.mu)
    slider = BLOCK
    image = Slider(B.move_points(slider.vertices, a, b), cf=B.move_points(slider.cf, a, b))
    swap = str.maketrans("rl", "lr") if mirror else str.maketrans("", "")
    rng = np.random.default_rng(14)
    for mode in ("ss", "ls", "sr"):
        cone, cone2 = contact_wrench_cone(config, mode), contact_wrench_cone(moved, mode.translate(swap))
        support, support2 = SupportModel.of_slider(slider, kind), SupportModel.of_slider(image, kind)
        gens = B.friction_generators(config.points, config.normals, config.mu, mode)
        for twist in np.vstack([random_cor_twists(rng, support, 10), near_possible_translations(rng, support, gens, 5)]):
            v, w = force_status(twist, cone, support), force_status(B.move_twist(twist, a, b), cone2, support2)
            assert set(v.consistent) & set(w.consistent), (mode, twist, v, w)


def test_region_map_agrees_with_pointwise_status():
    """The ray-bisection map tiles the window, and along the sampled rays, away from transitions,
    its label is the status there (between rays the map interpolates)."""
    config = ContactConfiguration.slider_edge(BLOCK, 0, 0.6)
    cone = contact_wrench_cone(config, "ss")
    support = SupportModel.of_slider(BLOCK, "footprint")
    window = (-6, -6, 6, 6)
    rays = 12
    regions = force_status_regions(cone, support, window=window, rays=rays, steps=8)
    box = shapely.box(*window)
    checked = 0
    for sense in (1, -1):
        assert shapely.union_all(list(regions[sense].values())).area == pytest.approx(box.area, rel=1e-6)
        for angle in 2 * np.pi * np.arange(rays) / rays:
            for dist in (0.3, 1.0, 2.0, 3.5, 5.0):
                p = support.cf + dist * np.array([np.cos(angle), np.sin(angle)])
                point = shapely.Point(p)
                labels = [s for s, g in regions[sense].items() if g.contains(point) and g.boundary.distance(point) > 0.05]
                if len(labels) != 1:
                    continue
                assert labels[0] in force_status(cor_to_twist(p, sense), cone, support).consistent, (sense, angle, dist)
                checked += 1
    assert checked > 60
