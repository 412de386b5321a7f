"""The quasi-static pushing simulator (mechanics.quasistatic) against independent reasoning.

Sources of truth, none of them the code under test (and none of the stable-region code):
* first principles re-written here: the load of a twist (Mason 1986) and a finite-difference
  gradient of the dissipated power; Coulomb's law checked by a linear program of this file;
* hand-derived pushes: a translation's load is a pure force through the CF for every support
  distribution, so it sticks iff its line crosses the contact inside the friction cone; far
  rotation centres of docs/mechanics.md, "Fixtures", fixture A (its STABLE wedge apexes are (-2, 0.5) CCW and
  (2, 0.5) CW, the wedges opening away from the part);
* Mason's voting theorem for a point contact (docs/mechanics.md, "Voting theorem");
* symmetry (mirror) and convergence of the integrator as the step shrinks.
"""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from scipy.optimize import linprog

from mechanics import cor_to_twist, exp_twist
from mechanics.quasistatic import (Contact, ContactMode, SupportDistribution, adjoint, dipod_supports,
                                   grid_support, random_support, simulate_push, solve_step, tripod_supports)

STICK, LEFT, RIGHT, SEPARATE = ContactMode.STICK, ContactMode.SLIDE_LEFT, ContactMode.SLIDE_RIGHT, ContactMode.SEPARATE
BLOCK = shapely.box(-1, 0, 1, 1)  # fixture A's 2 x 1 rectangle, pushed on its bottom edge
UP = np.array([0.0, 1.0])


def line_contact(mu, a=-1.0, b=1.0):
    return [Contact([a, 0.0], UP, mu), Contact([b, 0.0], UP, mu)]


def distributions(footprint, cf, seed, random=4, dipods=8, tripods=8):
    """Grid, random, dipods and tripods, all with their centre at ``cf``."""
    rng = np.random.default_rng(seed)
    return ([grid_support(footprint, 60, cf=cf)]
            + [random_support(footprint, 40, rng, cf=cf) for _ in range(random)]
            + dipod_supports(footprint, cf, dipods) + tripod_supports(footprint, cf, tripods, rng))


def modes(result):
    return [s.mode for s in result.solutions]


# -- independent first principles ------------------------------------------------------------------

def velocities(support, twist):
    vx, vy, w = twist
    x, y = support.points.T
    return np.stack([vx - w * y, vy + w * x], axis=1)


def load(support, twist, keep=slice(None)):
    """Mason's load: sum_i w_i (u_i, x_i x u_i), u_i the unit velocity of support point i."""
    v = velocities(support, twist)[keep]
    u = v / np.linalg.norm(v, axis=1, keepdims=True)
    x, y = support.points[keep].T
    return support.weights[keep] @ np.stack([u[:, 0], u[:, 1], x * u[:, 1] - y * u[:, 0]], axis=1)


def at_rest(support, twist):
    """Support points at the COR of ``twist`` (their friction force is undetermined)."""
    speed = np.linalg.norm(velocities(support, twist), axis=1)
    return speed <= 1e-6 * np.linalg.norm(twist) * (1 + support.radius)


def cone_generators(contacts, mode):
    """Wrenches spanning the contact forces Coulomb's law allows in ``mode``, columns (3, k)."""
    gens = []
    for c, m in zip(contacts, mode):
        t = np.array([c.normal[1], -c.normal[0]])
        dirs = {STICK: [c.normal - c.mu * t, c.normal + c.mu * t], LEFT: [c.normal - c.mu * t],
                RIGHT: [c.normal + c.mu * t], SEPARATE: []}[m]
        gens += [[d[0], d[1], c.point[0] * d[1] - c.point[1] * d[0]] for d in dirs]
    return np.array(gens).reshape(-1, 3).T


