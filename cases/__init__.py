"""The scenes: one module per case, each registering itself in `CASES`.

A scene module holds its coordinates, parameters, references, ground truth and the studies it
declares. It may import `lawbench.core`, `lawbench.numerics` and `lawbench.checks`, and other
scenes, never a law (it names laws only as strings), the study engine or a view.
"""
