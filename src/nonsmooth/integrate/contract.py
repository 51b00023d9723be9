"""The contract every trajectory kernel implements (smoothed RKF45, exact, later models).

A kernel ``advance(p, opts, state, per_period, n_skip, n_out, X, V, R, M, Xmax, Xmin) -> status``
integrates from a forcing-period boundary (local time 0) over ``n_skip + n_out`` output
intervals of length T / ``per_period`` (T = 2 pi / omega); the local time is reset to 0 at every
period boundary, so the numbers do not depend on how a run is split into calls that each start
on a period boundary. For output k (0 <= k < n_out), at the end of interval ``n_skip + k``:

* ``X[k], V[k]``  the state;
* ``R[k]``        the region/mode code at that instant (int8);
* ``M[k]``        bit mask of the codes visited during the interval (uint8, bit r = code r);
* ``Xmax[k], Xmin[k]``  the extremes of X over the interval (interior extrema included).

``p`` is ``Params.pack()``; ``opts`` and ``state`` are float64 arrays with the layouts below;
``state`` is updated in place so that the next call continues the same trajectory. Kernels never
print or raise: they return a status code from :mod:`nonsmooth.status`.
"""

# opts layout
OPT_RTOL = 0
OPT_ATOL = 1
OPT_MAX_STEPS = 2  # steps allowed per forcing period, on average over a call
OPT_TRANSITION = 3  # models.switch.TRANSITION_EQ13 / TRANSITION_EQ12 (smoothed model only)
N_OPTS = 4

# state layout
ST_X = 0
ST_V = 1
ST_VA = 2  # entry velocity into Sigma_alpha (eq. 13a memory); unused by the exact model
ST_MODE = 3  # region/mode code; -1 = classify from (X, V) at the start
ST_H = 4  # step size to try next (adaptive kernels); <= 0 = choose
N_STATE = 5


def _signatures():
    from numba import types as t

    f8 = t.float64[:]  # any layout: the kernels touch these arrays once per call or interval
    args = (f8, f8, f8, t.int64, t.int64, t.int64, f8, f8, t.int8[:], t.uint8[:], f8, f8)
    return t.int64(*args), t.int64(t.int64, *args)


#: Explicit numba signatures of a kernel and of the method dispatcher. Compiling the kernels
#: for exactly these types means one machine-code version each: without them numba would
#: compile (and cache) a new copy of every kernel for each combination of literal integers
#: that a caller happens to pass.
KERNEL_SIGNATURE, DISPATCH_SIGNATURE = _signatures()
