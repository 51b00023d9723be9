"""Run many independent trajectories: all local cores by default (numba threads).

Every trajectory is independent and computed by the same kernel with the same inputs, so the
numbers do not depend on the number of workers or on how the points are split into chunks.
A failing trajectory gets a non-zero ``status`` (see :mod:`nonsmooth.status`) and NaN outputs;
it never stops the sweep.
"""

from __future__ import annotations

import contextlib
import os
import signal
import threading
import time

import numba as nb
import numpy as np

from .checks import check_workers
from .errors import ParameterError
from .kernels import Solver, tangent_function
from .integrate.contract import KERNEL_FN_TYPE, MODEL_FNS_TYPE, N_STATE, OPT_N
from .models.base import KERNEL_GENERIC


_F2 = nb.float64[:, :]
#: one signature (any layout): time slices of the outputs are non-contiguous views
_RUN_MANY_SIG = nb.void(KERNEL_FN_TYPE, MODEL_FNS_TYPE, _F2, nb.float64[:], _F2, nb.int64, nb.int64, nb.int64, _F2, _F2,
                        nb.int8[:, :], nb.uint8[:, :], _F2, _F2, nb.int64[:])


@nb.njit(_RUN_MANY_SIG, cache=True, parallel=True)
def _run_many(kernel, fns, P, opts, states, per_period, n_skip, n_out, X, V, R, M, Xmax, Xmin,
              status):
    """One slice of every trajectory whose ``status`` is still 0 (failed ones are skipped);
    ``kernel`` a :class:`~nonsmooth.integrate.contract.KernelFunction`."""
    for i in nb.prange(P.shape[0]):
        if status[i] == 0:
            status[i] = kernel(fns, P[i], opts, states[i], per_period, n_skip, n_out,
                                X[i], V[i], R[i], M[i], Xmax[i], Xmin[i])


@nb.njit(cache=True, parallel=True)
def _run_many_components(tangent, fns, P, opts, states, per_period, n_skip, n_out, X, V, R, M,
                         Xmax, Xmin, status, U):
    """``_run_many`` on the generic kernel that also records every state component:
    U[i, k, :] = u at output k of trajectory i (``hybrid.advance_tangent`` without tangent
    vectors)."""
    n = int(opts[OPT_N])
    for i in nb.prange(P.shape[0]):
        if status[i] == 0:
            Ui = np.empty((n_out, n))
            status[i] = tangent(fns, P[i], opts, states[i], per_period, n_skip, n_out, X[i],
                                V[i], R[i], M[i], Xmax[i], Xmin[i], np.zeros((n, 0)),
                                np.zeros((0, 0)), np.zeros(0, np.int64), 0, Ui, np.zeros(0),
                                np.zeros(4), np.zeros((0, 0)), np.zeros(0))
            for k in range(n_out):
                for c in range(n):
                    U[i, k, c] = Ui[k, c]


#: Seconds of work per compiled call of a long run: Ctrl-C (KeyboardInterrupt) and progress
#: reports happen between calls, so a run stops within about this time of a SIGINT.
SLICE_SECONDS = 0.1


_DEFERRED = (signal.SIGINT, signal.SIGTERM)


