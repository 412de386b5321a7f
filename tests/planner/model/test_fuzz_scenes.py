"""Property-based fuzzing of scene files (issue 12): whatever a scene file holds, reading it and
checking the command line either succeeds or raises one :class:`SceneError`, whose message is one
printable line of at most 300 characters naming a field, and nothing is written.

Scenes are generated three ways: a valid scene with a few of its fields replaced, deleted, added
or shared (so the dump holds aliases) by hostile values (NaN, infinities, huge and tiny numbers,
ints beyond a float, wrong types, control characters, degenerate, duplicate and self-intersecting
polygons); that scene's YAML text with hostile lines spliced in (aliases and alias bombs, YAML 1.1
forms, duplicate keys, unknown tags, control characters) or cut short; and its bytes with
non-UTF-8 bytes spliced in. Each file goes through :func:`planner.load_scene` and through the
command line's input stage, :func:`planner.cli.read_inputs` (everything before planning), with
hostile flags. The example budget is the Hypothesis profile's (``tests/conftest.py``): a fixed,
derandomised ``ci`` budget by default, ``--hypothesis-profile long`` for 10,000 examples a test.
"""

from __future__ import annotations

import copy
import math
import os
import re
import warnings
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from hypothesis import event, given
from hypothesis import strategies as st

from planner import load_scene
from planner.cli import read_inputs
from planner.model.fields import ANGLE, LENGTH, SceneError
from planner.model.scene import Scene
from planner.model.scene_file import MIN_SIZE
from test_cli import BATTERY
from test_hostile_scenes import STAR, alias_bomb

#: A valid scene using every optional key, on which the mutations start (besides the battery).
FULL = {
    "name": "full",
    "slider": {"vertices": [[0.0, 0.0], [0.09, 0.0], [0.09, 0.035], [0.035, 0.035], [0.035, 0.09], [0.0, 0.09]],
               "cf": [0.03, 0.03], "cf_uncertainty": 0.002},
    "pusher": {"width": 0.03, "depth": 0.01, "mu": [0.4, 0.6], "edges": [0, 1, 4, 5], "transit": "lift"},
    "obstacles": [{"polygon": [[0.3, 0.3], [0.4, 0.3], [0.35, 0.4]]},
                  {"box": {"center": [-0.3, 0.2], "size": [0.1, 0.05], "angle": 30.0}}],
    "workspace": {"min": [-0.5, -0.5], "max": [0.5, 0.5]},
    "start": [-0.2, -0.2, 180.0],
    "goal": [0.2, 0.0, -90.0],
    "tolerance": {"position": 0.01, "angle": 2.0},
    "planner": {"name": "kpiece", "time_limit": 5, "seed": 7, "regions": "exact", "switch_cost": 0.1},
}
#: The first part of every field name a message may give: the file, a flag, or a scene key.
# "parts": a file of neither form (its slider, start and goal gone) is told of a tray's key too.
ROOTS = {"scene", "plan", "parts", "--out", "--plan", "--verify", "--seed", "--time-limit", *FULL}
#: Where a field name's first part ends.
ROOT_END = re.compile(r"[.\[]")

# --- hostile values ---------------------------------------------------------------------------------

SPECIAL_NUMBERS = [0, 0.0, -0.0, 5e-324, 1e-300, 1e-7, MIN_SIZE, 1e-3, 0.5, 180.0, -180.0, 540.0,
                   LENGTH.bound, LENGTH.bound * (1 + 1e-12), ANGLE.bound, ANGLE.bound * 1.5, 1e16, 1e154, 1e200,
                   -1e300, 1.7976931348623157e308, 2**53 + 1]
numbers = st.one_of(st.sampled_from(SPECIAL_NUMBERS), st.floats(), st.floats(-2.0, 2.0),
                    st.integers(-330, 330).map(lambda e: 10**abs(e) * (-1 if e < 0 else 1)))  # ints beyond a float
