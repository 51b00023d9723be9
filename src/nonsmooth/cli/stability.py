"""`nonsmooth lyapunov` (Lyapunov spectrum) and `nonsmooth orbit` (periodic orbit by Newton
shooting, with its Floquet multipliers)."""

from __future__ import annotations

import math
from typing import Annotated, Optional

import typer

from .analyses import TransientOpt, V0Opt, X0Opt, _progress
from .app import app
from .common import (extent_text, U0Opt, DEFAULT_MODEL, SectionPhaseOpt, AtolOpt, MethodOpt, ModelOpt, OutOpt, PlotOpt, PresetOpt, RtolOpt, SetOpt, ShowOpt,
                     check_outputs, echo_written, load_params, preset_label, resolve_method,
                     save_outputs)

#: ``orbit`` exits with this status, and one line, when Newton's iteration found no orbit.
EXIT_NOT_FOUND = 1

OrbitMethodOpt = Annotated[Optional[str], typer.Option(
    "--method", show_default=False,
    help="exact (eta = 0; event-driven) or smooth (switch model, RKF45); default: exact, or "
         "the model's first method if it has no exact one")]


def print_table(columns, rows, title: str | None = None) -> None:
    """A small rich table on stdout (no colours or markup from the values)."""
    from rich import box
    from rich.console import Console
    from rich.table import Table

    table = Table(*columns, title=title, box=box.SIMPLE_HEAD, title_justify="left",
                  pad_edge=False, show_edge=False)
    for row in rows:
        table.add_row(*row)
    Console(highlight=False, soft_wrap=False).print(table)


def _num(x: float, fmt: str = "+.6g") -> str:
    return format(x, fmt) if math.isfinite(x) else str(x)


def _err(x: float) -> str:
    return f"± {x:.2g}" if math.isfinite(x) else "-"


def _verdict_reason(cls: int) -> str:
    from ..analysis.stability import CHAOTIC, N_SIGMA, PERIODIC, QUASI_PERIODIC
    return {CHAOTIC: f"lambda1 > 0 by more than {N_SIGMA:g} standard errors",
            QUASI_PERIODIC: f"lambda1 within {N_SIGMA:g} standard errors of 0",
            PERIODIC: f"lambda1 < 0 by more than {N_SIGMA:g} standard errors: a stable "
                      f"periodic orbit; `nonsmooth poincare` gives its period"}.get(cls, "")


@app.command("lyapunov")
def lyapunov_cmd(
    model: ModelOpt = DEFAULT_MODEL,
    preset: PresetOpt = None,
    set_: SetOpt = None,
    periods: Annotated[int, typer.Option(
        "--periods", help="forcing periods averaged over")] = 10000,
    transient: TransientOpt = 1000,
    x0: X0Opt = 0.0,
    v0: V0Opt = 0.0,
    u0: U0Opt = None,
    blocks: Annotated[int, typer.Option(
        "--blocks", help="block means for the standard errors (>= 2)")] = 20,
    method: MethodOpt = None,
    rtol: RtolOpt = 1e-8,
    atol: AtolOpt = 1e-10,
    section_phase: SectionPhaseOpt = 0.0,
    out: OutOpt = None,
    plot: PlotOpt = None,
):
    """Lyapunov spectrum of the trajectory from (x0, v0) (Benettin's method on the variational
    equations with saltation matrices): exponents per unit time and per forcing period with
    standard errors, their sum and a verdict (chaotic, quasi-periodic, not settled)."""
    params = load_params(preset, set_, model, "table3", method=method)
    from ..checks import check_int, check_solver_options
    method = resolve_method(params, method)
    preset = preset_label(params, preset, "table3")
    check_int("periods", periods, 1)
    check_int("transient", transient, 0)
    check_int("blocks", blocks, 2)
    check_solver_options(rtol, atol, section_phase)
    check_outputs(out, plot)
    from ..analysis.stability import lyapunov  # (after the checks: the kernels load with it)
    with _progress("lyapunov") as prog:
        ds = lyapunov(params, periods=periods, transient=transient, x0=x0, v0=v0, u0=u0,
                      method=method, rtol=rtol, atol=atol, section_phase=section_phase, blocks=blocks, progress=prog)
    from ..plot.stability import plot_lyapunov
    save_outputs(ds, preset, out, plot, plot_lyapunov)
    T = float(ds.attrs["forcing_period"])
    typer.echo(f"{preset} ({method}): {periods} periods after {transient}, T = {T:.6g} s")
    rows = [(str(int(i)), _num(float(ds.exponent[j])), _err(float(ds.stderr[j])),
             _num(float(ds.exponent_per_period[j])), _err(float(ds.stderr[j]) * T))
            for j, i in enumerate(ds.i.values)]
    rows.append(("sum", _num(float(ds.exponent_sum)), "",
                 _num(float(ds.exponent_sum) * T), ""))
    print_table(("i", "exponent [1/s]", "s.e.", "per period", "s.e."), rows)
    reason = _verdict_reason(int(ds.lyapunov_class))
    typer.echo(f"verdict: {ds.attrs['verdict']}" + (f" ({reason})" if reason else ""))
    echo_written(out, plot)


