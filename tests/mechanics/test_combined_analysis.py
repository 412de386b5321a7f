"""Lynch 1992 §4-§5: the combined analysis, stable pushing, one-step goals, contact synthesis."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from mechanics import (
    ContactConfiguration,
    Slider,
    SupportModel,
    classify_goal,
    cor_to_twist,
    mode_possible,
    modes_of_motion,
    possible_motions,
    stable_edges,
    stable_region,
)
from planner import load_scene, one_step

BATTERY = Slider([[-0.02425, -0.01325], [0.02425, -0.01325], [0.02425, 0.01325], [-0.02425, 0.01325]])
BACK_FACE = 3  # x = -24.25 mm, opposite the terminals; the whole 26.5 mm edge touches the pusher
SCENE = Path(__file__).resolve().parents[2] / "scenes" / "battery.yaml"


@pytest.fixture(scope="module")
def battery():
    return ContactConfiguration.slider_edge(BATTERY, BACK_FACE, 1.0), SupportModel.of_slider(BATTERY)


def test_slider_moving_with_the_pusher_is_sticking(battery):
    config, _ = battery
    for pusher in (cor_to_twist([0.0, -0.09], -1), cor_to_twist([0.03, 0.05], 1), [1.0, 0.2, 0.0]):
        assert modes_of_motion(config, pusher, pusher) == ("ss",)


def test_stable_cor_p_excludes_every_other_mode(battery):
    # Fig. 11: a CW COR_p in the ss P region; only ss can occur (fr and sf in particular cannot).
    config, support = battery
    pusher = cor_to_twist([0.0, -0.09], -1)
    assert stable_region(BATTERY, BACK_FACE, 1.0).contains(pusher)
    motions = possible_motions(config, pusher, support)
    assert motions["ss"].can_occur and motions["ss"].status == "P"
    np.testing.assert_allclose(motions["ss"].witness / np.linalg.norm(motions["ss"].witness),
                               pusher / np.linalg.norm(pusher))
    assert [mode for mode, m in motions.items() if m.can_occur] == ["ss"]
    assert not motions["fr"].can_occur and not motions["sf"].can_occur
    assert mode_possible(config, "ss", pusher, pusher, support)


def test_rotating_about_the_cf_leaves_the_mode_open(battery):
    config, support = battery
    motions = possible_motions(config, cor_to_twist(BATTERY.cf, -1), support, samples=8)
    assert motions["ss"].status == "U"
    witness = motions["sf"].witness  # a pivot about the top contact, not force impossible
    assert witness is not None and mode_possible(config, "sf", cor_to_twist(BATTERY.cf, -1), witness, support)


def test_mode_possible_needs_the_kinematics(battery):
    config, support = battery
    pusher = cor_to_twist([0.0, -0.09], -1)
    assert not mode_possible(config, "sf", pusher, pusher, support)  # COR_s = COR_p is ss only
    assert not mode_possible(config, "ff", pusher, [1.0, 0.0, 0.0], support)  # no contact force


def test_goal_classes(battery):
    _, support = battery
    def label(twist):
        return classify_goal(BATTERY, BACK_FACE, 1.0, twist, support)
    assert label(cor_to_twist([0.0, -0.09], -1)) == "guaranteed"  # inside STABLE
    assert label(cor_to_twist([0.02, -0.05], -1)) == "guaranteed"  # outside STABLE, ss P and alone
    assert label(cor_to_twist(BATTERY.cf, 1)) == "possible"  # ss is U
    assert label([-1.0, 0.0, 0.0]) == "impossible"  # pulling back
    assert label([0.0, 1.0, 0.0]) == "impossible"  # sideways, outside the friction cone


def test_one_step_verdicts_on_the_battery_scene():
    scene = load_scene(SCENE)
    assert one_step(scene).verdicts == {BACK_FACE: "goal1"}
    backwards = one_step(scene, goal=[-0.05, 0.0, 0.0])
    assert not backwards.reachable and backwards.verdicts == {BACK_FACE: "goal3"}
    assert one_step(scene, goal=scene.start).verdicts == {}


def test_contact_synthesis_on_a_rectangle():
    block = Slider([[-1, 0], [1, 0], [1, 1], [-1, 1]])
    support = SupportModel.of_slider(block)
    for edge in block.pushable_edges:
        n = block.inward_normal(edge)
        push = np.array([n[0], n[1], 0.0])  # a straight push along the normal, through the CF
        assert stable_edges(block, 0.5, push, support) == (edge,)
    # The reversed twist of the bottom face's push belongs to the top face only.
    assert stable_edges(block, 0.5, [0.0, -1.0, 0.0], support) == (2,)
