"""Attractors of ``basins``: periodic candidates refined and confirmed, matched by their
section points; undecided trajectories grouped into chaotic attractors by their section
clouds."""

from __future__ import annotations

import numpy as np

from ...integrate.contract import ST_X
from ...kernels import new_state, output_buffers
from ..periodicity import detect_period
from ._core import N_CONFIRM

#: candidate section points within MATCH_FACTOR * tol of a known attractor's points are that
#: attractor (a settled trajectory is within ~tol / (1 - contraction) of its orbit).
MATCH_FACTOR = 100.0
KIND_NAMES = ("periodic", "chaotic")
KIND_PERIODIC, KIND_CHAOTIC = 0, 1

_POLISH_MAX = 400   # periods spent refining a new attractor's section points
_CONFIRM_MIN = 128  # periods (at least _CONFIRM_MULT periods of the orbit) a candidate must
_CONFIRM_MULT = 8   # stay on its refined section points to be confirmed
_CLOUD = 64         # recent section points kept per trajectory (chaotic grouping)
_CLOUD_CELLS = 32   # cells per axis of the window in the lattice that groups the clouds
_CHAOS_PERIODS = 512  # periods followed to confirm a chaotic group (with a perturbed twin)
_TWIN = 1e-6        # the twin's initial offset in X (times the window's scale)
_TWIN_GROWTH = 1e3  # separation growth that shows sensitive dependence


def _same_orbit(pts, a, tol):
    """The section points ``pts`` (q, 2) are those of ``a`` (p, 2), p dividing q, within tol in
    any cyclic order."""
    if len(pts) % len(a) != 0:
        return False
    d = np.abs(pts[:, None, :] - a[None, :, :]).max(axis=2)
    return bool((d.min(axis=1) <= tol).all() and (d.min(axis=0) <= tol).all())


class _Attractors:
    """Attractors found so far, in discovery order (before the final relabelling), and the
    candidates that failed confirmation (not attractors: a trajectory that passes the
    periodicity test near one of them again goes on at once)."""

    def __init__(self, tol):
        self.tol = tol
        self.match_tol = MATCH_FACTOR * tol
        self.points = []   # (q, 2) arrays
        self.max_x = []
        self.min_x = []
        self.mask = []  # modes visited on the attractor
        self.radius = []   # (q,) capture radii
        self.certified = []
        self.kind = []
        self.states = []  # kernel state at the first section point (None: from X, V alone)
        self.full = []  # (q, n) every state component at the section points (None: n = 2)
        self.rejected = []  # (q, 2) arrays

    def flat(self):
        if not self.points:
            return np.zeros((0, 2)), np.zeros(0), np.zeros(0, np.int64)
        apts = np.concatenate(self.points)
        arad = np.concatenate(self.radius)
        alab = np.concatenate([np.full(len(pt), k, np.int64) for k, pt in enumerate(self.points)])
        return apts, arad ** 2, alab

    def centres(self, k):
        """Every component at attractor k's section points, row i at ``points[k][i]`` (the
        centres of its certified balls on a grid with every component); NaN rows where they
        are not known (a chaotic attractor, a run that failed)."""
        pts = self.points[k]
        f = self.full[k]
        if f is None or self.kind[k] != KIND_PERIODIC or len(f) != len(pts):
            return np.full((len(pts), self.n_full()), np.nan)
        f = np.roll(f, 1, axis=0)  # _full_points' last row is the first section point
        if not (np.abs(f[:, :2] - pts) <= self.tol).all():
            return np.full_like(f, np.nan)
        return f

    def n_full(self):
        return next((len(f[0]) for f in self.full if f is not None), 2)

    def flat_full(self):
        """``flat`` with every component of the section points (``centres``)."""
        if not self.points:
            return np.zeros((0, self.n_full())), np.zeros(0), np.zeros(0, np.int64)
        _, arad2, alab = self.flat()
        return np.concatenate([self.centres(k) for k in range(len(self.points))]), arad2, alab

    def match(self, pts, u=None):
        """Label of the known periodic attractor with the same set of section points (within
        match_tol) whose period is the candidate's or divides it (a slowly converging orbit can
        pass the periodicity test for a multiple of its period first), or -1. With ``u`` (a
        model with more than X and V: every component at one of the candidate's section
        points), that state must also be one of the attractor's: two attractors may share
        their (X, V)."""
        for k, a in enumerate(self.points):
            if self.kind[k] == KIND_PERIODIC and _same_orbit(pts, a, self.match_tol):
                f = self.full[k]
                if u is None or f is None or np.abs(f - u).max(axis=1).min() <= self.match_tol:
                    return k
        return -1

    def was_rejected(self, pts):
        return any(_same_orbit(pts, a, self.match_tol) for a in self.rejected)

    def add(self, pts, extremes, kind=KIND_PERIODIC, state=None, full=None):
        """A new attractor with section points ``pts`` and ``extremes`` = (max X, min X,
        visited-mode mask) over the periods followed (and, for a model with more than X and V,
        the kernel ``state`` at its first section point and ``full``, every component at each
        section point); returns its label."""
        self.states.append(None if state is None else np.array(state, dtype=np.float64))
        self.full.append(None if full is None else np.array(full, dtype=np.float64))
        self.points.append(np.array(pts, dtype=np.float64))
        self.max_x.append(float(extremes[0]))
        self.min_x.append(float(extremes[1]))
        self.mask.append(int(extremes[2]))
        self.radius.append(np.zeros(len(pts)))
        self.certified.append(kind != KIND_PERIODIC)
        self.kind.append(kind)
        return len(self.points) - 1

    def near(self, X, V):
        """True where (X, V) lies within match_tol of a periodic attractor's section point (a
        trajectory still converging to it, not a chaotic one)."""
        out = np.zeros(len(X), np.bool_)
        for k, a in enumerate(self.points):
            if self.kind[k] == KIND_PERIODIC:
                d = np.maximum(np.abs(X[:, None] - a[None, :, 0]), np.abs(V[:, None] - a[None, :, 1]))
                out |= d.min(axis=1) <= self.match_tol
        return out


