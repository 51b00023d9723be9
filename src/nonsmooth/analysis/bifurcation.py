"""Bifurcation (orbit) diagrams over any parameter, with continuation up and down.

``up``/``down`` sweeps carry the whole kernel state (X, V, the eq. 13a memory Va, the region and
the step size) from one parameter value to the next, so the response follows a branch until it
disappears: that is how jumps and hysteresis show. The two directions are independent and run
in parallel (numba ``prange`` over the directions); within a direction the values are
sequential. ``fresh`` restarts every value from (x0, v0) and runs all values in parallel.
The compiled continuation core :func:`continuation` is shared with the resonance curves.

A failing point (non-zero kernel status) gets NaN data and its status; the sweep continues on
that branch from (x0, v0) at the next value.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np
import xarray as xr

from .. import status as st
from ..checks import SWEEPS, check_sweep_memory  # noqa: F401 (here first)
from ..errors import ParameterError
from ..io import apply_state_units, provenance_attrs
from ..integrate.contract import KERNEL_FN_TYPE, MODEL_FNS_TYPE
from ..kernels import Solver, mode_holds
from ..models.base import ParamsBase
from ..sweep import parallel_chunks
from .poincare import (MAX_PERIOD, PERIOD_LONG_NAME, SETTLE_WINDOW, classify_many, settle,
                       settle_tolerance)



@nb.njit(cache=True)
def _fix_mode(method, fns, p, opts, state):
    """After a parameter change, reclassify the mode if the carried one no longer holds
    (mode borders move with the parameters). The memory is kept where the mode holds."""
    if state[3] >= 0 and not mode_holds(method, fns, p, opts, state):
        state[3] = -1.0


_F3 = nb.float64[:, :, :]
_I8_2 = nb.int64[:, :]
#: one signature (any layout): chunks of the value axis are non-contiguous views, whole small
#: sweeps are contiguous; without it numba would compile and cache both versions
_CONTINUATION_SIG = nb.void(KERNEL_FN_TYPE, nb.int64, MODEL_FNS_TYPE, _F3, nb.float64[:], nb.float64[:, :], nb.float64[:], nb.int64,
                            nb.float64, _F3, _F3, nb.int8[:, :, :], nb.uint8[:, :, :], _F3, _F3,
                            _I8_2, _I8_2, _F3, _I8_2, nb.int64)

#: Columns of the per-branch progress counters ``prog`` of :func:`continuation`: the value
#: index, the transient periods done at that value, the phase, the section points recorded.
PG_VALUE, PG_DONE, PG_PHASE, PG_REC = 0, 1, 2, 3
N_PROG = 4
_START, _SETTLE, _RECORD = 0, 1, 2


@nb.njit(_CONTINUATION_SIG, cache=True, parallel=True)
def continuation(kernel, method, fns, P, opts, states, init, transient, settle_tol,
                 X, V, R, M, Xmax, Xmin, status, used, S, prog, budget):
    """For every branch b (in parallel) and parameter row i (in order): continue
    ``states[b]`` with parameters ``P[b, i]`` for ``transient`` periods (ended early when
    settled, ``settle_tol`` > 0, see ``poincare.settle``) and record ``X.shape[2]`` section
    points into ``X[b, i]`` ... and the state after it into ``S[b, i]``. A failed point gets
    NaN outputs and status != 0, and the branch restarts from ``init`` at the next row.

    Resumable: each call integrates about ``budget`` forcing periods per branch and returns;
    ``states`` and the progress counters ``prog`` (branch, N_PROG; zeros to start) are updated
    in place, and the next call goes on from there. Calls cut on settle-window and period
    boundaries, so the results do not depend on the budgets. ``kernel``: the solver's
    ``KernelFunction``, ``method`` its kernel code (for ``mode_holds``)."""
    nb_, ni = P.shape[0], P.shape[1]
    nrec = X.shape[2]
    for b in nb.prange(nb_):
        work = 0
        while prog[b, PG_VALUE] < ni and work < budget:
            i = prog[b, PG_VALUE]
            if prog[b, PG_PHASE] == _START:
                _fix_mode(method, fns, P[b, i], opts, states[b])
                prog[b, PG_DONE] = 0
                prog[b, PG_REC] = 0
                prog[b, PG_PHASE] = _SETTLE
            code = 0
            if prog[b, PG_PHASE] == _SETTLE:
                d0 = prog[b, PG_DONE]
                code, d, fin = settle(kernel, fns, P[b, i], opts, states[b], transient, settle_tol,
                                      d0, budget - work)
                work += d - d0
                prog[b, PG_DONE] = d
                if code == 0 and fin:
                    prog[b, PG_PHASE] = _RECORD
            if code == 0 and prog[b, PG_PHASE] == _RECORD and (work < budget or nrec == 0):
                r = prog[b, PG_REC]
                n = min(nrec - r, max(budget - work, 1))
                code = kernel(fns, P[b, i], opts, states[b], 1, 0, n, X[b, i, r:r + n],
                              V[b, i, r:r + n], R[b, i, r:r + n], M[b, i, r:r + n],
                              Xmax[b, i, r:r + n], Xmin[b, i, r:r + n])
                work += n
                prog[b, PG_REC] = r + n
                if code == 0 and r + n == nrec:
                    prog[b, PG_PHASE] = _START
            if code != 0:
                for k in range(nrec):
                    X[b, i, k] = np.nan
                    V[b, i, k] = np.nan
                    Xmax[b, i, k] = np.nan
                    Xmin[b, i, k] = np.nan
                    R[b, i, k] = -1
                    M[b, i, k] = 0
                prog[b, PG_PHASE] = _START
            if prog[b, PG_PHASE] == _START:  # this value is finished
                status[b, i] = code
                used[b, i] = prog[b, PG_DONE]
                if code != 0:
                    for k in range(states.shape[1]):
                        states[b, k] = init[k]
                for k in range(states.shape[1]):
                    S[b, i, k] = states[b, k]
                prog[b, PG_VALUE] = i + 1


def check_values(name: str, values) -> np.ndarray:
    """1-d float array of at least 2 finite, distinct values, sorted ascending."""
    try:
        v = np.asarray(values, dtype=np.float64).ravel()
    except (TypeError, ValueError):
        raise ParameterError(f"{name}: expected numbers") from None
    if v.size < 2:
        raise ParameterError(f"{name}: need at least 2 values, got {v.size}")
    if not np.all(np.isfinite(v)):
        raise ParameterError(f"{name}: values must be finite")
    v = np.sort(v)
    if np.any(np.diff(v) <= 0):
        raise ParameterError(f"{name}: values must be distinct")
    return v


def param_rows(params: ParamsBase, param: str, values) -> np.ndarray:
    """Packed parameters, one row per value. A parameter's allowed values are an interval (and
    a model's cross-field rule holds on an interval of each parameter, as support's omega_s = 0
    needs xi_s = 0), so validating the smallest and the largest value validates them all."""
    values = np.asarray(values, dtype=np.float64)
    for x in (values.min(), values.max()):
        params.replace(**{param: float(x)})
    rows = np.tile(params.pack(), (values.size, 1))
    rows[:, params.model.index[param]] = values
    return rows


def follow(P, solver: Solver, states, init, transient: int, settle_tol: float, record: int,
           *, workers=None, progress=None, group: int | None = None, start=None,
           on_slice=None):
    """Run :func:`continuation` over the packed parameters ``P`` (branch, value, 7) from
    ``states`` (branch, 5; updated in place) in time slices (``sweep.Slicer``: each compiled
    call returns to Python after about 0.1 s, so Ctrl-C stops it and progress is reported,
    ``progress(done, total)`` in periods of the planned work), ``group`` branches at a time.
    Returns dict of X, V, R, M, Xmax, Xmin (branch, value, record), ``status`` and ``used``
    (branch, value) and ``S`` (branch, value, 5). ``start``: the value index each branch
    starts at (default 0; the outputs before it are left unset); ``on_slice(values_done,
    out)`` is called after each slice with the number of values each branch has finished."""
    from ..sweep import Slicer, threads
    nbr, nval = P.shape[0], P.shape[1]
    X = np.empty((nbr, nval, record))
    out = {"X": X, "V": np.empty_like(X), "R": np.empty(X.shape, np.int8),
           "M": np.empty(X.shape, np.uint8), "Xmax": np.empty_like(X),
           "Xmin": np.empty_like(X), "status": np.zeros((nbr, nval), np.int64),
           "used": np.zeros((nbr, nval), np.int64), "S": np.empty((nbr, nval, states.shape[1]))}
    prog = np.zeros((nbr, N_PROG), np.int64)
    if start is not None:
        prog[:, PG_VALUE] = start
    opts = solver.opts()
    per_value = transient + record
    group = nbr if group is None else max(1, group)
    with threads(workers):
        for a in range(0, nbr, group):
            b = min(nbr, a + group)
            sl = Slicer(first=SETTLE_WINDOW, minimum=SETTLE_WINDOW)
            args = [v[a:b] for v in (out["X"], out["V"], out["R"], out["M"], out["Xmax"],
                                     out["Xmin"], out["status"], out["used"], out["S"])]
            while np.any(prog[a:b, PG_VALUE] < nval):
                sl.run(lambda size: continuation(solver.kernel, solver.code, solver.fns, P[a:b], opts, states[a:b], init,
                                                 transient, settle_tol, *args, prog[a:b], size))
                if progress is not None:
                    g = prog[:b]
                    part = np.where(g[:, PG_PHASE] == _RECORD, transient + g[:, PG_REC],
                                    np.where(g[:, PG_PHASE] == _SETTLE, g[:, PG_DONE], 0))
                    progress(int(np.sum(g[:, PG_VALUE] * per_value + part)),
                             nbr * nval * per_value)
                if on_slice is not None:
                    on_slice(prog[:, PG_VALUE], out)
    return out


#: Values per chunk of a continuation sweep (each direction is a chain of chunks, each chunk
#: continued from the state its predecessor ended with; the directions never wait for each
#: other) and of a fresh sweep (independent chunks). Chunks are the unit of resumption
#: (``nonsmooth.chunks``); they never change a number.
BRANCH_CHUNK = 25
FRESH_CHUNK = 100


#: Cost of a recorded period of lambda1 evidence, in periods of the sweep (progress estimate).
_EVIDENCE_COST = 3


def run_branches(params: ParamsBase, param: str, values, solver: Solver, *, directions,
                 transient: int, record: int, x0: float, v0: float, settle: bool,
                 workers=None, progress=None, lyapunov: bool = False, store=None, engine=None,
                 analysis: str = "bifurcation", fingerprint: dict | None = None,
                 first_window: bool = False, extra=()):
    """Run continuation branches over sorted ``values``; ``directions`` lists "up", "down"
    or "fresh"; the first value starts from (x0, v0, ``extra`` = u[2:]). Returns dict of arrays (branch, value, n) in ascending value order, plus
    ``status`` and ``used`` (branch, value), ``S`` the kernel state after each value
    (branch, value, 5), the classification of :func:`summarize` (``period``, ``max_X``,
    ``min_X``, ``contact``), with ``lyapunov`` ``lambda1``, ``lambda1_stderr`` and ``motion``,
    and the final ``state`` per branch. With ``first_window``, also ``first_max_X``,
    ``first_S`` and ``first_status``: max X, state and status of the first recorded window,
    before sections still converging were extended (what the resonance refinement starts from).

    The sweeps are computed in chunks (:data:`BRANCH_CHUNK` values of every direction, each
    chunk continued from the states the previous one ended with; a fresh sweep in independent
    chunks of :data:`FRESH_CHUNK`) by ``engine`` (``chunks.execute``); with ``store`` (a
    directory) finished chunks are written there and a re-run resumes from them. The
    classification (:func:`classify_block`) then runs once over all values, here: its
    extensions of the sections still converging and its lambda1 run in parallel over every
    point of the sweep, not a chunk's few. ``progress(done, total)`` is called after each
    time slice (see :func:`follow`)."""
    from ..chunks import Plan, chunk_bounds, execute, plan_solver
    from ..kernels import new_state
    values = np.asarray(values, dtype=np.float64)
    nv = values.size
    rows = param_rows(params, param, values)
    init = new_state(x0, v0, tuple(extra))
    fresh = list(directions) == ["fresh"]
    orders = [np.arange(nv) if d != "down" else np.arange(nv)[::-1] for d in directions]
    bounds = chunk_bounds(nv, FRESH_CHUNK if fresh else BRANCH_CHUNK)
    nk = len(bounds)
    spec = {"solver": plan_solver(solver, engine), "rows": rows, "orders": orders,
            "fresh": fresh, "init": init, "transient": int(transient), "record": int(record),
            "settle_tol": settle_tolerance(solver, settle), "bounds": bounds}
    nbr = 1 if fresh else len(directions)
    plan = Plan(analysis, {**(fingerprint or {}), "param": param, "values": values,
                           "directions": list(directions), "transient": transient,
                           "record": record, "x0": x0, "v0": v0, "settle": bool(settle),
                           **({"u0_extra": [float(e) for e in extra]} if len(extra) else {}),
                           "params": dict(zip(params.model.param_names, rows[0])),
                           "solver": spec["solver"], "chunk": bounds[0][1] - bounds[0][0]},
                nbr * nk, _branch_chunk, spec,
                chains=None if fresh else [i // nk for i in range(nbr * nk)],
                stream=None if fresh else _branch_stream,
                weights=[(b - a) * (transient + record) for _ in range(nbr) for a, b in bounds])
    X = np.empty((nbr, nv, record))
    out = {"X": X, "V": np.empty_like(X), "R": np.empty(X.shape, np.int8),
           "M": np.empty(X.shape, np.uint8), "Xmax": np.empty_like(X),
           "Xmin": np.empty_like(X), "status": np.zeros((nbr, nv), np.int64),
           "used": np.zeros((nbr, nv), np.int64), "S": np.empty((nbr, nv, init.size)),
           "state": np.tile(init, (nbr, 1))}

    def collect(i, res):
        d, k = divmod(i, nk)
        a, b = bounds[k]
        for key, v in res.items():
            if key == "carry":
                if k == nk - 1:
                    out["state"][d] = v
            else:
                out[key][d, orders[d][a:b]] = v
    # the classification after the chunks (extensions of converging sections, lambda1) is
    # part of the work: the progress total holds an estimate of it, reported done at its end
    seen = [0]
    extra = nbr * nv * record * (_EVIDENCE_COST if lyapunov else 1)

    def report(done, total):
        seen[0] = total + extra
        progress(done, total + extra)
    execute(plan, collect, store=store, engine=engine, workers=workers,
            progress=None if progress is None else report)
    if fresh:
        out["state"] = out["S"][0].copy()
    P = np.ascontiguousarray(np.broadcast_to(rows[None], (nbr,) + rows.shape))
    classify_block(out, P, solver, transient, record, lyapunov, floquet=True,
                   first_window=first_window, workers=workers)
    if progress is not None and seen[0]:
        progress(seen[0], seen[0])
    return out


def _branch_rows(spec, d, a, b):
    """Packed parameters of values a ... b-1 of direction d (its sweep order)."""
    return spec["rows"][spec["orders"][d][a:b]]


def _branch_chunk(spec, i, carry, workers=None, progress=None):
    """Chunk ``i`` of :func:`run_branches` (a ``chunks.Plan`` task): a block of values of one
    direction (fresh: independent values), continued from ``carry``."""
    from ..chunks import solver_from_spec
    solver = solver_from_spec(spec["solver"])
    nk = len(spec["bounds"])
    d, k = divmod(i, nk)
    a, b = spec["bounds"][k]
    init = spec["init"]
    if spec["fresh"]:
        P = np.ascontiguousarray(_branch_rows(spec, 0, a, b)[:, None, :])
    else:
        P = np.ascontiguousarray(_branch_rows(spec, d, a, b)[None])
    states = (np.array(carry, dtype=np.float64, copy=True)[None] if carry is not None
              else np.tile(init, (P.shape[0], 1)))
    with parallel_chunks():
        out = follow(P, solver, states, init, spec["transient"], spec["settle_tol"],
                     spec["record"], workers=workers, progress=progress)
    if spec["fresh"]:
        return {key: v[:, 0] for key, v in out.items()}  # (value, ...)
    res = {key: v[0] for key, v in out.items()}
    res["carry"] = states[0].copy()
    return res


def _branch_stream(spec, todo, carries, emit, workers=None, progress=None):
    """All the pending chunks of the continuation directions in one :func:`follow` (a
    ``chunks.Plan`` stream): every direction runs on without waiting for the others at chunk
    boundaries, and each block is emitted (with the state after its last value as carry) as
    soon as its direction has finished it. Each chunk equals :func:`_branch_chunk`'s."""
    from ..chunks import solver_from_spec
    solver = solver_from_spec(spec["solver"])
    bounds, nk, init = spec["bounds"], len(spec["bounds"]), spec["init"]
    dirs = sorted(todo)
    nv = spec["rows"].shape[0]
    P = np.ascontiguousarray(np.stack([_branch_rows(spec, d, 0, nv) for d in dirs]))
    states = np.stack([init if carries[d] is None else np.asarray(carries[d], np.float64)
                       for d in dirs])
    pending = [list(todo[d]) for d in dirs]
    start = np.array([bounds[q[0] % nk][0] for q in pending], np.int64)

    def on_slice(values_done, out):
        for j, d in enumerate(dirs):
            while pending[j] and values_done[j] >= bounds[pending[j][0] % nk][1]:
                i = pending[j].pop(0)
                a, b = bounds[i % nk]
                res = {key: v[j, a:b].copy() for key, v in out.items()}
                res["carry"] = out["S"][j, b - 1].copy()
                emit(i, res)
    with parallel_chunks():
        follow(P, solver, states, init, spec["transient"], spec["settle_tol"], spec["record"],
               workers=workers, progress=progress, start=start, on_slice=on_slice)


