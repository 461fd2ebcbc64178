"""Tags: what a law can treat and what a scene requires, in one type.

A law's tags say which features of a problem it treats (friction, several contacts, spatial
contacts), whether it reads contact stiffness, and which option is its accuracy knob. A scene's
tags say which of those features its problems have. A law can be given a scene when its tags
cover the scene's (`Tags.missing` is empty), and a problem when `Law.refusal` finds no reason
in the problem (`lawbench.core.law`).
"""

from __future__ import annotations

from dataclasses import dataclass

# The features a scene can require and a law can treat, with their words for messages.
FEATURES = {
    "friction": "friction",
    "several_contacts": "several contacts",
    "spatial": "spatial contacts",
}


@dataclass(frozen=True)
class Tags:
    """Features of a law (what it treats) or of a scene (what it requires).

    Attributes
    ----------
    friction : bool
        Coulomb friction: a tangential Jacobian and mu > 0.
    several_contacts : bool
        More than one contact in one impact.
    spatial : bool
        Spatial contacts (two tangential directions).
    stiffness : bool
        A law reads the contacts' stiffness and exponent; a scene's outcome depends on them.
    accuracy_knob : str or None
        For a law, the option that trades accuracy for cost; None for exact laws.
    finest_knob : float or None
        For a law whose accuracy knob is a time step, whose work grows as the step shrinks
        with no bound of its own: the finest step a sweep gives it and the one its own
        converged answer is taken at (`lawbench.checks.knobs.tightest`). None: the knob's
        spec bounds it.
    """

    friction: bool = False
    several_contacts: bool = False
    spatial: bool = False
    stiffness: bool = False
    accuracy_knob: str | None = None
    finest_knob: float | None = None

    def missing(self, required: Tags) -> list[str]:
        """The features ``required`` has and these tags do not treat, in words."""
        return [
            word
            for name, word in FEATURES.items()
            if getattr(required, name) and not getattr(self, name)
        ]

    def covers(self, required: Tags) -> bool:
        """Whether a law with these tags treats every feature ``required`` names."""
        return not self.missing(required)