def balanced_by(support, generators, twist, sides=256):
    """A non-negative combination of ``generators`` equals the load of ``twist``, each support
    point at the COR adding any force of norm <= its weight (circumscribed polygon)."""
    rest = at_rest(support, twist)
    angles = 2 * np.pi * np.arange(sides) / sides
    cols = [generators]
    for (px, py), wk in zip(support.points[rest], support.weights[rest]):
        f = -wk / np.cos(np.pi / sides) * np.stack([np.cos(angles), np.sin(angles)])
        cols.append(np.vstack([f, px * f[1] - py * f[0]]))
    a_eq = np.hstack(cols)
    a_ub = np.zeros((rest.sum(), a_eq.shape[1]))
    for i in range(rest.sum()):
        a_ub[i, generators.shape[1] + i * sides:generators.shape[1] + (i + 1) * sides] = 1
    res = linprog(np.zeros(a_eq.shape[1]), A_ub=a_ub, b_ub=np.ones(rest.sum()), A_eq=a_eq,
                  b_eq=load(support, twist, ~rest), bounds=(0, None), method="highs")
    return res.status == 0


def balanced(support, contacts, mode, twist):
    """Coulomb force balance for ``mode`` at ``twist``."""
    return balanced_by(support, cone_generators(contacts, mode), twist)


def kinematics(contacts, mode, twist, pusher_twist, tol=1e-7):
    """Contact velocities agree with ``mode`` (relative velocity of the slider at each contact)."""
    scale = tol * (np.linalg.norm(twist) + np.linalg.norm(pusher_twist))
    for c, m in zip(contacts, mode):
        rel = np.subtract(twist, pusher_twist)
        u = rel[:2] + rel[2] * np.array([-c.point[1], c.point[0]])
        un, ut = u @ c.normal, u @ np.array([c.normal[1], -c.normal[0]])
        ok = {STICK: abs(un) <= scale and abs(ut) <= scale, LEFT: abs(un) <= scale and ut > 0,
              RIGHT: abs(un) <= scale and ut < 0, SEPARATE: un > 0}[m]
        if not ok:
            return False
    return True


# -- support distributions and the limit surface ---------------------------------------------------

def test_support_validation():
    s = SupportDistribution([[0, 0], [2, 0], [0, 2]], [2, 1, 1])
    np.testing.assert_allclose(s.weights, [0.5, 0.25, 0.25])
    np.testing.assert_allclose(s.centre, [0.5, 0.5])
    for points, weights, match in [([[0, 0]], None, "at least two"), ([[0, 0], [1, 0]], [1, 0], "positive"),
                                   ([[0, 0], [0, 0]], None, "distinct"), ([[0, 0], [1, np.nan]], None, "finite"),
                                   ([[0, 0], [1, 0]], [1], "weights")]:
        with pytest.raises(ValueError, match=match):
            SupportDistribution(points, weights)


@pytest.mark.parametrize("footprint", [BLOCK, shapely.Polygon([(0, 0), (3, 0), (3, 1), (1, 1), (1, 2), (0, 2)])],
                         ids=["rectangle", "L-shape"])
def test_distributions_have_centre_at_cf_and_lie_in_footprint(footprint):
    cf = np.array(footprint.centroid.coords[0]) + [0.1, -0.05]
    for s in distributions(footprint, cf, seed=3):
        np.testing.assert_allclose(s.centre, cf, atol=1e-9)
        assert all(footprint.buffer(1e-9).covers(shapely.Point(p)) for p in s.points)


def test_load_is_the_gradient_of_dissipation():
    rng = np.random.default_rng(0)
    for s in distributions(BLOCK, [0.2, 0.4], seed=0, random=2, dipods=2, tripods=2):
        for twist in rng.normal(size=(10, 3)):
            np.testing.assert_allclose(s.wrench(twist), load(s, twist), atol=1e-12)
            h = 1e-6
            grad = [(s.dissipation(twist + h * e) - s.dissipation(twist - h * e)) / (2 * h) for e in np.eye(3)]
            np.testing.assert_allclose(s.wrench(twist), grad, atol=1e-6)


