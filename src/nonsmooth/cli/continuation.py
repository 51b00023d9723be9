"""`nonsmooth continue`: a branch of periodic orbits followed in one parameter (pseudo-arclength
continuation through folds), with its stability and special points."""

from __future__ import annotations

import math
from typing import Annotated, Optional

import typer

from ..errors import ParameterError
from .analyses import V0Opt, X0Opt
from .app import app
from .common import (U0Opt, DEFAULT_MODEL, SectionPhaseOpt, AtolOpt, ModelOpt, OutOpt, PlotOpt, PresetOpt, RtolOpt, SetOpt,
                     check_outputs, echo_written, load_params, preset_label, resolve_method,
                     save_outputs)
from .autonomous import MaxTimeOpt
from .stability import OrbitMethodOpt, _num, print_table

#: Words for the special-point types (CF flag values of ``special_type``).
SPECIAL_TEXT = {1: "fold (F)", 2: "period doubling (PD)", 3: "Neimark-Sacker (NS)",
                4: "grazing (G)"}


def _check_bounds(bounds) -> tuple[float, float] | None:
    if bounds is None:
        return None
    lo, hi = (float(b) for b in bounds)
    for b in (lo, hi):
        if math.isnan(b):
            raise ParameterError(f"bounds: expected numbers, got {b}")
    if not lo < hi:
        raise ParameterError(f"bounds: empty or reversed range: LO {lo:g} must be < HI {hi:g}")
    return lo, hi


def _multiplier(re: float, im: float) -> str:
    return f"{re:.6g}" if im == 0 else f"{re:.6g}{im:+.6g}j"


