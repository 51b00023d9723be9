"""Writing a kernel's outputs and final state in the layout of :mod:`.contract` (shared by
every kernel so the layout lives in one place)."""

import numba as nb

from .contract import ST_H, ST_MODE, ST_V, ST_VA, ST_X


@nb.njit(cache=True, inline="always")
def record_interval(it, n_skip, X, V, mode, mask, xmax, xmin, X_out, V_out, R_out, M_out,
                    Xmax_out, Xmin_out):
    """Store the end of output interval ``it`` (nothing while ``it < n_skip``)."""
    if it >= n_skip:
        k = it - n_skip
        X_out[k] = X
        V_out[k] = V
        R_out[k] = mode
        M_out[k] = mask
        Xmax_out[k] = xmax
        Xmin_out[k] = xmin


@nb.njit(cache=True, inline="always")
def store_state(state, X, V, Va, mode, h):
    """Write the continuation state (see ``contract``) back for the next call."""
    state[ST_X] = X
    state[ST_V] = V
    state[ST_VA] = Va
    state[ST_MODE] = mode
    state[ST_H] = h
