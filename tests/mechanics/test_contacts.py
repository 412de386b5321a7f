"""Contact configurations, polyhedral cones and composite wrench cones (Lynch 1992, §1.1, §3.1).

Sources of truth: the paper's statements, non-negative least squares on the generators
(``brute_force.in_cone``) instead of the facets under test, and moments computed directly.
"""

from __future__ import annotations

import numpy as np
import pytest
import shapely

import brute_force as B
from mechanics import (
    Cone,
    ContactConfiguration,
    Slider,
    contact_wrench_cone,
    cor_to_twist,
    friction_cone_edges,
    moment_labels,
    point_wrench,
)

WINDOW = (-4, -4, 4, 4)


def random_configuration(rng, k=None, mu=None):
    k = k or int(rng.integers(1, 4))
    angle = rng.uniform(0, 2 * np.pi, k)
    return ContactConfiguration(rng.uniform(-1, 1, (k, 2)), np.stack([np.cos(angle), np.sin(angle)], 1),
                                rng.uniform(0, 1.5) if mu is None else mu)


# ----------------------------------------------------------------------------------------------
# Contact configurations


def test_configuration_normalises_and_validates():
    c = ContactConfiguration([[0, 0], [1, 0]], [[0, 3], [4, 0]], 0.5)
    np.testing.assert_allclose(c.normals, [[0, 1], [1, 0]])
    np.testing.assert_allclose(c.tangents, [[1, 0], [0, -1]])  # right of the normal, seen from the pusher
    with pytest.raises(ValueError):
        ContactConfiguration([[0, 0]], [[0, 0]], 0.5)
    with pytest.raises(ValueError):
        ContactConfiguration([[0, 0]], [[0, 1]], -0.1)
    with pytest.raises(ValueError):
        ContactConfiguration([[0, 0], [1, 1]], [[0, 1]], 0.1)


def test_slider_edge_is_the_flat_pushers_two_end_points():
    s = Slider([[0, 0], [2, 0], [2, 1], [0, 1]])
    c = ContactConfiguration.slider_edge(s, 1, 0.3)
    np.testing.assert_allclose(c.points, s.contact(1))
    np.testing.assert_allclose(c.normals, [s.inward_normal(1)] * 2)
    assert c.mu == 0.3 and len(c) == 2


# ----------------------------------------------------------------------------------------------
# Cones


@pytest.mark.parametrize("seed", range(6))
def test_cone_facets_agree_with_nnls_membership(seed):
    rng = np.random.default_rng(seed)
    g = rng.normal(size=(int(rng.integers(1, 6)), 3))
    if seed % 3 == 1:  # a flat cone: generators in a plane
        g[:, 2] = g[:, 0] + 2 * g[:, 1]
    cone = Cone.from_generators(g)
    x = rng.normal(size=(300, 3))
    x = np.vstack([x, rng.random((40, len(g))) @ g])  # points of the cone, some on its boundary
    brute = np.array([B.in_cone(v, g, tol=1e-9) for v in x])
    np.testing.assert_array_equal(cone.contains(x, tol=1e-7), brute)
    # The rows describe the same cone from the other side.
    again = Cone.from_rows(cone.rows)
    np.testing.assert_array_equal(again.contains(x, tol=1e-7), brute)


def test_special_cones():
    whole = Cone.from_generators(np.vstack([np.eye(3), -np.eye(3)]))
    assert len(whole.rows) == 0 and whole.dimension == 3 and whole.contains([-1, 2, -3])
    zero = Cone.from_generators(np.zeros((0, 3)))
    assert zero.dimension == 0 and zero.contains([0, 0, 0]) and not zero.contains([0, 0, 1e-3])
    half = Cone.from_rows([[0, 0, 1]])
    assert half.dimension == 3 and half.contains([5, -5, 0]) and not half.contains([0, 0, -1])
    plane = Cone.from_generators([[1, 0, 0], [0, 1, 0]])
    assert plane.dimension == 2 and plane.equalities.sum() == 2
    assert plane.contains([1, 1, 0], interior=True) and not plane.contains([1, 0, 0], interior=True)


def test_dual_of_dual_and_polarity():
    rng = np.random.default_rng(7)
    cone = Cone.from_generators(rng.normal(size=(4, 3)) + [0, 0, 2])
    dual = cone.dual()
    assert np.all(dual.generators @ cone.generators.T >= -1e-12)  # y . x >= 0
    x = rng.normal(size=(200, 3))
    np.testing.assert_array_equal(dual.dual().contains(x), cone.contains(x))