@app.command("continue")
def continue_cmd(
    param: Annotated[str, typer.Option(
        "--param", show_default=False, help="the continued parameter, one of the model's "
                                            "(e.g. omega)")],
    model: ModelOpt = DEFAULT_MODEL,
    preset: PresetOpt = None,
    set_: SetOpt = None,
    k: Annotated[int, typer.Option("--k", help="period of the orbits in forcing periods")] = 1,
    x0: X0Opt = 0.0,
    v0: V0Opt = 0.0,
    u0: U0Opt = None,
    transient: Annotated[int, typer.Option(
        "--transient", help="forcing periods run from (x0, v0) before the first orbit's "
                            "Newton search")] = 0,
    direction: Annotated[str, typer.Option(
        "--direction", help="up (the parameter increasing at first) or down")] = "up",
    step: Annotated[float, typer.Option(
        "--step", help="first arclength step (parameter and section point units)")] = 0.01,
    max_step: Annotated[Optional[float], typer.Option(
        "--max-step", show_default=False,
        help="largest arclength step; default 10 x --step")] = None,
    bounds: Annotated[Optional[tuple[float, float]], typer.Option(
        "--bounds", show_default=False,
        help="stop when the parameter leaves LO HI (must contain the start); default: "
             "none")] = None,
    max_points: Annotated[int, typer.Option(
        "--max-points", help="points on the branch at most")] = 400,
    tol: Annotated[float, typer.Option(
        "--tol", help="Newton tolerance of the orbits: |P^k(z) - z| <= tol (1 + |z|)")] = 1e-10,
    method: OrbitMethodOpt = None,
    rtol: RtolOpt = 1e-10,
    atol: AtolOpt = 1e-12,
    section_phase: SectionPhaseOpt = 0.0,
    two_param: Annotated[Optional[str], typer.Option(
        "--two-param", show_default=False,
        help="a second parameter: follow the --special points of the branch as it changes "
             "over --values (a two-parameter curve)")] = None,
    values: Annotated[Optional[tuple[float, float, int]], typer.Option(
        "--values", show_default=False,
        help="FROM TO N: the values of --two-param")] = None,
    special: Annotated[str, typer.Option(
        "--special", help="fold, period_doubling, neimark_sacker or grazing (--two-param)")]
    = "fold",
    section: Annotated[Optional[str], typer.Option(
        "--section", show_default=False,
        help="limit cycles of a self-excited system on this section surface (an expression "
             "in the state, parameters allowed, e.g. V or 'X**2 + V**2 - 4'; default V for a "
             "model without forcing): --k is "
             "then crossings per cycle and --transient crossings before the first Newton "
             "search")] = None,
    crossing: Annotated[str, typer.Option(
        "--crossing", help="with --section: the crossings counted, decreasing, increasing "
                           "or both")] = "decreasing",
    extended: Annotated[Optional[str], typer.Option(
        "--extended", show_default=False,
        help="with --two-param and --special (fold, period_doubling, neimark_sacker or "
             "grazing): continue the branch's first such point as one extended system in (--param, --two-param), through "
             "turning points and cusps, with --two-param going up or down at first (no "
             "--values)")] = None,
    bounds2: Annotated[Optional[tuple[float, float]], typer.Option(
        "--bounds2", show_default=False,
        help="with --extended: stop when --two-param leaves LO HI")] = None,
    max_time: MaxTimeOpt = 1e4,
    out: OutOpt = None,
    plot: PlotOpt = None,
):
    """Continuation of a branch of k-periodic orbits in --param from the orbit found at the
    preset's value (Newton shooting from (x0, v0)): pseudo-arclength, through folds, with the
    Floquet multipliers and stability of every point and the special points located on it
    (fold, period doubling, Neimark-Sacker, grazing); the branch figure, stable solid,
    unstable dashed. With --section (or a model without forcing): the limit cycles of a
    self-excited system on that section surface, their periods unknowns."""
    params = load_params(preset, set_, model, "fig6a", method=method or "exact")
    from ..checks import check_float, check_int, check_positive, check_solver_options
    if method is None and "exact" in params.model.methods:
        method = "exact"
    method = resolve_method(params, method)
    preset = preset_label(params, preset, "fig6a")
    param = params.model.param(param).name
    check_int("k", k, 1)
    check_int("transient", transient, 0)
    check_int("max_points", max_points, 2)
    if direction not in ("up", "down"):
        raise ParameterError(f"direction: expected 'up' or 'down', got {direction!r}")
    check_positive("step", step)
    if max_step is not None and not check_float("max_step", max_step) >= step:
        raise ParameterError(f"max_step: must be >= step ({step:g}), got {max_step:g}")
    bounds = _check_bounds(bounds)
    check_positive("tol", tol)
    check_positive("max_time", max_time)
    check_solver_options(rtol, atol, section_phase)
    lam0 = float(getattr(params, param))
    if bounds is not None and not bounds[0] <= lam0 <= bounds[1]:
        raise ParameterError(f"bounds: {bounds[0]:g} ... {bounds[1]:g} exclude the start "
                             f"{param} = {lam0:g} (set it with --set {param}=VALUE)")
    cycles = section is not None or params.model.autonomous
    sec = (section or "V", crossing) if cycles else None
    if sec is not None:
        from ..section_surface import parse_section
        parse_section(params, sec)  # (a one-line error before the kernels load)
    if extended is not None and values is not None:
        raise ParameterError("values: --extended follows the curve itself; give --bounds2, "
                             "not --values")
    if extended is None and bounds2 is not None:
        raise ParameterError("bounds2: only with --extended")
    if extended is not None:
        return _extended(params, preset, param, two_param, special, extended, bounds2, k, x0,
                         v0, u0, transient, direction, step, max_step, bounds, max_points,
                         method, tol, rtol, atol, section_phase, sec, max_time, out, plot)
    if two_param is not None:
        return _two_parameter(params, preset, param, two_param, values, special, k, x0, v0,
                              step, bounds, max_points, method, tol, out, plot, section_phase,
                              u0, direction, sec, max_time)
    check_outputs(out, plot)
    from ..analysis.continuation import continuation  # (after the checks: the kernels load)
    ds = continuation(params, param, k=k, x0=x0, v0=v0, u0=u0, transient=transient,
                      direction=direction, step=step, max_step=max_step, bounds=bounds,
                      max_points=max_points, method=method, tol=tol, rtol=rtol, atol=atol,
                      section_phase=section_phase, section=sec, max_time=max_time)
    from ..plot.continuation import plot_continuation
    save_outputs(ds, preset, out, plot, plot_continuation)
    lam = ds[param].values
    stable = ds["stable"].values.astype(bool)
    what = (f"limit-cycle branch on {ds.attrs['section']}" if cycles
            else f"period-{k} branch")
    typer.echo(f"{preset} ({method}): {what} in {param}, {lam.size} points from "
               f"{param} = {lam[0]:.6g} to {lam[-1]:.6g} (range {lam.min():.6g} ... "
               f"{lam.max():.6g}), {int(stable.sum())} stable, {int((~stable).sum())} unstable")
    if cycles:
        T = ds["period"].values
        typer.echo(f"periods {float(T.min()):.6g} ... {float(T.max()):.6g}")
    typer.echo(f"status: {ds.attrs['status']}")
    if "section_moved" in ds.attrs:
        typer.echo(f"section moved off an event on it: {ds.attrs['section_moved']}")
    n = ds.sizes["special"]
    if n:
        sp = ds[f"special_{param}"].values
        rows = []
        for i in range(n):
            re = float(ds.special_multiplier_real[i])
            im = float(ds.special_multiplier_imag[i])
            rows.append((SPECIAL_TEXT.get(int(ds.special_type[i]), "?"), f"{sp[i]:.6f}",
                         _multiplier(re, im), _num(abs(complex(re, im)), ".6g"),
                         str(int(ds.special_after_point[i]))))
        print_table(("special point", param, "multiplier", "|mu|", "after point"), rows)
    else:
        typer.echo("no special points")
    echo_written(out, plot)


