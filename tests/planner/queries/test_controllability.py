"""Accessibility, controllability and STLC by stable pushes (Lynch & Mason 1996, §2-3; docs/mechanics.md, "Controllability").

The hand-built twist sets are checked against reasoning that does not use the code's linear
programmes: the Lie bracket computed by finite differences for Prop. 1, the convex hull of the
twists for Sussmann's Thm. 1, and pictures of rotation centres for Prop. 4 (Fig. 7).
"""

import re

import numpy as np
import pytest
from scipy.spatial import ConvexHull

from mechanics import controllability as twists_controllability
from planner import SceneError, controllability, load_scene, parse_scene
from planner.actions.controls import edge_controls


def ccw(c):
    """Counter-clockwise rotation about centre ``c`` (docs/mechanics.md, "Conventions")."""
    return [c[1], -c[0], 1.0]


def cw(c):
    """Clockwise rotation about centre ``c``."""
    return [-c[1], c[0], -1.0]


# A parallelogram whose short edges 0 and 2 have their CF beyond the contact and too little friction
# to push through it (Prop. 6: no stable push), while the long edges 1 and 3 face each other.
SKEW = dict(slider=dict(vertices=[[0, 0], [0.1, 0], [0.3, 0.1], [0.2, 0.1]]),
            pusher=dict(width=0.3, depth=0.01, mu=0.1),
            workspace=dict(min=[-1, -1], max=[1, 1]), start=[0, 0, 0], goal=[0.5, 0.5, 0])


@pytest.fixture(scope="module")
def parking():
    return load_scene("scenes/parking.yaml")


# --- Prop. 1 and 2: accessibility and controllability ---------------------------------------

@pytest.mark.parametrize("twists, accessible", [
    ([ccw([0, 0]), ccw([1, 0])], True),            # two centres, one sense (Fig. 5)
    ([ccw([0, 0]), cw([1, 0])], True),             # two centres, both senses
    ([ccw([2, 1]), [0, 1, 0]], True),              # a rotation and a translation (Fig. 4)
    ([[1, 0, 0], [0, 1, 0]], False),               # two translations
    ([[1, 0, 0], [0, 1, 0], [-1, -1, 0]], False),  # translations every way: still no turning
    ([ccw([1, 2]), ccw([1, 2])], False),           # one control twice
    ([ccw([1, 2]), np.multiply(3, ccw([1, 2]))], False),  # the same direction, faster
    ([ccw([0, 0]), cw([0, 0])], False),            # turning both ways on the spot: one degree of freedom
    ([ccw([1, 2])], False),
    (np.zeros((0, 3)), False),
])
def test_prop1_accessibility(twists, accessible):
    c = twists_controllability(twists)
    assert (c.accessible, c.controllable) == (accessible, accessible)
    assert (c.pair is not None) == accessible
    assert not (c.stlc and not accessible)


def _bracket_det(v1, v2, q):
    """``det(X1, X2, [X1, X2])`` at ``q`` with the bracket by central differences: the vector
    fields are ``X(q) = R(theta) v``, which depend on theta only."""
    def field(v, theta):
        c, s = np.cos(theta), np.sin(theta)
        return np.array([c * v[0] - s * v[1], s * v[0] + c * v[1], v[2]])

    h = 1e-6
    d1 = (field(v1, q[2] + h) - field(v1, q[2] - h)) / (2 * h)
    d2 = (field(v2, q[2] + h) - field(v2, q[2] - h)) / (2 * h)
    bracket = d2 * v1[2] - d1 * v2[2]  # DX2 X1 - DX1 X2, only the theta column is nonzero
    return np.linalg.det(np.column_stack([field(v1, q[2]), field(v2, q[2]), bracket]))


def test_prop1_pair_agrees_with_the_lie_bracket():
    rng = np.random.default_rng(0)
    samples = [rng.normal(size=(2, 3)) for _ in range(200)]
    samples += [np.array([[*rng.normal(size=2), 0], [*rng.normal(size=2), 0]]) for _ in range(20)]  # translations
    samples += [np.array([v, -2.5 * v]) for v in rng.normal(size=(20, 3))]  # one line
    for v in samples:
        unit = v / np.linalg.norm(v, axis=1)[:, None]
        det = _bracket_det(unit[0], unit[1], rng.uniform(-np.pi, np.pi, size=3))
        assert twists_controllability(v).accessible == (abs(det) > 1e-8), v


# --- Prop. 4 and Thm. 1: small-time local controllability -----------------------------------

