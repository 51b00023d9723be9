"""Time response of one trajectory: ``simulate(params, ...) -> xarray.Dataset``."""

from __future__ import annotations

import math

import numpy as np
import xarray as xr

from . import status as st
from .errors import IntegrationError, ParameterError
from .integrate.contract import ST_MODE
from .io import provenance_attrs
from .kernels import Solver, advance, new_state, output_buffers
from .models.switch import REGION_LEGEND
from .params import Params


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


def check_params(params) -> Params:
    if not isinstance(params, Params):
        raise ParameterError(f"params: expected nonsmooth.Params, got {type(params).__name__}")
    return params


def start_trajectory(params, x0, v0, method, rtol, atol, transition):
    """Validated single-trajectory set-up: (params, solver, packed params, kernel opts, initial
    kernel state). Every error names its field."""
    params = check_params(params)
    x0 = check_float("x0", x0)
    v0 = check_float("v0", v0)
    solver = Solver(method=method, rtol=rtol, atol=atol, transition=transition)
    return params, solver, params.pack(), solver.opts(), new_state(x0, v0)


def simulate(params: Params, *, periods: int, transient: int = 0, samples_per_period: int = 100,
             x0: float = 0.0, v0: float = 0.0, method: str = "smooth", rtol: float = 1e-8,
             atol: float = 1e-10, transition: str = "eq13") -> xr.Dataset:
    """Integrate one trajectory from (x0, v0) at t = 0 (forcing phase 0).

    After ``transient`` whole forcing periods T = 2 pi/omega, the state is sampled at
    t = t0 + k T / samples_per_period, k = 0 ... periods * samples_per_period.
    ``method="smooth"``: the switch model of eqs. 10-14 (RKF45); ``"exact"``: the non-smooth
    system of eqs. 4, 7-9 (closed form between located switching events).

    Returns a Dataset with coordinate ``t`` and variables ``X``, ``V``, ``region``
    (0 Gamma-, 1 Sigma_alpha, 2 Sigma_beta, 3 Gamma+; the exact model uses 0 and 3) and
    ``visited`` (bit mask of the regions visited since the previous sample, so that a pass
    through a thin band between two samples is not lost).
    """
    params, solver, p, opts, state = start_trajectory(params, x0, v0, method, rtol, atol,
                                                      transition)
    periods = check_int("periods", periods, 1)
    transient = check_int("transient", transient, 0)
    spp = check_int("samples_per_period", samples_per_period, 1)
    x0, v0 = float(state[0]), float(state[1])
    empty = output_buffers(0)
    code = advance(solver.code, p, opts, state, 1, transient, 0, *empty)
    if code != st.OK:
        raise IntegrationError(f"simulate: transient failed: {st.message(code)}")
    n = periods * spp
    X, V, R, M, _xmax, _xmin = output_buffers(n + 1)
    X[0], V[0], R[0] = state[0], state[1], int(state[ST_MODE])
    M[0] = 1 << R[0]
    code = advance(solver.code, p, opts, state, spp, 0, n, X[1:], V[1:], R[1:], M[1:],
                   _xmax[1:], _xmin[1:])
    if code != st.OK:
        raise IntegrationError(f"simulate: integration failed: {st.message(code)}")
    T = params.period
    t0 = transient * T
    t = t0 + np.arange(n + 1) * (T / spp)
    ds = xr.Dataset(
        {
            "X": ("t", X, {"long_name": "displacement X = x/g", "units": "1"}),
            "V": ("t", V, {"long_name": "velocity dX/dt", "units": "1/s"}),
            "region": ("t", R, {"long_name": "region of eq. 14 at t", "legend": REGION_LEGEND}),
            "visited": ("t", M, {"long_name": "regions visited since the previous sample",
                                 "legend": "bit mask, bit r set = region code r visited"}),
        },
        coords={"t": ("t", t, {"long_name": "time", "units": "s"})},
        attrs=provenance_attrs(params, solver, analysis="simulate", periods=periods,
                               transient=transient, samples_per_period=spp, x0=x0, v0=v0,
                               forcing_period=T, region_legend=REGION_LEGEND),
    )
    return ds
