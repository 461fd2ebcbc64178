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


class UnknownName(InvalidProblem, KeyError):
    """A name that no registry (laws, cases, studies) knows; the message lists the known ones.

    Both an `InvalidProblem` (bad input) and a `KeyError` (a registry is a mapping).
    """

    # KeyError quotes its message; the message is a sentence.
    __str__ = Exception.__str__


class NotApplicable(LawbenchError):
    """A law cannot treat this problem (for example friction given to a frictionless law)."""


class SolverFailure(LawbenchError):
    """A numerical method failed; the message gives the solver's status or the count reached."""


class LossyExport(UserWarning):
    """A file format cannot hold part of a problem; the message names what is left out."""


class BudgetExceeded(SolverFailure):
    """A numerical method ran out of a named budget before it finished.

    Parameters
    ----------
    message : str
        What ran out, in words.
    budget : str
        The option that sets the budget (``max_steps``, ``max_seconds``, ...).
    amount : float
        The budget's value.
    spent_s : float or None
        Wall time spent when the budget ran out, when known.
    """

    def __init__(
        self, message: str, budget: str, amount: float, spent_s: float | None = None
    ) -> None:
        super().__init__(message)
        self.budget, self.amount, self.spent_s = budget, amount, spent_s

    def __reduce__(self) -> tuple:
        return (type(self), (str(self), self.budget, self.amount, self.spent_s))
