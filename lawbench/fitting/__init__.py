"""Fitting: a law's coefficients identified from measured pre- and post-impact velocities.

Owns the reading of measured trials (`lawbench.fitting.trials`), the free coefficients and
their scales, the least squares, the uncertainty of what it finds and `FitResult`; `fit` is
the way in. It also holds the measured study (`lawbench.fitting.measured`: every law fitted on
a measured set's training impacts and judged on its test impacts, beside the baselines of
`lawbench.fitting.heldout`) and Kharaz's oblique-impact curves
(`lawbench.fitting.kharaz_curves`). May import the core, numerics, files, checks, the laws and
cases (through their registries), the measured impacts and the study engine; never a view,
never the bench.
"""

from lawbench.fitting.identify import fit
from lawbench.fitting.result import FitResult

__all__ = ["FitResult", "fit"]