def sweep_block(P, solver: Solver, states, init, transient: int, settle_tol: float, record: int,
                lyapunov: bool = False, *, floquet: bool = False, workers=None,
                progress=None) -> dict:
    """:func:`follow` over packed parameters ``P`` (branch, value, n_par) from ``states``
    (branch, 5), then :func:`classify_block`. ``carry``: the states after the last value of
    each branch. Parallel loops are scheduled dynamically (``sweep.parallel_chunks``)."""
    with parallel_chunks():
        out = follow(P, solver, states, init, transient, settle_tol, record, workers=workers,
                     progress=progress)
        out["carry"] = states.copy()
        classify_block(out, P, solver, transient, record, lyapunov, floquet=floquet,
                       workers=workers)
    return out


def classify_block(out, P, solver: Solver, transient: int, record: int, lyapunov: bool = False,
                   *, floquet: bool = False, first_window: bool = False, workers=None) -> dict:
    """Add to the :func:`follow` output ``out`` (points (branch, value), packed parameters
    ``P`` (branch, value, n_par)) the classification of :func:`summarize` (``period``,
    ``max_X``, ``min_X``, ``contact``; sections still converging are extended in ``out``) and,
    with ``lyapunov``, ``lambda1``, ``lambda1_stderr``, ``motion`` per point (over ``record``
    further periods of its attractor, ``analysis.stability.lambda1_points``; with ``floquet``
    a periodic point's lambda1 is ln|mu_1| / (p T) of its leading Floquet multiplier instead,
    with stderr 0, ``stability.floquet_lambda1_points``). With ``first_window``, first
    ``first_max_X``, ``first_S``, ``first_status`` of the window before any extension."""
    with parallel_chunks():
        if first_window:  # before summarize extends the sections still converging
            out.update(first_max_X=out["Xmax"].max(axis=2), first_S=out["S"].copy(),
                       first_status=out["status"].copy())
        period, mx, mn, contact = summarize(out, P, solver, transient, record, workers)
        out.update(period=period, max_X=mx, min_X=mn, contact=contact)
        if lyapunov:
            from .stability import classify_points, lambda1_evidence
            nb_, nv = period.shape
            flat_P, flat_S = P.reshape(nb_ * nv, -1), out["S"].reshape(nb_ * nv, -1)
            per = period.ravel() if floquet else np.zeros(nb_ * nv, np.int64)
            lam, err = lambda1_evidence(flat_P, solver, flat_S, record, per, workers=workers)
            lam, err = lam.reshape(nb_, nv), err.reshape(nb_, nv)
            failed = out["status"] != st.OK
            lam[failed] = np.nan
            err[failed] = np.nan
            motion = classify_points(lam, err, period)
            motion[failed] = 0
            out.update(lambda1=lam, lambda1_stderr=err, motion=motion)
    return out


