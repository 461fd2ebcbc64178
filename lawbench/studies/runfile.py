"""The files of a run: its lock, its checksummed chunks, and its tidy table with metadata.

A run writing ``OUT`` holds the lock ``OUT.lock`` (``flock`` on the file) from its first read to
its last write, and names itself in ``OUT.lock.owner`` (process, machine, start time, command),
so a second run on the same output stops with that name, or waits for the lock. The run removes
both files as it ends, the lock's name before its lock: a run that waited on the removed file
gets its lock, finds the name gone or naming another file, and locks the name anew, so two runs
never hold the output at once and no lock file is left behind.

Finished cells go to ``OUT.parts/part-NNNNNN.parquet`` in chunks, each written under a
temporary name and moved in place (`os.replace`) after its SHA-256 sidecar
(``part-NNNNNN.parquet.sha256``, the format ``sha256sum -c`` reads) is in place. On resume a
chunk whose sidecar is missing or disagrees, or that cannot be read, is deleted and its cells
computed again.

The final table is tidy: one row per cell, one column per grid parameter (numbers where every
value is a number, list columns where a value is a per-contact vector), list columns for the
outcome's vectors (``v_plus``, ``Pn``, ``Pt``), verdicts as a categorical of the
`lawbench.core.verdicts.Verdict` classes. ``params`` and ``options`` stay as JSON text: they are the
cell's exact identity. The format follows the extension: Parquet and Feather keep list columns
as Arrow lists and the run's metadata in the schema's key-value metadata (key ``lawbench``);
CSV expands a vector into ``v_plus_0, v_plus_1, ...`` and keeps the metadata in the sidecar
``OUT.meta.json``. `load_run` reads any of the three back into the same DataFrame.
"""

from __future__ import annotations

import datetime
import fcntl
import hashlib
import importlib.metadata
import json
import logging
import os
import platform
import socket
import subprocess
import sys
from collections.abc import Iterator, Mapping, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.feather as feather
import pyarrow.parquet as pq

from lawbench.core.errors import InvalidProblem
from lawbench.core.verdicts import Verdict
from lawbench.files.paths import input_file, output_file, replaced, write_error

log = logging.getLogger("lawbench.studies.runner")
# The grid an unfinished output belongs to, beside its chunks.
GRID_FILE = "grid.json"

FORMATS = {".parquet": "parquet", ".csv": "csv", ".feather": "feather"}
VECTORS = ("v_plus", "Pn", "Pt")
VERDICTS = [str(v) for v in Verdict]
META_KEY = b"lawbench"
# Versions recorded in a run's metadata.
PACKAGES = ("lawbench", "numpy", "scipy", "clarabel", "pandas", "pyarrow")


def file_format(out: Path, given: str | None = None) -> str:
    """The table format of ``out``, from its extension.

    Raises
    ------
    InvalidProblem
        For an extension that is not ``.parquet``, ``.csv`` or ``.feather``, or a ``given``
        format that contradicts it.
    """
    suffix = Path(out).suffix.lower()
    if suffix not in FORMATS:
        known = ", ".join(FORMATS)
        raise InvalidProblem(f"--out {out}: unknown extension {suffix or '(none)'!r}; use {known}")
    if given is not None and given != FORMATS[suffix]:
        raise InvalidProblem(f"--format {given} contradicts --out {out} ({FORMATS[suffix]})")
    return FORMATS[suffix]


def metadata(seed: int | None = None) -> dict[str, Any]:
    """What a run's file says of where and when it ran.

    Package versions, the git commit of the lawbench source when it is a checkout, the machine,
    the Python version, the seed of random samples and the start time (UTC, ISO 8601).
    """
    versions = {}
    for name in PACKAGES:
        try:
            versions[name] = importlib.metadata.version(name)
        except importlib.metadata.PackageNotFoundError:
            versions[name] = None
    return {
        "versions": versions,
        "git_commit": _commit(),
        "machine": {
            "host": socket.gethostname(),
            "platform": platform.platform(),
            "processor": platform.machine(),
            "cpus": os.cpu_count(),
            "python": platform.python_version(),
        },
        "seed": seed,
        "started": datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds"),
    }


def _commit() -> str | None:
    source = Path(__file__).resolve().parent
    try:
        done = subprocess.run(
            ["git", "rev-parse", "HEAD"], cwd=source, capture_output=True, text=True, timeout=5
        )
    except (OSError, subprocess.SubprocessError):
        return None
    return done.stdout.strip() or None if done.returncode == 0 else None


