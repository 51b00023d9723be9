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

   A trajectory that fails (kernel status != 0, non-finite state) or is still undecided after
   ``max_periods`` periods gets label -1.
3. **Merge** (serial, in the fixed order of the points): a candidate with the period and the
   set of section points (any cyclic order, within ``match_tol = 100 tol``) of a known
   attractor gets its label (also when its period is a multiple of the attractor's: a slowly
   converging orbit with a multiplier near -1 passes the test for 2q first); otherwise its
   points are refined by following it further and its period is re-detected on them
   (``_polish``), and unless it now matches a known attractor it becomes a new attractor,
   which later rounds use.
   Labels are finally renumbered in a canonical order (no contact first, then by period, then
   by largest X), so the result never depends on the number of workers or on thread timing:
   within a round each point depends only on its own initial condition and the attractors
   known before the round.
4. **Capture balls (the early stop).** For each point a_i of a new attractor of period p the
   largest radius r is sought (starting just below the distance to the nearest other attractor
   point, at most ``_R_MAX``, multiplied by ``_RETRY`` on failure, deterministic) such that,
   for every radius r_j = r c^j (c = ``_SHRINK``) down to r_end = max(``_R_END``, 10 tol), the
   circle of radius r_j around a_i, sampled by ``_N_CIRCLE`` points, is mapped by f^(m p)
   (f = the stroboscopic map, m <= ``_M_MAX`` the first multiple that works) inside the disc
   of radius c r_j around a_i, with a margin of half the largest gap between neighbouring
   image points. The stroboscopic map is a homeomorphism of the plane, so the image of a disc
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

The attractors' periodic orbits are resampled (``samples_per_period`` points per forcing period
over p periods) from their first section point, so that plots never integrate.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np
import xarray as xr

from ..errors import ParameterError
from ..integrate.contract import N_STATE, ST_H, ST_MODE, ST_V, ST_VA, ST_X
from ..io import provenance_attrs
from ..kernels import Solver, advance
from ..params import Params
from ..simulate import check_float, check_int, check_params
from ..sweep import resolve_workers, threads
from .periodicity import section_tolerance

#: section points that must repeat beyond one period before a period q is accepted:
#: the last q + max(q, N_CONFIRM) points are checked.
N_CONFIRM = 4
#: candidate section points within MATCH_FACTOR * tol of a known attractor's points are that
#: attractor (a settled trajectory is within ~tol / (1 - contraction) of its orbit).
MATCH_FACTOR = 100.0

_R_MAX = 1.5        # largest capture radius tried
_R_END = 1e-4       # smallest radius of the certification sequence (at least 10 tol)
_SHRINK = 0.6       # contraction demanded at each radius (c)
_N_CIRCLE = 48      # samples of each certification circle
_M_MAX = 12         # at most this many periods of the orbit to map a circle inside
_N_TRY = 24         # starting radii tried (each _RETRY times the previous) before giving up
_RETRY = 0.85
_CHUNK_MAX = 16384  # largest round
_POLISH_MAX = 400   # periods spent refining a new attractor's section points
_CELL_SAMPLES = 16  # circle samples of a lattice cell's disc
_CELL_M_MAX = 24    # periods allowed for a cell's disc to map into an attractor disc

LABEL_UNDECIDED = -1
_RES_NEW = -2       # settled on a periodic orbit: candidate attractor
_RES_FAILED = -3


@nb.njit(cache=True, inline="always")
def _init_state(state, x0, v0):
    state[ST_X] = x0
    state[ST_V] = v0
    state[ST_VA] = v0
    state[ST_MODE] = -1.0
    state[ST_H] = 0.0


