"""How a run is stopped from outside: Ctrl-C (SIGINT) and SIGTERM, the signal that schedulers,
``timeout`` and CI jobs send.

Both end a run at once with nothing partial written: Ctrl-C as :class:`KeyboardInterrupt`, SIGTERM
as :class:`Terminated` (exit code 143, the shell's convention of 128 + the signal number, as 130
is for Ctrl-C). Python raises a signal's exception wherever the main thread happens to be; inside
a callback of OMPL's C++ code it would be swallowed there, so a search runs under
:func:`signals_deferred`, which only notes the signal and raises its exception once the C++ code
has returned.

A process the run starts (the recorder, region workers) must not outlive it, however it ends,
even by SIGKILL, which runs no cleanup: each calls :func:`die_with_parent` first thing.
"""

from __future__ import annotations

import ctypes
import os
import signal
import sys
import threading
from collections.abc import Iterator
from contextlib import contextmanager

__all__ = ["Terminated", "die_with_parent", "raise_on_sigterm", "signals_deferred"]


class Terminated(BaseException):
    """The run received SIGTERM. A BaseException, like KeyboardInterrupt, so that no
    ``except Exception`` on the way swallows it."""


def _terminate(signum, frame) -> None:
    raise Terminated


@contextmanager
def raise_on_sigterm() -> Iterator[None]:
    """SIGTERM raises :class:`Terminated` in the main thread within the block (elsewhere, where
    signals cannot be handled, nothing changes)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGTERM, _terminate)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


@contextmanager
def signals_deferred() -> Iterator[list[int]]:
    """Within the block, SIGINT and SIGTERM are only noted in the list it gives (code that polls
    it can stop early); on leaving, the first one noted is raised as :class:`KeyboardInterrupt` or
    :class:`Terminated`. Outside the main thread, where signals cannot be handled, the list stays
    empty.

    >>> import os
    >>> try:
    ...     with signals_deferred() as noted:
    ...         os.kill(os.getpid(), signal.SIGTERM)
    ...         print("still running, noted:", noted == [signal.SIGTERM])
    ... except Terminated:
    ...     print("terminated on leaving")
    still running, noted: True
    terminated on leaving
    """
    noted: list[int] = []
    if threading.current_thread() is not threading.main_thread():
        yield noted
        return
    previous = {s: signal.signal(s, lambda signum, frame: noted.append(signum))
                for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield noted
    finally:
        for s, handler in previous.items():
            signal.signal(s, handler)
    if noted:
        raise KeyboardInterrupt if noted[0] == signal.SIGINT else Terminated


_PR_SET_PDEATHSIG = 1  # linux/prctl.h


def die_with_parent(parent: int) -> None:
    """Make this child process get SIGTERM (raised as :class:`Terminated`) when its parent
    ``parent`` (a pid) dies, whatever kills it.

    On Linux the kernel sends it (``prctl(PR_SET_PDEATHSIG)``): nothing to poll, and it works while
    the child is blocked in C code. If the parent died before the call, the child stops at once.
    Elsewhere a daemon thread watches the parent's pid every 0.2 s and signals the child itself.
    """
    signal.signal(signal.SIGTERM, _terminate)
    if sys.platform.startswith("linux"):
        ctypes.CDLL(None, use_errno=True).prctl(_PR_SET_PDEATHSIG, signal.SIGTERM)
    else:
        def watch() -> None:
            while os.getppid() == parent:
                threading.Event().wait(0.2)
            os.kill(os.getpid(), signal.SIGTERM)

        threading.Thread(target=watch, name="stablepush-parent-watch", daemon=True).start()
    if os.getppid() != parent:  # it died before the kernel was told
        raise Terminated
