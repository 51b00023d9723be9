"""Stroboscopic Poincaré map (section t = kT) with period classification and a phase portrait.

``poincare(params, ...)`` is the convenience call; the compiled per-point core
:func:`settle_and_record` (transient, optionally ended early once provably settled, then the
recorded section) is shared with the bifurcation and resonance sweeps.

Definitions
-----------
* Section: the state (X, V) at t = kT, k = transient + 1 ... transient + points (forcing phase 0).
* ``period``: the smallest p <= 64 such that every recorded section point repeats after p
  periods within ``section_tolerance(rtol, atol, scale)`` (scale = largest |X|, |V| seen), i.e.
  1e3 times the integration tolerance; 0 = no repetition (chaotic, quasi-periodic or not yet
  settled). At least 2 p points are needed to accept period p.
* ``max_X``, ``min_X``: the true extremes of X over the recorded periods (interior extrema
  included, from the kernels' per-interval Xmax/Xmin), not only the section values.
* ``contact``: 1 when, during the recorded periods, the trajectory left the free-flight region
  Gamma- (visited Sigma_alpha, Sigma_beta or Gamma+) AND max X >= 1 (the mass reached the
  support position h_alpha = 0); else 0. The second condition keeps a smoothed trajectory
  that only dips into the band 1 - eta < X < 1 from counting as contact; for the exact model
  leaving Gamma- already implies X >= 1.

Early end of the transient (``settle=True``)
---------------------------------------------
The transient is integrated in windows of ``SETTLE_WINDOW`` periods. After each window the
section points are tested: for the smallest p <= ``SETTLE_MAX_PERIOD`` for which all points of
the window repeat after p periods within the settle tolerance, the decay rate lam of the
repetition defects d_k = |s_{k+p} - s_k| is estimated from the two halves of the window, and
the transient stops when the estimated remaining distance to the periodic orbit,
d / (1 - lam^p), is below the settle tolerance (``SETTLE_FRACTION`` x the section tolerance),
or when the defects are at the round-off floor. A slow drift (multiplier near 1, e.g. near a
saddle-node) therefore never ends the transient early; chaotic and quasi-periodic motion never
does either. The recorded section then differs from the one after the full transient by less
than 1 % of the period tolerance, so classification and figures are unchanged while settled
periodic points cost a fraction of the transient.
"""

from __future__ import annotations

import numba as nb
import numpy as np
import xarray as xr

from .. import status as st
from ..errors import IntegrationError
from ..integrate.contract import ST_MODE
from ..io import provenance_attrs
from ..kernels import Solver, advance, output_buffers
from ..models.switch import REGION_LEGEND
from ..params import Params
from .periodicity import detect_period, section_tolerance

#: Largest period the period detection looks for.
MAX_PERIOD = 64
#: Periods per settle test window, and the largest period the settle test recognises.
SETTLE_WINDOW = 24
SETTLE_MAX_PERIOD = 8
#: Settle tolerance as a fraction of the section (period) tolerance.
SETTLE_FRACTION = 1e-2
#: Repetition defects below this fraction of the settle tolerance count as converged.
_FLOOR = 1e-3


@nb.njit(cache=True)
def _settled(X, V, tol, pmax):
    """True if the window of section points (X, V) has provably converged to a periodic orbit
    (see module docstring)."""
    n = X.shape[0]
    for p in range(1, pmax + 1):
        m = n - p
        if m < 4:
            return False
        ok = True
        for k in range(m):
            if not (abs(X[k + p] - X[k]) <= tol and abs(V[k + p] - V[k]) <= tol):
                ok = False
                break
        if not ok:
            continue
        half = m // 2
        da = 0.0
        db = 0.0
        for k in range(half):
            da = max(da, abs(X[k + p] - X[k]), abs(V[k + p] - V[k]))
        for k in range(m - half, m):
            db = max(db, abs(X[k + p] - X[k]), abs(V[k + p] - V[k]))
        if db <= _FLOOR * tol:
            return True
        if not db < da:
            return False
        lam = (db / da) ** (1.0 / (m - half))
        lp = lam ** p
        return db / (1.0 - lp) <= tol
    return False


