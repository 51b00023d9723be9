"""Kernel dispatch and solver settings shared by ``simulate`` and every analysis.

Every analysis calls a kernel with the model's compiled functions ``fns`` (a tuple of numba
first-class functions, see :mod:`nonsmooth.models.base`): the generic kernel
(:mod:`nonsmooth.integrate.hybrid`) integrates any model from ``fns``; the built-in ``support``
model also has specialised kernels with its functions inlined (today's speed). Python code calls
:func:`run` with the kernel's code; the compiled cores that run many trajectories receive the
kernel as a first-class function (:attr:`Solver.kernel`, :func:`tangent_function`), so that
numba does not link and optimise the kernel again into each of them. Passing compiled functions
as first-class ``FunctionType`` values keeps every core cacheable on disk (a dispatcher argument
would not be). A new model needs no edit here.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numba as nb
import numpy as np

from .checks import check_solver_options
from .errors import ParameterError
import warnings

from .integrate.contract import (
    DISPATCH_SIGNATURE,
    GENERIC_KERNEL_SIGNATURE,
    KERNEL_SIGNATURE,
    MAX_GUARDS,
    N_OPTS,
    N_STATE,
    OPT_ATOL,
    OPT_CLOSED_FORM,
    OPT_MAX_STEPS,
    OPT_N,
    OPT_NMEM,
    OPT_FRAME_PERIOD,
    OPT_NO_DOP853,
    OPT_OMEGA,
    OPT_PHASE,
    OPT_RTOL,
    OPT_VARIANT,
    ST_EXTRA,
    ST_MODE,
    ST_V,
    ST_X,
    TANGENT_KERNEL_SIGNATURE,
    KernelFunction,
)
from .integrate.hybrid import advance_generic, advance_tangent, frame_omega
from .models.base import DEFAULT_MODEL, KERNEL_GENERIC, KERNEL_SUPPORT_EXACT, KERNEL_SUPPORT_SMOOTH
from .models.support.exact_kernel import advance_exact
from .models.support.smooth_kernel import advance_smooth
from .models.support.switch import beta_ratio, inside_margin
from .models.support.parameters import IDX

_I_OMEGA_S = IDX["omega_s"]
_I_XI_S = IDX["xi_s"]
_I_ETA = IDX["eta"]

warnings.filterwarnings("ignore", category=nb.NumbaExperimentalFeatureWarning)

#: Kernel codes of the built-in support model's methods (kept for today's callers).
METHOD_SMOOTH = KERNEL_SUPPORT_SMOOTH
METHOD_EXACT = KERNEL_SUPPORT_EXACT
METHODS = {"smooth": METHOD_SMOOTH, "exact": METHOD_EXACT}


@nb.njit(DISPATCH_SIGNATURE, cache=True, inline="always")
def run(kernel, fns, p, opts, state, per_period, n_skip, n_out, X, V, R, M, Xmax, Xmin):
    """Run kernel ``kernel`` (a code of ``models.base``) on the model functions ``fns`` (see
    ``integrate.contract``); returns its status."""
    if kernel == KERNEL_GENERIC:
        return advance_generic(fns, p, opts, state, per_period, n_skip, n_out, X, V, R, M,
                               Xmax, Xmin)
    if kernel == KERNEL_SUPPORT_EXACT:
        return advance_exact(p, opts, state, per_period, n_skip, n_out, X, V, R, M, Xmax, Xmin)
    return advance_smooth(p, opts, state, per_period, n_skip, n_out, X, V, R, M, Xmax, Xmin)


@nb.njit(GENERIC_KERNEL_SIGNATURE, cache=True)
def _support_exact(fns, p, opts, state, per_period, n_skip, n_out, X, V, R, M, Xmax, Xmin):
    """The support model's exact kernel behind the generic signature (``fns`` unused)."""
    return advance_exact(p, opts, state, per_period, n_skip, n_out, X, V, R, M, Xmax, Xmin)


@nb.njit(GENERIC_KERNEL_SIGNATURE, cache=True)
def _support_smooth(fns, p, opts, state, per_period, n_skip, n_out, X, V, R, M, Xmax, Xmin):
    """The support model's smoothed kernel behind the generic signature (``fns`` unused)."""
    return advance_smooth(p, opts, state, per_period, n_skip, n_out, X, V, R, M, Xmax, Xmin)


