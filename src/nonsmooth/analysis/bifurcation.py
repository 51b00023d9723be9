"""Bifurcation (orbit) diagrams over any parameter, with continuation up and down.

``up``/``down`` sweeps carry the whole kernel state (X, V, the eq. 13a memory Va, the region and
the step size) from one parameter value to the next, so the response follows a branch until it
disappears: that is how jumps and hysteresis show. The two directions are independent and run
in parallel (numba ``prange`` over the directions); within a direction the values are
sequential. ``fresh`` restarts every value from (x0, v0) and runs all values in parallel.
The compiled continuation core :func:`continuation` is shared with the resonance curves.

A failing point (non-zero kernel status) gets NaN data and its status; the sweep continues on
that branch from (x0, v0) at the next value.
"""

from __future__ import annotations

import numba as nb
import numpy as np
import xarray as xr

from .. import status as st
from ..errors import ParameterError
from ..io import provenance_attrs
from ..kernels import METHOD_SMOOTH, Solver
from ..models.switch import beta_ratio, inside_margin
from ..params import IDX, PARAM_INFO, Params, check_param_name
from .poincare import MAX_PERIOD, classify, settle_and_record, settle_tolerance

SWEEPS = ("up", "down", "both", "fresh")

_I_OMEGA_S = IDX["omega_s"]
_I_XI_S = IDX["xi_s"]
_I_ETA = IDX["eta"]


@nb.njit(cache=True)
def _fix_mode(method, p, state):
    """After a parameter change, reclassify the region if the carried one no longer holds
    (band borders move with eta, omega_s, xi_s). The entry velocity Va is kept."""
    if method == METHOD_SMOOTH and state[3] >= 0:
        r = beta_ratio(p[_I_OMEGA_S], p[_I_XI_S])
        if inside_margin(int(state[3]), state[0], state[1], p[_I_ETA], r) < 0.0:
            state[3] = -1.0


_F3 = nb.float64[:, :, :]
_I8_2 = nb.int64[:, :]
#: one signature (any layout): chunks of the value axis are non-contiguous views, whole small
#: sweeps are contiguous; without it numba would compile and cache both versions
_CONTINUATION_SIG = nb.void(nb.int64, _F3, nb.float64[:], nb.float64[:, :], nb.float64[:], nb.int64,
                            nb.float64, _F3, _F3, nb.int8[:, :, :], nb.uint8[:, :, :], _F3, _F3,
                            _I8_2, _I8_2, _F3)


@nb.njit(_CONTINUATION_SIG, cache=True, parallel=True)
def continuation(method, P, opts, states, init, transient, settle_tol,
                 X, V, R, M, Xmax, Xmin, status, used, S):
    """For every branch b (in parallel) and parameter row i (in order): continue
    ``states[b]`` with parameters ``P[b, i]`` for ``transient`` periods (ended early when
    settled, ``settle_tol`` > 0) and record ``X.shape[2]`` section points into
    ``X[b, i]`` ... and the state after it into ``S[b, i]``. A failed point gets NaN outputs
    and status != 0, and the branch restarts from ``init`` at the next row. ``states`` is
    updated in place (resumable)."""
    nb_, ni = P.shape[0], P.shape[1]
    for b in nb.prange(nb_):
        for i in range(ni):
            _fix_mode(method, P[b, i], states[b])
            code, u = settle_and_record(method, P[b, i], opts, states[b], transient, settle_tol,
                                        X[b, i], V[b, i], R[b, i], M[b, i], Xmax[b, i],
                                        Xmin[b, i])
            status[b, i] = code
            used[b, i] = u
            if code != 0:
                for k in range(states.shape[1]):
                    states[b, k] = init[k]
            for k in range(states.shape[1]):
                S[b, i, k] = states[b, k]


def check_values(name: str, values) -> np.ndarray:
    """1-d float array of at least 2 finite, distinct values, sorted ascending."""
    try:
        v = np.asarray(values, dtype=np.float64).ravel()
    except (TypeError, ValueError):
        raise ParameterError(f"{name}: expected numbers") from None
    if v.size < 2:
        raise ParameterError(f"{name}: need at least 2 values, got {v.size}")
    if not np.all(np.isfinite(v)):
        raise ParameterError(f"{name}: values must be finite")
    v = np.sort(v)
    if np.any(np.diff(v) <= 0):
        raise ParameterError(f"{name}: values must be distinct")
    return v


