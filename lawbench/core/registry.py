"""Registries of laws and cases, filled by the modules of a package and by plugins on first use.

Each module of ``lawbench.laws`` (``lawbench.cases``) registers its entry when imported. Other
distributions add entries through entry points of the group of the same name
(``[project.entry-points."lawbench.laws"]``): an entry point names a module (importing it
registers its entries, like the built-in ones) or a `Law`/`Case` subclass or instance (the
registry registers it). Asked for one name, a registry imports the module of that name (a
built-in module or a plugin's entry point) and only that, when it registers the name; asked
for every name, it imports everything. So importing lawbench, and solving with one law on one
scene, stay cheap. A module or plugin that fails to import, raises, or
registers a name twice is skipped and its reason kept in `Registry.unavailable` instead of
breaking the others. So is a plugin whose import calls `sys.exit`, raises `KeyboardInterrupt`
itself (a Ctrl-C from the user still ends the command: `lawbench.core.guards.user_interrupts`),
or runs longer than `PLUGIN_IMPORT_S` seconds (`lawbench.core.guards.alarm`, which stops Python
code; an import stuck inside compiled code is beyond an in-process bound).

A registry is a read-only mapping of names to entries: ``LAWS["newton"]``, ``"newton" in
LAWS``, iteration over the names, ``keys()``, ``values()``, ``items()``, ``len()``. An unknown
name raises `UnknownName`, both the mapping's `KeyError` and lawbench's `InvalidProblem`, with
the known names in the message.
"""

from __future__ import annotations

import importlib
import importlib.util
import inspect
import pkgutil
from collections.abc import Iterator, Mapping
from typing import Any, Protocol, TypeVar

from lawbench.core.errors import BudgetExceeded, UnknownName
from lawbench.core.guards import alarm, from_user, held, user_interrupts

# Seconds a plugin's import may take before it is listed as unavailable: an import reads
# modules and perhaps data, and lawbench's own slowest optional engine imports in about two.
PLUGIN_IMPORT_S = 10.0


def _entry_points(**selection: str) -> list:
    """The installed entry points selected (``group``, ``name``).

    importlib.metadata is imported here, on first use: it costs a third of the start-up of a
    command that solves one built-in law on one built-in scene.
    """
    import importlib.metadata

    return list(importlib.metadata.entry_points(**selection))


class _Named(Protocol):
    name: str


Entry = TypeVar("Entry", bound=_Named)


