"""The impact laws: one module (or package) per law, each registering itself in `LAWS`.

A law module holds its law and the dynamics only it uses. It may import `lawbench.core`,
`lawbench.numerics` and `lawbench.checks` (its claims, regions and declared studies), never a
scene, the study engine or a view. Findings that several laws share are in `_claims`.
"""