def param_rows(params: Params, param: str, values) -> np.ndarray:
    """Packed parameters, one row per value (each validated by Params)."""
    return np.stack([params.replace(**{param: float(x)}).pack() for x in values])


def run_branches(params: Params, param: str, values, solver: Solver, *, directions,
                 transient: int, record: int, x0: float, v0: float, settle: bool,
                 workers=None, progress=None, chunk: int = 25):
    """Run continuation branches over sorted ``values``; ``directions`` lists "up", "down"
    or "fresh". Returns dict of arrays (branch, value, n) in ascending value order, plus
    ``status`` and ``used`` (branch, value), ``S`` the kernel state after each value
    (branch, value, 5) and the final ``state`` per branch.
    ``progress(done, total)`` is called after each chunk of values."""
    from ..kernels import new_state
    from ..sweep import threads
    values = np.asarray(values, dtype=np.float64)
    nv = values.size
    rows = param_rows(params, param, values)
    init = new_state(x0, v0)
    opts = solver.opts()
    tol = settle_tolerance(solver, settle)
    fresh = list(directions) == ["fresh"]
    if fresh:
        # every value is its own one-point branch, all in parallel
        P = rows[:, None, :]
        orders = [np.arange(nv)]
    else:
        orders = [np.arange(nv) if d == "up" else np.arange(nv)[::-1] for d in directions]
        P = np.stack([rows[o] for o in orders])  # (branch, value in sweep order, 7)
    nbr, nval = P.shape[0], P.shape[1]
    states = np.tile(init, (nbr, 1))
    X = np.empty((nbr, nval, record))
    V = np.empty_like(X)
    R = np.empty((nbr, nval, record), np.int8)
    M = np.empty((nbr, nval, record), np.uint8)
    Xmax = np.empty_like(X)
    Xmin = np.empty_like(X)
    status = np.zeros((nbr, nval), np.int64)
    used = np.zeros((nbr, nval), np.int64)
    S = np.empty((nbr, nval, init.size))
    with threads(workers):
        if fresh:
            step = max(chunk, 1) * 4
            for a in range(0, nbr, step):
                b = min(nbr, a + step)
                continuation(solver.code, P[a:b], opts, states[a:b], init, transient, tol,
                             X[a:b], V[a:b], R[a:b], M[a:b], Xmax[a:b], Xmin[a:b],
                             status[a:b], used[a:b], S[a:b])
                if progress is not None:
                    progress(b, nbr)
        else:
            for a in range(0, nval, chunk):
                b = min(nval, a + chunk)
                continuation(solver.code, P[:, a:b], opts, states, init, transient, tol,
                             X[:, a:b], V[:, a:b], R[:, a:b], M[:, a:b], Xmax[:, a:b],
                             Xmin[:, a:b], status[:, a:b], used[:, a:b], S[:, a:b])
                if progress is not None:
                    progress(b, nval)
    out = {"X": X, "V": V, "R": R, "M": M, "Xmax": Xmax, "Xmin": Xmin, "status": status,
           "used": used, "S": S}
    if fresh:
        out = {k: np.moveaxis(a, 0, 1) for k, a in out.items()}  # (1, value, ...)
    else:
        for k, a in out.items():
            out[k] = np.stack([a[j][np.argsort(o)] for j, o in enumerate(orders)])
    out["state"] = states
    return out


def summarize(out, rtol: float, atol: float):
    """period, max_X, min_X, contact per (branch, value)."""
    shape = out["status"].shape
    period = np.zeros(shape, np.int64)
    mx = np.full(shape, np.nan)
    mn = np.full(shape, np.nan)
    contact = np.zeros(shape, np.int8)
    for j in range(shape[0]):
        for i in range(shape[1]):
            if out["status"][j, i] == st.OK:
                period[j, i], mx[j, i], mn[j, i], contact[j, i] = classify(
                    out["X"][j, i], out["V"][j, i], out["Xmax"][j, i], out["Xmin"][j, i],
                    out["M"][j, i], rtol, atol)
    return period, mx, mn, contact


