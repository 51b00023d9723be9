"""`nonsmooth reproduce`: every figure of the paper and an agreement report."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Optional

import typer

from .app import app
from .common import WorkersOpt


@app.command("reproduce")
def reproduce_cmd(
    out: Annotated[Path, typer.Option(
        "--out", "-o", help="output folder (created if missing; its parent must exist)")
    ] = Path("reproduce"),
    only: Annotated[Optional[str], typer.Option(
        "--only", help="comma-separated figure ids, e.g. fig9,fig11 (fig6 = fig6a,fig6b); the "
                       "report in --out keeps the other figures of earlier runs")] = None,
    quick: Annotated[bool, typer.Option(
        "--quick/--full", metavar="", help="coarse grids, short runs (about 15 s once "
                                           "the kernels are compiled; the first run on a "
                                           "machine compiles them, 3 to 5 minutes), or full "
                                           "resolution")] = False,
    workers: WorkersOpt = None,
):
    """Regenerate the paper's Figs. 3-12 (PNG + netCDF each) and write report.md / report.html."""
    import sys

    from ..reproduction import DIFFERS, figure_ids, reproduce

    figure_ids(only)  # unknown ids fail before any work
    log = lambda msg: typer.echo(msg, err=True)  # noqa: E731
    records = reproduce(out, only=only, quick=quick, workers=workers, log=log,
                        command="nonsmooth " + " ".join(sys.argv[1:]))
    failed = [r.id for r in records if r.error]
    n_diff = sum(1 for r in records for c in r.checks if c.verdict == DIFFERS)
    n_all = sum(len(r.checks) for r in records)
    typer.echo(f"{len(records)} figures, {n_all} checks ({n_diff} differ from the paper), "
               f"{len(failed)} failed{': ' + ', '.join(failed) if failed else ''}")
    typer.echo(f"wrote {out / 'report.md'}\nwrote {out / 'report.html'}\n"
               f"wrote {out / 'summary.json'}")
    if failed:
        raise typer.Exit(1)
