"""`nonsmooth eta-study`: audit the band half-width eta against the exact model (Fig. 4)."""

from __future__ import annotations

from typing import Annotated, Optional

import typer

from ..errors import ParameterError
from .app import app
from .analyses import HiddenIntOpt, _progress
from .common import (DEFAULT_MODEL, AtolOpt, DaskOpt, ModelOpt, OutOpt, PlotOpt, PresetOpt, RtolOpt, SetOpt,
                     WorkersOpt, check_outputs, chunk_store, echo_written, load_params,
                     preset_label, require_output, save_outputs)


def parse_etas(values) -> list[float]:
    """eta values from ``--eta`` options and the extra arguments that follow them; each item may
    hold several values separated by commas. One-line ParameterError naming ``eta``."""
    out = []
    for item in values or ():
        for part in str(item).split(","):
            part = part.strip()
            if not part:
                continue
            try:
                out.append(float(part))
            except ValueError:
                raise ParameterError(f"eta: expected a number, got {part!r}") from None
    if not out:
        raise ParameterError("eta: give at least one value, e.g. --eta 0.28 0.028 0.0028")
    return out


@app.command("eta-study")
def eta_study_cmd(
    more: Annotated[Optional[list[str]], typer.Argument(
        metavar="[ETA]...", show_default=False,
        help="further eta values (so that --eta takes a space-separated list)")] = None,
    eta: Annotated[Optional[list[str]], typer.Option(
        "--eta", "-e", help="band half-width(s) eta to audit, 0 < eta < 0.5: "
                            "--eta 0.28 0.028, --eta 0.28 --eta 0.028 or --eta 0.28,0.028")] = None,
    model: ModelOpt = DEFAULT_MODEL,
    preset: PresetOpt = None,
    set_: SetOpt = None,
    transient: Annotated[int, typer.Option(help="forcing periods discarded first")] = 300,
    record: Annotated[int, typer.Option(help="section points (t = kT) compared")] = 200,
    orbit_periods: Annotated[int, typer.Option(help="periods drawn in each portrait")] = 10,
    points: HiddenIntOpt("--points") = None,
    portrait_periods: HiddenIntOpt("--portrait-periods") = None,
    samples_per_period: Annotated[int, typer.Option(help="portrait samples per period")] = 200,
    method: Annotated[str, typer.Option(
        "--method", help="the smoothed method audited (support: smooth or smooth_eq12)")] = "smooth",
    x0: Annotated[float, typer.Option(help="initial X")] = 0.0,
    v0: Annotated[float, typer.Option(help="initial V")] = 0.0,
    rtol: RtolOpt = 1e-8,
    atol: AtolOpt = 1e-10,
    distance_tol: Annotated[float, typer.Option(
        help="section distance to the exact points counted as agreement (gap units)")] = 1e-3,
    workers: WorkersOpt = None,
    dask: DaskOpt = None,
    out: OutOpt = None,
    plot: PlotOpt = None,
):
    """Compare the smoothed model for several eta with the exact (eta = 0) model: does the
    settled orbit reach Gamma+, its period, the distance of its Poincaré points to the exact
    ones; recommend the largest eta that agrees. Plot: phase portraits as in Fig. 4.
    The values are audited from the largest to the smallest."""
    import math

    from ..checks import check_etas, check_float, check_int, check_solver_options

    record = points if points is not None else record  # deprecated names
    orbit_periods = portrait_periods if portrait_periods is not None else orbit_periods
    etas = sorted(check_etas(parse_etas(list(eta or []) + list(more or []))), reverse=True)
    params = load_params(preset, set_, model, "fig4")
    preset = preset_label(params, preset, "fig4")
    check_int("transient", transient, 0)
    check_int("record", record, 2)
    check_int("orbit_periods", orbit_periods, 1)
    check_int("samples_per_period", samples_per_period, 1)
    if not check_float("distance_tol", distance_tol) >= 0:
        raise ParameterError(f"distance_tol: must be >= 0, got {distance_tol}")
    check_solver_options(rtol, atol)
    require_output(out, plot)
    check_outputs(out, plot)
    from ..analysis.eta_study import eta_study  # (after the checks: the kernels load with it)
    store, engine = chunk_store(out, dask)
    with _progress("eta study") as prog:
        ds = eta_study(params, etas, transient=transient, record=record,
                       orbit_periods=orbit_periods, samples_per_period=samples_per_period,
                       x0=x0, v0=v0, rtol=rtol, atol=atol, distance_tol=distance_tol,
                       method=method,
                       workers=workers, progress=prog,
                       store=store, engine=engine)
    m = params.model
    full = m.contact_text
    col = m.contact_label or "contact"
    from ..plot.eta_study import plot_eta_study
    save_outputs(ds, preset, out, plot, plot_eta_study, store=store)
    typer.echo(f"{preset}: exact model period {int(ds.exact_period) or 'none'}, "
               f"{'reaches' if int(ds.exact_reaches_gamma_plus) else 'never reaches'} {full}")
    typer.echo(f"{'eta':>10s} {col:>7s} {'period':>7s} {'distance':>10s}  agrees")
    for i, e in enumerate(ds["eta"].values):
        typer.echo(f"{e:10.3g} {int(ds.reaches_gamma_plus[i]):7d} {int(ds.period[i]):7d} "
                   f"{float(ds.distance_to_exact[i]):10.3g}  {'yes' if ds.agrees[i] else 'no'}")
    rec = float(ds.recommended_eta)
    typer.echo(f"recommended eta: {rec:.3g}" if math.isfinite(rec) else
               "recommended eta: none of the values agrees with the exact model")
    echo_written(out, plot)
