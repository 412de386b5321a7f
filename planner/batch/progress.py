"""A batch's progress on standard error: a tqdm bar with the done and failed counts and the ETA on
a terminal; elsewhere (a log, CI) one plain line per finished task, which a bar would fill with
carriage returns.

>>> import io
>>> stream = io.StringIO()
>>> with Progress(2, stream=stream) as progress:
...     progress.update("a-s1", "solved"); progress.update("a-s2", "failed")
>>> print(stream.getvalue(), end="")
[1/2] a-s1: solved (1 done, 0 failed)
[2/2] a-s2: failed (2 done, 1 failed)
"""

from __future__ import annotations

import sys
from typing import TextIO

__all__ = ["Progress"]


class Progress:
    """Progress of ``total`` tasks, ``done`` of them finished already (a resumed run)."""

    def __init__(self, total: int, done: int = 0, stream: TextIO | None = None):
        self.total, self.done, self.failed = total, done, 0
        self.stream = sys.stderr if stream is None else stream
        self._bar = None
        if self.stream.isatty():
            from tqdm import tqdm

            self._bar = tqdm(total=total, initial=done, file=self.stream, unit="task", dynamic_ncols=True,
                             postfix={"failed": 0})

    def update(self, task: str, status: str) -> None:
        """Task ``task`` finished with ``status``."""
        self.done += 1
        self.failed += status == "failed"
        if self._bar is not None:
            self._bar.set_postfix(failed=self.failed, refresh=False)
            self._bar.update(1)
        else:
            print(f"[{self.done}/{self.total}] {task}: {status} ({self.done} done, {self.failed} failed)",
                  file=self.stream, flush=True)

    def __enter__(self) -> Progress:
        return self

    def __exit__(self, *exc) -> None:
        if self._bar is not None:
            self._bar.close()
