"""Reading a file the user names (a scene, a plan, a batch's results): only a regular file, only
so many bytes, only UTF-8 text, each refusal one :class:`~planner.model.fields.SceneError`.

The file is opened without blocking and checked before a byte is read: a named pipe, a device or
a folder would otherwise block the run for ever or feed it without end.

>>> import os, tempfile
>>> folder = tempfile.mkdtemp()
>>> os.mkfifo(f"{folder}/pipe")
>>> read_text(f"{folder}/pipe", "scene", 100)  # doctest: +ELLIPSIS
Traceback (most recent call last):
...
planner.model.fields.SceneError: scene: '.../pipe' is not a regular file (a named pipe)
"""

from __future__ import annotations

import os
import stat
from pathlib import Path

from .fields import SceneError, shown

__all__ = ["read_bytes", "read_text"]

_KINDS = ((stat.S_ISDIR, "a folder"), (stat.S_ISFIFO, "a named pipe"), (stat.S_ISCHR, "a character device"),
          (stat.S_ISBLK, "a block device"), (stat.S_ISSOCK, "a socket"))


def read_text(path: str | Path, name: str, max_bytes: int) -> str:
    """The text of the regular file ``path``, at most ``max_bytes`` bytes of UTF-8.

    Raises
    ------
    SceneError
        Naming ``name``: the file cannot be opened, is not a regular file, is larger than
        ``max_bytes`` or is not UTF-8.
    """
    raw = read_bytes(path, name, max_bytes)
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError as err:
        raise SceneError(name, f"{shown(str(path))} is not UTF-8 text (bad byte at offset {err.start})") from None


def read_bytes(path: str | Path, name: str, max_bytes: int) -> bytes:
    """The bytes of the regular file ``path``, at most ``max_bytes`` of them (no more is read: a
    huge file is refused unread); else a :class:`SceneError` naming ``name``."""
    shown_path = shown(str(path))
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    except (OSError, ValueError) as err:  # ValueError: a NUL in the path
        raise SceneError(name, f"cannot read {shown_path}: {getattr(err, 'strerror', None) or err}") from None
    mode = os.fstat(fd).st_mode
    if not stat.S_ISREG(mode):
        os.close(fd)
        kind = next((what for test, what in _KINDS if test(mode)), "not a file")
        raise SceneError(name, f"{shown_path} is not a regular file ({kind})")
    with os.fdopen(fd, "rb") as f:
        try:
            raw = f.read(max_bytes + 1)  # no more: a huge file is refused unread
        except OSError as err:
            raise SceneError(name, f"cannot read {shown_path}: {err.strerror or err}") from None
    if len(raw) > max_bytes:
        raise SceneError(name, f"{shown_path} is larger than {max_bytes} bytes")
    return raw
