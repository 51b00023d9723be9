"""Certificates of the early stop: capture discs around a periodic attractor's section points
and lattice cells mapped inside them. Both are proofs only because the stroboscopic map is a
homeomorphism of the plane (the image of a disc is the inside of the image of its circle):
``basins`` uses them only where ``MAP_IS_HOMEOMORPHISM`` holds."""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from ...integrate.contract import N_STATE, ST_MODE, ST_V, ST_VA, ST_X
from ._core import _SHRINK, _certify_cells, _map_points
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
        self.pace = _Pace(2 * nb.get_num_threads() * _CELL_SAMPLES * _CELL_M_MAX)
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
        """(Re)try the cells not certified yet against the attractors known now (in slices of
        cells, each one compiled call of about ``SLICE_SECONDS``)."""
        apts, arad2, alab = found.flat()
        todo = np.flatnonzero(self.cells.ravel() < 0)
        out = self.cells.ravel().copy()
        work = np.zeros(len(out), np.int64)
        a = 0
        while a < len(todo):
            b = min(len(todo), a + self.pace.share(_CELL_SAMPLES * _CELL_M_MAX))

            def call():
                _certify_cells(solver.kernel, solver.fns, pk, solver.opts(), self.cx, self.cv, self.rc,
                               todo[a:b], _CELL_SAMPLES, _CELL_M_MAX, apts, arad2, alab, out,
                               work)
                return int(work[todo[a:b]].sum())
            self.pace.run(call, b - a, (b - a) * _CELL_SAMPLES * _CELL_M_MAX)
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