@functools.cache
def kernel_function(code: int) -> KernelFunction:
    """The kernel of ``code`` (a code of ``models.base``) as a first-class function with the
    generic kernel's signature, for the compiled cores that take it as an argument (one
    object per process: its address is looked up once)."""
    return KernelFunction({KERNEL_GENERIC: advance_generic, KERNEL_SUPPORT_EXACT: _support_exact,
                           KERNEL_SUPPORT_SMOOTH: _support_smooth}[code],
                          GENERIC_KERNEL_SIGNATURE)


@functools.cache
def tangent_function() -> KernelFunction:
    """``hybrid.advance_tangent`` as a first-class function (see :func:`kernel_function`)."""
    return KernelFunction(advance_tangent, TANGENT_KERNEL_SIGNATURE)


@nb.njit(cache=True)
def mode_holds(kernel, fns, p, opts, state):
    """Does the mode carried in ``state`` still hold for parameters ``p`` (at the section,
    forcing phase ``opts[OPT_PHASE]``)? Used
    after a parameter change in a continuation sweep: mode borders move with parameters."""
    mode = int(state[ST_MODE])
    if kernel == KERNEL_SUPPORT_SMOOTH:
        r = beta_ratio(p[_I_OMEGA_S], p[_I_XI_S])
        return inside_margin(mode, state[ST_X], state[ST_V], p[_I_ETA], r) >= 0.0
    if kernel != KERNEL_GENERIC:
        return True
    n = int(opts[OPT_N])
    nm = int(opts[OPT_NMEM])
    u = np.empty(n)
    u[0] = state[ST_X]
    u[1] = state[ST_V]
    for i in range(2, n):
        u[i] = state[ST_EXTRA + i - 2]
    mem = np.empty(max(nm, 1))
    for i in range(nm):
        mem[i] = state[ST_EXTRA + n - 2 + i]
    pp = np.empty(p.shape[0])
    pp[:] = p
    G = np.empty((MAX_GUARDS, n + 3))
    ng = fns[2](mode, pp, mem, G)
    psi = opts[OPT_PHASE]  # t = t_s: the forcing phase of the section
    c = math.cos(psi)
    s = math.sin(psi)
    grad = np.empty(n + 1)
    for k in range(ng):
        if math.isnan(G[k, n]):  # a curved guard (``curved_row``)
            g = fns[6](mode, k, psi / frame_omega(pp, opts), c, s, u, pp, mem, grad)
        else:
            g = G[k, n] + G[k, n + 1] * c + G[k, n + 2] * s
            for i in range(n):
                g += G[k, i] * u[i]
        if g < 0.0:
            return False
    return True


@nb.njit(KERNEL_SIGNATURE.return_type(nb.int64, *KERNEL_SIGNATURE.args), cache=True)
def advance(method, p, opts, state, per_period, n_skip, n_out, X, V, R, M, Xmax, Xmin):
    """The support model's kernels by method code (``METHOD_SMOOTH``/``METHOD_EXACT``), as
    before the model interface; returns the status."""
    if method == METHOD_EXACT:
        return advance_exact(p, opts, state, per_period, n_skip, n_out, X, V, R, M, Xmax, Xmin)
    return advance_smooth(p, opts, state, per_period, n_skip, n_out, X, V, R, M, Xmax, Xmin)


