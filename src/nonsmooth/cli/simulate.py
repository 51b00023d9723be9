"""`nonsmooth simulate` and `nonsmooth presets`."""

from __future__ import annotations

from typing import Annotated, Optional

import typer

from .app import app
from .common import (extent_text, ShowOpt, U0Opt, DEFAULT_MODEL, SectionPhaseOpt, AtolOpt, MethodOpt, ModelOpt, OutOpt, PlotOpt, PresetOpt, RtolOpt, SetOpt,
                     check_outputs, echo_written, load_params, preset_label,
                     require_output, resolve_method, save_outputs)


@app.command("simulate")
def simulate_cmd(
    model: ModelOpt = DEFAULT_MODEL,
    preset: PresetOpt = None,
    set_: SetOpt = None,
    periods: Annotated[int, typer.Option(help="recorded forcing periods")] = 10,
    transient: Annotated[int, typer.Option(help="forcing periods discarded first")] = 0,
    samples_per_period: Annotated[Optional[int], typer.Option(
        help="samples per forcing period  [default: that of nonsmooth.simulate, 200]",
        show_default=False)] = None,
    x0: Annotated[float, typer.Option(help="initial X")] = 0.0,
    v0: Annotated[float, typer.Option(help="initial V")] = 0.0,
    u0: U0Opt = None,
    method: MethodOpt = None,
    rtol: RtolOpt = 1e-8,
    atol: AtolOpt = 1e-10,
    section_phase: SectionPhaseOpt = 0.0,
    show: ShowOpt = None,
    out: OutOpt = None,
    plot: PlotOpt = None,
):
    """Integrate one trajectory; save every state component and the region over time (netCDF)
    and a Fig. 3-style plot."""
    params = load_params(preset, set_, model, "table1", method=method)
    method = resolve_method(params, method)
    preset = preset_label(params, preset, "table1")
    from ..plot.common import check_show
    pair = check_show(show, params.model.state_names)
    require_output(out, plot)
    from ..checks import check_int, check_solver_options  # (here before the kernels load)
    check_solver_options(rtol, atol, section_phase)
    check_outputs(out, plot)
    check_int("periods", periods, 1)
    check_int("transient", transient, 0)
    if samples_per_period is not None:
        check_int("samples_per_period", samples_per_period, 1)
    from ..simulate import mask_names, simulate
    from .analyses import _progress
    spp = {} if samples_per_period is None else {"samples_per_period": samples_per_period}
    with _progress("simulate") as prog:
        ds = simulate(params, periods=periods, transient=transient, x0=x0, v0=v0, u0=u0, method=method,
                      rtol=rtol, atol=atol, section_phase=section_phase, progress=prog, **spp)
    from ..plot.time_response import plot_time_response
    save_outputs(ds, preset, out, plot, lambda d: plot_time_response(d, show=pair))
    typer.echo(f"{preset}: {periods} periods after {transient}, {extent_text(ds, params.model)}, "
               f"{params.model.mode_word} visited: "
               f"{', '.join(mask_names(ds.regions_visited))}")
    echo_written(out, plot)


@app.command("presets")
def presets_cmd():
    """List the built-in parameter sets and where they come from in the paper."""
    from ..models.support import PRESETS, preset as get
    for name, (_, source) in PRESETS.items():
        p = get(name)
        vals = ", ".join(f"{k}={v:g}" for k, v in p.as_dict().items())
        typer.echo(f"{name:8s} {vals}\n         source: {source}")