HOSTILE_TEXT = ["", " ", "a\nb", "a\rb", "\x00", "\x07", "\x1b[31mred", "\u2028", "\x85", "\ufeff", "\t",
                "1:30", "017", "yes", "~", ".nan", "-.inf", "2001-12-14", "<<", "*a", "&a", "!!int",
                "plan: error: x", "../../etc/passwd", "a/b", "'", '"']
long_texts = st.integers(100, 5000).map("x".__mul__)
texts = st.one_of(st.sampled_from(HOSTILE_TEXT), st.text(max_size=30), long_texts)
keys = st.one_of(st.sampled_from([*FULL, "vertices", "cf", "mu", "box", "polygon", "center", "size", "min", "max",
                                  "colour", "a\nb", "\x00", "a.b"]), texts, st.integers(), st.booleans())
leaves = st.one_of(numbers, texts, st.booleans(), st.none())
anything = st.recursive(leaves, lambda inner: st.one_of(st.lists(inner, max_size=6),
                                                         st.dictionaries(keys, inner, max_size=4)), max_leaves=24)

#: Coordinates that make collinear, repeated, crossing and tiny polygons often.
coordinates = st.one_of(st.sampled_from([0.0, 0.0, 0.01, 0.02, -0.01, 1e-9, 1e-7, 1e3, 1e200, math.nan]),
                        st.floats(-0.1, 0.1))
points = st.lists(st.one_of(st.tuples(coordinates, coordinates).map(list), anything), min_size=0, max_size=9)
POLYGONS = [
    [[0, 0], [0.01, 0.01], [0.03, 0.03]],  # collinear
    [[0, 0], [0.02, 0], [0.02, 0.02], [0, 0]],  # first vertex repeated
    [[0, 0], [0.02, 0.02], [0.02, 0], [0, 0.02]],  # bow-tie
    [[0, 0], [1e-7, 0], [0, 1e-7]],  # tiny
    [[0, 0], [1e160, 0], [0, 1e160]],  # huge
    STAR,  # no edge on its convex hull
]
polygons = st.one_of(st.sampled_from(POLYGONS), points)
#: What replaces a field: hostile values, and polygons where polygons go (copied: the mutations
#: edit them in place, and POLYGONS must stay as it is for the next example).
replacements = st.one_of(anything, numbers, polygons).map(copy.deepcopy)

# --- mutations of the scene's mapping ----------------------------------------------------------------


def children(node: Any) -> Iterator[tuple[Any, Any]]:
    """``(key, child)`` for each child of a mapping or list; nothing for a scalar."""
    yield from node.items() if isinstance(node, dict) else enumerate(node) if isinstance(node, list) else ()


def paths(node: Any, prefix: tuple = ()) -> Iterator[tuple]:
    """Every path (of keys and indices) to a node of ``node``, the root's ``()`` first."""
    yield prefix
    for key, child in children(node):
        yield from paths(child, (*prefix, key))


def contains(node: Any, target: Any) -> bool:
    """Whether ``target`` is ``node`` or inside it (by identity)."""
    return node is target or any(contains(child, target) for _, child in children(node))


def at(doc: Any, path: tuple) -> Any:
    """The node of ``doc`` at ``path``."""
    for key in path:
        doc = doc[key]
    return doc


def mutate(data: st.DataObject, doc: dict) -> None:
    """Apply one mutation to ``doc`` at a drawn place: replace, delete or add a value, repeat a list's
    item, or put the value in a second place too (so the dump holds an anchor and an alias)."""
    places = list(paths(doc))[1:]
    path = data.draw(st.sampled_from(places), label="path")
    parent, last = at(doc, path[:-1]), path[-1]
    kinds = ["replace", "replace", "delete", "add", "share", *(["repeat"] if isinstance(parent, list) else [])]
    kind = data.draw(st.sampled_from(kinds), label="kind")
    if kind == "replace":
        parent[last] = data.draw(replacements, label="value")
    elif kind == "delete":
        del parent[last]
    elif kind == "add" and isinstance(parent, dict):
        parent[data.draw(keys, label="key")] = data.draw(replacements, label="value")
    elif kind == "add":
        parent.insert(last, data.draw(replacements, label="value"))
    elif kind == "repeat":  # a repeated vertex or obstacle
        parent.insert(last, parent[last])
    else:
        target = data.draw(st.sampled_from(places), label="target")
        holder = at(doc, target[:-1])
        if not contains(parent[last], holder):  # else the document would hold itself
            holder[target[-1]] = parent[last]


