"""Views: what a person reads: the command line, the comparison report and the figures.

Owns `lawbench.views.cli`, the report (`lawbench.views.report`), the plotting functions that
take an outcome or a run table, and the JSON form of a trial. May import every other layer;
nothing imports a view.
"""
