"""Executors: run one picklable function over many items in worker processes, and hear of each
call as it ends, whatever happens to the workers.

An executor's :meth:`~Executor.run` calls ``fn(item, shared)`` for every item and yields
``(index, Outcome)`` in the order the calls finish. ``shared`` is sent to each worker once per run
(the batch's stable regions), not with every item. A call whose worker dies (killed, out of memory,
its node lost) is begun again on a new worker, up to ``retries`` times, then answered as failed
with the reason; a call that raises is answered failed at once (it would raise again: the same
item gives the same call); a call still running ``timeout`` seconds after it began has its worker
killed and is answered failed. So a run always ends with every item answered.

:class:`LocalExecutor` is a pool of this machine's processes. Its workers are new interpreters
running :mod:`planner.batch.worker`, not forks: a fork copies only the forking thread, so a lock
held by another thread (a progress bar's, Ray's, OMPL's, a profiler's) would stay held in the child
for ever (:mod:`planner.model.processes`); nor multiprocessing's ``spawn`` or ``forkserver``
children, which run the parent's ``__main__`` again (a user's script without its guard would start
its batch again in every worker). A worker imports the planner once, then plans task after task;
a call's function and item are pickled, so the function must be importable by its module's name
(:func:`importable`: one of a module run as ``python -m`` is found by that name). A worker dies with the run
(:func:`~planner.model.processes.die_with_parent`), ignores Ctrl-C (the run kills it) and is killed
by pid when the run ends or is interrupted, so none is left behind. A dead worker breaks nothing
but its own call, unlike :class:`multiprocessing.pool.Pool` (which hangs) or
:class:`concurrent.futures.ProcessPoolExecutor` (whose every pending call fails with
``BrokenProcessPool``).

>>> with LocalExecutor(2) as pool:
...     sorted((i, o.value) for i, o in pool.run(divmod, [7, 9], shared=2))
[(0, (3, 1)), (1, (4, 1))]
"""

from __future__ import annotations

import functools
import importlib
import os
import socket
import subprocess
import sys
import time
from collections import deque
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, replace
from multiprocessing import Pipe
from multiprocessing.connection import wait
from pathlib import Path
from typing import Any, Protocol

from ..model.processes import cores
from ..model.stop import signals_blocked

__all__ = ["Executor", "Feed", "LocalExecutor", "Outcome", "describe", "importable"]


@dataclass(frozen=True)
class Outcome:
    """How one call ended: its ``value``, or ``error`` (why it failed, one line); the ``host`` and
    process id of the worker that answered, the ``attempts`` it took (more than one when a worker
    died under it) and the ``seconds`` the call itself took in its worker (what is not, of a run's
    wall time, is the executor's overhead: planner.bench.batch)."""

    value: Any = None
    error: str | None = None
    host: str = ""
    pid: int = 0
    attempts: int = 1
    seconds: float = 0.0

    @property
    def failed(self) -> bool:
        return self.error is not None


class Executor(Protocol):
    """What runs a batch's calls (:class:`LocalExecutor`, :class:`planner.batch.ray_engine.RayExecutor`)."""

    workers: int  # calls that run at once

    def run(self, fn: Callable[[Any, Any], Any], items: Iterable, shared: Any = None, *, retries: int = 2,
            timeout: float | None = None) -> Iterator[tuple[int, Outcome]]: ...

    def close(self) -> None: ...

    def __enter__(self) -> Executor: ...

    def __exit__(self, *exc) -> None: ...


def describe(err: BaseException) -> str:
    """One line for an exception: its type and message, as a results file records it.

    >>> describe(ValueError("no\\nmore")), describe(KeyError())
    ('ValueError: no', 'KeyError')
    """
    return f"{type(err).__name__}: {err}".splitlines()[0] if str(err) else type(err).__name__


