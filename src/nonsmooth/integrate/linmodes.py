"""Closed-form propagation of linear modes of any dimension and any stiffness (issue 23,
item 4): u' = A u + b + f_c cos(omega t) + f_s sin(omega t) with constant A, b, f_c, f_s
(free flight, gravity, several coupled degrees of freedom, a mass at rest on a stop, a stiff
compliant contact).

With the augmented state z = (u, 1, cos omega t, sin omega t) the mode is z' = M z,

    M = [[A, b, f_c, f_s], [0, 0, 0, 0], [0, 0, 0, -omega], [0, 0, omega, 0]],

so z(s) = exp(M s) z(0): the matrix exponential with its integral for the forcing, whatever
A (singular or not, resonant or not). On a piece of length L with rho L <= THETA_POLY
(rho: the balanced norm of M, ``lin_matrix``) the exponential series converges fast: z(s) = sum_j w_j s^j with
w_j = M^j z0 / j!, and N_TAYLOR = 28 terms leave a remainder below 2^29 / 29! ~ 6e-23 of
the scale of the state. The state is then a polynomial in s known to round-off, and so is
every affine guard: g(s) = sum_j (G_k . w_j) s^j (a guard row is a row over z). Its derivative
bounds follow from the coefficients, so the exit test is certified (``poly_first_negative``).

A model declares such a mode through ``linear(mode, p, out) -> 2`` with ``out[0:n*n]`` = A
(row-major), then b, f_c, f_s (n each); see ``models.base``.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from .pwlinear import herm_coeffs
from .roots import illinois_point, illinois_update, quad_roots01

THETA_POLY = 2.0  # rho L on a full piece
N_TAYLOR = 28  # terms beyond the constant one
POLY_DEPTH = 30  # halvings of a piece in its exit test (<= hybrid.SCAN_DEPTH: its stack)
X_SAMPLES = 4  # samples of V per piece for the extrema of X


@nb.njit(cache=True)
def lin_matrix(lin, n, om, Mx):
    """Fill the (n+3) x (n+3) matrix M (row-major in the flat ``Mx``) from a general-form
    ``linear`` row; returns its rate rho = ||D^-1 M D||_inf with D the diagonal that balances
    M (Osborne's iteration in powers of 2): about the fastest rate of the mode, e.g.
    sqrt(k) + c for a stiff spring k where ||M||_inf = k + c would cut the pieces sqrt(k)
    times too short. The series itself is taken on z unscaled (the same terms)."""
    m = n + 3
    for i in range(m * m):
        Mx[i] = 0.0
    for i in range(n):
        for j in range(n):
            Mx[i * m + j] = lin[i * n + j]
        Mx[i * m + n] = lin[n * n + i]
        Mx[i * m + n + 1] = lin[n * n + n + i]
        Mx[i * m + n + 2] = lin[n * n + 2 * n + i]
    Mx[(n + 1) * m + n + 2] = -om
    Mx[(n + 2) * m + n + 1] = om
    D = np.ones(m)
    for _ in range(40):
        done = True
        for i in range(m):
            c = 0.0
            r = 0.0
            for j in range(m):
                if j != i:
                    c += abs(Mx[j * m + i]) * D[i] / D[j]
                    r += abs(Mx[i * m + j]) * D[j] / D[i]
            if c == 0.0 or r == 0.0:
                continue
            f = 2.0 ** round(0.5 * math.log2(r / c))
            if c * f + r / f < 0.95 * (c + r):
                D[i] *= f
                done = False
        if done:
            break
    rho = om
    for i in range(m):
        r = 0.0
        for j in range(m):
            r += abs(Mx[i * m + j]) * D[j] / D[i]
        rho = max(rho, r)
    return rho


@nb.njit(cache=True, fastmath={"contract", "reassoc"})
def taylor_terms(Mx, n, u, C, S, TW):
    """TW[j] = M^j z0 / j! (j = 0..N_TAYLOR) for z0 = (u, 1, C, S)."""
    m = n + 3
    for i in range(n):
        TW[0, i] = u[i]
    TW[0, n] = 1.0
    TW[0, n + 1] = C
    TW[0, n + 2] = S
    for j in range(1, N_TAYLOR + 1):
        inv = 1.0 / j
        for i in range(m):
            acc = 0.0
            for q in range(m):
                acc += Mx[i * m + q] * TW[j - 1, q]
            TW[j, i] = acc * inv


@nb.njit(cache=True, inline="always")
def poly_state(TW, n, s, out):
    """out[0:n] = u(s) (Horner over the Taylor terms)."""
    for i in range(n):
        acc = TW[N_TAYLOR, i]
        for j in range(N_TAYLOR - 1, -1, -1):
            acc = acc * s + TW[j, i]
        out[i] = acc


@nb.njit(cache=True, inline="always")
def poly_component(TW, i, s):
    """(value, derivative) at s of component i of z."""
    v = TW[N_TAYLOR, i]
    d = N_TAYLOR * TW[N_TAYLOR, i]
    for j in range(N_TAYLOR - 1, 0, -1):
        v = v * s + TW[j, i]
        d = d * s + j * TW[j, i]
    return v * s + TW[0, i], d


@nb.njit(cache=True)
def guard_poly(G, k, n, TW, c):
    """c[j] = G[k] . TW[j]: the guard as a polynomial in s on the piece."""
    m = n + 3
    for j in range(N_TAYLOR + 1):
        acc = 0.0
        for i in range(m):
            acc += G[k, i] * TW[j, i]
        c[j] = acc


@nb.njit(cache=True, inline="always")
def _pval(c, s):
    """(p(s), p'(s)) of the polynomial c."""
    v = c[N_TAYLOR]
    d = N_TAYLOR * c[N_TAYLOR]
    for j in range(N_TAYLOR - 1, 0, -1):
        v = v * s + c[j]
        d = d * s + j * c[j]
    return v * s + c[0], d


@nb.njit(cache=True, inline="always")
def _m4(c, b):
    """Bound of |p''''| on [0, b] from the coefficients (plus the series' remainder, far
    below round-off on a piece)."""
    acc = 0.0
    for j in range(N_TAYLOR, 3, -1):  # Horner in b
        acc = acc * b + abs(c[j]) * (j * (j - 1) * (j - 2) * (j - 3))
    return acc


@nb.njit(cache=True)
def _clear(ga, da, gb, db, L, M4):
    """g >= 0 on the piece is certified: the cubic Hermite of (g, g') less its pointwise
    error bound has nonnegative Bernstein coefficients (as ``hybrid._herm_clear``)."""
    b1, b2, b3 = herm_coeffs(ga, da, gb, db, L)
    e = M4 * (L * L) * (L * L) / 24.0
    a2 = b2 - e
    a3 = b3 + 2.0 * e
    return (ga >= 0.0 and gb >= 0.0 and ga + 0.25 * b1 >= 0.0
            and ga + 0.5 * b1 + a2 / 6.0 >= 0.0
            and ga + 0.75 * b1 + 0.5 * a2 + 0.25 * a3 >= 0.0)


@nb.njit(cache=True)
def _poly_scan(c, end, s_best, stack):
    """The first piece of [0, end] (left to right) that holds a negative value of the
    polynomial ``c``: (a, b, g(b)) with g(a) >= 0 > g(b), or (-1, -1, 0) when g >= 0 is
    certified up to min(end, s_best). A piece passes when its Hermite of (g, g') less the
    coefficients' bound of the fourth derivative clears zero; else it is halved (at most
    POLY_DEPTH times); on a piece whose end is negative the Hermite's interior minima are
    tried first."""
    ga, da = _pval(c, 0.0)
    ga = max(ga, 0.0)  # round-off after the switch into this mode
    gb, db = _pval(c, end)
    M4 = _m4(c, end)
    a = 0.0
    b = end
    depth = 0
    top = 0
    while True:
        if a >= s_best:
            return -1.0, -1.0, 0.0
        w = b - a
        if gb < 0.0:
            b1, b2, b3 = herm_coeffs(ga, da, gb, db, w)
            r1, r2 = quad_roots01(b1, 2.0 * b2, 3.0 * b3)
            for q in (min(r1, r2), max(r1, r2)):
                if 0.0 < q < 1.0 and 2.0 * b2 + 6.0 * b3 * q > 0.0:
                    gq, _ = _pval(c, a + q * w)
                    if gq < 0.0:
                        return a, a + q * w, gq
            return a, b, gb
        if not _clear(ga, da, gb, db, w, M4 if depth == 0 else _m4(c, b)):
            if depth < POLY_DEPTH:
                stack[top, 0] = b
                stack[top, 1] = gb
                stack[top, 2] = db
                stack[top, 4] = depth + 1
                top += 1
                b = 0.5 * (a + b)
                gb, db = _pval(c, b)
                depth += 1
                continue
            gm, _ = _pval(c, 0.5 * (a + b))
            if gm < 0.0:
                return a, 0.5 * (a + b), gm
        if top == 0:
            return -1.0, -1.0, 0.0
        top -= 1
        a = b
        ga = gb
        da = db
        b = stack[top, 0]
        gb = stack[top, 1]
        db = stack[top, 2]
        depth = int(stack[top, 4])


@nb.njit(cache=True)
def poly_exit(c, L, s_best, stack, tol):
    """Exit test of a guard that is the polynomial ``c`` in s on a piece [0, L]: (lo, hi)
    bracketing its first crossing to ``tol`` (times, g(lo) >= 0 > g(hi)), (2L, 2L) when it
    stays >= 0 up to ``s_best`` (a time: an earlier crossing of another guard), (-1, -1)
    when location fails. The first negative piece (``_poly_scan``) is bracketed and the
    crossing located by Illinois; then [0, lo] is scanned again, so that a dip and a return
    before it are found too (the first crossing, as ``hybrid._first_crossing`` ensures for
    affine guards)."""
    ga, da = _pval(c, 0.0)
    gb, db = _pval(c, L)
    if _clear(max(ga, 0.0), da, gb, db, L, _m4(c, L)):
        return 2.0 * L, 2.0 * L
    lo, hi, ghi = _poly_scan(c, L, s_best, stack)
    if hi < 0.0:
        return 2.0 * L, 2.0 * L
    for _ in range(8):
        if lo >= s_best:
            return 2.0 * L, 2.0 * L
        glo = _pval(c, lo)[0] if lo > 0.0 else max(ga, 0.0)
        side = 0
        for _ in range(200):
            if hi - lo <= tol:
                break
            sm = illinois_point(lo, hi, glo, ghi)
            gm = _pval(c, sm)[0]
            lo, hi, glo, ghi, side = illinois_update(lo, hi, glo, ghi, side, sm, gm)
        if hi - lo > tol:
            return -1.0, -1.0
        if not lo > 0.0:
            break
        a2, b2, g2 = _poly_scan(c, lo, lo, stack)  # an earlier crossing inside [0, lo]?
        if b2 < 0.0:
            break
        lo, hi, ghi = a2, b2, g2
    return lo, hi


@nb.njit(cache=True)
def poly_x_extrema(TW, hs, xmax, xmin):
    """(xmax, xmin) with the interior extrema of X = z[0] on the piece [0, hs]: where
    V = z[0]' changes sign between X_SAMPLES + 1 points (a piece spans THETA_POLY = 2 of the
    fastest rate: at most one sign change is expected between two of them)."""
    va = poly_component(TW, 0, 0.0)[1]
    for q in range(1, X_SAMPLES + 1):  # V at X_SAMPLES points: each sign change an extremum
        a = (q - 1) * hs / X_SAMPLES
        b = q * hs / X_SAMPLES
        vb = poly_component(TW, 0, b)[1]
        if va * vb < 0.0:
            sg = 1.0 if va >= 0.0 else -1.0  # g = sg V >= 0 at the lower end
            lo, hi, glo, ghi = a, b, sg * va, sg * vb
            side = 0
            for _ in range(100):
                if hi - lo <= 1e-15 * hs:
                    break
                sm = illinois_point(lo, hi, glo, ghi)
                gm = sg * poly_component(TW, 0, sm)[1]
                lo, hi, glo, ghi, side = illinois_update(lo, hi, glo, ghi, side, sm, gm)
            x = poly_component(TW, 0, 0.5 * (lo + hi))[0]
            xmax = max(xmax, x)
            xmin = min(xmin, x)
        va = vb
    return xmax, xmin


@nb.njit(cache=True, fastmath={"contract", "reassoc"})
def poly_tangent(Mx, n, h, Y, t0, t1):
    """Y[0:n] <- exp(A h) Y[0:n] (the homogeneous part; memory rows unchanged) by the same
    series; t0, t1: work vectors of length n."""
    m = n + 3
    for col in range(Y.shape[1]):
        for i in range(n):
            t0[i] = Y[i, col]
        for j in range(1, N_TAYLOR + 1):
            f = h / j
            for i in range(n):
                acc = 0.0
                for q in range(n):
                    acc += Mx[i * m + q] * t0[q]
                t1[i] = acc * f
            for i in range(n):
                t0[i] = t1[i]
                Y[i, col] += t1[i]
