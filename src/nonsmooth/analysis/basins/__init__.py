"""Basins of attraction on a grid of initial conditions: "featurize, then group".

``basins(params, x=(-3, 3), v=(-3, 3), grid=400) -> xarray.Dataset``

Every initial condition (X, V) of the grid starts at forcing phase 0 and is followed on the
stroboscopic section (one point per forcing period T). Nobody supplies a list of attractors:
they are found from the trajectories themselves and grouped by their features (the set of their
section points, their period, whether they reach the support).

Algorithm
---------
1. **Order.** The grid points are visited in a fixed coarse-to-fine order (the points of a coarse
   sub-grid (4 to 8 points per axis) first, then the points of ever finer sub-grids) and
   processed in *rounds*: the coarse sub-grid, then rounds 4 times larger each time, at most
   ``_CHUNK_MAX`` points. The order and the round boundaries depend only on the grid.
2. **Per point** (compiled, all rounds run in parallel over their points): the trajectory is
   advanced one forcing period at a time (``kernels.advance`` with ``per_period=1``). After
   each period its section point is

   * tested against the *capture balls* of the attractors known at the start of the round: a
     point inside one is provably on that attractor (see 4) and the trajectory stops at once,
     labelled (the initial condition itself is tested first: 0 periods);
   * otherwise, after ``transient`` periods, tested for periodicity: the last
     ``q + max(q, N_CONFIRM)`` section points repeat with period q <= ``max_period`` within
     ``tol = section_tolerance(rtol, atol, scale)`` (the tolerance of ``detect_period``, tied
     to the integration tolerance). The q points and the largest X over the last q periods
     are the candidate attractor's features.

   A trajectory that fails (kernel status != 0, non-finite state) gets label -1 (its
   ``status`` says why); one still undecided after ``max_periods`` periods too, unless it is
   on a chaotic attractor (6). **Slices:** the compiled calls return to Python about every
   ``_SLICE_FACTOR * sweep.SLICE_SECONDS`` = 0.2 s (Ctrl-C, progress): each point's kernel
   state, its last section points and its counters live in arrays between calls and every
   call continues them for a budget of periods sized from the measured speed of the previous
   call, so the slices never change a number.
3. **Merge** (serial, in the fixed order of the points): a candidate with the period and the
   set of section points (any cyclic order, within ``match_tol = 100 tol``) of a known
   attractor gets its label (also when its period is a multiple of the attractor's: a slowly
   converging orbit with a multiplier near -1 passes the test for 2q first); otherwise it is
   refined and **confirmed** (``_polish``): followed until its section repeats to tol / 1000,
   its period re-detected on the refined points, then it must close (its last q section
   points repeat the q before within tol) and stay on its points over a further window of at
   least ``_CONFIRM_MIN`` periods (``_CONFIRM_MULT`` of its periods). A chaotic trajectory that
   shadowed an unstable periodic orbit long enough to pass the test drifts away and is
   rejected: the rejected set is remembered, and the trajectory goes on (its periodicity is
   tested again once its section history is new). A confirmed candidate that does not match
   a known attractor becomes a new attractor, which later rounds use.
   Labels are finally renumbered in a canonical order (periodic before chaotic, no contact
   first, then by period, then by largest X), so the result never depends on the number of
   workers, on thread timing or on the slices: within a round each point depends only on its
   own initial condition and the attractors known before the round (a trajectory resumed
   after a rejected candidate: before its resumption).
4. **Capture balls (the early stop).** For each point a_i of a new attractor of period p the
   largest radius r is sought (starting just below the distance to the nearest other attractor
   point, at most ``_R_MAX``, multiplied by ``_RETRY`` on failure, deterministic) such that,
   for every radius r_j = r c^j (c = ``_SHRINK``) down to r_end = max(``_R_END``, 10 tol), the
   circle of radius r_j around a_i, sampled by ``_N_CIRCLE`` points, is mapped by f^(m p)
   (f = the stroboscopic map, m <= ``_M_MAX`` the first multiple that works) inside the disc
   of radius c r_j around a_i, with a margin of half the largest gap between neighbouring
   image points. The stroboscopic map is a homeomorphism of the plane (the model's
   ``flow_is_homeomorphism``; without it no certificate is used), so the image of a disc
   is the inside of the image of its circle: B(a_i, r_j) is mapped into B(a_i, r_{j+1}), and by
   induction every point of B(a_i, r) ends within r_end of a_i (where the linearization rules)
   -- the disc lies in the attractor's basin, and it cannot contain another attractor. A
   trajectory that enters such a disc needs no further integration: this is the speed lever
   (``periods_used`` shows it; ``capture_radius`` gives the radii; 0 = none certified, e.g.
   a weakly contracting orbit, whose points then run until their section is periodic). The
   proof is up to the sampling of the circles (the margin covers curvature between samples
   of a smooth image curve). With ``early_stop=False`` no disc is used and every point runs
   until its section is periodic (the slow reference the tests compare with).

5. **Certified lattice cells (the second lever, grids of 64 x 64 points or more).** After the
   first two rounds, a coarse lattice (about one cell per 16 x 16 grid points) is laid over
   the grid; the disc covering each cell is certified for attractor L if, after some
   m <= ``_CELL_M_MAX`` periods, the images of ``_CELL_SAMPLES`` points of its circle lie
   inside one of L's certified discs (shrunk by c, with the same gap margin) -- the same
   homeomorphism argument, so the whole cell lies in L's basin. A trajectory (or initial
   condition) inside a certified cell is decided at once; cells on basin boundaries are
   simply not certified. This costs a few per cent of the grid's work and removes most of
   the transient (``certified_cells``/``lattice_cells`` in the attrs). The lattice is
   re-tried when a new attractor appears; it depends only on the grid and on the attractors.

6. **Chaotic attractors.** The trajectories still undecided after ``max_periods`` (and not
   within ``match_tol`` of a periodic attractor, i.e. still converging to it) are grouped by
   their last ``_CLOUD`` section points: these occupy cells of a fixed lattice over the
   section (the grid window cut into ``_CLOUD_CELLS`` per axis, continued beyond it), and
   trajectories sharing a cell, directly or through others, form one group (connected
   components: independent of the order of the points). A group becomes a chaotic attractor
   (kind 1, period 0) if its first member, followed ``_CHAOS_PERIODS`` more periods, stays
   aperiodic and separates from a twin started ``_TWIN`` (times the window's scale) away by
   ``_TWIN_GROWTH`` times that (sensitive dependence); otherwise its points stay undecided.
   Its section points are ``_CLOUD`` consecutive ones of that run, its largest X the run's.
   A ``UserWarning`` says when more than 10% of the points are undecided (budget too small).

The attractors' orbits are resampled (``samples_per_period`` points per forcing period over p
periods; a chaotic one over ``_CHAOS_ORBIT_PERIODS``) from their first section point, so that
plots never integrate.

Modules: ``_core`` (the compiled per-point code), ``order`` (visiting order, rounds, slices),
``certify`` (capture discs and lattice cells), ``attractors`` (confirmation, matching, chaotic
groups); this module runs the rounds and builds the Dataset.
"""