def importable(fn: Callable) -> Callable:
    """``fn`` as a worker can import it: itself, or, for a function of a module run as ``python -m
    NAME`` (whose ``__module__`` is ``'__main__'``), the same function reached through ``NAME``.
    A worker imports modules by name and never runs the parent's ``__main__`` (module docstring).

    Raises
    ------
    TypeError
        For a function of a script run by its path, which a worker cannot import: one line
        saying to move it into a module.
    """
    if getattr(fn, "__module__", None) != "__main__":
        return fn
    main = sys.modules["__main__"]
    name = getattr(getattr(main, "__spec__", None), "name", None)
    if not name:
        raise TypeError(f"{getattr(fn, '__qualname__', fn)!s} is defined in the script being run "
                        f"({getattr(main, '__file__', '__main__')}), which batch workers do not run: "
                        "define it in a module they can import")
    return functools.reduce(getattr, fn.__qualname__.split("."), importlib.import_module(name))


def _environment() -> dict[str, str]:
    """The environment a worker starts with: this one, the planner importable first (its ``-P``
    leaves the current folder out of its path, as the parent's may not hold it), and one BLAS
    thread unless the user chose a number, as the ``plan`` command asks for itself (planner.cli):
    a worker plans one task on one core, its matrices are tiny, and BLAS threads would only
    compete with the other workers for the cores."""
    root = str(Path(__file__).resolve().parents[2])
    path = os.pathsep.join(p for p in (root, os.environ.get("PYTHONPATH")) if p)
    return dict.fromkeys(_BLAS_THREADS, "1") | dict(os.environ) | {"PYTHONPATH": path}


#: Thread counts of the BLAS libraries numpy may load, read when the library loads.
_BLAS_THREADS = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")


class Feed:
    """The items of a run, taken one at a time as workers are free for them (an iterator is read
    no further ahead than that), calls begun again first, and each call's attempts so far.

    >>> feed = Feed(iter("ab"))
    >>> feed.take(), feed.peek()
    ((0, 'a'), (1, 'b'))
    >>> feed.again(0, "a"); feed.take(), feed.attempts[0]
    ((0, 'a'), 2)
    >>> feed.answered(0), feed.take(), feed.take(), feed.peek()
    (2, (1, 'b'), None, None)
    """

    def __init__(self, items: Iterable):
        self._items = enumerate(items)
        self._again: deque[tuple[int, Any]] = deque()
        self._next: tuple[int, Any] | None = None
        self.attempts: dict[int, int] = {}  # of each call begun and not yet answered

    def peek(self) -> tuple[int, Any] | None:
        """The next ``(index, item)`` to begin, or None when none is left."""
        if self._again:
            return self._again[0]
        if self._next is None:
            self._next = next(self._items, None)
        return self._next

    def take(self) -> tuple[int, Any] | None:
        """:meth:`peek`'s call, now begun (an attempt more)."""
        call = self.peek()
        if call is not None:
            if self._again:
                self._again.popleft()
            else:
                self._next = None
            self.attempts[call[0]] = self.attempts.get(call[0], 0) + 1
        return call

    def again(self, index: int, item: Any) -> None:
        """Begin call ``index`` again, before any other."""
        self._again.appendleft((index, item))

    def answered(self, index: int) -> int:
        """Forget call ``index``, answered now; return its attempts."""
        return self.attempts.pop(index)


def _pidfd(pid: int) -> int | None:
    """A file descriptor readable when process ``pid`` ends, whoever else holds its end of the
    connection (Linux 5.3 and later); None elsewhere, where the connection's end alone tells."""
    try:
        return os.pidfd_open(pid)
    except (AttributeError, OSError):
        return None


class _Worker:
    """One worker process (:mod:`planner.batch.worker`) and the connection to it."""

    def __init__(self, shared: Any):
        self.conn, child = Pipe()
        with signals_blocked():  # until the worker has its own handlers (worker.serve)
            self.process = subprocess.Popen(
                [sys.executable, "-P", "-m", "planner.batch.worker", str(child.fileno()), str(os.getpid())],
                pass_fds=[child.fileno()], env=_environment(), stdin=subprocess.DEVNULL)
        child.close()
        self.sentinel = _pidfd(self.process.pid)
        self.conn.send(("path", sys.path))
        self.conn.send(("shared", shared))
        self.index: int | None = None  # the call it runs
        self.item: Any = None  # and its item, to begin it again if the worker dies
        self.began = 0.0

    def begin(self, index: int, fn: Callable, item: Any) -> None:
        self.conn.send(("call", index, fn, item))
        self.index, self.began = index, time.monotonic()

    def waited_on(self) -> list:
        """What :func:`~multiprocessing.connection.wait` watches for it: an answer, or its end."""
        return [self.conn] if self.sentinel is None else [self.conn, self.sentinel]

    def exit_code(self, timeout: float) -> int | None:
        """Its exit code (minus the signal that ended it), waiting up to ``timeout`` s; None if it runs on."""
        try:
            return self.process.wait(timeout)
        except subprocess.TimeoutExpired:
            return None

    def kill(self) -> None:
        """Kill it by pid and reap it."""
        if self.process.poll() is None:
            self.process.kill()
        self.process.wait()
        self.conn.close()
        if self.sentinel is not None:
            os.close(self.sentinel)
            self.sentinel = None