def test_twist_for_inverts_the_load():
    rng = np.random.default_rng(1)
    facets = 0
    for s in distributions(BLOCK, [-0.3, 0.6], seed=1, random=3, dipods=2, tripods=3):
        for wrench in rng.normal(size=(20, 3)):
            twist = s.twist_for(wrench)
            assert s.dissipation(twist) == pytest.approx(1.0)
            # Off a facet the load is along the wrench; on one (a support point at rest) the
            # wrench must fit the facet.
            g = wrench / np.linalg.norm(wrench)
            if at_rest(s, twist).any():
                facets += 1
                assert balanced_by(s, g[:, None], twist)
            else:
                w = load(s, twist)
                np.testing.assert_allclose(w / np.linalg.norm(w), g, atol=1e-9)
        for twist in rng.normal(size=(10, 3)):  # round trip from the twist side
            back = s.twist_for(s.wrench(twist))
            if len(s.points) > 2:  # a dipod's limit surface has vertices; others are strictly convex
                np.testing.assert_allclose(back, twist / s.dissipation(twist), atol=1e-8)
    assert 10 < facets < 150  # both kinds of answer were checked


def test_facet_absorbs_force():
    """Three points, a heavy one at the CF: a wrench with a small force turns the part about the
    heavy point exactly (its friction takes any force up to its weight)."""
    s = SupportDistribution([[0.0, 0.0], [1.0, 0.0], [-1.0, 0.0], [0.0, 0.5]], [8.0, 1.0, 1.0, 1e-3])
    twist = s.twist_for([0.05, -0.02, 0.3])
    np.testing.assert_allclose(twist[:2] / twist[2], [0.0, 0.0], atol=1e-15)
    assert twist[2] > 0


# -- sticking pushes -------------------------------------------------------------------------------

@pytest.mark.parametrize("mu", [0.2, 1.0])
@pytest.mark.parametrize("cf", [(0.0, 0.5), (0.4, 0.3), (-0.7, 0.8)])
def test_push_through_cf_along_normal_sticks(cf, mu):
    """A translation along the edge normal needs the pure force n through the CF, inside the
    friction cone of the contact point below the CF, for every distribution."""
    for s in distributions(BLOCK, cf, seed=int(10 * mu)):
        line = solve_step(s, line_contact(mu), [0.0, 1.0, 0.0])
        assert line.sticks, (s, line)
        np.testing.assert_array_equal(line.solutions[0].twist, [0.0, 1.0, 0.0])
        point = solve_step(s, [Contact([cf[0], 0.0], UP, mu)], [0.0, 1.0, 0.0])
        assert point.sticks, (s, point)
        np.testing.assert_allclose(point.solutions[0].twist, [0.0, 1.0, 0.0], atol=1e-9)


ALPHA = np.arctan(0.5)
STABLE_TWISTS = {  # fixture A: BLOCK, CF (0, 0.5), bottom edge, mu = 0.5
    "translation along n": [0.0, 1.0, 0.0],
    "translation tilted left": [-np.sin(ALPHA / 2), np.cos(ALPHA / 2), 0.0],  # line through CF hits x = -0.12
    "translation tilted right": [np.sin(ALPHA / 2), np.cos(ALPHA / 2), 0.0],
    "CCW about (-8, 0.5)": cor_to_twist([-8.0, 0.5], 1),
    "CW about (8, 0.5)": cor_to_twist([8.0, 0.5], -1),
    "CCW about (-6, -2)": cor_to_twist([-6.0, -2.0], 1),
}


