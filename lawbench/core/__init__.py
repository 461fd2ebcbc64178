"""The core: what every other part of lawbench speaks.

Owns the impact problem and its algebra at a frozen configuration (`ImpactProblem`, batches,
kinetic energy, velocities after impulses), the `Outcome` every law returns, Coulomb's
frictional contact problem in contact space with its solution (`ContactProblem`,
`ContactSolution`: FCLIB's local form, which has no generalized coordinates), the law and case
protocols with their registries, option specifications and capability tags, the solve's
budget, the errors, the verdict taxonomy with claims and regions, the named transforms of a
built problem (grazing speed, a duplicated contact), and the `Trial` with the entry points
that make one (`solve`, `evaluate`, `solve_batch`). Imports nothing else of
lawbench: every other layer may import it.
"""