from __future__ import annotations

import functools
import warnings

import numpy as np
import xarray as xr

from ...checks import check_axes, check_grid, check_range
from ...integrate.contract import N_STATE
from ...io import (apply_state_units, check_memory, flag_attrs, provenance_attrs,
                   status_flags)
from ...kernels import Solver, new_state, output_buffers
from ...models.base import ParamsBase
from ...simulate import check_int, check_params, state_u
from ...sweep import parallel_chunks, resolve_workers, threads
from ..periodicity import section_tolerance
from ._core import (_HOLD, _K, _N_REC, _Q, _RES, _RES_FAILED, _RES_NEW, _RUNNING, _STATUS,
                    LABEL_UNDECIDED, N_CONFIRM, _run_round)
from .attractors import (_CLOUD, KIND_CHAOTIC, KIND_NAMES, KIND_PERIODIC, MATCH_FACTOR,
                         _Attractors, _Clouds, _confirm_chaos, _polish)
from .certify import _certify_all, _Lattice, sphere_certificates
from .order import _coarse_to_fine_order, _Pace, _round_sizes

__all__ = ["basins", "MAP_IS_HOMEOMORPHISM", "N_CONFIRM", "MATCH_FACTOR", "LABEL_UNDECIDED",
           "KIND_NAMES"]

#: The capture discs and lattice cells (the early stop) are certificates only where the
#: stroboscopic map is a homeomorphism of the plane (the image of a disc is the inside of the
#: image of its circle). Each model method declares it (``Method.flow_is_homeomorphism``:
#: false for sticking, where trajectories merge); this switch turns certificates off for
#: every model. Where either is False every point runs until it is decided.
MAP_IS_HOMEOMORPHISM = True

