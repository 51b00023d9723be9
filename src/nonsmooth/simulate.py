"""Time response of one trajectory: ``simulate(params, ...) -> xarray.Dataset``."""

from __future__ import annotations

import warnings

import numpy as np
import xarray as xr

from . import status as st
from .errors import IntegrationError, ParameterError
from .integrate.contract import ST_EXTRA, ST_MODE
from .io import apply_state_units, provenance_attrs, state_long_name
from .kernels import Solver, new_state
from .checks import (check_float, check_forced, check_int, check_params,  # noqa: F401
                     component_pair)  # (here first)
from .models.base import ParamsBase


def initial_u(model, x0=0.0, v0=0.0, u0=None) -> np.ndarray:
    """The initial state u (all ``model.n`` components) from ``x0``, ``v0`` (u[0], u[1]; the
    other components 0) or from ``u0``: a sequence of n numbers in the order of
    ``model.state_names``, or a mapping {component name: value} (components it does not name
    start at 0). One-line ParameterErrors name the field."""
    n = model.n
    u = np.zeros(n)
    if u0 is None:
        u[0] = check_float("x0", x0)
        u[1] = check_float("v0", v0)
        return u
    if check_float("x0", x0) != 0.0 or check_float("v0", v0) != 0.0:
        raise ParameterError("u0: give the initial state either as u0 or as x0, v0, not both")
    names = tuple(model.state_names)
    if isinstance(u0, str):
        u0 = parse_components(u0, names, "u0")
    if isinstance(u0, dict):
        for name, value in u0.items():
            if name not in names:
                raise ParameterError(f"u0: unknown component {name!r} (model "
                                     f"{model.name!r} has {', '.join(names)})")
            u[names.index(name)] = check_float(f"u0[{name}]", value)
        return u
    try:
        vals = list(np.asarray(u0, dtype=object).ravel())
    except Exception:  # noqa: BLE001 - anything not array-like
        raise ParameterError(f"u0: expected {n} numbers or a mapping of component names "
                             f"({', '.join(names)}), got {u0!r}") from None
    if len(vals) != n:
        raise ParameterError(f"u0: expected {n} numbers ({', '.join(names)}), got {len(vals)}")
    for i, value in enumerate(vals):
        u[i] = check_float(f"u0[{names[i]}]", value)
    return u


def parse_components(text: str, names, field: str) -> dict:
    """``"X=0.1,Y=-2"`` -> {"X": 0.1, "Y": -2.0} (the CLI's ``--u0``); one-line errors."""
    out = {}
    for part in filter(None, (t.strip() for t in text.split(","))):
        name, sep, value = part.partition("=")
        if not sep:
            raise ParameterError(f"{field}: expected NAME=VALUE pairs separated by commas "
                                 f"(components {', '.join(names)}), got {part!r}")
        out[name.strip()] = value.strip()
    if not out:
        raise ParameterError(f"{field}: empty (components {', '.join(names)})")
    return out


def state_from_u(u) -> np.ndarray:
    """The initial kernel state of the state vector u (mode classified by the kernel)."""
    return new_state(float(u[0]), float(u[1]), tuple(float(x) for x in u[2:]))


def check_admissible(solver, params, u, field: str = "u0") -> None:
    """A one-line ParameterError naming ``field`` if the start u is outside the admissible set
    of the solver's method (``Method.admissible``, e.g. a ball below its table)."""
    m = solver.spec
    if m.admissible is not None and not m.admissible(u, params):
        state = ", ".join(f"{nm}={float(x):g}" for nm, x in zip(params.model.state_names, u))
        raise ParameterError(f"{field}: the start ({state}) is outside what {params.model.name}"
                             f" ({solver.method}) admits: {m.admissible_text}")


def start_trajectory(params, x0, v0, method, rtol, atol, section_phase=0.0, u0=None):
    """Validated single-trajectory set-up: (params, solver, packed params, kernel opts, initial
    kernel state). Every error names its field."""
    params = check_params(params)
    u = initial_u(params.model, x0, v0, u0)
    solver = Solver(method=method, rtol=rtol, atol=atol, model=params.model,
                    section_phase=section_phase)
    check_admissible(solver, params, u)
    return params, solver, params.pack(), solver.opts(), state_from_u(u)


def state_u(model, state) -> np.ndarray:
    """The state vector u (n components) held in a kernel state."""
    n = model.n
    return np.concatenate([state[:2], state[ST_EXTRA:ST_EXTRA + n - 2]])


