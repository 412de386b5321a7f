"""Writing the rerun recording beside the search: the ``plan`` command's recorder.

Importing rerun takes about 0.3 s, as long as many searches, and drawing the pushed edge's
force-status map another 0.1 s. :func:`recorder` forks a child process before the search; while
the parent plans, the child imports rerun and the recording code and draws the map of each edge
the plan may start on, then writes the recording it is sent. On a two-core machine the import costs the command
nothing. The child is forked only where that is safe (:func:`planner.model.processes.fork_context`:
a platform with ``fork``, this process running one thread, so rerun not imported yet); otherwise
the recording is written in this process, as :func:`planner.outputs.recording.write_recording` does. Either way one
:class:`~planner.actions.region_cache.RegionCache` serves: the child, forked with a copy of it,
keeps there the analyses it prepares and draws them from it; the regions the search computes
meanwhile reach it through the cache's folder.

>>> with recorder(scene) as write:   # doctest: +SKIP
...     result = plan(scene)
...     write("out/scene.rrd", scene, result)
"""

from __future__ import annotations

import functools
import os
import sys
import traceback
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from importlib import import_module
from pathlib import Path

from ..actions.region_cache import RegionCache, default_cache
from ..model.scene import Scene
from ..model.processes import die_with_parent, fork_context
from ..model.stop import Terminated, quiet_child, signals_blocked, terminate

__all__ = ["RecordingFailed", "recorder"]

#: Seconds the parent waits for a child that has been told to stop.
_GRACE = 5.0


def _write_inline(cache: RegionCache, path: str | Path, *args) -> None:
    from .recording import write_recording  # rerun takes a third of a second to import

    try:
        write_recording(path, *args, cache=cache)
    except OSError:
        raise
    except Exception as err:
        raise RecordingFailed.of(err) from err


def _child(conn, parents_end, parent: int, scene: Scene, cache: RegionCache) -> None:
    """The forked recorder: import rerun and prepare the recording of ``scene`` now, write it
    when sent the plan. It ends with the parent, however that ends: the parent's end of the pipe
    is closed here (so the parent's exit is an end of file), and a signal comes if the parent is
    killed. Whatever fails is sent back as one :class:`RecordingFailed`, never printed here."""
    parents_end.close()
    try:
        die_with_parent(parent)
        quiet_child(terminate)  # Ctrl-C is the parent's to report; SIGTERM ends this process below
        failed = None
        try:
            import_module(".recording", __package__)  # rerun and the drawing code: the import the parent is spared
            from .analysis import prepare

            prepare(scene, conn.poll, cache)
        except Exception as err:  # reported when the recording is asked for, with what it says
            failed = RecordingFailed.of(err)
        job = conn.recv()
        if failed is not None:
            conn.send(failed)
            return
        try:
            _write_inline(cache, *job)
            conn.send(None)
        except (OSError, RecordingFailed) as err:
            conn.send(err)
    except (EOFError, BrokenPipeError, Terminated):  # the parent has stopped: so does this process
        return


class RecordingFailed(Exception):
    """The recording could not be made (not an OS error: the message names the exception;
    ``details`` holds its traceback)."""

    def __init__(self, message: str, details: str = ""):
        super().__init__(message)
        self.details = details

    @classmethod
    def of(cls, err: Exception) -> "RecordingFailed":
        return cls(f"{type(err).__name__}: {err}".splitlines()[0], traceback.format_exc())

    def __reduce__(self):  # sent through the pipe with its details
        return RecordingFailed, (str(self), self.details)


@contextmanager
def recorder(scene: Scene, cache: RegionCache | None = None) -> Iterator[Callable[..., None]]:
    """A function with :func:`planner.outputs.recording.write_recording`'s arguments but its
    ``cache``, writing through a child forked now (module docstring) or else in this process; the
    child is stopped on leaving. A child also prepares what any recording of ``scene`` needs
    (:func:`planner.outputs.analysis.prepare`). Both read and keep the regions and analyses in
    ``cache`` (default: :func:`~planner.actions.region_cache.default_cache`); the search's
    regions reach the child through its folder.

    Raises
    ------
    OSError
        From the call, if the recording cannot be written (as ``write_recording`` raises it).
    RecordingFailed
        From the call, if anything else stopped the recording (the recorder process included).
    """
    cache = default_cache() if cache is None else cache
    context = None if "rerun" in sys.modules else fork_context()
    if context is None:
        yield functools.partial(_write_inline, cache)
        return
    conn, theirs = context.Pipe()
    child = context.Process(target=_child, args=(theirs, conn, os.getpid(), scene, cache), name="stablepush-recorder",
                            daemon=True)
    with signals_blocked():  # until the child has set its own handlers
        child.start()
    theirs.close()

    sent = []

    def write(path: str | Path, *args) -> None:
        try:
            conn.send((path, *args))
            sent.append(path)
            error = conn.recv()
        except (BrokenPipeError, EOFError):
            child.join(_GRACE)
            raise RecordingFailed(f"the recorder process ended unexpectedly (exit code {child.exitcode})") from None
        if error is not None:
            raise error

    try:
        yield write
    finally:
        conn.close()
        if sent:  # it has answered: it is ending
            child.join(_GRACE)
        if child.is_alive():  # nothing to record (an error, Ctrl-C): not worth waiting for
            child.kill()
            child.join()