def tidy(table: pd.DataFrame) -> tuple[pd.DataFrame, dict[str, Any]]:
    """The tidy table of a run's records, and the column layout `untidy` needs to undo it.

    Record columns hold the parameters and vectors as JSON text (`lawbench.studies.record.Record`);
    here every grid parameter becomes its own column, placed after ``params``, and the vectors
    list columns. A parameter whose name is already a column is left in ``params`` only.
    """
    table = table.copy()
    params = [json.loads(text) for text in table["params"]] if len(table) else []
    names = list(dict.fromkeys(name for p in params for name in p if name not in table.columns))
    at = table.columns.get_loc("params") + 1 if "params" in table else len(table.columns)
    for offset, name in enumerate(names):
        table.insert(at + offset, name, _column([p.get(name) for p in params]))
    for name in VECTORS:
        if name in table:
            table[name] = [json.loads(v) if isinstance(v, str) and v else None for v in table[name]]
    for name in _verdict_columns(table):
        table[name] = pd.Categorical(table[name], categories=VERDICTS)
    lists = [name for name in names if table[name].dtype == object and _holds_lists(table[name])]
    return table, {"params": names, "vectors": [v for v in VECTORS if v in table], "lists": lists}


def _holds_lists(column: pd.Series) -> bool:
    return any(isinstance(v, list) for v in column)


def _column(values: list[Any]) -> pd.Series:
    """A parameter's column: numbers, lists of numbers when a value is a vector, else text."""
    given = [v for v in values if v is not None]
    if any(isinstance(v, list) for v in given):
        return pd.Series([None if v is None else list(np.atleast_1d(v)) for v in values])
    if all(isinstance(v, int | float) and not isinstance(v, bool) for v in given):
        return pd.Series(values, dtype=float if None in values else None)
    return pd.Series([None if v is None else str(v) for v in values], dtype=object)


def _verdict_columns(table: pd.DataFrame) -> list[str]:
    return [c for c in table.columns if c == "verdict" or str(c).endswith("_verdict")]


def untidy(table: pd.DataFrame, layout: Mapping[str, Any]) -> pd.DataFrame:
    """The record columns of a tidy table (the inverse of `tidy`)."""
    table = table.drop(columns=list(layout.get("params", [])))
    for name in layout.get("vectors", []):
        table[name] = ["" if v is None else json.dumps([float(x) for x in v]) for v in table[name]]
    for name in _verdict_columns(table):
        table[name] = table[name].astype(str)
    return table


def write_table(table: pd.DataFrame, path: Path, meta: Mapping[str, Any]) -> None:
    """Write a tidy ``table`` to ``path`` in the format of its extension, whole or not at all.

    ``meta`` (run metadata and the column layout of `tidy`) goes into the file's metadata, or
    into ``PATH.meta.json`` beside a CSV file.
    """
    path = Path(path)
    kind = file_format(path)
    if kind == "csv":
        _atomic_text(_sidecar(path), json.dumps(meta, indent=1))
        with replaced(path, "run table") as temporary:
            _expanded(table, _wide(meta)).to_csv(temporary, index=False)
        return
    arrow = pa.Table.from_pandas(table, preserve_index=False)
    given = dict(arrow.schema.metadata or {})
    arrow = arrow.replace_schema_metadata({**given, META_KEY: json.dumps(meta).encode()})
    # Written to an open file: Arrow takes a path as UTF-8, which a file name need not be.
    with replaced(path, "run table") as temporary, temporary.open("wb") as handle:
        if kind == "parquet":
            pq.write_table(arrow, handle)
        else:
            feather.write_feather(arrow, handle)


def save_run(records: pd.DataFrame, path: Path, meta: Mapping[str, Any]) -> Path:
    """Write a run's records as its tidy table at ``path``; return ``path``.

    The one writer of run tables (``lawbench run``, ``lawbench study --out``): `tidy` makes
    the table and its layout, `write_table` writes both with ``meta``, so that `load_run` reads
    any of them back. The folder of ``path`` is created when missing.

    Parameters
    ----------
    records : pandas.DataFrame
        One `lawbench.studies.record.Record` row per cell, in cell order.
    path : Path
        A ``.parquet``, ``.csv`` or ``.feather`` file.
    meta : mapping
        The run's metadata (`metadata`), with anything else to keep beside it.

    Raises
    ------
    InvalidProblem
        For an unknown extension, or a file that cannot be written.
    """
    path = output_file(path, "run table")
    file_format(path)
    tidied, layout = tidy(records)
    write_table(tidied, path, {**meta, **layout})
    return path


