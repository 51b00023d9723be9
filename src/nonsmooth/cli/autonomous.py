"""`nonsmooth limit-cycle`, `nonsmooth surface-bifurcation` and `nonsmooth equilibria`:
self-excited (unforced) systems, whose limit cycles have unknown periods and whose sections are
surfaces (issue 23, item 3)."""

from __future__ import annotations

from typing import Annotated, Optional

import typer

from .analyses import V0Opt, X0Opt
from .app import app
from .common import (DEFAULT_MODEL, AtolOpt, ModelOpt, OutOpt, PlotOpt, PresetOpt, RtolOpt,
                     SetOpt, U0Opt, check_outputs, echo_written, load_params, preset_label,
                     resolve_method, save_outputs)
from .stability import EXIT_NOT_FOUND, OrbitMethodOpt, _num, print_table

SectionOpt = Annotated[str, typer.Option(
    "--section", help="section surface, an expression in the state (parameters "
                      "allowed), e.g. V, 'X - 0.5' or 'X**2 + V**2 - 4'")]
DirectionOpt = Annotated[str, typer.Option(
    "--direction", "--crossing",
    help="crossings counted: decreasing (the surface's expression goes from positive to "
         "negative), increasing or both")]

MaxTimeOpt = Annotated[float, typer.Option(
    "--max-time", help="time allowed to reach the next crossing")]


def _method(params, method):
    if method is None and "exact" in params.model.methods:
        method = "exact"
    return resolve_method(params, method)


def _check_flow(params, section, direction, rtol, atol, max_time):
    """The section surface, the tolerances and max_time of a command on a section, checked
    before the kernels load (the analysis checks them again)."""
    from ..checks import check_positive, check_solver_options
    from ..section_surface import parse_section
    parse_section(params, (section, direction))
    check_solver_options(rtol, atol)
    check_positive("max_time", max_time)


@app.command("limit-cycle")
def limit_cycle_cmd(
    model: ModelOpt = "stick_slip",
    preset: PresetOpt = None,
    set_: SetOpt = None,
    section: SectionOpt = "V",
    direction: DirectionOpt = "decreasing",
    x0: X0Opt = 0.0,
    v0: V0Opt = 0.0,
    u0: U0Opt = None,
    transient: Annotated[int, typer.Option(
        "--transient", help="crossings of the section before Newton starts (>= 1)")] = 20,
    tol: Annotated[float, typer.Option("--tol", help="Newton tolerance")] = 1e-10,
    max_time: MaxTimeOpt = 1e4,
    method: OrbitMethodOpt = None,
    rtol: RtolOpt = 1e-10,
    atol: AtolOpt = 1e-12,
    out: OutOpt = None,
):
    """A limit cycle of a self-excited system (its forcing amplitude 0), stable or unstable, by
    Newton shooting on a section surface: its period, section point and nontrivial Floquet
    multipliers. Exit status 1 when no cycle was found."""
    params = load_params(preset, set_, model, method=method)
    from ..checks import check_int, check_positive
    from ..io import components
    method = _method(params, method)
    preset = preset_label(params, preset, None)
    from ..section_surface import check_autonomous
    check_autonomous(params, "limit_cycle")
    _check_flow(params, section, direction, rtol, atol, max_time)
    check_int("transient", transient, 1)
    check_positive("tol", tol)
    check_outputs(out, None)
    from ..analysis.autonomous import limit_cycle  # (after the checks: the kernels load with it)
    ds = limit_cycle(params, (section, direction), x0=x0, v0=v0, u0=u0, transient=transient,
                     method=method, tol=tol, rtol=rtol, atol=atol, max_time=max_time)
    a = ds.attrs
    if a["status"] != "converged":
        typer.echo(f"error: limit-cycle: no cycle found on {a['section']}: {a['status']} "
                   f"(after {a['iterations']} iteration{'' if a['iterations'] == 1 else 's'}); "
                   f"try another start (--x0, --v0, "
                   f"--u0), section or --transient", err=True)
        raise typer.Exit(EXIT_NOT_FOUND)
    save_outputs(ds, preset, out, None)
    typer.echo(f"{preset} ({method}): limit cycle on {a['section']}, period "
               f"{float(ds.period):.10g}, converged in {a['iterations']} "
               f"iteration{'' if a['iterations'] == 1 else 's'} "
               f"(residual {a['residual']:.3g})")
    names = params.model.state_names
    print_table(names, [tuple(_num(float(x)) for x in
                              components(ds, suffix="_section").values)])
    print_table(("multiplier", "mu", "|mu|"),
                [(str(j + 1), f"{complex(ds.multiplier_real[j], ds.multiplier_imag[j]):.6g}",
                  f"{float(ds.multiplier_abs[j]):.6g}") for j in range(ds.sizes["multiplier"])])
    typer.echo(f"verdict: {a['verdict']} (nontrivial multipliers; the trivial 1, along the "
               f"flow, is removed)")
    echo_written(out)