_CHAOS_ORBIT_PERIODS = 16  # forcing periods of a chaotic attractor's sampled orbit
#: bytes held per grid point (ordering, start points, labels, counters, the Dataset)
_BYTES_PER_POINT = 112


def basins(params: ParamsBase, *, x=(-3.0, 3.0), v=(-3.0, 3.0), grid=400, method: str = "smooth",
           transient: int = 10, max_periods: int = 1000, max_period: int = 16, rtol: float = 1e-8,
           atol: float = 1e-10, early_stop: bool = True,
           samples_per_period: int = 200, workers: int | None = None,
           progress=None, lyapunov: bool | None = None, store=None,
           engine=None, section_phase: float = 0.0, axes=None, u0=None) -> xr.Dataset:
    """Basins of attraction of the stroboscopic map on a grid of initial conditions.

    ``x``, ``v``: (min, max) ranges of the initial X and V (forcing phase 0), or of the two
    state components ``axes`` names (default: the first two; e.g. ("X", "Y") for a model with
    more; the others start from ``u0``, a mapping {name: value} or n numbers, else 0);
    ``grid``: points
    per axis (int) or (nx, nv), each >= 2. ``transient``: periods before periodicity is tested
    (capture balls act from the start); ``max_periods``: budget per initial condition;
    ``max_period``: longest period looked for; ``early_stop``: stop a trajectory as soon as it
    enters a certified capture ball of a known attractor (False: every trajectory runs until
    its section repeats; same labels, much slower). ``workers``: threads (None = all cores;
    results do not depend on it). ``progress`` (None or False: silent; True: a progress bar with a
    time estimate on a terminal, plain lines elsewhere; or a callable ``progress(done, total)``) is
    called about every 0.1 s with
    the number of grid points decided. A ``UserWarning`` says when most points are undecided
    because ``max_periods`` was too small.

    Returns a Dataset with ``label`` (x0, v0) (CF flags; -1 = undecided: neither periodic
    nor on a confirmed chaotic attractor within the budget, or integration failed),
    ``periods_used`` and ``status`` (the kernel status; non-zero = failed) (x0, v0), the
    scalars ``undecided_fraction``, ``undecided_count``, ``failed_count``, and per
    ``attractor``: ``kind`` (periodic / chaotic), ``fraction``, ``count``, ``period`` (0 for
    chaotic), ``contact`` (the orbit reaches X >= 1), ``max_X``, and on (attractor, n) the
    section points ``attractor_X``/``attractor_V`` (a chaotic attractor: _CLOUD consecutive
    ones; NaN-padded) with ``capture_radius``, and on (attractor, sample) the sampled orbit
    ``orbit_X``/``orbit_V`` (time coordinate ``orbit_t``, in forcing periods). The
    ``fraction`` values and ``undecided_fraction`` sum to 1. See the module docstring for the
    algorithm. ``lyapunov`` (None = where tangent dynamics exist, i.e. not for eq. 12): also
    each attractor's ``lambda1`` with ``lambda1_stderr`` (per
    unit time, over ``LYAPUNOV_PERIODS`` periods from its first section point: tangent
    dynamics with saltation matrices, ``analysis.stability``); for a periodic attractor it is
    ln|mu_1| / T of its leading Floquet multiplier.

    ``store`` / ``engine``: chunked, resumable runs and where they run (``nonsmooth.chunks``):
    each round is a chunk, continued from the attractors the rounds before it found, so the
    rounds run one after the other (on Dask: one worker at a time, with its threads).

    A model with more than X and V (or other axes, or ``u0``): the trajectories start from
    every component, the attractors are told apart by every component at their section
    points, and the discs and cells are balls in the whole state space (``certify``: the
    image of a ball is the inside of the image of its sphere), certified only with at most
    ``certify.MAX_SPHERE_N`` components, no continuous memory and a grid of at least
    ``certify.SPHERE_MIN_GRID`` points per axis; otherwise every point runs until its section
    repeats.
    """
    from ...simulate import check_forced
    check_forced(params, "basins")
    from ...sweep import progress_callback
    progress = progress_callback(progress, "basins")
    from ...chunks import Plan, check_engine, execute, plan_solver
    from ..stability import wants_lyapunov
    engine = check_engine(engine)
    params = check_params(params)
    x_lo, x_hi = check_range("x", x)
    v_lo, v_hi = check_range("v", v)
    nx, nv = check_grid(grid)
    ia, ib, base = _check_axes(params.model, axes, u0)
    transient = check_int("transient", transient, 0)
    max_periods = check_int("max_periods", max_periods, 1)
    max_period = check_int("max_period", max_period, 1)
    spp = check_int("samples_per_period", samples_per_period, 2)
    solver = Solver(method=method, rtol=rtol, atol=atol,
                    model=params.model, section_phase=section_phase)
    nw = resolve_workers(workers)
    n = nx * nv
    check_memory(n * _BYTES_PER_POINT, "grid",
                 f"a {nx} x {nv} grid holds {n} initial conditions; use a smaller --grid",
                 size=(max(nx, nv), 2))
    # a round keeps the last 2 max_period section points of each of its trajectories
    check_memory(n * 32.0 * (2 * max_period + N_CONFIRM), "max_period",
                 f"each of the {n} initial conditions keeps its last {2 * max_period} section "
                 f"points; look for shorter periods", size=(max_period, 1))

    xs = np.linspace(x_lo, x_hi, nx)
    vs = np.linspace(v_lo, v_hi, nv)
    pk = params.pack()
    scale = max(abs(x_lo), abs(x_hi), abs(v_lo), abs(v_hi), 1.0)
    tol = section_tolerance(rtol, atol, scale)
    certified = (bool(early_stop) and MAP_IS_HOMEOMORPHISM and solver.spec.flow_is_homeomorphism
                 and (base.size == 0 or sphere_certificates(params.model, solver.spec, nx, nv)))
    order, first = _order(nx, nv)
    rounds = list(_round_sizes(n, first))
    spec = {"solver": plan_solver(solver, engine), "pk": pk, "x": (x_lo, x_hi),
            "v": (v_lo, v_hi), "nx": nx, "nv": nv, "transient": transient,
            "max_periods": max_periods, "max_period": max_period, "tol": tol,
            "certified": certified, "rounds": rounds}
    if base.size:  # (only then: stores of plain (X, V) runs stay resumable)
        spec.update(axes=(ia, ib), base=[float(b) for b in base])
    plan = Plan("basins", {k: v for k, v in spec.items() if k not in ("rounds", "pk")} | {
        "params": dict(zip(params.model.param_names, pk)),
        "early_stop": bool(early_stop), "samples_per_period": spp,
        "lyapunov": bool(wants_lyapunov(lyapunov, solver))}, len(rounds), _basins_round,
        spec, chained=True, weights=[b - a for a, b in rounds])
    label = np.full(n, LABEL_UNDECIDED, np.int64)  # in processing order
    used = np.zeros(n, np.int32)
    status = np.zeros(n, np.int64)
    last = {}
    clouds = _Clouds(x_lo, x_hi, v_lo, v_hi, n)

    def collect(i, res):
        a, b = rounds[i]
        label[a:b] = res["label"]
        used[a:b] = res["used"]
        status[a:b] = res["status"]
        last["carry"] = res["carry"]
        if res["cloud_pos"].size:  # the round's undecided trajectories, in round order
            clouds.add(res["cloud_pos"], res["cloud_X"], res["cloud_V"], res["cloud_state"])
    try:
        execute(plan, collect, store=store, engine=engine, workers=nw,
                progress=None if progress is None else (lambda d, t: progress(d, n)))
    finally:
        _order.cache_clear()  # the visiting order of a large grid is not kept after the run
    found, lat, cert = (last["carry"][k] for k in ("found", "lat", "cert"))
    with threads(nw):
        for members, state in clouds.groups():
            chaos = _confirm_chaos(solver, pk, state, tol, max_period, scale)
            if chaos is not None:
                first = None
                if base.size:  # the state at the first cloud point: one period on
                    first = state.copy()
                    solver.advance(pk, solver.opts(), first, 1, 0, 1, *output_buffers(1))
                label[members] = found.add(*chaos, kind=KIND_CHAOTIC, state=first)
        orbits = _sample_orbits(found, solver, pk, spp)
        lyap = None
        if wants_lyapunov(lyapunov, solver):
            lyap = _attractor_lyapunov(found, solver, pk)

    # back to grid order, canonical labels
    grid = {}
    for name, arr in (("label", label), ("used", used), ("status", status)):
        grid[name] = np.empty(n, arr.dtype)
        grid[name][order] = arr
    del label, used, status
    n_att = len(found.points)
    kind = np.array(found.kind, dtype=np.int64)
    contact = np.array([int(params.model.is_contact(params, mk, mx, mn)) for mx, mn, mk in
                        zip(found.max_x, found.min_x, found.mask)], dtype=np.int64)
    periods = np.array([len(pt) if kd == KIND_PERIODIC else 0
                        for pt, kd in zip(found.points, found.kind)], dtype=np.int64)
    max_x = np.array(found.max_x, dtype=np.float64)
    key = sorted(range(n_att), key=lambda k: (kind[k], contact[k], periods[k], max_x[k]))
    new_of_old = np.full(n_att + 1, LABEL_UNDECIDED, np.int64)
    new_of_old[key] = np.arange(n_att)
    lab = grid["label"]
    grid_label = np.where(lab >= 0, new_of_old[np.where(lab >= 0, lab, n_att)], LABEL_UNDECIDED)
    undecided = int(np.count_nonzero((grid_label < 0) & (grid["status"] == 0)))
    if undecided > 0.1 * n:
        warnings.warn(
            f"basins: {100 * undecided / n:.1f}% of the initial conditions are undecided after "
            f"max_periods={max_periods} forcing periods (periodicity is tested from period "
            f"transient={transient} on, over at least {1 + N_CONFIRM} more); raise max_periods",
            UserWarning, stacklevel=2)
    return _dataset(params, solver, xs, vs, grid_label.reshape(nx, nv),
                    grid["used"].reshape(nx, nv), grid["status"].reshape(nx, nv), found, key,
                    kind, contact, periods, max_x, orbits, spp, lyap,
                    dict(transient=transient, max_periods=max_periods, max_period=max_period,
                         early_stop=int(bool(early_stop)), section_tol=tol,
                         match_tol=found.match_tol,
                         certification_periods=cert["periods"],
                         certified_cells=lat.n_certified(), lattice_cells=lat.size()),
                    axes=(ia, ib), base=base)