def start_attrs(u) -> dict:
    """Provenance of the initial state: x0, v0 (u[0], u[1]) and u0 (every component)."""
    return {"x0": float(u[0]), "v0": float(u[1]), "u0": np.asarray(u, dtype=np.float64)}


def component_variables(model, dims, U, prefix: str = "", suffix: str = "",
                        what: str = "") -> dict:
    """Dataset variables ``<prefix><name><suffix>`` of the components u[2:] of ``U`` (last
    axis: the components; X and V are written by each analysis), each with the model's units
    and long name (CF: one unit per variable)."""
    from .io import component_names
    out = {}
    names = component_names(model.state_names)
    for i in range(2, model.n):
        units = model.state_units[i] if len(model.state_units) > i else "1"
        out[f"{prefix}{names[i]}{suffix}"] = (dims, U[..., i], {
            "long_name": f"{state_long_name(model, i)}{what}", "units": units})
    return out


def renamed(name: str, value, old_name: str, old_value, default=None):
    """Value of keyword ``name`` given either as ``name`` or under its deprecated ``old_name``
    (accepted for one release, with a DeprecationWarning), else ``default``; one-line
    ParameterError if both are given, or neither without a default."""
    if old_value is not None:
        if value is not None:
            raise ParameterError(f"{name}: give {name} only ({old_name} is its deprecated name)")
        warnings.warn(f"{old_name}= is deprecated, use {name}=", DeprecationWarning, stacklevel=3)
        return old_value
    if value is None and default is not None:
        return default
    if value is None:
        raise ParameterError(f"{name}: required (the number of forcing periods recorded)")
    return value


def mask_names(var, mask=None) -> list[str]:
    """The flag meanings set in a bit-mask variable with CF ``flag_masks`` (its value, or
    ``mask``)."""
    mask = int(var.values if mask is None else mask)
    names = var.attrs["flag_meanings"].split()
    return [w for w, m in zip(names, np.asarray(var.attrs["flag_masks"])) if mask & int(m)]


#: Samples per forcing period of :func:`simulate` (and of ``nonsmooth simulate``).
SAMPLES_PER_PERIOD = 200
#: Bytes held per sample (X, V, X_max, X_min, t: float64; region, visited: 1 byte).
_SAMPLE_BYTES = 5 * 8 + 2


