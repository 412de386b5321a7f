"""The part's hull and what is read off it (issue 41: a circle from CAD of 131,073 vertices spent
over 120 s finding its pushable edges, every edge against every vertex).

Each query is checked against brute force written here from the definitions, without
``mechanics``: an edge is pushable when no vertex lies beyond its line (deeper than ``1e-9`` of
the part's radius), the extent along a direction is the largest dot product over every vertex, a
symmetry is a rotation about the CF carrying every vertex ``k`` onto ``k + r``, and the hull side
holding an edge is the one whose line it lies on. Polygons are random (star-shaped about the
origin, so simple) with integer vertices too, whose collinear runs put several edges on one hull
side. Then parts of a hundred thousand vertices, which the brute force would take minutes on,
are answered within a generous bound.
"""

from __future__ import annotations

import math
import time

import numpy as np
import pytest
import shapely

from mechanics import Slider, procedure_stable

RNG_SEEDS = range(40)


def star(rng: np.random.Generator, n: int, integer: bool) -> np.ndarray:
    """A simple polygon of ``n`` vertices round the origin, counter-clockwise or not."""
    angle = np.sort(rng.uniform(0.0, 2 * np.pi, n))
    radius = rng.uniform(0.3, 1.0, n)
    v = np.c_[radius * np.cos(angle), radius * np.sin(angle)]
    if integer:  # coarse grid: repeated and collinear vertices (those make no part: skipped)
        v = np.round(v * 4)
    return v[::-1] if rng.random() < 0.5 else v


def parts(seed: int) -> list[Slider]:
    rng = np.random.default_rng(seed)
    out = []
    for n in (3, 4, 5, 8, 13, 30):
        for integer in (False, True):
            v = star(rng, n, integer)
            if np.any(np.hypot(*(v - np.roll(v, -1, axis=0)).T) == 0):
                continue
            try:
                out.append(Slider(v + rng.uniform(-2, 2, 2)))
            except ValueError:  # self-touching or flat after rounding
                continue
    return out


def brute_pushable(v: np.ndarray, radius: float) -> tuple[int, ...]:
    out = []
    for i in range(len(v)):
        a, b = v[i], v[(i + 1) % len(v)]
        d = (b - a) / math.hypot(*(b - a))
        normal = np.array([-d[1], d[0]])
        depth = (v - a) @ normal
        if np.all(depth >= -1e-9 * radius) or np.all(depth <= 1e-9 * radius):  # all on one side, either winding
            out.append(i)
    return tuple(out)


def brute_turns(v: np.ndarray, cf: np.ndarray, radius: float) -> tuple[int, ...]:
    rel, n = v - cf, len(v)
    found = []
    for r in range(1, n):
        angle = math.atan2(rel[r % n, 1], rel[r % n, 0]) - math.atan2(rel[0, 1], rel[0, 0])
        c, s = math.cos(angle), math.sin(angle)
        turned = np.c_[c * rel[:, 0] - s * rel[:, 1], s * rel[:, 0] + c * rel[:, 1]]
        if np.all(np.hypot(*(turned - np.roll(rel, -r, axis=0)).T) <= 1e-10 * radius):
            found.append(r)
    return tuple(found)


@pytest.mark.parametrize("seed", RNG_SEEDS)
def test_pushable_edges_extent_and_hull_sides_agree_with_brute_force(seed):
    rng = np.random.default_rng(1000 + seed)
    for part in parts(seed):
        v = part.vertices
        pushable = brute_pushable(v, part.radius)
        assert part.pushable_edges == pushable
        assert [part.is_pushable(e) for e in range(part.n)] == [e in pushable for e in range(part.n)]
        directions, origin = rng.normal(size=(25, 2)), rng.normal(size=2)
        np.testing.assert_allclose(part.extent(directions, origin), ((v - origin) @ directions.T).max(axis=0),
                                   rtol=0, atol=1e-12)
        hull = part.hull
        assert shapely.Polygon(hull).equals(shapely.MultiPoint(v).convex_hull)
        for e in pushable:
            j = part.hull_side(e)
            a, b = hull[j], hull[(j + 1) % len(hull)]
            for p in (v[e], v[(e + 1) % part.n]):  # both ends of the edge on that side's segment
                assert shapely.LineString([a, b]).distance(shapely.Point(p)) <= 1e-9


