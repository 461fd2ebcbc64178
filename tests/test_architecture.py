"""The import contract: lawbench's layers import one way, and no module imports itself back.

The layers, lowest first, are those the subpackages' docstrings state: a module may import
its own layer and those below it, never above and never a sibling of its layer. Every import
statement counts, at module level, inside a function or under ``TYPE_CHECKING``: a circle
closed by a lazy import is a circle all the same. Nothing in the package imports ``lawbench``
itself, which only gathers the public names.

import-linter checks contracts of this kind, but it builds its graph by walking the package's
folder, so it does not see ``laws/`` and ``cases/``, which install as ``lawbench.laws`` and
``lawbench.cases`` from folders of their own: the layer in the middle. The graph here is read
from the three folders with `ast`, as they install.
"""

import ast
import shutil
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
# Where each package's sources are, as it installs (pyproject's package-dir).
SOURCES = {"lawbench": "lawbench", "lawbench.laws": "laws", "lawbench.cases": "cases"}
# Lowest first; the packages of one layer are siblings that never import each other. The
# scenes and laws declare their studies as data; the study engine above them builds and runs
# them; the bench and the fits use the engine; the views show it all. A layer's package not
# (yet) in the tree is skipped: ``lawbench.bench`` and ``lawbench.fitting`` grow out of
# ``lawbench.studies.bench`` and ``lawbench.studies.fitting``.
LAYERS = (
    ("lawbench.core",),
    ("lawbench.numerics", "lawbench.files"),
    ("lawbench.checks",),
    ("lawbench.laws", "lawbench.cases", "lawbench.measurements"),
    ("lawbench.studies",),
    ("lawbench.bench", "lawbench.fitting"),
    ("lawbench.views",),
)
# Outside the layers: the public names, and ``python -m lawbench``.
FRONT = ("lawbench", "lawbench.__main__")
MAX_LEVELS = 9


def module_files(root: Path) -> dict[str, Path]:
    """Dotted module name -> source file, for every module of the three folders."""
    modules = {}
    for package, folder in SOURCES.items():
        for path in sorted((root / folder).rglob("*.py")):
            parts = list(path.relative_to(root / folder).with_suffix("").parts)
            if parts[-1] == "__init__":
                parts.pop()
            name = ".".join([package, *parts])
            if package == "lawbench" and name.startswith(("lawbench.laws", "lawbench.cases")):
                continue
            modules[name] = path
    return modules


def imports(name: str, path: Path, modules: dict[str, Path]) -> set[str]:
    """The lawbench modules that ``name`` imports anywhere in its source."""
    found = set()
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            targets = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = package.split(".")[: len(package.split(".")) - node.level + 1]
                base = ".".join([*anchor, *([base] if base else [])])
            # A name that is a submodule is that module; any other name is the package's own.
            targets = [
                f"{base}.{alias.name}" if f"{base}.{alias.name}" in modules else base
                for alias in node.names
            ]
        else:
            continue
        for target in targets:
            while target and target not in modules:
                target = target.rpartition(".")[0]
            if target and target != name:
                found.add(target)
    return found


def graph(root: Path = ROOT) -> dict[str, set[str]]:
    """Module -> the modules it imports."""
    modules = module_files(root)
    return {name: imports(name, path, modules) for name, path in modules.items()}


def layer_of(module: str) -> tuple[int, str] | None:
    """The layer's index and the package of ``module``; None for the front modules."""
    for index, packages in enumerate(LAYERS):
        for package in packages:
            if module == package or module.startswith(package + "."):
                return index, package
    return None


def upward_imports(edges: dict[str, set[str]]) -> list[str]:
    """Every import against the layers, as 'importer -> imported (why)'."""
    found = []
    for importer, targets in sorted(edges.items()):
        mine = layer_of(importer)
        for target in sorted(targets):
            if target == "lawbench" and importer != "lawbench.__main__":
                found.append(f"{importer} -> lawbench (the public names import the package)")
                continue
            theirs = layer_of(target)
            if mine is None or theirs is None:
                continue
            if theirs[0] > mine[0]:
                found.append(f"{importer} -> {target} (a higher layer)")
            elif theirs[0] == mine[0] and theirs[1] != mine[1]:
                found.append(f"{importer} -> {target} (a sibling layer)")
    return found