@functools.lru_cache(maxsize=2)
def _order(nx: int, nv: int):
    """The coarse-to-fine visiting order of an nx x nv grid (computed once per process)."""
    return _coarse_to_fine_order(nx, nv)


def _basins_round(spec, i, carry, workers=None, progress=None):
    """Round ``i`` of :func:`basins` (a chained ``chunks.Plan`` task): the records of its
    points, its still undecided trajectories (``cloud_*``: the client groups them into
    chaotic candidates, ``_Clouds``) and, as ``carry``, what later rounds depend on (the
    attractors found, their certified discs, the lattice)."""
    from ...chunks import solver_from_spec
    solver = solver_from_spec(spec["solver"])
    (x_lo, x_hi), (v_lo, v_hi), nx, nv = spec["x"], spec["v"], spec["nx"], spec["nv"]
    n = nx * nv
    order, first = _order(nx, nv)
    axes = spec.get("axes", (0, 1))
    base = np.asarray(spec.get("base", ()), dtype=np.float64)
    if carry is None:
        carry = {"found": _Attractors(spec["tol"]),
                 "lat": _Lattice(x_lo, x_hi, v_lo, v_hi, nx, nv, first, axes, base),
                 "cert": {"periods": 0}}
    found, lat, cert = (carry[k] for k in ("found", "lat", "cert"))
    a, b = spec["rounds"][i]
    idx = order[a:b]
    X0 = np.linspace(x_lo, x_hi, nx)[idx // nv]
    V0 = np.linspace(v_lo, v_hi, nv)[idx % nv]
    pk, certified = spec["pk"], spec["certified"]
    with threads(workers), parallel_chunks(8):
        rec, cloud = _run_round_points(solver, pk, X0, V0, a, n, spec["max_periods"],
                                       spec["transient"], spec["tol"], spec["max_period"],
                                       certified, found, lat, _Pace(2 * first),
                                       None if progress is None else
                                       (lambda d, _t: progress(d - a, b - a)), axes, base)
        if certified and not all(found.certified):
            _certify_all(found, solver, pk, cert, full=base.size > 0)
            lat.stale = True
        if certified and lat.stale and lat.active and b >= lat.start_after:
            lat.certify(found, solver, pk, cert)
    return {"label": rec[:, _RES], "used": rec[:, _K], "status": rec[:, _STATUS],
            "cloud_pos": cloud[0], "cloud_X": cloud[1], "cloud_V": cloud[2],
            "cloud_state": cloud[3], "carry": carry}


def _run_round_points(solver, pk, X0, V0, done_before, n, max_periods, transient, tol,
                      max_period, certified, found, lat, pace, progress, axes=(0, 1),
                      base=np.zeros(0)):
    """Decide the points of one round; returns their records (m, _N_REC): rec[:, _RES] the
    label in discovery numbering (-1 undecided or failed), rec[:, _K] the periods used,
    rec[:, _STATUS] the kernel status; and the undecided trajectories not near a known
    attractor, for ``_Clouds.add``: (processing positions, their last section points X, V,
    their kernel states).

    The points are followed in slices (compiled calls of about ``SLICE_SECONDS``, sized by
    ``pace`` from the measured speed; a round shorter than that is one call) against the
    attractors known at the start of the round, until each is captured, periodic, failed or
    out of budget; then the periodic candidates are merged in
    the fixed order of the points (matched, or refined and confirmed as a new attractor, or
    rejected: then the trajectory goes on, its periodicity tested again only once its section
    history is new). The slices never change a result: each point depends only on its own
    trajectory and on the attractors known when its sub-round started."""
    m = len(X0)
    L = max(max_period + max(max_period, N_CONFIRM), _CLOUD)
    opts = solver.opts()
    states = np.empty((m, N_STATE))
    bufs = np.empty((m, 3, L))
    recs = np.zeros((m, _N_REC), np.int64)
    recs[:, _RES] = _RUNNING
    cX = np.empty((m, max_period))
    cV = np.empty((m, max_period))
    cxm = np.empty(m)
    ofs, oi8, ou8 = np.empty((m, 4, 1)), np.empty((m, 1), np.int8), np.empty((m, 1), np.uint8)
    while True:
        apts, arad2, alab = found.flat_full() if base.size else found.flat()
        active = np.flatnonzero(recs[:, _RES] == _RUNNING)
        while active.size:
            budget = pace.share(active.size)

            def call():
                before = int(recs[active, _K].sum())
                _run_round(solver.kernel, solver.fns, pk, opts, X0, V0, active, max_periods, transient, tol,
                           max_period, certified, apts, arad2, alab, lat.cells, lat.geo,
                           budget, states, bufs, recs, cX, cV, cxm, ofs, oi8, ou8,
                           int(axes[0]), int(axes[1]), base)
                return int(recs[active, _K].sum()) - before
            pace.run(call, active.size, budget * active.size)
            active = active[recs[active, _RES] == _RUNNING]
            if progress is not None:
                progress(done_before + m - active.size, n)
        resumed = False
        for i in np.flatnonzero(recs[:, _RES] == _RES_NEW):
            q = int(recs[i, _Q])
            pts = np.stack([cX[i, :q], cV[i, :q]], axis=1)
            # a model with more than X and V: every component takes part (its state is at
            # the candidate's last section point)
            u = state_u(solver.model, states[i]) if base.size else None
            k = found.match(pts, u)
            if k < 0 and not found.was_rejected(pts):
                # a model with more than X and V: polish from the trajectory's own state
                confirmed = _polish(solver, pk, pts, tol, states[i] if base.size else None)
                if confirmed is None:
                    found.rejected.append(pts)
                else:
                    full = (_full_points(solver, pk, confirmed[2], len(confirmed[0]))
                            if base.size else None)
                    k = found.match(confirmed[0], None if full is None else full[-1])
                    if k < 0:
                        k = found.add(confirmed[0], confirmed[1],
                                      state=confirmed[2] if len(confirmed) > 2 else None,
                                      full=full)
            if k >= 0:
                recs[i, _RES] = k
            elif recs[i, _K] < max_periods:
                recs[i, _RES] = _RUNNING
                recs[i, _HOLD] = recs[i, _K] + L
                resumed = True
            else:
                recs[i, _RES] = LABEL_UNDECIDED
        if not resumed:
            break
    und = np.flatnonzero(recs[:, _RES] == LABEL_UNDECIDED)
    c = min(L, max_periods)
    und = und[~found.near(bufs[und, 0, (recs[und, _K] - 1) % L], bufs[und, 1, (recs[und, _K] - 1) % L])]
    cloud = (done_before + und, bufs[und, 0, :c], bufs[und, 1, :c], states[und])
    recs[recs[:, _RES] == _RES_FAILED, _RES] = LABEL_UNDECIDED
    return recs, cloud


def _full_points(solver, pk, state, q):
    """Every state component at the q section points of a periodic attractor from the kernel
    ``state`` at its first one (the last row: back at that point); NaN where the run fails."""
    from ...sweep import run_trajectories
    res = run_trajectories(pk[None, :], solver, state[None, :], per_period=1, n_skip=0,
                           n_out=q, workers=1, components=True)
    return res["U"][0]


def _check_axes(model, axes, u0):
    """(ia, ib, base) of ``axes`` (two state component names) and ``u0``: base is empty for
    the plain grid in (X, V) of a two-component model (the compiled path of old), else the
    full start state u (the axes' values replaced per grid point)."""
    from ...simulate import initial_u
    ia, ib = check_axes(model, axes)
    u = initial_u(model, 0.0, 0.0, u0)
    if model.n == 2 and (ia, ib) == (0, 1) and u0 is None:
        return ia, ib, np.zeros(0)
    return ia, ib, u


def _sample_orbits(found, solver, pk, spp):
    """Each attractor's orbit from its first section point, spp samples per forcing period,
    over its period (a chaotic one: _CHAOS_ORBIT_PERIODS periods)."""
    out = []
    for pts, kind, st0 in zip(found.points, found.kind, found.states):
        nout = (len(pts) if kind == KIND_PERIODIC else _CHAOS_ORBIT_PERIODS) * spp
        X, V, R, M, XM, Xm = output_buffers(nout)
        s0 = new_state(pts[0, 0], pts[0, 1]) if st0 is None else st0.copy()
        if solver.advance(pk, solver.opts(), s0, spp, 0, nout, X, V, R, M, XM, Xm) != 0:
            X[:] = np.nan
            V[:] = np.nan
        out.append((np.concatenate([[pts[0, 0]], X]), np.concatenate([[pts[0, 1]], V])))
    return out


#: Periods over which an attractor's lambda1 is estimated.
LYAPUNOV_PERIODS = 400


def _attractor_lyapunov(found, solver, pk):
    """(lambda1, stderr) per attractor (order of ``found``), from its first section point."""
    from ..stability import evidence_solver, lambda1_points
    if not found.points:
        return np.zeros(0), np.zeros(0)
    states = np.stack([new_state(pts[0, 0], pts[0, 1]) if st0 is None else st0
                       for pts, st0 in zip(found.points, found.states)])
    P = np.tile(pk, (len(states), 1))
    lam, err, _ = lambda1_points(P, *evidence_solver(solver, states), LYAPUNOV_PERIODS)
    return lam, err


def _label_meanings(key, kind, contact, periods):
    """One CF flag meaning per label value: undecided, then attractor_<k>_<kind>_<contact>."""
    words = ["undecided"]
    for new, old in enumerate(key):
        what = f"period_{periods[old]}" if kind[old] == KIND_PERIODIC else "chaotic"
        words.append(f"attractor_{new}_{what}_{'contact' if contact[old] else 'no_contact'}")
    return words


def _dataset(params, solver, xs, vs, label, used, status, found, key, kind, contact, periods,
             max_x, orbits, spp, lyap, extra, axes=(0, 1), base=np.zeros(0)):
    n = label.size
    n_att = len(key)
    npt = max([len(found.points[k]) for k in key], default=1)
    nsamp = max([len(orbits[k][0]) for k in key], default=1)
    AX = np.full((n_att, npt), np.nan)
    AV = np.full((n_att, npt), np.nan)
    RAD = np.full((n_att, npt), np.nan)
    OX = np.full((n_att, nsamp), np.nan)
    OV = np.full((n_att, nsamp), np.nan)
    for new, old in enumerate(key):
        q = len(found.points[old])
        AX[new, :q] = found.points[old][:, 0]
        AV[new, :q] = found.points[old][:, 1]
        RAD[new, :q] = found.radius[old]
        OX[new, :len(orbits[old][0])] = orbits[old][0]
        OV[new, :len(orbits[old][1])] = orbits[old][1]
    key = np.asarray(key, np.int64)
    counts = np.array([np.count_nonzero(label == k) for k in range(n_att)], dtype=np.int64)
    undecided = int(np.count_nonzero(label < 0))
    failed = int(np.count_nonzero(status != 0))
    lyap_vars = {}
    if lyap is not None:
        from ..stability import evidence_method
        lyap_vars = {
            "lambda1": ("attractor", lyap[0][key], {
                "long_name": "largest Lyapunov exponent of the attractor (tangent dynamics with "
                             "saltation matrices)", "units": "1/s",
                "periods": LYAPUNOV_PERIODS,
                "tangent_method": evidence_method(solver)}),
            "lambda1_stderr": ("attractor", lyap[1][key], {
                "long_name": "standard error of lambda1 (10 block means)", "units": "1/s"}),
        }
    ds = xr.Dataset(
        {
            "label": (("x0", "v0"), label.astype(np.int32), flag_attrs(
                _label_meanings(key, kind, contact, periods), range(-1, n_att), dtype=np.int32,
                long_name="attractor reached (-1 = undecided or failed)")),
            "periods_used": (("x0", "v0"), used.astype(np.int32),
                             {"long_name": "forcing periods integrated before the point was decided",
                              "units": "1"}),
            "status": (("x0", "v0"), status, status_flags(
                long_name="kernel status of the trajectory (non-zero: integration failed)")),
            "undecided_fraction": ((), undecided / n, {
                "long_name": "share of the grid points undecided or failed", "units": "1"}),
            "undecided_count": ((), undecided, {
                "long_name": "grid points undecided or failed", "units": "1"}),
            "failed_count": ((), failed, {
                "long_name": "grid points whose integration failed", "units": "1"}),
            "kind": ("attractor", kind[key].astype(np.int8), flag_attrs(
                KIND_NAMES, dtype=np.int8, long_name="kind of attractor")),
            "fraction": ("attractor", counts / n,
                         {"long_name": "share of the grid points in the basin", "units": "1"}),
            "count": ("attractor", counts, {"long_name": "grid points in the basin", "units": "1"}),
            "period": ("attractor", periods[key].astype(np.int32),
                       {"long_name": "period in forcing periods (0 = chaotic)", "units": "1"}),
            "contact": ("attractor", contact[key].astype(np.int8), flag_attrs(
                ("no_contact", "contact"), dtype=np.int8,
                long_name=f"1: {params.model.contact_name}")),
            "max_X": ("attractor", max_x[key],
                      {"long_name": "largest X on the orbit", "units": "1"}),
            "attractor_X": (("attractor", "n"), AX,
                            {"long_name": "section points X (t = kT)", "units": "1"}),
            "attractor_V": (("attractor", "n"), AV,
                            {"long_name": "section points V (t = kT)", "units": "1/s"}),
            "capture_radius": (("attractor", "n"), RAD,
                               {"long_name": "certified capture radius around each section point "
                                             "(0 = none)", "units": "1"}),
            "orbit_X": (("attractor", "sample"), OX,
                        {"long_name": "attractor orbit X from its first section point",
                         "units": "1"}),
            "orbit_V": (("attractor", "sample"), OV,
                        {"long_name": "attractor orbit V from its first section point",
                         "units": "1/s"}),
            **lyap_vars,
        },
        coords={
            "x0": ("x0", xs, {"long_name": "initial X", "units": "1"}),
            "v0": ("v0", vs, {"long_name": "initial V", "units": "1/s"}),
            "attractor": ("attractor", np.arange(n_att), {"long_name": "attractor label"}),
            "t_section": ("n", np.arange(npt), {
                "long_name": "time since the attractor's first section point, in forcing periods",
                "units": "1"}),
            "orbit_t": ("sample", np.arange(nsamp) / spp, {
                "long_name": "time since the attractor's first section point, in forcing periods",
                "units": "1"}),
        },
        attrs=provenance_attrs(
            params, solver, analysis="basins", grid_nx=len(xs), grid_nv=len(vs),
            x_min=float(xs[0]), x_max=float(xs[-1]), v_min=float(vs[0]), v_max=float(vs[-1]),
            n_attractors=n_att, total_periods=int(used.sum()),
            mean_periods_used=float(used.mean()), samples_per_period=spp,
            forcing_period=params.period, **extra),
    )
    if any(found.full[k] is not None for k in key):  # more than X and V: every component
        from ...simulate import component_variables
        AU = np.full((n_att, npt, params.model.n), np.nan)
        for new, old in enumerate(key):
            if found.full[old] is not None:  # its rows start one period on: roll to the first
                AU[new, :len(found.full[old])] = np.roll(found.full[old], 1, axis=0)
        ds.update(component_variables(params.model, ("attractor", "n"), AU,
                                      prefix="attractor_", what=" at the section points"))
    ds = apply_state_units(ds, params.model)
    if base.size:  # the grid's axes are other components: say which, and the fixed rest
        m = params.model
        names = m.state_names
        units = tuple(m.state_units) + ("1",) * m.n
        for c, i in (("x0", axes[0]), ("v0", axes[1])):
            ds[c].attrs.update(long_name=f"initial {names[i]}", units=units[i])
        ds.attrs["axes"] = f"{names[axes[0]]} {names[axes[1]]}"
        ds.attrs["u0"] = np.asarray(base, dtype=np.float64)
    return ds
