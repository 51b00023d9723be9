"""Run many independent trajectories: all local cores by default (numba threads).

Every trajectory is independent and computed by the same kernel with the same inputs, so the
numbers do not depend on the number of workers or on how the points are split into chunks.
A failing trajectory gets a non-zero ``status`` (see :mod:`nonsmooth.status`) and NaN outputs;
it never stops the sweep.
"""

from __future__ import annotations

import contextlib
import os
import time

import numba as nb
import numpy as np

from .errors import ParameterError
from .kernels import Solver, advance
from .integrate.contract import N_STATE


@nb.njit(cache=True, parallel=True)
def _run_many(method, P, opts, states, per_period, n_skip, n_out, X, V, R, M, Xmax, Xmin, status):
    n = P.shape[0]
    for i in nb.prange(n):
        status[i] = advance(method, P[i], opts, states[i], per_period, n_skip, n_out,
                            X[i], V[i], R[i], M[i], Xmax[i], Xmin[i])
        if status[i] != 0:
            for k in range(n_out):
                X[i, k] = np.nan
                V[i, k] = np.nan
                Xmax[i, k] = np.nan
                Xmin[i, k] = np.nan
                R[i, k] = -1
                M[i, k] = 0


def resolve_workers(workers: int | None) -> int:
    """Number of threads: ``None`` or 0 = all local cores."""
    n_max = nb.config.NUMBA_NUM_THREADS
    if workers is None or workers == 0:
        return n_max
    if not isinstance(workers, (int, np.integer)) or workers < 0:
        raise ParameterError(f"workers: must be a positive integer, got {workers!r}")
    return int(min(workers, n_max))


@contextlib.contextmanager
def threads(workers: int | None):
    """Context manager setting numba's thread count for the parallel kernels."""
    old = nb.get_num_threads()
    nb.set_num_threads(resolve_workers(workers))
    try:
        yield
    finally:
        nb.set_num_threads(old)


def run_trajectories(P, solver: Solver, states, *, per_period: int, n_skip: int, n_out: int,
                     workers: int | None = None, chunk: int | None = None, progress=None):
    """Integrate ``len(P)`` trajectories (rows of packed parameters ``P``, initial kernel
    states ``states``, both modified copies are returned) over ``n_skip + n_out`` intervals
    of T/per_period, recording the last ``n_out`` (see ``integrate.contract``).

    Returns a dict with X, V, R, M, Xmax, Xmin of shape (n, n_out), ``status`` (n,) and the
    final ``state`` (n, 5). ``progress(done, total)`` is called after each chunk.
    """
    P = np.ascontiguousarray(np.atleast_2d(np.asarray(P, dtype=np.float64)))
    states = np.array(states, dtype=np.float64, copy=True).reshape(-1, N_STATE)
    n = P.shape[0]
    if states.shape[0] != n:
        raise ParameterError(f"states: expected {n} rows, got {states.shape[0]}")
    out = {
        "X": np.empty((n, n_out)), "V": np.empty((n, n_out)),
        "R": np.empty((n, n_out), np.int8), "M": np.empty((n, n_out), np.uint8),
        "Xmax": np.empty((n, n_out)), "Xmin": np.empty((n, n_out)),
        "status": np.zeros(n, np.int64),
    }
    opts = solver.opts()
    nw = resolve_workers(workers)
    if chunk is None:
        chunk = max(4 * nw, n // 50 or 1)
    with threads(nw):
        for a in range(0, n, chunk):
            b = min(n, a + chunk)
            _run_many(solver.code, P[a:b], opts, states[a:b], per_period, n_skip, n_out,
                      out["X"][a:b], out["V"][a:b], out["R"][a:b], out["M"][a:b],
                      out["Xmax"][a:b], out["Xmin"][a:b], out["status"][a:b])
            if progress is not None:
                progress(b, n)
    out["state"] = states
    return out


class Progress:
    """A rich progress bar with ETA that only appears for runs longer than ``delay`` seconds
    and only on a terminal (or when NONSMOOTH_PROGRESS=1)."""

    def __init__(self, description: str, delay: float = 2.0, enabled: bool | None = None):
        self.description = description
        self.delay = delay
        if enabled is None:
            enabled = os.environ.get("NONSMOOTH_PROGRESS", "") == "1" or (
                hasattr(os.sys.stderr, "isatty") and os.sys.stderr.isatty())
        self.enabled = enabled
        self._bar = None
        self._task = None
        self._t0 = time.perf_counter()

    def __call__(self, done: int, total: int):
        if not self.enabled:
            return
        if self._bar is None:
            if time.perf_counter() - self._t0 < self.delay and done < total:
                return
            from rich.progress import (BarColumn, MofNCompleteColumn, Progress as RP,
                                       TimeElapsedColumn, TimeRemainingColumn)
            from rich.console import Console
            self._bar = RP("[progress.description]{task.description}", BarColumn(),
                           MofNCompleteColumn(), TimeElapsedColumn(), TimeRemainingColumn(),
                           console=Console(stderr=True), transient=False)
            self._bar.start()
            self._task = self._bar.add_task(self.description, total=total)
        self._bar.update(self._task, completed=done, total=total)
        if done >= total:
            self.close()

    def close(self):
        if self._bar is not None:
            self._bar.stop()
            self._bar = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
