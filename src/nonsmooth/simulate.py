"""Time response of one trajectory: ``simulate(params, ...) -> xarray.Dataset``."""

from __future__ import annotations

import math
import warnings

import numpy as np
import xarray as xr

from . import status as st
from .errors import IntegrationError, ParameterError
from .integrate.contract import ST_MODE
from .io import provenance_attrs
from .kernels import Solver, new_state
from .models.base import ParamsBase


def check_int(name: str, value, minimum: int) -> int:
    """``value`` as an int >= minimum, else a one-line ParameterError naming ``name``."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
        if isinstance(value, (float, np.floating)) and float(value).is_integer():
            value = int(value)
        else:
            raise ParameterError(f"{name}: expected a whole number, got {value!r}")
    if value < minimum:
        raise ParameterError(f"{name}: must be >= {minimum}, got {value}")
    return int(value)


def check_float(name: str, value) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ParameterError(f"{name}: expected a number, got {value!r}") from None
    if not math.isfinite(v):
        raise ParameterError(f"{name}: must be finite, got {v}")
    return v


def check_params(params) -> ParamsBase:
    """``params`` if it is a model's validated parameters (``model(...).params(...)``,
    ``preset(...)``), else a one-line ParameterError."""
    if not isinstance(params, ParamsBase):
        raise ParameterError(f"params: expected model(...).params(...) or preset(...), "
                             f"got {type(params).__name__}")
    return params


def start_trajectory(params, x0, v0, method, rtol, atol, section_phase=0.0):
    """Validated single-trajectory set-up: (params, solver, packed params, kernel opts, initial
    kernel state). Every error names its field."""
    params = check_params(params)
    x0 = check_float("x0", x0)
    v0 = check_float("v0", v0)
    solver = Solver(method=method, rtol=rtol, atol=atol, model=params.model,
                    section_phase=section_phase)
    return params, solver, params.pack(), solver.opts(), new_state(x0, v0)


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
             progress=None, section_phase: float = 0.0) -> xr.Dataset:
    """Integrate one trajectory from (x0, v0) at t = 0 (forcing phase 0; at
    t = section_phase / omega with ``section_phase``, the forcing phase in radians).

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
    recorded run) and ``regions_visited`` (bit mask over the run). The run is integrated in
    time slices; ``progress`` (None or False: silent; True: a progress bar with a time estimate on
    a terminal, plain lines elsewhere; or a callable ``progress(done, total)``) (in forcing
    periods) is called between them.
    """
    from .sweep import progress_callback
    progress = progress_callback(progress, "simulate")
    from .io import check_memory, flag_attrs, format_bytes
    from .sweep import run_trajectories
    params, solver, p, opts, state = start_trajectory(params, x0, v0, method, rtol, atol,
                                                      section_phase)
    periods = check_int("periods", periods, 1)
    transient = check_int("transient", transient, 0)
    spp = check_int("samples_per_period", samples_per_period, 1)
    n = periods * spp
    big = ("periods", periods) if periods >= spp else ("samples_per_period", spp)
    check_memory(_SAMPLE_BYTES * (n + 1.0), big[0],
                 f"record fewer periods or samples per period ({n + 1} samples at "
                 f"{format_bytes(_SAMPLE_BYTES)} each)", size=(big[1], 1))
    x0, v0 = float(state[0]), float(state[1])
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
                           workers=1, progress=report)
    if rec["status"][0] != st.OK:
        raise IntegrationError(f"simulate: integration failed: {st.message(rec['status'][0])}")
    X = np.concatenate([[state[0]], rec["X"][0]])
    V = np.concatenate([[state[1]], rec["V"][0]])
    R = np.concatenate([[int(state[ST_MODE])], rec["R"][0]]).astype(np.int8)
    M = np.concatenate([[1 << int(R[0])], rec["M"][0]]).astype(np.uint8)
    Xmax = np.concatenate([[state[0]], rec["Xmax"][0]])
    Xmin = np.concatenate([[state[0]], rec["Xmin"][0]])
    T = params.period
    t0 = transient * T + solver.section_phase / getattr(params, params.model.omega)
    t = t0 + np.arange(n + 1) * (T / spp)
    modes = params.model.mode_names
    regions = flag_attrs(modes, dtype=np.int8)
    masks = flag_attrs(modes, dtype=np.uint8, masks=True)
    ds = xr.Dataset(
        {
            "X": ("t", X, {"long_name": "displacement X = x/g", "units": "1"}),
            "V": ("t", V, {"long_name": "velocity dX/dt", "units": "1/s"}),
            "region": ("t", R, dict(regions, long_name="region of eq. 14 at t")),
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
        },
        coords={"t": ("t", t, {"long_name": "time", "units": "s"})},
        attrs=provenance_attrs(params, solver, analysis="simulate", periods=periods,
                               transient=transient, samples_per_period=spp, x0=x0, v0=v0,
                               forcing_period=T),
    )
    return ds
