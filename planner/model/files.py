"""Output files written whole or not at all: readers see the old file or the complete new one.

Every file a run writes (plan, recording, pictures, benchmark logs, cached regions) goes through
:func:`atomic_path`: it is written to a temporary file beside its final name, checked, flushed to
disk and renamed into place. A failed or short write raises :class:`OSError` naming the final
file and leaves nothing under that name. The temporary file carries the writer's process id, so
a run that was killed mid-write (and so could not clean up) leaves a file that the next write into
the same folder recognises as an orphan and removes.
"""

from __future__ import annotations

import os
import re
import shutil
import tempfile
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

__all__ = ["atomic_path", "remove_orphans", "staged_folder", "write_atomic"]

# ".<final name>.<pid>-<random>.tmp": the pid tells an orphan from a file still being written.
_TEMPORARY = re.compile(r"\..+\.(\d+)-[A-Za-z0-9_]+\.tmp\Z")


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # someone else's process: alive
        return True
    return True


def remove_orphans(folder: str | Path) -> list[Path]:
    """Remove the temporary files (and staged folders, :func:`staged_folder`) in ``folder`` whose
    writer is no longer running, and return them.

    >>> import tempfile
    >>> folder = Path(tempfile.mkdtemp())
    >>> (folder / ".plan.json.999999999-abc.tmp").write_text("half")  # a writer long gone
    4
    >>> (folder / f".plan.json.{os.getpid()}-def.tmp").write_text("busy")  # this process
    4
    >>> [p.name for p in remove_orphans(folder)], [p.name for p in folder.iterdir()] == [f".plan.json.{os.getpid()}-def.tmp"]
    (['.plan.json.999999999-abc.tmp'], True)
    """
    removed = []
    try:
        names = [p for p in Path(folder).iterdir() if p.name.endswith(".tmp")]
    except OSError:
        return removed
    for path in names:
        match = _TEMPORARY.match(path.name)
        if match and not _alive(int(match.group(1))):
            try:
                shutil.rmtree(path) if path.is_dir() and not path.is_symlink() else path.unlink()
                removed.append(path)
            except OSError:
                pass  # another run removed it first, or the folder is read-only: nothing to do
    return removed


def _named(err: OSError, path: Path) -> OSError:
    """``err`` naming ``path``, the file the caller wanted, not the temporary one."""
    return type(err)(err.errno, err.strerror or str(err), str(path)) if err.errno else err


@contextmanager
def atomic_path(path: str | Path, check: Callable[[Path], None] | None = None) -> Iterator[Path]:
    """Yield a temporary path beside ``path``; when the block succeeds, ``check(tmp)`` it (it
    raises :class:`OSError` if the file is not complete), flush it to disk and rename it onto
    ``path``; when anything fails, delete it. Orphans of killed writers in the folder are removed
    first (:func:`remove_orphans`).

    Raises
    ------
    OSError
        Naming ``path``, if it cannot be written, checked or put in place.
    """
    path = Path(path)
    remove_orphans(path.parent)
    try:
        fd, name = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.{os.getpid()}-", suffix=".tmp")
    except OSError as err:
        raise _named(err, path) from None
    os.close(fd)
    tmp = Path(name)
    try:
        yield tmp
        if check is not None:
            check(tmp)
        tmp.chmod(0o666 & ~_umask())  # mkstemp makes files private; outputs are ordinary files
        with open(tmp, "rb") as f:
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except OSError as err:
        tmp.unlink(missing_ok=True)
        raise _named(err, path) from None
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise


def write_atomic(path: str | Path, data: str | bytes) -> None:
    """Write ``data`` to ``path`` atomically (see :func:`atomic_path`), every byte checked.

    >>> import tempfile
    >>> target = Path(tempfile.mkdtemp()) / "plan.json"
    >>> write_atomic(target, '{"solved": true}'); target.read_text()
    '{"solved": true}'
    >>> write_atomic(target.parent / "missing" / "plan.json", "x")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    FileNotFoundError: [Errno 2] No such file or directory: '.../missing/plan.json'
    """
    raw = data.encode() if isinstance(data, str) else bytes(data)

    def complete(tmp: Path) -> None:
        if tmp.stat().st_size != len(raw):
            raise OSError(5, f"only {tmp.stat().st_size} of {len(raw)} bytes were written", str(tmp))

    with atomic_path(path, complete) as tmp:
        with open(tmp, "wb") as f:  # a full disk raises here, or when the file is closed
            f.write(raw)


@contextmanager
def staged_folder(folder: str | Path) -> Iterator[Path]:
    """Yield where to write the files of ``folder`` so that they appear together: a new folder is
    written as a temporary one beside it and renamed into place when the block succeeds (removed
    when it fails); an existing folder is written in place, each file atomically.

    >>> import tempfile
    >>> out = Path(tempfile.mkdtemp()) / "run"
    >>> with staged_folder(out) as stage:
    ...     _ = (stage / "plan.json").write_text("{}")
    ...     print(out.exists(), stage != out)
    False True
    >>> sorted(p.name for p in out.iterdir()), sorted(p.name for p in out.parent.iterdir())
    (['plan.json'], ['run'])
    """
    folder = Path(folder)
    if folder.is_dir():
        yield folder
        return
    folder.parent.mkdir(parents=True, exist_ok=True)
    remove_orphans(folder.parent)
    stage = Path(tempfile.mkdtemp(dir=folder.parent, prefix=f".{folder.name}.{os.getpid()}-", suffix=".tmp"))
    try:
        yield stage
        stage.chmod(0o777 & ~_umask())  # mkdtemp makes folders private; outputs are ordinary folders
        os.rename(stage, folder)
    except BaseException:
        shutil.rmtree(stage, ignore_errors=True)
        raise


def _umask() -> int:
    umask = os.umask(0)
    os.umask(umask)
    return umask
