"""Options and helpers shared by the CLI commands (keep commands thin).

Nothing heavy is imported here (no numpy, numba, xarray or matplotlib): ``nonsmooth --help``
only needs the options. A command imports what it computes with inside its function.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Optional

import typer

from ..errors import OutputError, ParameterError
from .._builtin import DEFAULT_MODEL

PresetOpt = Annotated[Optional[str], typer.Option(
    "--preset", "-p", show_default=False,
    help="parameter set: the paper's (see `nonsmooth presets`) for --model support, else one of "
         "the model's presets (see `nonsmooth models NAME`); default: the command's paper set "
         "for support, the model's defaults otherwise")]
ModelOpt = Annotated[str, typer.Option(
    "--model", "-m", help="built-in model (see `nonsmooth models`) or path/to/file.py:NAME "
                          "(a Model defined in your script)")]
SetOpt = Annotated[Optional[list[str]], typer.Option(
    "--set", "-s", help="override a parameter, NAME=VALUE (repeatable)")]
OutOpt = Annotated[Optional[Path], typer.Option("--out", "-o", help="netCDF result file")]
PlotOpt = Annotated[Optional[Path], typer.Option(
    "--plot", help="figure file, format from the suffix: .png, .pdf, .svg, ... (none: PNG)")]
MethodOpt = Annotated[Optional[str], typer.Option(
    "--method", show_default=False,
    help="smooth (switch model, RKF45) or exact (eta = 0; event-driven: --set eta=... is "
         "accepted and ignored, the exact model has no band), or another method of the model "
         "(support: smooth_eq12, the convex transition fields of eq. 12; smooth_closed_form, "
         "eq. 13 solved exactly); default: smooth, or "
         "the model's first method if it has no smooth one")]
RtolOpt = Annotated[float, typer.Option("--rtol", help="relative tolerance")]
AtolOpt = Annotated[float, typer.Option("--atol", help="absolute tolerance")]
SectionPhaseOpt = Annotated[float, typer.Option(
    "--section-phase", help="forcing phase (radians, 0 <= phase < 2 pi) of the stroboscopic "
                            "section t = t_s + kT: the trajectory starts there (continuation "
                            "moves it off events that fall on it by itself)")]
U0Opt = Annotated[Optional[str], typer.Option(
    "--u0", show_default=False,
    help="initial state of any components, NAME=VALUE,... in the model's state names (e.g. "
         "X=0.1,Y=-0.2 for impact_2dof; the others start at 0), instead of --x0/--v0")]
ShowOpt = Annotated[Optional[str], typer.Option(
    "--show", show_default=False,
    help="the two state components the figure shows, A,B (e.g. X,Y for impact_2dof); default: "
         "the first two (X, V)")]


def _workers_value(value: Optional[int]) -> Optional[int]:
    """--workers, checked with the other options (before the kernels load)."""
    from ..checks import check_workers
    check_workers(value)
    return value


WorkersOpt = Annotated[Optional[int], typer.Option("--workers", "-j", callback=_workers_value,
                                                   help="threads (default, or 0: all cores)")]
DaskOpt = Annotated[Optional[str], typer.Option(
    "--dask", show_default=False,
    help="run the chunks on a Dask cluster: a scheduler address (tcp://host:8786), or local "
         "/ local:N to start N local worker processes; default: this machine's cores")]


#: Output paths this run was asked for -> the file each is written to (a figure without
#: suffix gets ``.png``); also tells the message of an interrupted run what was not written.
planned: dict[Path, Path] = {}


def get_model(name: str):
    """The model ``--model`` names (a built-in name or ``path/to/file.py:NAME``); a one-line
    ParameterError otherwise."""
    from ..models import model
    return model(name)


def load_params(preset: str | None, sets: list[str] | None, model: str = DEFAULT_MODEL,
                default_preset: str | None = None, method: str | None = None):
    """The parameters of ``model``: one of its presets (``None``: the command's paper set
    ``default_preset`` for the default model, the paper's; the model's defaults for any other)
    with ``--set`` overrides applied. Every error names the field.

    With ``method="exact"`` an ``eta`` override (the smoothed model's band) is not applied:
    the exact model has no band, so ``--set eta=0`` is accepted there (the value must still be
    a number) and the preset's eta, unused, stays in the parameters."""
    m = get_model(model)
    if method == "exact" and "exact" in m.methods and "eta" in m.param_names:
        sets = _without_eta(sets)
    values = _assignments(sets, m)
    preset = preset or _default_preset(m, default_preset)
    base = m.preset(preset) if preset is not None else m.params()
    return base.replace(**values) if values else base


def _default_preset(m, default_preset: str | None) -> str | None:
    """The command's paper set where ``m`` is the paper's (built-in default) model."""
    paper = m.name == DEFAULT_MODEL and m.source == "built-in" and default_preset in m.presets
    return default_preset if paper else None


def _without_eta(items) -> list:
    """``--set`` items less those assigning eta (checked to be numbers)."""
    out = []
    for item in items or ():
        name, _, value = item.partition("=")
        if name.strip() == "eta":
            try:
                float(value)
            except ValueError:
                raise ParameterError(f"eta: expected a number, got {value.strip()!r}") from None
            continue
        out.append(item)
    return out


def _assignments(items, m) -> dict:
    """``--set NAME=VALUE`` items checked against the parameters of model ``m``."""
    out = {}
    for item in items or ():
        if "=" not in item:
            raise ParameterError(f"--set {item}: expected NAME=VALUE")
        name, _, value = item.partition("=")
        name = name.strip()
        m.param(name)  # one line naming the field (and the model that has it)
        try:
            out[name] = float(value)
        except ValueError:
            raise ParameterError(f"{name}: expected a number, got {value.strip()!r}") from None
    return out


def _number(v) -> str:
    return f"{v:.10g}" if isinstance(v, float) else str(v)


class PresetLabel(str):
    """The parameter set as the command's summary line names it: the preset, then what
    ``--set`` changed in it ("table3 with omega=0.92"). ``name`` is the preset alone (the
    result file's ``preset`` attribute), ``changes`` the changed values ("omega=0.92", the
    ``preset_changes`` attribute; empty without ``--set``)."""

    def __new__(cls, name: str, changes: str = ""):
        self = super().__new__(cls, f"{name} with {changes}" if changes else name)
        self.name = name
        self.changes = changes
        return self


def preset_label(params, preset: str | None, default_preset: str | None = None) -> PresetLabel:
    """What the outputs call the parameter set ``params`` (from :func:`load_params`): the
    preset (``model/preset`` for a model other than the paper's), or ``model (defaults)``,
    with the values ``--set`` changed in it (:class:`PresetLabel`)."""
    m = params.model
    preset = preset or _default_preset(m, default_preset)
    base = m.preset(preset) if preset is not None else m.params()
    changes = ", ".join(f"{k}={_number(getattr(params, k))}" for k in m.param_names
                        if getattr(params, k) != getattr(base, k))
    if preset and m.name == DEFAULT_MODEL and m.source == "built-in":
        return PresetLabel(preset, changes)
    return PresetLabel(f"{m.name}/{preset}" if preset else f"{m.name} (defaults)", changes)


def resolve_method(params, method: str | None) -> str:
    """``--method`` or, not given, ``smooth`` where the model has it, else its first method."""
    methods = params.model.methods
    if method is None:
        return "smooth" if "smooth" in methods else next(iter(methods))
    params.model.method(method)  # one-line error for an unknown method
    return method


def check_outputs(out: Path | None, plot: Path | None, **figures: Path | None) -> None:
    """Fail before computing if an output cannot be written or a figure format is unknown
    (``figures``: further figure options, e.g. ``orbits_plot=path``, named after the option)."""
    from ..io import NETCDF_SUFFIXES, check_writable, figure_formats, figure_path

    if out is not None:
        suffix = Path(out).suffix.lower()
        if suffix not in NETCDF_SUFFIXES:
            hint = " (a figure: --plot)" if suffix[1:] in figure_formats() else ""
            raise OutputError(f"output: {str(out)!r}: a result is a netCDF file, give a name "
                              f"ending in .nc{hint}")
        planned[Path(out)] = check_writable(out, "output")
    for what, path in {"plot": plot, **figures}.items():
        if path is not None:
            planned[Path(path)] = figure_path(path, what.replace("_", "-"))


def require_output(out: Path | None, plot: Path | None) -> None:
    if out is None and plot is None:
        raise ParameterError("output: give -o FILE.nc and/or --plot FILE.png")


def chunk_store(out: Path | None, dask: str | None = None):
    """The chunk store of a sweep written to ``out`` (``<out>.chunks``: finished chunks are
    kept there until the result file is written, and a re-run with the same ``-o`` resumes
    from them; none without ``-o``) and the checked ``--dask`` engine."""
    from ..chunks import check_engine, store_for
    return store_for(out), check_engine(dask)


def save_outputs(ds, preset: str, out: Path | None, plot: Path | None, figure=None,
                 store=None) -> None:
    """Record the preset (and what ``--set`` changed in it), write the netCDF file and render
    ``figure(ds)`` (a plot function: Dataset in, Figure out) to ``plot`` where asked (each
    file written atomically). Once the result file is written, this run's chunk ``store``
    (:func:`chunk_store`) is removed."""
    from ..io import save_dataset, save_figure

    ds.attrs["preset"] = getattr(preset, "name", preset)
    if getattr(preset, "changes", ""):
        ds.attrs["preset_changes"] = preset.changes
    if out is not None:
        save_dataset(ds, out)
        if store is not None:
            from ..chunks import remove_store
            remove_store(store)
    if plot is not None and figure is not None:
        save_figure(figure(ds), plot)


def extent_text(ds, model) -> str:
    """'max X = ..., min X = ...' of a result's ``max_X`` / ``min_X``, named by the model's
    first state component (the bouncing ball's Z)."""
    x = model.state_names[0]
    return f"max {x} = {float(ds.max_X):.6g}, min {x} = {float(ds.min_X):.6g}"


def echo_written(*paths) -> None:
    """Print ``wrote <file>`` for each output path asked for (None skipped), under the name
    of the file actually written (a figure without suffix got ``.png``)."""
    for p in paths:
        if p is not None:
            typer.echo(f"wrote {planned.get(Path(p), p)}")
