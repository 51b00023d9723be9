"""Period detection on stroboscopic section points, with a tolerance tied to the integrator's."""

from __future__ import annotations

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


def period_of(X, V, rtol: float, atol: float, max_period: int = 64) -> int:
    """Convenience wrapper: period of the section points with the solver's tolerance."""
    X = np.ascontiguousarray(X, dtype=np.float64)
    V = np.ascontiguousarray(V, dtype=np.float64)
    scale = float(np.nanmax(np.abs(np.concatenate([X, V])))) if X.size else 1.0
    return int(detect_period(X, V, section_tolerance(rtol, atol, scale), max_period))
