"""`nonsmooth map`: two-parameter maps of the settled motion (period, chaos, lambda1)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Optional

import typer

from ..errors import ParameterError
from .analyses import SettleOpt, TransientOpt, X0Opt, V0Opt, _progress
from .app import app
from .common import (U0Opt, DEFAULT_MODEL, SectionPhaseOpt, AtolOpt, DaskOpt, MethodOpt, ModelOpt, OutOpt, PlotOpt, PresetOpt,
                     RtolOpt, SetOpt, WorkersOpt, check_outputs, chunk_store,
                     echo_written, load_params, preset_label, require_output, resolve_method,
                     save_outputs)

AxisOpt = tuple[str, float, float, int]


@app.command("map")
def map_cmd(
    model: ModelOpt = DEFAULT_MODEL,
    preset: PresetOpt = None,
    set_: SetOpt = None,
    x: Annotated[Optional[tuple[str, float, float, int]], typer.Option(
        "--x", show_default=False,
        help="horizontal axis: PARAM MIN MAX N (default: the forcing frequency 0.8 1.0 100)")] = None,
    y: Annotated[Optional[tuple[str, float, float, int]], typer.Option(
        "--y", show_default=False,
        help="vertical axis: PARAM MIN MAX N (default: F0 0.15 0.45 100)")] = None,
    start: Annotated[str, typer.Option(
        "--start", help="fresh (every point from x0, v0) or continued (along x, as the up "
                        "sweeps)")] = "fresh",
    transient: TransientOpt = 500,
    record: Annotated[int, typer.Option("--record", help="section points recorded per point")] = 100,
    x0: X0Opt = 0.0,
    v0: V0Opt = 0.0,
    u0: U0Opt = None,
    method: MethodOpt = None,
    rtol: RtolOpt = 1e-8,
    atol: AtolOpt = 1e-10,
    section_phase: SectionPhaseOpt = 0.0,
    settle: SettleOpt = True,
    lyapunov: Annotated[Optional[bool], typer.Option(
        "--lyapunov/--no-lyapunov", show_default=False,
        help="lambda1 per point (default: wherever tangent dynamics exist)")] = None,
    workers: WorkersOpt = None,
    dask: DaskOpt = None,
    chunk: Annotated[Optional[int], typer.Option(
        "--chunk", show_default=False,
        help="points (fresh) or rows (continued) per chunk: the unit of resumption and of Dask "
             "tasks (default: from the grid size)")] = None,
    out: OutOpt = None,
    plot: PlotOpt = None,
    lambda_plot: Annotated[Optional[Path], typer.Option(
        "--lambda-plot", help="figure of the lambda1 map")] = None,
):
    """Two-parameter map of the settled motion: period, chaos (lambda1), amplitude, contact.
    With -o the finished chunks are kept in FILE.chunks and the same command resumes there."""
    params = load_params(preset, set_, model, "table3", method=method)
    method = resolve_method(params, method)
    preset = preset_label(params, preset, "table3")
    from ..checks import check_forced
    check_forced(params, "map")
    w = params.model.forcing_param
    x = tuple(x) if x is not None else (w, *params.model.forcing_range(0.8, 1.0), 100)
    if y is None:
        if "F0" not in params.model.param_names:
            raise ParameterError(f"y: model {params.model.name!r} has no F0; give --y PARAM MIN "
                                 f"MAX N")
        y = ("F0", 0.15, 0.45, 100)
    require_output(out, plot if plot is not None else lambda_plot)
    from ..checks import STARTS, check_axis, check_int, check_solver_options
    xname = check_axis("x", x, params)[0]
    if check_axis("y", y, params)[0] == xname:
        raise ParameterError(f"y: the two axes need different parameters, both are {xname!r}")
    if start not in STARTS:
        raise ParameterError(f"start: expected one of {', '.join(STARTS)}, got {start!r}")
    check_int("transient", transient, 0)
    check_int("record", record, 1)
    if chunk is not None:
        check_int("chunk", chunk, 1)
    check_solver_options(rtol, atol, section_phase)
    check_outputs(out, plot, lambda_plot=lambda_plot)
    from ..analysis.parameter_map import parameter_map, regimes  # (after the checks)
    store, engine = chunk_store(out, dask)
    with _progress(f"map {x[0]} x {y[0]}") as prog:
        ds = parameter_map(params, x=x, y=tuple(y), transient=transient, record=record,
                           method=method, start=start, x0=x0, v0=v0, u0=u0, rtol=rtol, atol=atol, section_phase=section_phase,
                           settle=settle, lyapunov=lyapunov,
                           workers=workers, progress=prog, store=store, engine=engine,
                           chunk=chunk)
    from ..plot.parameter_map import plot_lambda1_map, plot_parameter_map
    save_outputs(ds, preset, out, plot, plot_parameter_map, store=store)
    if lambda_plot is not None:
        from ..io import save_figure
        save_figure(plot_lambda1_map(ds), lambda_plot, what="lambda-plot")
    code, names = regimes(ds)
    counts = [(names[k], int(c)) for k, c in enumerate(
        __import__("numpy").bincount(code.ravel(), minlength=len(names))) if c]
    ny, nx = code.shape
    typer.echo(f"{preset}: {ny} x {nx} points ({y[0]} x {x[0]}), {method}, {start} start: "
               + ", ".join(f"{n} {name}" for name, n in counts))
    echo_written(out, plot, lambda_plot)
