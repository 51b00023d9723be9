"""`nonsmooth poincare`, `nonsmooth bifurcation`, `nonsmooth resonance`."""

from __future__ import annotations

import math
from typing import Annotated, Optional

import typer

from ..errors import ParameterError
from .app import app
from .common import (extent_text, ShowOpt, U0Opt, DEFAULT_MODEL, SectionPhaseOpt, AtolOpt, DaskOpt, MethodOpt, ModelOpt, OutOpt, PlotOpt, PresetOpt, RtolOpt, SetOpt,
                     WorkersOpt, check_outputs, chunk_store, echo_written, load_params,
                     preset_label, require_output, resolve_method, save_outputs)

FromOpt = Annotated[Optional[float], typer.Option(
    "--from", show_default=False,
    help="first value of the range (default: the command's frequency range, as periods for a "
         "model with a forcing period)")]
ToOpt = Annotated[Optional[float], typer.Option("--to", show_default=False,
                                                help="last value of the range")]


def default_range(params, param: str, lo, hi, omega_lo: float, omega_hi: float):
    """--from/--to, each defaulting to the command's range of forcing frequencies (omega_lo,
    omega_hi): as periods where ``param`` is the model's forcing period
    (``Model.forcing_range``)."""
    if lo is None or hi is None:
        m = params.model
        d = (m.forcing_range(omega_lo, omega_hi) if param == m.forcing_param
             else (omega_lo, omega_hi))
        lo = d[0] if lo is None else lo
        hi = d[1] if hi is None else hi
    return lo, hi
StepsOpt = Annotated[int, typer.Option("--steps", help="number of values (>= 2)")]
TransientOpt = Annotated[int, typer.Option("--transient", help="forcing periods discarded first")]
X0Opt = Annotated[float, typer.Option("--x0", help="initial X")]
V0Opt = Annotated[float, typer.Option("--v0", help="initial V")]
SettleOpt = Annotated[bool, typer.Option(
    "--settle/--no-settle", help="end the transient early once the section has provably settled")]



def HiddenIntOpt(name: str):
    """A hidden integer option: the deprecated name of another option (kept one release)."""
    return Annotated[Optional[int], typer.Option(name, hidden=True)]


def value_range(lo: float, hi: float, steps: int, name: str = "range", branches: int = 1,
                record: int = 0, field: str = "steps"):
    """Evenly spaced values lo ... hi (validated: finite, lo < hi, steps >= 2; ``steps`` values
    of ``branches`` sweeps recording ``record`` periods each must fit in memory, checked
    before the values are built). ``field``: the option that gave ``steps``; an option of
    its own ("values": FROM TO N in one option) gives all three, and the errors name it."""
    import numpy as np
    from ..checks import check_sweep_memory
    one = field != "steps"  # FROM TO N in one option, ``field``
    for end, v in (("from", lo), ("to", hi)):
        if not math.isfinite(v):
            raise ParameterError(f"{field}: {end.upper()} must be finite, got {v}" if one
                                 else f"{end}: must be finite, got {v}")
    if not lo < hi:
        raise ParameterError(
            f"{field}: empty or reversed {name}: FROM {lo:g} must be < TO {hi:g}" if one
            else f"from/to: empty or reversed {name}: --from {lo:g} must be < --to {hi:g}")
    if steps < 2:
        raise ParameterError(f"{field}: N must be >= 2, got {steps}" if one
                             else f"steps: must be >= 2, got {steps}")
    check_sweep_memory(steps, branches, record, field)
    return np.linspace(lo, hi, steps)


def period_text(period: int) -> str:
    """Words for a period code (0 = not periodic, -1 = not settled)."""
    if period > 0:
        return f"period {period}"
    return "not settled (period -1)" if period < 0 else "not periodic (period 0)"


def point_counts(ds) -> str:
    """Counts of periodic, non-periodic, not settled and failed points of a sweep Dataset
    (each point counted once; over all its sweeps)."""
    per = ds.period.values
    ok = ds.status.values == 0
    nsw = ds.sizes["sweep"]
    over = f"over {nsw} sweeps x {per.shape[1]} values: " if nsw > 1 else ""
    return (f"{over}{int((ok & (per > 0)).sum())} periodic, {int((ok & (per == 0)).sum())} "
            f"non-periodic, {int((ok & (per < 0)).sum())} not settled, {int((~ok).sum())} failed")


def _progress(text: str):
    from ..sweep import Progress
    return Progress(text)


