"""``python -m lawbench``: the same as the ``lawbench`` command."""

import sys

from lawbench.views.program import program

sys.exit(program())