def _two_parameter(params, preset, param, param2, values, special, k, x0, v0, step, bounds,
                   max_points, method, tol, out, plot, section_phase=0.0, u0=None,
                   direction="up", section=None, max_time=1e4):
    """``nonsmooth continue --two-param``: the curve of --special points in (param, param2)."""
    import numpy as np

    from .analyses import value_range

    params.model.param(param2)
    if values is None:
        raise ParameterError("values: --two-param needs --values FROM TO N")
    grid = value_range(values[0], values[1], values[2], f"{param2} values", field="values")
    check_outputs(out, plot)
    from ..analysis.continuation import two_parameter_curve  # (after the checks)
    from ..plot.continuation import plot_two_parameter
    ds = two_parameter_curve(params, param, param2, grid, special=special, k=k, x0=x0, v0=v0,
                             u0=u0,
                             bounds=bounds, step=step, max_points=max_points, method=method,
                             tol=tol, section_phase=section_phase, direction=direction,
                             section=section, max_time=max_time)
    save_outputs(ds, preset, out, plot, plot_two_parameter)
    found = int(np.isfinite(ds[param].values).any(axis=1).sum())
    typer.echo(f"{preset} ({method}): {special} points in ({param}, {param2}) at {found} of "
               f"{grid.size} values of {param2}")
    print_table((param2, *[f"{param} #{j}" for j in range(ds.sizes['n'])]),
                [(f"{v:.6g}", *[("-" if not np.isfinite(x) else f"{x:.8f}") for x in row])
                 for v, row in zip(ds[param2].values, ds[param].values)])
    echo_written(out, plot)


def _extended(params, preset, param, param2, special, way, bounds2, k, x0, v0, u0, transient,
              direction, step, max_step, bounds, max_points, method, tol, rtol, atol,
              section_phase, sec, max_time, out, plot):
    """``nonsmooth continue --two-param P2 --extended up|down``: the branch's first fold (or
    period doubling, or grazing) continued as an extended system (``fold_curve``,
    ``period_doubling_curve``, ``grazing_curve``)."""
    if param2 is None:
        raise ParameterError("extended: --extended needs --two-param (the second parameter)")
    if way not in ("up", "down"):
        raise ParameterError(f"extended: expected 'up' or 'down', got {way!r}")
    curves = ("fold", "period_doubling", "grazing", "neimark_sacker")
    if special not in curves:
        raise ParameterError(f"special: --extended follows fold, period_doubling, "
                             f"neimark_sacker or grazing, got {special!r}")
    if sec is not None:
        raise ParameterError("extended: limit cycles on a section are not supported here")
    p2 = params.model.param(param2).name
    check_outputs(out, plot)
    from ..analysis import fold_curve  # (after the checks: the kernels load with it)
    from ..analysis.continuation import continuation
    from ..plot.continuation import plot_special_curve
    br = continuation(params, param, k=k, x0=x0, v0=v0, u0=u0, transient=transient,
                      direction=direction, step=step, max_step=max_step, bounds=bounds,
                      max_points=max_points, method=method, tol=tol, rtol=rtol, atol=atol,
                      section_phase=section_phase, max_time=max_time)
    curve = getattr(fold_curve, f"{special}_curve")  # fold_curve, period_doubling_curve, ...
    ds = curve(params, param, p2, start=br, direction=way, step=step, max_step=max_step,
               bounds=bounds, bounds2=bounds2, max_points=max_points, tol=max(tol, 1e-9),
               rtol=rtol, atol=atol)
    save_outputs(ds, preset, out, plot, plot_special_curve)
    a, b = ds[param].values, ds[p2].values
    typer.echo(f"{preset} ({method}): {special.replace('_', ' ')} of the period-{k} branch at "
               f"{param} = {a[0]:.8g}, {p2} = {b[0]:.8g}, continued in ({param}, {p2}): "
               f"{a.size} points, {p2} from {b.min():.6g} to {b.max():.6g}, {param} from "
               f"{a.min():.6g} to {a.max():.6g}")
    typer.echo(f"status: {ds.attrs['status']}")
    for i in range(ds.sizes["cusp"]):
        typer.echo(f"cusp at {param} = {float(ds['cusp_' + param][i]):.8g}, {p2} = "
                   f"{float(ds['cusp_' + p2][i]):.8g}")
    names = ds["codim2_type"].attrs["flag_meanings"].split()
    for i in range(ds.sizes["codim2"]):
        typer.echo(f"{names[int(ds.codim2_type[i])].replace('_', ' ')} at {param} = "
                   f"{float(ds['codim2_' + param][i]):.8g}, {p2} = "
                   f"{float(ds['codim2_' + p2][i]):.8g}")
    echo_written(out, plot)
