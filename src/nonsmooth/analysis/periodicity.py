"""Period detection on stroboscopic section points, with a tolerance tied to the integrator's."""

from __future__ import annotations

import math

import numba as nb
import numpy as np

#: How many times the integration tolerance two section points of a periodic orbit may differ.
#: Section points of a settled periodic orbit repeat to about the global integration error,
#: which stays within ~100x the local tolerance over a period; chaotic section points are
#: orders of magnitude further apart.
TOL_FACTOR = 1e3


def section_tolerance(rtol: float, atol: float, scale: float = 1.0) -> float:
    """Distance under which two section points count as the same: TOL_FACTOR*(rtol*scale+atol)."""
    return TOL_FACTOR * (rtol * max(1.0, abs(scale)) + atol)


@nb.njit(cache=True)
def detect_period(X, V, tol, max_period):
    """Smallest p <= max_period such that every recorded section point repeats after p
    periods within ``tol`` (in X and in V); 0 if none (chaotic, quasi-periodic or not settled).
    Needs at least 2 p points to accept period p. NaNs give 0."""
    n = X.shape[0]
    for p in range(1, max_period + 1):
        if n < 2 * p:
            return 0
        ok = True
        for k in range(n - p):
            if not (abs(X[k + p] - X[k]) <= tol and abs(V[k + p] - V[k]) <= tol):
                ok = False
                break
        if ok:
            return p
    return 0


#: Period code of a section that is still converging to a periodic orbit whose period could
#: not be decided within the allowed transient ("not settled"; 0 = not periodic).
NOT_SETTLED = -1
#: Without a period found, a section counts as converging only if the largest repetition
#: defect fell by at least this factor over the recorded window (chaotic defects fluctuate,
#: they do not decay); with a period p found, a smaller period q dividing p is still being
#: approached if its defects fell by more than 4 x the tolerance (on a settled period-p
#: orbit they vary by at most 2 x the tolerance).
MIN_DECAY = 0.8
#: ... and the decay rates between the window's segments agree within this factor (geometric
#: decay).
RATE_SPREAD = 4.0


#: The recorded window is cut into this many segments for the convergence test.
N_SEGMENTS = 8


@nb.njit(cache=True)
def _segment_maxima(X, V, q, out):
    """Largest repetition defect max(|X[k+q]-X[k]|, |V[k+q]-V[k]|) in each of the last
    ``len(out)`` equal segments of the window (oldest first); returns the segment length."""
    m = X.shape[0] - q
    ns = out.shape[0]
    L = m // ns
    s = m - ns * L
    for j in range(ns):
        d = 0.0
        for k in range(s + j * L, s + (j + 1) * L):
            d = max(d, abs(X[k + q] - X[k]), abs(V[k + q] - V[k]))
        out[j] = d
    return L


@nb.njit(cache=True)
def still_converging(X, V, tol, period, max_period):
    """Periods still needed before the section (X, V) repeats within ``tol`` with a smaller
    period than ``period`` (0 = none found): for every candidate q (q < period dividing it,
    or any q <= max_period when period = 0; each of the window's N_SEGMENTS segments, half as
    many when a period was found, must span at least q periods), the largest repetition defect of each segment is computed; the
    section is converging with period q if these fall strictly from segment to segment (see
    MIN_DECAY), at rates agreeing within RATE_SPREAD, and are still above ``tol``. Returns the
    estimated periods until the defects are below ``tol`` (geometric extrapolation from the
    observed rate) for the first such q, 0.0 if there is none. A transient that still looks
    chaotic at the end of the window is not recognised (it gives 0.0)."""
    n = X.shape[0]
    nseg = N_SEGMENTS if period == 0 else N_SEGMENTS // 2  # chaos is excluded when p repeats
    mq = np.empty(nseg)
    last = nseg - 1
    qmax = period - 1 if period > 0 else max_period
    for q in range(1, qmax + 1):
        if period > 0 and period % q != 0:
            continue
        if nseg * q > n - q:
            break
        L = _segment_maxima(X, V, q, mq)
        # no period found (chaos?): a clear decay; a period found (the orbit repeats): any
        # decay well above the repetition tolerance
        if not (mq[last] > tol and (mq[last] <= MIN_DECAY * mq[0] if period == 0
                                    else mq[0] - mq[last] > 4.0 * tol)):
            continue
        lo = 0.0
        hi = -np.inf
        falling = True
        for j in range(last):
            falling = falling and mq[j + 1] < mq[j]
            if falling:
                r = math.log(mq[j + 1] / mq[j])
                lo = min(lo, r)
                hi = max(hi, r)
        if not falling or hi * RATE_SPREAD > lo:  # the slowest rate RATE_SPREAD x slower
            continue
        rate = math.log(mq[last] / mq[0]) / (last * L)  # per period, < 0
        return math.log(tol / mq[last]) / rate + L
    return 0.0


def period_of(X, V, rtol: float, atol: float, max_period: int = 64) -> int:
    """Convenience wrapper: period of the section points with the solver's tolerance."""
    X = np.ascontiguousarray(X, dtype=np.float64)
    V = np.ascontiguousarray(V, dtype=np.float64)
    scale = float(np.nanmax(np.abs(np.concatenate([X, V])))) if X.size else 1.0
    return int(detect_period(X, V, section_tolerance(rtol, atol, scale), max_period))
