"""How a run is stopped from outside: Ctrl-C (SIGINT) and SIGTERM, the signal that schedulers,
``timeout`` and CI jobs send.

Both end a run at once with nothing partial written: Ctrl-C as :class:`KeyboardInterrupt`, SIGTERM
as :class:`Terminated` (exit code 143, the shell's convention of 128 + the signal number, as 130
is for Ctrl-C). Python raises a signal's exception wherever the main thread happens to be; inside
a callback of OMPL's C++ code it would be swallowed there, so a search runs under
:func:`signals_deferred`, which only notes the signal and raises its exception once the C++ code
has returned.
"""

from __future__ import annotations

import signal
import threading
from collections.abc import Iterator
from contextlib import contextmanager

__all__ = ["Terminated", "quiet_child", "raise_on_sigterm", "signals_blocked", "signals_deferred", "terminate"]


class Terminated(BaseException):
    """The run received SIGTERM. A BaseException, like KeyboardInterrupt, so that no
    ``except Exception`` on the way swallows it."""


def terminate(signum, frame) -> None:
    """A signal handler that raises :class:`Terminated`."""
    raise Terminated


@contextmanager
def raise_on_sigterm() -> Iterator[None]:
    """SIGTERM raises :class:`Terminated` in the main thread within the block (elsewhere, where
    signals cannot be handled, nothing changes)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGTERM, terminate)
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
                for s in (signal.SIGINT, signal.SIGTERM) if signal.getsignal(s) is not signal.SIG_IGN}
    try:
        yield noted
    finally:
        for s, handler in previous.items():
            signal.signal(s, handler)
    if noted:
        raise KeyboardInterrupt if noted[0] == signal.SIGINT else Terminated


_STOPS = {signal.SIGINT, signal.SIGTERM}


@contextmanager
def signals_blocked() -> Iterator[None]:
    """Within the block, SIGINT and SIGTERM wait (blocked) and are delivered on leaving it, and
    SIGINT is ignored, so that a child started within it cannot get either before it has set its
    own handlers (:func:`quiet_child`): otherwise Ctrl-C in a child's first moments prints its
    traceback. A forked child keeps the mask; a spawned one (an exec, whose mask multiprocessing
    clears) keeps SIGINT ignored, and Python then installs no KeyboardInterrupt handler; SIGTERM
    ends it silently, Python having none for it. (A Ctrl-C between the blocking and the ignoring,
    microseconds, is lost.)"""
    if not hasattr(signal, "pthread_sigmask"):
        yield
        return
    mask = signal.pthread_sigmask(signal.SIG_BLOCK, _STOPS)
    handler = signal.getsignal(signal.SIGINT)
    ignoring = threading.current_thread() is threading.main_thread() and handler is not None
    if ignoring:
        signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        if ignoring:
            signal.signal(signal.SIGINT, handler)
        signal.pthread_sigmask(signal.SIG_SETMASK, mask)


def quiet_child(on_sigterm=signal.SIG_DFL) -> None:
    """In a child process started under :func:`signals_blocked`: ignore Ctrl-C (it reaches the
    whole group; the run handles it and stops its children), handle SIGTERM by ``on_sigterm``
    (by default it ends the child at once and silently, not as the run's own :class:`Terminated`,
    inherited over a fork, which would print a traceback there), then take signals again."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, on_sigterm)
    if hasattr(signal, "pthread_sigmask"):
        signal.pthread_sigmask(signal.SIG_UNBLOCK, _STOPS)