@pytest.mark.parametrize("name", STABLE_TWISTS)
def test_stable_twists_stick_for_every_distribution(name):
    twist = STABLE_TWISTS[name]
    for s in distributions(BLOCK, (0.0, 0.5), seed=5, random=6, dipods=12, tripods=12):
        result = solve_step(s, line_contact(0.5), twist)
        assert result.sticks, (name, s, result)
    push = simulate_push(distributions(BLOCK, (0.0, 0.5), seed=5)[0], line_contact(0.5), twist, 0.3,
                         footprint=BLOCK)
    assert push.sticks
    np.testing.assert_allclose(push.final_pose, exp_twist([0, 0, 0], twist, 0.3), atol=1e-12)


# -- unstable pushes -------------------------------------------------------------------------------

def test_push_beyond_friction_cone_slides_for_every_distribution():
    """Translation at twice the friction angle: its load (a pure force along it) is outside the
    cone for every distribution, so the long edge slides along the pusher."""
    long_bar = shapely.box(-2, 0, 2, 0.5)
    angle = 2 * ALPHA
    for sign, mode in [(1, RIGHT), (-1, LEFT)]:
        twist = [sign * np.sin(angle), np.cos(angle), 0.0]
        for s in distributions(long_bar, (0.0, 0.25), seed=7):
            result = solve_step(s, line_contact(0.5, -2.0, 2.0), twist)
            assert modes(result) == [(mode, mode)], (s, result)
            v = result.solutions[0].twist
            # The part translates along the cone edge on the side of the slip.
            np.testing.assert_allclose(v[2], 0.0, atol=1e-9)
            assert v[0] / v[1] == pytest.approx(sign * 0.5)


@pytest.mark.parametrize("cor, sense", [((1.2, -0.1), -1), ((-1.2, -0.1), 1), ((0.3, 0.2), -1)])
def test_rotation_about_a_cor_near_the_contact_slips_for_some_distribution(cor, sense):
    twist = cor_to_twist(cor, sense)
    results = [solve_step(s, line_contact(0.5), twist) for s in distributions(BLOCK, (0.0, 0.5), seed=11)]
    assert not all(r.sticks for r in results)
    assert any((STICK, STICK) not in modes(r) for r in results)  # sticking is not even possible
    assert all(r.solutions for r in results)
    unstable = next(s for s, r in zip(distributions(BLOCK, (0.0, 0.5), seed=11), results) if not r.sticks)
    assert not simulate_push(unstable, line_contact(0.5), twist, 0.2, footprint=BLOCK).sticks


def test_pulling_away_separates():
    s = grid_support(BLOCK, 30)
    result = solve_step(s, line_contact(0.5), [0.3, -1.0, 0.0])
    assert modes(result) == [(SEPARATE, SEPARATE)]
    np.testing.assert_array_equal(result.solutions[0].twist, 0.0)
    push = simulate_push(s, line_contact(0.5), [0.3, -1.0, 0.0], 1.0)
    assert (push.status, push.steps, push.final_pose.tolist()) == ("separated", 0, [0.0, 0.0, 0.0])


# -- every reported solution obeys the laws, and there is one -------------------------------------

def random_distribution(rng):
    cf = rng.uniform([-0.8, 0.2], [0.8, 0.8])
    kind = rng.integers(4)
    if kind == 0:
        return grid_support(BLOCK, 40, cf=cf)
    if kind == 1:
        return random_support(BLOCK, int(rng.integers(3, 30)), rng)
    if kind == 2:
        return dipod_supports(BLOCK, cf, 5)[rng.integers(5)]
    return tripod_supports(BLOCK, cf, 1, rng)[0]


def random_case(rng):
    """A random support, a line or point contact on the bottom edge, a pusher twist pressing or
    pulling (not gliding) at each contact."""
    a, b = sorted(rng.uniform(-1, 1, 2))
    contacts = line_contact(rng.uniform(0.1, 1.5), a, b) if rng.random() < 0.6 else [
        Contact([rng.uniform(-1, 1), 0.0], UP, rng.uniform(0.1, 1.5))]
    s = random_distribution(rng)
    while True:
        twist = cor_to_twist(rng.uniform([-4, -3], [4, 3]), rng.choice([-1, 1])) if rng.random() < 0.8 else \
            np.r_[rng.normal(size=2), 0.0]
        speeds = [(twist[:2] + twist[2] * np.array([-c.point[1], c.point[0]])) @ UP for c in contacts]
        if min(abs(v) for v in speeds) > 1e-3 * np.linalg.norm(twist):
            return s, contacts, twist


