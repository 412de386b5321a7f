"""Kinematic analysis: Reuleaux's method and the positive combination (Lynch 1992, §2).

Sources of truth: the paper's rules as assertions (sign rule of §2.1, fig. 6's positive
combination, COR_s = COR_p is ss, all regions meet at COR_p, no overlap when every contact is
pushed into the slider, footnote 2's overlap otherwise) and contact-point velocities written out
in ``brute_force``.
"""

from __future__ import annotations

import numpy as np
import pytest
import shapely

import brute_force as B
from mechanics import (
    ContactConfiguration,
    contact_modes,
    contact_wrench_cone,
    cor_to_twist,
    force_status,
    kinematic_cone,
    kinematic_cones,
    modes_of_motion,
    relative_cone,
    relative_mode,
    SupportModel,
)

EDGE = ContactConfiguration.edge([-1, 0], [1, 0], [0, 1], 0.5)
# Fig. 5-like corner: a contact on the bottom face and one on the left face.
CORNER = ContactConfiguration([[0.2, 0], [-1, 0.6]], [[0, 1], [1, 0]], 0.5)
WINDOW = (-6, -6, 6, 6)


def random_configuration(rng):
    k = int(rng.integers(1, 4))
    angle = rng.uniform(0, 2 * np.pi, k)
    return ContactConfiguration(rng.uniform(-1, 1, (k, 2)), np.stack([np.cos(angle), np.sin(angle)], 1), 0.5)


def normal_speeds(config, twist):
    """Normal velocity of the slider at each contact: > 0 separates, < 0 penetrates."""
    return np.sum(B.velocity(twist, config.points) * config.normals, axis=1)


def pushing_twist(rng, config):
    """A random pusher twist that moves into the slider at every contact."""
    while True:
        v = np.r_[rng.normal(size=2), rng.normal()]
        if np.all(normal_speeds(config, v) > 0.05 * np.linalg.norm(v)):
            return v


# ----------------------------------------------------------------------------------------------
# Reuleaux (§2.1)


@pytest.mark.parametrize("seed", range(4))
def test_reuleaux_sign_rule(seed):
    """A CCW relative COR must lie left of every contact normal it is not on, a CW one right."""
    rng = np.random.default_rng(seed)
    config = random_configuration(rng)
    for _ in range(200):
        c, sense = rng.uniform(-3, 3, 2), int(rng.choice([-1, 1]))
        side = B.cross(config.normals, c - config.points)  # > 0: c left of the directed normal
        legal = np.all(sense * side > 0)
        mode = relative_mode(config, cor_to_twist(c, sense))
        assert (mode is not None) == legal
        if legal:
            assert mode == "f" * len(config)


def test_labels_on_the_normal_and_at_the_contact():
    """§2.1: a COR at the contact point sticks there; elsewhere on its normal it slides, r or l by
    the sense; elsewhere it breaks."""
    c = ContactConfiguration([[0, 0]], [[0, 1]], 0.5)
    assert relative_mode(c, cor_to_twist([0, 0], 1)) == "s"
    assert relative_mode(c, cor_to_twist([0, 0], -1)) == "s"
    assert relative_mode(c, cor_to_twist([0, 2], 1)) == "r"  # CCW above: the contact point moves right
    assert relative_mode(c, cor_to_twist([0, 2], -1)) == "l"
    assert relative_mode(c, cor_to_twist([0, -2], 1)) == "l"
    assert relative_mode(c, cor_to_twist([-1, 1], 1)) == "f"
    assert relative_mode(c, [1, 0, 0]) == "r" and relative_mode(c, [0, 1, 0]) == "f"
    assert relative_mode(c, [0, -1, 0]) is None


def test_edge_contact_modes():
    """Edge contact (§3.5): both sliding, pivoting on either end, one end sliding while the other
    lifts, and ss; never one end sliding while the other sticks."""
    assert set(contact_modes(EDGE)) == {"ss", "sf", "fs", "rr", "ll", "rf", "fr", "lf", "fl"}
    assert "ff" in contact_modes(EDGE, include_free=True) and "ff" not in contact_modes(EDGE)


@pytest.mark.parametrize("seed", range(4))
def test_modes_partition_the_legal_relative_twists(seed):
    """Every non-penetrating relative twist has exactly one mode, the one whose open cone holds it."""
    rng = np.random.default_rng(seed)
    config = random_configuration(rng)
    modes = contact_modes(config, include_free=True)
    cones = {m: relative_cone(config, m) for m in modes}
    for _ in range(150):
        rho = rng.normal(size=3)
        mode = relative_mode(config, rho)
        holders = [m for m, cone in cones.items() if cone.contains(rho, interior=True)]
        assert holders == ([] if mode is None else [mode])


def test_relative_twists_on_mode_boundaries():
    """Lower-dimensional modes: sliding both ends is a translation along the face; pivoting on the
    left end a rotation about it."""
    np.testing.assert_allclose(relative_cone(EDGE, "rr").generators, [[1, 0, 0]], atol=1e-12)
    (g,) = relative_cone(EDGE, "sf").generators
    np.testing.assert_allclose(g / g[2], cor_to_twist([-1, 0], 1), atol=1e-12)


# ----------------------------------------------------------------------------------------------
# Slider motions in the support frame (§2.2-2.3)


@pytest.mark.parametrize("config", [EDGE, CORNER], ids=["edge", "corner"])
def test_moving_with_the_pusher_is_ss(config):
    rng = np.random.default_rng(1)
    for _ in range(10):
        vp = pushing_twist(rng, config)
        assert modes_of_motion(config, vp, vp) == ("s" * len(config),)
        assert modes_of_motion(config, vp, 2.5 * vp) == ("s" * len(config),)  # directions only


