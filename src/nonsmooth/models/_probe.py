"""Calls into a model's compiled functions from Python (definition-time checks and tests):
one compiled, cached entry per function kind, for every model (the functions arrive as the
first-class ``fns`` tuple, as in the generic kernel)."""

import warnings

import numba as nb

warnings.filterwarnings("ignore", category=nb.NumbaExperimentalFeatureWarning)


@nb.njit(cache=True)
def call_field(fns, mode, t, c, s, u, p, mem, du):
    return fns[0](mode, t, c, s, u, p, mem, du)


@nb.njit(cache=True)
def call_jacobian(fns, mode, t, c, s, u, p, mem, J):
    return fns[1](mode, t, c, s, u, p, mem, J)


@nb.njit(cache=True)
def call_guards(fns, mode, p, mem, G):
    return fns[2](mode, p, mem, G)


@nb.njit(cache=True)
def call_transition(fns, mode, k, t, c, s, u, p, mem):
    return fns[3](mode, k, t, c, s, u, p, mem)


@nb.njit(cache=True)
def call_initial(fns, c, s, u, p, mem):
    return fns[4](c, s, u, p, mem)


@nb.njit(cache=True)
def call_linear(fns, mode, p, out):
    return fns[5](mode, p, out)


@nb.njit(cache=True)
def call_curved(fns, mode, k, t, c, s, u, p, mem, grad):
    return fns[6](mode, k, t, c, s, u, p, mem, grad)
