"""The packages of the distribution, found by setuptools' discovery.

``lawbench`` and its subpackages are found where they are; ``laws/`` and ``cases/`` install as
``lawbench.laws`` and ``lawbench.cases`` (``package-dir`` in pyproject.toml), with their own
subpackages found under them. Everything else is in pyproject.toml.
"""

from setuptools import find_packages, setup


def packages_in(folder: str, prefix: str) -> list[str]:
    """The package ``prefix`` installed from ``folder``, and every package found below it."""
    return [prefix, *(f"{prefix}.{name}" for name in find_packages(folder))]


setup(
    packages=[
        *find_packages(include=["lawbench", "lawbench.*"]),
        *packages_in("laws", "lawbench.laws"),
        *packages_in("cases", "lawbench.cases"),
    ]
)
