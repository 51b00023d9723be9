"""Options and helpers shared by the CLI commands (keep commands thin).

Nothing heavy is imported here (no numpy, numba, xarray or matplotlib): ``nonsmooth --help``
only needs the options. A command imports what it computes with inside its function.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Optional

import typer

from ..errors import ParameterError

PresetOpt = Annotated[str, typer.Option("--preset", "-p", help="parameter set (see `nonsmooth presets`)")]
SetOpt = Annotated[Optional[list[str]], typer.Option(
    "--set", "-s", help="override a parameter, NAME=VALUE (repeatable)")]
OutOpt = Annotated[Optional[Path], typer.Option("--out", "-o", help="netCDF result file")]
PlotOpt = Annotated[Optional[Path], typer.Option(
    "--plot", help="figure file, format from the suffix: .png, .pdf, .svg, ... (none: PNG)")]
MethodOpt = Annotated[str, typer.Option("--method", help="smooth (switch model, RKF45) or exact (eta = 0)")]
RtolOpt = Annotated[float, typer.Option("--rtol", help="relative tolerance")]
AtolOpt = Annotated[float, typer.Option("--atol", help="absolute tolerance")]
TransitionOpt = Annotated[str, typer.Option("--transition", help="eq13 (paper, default) or eq12 (convex)")]
WorkersOpt = Annotated[Optional[int], typer.Option("--workers", "-j", help="threads (default: all cores)")]


#: Output paths this run was asked for -> the file each is written to (a figure without
#: suffix gets ``.png``); also tells the message of an interrupted run what was not written.
planned: dict[Path, Path] = {}


def load_params(preset: str, sets: list[str] | None):
    """Preset with ``--set`` overrides applied (every error names the field)."""
    from ..params import parse_assignments
    from ..presets import preset as get_preset
    return get_preset(preset).replace(**parse_assignments(sets))


def check_outputs(out: Path | None, plot: Path | None, **figures: Path | None) -> None:
    """Fail before computing if an output cannot be written or a figure format is unknown
    (``figures``: further figure options, e.g. ``orbits_plot=path``, named after the option)."""
    from ..io import check_writable, figure_path

    if out is not None:
        planned[Path(out)] = check_writable(out, "output")
    for what, path in {"plot": plot, **figures}.items():
        if path is not None:
            planned[Path(path)] = figure_path(path, what.replace("_", "-"))


def require_output(out: Path | None, plot: Path | None) -> None:
    if out is None and plot is None:
        raise ParameterError("output: give -o FILE.nc and/or --plot FILE.png")


def save_outputs(ds, preset: str, out: Path | None, plot: Path | None, figure=None) -> None:
    """Record the preset, write the netCDF file and render ``figure(ds)`` (a plot function:
    Dataset in, Figure out) to ``plot`` where asked (each file written atomically)."""
    from ..io import save_dataset, save_figure

    ds.attrs["preset"] = preset
    if out is not None:
        save_dataset(ds, out)
    if plot is not None and figure is not None:
        save_figure(figure(ds), plot)


def echo_written(*paths) -> None:
    """Print ``wrote <file>`` for each output path asked for (None skipped), under the name
    of the file actually written (a figure without suffix got ``.png``)."""
    for p in paths:
        if p is not None:
            typer.echo(f"wrote {planned.get(Path(p), p)}")
