"""The exact stable region of an edge (mechanics.exact_region) against independent reasoning.

Sources of truth, none of them the code under test:
* the membership table of docs/mechanics.md, "Membership table" (its "exact V_F" column, computed by the note's own
  LP oracle), and the note's statement that STABLE finds every stable translation;
* ``oracle.LPOracle``: the exact V_F test of docs/mechanics.md, "Exact LP oracle", linear programmes over explicit
  support distributions on a grid of the part (no ``mechanics`` code), plus Theorem 4's
  condition re-derived here (the COR lies beyond the part along the edge);
* containment of procedure STABLE's region, monotonicity in mu and mirror symmetry.
"""

from __future__ import annotations

import numpy as np
import pytest
import shapely

import oracle as O
from mechanics import Slider, StableSteering, cor_to_twist, exact_region, stable_region

RECT, PARTS = O.RECT, O.PARTS  # fixtures A, B, D, an L and a random convex part (tests/oracle.py)
RAYS = 24  # a coarse trace keeps the suite fast; the guarantee does not depend on it


def regions(g, rays=RAYS):
    slider = Slider(g["vertices"], cf=g["cf"])
    return (exact_region(slider, g["edge"], g["mu"], width=g["width"], rays=rays),
            stable_region(slider, g["edge"], g["mu"], width=g["width"]))


CACHE: dict[str, tuple] = {}


def part(name):
    if name not in CACHE:
        CACHE[name] = regions(PARTS[name])
    return CACHE[name]


# docs/mechanics.md, "Membership table", rows whose COR lies beyond the part along the edge (Theorem 4).
TABLE = [
    ("A", (-3, 0.5), 1, True), ("A", (-3, 1.2), 1, True), ("A", (-1.5, 0.5), 1, True),
    ("A", (-3, 0.5), -1, False), ("A", (10, 0.5), -1, True),
    ("B", (-5, 0.3), 1, True), ("B", (-3.5, 0.3), 1, True), ("B", (2.05, 0.5), -1, True), ("B", (6, -1), -1, True),
    ("D", (-12, 6), 1, True), ("D", (-12, 3), 1, True), ("D", (5.5, 3), -1, True),
]


@pytest.mark.parametrize("name, cor, sense, exact", TABLE)
def test_membership_table(name, cor, sense, exact):
    region, _ = part(name)
    assert bool(region.contains(cor_to_twist(cor, sense))) == exact


def theorem4_ok(twists, g):
    """CCW CORs left of the whole part along t, CW right of it (translations pass)."""
    f = O.edge_frame(g["vertices"], g["edge"], g["width"])
    along = g["vertices"] @ f["t"]
    v = np.asarray(twists, float)
    rot = np.abs(v[:, 2]) > 1e-12
    c = np.column_stack([-v[rot, 1], v[rot, 0]]) / v[rot, 2:]
    ct = c @ f["t"]
    ok = np.where(v[rot, 2] > 0, ct <= along.min() + 1e-9, ct >= along.max() - 1e-9)
    return bool(ok.all())


@pytest.mark.parametrize("name", list(PARTS))
def test_exact_region_is_sound(name):
    """Its boundary (traced vertices and points between them, finer than the trace) and a grid of
    CORs inside it all pass the independent LP over distributions, and Theorem 4."""
    g = PARTS[name]
    region, stable = part(name)
    assert not region.is_empty
    polygon, _ = region.section()
    ring = polygon.exterior
    boundary = shapely.get_coordinates(shapely.line_interpolate_point(ring, np.linspace(0, 1, 97)[:-1], normalized=True))
    inside = shapely.get_coordinates(shapely.points(np.random.default_rng(0).uniform(
        polygon.bounds[:2], polygon.bounds[2:], size=(600, 2))))
    inside = inside[shapely.contains_xy(polygon, inside[:, 0], inside[:, 1])][:60]
    twists = region.plane.twists(np.vstack([boundary, inside]))
    assert region.contains(twists).all()
    assert theorem4_ok(twists, g)
    ref = O.Reference(g["vertices"], g["cf"], g["edge"], g["mu"], g["width"])
    lp = O.LPOracle(ref, O.support_samples(g["vertices"], 12))
    worst = max(lp.max_violation(v) for v in twists)
    assert worst <= 1e-9, worst


