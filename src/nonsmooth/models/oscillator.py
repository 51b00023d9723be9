"""Helpers shared by the built-in one-degree-of-freedom models (state u = (X, V)): a switching
surface as an affine guard row (see :mod:`.base`), inlined into the models' compiled
functions; :func:`curved_row` marks a guard of any smooth form, for models of any dimension."""

import math

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


@nb.njit(cache=True, inline="always")
def curved_row(G, k):
    """Surface k is curved: the kernel evaluates it, and its gradient, by the method's
    ``curved(mode, k, t, c, s, u, p, mem, grad)`` (marker: NaN in the constant column)."""
    n = G.shape[1] - 3
    for i in range(G.shape[1]):
        G[k, i] = 0.0
    G[k, n] = math.nan


@nb.njit(cache=True, inline="always")
def label_row(G, k):
    """Surface k is curved and a *label* (``integrate.contract``): the mode across it has the
    same field, the transition resets nothing, and it is the only surface of both modes, so
    the kernel switches the mode at the end of the first step past it instead of locating the
    crossing."""
    curved_row(G, k)
    G[k, G.shape[1] - 2] = 1.0