@app.command("poincare")
def poincare_cmd(
    model: ModelOpt = DEFAULT_MODEL,
    preset: PresetOpt = None,
    set_: SetOpt = None,
    record: Annotated[int, typer.Option("--record", help="section points recorded")] = 2000,
    points: HiddenIntOpt("--points") = None,
    transient: TransientOpt = 500,
    x0: X0Opt = 0.0,
    v0: V0Opt = 0.0,
    u0: U0Opt = None,
    method: MethodOpt = None,
    rtol: RtolOpt = 1e-8,
    atol: AtolOpt = 1e-10,
    section_phase: SectionPhaseOpt = 0.0,
    orbit_samples: Annotated[int, typer.Option(help="phase-portrait samples per period")] = 200,
    show: ShowOpt = None,
    out: OutOpt = None,
    plot: PlotOpt = None,
):
    """Stroboscopic Poincaré map (t = kT) with period and contact classification; plot like
    Figs. 10 and 12 (phase portrait with its section points, and the map)."""
    params = load_params(preset, set_, model, "table3", method=method)
    from ..checks import check_int, check_solver_options
    if points is not None:  # deprecated name
        record = check_int("points", points, 1)
    method = resolve_method(params, method)
    preset = preset_label(params, preset, "table3")
    check_int("record", record, 1)
    check_int("transient", transient, 0)
    from ..plot.common import check_show
    pair = check_show(show, params.model.state_names)
    require_output(out, plot)
    check_solver_options(rtol, atol, section_phase)
    check_outputs(out, plot)
    from ..analysis.poincare import poincare  # (after the checks: the kernels load with it)
    with _progress("poincare") as prog:
        ds = poincare(params, record=record, transient=transient, x0=x0, v0=v0, u0=u0, method=method,
                      rtol=rtol, atol=atol, section_phase=section_phase, orbit_samples=orbit_samples,
                      progress=prog)
    from ..plot.poincare import plot_poincare
    save_outputs(ds, preset, out, plot, lambda d: plot_poincare(d, show=pair))
    typer.echo(f"{preset}: {period_text(int(ds.period))}{motion_text(ds)}, contact "
               f"{int(ds.contact)}, {extent_text(ds, params.model)}")
    echo_written(out, plot)


def motion_text(ds) -> str:
    """', chaotic (lambda1 = 0.0633 1/s)' for a non-periodic point whose result has the motion
    verdict and lambda1 (a periodic one says nothing more than its period)."""
    if "motion" not in ds or int(ds.period) > 0:
        return ""
    from ..plot.poincare import motion_word
    word = motion_word(ds)
    lam = f" (lambda1 = {float(ds.lambda1):.3g} 1/s)" if "lambda1" in ds else ""
    return f": {word}{lam}"


@app.command("bifurcation")
def bifurcation_cmd(
    model: ModelOpt = DEFAULT_MODEL,
    preset: PresetOpt = None,
    set_: SetOpt = None,
    param: Annotated[Optional[str], typer.Option(
        "--param", show_default=False,
        help="swept parameter, one of the model's; default: its forcing frequency (omega)")] = None,
    from_: FromOpt = None,
    to: ToOpt = None,
    steps: StepsOpt = 400,
    sweep: Annotated[str, typer.Option("--sweep", help="up, down, both or fresh")] = "both",
    transient: TransientOpt = 500,
    record: Annotated[int, typer.Option("--record", help="section points recorded per value")] = 200,
    x0: X0Opt = 0.0,
    v0: V0Opt = 0.0,
    u0: U0Opt = None,
    method: MethodOpt = None,
    rtol: RtolOpt = 1e-8,
    atol: AtolOpt = 1e-10,
    section_phase: SectionPhaseOpt = 0.0,
    settle: SettleOpt = True,
    workers: WorkersOpt = None,
    dask: DaskOpt = None,
    out: OutOpt = None,
    plot: PlotOpt = None,
):
    """Bifurcation diagram of the section X(kT) over a parameter (Figs. 9 and 11)."""
    params = load_params(preset, set_, model, "table3", method=method)
    from ..checks import SWEEPS, check_int, check_solver_options
    method = resolve_method(params, method)
    preset = preset_label(params, preset, "table3")
    from ..checks import check_forced
    check_forced(params, "bifurcation")
    param = params.model.param(param or params.model.forcing_param).name
    from_, to = default_range(params, param, from_, to, 0.8, 1.0)
    if sweep not in SWEEPS:
        raise ParameterError(f"sweep: unknown sweep {sweep!r} (known: {', '.join(SWEEPS)})")
    values = value_range(from_, to, steps, f"{param} range", 2 if sweep == "both" else 1,
                         max(record, 0))
    for v in (values[0], values[-1]):
        params.replace(**{param: float(v)})
    check_int("transient", transient, 0)
    check_int("record", record, 1)
    require_output(out, plot)
    check_solver_options(rtol, atol, section_phase)
    check_outputs(out, plot)
    from ..analysis.bifurcation import bifurcation_diagram  # (after the checks)
    store, engine = chunk_store(out, dask)
    with _progress(f"bifurcation {param} ({sweep})") as prog:
        ds = bifurcation_diagram(params, param, values, sweep=sweep, transient=transient,
                                 record=record, method=method, x0=x0, v0=v0, u0=u0, rtol=rtol,
                                 atol=atol, section_phase=section_phase, settle=settle,
                                 workers=workers, progress=prog, store=store, engine=engine)
    from ..plot.bifurcation import plot_bifurcation
    save_outputs(ds, preset, out, plot, plot_bifurcation, store=store)
    typer.echo(f"{preset}: {param} {from_:g} ... {to:g}, {steps} values, sweep {sweep}: "
               f"{point_counts(ds)}")
    echo_written(out, plot)


