"""A batch worker's program, run as ``python -P -m planner.batch.worker FD PARENT`` by
:class:`~planner.batch.executors.LocalExecutor`: it answers calls over the connection on file
descriptor ``FD`` until it closes, and dies with its parent, the process ``PARENT``.

A worker is a fresh interpreter that imports only the planner and what the calls it gets name,
never the program that started the batch (multiprocessing's ``spawn`` and ``forkserver`` both run
the parent's ``__main__`` again in each child, so a script without an ``if __name__ ==
"__main__":`` guard would start its batch again in every worker; docs/stack.md, "Batch workers").
"""

from __future__ import annotations

import os
import signal
import sys
import time
import traceback
from multiprocessing.connection import Connection

from ..model.processes import die_with_parent
from ..model.stop import quiet_child
from .executors import describe  # not the other way: the package must not import this module, run as __main__

__all__ = ["serve"]


def serve(conn: Connection, parent: int) -> None:
    """A worker's life: receive ``("path", sys_path)`` (the parent's, so that a call's function
    imports here as it does there), ``("shared", obj)`` and ``("call", index, fn, item)`` messages,
    answer each call with ``(index, value, error, pid, seconds)``, until the connection closes."""
    die_with_parent(parent, signal.SIGKILL)  # it writes nothing: SIGKILL is the right end
    quiet_child()  # Ctrl-C reaches the whole group: the run handles it
    shared = None
    while True:
        try:
            message = conn.recv()
        except (EOFError, OSError):
            return
        if message[0] == "path":
            sys.path[:] = message[1]
            continue
        if message[0] == "shared":
            shared = message[1]
            continue
        _, index, fn, item = message
        clock = time.perf_counter()
        try:
            value, error = fn(item, shared), None
        except Exception as err:  # the call's own failure: reported, the worker goes on
            value, error = None, describe(err)
            traceback.print_exc()
        conn.send((index, value, error, os.getpid(), time.perf_counter() - clock))


if __name__ == "__main__":
    serve(Connection(int(sys.argv[1])), int(sys.argv[2]))