@dataclass(frozen=True)
class Solver:
    """How trajectories of ``model`` (default: the paper's ``support``) are computed:
    ``method`` one of the model's methods ("smooth": a switch model, RKF45; "exact":
    non-smooth, event-driven; support also has "smooth_eq12"); tolerances; ``max_steps`` per
    forcing period before giving up; ``section_phase``: the forcing phase psi = omega t_s
    (radians, 0 <= psi < 2 pi) at which periods start, so the stroboscopic section is
    t = t_s + kT and a trajectory starts at t_s (the generic kernel runs a model whose
    specialised kernels know only psi = 0)."""

    method: str = "smooth"
    rtol: float = 1e-8
    atol: float = 1e-10
    max_steps: int = 200_000
    model: object = None
    section_phase: float = 0.0

    def __post_init__(self):
        from .models import model as get_model
        object.__setattr__(self, "model", get_model(self.model or DEFAULT_MODEL))
        self.model.method(self.method)  # one-line error for an unknown method
        ph = check_solver_options(self.rtol, self.atol, self.section_phase)
        if not (isinstance(self.max_steps, int) and self.max_steps > 0):
            raise ParameterError(f"max_steps: must be a positive integer, got {self.max_steps!r}")
        object.__setattr__(self, "section_phase", ph)

    @property
    def spec(self):
        """The model's :class:`~nonsmooth.models.base.Method` of this solver."""
        return self.model.method(self.method)

    @property
    def code(self) -> int:
        """Kernel code for :func:`run` (the generic kernel at a section phase other than 0)."""
        return self.spec.kernel if self.section_phase == 0.0 else KERNEL_GENERIC

    @property
    def kernel(self) -> KernelFunction:
        """The kernel of :attr:`code` as a first-class function (:func:`kernel_function`)."""
        return kernel_function(self.code)

    @property
    def fns(self) -> tuple:
        """The model's compiled functions for :func:`run` (compiled once, cached)."""
        return self.model.fns(self.method)

    def advance(self, p, opts, state, per_period, n_skip, n_out, X, V, R, M, Xmax, Xmin) -> int:
        """One kernel call from Python (see ``integrate.contract``); returns the status. A
        specialised kernel is called without the model's functions: passing them from Python
        costs ~30 us per call (numba unboxes each first-class function)."""
        if self.code == KERNEL_GENERIC:
            return run(self.code, self.fns, p, opts, state, per_period, n_skip, n_out, X, V, R,
                       M, Xmax, Xmin)
        return advance(self.code, p, opts, state, per_period, n_skip, n_out, X, V, R, M, Xmax,
                       Xmin)

    def opts(self) -> np.ndarray:
        m = self.spec
        o = np.zeros(N_OPTS)
        o[OPT_RTOL] = self.rtol if m.rtol is None else min(self.rtol, m.rtol)
        o[OPT_ATOL] = self.atol if m.atol is None else min(self.atol, m.atol)
        o[OPT_MAX_STEPS] = self.max_steps
        o[OPT_VARIANT] = m.variant
        o[OPT_OMEGA] = self.model.frame_index
        o[OPT_FRAME_PERIOD] = 1.0 if self.model.period is not None else 0.0
        o[OPT_N] = self.model.n
        o[OPT_NMEM] = self.model.n_memory
        o[OPT_CLOSED_FORM] = 1.0 if m.closed_form else 0.0
        o[OPT_PHASE] = self.section_phase
        o[OPT_NO_DOP853] = 0.0 if m.dop853 else 1.0
        return o

    def attrs(self) -> dict:
        m = self.spec
        o = self.opts()
        a = {"model": self.model.name, "state_names": " ".join(self.model.state_names),
             "method": self.method, "rtol": float(o[OPT_RTOL]),
             "atol": float(o[OPT_ATOL]), "max_steps_per_period": int(self.max_steps),
             "section_phase": self.section_phase}
        if self.model.source != "built-in":  # a user's file (``path.py:NAME``): figures load it
            a["model_source"] = self.model.source
        if m.unused:  # (their param_* attrs are the values kept, not read: exact's eta)
            a["unused_parameters"] = " ".join(m.unused)
        if self.code == KERNEL_SUPPORT_SMOOTH:
            a["integrator"] = smooth_integrator()
        elif self.code == KERNEL_SUPPORT_EXACT:
            a["integrator"] = ("closed form between located switching events (event times to "
                               "2e-14 max(1, T); rtol and atol are not used)")
        else:
            a["integrator"] = m.description or generic_integrator(m.closed_form)
        return a


def smooth_integrator() -> str:
    """Description of the smoothed-model integrator, read from the constants of the code that
    runs (``integrate.rkstep``: propagated order, step-size controller)."""
    from .integrate import rkstep as k
    q = k.RKF45_ORDER
    return (f"RKF45 (order-{q + 1} propagation, elementary step-size control "
            f"h_new = {k._SAFETY:g} h err^(-{k._EXPO:g}) limited to [{k._FAC_MIN:g}, "
            f"{k._FAC_MAX:g}] h, located switches)")


def generic_integrator(closed_form: bool) -> str:
    """Description of the generic kernel's integration."""
    base = smooth_integrator().replace(", located switches)", ", located switches and resets)")
    if closed_form:
        return "closed form for linear modes, else " + base
    return base


def new_state(x0: float, v0: float, extra=()) -> np.ndarray:
    """Initial kernel state (mode classified by the kernel, step size chosen by it);
    ``extra`` = u[2:] of a model with more than two state components."""
    s = np.zeros(N_STATE)
    s[ST_EXTRA:ST_EXTRA + len(extra)] = extra
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