@app.command("orbit")
def orbit_cmd(
    model: ModelOpt = DEFAULT_MODEL,
    preset: PresetOpt = None,
    set_: SetOpt = None,
    k: Annotated[int, typer.Option("--k", help="period of the orbit in forcing periods")] = 1,
    x0: X0Opt = 0.0,
    v0: V0Opt = 0.0,
    u0: U0Opt = None,
    transient: Annotated[int, typer.Option(
        "--transient", help="forcing periods run from (x0, v0) before Newton starts")] = 0,
    tol: Annotated[float, typer.Option(
        "--tol", help="Newton tolerance: |P^k(z) - z| <= tol (1 + |z|)")] = 1e-10,
    max_iter: Annotated[int, typer.Option("--max-iter", help="Newton iterations at most")] = 40,
    method: OrbitMethodOpt = None,
    rtol: RtolOpt = 1e-10,
    atol: AtolOpt = 1e-12,
    section_phase: SectionPhaseOpt = 0.0,
    out: OutOpt = None,
    plot: PlotOpt = None,
    show: ShowOpt = None,
):
    """A k-periodic orbit, stable or unstable, by Newton shooting from (x0, v0): section
    points, Floquet multipliers, stability, max/min X and contact fraction; a phase portrait
    with the multipliers (in the plane --show names). Exit status 1 when no orbit was found."""
    params = load_params(preset, set_, model, "fig7", method=method or "exact")
    from ..checks import check_int, check_positive, check_solver_options
    if method is None and "exact" in params.model.methods:
        method = "exact"
    method = resolve_method(params, method)
    preset = preset_label(params, preset, "fig7")
    check_int("k", k, 1)
    check_int("transient", transient, 0)
    check_int("max_iter", max_iter, 1)
    check_positive("tol", tol)
    check_solver_options(rtol, atol, section_phase)
    check_outputs(out, plot)
    from ..plot.common import check_show
    pair = check_show(show, params.model.state_names)
    from ..analysis.stability import periodic_orbit  # (after the checks)
    ds = periodic_orbit(params, k=k, x0=x0, v0=v0, u0=u0, method=method, transient=transient,
                        tol=tol, max_iter=max_iter, rtol=rtol, atol=atol,
                      section_phase=section_phase)
    a = ds.attrs
    if a["status"] != "converged":
        names = params.model.state_names
        start = (f"(x0, v0) = ({x0:g}, {v0:g})" if u0 is None else
                 ", ".join(f"{nm}={float(x):g}" for nm, x in zip(names, a["u0"])))
        typer.echo(f"error: orbit: no period-{k} orbit found from {start}: "
                   f"{a['status']} after {a['iterations']} iterations (residual "
                   f"{a['residual']:.3g}); try another start (--x0, --v0 or --u0), --transient "
                   f"or --max-iter", err=True)
        raise typer.Exit(EXIT_NOT_FOUND)
    from ..io import components
    from ..plot.stability import multiplier_value, plot_orbit
    save_outputs(ds, preset, out, plot, lambda d: plot_orbit(d, show=pair))
    typer.echo(f"{preset} ({method}): period-{k} orbit converged in {a['iterations']} "
               f"iteration{'' if a['iterations'] == 1 else 's'} (residual {a['residual']:.3g})")
    print_table(("point",) + tuple(f"{nm}(jT)" for nm in params.model.state_names),
                [(str(j),) + tuple(_num(float(x))
                                   for x in components(ds, suffix="_section").values[j])
                 for j in range(ds.sizes["point"])])
    print_table(("multiplier", "mu", "|mu|"),
                [(str(j + 1), multiplier_value(ds, j, 6), f"{float(ds.multiplier_abs[j]):.6g}")
                 for j in range(ds.sizes["multiplier"])])
    mu1 = float(ds.multiplier_abs[0]) if ds.sizes["multiplier"] else math.nan
    rel = "<" if a["verdict"] == "stable" else "=" if a["verdict"] == "neutral" else ">"
    typer.echo(f"verdict: {a['verdict']} (|mu1| = {mu1:.6g} {rel} 1)")
    typer.echo(f"{extent_text(ds, params.model)}, contact fraction {float(ds.contact_fraction):.4g}")
    echo_written(out, plot)