@app.command("equilibria")
def equilibria_cmd(
    model: ModelOpt = "stick_slip",
    preset: PresetOpt = None,
    set_: SetOpt = None,
    param: Annotated[Optional[str], typer.Option(
        "--param", show_default=False,
        help="follow the first equilibrium along this parameter and locate its Hopf points "
             "(with --from, --to, --steps)")] = None,
    from_: Annotated[Optional[float], typer.Option("--from", show_default=False)] = None,
    to: Annotated[Optional[float], typer.Option("--to", show_default=False)] = None,
    steps: Annotated[int, typer.Option("--steps", help="values of --param (>= 2)")] = 50,
    method: OrbitMethodOpt = None,
    out: OutOpt = None,
):
    """Equilibria of a self-excited system (its forcing amplitude 0) in every mode, with their
    eigenvalues; with --param, the first one followed along a parameter with its Hopf
    points."""
    params = load_params(preset, set_, model, method=method)
    from ..errors import ParameterError
    from ..io import components
    from .analyses import value_range
    method = _method(params, method)
    preset = preset_label(params, preset, None)
    from ..section_surface import check_autonomous
    check_autonomous(params, "equilibria" if param is None else "equilibrium_branch")
    check_outputs(out, None)
    if param is not None:
        if from_ is None or to is None:
            raise ParameterError("from: --param needs --from and --to")
        values = value_range(from_, to, steps, f"{param} range")
    from ..analysis.autonomous import equilibria, equilibrium_branch  # (after the checks)
    if param is None:
        ds = equilibria(params, method=method)
        rows = []
        U = components(ds).values
        for i in range(ds.sizes["equilibrium"]):
            ev = ds.eigenvalue_real.values[i] + 1j * ds.eigenvalue_imag.values[i]
            rows.append((params.model.mode_names[int(ds.mode[i])],
                         " ".join(_num(float(x)) for x in U[i]),
                         ", ".join(f"{e:.6g}" for e in ev),
                         "stable" if int(ds.stable[i]) else "unstable"))
        print_table(("mode", "state (" + ", ".join(params.model.state_names) + ")",
                     "eigenvalues", "verdict"), rows)
        if not rows:
            typer.echo(f"{preset}: no equilibrium found")
    else:
        ds = equilibrium_branch(params, param, values, method=method)
        hopf = ds[f"hopf_{ds.attrs['param']}"].values
        typer.echo(f"{preset}: equilibrium in mode "
                   f"{params.model.mode_names[int(ds.mode[0])]} along {param} "
                   f"{from_:g} ... {to:g}: {len(hopf)} Hopf point(s)")
        for h, w in zip(hopf, ds.hopf_frequency.values):
            typer.echo(f"  Hopf at {param} = {h:.10g} (frequency {w:.6g} rad/s)")
    save_outputs(ds, preset, out, None)
    echo_written(out)


@app.command("surface-bifurcation")
def surface_bifurcation_cmd(
    param: Annotated[str, typer.Option("--param", help="the parameter swept")],
    from_: Annotated[float, typer.Option("--from", help="first value")],
    to: Annotated[float, typer.Option("--to", help="last value")],
    model: ModelOpt = "stick_slip",
    preset: PresetOpt = None,
    set_: SetOpt = None,
    steps: Annotated[int, typer.Option("--steps", help="values of --param (>= 2)")] = 100,
    section: SectionOpt = "V",
    direction: DirectionOpt = "decreasing",
    x0: X0Opt = 0.0,
    v0: V0Opt = 0.0,
    u0: U0Opt = None,
    transient: Annotated[int, typer.Option(
        "--transient", help="crossings skipped at each value")] = 100,
    crossings: Annotated[int, typer.Option(
        "--crossings", help="crossings recorded at each value")] = 50,
    max_time: MaxTimeOpt = 1e4,
    method: OrbitMethodOpt = None,
    rtol: RtolOpt = 1e-10,
    atol: AtolOpt = 1e-12,
    show: Annotated[Optional[str], typer.Option(
        "--show", show_default=False,
        help="the state component plotted (default X), or phase (a forced system)")] = None,
    out: OutOpt = None,
    plot: PlotOpt = None,
):
    """Bifurcation diagram on a section surface: at each value of --param (each run
    continuing from the previous one), the crossings of the section after a transient; cycles,
    their crossings per turn, and values that come to rest. A self-excited system, or a forced
    one (an impact map on a switching surface, with the forcing phase: --show phase)."""
    params = load_params(preset, set_, model, method=method)
    from ..checks import check_int
    from ..plot.common import check_show
    from .analyses import value_range
    method = _method(params, method)
    preset = preset_label(params, preset, None)
    params.model.param(param)
    _check_flow(params, section, direction, rtol, atol, max_time)
    check_int("crossings", crossings, 2)
    check_int("transient", transient, 0)
    check_outputs(out, plot)
    if show == "phase":
        from ..errors import ParameterError
        from ..section_surface import is_forced
        if not is_forced(params):
            raise ParameterError("show: phase: only a forced system's crossings have a forcing "
                                 "phase")
    elif show is not None:
        check_show(f"{show},{show}", params.model.state_names)
    values = value_range(from_, to, steps, f"{param} range")
    from ..analysis.autonomous import surface_bifurcation_diagram  # (after the checks)
    from ..plot.autonomous import plot_surface_bifurcation
    ds = surface_bifurcation_diagram(params, param, values, (section, direction),
                                     crossings=crossings, transient=transient, x0=x0, v0=v0,
                                     u0=u0, method=method, rtol=rtol, atol=atol,
                                     max_time=max_time)
    save_outputs(ds, preset, out, plot, lambda d: plot_surface_bifurcation(d, show))
    q = ds.cycle_crossings.values
    cyc = q > 0
    n_rest, n_fail = int(ds.at_equilibrium.sum()), int(ds.status.sum())
    kinds = ", ".join(f"{k} crossing(s) per turn: {int((q == k).sum())}"
                      for k in sorted(set(q[cyc].tolist())))
    typer.echo(f"{preset} ({method}): {values.size} values of {param} on "
               f"{ds.attrs['section']}: {int(cyc.sum())} cycles ({kinds or 'none'}), {n_rest} "
               f"at rest, {values.size - int(cyc.sum()) - n_rest - n_fail} without repetition, "
               f"{n_fail} failed")
    echo_written(out, plot)
