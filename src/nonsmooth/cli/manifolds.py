"""`nonsmooth manifolds`: the stable and unstable manifolds of a saddle periodic orbit (found
first by Newton shooting, as `nonsmooth orbit`), their homoclinic points, and a figure over the
basins."""

from __future__ import annotations

import math
from typing import Annotated, Optional

import typer

from ..errors import ParameterError
from .analyses import V0Opt, X0Opt
from .app import app
from .common import (DEFAULT_MODEL, AtolOpt, ModelOpt, OutOpt, PlotOpt, PresetOpt, RtolOpt,
                     SectionPhaseOpt, SetOpt, U0Opt, check_outputs, echo_written, load_params,
                     preset_label, resolve_method, save_outputs)
from .stability import EXIT_NOT_FOUND, OrbitMethodOpt, print_table


@app.command("manifolds")
def manifolds_cmd(
    model: ModelOpt = DEFAULT_MODEL,
    preset: PresetOpt = None,
    set_: SetOpt = None,
    k: Annotated[int, typer.Option("--k", help="period of the saddle in forcing periods")] = 1,
    point: Annotated[int, typer.Option(
        "--point", help="which of a period-k saddle's k section points (0 ... k-1)")] = 0,
    x0: X0Opt = -1.5,
    v0: V0Opt = 0.25,
    u0: U0Opt = None,
    x: Annotated[tuple[float, float], typer.Option(
        "--x", help="window of X (of the first of --axes) the branches are grown in: MIN MAX")] = (-3.0, 3.0),
    v: Annotated[tuple[float, float], typer.Option(
        "--v", help="window of V (of the second of --axes): MIN MAX")] = (-3.0, 3.0),
    spacing: Annotated[Optional[float], typer.Option(
        "--spacing", help="largest distance between consecutive points (default: 1/200 of "
                          "the window's diagonal)")] = None,
    length: Annotated[Optional[float], typer.Option(
        "--length", help="largest arc length of a branch (default: 4 window diagonals)")] = None,
    axes: Annotated[Optional[str], typer.Option(
        "--axes", show_default=False,
        help="the two state components of the window, A,B (--x and --v are their ranges); "
             "with more than two, the stable manifold is traced in their plane through the "
             "saddle; default: the first two")] = None,
    stable: Annotated[bool, typer.Option(
        "--stable/--no-stable", help="also the stable manifold (a search method)")] = True,
    basins_grid: Annotated[int, typer.Option(
        "--basins-grid", help="draw the figure over the basins on this grid (0: none)")] = 0,
    method: OrbitMethodOpt = None,
    rtol: RtolOpt = 1e-10,
    atol: AtolOpt = 1e-12,
    section_phase: SectionPhaseOpt = 0.0,
    out: OutOpt = None,
    plot: PlotOpt = None,
):
    """The stable and unstable manifolds of the saddle found from (x0, v0) by Newton shooting
    (default: Fig. 7's saddle): both branches of each, grown in the window (--x, --v), their
    homoclinic points, and a figure over the basins (--basins-grid). Exit status 1 when no
    orbit was found from the start, 2 when the orbit found is not a saddle."""
    params = load_params(preset, set_, model, "fig7", method=method or "exact")
    from ..checks import (check_axes, check_int, check_positive, check_solver_options,
                          check_window)
    if method is None and "exact" in params.model.methods:
        method = "exact"
    method = resolve_method(params, method)
    preset = preset_label(params, preset, "fig7")
    check_int("k", k, 1)
    if check_int("point", point, 0) >= k:
        raise ParameterError(f"point: a period-{k} orbit has section points 0 ... {k - 1}, "
                             f"got {point}")
    grid = check_int("basins_grid", basins_grid, 0)
    check_window(x, v)
    for name, val in (("spacing", spacing), ("length", length)):
        if val is not None:
            check_positive(name, val)
    check_axes(params.model, axes)
    check_solver_options(rtol, atol, section_phase)
    check_outputs(out, plot)
    from ..analysis.manifolds import BRANCH_NAMES, manifolds  # (after the checks)
    from ..analysis.stability import periodic_orbit
    orbit = periodic_orbit(params, k=k, x0=x0, v0=v0, u0=u0, method=method, rtol=rtol,
                           atol=atol, section_phase=section_phase)
    if orbit.attrs["status"] != "converged":
        typer.echo(f"error: manifolds: no period-{k} orbit found from (x0, v0) = ({x0:g}, "
                   f"{v0:g}): {orbit.attrs['status']}; try another start (--x0, --v0, --u0)",
                   err=True)
        raise typer.Exit(EXIT_NOT_FOUND)
    from ..sweep import Progress
    with Progress("manifolds") as bar:
        ds = manifolds(params, orbit, x=x, v=v, spacing=spacing, length=length, stable=stable,
                       point=point, axes=axes, progress=bar)
    bas = None
    if plot is not None and grid:
        from ..analysis.basins import basins
        from ..io import component_names, components
        state = list(params.model.state_names)
        names = component_names(state)
        plane = [state[names.index(c)] for c in ds.attrs["axes"].split()]
        # the grid's plane through the saddle (its other components the saddle's)
        extra = ({} if params.model.n == 2 and plane == state[:2] else dict(
            axes=plane, u0=[float(c) for c in components(ds, prefix="saddle_").values]))
        bas = basins(params, x=x, v=v, grid=grid, method=method, rtol=rtol, atol=atol,
                     lyapunov=False, section_phase=section_phase, **extra)
    from ..plot.manifolds import plot_manifolds
    save_outputs(ds, preset, out, plot, lambda d: plot_manifolds(d, basins=bas))
    mu = ds.multiplier_real.values + 1j * ds.multiplier_imag.values
    ca, cb = ds.attrs["axes"].split()
    typer.echo(f"{preset} ({method}): saddle of period {k} at ({ca}, {cb}) = "
               f"({float(ds['saddle_' + ca]):+.6g}, {float(ds['saddle_' + cb]):+.6g}), "
               f"multipliers "
               + ", ".join(f"{m.real:.6g}" if m.imag == 0 else f"{m:.6g}" for m in mu))
    flag = ds.branch.values
    rows = []
    for b in range(ds.sizes["branch_index"]):
        end = float(ds["end_" + ca][b]), float(ds["end_" + cb][b])
        rows.append((BRANCH_NAMES[b], str(int((flag == b).sum())),
                     ds.attrs[f"status_{BRANCH_NAMES[b]}"],
                     f"({end[0]:+.5g}, {end[1]:+.5g})" if math.isfinite(end[0]) else "-"))
    print_table(("branch", "points", "status", "end"), rows)
    if stable:
        n = ds.sizes["crossing"]
        typer.echo(f"homoclinic points: {n}" + (
            f" (smallest crossing angle {math.degrees(float(ds.crossing_angle.min())):.3g} deg)"
            if n else ""))
        typer.echo(f"stable manifold: {ds.attrs['stable_method']}")
    echo_written(out, plot)