@pytest.mark.parametrize("twists, stlc, lineality", [
    # Fig. 7: CCW about (0, 1), CW about (0, -1), translations both ways across their line x = 0.
    ([ccw([0, 1]), cw([0, -1]), [1, 0, 0], [-1, 0, 0]], True, 2),
    # Both senses about two centres: every centre on their line, both senses.
    ([ccw([0, 1]), cw([0, 1]), ccw([0, -1]), cw([0, -1])], True, 2),
    # A CCW and a CW centre alone: the line outside the segment between them, one way only.
    ([ccw([0, 1]), cw([0, -1])], False, 0),
    # Two same-sense centres and the translations between: a segment of centres, no great circle.
    ([ccw([0, 1]), ccw([0, -1]), [1, 0, 0], [-1, 0, 0]], False, 1),
    # Translations every way plus a turn: the only great circle is omega = 0 (boundary case).
    ([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], ccw([0.3, 0.2])], False, 2),
    ([[1, 0, 0], [0, 1, 0], [-1, -1, 0], ccw([0.3, 0.2]), ccw([-1, 0])], False, 2),
    # Turns both ways plus translations every way: a CW turn is undone by a CCW one and a
    # translation (their sum is a translation), so every direction is spanned.
    ([[1, 0, 0], [0, 1, 0], [-1, -1, 0], cw([0.3, 0.2]), ccw([-1, 0])], True, 3),
    # Turning both ways on the spot, translating only one way: a line, no circle.
    ([ccw([0, 0]), cw([0, 0]), [1, 0, 0]], False, 1),
    # Every direction (0 inside the convex hull, Thm. 1).
    ([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], True, 3),
    ([[1, 0, 0], [0, 1, 0], [0, 0, 1], [-1, -1, -1]], True, 3),
])
def test_prop4_cases(twists, stlc, lineality):
    c = twists_controllability(twists)
    assert (c.stlc, c.lineality) == (stlc, lineality)
    assert bool(c.spanning) == stlc
    assert re.search(r"\(Props?\. (2, )?4\)$", c.reason) and c.reason.startswith("small-time") == stlc


def _stlc_alone(twists):
    return twists_controllability(twists).stlc


def _random_sets(seed, count=150):
    rng = np.random.default_rng(seed)
    return [rng.normal(size=(rng.integers(2, 8), 3)) for _ in range(count)]


def test_thm1_generic_sets_agree_with_the_convex_hull():
    """Generic twists span no plane exactly, so STLC is exactly 0 inside their convex hull."""
    for v in _random_sets(1):
        unit = v / np.linalg.norm(v, axis=1)[:, None]
        points = np.vstack([unit, np.zeros(3)])
        # In general position 0 is inside the twists' hull iff it is not a corner of the hull of
        # the twists and 0 (three twists and 0 make a tetrahedron with 0 a corner).
        inside = len(unit) >= 4 and len(unit) not in ConvexHull(points).vertices
        c = twists_controllability(v)
        assert c.stlc == inside, v
        assert c.lineality == (3 if inside else 0)


def test_spanning_set_is_minimal_and_enough():
    cases = [v for v in _random_sets(2, 80) if _stlc_alone(v)]
    cases.append(np.array([ccw([0, 1]), cw([0, -1]), [1, 0, 0], [-1, 0, 0], [0, 1, 0]]))
    assert len(cases) > 10
    for v in cases:
        spanning = list(twists_controllability(v).spanning)
        assert 3 <= len(spanning) <= 6
        assert _stlc_alone(v[spanning])
        for k in spanning:
            assert not _stlc_alone(v[[i for i in spanning if i != k]])


def test_zero_rows_are_ignored_and_indices_kept():
    c = twists_controllability([[0, 0, 0], ccw([0, 1]), cw([0, -1]), [0, 0, 0], [-1, 0, 0]])
    assert c.stlc and c.spanning == (1, 2, 4)
    with pytest.raises(ValueError):
        twists_controllability([[np.nan, 0, 1]])


def _verdict(v):
    c = twists_controllability(v)
    return c.accessible, c.stlc, c.lineality


def test_invariant_under_positive_scaling_and_rotation_of_the_slider_frame():
    rng = np.random.default_rng(3)
    hand = [np.array(v, dtype=float) for v in (
        [ccw([0, 1]), cw([0, -1]), [1, 0, 0], [-1, 0, 0]],
        [[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], ccw([0.3, 0.2])],
        [ccw([0, 1]), ccw([0, -1]), [1, 0, 0], [-1, 0, 0]],
        [[1, 0, 0], [0, 1, 0], [-1, -1, 0]],
        [ccw([0, 0]), ccw([1, 0])],
    )]
    for v in hand + _random_sets(4, 30):
        expected = _verdict(v)
        for _ in range(3):
            scaled = v * rng.uniform(0.01, 100, size=(len(v), 1))
            phi = rng.uniform(-np.pi, np.pi)
            rot = np.array([[np.cos(phi), -np.sin(phi), 0], [np.sin(phi), np.cos(phi), 0], [0, 0, 1]])
            assert _verdict(scaled) == expected
            assert _verdict(v @ rot.T) == expected


