"""The Ray engine: a batch's calls as Ray tasks, on an existing cluster (``address``) or on one
started on this machine for the run and stopped after it.

Ray is an optional extra (``pip install 'stablepush[ray]'``); without it :class:`RayExecutor`
raises a :class:`~planner.model.fields.SceneError` naming ``--engine``, which the ``plan`` command
prints as its one line. A cluster started here listens on 127.0.0.1 only as far as Ray allows
(``_node_ip_address``; docs/stack.md, "Ray"), has no dashboard, and its processes are stopped by
:func:`ray.shutdown` when the run ends, however it ends.

The calls behave as :class:`~planner.batch.executors.LocalExecutor`'s: the ``shared`` object is put
once into Ray's object store (each node keeps one copy, its workers read it from there); a task
whose worker dies is resubmitted here (Ray's own ``max_retries`` is 0, so that attempts are counted
the same on every engine) and, after ``retries``, answered failed with Ray's reason; a task past
``timeout`` is cancelled with its worker killed (``ray.cancel(force=True)``).
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Iterable, Iterator
from typing import Any

from ..model.fields import SceneError
from .executors import Feed, Outcome, describe

__all__ = ["RayExecutor", "needs_ray"]


def needs_ray():
    """The ``ray`` module, or a :class:`SceneError` saying how to install it. Ray 2.60's clusters
    (``ray start``) want token authentication, and Ray reads the mode once, when it is first
    imported: a driver that has not chosen one asks for it (the token is read from
    ``~/.ray/auth_token``, or as ``RAY_AUTH_TOKEN_PATH`` or ``RAY_AUTH_TOKEN`` say)."""
    os.environ.setdefault("RAY_AUTH_MODE", "token")
    try:
        import ray
    except ImportError:
        raise SceneError("engine", "ray is not installed: pip install 'stablepush[ray]'") from None
    return ray


def _call(fn: Callable[[Any, Any], Any], item: Any, shared: Any) -> tuple[Any, str | None, str, int, float]:
    """In a Ray worker: ``fn(item, shared)``, an exception it raises as its one-line description
    (so that Ray does not retry or wrap it), with the worker's host and pid and the call's seconds."""
    import socket

    clock = time.perf_counter()
    try:
        value, error = fn(item, shared), None
    except Exception as err:
        value, error = None, describe(err)
    return value, error, socket.gethostname(), os.getpid(), time.perf_counter() - clock


class RayExecutor:
    """Up to ``workers`` calls at once (default: every CPU of the cluster) as Ray tasks on the
    cluster at ``address``, or on a cluster of ``workers`` CPUs (default: this machine's) started now
    on 127.0.0.1 and stopped by :meth:`close`. With Ray already initialised in this process (a
    test's cluster), that one is used and left running."""

    def __init__(self, workers: int | None = None, address: str | None = None):
        ray = needs_ray()
        self._ray = ray
        self._started = not ray.is_initialized()
        if self._started:
            options = dict(include_dashboard=False, log_to_driver=False, configure_logging=False,
                           _node_ip_address="127.0.0.1")
            try:
                if address is None:
                    ray.init(num_cpus=workers, **options)
                else:
                    ray.init(address=address, **options)
            except (ConnectionError, RuntimeError, ValueError) as err:
                raise SceneError("address", f"cannot join the Ray cluster at {address}: {describe(err)}") from None
        cpus = int(ray.cluster_resources().get("CPU", 1))
        self.workers = max(1, min(cpus, workers) if workers else cpus)
        self._remote = ray.remote(num_cpus=1, max_retries=0)(_call)

    def __enter__(self) -> RayExecutor:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def close(self) -> None:
        """Stop the cluster this executor started (every process of it), and only that one."""
        if self._started and self._ray.is_initialized():
            self._ray.shutdown()

    def run(self, fn: Callable[[Any, Any], Any], items: Iterable, shared: Any = None, *, retries: int = 2,
            timeout: float | None = None) -> Iterator[tuple[int, Outcome]]:
        """Call ``fn(item, shared)`` for each item; yield ``(index, Outcome)`` as calls end."""
        ray = self._ray
        shared_ref = ray.put(shared)
        feed = Feed(items)
        running: dict[Any, tuple[int, Any, float]] = {}  # ref: (index, item, when it was submitted)

        def submit() -> None:
            # Two per worker in flight: one queued behind each running call hides Ray's round trip
            # (about 5 ms), and a task's clock, started when it is submitted, runs at most one
            # call early.
            while len(running) < 2 * self.workers and (call := feed.take()) is not None:
                index, item = call
                running[self._remote.remote(fn, item, shared_ref)] = (index, item, time.monotonic())

        try:
            submit()
            while running:
                soonest = min(began for _, _, began in running.values()) + timeout if timeout else None
                done, _ = ray.wait(list(running), num_returns=1,
                                   timeout=None if soonest is None else max(0.01, soonest - time.monotonic()))
                for ref in done:
                    index, item, _ = running.pop(ref)
                    try:
                        value, error, host, pid, seconds = ray.get(ref)
                    except (ray.exceptions.WorkerCrashedError, ray.exceptions.NodeDiedError,
                            ray.exceptions.OutOfMemoryError, ray.exceptions.LocalRayletDiedError) as err:
                        if feed.attempts[index] <= retries:
                            feed.again(index, item)
                        else:
                            tries = feed.answered(index)
                            yield index, Outcome(error=f"its worker died ({describe(err)}), {tries} times",
                                                 attempts=tries)
                        continue
                    yield index, Outcome(value, error, host, pid, feed.answered(index), seconds)
                if timeout:
                    for ref, (index, _, began) in list(running.items()):
                        if time.monotonic() - began > timeout:
                            ray.cancel(ref, force=True)
                            del running[ref]
                            yield index, Outcome(error=f"stopped after {timeout:g} s, past its time limit",
                                                 attempts=feed.answered(index))
                submit()
        finally:
            # Cancelling a task that completes at that moment trips a check inside Ray 2.60
            # ("Tried to complete task that was not pending") that aborts this process, as a
            # SIGTERM mid-batch did once in CI. A cluster this executor started is shut down next,
            # which stops its tasks anyway; on another cluster only the tasks not done are cancelled.
            if running and not self._started:
                done, _ = ray.wait(list(running), num_returns=len(running), timeout=0)
                for ref in set(running) - set(done):
                    ray.cancel(ref, force=True)