class LocalExecutor:
    """Up to ``workers`` calls at once (default: one per core) in processes of this machine (module
    docstring). Workers are started by :meth:`run` and killed when it ends."""

    def __init__(self, workers: int | None = None):
        self.workers = max(1, cores() if workers is None else int(workers))
        self.host = socket.gethostname()

    def __enter__(self) -> LocalExecutor:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def close(self) -> None:
        """Nothing to release: each run stops its own workers."""

    def run(self, fn: Callable[[Any, Any], Any], items: Iterable, shared: Any = None, *, retries: int = 2,
            timeout: float | None = None) -> Iterator[tuple[int, Outcome]]:
        """Call ``fn(item, shared)`` for each item, taken from ``items`` as a worker is free for it
        (a worker is started only for an item waiting, so never more than the items); yield
        ``(index, Outcome)`` as calls end, ``index`` counting the items from 0 (module docstring)."""
        fn = importable(fn)
        feed = Feed(items)
        pool: list[_Worker] = []
        try:
            while True:
                # A worker is started only for a call waiting for one: never more than the calls.
                while (call := feed.peek()) is not None:
                    worker = next((w for w in pool if w.index is None), None)
                    if worker is None and len(pool) < self.workers:
                        worker = _Worker(shared)
                        pool.append(worker)
                    if worker is None:
                        break
                    try:
                        worker.begin(call[0], fn, call[1])
                    except OSError:  # it died while idle: replaced, the call not begun
                        pool.remove(worker)
                        worker.kill()
                        continue
                    worker.item = call[1]
                    feed.take()
                busy = [w for w in pool if w.index is not None]
                if not busy:
                    break  # nothing waits: every call is answered
                soonest = min((w.began + timeout for w in busy), default=None) if timeout else None
                ready = wait([c for w in busy for c in w.waited_on()],
                             None if soonest is None else max(0.0, soonest - time.monotonic()))
                for worker in busy:
                    index = worker.index
                    outcome = self._answer(worker, ready, timeout)
                    if outcome is None:
                        continue
                    if outcome == "died":
                        pool.remove(worker)
                        code = worker.exit_code(1.0)  # its own, if it is exiting of itself
                        worker.kill()
                        why = (f"its worker died (signal {-code})" if code is not None and code < 0
                               else f"its worker died (exit code {code})")
                        if feed.attempts[index] <= retries:
                            feed.again(index, worker.item)  # again, first, on a new worker
                            continue
                        yield index, Outcome(error=f"{why}, {feed.attempts[index]} times", host=self.host,
                                             attempts=feed.answered(index))
                    elif outcome == "late":
                        pool.remove(worker)
                        worker.kill()
                        yield index, Outcome(error=f"stopped after {timeout:g} s, past its time limit",
                                             host=self.host, attempts=feed.answered(index))
                    else:
                        worker.index = worker.item = None
                        yield index, replace(outcome, attempts=feed.answered(index))
        finally:
            for worker in pool:
                worker.kill()

    def _answer(self, worker: _Worker, ready: list, timeout: float | None) -> Outcome | str | None:
        """The worker's answer if it gave one, ``'died'``, ``'late'`` (past ``timeout``), or None (still running)."""
        if worker.conn in ready:
            try:
                index, value, error, pid, seconds = worker.conn.recv()
            except (EOFError, OSError):
                return "died"
            return Outcome(value, error, self.host, pid, seconds=seconds)
        if worker.sentinel in ready or worker.process.poll() is not None:
            return "died"
        if timeout and time.monotonic() - worker.began > timeout:
            return "late"
        return None

