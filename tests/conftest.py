"""What several test modules share: the small report the report's tests read.

The suite runs on one worker per core (``pytest --numprocesses=auto``): each test file goes
whole to one worker, so that its module fixtures are built once, and the files that read the
small report go together to one worker, which builds it once.
"""

import dataclasses
from pathlib import Path

import pytest

from lawbench.views.report import QUICK, write_report

# The test files that read the session's small report.
READ_THE_SMALL_REPORT = ("test_report", "test_report_answer")

CLOSED_FORM = ("newton", "poisson", "sequential", "moreau")

# The closed-form laws and two single-contact laws on the scenes every section needs; the section
# against measurements has its own tests (test_report_measured.py) and draws Kharaz's curves here.
SMALL = dataclasses.replace(
    QUICK,
    measurements=(),
    laws=(*CLOSED_FORM, "brach", "darboux_keller"),
    cases=(
        "three_ball_chain",
        "two_balls_wall",
        "ball_chain",
        "falling_rod",
        "double_pendulum",
        "lamina",
    ),
)


@pytest.fixture(scope="session")
def report(tmp_path_factory):
    return write_report(tmp_path_factory.mktemp("report") / "small", config=SMALL)


def pytest_xdist_make_scheduler(config: pytest.Config, log: object) -> object:
    """Give each worker whole test files, and the small report's readers all to one worker."""
    from xdist.scheduler import LoadFileScheduling

    class ByFile(LoadFileScheduling):
        def _split_scope(self, nodeid: str) -> str:
            path = super()._split_scope(nodeid)
            return "small report" if Path(path).stem in READ_THE_SMALL_REPORT else path

    return ByFile(config, log)
