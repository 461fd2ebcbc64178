"""On one frictionless contact every law is Newton's binary impact.

For a single frictionless contact that approaches, the kinematic (Newton), kinetic (Poisson)
and energetic (Stronge) coefficients coincide (Brogliato 2010, 'Newton, Poisson, energetic
coefficients': they differ only with friction or several contacts), so with equal e every law
gives ``un+ = -e un-``; the compliant and energetic laws reach it with their own models
(Kelvin-Voigt damping from e, Stronge's coefficient per contact). At e = 0 a compliant contact
is plastic: its spring loads it and lets go where the indentation stops growing.
"""

import numpy as np
import pytest

import lawbench
from lawbench import Contact, ImpactProblem

TOLERANCE = {"compliant": 1e-6, "lzb": 1e-7, "jia": 1e-7, "darboux_keller": 1e-9}


@pytest.mark.parametrize("e", [0.0, 0.4, 1.0])
@pytest.mark.parametrize("law", lawbench.LAWS.names())
def test_every_law_agrees_on_one_frictionless_contact(law, e):
    problem = ImpactProblem(
        M=np.diag([2.0, 0.5]),
        Wn=[[-1.0], [1.0]],
        v=[1.0, -0.5],
        contacts=[Contact(e=e, stiffness=1e6, exponent=1.0)],
    )
    if reason := lawbench.LAWS.get(law).refusal(problem):
        pytest.skip(f"refused: {reason}")  # an engine builds only a scene with its geometry
    options = {"model": "kelvin_voigt", "termination": "gap"} if law == "compliant" else {}
    outcome = lawbench.LAWS.get(law).resolve(problem, **options)
    newton = lawbench.LAWS.get("newton").resolve(problem)
    np.testing.assert_allclose(outcome.v_plus, newton.v_plus, atol=TOLERANCE.get(law, 1e-12))