@app.command("resonance")
def resonance_cmd(
    model: ModelOpt = DEFAULT_MODEL,
    preset: PresetOpt = None,
    set_: SetOpt = None,
    from_: FromOpt = None,
    to: ToOpt = None,
    steps: StepsOpt = 400,
    transient: TransientOpt = 500,
    record: Annotated[int, typer.Option("--record", help="periods recorded per value")] = 50,
    x0: X0Opt = 0.0,
    v0: V0Opt = 0.0,
    u0: U0Opt = None,
    method: MethodOpt = None,
    rtol: RtolOpt = 1e-8,
    atol: AtolOpt = 1e-10,
    section_phase: SectionPhaseOpt = 0.0,
    settle: SettleOpt = True,
    resolution: Annotated[float, typer.Option(help="bisection resolution of omega_a/b/c")] = 1e-4,
    all_branches: Annotated[bool, typer.Option(
        "--all", help="also every period-1 branch, stable and unstable, by continuation, with "
                      "omega_a (grazing), omega_b, omega_c (folds) located on it")] = False,
    workers: WorkersOpt = None,
    dask: DaskOpt = None,
    out: OutOpt = None,
    plot: PlotOpt = None,
):
    """Resonance curve (max X, min X versus omega, swept up and down with continuation) and
    the frequencies omega_a (contact starts), omega_b, omega_c (jumps), like Fig. 6."""
    params = load_params(preset, set_, model, "fig6a", method=method)
    from ..checks import check_int, check_solver_options
    method = resolve_method(params, method)
    preset = preset_label(params, preset, "fig6a")
    from ..checks import check_forced
    check_forced(params, "resonance")
    w = params.model.forcing_param  # the model's forcing frequency (or period)
    from_, to = default_range(params, w, from_, to, 0.5, 1.6)
    omegas = value_range(from_, to, steps, f"{w} range", 2, max(record, 0))
    for v in (omegas[0], omegas[-1]):
        params.replace(**{w: float(v)})
    check_int("transient", transient, 0)
    check_int("record", record, 1)
    require_output(out, plot)
    check_solver_options(rtol, atol, section_phase)
    check_outputs(out, plot)
    from ..analysis.resonance import resonance_curve  # (after the checks)
    store, engine = chunk_store(out, dask)
    with _progress("resonance (up and down)") as prog:
        ds = resonance_curve(params, omegas, method=method, transient=transient, record=record,
                             x0=x0, v0=v0, u0=u0, rtol=rtol, atol=atol, section_phase=section_phase,
                             settle=settle, resolution=resolution, workers=workers,
                             progress=prog, branches="all" if all_branches else "stable",
                             store=store, engine=engine)
    from ..plot.resonance import plot_resonance
    save_outputs(ds, preset, out, plot, plot_resonance, store=store)
    from ..analysis.resonance import jump_names
    a = ds.attrs
    na, nb, nc = jump_names(ds)   # omega_a, ... or, sweeping a period T, T_a, ...
    typer.echo(f"{preset}: {na} = {a[na]:.5f} (contact starts), "
               f"{nb} = {a[nb]:.5f}, {nc} = {a[nc]:.5f} (jumps; NaN = none)")
    if all_branches:
        typer.echo(f"continuation ({a['branch_status']}): "
                   f"{na} = {a[na + '_continuation']:.8f} (grazing), "
                   f"{nb} = {a[nb + '_continuation']:.8f}, "
                   f"{nc} = {a[nc + '_continuation']:.8f} (folds; NaN = none)")
    echo_written(out, plot)