@pytest.mark.parametrize("name", ["A", "B", "L"])
def test_exact_region_is_tight(name):
    """Just beyond its boundary (10 % further from the centre) twists fail the LP or Theorem 4 on
    most rays: the region is close to as large as the guarantee allows."""
    g = PARTS[name]
    region, _ = part(name)
    polygon, centre = region.section()
    ring = np.asarray(polygon.exterior.coords)[:-1]
    outside = centre + 1.1 * (ring[:: max(1, len(ring) // 12)] - centre)
    twists = region.plane.twists(outside)
    ref = O.Reference(g["vertices"], g["cf"], g["edge"], g["mu"], g["width"])
    lp = O.LPOracle(ref, O.support_samples(g["vertices"], 12))
    fails = [lp.max_violation(v) > 1e-9 or not theorem4_ok(v[None], g) for v in twists]
    assert np.mean(fails) >= 0.6, fails


@pytest.mark.parametrize("name", list(PARTS))
def test_contains_stable_and_is_larger(name):
    """STABLE's pushes (sampled through its steering map) are all exact-stable, the translations
    are STABLE's, and the exact COR regions are larger within a window about the part."""
    region, stable = part(name)
    u = np.random.default_rng(1).random((3000, 2))
    assert region.contains(StableSteering(stable).twist(u)).all()
    assert region.translation_range == stable.translation_range
    window = (*(stable.cf - 6 * stable.scale), *(stable.cf + 6 * stable.scale))
    ex, st = region.cor_polygons(window), stable.cor_polygons(window)
    for sense in (1, -1):
        assert ex[sense].buffer(1e-6 * stable.scale).contains(st[sense])
    exact_area = sum(ex[s].area for s in (1, -1))
    stable_area = sum(st[s].area for s in (1, -1))
    assert exact_area > 1.05 * stable_area
    print(f"{name}: COR area within +-6r, exact {exact_area:.3g}, STABLE {stable_area:.3g}, "
          f"ratio STABLE/exact {stable_area / exact_area:.2f}")


def test_steering_covers_the_exact_region():
    """Every control maps to a stable push, and the images reach every part of the region."""
    region, _ = part("A")
    steer = StableSteering(region)
    twists = steer.twist(np.random.default_rng(2).random((4000, 2)))
    assert region.contains(twists).all()
    points = region.plane.points(twists)
    polygon, _ = region.section()
    hull = shapely.MultiPoint(points).convex_hull
    assert hull.area >= 0.95 * polygon.convex_hull.area


def test_monotone_in_mu():
    g = PARTS["A"]
    low, _ = regions({**g, "mu": 0.4})
    high, _ = regions({**g, "mu": 0.8})
    polygon, _ = low.section()
    assert high.section()[0].buffer(0.02 * np.sqrt(polygon.area)).contains(polygon)
    assert high.section()[0].area > polygon.area


def test_mirror_symmetry():
    """Fixture A is symmetric about the normal through the contact's midpoint: CCW and CW regions
    are mirror images (the push plane's point reflection (s, w) -> (-s, -w))."""
    region, _ = part("A")
    polygon, _ = region.section()
    mirrored = shapely.affinity.scale(polygon, -1, -1, origin=(0, 0))
    assert polygon.symmetric_difference(mirrored).area <= 0.03 * polygon.area


def test_no_stable_push_without_a_force_through_the_cf():
    """Fixture E (docs/mechanics.md, "Fixtures"): the contact's cone holds no pure force, so nothing is stable
    (Proposition 6), whatever the method."""
    slider = Slider([(-1, 0), (0.5, 0), (1, 0), (1, 1), (-1, 1)], cf=[0.8, 0.5])
    region = exact_region(slider, 0, 0.5, rays=RAYS)
    assert region.is_empty
    assert not region.contains([[0.0, 1.0, 0.0], cor_to_twist([-3, 0.5], 1)]).any()
    assert region.extremal_twists().shape == (0, 3)


# -- robustness (Lynch 1992, §6) -------------------------------------------------------------------

def test_friction_interval_gives_its_lowest_value():
    """A wider friction cone holds the narrower one, so sticking at the lowest mu implies sticking
    above it: the interval's region is the lowest value's, inside the highest value's."""
    g = PARTS["A"]
    slider = Slider(g["vertices"], cf=g["cf"])
    interval = exact_region(slider, 0, (0.4, 0.8), rays=RAYS)
    low = exact_region(slider, 0, 0.4, rays=RAYS)
    high = exact_region(slider, 0, 0.8, rays=RAYS)
    assert interval.polygon.equals(low.polygon)
    assert high.polygon.buffer(0.02).contains(interval.polygon)
    with pytest.raises(ValueError, match="mu"):
        exact_region(slider, 0, (0.0, 0.5))


def disk_cfs(cf, rho, count=8):
    angle = 2 * np.pi * np.arange(count) / count
    return [np.asarray(cf, float)] + [cf + rho * np.array([np.cos(a), np.sin(a)]) for a in angle]


@pytest.mark.parametrize("name, rho", [("A", 0.1), ("B", 0.05)])
def test_uncertain_cf_region_is_sound_for_every_cf_in_the_disk(name, rho):
    """Boundary and interior twists of the robust region pass the independent LP with the support
    centred at the nominal CF and at points on the uncertainty disk's rim."""
    g = PARTS[name]
    region = exact_region(Slider(g["vertices"], cf=g["cf"]), g["edge"], g["mu"], cf_radius=rho, rays=RAYS)
    polygon, centre = region.section()
    assert polygon.area > 0
    ring = polygon.exterior
    points = shapely.get_coordinates(shapely.line_interpolate_point(ring, np.linspace(0, 1, 41)[:-1], normalized=True))
    twists = region.plane.twists(np.vstack([points, centre + 0.5 * (points[::4] - centre)]))
    assert region.contains(twists).all() and theorem4_ok(twists, g)
    samples = O.support_samples(g["vertices"], 12)
    for cf in disk_cfs(g["cf"], rho):
        lp = O.LPOracle(O.Reference(g["vertices"], cf, g["edge"], g["mu"], g["width"]), samples)
        worst = max(lp.max_violation(v) for v in twists)
        assert worst <= 1e-9, (cf, worst)


def test_uncertain_cf_shrinks_the_region_and_needs_to():
    """More uncertainty, a smaller region, nested; the limit of no uncertainty is the known-CF
    region; and pushes of the known-CF region left out fail for some CF in the disk."""
    g = PARTS["A"]
    slider = Slider(g["vertices"], cf=g["cf"])
    known, _ = part("A")
    tiny = exact_region(slider, 0, 0.5, cf_radius=1e-4, rays=RAYS)
    small = exact_region(slider, 0, 0.5, cf_radius=0.05, rays=RAYS)
    large = exact_region(slider, 0, 0.5, cf_radius=0.15, rays=RAYS)
    areas = [r.polygon.area for r in (known, tiny, small, large)]
    assert areas[1] >= 0.93 * areas[0] and areas[0] > areas[2] > areas[3]
    for outer, inner in ((known, small), (small, large)):
        assert outer.polygon.buffer(0.02).contains(inner.polygon)
    # The known-CF region's corners that the rho = 0.15 region drops: most fail at some CF.
    corners = np.asarray(known.polygon.exterior.coords)[:-1]
    dropped = corners[~shapely.contains_xy(large.polygon.buffer(0.02), corners[:, 0], corners[:, 1])][::2]
    assert len(dropped) >= 4
    samples = O.support_samples(g["vertices"], 12)
    oracles = [O.LPOracle(O.Reference(g["vertices"], cf, 0, 0.5), samples) for cf in disk_cfs(g["cf"], 0.15)]
    fails = [max(lp.max_violation(v) for lp in oracles) > 1e-9 for v in known.plane.twists(dropped)]
    assert np.mean(fails) >= 0.5, fails


def test_uncertain_cf_translations_match_the_hand_derived_range():
    """A 2 x 1 block pushed by a 0.5-wide face, mu = 1, CF (0, 0.5) known within rho = 0.1. The
    line of the push through any CF c of the disk must cross the face: with tau = tan(angle) and
    h = 0.5 the CF's height, 0.5 |tau| + rho sqrt(1 + tau^2) <= 0.25, so tau <= 0.2917 (16.26 deg)
    instead of 0.5 (26.57 deg) for a known CF; friction (|tau| <= 1) does not bind."""
    from scipy.optimize import brentq

    slider = Slider(RECT, cf=[0.0, 0.5])
    region = exact_region(slider, 0, 1.0, width=0.5, cf_radius=0.1, rays=RAYS)
    tau = brentq(lambda x: 0.5 * x + 0.1 * np.sqrt(1 + x * x) - 0.25, 0.0, 0.5)
    lo, hi = region.translation_range
    assert np.tan(hi) <= tau + 1e-9 and np.tan(hi) >= 0.95 * tau
    assert np.tan(-lo) <= tau + 1e-9 and np.tan(-lo) >= 0.95 * tau
    known = exact_region(slider, 0, 1.0, width=0.5, rays=RAYS)
    np.testing.assert_allclose(np.tan(known.translation_range), [-0.5, 0.5])


@pytest.mark.parametrize("angle, shift, scale", [(0.0, (3.0, -2.0), 0.02), (-2.1, (-0.5, 0.4), 0.02)])
def test_invariant_under_rigid_motion_and_scaling(angle, shift, scale):
    """The push plane's coordinates are intrinsic (speeds per unit normal speed, omega times the
    part's radius), so moving and scaling the part leaves its region where it was: exactly under
    scaling, and under rotation up to the certificate's support grid, which is aligned with the
    frame (about 5 % of the area here, each version sound on its own)."""
    g = PARTS["B"]
    c, s = np.cos(angle), np.sin(angle)
    move = lambda p: scale * np.asarray(p, float) @ np.array([[c, -s], [s, c]]).T + shift  # noqa: E731
    here = exact_region(Slider(g["vertices"], cf=g["cf"]), 0, 0.5, rays=16).polygon
    there = exact_region(Slider(move(g["vertices"]), cf=move(g["cf"])), 0, 0.5, rays=16).polygon
    assert here.symmetric_difference(there).area <= (0.1 if angle else 0.01) * here.area


def test_the_simulator_sticks_on_the_exact_regions_corners():
    """The most aggressive exact pushes (the corners of the region's hull, which STABLE rejects)
    stick under grid, random and extreme two- and three-point distributions in the independent
    quasi-static simulator (mechanics.quasistatic knows nothing of stable regions), and pushes 10 %
    beyond the region's boundary slip or separate under some of them."""
    from mechanics.quasistatic import Contact, dipod_supports, grid_support, random_support, solve_step, tripod_supports

    g = PARTS["A"]
    region, stable = part("A")
    corners = region.extremal_twists()
    beyond = corners[~stable.contains(corners)]
    assert len(beyond) >= 6
    block = shapely.Polygon(g["vertices"])
    rng = np.random.default_rng(3)
    supports = ([grid_support(block, 60, cf=g["cf"])] + [random_support(block, 40, rng, cf=g["cf"]) for _ in range(4)]
                + dipod_supports(block, g["cf"], 16) + tripod_supports(block, g["cf"], 16, rng))
    line = [Contact([-1.0, 0.0], [0.0, 1.0], 0.5), Contact([1.0, 0.0], [0.0, 1.0], 0.5)]
    for twist in beyond:
        for support in supports:
            assert solve_step(support, line, twist).sticks, (twist, support)
    polygon, centre = region.section()
    ring = np.asarray(polygon.exterior.coords)[:-1:3]
    outside = region.plane.twists(centre + 1.1 * (ring - centre))
    slips = [not all(solve_step(support, line, twist).sticks for support in supports) for twist in outside]
    assert np.mean(slips) >= 0.75, slips


# -- completeness: the trace follows needles, hugs the certified boundary, bounds its gap ----------

# A 2 x 1 block pushed by a 1.1-wide face with its CF (0.75, 0.25) beyond the contact's right end,
# mu = 0.9: the only stable translations tilt far to one side, and the region is a thin needle.
NEEDLE = dict(vertices=np.array(RECT, float), cf=np.array([0.75, 0.25]), edge=0, mu=0.9, width=1.1)


def fine_oracle(g):
    """The note's LP over explicit distributions on a 24 x 24 grid of the part and 96 points of its
    boundary (where the extreme distributions that decide a thin region put their weight)."""
    ref = O.Reference(g["vertices"], g["cf"], g["edge"], g["mu"], g["width"])
    ring = shapely.Polygon(g["vertices"]).exterior
    rim = shapely.get_coordinates(shapely.line_interpolate_point(ring, np.linspace(0, 1, 96, endpoint=False), normalized=True))
    return O.LPOracle(ref, np.vstack([O.support_samples(g["vertices"], 24), rim]))


def test_a_needle_is_traced_to_its_tip():
    """Push-plane points along the needle's axis, from where an even trace of 48 rays with a 2 %
    margin gave up (0.6 of the way from the centre, found by hand) to 0.95 of the way to the tip,
    all stuck for every distribution of the independent LP: all are in the region. A point past
    the tip is not (the LP finds a distribution that breaks sticking)."""
    region = exact_region(Slider(NEEDLE["vertices"], cf=NEEDLE["cf"]), 0, NEEDLE["mu"], NEEDLE["width"])
    centre, tip = np.array([0.81963, -0.04673]), np.array([0.45552, -0.81658])
    along = region.plane.twists(centre + np.array([0.6, 0.8, 0.95, 1.1])[:, None] * (tip - centre))
    lp = fine_oracle(NEEDLE)
    violation = [lp.max_violation(v) for v in along]
    assert max(violation[:3]) < 0 < violation[3], violation
    assert region.contains(along).tolist() == [True, True, True, False]
    assert theorem4_ok(along[:3], NEEDLE)


@pytest.mark.parametrize("name", ["B", "L"])
def test_just_inside_the_certified_boundary_is_stable_and_just_outside_is_not(name):
    """At a dozen of the region's vertices beyond STABLE's region, the twist 1 % closer to the
    centre is in the region and stuck for every distribution of the independent LP (its optimum is
    an extreme, two- or three-point distribution); the twist 3 % farther out is outside the region,
    and for most vertices the LP finds a distribution that breaks sticking there: the polygon hugs
    the certified boundary, with no safety margin."""
    g = PARTS[name]
    region, stable = part(name)
    polygon, centre = region.section()
    ring = np.asarray(polygon.exterior.coords)[:-1]
    beyond = ring[~stable.contains(region.plane.twists(ring))]
    pick = beyond[np.linspace(0, len(beyond), 12, endpoint=False).astype(int)]
    inside = region.plane.twists(centre + 0.99 * (pick - centre))
    outside = region.plane.twists(centre + 1.03 * (pick - centre))
    assert region.contains(inside).all() and not region.contains(outside).any()
    lp = fine_oracle(g)
    assert max(lp.max_violation(v) for v in inside) <= 1e-9
    broken = [lp.max_violation(v) > 1e-9 or not theorem4_ok(v[None], g) for v in outside]
    assert np.mean(broken) >= 0.75, broken


@pytest.mark.parametrize("name", ["B", "L"])
def test_the_gap_bound_holds_against_a_dense_brute_force_trace(name):
    """64 even rays from the region's centre, each bisected 14 times with the certificate: every
    point certified stable lies within the region's reported gap of its polygon (the gap bounds
    how much certified stable set the adaptive trace leaves out), and the gap is small."""
    from mechanics import ContactConfiguration, SupportModel, contact_wrench_cone, force_possible

    g = PARTS[name]
    slider = Slider(g["vertices"], cf=g["cf"])
    region, _ = part(name)
    polygon, centre = region.section()
    assert 0 < region.gap < 0.5 * np.sqrt(polygon.area)
    cone = contact_wrench_cone(ContactConfiguration.slider_edge(slider, g["edge"], g["mu"], g["width"]), "ss")
    support = SupportModel.of_slider(slider, "footprint")
    w_lo, w_hi = region.plane.theorem4_strip(g["vertices"])
    angle = 2 * np.pi * np.arange(64) / 64
    e = np.c_[np.cos(angle), np.sin(angle)]
    with np.errstate(divide="ignore"):
        far = np.where(e[:, 1] != 0, np.abs(np.where(e[:, 1] > 0, w_hi, w_lo) - centre[1]) / np.abs(e[:, 1]), np.inf)
    lo, hi = np.zeros(64), np.minimum(far, 4 * np.sqrt(polygon.area)) * (1 - 1e-9)
    for _ in range(14):
        mid = (lo + hi) / 2
        ok = force_possible(region.plane.twists(centre + mid[:, None] * e), cone, support, refinements=2)
        lo, hi = np.where(ok, mid, lo), np.where(ok, hi, mid)
    certified = centre + lo[:, None] * e
    distance = shapely.distance(polygon, shapely.points(certified))
    print(f"{name}: largest distance {distance.max():.4f}, gap {region.gap:.4f}, size {np.sqrt(polygon.area):.3f}")
    assert distance.max() <= region.gap + 1e-9, (distance.max(), region.gap)