#: A section that is still converging (``periodicity.still_converging``) is integrated
#: further, from the end of its recorded window, by about 1.5 x the number of periods it is
#: estimated to need (rounded up to a power of 2, at least ``record``; ended early once settled,
#: ``poincare.settle``; points of equal extension run in parallel) and recorded again, in
#: at most MAX_ROUNDS rounds and MAX_EXTENSION x max(transient, record) periods in all; what is
#: still undecided then is labelled NOT_SETTLED (period -1). Sections that do not converge
#: (chaos) are never extended.
MAX_EXTENSION = 20
MAX_ROUNDS = 3


def summarize(out, rows, solver: Solver, transient: int, record: int, workers=None):
    """period, max_X, min_X, contact per (branch, value) of ``out``; ``rows``: the packed
    parameters, (value, n_par) shared by the branches or (branch, value, n_par). Sections still converging are extended
    first (see MAX_EXTENSION): their data in ``out`` (X ... Xmin, ``used``: the periods
    before the recorded window, ``S``) are replaced by the later window."""
    shape = out["status"].shape
    rows = np.asarray(rows)
    if rows.ndim == 2:
        rows = np.broadcast_to(rows[None], (shape[0],) + rows.shape)
    period = np.zeros(shape, np.int64)
    mx = np.full(shape, np.nan)
    mn = np.full(shape, np.nan)
    contact = np.zeros(shape, np.int8)
    cap = MAX_EXTENSION * max(transient, record)
    extra = np.zeros(shape, np.int64)
    todo = [tuple(q) for q in np.argwhere(out["status"] == st.OK).tolist()]
    model = solver.model

    def is_contact(row, m, a, b):  # the model's contact predicate at the packed ``row``
        return model.is_contact(_LazyParams(model, row), m, a, b)

    for rnd in range(MAX_ROUNDS + 1):
        pending = {}  # extension (a power of 2 periods, at least ``record``) -> points
        jj = np.array([q[0] for q in todo], np.int64)
        ii = np.array([q[1] for q in todo], np.int64)
        c_per, c_mx, c_mn, c_mask, c_need, c_ok = classify_many(
            out["X"][jj, ii], out["V"][jj, ii], out["Xmax"][jj, ii], out["Xmin"][jj, ii],
            out["M"][jj, ii], solver.rtol, solver.atol)
        period[jj, ii], mx[jj, ii], mn[jj, ii], contact[jj, ii] = c_per, c_mx, c_mn, 0
        for k in np.flatnonzero(c_ok).tolist():
            j, i = todo[k]
            contact[j, i] = int(bool(is_contact(rows[j, i], int(c_mask[k]), float(c_mx[k]),
                                                float(c_mn[k]))))
        for k in np.flatnonzero(c_need > 0).tolist():
            j, i = todo[k]
            need = float(c_need[k])
            if rnd < MAX_ROUNDS and extra[j, i] + record + need <= cap:
                ext = max(record, 1 << int(math.ceil(math.log2(1.5 * need))))
                ext = min(ext, cap - int(extra[j, i]) - record)
                pending.setdefault(ext, []).append((j, i))
        for ext, points in pending.items():
            idx = tuple(np.array(points).T)
            states = out["S"][idx].copy()
            res = follow(np.ascontiguousarray(rows[idx][:, None, :]), solver, states,
                         states[0].copy(), ext, settle_tolerance(solver, True), record,
                         workers=workers)
            for k, (j, i) in enumerate(points):
                out["status"][j, i] = res["status"][k, 0]
                for key in ("X", "V", "R", "M", "Xmax", "Xmin", "S"):
                    out[key][j, i] = res[key][k, 0]
                out["used"][j, i] += record + res["used"][k, 0]
                extra[j, i] += record + res["used"][k, 0]
        todo = [q for points in pending.values() for q in points]
        if not todo:
            break
    if model.n > 2:
        _confirm_full_state(out, rows, solver, period, workers)
    failed = out["status"] != st.OK
    period[failed], contact[failed], mx[failed], mn[failed] = 0, 0, np.nan, np.nan
    return period, mx, mn, contact


