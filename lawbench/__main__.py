"""``python -m lawbench``: the same as the ``lawbench`` command."""

import sys

from lawbench.cli import main

sys.exit(main())