def simulate(params: ParamsBase, *, periods: int, transient: int = 0,
             samples_per_period: int = SAMPLES_PER_PERIOD, x0: float = 0.0, v0: float = 0.0,
             method: str = "smooth", rtol: float = 1e-8, atol: float = 1e-10,
             progress=None, section_phase: float = 0.0, u0=None) -> xr.Dataset:
    """Integrate one trajectory from (x0, v0) at t = 0 (forcing phase 0; at
    t = section_phase / omega with ``section_phase``, the forcing phase in radians); ``u0``:
    the initial state of every component instead (n numbers in the order of the model's
    ``state_names``, or a mapping {name: value}, the unnamed components 0).

    After ``transient`` whole forcing periods T = 2 pi/omega, the state is sampled at
    t = t0 + k T / samples_per_period, k = 0 ... periods * samples_per_period.
    ``method="smooth"``: the switch model of eqs. 10-14 (RKF45; ``"smooth_eq12"`` with the
    transition fields of eq. 12); ``"exact"``: the non-smooth system of eqs. 4, 7-9 (closed
    form between located switching events); another model's methods likewise.

    Returns a Dataset with coordinate ``t`` and variables ``X``, ``V``, ``region``
    (0 Gamma-, 1 Sigma_alpha, 2 Sigma_beta, 3 Gamma+; the exact model uses 0 and 3; CF flags),
    ``visited`` (bit mask of the regions visited since the previous sample, so that a pass
    through a thin band between two samples is not lost; CF flag_masks), ``X_max``, ``X_min``
    (the true extremes of X since the previous sample, interior extrema included; at the first
    sample X itself) and the scalars ``max_X``, ``min_X`` (true extremes over the whole
    recorded run) and ``regions_visited`` (bit mask over the run); a model with more state
    components has one variable each, named by its ``state_names`` (X and V are u[0], u[1];
    ``nonsmooth.io.components(ds)`` assembles them over a dimension ``component``). The run is integrated in
    time slices; ``progress`` (None or False: silent; True: a progress bar with a time estimate on
    a terminal, plain lines elsewhere; or a callable ``progress(done, total)``) (in forcing
    periods) is called between them.
    """
    from .sweep import progress_callback
    progress = progress_callback(progress, "simulate")
    from .io import check_memory, flag_attrs, format_bytes
    from .sweep import run_trajectories
    params, solver, p, opts, state = start_trajectory(params, x0, v0, method, rtol, atol,
                                                      section_phase, u0)
    periods = check_int("periods", periods, 1)
    transient = check_int("transient", transient, 0)
    spp = check_int("samples_per_period", samples_per_period, 1)
    n = periods * spp
    big = ("periods", periods) if periods >= spp else ("samples_per_period", spp)
    check_memory(_SAMPLE_BYTES * (n + 1.0), big[0],
                 f"record fewer periods or samples per period ({n + 1} samples at "
                 f"{format_bytes(_SAMPLE_BYTES)} each)", size=(big[1], 1))
    u_start = state_u(params.model, state)
    P = p[None, :]
    total = transient + periods
    report = None if progress is None else (lambda d, _t: progress(d, total))
    tr = run_trajectories(P, solver, state[None, :], per_period=1, n_skip=transient, n_out=0,
                          workers=1, progress=report)
    if tr["status"][0] != st.OK:
        raise IntegrationError(f"simulate: transient failed: {st.message(tr['status'][0])}")
    state = tr["state"][0]
    if progress is not None:
        report = lambda d, _t: progress(transient + d, total)  # noqa: E731
    rec = run_trajectories(P, solver, state[None, :], per_period=spp, n_skip=0, n_out=n,
                           workers=1, progress=report, components=True)
    if rec["status"][0] != st.OK:
        raise IntegrationError(f"simulate: integration failed: {st.message(rec['status'][0])}")
    X = np.concatenate([[state[0]], rec["X"][0]])
    V = np.concatenate([[state[1]], rec["V"][0]])
    R = np.concatenate([[int(state[ST_MODE])], rec["R"][0]]).astype(np.int8)
    M = np.concatenate([[1 << int(R[0])], rec["M"][0]]).astype(np.uint8)
    Xmax = np.concatenate([[state[0]], rec["Xmax"][0]])
    Xmin = np.concatenate([[state[0]], rec["Xmin"][0]])
    U = np.concatenate([state_u(params.model, state)[None, :], rec["U"][0]])
    T = params.period
    w = params.model.omega
    t0 = transient * T + (solver.section_phase / getattr(params, w) if w
                          else solver.section_phase * T / (2.0 * np.pi))
    t = t0 + np.arange(n + 1) * (T / spp)
    modes = params.model.mode_names
    regions = flag_attrs(modes, dtype=np.int8)
    masks = flag_attrs(modes, dtype=np.uint8, masks=True)
    ds = xr.Dataset(
        {
            "X": ("t", X, {"long_name": state_long_name(params.model, 0), "units": "1"}),
            "V": ("t", V, {"long_name": state_long_name(params.model, 1), "units": "1/s"}),
            "region": ("t", R, dict(regions, long_name=params.model.mode_long_name + " at t")),
            "visited": ("t", M, dict(masks, long_name="regions visited since the previous "
                                                      "sample")),
            "X_max": ("t", Xmax, {"long_name": "largest X since the previous sample (interior "
                                               "extrema included)", "units": "1"}),
            "X_min": ("t", Xmin, {"long_name": "smallest X since the previous sample (interior "
                                               "extrema included)", "units": "1"}),
            "max_X": ((), float(Xmax.max()), {"long_name": "largest X over the recorded run "
                                                           "(interior extrema included)",
                                              "units": "1"}),
            "min_X": ((), float(Xmin.min()), {"long_name": "smallest X over the recorded run "
                                                           "(interior extrema included)",
                                              "units": "1"}),
            "regions_visited": ((), np.bitwise_or.reduce(M), dict(
                masks, long_name="regions visited over the recorded run")),
            **component_variables(params.model, "t", U),
        },
        coords={"t": ("t", t, {"long_name": "time", "units": "s"})},
        attrs=provenance_attrs(params, solver, analysis="simulate", periods=periods,
                               transient=transient, samples_per_period=spp,
                               **start_attrs(u_start), forcing_period=T),
    )
    return apply_state_units(ds, params.model)
