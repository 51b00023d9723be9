"""Reproduce every figure of the paper (Figs. 3-12) with an agreement report.

``reproduce(out, only=None, quick=False, workers=None)`` runs the registered figures (see
:data:`FIGURES`), writes for each a PNG and its netCDF data into ``out``, then ``report.md``,
a self-contained ``report.html`` and a machine-readable ``summary.json``. A figure whose analysis
fails or is missing is reported as failed; the other figures are unaffected.
"""

from __future__ import annotations

import datetime as _dt
import json
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
    """Run the figures and write the report; returns the per-figure records."""
    from .._version import __version__
    from ..io import check_writable
    from ..sweep import resolve_workers, threads
    from .report import platform_text, write_html, write_markdown

    ids = figure_ids(only)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    check_writable(out / "report.md", "out")
    nw = resolve_workers(workers)
    ctx = Context(out, quick=quick, workers=nw, log=log)
    t0 = time.perf_counter()
    with threads(nw):
        records = run_figures(ids, ctx)
    seconds = time.perf_counter() - t0
    meta = {"command": command or _command(out, only, quick, workers), "quick": quick,
            "seconds": seconds, "workers": nw, "version": __version__,
            "platform": platform_text(),
            "date": _dt.datetime.now().isoformat(timespec="seconds")}
    evidence = ctx.cache.get("gap_evidence", {})
    write_markdown(records, meta, evidence, out)
    write_html(records, meta, evidence, out)
    summary = {
        "meta": meta,
        "figures": [{
            "id": r.id, "title": r.title, "seconds": r.seconds, "error": r.error,
            "files": [p.name for p in r.files], "params": r.params, "method": r.method,
            "checks": [c.__dict__ for c in r.checks]} for r in records],
        "gap_evidence": evidence,
    }
    (out / "summary.json").write_text(json.dumps(summary, indent=1), encoding="utf-8")
    return records


def _command(out, only, quick, workers) -> str:
    parts = ["nonsmooth reproduce", f"--out {out}"]
    if only:
        parts.append(f"--only {only if isinstance(only, str) else ','.join(only)}")
    if quick:
        parts.append("--quick")
    if workers:
        parts.append(f"--workers {workers}")
    return " ".join(parts)
