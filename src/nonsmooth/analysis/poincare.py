"""Stroboscopic Poincaré map (section t = kT) with period classification and a phase portrait.

``poincare(params, ...)`` is the convenience call; it runs one point of the sweeps' resumable
continuation core (``bifurcation.continuation`` driven by ``bifurcation.follow``: the
transient of :func:`settle`, optionally ended early once provably settled, then the recorded
section, in time slices so that Ctrl-C and progress work inside one trajectory), and classifies
the section like the bifurcation and resonance sweeps (``bifurcation.summarize``).

Definitions
-----------
* Section: the state (X, V) at t_section = t_s + kT, k = transient + 1 ... transient + record
  (t_s = section_phase / omega, 0 by default)
  (forcing phase 0).
* ``period``: the smallest p <= 64 such that every recorded section point repeats after p
  periods within ``section_tolerance(rtol, atol, scale)`` (scale = largest |X|, |V| seen), i.e.
  1e3 times the integration tolerance. At least 2 p points are needed to accept period p.
  A period is never reported from a section that is still converging: when the repetition
  defects of no period, or of a smaller period q dividing p, still decay geometrically
  (``periodicity.still_converging``), the trajectory is integrated further, by the number of
  periods the observed decay rate needs, and recorded again (``bifurcation.MAX_EXTENSION``:
  at most 20 x max(transient, record) periods in all); if that is not enough, the period is
  -1 (``NOT_SETTLED``, "not settled"). 0 = no repetition and no convergence seen (chaotic,
  quasi-periodic, or a transient that still looks chaotic at the end of the window); chaotic
  sections are never extended.
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
from ..io import apply_state_units, provenance_attrs
from ..kernels import Solver
from ..models.base import ParamsBase
from .periodicity import (NOT_SETTLED, TOL_FACTOR, detect_period, section_tolerance,
                          still_converging)

#: Largest period the period detection looks for.
MAX_PERIOD = 64
#: long_name of every ``period`` variable.
PERIOD_LONG_NAME = ("period of the section in forcing periods (0 = not periodic, -1 = not "
                    "settled: still converging after the longest transient allowed)")
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
def settle(kernel, fns, p, opts, state, transient, settle_tol, done, budget):
    """Continue a transient of ``transient`` forcing periods of which ``done`` are integrated
    (``state`` is updated), for about ``budget`` more periods: whole settle windows (at least
    one), so that a transient cut into such calls is identical to one call. ``settle_tol > 0``
    ends the transient early once settled (module docstring; the scale of the tolerance is the
    largest |X|, |V| in the window; ``kernel`` a ``KernelFunction``). Returns (status,
    periods done, finished)."""
    if settle_tol <= 0.0 or transient < SETTLE_WINDOW:
        n = max(0, min(budget, transient - done))
        e0 = np.empty(0)
        code = kernel(fns, p, opts, state, 1, n, 0, e0, e0, np.empty(0, np.int8),
                      np.empty(0, np.uint8), e0, e0)
        done += n
        return code, done, code != 0 or done >= transient
    w = SETTLE_WINDOW
    bx = np.empty(w)
    bv = np.empty(w)
    br = np.empty(w, np.int8)
    bm = np.empty(w, np.uint8)
    b1 = np.empty(w)
    b2 = np.empty(w)
    start = done
    while done < transient and (done == start or done - start < budget):
        n = min(w, transient - done)
        code = kernel(fns, p, opts, state, 1, 0, n, bx[:n], bv[:n], br[:n], bm[:n], b1[:n],
                      b2[:n])
        done += n
        if code != 0:
            return code, done, True
        if n == w:
            scale = 1.0
            for k in range(w):
                scale = max(scale, abs(bx[k]), abs(bv[k]))
            if _settled(bx, bv, settle_tol * scale, SETTLE_MAX_PERIOD):
                return 0, done, True
    return 0, done, done >= transient


def settle_tolerance(solver: Solver, settle: bool) -> float:
    """Unscaled settle tolerance handed to the compiled core (0 = integrate the full transient)."""
    return SETTLE_FRACTION * section_tolerance(solver.rtol, solver.atol) if settle else 0.0


def classify(X, V, Xmax, Xmin, M, rtol: float, atol: float, max_period: int = MAX_PERIOD,
             contact=None):
    """(period, max_X, min_X, contact, need) of recorded section data (see module docstring).
    ``need`` > 0: the section is still converging (``periodicity.still_converging``), period
    is then NOT_SETTLED and ``need`` estimates the further periods it takes to settle.
    ``contact(mask, max_X, min_X)``: the model's contact predicate (default: the support
    model's). NaN data give (0, nan, nan, 0, 0)."""
    X = np.ascontiguousarray(X, dtype=np.float64)
    V = np.ascontiguousarray(V, dtype=np.float64)
    if X.size == 0 or not (np.all(np.isfinite(X)) and np.all(np.isfinite(V))):
        return 0, float("nan"), float("nan"), 0, 0.0
    scale = float(max(np.max(np.abs(X)), np.max(np.abs(V))))
    tol = section_tolerance(rtol, atol, scale)
    period = int(detect_period(X, V, tol, max_period))
    need = float(still_converging(X, V, tol, period, max_period))
    if need > 0:
        period = NOT_SETTLED
    mx = float(np.max(Xmax))
    mn = float(np.min(Xmin))
    mask = int(np.bitwise_or.reduce(np.asarray(M, dtype=np.uint8).ravel())) if np.size(M) else 0
    if contact is None:
        hit = bool(mask & 0b1110) and mx >= 1.0
    else:
        hit = bool(contact(mask, mx, mn))
    contact = int(hit)
    return period, mx, mn, contact, need


