"""Property-based fuzzing of scenes of several parts (issue 41, part 6): whatever a tray's file
holds, the command line's input stage (:func:`planner.cli.read_inputs`: reading the scene,
checking it and the flags) either accepts it, and then what it promises holds, or raises one
:class:`SceneError` whose message is one short line naming a field, within a time bound, and
writes nothing.

Trays are the shipped ones (``scenes/parts/*.yaml``) with one to three mutations of what makes a
tray a tray: parts dropped, repeated or multiplied; a part scaled to nothing, to microns, to
kilometres, or to NaN; two parts put on each other at their starts or goals; names shared or
hostile; a part started or ended on an obstacle or off the table; a key deleted; and the scene
mutations of :mod:`test_fuzz_scenes` (hostile values anywhere). The budget is a tenth of the
Hypothesis profile's (``tests/conftest.py``: 80 examples in CI, a few seconds) for each test here
in the quick subset; :func:`test_many_mutated_trays` runs half the profile's (400 in CI) and is
listed in ``tests/slow_tests.txt``, so ``-m "not slow"`` leaves it out and the full run has its
several hundred cases.
"""

from __future__ import annotations

import copy
import math
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
import shapely
import yaml
from hypothesis import event, example, given, settings
from hypothesis import strategies as st

from planner.cli import read_inputs
from planner.model.fields import LENGTH, SceneError
from planner.model.scene import Scene
from planner.model.scene_file import MIN_SIZE
from test_fuzz_scenes import ROOTS, assert_one_line_naming_a_field, dump, flags, inside, mutate, root, texts

