"""Method dispatch and solver settings shared by ``simulate`` and every analysis.

Numba cannot cache functions that receive other compiled functions as arguments, so the
methods are selected by an integer code inside one compiled dispatcher. A new model adds its
kernel module (implementing :mod:`nonsmooth.integrate.contract`) and one branch here.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba as nb
import numpy as np

from .errors import ParameterError
from .integrate.contract import DISPATCH_SIGNATURE, N_OPTS, N_STATE, OPT_ATOL, OPT_MAX_STEPS, OPT_RTOL, OPT_TRANSITION
from .integrate.exact import advance_exact
from .integrate.rkf45 import advance_smooth
from .models.switch import TRANSITIONS

METHOD_SMOOTH = 0
METHOD_EXACT = 1
METHODS = {"smooth": METHOD_SMOOTH, "exact": METHOD_EXACT}


@nb.njit(DISPATCH_SIGNATURE, cache=True)
def advance(method, p, opts, state, per_period, n_skip, n_out, X, V, R, M, Xmax, Xmin):
    """Run the kernel of ``method`` (see ``integrate.contract``); returns its status."""
    if method == METHOD_EXACT:
        return advance_exact(p, opts, state, per_period, n_skip, n_out, X, V, R, M, Xmax, Xmin)
    return advance_smooth(p, opts, state, per_period, n_skip, n_out, X, V, R, M, Xmax, Xmin)


@dataclass(frozen=True)
class Solver:
    """How trajectories are computed: ``method`` "smooth" (switch model, RKF45) or "exact"
    (event-driven closed form, eta = 0); tolerances; ``transition`` "eq13" (paper) or "eq12"
    (convex combinations); ``max_steps`` per forcing period before giving up."""

    method: str = "smooth"
    rtol: float = 1e-8
    atol: float = 1e-10
    transition: str = "eq13"
    max_steps: int = 200_000

    def __post_init__(self):
        if self.method not in METHODS:
            raise ParameterError(f"method: unknown method {self.method!r} (known: {', '.join(METHODS)})")
        if self.transition not in TRANSITIONS:
            raise ParameterError(
                f"transition: unknown transition {self.transition!r} (known: {', '.join(TRANSITIONS)})")
        for name in ("rtol", "atol"):
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and 0 < v < 1):
                raise ParameterError(f"{name}: must satisfy 0 < {name} < 1, got {v!r}")
        if not (isinstance(self.max_steps, int) and self.max_steps > 0):
            raise ParameterError(f"max_steps: must be a positive integer, got {self.max_steps!r}")

    @property
    def code(self) -> int:
        return METHODS[self.method]

    def opts(self) -> np.ndarray:
        o = np.zeros(N_OPTS)
        o[OPT_RTOL] = self.rtol
        o[OPT_ATOL] = self.atol
        o[OPT_MAX_STEPS] = self.max_steps
        o[OPT_TRANSITION] = TRANSITIONS[self.transition]
        return o

    def attrs(self) -> dict:
        a = {"method": self.method, "rtol": float(self.rtol), "atol": float(self.atol),
             "max_steps_per_period": int(self.max_steps)}
        if self.method == "smooth":
            a["transition"] = self.transition
            a["integrator"] = smooth_integrator()
        else:
            a["integrator"] = "closed form between located switching events"
        return a


def smooth_integrator() -> str:
    """Description of the smoothed-model integrator, read from the constants of the code that
    runs (``integrate.rkf45``: propagated order, step-size controller)."""
    from .integrate import rkf45 as k
    q = k.RKF45_ORDER
    return (f"RKF45 (order-{q + 1} propagation, elementary step-size control "
            f"h_new = {k._SAFETY:g} h err^(-{k._EXPO:g}) limited to [{k._FAC_MIN:g}, "
            f"{k._FAC_MAX:g}] h, located switches)")


def new_state(x0: float, v0: float) -> np.ndarray:
    """Initial kernel state (mode classified by the kernel, step size chosen by it)."""
    s = np.zeros(N_STATE)
    s[0] = x0
    s[1] = v0
    s[2] = v0
    s[3] = -1.0
    s[4] = 0.0
    return s


def output_buffers(n: int):
    """Arrays for ``n`` outputs: X, V, R, M, Xmax, Xmin."""
    return (np.empty(n), np.empty(n), np.empty(n, np.int8), np.empty(n, np.uint8),
            np.empty(n), np.empty(n))
