"""The paths a user names: what may be read, and what may be written over.

An input must be a regular file of bounded size: opening a FIFO blocks until something writes
to it (for ever, from a shell), a device or ``/dev/zero`` never ends, and a directory is not a
problem. An output must be a regular file or not exist yet: writing into a FIFO blocks, and
writing over a device or a directory is never what was meant. Both are decided from the path's
status, which never blocks, before anything is opened.
"""

from __future__ import annotations

import os
import stat
from pathlib import Path

from lawbench.core.errors import InvalidProblem

# The largest input file read (bytes): the largest FCLIB problems of the field are a few MB.
MAX_BYTES = 1 << 30
KINDS = {
    stat.S_ISDIR: "a directory",
    stat.S_ISFIFO: "a FIFO",
    stat.S_ISCHR: "a character device",
    stat.S_ISBLK: "a block device",
    stat.S_ISSOCK: "a socket",
}


def _kind(mode: int) -> str:
    return next((name for test, name in KINDS.items() if test(mode)), "not a regular file")


def _path(path: object, what: str) -> Path:
    if not isinstance(path, str | os.PathLike):
        raise TypeError(f"{what}: a path (str or os.PathLike), not {type(path).__name__}")
    if "\x00" in os.fspath(path):
        raise InvalidProblem(f"{what} {os.fspath(path)!r}: a path cannot hold a NUL character")
    return Path(path)


def input_file(path: str | Path, what: str = "file") -> Path:
    """``path`` as a `Path` once it is known to be a readable regular file of bounded size.

    Raises
    ------
    InvalidProblem
        Naming ``what`` and the path: missing, not a regular file, or larger than `MAX_BYTES`.
    TypeError
        For a ``path`` that is not a path.
    """
    path = _path(path, what)
    try:
        info = path.stat()
    except OSError as exc:
        raise InvalidProblem(f"{what} {path}: cannot be read ({exc.strerror or exc})") from None
    if not stat.S_ISREG(info.st_mode):
        raise InvalidProblem(f"{what} {path}: {_kind(info.st_mode)}, not a regular file")
    if info.st_size > MAX_BYTES:
        raise InvalidProblem(
            f"{what} {path}: {info.st_size} bytes, more than the {MAX_BYTES} read at most"
        )
    return path


def output_file(path: str | Path, what: str = "output") -> Path:
    """``path`` as a `Path` once it is known to be a regular file or a new one.

    Raises
    ------
    InvalidProblem
        Naming ``what`` and the path, for an existing path that is not a regular file.
    TypeError
        For a ``path`` that is not a path.
    """
    path = _path(path, what)
    try:
        mode = path.stat().st_mode
    except FileNotFoundError:
        return path
    except OSError as exc:
        raise InvalidProblem(f"{what} {path}: cannot be written ({exc.strerror or exc})") from None
    if not stat.S_ISREG(mode):
        raise InvalidProblem(f"{what} {path}: {_kind(mode)}, not a regular file")
    return path


def output_folder(path: str | Path, what: str = "output folder") -> Path:
    """``path`` as a `Path` once it is known to be a directory or one that can be made.

    Raises
    ------
    InvalidProblem
        Naming ``what`` and the path, for an existing path that is not a directory, or one
        below a path that is not.
    TypeError
        For a ``path`` that is not a path.
    """
    path = _path(path, what)
    for ancestor in (path, *path.parents):
        try:
            mode = ancestor.stat().st_mode
        except FileNotFoundError:
            continue
        except OSError as exc:
            raise InvalidProblem(
                f"{what} {path}: cannot be written ({exc.strerror or exc})"
            ) from None
        if not stat.S_ISDIR(mode):
            kind = "a regular file" if stat.S_ISREG(mode) else _kind(mode)
            where = "" if ancestor == path else f"{ancestor} is "
            raise InvalidProblem(f"{what} {path}: {where}{kind}, not a directory")
        return path
    return path