class _Clouds:
    """Recent section points of the trajectories still undecided after ``max_periods``,
    grouped into candidate chaotic attractors: each trajectory's last points occupy cells of a
    fixed lattice over the section (the grid window cut into _CLOUD_CELLS cells per axis,
    continued beyond it); trajectories that share a cell, directly or through others, form one
    group (connected components: the grouping does not depend on the order of the points).
    The first member of a group occupies no cell occupied before it (a *seed*); the seeds'
    kernel states are kept to confirm the groups."""

    _OFF = 1 << 20

    def __init__(self, x_lo, x_hi, v_lo, v_hi, n):
        self.geo = (x_lo, v_lo, (x_hi - x_lo) / _CLOUD_CELLS, (v_hi - v_lo) / _CLOUD_CELLS)
        # members (processing positions, increasing) and the first cell of each
        self.pos = np.zeros(0, np.int64)
        self.first_cell = np.zeros(0, np.int64)
        self.edges = np.zeros((0, 2), np.int64)
        self.seen = np.zeros(0, np.int64)
        self.seeds = {}  # processing position -> kernel state

    def add(self, pos, X, V, states):
        """Trajectories at processing positions ``pos`` (in increasing order) with their recent
        section points X, V (u, c) and kernel states (u, N_STATE)."""
        x0, v0, dx, dv = self.geo
        i = np.clip(np.floor((X - x0) / dx), -self._OFF, self._OFF - 1).astype(np.int64) + self._OFF
        j = np.clip(np.floor((V - v0) / dv), -self._OFF, self._OFF - 1).astype(np.int64) + self._OFF
        ids = np.sort(i * (2 * self._OFF) + j, axis=1)
        rows = np.repeat(np.arange(len(pos)), ids.shape[1])
        flat = ids.ravel()
        keep = np.ones(flat.size, np.bool_)
        keep[1:] = (flat[1:] != flat[:-1]) | (rows[1:] != rows[:-1])
        rows, flat = rows[keep], flat[keep]
        self.pos = np.concatenate([self.pos, np.asarray(pos, np.int64)])
        self.first_cell = np.concatenate([self.first_cell, ids[:, 0]])
        self.edges = np.unique(np.concatenate([self.edges, np.stack([ids[rows, 0], flat], axis=1)]),
                               axis=0)
        cells, first = np.unique(flat, return_index=True)  # first: the earliest row per cell
        taken = np.isin(flat, self.seen) | (rows[first[np.searchsorted(cells, flat)]] != rows)
        for r in np.setdiff1d(np.arange(len(pos)), rows[taken]):
            self.seeds[int(pos[r])] = states[r].copy()
        self.seen = np.union1d(self.seen, cells)

    def groups(self):
        """[(processing positions of the members, kernel state of the first member)], in the
        order of the first members."""
        if not self.seeds:
            return []
        from scipy.sparse import coo_matrix
        from scipy.sparse.csgraph import connected_components
        cells = np.unique(self.edges)
        a = np.searchsorted(cells, self.edges[:, 0])
        b = np.searchsorted(cells, self.edges[:, 1])
        graph = coo_matrix((np.ones(len(a)), (a, b)), shape=(len(cells), len(cells)))
        comp = connected_components(graph, directed=False)[1]
        order = np.argsort(self.pos, kind="stable")
        members, first = self.pos[order], self.first_cell[order]
        mcomp = comp[np.searchsorted(cells, first)]
        out, done = [], set()
        for s in sorted(self.seeds):
            c = int(comp[np.searchsorted(cells, first[np.searchsorted(members, s)])])
            if c not in done:
                done.add(c)
                out.append((members[mcomp == c], self.seeds[s]))
        return out


