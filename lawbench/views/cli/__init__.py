"""The ``lawbench`` command line.

Exit codes: 0 done; 2 bad usage or invalid input; 3 the law does not apply; 4 solver failure;
5 a regression drifted past its baseline; 6 a law fails the common checks (``lawbench check``);
1 an unexpected internal error. Errors are one line
on stderr, never a traceback.
"""

from lawbench.views.cli.main import build_parser, main
from lawbench.views.program import program

__all__ = ["build_parser", "main", "program"]
