"""The ``lawbench`` program: room for the numerical libraries first, then the command line.

This module imports the standard library only, and the package's ``__init__`` loads nothing, so
that what fails while numpy, scipy and lawbench's modules load is still said in one line.
Under an address-space limit (``ulimit -v``) their start can fail in native code, beyond
Python's reach: OpenBLAS, unable to map its buffers, loops without end, exits, or raises SIGINT
(read by Python as the user's Ctrl-C), and a library that cannot be mapped is an ImportError
with a traceback. So `program` first reserves, and gives back, the address space those
libraries map as they load; where the limit leaves less, or a MemoryError or an unmappable
library still stops the start, it says so in one line with a solver failure's exit code, 4:
the work needs more memory than it was given.
"""

from __future__ import annotations

import errno
import mmap
import os
import resource
import sys

# Address space the start maps beyond the interpreter's: a fixed part and, per BLAS thread, a
# buffer and a stack in each of numpy's and scipy's OpenBLAS builds (measured on Linux x86-64
# with numpy 2.4 and scipy 1.16: the peak of ``lawbench list`` is 148 MiB plus 80 MiB per
# thread, the interpreter's 14 MiB included). OpenBLAS starts a thread per core, at most
# MAX_THREADS (64 in both builds), or as many as OPENBLAS_NUM_THREADS or OMP_NUM_THREADS say.
START_BYTES = 135 << 20
BLAS_THREAD_BYTES = 80 << 20
BLAS_THREADS_MAX = 64
# The exit code of a solver failure, which running out of memory is (`lawbench.views.cli`).
OUT_OF_MEMORY = 4
# Exit code of an internal error: a library that cannot be imported for another reason.
INTERNAL = 1


def program() -> int:
    """Run ``lawbench`` on this process's arguments, owning the process; return the exit code."""
    short = _room_to_start()
    if short:
        return _refuse(f"lawbench: out of memory: {short}", OUT_OF_MEMORY)
    try:
        from lawbench.views.cli.main import main
    except MemoryError:
        return _refuse("lawbench: out of memory while starting (MemoryError)", OUT_OF_MEMORY)
    except (ImportError, OSError) as exc:
        if _unmappable(exc):
            return _refuse(f"lawbench: out of memory while starting ({_cause(exc)})", OUT_OF_MEMORY)
        return _refuse(f"lawbench: internal error: cannot start: {_cause(exc)}", INTERNAL)
    return main(own_process=True)


def blas_threads() -> int:
    """The threads OpenBLAS starts in this process (see `START_BYTES`)."""
    for name in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS"):
        value = os.environ.get(name, "").strip()
        if value.isdigit() and int(value) > 0:
            return min(int(value), BLAS_THREADS_MAX)
    return min(len(os.sched_getaffinity(0)), BLAS_THREADS_MAX)


def _room_to_start() -> str:
    """Why the address space left is too small for the start, or '' when it is not.

    Without a limit there is nothing to check. With one, the start's address space is mapped
    (readable, never touched, so no memory is used) and unmapped at once.
    """
    limit = resource.getrlimit(resource.RLIMIT_AS)[0]
    if limit == resource.RLIM_INFINITY:
        return ""
    need = START_BYTES + BLAS_THREAD_BYTES * blas_threads()
    try:
        flags = mmap.MAP_PRIVATE | mmap.MAP_ANONYMOUS
        mmap.mmap(-1, need, flags=flags, prot=mmap.PROT_READ).close()
    except (OSError, MemoryError):
        return (
            f"the address-space limit (ulimit -v, {limit >> 20} MiB) leaves less than the "
            f"{need >> 20} MiB numpy and scipy map as they load"
        )
    return ""


def _unmappable(exc: BaseException) -> bool:
    """Whether ``exc`` (or an error that caused it) is a library that memory could not hold."""
    while exc is not None:
        if isinstance(exc, MemoryError) or getattr(exc, "errno", None) == errno.ENOMEM:
            return True
        text = str(exc).lower()
        if "failed to map segment" in text or "cannot allocate memory" in text:
            return True
        exc = exc.__cause__ or exc.__context__
    return False


def _cause(exc: BaseException) -> str:
    """The first line that says what ``exc`` is (numpy's ImportError is a page of advice)."""
    root = exc
    while root.__cause__ is not None:
        root = root.__cause__
    lines = [line.strip() for line in str(root).splitlines() if line.strip()]
    return f"{type(root).__name__}: {lines[0] if lines else ''}".rstrip(": ")


def _refuse(line: str, code: int) -> int:
    """Write ``line`` on standard error, unless it is closed; return ``code``."""
    if sys.stderr is not None:
        try:
            print(line, file=sys.stderr, flush=True)
        except OSError:
            pass
    return code
