"""The README's generated blocks and pictures (planner.bench.docs) against what the current code
makes: the numbers are compared, never the pixels. ``python -m planner.bench.docs`` fixes a failure."""

from __future__ import annotations

import re

import pytest
from PIL import Image

from planner.bench import docs

README = docs.README.read_text()
COMMITTED = {m["name"]: m["body"] for m in docs.BLOCK.finditer(README)}
FIX = "stale: run python -m planner.bench.docs"


def test_the_readme_has_every_generated_block_once():
    names = [m["name"] for m in docs.BLOCK.finditer(README)]
    assert sorted(names) == sorted(docs.blocks()), names


@pytest.mark.parametrize("name", sorted(docs.blocks(mujoco=False)))
def test_each_block_is_what_the_code_makes_now(name):
    assert COMMITTED[name] == docs.blocks(mujoco=False)[name](), FIX


@pytest.mark.parametrize("name", sorted(docs.PICTURES))
def test_each_picture_shows_the_plan_its_caption_gives(name):
    scene, result = docs.seed_one(name)
    text = Image.open(docs.ROOT / "docs" / f"{docs.PICTURES[name]}.png").text
    assert text.get("Description") == f"{scene.name}: {result.headline()}", FIX


def test_the_mujoco_table_holds_every_shipped_scene_with_its_seed_one_plan():
    rows = [line.split(" | ") for line in COMMITTED["mujoco-table"].splitlines()[2:] if line.startswith("| ")]
    assert {row[0].lstrip("| "): row[1] for row in rows} == docs.table_plans(), FIX


def _numbers(text: str) -> list[tuple[float, float]]:
    """Each number in ``text`` with half a unit of its last printed digit (what rounding allows)."""
    return [(float(n), 0.5 * 10.0 ** -len(n.partition(".")[2])) for n in re.findall(r"-?\d+(?:\.\d+)?", text)]


def test_the_mujoco_tables_battery_row_is_what_the_simulation_gives():
    pytest.importorskip("mujoco")
    from planner.bench.simulate import row
    from planner.execution.mujoco_sim import simulate

    scene, result = docs.seed_one("battery")
    fresh = row(scene, result, simulate(scene, result, docs.MUJOCO_RUNS, seed=1), timing=False)
    [committed] = [line for line in COMMITTED["mujoco-table"].splitlines() if line.startswith("| battery |")]
    pairs = list(zip(_numbers(committed), _numbers(fresh), strict=True))
    assert all(abs(a - b) <= 2 * max(da, db) for (a, da), (b, db) in pairs), (committed, fresh)


def test_regenerating_replaces_only_the_blocks_and_a_second_time_changes_nothing():
    made = {"summary-line": "```text\nsolved: 1 push, cost 0.100 m, length 0.100 m\n```\n"}
    once = docs.regenerate(README, made)
    assert once != README and docs.regenerate(once, made) == once
    assert [m["name"] for m in docs.BLOCK.finditer(once)] == [m["name"] for m in docs.BLOCK.finditer(README)]
    assert docs.BLOCK.sub("", once) == docs.BLOCK.sub("", README)  # the prose around them is kept
