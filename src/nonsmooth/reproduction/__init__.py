"""Reproduce every figure of the paper (Figs. 3-12) with an agreement report.

``reproduce(out, only=None, quick=False, workers=None)`` runs the registered figures (see
:data:`FIGURES`), writes for each a PNG and its netCDF data into ``out`` as it finishes, and
keeps ``report.md``, a self-contained ``report.html`` and a machine-readable ``summary.json``
up to date with every figure in the folder (figures of earlier runs into the same folder
included). A figure whose analysis fails or is missing is reported as failed; the other figures
are unaffected.
"""

from __future__ import annotations

import datetime as _dt
import time
from pathlib import Path

from . import figures as _figures  # noqa: F401  (registers the figures)
from .core import (AGREES, DIFFERS, FIGURES, NOT_STATED, Check, Context, FigureRecord,
                   run_figures)

__all__ = ["reproduce", "FIGURES", "figure_ids", "Check", "FigureRecord", "AGREES", "DIFFERS",
           "NOT_STATED"]


def figure_ids(only=None) -> list[str]:
    """The figure ids to run, in paper order. ``only``: iterable or comma-separated string."""
    from ..errors import ParameterError
    if only is None or only == "" or only == []:
        return list(FIGURES)
    if isinstance(only, str):
        only = [only]
    wanted = []
    for item in only:
        for fid in str(item).split(","):
            fid = fid.strip().lower()
            if not fid:
                continue
            if fid in FIGURES:
                hits = [fid]
            else:  # "fig6" selects fig6a and fig6b, "fig12" selects a, b, c
                hits = [k for k in FIGURES if k.rstrip("abc") == fid]
            if not hits:
                raise ParameterError(
                    f"only: unknown figure {fid!r} (known: {', '.join(FIGURES)})")
            wanted += [h for h in hits if h not in wanted]
    return [k for k in FIGURES if k in wanted]


def reproduce(out="reproduce", only=None, quick: bool = False, workers: int | None = None,
              log=None, command: str = "") -> list[FigureRecord]:
    """Run the figures and write the report; returns the records of the figures run.

    ``out`` is created if missing (its parent folder must exist). A folder that holds the
    ``summary.json`` of an earlier run keeps that run's other figures: the report is rebuilt
    from all of them, and says which run (command, quick or full, date) computed each. The
    report is rewritten as each figure finishes, so an interrupted run keeps what is done.
    """
    from .._version import __version__
    from ..sweep import resolve_workers, threads
    from .report import load_summary, platform_text, write_reports

    ids = figure_ids(only)
    nw = resolve_workers(workers)
    out = output_folder(out)
    shown = load_summary(out)
    if not shown and (out / "summary.json").is_file() and log:
        log(f"{out / 'summary.json'} is not a summary this version can read: the report will "
            "list the figures of this run only")
    run = {"command": command or _command(out, only, quick, workers), "quick": bool(quick),
           "seconds": 0.0, "workers": nw, "version": __version__, "platform": platform_text(),
           "date": _dt.datetime.now().isoformat(timespec="seconds")}
    t0 = time.perf_counter()

    def done(rec: FigureRecord) -> None:
        run["seconds"] = time.perf_counter() - t0
        rec.run = run
        shown[rec.id] = rec
        write_reports([shown[k] for k in FIGURES if k in shown], out)

    ctx = Context(out, quick=quick, workers=nw, log=log)
    with threads(nw):
        return run_figures(ids, ctx, done)


def output_folder(out) -> Path:
    """``out`` as a writable folder, created when missing; a one-line OutputError naming
    ``out`` when it is a file, its parent folder does not exist or it cannot be written."""
    from ..errors import OutputError
    from ..io import check_writable
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise OutputError(f"out: {str(out)!r} exists and is not a folder")
    if not out.exists():
        parent = out.parent if str(out.parent) else Path(".")
        if not parent.is_dir():
            raise OutputError(f"out: cannot create {str(out)!r}: folder {str(parent)!r} does "
                              "not exist")
        try:
            out.mkdir()
        except OSError as exc:
            raise OutputError(f"out: cannot create {str(out)!r}: {exc.strerror or exc}") from None
    check_writable(out / "report.md", "out")
    return out


def _command(out, only, quick, workers) -> str:
    parts = ["nonsmooth reproduce", f"--out {out}"]
    if only:
        parts.append(f"--only {only if isinstance(only, str) else ','.join(only)}")
    if quick:
        parts.append("--quick")
    if workers:
        parts.append(f"--workers {workers}")
    return " ".join(parts)
