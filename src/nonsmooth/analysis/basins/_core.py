"""Compiled core of ``basins`` (numba; no xarray): the grid points followed in resumable
slices, circles and lattice cells mapped for the certificates."""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from ...integrate.contract import N_STATE, ST_EXTRA, ST_H, ST_MODE, ST_V, ST_VA, ST_X
from ...status import NON_FINITE

#: section points that must repeat beyond one period before a period q is accepted:
#: the last q + max(q, N_CONFIRM) points are checked.
N_CONFIRM = 4
_SHRINK = 0.6       # contraction demanded at each radius of a certificate (c)

LABEL_UNDECIDED = -1
_RES_NEW = -2       # settled on a periodic orbit: candidate attractor
_RES_FAILED = -3
_RUNNING = -4       # still being followed (a slice ended)

# per-point integer record of a round (int64 columns): periods done, periodicity tested from
# this period on (after a rejected candidate), result, candidate period, kernel status
_K, _HOLD, _RES, _Q, _STATUS = range(5)
_N_REC = 5


@nb.njit(cache=True, inline="always")
def _init_state(state, x0, v0):
    """``kernels.new_state(x0, v0)`` in place: the further state components and the memory
    slots (``state[ST_EXTRA:]``) start at 0, whatever the (uninitialised) array held."""
    state[ST_X] = x0
    state[ST_V] = v0
    state[ST_VA] = v0
    state[ST_MODE] = -1.0
    state[ST_H] = 0.0
    for i in range(ST_EXTRA, state.shape[0]):
        state[i] = 0.0


@nb.njit(cache=True, inline="always")
def _init_state_axes(state, a, b, ia, ib, base):
    """A start with every state component from ``base`` (u, n values) but components ``ia``
    and ``ib`` (the grid's axes) set to a and b; memory slots 0, mode classified."""
    _init_state(state, base[0], base[1])
    for i in range(2, base.shape[0]):
        state[ST_EXTRA + i - 2] = base[i]
    for i, val in ((ia, a), (ib, b)):
        if i == 0:
            state[ST_X] = val
        elif i == 1:
            state[ST_V] = val
            state[ST_VA] = val
        else:
            state[ST_EXTRA + i - 2] = val


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
def _follow(kernel, fns, p, opts, x0, v0, max_periods, transient, tol, max_period, early, apts,
            arad2, alab, cells, cgeo, budget, state, buf, rec, cX, cV, cxm, of, oi8, ou8, ia, ib,
            base):
    """Follow one initial condition for at most ``budget`` more periods, resuming where the
    previous call stopped: ``state`` (kernel state), ``buf`` (3, L: the last L section points X,
    V and the largest X of their periods) and ``rec`` (the _N_REC counters) carry everything
    between calls, so a trajectory cut into calls is bit-identical to one call. On return
    rec[_RES] is _RUNNING (budget used up), a captured label >= 0, -1 undecided after
    ``max_periods``, -2 periodic (candidate points in cX[:q], cV[:q] in time order, q in
    rec[_Q], the largest X over its last q periods in cxm[0]) or -3 failed (kernel status in
    rec[_STATUS]). ``of`` (4, 1), ``oi8``, ``ou8`` (1,) are scratch space. The grid's axes
    are state components ``ia``, ``ib`` (0, 1: X, V; the others from ``base``; an empty
    ``base``: all others 0)."""
    k = rec[_K]
    if k == 0:
        if early:
            lab = _captured(x0, v0, apts, arad2, alab, cells, cgeo)
            if lab >= 0:
                rec[_RES] = lab
                return
        if base.shape[0] == 0:
            _init_state(state, x0, v0)
        else:
            _init_state_axes(state, x0, v0, ia, ib, base)
    L = buf.shape[1]
    bx = buf[0]
    bv = buf[1]
    bm = buf[2]
    ox = of[0]
    ov = of[1]
    oxa = of[2]
    oxi = of[3]
    hold = max(transient, rec[_HOLD])
    end = min(max_periods, k + budget)
    while k < end:
        k += 1
        s = kernel(fns, p, opts, state, 1, 0, 1, ox, ov, oi8, ou8, oxa, oxi)
        x = ox[0]
        v = ov[0]
        if s != 0 or not (math.isfinite(x) and math.isfinite(v)):
            rec[_K] = k
            rec[_RES] = _RES_FAILED
            rec[_STATUS] = s if s != 0 else NON_FINITE
            return
        j = (k - 1) % L
        bx[j] = x
        bv[j] = v
        bm[j] = oxa[0]
        if early:
            lab = _captured(x, v, apts, arad2, alab, cells, cgeo)
            if lab >= 0:
                rec[_K] = k
                rec[_RES] = lab
                return
        if k < hold:
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
                cxm[0] = xm
                rec[_K] = k
                rec[_Q] = q
                rec[_RES] = _RES_NEW
                return
    rec[_K] = k
    if k >= max_periods:
        rec[_RES] = LABEL_UNDECIDED


