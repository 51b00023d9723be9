"""`nonsmooth basins`: basins of attraction on a grid of initial conditions (Figs. 7 and 8)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated, Optional

import typer

from .analyses import FromOpt, ToOpt
from .app import app
from .common import (DEFAULT_MODEL, SectionPhaseOpt, AtolOpt, DaskOpt, MethodOpt, ModelOpt, OutOpt, PlotOpt, PresetOpt, RtolOpt, SetOpt,
                     U0Opt, WorkersOpt, check_outputs, chunk_store, echo_written, load_params,
                     preset_label, require_output, resolve_method, save_outputs)


@app.command("basins")
def basins_cmd(
    model: ModelOpt = DEFAULT_MODEL,
    preset: PresetOpt = None,
    set_: SetOpt = None,
    x: Annotated[tuple[float, float], typer.Option("--x", help="range of the initial X: MIN MAX")] = (-3.0, 3.0),
    v: Annotated[tuple[float, float], typer.Option("--v", help="range of the initial V: MIN MAX")] = (-3.0, 3.0),
    grid: Annotated[int, typer.Option("--grid", help="initial conditions per axis (>= 2)")] = 400,
    max_periods: Annotated[int, typer.Option("--max-periods", help="forcing periods allowed per initial condition")] = 1000,
    transient: Annotated[int, typer.Option("--transient", help="periods before periodicity is tested")] = 10,
    max_period: Annotated[int, typer.Option("--max-period", help="longest period looked for")] = 16,
    no_early_stop: Annotated[bool, typer.Option("--no-early-stop", help="integrate every point until periodic (slow reference)")] = False,
    method: MethodOpt = None,
    rtol: RtolOpt = 1e-8,
    atol: AtolOpt = 1e-10,
    section_phase: SectionPhaseOpt = 0.0,
    workers: WorkersOpt = None,
    dask: DaskOpt = None,
    out: OutOpt = None,
    plot: PlotOpt = None,
    orbits_plot: Annotated[Optional[Path], typer.Option("--orbits-plot", help="figure of the coexisting orbits (Fig. 8)")] = None,
    axes: Annotated[Optional[str], typer.Option("--axes", show_default=False, help="the two state components of the grid, A,B (--x and --v are their ranges; e.g. X,Y for impact_2dof); default: the first two")] = None,
    u0: U0Opt = None,
    entropy: Annotated[bool, typer.Option("--entropy", help="also the basin entropy S_b, the boundary basin entropy S_bb (> ln 2: a fractal boundary) and the uncertainty exponent alpha (1: smooth boundary), written to the same file")] = False,
    box: Annotated[int, typer.Option("--box", help="box side in grid cells for --entropy")] = 5,
    entropy_plot: Annotated[Optional[Path], typer.Option("--entropy-plot", help="figure of the box entropies and the fit of alpha (implies --entropy)")] = None,
):
    """Basins of attraction (periodic and chaotic attractors found automatically); a Fig. 7-style
    image and a Fig. 8-style figure of the coexisting attractors."""
    import warnings

    from ..io import save_figure

    params = load_params(preset, set_, model, "fig7", method=method)
    method = resolve_method(params, method)
    preset = preset_label(params, preset, "fig7")
    require_output(out, plot if plot is not None else orbits_plot or entropy_plot)
    from ..checks import check_axes, check_grid, check_int, check_range, check_solver_options
    check_range("x", x)
    check_range("v", v)
    check_grid(grid)
    check_int("transient", transient, 0)
    check_int("max_periods", max_periods, 1)
    check_int("max_period", max_period, 1)
    check_axes(params.model, axes)
    check_solver_options(rtol, atol, section_phase)
    check_outputs(out, plot, orbits_plot=orbits_plot, entropy_plot=entropy_plot)
    entropy = entropy or entropy_plot is not None
    if entropy:
        from ..analysis.basin_entropy import check_box
        check_box(box, grid)
    from ..analysis.basins import basins  # (after the checks: the kernels load with it)
    from ..sweep import Progress
    store, engine = chunk_store(out, dask)
    with Progress("basins") as bar, warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", UserWarning)
        ds = basins(params, x=x, v=v, grid=grid, method=method, transient=transient,
                    max_periods=max_periods, max_period=max_period, rtol=rtol, atol=atol, section_phase=section_phase,
                    early_stop=not no_early_stop, workers=workers,
                    progress=bar, store=store, engine=engine, axes=axes,
                    u0=u0)
    ent = None
    if entropy:
        from ..analysis.basin_entropy import basin_entropy
        ent = basin_entropy(ds, box)
        ds = ds.merge(ent, combine_attrs="override")  # the basins' attrs, and the box's
        ds.attrs["entropy_box"] = box
    from ..plot.basins import plot_basins
    save_outputs(ds, preset, out, plot, plot_basins, store=store)
    if entropy_plot is not None:
        from ..plot.basin_entropy import plot_basin_entropy
        save_figure(plot_basin_entropy(ent), entropy_plot, what="entropy-plot")
    if orbits_plot is not None:
        from ..plot.basins import plot_attractors
        save_figure(plot_attractors(ds), orbits_plot, what="orbits-plot")
    n = ds.sizes["attractor"]
    typer.echo(f"{preset}: {ds.attrs['grid_nx']}x{ds.attrs['grid_nv']} initial conditions, "
               f"{n} attractor(s), undecided {100 * float(ds.undecided_fraction):.2f}% "
               f"(failed {int(ds.failed_count)}), "
               f"{ds.attrs['mean_periods_used']:.2f} periods per point on average")
    for k in range(n):
        kind = "chaotic" if int(ds.kind[k]) else f"period {int(ds.period[k])}"
        typer.echo(f"  A{k}: {kind}, contact {int(ds.contact[k])}, max {params.model.state_names[0]} {float(ds.max_X[k]):.6g}, "
                   f"fraction {float(ds.fraction[k]):.4f}")
    if ent is not None:
        sbb = float(ent.boundary_basin_entropy)
        alpha = float(ent.uncertainty_exponent)
        typer.echo(f"  basin entropy S_b = {float(ent.basin_entropy):.4f}, boundary S_bb = "
                   f"{sbb:.4f} ({'> ln 2: the boundary is fractal' if sbb > 0.6931471805599453 else '<= ln 2: no fractal boundary shown'}; "
                   f"{box}x{box}-cell boxes), uncertainty exponent alpha = "
                   + (f"{alpha:.3f} +- {float(ent.uncertainty_exponent_stderr):.3f} "
                      "(1: smooth boundary)" if math.isfinite(alpha) else
                      ("not defined (one basin: no boundary)" if n <= 1 else
                       "not defined (boxes meet a boundary at fewer than two sizes)")))
    for w in caught:
        typer.echo(f"  warning: {w.message}".replace("basins: ", ""))
    echo_written(out, plot, orbits_plot, entropy_plot)


@app.command("attractors")
def attractors_cmd(
    model: ModelOpt = DEFAULT_MODEL,
    preset: PresetOpt = None,
    set_: SetOpt = None,
    param: Annotated[Optional[str], typer.Option("--param", show_default=False, help="the parameter followed, one of the model's; default: its forcing frequency (omega)")] = None,
    from_: FromOpt = None,
    to: ToOpt = None,
    steps: Annotated[int, typer.Option("--steps", help="number of values (>= 2)")] = 26,
    x: Annotated[tuple[float, float], typer.Option("--x", help="range of the initial X: MIN MAX")] = (-3.0, 3.0),
    v: Annotated[tuple[float, float], typer.Option("--v", help="range of the initial V: MIN MAX")] = (-3.0, 3.0),
    grid: Annotated[int, typer.Option("--grid", help="initial conditions per axis at each value (>= 2)")] = 40,
    max_periods: Annotated[int, typer.Option("--max-periods", help="forcing periods allowed per initial condition")] = 1000,
    match_tol: Annotated[Optional[float], typer.Option("--match-tol", show_default=False, help="largest distance of two section sets taken as one attractor; default: a tenth of the window's diagonal")] = None,
    method: MethodOpt = None,
    rtol: RtolOpt = 1e-8,
    atol: AtolOpt = 1e-10,
    workers: WorkersOpt = None,
    dask: DaskOpt = None,
    out: OutOpt = None,
    plot: PlotOpt = None,
):
    """Attractors followed across a parameter: found at each value from a grid of initial
    conditions (as basins), matched value to value, with their basin shares, births and
    deaths. With -o, finished values are kept in <out>.chunks until the result is written:
    the same command resumes an interrupted run."""
    params = load_params(preset, set_, model, "fig7", method=method)
    from .analyses import default_range, value_range
    method = resolve_method(params, method)
    preset = preset_label(params, preset, "fig7")
    from ..checks import check_forced
    check_forced(params, "attractors")
    param = params.model.param(param or params.model.forcing_param).name
    from_, to = default_range(params, param, from_, to, 1.0, 1.25)
    values = value_range(from_, to, steps, f"{param} range")
    for val in (values[0], values[-1]):
        params.replace(**{param: float(val)})
    require_output(out, plot)
    from ..checks import check_grid, check_int, check_positive, check_range, check_solver_options
    check_range("x", x)
    check_range("v", v)
    check_grid(grid)
    check_int("max_periods", max_periods, 1)
    if match_tol is not None:
        check_positive("match_tol", match_tol)
    check_solver_options(rtol, atol)
    check_outputs(out, plot)
    from ..analysis.attractor_continuation import attractor_continuation  # (after the checks)
    from ..sweep import Progress
    store, engine = chunk_store(out, dask)
    with Progress(f"attractors over {param}") as bar:
        ds = attractor_continuation(params, param, values, x=x, v=v, grid=grid, method=method,
                                    match_tol=match_tol, max_periods=max_periods, rtol=rtol,
                                    atol=atol, workers=workers, progress=bar, store=store,
                                    engine=engine)
    from ..plot.attractor_continuation import plot_attractor_continuation
    save_outputs(ds, preset, out, plot, plot_attractor_continuation, store=store)
    na = ds.sizes["attractor"]
    typer.echo(f"{preset}: {param} {from_:g} ... {to:g}, {steps} values, {grid}x{grid} initial "
               f"conditions each: {na} attractor(s) along the path, at most "
               f"{int(ds.n_attractors.max())} at once")
    for a in range(na):
        per = sorted({int(q) for q in ds.period.values[:, a] if q >= 0})
        kinds = ", ".join("chaotic" if q == 0 else f"period {q}" for q in per)
        born, died = float(ds.born[a]), float(ds.died[a])
        life = (f"from {param} = {born:g}" if born == born else "from the first value") + \
            (f" until {died:g}" if died == died else " to the last")
        share = ds.fraction.values[:, a][ds.exists.values[:, a] == 1]
        typer.echo(f"  A{a}: {kinds}; {life}; basin share {share.min():.3f} ... "
                   f"{share.max():.3f}")
    echo_written(out, plot)
