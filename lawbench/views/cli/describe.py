"""``lawbench describe NAME``: a law's options and claims, or a case's parameters and truth."""

from __future__ import annotations

import argparse

from lawbench.core.case import CASES, Case
from lawbench.core.errors import InvalidProblem
from lawbench.core.law import LAWS, Law

# The command's name and the settings of its parser (`lawbench.views.cli.build_parser`).
COMMAND = ("describe", {"help": "describe a law or a case"})


def arguments(describe: argparse.ArgumentParser) -> None:
    """The arguments of the ``describe`` command."""
    describe.add_argument("name", help="a law or case name")
    describe.set_defaults(run=run)


def run(args: argparse.Namespace) -> None:
    """Describe the law or the case ``args.name``."""
    if args.name in LAWS:
        _describe_law(LAWS.get(args.name))
    elif args.name in CASES:
        _describe_case(CASES.get(args.name))
    else:
        known = ", ".join(LAWS.names() + CASES.names())
        raise InvalidProblem(f"unknown law or case {args.name!r}; known: {known}")


def _describe_law(law: Law) -> None:
    tags = law.tags
    print(f"law {law.name}: {law.summary}")
    print(f"source: {law.source}")
    print(
        f"tags: friction={tags.friction} several_contacts={tags.several_contacts} "
        f"spatial={tags.spatial} stiffness={tags.stiffness} "
        f"accuracy_knob={tags.accuracy_knob}"
    )
    print("options:" if law.options else "options: none")
    for spec in law.options:
        print(f"  {spec.name} = {spec.default!r}  ({spec.describe_range()}) {spec.doc}")
    for title, claims in (("findings", law.findings), ("guarantees", law.guarantees)):
        print(f"{title}:" if claims else f"{title}: none")
        for claim in claims:
            print(f"  {claim.check}: {claim.reason}")
            print(f"    where: {claim.region.text}; source: {claim.source}")


def _describe_case(case: Case) -> None:
    params = case.parameters()
    print(f"case {case.name}: {case.summary}")
    print(f"coordinates (defaults): {', '.join(case.coordinates(params))}")
    print("parameters:")
    for spec in case.params:
        unit = f" [{spec.unit}]" if spec.unit else ""
        print(f"  {spec.name} = {spec.default!r}{unit}  ({spec.describe_range()}) {spec.doc}")
    truth = case.ground_truth
    print(f"ground truth: {truth.describe()}: {truth.why}" if truth else "ground truth: none")
    print("references:" if case.references else "references: none")
    for ref in case.references:
        options = "".join(f" {k}={v}" for k, v in ref.options.items())
        print(f"  {ref.name} [{ref.law}{options}]: {ref.source}")