@pytest.mark.parametrize("config", [EDGE, CORNER], ids=["edge", "corner"])
def test_all_mode_regions_meet_at_the_pushers_cor(config):
    rng = np.random.default_rng(2)
    for _ in range(5):
        vp = pushing_twist(rng, config)
        vp = vp / abs(vp[2])
        cor_p, sense = np.array([-vp[1], vp[0]]) / vp[2], int(np.sign(vp[2]))
        window = (*(cor_p - 6), *(cor_p + 6))
        for mode in contact_modes(config):
            cone = kinematic_cone(config, mode, vp)
            assert cone.contains(vp), mode
            assert cone.cor_region(sense, window).distance(shapely.Point(cor_p)) < 1e-9, mode


@pytest.mark.parametrize("config", [EDGE, CORNER], ids=["edge", "corner"])
def test_no_overlap_when_every_contact_is_pushed_into_the_slider(config):
    """§2.3: then a (COR_p, COR_s) pair is illegal or has a unique mode."""
    rng = np.random.default_rng(3)
    for _ in range(6):
        vp = pushing_twist(rng, config)
        cones = kinematic_cones(config, vp).values()
        for vs in rng.normal(size=(150, 3)):
            assert sum(bool(c.contains(vs, interior=True)) for c in cones) <= 1


def test_overlap_when_a_contact_recedes():
    """Footnote 2: contact can be kept at a point moving away from the slider, and then the regions
    of different modes overlap."""
    vp = cor_to_twist([0.0, -1.0], -1)  # CW about (0, -1): the right end recedes, the left one pushes
    assert min(normal_speeds(EDGE, vp)) < 0 < max(normal_speeds(EDGE, vp))
    rng = np.random.default_rng(4)
    cones = kinematic_cones(EDGE, vp).values()
    counts = [sum(bool(c.contains(vs, interior=True)) for c in cones) for vs in rng.normal(size=(400, 3))]
    assert max(counts) >= 2


@pytest.mark.parametrize("seed", range(3))
def test_union_of_modes_is_every_legal_slider_motion(seed):
    """V_s is legal iff V_s = a V_p + rho with a > 0 and rho non-penetrating: an interval of a,
    computed here from the contact-point velocities."""
    rng = np.random.default_rng(seed)
    config = random_configuration(rng)
    vp = rng.normal(size=3)
    modes = contact_modes(config, include_free=True)
    cones = [kinematic_cone(config, m, vp) for m in modes]
    checked = 0
    for vs in rng.normal(size=(300, 3)):
        s, p = normal_speeds(config, vs), normal_speeds(config, vp)  # need s - a p >= 0
        lo = max([0.0] + [si / pi for si, pi in zip(s, p) if pi < 0])
        hi = min([np.inf] + [si / pi for si, pi in zip(s, p) if pi > 0])
        if abs(hi - lo) < 1e-6:  # too close to a boundary to call
            continue
        legal = hi > lo
        assert any(c.contains(vs, interior=True) for c in cones) == legal
        checked += 1
    assert checked > 200


def test_positive_combination_rule_same_sense():
    """Fig. 6: same-sense CORs combine to the open segment between them."""
    vp = cor_to_twist([-3.0, 2.0], 1)  # CCW about (-3, 2), pushing both ends in
    assert np.all(normal_speeds(EDGE, vp) > 0)
    cone = kinematic_cone(EDGE, "sf", vp)  # relative: CCW about the left end (-1, 0)
    segment = cone.cor_region(1, WINDOW)
    assert segment.normalize().equals_exact(shapely.LineString([[-1, 0], [-3, 2]]).normalize(), 1e-9)
    assert cone.cor_region(-1, WINDOW).is_empty
    for t in (0.1, 0.5, 0.9):
        c = (1 - t) * np.array([-1.0, 0.0]) + t * np.array([-3.0, 2.0])
        assert modes_of_motion(EDGE, vp, cor_to_twist(c, 1)) == ("sf",)


def test_positive_combination_rule_opposite_senses():
    """Fig. 6: opposite-sense CORs combine to the outer parts of their line; the sense flips at
    infinity (translation)."""
    vp = cor_to_twist([3.0, 2.0], -1)  # CW about (3, 2)
    assert np.all(normal_speeds(EDGE, vp) > 0)
    cone = kinematic_cone(EDGE, "sf", vp)  # relative CCW about (-1, 0)
    a, b = np.array([-1.0, 0.0]), np.array([3.0, 2.0])
    for t, sense in ((-0.5, 1), (-2.0, 1), (1.5, -1), (3.0, -1)):  # beyond a: CCW, beyond b: CW
        c = a + t * (b - a)
        assert cone.contains(cor_to_twist(c, sense), interior=True), (t, sense)
        assert not cone.contains(cor_to_twist(c, -sense), interior=True)
    for t in (0.3, 0.7):  # between them: neither sense
        c = a + t * (b - a)
        assert not cone.contains(cor_to_twist(c, 1)) and not cone.contains(cor_to_twist(c, -1))
    e = (a - b) / np.linalg.norm(a - b)  # a CCW COR far beyond a is the translation (e_y, -e_x)
    assert cone.contains([e[1], -e[0], 0.0], interior=True)


def test_ff_is_not_a_motion():
    """The all-breaking mode carries no force, so it is never mapped and every motion is I."""
    vp = cor_to_twist([0.0, -5.0], 1)
    assert all("ff" != m for m in modes_of_motion(EDGE, vp, [0, 1, 1]))
    support = SupportModel.disk([0, 0.5], 1.2)
    cone = contact_wrench_cone(EDGE, "ff")
    for twist in ([0, 1, 0], cor_to_twist([0, 0.5], 1), cor_to_twist([3, 1], -1)):
        assert force_status(twist, cone, support).status == "I"