@st.composite
def scene_docs(draw: Callable) -> dict:
    """A valid scene with one to three mutations."""
    doc = copy.deepcopy(draw(st.sampled_from([BATTERY, FULL])))
    data = draw(st.data())
    for _ in range(draw(st.integers(1, 3))):
        mutate(data, doc)
    return doc


def dump(doc: dict) -> str:
    """``doc`` as YAML, as a tool would write it (aliases for shared values, unicode as it is)."""
    return yaml.safe_dump(doc, allow_unicode=True, width=1000)


# --- mutations of the text and the bytes -----------------------------------------------------------


HOSTILE_LINES = [
    "mu: 1:30", "seed: 017", "  mu: 017", "name: yes", "name: 2001-12-14", "start: [0, 0, 1:30]",
    "slider: {vertices: [[0, 0], [1, 0], [0, 1]]}", "goal: [0, 0, 0]", "goal: [0.0, 0.0, 1e300]",
    "a\x07b: 1", '"a\\nb": 1', '"a\\u2028b": 1', "name: \"a\\x00b\"", "x: &a [1, 2]\ny: *a", "z: *nope",
    "self: &s [*s]", "<<: {name: merged}", "name: !!python/object:os.system x", "name: !!binary aGVsbG8=",
    "name: !!timestamp 2001-12-14", "seed: !!int 1:30", "? [1, 2]\n: 3", "---", "--- !!set", "%YAML 1.1\n---",
    "\tname: tab", "name: [" * 40, "name: " + "[" * 20 + "]" * 20, "obstacles: " + "[" * 30, "\ufeffname: bom",
    "workspace: {min: [-1e200, -1e200], max: [1e200, 1e200]}", "tolerance: {angle: .nan}",
    "planner: {switch_cost: -0.0, seed: 0x10}", "pusher: {width: 1, depth: 1, mu: 1, transit: teleport}",
    "name: &n x\nplanner: {name: *n}",
]
hostile_lines = st.one_of(st.sampled_from(HOSTILE_LINES), long_texts.map("name: {}".format),
                          st.builds("{}: {}".format, st.sampled_from(["name", "planner", "slider", "extra"]),
                                    st.builds(alias_bomb, st.integers(2, 9), st.integers(2, 9))),
                          st.text(max_size=40))


@st.composite
def scene_texts(draw: Callable) -> str:
    """A scene's YAML text with hostile lines spliced in, characters replaced or its end cut off."""
    lines = dump(draw(scene_docs())).splitlines()
    for _ in range(draw(st.integers(1, 3))):
        kind = draw(st.sampled_from(["line", "line", "char", "cut"]))
        where = draw(st.integers(0, len(lines)))
        if kind == "line":
            lines.insert(where, draw(hostile_lines))
        elif kind == "cut":
            del lines[where:]
        elif lines:  # a character replaced (or added at the end of a line)
            where = min(where, len(lines) - 1)
            k = draw(st.integers(0, len(lines[where])))
            lines[where] = lines[where][:k] + draw(st.characters(codec="utf-8")) + lines[where][k + 1:]
    return "\n".join(lines) + "\n"


BAD_BYTES = [b"\xff", b"\xfe\xff", b"\xc3", b"\xed\xa0\x80", b"\xf4\x90\x80\x80", b"\x00", b"\xc0\xaf", b"\x80"]


@st.composite
def scene_bytes(draw: Callable) -> bytes:
    """A scene's text encoded as UTF-8, with invalid bytes spliced in, or as UTF-16."""
    text = draw(st.one_of(scene_texts(), st.builds(dump, scene_docs())))
    if draw(st.booleans()):
        return text.encode("utf-16")
    raw = text.encode()
    k = draw(st.integers(0, len(raw)))
    return raw[:k] + draw(st.sampled_from(BAD_BYTES)) + raw[k:]