ROOT = Path(__file__).resolve().parents[3]
TRAYS = {path.stem: yaml.safe_load(path.read_text()) for path in sorted((ROOT / "scenes" / "parts").glob("*.yaml"))}
#: The first part of every field a tray's message may name.
PART_ROOTS = ROOTS | {"parts"}
#: A tenth of the profile's examples, as tests/planner/execution/test_fuzz_plans.py: each reads a scene.
FEW = settings(max_examples=max(10, settings().max_examples // 10))
#: Half the profile's, for the slow suite.
MANY = settings(max_examples=max(10, settings().max_examples // 2))
#: Seconds an example may take: a tray's checks are per part and per pair of parts.
SLOWEST = 5.0

SCALES = [0.0, 1e-12, 1e-7, 2e-5, 1e-3, 0.5, 10.0, 1e3, 1e6, 1e200, -1.0, math.nan, math.inf]


def _parts(doc: dict) -> list[dict] | None:
    """The tray's parts, if they are still a list of mappings."""
    parts = doc.get("parts")
    return parts if isinstance(parts, list) and parts and all(isinstance(p, dict) for p in parts) else None


def mutate_tray(data: st.DataObject, doc: dict) -> None:
    """One mutation of what makes ``doc`` a tray (module docstring), or of anything in it."""
    parts = _parts(doc)
    kinds = ["count", "scale", "overlap", "name", "collide", "missing", "anything"] if parts else ["anything"]
    kind = data.draw(st.sampled_from(kinds), label="kind")
    if kind == "anything":
        mutate(data, doc)
        return
    i = data.draw(st.integers(0, len(parts) - 1), label="part")
    j = data.draw(st.integers(0, len(parts) - 1), label="other")
    part = parts[i]
    if kind == "count":
        how = data.draw(st.sampled_from(["drop", "repeat", "many"]), label="how")
        if how == "drop":
            del parts[i:]
        elif how == "repeat":  # the same part twice: its name and its poses shared
            parts.insert(i, copy.deepcopy(part))
        else:  # dozens of copies, each renamed: overlapping wherever they are not moved apart
            parts.extend({**copy.deepcopy(part), "name": f"copy{k}"} for k in range(data.draw(st.integers(2, 60))))
    elif kind == "scale" and isinstance(part.get("vertices"), list):
        factor = data.draw(st.sampled_from(SCALES), label="factor")
        try:
            with np.errstate(over="ignore", invalid="ignore"):  # to infinities and NaN: that is the point
                part["vertices"] = (np.asarray(part["vertices"], dtype=float) * factor).tolist()
        except (TypeError, ValueError):
            part["vertices"] = factor
    elif kind == "overlap":  # at another part's start or goal
        which, theirs = (data.draw(st.sampled_from(["start", "goal"])) for _ in range(2))
        part[which] = copy.deepcopy(parts[j].get(theirs))
    elif kind == "name":
        part["name"] = copy.deepcopy(parts[j].get("name")) if data.draw(st.booleans()) else data.draw(texts)
    elif kind == "collide":  # on an obstacle's centre, or off the table
        centres = [o["box"]["center"] for o in doc.get("obstacles") or [] if isinstance(o, dict)
                   and isinstance(o.get("box"), dict) and "center" in o["box"]]
        where = data.draw(st.sampled_from(centres + [[5.0, 5.0], [-0.49, 0.0], [1e9, 0.0]]), label="where")
        part[data.draw(st.sampled_from(["start", "goal"]))] = [*where, 0.0]
    elif kind == "missing":
        holder = data.draw(st.sampled_from([part, doc]), label="holder")
        keys = [k for k in ("name", "vertices", "start", "goal", "parts", "pusher", "workspace") if k in holder]
        if keys:
            del holder[data.draw(st.sampled_from(keys), label="key")]


@st.composite
def tray_docs(draw: Callable) -> dict:
    """A shipped tray with one to three mutations."""
    doc = copy.deepcopy(TRAYS[draw(st.sampled_from(sorted(TRAYS)))])
    data = draw(st.data())
    for _ in range(draw(st.integers(1, 3))):
        mutate_tray(data, doc)
    return doc


@pytest.fixture(scope="module")
def folder(tmp_path_factory) -> Path:
    """The working folder of every example: the scene file and nothing else, before and after."""
    return tmp_path_factory.mktemp("fuzz-parts")


def at(vertices: np.ndarray, pose: np.ndarray) -> shapely.Polygon:
    """A part's outline at ``pose`` (radians), placed here, not by the planner's own code."""
    c, s = math.cos(pose[2]), math.sin(pose[2])
    return shapely.Polygon(vertices @ np.array([[c, s], [-s, c]]) + pose[:2])


def assert_sane_tray(scene: Scene) -> None:
    """What an accepted tray promises: parts named once each, with pushable edges, every start and
    goal on the table (in range, angles wrapped), inside the workspace, off the obstacles and off
    the other parts' at the same stage."""
    names = [p.name for p in scene.parts]
    assert names and len(set(names)) == len(names)
    assert MIN_SIZE <= min(scene.pusher.width, scene.pusher.depth)
    table, obstacles = shapely.box(*scene.workspace), shapely.union_all(scene.obstacles)
    for which in ("start", "goal"):
        bodies = []
        for p in scene.parts:
            pose = getattr(p, which)
            assert np.all(np.abs(pose[:2]) <= LENGTH.bound) and -math.pi <= pose[2] < math.pi
            body = at(p.slider.vertices, pose)
            assert body.buffer(-1e-9 * p.slider.radius).within(table), (p.name, which)
            assert not body.buffer(-1e-9 * p.slider.radius).intersects(obstacles), (p.name, which)
            bodies.append(body)
        for a in range(len(bodies)):
            for b in range(a):
                assert not bodies[a].buffer(-1e-9).intersects(bodies[b]), (names[a], names[b], which)
    for p in scene.parts:
        assert p.edges and all(p.slider.is_pushable(e) for e in p.edges)


def check_tray(folder: Path, content: bytes, argv: list[str]) -> None:
    """The input stage of ``plan scene.yaml ARGV``: a sane tray or one good line, soon, and nothing
    written."""
    (folder / "scene.yaml").write_bytes(content)
    began = time.monotonic()
    with inside(folder):
        try:
            scene = read_inputs(["scene.yaml", *argv]).scene
        except SceneError as err:
            assert_one_line_naming_a_field(err, PART_ROOTS)
            event(f"refused: {root(err) if root(err) in PART_ROOTS else 'another key'}")
        else:
            assert_sane_tray(scene)
            event(f"accepted: {len(scene.parts)} part(s)")
    assert time.monotonic() - began < SLOWEST
    assert [p.name for p in folder.iterdir()] == ["scene.yaml"], "reading input must write nothing"


@FEW
@given(doc=tray_docs(), argv=flags)
@example(doc={**TRAYS["swap"], "parts": [{**TRAYS["swap"]["parts"][0], "name": "blue"}, TRAYS["swap"]["parts"][1]]},
         argv=[])  # two parts of one name
@example(doc={**TRAYS["swap"], "parts": [{**p, "vertices": (np.asarray(p["vertices"]) * 2e-5).tolist()}
                                          for p in TRAYS["swap"]["parts"]]}, argv=[])  # parts of microns
def test_mutated_trays(folder, doc, argv):
    check_tray(folder, dump(doc).encode(), argv)


@MANY
@given(doc=tray_docs(), argv=flags)
def test_many_mutated_trays(folder, doc, argv):
    check_tray(folder, dump(doc).encode(), argv)