def test_every_solution_satisfies_kinematics_and_force_balance():
    rng = np.random.default_rng(2024)
    for _ in range(80):
        s, contacts, twist = random_case(rng)
        result = solve_step(s, contacts, twist)
        assert result.solutions, (s, contacts, twist)  # quasi-static pushing always has a motion
        for sol in result.solutions:
            assert kinematics(contacts, sol.mode, sol.twist, twist), (sol, contacts, twist)
            assert balanced(s, contacts, sol.mode, sol.twist), (sol, contacts, twist)


def test_the_force_balance_check_can_fail():
    """The check above is not vacuous: a solution's twist moved off its root breaks balance."""
    s = grid_support(BLOCK, 40)
    contacts = [Contact([0.6, 0.0], UP, 0.3)]
    sol = solve_step(s, contacts, [0.0, 1.0, 0.0]).solutions[0]
    assert balanced(s, contacts, sol.mode, sol.twist)
    assert not balanced(s, contacts, sol.mode, sol.twist + [0.0, 0.0, 0.05])


def test_ambiguous_corner_push_reports_every_mode():
    """An L-shaped pusher on the bottom-left corner, high friction, pushing up and slightly right:
    Coulomb friction allows both carrying the part rigidly and pivoting it about the bottom
    contact away from the side finger. Both are reported, each obeys the laws, the push is not
    called stable."""
    s = grid_support(BLOCK, 40)
    corner = [Contact([-0.5, 0.0], UP, 1.2), Contact([-1.0, 0.2], [1.0, 0.0], 1.2)]
    twist = [np.cos(1.276), np.sin(1.276), 0.0]
    result = solve_step(s, corner, twist)
    assert modes(result) == [(STICK, STICK), (STICK, SEPARATE)] and result.ambiguous and not result.sticks
    for sol in result.solutions:
        assert kinematics(corner, sol.mode, sol.twist, twist) and balanced(s, corner, sol.mode, sol.twist)
    push = simulate_push(s, corner, twist, 0.1, dt=0.01)
    assert push.ambiguous_steps == 10 and not push.sticks


def test_cor_on_a_heavy_support_point_can_stick():
    """The pusher turns about a heavy support point: that point's friction can take any force up
    to its weight (a facet of the limit surface), which is what lets both ends stick here; the
    other points alone load the pusher with an almost pure moment, outside the contact's cone."""
    heavy = np.array([0.5, 0.4])
    s = SupportDistribution([heavy, [-0.5, 0.2], [0.0, 0.8], [-0.8, 0.7]], [0.9, 0.04, 0.03, 0.03])
    twist = cor_to_twist(heavy, 1)
    result = solve_step(s, line_contact(0.5), twist)
    assert (STICK, STICK) in modes(result)
    assert balanced(s, line_contact(0.5), (STICK, STICK), twist)
    others = SupportDistribution(s.points[1:], s.weights[1:])
    assert not balanced(others, line_contact(0.5), (STICK, STICK), twist)


def test_point_push_pivots_about_a_heavy_leg():
    """A finger pushes the bottom edge straight up while a heavy support point sits on the bottom
    edge to its right: the part pivots about that leg, the finger sticking. The pivot's COR is the
    leg itself (on a facet), so only the facet's free force balances the push."""
    leg = np.array([0.8, 0.0])
    s = SupportDistribution([leg, [-0.5, 0.5], [0.3, 0.8], [-0.2, 0.2]], [0.85, 0.05, 0.05, 0.05])
    finger = [Contact([0.0, 0.0], UP, 0.5)]
    result = solve_step(s, finger, [0.0, 1.0, 0.0])
    assert modes(result) == [(STICK,)]
    twist = result.solutions[0].twist
    np.testing.assert_allclose(twist, cor_to_twist(leg, -1) / 0.8, atol=1e-9)  # CW about the leg
    assert balanced(s, finger, (STICK,), twist)


