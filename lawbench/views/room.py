"""Room in the address space for the numerical libraries, checked before they need it.

Under an address-space limit (``ulimit -v``) numpy's, scipy's and numba's native code fails
beyond Python's reach: OpenBLAS, unable to map its buffers, loops without end, exits, or raises
SIGINT (read by Python as the user's Ctrl-C); LLVM and glibc abort; a library that cannot be
mapped is an ImportError or an OSError. So the program reserves, and gives back, the address
space the start maps (`room_to_start`), and a command that solves what a solve maps
(`room_to_solve`). This module imports the standard library only: the program calls it before
numpy loads.
"""

from __future__ import annotations

import errno
import mmap
import os
import resource

# Address space the start maps beyond the interpreter's: a fixed part and, per BLAS thread, a
# buffer and a stack in each of numpy's and scipy's OpenBLAS builds (measured on Linux x86-64
# with numpy 2.4 and scipy 1.16: the peak of ``lawbench list`` is 148 MiB plus 80 MiB per
# thread, the interpreter's 14 MiB included). OpenBLAS starts a thread per core, at most
# MAX_THREADS (64 in both builds), or as many as OPENBLAS_NUM_THREADS or OMP_NUM_THREADS say.
START_BYTES = 135 << 20
BLAS_THREAD_BYTES = 80 << 20
BLAS_THREADS_MAX = 64
# Address space a command that solves maps beyond the start: numba's LLVM loading and compiling
# its kernels, clarabel, and again a buffer per BLAS thread as the first products run (measured
# as above: ``lawbench solve moreau sphere_wall`` needs 540 MiB in all with one BLAS thread and
# 640 MiB with two; below, LLVM aborts, llvmlite cannot be mapped, OpenBLAS exits or raises
# SIGINT, glibc aborts a thread's start, or the process hangs).
SOLVE_BYTES = 360 << 20


def blas_threads() -> int:
    """The threads OpenBLAS starts in this process (see `START_BYTES`)."""
    for name in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS"):
        value = os.environ.get(name, "").strip()
        if value.isdigit() and int(value) > 0:
            return min(int(value), BLAS_THREADS_MAX)
    return min(len(os.sched_getaffinity(0)), BLAS_THREADS_MAX)


def room_to_start() -> str:
    """Why the address space left is too small for the start, or '' when it is not."""
    need = START_BYTES + BLAS_THREAD_BYTES * blas_threads()
    return _room(need, "numpy and scipy map as they load")


def room_to_solve() -> str:
    """Why the address space left is too small for a command that solves, or '' (`SOLVE_BYTES`).

    Called once the command line has started: what the start mapped is already taken.
    """
    need = SOLVE_BYTES + BLAS_THREAD_BYTES * blas_threads()
    return _room(need, "a solve maps (numba's compiler, clarabel, BLAS buffers)")


def _room(need: int, what: str) -> str:
    """Why ``need`` bytes of address space cannot be mapped now (``what`` maps them), or ''.

    Without a limit there is nothing to check. With one, the address space is mapped (readable,
    never touched, so no memory is used) and unmapped at once.
    """
    limit = resource.getrlimit(resource.RLIMIT_AS)[0]
    if limit == resource.RLIM_INFINITY:
        return ""
    try:
        flags = mmap.MAP_PRIVATE | mmap.MAP_ANONYMOUS
        mmap.mmap(-1, need, flags=flags, prot=mmap.PROT_READ).close()
    except (OSError, MemoryError):
        return (
            f"the address-space limit (ulimit -v, {limit >> 20} MiB) leaves less than the "
            f"{need >> 20} MiB {what}"
        )
    return ""


def unmappable(exc: BaseException) -> bool:
    """Whether ``exc`` (or an error that caused it) is a library that memory could not hold."""
    while exc is not None:
        if isinstance(exc, MemoryError) or getattr(exc, "errno", None) == errno.ENOMEM:
            return True
        text = str(exc).lower()
        if "failed to map segment" in text or "cannot allocate memory" in text:
            return True
        exc = exc.__cause__ or exc.__context__
    return False