# --- scenes: the paper's cases ----------------------------------------------------------------

def test_one_edge_of_a_rectangle_is_controllable_not_stlc(parking):
    c = controllability(parking.with_part(edges=(0,)))
    assert c.controllable and not c.stlc and c.stlc_edges == ()
    assert c.summary() == ("controllable (edge 0); not small-time locally controllable: one edge never is "
                           "(it cannot pull back)")


@pytest.mark.parametrize("edges", [(0, 2), (1, 3)])
def test_two_opposite_edges_of_a_rectangle_are_stlc(parking, edges):
    """The corollary to Thm. 7: a rectangle with the CF inside, pushed on two opposing edges."""
    c = controllability(parking.with_part(edges=edges))
    assert c.stlc and c.stlc_edges == edges and c.opposite
    assert not any(e.stlc for e in c.per_edge.values())  # it takes both


def test_stable_regions_too(parking):
    """Thm. 7 is about procedure STABLE's pushes, inside the exact ones."""
    assert controllability(parking.with_part(edges=(0, 2)), regions="stable").stlc
    assert not controllability(parking.with_part(edges=(0,)), regions="stable").stlc


def test_an_edge_with_no_stable_push_is_skipped():
    c = controllability(parse_scene(SKEW))
    assert c.empty == (0, 2) and set(c.per_edge) == {1, 3}
    assert c.stlc and c.stlc_edges == (1, 3) and c.opposite
    assert c.summary().endswith("; edges 0 and 2 have no stable push")


def test_no_stable_push_at_all_is_not_accessible():
    c = controllability(parse_scene({**SKEW, "pusher": {**SKEW["pusher"], "edges": [0, 2]}}))
    assert not c.controllable and not c.stlc and c.per_edge == {}
    assert c.summary() == "not accessible: no allowed edge has a stable push (edges 0 and 2)"


def test_refused_method_is_not_reported_as_no_push(parking):
    with pytest.raises(SceneError, match="planner.regions"):
        controllability(parking.with_part(cf_uncertainty=0.001), regions="stable")


@pytest.mark.parametrize("name", ["parking", "nonconvex", "battery"])
@pytest.mark.parametrize("regions", ["exact", "stable"])
def test_one_edge_lies_in_a_half_space(name, regions):
    """Every stable twist of an edge moves the contact's midpoint m into the part:
    ``a = (v_xy + omega k x m) . n > 0``, so its cone holds no line and the edge alone is not STLC."""
    scene = load_scene(f"scenes/{name}.yaml")
    c = controllability(scene, regions=regions, transit="none")
    twists = {p.edge: p.region.extremal_twists() for p in edge_controls(scene, regions=regions)}
    assert set(twists) == set(c.per_edge)
    for edge, alone in c.per_edge.items():
        n = scene.slider.inward_normal(edge)
        m = scene.slider.contact(edge, scene.pusher.width).mean(axis=0)
        v = twists[edge]
        a = (v[:, :2] + v[:, 2:] * np.array([-m[1], m[0]])) @ n
        assert np.all(a > 0), (edge, a.min())
        assert alone.controllable and not alone.stlc and alone.lineality == 0
    assert not c.stlc


# --- the shipped scenes -------------------------------------------------------------------------

def test_parking_is_stlc_with_switching_and_no_edge_alone_is(parking):
    c = controllability(parking, transit=parking.options.transit)
    assert parking.options.transit == "plane" and set(c.per_edge) == {0, 1, 2, 3}
    assert c.controllable and c.stlc and c.stlc_edges == (0, 2) and c.union.lineality == 3
    assert c.summary() == ("controllable (edges 0, 1, 2, 3); small-time locally controllable with edges 0 and 2 "
                           "(opposite faces)")
    none = controllability(parking, transit="none")
    assert none.controllable and not none.stlc
    assert all(e.controllable and not e.stlc for e in none.per_edge.values())
    assert "transit none keeps to one edge" in none.summary()


@pytest.mark.parametrize("name, stlc", [("battery", False), ("cluttered", True), ("corridor", True),
                                        ("junction", True), ("narrow_junction", True), ("nonconvex", True)])
def test_shipped_scenes(name, stlc):
    c = controllability(load_scene(f"scenes/{name}.yaml"))
    assert c.controllable and c.stlc == stlc
    if stlc:
        assert len(c.stlc_edges) == 2 and c.opposite
