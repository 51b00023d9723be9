"""Tangent dynamics of any model: the monodromy of the stroboscopic (period) map and
Benettin-normalised tangent vectors, from the tangent kernel ``integrate.hybrid.advance_tangent``
(variational equations within modes, saltation matrices at switches and resets).

The tangent space is the model's state u (n components) followed by its continuous memory
slots (``Method.continuous_memory``, e.g. the entry velocity of eq. 13a in the smoothed support
model): N = n + n_cm. A section point of the period map is therefore ``z = (u, memory)``;
models without continuous memory have z = u.
"""

from __future__ import annotations

import numpy as np

from . import status as st
from .errors import ParameterError
from .integrate.contract import ST_EXTRA, ST_V, ST_X
from .integrate.hybrid import advance_tangent
from .kernels import Solver, output_buffers


class TangentSetup:
    """What the tangent kernel needs for one solver: the model's functions, opts and the
    indices of its continuous memory slots."""

    def __init__(self, solver: Solver):
        m = solver.model
        self.solver = solver
        self.model = m
        self.fns = solver.fns
        self.opts = solver.opts()
        self.cmi = np.asarray(solver.spec.continuous_memory, dtype=np.int64)
        self.n = m.n
        self.N = m.n + len(self.cmi)

    # ---- section point z <-> kernel state ----
    def z_of(self, state: np.ndarray) -> np.ndarray:
        """The section point (u, continuous memory) of a kernel state."""
        n = self.n
        z = np.empty(self.N)
        z[0] = state[ST_X]
        z[1] = state[ST_V]
        z[2:n] = state[ST_EXTRA:ST_EXTRA + n - 2]
        for q, i in enumerate(self.cmi):
            z[n + q] = state[ST_EXTRA + n - 2 + i]
        return z

    def state_of(self, z: np.ndarray, template: np.ndarray) -> np.ndarray:
        """A kernel state at section point z, with the mode, flags and step size of
        ``template`` (mode < 0 lets the kernel classify the point)."""
        n = self.n
        s = template.copy()
        s[ST_X] = z[0]
        s[ST_V] = z[1]
        s[2] = z[1]
        s[ST_EXTRA:ST_EXTRA + n - 2] = z[2:n]
        for q, i in enumerate(self.cmi):
            s[ST_EXTRA + n - 2 + i] = z[n + q]
        return s

    def run(self, p, state, periods, Y, L=None, transient=0, per_period=1, out=None, U=None,
            section=None):
        """Advance ``state`` in place over ``transient + periods`` periods carrying Y; with L
        (periods x Y.shape[1]) re-orthonormalise each period and record the log norms; with U
        (outputs x n) record every state component; ``section`` = (H, SEC, U_sec, T_sec): a
        section surface (see ``hybrid.advance_tangent``). Returns (status, outputs) with the
        kernel's output buffers of the recorded periods."""
        n_out = periods * per_period
        bufs = out if out is not None else output_buffers(n_out)
        qr = 1 if L is not None else 0
        Lk = L if L is not None else np.zeros((0, 0))
        code = advance_tangent(self.fns, p, self.opts, state, per_period, transient * per_period,
                               n_out, *bufs, Y, Lk, self.cmi, qr,
                               U if U is not None else np.zeros((0, 0)),
                               *(section or (np.zeros(0), np.zeros(4), np.zeros((0, 0)),
                                             np.zeros(0))))
        return int(code), bufs


def period_map(setup: TangentSetup, p: np.ndarray, state: np.ndarray, k: int = 1):
    """The k-fold stroboscopic map from ``state`` (at a period boundary) and its Jacobian with
    respect to the section point z: returns (state after k periods, monodromy N x N, status,
    output buffers of the k periods, followed by U: every state component after each period,
    k x n). ``state`` is not modified."""
    s = state.copy()
    Y = np.eye(setup.N)
    U = np.empty((k, setup.n))
    code, bufs = setup.run(p, s, k, Y, U=U)
    return s, Y, code, (*bufs, U)


def fd_period_map(setup: TangentSetup, p: np.ndarray, state: np.ndarray, k: int = 1,
                  eps: float = 1e-6) -> np.ndarray:
    """Central finite differences of the kernel's own k-fold map of the section point z (no
    tangent dynamics): the independent check of :func:`period_map`'s monodromy. Each z_j is
    perturbed by eps max(1, |z_j|); raises if a perturbed trajectory fails."""
    from .kernels import run
    from .models.base import KERNEL_GENERIC
    z0 = setup.z_of(state)
    M = np.empty((setup.N, setup.N))
    for j in range(setup.N):
        h = eps * max(1.0, abs(z0[j]))
        cols = []
        for sg in (1.0, -1.0):
            z = z0.copy()
            z[j] += sg * h
            s = setup.state_of(z, state)
            code = run(KERNEL_GENERIC, setup.fns, p, setup.opts, s, 1, 0, k,
                       *output_buffers(k))
            check_code(code, "fd_period_map")
            cols.append(setup.z_of(s))
        M[:, j] = (cols[0] - cols[1]) / (2.0 * h)
    return M


def check_code(code: int, what: str) -> None:
    if code != st.OK:
        raise ParameterError(f"{what}: the trajectory failed ({st.message(code)})")


__all__ = ["TangentSetup", "period_map", "fd_period_map"]
