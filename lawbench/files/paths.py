"""The paths a user names: what may be read, and what may be written over.

An input must be a regular file of bounded size: opening a FIFO blocks until something writes
to it (for ever, from a shell), a device or ``/dev/zero`` never ends, and a directory is not a
problem. An output must be a regular file or not exist yet: writing into a FIFO blocks, and
writing over a device or a directory is never what was meant. Both are decided from the path's
status, which never blocks, before anything is opened.

Every file is written whole or not at all (`replaced`): into a temporary file beside it, created
before the work so that a folder that cannot be written is known at once, then moved over the
path with `os.replace`. A symbolic link is written through: the file it names is replaced, the
link kept. A full disk is a `SolverFailure` (the work failed for want of room), a path that
cannot be written an `InvalidProblem`; either names the path, and no file is left half written.
"""

from __future__ import annotations

import errno
import os
import stat
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from lawbench.core.errors import InvalidProblem, LawbenchError, SolverFailure

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


def writable_folder(path: str | Path, what: str = "output folder") -> Path:
    """``path`` as `output_folder` accepts it, made, once a file could be created in it.

    Raises
    ------
    InvalidProblem, SolverFailure
        As `output_folder`, and as `write_error` for a folder that cannot be made or written.
    """
    path = output_folder(path, what)
    try:
        path.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=path):
            pass
    except OSError as exc:
        raise write_error(exc, what, path) from None
    return path


# The errors of a write that ran out of room rather than of permission.
NO_ROOM = (errno.ENOSPC, errno.EDQUOT, errno.EFBIG)


def write_error(exc: OSError, what: str, path: str | Path) -> LawbenchError:
    """The error to raise for ``exc``, met writing ``what`` at ``path``, in one line.

    Out of room (`NO_ROOM`: a full disk, a quota, a file too large) is a `SolverFailure`; any
    other (a read-only file system, a permission, a path that is no folder) an `InvalidProblem`.
    """
    reason = exc.strerror or str(exc)
    if exc.errno in NO_ROOM:
        return SolverFailure(f"{what} {path}: cannot be written ({reason}); nothing was replaced")
    return InvalidProblem(f"{what} {path}: cannot be written ({reason})")


@contextmanager
def replaced(path: str | Path, what: str = "output") -> Iterator[Path]:
    """A temporary file beside ``path`` to write, moved over ``path`` when the block ends.

    The temporary file is created on entry, before any work of the block. A symbolic link
    ``path`` is written through (the file it names is replaced). When the block raises, the
    temporary file is removed and ``path`` is left as it was.

    Raises
    ------
    InvalidProblem, SolverFailure
        As `write_error`, for an ``OSError`` of the folder, of the block's writes or of the
        move; ``InvalidProblem`` as `output_file` for a ``path`` that is not a regular file.
    """
    target = Path(os.path.realpath(output_file(path, what)))
    temporary = target.with_name(f".{target.name}.{os.getpid()}.tmp")
    try:
        temporary.parent.mkdir(parents=True, exist_ok=True)
        os.close(os.open(temporary, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666))
    except OSError as exc:
        raise write_error(exc, what, path) from None
    try:
        yield temporary
        os.replace(temporary, target)
    except OSError as exc:
        temporary.unlink(missing_ok=True)
        raise write_error(exc, what, path) from None
    except BaseException:
        temporary.unlink(missing_ok=True)
        raise
