"""Commands a test stops with Ctrl-C (SIGINT) must start with it at its default, as a command typed
at a terminal does: a process started with SIGINT ignored passes that on to what it starts, and the
command then rightly goes on ignoring it (planner.cli.main). pytest run under ``nohup`` or as a
background job of a shell is such a process, and the tests would fail there for that alone."""

from __future__ import annotations

import signal

__all__ = ["sigint_default"]


def sigint_default() -> None:
    """A ``preexec_fn`` for :class:`subprocess.Popen`: SIGINT at its default in the command started."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)
