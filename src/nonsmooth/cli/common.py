"""Options and helpers shared by the CLI commands (keep commands thin)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Optional

import typer

from ..errors import ParameterError
from ..io import check_writable
from ..kernels import Solver
from ..params import Params, parse_assignments
from ..presets import preset as get_preset

PresetOpt = Annotated[str, typer.Option("--preset", "-p", help="parameter set (see `nonsmooth presets`)")]
SetOpt = Annotated[Optional[list[str]], typer.Option(
    "--set", "-s", help="override a parameter, NAME=VALUE (repeatable)")]
OutOpt = Annotated[Optional[Path], typer.Option("--out", "-o", help="netCDF result file")]
PlotOpt = Annotated[Optional[Path], typer.Option("--plot", help="figure file (PNG, PDF, SVG)")]
MethodOpt = Annotated[str, typer.Option("--method", help="smooth (switch model, RKF45) or exact (eta = 0)")]
RtolOpt = Annotated[float, typer.Option("--rtol", help="relative tolerance")]
AtolOpt = Annotated[float, typer.Option("--atol", help="absolute tolerance")]
TransitionOpt = Annotated[str, typer.Option("--transition", help="eq13 (paper, default) or eq12 (convex)")]
WorkersOpt = Annotated[Optional[int], typer.Option("--workers", "-j", help="threads (default: all cores)")]


def load_params(preset: str, sets: list[str] | None) -> Params:
    """Preset with ``--set`` overrides applied (every error names the field)."""
    return get_preset(preset).replace(**parse_assignments(sets))


def make_solver(method: str, rtol: float, atol: float, transition: str = "eq13") -> Solver:
    return Solver(method=method, rtol=rtol, atol=atol, transition=transition)


def check_outputs(out: Path | None, plot: Path | None) -> None:
    """Fail before computing if an output path cannot be written."""
    if out is not None:
        check_writable(out, "output")
    if plot is not None:
        check_writable(plot, "plot")


def require_output(out: Path | None, plot: Path | None) -> None:
    if out is None and plot is None:
        raise ParameterError("output: give -o FILE.nc and/or --plot FILE.png")


def save_outputs(ds, preset: str, out: Path | None, plot: Path | None, figure=None) -> None:
    """Record the preset, write the netCDF file and render ``figure(ds)`` (a plot function:
    Dataset in, Figure out) to ``plot`` where asked."""
    from ..io import save_dataset, save_figure

    ds.attrs["preset"] = preset
    if out is not None:
        save_dataset(ds, out)
    if plot is not None and figure is not None:
        save_figure(figure(ds), plot)


def echo_written(*paths) -> None:
    for p in paths:
        if p is not None:
            typer.echo(f"wrote {p}")