@nb.njit(cache=True, parallel=True)
def _run_round(kernel, fns, p, opts, X0, V0, active, max_periods, transient, tol, max_period, early,
               apts, arad2, alab, cells, cgeo, budget, states, bufs, recs, cX, cV, cxm, ofs,
               oi8, ou8, ia, ib, base):
    """One slice of a round: every point ``active[j]`` followed for at most ``budget`` more
    periods (``_follow``; per-point arrays indexed by the point)."""
    for j in nb.prange(active.shape[0]):
        i = active[j]
        _follow(kernel, fns, p, opts, X0[i], V0[i], max_periods, transient, tol, max_period, early,
                apts, arad2, alab, cells, cgeo, budget, states[i], bufs[i], recs[i], cX[i],
                cV[i], cxm[i:i + 1], ofs[i], oi8[i], ou8[i], ia, ib, base)


@nb.njit(cache=True, inline="always")
def _one_interval():
    """Output buffers of the kernel contract for one interval (X, V, R, M, Xmax, Xmin)."""
    return (np.empty(1), np.empty(1), np.empty(1, np.int8), np.empty(1, np.uint8), np.empty(1),
            np.empty(1))


@nb.njit(cache=True, parallel=True)
def _map_points(kernel, fns, p, opts, states, period, outX, outV, ok):
    """Advance every state by outX.shape[1] times ``period`` forcing periods, recording its
    section point after each (outX[i, j]); rows with ok[i] False are skipped, ok[i] = False if
    the kernel failed."""
    for i in nb.prange(states.shape[0]):
        ox, ov, orr, om, oxa, oxi = _one_interval()
        for j in range(outX.shape[1]):
            if not ok[i]:
                break
            s = kernel(fns, p, opts, states[i], 1, period - 1, 1, ox, ov, orr, om, oxa, oxi)
            if s != 0 or not (math.isfinite(ox[0]) and math.isfinite(ov[0])):
                ok[i] = False
            outX[i, j] = ox[0]
            outV[i, j] = ov[0]


@nb.njit(cache=True, parallel=True)
def _certify_cells(kernel, fns, p, opts, cx, cv, rc, todo, nsamp, m_max, apts, arad2, alab, out,
                   work):
    """For every cell k listed in ``todo``: the disc of radius rc around (cx[k], cv[k]) is
    certified (out[k] = label) if, after some m <= m_max periods, the images of nsamp points of
    its circle all lie inside one attractor disc with a margin of half the largest gap between
    neighbouring images (then the image of the whole disc does: homeomorphism)."""
    for kk in nb.prange(todo.shape[0]):
        k = todo[kk]
        out[k] = -1
        work[k] = 0
        states = np.empty((nsamp, N_STATE))
        for j in range(nsamp):
            th = 2.0 * np.pi * j / nsamp
            _init_state(states[j], cx[k] + rc * math.cos(th), cv[k] + rc * math.sin(th))
        xs = np.empty(nsamp)
        vs = np.empty(nsamp)
        ox, ov, orr, om, oxa, oxi = _one_interval()
        for m in range(m_max):
            bad = False
            for j in range(nsamp):
                s = kernel(fns, p, opts, states[j], 1, 0, 1, ox, ov, orr, om, oxa, oxi)
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
