"""Certificates of the early stop: capture discs around a periodic attractor's section points
and lattice cells mapped inside them. Both are proofs only because the stroboscopic map is a
homeomorphism of the plane (the image of a disc is the inside of the image of its circle):
``basins`` uses them only where ``MAP_IS_HOMEOMORPHISM`` holds.

A grid with every state component (a model with n > 2 components, or other axes) uses balls
in the whole state space instead: by the Jordan-Brouwer separation theorem the image of a ball
under a homeomorphism of R^n is the inside of the image of its sphere, so a sphere mapped
into a smaller ball proves the same. The sphere is sampled by the cube's boundary grid
(``sphere``), and the margin is the longest image of an edge between neighbouring samples
(any point of the sphere lies in a grid cell all of whose corners neighbour each other).
Up to n = ``MAX_SPHERE_N`` components, and only without continuous memory slots (the map
must act on u alone)."""

from __future__ import annotations

import functools
import math

import numba as nb
import numpy as np

from ...integrate.contract import N_STATE, ST_MODE, ST_V, ST_VA, ST_X
from ...kernels import new_state
from ._core import _SHRINK, _certify_cells, _certify_cells_u, _map_points, _map_u
from .order import _Pace

_R_MAX = 1.5        # largest capture radius tried
_R_END = 1e-4       # smallest radius of the certification sequence (at least 10 tol)
_N_CIRCLE = 48      # samples of each certification circle
_M_MAX = 12         # at most this many periods of the orbit to map a circle inside
_N_TRY = 24         # starting radii tried (each _RETRY times the previous) before giving up
_RETRY = 0.85
_MAP_WORK = 10000   # trajectory-periods per compiled call when mapping a circle
_CELL_SAMPLES = 16  # circle samples of a lattice cell's disc
_CELL_M_MAX = 24    # periods allowed for a cell's disc to map into an attractor disc
#: grid steps per edge of the cube whose boundary samples the sphere of a ball (n components:
#: (k + 1)^n - (k - 1)^n samples), for capture balls and for lattice cells
_BALL_K = {2: 12, 3: 4, 4: 3}
_BALL_M_MAX = 24  # a ball's sphere (coarser than a circle: a wider margin) may take longer
_CELL_K = {2: 4, 3: 2, 4: 2}
MAX_SPHERE_N = 4
SPHERE_MIN_GRID = 64


@functools.lru_cache(maxsize=8)
def sphere(n: int, k: int):
    """Unit directions sampling the sphere S^(n-1) and the neighbour pairs between them: the
    points of the boundary of the cube [-1, 1]^n on a grid of k steps per edge, projected
    onto the sphere, and the pairs one grid step apart (diagonals included) in every
    coordinate. Returns (W (m, n), E (e, 2))."""
    g = np.stack(np.meshgrid(*[np.arange(k + 1)] * n, indexing="ij"), axis=-1).reshape(-1, n)
    g = g[((g == 0) | (g == k)).any(axis=1)]
    c = -1.0 + 2.0 * g / k
    W = c / np.linalg.norm(c, axis=1)[:, None]
    a, b = np.nonzero(np.triu(np.abs(g[:, None, :] - g[None, :, :]).max(axis=2) == 1))
    return W, np.stack([a, b], axis=1).astype(np.int64)


def sphere_certificates(model, spec, nx: int, nv: int) -> bool:
    """Whether balls in the whole state space are certified for ``model``'s method ``spec`` on
    an nx x nv grid: at most MAX_SPHERE_N components, no continuous memory, and a grid of at
    least SPHERE_MIN_GRID points per axis (a sphere costs several times a circle: on a
    smaller grid the certificates cost more than they save)."""
    return (2 <= model.n <= MAX_SPHERE_N and not spec.continuous_memory
            and min(nx, nv) >= SPHERE_MIN_GRID)