class Registry(Mapping[str, Entry]):
    """Read-only name -> entry mapping for the entries of one kind ('law', 'case' or 'study').

    Parameters
    ----------
    kind : str
        What the entries are, for messages.
    package : str
        Dotted name of the package whose modules register entries.
    entry_type : type
        The class of the entries: `get` passes one through and refuses any other non-name.
    """

    def __init__(self, kind: str, package: str, entry_type: type) -> None:
        self.kind = kind
        self.package = package
        self.entry_type = entry_type
        self._entries: dict[str, Entry] = {}
        self.unavailable: dict[str, str] = {}
        self._loaded = False

    def register(self, entry: Entry) -> Entry:
        """Add ``entry`` under its name; a name registered twice is an error."""
        if entry.name in self._entries:
            raise ValueError(f"{self.kind} {entry.name!r} is already registered")
        self._entries[entry.name] = entry
        return entry

    def missing(self, name: str, reason: str) -> None:
        """Record that the entry ``name`` did not load, and why.

        For a module that registers several entries, each with a dependency of its own: the
        others load, and ``name`` is listed in `unavailable` like a module that failed.
        """
        self.unavailable[name] = reason

    def _load(self) -> None:
        if self._loaded:
            return
        self._loaded = True
        try:
            with held():
                self._import_modules()
        except BaseException:
            # A stop that rang meanwhile (held until every module was in): the next use
            # finishes the load.
            self._loaded = False
            raise
        for point in _entry_points(group=self.package):
            reason = self._plug_guarded(point)
            if reason:
                self.unavailable[point.name] = f"plugin {point.value}: {reason}"

    def _import_modules(self) -> None:
        """Import every built-in module of the package, each registering its entries.

        Run whole (`lawbench.core.guards.held`): a time bound that stopped the loop half-way
        would leave the registry without the modules after it for the rest of the process.
        """
        package = importlib.import_module(self.package)
        for module in sorted(pkgutil.iter_modules(package.__path__), key=lambda m: m.name):
            if module.name.startswith("_"):
                continue
            try:
                importlib.import_module(f"{self.package}.{module.name}")
            except ImportError as exc:
                self.unavailable[module.name] = f"missing dependency: {exc}"

    def _load_one(self, name: str) -> None:
        """Import the built-in module called ``name``, or the plugin of that name, if any."""
        if self._loaded or not name.isidentifier() or name.startswith("_"):
            return
        module = f"{self.package}.{name}"
        try:
            if importlib.util.find_spec(module) is not None:
                with held():  # a module stopped half-way would be left half-registered
                    importlib.import_module(module)
                return
        except ImportError:
            return  # the full load records why
        for point in _entry_points(group=self.package, name=name):
            if self._plug_guarded(point):
                return  # the full load records why

    def _plug_guarded(self, point: Any) -> str:
        """Load and register the entry point ``point``; why it failed, or '' when it did not.

        A plugin's import is bounded by `PLUGIN_IMPORT_S` and may neither end the command
        (`SystemExit`) nor pass its own `KeyboardInterrupt` off as the user's.
        """
        before = user_interrupts()
        try:
            with alarm(PLUGIN_IMPORT_S):
                self._plug(point.load())
        except BudgetExceeded:
            return f"its import took longer than {PLUGIN_IMPORT_S:g} s and was stopped"
        except SystemExit as exc:
            return f"its import called sys.exit({exc.code!r})"
        except KeyboardInterrupt:
            if from_user(before):
                raise
            return "its import raised KeyboardInterrupt"
        except Exception as exc:  # a broken plugin is reported, the others still load
            return f"{type(exc).__name__}: {exc}"
        return ""

    def _plug(self, loaded: object) -> None:
        """Register what an entry point names: a module registered itself on import."""
        if inspect.ismodule(loaded):
            return
        kind = loaded if inspect.isclass(loaded) else type(loaded)
        name = getattr(loaded, "name", None)
        if not isinstance(name, str):
            raise TypeError(f"{loaded!r} is neither a module nor a {self.kind} with a name")
        if isinstance(self._entries.get(name), kind):
            return  # its module registered it when the entry point imported it
        self.register(loaded() if inspect.isclass(loaded) else loaded)

    def get(self, name: str | Entry) -> Entry:  # type: ignore[override]
        """Return the entry called ``name`` (an entry is returned as it is).

        Unlike a dict's ``get``, an unknown name is an error: a misspelled law or scene never
        passes silently as None.

        Raises
        ------
        UnknownName
            For an unknown name; the message lists the known ones.
        TypeError
            For an argument that is neither a name nor an entry.
        """
        if isinstance(name, str):
            return self[name]
        if isinstance(name, self.entry_type):
            return name
        raise TypeError(
            f"{self.kind} must be a {self.kind} name (str) or a {self.entry_type.__name__}, "
            f"not {type(name).__name__}"
        )

    def __getitem__(self, name: str) -> Entry:
        if name not in self._entries:
            self._load_one(name)
        if name not in self._entries:
            self._load()
        try:
            return self._entries[name]
        except KeyError:
            known = ", ".join(self.names())
            reason = self.unavailable.get(name)
            extra = f" ({reason})" if reason else ""
            raise UnknownName(f"unknown {self.kind} {name!r}{extra}; known: {known}") from None

    def names(self) -> list[str]:
        """Registered names, sorted."""
        self._load()
        return sorted(self._entries)

    def __iter__(self) -> Iterator[str]:
        return iter(self.names())

    def __len__(self) -> int:
        return len(self.names())

    def __contains__(self, name: object) -> bool:
        self._load()
        return name in self._entries

    def __repr__(self) -> str:
        return f"<{self.kind} registry: {', '.join(self.names())}>"
