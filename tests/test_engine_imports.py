"""An engine's first import is done whole, whatever bound rings during it."""

import subprocess
import sys

import pytest

pytest.importorskip("pydrake")

# A fresh interpreter: Drake's first solve imports pydrake (about a second) inside a bound of
# 50 ms, which rings during the import; the next solve must find Drake whole.
SCRIPT = """
import lawbench
from lawbench.core.errors import BudgetExceeded
from lawbench.core.guards import alarm

problem = lawbench.CASES.get("three_ball_chain").build()
drake = lawbench.LAWS.get("drake")
try:
    with alarm(0.05):
        drake.resolve(problem)
except BudgetExceeded:
    print("stopped")
print(drake.resolve(problem).status)
"""


def test_a_bound_that_rings_during_drake_s_first_import_leaves_it_whole():
    """pydrake's bindings stopped half-way through their import fail every later import of the
    process ("ImportError: ... already registered"): the quick report's workers lost their Drake
    cells to it when their first cell's bound rang during the import."""
    run = subprocess.run(
        [sys.executable, "-c", SCRIPT], capture_output=True, text=True, timeout=120
    )
    assert run.returncode == 0, run.stderr[-2000:]
    assert run.stdout.split() == ["stopped", "ok"]