def _polish(solver, pk, pts, tol, state=None):
    """A candidate attractor's section points, refined and confirmed; None if it is not a
    periodic attractor.

    Refined: the orbit is followed until its section repeats to within tol / 1000 (at most
    _POLISH_MAX periods) and its period re-detected on the refined points (the points found
    when the periodicity test passed are only within ~tol / (1 - contraction) of the orbit,
    and a slowly converging orbit whose multiplier is near -1 passes the test for 2q before it
    passes for q). Confirmed: the refined orbit closes (its last q section points repeat the
    q before them within tol) and stays on its points within tol for a further window of at
    least _CONFIRM_MIN periods (and _CONFIRM_MULT of its periods): a chaotic trajectory that
    shadowed an unstable periodic orbit long enough to pass the test drifts away. Returns
    (points, (max X, min X, visited-mode mask)).

    ``state``: the trajectory's kernel state at its last candidate point (a model with more
    than X and V: the other components are not in ``pts``); the orbit is followed from it,
    and a third item is returned, the kernel state at the first returned point."""
    q = len(pts)
    full = state is not None
    state = state.copy() if full else new_state(pts[-1, 0], pts[-1, 1])
    X, V, R, M, XM, Xm = output_buffers(q)
    opts = solver.opts()
    last = pts[-1].copy()
    for it in range(max(1, _POLISH_MAX // q)):
        prev = np.stack([X, V], axis=1) if it else pts
        if solver.advance(pk, opts, state, 1, 0, q, X, V, R, M, XM, Xm) != 0:
            return None
        if not (np.isfinite(X).all() and np.isfinite(V).all()):
            return None
        change = max(abs(X[-1] - last[0]), abs(V[-1] - last[1]))
        last = np.array([X[-1], V[-1]])
        if change <= 1e-3 * tol:
            break
    if not (np.abs(X - prev[:, 0]) <= tol).all() or not (np.abs(V - prev[:, 1]) <= tol).all():
        return None
    d = next((d for d in range(1, q) if q % d == 0 and (np.abs(X[d:] - X[:-d]) <= tol).all()
              and (np.abs(V[d:] - V[:-d]) <= tol).all()), q)
    out = np.stack([X[:d], V[:d]], axis=1), _extremes(XM[:d], Xm[:d], M[:d])
    W = X.copy(), V.copy()
    for _ in range(max(_CONFIRM_MULT, -(-_CONFIRM_MIN // q))):
        if solver.advance(pk, opts, state, 1, 0, q, X, V, R, M, XM, Xm) != 0:
            return None
        if not ((np.abs(X - W[0]) <= tol).all() and (np.abs(V - W[1]) <= tol).all()):
            return None
    if full:  # the state is at the last point X[q-1] = X[d-1]: rotate it first
        pts_d = np.roll(out[0], 1, axis=0)
        return pts_d, out[1], state
    return out


def _extremes(XM, Xm, M):
    """(max X, min X, visited-mode mask) of recorded intervals."""
    return float(XM.max()), float(Xm.min()), int(np.bitwise_or.reduce(M))


def _confirm_chaos(solver, pk, state, tol, max_period, scale):
    """A group of undecided trajectories is a chaotic attractor if its first member, followed
    _CHAOS_PERIODS more periods, stays aperiodic (no period <= max_period over its last
    section points) and shows sensitive dependence: a twin started _TWIN * scale away in X
    separates by _TWIN_GROWTH times that. Returns (_CLOUD section points, (max X, min X, mode mask) over the
    periods followed) or None."""
    runs = []
    for dx in (0.0, _TWIN * scale):
        s = state.copy()
        s[ST_X] += dx
        X, V, R, M, XM, Xm = output_buffers(_CHAOS_PERIODS)
        if solver.advance(pk, solver.opts(), s, 1, 0, _CHAOS_PERIODS, X, V, R, M, XM,
                   Xm) != 0 or not (np.isfinite(X).all() and np.isfinite(V).all()):
            return None
        runs.append((X, V, XM, Xm, M))
    (X, V, XM, Xm, M), (X2, V2, *_) = runs
    w = 2 * max_period + max(max_period, N_CONFIRM)
    if detect_period(X[-w:], V[-w:], tol, max_period) > 0:
        return None
    if not np.hypot(X - X2, V - V2).max() >= _TWIN_GROWTH * _TWIN * scale:
        return None
    return np.stack([X[:_CLOUD], V[:_CLOUD]], axis=1), _extremes(XM, Xm, M)
