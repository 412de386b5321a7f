"""A hardened YAML 1.2 reader: a file read into plain data (dicts, lists, strings, numbers, booleans
and None), or refused with a one-line :class:`~planner.model.fields.SceneError`.

It knows nothing of what the file describes; :mod:`.scene` reads scene files with it. Whatever
the bytes, reading stays bounded: at most :data:`MAX_BYTES` are read, aliases count as all of the
node they name (:data:`MAX_NODES` in all) and lists and mappings nest at most :data:`MAX_DEPTH`
deep. The core schema of YAML 1.2 is read, not PyYAML's YAML 1.1 (:class:`_Loader`), and a key
given twice in a mapping is refused rather than silently overriding the first.

>>> import tempfile
>>> def read(text: str):
...     with tempfile.TemporaryDirectory() as folder:
...         path = Path(folder) / "scene.yaml"
...         path.write_text(text)
...         return read_yaml(path, "scene")
>>> read("mu: 1e-3\\nedges: [0, 017]\\nwhen: 1:30\\n")
{'mu': 0.001, 'edges': [0, 17], 'when': '1:30'}
>>> read("mu: 1\\nmu: 2\\n")
Traceback (most recent call last):
...
planner.model.fields.SceneError: mu: duplicate key (at line 1, column 1 and line 2, column 1)
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import yaml

from .fields import SceneError, member, shown
from .input_file import read_text

__all__ = ["MAX_BYTES", "MAX_DEPTH", "MAX_NODES", "read_yaml"]

#: Largest file read: a scene is a few kilobytes; a megabyte holds parts of thousands of
#: vertices and still parses in a few seconds.
MAX_BYTES = 1_000_000
#: Most values (nodes) a file may hold, counting each alias as all of the node it names:
#: a part of 30000 vertices, or a megabyte of plain numbers, and no more.
MAX_NODES = 100_000
#: Deepest nesting of lists and mappings read: a scene's own goes 5 deep (obstacles[0].box.center).
MAX_DEPTH = 16


def read_yaml(path: str | Path, name: str) -> Any:
    """The document in the YAML file ``path`` as plain data (None for an empty file).

    Parameters
    ----------
    path : str or Path
    name : str
        The field the file stands for in messages: a problem with the file itself is reported as
        ``name: problem``, a duplicate key as its dotted name under ``name`` (:func:`.fields.member`:
        ``"scene"`` adds no prefix).

    Raises
    ------
    SceneError
        If the file cannot be read, is larger than :data:`MAX_BYTES`, is not UTF-8, is not YAML
        ("malformed"), or is YAML this reader refuses ("unsupported": beyond :data:`MAX_NODES` or
        :data:`MAX_DEPTH`, an alias to no whole node before it); or if a key is given twice.
    """
    text = read_text(path, name, MAX_BYTES)  # a regular file of at most MAX_BYTES, UTF-8
    try:
        return _parse_yaml(text, name)
    except yaml.YAMLError as err:
        mark = getattr(err, "problem_mark", None)
        where = f" at {_position(mark)}" if mark else ""
        problem = getattr(err, "problem", None) or " ".join(str(err).split())  # some messages span two lines
        kind = "unsupported" if isinstance(err, _Refused) else "malformed"
        raise SceneError(name, f"{kind} YAML{where}: {problem}") from None


def _parse_yaml(text: str, name: str) -> Any:
    """The document in ``text`` (YAML 1.2 core schema, :class:`_Loader`), once :func:`_check_events`
    and :func:`_check_keys` have found nothing to refuse."""
    _check_events(text)
    loader = _Loader(text)
    try:
        node = loader.get_single_node()
        if node is None:  # an empty file
            return None
        _check_keys(node, name)
        return loader.construct_document(node)
    finally:
        loader.dispose()


class _Refused(yaml.MarkedYAMLError):
    """Valid YAML that this reader refuses."""


def _check_events(text: str) -> None:
    """Refuse, before anything is built, a document that nests or expands beyond bounds.

    An alias stands for all of the node it names, so a few hundred bytes of aliases of aliases
    expand to gigabytes: each node's size is counted with its aliases expanded, and a document
    may hold :data:`MAX_NODES` nodes and nest :data:`MAX_DEPTH` deep (building it recurses).
    """
    done: dict[str, tuple[int, int]] = {}  # anchor -> (nodes, depth) of the node it names
    stack: list[list] = []  # open lists and mappings: [anchor, nodes so far, depth of the deepest child]
    # depth: how many lists and mappings a node nests, 0 for a scalar; it sits in len(stack) more.
    for event in yaml.parse(text, Loader=_Loader):
        if isinstance(event, yaml.CollectionStartEvent):
            stack.append([event.anchor, 1, 0])
            size, depth = 1, 0  # its depth is counted on the stack until it ends
        elif isinstance(event, yaml.AliasEvent):
            if event.anchor not in done:  # undefined, or inside the node it names: a loop
                raise _Refused(problem=f"alias *{event.anchor} does not name a whole node before it",
                               problem_mark=event.start_mark)
            size, depth = done[event.anchor]
        elif isinstance(event, yaml.CollectionEndEvent):
            anchor, size, deepest = stack.pop()
            depth = deepest + 1
            if anchor is not None:
                done[anchor] = size, depth
        elif isinstance(event, yaml.ScalarEvent):
            size, depth = 1, 0
            if event.anchor is not None:
                done[event.anchor] = size, depth
        else:  # stream and document boundaries
            continue
        if depth + len(stack) > MAX_DEPTH:
            raise _Refused(problem=f"lists and mappings nest more than {MAX_DEPTH} deep",
                           problem_mark=event.start_mark)
        if stack and not isinstance(event, yaml.CollectionStartEvent):
            stack[-1][1] += size
            stack[-1][2] = max(stack[-1][2], depth)
            size = stack[-1][1]
        if size > MAX_NODES:
            raise _Refused(problem=f"more than {MAX_NODES} values, counting what aliases stand for",
                           problem_mark=event.start_mark)


def _check_keys(node: yaml.Node, name: str) -> None:
    """Refuse a key given twice in any mapping under ``node`` (named ``name``): PyYAML would keep the
    last one silently, and an edit that added a second ``mu:`` would seem to do nothing."""
    if isinstance(node, yaml.SequenceNode):
        for i, item in enumerate(node.value):
            _check_keys(item, f"{name}[{i}]")
    elif isinstance(node, yaml.MappingNode):
        first: dict[tuple[str, str], yaml.Mark] = {}
        for key, value in node.value:
            if not isinstance(key, yaml.ScalarNode):  # a list or mapping as a key: refused when built
                continue
            field = member(name, key.value)
            if (key.tag, key.value) in first:
                raise SceneError(field, f"duplicate key (at {_position(first[key.tag, key.value])} "
                                        f"and {_position(key.start_mark)})")
            first[key.tag, key.value] = key.start_mark
            _check_keys(value, field)


def _position(mark: yaml.Mark) -> str:
    return f"line {mark.line + 1}, column {mark.column + 1}"


class _Loader(getattr(yaml, "CSafeLoader", yaml.SafeLoader)):  # libyaml's parser, when PyYAML has it: 6 times faster
    """PyYAML's safe loader reading YAML 1.2's core schema, not YAML 1.1's.

    So ``1e-3`` is a number (YAML 1.1 wants ``1.0e-3``), ``017`` is 17 (not octal 15; octal is
    ``0o17``), and ``1:30`` (not 90), ``yes``, ``on`` and ``2001-12-14`` are strings; merge keys
    (``<<``) are plain keys and only the core tags (``!!str``, ``!!int``, ``!!float``, ``!!bool``,
    ``!!null``, ``!!seq``, ``!!map``) are known.
    """

    yaml_implicit_resolvers: dict = {}
    yaml_constructors: dict = {}

    def construct_mapping(self, node: yaml.MappingNode, deep: bool = False) -> dict:
        return yaml.constructor.BaseConstructor.construct_mapping(self, node, deep)  # without 1.1's merge keys


# YAML 1.2 core schema (§10.3.2); ints before floats, which also match "1".
_NULL = re.compile(r"(?:~|null|Null|NULL|)\Z")
_BOOL = re.compile(r"(?:true|True|TRUE|false|False|FALSE)\Z")
_INT = re.compile(r"(?:[-+]?[0-9]+|0o[0-7]+|0x[0-9a-fA-F]+)\Z")
_FLOAT = re.compile(r"(?:[-+]?(?:\.[0-9]+|[0-9]+(?:\.[0-9]*)?)(?:[eE][-+]?[0-9]+)?"
                    r"|[-+]?\.(?:inf|Inf|INF)|\.(?:nan|NaN|NAN))\Z")
for _tag, _pattern, _first in (("null", _NULL, ["~", "n", "N", ""]), ("bool", _BOOL, list("tTfF")),
                               ("int", _INT, list("-+0123456789")), ("float", _FLOAT, list("-+.0123456789"))):
    _Loader.add_implicit_resolver(f"tag:yaml.org,2002:{_tag}", _pattern, _first)


def _scalar(loader: _Loader, node: yaml.ScalarNode, pattern: re.Pattern, kind: str) -> str:
    """The text of ``node``, which its tag says is a ``kind``: it must read as one by YAML 1.2."""
    text = loader.construct_scalar(node)
    if not pattern.match(text):
        raise yaml.constructor.ConstructorError(problem=f"{shown(text)} is not a YAML 1.2 {kind}",
                                                problem_mark=node.start_mark)
    return text


def _construct_bool(loader: _Loader, node: yaml.ScalarNode) -> bool:
    return _scalar(loader, node, _BOOL, "boolean").lower() == "true"


def _construct_int(loader: _Loader, node: yaml.ScalarNode) -> int:
    text = _scalar(loader, node, _INT, "integer")
    try:
        return int(text[2:], 8 if text[1] == "o" else 16) if text[:2] in ("0o", "0x") else int(text)
    except ValueError:  # Python reads at most 4300 digits (sys.get_int_max_str_digits)
        raise yaml.constructor.ConstructorError(problem=f"an integer of {len(text)} digits is too long",
                                                problem_mark=node.start_mark) from None


def _construct_float(loader: _Loader, node: yaml.ScalarNode) -> float:
    text = _scalar(loader, node, _FLOAT, "number").lower()
    return float(text.replace(".inf", "inf").replace(".nan", "nan"))


for _tag, _constructor in (("null", yaml.SafeLoader.construct_yaml_null), ("bool", _construct_bool),
                           ("int", _construct_int), ("float", _construct_float),
                           ("str", yaml.SafeLoader.construct_yaml_str), ("seq", yaml.SafeLoader.construct_yaml_seq),
                           ("map", yaml.SafeLoader.construct_yaml_map)):
    _Loader.add_constructor(f"tag:yaml.org,2002:{_tag}", _constructor)
_Loader.add_constructor(None, yaml.SafeLoader.construct_undefined)  # any other tag is an error