@nb.njit(cache=True)
def settle(method, p, opts, state, transient, settle_tol):
    """Integrate up to ``transient`` forcing periods from a period boundary, updating ``state``.
    ``settle_tol > 0`` ends early once settled (module docstring; the scale of the tolerance
    is the largest |X|, |V| in the window). Returns (status, periods integrated)."""
    if settle_tol <= 0.0 or transient < SETTLE_WINDOW:
        e0 = np.empty(0)
        code = advance(method, p, opts, state, 1, transient, 0, e0, e0, np.empty(0, np.int8),
                       np.empty(0, np.uint8), e0, e0)
        return code, transient
    w = SETTLE_WINDOW
    bx = np.empty(w)
    bv = np.empty(w)
    br = np.empty(w, np.int8)
    bm = np.empty(w, np.uint8)
    b1 = np.empty(w)
    b2 = np.empty(w)
    done = 0
    while done < transient:
        n = min(w, transient - done)
        code = advance(method, p, opts, state, 1, 0, n, bx[:n], bv[:n], br[:n], bm[:n],
                       b1[:n], b2[:n])
        done += n
        if code != 0:
            return code, done
        if n == w:
            scale = 1.0
            for k in range(w):
                scale = max(scale, abs(bx[k]), abs(bv[k]))
            if _settled(bx, bv, settle_tol * scale, SETTLE_MAX_PERIOD):
                break
    return 0, done


@nb.njit(cache=True)
def settle_and_record(method, p, opts, state, transient, settle_tol, X, V, R, M, Xmax, Xmin):
    """Per-point core: :func:`settle` over the transient, then record ``len(X)`` section points
    (one per forcing period, kernel contract outputs). Returns (status, transient periods used).
    On failure the outputs are NaN."""
    code, used = settle(method, p, opts, state, transient, settle_tol)
    if code == 0:
        code = advance(method, p, opts, state, 1, 0, X.shape[0], X, V, R, M, Xmax, Xmin)
    if code != 0:
        for k in range(X.shape[0]):
            X[k] = np.nan
            V[k] = np.nan
            Xmax[k] = np.nan
            Xmin[k] = np.nan
            R[k] = -1
            M[k] = 0
    return code, used


def settle_tolerance(solver: Solver, settle: bool) -> float:
    """Unscaled settle tolerance handed to the compiled core (0 = integrate the full transient)."""
    return SETTLE_FRACTION * section_tolerance(solver.rtol, solver.atol) if settle else 0.0


def classify(X, V, Xmax, Xmin, M, rtol: float, atol: float, max_period: int = MAX_PERIOD):
    """(period, max_X, min_X, contact) of recorded section data (see module docstring).
    NaN data give (0, nan, nan, 0)."""
    X = np.ascontiguousarray(X, dtype=np.float64)
    V = np.ascontiguousarray(V, dtype=np.float64)
    if X.size == 0 or not (np.all(np.isfinite(X)) and np.all(np.isfinite(V))):
        return 0, float("nan"), float("nan"), 0
    scale = float(max(np.max(np.abs(X)), np.max(np.abs(V))))
    period = int(detect_period(X, V, section_tolerance(rtol, atol, scale), max_period))
    mx = float(np.max(Xmax))
    mn = float(np.min(Xmin))
    contact = int(bool(np.any(np.asarray(M) & np.uint8(0b1110))) and mx >= 1.0)
    return period, mx, mn, contact