def _confirm_full_state(out, rows, solver: Solver, period, workers=None) -> None:
    """A model with more state components than X and V: a period p found on the section's
    (X, V) must repeat every component too. Each such point is integrated p periods on from
    its final state (``out["S"]``, on the section) and each component compared with the
    section tolerance of :func:`~.periodicity.detect_period`; where one differs (a component
    that X and V do not see, or barely), the point is not periodic (``period`` 0, in place)."""
    from ..integrate.contract import ST_EXTRA, ST_V, ST_X
    from ..sweep import run_trajectories
    from .periodicity import section_tolerance
    cols = [ST_X, ST_V] + list(range(ST_EXTRA, ST_EXTRA + solver.model.n - 2))
    for p in np.unique(period[period > 0]).tolist():
        idx = tuple(np.argwhere(period == p).T)
        S = out["S"][idx]
        res = run_trajectories(rows[idx], solver, S, per_period=1, n_skip=int(p), n_out=0,
                               workers=workers)
        U0, U1 = S[:, cols], res["state"][:, cols]
        tol = np.array([section_tolerance(solver.rtol, solver.atol, float(np.max(np.abs(u))))
                        for u in U0])
        same = (res["status"] == st.OK) & np.all(np.abs(U1 - U0) <= tol[:, None], axis=1)
        period[tuple(a[~same] for a in idx)] = 0


