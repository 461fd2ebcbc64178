"""What several test modules share: the small report the report's tests read."""

import dataclasses

import pytest

from lawbench.views.report import QUICK, write_report

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