@nb.njit(cache=True, inline="always")
def _captured(x, v, apts, arad2, alab, cells, cgeo):
    """Label of the certified disc containing (x, v): a certified cell of the lattice
    (cells[i, j] >= 0, geometry cgeo = (x_lo, v_lo, dx, dv)) or an attractor's disc; else -1."""
    if cells.shape[0] > 0:
        fi = (x - cgeo[0]) / cgeo[2]
        fj = (v - cgeo[1]) / cgeo[3]
        if 0.0 <= fi < cells.shape[0] and 0.0 <= fj < cells.shape[1]:
            lab = cells[int(fi), int(fj)]
            if lab >= 0:
                return lab
    for k in range(apts.shape[0]):
        dx = x - apts[k, 0]
        dv = v - apts[k, 1]
        if dx * dx + dv * dv < arad2[k]:
            return alab[k]
    return -1


@nb.njit(cache=True)
def _follow(method, p, opts, x0, v0, max_periods, transient, tol, max_period, early,
            apts, arad2, alab, cells, cgeo, cX, cV, state, buf, of, oi8, ou8):
    """Follow one initial condition; returns (result, periods used, period q, max X over the
    last q periods). result >= 0: captured label; -1 undecided; -2 periodic (candidate points
    in cX[:q], cV[:q], in time order); -3 failed. ``state``, ``buf`` (3, L), ``of`` (4, 1),
    ``oi8``, ``ou8`` (1,) are scratch space (no allocation per point)."""
    if early:
        lab = _captured(x0, v0, apts, arad2, alab, cells, cgeo)
        if lab >= 0:
            return lab, 0, 0, np.nan
    L = buf.shape[1]
    bx = buf[0]
    bv = buf[1]
    bm = buf[2]
    _init_state(state, x0, v0)
    ox = of[0]
    ov = of[1]
    oxa = of[2]
    oxi = of[3]
    for k in range(1, max_periods + 1):
        s = advance(method, p, opts, state, 1, 0, 1, ox, ov, oi8, ou8, oxa, oxi)
        x = ox[0]
        v = ov[0]
        if s != 0 or not (math.isfinite(x) and math.isfinite(v)):
            return _RES_FAILED, k, 0, np.nan
        j = (k - 1) % L
        bx[j] = x
        bv[j] = v
        bm[j] = oxa[0]
        if early:
            lab = _captured(x, v, apts, arad2, alab, cells, cgeo)
            if lab >= 0:
                return lab, k, 0, np.nan
        if k < transient:
            continue
        for q in range(1, max_period + 1):
            w = q + max(q, N_CONFIRM)
            if k < w:
                break
            ok = True
            for i in range(w - q):
                a = (k - 1 - i) % L
                b = (k - 1 - i - q) % L
                if not (abs(bx[a] - bx[b]) <= tol and abs(bv[a] - bv[b]) <= tol):
                    ok = False
                    break
            if ok:
                xm = -np.inf
                for i in range(q):
                    a = (k - q + i) % L
                    cX[i] = bx[a]
                    cV[i] = bv[a]
                    if bm[a] > xm:
                        xm = bm[a]
                return _RES_NEW, k, q, xm
    return LABEL_UNDECIDED, max_periods, 0, np.nan


@nb.njit(cache=True, parallel=True)
def _run_round(method, p, opts, X0, V0, max_periods, transient, tol, max_period, early,
               apts, arad2, alab, cells, cgeo, res, used, cq, cX, cV, cxm):
    n = X0.shape[0]
    L = max_period + max(max_period, N_CONFIRM)
    # scratch per point, allocated once per round
    states = np.empty((n, N_STATE))
    bufs = np.empty((n, 3, L))
    ofs = np.empty((n, 4, 1))
    oi8 = np.empty((n, 1), np.int8)
    ou8 = np.empty((n, 1), np.uint8)
    for i in nb.prange(n):
        r, k, q, xm = _follow(method, p, opts, X0[i], V0[i], max_periods, transient, tol,
                              max_period, early, apts, arad2, alab, cells, cgeo, cX[i], cV[i], states[i],
                              bufs[i], ofs[i], oi8[i], ou8[i])
        res[i] = r
        used[i] = k
        cq[i] = q
        cxm[i] = xm


