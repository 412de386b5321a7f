"""The executors by name, as the ``plan`` command's ``--engine`` gives them."""

from __future__ import annotations

from ..model.fields import SceneError
from .executors import Executor, LocalExecutor
from .ray_engine import RayExecutor

__all__ = ["ENGINES", "executor"]

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
        raise SceneError("--engine", f"must be one of {', '.join(ENGINES)}, got {engine!r}")
    if workers is not None and workers < 1:
        raise SceneError("--jobs", f"must be at least 1, got {workers}")
    if engine == "local":
        if address is not None:
            raise SceneError("--address", "needs --engine ray")
        return LocalExecutor(workers)
    return RayExecutor(workers, address)