@nb.njit(cache=True)
def _classify_many(X, V, Xmax, Xmin, M, rtol, atol, max_period, period, need, mx, mn, mask, ok):
    """:func:`classify` (less the contact predicate) of every row k of the section data:
    the same operations in the same order, so the same numbers, without a Python call per
    point. ``ok[k]`` = 0 where the data are not finite (classify's NaN case)."""
    for k in range(X.shape[0]):
        n = X.shape[1]
        finite = n > 0
        scale = 0.0
        for q in range(n):
            if not (np.isfinite(X[k, q]) and np.isfinite(V[k, q])):
                finite = False
                break
            scale = max(scale, abs(X[k, q]), abs(V[k, q]))
        if not finite:
            period[k], need[k], mx[k], mn[k], mask[k], ok[k] = 0, 0.0, np.nan, np.nan, 0, 0
            continue
        ok[k] = 1
        tol = TOL_FACTOR * (rtol * max(1.0, abs(scale)) + atol)
        p = detect_period(X[k], V[k], tol, max_period)
        nd = float(still_converging(X[k], V[k], tol, p, max_period))
        period[k] = NOT_SETTLED if nd > 0 else p
        need[k] = nd
        a = Xmax[k, 0]
        b = Xmin[k, 0]
        m = 0
        for q in range(Xmax.shape[1]):
            if np.isnan(Xmax[k, q]) or np.isnan(a):
                a = np.nan
            elif Xmax[k, q] > a:
                a = Xmax[k, q]
            if np.isnan(Xmin[k, q]) or np.isnan(b):
                b = np.nan
            elif Xmin[k, q] < b:
                b = Xmin[k, q]
        for q in range(M.shape[1]):
            m |= M[k, q]
        mx[k], mn[k], mask[k] = a, b, m


def classify_many(X, V, Xmax, Xmin, M, rtol: float, atol: float, max_period: int = MAX_PERIOD):
    """(period, max_X, min_X, mask, need, ok) of section data with one row per point (see
    :func:`classify`; the contact predicate is applied by the caller where ``ok``)."""
    k = X.shape[0]
    period = np.zeros(k, np.int64)
    need = np.zeros(k)
    mx = np.empty(k)
    mn = np.empty(k)
    mask = np.zeros(k, np.int64)
    ok = np.zeros(k, np.int8)
    _classify_many(np.ascontiguousarray(X, dtype=np.float64),
                   np.ascontiguousarray(V, dtype=np.float64),
                   np.ascontiguousarray(Xmax, dtype=np.float64),
                   np.ascontiguousarray(Xmin, dtype=np.float64),
                   np.ascontiguousarray(M, dtype=np.uint8), float(rtol), float(atol),
                   int(max_period), period, need, mx, mn, mask, ok)
    return period, mx, mn, mask, need, ok