@nb.njit(cache=True, parallel=True)
def _map_points(method, p, opts, X0, V0, periods, outX, outV, ok):
    """Section points of every start point after periods[j] periods, j = 0..len-1
    (outX[i, j]); ok[i] = False if the kernel failed."""
    n = X0.shape[0]
    nj = periods.shape[0]
    for i in nb.prange(n):
        state = np.empty(N_STATE)
        _init_state(state, X0[i], V0[i])
        ox = np.empty(1)
        ov = np.empty(1)
        orr = np.empty(1, np.int8)
        om = np.empty(1, np.uint8)
        oxa = np.empty(1)
        oxi = np.empty(1)
        done = 0
        ok[i] = True
        for j in range(nj):
            s = advance(method, p, opts, state, 1, periods[j] - done - 1, 1, ox, ov, orr, om,
                        oxa, oxi)
            done = periods[j]
            if s != 0 or not (math.isfinite(ox[0]) and math.isfinite(ov[0])):
                ok[i] = False
                for jj in range(j, nj):
                    outX[i, jj] = np.nan
                    outV[i, jj] = np.nan
                break
            outX[i, j] = ox[0]
            outV[i, j] = ov[0]


@nb.njit(cache=True, parallel=True)
def _certify_cells(method, p, opts, cx, cv, rc, todo, nsamp, m_max, apts, arad2, alab, out,
                   work):
    """For every cell k with todo[k]: the disc of radius rc around (cx[k], cv[k]) is certified
    (out[k] = label) if, after some m <= m_max periods, the images of nsamp points of its circle
    all lie inside one attractor disc with a margin of half the largest gap between
    neighbouring images (then the image of the whole disc does: homeomorphism)."""
    n = cx.shape[0]
    for k in nb.prange(n):
        if not todo[k]:
            continue
        out[k] = -1
        work[k] = 0
        states = np.empty((nsamp, N_STATE))
        for j in range(nsamp):
            th = 2.0 * np.pi * j / nsamp
            _init_state(states[j], cx[k] + rc * math.cos(th), cv[k] + rc * math.sin(th))
        xs = np.empty(nsamp)
        vs = np.empty(nsamp)
        ox = np.empty(1)
        ov = np.empty(1)
        orr = np.empty(1, np.int8)
        om = np.empty(1, np.uint8)
        oxa = np.empty(1)
        oxi = np.empty(1)
        for m in range(m_max):
            bad = False
            for j in range(nsamp):
                s = advance(method, p, opts, states[j], 1, 0, 1, ox, ov, orr, om, oxa, oxi)
                if s != 0 or not (math.isfinite(ox[0]) and math.isfinite(ov[0])):
                    bad = True
                    break
                xs[j] = ox[0]
                vs[j] = ov[0]
            work[k] += nsamp
            if bad:
                break
            gap = 0.0
            for j in range(nsamp):
                jn = (j + 1) % nsamp
                g = math.hypot(xs[jn] - xs[j], vs[jn] - vs[j])
                if g > gap:
                    gap = g
            done = False
            for a in range(apts.shape[0]):
                r = math.sqrt(arad2[a])
                if r <= 0.0:
                    continue
                inside = True
                for j in range(nsamp):
                    if math.hypot(xs[j] - apts[a, 0], vs[j] - apts[a, 1]) + 0.5 * gap >= _SHRINK * r:
                        inside = False
                        break
                if inside:
                    out[k] = alab[a]
                    done = True
                    break
            if done:
                break


