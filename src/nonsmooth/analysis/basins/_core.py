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


@nb.njit(cache=True, inline="always")
def _u_at(state, i):
    """Component i of the state vector u held in a kernel state."""
    return state[i] if i < 2 else state[ST_EXTRA + i - 2]


@nb.njit(cache=True, inline="always")
def _captured_u(state, apts, arad2, alab, cells, cgeo, ia, ib, base):
    """``_captured`` for a start with every component (``base``, the grid's axes ``ia``, ``ib``):
    the label of the certified ball holding the kernel state's u, a lattice cell's (the ball
    of radius sqrt(cgeo[4]) around the cell's centre, the other components those of ``base``)
    or an attractor's (``apts`` (K, n): every component of its section points); else -1."""
    n = base.shape[0]
    if cells.shape[0] > 0:
        fi = (_u_at(state, ia) - cgeo[0]) / cgeo[2]
        fj = (_u_at(state, ib) - cgeo[1]) / cgeo[3]
        if 0.0 <= fi < cells.shape[0] and 0.0 <= fj < cells.shape[1]:
            lab = cells[int(fi), int(fj)]
            if lab >= 0:
                d2 = 0.0
                for i in range(n):
                    if i == ia:
                        c = cgeo[0] + (int(fi) + 0.5) * cgeo[2]
                    elif i == ib:
                        c = cgeo[1] + (int(fj) + 0.5) * cgeo[3]
                    else:
                        c = base[i]
                    d = _u_at(state, i) - c
                    d2 += d * d
                if d2 < cgeo[4]:
                    return lab
    for k in range(apts.shape[0]):
        d2 = 0.0
        for i in range(n):
            d = _u_at(state, i) - apts[k, i]
            d2 += d * d
        if d2 < arad2[k]:
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
    ``base``: all others 0). With ``base``, the certified balls hold every component
    (``_captured_u``; ``apts`` (K, n)), else (X, V) only."""
    k = rec[_K]
    full = base.shape[0] > 0
    if k == 0:
        if early and not full:
            lab = _captured(x0, v0, apts, arad2, alab, cells, cgeo)
            if lab >= 0:
                rec[_RES] = lab
                return
        if not full:
            _init_state(state, x0, v0)
        else:
            _init_state_axes(state, x0, v0, ia, ib, base)
            if early:
                lab = _captured_u(state, apts, arad2, alab, cells, cgeo, ia, ib, base)
                if lab >= 0:
                    rec[_RES] = lab
                    return
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
            if full:
                lab = _captured_u(state, apts, arad2, alab, cells, cgeo, ia, ib, base)
            else:
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


@nb.njit(cache=True, inline="always")
def _init_state_u(state, u):
    """``_init_state`` from every component of u (memory slots 0, mode classified)."""
    _init_state(state, u[0], u[1])
    for i in range(2, u.shape[0]):
        state[ST_EXTRA + i - 2] = u[i]


@nb.njit(cache=True, parallel=True)
def _map_u(kernel, fns, p, opts, states, period, out, ok):
    """Advance every state with ok[i] by ``period`` forcing periods, recording every component
    of its u (out[i, :n], n = out.shape[1]); ok[i] = False if the kernel failed."""
    for i in nb.prange(states.shape[0]):
        if not ok[i]:
            continue
        ox, ov, orr, om, oxa, oxi = _one_interval()
        s = kernel(fns, p, opts, states[i], 1, period - 1, 1, ox, ov, orr, om, oxa, oxi)
        for c in range(out.shape[1]):
            out[i, c] = _u_at(states[i], c)
            if not math.isfinite(out[i, c]):
                ok[i] = False
        if s != 0:
            ok[i] = False


@nb.njit(cache=True, inline="always")
def _inside_ball(U, E, apts, arad2, alab):
    """Label of the attractor ball (``apts`` (K, n), radii squared ``arad2``) that holds the
    image sphere U (samples (m, n), edges E between neighbouring samples) shrunk by _SHRINK,
    with a margin of its longest edge (any image point lies within it of a sample); else -1."""
    n = U.shape[1]
    gap = 0.0
    for e in range(E.shape[0]):
        d2 = 0.0
        for c in range(n):
            d = U[E[e, 0], c] - U[E[e, 1], c]
            d2 += d * d
        if d2 > gap:
            gap = d2
    gap = math.sqrt(gap)
    for a in range(apts.shape[0]):
        r = math.sqrt(arad2[a])
        if r <= 0.0:
            continue
        inside = True
        for j in range(U.shape[0]):
            d2 = 0.0
            for c in range(n):
                d = U[j, c] - apts[a, c]
                d2 += d * d
            if math.sqrt(d2) + gap >= _SHRINK * r:
                inside = False
                break
        if inside:
            return alab[a]
    return -1


@nb.njit(cache=True, parallel=True)
def _certify_cells_u(kernel, fns, p, opts, cx, cv, rc, todo, W, E, m_max, apts, arad2, alab,
                     out, work, ia, ib, base):
    """``_certify_cells`` for starts with every component: the ball of radius rc around each
    cell's centre (components ``ia``, ``ib`` = (cx[k], cv[k]), the others from ``base``) is
    certified if, after some m <= m_max periods, the images of its sphere's samples (unit
    directions W, neighbours E) lie inside one attractor ball (``_inside_ball``)."""
    n = base.shape[0]
    ns = W.shape[0]
    for kk in nb.prange(todo.shape[0]):
        k = todo[kk]
        out[k] = -1
        work[k] = 0
        states = np.empty((ns, N_STATE))
        u = np.empty(n)
        for j in range(ns):
            for c in range(n):
                u[c] = base[c] + rc * W[j, c]
            u[ia] = cx[k] + rc * W[j, ia]
            u[ib] = cv[k] + rc * W[j, ib]
            _init_state_u(states[j], u)
        U = np.empty((ns, n))
        ox, ov, orr, om, oxa, oxi = _one_interval()
        for m in range(m_max):
            bad = False
            for j in range(ns):
                s = kernel(fns, p, opts, states[j], 1, 0, 1, ox, ov, orr, om, oxa, oxi)
                for c in range(n):
                    U[j, c] = _u_at(states[j], c)
                    if not math.isfinite(U[j, c]):
                        bad = True
                if s != 0 or bad:
                    bad = True
                    break
            work[k] += ns
            if bad:
                break
            lab = _inside_ball(U, E, apts, arad2, alab)
            if lab >= 0:
                out[k] = lab
                break
