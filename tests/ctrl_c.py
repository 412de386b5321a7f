"""Commands a test stops with Ctrl-C (SIGINT) must start with it at its default, as a command typed
at a terminal does: a process started with SIGINT ignored passes that on to what it starts, and the
command then rightly goes on ignoring it (planner.cli.main). pytest run under ``nohup`` or as a
background job of a shell is such a process, and the tests would fail there for that alone.

The command is started through a small Python that sets SIGINT to its default and ``exec`` s it
(not a ``preexec_fn``, which runs Python between fork and exec of a process that may have threads)."""

from __future__ import annotations

import sys

__all__ = ["sigint_default"]

_TRAMPOLINE = "import os, signal, sys; signal.signal(signal.SIGINT, signal.SIG_DFL); os.execv(sys.argv[1], sys.argv[1:])"


def sigint_default(argv: list[str]) -> list[str]:
    """``argv`` (its first item a path to an executable) run with SIGINT at its default."""
    return [sys.executable, "-c", _TRAMPOLINE, *argv]