def _wide(layout: Mapping[str, Any]) -> list[str]:
    """The list columns of a tidy table: the outcome's vectors and the vector parameters."""
    return [*layout.get("vectors", []), *layout.get("lists", [])]


def _sidecar(path: Path) -> Path:
    return path.with_name(path.name + ".meta.json")


def _lock(path: Path, wait: bool) -> int:
    """A descriptor of ``path`` holding its exclusive ``flock``.

    Raises `BlockingIOError` when another process holds it and ``wait`` is False. A lock taken
    on a file whose name was removed or reused meanwhile (its holder ended) is let go and taken
    again on the file the name now gives.
    """
    while True:
        descriptor = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
        try:
            fcntl.flock(descriptor, fcntl.LOCK_EX | (0 if wait else fcntl.LOCK_NB))
            held = os.fstat(descriptor)
            try:
                named = os.stat(path)
            except FileNotFoundError:
                named = None
        except BaseException:
            os.close(descriptor)
            raise
        if named is not None and os.path.samestat(held, named):
            return descriptor
        os.close(descriptor)


def _atomic_text(path: Path, text: str) -> None:
    # A command line may hold a file name that is not UTF-8: escaped, never refused.
    with replaced(path, "run file") as temporary:
        temporary.write_text(text, encoding="utf-8", errors="backslashreplace")


def _expanded(table: pd.DataFrame, vectors: Sequence[str]) -> pd.DataFrame:
    """CSV's form of list columns: one column per entry, ``NAME_0, NAME_1, ...``."""
    for name in vectors:
        width = max((len(v) for v in table[name] if v is not None), default=0)
        wide = [(list(v) if v is not None else []) + [np.nan] * width for v in table[name]]
        at = table.columns.get_loc(name)
        table = table.drop(columns=name)
        for k in range(width):
            table.insert(at + k, f"{name}_{k}", [row[k] for row in wide])
    return table


def _gathered(table: pd.DataFrame, vectors: Sequence[str]) -> pd.DataFrame:
    """The list columns of a table read from CSV (the inverse of `_expanded`).

    A cell without an outcome (status 'error') has no outcome vector; an answered one has a
    list, empty for a vector of no entries (``Pt`` without friction). A parameter left at its
    default in a row has no value.
    """
    for name in vectors:
        parts = [
            c for c in table.columns if c.startswith(f"{name}_") and c[len(name) + 1 :].isdigit()
        ]
        parts.sort(key=lambda c: int(c[len(name) + 1 :]))
        at = table.columns.get_loc(parts[0]) if parts else len(table.columns)
        entries = table[parts].to_numpy(dtype=float) if parts else np.empty((len(table), 0))
        if name in VECTORS and "status" in table:
            answered = list(table["status"] != "error")
        else:
            answered = [bool(np.isfinite(row).any()) for row in entries]
        column = [
            [float(x) for x in row if x == x] if ok else None
            for row, ok in zip(entries, answered, strict=True)
        ]
        table = table.drop(columns=parts)
        table.insert(at, name, column)
    return table


def read_table(path: Path) -> tuple[pd.DataFrame, dict[str, Any]]:
    """A run's tidy table and its metadata, from any of the three formats.

    Raises
    ------
    InvalidProblem
        Naming the file, for one that is not a table of its format (junk, a truncated file),
        whose metadata is not JSON, or a CSV file's metadata sidecar that is not a regular file.
    """
    path = Path(path)
    kind = file_format(path)
    sidecar = _sidecar(path)
    meta = _json(sidecar, "run metadata") if kind == "csv" and sidecar.exists() else {}
    try:
        return _read(path, kind, meta)
    except (OSError, ValueError, pa.ArrowException) as exc:
        reason = " ".join(str(exc).split())  # a reader's message may span lines
        raise InvalidProblem(f"run table {path}: not a table a run wrote ({reason})") from None


def _read(path: Path, kind: str, meta: dict[str, Any]) -> tuple[pd.DataFrame, dict[str, Any]]:
    """The table of ``path`` in format ``kind`` and its metadata (a CSV file's is ``meta``)."""
    if kind == "csv":
        table = pd.read_csv(path, keep_default_na=False, na_values=[""])
        table = _gathered(table, _wide(meta))
        for name in _verdict_columns(table):
            table[name] = pd.Categorical(table[name], categories=VERDICTS)
        return table, meta
    with path.open("rb") as handle:
        arrow = pq.read_table(handle) if kind == "parquet" else feather.read_table(handle)
    meta = json.loads((arrow.schema.metadata or {}).get(META_KEY, b"{}"))
    return arrow.to_pandas(), meta


