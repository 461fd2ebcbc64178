"""Views: what a person reads: the command line, the comparison report and the figures.

Owns `lawbench.views.cli` (with a solve's JSON record), the report (`lawbench.views.report`)
and the plotting functions that take an outcome or a run table. May import every other layer;
nothing imports a view.
"""