def circles(edges: dict[str, set[str]]) -> list[list[str]]:
    """The import circles: strongly connected components of more than one module (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    found = []

    def visit(module: str) -> None:
        index[module] = low[module] = len(index)
        stack.append(module)
        for target in sorted(edges.get(module, ())):
            if target not in index:
                visit(target)
                low[module] = min(low[module], low[target])
            elif target in stack:
                low[module] = min(low[module], index[target])
        if low[module] == index[module]:
            component = []
            while True:
                top = stack.pop()
                component.append(top)
                if top == module:
                    break
            if len(component) > 1:
                found.append(sorted(component))

    for module in sorted(edges):
        if module not in index:
            visit(module)
    return found


def levels(edges: dict[str, set[str]], depth: int) -> int:
    """The number of import levels between packages at ``depth`` dots below ``lawbench``.

    A package's level is one more than the highest level of what it imports (1 for one that
    imports nothing): each folder of ``lawbench/`` (and ``laws/``, ``cases/``) is one room.
    """

    def room(module: str) -> str:
        return ".".join(module.split(".")[: depth + 1])

    rooms: dict[str, set[str]] = {}
    for importer, targets in edges.items():
        rooms.setdefault(room(importer), set()).update(
            room(t) for t in targets if room(t) != room(importer)
        )
    level: dict[str, int] = {}

    def of(name: str) -> int:
        if name not in level:
            level[name] = 0  # a circle would count once; `circles` fails on it
            level[name] = 1 + max((of(t) for t in rooms.get(name, ())), default=0)
        return level[name]

    return max(of(name) for name in rooms)


def test_every_module_belongs_to_a_layer_or_the_front():
    stray = [m for m in graph() if layer_of(m) is None and m not in FRONT]
    assert not stray, f"modules in no layer: {stray}"


def test_imports_run_one_way_down_the_layers():
    assert upward_imports(graph()) == []


def test_no_import_circle_lazy_imports_included():
    assert circles(graph()) == []


def test_the_layers_are_at_most_nine_levels_deep():
    assert levels(graph(), depth=1) <= MAX_LEVELS


def test_at_most_twelve_modules_at_the_top_of_lawbench():
    top = [
        p
        for p in (ROOT / "lawbench").iterdir()
        if p.suffix == ".py" or (p / "__init__.py").exists()
    ]
    assert len(top) <= 12, sorted(p.name for p in top)


def test_every_subpackage_says_what_it_owns_and_may_import():
    modules = module_files(ROOT)
    for package in (p for layer in LAYERS for p in layer if p in modules):
        path = modules[package]
        doc = ast.get_docstring(ast.parse(path.read_text(encoding="utf-8"))) or ""
        assert "import" in doc, f"{package}: its docstring does not say what it may import"


@pytest.fixture
def planted(tmp_path):
    """A copy of the three source folders, to plant a bad import in."""
    for folder in SOURCES.values():
        shutil.copytree(ROOT / folder, tmp_path / folder, ignore=shutil.ignore_patterns("*.pyc"))
    return tmp_path


def plant(root: Path, relative: str, line: str) -> None:
    """Append a function that imports lazily to the file ``relative`` under ``root``."""
    path = root / relative
    path.write_text(path.read_text(encoding="utf-8") + f"\n\ndef _planted():\n    {line}\n")


def test_a_planted_upward_import_breaks_the_contract(planted):
    plant(planted, "lawbench/core/problem.py", "from lawbench.views.plotting import plot_outcome")
    assert upward_imports(graph(planted)) == [
        "lawbench.core.problem -> lawbench.views.plotting (a higher layer)"
    ]


def test_a_planted_import_of_a_sibling_or_of_the_package_breaks_the_contract(planted):
    plant(planted, "laws/newton.py", "import lawbench.cases.lamina")
    plant(planted, "lawbench/numerics/roots.py", "from lawbench import solve")
    assert upward_imports(graph(planted)) == [
        "lawbench.laws.newton -> lawbench.cases.lamina (a sibling layer)",
        "lawbench.numerics.roots -> lawbench (the public names import the package)",
    ]


def test_a_planted_lazy_import_that_closes_a_circle_is_found(planted):
    plant(planted, "lawbench/core/errors.py", "from lawbench.core.problem import ImpactProblem")
    (circle,) = circles(graph(planted))
    assert {"lawbench.core.errors", "lawbench.core.problem"} <= set(circle)
