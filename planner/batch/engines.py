"""The executors by name, as the ``plan`` command's ``--engine`` gives them."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

from ..model.fields import SceneError
from .executors import Executor, LocalExecutor
from .ray_engine import RayExecutor

__all__ = ["ENGINES", "executor", "map_ordered"]

ENGINES = ("local", "ray")


def executor(engine: str = "local", workers: int | None = None, address: str | None = None) -> Executor:
    """The executor ``engine`` names, with ``workers`` calls at once (default: one per core of this
    machine, or every CPU of the Ray cluster); ``address`` is an existing Ray cluster's.

    Raises
    ------
    SceneError
        For an unknown engine, a worker count below 1, an address without Ray, or Ray not installed.
    """
    if engine not in ENGINES:
        raise SceneError("engine", f"must be one of {', '.join(ENGINES)}, got {engine!r}")
    if workers is not None and workers < 1:
        raise SceneError("jobs", f"must be at least 1, got {workers}")
    if engine == "local":
        if address is not None:
            raise SceneError("address", "needs the ray engine")
        return LocalExecutor(workers)
    return RayExecutor(workers, address)


def map_ordered(fn: Callable[[Any, Any], Any], items: Sequence, workers: int | None = None, engine: str = "local",
                address: str | None = None) -> list:
    """``fn(item, None)`` for each of ``items`` on the ``engine`` executor (:func:`executor`), the
    values in the items' order: for the benchmarks and maps, which need every value.

    >>> map_ordered(divmod, [7, 9], 1)
    Traceback (most recent call last):
    ...
    RuntimeError: item 0 failed: TypeError: unsupported operand type(s) for divmod(): 'int' and 'NoneType'

    Raises
    ------
    RuntimeError
        If a call failed (raised, or its worker died more often than it is retried).
    """
    values: list = [None] * len(items)
    with executor(engine, workers, address) as pool:
        for index, outcome in pool.run(fn, items):
            if outcome.failed:
                raise RuntimeError(f"item {index} failed: {outcome.error}")
            values[index] = outcome.value
    return values