class _LazyParams:
    """The model's validated parameters at a packed row, built only if a contact predicate
    reads one (most read none: building them for every point of a map costs more than
    classifying it)."""

    def __init__(self, model, row):
        self._model, self._row, self._params = model, row, None

    def __getattr__(self, name):
        if self._params is None:
            m = self._model
            self._params = m.params(**dict(zip(m.param_names, map(float, self._row))))
        return getattr(self._params, name)


def bifurcation_diagram(params: ParamsBase, param: str, values, *, sweep: str = "both",
                        transient: int = 500, record: int = 200, method: str = "smooth",
                        x0: float = 0.0, v0: float = 0.0, rtol: float = 1e-8,
                        atol: float = 1e-10, settle: bool = True,
                        max_steps: int = 200_000, workers: int | None = None,
                        progress=None, lyapunov: bool | None = None, store=None,
                        engine=None, section_phase: float = 0.0, u0=None) -> xr.Dataset:
    """Orbit diagram of the stroboscopic section over ``param`` (any parameter of the model:
    omega, F0, omega_s, xi, xi_s, omega0, eta for support) at ``values`` (sorted ascending; each
    validated by the model).

    ``sweep``: "up" / "down" continue the state from value to value in increasing /
    decreasing order, "both" does both (in parallel), "fresh" restarts every value from
    (x0, v0) (all values in parallel). The first value of a continuation sweep starts from
    (x0, v0) (or ``u0``: every component, see ``simulate``). Each value: ``transient`` periods (ended early once the section has provably
    settled when ``settle=True``, see ``analysis.poincare``), then ``record`` section points.

    A section still converging to a periodic orbit after that is integrated further before it
    is classified (``MAX_EXTENSION``); chaotic sections are not.

    Returns a Dataset with coordinates ``<param>`` and ``sweep`` (integer codes with CF
    flag_values/flag_meanings, ``SWEEP_CODES``; names by ``plot.bifurcation.sweep_names``) and variables
    ``X``, ``V`` (sweep, <param>, n), ``period`` (0 = not periodic, -1 = not settled),
    ``max_X``, ``min_X``, ``contact``, ``status`` (0 = ok; failed points have NaN data) and
    ``transient_used`` (periods before the recorded window). The swept parameter is not in
    the attrs (``param_<param>`` is dropped).
    ``max_steps``: integration steps allowed per forcing period (see ``kernels.Solver``).
    ``lyapunov`` (None = where tangent dynamics exist, i.e. not for eq. 12): also ``lambda1`` with ``lambda1_stderr`` (over ``record`` further periods
    of each point's attractor) and the verdict ``motion`` (periodic / quasi-periodic /
    chaotic / not settled; see ``analysis.stability.classify``).
    ``store``: a directory where finished chunks are written as they finish; running the same
    sweep with the same store again resumes (see ``nonsmooth.chunks``). ``engine``: None (all
    local cores), "local[:N]" (a Dask LocalCluster), a Dask scheduler address or a
    ``dask.distributed.Client``; the numbers do not depend on it.
    ``progress`` (None or False: silent; True: a progress bar with a time estimate on a terminal,
    plain lines elsewhere; or a callable ``progress(done, total)``): reports the work done.
    """
    from ..simulate import check_forced
    check_forced(params, "bifurcation_diagram")
    from ..sweep import progress_callback
    progress = progress_callback(progress, "bifurcation")
    from ..chunks import check_engine
    from ..simulate import check_admissible, check_int, check_params, initial_u, start_attrs
    params = check_params(params)
    engine = check_engine(engine)
    if not isinstance(param, str):
        raise ParameterError(f"param: expected a parameter name, got {param!r}")
    param = params.model.param(param).name
    if sweep not in SWEEPS:
        raise ParameterError(f"sweep: unknown sweep {sweep!r} (known: {', '.join(SWEEPS)})")
    transient = check_int("transient", transient, 0)
    record = check_int("record", record, 1)
    check_sweep_memory(np.size(values), 2 if sweep == "both" else 1, record)
    values = check_values(param, values)
    u = initial_u(params.model, x0, v0, u0)
    solver = Solver(model=params.model, method=method, rtol=rtol, atol=atol,
                    max_steps=max_steps, section_phase=section_phase)
    check_admissible(solver, params, u)
    directions = {"up": ["up"], "down": ["down"], "both": ["up", "down"], "fresh": ["fresh"]}[sweep]
    from .stability import wants_lyapunov
    out = run_branches(params, param, values, solver, directions=directions,
                       transient=transient, record=record, x0=u[0], v0=u[1], extra=u[2:],
                       settle=settle, workers=workers, progress=progress,
                       lyapunov=wants_lyapunov(lyapunov, solver), store=store, engine=engine)
    return branches_dataset(params, param, values, solver, directions, out,
                            analysis="bifurcation", transient=transient, record=record,
                            **start_attrs(u), settle=settle, sweep_mode=sweep)


