"""The ``lawbench`` program: room for the numerical libraries first, then the command line.

This module imports the standard library only, and the package's ``__init__`` loads nothing, so
that what fails while numpy, scipy and lawbench's modules load is still said in one line.
Under an address-space limit (``ulimit -v``) their start can fail in native code, beyond
Python's reach: OpenBLAS, unable to map its buffers, loops without end, exits, or raises SIGINT
(read by Python as the user's Ctrl-C), and a library that cannot be mapped is an ImportError
with a traceback. So `program` first reserves, and gives back, the address space those
libraries map as they load (`lawbench.views.room`); where the limit leaves less, or a
MemoryError or an unmappable library still stops the start, it says so in one line with a
solver failure's exit code, 4: the work needs more memory than it was given. A command
that is over ends its process, even where a law left a thread running.
"""

from __future__ import annotations

import os
import sys
import threading

from lawbench.views.room import room_to_start, unmappable

# The exit code of a solver failure, which running out of memory is (`lawbench.views.cli`).
OUT_OF_MEMORY = 4
# Exit code of an internal error: a library that cannot be imported for another reason.
INTERNAL = 1


def program() -> int:
    """Run ``lawbench`` on this process's arguments, owning the process; return the exit code."""
    short = room_to_start()
    if short:
        return _refuse(f"lawbench: out of memory: {short}", OUT_OF_MEMORY)
    try:
        from lawbench.views.cli.main import main
    except MemoryError:
        return _refuse("lawbench: out of memory while starting (MemoryError)", OUT_OF_MEMORY)
    except (ImportError, OSError) as exc:
        if unmappable(exc):
            return _refuse(f"lawbench: out of memory while starting ({_cause(exc)})", OUT_OF_MEMORY)
        return _refuse(f"lawbench: internal error: cannot start: {_cause(exc)}", INTERNAL)
    code = main(own_process=True)
    if _left_running():
        # A plugin left a thread running: the command is over, and so is its process.
        for stream in (sys.stdout, sys.stderr):
            try:
                if stream is not None:
                    stream.flush()
            except (OSError, ValueError):
                pass
        os._exit(code)
    return code


def _left_running() -> bool:
    """Whether a thread that the interpreter would wait for at its exit is still running."""
    return any(
        thread is not threading.main_thread() and not thread.daemon and thread.is_alive()
        for thread in threading.enumerate()
    )


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
