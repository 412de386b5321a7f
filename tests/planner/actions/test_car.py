"""The Dubins car of an edge (planner.actions.car): every motion it can make is a stable push.

Checked against the test-only LP oracle over support distributions on the part and Theorem 4's
condition (tests/oracle.py, which shares no code with ``mechanics``), on every shipped part's
allowed edges.
"""

from __future__ import annotations

import gc
import weakref
from pathlib import Path

import numpy as np
import pytest

from oracle import guaranteed_stable
from planner import load_scene
from planner.actions.car import edge_car
from planner.actions.controls import edge_controls

ROOT = Path(__file__).resolve().parents[3]
PARTS = ["battery", "corridor", "nonconvex", "parking"]  # one scene per distinct part


def stable_by_oracle(scene, edge: int, twist: np.ndarray) -> bool:
    return guaranteed_stable(scene.slider.vertices, scene.slider.cf, edge, scene.pusher.mu, scene.pusher.width, twist)


@pytest.mark.parametrize("name", PARTS)
def test_every_curvature_of_the_car_is_stable(name):
    scene = load_scene(ROOT / "scenes" / f"{name}.yaml")
    cars = [edge_car(p, scene.slider.cf) for p in edge_controls(scene)]
    assert any(cars), "a part with stable translations has a car"
    for car in filter(None, cars):
        assert 0 < car.radius < 10 * scene.slider.radius
        kappa = np.linspace(-1.0, 1.0, 41) / car.radius
        for twist in car.twist(kappa):
            assert stable_by_oracle(scene, car.push.edge, twist), (name, car.push.edge, twist)
        # The CF moves along the heading at unit speed whatever the curvature.
        cf_velocity = car.twist(kappa)[:, :2] + kappa[:, None] * np.array([-scene.slider.cf[1], scene.slider.cf[0]])
        np.testing.assert_allclose(cf_velocity, np.tile(car.heading, (len(kappa), 1)), atol=1e-12)


@pytest.mark.parametrize("name", PARTS)
def test_the_radius_is_tight_for_the_region(name):
    # A little tighter than the car's radius, one of the two turns leaves the planner's region.
    scene = load_scene(ROOT / "scenes" / f"{name}.yaml")
    for car in filter(None, (edge_car(p, scene.slider.cf) for p in edge_controls(scene))):
        tighter = car.twist(np.array([-1.0, 1.0]) / (0.97 * car.radius))
        assert not car.push.region.contains(tighter).all()


def test_states_and_poses_are_inverse():
    scene = load_scene(ROOT / "scenes" / "nonconvex.yaml")
    car = edge_car(edge_controls(scene)[0], scene.slider.cf)
    rng = np.random.default_rng(3)
    for pose in rng.uniform([-1, -1, -np.pi], [1, 1, np.pi], (20, 3)):
        back = car.pose(car.state(pose))
        np.testing.assert_allclose(back[:2], pose[:2], atol=1e-12)
        assert abs((back[2] - pose[2] + np.pi) % (2 * np.pi) - np.pi) < 1e-12
        # The state's position is the CF's.
        c, s = np.cos(pose[2]), np.sin(pose[2])
        cf = pose[:2] + np.array([[c, -s], [s, c]]) @ scene.slider.cf
        np.testing.assert_allclose(car.state(pose)[:2], cf, atol=1e-12)


def test_a_cars_memo_keeps_no_region_alive(tmp_path):
    """Cars are remembered by region, weakly: controls rebuilt on the same region get the same
    car, procedure STABLE's regions (made afresh) get theirs, and once nothing else holds a
    region (its own cache gone) the memo does not keep it."""
    from dataclasses import replace

    from planner.actions.region_cache import RegionCache

    scene = load_scene(ROOT / "scenes" / "parking.yaml")
    first = edge_controls(scene, cache=RegionCache(tmp_path))[0]
    car = edge_car(first, scene.slider.cf)
    again = edge_car(replace(first), scene.slider.cf)
    assert again.push is not first and (again.heading == car.heading).all() and again.radius == car.radius
    stable = edge_controls(scene, regions="stable")[0]
    stable_car = edge_car(stable, scene.slider.cf)
    assert stable.region.contains(stable_car.twist(np.linspace(-1.0, 1.0, 21) / stable_car.radius)).all()
    region = weakref.ref(first.region)
    del first, car, again
    gc.collect()
    assert region() is None
