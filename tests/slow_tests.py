"""Which tests are ``slow``: ``python -m pytest -q -m "not slow"`` runs the rest, the quick subset.

The list is data, ``tests/slow_tests.txt``: the tests that took at least :data:`THRESHOLD`
seconds (setup, call and teardown) in a full run here. Regenerate it after adding slow tests::

    python -m pytest -q --durations=0 > durations.log
    python tests/slow_tests.py durations.log

A test not in the list counts as quick, so the quick subset can only grow slower, never miss a
test of the full suite: CI runs everything.
"""

from __future__ import annotations

import re
import sys
from collections import Counter
from pathlib import Path

#: Seconds from which a test is slow.
THRESHOLD = 0.3
LIST = Path(__file__).with_name("slow_tests.txt")


def slow(log: str) -> list[str]:
    """Node ids of the tests at or over :data:`THRESHOLD` in a ``--durations=0`` report.

    >>> slow("1.20s call     tests/test_a.py::test_x\\n0.30s setup    tests/test_a.py::test_x\\n"
    ...      "0.20s call     tests/test_a.py::test_y")
    ['tests/test_a.py::test_x']
    """
    spent: Counter[str] = Counter()
    for line in log.splitlines():
        if m := re.match(r"\s*([\d.]+)s (?:setup|call|teardown)\s+(.+?)\s*$", line):  # ids may hold spaces
            spent[m.group(2)] += float(m.group(1))
    return sorted(name for name, seconds in spent.items() if seconds >= THRESHOLD)


def marked() -> set[str]:
    """The node ids in :data:`LIST`."""
    return set(LIST.read_text().splitlines()) if LIST.exists() else set()


if __name__ == "__main__":
    LIST.write_text("\n".join(slow(Path(sys.argv[1]).read_text())) + "\n")