@contextlib.contextmanager
def deferred_interrupts():
    """Within the block (a compiled call), SIGINT and SIGTERM are held and delivered when it
    ends: a signal that arrived while numba was unboxing a model's compiled functions would
    otherwise surface as a TypeError from numba's dispatcher instead of a clean stop. Compiled
    code cannot be interrupted anyway, so no responsiveness is lost. Main thread only."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    got = []
    old = {}
    for s in _DEFERRED:
        h = signal.getsignal(s)
        if callable(h):  # a Python handler (KeyboardInterrupt, the CLI's SIGTERM): hold it
            old[s] = h
            signal.signal(s, lambda signum, frame: got.append(signum))
    try:
        yield
    finally:
        for s, h in old.items():
            signal.signal(s, h)
        for s in dict.fromkeys(got):
            signal.raise_signal(s)


class Slicer:
    """Sizes of the slices of a long run (forcing periods per trajectory and compiled call):
    each slice is sized from the measured speed of the previous one so that a call takes about
    ``SLICE_SECONDS`` (growing at most 4x per slice, never below ``minimum``). The kernels are
    split-invariant (contract), so the results do not depend on the slices."""

    def __init__(self, first: int = 1, minimum: int = 1):
        self.minimum = max(1, int(minimum))
        self.size = max(self.minimum, int(first))

    def run(self, call):
        """``call(size)`` once, timed; adapts the next size. Returns what ``call`` returns."""
        t0 = time.perf_counter()
        with deferred_interrupts():
            res = call(self.size)
        dt = time.perf_counter() - t0
        grow = 4.0 if dt <= 0.0 else min(4.0, SLICE_SECONDS / dt)
        self.size = max(self.minimum, int(self.size * grow))
        return res


def resolve_workers(workers: int | None) -> int:
    """Number of threads: ``None`` or 0 = all local cores."""
    n_max = nb.config.NUMBA_NUM_THREADS
    check_workers(workers)
    if workers is None or workers == 0:
        return n_max
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


@contextlib.contextmanager
def parallel_chunks(size: int = 8):
    """Within the block, numba's parallel loops hand out iterations in chunks of ``size``
    (dynamic scheduling) instead of one equal share per thread: points of very unequal cost
    (a settled point stops early, a chaotic one runs its whole transient) then keep every
    thread busy. Only the scheduling changes, never a number."""
    old = nb.get_parallel_chunksize()
    nb.set_parallel_chunksize(size)
    try:
        yield
    finally:
        nb.set_parallel_chunksize(old)


def run_trajectories(P, solver: Solver, states, *, per_period: int, n_skip: int, n_out: int,
                     workers: int | None = None, chunk: int | None = None, progress=None,
                     components: bool = False):
    """Integrate ``len(P)`` trajectories (rows of packed parameters ``P``, initial kernel
    states ``states``, both modified copies are returned) over ``n_skip + n_out`` intervals
    of T/per_period, recording the last ``n_out`` (see ``integrate.contract``).

    Returns a dict with X, V, R, M, Xmax, Xmin of shape (n, n_out), ``status`` (n,) and the
    final ``state`` (n, 5). The trajectories are run in chunks of ``chunk`` and each chunk in
    time slices (:class:`Slicer`); ``progress(done, total)`` is called after each slice, in
    trajectory-periods. ``components=True`` adds ``U`` (n, n_out, model.n): every state
    component at each output (a model with n > 2 then runs on the generic kernel's entry that
    records them; for n = 2, U is (X, V)).
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
    full = components and solver.model.n > 2
    if full:
        if solver.code != KERNEL_GENERIC:
            raise ParameterError("components: a specialised kernel records X and V only")
        out["U"] = np.empty((n, n_out, solver.model.n))
    nw = resolve_workers(workers)
    if chunk is None:
        chunk = max(4 * nw, n // 50 or 1)
    total = n_skip + n_out  # intervals of T/per_period
    with threads(nw):
        for a in range(0, n, chunk):
            b = min(n, a + chunk)
            slicer = Slicer()
            k = 0
            while True:  # one call at least, also for no intervals (it classifies the mode)
                m = min(total - k, slicer.size * per_period)
                skip = max(0, min(k + m, n_skip) - k)
                o0, o1 = max(k, n_skip) - n_skip, k + m - n_skip
                o1 = max(o0, o1)
                sl = (slice(a, b), slice(o0, o1))
                args = (P[a:b], opts, states[a:b], per_period, skip, o1 - o0,
                        *(out[key][sl] for key in ("X", "V", "R", "M", "Xmax", "Xmin")),
                        out["status"][a:b])
                if full:
                    slicer.run(lambda _size: _run_many_components(tangent_function(), solver.fns,
                                                                  *args,
                                                                  out["U"][sl]))
                else:
                    slicer.run(lambda _size: _run_many(solver.kernel, solver.fns, *args))
                k += m
                if progress is not None:
                    progress((a * total + (b - a) * k) // per_period, n * total // per_period)
                if k >= total:
                    break
    failed = out["status"] != 0
    if components and not full:
        out["U"] = np.stack([out["X"], out["V"]], axis=-1)
    for key in ("X", "V", "Xmax", "Xmin") + (("U",) if components else ()):
        out[key][failed] = np.nan
    out["R"][failed] = -1
    out["M"][failed] = 0
    out["state"] = states
    return out


def progress_callback(progress, description: str):
    """The callable behind a ``progress`` argument of the public API: None or False -> None
    (silent); True -> a :class:`Progress` bar named ``description``; a callable
    ``progress(done, total)`` -> itself. Anything else is a one-line ParameterError."""
    if progress is None or progress is False:
        return None
    if progress is True:
        return Progress(description, enabled=True)
    if callable(progress):
        return progress
    raise ParameterError(f"progress: expected True, False, None or a callable progress(done, "
                         f"total), got {progress!r}")


class Progress:
    """A rich progress bar with ETA that only appears for runs longer than ``delay`` seconds
    and only on a terminal; with NONSMOOTH_PROGRESS=1 and no terminal, plain progress lines.
    ``progress(done, total)`` may report any unit of work (points, forcing periods)."""

    #: Seconds between two plain progress lines.
    LINE_EVERY = 10.0

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
        self._next_line = 0.0

    def __call__(self, done: int, total: int):
        if not self.enabled:
            return
        if not (hasattr(os.sys.stderr, "isatty") and os.sys.stderr.isatty()):
            self._line(done, total)
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

    def _line(self, done: int, total: int):
        """Not on a terminal (a log, NONSMOOTH_PROGRESS=1): a plain line every LINE_EVERY
        seconds after ``delay``, with the fraction done and the time left at the mean rate."""
        now = time.perf_counter() - self._t0
        if now < self.delay or now < self._next_line or done >= total or done <= 0:
            return
        self._next_line = now + self.LINE_EVERY
        left = now * (total - done) / done
        print(f"{self.description}: {100.0 * done / total:.1f}% of {total}, "
              f"{now:.0f} s elapsed, about {left:.0f} s left", file=os.sys.stderr, flush=True)

    def close(self):
        if self._bar is not None:
            self._bar.stop()
            self._bar = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
