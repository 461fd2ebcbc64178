"""The scenes: one module per case, each registering itself in `lawbench.case.CASES`."""