def poincare(params: Params, *, points: int, transient: int, x0: float = 0.0, v0: float = 0.0,
             method: str = "smooth", rtol: float = 1e-8, atol: float = 1e-10,
             transition: str = "eq13", orbit_samples: int = 200, orbit_periods: int | None = None,
             settle: bool = False) -> xr.Dataset:
    """Stroboscopic Poincaré section of one trajectory from (x0, v0) at t = 0.

    Integrates ``transient`` forcing periods (all of them unless ``settle=True``), then records
    ``points`` section points X[n], V[n] at t = (transient + n + 1) T. Attrs ``period``
    (0 = not periodic), ``max_X``, ``min_X``, ``contact`` are defined in the module docstring.
    After the section run, a phase-portrait trajectory ``orbit_X``, ``orbit_V``,
    ``orbit_region`` (dimension ``sample``) covers ``orbit_periods`` further periods (default:
    the detected period, or 20 periods when not periodic) at ``orbit_samples`` per period; it
    starts on the last section point, so the section points lie on it.

    Raises IntegrationError if the trajectory fails (sweeps record failures instead).
    """
    from ..simulate import check_int, start_trajectory
    params, solver, p, opts, state = start_trajectory(params, x0, v0, method, rtol, atol,
                                                      transition)
    x0, v0 = float(state[0]), float(state[1])
    points = check_int("points", points, 1)
    transient = check_int("transient", transient, 0)
    orbit_samples = check_int("orbit_samples", orbit_samples, 1)
    if orbit_periods is not None:
        orbit_periods = check_int("orbit_periods", orbit_periods, 1)
    X, V, R, M, Xmax, Xmin = output_buffers(points)
    code, used = settle_and_record(solver.code, p, opts, state, transient,
                                   settle_tolerance(solver, settle), X, V, R, M, Xmax, Xmin)
    if code != st.OK:
        raise IntegrationError(f"poincare: integration failed: {st.message(code)}")
    period, mx, mn, contact = classify(X, V, Xmax, Xmin, M, rtol, atol)

    n_orb = orbit_periods or (period if period > 0 else 20)
    ns = n_orb * orbit_samples
    oX, oV, oR, oM, _a, _b = output_buffers(ns + 1)
    oX[0], oV[0] = state[0], state[1]
    oR[0] = int(state[ST_MODE])
    oM[0] = 1 << max(int(oR[0]), 0)
    code = advance(solver.code, p, opts, state, orbit_samples, 0, ns, oX[1:], oV[1:], oR[1:],
                   oM[1:], _a[1:], _b[1:])
    if code != st.OK:
        raise IntegrationError(f"poincare: orbit integration failed: {st.message(code)}")

    T = params.period
    ds = xr.Dataset(
        {
            "X": ("n", X, {"long_name": "section displacement X(t_n)", "units": "1"}),
            "V": ("n", V, {"long_name": "section velocity dX/dt(t_n)", "units": "1/s"}),
            "orbit_X": ("sample", oX, {"long_name": "phase-portrait displacement", "units": "1"}),
            "orbit_V": ("sample", oV, {"long_name": "phase-portrait velocity", "units": "1/s"}),
            "orbit_region": ("sample", oR, {"long_name": "region of eq. 14",
                                            "legend": REGION_LEGEND}),
        },
        coords={
            "n": ("n", np.arange(points), {"long_name": "section index"}),
            "t_n": ("n", (used + 1 + np.arange(points)) * T,
                    {"long_name": "section time", "units": "s"}),
            "orbit_t": ("sample", (used + points) * T + np.arange(ns + 1) * (T / orbit_samples),
                        {"long_name": "phase-portrait time", "units": "s"}),
        },
        attrs=provenance_attrs(params, solver, analysis="poincare", points=points,
                               transient=transient, transient_used=int(used), settle=settle,
                               x0=x0, v0=v0, forcing_period=T, period=period, max_X=mx,
                               min_X=mn, contact=contact, max_period=MAX_PERIOD,
                               period_tolerance=section_tolerance(
                                   rtol, atol, max(np.max(np.abs(X)), np.max(np.abs(V)))),
                               orbit_periods=n_orb, orbit_samples=orbit_samples,
                               region_legend=REGION_LEGEND),
    )
    return ds