#: Integer codes of the ``sweep`` coordinate (CF flag_values / flag_meanings).
SWEEP_CODES = {"up": 0, "down": 1, "fresh": 2}


def branches_dataset(params, param, values, solver, directions, out, **attrs) -> xr.Dataset:
    """The Dataset of :func:`run_branches` output (with ``lambda1`` and ``motion`` where
    it has them)."""
    from ..io import flag_attrs, status_flags
    from .stability import lyapunov_attrs
    period, mx, mn, contact = out["period"], out["max_X"], out["min_X"], out["contact"]
    spec = params.model.param(param)
    desc, unit = spec.long_name, spec.units
    dims = ("sweep", param)
    nfail = int(np.count_nonzero(out["status"]))
    extra = {k: (dims, out[k], a) for k, a in lyapunov_attrs(attrs["record"], solver).items()
             if k in out}
    ds = xr.Dataset(
        {
            "X": (dims + ("n",), out["X"], {"long_name": "section displacement X(kT)",
                                            "units": "1"}),
            "V": (dims + ("n",), out["V"], {"long_name": "section velocity dX/dt(kT)",
                                            "units": "1/s"}),
            "period": (dims, period, {"long_name": PERIOD_LONG_NAME, "units": "1"}),
            "max_X": (dims, mx, {"long_name": "largest X over the recorded periods",
                                 "units": "1"}),
            "min_X": (dims, mn, {"long_name": "smallest X over the recorded periods",
                                 "units": "1"}),
            "contact": (dims, contact, flag_attrs(("no_contact", "contact"), dtype=np.int8,
                                                  long_name=params.model.contact_name)),
            "status": (dims, out["status"], status_flags(long_name="kernel status")),
            "transient_used": (dims, out["used"], {
                "long_name": "forcing periods integrated before the recorded window",
                "units": "1"}),
            **extra,
        },
        coords={
            param: (param, values, {"long_name": desc, "units": unit}),
            "sweep": ("sweep", np.array([SWEEP_CODES[d] for d in directions], np.int8),
                      flag_attrs(list(SWEEP_CODES), dtype=np.int8,
                                 long_name="continuation direction (fresh = restart each "
                                           "value)")),
            "n": ("n", np.arange(out["X"].shape[2]), {"long_name": "section index"}),
        },
        attrs=provenance_attrs(params, solver, param=param, max_period=MAX_PERIOD,
                               n_failed=nfail, **attrs),
    )
    ds.attrs["swept_param"] = param
    del ds.attrs[f"param_{param}"]  # swept: a coordinate, not a single value
    return apply_state_units(ds, params.model)
