"""Helpers shared by the built-in one-degree-of-freedom models (state u = (X, V)): a switching
surface as an affine guard row (see :mod:`.base`), inlined into the models' compiled
functions."""

import numba as nb


@nb.njit(cache=True, inline="always")
def forced_row(G, k, cx, cv, c0, ccos):
    """Surface k: g = cx X + cv V + c0 + ccos cos(omega t) (>= 0 inside the mode)."""
    G[k, 0] = cx
    G[k, 1] = cv
    G[k, 2] = c0
    G[k, 3] = ccos
    G[k, 4] = 0.0


@nb.njit(cache=True, inline="always")
def row(G, k, cx, cv, c0):
    """Surface k: g = cx X + cv V + c0 (>= 0 inside the mode)."""
    forced_row(G, k, cx, cv, c0, 0.0)