def _json(path: Path, what: str) -> dict[str, Any]:
    """The JSON object in the regular file ``path``; ``what`` names it in messages.

    Raises
    ------
    InvalidProblem
        For a path that is not a regular file, or text that is not a JSON object.
    """
    path = input_file(path, what)
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:  # JSONDecodeError and UnicodeDecodeError included
        raise InvalidProblem(f"{what} {path}: not JSON ({' '.join(str(exc).split())})") from None
    if not isinstance(data, dict):
        raise InvalidProblem(f"{what} {path}: a JSON {type(data).__name__}, not an object")
    return data


def load_run(path: str | os.PathLike[str]) -> pd.DataFrame:
    """The table of a finished run (``lawbench run --out PATH``), ready for pandas.

    Parameters
    ----------
    path : str or path-like
        A ``.parquet``, ``.feather`` or ``.csv`` file written by a run.

    Returns
    -------
    pandas.DataFrame
        One row per cell: a column per grid parameter, list columns ``v_plus``, ``Pn``, ``Pt``,
        categorical verdicts. The run's metadata (versions, commit, machine, seed, start time)
        is in ``DataFrame.attrs["lawbench"]``.

    Raises
    ------
    InvalidProblem
        For an unknown extension, a path that is not a regular file of bounded size (missing,
        a FIFO, a folder: `lawbench.files.paths.input_file`), or a file that is not a run's
        table.
    TypeError
        For a ``path`` that is not a path.
    """
    table, meta = read_table(input_file(path, "run file"))
    table.attrs["lawbench"] = meta
    return table


def fingerprint(name: str, keys: Sequence[str]) -> str:
    """The identity of a grid: a digest of its plan's name and its cells' sorted keys."""
    return hashlib.sha256("\n".join([name, *sorted(keys)]).encode()).hexdigest()


def _digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


