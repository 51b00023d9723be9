"""Stable and unstable manifolds of a saddle periodic orbit of the stroboscopic map, and their
homoclinic crossings (issue 21, item 2).

``manifolds(params, orbit) -> xarray.Dataset``

``orbit`` is a converged :func:`nonsmooth.periodic_orbit` of the k-fold map P^k with one
multiplier outside the unit circle (mu_u, eigenvector e_u; in a two-dimensional section the
other is mu_s, eigenvector e_s). Where mu_u < 0 the map used is P^2k, so that each branch
is invariant on its own (lambda = mu_u^2); otherwise P^k (lambda = mu_u). Each manifold has two
branches, leaving the saddle z* on either side of its eigenvector.

**Unstable manifold: forward iteration of a fundamental domain.** A branch is the curve

    w(j + s) = P^j(z* +- delta lambda^s e_u),    0 <= s < 1,  j = 0, 1, 2, ...

(the linear approximation of the manifold at distance delta, where its error is O(delta^2),
carried forward by the kernel's own map; its images are the manifold itself, so a point of the
branch mapped by the kernel lands on the branch). Each level j is sampled on s and refined by
bisection in s until consecutive points are closer than ``spacing``, and, where the curve
turns by more than ``max_angle`` at a point (it bends, or crosses a switching surface where the
map has a kink), until they are closer than ``spacing / 100``. A branch ends when a level adds
less than ``spacing / 10`` of length (it has converged onto an attractor: the end point is
reported), when it leaves the window, or at ``length``, ``iterates`` or ``max_points``.

**Stable manifold: a search method, no inverse map.** A map with impacts of restitution r < 1
or with sticking is not invertible (and the kernel integrates forward only), so the stable
manifold is not grown by iterating P^-1. Instead each point is the boundary between initial
conditions whose orbits leave the saddle's neighbourhood along one unstable branch or the
other: a point is classified by iterating the map until it has come within ``radius`` of z*
(in the eigen-coordinates (c_u, c_s)) and then leaves it with |c_u| >= radius; the sign of
c_u is its side. The branch is continued from z* +- delta e_s by steps along its tangent,
each point located by bisection across the curve (to ``tol``) between two points of opposite
sides, the step halved where no such pair is found or the curve turns by more than
``max_angle``, and grown back towards ``spacing`` otherwise. A branch ends when it leaves the
window, at ``length`` or ``max_points``, or where its points can no longer be classified
(they do not reach the saddle within ``max_search`` iterates of the map).

**Sections of more than two coordinates** (n > 2, or a memory slot the map depends on): the
unstable manifold is grown as above in the full section; the stable manifold, of dimension
one less than the section's, is traced where it meets a plane of two state components through
the saddle (the others held at the saddle's values), by the same search, starting along the
line where the plane meets the stable subspace (c_u = 0).

**Homoclinic points.** Transversal crossings of a stable and an unstable branch (segment
intersections of the two polylines, away from z*) are reported with their crossing angle; a
small angle marks a near tangency. A first homoclinic tangency along a parameter lies between
a value without crossings and one with them.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np
import xarray as xr

from .. import status as st
from ..errors import ParameterError
from ..checks import check_positive, check_window
from ..integrate.contract import ST_EXTRA, ST_V, ST_X
from ..io import apply_state_units, component_names, components, provenance_attrs
from ..kernels import new_state, output_buffers, run
from ..models.base import KERNEL_GENERIC
from ..simulate import check_int, check_params, component_variables
from ..tangent import TangentSetup
from .basins import _check_axes
from .basins._core import _map_points, _one_interval
from .stability import _active

BRANCH_NAMES = ("unstable_plus", "unstable_minus", "stable_plus", "stable_minus")


@nb.njit(cache=True, parallel=True)
def _exit_sides(kernel, fns, p, opts, states, q, idx, zs, Einv, r, r_lo, max_iter, side, used):
    """For each state (at a period boundary): the side (+1 / -1, the sign of c_u) on which its
    orbit under the q-period map leaves the saddle zs after having entered its box
    |c_u| < r, |c_s| < r ((c_u, c_1, c_2, ...) = Einv (z - zs), row 0 of Einv giving c_u;
    |c_s| the Euclidean norm of the others; z the section coordinates at the kernel state
    positions idx): where |c_u| >= r, or already where |c_u| >= r_lo >= |c_s|
    (r_lo = r / (2 lambda): a strongly expanding saddle carries a point from inside the box
    far beyond it in one map; there the local stable manifold, c_u = O(|c_s|^2), is far below
    r_lo). 0 if it does not within max_iter maps or its integration fails. used[i]: the maps
    it took."""
    m = idx.shape[0]
    rows = Einv.shape[0]
    for i in nb.prange(states.shape[0]):
        ox, ov, orr, om, oxa, oxi = _one_interval()
        entered = False
        side[i] = 0
        used[i] = 0
        for j in range(max_iter + 1):
            if j > 0:
                s = kernel(fns, p, opts, states[i], 1, q - 1, 1, ox, ov, orr, om, oxa, oxi)
                used[i] = j
                if s != 0:
                    break
            cu = 0.0
            cs2 = 0.0  # the Euclidean norm of the other coordinates, squared
            finite = True
            for a in range(rows):
                c = 0.0
                for b in range(m):
                    c += Einv[a, b] * (states[i, idx[b]] - zs[b])
                if not math.isfinite(c):
                    finite = False
                if a == 0:
                    cu = c
                else:
                    cs2 += c * c
            if not finite:
                break
            cs = math.sqrt(cs2)  # (|c_s| itself for one stable coordinate)
            if abs(cu) < r and cs < r:
                entered = True
            if entered and (abs(cu) >= r or (abs(cu) >= r_lo and cs <= r_lo)):
                side[i] = 1 if cu > 0 else -1
                break


class _Map:
    """The q-period stroboscopic map of many section points at once (the kernel's own map)."""

    def __init__(self, setup: TangentSetup, solver, p, q: int, window):
        self.setup, self.solver, self.p, self.q = setup, solver, p, q
        self.template = new_state(0.0, 0.0)  # mode -1: each point classified by the model
        self.window = window
        # a stable branch is followed out of the window up to this distance, where it may
        # turn back into it
        self.reach = (0.5 * max(window[0][1] - window[0][0], window[1][1] - window[1][0])
                      if window else math.inf)
        self.lam = 1.0  # the unstable multiplier of the q-period map
        self.zfill = None  # the saddle's section point (components the stable search fixes)
        self.plane = [0, 1]  # the section coordinates the stable search varies
        self.idx = None  # kernel state positions of the active section coordinates
        self.periods = 0  # forcing periods integrated (work done)
        self.progress = None  # progress(done, total) in points, ``per_branch`` a branch
        self.per_branch = 0
        self.total = 0
        self.base = 0  # the count at the start of the branch being grown
        self.count = 0  # its points so far

    def report(self, points: int):
        """Count ``points`` more points of the branch being grown (progress)."""
        self.count += points
        if self.progress is not None:
            self.progress(self.base + min(self.count, self.per_branch), self.total)

    def next_branch(self):
        """The branch being grown is finished (however many points it has)."""
        self.base += self.per_branch
        self.count = 0
        self.report(0)

    def embed(self, Z):
        """Section points (rows z) from rows Z in the plane's two coordinates, the further
        coordinates the saddle's (``self.zfill``)."""
        full = np.repeat(self.zfill[None, :], len(Z), axis=0)
        full[:, self.plane] = Z
        return full

    def states(self, Z):
        return np.array([self.setup.state_of(z, self.template) for z in Z])

    def zs(self, states):
        return np.array([self.setup.z_of(s) for s in states])

    def iterate(self, Z, n: int):
        """The n-th iterates of the rows of Z (NaN rows where the kernel failed)."""
        states = self.states(Z)
        ok = np.ones(len(Z), np.bool_)
        if n > 0 and len(Z):
            ox = np.empty((len(Z), n))
            ov = np.empty((len(Z), n))
            _map_points(self.solver.kernel, self.setup.fns, self.p, self.setup.opts, states,
                        self.q, ox, ov, ok)
            self.periods += len(Z) * n * self.q
        out = self.zs(states)
        out[~ok] = np.nan
        return out

    def sides(self, Z, zs, Einv, r, max_iter):
        """Exit sides (see _exit_sides) of the points Z: rows in the plane's two coordinates
        (``embed``)."""
        return self.sides_full(self.embed(Z), zs, Einv, r, max_iter)

    def sides_full(self, Z, zs, Einv, r, max_iter):
        """Exit sides of the section points Z (rows z): zs and Einv on the active
        coordinates (kernel state positions ``self.idx``)."""
        states = self.states(Z)
        side = np.zeros(len(Z), np.int64)
        used = np.zeros(len(Z), np.int64)
        if len(Z):
            _exit_sides(self.solver.kernel, self.setup.fns, self.p, self.setup.opts, states,
                        self.q, self.idx, zs, Einv, r, r / (2.0 * self.lam), max_iter, side,
                        used)
        self.periods += int(used.sum()) * self.q
        return side


# ---- geometry of polylines -------------------------------------------------------------------
def _turn(P):
    """Turning angle at each interior point of the polyline P (rows), NaN-free: 0 at the ends."""
    out = np.zeros(len(P))
    if len(P) < 3:
        return out
    a = P[1:-1] - P[:-2]
    b = P[2:] - P[1:-1]
    na = np.linalg.norm(a, axis=1)
    nb_ = np.linalg.norm(b, axis=1)
    c = np.einsum("ij,ij->i", a, b) / np.maximum(na * nb_, 1e-300)
    out[1:-1] = np.arccos(np.clip(c, -1.0, 1.0))
    return out


def _outside(P, window, margin):
    """Which rows of P lie outside the window (X, V box) widened by ``margin`` (per row)."""
    if window is None:
        return np.zeros(len(P), bool)
    (x0, x1), (v0, v1) = window
    return ((P[:, 0] < x0 - margin) | (P[:, 0] > x1 + margin)
            | (P[:, 1] < v0 - margin) | (P[:, 1] > v1 + margin))


def _inside(P, window):
    return ~_outside(P, window, np.zeros(len(P)))


def _crossings(A, B, skip_a: int = 1, skip_b: int = 1):
    """Transversal crossings of polylines A and B (rows (X, V)): list of (point, angle, i, j)
    with segment i of A and j of B; the first ``skip_*`` segments (at the saddle) left out."""
    out = []
    if len(A) < skip_a + 2 or len(B) < skip_b + 2:
        return out
    a0, a1 = A[skip_a:-1], A[skip_a + 1:]
    b0, b1 = B[skip_b:-1], B[skip_b + 1:]
    da = a1 - a0
    db = b1 - b0
    lo_a, hi_a = np.minimum(a0, a1), np.maximum(a0, a1)
    lo_b, hi_b = np.minimum(b0, b1), np.maximum(b0, b1)
    for i0 in range(0, len(a0), 512):
        sl = slice(i0, i0 + 512)
        box = ((lo_a[sl, None, 0] <= hi_b[None, :, 0]) & (lo_b[None, :, 0] <= hi_a[sl, None, 0])
               & (lo_a[sl, None, 1] <= hi_b[None, :, 1]) & (lo_b[None, :, 1] <= hi_a[sl, None, 1]))
        for i, j in zip(*np.nonzero(box)):
            i = i + i0
            den = da[i, 0] * db[j, 1] - da[i, 1] * db[j, 0]
            if den == 0.0:
                continue
            w = b0[j] - a0[i]
            ta = (w[0] * db[j, 1] - w[1] * db[j, 0]) / den
            tb = (w[0] * da[i, 1] - w[1] * da[i, 0]) / den
            if 0.0 <= ta < 1.0 and 0.0 <= tb < 1.0:
                cosang = abs(np.dot(da[i], db[j])) / (np.linalg.norm(da[i]) *
                                                     np.linalg.norm(db[j]))
                out.append((a0[i] + ta * da[i], float(np.arccos(min(1.0, cosang))),
                            i + skip_a, j + skip_b))
    return out


# ---- the unstable manifold: forward iteration of a fundamental domain --------------------------
def _unstable_branch(mp: _Map, zs, e, lam, sign, delta, spacing, max_angle, length, iterates,
                     max_points, nshow):
    """Points (rows z) of one unstable branch, their iterate level j + s, the status, and the
    end point if the branch converged."""
    fine = spacing / 100.0

    def level(j, S):
        base = zs[None, :] + sign * delta * (lam ** S)[:, None] * e[None, :]
        return mp.iterate(base, j)

    pts, ts = [], []
    total = 0.0
    prev = last = math.inf
    count = 0
    coarse = 0  # chords left longer than spacing: the fundamental domain's resolution
    status = f"iterates: {iterates} iterates of the map"
    end = None
    for j in range(iterates):
        S = np.linspace(0.0, 1.0, 9)
        P = level(j, S)
        while True:
            bad = ~np.all(np.isfinite(P), axis=1)
            if bad.any():  # keep what precedes the first failed point
                k = int(np.flatnonzero(bad)[0])
                S, P = S[:k], P[:k]
                status = "integration failed"
                break
            Q = P[:, :nshow]
            d = np.linalg.norm(np.diff(Q, axis=0), axis=1)
            turn = _turn(Q)
            sharp = np.maximum(turn[:-1], turn[1:]) > max_angle
            mark = (d > spacing) | (sharp & (d > fine))
            # both ends beyond the window by more than the chord: the curve between cannot
            # reach the window (for a chord of bounded curvature) and is not refined
            Qp = Q[:, mp.plane]
            out = (_outside(Qp, mp.window, np.r_[d, 0.0])
                   & _outside(Qp, mp.window, np.r_[0.0, d]))
            mark &= ~(out[:-1] & out[1:])
            fine_enough = np.diff(S) > 1e-13
            coarse += int(np.count_nonzero(mark & ~fine_enough & (d > spacing)))
            mark &= fine_enough
            if not mark.any() or count + len(S) >= max_points:
                break
            new_s = 0.5 * (S[:-1] + S[1:])[mark][:max(1, max_points - count - len(S))]
            new_p = level(j, new_s)
            S = np.r_[S, new_s]
            P = np.r_[P, new_p]
            order = np.argsort(S, kind="stable")
            S, P = S[order], P[order]
        if len(S) < 2:
            break
        Q = P[:, :nshow]
        seg = np.linalg.norm(np.diff(Q, axis=0), axis=1)
        keep = len(S) - 1  # s = 1 is the next level's s = 0
        pts.append(P[:keep])
        ts.append(j + S[:keep])
        count += keep
        mp.report(keep)
        cum = total + np.r_[0.0, np.cumsum(seg)]
        if status == "integration failed":
            pts[-1], ts[-1] = P, j + S
            break
        if cum[-1] >= length:
            k = int(np.searchsorted(cum, length)) + 1
            pts[-1], ts[-1] = P[:k], j + S[:k]
            status = f"length: {length:g} reached"
            break
        total = cum[-1]
        prev, last = last, seg.sum()
        if math.isfinite(prev) and last < min(spacing / 10.0, prev):  # onto an attractor
            pts[-1], ts[-1] = P, j + S
            end = P[-1]
            status = "converged onto an attractor"
            break
        if mp.window is not None and np.all(_outside(Q[:, mp.plane], mp.window, mp.reach)):
            # beyond the window by more than half its size (nearer, later levels may come
            # back into it and are followed, unrefined outside it)
            pts[-1], ts[-1] = P, j + S
            status = "left the window"
            break
        if count >= max_points:
            pts[-1], ts[-1] = P, j + S
            status = f"max_points: {max_points} points"
            break
    P = np.concatenate([zs[None, :]] + pts) if pts else zs[None, :]
    T = np.concatenate([[-np.inf]] + ts) if ts else np.array([-np.inf])
    if coarse:
        status += (f"; {coarse} chords longer than spacing (s resolved to 1e-13: a strongly "
                   f"expanding saddle; a shorter length or a larger delta)")
    return P, T, status, end


# ---- the stable manifold: a search method -----------------------------------------------------
def _bisect(mp, a, b, side_a, zs, Einv, r, max_iter, tol, workers: int = 7):
    """A point within tol of the boundary between a (side side_a) and b (the other side), by
    rounds of ``workers`` interior points classified at once; None where one is undecided."""
    while np.linalg.norm(b - a) > tol:
        f = np.arange(1, workers + 1) / (workers + 1)
        Z = a[None, :] + f[:, None] * (b - a)[None, :]
        sides = mp.sides(Z, zs, Einv, r, max_iter)
        if np.any(sides == 0):
            return None
        k = int(np.sum(sides == side_a))
        if not (np.all(sides[:k] == side_a) and np.all(sides[k:] == -side_a)):
            return None  # not monotone: several boundaries on the segment
        a_new = Z[k - 1] if k > 0 else a
        b_new = Z[k] if k < workers else b
        a, b = a_new, b_new
    return 0.5 * (a + b)


def _around(mp, c, tang, rad, zs, Einv, r, max_iter, tol, n: int = 72):
    """The boundary point on the circle of radius rad around c nearest the forward direction
    ``tang`` (sign changes within 60 degrees of the backward direction are the curve already
    drawn), or None."""
    th = 2.0 * np.pi * np.arange(n) / n
    base = math.atan2(tang[1], tang[0])
    Z = c[None, :] + rad * np.column_stack([np.cos(base + th), np.sin(base + th)])
    sides = mp.sides(Z, zs, Einv, r, max_iter)
    best = None
    for i in range(n):
        j = (i + 1) % n
        if sides[i] == 0 or sides[j] != -sides[i]:
            continue
        ang = abs(((th[i] + th[j] + (2 * np.pi if j == 0 else 0.0)) / 2 + np.pi) % (2 * np.pi)
                  - np.pi)  # angle from the forward direction
        if ang > np.pi - np.pi / 3:
            continue
        if best is None or ang < best[0]:
            best = (ang, i, j)
    if best is None:
        return None
    _, i, j = best
    return _bisect(mp, Z[i], Z[j], sides[i], zs, Einv, r, max_iter, tol)


def _stable_branch(mp: _Map, start, zs, e_s, Einv, sign, delta, spacing, max_angle, length,
                   max_points, r, max_iter, tol):
    """Points of one stable branch (rows in the plane's coordinates, from the saddle's point
    ``start`` along ``e_s``) and the status; zs and Einv classify (active coordinates)."""
    W = [start.copy(), start + sign * delta * e_s]
    h = min(spacing, 10.0 * delta)
    h_min = max(tol * 10.0, 1e-4 * spacing)
    total = delta
    status = f"max_points: {max_points} points"
    while len(W) < max_points:
        tang = W[-1] - W[-2]
        tang = tang / np.linalg.norm(tang)
        nrm = np.array([-tang[1], tang[0]])
        found = None
        while h >= h_min:
            pred = W[-1] + h * tang
            # the bracket across the curve, widened from small: a strongly expanding saddle
            # leaves only points very near its stable manifold undecided-free
            w_max = h * max(math.tan(max_angle), 0.25)
            w = min(w_max, max(0.01 * h, 10.0 * tol))
            while True:
                ends = np.array([pred - w * nrm, pred + w * nrm])
                sides = mp.sides(ends, zs, Einv, r, max_iter)
                if sides[0] == 0 or sides[1] != sides[0] or w >= w_max:
                    break
                w = min(w_max, 4.0 * w)
            if sides[0] != 0 and sides[1] == -sides[0]:
                pt = _bisect(mp, ends[0], ends[1], sides[0], zs, Einv, r, max_iter, tol)
                if pt is not None:
                    step = pt - W[-1]
                    c = float(np.dot(step, tang) / np.linalg.norm(step))
                    if math.acos(max(-1.0, min(1.0, c))) <= max_angle:
                        found = pt
                        break
            h *= 0.5
        if found is None:  # a corner (the map's kink) or a fold: search around the point
            found = _around(mp, W[-1], tang, max(h_min, spacing / 20.0), zs, Einv, r,
                            max_iter, tol)
            h = max(h_min, spacing / 20.0)
        if found is None:
            status = "lost: no point of the boundary found within the smallest step"
            break
        W.append(found)
        mp.report(1)
        total += float(np.linalg.norm(found - W[-2]))
        h = min(spacing, 1.5 * h)
        if total >= length:
            status = f"length: {length:g} reached"
            break
        if mp.window is not None and _outside(found[None, :], mp.window, mp.reach)[0]:
            status = "left the window"  # (widened: the branch may come back into it)
            break
    return np.array(W), status


# ---- the analysis ------------------------------------------------------------------------------
def _centred(params, orbit, point):
    """``orbit`` with its section point ``point`` first: Newton shooting from it (converged
    there already) gives that point's monodromy."""
    from ..simulate import check_int
    from .stability import periodic_orbit

    point = check_int("point", point, 0)
    if not isinstance(orbit, xr.Dataset) or orbit.attrs.get("analysis") != "periodic_orbit":
        raise ParameterError("orbit: expected the Dataset of periodic_orbit(...)")
    k = int(orbit.attrs.get("k", 1))
    if point >= k:
        raise ParameterError(f"point: a period-{k} orbit has section points 0 ... {k - 1}, "
                             f"got {point}")
    if point == 0:
        return orbit
    u = np.asarray(components(orbit, suffix="_section").values[point], dtype=float)
    again = periodic_orbit(params, k=k, u0=[float(c) for c in u],
                           method=str(orbit.attrs.get("method", "exact")),
                           rtol=float(orbit.attrs.get("rtol", 1e-10)),
                           atol=float(orbit.attrs.get("atol", 1e-12)),
                           section_phase=float(orbit.attrs.get("section_phase", 0.0)))
    if int(again.attrs.get("converged", 0)) != 1:
        raise ParameterError(f"point: the orbit re-centred at its point {point} does not "
                             f"converge ({again.attrs.get('status')})")
    return again


def _saddle(params, orbit):
    """(solver, setup, k, z*, active mask, mu (active), eigenvectors (active, columns))."""
    from ..kernels import Solver
    m = params.model
    if not isinstance(orbit, xr.Dataset) or orbit.attrs.get("analysis") != "periodic_orbit":
        raise ParameterError("orbit: expected the Dataset of periodic_orbit(...)")
    if orbit.attrs.get("model") != m.name:
        raise ParameterError(f"orbit: an orbit of model {orbit.attrs.get('model')}, not {m.name}")
    for name, value in params.as_dict().items():
        got = orbit.attrs.get(f"param_{name}")
        if got is not None and not (float(got) == float(value)):
            raise ParameterError(f"orbit: computed at {name} = {float(got):g}, not {value:g}")
    if int(orbit.attrs.get("converged", 0)) != 1:
        raise ParameterError(f"orbit: not a converged orbit (status: "
                             f"{orbit.attrs.get('status')})")
    k = int(orbit.attrs.get("k", 1))
    solver = Solver(method=str(orbit.attrs.get("method", "exact")), model=m,
                    rtol=float(orbit.attrs.get("rtol", 1e-10)),
                    atol=float(orbit.attrs.get("atol", 1e-12)),
                    section_phase=float(orbit.attrs.get("section_phase", 0.0)))
    setup = TangentSetup(solver)
    p = params.pack()
    u = np.asarray(components(orbit, suffix="_section").values[0], dtype=float)
    s = new_state(u[0], u[1], u[2:])
    # one pass over the orbit fills the continuous memory, if any
    if run(KERNEL_GENERIC, setup.fns, p, setup.opts, s, 1, k, 0, *output_buffers(0)) != st.OK:
        raise ParameterError("orbit: its section point cannot be integrated")
    z = setup.z_of(s)
    M = np.asarray(orbit.monodromy.values, dtype=float)
    act = _active(M, setup.n)
    mu, E = np.linalg.eig(M[np.ix_(act, act)])
    unstable = np.flatnonzero(np.abs(mu) > 1.0)
    if unstable.size != 1 or abs(mu[unstable[0]].imag) > 0.0:
        raise ParameterError(f"orbit: a saddle has one real multiplier outside the unit circle; "
                             f"this orbit's are {np.round(mu, 6).tolist()}")
    return solver, setup, k, p, z, act, mu, E


def manifolds(params, orbit, *, x=None, v=None, spacing: float | None = None,
              delta: float | None = None, max_angle: float = 0.3, length: float | None = None,
              iterates: int | None = None, max_points: int = 4000, stable: bool = True,
              radius: float | None = None, max_search: int = 100,
              tol: float | None = None, point: int = 0, axes=None,
              progress=None) -> xr.Dataset:
    """The stable and unstable manifolds of the saddle ``orbit`` (a converged
    :func:`nonsmooth.periodic_orbit` of ``params``, same model and parameters; its method, k,
    tolerances and section phase are used) as polylines, by the methods of the module
    documentation; their homoclinic crossings.

    ``x``, ``v``: the window (the ranges of the two ``axes``, default X and V) the branches
    are grown in (default: none, then
    ``length`` bounds them); ``spacing``: the largest distance between consecutive points,
    to a few per cent (default: 1/200 of the window's diagonal, else 0.01 (1 + ‖z*‖)); ``delta``: the distance
    of the first point from the saddle (default spacing / 1000); ``max_angle``: the largest
    turn (radians) at a point before it is refined; ``length``: the largest arc length of a
    branch (default 4 window diagonals, else 100 spacings); ``iterates``: the most
    iterates of a fundamental domain (unstable; default 100 more than it takes the multiplier
    to carry delta to ``length``); ``max_points`` per branch; ``stable``: also
    the stable manifold (in a section of more than two coordinates, its trace in the plane
    of ``axes`` through the saddle); ``radius``: the saddle's
    neighbourhood in the classification (default 5 spacings); ``max_search``: iterates of the
    map before a point is called unclassified; ``tol``: the stable points' accuracy across
    the curve (default spacing / 10^4); ``point``: which of a period-k saddle's k section
    points the manifolds belong to (default 0; the orbit is re-centred there by Newton
    shooting, its monodromy taken there: the manifolds of point j are those of P^k at z_j);
    ``axes``: the two state components of the window and of the stable search, by the
    model's state names (default the first two; e.g. ("X", "Y") or "X,Y"; the result's attr
    ``axes`` names them as its variables are named, X and V for the first two). Where the
    section has more than two coordinates (n > 2, or a memory slot the map depends on) the
    stable manifold of a saddle with one unstable multiplier is a hypersurface: what is grown
    is the curve where it meets the plane of ``axes`` through the saddle (the other
    coordinates held at the saddle's: for n > 2 without memory, the boundary that ``basins``
    with ``axes`` and ``u0`` = the saddle's point draws), and homoclinic points are not
    sought there (attr ``section_coordinates``). ``progress`` (None or False: silent; True:
    a progress bar; or a callable ``progress(done, total)``): points grown, ``max_points``
    per branch (a branch that ends sooner counts as finished).

    Returns a Dataset over ``point`` (all branches one after the other): ``X``, ``V`` (and the
    further state components), ``branch`` (flag: unstable_plus, unstable_minus, stable_plus,
    stable_minus) and ``level`` (j + s of the unstable points; NaN on the stable ones); attrs
    ``status_<branch>`` (how each ended); over ``branch_index``: ``end_X``/``end_V`` (where an
    unstable branch converged, else NaN); the saddle (``saddle_X``, ``saddle_V``, the multipliers and
    eigenvectors); over ``crossing``: the homoclinic points (``crossing_X``, ``crossing_V``,
    ``crossing_angle``, ``crossing_unstable``, ``crossing_stable``; inside the window, where
    one is given). Points lie within ``spacing`` of each other inside the window; outside it
    the unstable branches are followed but not refined."""
    params = check_params(params)
    m = params.model
    if m.autonomous:
        raise ParameterError(f"manifolds: model {m.name} declares no forcing; the manifolds "
                             f"here are those of the stroboscopic map")
    window = check_window(x, v)
    plane = list(_check_axes(m, axes, None)[:2])
    orbit = _centred(params, orbit, point)
    solver, setup, k, p, zs, act, mu, E = _saddle(params, orbit)
    diag = (math.hypot(window[0][1] - window[0][0], window[1][1] - window[1][0])
            if window else None)
    spacing = (check_positive("spacing", spacing) if spacing is not None
               else diag / 200.0 if diag else 0.01 * (1.0 + float(np.linalg.norm(zs[plane]))))
    delta = check_positive("delta", delta) if delta is not None else spacing / 1000.0
    max_angle = check_positive("max_angle", max_angle)
    length = (check_positive("length", length) if length is not None
              else 4.0 * diag if diag else 100.0 * spacing)
    iterates = check_int("iterates", iterates, 1) if iterates is not None else None
    max_points = check_int("max_points", max_points, 3)
    max_search = check_int("max_search", max_search, 1)
    radius = check_positive("radius", radius) if radius is not None else 5.0 * spacing
    tol = check_positive("tol", tol) if tol is not None else spacing * 1e-4
    iu = int(np.flatnonzero(np.abs(mu) > 1.0)[0])
    mu_u = float(mu[iu].real)
    q = k if mu_u > 0 else 2 * k
    lam = mu_u ** (q // k)
    N = setup.N
    e_u = np.zeros(N)
    e_u[act] = E[:, iu].real / np.linalg.norm(E[:, iu].real)
    planar = int(act.sum()) == 2  # the section is the plane itself
    if iterates is None:  # enough levels to carry the fundamental domain across the window
        iterates = 100 + int(math.ceil(math.log(max(length, 10 * spacing) / delta)
                                       / math.log(abs(lam))))
    mp = _Map(setup, solver, p, q, window)
    mp.zfill = zs
    mp.lam = abs(lam)
    mp.plane = plane
    mp.idx = _state_positions(setup)[act]
    from ..sweep import progress_callback
    mp.progress = progress_callback(progress, "manifolds")
    mp.per_branch = max_points
    mp.total = (4 if stable else 2) * max_points
    nshow = m.n
    branches, statuses, ends, levels = [], [], [], []
    for sign in (1.0, -1.0):
        P, T, status, end = _unstable_branch(mp, zs, e_u, lam, sign, delta, spacing, max_angle,
                                             length, iterates, max_points, nshow)
        branches.append(P[:, :nshow])
        mp.next_branch()
        levels.append(T)
        statuses.append(status)
        ends.append(end[:nshow] if end is not None else np.full(nshow, np.nan))
    e_s = np.full(2, np.nan)
    stable_method = ""
    cross = []
    if stable:
        za = zs[act]
        M = np.asarray(orbit.monodromy.values, dtype=float)[np.ix_(act, act)]
        Einv, e_s = _stable_coordinates(E, mu, iu, e_u[act], act, plane, M)
        stable_method = ("search: each point bisected across the curve between initial "
                         "conditions that leave the saddle along opposite unstable branches "
                         "(no inverse map)")
        if not planar:
            names = component_names(m.state_names)
            stable_method += (f"; the trace of the {int(act.sum()) - 1}-dimensional stable "
                              f"manifold in the plane ({names[plane[0]]}, {names[plane[1]]}) "
                              f"through the saddle, the other coordinates the saddle's; "
                              f"homoclinic points not sought (the trace is not the manifold)")
        for sign in (1.0, -1.0):
            W, status = _stable_branch(mp, zs[plane], za, e_s, Einv, sign, delta, spacing,
                                       max_angle, length, max_points, radius, max_search, tol)
            branches.append(mp.embed(W)[:, :nshow])
            mp.next_branch()
            levels.append(np.full(len(W), np.nan))
            statuses.append(status)
            ends.append(np.full(nshow, np.nan))
        # homoclinic points (inside the window: outside it the branches are not refined)
        if planar:  # crossings of the unstable and the stable polylines
            for a in (0, 1):
                for b in (2, 3):
                    for pt, ang, i, j in _crossings(branches[a][:, plane],
                                                    branches[b][:, plane]):
                        row = np.zeros(nshow)
                        row[plane] = pt
                        cross.append((row, ang, a, b))
        cross = [c for c in cross if window is None or _inside(c[0][None, plane], window)[0]]
    return _dataset(params, solver, k, q, zs[:nshow], mu, e_u, e_s, branches, levels,
                    statuses, ends, cross, stable_method, plane, dict(
                        spacing=spacing, delta=delta, max_angle=max_angle, length=length,
                        iterates=iterates, max_points=max_points, radius=radius,
                        max_search=max_search, tol=tol, periods_integrated=mp.periods,
                        orbit_point=int(point), section_coordinates=int(act.sum())))


def _state_positions(setup: TangentSetup):
    """The kernel state position of each section coordinate z (as TangentSetup.z_of reads
    them)."""
    n = setup.n
    pos = [ST_X, ST_V] + [ST_EXTRA + i for i in range(n - 2)]
    pos += [ST_EXTRA + n - 2 + int(i) for i in setup.cmi]
    return np.asarray(pos, np.int64)


def _stable_coordinates(E, mu, iu, e_u, act, plane, M):
    """(Einv, e_s): the rows that give the classifier's coordinates of z - z* (row 0: the
    unstable coordinate c_u; the others: the stable part) and the stable direction in the
    plane.

    A planar section: the inverse of the eigenbasis (e_u, e_s), and e_s. More coordinates: c_u
    from the left eigenvector l_u of mu_u (l_u e_u = 1; ``M`` the active monodromy) and the
    stable part as the components of z - z* - c_u e_u (no inverse of the whole eigenbasis,
    which repeated or defective stable multipliers, e.g. zeros from sticking, make singular);
    the direction: the line where the plane meets c_u = 0."""
    at = np.flatnonzero(act)
    pa, pb = (int(np.flatnonzero(at == c)[0]) for c in plane)
    if len(at) == 2:  # a planar section
        i_s = 1 - iu
        if abs(mu[i_s].imag) > 0.0:
            raise ParameterError("orbit: complex stable multipliers")
        e_s = E[:, i_s].real / np.linalg.norm(E[:, i_s].real)
        Einv = np.linalg.inv(np.column_stack([e_u, e_s]))
        return Einv, np.array([e_s[pa], e_s[pb]])
    lam, L = np.linalg.eig(M.T)
    j = int(np.argmin(np.abs(lam - mu[iu])))
    lu = L[:, j].real
    scale = float(lu @ e_u)
    if not abs(scale) > 1e-12 * np.linalg.norm(lu):
        raise ParameterError("orbit: the unstable multiplier's left and right eigenvectors are "
                             "orthogonal (a defective multiplier); no stable manifold here")
    lu = lu / scale
    Einv = np.vstack([lu[None, :], np.eye(len(e_u)) - np.outer(e_u, lu)])
    lo, hi = sorted((pa, pb))  # the same branch "plus" whichever order the axes are given
    along = {lo: -lu[hi], hi: lu[lo]}
    d = np.array([along[pa], along[pb]])
    if not np.linalg.norm(d) > 1e-9 * np.linalg.norm(lu):
        raise ParameterError("axes: the plane lies in the saddle's stable subspace (no curve "
                             "to trace there); choose other axes")
    return Einv, d / np.linalg.norm(d)


def _dataset(params, solver, k, q, zs, mu, e_u, e_s, branches, levels, statuses, ends, cross,
             stable_method, plane, settings):
    m = params.model
    cnames = component_names(m.state_names)
    axes = [cnames[i] for i in plane]
    U = np.concatenate(branches)
    flag = np.concatenate([np.full(len(b), i, np.int8) for i, b in enumerate(branches)])
    nb_ = len(branches)
    names = BRANCH_NAMES[:nb_]
    E = np.array(ends)
    order = np.argsort(-np.abs(mu), kind="stable")
    cp = np.array([c[0] for c in cross]).reshape(-1, m.n)
    ds = xr.Dataset(
        {
            "X": ("point", U[:, 0], {"long_name": "X on the manifold (at the section)"}),
            "V": ("point", U[:, 1], {"long_name": "V on the manifold (at the section)"}),
            "branch": ("point", flag, {"long_name": "branch of the manifold",
                                       "flag_values": np.arange(nb_, dtype=np.int8),
                                       "flag_meanings": " ".join(names)}),
            "level": ("point", np.concatenate(levels), {
                "long_name": "j + s: the point is P^j of the fundamental domain's point s "
                             "(unstable branches; -inf at the saddle, NaN on stable ones)",
                "units": "1"}),
            "end_X": ("branch_index", E[:, 0], {"long_name": "X where the branch converged "
                                                             "onto an attractor (else NaN)"}),
            "end_V": ("branch_index", E[:, 1], {"long_name": "V where the branch converged "
                                                             "onto an attractor (else NaN)"}),
            "saddle_X": ((), float(zs[0]), {"long_name": "X of the saddle's section point"}),
            "saddle_V": ((), float(zs[1]), {"long_name": "V of the saddle's section point"}),
            "multiplier_real": ("multiplier", mu[order].real, {"units": "1"}),
            "multiplier_imag": ("multiplier", mu[order].imag, {"units": "1"}),
            "unstable_direction": ("component_index", e_u[plane], {
                "long_name": "unit eigenvector of the unstable multiplier (its components "
                             "in the plane)", "units": "1"}),
            "stable_direction": ("component_index", np.asarray(e_s, float), {
                "long_name": "unit tangent of the stable branches at the saddle, in the "
                             "plane", "units": "1"}),
            "crossing_X": ("crossing", cp[:, 0], {"long_name": "X of a homoclinic point"}),
            "crossing_V": ("crossing", cp[:, 1], {"long_name": "V of a homoclinic point"}),
            "crossing_angle": ("crossing", np.array([c[1] for c in cross], float), {
                "long_name": "angle between the branches at the crossing", "units": "rad"}),
            "crossing_unstable": ("crossing", np.array([c[2] for c in cross], np.int8), {
                "long_name": "the unstable branch", "flag_values": np.arange(nb_, dtype=np.int8),
                "flag_meanings": " ".join(names)}),
            "crossing_stable": ("crossing", np.array([c[3] for c in cross], np.int8), {
                "long_name": "the stable branch", "flag_values": np.arange(nb_, dtype=np.int8),
                "flag_meanings": " ".join(names)}),
        },
        coords={"point": np.arange(len(U)), "branch_index": ("branch_index", np.arange(nb_), {
            "long_name": "branch", "flag_values": np.arange(nb_, dtype=np.int8),
            "flag_meanings": " ".join(names)}),
                "multiplier": np.arange(1, len(mu) + 1), "component_index": axes,
                "crossing": np.arange(len(cross))},
        attrs=provenance_attrs(params, solver, analysis="manifolds", k=k, map_periods=q,
                               stable_method=stable_method, axes=" ".join(axes),
                               **{f"status_{nm}": s for nm, s in zip(names, statuses)},
                               n_crossings=len(cross), **settings),
    )
    ds.update(component_variables(m, ("point",), U, what=" on the manifold"))
    ds.update(component_variables(m, (), np.asarray(zs), prefix="saddle_",
                                  what=" of the saddle's section point"))
    ds.update(component_variables(m, ("branch_index",), E, prefix="end_",
                                  what=" where the branch converged onto an attractor (else NaN)"))
    ds.update(component_variables(m, ("crossing",), cp, prefix="crossing_",
                                  what=" of a homoclinic point"))
    return apply_state_units(ds, m)


# ---- the first homoclinic tangency along a parameter -------------------------------------------
def homoclinic_tangency(params, orbit, param: str, bounds, *, tol: float = 1e-4,
                        progress=None, **manifold_kw) -> xr.Dataset:
    """The first homoclinic tangency of the saddle ``orbit`` (a converged
    :func:`nonsmooth.periodic_orbit` of ``params``) along ``param`` in ``bounds`` = (a, b):
    the value where its stable and unstable manifolds (as :func:`manifolds` computes them with
    ``manifold_kw``: the window, lengths and spacing decide which parts of the branches count)
    first touch, located by bisection to ``tol`` between a value without crossings (a) and one
    with them (b). The saddle is followed from ``params`` by Newton shooting
    (:func:`nonsmooth.periodic_orbit`, its method, k and tolerances) from the nearest value
    already done.

    Returns a Dataset: ``<param>`` (the midpoint of the final bracket), ``<param>_below``
    and ``<param>_above`` (the bracket: without and with crossings), over ``evaluation`` the
    values tried with their crossing counts (``value``, ``n_crossings``), and the manifolds
    at the bracket's upper end as ``crossing_X``, ``crossing_V``, ``crossing_angle``; attrs
    ``status``. A one-line ParameterError where ``a`` already has crossings or ``b`` none.
    ``progress`` (None or False: silent; True: a progress bar; or a callable
    ``progress(done, total)``): manifold computations done, of the two ends and the
    bisection's steps."""
    from .stability import periodic_orbit
    params = check_params(params)
    name = params.model.param(param).name
    try:
        a, b = (float(x) for x in bounds)
    except (TypeError, ValueError):
        raise ParameterError(f"bounds: expected (a, b), got {bounds!r}") from None
    if not (math.isfinite(a) and math.isfinite(b) and a != b):
        raise ParameterError(f"bounds: expected two different finite values, got {bounds!r}")
    tol = check_positive("tol", tol)
    import inspect
    known = set(inspect.signature(manifolds).parameters) - {"params", "orbit", "stable",
                                                             "progress"}
    for key in manifold_kw:
        if key not in known:
            raise ParameterError(f"{key}: not an option of manifolds here (known: "
                                 f"{', '.join(sorted(known))})")
    act = _saddle(params, orbit)[5]  # checks the orbit
    if int(act.sum()) != 2:
        raise ParameterError(f"orbit: the first homoclinic tangency is sought for a "
                             f"two-dimensional section; this one has {int(act.sum())} "
                             f"coordinates")
    done = {float(getattr(params, name)): orbit}
    kw = dict(k=int(orbit.attrs.get("k", 1)), method=str(orbit.attrs.get("method", "exact")),
              rtol=float(orbit.attrs.get("rtol", 1e-10)), atol=float(orbit.attrs.get("atol",
                                                                                     1e-12)),
              section_phase=float(orbit.attrs.get("section_phase", 0.0)))
    evals = []
    from ..sweep import progress_callback
    progress = progress_callback(progress, "homoclinic tangency")
    steps = 2 + max(0, math.ceil(math.log2(abs(b - a) / tol)))  # the ends, the bisection

    def saddle(value, depth=0):
        """The saddle at ``value``: Newton from the line through the two nearest saddles
        done (or the nearest), or, where it fails, by way of the value halfway there."""
        near = sorted(done, key=lambda v: abs(v - value))[:2]
        u = [np.asarray(components(done[v], suffix="_section").values[0]) for v in near]
        guess = (u[0] if len(near) < 2 else
                 u[0] + (u[1] - u[0]) * (value - near[0]) / (near[1] - near[0]))
        pv = params.replace(**{name: value})
        got = periodic_orbit(pv, u0=guess, **kw)
        if int(got.attrs.get("converged", 0)) != 1:
            if depth >= 6:
                raise ParameterError(f"{name}: the saddle is lost at {name} = {value:g} "
                                     f"({got.attrs.get('status')})")
            saddle(0.5 * (value + near[0]), depth + 1)
            return saddle(value, depth + 1)
        done[value] = got
        return pv, got

    def crossings(value):
        pv, got = saddle(value)
        ds = manifolds(pv, got, **manifold_kw)
        if ds.attrs["section_coordinates"] != 2:
            raise ParameterError(f"{name}: at {name} = {value:g} the section has "
                                 f"{ds.attrs['section_coordinates']} coordinates (a memory "
                                 f"slot the map depends on): homoclinic points are sought "
                                 f"in two")
        evals.append((value, int(ds.sizes["crossing"])))
        if progress is not None:
            progress(len(evals), steps)
        short = [b for b in BRANCH_NAMES[:2] if ds.attrs[f"status_{b}"].startswith(
            ("iterates", "max_points", "integration failed"))]
        if not ds.sizes["crossing"] and short:  # no crossing found, but not a full search
            raise ParameterError(f"{name}: at {name} = {value:g} the unstable branch {short[0]} "
                                 f"stopped early ({ds.attrs[f'status_{short[0]}']}); give "
                                 f"more iterates or max_points")
        return ds

    lo_ds = crossings(a)
    if lo_ds.sizes["crossing"]:
        raise ParameterError(f"bounds: the manifolds already cross at {name} = {a:g}")
    hi_ds = crossings(b)
    if not hi_ds.sizes["crossing"]:
        raise ParameterError(f"bounds: the manifolds do not cross at {name} = {b:g}")
    while abs(b - a) > tol:
        mid = 0.5 * (a + b)
        ds = crossings(mid)
        if ds.sizes["crossing"]:
            b, hi_ds = mid, ds
        else:
            a = mid
    s = params.model.param(name)
    vals = np.array([e[0] for e in evals])
    out = xr.Dataset(
        {
            name: ((), 0.5 * (a + b), {"long_name": f"{name} at the first homoclinic tangency",
                                       "units": s.units}),
            f"{name}_below": ((), a, {"long_name": f"largest {name} tried without crossings",
                                      "units": s.units}),
            f"{name}_above": ((), b, {"long_name": f"smallest {name} tried with crossings",
                                      "units": s.units}),
            "value": ("evaluation", vals, {"long_name": f"{name} tried", "units": s.units}),
            "n_crossings": ("evaluation", np.array([e[1] for e in evals], np.int64), {
                "long_name": "homoclinic crossings found there"}),
            "crossing_X": ("crossing", hi_ds.crossing_X.values, hi_ds.crossing_X.attrs),
            "crossing_V": ("crossing", hi_ds.crossing_V.values, hi_ds.crossing_V.attrs),
            "crossing_angle": ("crossing", hi_ds.crossing_angle.values,
                               hi_ds.crossing_angle.attrs),
        },
        coords={"evaluation": np.arange(len(evals)),
                "crossing": np.arange(hi_ds.sizes["crossing"])},
        attrs=provenance_attrs(params, None, swept=(name,), analysis="homoclinic_tangency",
                               param=name, tol=tol, method=kw["method"], k=kw["k"],
                               status="located", **{f"manifolds_{k}": v for k, v in
                                                    hi_ds.attrs.items() if k in (
                                                        "spacing", "length", "delta")}),
    )
    return out