def test_cor_region_of_a_twist_cone_is_its_rotation_centres():
    """The picture in COR space (§2.2): a CCW centre c is in the region iff its twist is in the cone."""
    rng = np.random.default_rng(3)
    cone = Cone.from_generators(cor_to_twist(rng.uniform(-2, 2, (3, 2)), [1, 1, -1]))
    for sense in (1, -1):
        region = cone.cor_region(sense, WINDOW)
        c = rng.uniform(-4, 4, (400, 2))
        inside = cone.contains(cor_to_twist(c, sense), tol=1e-12)
        points = shapely.points(c)
        clear = region.boundary.distance(points) > 1e-6
        np.testing.assert_array_equal(region.contains(points)[clear], inside[clear])


# ----------------------------------------------------------------------------------------------
# Composite wrench cones (§3.1)


def test_friction_cone_edges_are_at_atan_mu_from_the_normal():
    c = ContactConfiguration([[0, 0]], [[0, 1]], 0.5)
    left, right = friction_cone_edges(c)[0]
    assert np.degrees(np.arctan2(left[0], left[1])) == pytest.approx(-np.degrees(np.arctan(0.5)))
    assert np.degrees(np.arctan2(right[0], right[1])) == pytest.approx(np.degrees(np.arctan(0.5)))


@pytest.mark.parametrize("seed", range(5))
def test_composite_cone_matches_the_paper_rules(seed):
    """s: the whole friction cone; r: the left edge (opposing motion to the right); l: the right
    edge; f: nothing. The total is any positive combination (independent generators + NNLS)."""
    rng = np.random.default_rng(seed)
    config = random_configuration(rng, k=2)
    for mode in ("ss", "sr", "lf", "rl", "fs"):
        cone = contact_wrench_cone(config, mode)
        g = B.friction_generators(config.points, config.normals, config.mu, mode)
        for w in np.vstack([rng.normal(size=(60, 3)), g]):
            assert cone.contains(w, tol=1e-7) == B.in_cone(w, g, tol=1e-9), (mode, w)


def test_sliding_contact_force_opposes_the_relative_motion():
    """Slider sliding right (+t) relative to the pusher: the friction on it points to -t."""
    c = ContactConfiguration([[0, 0]], [[0, 1]], 0.4)
    (g,) = contact_wrench_cone(c, "r").generators
    assert g[0] < 0 and g[0] / g[1] == pytest.approx(-0.4)
    (g,) = contact_wrench_cone(c, "l").generators
    assert g[0] > 0 and g[0] / g[1] == pytest.approx(0.4)


def test_ff_carries_no_force():
    c = ContactConfiguration.edge([-1, 0], [1, 0], [0, 1], 1.0)
    cone = contact_wrench_cone(c, "ff")
    assert cone.dimension == 0 and not cone.contains([0, 1, 0])


def test_bad_mode_is_rejected():
    c = ContactConfiguration.edge([-1, 0], [1, 0], [0, 1], 1.0)
    with pytest.raises(ValueError):
        contact_wrench_cone(c, "s")
    with pytest.raises(ValueError):
        contact_wrench_cone(c, "sx")


@pytest.mark.parametrize("mu, spans", [(1.2, True), (0.8, False)])
def test_two_perpendicular_sticking_contacts_span_the_force_space_when_mu_exceeds_one(mu, spans):
    """§3.1: for ss the moment-labelling regions disappear for mu > 1 (contacts with normals 90
    degrees apart, as in the corner configuration of fig. 5)."""
    c = ContactConfiguration([[0, -1], [-1, 0]], [[0, 1], [1, 0]], mu)
    cone = contact_wrench_cone(c, "ss")
    labels = moment_labels(cone, WINDOW)
    assert (len(cone.rows) == 0) == spans
    assert (labels[1].is_empty and labels[-1].is_empty) == spans


@pytest.mark.parametrize("seed", range(4))
def test_moment_labels_by_direct_moments(seed):
    """P+ holds the points about which every generator has a non-negative moment, P- non-positive."""
    rng = np.random.default_rng(seed)
    config = random_configuration(rng, k=2, mu=0.3)
    cone = contact_wrench_cone(config, "ss")
    labels = moment_labels(cone, WINDOW)
    q = rng.uniform(-4, 4, (500, 2))
    g = cone.generators
    moment = g[:, 2][None] - (q[:, 0:1] * g[:, 1][None] - q[:, 1:2] * g[:, 0][None])  # about q
    for sense, region in labels.items():
        want = np.all(sense * moment >= 0, axis=1)
        clear = region.boundary.distance(shapely.points(q)) > 1e-6 if not region.is_empty else np.ones(len(q), bool)
        got = region.contains(shapely.points(q)) if not region.is_empty else np.zeros(len(q), bool)
        np.testing.assert_array_equal(got[clear], want[clear])


def test_moment_about_a_point_is_power_on_a_rotation_about_it():
    rng = np.random.default_rng(0)
    p, f, q = rng.normal(size=(3, 20, 2))
    w = point_wrench(p, f)
    np.testing.assert_allclose(np.sum(w * cor_to_twist(q, 1), axis=1), B.cross(p - q, f))