def poincare(params: ParamsBase, *, record: int | None = None, transient: int, x0: float = 0.0,
             v0: float = 0.0, method: str = "smooth", rtol: float = 1e-8, atol: float = 1e-10,
             orbit_samples: int = 200, orbit_periods: int | None = None,
             settle: bool = False, progress=None, points: int | None = None,
             lyapunov: bool | None = None, section_phase: float = 0.0, u0=None) -> xr.Dataset:
    """Stroboscopic Poincaré section of one trajectory from (x0, v0) at t = 0 (at the forcing
    phase ``section_phase``, radians: the section is then t = t_s + kT, omega t_s = that
    phase).

    Integrates ``transient`` forcing periods (all of them unless ``settle=True``), then records
    ``record`` section points X[n], V[n] at t_section = (transient + n + 1) T (``points`` is
    the deprecated name of ``record``). A section still converging to a periodic orbit is
    integrated further before it is classified (``bifurcation.MAX_EXTENSION``); the variable
    ``transient_used`` gives the periods before the recorded window. Scalar variables
    ``period`` (0 = not periodic, -1 = not settled), ``max_X``, ``min_X``, ``contact`` are
    defined in the module docstring. After the section run, a phase-portrait trajectory
    ``orbit_X``, ``orbit_V``, ``orbit_region`` (dimension ``sample``, time ``orbit_t``) covers
    ``orbit_periods`` further periods (default: the detected period, or 20 periods when not
    periodic) at ``orbit_samples`` per period; it starts on the last section point, so the
    section points lie on it. ``progress`` (None or False: silent; True: a progress bar with a time
    estimate on a terminal, plain lines elsewhere; or a callable ``progress(done, total)``) is
    called between time slices.

    ``lyapunov`` (None, the default: yes; every model and method has tangent dynamics): also
    ``lambda1`` (largest Lyapunov exponent, per unit time) with its
    ``lambda1_stderr`` over ``record`` further periods of the attractor reached (tangent
    dynamics with saltation matrices, ``analysis.stability``), and ``motion``: periodic (a
    period was found), chaotic (lambda1 > 0 beyond 3 standard errors), quasi-periodic (no
    period, lambda1 within 3 errors of 0) or not settled.

    ``u0``: the initial state of every component instead of (x0, v0) (see ``simulate``).
    A model with more than two state components has a variable for each further one at the
    section points (named by its ``state_names``) and on the phase portrait (``orbit_<name>``)
    (the section is then integrated once more to record them: split-invariant kernels give
    the same points); ``nonsmooth.io.components(ds)`` / ``(ds, prefix="orbit_")`` assemble
    them.

    Raises IntegrationError if the trajectory fails (sweeps record failures instead).
    """
    from ..simulate import check_forced
    check_forced(params, "poincare")
    from ..sweep import progress_callback
    progress = progress_callback(progress, "poincare")
    from ..io import check_memory, flag_attrs, status_flags
    from ..simulate import (check_int, component_variables, renamed, start_attrs,
                            start_trajectory, state_u)
    from ..sweep import run_trajectories
    from .bifurcation import follow, summarize
    record = renamed("record", record, "points", points)
    params, solver, p, opts, state = start_trajectory(params, x0, v0, method, rtol, atol,
                                                      section_phase, u0)
    u_start = state_u(params.model, state)
    start_state = state.copy()
    record = check_int("record", record, 1)
    transient = check_int("transient", transient, 0)
    orbit_samples = check_int("orbit_samples", orbit_samples, 1)
    if orbit_periods is not None:
        orbit_periods = check_int("orbit_periods", orbit_periods, 1)
    big = max((record, "record"), (orbit_samples, "orbit_samples"),
              (orbit_periods or 64, "orbit_periods"))
    check_memory(34.0 * (record + orbit_samples * (orbit_periods or 64)), big[1],
                 "record fewer section points or draw a shorter, coarser orbit",
                 size=(big[0], 1))
    out = follow(p[None, None, :], solver, state[None, :], state.copy(), transient,
                 settle_tolerance(solver, settle), record, progress=progress)
    if out["status"][0, 0] == st.OK:
        summary = summarize(out, p[None, :], solver, transient, record)
    if out["status"][0, 0] != st.OK:
        raise IntegrationError(f"poincare: integration failed: {st.message(out['status'][0, 0])}")
    period, mx, mn, contact = (a[0, 0] for a in summary)
    used = int(out["used"][0, 0])
    X, V = out["X"][0, 0], out["V"][0, 0]
    if params.model.n > 2:  # the same section again, recording every component
        sec = run_trajectories(p[None, :], solver, start_state[None, :], per_period=1,
                               n_skip=used, n_out=record, workers=1, components=True)
        U = sec["U"][0]
        scale = 1.0 + float(np.max(np.abs(U[:, :2]))) if sec["status"][0] == st.OK else 0.0
        if sec["status"][0] != st.OK or not np.max(np.abs(U[:, 0] - X)) <= 1e-9 * scale:
            raise IntegrationError("poincare: the section integrated again to record every "
                                   "component does not repeat it")
    else:
        U = np.stack([X, V], axis=-1)

    n_orb = orbit_periods or (period if period > 0 else 20)
    ns = n_orb * orbit_samples
    state = out["S"][0, 0]
    orb = run_trajectories(p[None, :], solver, state[None, :], per_period=orbit_samples,
                           n_skip=0, n_out=ns, workers=1, components=True)
    if orb["status"][0] != st.OK:
        raise IntegrationError(f"poincare: orbit integration failed: "
                               f"{st.message(orb['status'][0])}")
    oX = np.concatenate([[state[0]], orb["X"][0]])
    oV = np.concatenate([[state[1]], orb["V"][0]])
    oR = np.concatenate([[int(state[ST_MODE])], orb["R"][0]]).astype(np.int8)
    oU = np.concatenate([state_u(params.model, state)[None, :], orb["U"][0]])

    T = params.period
    regions = flag_attrs(params.model.mode_names, dtype=np.int8)
    extra = {}
    from .stability import lyapunov_variables, wants_lyapunov
    if wants_lyapunov(lyapunov, solver):
        extra = lyapunov_variables(p[None, :], solver, out["S"][0], record,
                                   np.array([period]), ())
    ts = solver.section_phase * T / (2.0 * np.pi)  # the section's time in a period
    ds = xr.Dataset(
        {
            "X": ("n", X, {"long_name": "section displacement X(t_section)", "units": "1"}),
            "V": ("n", V, {"long_name": "section velocity dX/dt(t_section)", "units": "1/s"}),
            "period": ((), np.int64(period), {"long_name": PERIOD_LONG_NAME, "units": "1"}),
            "max_X": ((), mx, {"long_name": "largest X over the recorded periods (interior "
                                            "extrema included)", "units": "1"}),
            "min_X": ((), mn, {"long_name": "smallest X over the recorded periods (interior "
                                            "extrema included)", "units": "1"}),
            "contact": ((), np.int8(contact), flag_attrs(
                ("no_contact", "contact"), dtype=np.int8, long_name=f"{params.model.contact_name} "
                "during the recorded periods")),
            "status": ((), np.int64(st.OK), status_flags(long_name="kernel status")),
            "transient_used": ((), np.int64(used), {
                "long_name": "forcing periods integrated before the recorded window",
                "units": "1"}),
            "orbit_X": ("sample", oX, {"long_name": "phase-portrait displacement", "units": "1"}),
            "orbit_V": ("sample", oV, {"long_name": "phase-portrait velocity", "units": "1/s"}),
            "orbit_region": ("sample", oR, dict(regions, long_name=params.model.mode_long_name)),
            **component_variables(params.model, "n", U, what=" at the section"),
            **component_variables(params.model, "sample", oU, prefix="orbit_",
                                  what=" (phase portrait)"),
            **extra,
        },
        coords={
            "n": ("n", np.arange(record), {"long_name": "section index"}),
            "t_section": ("n", ts + (used + 1 + np.arange(record)) * T,
                          {"long_name": "section time", "units": "s"}),
            "orbit_t": ("sample", ts + (used + record) * T
                        + np.arange(ns + 1) * (T / orbit_samples),
                        {"long_name": "phase-portrait time", "units": "s"}),
        },
        attrs=provenance_attrs(params, solver, analysis="poincare", record=record,
                               transient=transient, settle=settle, **start_attrs(u_start),
                               forcing_period=T, max_period=MAX_PERIOD,
                               period_tolerance=section_tolerance(
                                   rtol, atol, max(np.max(np.abs(X)), np.max(np.abs(V)))),
                               orbit_periods=n_orb, orbit_samples=orbit_samples),
    )
    return apply_state_units(ds, params.model)