class _Lattice:
    """Cells of a coarse lattice over the grid whose covering discs are certified to lie in one
    attractor's basin (mapped inside one of its certified discs): a trajectory entering such a
    cell is decided at once. Only used for grids of at least 64 x 64 points (about 1 cell per
    16 x 16 grid points, _CELL_SAMPLES circle points each: a few per cent of the work)."""

    def __init__(self, x_lo, x_hi, v_lo, v_hi, nx, nv, first):
        self.ncx, self.ncv = max(1, nx // 16), max(1, nv // 16)
        self.active = self.ncx >= 4 and self.ncv >= 4
        self.start_after = 4 * first  # after the first two rounds
        self.stale = False
        if not self.active:
            self.cells = np.zeros((0, 0), np.int64)
            self.geo = np.zeros(4)
            return
        dx, dv = (x_hi - x_lo) / self.ncx, (v_hi - v_lo) / self.ncv
        self.geo = np.array([x_lo, v_lo, dx, dv])
        self.cells = np.full((self.ncx, self.ncv), -1, np.int64)
        self.tried = np.zeros((self.ncx, self.ncv), np.bool_)
        ci, cj = np.meshgrid(np.arange(self.ncx), np.arange(self.ncv), indexing="ij")
        self.cx = (x_lo + (ci + 0.5) * dx).ravel()
        self.cv = (v_lo + (cj + 0.5) * dv).ravel()
        self.rc = 0.5 * math.hypot(dx, dv) * 1.001

    def certify(self, found, solver, pk, cert):
        """(Re)try the cells not certified yet against the attractors known now."""
        apts, arad2, alab = found.flat()
        todo = (self.cells < 0).ravel()
        out = self.cells.ravel().copy()
        work = np.zeros(len(out), np.int64)
        _certify_cells(solver.code, pk, solver.opts(), self.cx, self.cv, self.rc, todo,
                       _CELL_SAMPLES, _CELL_M_MAX, apts, arad2, alab, out, work)
        cert["periods"] += int(work.sum())
        self.cells = out.reshape(self.ncx, self.ncv)
        self.stale = False

    def n_certified(self):
        return int(np.count_nonzero(self.cells >= 0))

    def size(self):
        return int(self.cells.size)


def _circle_contracts(solver, pk, a, r, period, cert):
    """True if f^(m period) maps the circle of radius r around ``a`` inside the disc of radius
    _SHRINK r around ``a`` for some m <= _M_MAX (margin: half the largest image gap)."""
    th = 2 * np.pi * np.arange(_N_CIRCLE) / _N_CIRCLE
    X0 = a[0] + r * np.cos(th)
    V0 = a[1] + r * np.sin(th)
    periods = period * np.arange(1, _M_MAX + 1, dtype=np.int64)
    outX = np.empty((_N_CIRCLE, _M_MAX))
    outV = np.empty((_N_CIRCLE, _M_MAX))
    ok = np.empty(_N_CIRCLE, np.bool_)
    _map_points(solver.code, pk, solver.opts(), X0, V0, periods, outX, outV, ok)
    cert["periods"] += int(_N_CIRCLE * periods[-1])
    if not ok.all():
        return False
    for m in range(_M_MAX):
        dx = outX[:, m] - a[0]
        dv = outV[:, m] - a[1]
        gap = np.hypot(np.diff(outX[:, m], append=outX[0, m]),
                       np.diff(outV[:, m], append=outV[0, m])).max()
        if np.hypot(dx, dv).max() + 0.5 * gap < _SHRINK * r:
            return True
    return False


def _certify(solver, pk, a, r_start, period, tol, cert):
    """Largest certified capture radius around section point ``a`` (0 if none)."""
    r_end = max(_R_END, 10.0 * tol)
    r0 = r_start
    for _ in range(_N_TRY):
        if r0 <= r_end:
            return 0.0
        r = r0
        good = True
        while r > r_end:
            if not _circle_contracts(solver, pk, a, r, period, cert):
                good = False
                break
            r *= _SHRINK
        if good:
            return float(r0)
        r0 *= _RETRY
    return 0.0


def _coarse_to_fine_order(nx: int, nv: int):
    """Flat indices (ix * nv + iv) ordered coarse sub-grids first, then by index; and the
    number of points of the coarsest sub-grid (the first round)."""
    L = max(0, int(math.floor(math.log2(max(nx, nv) / 4.0))))
    ix, iv = np.meshgrid(np.arange(nx), np.arange(nv), indexing="ij")

    def tz(a):
        out = np.full(a.shape, L)
        for lev in range(L - 1, -1, -1):
            out[(a % (2 ** (lev + 1))) != 0] = lev
        return out

    level = np.minimum(tz(ix), tz(iv)).ravel()
    idx = np.arange(nx * nv)
    return idx[np.lexsort((idx, -level))], int(np.count_nonzero(level == L))


def _round_sizes(n: int, first: int):
    size, start = max(1, first), 0
    while start < n:
        b = min(n, start + size)
        yield start, b
        start = b
        size = min(_CHUNK_MAX, size * 4)


def _check_range(name, r):
    try:
        lo, hi = r
    except (TypeError, ValueError):
        raise ParameterError(f"{name}: expected a (min, max) pair, got {r!r}") from None
    lo = check_float(f"{name} min", lo)
    hi = check_float(f"{name} max", hi)
    if not hi > lo:
        raise ParameterError(f"{name}: empty or reversed range ({lo:g}, {hi:g}); need min < max")
    return lo, hi


def _check_grid(grid):
    if isinstance(grid, (tuple, list, np.ndarray)):
        if len(grid) != 2:
            raise ParameterError(f"grid: expected an int or an (nx, nv) pair, got {grid!r}")
        return check_int("grid nx", grid[0], 2), check_int("grid nv", grid[1], 2)
    g = check_int("grid", grid, 2)
    return g, g


class _Attractors:
    """Attractors found so far, in discovery order (before the final relabelling)."""

    def __init__(self, tol):
        self.tol = tol
        self.match_tol = MATCH_FACTOR * tol
        self.points = []   # (q, 2) arrays
        self.max_x = []
        self.radius = []   # (q,) capture radii
        self.certified = []

    def flat(self):
        if not self.points:
            return np.zeros((0, 2)), np.zeros(0), np.zeros(0, np.int64)
        apts = np.concatenate(self.points)
        arad = np.concatenate(self.radius)
        alab = np.concatenate([np.full(len(pt), k, np.int64) for k, pt in enumerate(self.points)])
        return apts, arad ** 2, alab

    def match(self, pts):
        """Label of the known attractor with the same set of section points (within match_tol)
        whose period is the candidate's or divides it (a slowly converging orbit can pass the
        periodicity test for a multiple of its period first), or -1."""
        q = len(pts)
        for k, a in enumerate(self.points):
            if q % len(a) != 0:
                continue
            d = np.abs(pts[:, None, :] - a[None, :, :]).max(axis=2)
            if (d.min(axis=1) <= self.match_tol).all() and (d.min(axis=0) <= self.match_tol).all():
                return k
        return -1

    def add(self, pts, xmax):
        self.points.append(np.array(pts, dtype=np.float64))
        self.max_x.append(float(xmax))
        self.radius.append(np.zeros(len(pts)))
        self.certified.append(False)
        return len(self.points) - 1


def basins(params: Params, *, x=(-3.0, 3.0), v=(-3.0, 3.0), grid=400, method: str = "smooth",
           transient: int = 10, max_periods: int = 1000, max_period: int = 16, rtol: float = 1e-8,
           atol: float = 1e-10, transition: str = "eq13", early_stop: bool = True,
           samples_per_period: int = 200, workers: int | None = None,
           progress=None) -> xr.Dataset:
    """Basins of attraction of the stroboscopic map on a grid of initial conditions.

    ``x``, ``v``: (min, max) ranges of the initial X and V (forcing phase 0); ``grid``: points
    per axis (int) or (nx, nv), each >= 2. ``transient``: periods before periodicity is tested
    (capture balls act from the start); ``max_periods``: budget per initial condition;
    ``max_period``: longest period looked for; ``early_stop``: stop a trajectory as soon as it
    enters a certified capture ball of a known attractor (False: every trajectory runs until
    its section repeats; same labels, much slower). ``workers``: threads (None = all cores;
    results do not depend on it). ``progress(done, total)`` is called after every round.

    Returns a Dataset with ``label`` (x0, v0) (-1 = undecided: not periodic within the budget
    or integration failed), ``periods_used`` (x0, v0), and per ``attractor``: ``fraction``,
    ``period``, ``contact`` (0/1: the orbit reaches X >= 1), ``max_X``, ``capture_radius``,
    the section points ``attractor_X``/``attractor_V`` (attractor, point; NaN-padded) and the
    sampled periodic orbit ``orbit_X``/``orbit_V`` (attractor, sample; NaN-padded). The share
    of undecided points is the attr ``undecided_fraction``; with the ``fraction`` values it
    sums to 1. See the module docstring for the algorithm.
    """
    params = check_params(params)
    x_lo, x_hi = _check_range("x", x)
    v_lo, v_hi = _check_range("v", v)
    nx, nv = _check_grid(grid)
    transient = check_int("transient", transient, 0)
    max_periods = check_int("max_periods", max_periods, 1)
    max_period = check_int("max_period", max_period, 1)
    spp = check_int("samples_per_period", samples_per_period, 2)
    solver = Solver(method=method, rtol=rtol, atol=atol, transition=transition)
    nw = resolve_workers(workers)

    xs = np.linspace(x_lo, x_hi, nx)
    vs = np.linspace(v_lo, v_hi, nv)
    n = nx * nv
    order, first = _coarse_to_fine_order(nx, nv)
    X0 = np.repeat(xs, nv)[order]
    V0 = np.tile(vs, nx)[order]
    pk = params.pack()
    opts = solver.opts()
    scale = max(abs(x_lo), abs(x_hi), abs(v_lo), abs(v_hi), 1.0)
    tol = section_tolerance(rtol, atol, scale)
    found = _Attractors(tol)
    cert = {"periods": 0}

    lat = _Lattice(x_lo, x_hi, v_lo, v_hi, nx, nv, first)
    label = np.full(n, LABEL_UNDECIDED, np.int64)  # in processing order
    used = np.zeros(n, np.int64)
    failed = 0
    with threads(nw):
        old_chunk = nb.get_parallel_chunksize()
        nb.set_parallel_chunksize(8)
        try:
            for a, b in _round_sizes(n, first):
                m = b - a
                apts, arad2, alab = found.flat()
                res = np.empty(m, np.int64)
                cq = np.zeros(m, np.int64)
                cX = np.empty((m, max_period))
                cV = np.empty((m, max_period))
                cxm = np.empty(m)
                _run_round(solver.code, pk, opts, X0[a:b], V0[a:b], max_periods, transient, tol,
                           max_period, bool(early_stop), apts, arad2, alab, lat.cells, lat.geo,
                           res, used[a:b],
                           cq, cX, cV, cxm)
                failed += int(np.count_nonzero(res == _RES_FAILED))
                res[res == _RES_FAILED] = LABEL_UNDECIDED
                new_before = len(found.points)
                for i in np.flatnonzero(res == _RES_NEW):
                    q = int(cq[i])
                    pts = np.stack([cX[i, :q], cV[i, :q]], axis=1)
                    k = found.match(pts)
                    if k < 0:
                        pts, xm = _polish(solver, pk, pts, cxm[i], tol)
                        k = found.match(pts)
                        if k < 0:
                            k = found.add(pts, xm)
                    res[i] = k
                label[a:b] = res
                if early_stop and len(found.points) > new_before:
                    _certify_all(found, solver, pk, cert)
                    lat.stale = True
                if early_stop and lat.stale and lat.active and b >= lat.start_after:
                    lat.certify(found, solver, pk, cert)
                if progress is not None:
                    progress(b, n)
        finally:
            nb.set_parallel_chunksize(old_chunk)
        orbits = _sample_orbits(found, solver, pk, spp)

    # back to grid order, canonical labels
    grid_label = np.empty(n, np.int64)
    grid_label[order] = label
    grid_used = np.empty(n, np.int64)
    grid_used[order] = used
    n_att = len(found.points)
    contact = np.array([int(mx >= 1.0) for mx in found.max_x], dtype=np.int64)
    periods = np.array([len(pt) for pt in found.points], dtype=np.int64)
    max_x = np.array(found.max_x, dtype=np.float64)
    key = sorted(range(n_att), key=lambda k: (contact[k], periods[k], max_x[k]))
    new_of_old = np.empty(n_att + 1, np.int64)
    for new, old in enumerate(key):
        new_of_old[old] = new
    new_of_old[n_att] = LABEL_UNDECIDED
    grid_label = np.where(grid_label >= 0, new_of_old[np.where(grid_label >= 0, grid_label, n_att)],
                          LABEL_UNDECIDED)
    return _dataset(params, solver, xs, vs, grid_label.reshape(nx, nv),
                    grid_used.reshape(nx, nv), found, key, contact, periods, max_x, orbits, spp,
                    dict(transient=transient, max_periods=max_periods, max_period=max_period,
                         early_stop=int(bool(early_stop)), section_tol=tol,
                         match_tol=found.match_tol, failed_points=failed,
                         certification_periods=cert["periods"],
                         certified_cells=lat.n_certified(), lattice_cells=lat.size()))


def _polish(solver, pk, pts, xmax, tol):
    """A candidate attractor's section points, refined by following the orbit until its section
    repeats to within tol / 1000 (at most _POLISH_MAX periods), then its period re-detected on
    the refined points: the points found when the periodicity test passed are only within
    ~tol / (1 - contraction) of the orbit, and a slowly converging orbit whose multiplier is
    near -1 passes the test for 2q before it passes for q. Returns (points, max X)."""
    q = len(pts)
    state = np.empty(N_STATE)
    _init_state(state, pts[-1, 0], pts[-1, 1])
    X, V, R, M, XM, Xm = (np.empty(q), np.empty(q), np.empty(q, np.int8), np.empty(q, np.uint8),
                          np.empty(q), np.empty(q))
    last = pts[-1].copy()
    for _ in range(max(1, _POLISH_MAX // q)):
        if advance(solver.code, pk, solver.opts(), state, 1, 0, q, X, V, R, M, XM, Xm) != 0:
            return pts, xmax
        if not (np.isfinite(X).all() and np.isfinite(V).all()):
            return pts, xmax
        change = max(abs(X[-1] - last[0]), abs(V[-1] - last[1]))
        last = np.array([X[-1], V[-1]])
        if change <= 1e-3 * tol:
            break
    for d in range(1, q):
        if q % d == 0 and (np.abs(X[d:] - X[:-d]) <= tol).all() and (np.abs(V[d:] - V[:-d]) <= tol).all():
            return np.stack([X[:d], V[:d]], axis=1), float(XM[:d].max())
    return np.stack([X, V], axis=1), float(XM.max())


def _certify_all(found, solver, pk, cert):
    """Capture radii for the attractors not certified yet (in discovery order: deterministic)."""
    allpts = np.concatenate(found.points)
    owner = np.concatenate([np.full(len(pt), k) for k, pt in enumerate(found.points)])
    start = 0
    for k, pts in enumerate(found.points):
        q = len(pts)
        if not found.certified[k]:
            for i in range(q):
                d = np.hypot(allpts[:, 0] - pts[i, 0], allpts[:, 1] - pts[i, 1])
                d[start + i] = np.inf
                r_start = min(_R_MAX, 0.999 * float(d.min())) if len(d) > 1 else _R_MAX
                found.radius[k][i] = _certify(solver, pk, pts[i], r_start, q, found.tol, cert)
            found.certified[k] = True
        start += q
    # balls of different attractors must not overlap (possible when an attractor found later
    # lies near one certified earlier); a smaller ball inside a certified one stays certified
    flat_r = np.concatenate(found.radius)
    for i in range(len(allpts)):
        for j in range(i + 1, len(allpts)):
            if owner[i] != owner[j]:
                d = float(np.hypot(*(allpts[i] - allpts[j])))
                if flat_r[i] + flat_r[j] >= d:
                    flat_r[i] = min(flat_r[i], 0.5 * d)
                    flat_r[j] = min(flat_r[j], 0.5 * d)
    start = 0
    for k, pts in enumerate(found.points):
        found.radius[k] = flat_r[start:start + len(pts)].copy()
        start += len(pts)


def _sample_orbits(found, solver, pk, spp):
    """Each attractor's orbit over its period, spp samples per forcing period."""
    out = []
    for pts in found.points:
        q = len(pts)
        nout = q * spp
        state = np.empty(N_STATE)
        _init_state(state, pts[0, 0], pts[0, 1])
        X = np.empty(nout)
        V = np.empty(nout)
        R = np.empty(nout, np.int8)
        M = np.empty(nout, np.uint8)
        s = advance(solver.code, pk, solver.opts(), state, spp, 0, nout, X, V, R, M,
                    np.empty(nout), np.empty(nout))
        if s != 0:
            X[:] = np.nan
            V[:] = np.nan
        out.append((np.concatenate([[pts[0, 0]], X]), np.concatenate([[pts[0, 1]], V])))
    return out


def _dataset(params, solver, xs, vs, label, used, found, key, contact, periods, max_x, orbits,
             spp, extra):
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
    counts = np.array([np.count_nonzero(label == k) for k in range(n_att)], dtype=np.int64)
    undecided = int(np.count_nonzero(label < 0))
    ds = xr.Dataset(
        {
            "label": (("x0", "v0"), label.astype(np.int32),
                      {"long_name": "attractor reached (-1 = undecided)", "units": "1"}),
            "periods_used": (("x0", "v0"), used.astype(np.int32),
                             {"long_name": "forcing periods integrated before the point was decided",
                              "units": "1"}),
            "fraction": ("attractor", counts / n,
                         {"long_name": "share of the grid points in the basin", "units": "1"}),
            "count": ("attractor", counts, {"long_name": "grid points in the basin", "units": "1"}),
            "period": ("attractor", periods[key].astype(np.int32) if n_att else np.zeros(0, np.int32),
                       {"long_name": "period in forcing periods", "units": "1"}),
            "contact": ("attractor", contact[key].astype(np.int8) if n_att else np.zeros(0, np.int8),
                        {"long_name": "orbit reaches the support (max X >= 1)", "units": "1"}),
            "max_X": ("attractor", max_x[key] if n_att else np.zeros(0),
                      {"long_name": "largest X on the orbit", "units": "1"}),
            "attractor_X": (("attractor", "point"), AX,
                            {"long_name": "section points X (t = kT)", "units": "1"}),
            "attractor_V": (("attractor", "point"), AV,
                            {"long_name": "section points V (t = kT)", "units": "1/s"}),
            "capture_radius": (("attractor", "point"), RAD,
                               {"long_name": "certified capture radius around each section point",
                                "units": "1"}),
            "orbit_X": (("attractor", "sample"), OX,
                        {"long_name": "periodic orbit X over its period", "units": "1"}),
            "orbit_V": (("attractor", "sample"), OV,
                        {"long_name": "periodic orbit V over its period", "units": "1/s"}),
        },
        coords={
            "x0": ("x0", xs, {"long_name": "initial X", "units": "1"}),
            "v0": ("v0", vs, {"long_name": "initial V", "units": "1/s"}),
            "attractor": ("attractor", np.arange(n_att), {"long_name": "attractor label"}),
            "point": ("point", np.arange(npt)),
            "sample": ("sample", np.arange(nsamp) / spp,
                       {"long_name": "time since the first section point", "units": "T"}),
        },
        attrs=provenance_attrs(
            params, solver, analysis="basins", grid_nx=len(xs), grid_nv=len(vs),
            x_min=float(xs[0]), x_max=float(xs[-1]), v_min=float(vs[0]), v_max=float(vs[-1]),
            n_attractors=n_att, undecided_fraction=undecided / n, undecided_count=undecided,
            total_periods=int(used.sum()), mean_periods_used=float(used.mean()),
            samples_per_period=spp, forcing_period=params.period, **extra),
    )
    return ds