# -- Mason's voting theorem for a point contact ----------------------------------------------------

def test_point_contact_rotation_sense_follows_the_voting_theorem():
    """The pushing direction and the two friction-cone edges, as lines through the contact, each
    vote for the rotation sense their moment about the CF gives; the majority wins."""
    rng = np.random.default_rng(99)
    checked = 0
    while checked < 40:
        width, height = rng.uniform(0.5, 3, 2)
        box = shapely.box(-width / 2, 0, width / 2, height)
        cf = rng.uniform([-0.3 * width, 0.2 * height], [0.3 * width, 0.8 * height])
        s = [grid_support(box, 50, cf=cf), random_support(box, 30, rng),
             tripod_supports(box, cf, 1, rng)[0]][checked % 3]
        p = np.array([rng.uniform(-width / 2, width / 2), 0.0])
        mu, beta = rng.uniform(0.1, 1.5), rng.uniform(-1.2, 1.2)
        push = np.array([np.sin(beta), np.cos(beta)])
        t = np.array([1.0, 0.0])
        lines = [push, UP - mu * t, UP + mu * t]
        moments = [(p - s.centre)[0] * d[1] - (p - s.centre)[1] * d[0] for d in lines]
        if min(abs(m) / np.linalg.norm(d) for m, d in zip(moments, lines)) < 0.02 * width:
            continue  # a near tie: the vote is not decisive
        result = solve_step(s, [Contact(p, UP, mu)], [*push, 0.0])
        assert len(result.solutions) == 1, result  # a point contact's motion is unique
        omega = result.solutions[0].twist[2]
        assert np.sign(omega) == np.sign(sum(np.sign(moments))), (s, p, mu, beta, result)
        checked += 1


# -- symmetry --------------------------------------------------------------------------------------

MIRROR = np.diag([-1.0, 1.0])


def mirrored_contacts(contacts):
    return [Contact(MIRROR @ c.point, MIRROR @ c.normal, c.mu) for c in contacts]


def mirrored_twist(v):
    return np.array([-v[0], v[1], -v[2]])


def test_mirroring_part_contact_and_motion_mirrors_the_result():
    rng = np.random.default_rng(5)
    for _ in range(25):
        s, contacts, twist = random_case(rng)
        m = SupportDistribution(s.points @ MIRROR, s.weights)
        result = solve_step(s, contacts, twist)
        image = solve_step(m, mirrored_contacts(contacts), mirrored_twist(twist))
        expected = sorted((tuple(x.mirrored().value for x in sol.mode), tuple(mirrored_twist(sol.twist).round(7)))
                          for sol in result.solutions)
        got = sorted((tuple(x.value for x in sol.mode), tuple(sol.twist.round(7))) for sol in image.solutions)
        assert [e[0] for e in expected] == [g[0] for g in got]
        np.testing.assert_allclose([e[1] for e in expected], [g[1] for g in got], atol=1e-6)


def test_mirrored_push_mirrors_the_final_pose():
    s = grid_support(BLOCK, 40, cf=[0.2, 0.4])
    contacts = [Contact([0.3, 0.0], UP, 0.4)]
    push = simulate_push(s, contacts, [0.2, 1.0, 0.0], 0.6, dt=0.01, footprint=BLOCK)
    m = SupportDistribution(s.points @ MIRROR, s.weights)
    image = simulate_push(m, mirrored_contacts(contacts), [-0.2, 1.0, 0.0], 0.6, dt=0.01, footprint=BLOCK)
    assert push.status == image.status == "completed"
    assert [tuple(x.mirrored() for x in mode) for mode in push.modes_seen] == list(image.modes_seen)
    np.testing.assert_allclose(image.final_pose, mirrored_twist(push.final_pose), atol=1e-9)