# --- the properties ------------------------------------------------------------------------------

#: Command lines of the input stage: the scene file and hostile flags argparse itself accepts
#: (``--flag=value``, so that argparse takes ``-inf`` for a value, not a flag).
flags = st.lists(st.one_of(
    st.builds("--seed={}".format, st.integers(-(2**70), 2**70)),
    st.builds("--time-limit={!r}".format, st.one_of(st.floats(), st.sampled_from([0.0, 1e-300, 86400.0, 1e9]))),
    st.builds("--verify={}".format, st.integers(-3, 3)),
    st.just("--plan=missing.json"),
    st.builds("--regions={}".format, st.sampled_from(["stable", "exact"])),
    st.builds("--transit={}".format, st.sampled_from(["plane", "lift", "none"])),
    st.builds("--out={}".format, st.sampled_from(["out", "scene.yaml", "a" * 300, "deep/er/out"])),
), max_size=3)


@pytest.fixture(scope="module")
def folder(tmp_path_factory) -> Path:
    """The working folder of every example: the scene file and nothing else, before and after."""
    return tmp_path_factory.mktemp("fuzz")


@contextmanager
def inside(folder: Path) -> Iterator[None]:
    """Run in ``folder`` (where the default output folder logs/ would go), warnings as errors."""
    cwd = os.getcwd()
    os.chdir(folder)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # a warning would print a second line
            yield
    finally:
        os.chdir(cwd)


def root(err: SceneError) -> str:
    """The first part of the field ``err`` names (``slider`` of ``slider.vertices[0]``)."""
    return ROOT_END.split(err.field, maxsplit=1)[0]


def assert_one_line_naming_a_field(err: SceneError, roots: set[str] = ROOTS) -> None:
    """The message is ``field: problem``, one printable line of at most 300 characters, and names a
    field: one under a known root (of ``roots``), or a key unknown or given twice, named as itself."""
    message = str(err)
    assert err.field and err.problem and message == f"{err.field}: {err.problem}"
    assert message.isprintable() and len(message.splitlines()) == 1, message
    assert len(message) <= 300, message
    assert root(err) in roots or err.problem.startswith("unknown key") or err.problem.startswith("duplicate key"), message


def assert_sane(scene: Scene) -> None:
    """What an accepted scene promises: poses in range, angles wrapped, pushable edges."""
    for pose in (scene.start, scene.goal):
        assert np.all(np.abs(pose[:2]) <= LENGTH.bound) and -math.pi <= pose[2] < math.pi
    assert scene.edges and all(scene.slider.is_pushable(e) for e in scene.edges)
    assert MIN_SIZE <= min(scene.pusher.width, scene.pusher.depth)


def check_file(folder: Path, content: bytes, argv: list[str]) -> None:
    """Read the scene file ``content`` with the loader and the command line ``argv``: a scene or one
    good error line, and the folder left holding the scene file alone."""
    (folder / "scene.yaml").write_bytes(content)
    with inside(folder):
        for read in (lambda: load_scene("scene.yaml"), lambda: read_inputs(["scene.yaml", *argv]).scene):
            try:
                assert_sane(read())
                event("accepted")  # --hypothesis-show-statistics tells how often each outcome came
            except SceneError as err:
                assert_one_line_naming_a_field(err)
                event(f"refused: {root(err) if root(err) in ROOTS else 'another key'}")
    assert [p.name for p in folder.iterdir()] == ["scene.yaml"], "reading input must write nothing"


@given(doc=scene_docs(), argv=flags)
def test_mutated_scenes(folder, doc, argv):
    check_file(folder, dump(doc).encode(), argv)


@given(text=scene_texts(), argv=flags)
def test_hostile_yaml_text(folder, text, argv):
    check_file(folder, text.encode(), argv)


@given(raw=scene_bytes())
def test_hostile_bytes(folder, raw):
    check_file(folder, raw, [])
