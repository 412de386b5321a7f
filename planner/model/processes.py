"""Processes a run starts beside itself (the recorder, region workers): started safely, and never
outliving the run.

Forking copies only the thread that forks: a lock another thread held at that moment stays held
in the child for ever. So a run forks only while it has a single thread (:func:`fork_context`;
the ``plan`` command keeps numpy's BLAS to one thread for that, see :mod:`planner.cli`), and
otherwise does the work in its own process. Forking is chosen over spawning because a forked
child starts in milliseconds with everything imported, where a spawned one would import numpy,
shapely and the planner again (about half a second).

A child must not outlive its run, however the run ends, SIGKILL included, which runs no cleanup:
each calls :func:`die_with_parent` first thing.
"""

from __future__ import annotations

import ctypes
import os
import signal
import sys
import threading
from typing import TYPE_CHECKING

from .stop import Terminated, terminate

if TYPE_CHECKING:
    from multiprocessing.context import BaseContext

__all__ = ["cores", "die_with_parent", "fork_context", "threads"]

_PR_SET_PDEATHSIG = 1  # linux/prctl.h


def cores() -> int:
    """The CPUs this process may run on (its affinity, where the platform tells), the number of
    worker processes that can run at once."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


def threads() -> int:
    """The threads this process runs, native ones included where the platform tells
    (``/proc/self/task`` on Linux), else those Python knows of."""
    try:
        return len(os.listdir("/proc/self/task"))
    except OSError:
        return threading.active_count()


def fork_context() -> BaseContext | None:
    """The ``fork`` start method where forking is safe now: the platform has it and this process
    runs one thread; else None (the caller then works in its own process)."""
    import multiprocessing  # only where a child is started: a warm in-process plan() is spared it

    if "fork" not in multiprocessing.get_all_start_methods() or threads() != 1:
        return None
    return multiprocessing.get_context("fork")


def die_with_parent(parent: int, signum: int = signal.SIGTERM) -> None:
    """Make this child process get ``signum`` when its parent ``parent`` (a pid) dies, whatever
    kills it; SIGTERM is raised as :class:`~planner.model.stop.Terminated`, so that the child can
    remove what it was writing.

    On Linux the kernel sends it (``prctl(PR_SET_PDEATHSIG)``): nothing to poll, and it works while
    the child is blocked in C code. Elsewhere a daemon thread watches the parent's pid every 0.2 s.
    If the parent died before the call, the signal comes at once.
    """
    if signum == signal.SIGTERM:
        signal.signal(signal.SIGTERM, terminate)
    if sys.platform.startswith("linux"):
        ctypes.CDLL(None, use_errno=True).prctl(_PR_SET_PDEATHSIG, signum)
    else:
        def watch() -> None:
            while os.getppid() == parent:
                threading.Event().wait(0.2)
            os.kill(os.getpid(), signum)

        threading.Thread(target=watch, name="stablepush-parent-watch", daemon=True).start()
    if os.getppid() != parent:  # it died before the kernel was told
        if signum == signal.SIGTERM:
            raise Terminated
        os.kill(os.getpid(), signum)