class _Lattice:
    """Cells of a coarse lattice over the grid whose covering discs are certified to lie in one
    attractor's basin (mapped inside one of its certified discs): a trajectory entering such a
    cell is decided at once. Only used for grids of at least 64 x 64 points (about 1 cell per
    16 x 16 grid points, _CELL_SAMPLES circle points each: a few per cent of the work)."""

    def __init__(self, x_lo, x_hi, v_lo, v_hi, nx, nv, first, axes=(0, 1), base=np.zeros(0)):
        self.ncx, self.ncv = max(1, nx // 16), max(1, nv // 16)
        self.active = self.ncx >= 4 and self.ncv >= 4
        self.start_after = 4 * first  # after the first two rounds
        self.stale = False
        # a grid with every component (``base``): balls in the whole state space
        self.axes, self.base = (int(axes[0]), int(axes[1])), np.asarray(base, np.float64)
        self.nsamp = (len(sphere(len(self.base), _CELL_K[len(self.base)])[0])
                      if self.base.size else _CELL_SAMPLES)
        self.pace = _Pace(2 * nb.get_num_threads() * self.nsamp * _CELL_M_MAX)
        if not self.active:
            self.cells = np.zeros((0, 0), np.int64)
            self.geo = np.zeros(5)
            return
        dx, dv = (x_hi - x_lo) / self.ncx, (v_hi - v_lo) / self.ncv
        self.cells = np.full((self.ncx, self.ncv), -1, np.int64)
        self.tried = np.zeros((self.ncx, self.ncv), np.bool_)
        ci, cj = np.meshgrid(np.arange(self.ncx), np.arange(self.ncv), indexing="ij")
        self.cx = (x_lo + (ci + 0.5) * dx).ravel()
        self.cv = (v_lo + (cj + 0.5) * dv).ravel()
        self.rc = 0.5 * math.hypot(dx, dv) * 1.001
        self.geo = np.array([x_lo, v_lo, dx, dv, self.rc ** 2])

    def certify(self, found, solver, pk, cert):
        """(Re)try the cells not certified yet against the attractors known now (in slices of
        cells, each one compiled call of about ``SLICE_SECONDS``)."""
        full = self.base.size > 0
        apts, arad2, alab = found.flat_full() if full else found.flat()
        todo = np.flatnonzero(self.cells.ravel() < 0)
        out = self.cells.ravel().copy()
        work = np.zeros(len(out), np.int64)
        if full:
            W, E = sphere(len(self.base), _CELL_K[len(self.base)])
        a = 0
        while a < len(todo):
            b = min(len(todo), a + self.pace.share(self.nsamp * _CELL_M_MAX))

            def call():
                if full:
                    _certify_cells_u(solver.kernel, solver.fns, pk, solver.opts(), self.cx,
                                     self.cv, self.rc, todo[a:b], W, E, _CELL_M_MAX, apts,
                                     arad2, alab, out, work, *self.axes, self.base)
                else:
                    _certify_cells(solver.kernel, solver.fns, pk, solver.opts(), self.cx,
                                   self.cv, self.rc, todo[a:b], _CELL_SAMPLES, _CELL_M_MAX,
                                   apts, arad2, alab, out, work)
                return int(work[todo[a:b]].sum())
            self.pace.run(call, b - a, (b - a) * self.nsamp * _CELL_M_MAX)
            a = b
        cert["periods"] += int(work.sum())
        self.cells = out.reshape(self.ncx, self.ncv)
        self.stale = False

    def n_certified(self):
        return int(np.count_nonzero(self.cells >= 0))

    def size(self):
        return int(self.cells.size)


def _circle_contracts(solver, pk, a, r, period, cert):
    """True if f^(m period) maps the circle of radius r around ``a`` inside the disc of radius
    _SHRINK r around ``a`` for some m <= _M_MAX (margin: half the largest image gap). The
    multiples are mapped in compiled calls of at most about _MAP_WORK periods (bounded work
    between returns to Python)."""
    th = 2 * np.pi * np.arange(_N_CIRCLE) / _N_CIRCLE
    states = np.zeros((_N_CIRCLE, N_STATE))
    states[:, ST_X] = a[0] + r * np.cos(th)
    states[:, ST_V] = states[:, ST_VA] = a[1] + r * np.sin(th)
    states[:, ST_MODE] = -1.0
    outX = np.empty((_N_CIRCLE, _M_MAX))
    outV = np.empty((_N_CIRCLE, _M_MAX))
    ok = np.ones(_N_CIRCLE, np.bool_)
    cert["periods"] += int(_N_CIRCLE * period * _M_MAX)
    step = max(1, _MAP_WORK // (_N_CIRCLE * period))  # multiples per compiled call
    for m in range(0, _M_MAX, step):
        _map_points(solver.kernel, solver.fns, pk, solver.opts(), states, period, outX[:, m:m + step],
                    outV[:, m:m + step], ok)
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


def _ball_contracts(solver, pk, a, r, period, cert):
    """``_circle_contracts`` for a ball around ``a`` (every component u): f^(m period) maps
    its sphere (``sphere``) inside the ball of radius _SHRINK r around ``a`` for some m <=
    _BALL_M_MAX, with a margin of the longest image of an edge between neighbouring
    samples."""
    n = len(a)
    W, E = sphere(n, _BALL_K[n])
    states = np.array([new_state(u[0], u[1], u[2:]) for u in a[None, :] + r * W])
    U = np.empty((len(W), n))
    ok = np.ones(len(W), np.bool_)
    for _ in range(_BALL_M_MAX):
        _map_u(solver.kernel, solver.fns, pk, solver.opts(), states, period, U, ok)
        cert["periods"] += int(len(W) * period)
        if not ok.all():
            return False
        gap = np.sqrt(((U[E[:, 0]] - U[E[:, 1]]) ** 2).sum(axis=1)).max()
        if np.sqrt(((U - a) ** 2).sum(axis=1)).max() + gap < _SHRINK * r:
            return True
    return False


def _certify(solver, pk, a, r_start, period, tol, cert, contracts=_circle_contracts):
    """Largest certified capture radius around section point ``a`` (0 if none); ``contracts``
    the test of one radius (``_ball_contracts`` for every component)."""
    if not np.isfinite(a).all():
        return 0.0
    r_end = max(_R_END, 10.0 * tol)
    r0 = r_start
    for _ in range(_N_TRY):
        if r0 <= r_end:
            return 0.0
        r = r0
        good = True
        while r > r_end:
            if not contracts(solver, pk, a, r, period, cert):
                good = False
                break
            r *= _SHRINK
        if good:
            return float(r0)
        r0 *= _RETRY
    return 0.0


def _certify_all(found, solver, pk, cert, full=False):
    """Capture radii for the attractors not certified yet (in discovery order: deterministic);
    ``full``: balls around every component of the section points (``_Attractors.centres``;
    where those are unknown, no ball), else discs in (X, V)."""
    cen = [found.centres(k) for k in range(len(found.points))] if full else found.points
    allpts = np.concatenate(cen)
    owner = np.concatenate([np.full(len(c), k) for k, c in enumerate(cen)])

    def dist(a):
        """Distances from ``a`` to every centre (an unknown one: infinitely far)."""
        if not full:
            return np.hypot(allpts[:, 0] - a[0], allpts[:, 1] - a[1])
        d = np.sqrt(((allpts - a) ** 2).sum(axis=1))
        return np.where(np.isnan(d), np.inf, d)

    start = 0
    for k, c in enumerate(cen):
        q = len(c)
        if not found.certified[k]:
            for i in range(q):
                d = dist(c[i])
                d[start + i] = np.inf
                r_start = min(_R_MAX, 0.999 * float(d.min()))  # (alone: _R_MAX)
                found.radius[k][i] = _certify(solver, pk, c[i], r_start, q, found.tol, cert,
                                              _ball_contracts if full else _circle_contracts)
            found.certified[k] = True
        start += q
    # balls of different attractors must not overlap (possible when an attractor found later
    # lies near one certified earlier); a smaller ball inside a certified one stays certified
    flat_r = np.concatenate(found.radius)
    for i in range(len(allpts)):
        d = dist(allpts[i])
        for j in range(i + 1, len(allpts)):
            if owner[i] != owner[j] and flat_r[i] + flat_r[j] >= d[j]:
                flat_r[i] = min(flat_r[i], 0.5 * d[j])
                flat_r[j] = min(flat_r[j], 0.5 * d[j])
    start = 0
    for k, c in enumerate(cen):
        found.radius[k] = flat_r[start:start + len(c)].copy()
        start += len(c)