# -- integration -----------------------------------------------------------------------------------

def test_sliding_point_push_converges_with_the_step():
    """A point finger pushing a 10 x 6 cm block off-centre: it slides, sticks and slides again as
    the block turns. The final pose converges at first order (explicit Euler on SE(2))."""
    block = shapely.box(-0.05, 0, 0.05, 0.06)
    s = grid_support(block, 60)
    finger = [Contact([0.02, 0.0], UP, 0.3)]
    poses = []
    for steps in (40, 80, 160, 320):
        push = simulate_push(s, finger, [0.0, 0.05, 0.0], 1.6, dt=1.6 / steps, footprint=block)
        assert push.status == "completed" and push.ambiguous_steps == 0
        assert {(LEFT,), (STICK,)} <= set(push.modes_seen)
        poses.append(push.final_pose)
    diffs = [np.linalg.norm(b - a) for a, b in zip(poses, poses[1:])]
    assert diffs[0] > 1e-4  # the sliding makes the step matter
    for coarse, fine in zip(diffs, diffs[1:]):
        assert fine == pytest.approx(coarse / 2, rel=0.2)
    assert diffs[-1] < 2e-3


def test_finger_sliding_off_the_edge_stops_the_push():
    s = grid_support(BLOCK, 30)
    push = simulate_push(s, [Contact([0.9, 0.0], UP, 0.2)], [1.0, 1.0, 0.0], 1.0, dt=0.02, footprint=BLOCK)
    assert push.status == "slid_off_edge"
    assert (RIGHT,) in push.modes_seen


def test_pusher_twist_is_constant_in_the_pusher_frame():
    """The pusher moves by exp(V_p T) from the start whatever the slider does."""
    s = grid_support(BLOCK, 30)
    twist = cor_to_twist([3.0, 0.5], -1)
    push = simulate_push(s, [Contact([0.5, 0.0], UP, 0.3)], twist, 0.5, dt=0.01, footprint=BLOCK,
                         start_pose=[1.0, 2.0, 0.3])
    assert push.status == "completed" and (LEFT,) in push.modes_seen
    np.testing.assert_allclose(push.pusher_pose, exp_twist([1.0, 2.0, 0.3], twist, 0.5), atol=1e-12)


def test_adjoint_moves_a_body_twist_into_the_reference_frame():
    """A point q of a body at pose (R, t) is at R q + t and moves with R times its body-frame
    velocity; the adjoint twist must give that velocity at R q + t."""
    rng = np.random.default_rng(4)
    for pose, twist, q in zip(rng.normal(size=(10, 3)), rng.normal(size=(10, 3)), rng.normal(size=(10, 2))):
        c, s = np.cos(pose[2]), np.sin(pose[2])
        rot = np.array([[c, -s], [s, c]])
        body = twist[:2] + twist[2] * np.array([-q[1], q[0]])
        v = adjoint(pose, twist)
        where = rot @ q + pose[:2]
        np.testing.assert_allclose(v[:2] + v[2] * np.array([-where[1], where[0]]), rot @ body, atol=1e-12)


def test_bad_inputs():
    s = grid_support(BLOCK, 20)
    with pytest.raises(ValueError, match="at least one contact"):
        solve_step(s, [], [0, 1, 0])
    with pytest.raises(ValueError, match="normal velocity|along its normal"):
        solve_step(s, line_contact(0.5), [1.0, 0.0, 0.0])  # gliding along the edge
    with pytest.raises(ValueError, match="> 0"):
        Contact([0, 0], UP, 0.0)
    with pytest.raises(ValueError, match="duration"):
        simulate_push(s, line_contact(0.5), [0, 1, 0], 0.0)