class Store:
    """The lock, chunk files and final table of one run's output ``out``."""

    def __init__(self, out: Path) -> None:
        self.out = Path(out)
        self.format = file_format(self.out)
        self.parts = self.out.with_name(self.out.name + ".parts")
        self.lock_path = self.out.with_name(self.out.name + ".lock")
        self.owner_path = self.out.with_name(self.out.name + ".lock.owner")
        self.damaged: list[str] = []
        self._layout: dict[str, Any] = {}
        self._grid: dict[str, str] = {}

    @contextmanager
    def locked(self, wait: bool = False) -> Iterator[None]:
        """Hold the output's lock; without ``wait``, a held lock raises `InvalidProblem`."""
        try:
            # Creating the lock file is the first write: a folder that cannot be written (read
            # only, full, under /sys) is known before any cell is computed.
            self.out.parent.mkdir(parents=True, exist_ok=True)
            descriptor = _lock(self.lock_path, wait)
        except BlockingIOError:
            raise InvalidProblem(
                f"--out {self.out} is locked by another run ({self._owner()}; lock file "
                f"{self.lock_path}): wait for it with --wait, or choose another --out"
            ) from None
        except OSError as exc:
            raise write_error(exc, "--out", self.out) from None
        try:
            started = datetime.datetime.now().isoformat(timespec="seconds")
            owner = f"pid {os.getpid()} on {socket.gethostname()} since {started}: "
            _atomic_text(self.owner_path, owner + " ".join(sys.argv))
            yield
        finally:
            self.owner_path.unlink(missing_ok=True)
            self.lock_path.unlink(missing_ok=True)
            os.close(descriptor)  # releases the lock, after its name is gone

    def _owner(self) -> str:
        try:
            return self.owner_path.read_text().strip()
        except OSError:
            return "its owner has not written its name yet"

    def claim(self, grid: str, described: str) -> None:
        """Tie this output to the grid of fingerprint ``grid`` (``described`` in messages).

        Raises
        ------
        InvalidProblem
            When the output's finished table or chunks belong to another grid: resuming there
            would mix two grids' cells and never finish either.
        """
        held: dict[str, Any] = {}
        if (self.parts / GRID_FILE).exists():
            held = _json(self.parts / GRID_FILE, "run grid")
        elif self.out.exists():
            held = self._finished(grid)
        if held.get("grid", grid) != grid:
            raise InvalidProblem(
                f"--out {self.out} holds the cells of another grid ({held['grid_described']}); "
                f"this run's grid is {described}: give another --out"
            )
        self._grid = {"grid": grid, "grid_described": described}

    def _finished(self, grid: str) -> dict[str, Any]:
        """The metadata of the finished table at ``out``, once it is known to be a run's.

        Raises
        ------
        InvalidProblem
            For a table without a run's metadata (a user's own file: resuming would count its
            rows as cells), or whose rows are not the cells of the grid it names (rows added,
            removed or edited since the run wrote it).
        """
        table, held = read_table(self.out)
        if "grid" not in held or "key" not in table.columns or "study" not in table.columns:
            raise InvalidProblem(
                f"--out {self.out}: a table no run wrote (no run metadata): give another --out"
            )
        studies = set(table["study"].fillna(""))
        name = studies.pop() if len(studies) == 1 else None
        keys = sorted(str(key) for key in table["key"])
        if held["grid"] == grid and fingerprint(name or "", keys) != grid:
            raise InvalidProblem(
                f"--out {self.out}: its rows are not the cells of the grid it was written for "
                "(rows were added, removed or edited): give another --out"
            )
        return held

    def chunks(self) -> list[Path]:
        """The chunk files, in the order they were written."""
        return sorted(self.parts.glob("part-*.parquet")) if self.parts.exists() else []

    def done(self) -> pd.DataFrame:
        """Every record finished so far (final table and sound chunks), as record columns.

        A chunk whose checksum is missing or wrong, or that cannot be read, is deleted, named in
        ``damaged`` and reported (logger ``lawbench.studies.runner``): its cells are computed again.

        Raises
        ------
        InvalidProblem
            When ``out`` holds a table no run wrote (`read_table`, or no ``key`` column).
        """
        frames = []
        if self.out.exists():
            table, meta = read_table(self.out)
            if "key" not in table.columns:
                raise InvalidProblem(
                    f"--out {self.out}: a table no run wrote (no 'key' column): give another --out"
                )
            self._layout = meta
            frames.append(untidy(table, meta))
        for path in self.chunks():
            frame = self._sound(path)
            if frame is not None:
                frames.append(frame)
        if not frames:
            return pd.DataFrame()
        return pd.concat(frames, ignore_index=True).drop_duplicates("key")

    def _sound(self, path: Path) -> pd.DataFrame | None:
        sidecar = path.with_name(path.name + ".sha256")
        expected = sidecar.read_text().split()[0] if sidecar.exists() else None
        try:
            if expected is not None and _digest(path) == expected:
                with path.open("rb") as handle:
                    return pd.read_parquet(handle)
            reason = "no checksum" if expected is None else "checksum mismatch"
        except (OSError, pa.ArrowException) as exc:
            reason = f"unreadable: {exc}"
        log.warning("chunk %s is damaged (%s): its cells are computed again", path, reason)
        self.damaged.append(path.name)
        path.unlink()
        sidecar.unlink(missing_ok=True)
        return None

    def write_chunk(self, records: list[dict]) -> None:
        """Write one chunk whole: checksum sidecar first, then the chunk moved in place.

        Raises
        ------
        InvalidProblem, SolverFailure
            As `lawbench.files.paths.write_error`: a folder that became read only, a full disk.
        """
        try:
            self._write_chunk(records)
        except OSError as exc:
            raise write_error(exc, "--out", self.out) from None

    def _write_chunk(self, records: list[dict]) -> None:
        self.parts.mkdir(parents=True, exist_ok=True)
        if self._grid and not (self.parts / GRID_FILE).exists():
            _atomic_text(self.parts / GRID_FILE, json.dumps(self._grid))
        written = self.chunks()
        number = int(written[-1].stem.split("-")[1]) + 1 if written else 0
        path = self.parts / f"part-{number:06d}.parquet"
        temporary = path.with_name(f".{path.name}.tmp")
        with temporary.open("wb") as handle:
            pd.DataFrame(records).to_parquet(handle, index=False)
        _atomic_text(path.with_name(path.name + ".sha256"), f"{_digest(temporary)}  {path.name}\n")
        os.replace(temporary, path)

    def finish(self, total: int, meta: Mapping[str, Any]) -> pd.DataFrame:
        """Gather the chunks by cell index; when all ``total`` cells are done, write ``out``.

        The records come back as record columns; ``out`` holds their tidy table with ``meta``.
        """
        table = self.done()
        if not len(table):
            return table
        table = table.sort_values("index").reset_index(drop=True)
        if len(table) == total and (self.chunks() or not self.out.exists()):
            save_run(table, self.out, meta)
            for path in self.parts.iterdir():
                path.unlink()
            self.parts.rmdir()
        return table