@pytest.mark.parametrize("n", [3, 4, 5, 6, 12, 30, 60, 64, 97])
def test_turns_agree_with_brute_force_on_regular_and_near_regular_polygons(n):
    t = 2 * np.pi * np.arange(n) / n
    regular = np.c_[np.cos(t), np.sin(t)]
    rectangle = np.array([[-2.0, -1.0], [2.0, -1.0], [2.0, 1.0], [-2.0, 1.0]])
    # A regular polygon with every other vertex pulled in: the half of its turns that keep parity.
    pulled = regular * np.where(np.arange(n) % 2, 0.8, 1.0)[:, None] if n % 2 == 0 else regular
    for v in (regular, pulled, rectangle, regular + [0.3, 0.0]):
        for cf in (None, [0.01, 0.0]):
            part = Slider(v, cf=None if cf is None else np.mean(v, axis=0) + cf)
            assert part.turns == brute_turns(v, part.cf, part.radius), (n, cf)


def test_turns_of_random_parts_are_none_as_brute_force_finds():
    for seed in RNG_SEEDS:
        for part in parts(seed):
            assert part.turns == brute_turns(part.vertices, part.cf, part.radius)


def test_procedure_stable_reads_the_same_extents_as_every_vertex():
    """STABLE's steps 1 and 2 bound the CORs by how far the part reaches along the friction cone's
    edges: the rows it builds equal those with the reach taken over every vertex."""
    for seed in range(10):
        for part in parts(seed):
            for e in part.pushable_edges:
                region = procedure_stable(part, e, 0.5, 0.3)
                for sense, rows in region.rows.items():
                    for row in rows[:2]:  # a . V >= 0 with a = sense (d1, -d0, -offset)
                        d = np.array([-row[1], row[0]]) * sense
                        assert sense * -row[2] == pytest.approx((part.vertices @ d).max(), abs=1e-12)


@pytest.mark.parametrize("n, regular", [(100_003, True), (100_800, False)])
def test_a_part_of_a_hundred_thousand_vertices_is_read_in_seconds(n, regular):
    """A circle of about 100,000 vertices, evenly spaced or at random angles (no symmetry; 100,800
    has 126 divisors, each a shift its turns are tried at): every query above in seconds, not the
    minutes of every edge against every vertex. Independently: either is convex, so every edge is
    pushable, and lies on the side of the hull that holds both its ends; the even one turns onto
    itself at every shift."""
    rng = np.random.default_rng(7)
    t = 2 * np.pi * (np.arange(n) / n if regular else np.sort(rng.uniform(0.0, 1.0, n)))
    v = np.c_[np.cos(t), np.sin(t)] * 0.05
    began = time.perf_counter()
    part = Slider(v, cf=[0.0, 0.0])
    edges, turns = part.pushable_edges, part.turns
    sides = [part.hull_side(e) for e in edges]
    regions = [procedure_stable(part, e, 0.5, 0.03) for e in edges[:1000]]
    assert time.perf_counter() - began < 30.0
    assert edges == tuple(range(n)) and len(regions) == 1000
    assert turns == (tuple(range(1, n)) if regular else ())
    hull = part.hull
    for e in range(0, n, 97):
        side = shapely.LineString([hull[sides[e]], hull[(sides[e] + 1) % len(hull)]])
        assert max(side.distance(shapely.Point(p)) for p in (v[e], v[(e + 1) % n])) <= 1e-12


def test_a_regular_polygon_of_a_hundred_thousand_vertices_has_every_turn():
    n = 2**17
    t = 2 * np.pi * np.arange(n) / n
    began = time.perf_counter()
    part = Slider(np.c_[np.cos(t), np.sin(t)] * 0.05)
    assert part.turns == tuple(range(1, n))
    assert time.perf_counter() - began < 30.0
