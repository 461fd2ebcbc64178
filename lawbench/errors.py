"""Errors raised by lawbench.

Every failure a user can meet is one of three kinds, each with a message that names what went
wrong: bad input (`InvalidProblem`), a law that cannot treat a problem (`NotApplicable`), and a
numerical failure (`SolverFailure`). The command line maps them to exit codes 2, 3 and 4.
"""


class LawbenchError(Exception):
    """Base class of every error lawbench raises on purpose."""


class InvalidProblem(LawbenchError, ValueError):
    """A field of a problem, a case parameter or a law option has a bad value.

    The message names the field and the value.
    """


class NotApplicable(LawbenchError):
    """A law cannot treat this problem (for example friction given to a frictionless law)."""


class SolverFailure(LawbenchError):
    """A numerical method failed; the message gives the solver's status or the count reached."""