def bifurcation_diagram(params: Params, param: str, values, *, sweep: str = "both",
                        transient: int = 500, record: int = 200, method: str = "smooth",
                        x0: float = 0.0, v0: float = 0.0, rtol: float = 1e-8,
                        atol: float = 1e-10, transition: str = "eq13", settle: bool = True,
                        max_steps: int = 200_000, workers: int | None = None,
                        progress=None) -> xr.Dataset:
    """Orbit diagram of the stroboscopic section over ``param`` (any of omega, F0, omega_s,
    xi, xi_s, omega0, eta) at ``values`` (sorted ascending; each validated by Params).

    ``sweep``: "up" / "down" continue the state from value to value in increasing /
    decreasing order, "both" does both (in parallel), "fresh" restarts every value from
    (x0, v0) (all values in parallel). The first value of a continuation sweep starts from
    (x0, v0). Each value: ``transient`` periods (ended early once the section has provably
    settled when ``settle=True``, see ``analysis.poincare``), then ``record`` section points.

    Returns a Dataset with coordinates ``<param>`` and ``sweep`` and variables ``X``, ``V``
    (sweep, <param>, n), ``period`` (0 = not periodic), ``max_X``, ``min_X``, ``contact``,
    ``status`` (0 = ok; failed points have NaN data) and ``transient_used``.
    ``max_steps``: integration steps allowed per forcing period (see ``kernels.Solver``).
    """
    from ..simulate import check_float, check_int, check_params
    params = check_params(params)
    if not isinstance(param, str):
        raise ParameterError(f"param: expected a parameter name, got {param!r}")
    param = check_param_name(param)
    values = check_values(param, values)
    if sweep not in SWEEPS:
        raise ParameterError(f"sweep: unknown sweep {sweep!r} (known: {', '.join(SWEEPS)})")
    transient = check_int("transient", transient, 0)
    record = check_int("record", record, 1)
    x0 = check_float("x0", x0)
    v0 = check_float("v0", v0)
    solver = Solver(method=method, rtol=rtol, atol=atol, transition=transition,
                    max_steps=max_steps)
    directions = {"up": ["up"], "down": ["down"], "both": ["up", "down"], "fresh": ["fresh"]}[sweep]
    out = run_branches(params, param, values, solver, directions=directions,
                       transient=transient, record=record, x0=x0, v0=v0, settle=settle,
                       workers=workers, progress=progress)
    return branches_dataset(params, param, values, solver, directions, out,
                            analysis="bifurcation", transient=transient, record=record,
                            x0=x0, v0=v0, settle=settle, sweep_mode=sweep)


def branches_dataset(params, param, values, solver, directions, out, **attrs) -> xr.Dataset:
    period, mx, mn, contact = summarize(out, solver.rtol, solver.atol)
    desc, unit, _ = PARAM_INFO[param]
    dims = ("sweep", param)
    nfail = int(np.count_nonzero(out["status"]))
    ds = xr.Dataset(
        {
            "X": (dims + ("n",), out["X"], {"long_name": "section displacement X(kT)",
                                            "units": "1"}),
            "V": (dims + ("n",), out["V"], {"long_name": "section velocity dX/dt(kT)",
                                            "units": "1/s"}),
            "period": (dims, period, {"long_name": "period of the section (0 = not periodic)"}),
            "max_X": (dims, mx, {"long_name": "largest X over the recorded periods",
                                 "units": "1"}),
            "min_X": (dims, mn, {"long_name": "smallest X over the recorded periods",
                                 "units": "1"}),
            "contact": (dims, contact, {"long_name": "contact with the support (0/1)"}),
            "status": (dims, out["status"],
                       {"long_name": "kernel status (0 = ok)",
                        "legend": ", ".join(f"{k}: {v}" for k, v in st.MESSAGES.items())}),
            "transient_used": (dims, out["used"],
                               {"long_name": "transient periods integrated"}),
        },
        coords={
            param: (param, values, {"long_name": desc, "units": unit}),
            "sweep": ("sweep", np.array(directions, dtype=object),
                      {"long_name": "continuation direction (fresh = restart each value)"}),
            "n": ("n", np.arange(out["X"].shape[2]), {"long_name": "section index"}),
        },
        attrs=provenance_attrs(params, solver, param=param, max_period=MAX_PERIOD,
                               n_failed=nfail, **attrs),
    )
    ds.attrs["swept_param"] = param  # param_<param> holds the base value (not swept)
    return ds
