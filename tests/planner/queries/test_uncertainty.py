"""Planning with uncertain friction and CF (Lynch 1992, §6): scene fields, plans, verification.

Sources of truth, none of them the code under test: the test-only LP over support distributions
(tests/oracle.py) with the support centred at points of the CF's uncertainty disk, Theorem 4
re-derived, and the independent quasi-static simulator through ``plan --verify``.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml

import oracle as O
from planner import SceneError, parse_scene, plan
from planner.actions.controls import edge_controls
from planner.execution.verify import verify

ROOT = Path(__file__).resolve().parents[3]
PLAN = Path(sys.executable).parent / "plan"
RHO = 0.004  # 4 mm of a 9.4 cm part: the CF of an unevenly filled box


def corridor(**changes) -> dict:
    spec = yaml.safe_load((ROOT / "scenes" / "corridor.yaml").read_text())
    spec["pusher"]["edges"] = [3]  # the face at x = -0.04, pushed along +x (keeps the regions few)
    for dotted, value in changes.items():
        section, key = dotted.split(".")
        spec[section][key] = value
    return spec


@pytest.mark.parametrize("field, value, problem", [
    ("pusher.mu", [0.6, 0.4], "0 < low <= high"),
    ("pusher.mu", [0.0, 0.5], "0 < low <= high"),
    ("pusher.mu", [0.5], "list of 2 numbers"),
    ("slider.cf_uncertainty", -0.001, ">= 0"),
    ("slider.cf_uncertainty", 0.5, "less than the part's radius"),
    ("slider.cf_uncertainty", "1 mm", "finite number"),
])
def test_bad_uncertainty_names_the_field(field, value, problem):
    with pytest.raises(SceneError, match=rf"^{field.replace('.', '[.]')}: .*{problem}"):
        parse_scene(corridor(**{field: value}))


def test_friction_interval_plans_with_its_lowest_value():
    scene = parse_scene(corridor(**{"pusher.mu": [0.4, 0.9]}))
    assert (scene.pusher.mu, scene.pusher.mu_high) == (0.4, 0.9)
    assert parse_scene(corridor()).pusher.mu_high is None


@pytest.fixture(scope="module")
def uncertain():
    spec = corridor(**{"slider.cf_uncertainty": RHO})
    scene = parse_scene(spec, "corridor-uncertain")
    result = plan(scene, seed=1)
    return spec, scene, result


def test_every_push_sticks_for_every_cf_in_the_disk(uncertain):
    spec, scene, result = uncertain
    assert result.solved
    verts = np.asarray(spec["slider"]["vertices"], float)
    cf = verts.mean(axis=0)
    samples = O.support_samples(verts, 12)
    angles = 2 * np.pi * np.arange(8) / 8
    centres = [cf] + [cf + RHO * np.array([np.cos(a), np.sin(a)]) for a in angles]
    oracles = [O.LPOracle(O.Reference(verts, c, 3, 0.5, width=0.05), samples) for c in centres]
    along = verts @ oracles[0].ref.t
    for seg in result.segments:
        v = np.asarray(seg.twist)
        assert max(lp.max_violation(v) for lp in oracles) <= 1e-9, seg
        if v[2] != 0:  # Theorem 4: the centre of a turn lies beyond the part along the edge
            c_t = np.array([-v[1], v[0]]) / v[2] @ oracles[0].ref.t
            assert (c_t <= along.min()) if v[2] > 0 else (c_t >= along.max())


def test_verify_moves_the_centres_and_the_plan_passes(uncertain):
    _, scene, result = uncertain
    check = verify(scene, result, n=31, seed=2)
    assert check.passed, check.lines()
    gap = {k: [] for k in set(check.kinds)}
    for kind, support in zip(check.kinds, check.supports):
        gap[kind].append(float(np.linalg.norm(support.centre - scene.slider.cf)))
    assert gap["grid"] == [pytest.approx(0.0, abs=1e-12)]
    assert np.allclose(gap["dipod"] + gap["tripod"], RHO, rtol=1e-6)
    assert max(gap["random"]) <= RHO * (1 + 1e-6) and min(gap["random"]) < RHO


def test_stable_regions_cannot_take_an_uncertain_cf(tmp_path):
    (tmp_path / "scene.yaml").write_text(yaml.safe_dump(corridor(**{"slider.cf_uncertainty": RHO})))
    run = subprocess.run([str(PLAN), "scene.yaml", "--regions", "stable", "--out", "out"], cwd=tmp_path,
                         capture_output=True, text=True, timeout=120)
    assert run.returncode == 1
    assert run.stderr.strip().splitlines() == [
        "plan: error: planner.regions: procedure STABLE assumes a known CF; slider.cf_uncertainty needs the exact "
        "regions"]
    assert not (tmp_path / "out").exists()


def test_the_uncertain_regions_are_inside_the_known_ones(uncertain):
    _, scene, _ = uncertain
    (robust,) = edge_controls(scene)
    (known,) = edge_controls(parse_scene(corridor()))
    assert robust.region.cf_radius == RHO and known.region.cf_radius == 0
    small, large = robust.region.section()[0], known.region.section()[0]
    assert small.area < 0.95 * large.area and large.buffer(0.01).contains(small)
