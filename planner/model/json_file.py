"""Untrusted JSON (plan files, a batch's results lines, cache files) read within bounds, or
refused with a one-line :class:`~planner.model.fields.SceneError`.

:mod:`json` recurses once per level of nesting, so a file of a few thousand ``[`` raises
:class:`RecursionError` deep in the parser; and it turns a number of any length into an int.
Here the nesting is measured first, in one pass over the text with its strings taken out, and
refused beyond ``max_depth``; any other failure of the parser (malformed text, an integer of more
digits than Python converts) is the same one line. What the data means is the caller's to check,
field by field.

>>> parse_json('{"a": [1, 2.5, "x]"]}', "plan")
{'a': [1, 2.5, 'x]']}
>>> parse_json("[" * 5000 + "]" * 5000, "plan")
Traceback (most recent call last):
...
planner.model.fields.SceneError: plan: unsupported JSON: nests deeper than 16 lists and mappings
>>> parse_json('{"a": ', "plan")
Traceback (most recent call last):
...
planner.model.fields.SceneError: plan: malformed JSON: Expecting value: line 1 column 7 (char 6)
"""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

import numpy as np

from .fields import SceneError
from .input_file import read_text

__all__ = ["MAX_DEPTH", "depth", "parse_json", "read_json"]

#: Deepest nesting of lists and mappings read: a plan file's own goes 4 deep (segments[0].contact[1]).
MAX_DEPTH = 16
_STRING = re.compile(r'"(?:[^"\\]|\\.)*"', re.DOTALL)


def depth(text: str) -> int:
    """How deep the lists and mappings of the JSON ``text`` nest (outside its strings); on
    malformed text, at least as deep as any parse of it would go.

    >>> depth('[{"a": [1]}, "[[["]'), depth("7")
    (3, 0)
    """
    bare = np.frombuffer(_STRING.sub("", text).encode("utf-8", "surrogatepass"), dtype=np.uint8)
    steps = np.isin(bare, (ord("["), ord("{"))).astype(np.int64) - np.isin(bare, (ord("]"), ord("}")))
    return int(np.cumsum(steps).max(initial=0))


def parse_json(text: str, name: str, max_depth: int = MAX_DEPTH) -> Any:
    """The JSON value in ``text`` as plain data.

    Raises
    ------
    SceneError
        Naming ``name``: the text nests deeper than ``max_depth``, or is not JSON.
    """
    # Nesting needs an opening bracket a level: most texts have too few to be measured at all.
    if text.count("[") + text.count("{") > max_depth and depth(text) > max_depth:
        raise SceneError(name, f"unsupported JSON: nests deeper than {max_depth} lists and mappings")
    try:
        return json.loads(text)
    except (ValueError, RecursionError) as err:  # ValueError: JSONDecodeError, or an int of too many digits
        raise SceneError(name, f"malformed JSON: {' '.join(str(err).split())}") from None


def read_json(path: str | Path, name: str, max_bytes: int, max_depth: int = MAX_DEPTH) -> Any:
    """The JSON in the regular file ``path`` of at most ``max_bytes`` bytes (:func:`parse_json`).

    Raises
    ------
    SceneError
        Naming ``name``, for any file that is not such JSON (:func:`~planner.model.input_file.read_text`).
    """
    return parse_json(read_text(path, name, max_bytes), name, max_depth)
