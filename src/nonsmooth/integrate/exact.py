"""Exact event-driven solver of the non-smooth system (placeholder until the exact issue lands)."""

import numba as nb

from .. import status as st


@nb.njit(cache=True)
def advance_exact(p, opts, state, per_period, n_skip, n_out, X_out, V_out, R_out, M_out,
                  Xmax_out, Xmin_out):
    return st.EVENT_FAILED
