"""The comparison report: every law on every scene and every measured set, side by side.

`write_report` runs every registered study a section draws (`lawbench.views.report.config.view`) and
writes a self-contained folder: ``index.html`` and ``report.md`` with the same content, every
figure as PNG and SVG with the CSV of its data, every table as CSV, every study's table in
``runs/``. Sections, each a view of study tables: summary matrix of the checks with the
findings, every law against the measured impacts (fitted on one half of each set, judged on the
other), outcomes beside the ground truth and the references, speed versus accuracy (model
error and numerical error), stability at the extremes, energy-increase maps, dispersion and
continuity, paths inside an impact, and the yardstick checked by an independent engine (the
full report's). Every cell carries a verdict; the headline counts the unexplained ones. A law
or scene that is missing or fails is reported, never a crash.
"""

from __future__ import annotations

from pathlib import Path

from lawbench.views.report.config import FULL, QUICK, Config, preset


def write_report(out: Path, mode: str = "quick", config: Config | None = None) -> Path:
    """Write the report into ``out`` and return ``out``.

    Parameters
    ----------
    out : Path
        The folder; created when missing, its report files replaced.
    mode : str
        'quick' (each study as declared, slow ones left out: a few minutes on two cores) or
        'full' (each study's full sizes, slow ones in, resumable from ``out/runs``).
    config : Config, optional
        Settings replacing the preset of ``mode`` (a smaller grid for tests).

    Raises
    ------
    InvalidProblem
        For an unknown mode.

    Notes
    -----
    The work runs in spawned worker processes, which import the main module again: a script
    that calls this function must do so under ``if __name__ == "__main__":``.
    """
    # Imported here: the worker processes import this package and need none of the plotting.
    from lawbench.views.report.build import build

    return build(Path(out), config or preset(mode))


__all__ = ["FULL", "QUICK", "Config", "preset", "write_report"]
