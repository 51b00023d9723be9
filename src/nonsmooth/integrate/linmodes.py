"""Closed-form propagation of linear modes of any dimension and any stiffness (issue 23,
item 4): u' = A u + b + f_c cos(omega t) + f_s sin(omega t) with constant A, b, f_c, f_s
(free flight, gravity, several coupled degrees of freedom, a mass at rest on a stop, a stiff
compliant contact).

With the augmented state z = (u, 1, cos omega t, sin omega t) the mode is z' = M z,

    M = [[A, b, f_c, f_s], [0, 0, 0, 0], [0, 0, 0, -omega], [0, 0, omega, 0]],

so z(s) = exp(M s) z(0): the matrix exponential with its integral for the forcing, whatever
A (singular or not, resonant or not). On a piece of length L with rho L <= THETA_POLY
(rho: the balanced norm of M, ``lin_matrix``) the exponential series converges fast:
z(s) = sum_j w_j s^j with w_j = M^j z0 / j!, and N_TAYLOR = 28 terms leave a remainder below
1.1 * 3^29 / 29! ~ 9e-18 of the scale of the state (a twentieth of its last bit; the largest
term, 3^3 / 3! = 4.5, sets the round-off of the sum). The state is then a polynomial in s
known to round-off, and so is every affine guard: g(s) = sum_j (G_k . w_j) s^j (a guard row
is a row over z). Its derivative bounds follow from the coefficients (``poly_m4``), so the
exit test is certified (``hybrid._guard_exit``). A full piece (length L) ends at u(L) = E z0,
E = exp(M L)'s state rows computed once per mode and call (``series_propagator``; its left
block is the tangent's exp(A L)), and its Taylor terms are computed only for the rows that
its guards and the extrema of X read (``taylor_terms``' ``need``); a piece cut short by an
event, retaken, or ending an output interval takes every row and sums them at its length.

A model declares such a mode through ``linear(mode, p, out) -> 2`` with ``out[0:n*n]`` = A
(row-major), then b, f_c, f_s (n each); see ``models.base``.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np


THETA_POLY = 3.0  # rho L on a full piece
N_TAYLOR = 28  # terms beyond the constant one (a multiple of 4: ``pval``)
POLY_DEPTH = 30  # halvings of a piece in its exit test (<= hybrid.SCAN_DEPTH: its stack)
X_SAMPLES = 4  # samples of V per piece for the extrema of X
_HERMITE_TOL = 1e-9  # the first guess of ``poly_root``: fraction of its bracket
#: ``poly_root`` starts from the Taylor cubic's root when that lies in this first fraction of
#: the piece (rho s <= 0.75 on a full piece, where the terms past the cubic are small: on a
#: ball's bounce the guess is then within about 1 % and Newton needs 2-3 evaluations)
_TAYLOR_GUESS = 0.25


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
def series_powers(m, PW):
    """PW[:, j] = M^j / j! (j = 0..N_TAYLOR; entry (i, q) of each m x m matrix in row
    PW[i m + q], so that a row holds one entry's N_TAYLOR + 1 terms, contiguous) from
    PW[:, 1] = M (``lin_matrix`` writes it there): the series' matrices of a mode, computed once
    per mode and call (``taylor_terms`` then costs one product with z0 per term, independent
    of each other, instead of a chain of N_TAYLOR products each waiting for the last)."""
    mm = m * m
    for i in range(mm):
        PW[i, 0] = 0.0
    for i in range(m):
        PW[i * m + i, 0] = 1.0
    for j in range(2, N_TAYLOR + 1):
        inv = 1.0 / j
        for i in range(m):
            for q in range(m):
                acc = 0.0
                for r in range(m):
                    acc += PW[i * m + r, 1] * PW[r * m + q, j - 1]
                PW[i * m + q, j] = acc * inv


@nb.njit(cache=True, fastmath={"contract"})
def taylor_terms(PW, n, u, C, S, TW, need):
    """TW[:, j] = M^j z0 / j! (j = 0..N_TAYLOR) for z0 = (u, 1, C, S), from the matrices
    PW[:, j] = M^j / j! (``series_powers``): TW[i] holds component i's N_TAYLOR + 1 terms,
    for the rows i of z with ``need[i]`` != 0 (n + 3 flags; the constant's row is always
    written, the forcing pair's with need[n + 1]; the others are not written: a piece whose
    end comes from ``series_propagator`` needs only the rows its guards and the extrema of X
    read; each row is computed the same way whichever others are).
    Four terms at a time, each summed in registers over the row (forcing columns first, then
    the state's), on contiguous rows of PW; the sums read u, C and S, not TW[:, 0], which may
    alias them. The augmented rows are known in form: the constant's is 0 beyond j = 0 (M's
    row n is zero) and the forcing pair rotates, (C, S) -> (-om S, om C) / j, two terms of PW
    each."""
    m = n + 3
    for i in range(n):
        TW[i, 0] = u[i]
    TW[n, 0] = 1.0
    TW[n + 1, 0] = C
    TW[n + 2, 0] = S
    for i in range(n):
        if need[i] == 0.0:
            continue
        r = i * m
        t = TW[i]
        a = PW[r + n]
        b = PW[r + n + 1]
        c = PW[r + n + 2]
        for j in range(1, N_TAYLOR + 1, 4):  # (N_TAYLOR: a multiple of 4)
            s0 = a[j] + b[j] * C + c[j] * S
            s1 = a[j + 1] + b[j + 1] * C + c[j + 1] * S
            s2 = a[j + 2] + b[j + 2] * C + c[j + 2] * S
            s3 = a[j + 3] + b[j + 3] * C + c[j + 3] * S
            for q in range(n):
                w = PW[r + q]
                uq = u[q]
                s0 += w[j] * uq
                s1 += w[j + 1] * uq
                s2 += w[j + 2] * uq
                s3 += w[j + 3] * uq
            t[j] = s0
            t[j + 1] = s1
            t[j + 2] = s2
            t[j + 3] = s3
    rc = (n + 1) * m
    rs = (n + 2) * m
    for j in range(1, N_TAYLOR + 1):
        TW[n, j] = 0.0
    if need[n + 1] == 0.0:
        return
    for j in range(1, N_TAYLOR + 1):
        TW[n + 1, j] = PW[rc + n + 1, j] * C + PW[rc + n + 2, j] * S
        TW[n + 2, j] = PW[rs + n + 1, j] * C + PW[rs + n + 2, j] * S


@nb.njit(cache=True, inline="always", fastmath={"contract"})
def pval(c, s):
    """(p(s), p'(s)) of the polynomial c of degree N_TAYLOR (any 1-d array, also a column of
    TW): Horner in s^4 over the four residues of the exponent mod 4, four independent chains of
    N_TAYLOR / 4 steps instead of one of N_TAYLOR (evaluation is latency-bound), and four more
    for p' = sum_i (i + 1) c[i + 1] s^i."""
    s2 = s * s
    s4 = s2 * s2
    a0 = c[N_TAYLOR]
    a1 = 0.0
    a2 = 0.0
    a3 = 0.0
    d0 = 0.0
    d1 = 0.0
    d2 = 0.0
    d3 = 0.0
    for k in range(N_TAYLOR // 4 - 1, -1, -1):
        b = 4 * k
        a0 = a0 * s4 + c[b]
        a1 = a1 * s4 + c[b + 1]
        a2 = a2 * s4 + c[b + 2]
        a3 = a3 * s4 + c[b + 3]
        d0 = d0 * s4 + (b + 1) * c[b + 1]
        d1 = d1 * s4 + (b + 2) * c[b + 2]
        d2 = d2 * s4 + (b + 3) * c[b + 3]
        d3 = d3 * s4 + (b + 4) * c[b + 4]
    return (a0 + s * a1) + s2 * (a2 + s * a3), (d0 + s * d1) + s2 * (d2 + s * d3)


@nb.njit(cache=True, inline="always", fastmath={"contract"})
def pval7(c, s):
    """``pval`` of a polynomial of degree 7 at most (c[0:8]: a DOP853 step's dense output,
    ``rk8.rk8_dense``): Horner in s^2 over the two parities of the exponent."""
    s2 = s * s
    a0 = ((c[6] * s2 + c[4]) * s2 + c[2]) * s2 + c[0]
    a1 = ((c[7] * s2 + c[5]) * s2 + c[3]) * s2 + c[1]
    d0 = (7.0 * c[7] * s2 + 5.0 * c[5]) * s2 + 3.0 * c[3]
    d1 = (6.0 * c[6] * s2 + 4.0 * c[4]) * s2 + 2.0 * c[2]
    return a0 + s * a1, (d0 * s2 + c[1]) + s * d1


@nb.njit(cache=True, inline="always", fastmath={"contract"})
def pvalue(c, s):
    """p(s) alone (``pval``, inlined: the derivative's chains are dead code there)."""
    return pval(c, s)[0]


@nb.njit(cache=True, inline="always")
def poly_state(TW, n, s, out):
    """out[0:n] = u(s) (``pvalue`` of each component's Taylor terms)."""
    for i in range(n):
        out[i] = pvalue(TW[i], s)


@nb.njit(cache=True, inline="always")
def poly_component(TW, i, s):
    """(value, derivative) at s of component i of z."""
    return pval(TW[i], s)


@nb.njit(cache=True)
def guard_poly(G, k, n, TW, c):
    """c[j] = G[k] . TW[:, j]: the guard as a polynomial in s on the piece (each term summed
    over the components in order; a zero coefficient of the row adds nothing)."""
    for j in range(N_TAYLOR + 1):
        c[j] = 0.0
    for i in range(n + 3):
        g = G[k, i]
        if g != 0.0:
            t = TW[i]
            for j in range(N_TAYLOR + 1):
                c[j] += g * t[j]


@nb.njit(cache=True, inline="always")
def poly_m4(c, b):
    """Bound of |p''''| on [0, b] from the coefficients (plus the series' remainder, far
    below round-off on a piece)."""
    b2 = b * b
    b4 = b2 * b2
    # sum over j = 4..N_TAYLOR of |c_j| j (j-1) (j-2) (j-3) b^(j-4): Horner in b^4 over the
    # four residues of j mod 4 (as ``pval``)
    j = N_TAYLOR
    a0 = abs(c[j]) * (j * (j - 1) * (j - 2) * (j - 3))
    a1 = 0.0
    a2 = 0.0
    a3 = 0.0
    for k in range(N_TAYLOR // 4 - 2, -1, -1):
        j = 4 * k + 4
        a0 = a0 * b4 + abs(c[j]) * (j * (j - 1) * (j - 2) * (j - 3))
        a1 = a1 * b4 + abs(c[j + 1]) * ((j + 1) * j * (j - 1) * (j - 2))
        a2 = a2 * b4 + abs(c[j + 2]) * ((j + 2) * (j + 1) * j * (j - 1))
        a3 = a3 * b4 + abs(c[j + 3]) * ((j + 3) * (j + 2) * (j + 1) * j)
    return (a0 + b * a1) + b2 * (a2 + b * a3)


@nb.njit(cache=True)
def poly_x_extrema(TW, hs, xmax, xmin, cv, rho):
    """(xmax, xmin) with the interior extrema of X = z[0] on the piece [0, hs]: where
    V = z[0]' changes sign between sample points at most THETA_POLY / X_SAMPLES of the fastest
    rate ``rho`` apart (X_SAMPLES on a full piece, which spans THETA_POLY = 3 of it, so V's
    sign changes about pi apart: at most one is expected between two samples; fewer on a
    shorter piece, one interval on a piece cut short by an event), located by ``poly_root`` on
    V (``cv``: work, N_TAYLOR + 1; the kernel lends it the guard's polynomial ``cp``, rebuilt
    before every use)."""
    ns = min(X_SAMPLES, max(1, int(math.ceil(X_SAMPLES * rho * hs / THETA_POLY - 1e-9))))
    va = TW[0, 1]  # V at 0 (= poly_component(TW, 0, 0.0)[1], bit for bit)
    for q in range(1, ns + 1):  # V at ns points: each sign change an extremum
        vb = poly_component(TW, 0, q * hs / ns)[1]
        if va * vb < 0.0:
            sg = 1.0 if va >= 0.0 else -1.0  # g = sg V >= 0 at the lower end
            for j in range(N_TAYLOR):
                cv[j] = sg * (j + 1) * TW[0, j + 1]
            cv[N_TAYLOR] = 0.0
            lo, hi = poly_root(cv, hs, (q - 1) / ns, q / ns, sg * va, sg * vb, 1e-15)
            x = poly_component(TW, 0, 0.5 * (lo + hi) * hs)[0]
            xmax = max(xmax, x)
            xmin = min(xmin, x)
        va = vb
    return xmax, xmin


@nb.njit(cache=True, fastmath={"contract", "reassoc"})
def series_propagator(PW, n, h, E):
    """E[i, q] = exp(M h)[i, q] for the state rows i < n and every column q < n + 3 of the
    augmented matrix (``pvalue`` per entry on its row of PW, as ``poly_tangent``): the state
    at the end of a piece of length h is then u(h) = E z0, z0 = (u, 1, C, S), and E[:, :n] is
    the tangent's exp(A h) (bit for bit: the same sums under the same flags). Computed once
    per mode and call for the full piece."""
    m = n + 3
    for a in range(n):
        for b in range(m):
            E[a, b] = pvalue(PW[a * m + b], h)


@nb.njit(cache=True, inline="always")
def propagate_state(E, n, u, C, S, out):
    """out[0:n] = E z0 with z0 = (u, 1, C, S) (``series_propagator``'s E: a full piece)."""
    for a in range(n):
        acc = E[a, n] + E[a, n + 1] * C + E[a, n + 2] * S
        for b in range(n):
            acc += E[a, b] * u[b]
        out[a] = acc


@nb.njit(cache=True, fastmath={"contract", "reassoc"})
def poly_tangent(PW, n, h, Y, E, t, ready):
    """Y[0:n] <- exp(A h) Y[0:n] (the homogeneous part; memory rows unchanged): E = exp(A h) =
    sum_j h^j PW[:, j][:n, :n] (the top-left block of M^j / j! is A^j / j!; ``pvalue`` per
    entry, on its row of PW), then each column multiplied by it; E (n x n or wider) and t (n):
    work arrays. With ``ready`` E already holds exp(A h) (``series_propagator``'s, a full
    piece: the same values)."""
    m = n + 3
    if not ready:
        for a in range(n):
            for b in range(n):
                E[a, b] = pvalue(PW[a * m + b], h)
    for col in range(Y.shape[1]):
        for a in range(n):
            acc = 0.0
            for b in range(n):
                acc += E[a, b] * Y[b, col]
            t[a] = acc
        for a in range(n):
            Y[a, col] = t[a]


@nb.njit(cache=True, inline="always")
def _taylor_guess(a, b, c, d):
    """The smallest positive root of the cubic a + b s + c s^2 + d s^3 (a >= 0) near 0: the
    quadratic's smallest positive root (stable form), then one Newton step on the cubic; 0.0
    when the quadratic has none."""
    if a == 0.0:  # on the surface: the root of p(s) / s, if p moves in (b > 0)
        s = -b / c if b > 0.0 and c != 0.0 else 0.0
    elif c == 0.0:
        s = -a / b if b != 0.0 else 0.0
    else:
        disc = b * b - 4.0 * a * c
        if disc < 0.0:
            return 0.0
        q = -0.5 * (b + math.copysign(math.sqrt(disc), b))
        r1 = q / c
        r2 = a / q if q != 0.0 else 0.0
        if r1 > 0.0 and r2 > 0.0:
            s = min(r1, r2)
        else:
            s = max(r1, r2)
    if not s > 0.0:
        return 0.0
    dp = b + s * (2.0 * c + 3.0 * s * d)
    if dp != 0.0:
        s -= (a + s * (b + s * (c + s * d))) / dp
    return s


@nb.njit(cache=True)
def poly_root(c, hs, lo, hi, glo, ghi, tol):
    """The bracket [lo, hi] (fractions of the piece of length hs; p(lo hs) = glo >= 0 >
    ghi = p(hi hs)) of a root of the polynomial c, shrunk to ``tol``. Newton on p (its
    derivative comes with its value), started at the root of the cubic Hermite of (p, p') at
    the bracket's ends (to ``_HERMITE_TOL`` of the bracket: a first guess, which the Newton
    steps on p refine; with p(lo) = 0, as after a reset onto the guard's surface, the root of
    H(u) / u, so that the Hermite's root at the bracket's start does not attract it) and kept
    inside the bracket; a step that leaves it or does not halve the previous one is replaced by
    the bracket's midpoint. Converged, an iterate steps tol / 2 past the root so that the
    bracket closes from both sides. Returns (lo, hi).

    A bracket that starts at the piece's start (lo = 0) with a root in its first
    ``_TAYLOR_GUESS`` of the piece (a short flight, a bounce of a chattering sequence) starts
    Newton from the root of p's own Taylor cubic at 0 instead (``_taylor_guess``): the
    Hermite over the whole bracket would guess a root at a small fraction of it poorly."""
    if lo == 0.0:
        x = _taylor_guess(glo, c[1], c[2], c[3]) / hs
        if 0.0 < x < min(hi, _TAYLOR_GUESS):
            return _newton_root(c, hs, lo, hi, x, tol)
    L = (hi - lo) * hs
    dlo = pval(c, lo * hs)[1] * L
    dhi = pval(c, hi * hs)[1] * L
    # the Hermite H(u) = glo + a1 u + a2 u^2 + a3 u^3 on [0, 1]: its root in the bracket
    dg = ghi - glo
    a1 = dlo
    a2 = 3.0 * dg - 2.0 * dlo - dhi
    a3 = -2.0 * dg + dlo + dhi
    ul = 0.0
    uh = 1.0
    defl = glo == 0.0 and a1 > 0.0  # H(0) = 0, moving in: the root of H(u) / u
    u = a1 / (a1 - ghi) if defl else glo / (glo - ghi)
    for _ in range(60):
        if defl:
            h = a1 + u * (a2 + u * a3)
            hp = a2 + 2.0 * u * a3
        else:
            h = glo + u * (a1 + u * (a2 + u * a3))
            hp = a1 + u * (2.0 * a2 + 3.0 * u * a3)
        if h < 0.0:
            uh = u
        else:
            ul = u
        un = u - h / hp if hp != 0.0 else -1.0
        if not ul < un < uh:
            un = 0.5 * (ul + uh)
        done = abs(un - u) <= _HERMITE_TOL
        u = un
        if done or uh - ul <= _HERMITE_TOL:
            break
    x = lo + u * (hi - lo)
    if not lo < x < hi:
        x = 0.5 * (lo + hi)
    return _newton_root(c, hs, lo, hi, x, tol)


@nb.njit(cache=True, inline="always")
def _newton_root(c, hs, lo, hi, x, tol):
    """``poly_root``'s Newton iteration from the first guess x inside (lo, hi)."""
    dx_old = math.inf
    for _ in range(200):
        g, d = pval(c, x * hs)
        if g < 0.0:
            hi = x
        else:
            lo = x
        if hi - lo <= tol:
            break
        dh = d * hs
        dx = -g / dh if dh != 0.0 else math.inf
        past = abs(dx) < 0.25 * tol
        if past:  # converged: step past the root, to close the bracket
            dx = 0.5 * tol if dx >= 0.0 else -0.5 * tol
        xn = x + dx
        if not (lo < xn < hi and (past or abs(dx) <= 0.5 * dx_old)):
            xn = 0.5 * (lo + hi)
            dx = xn - x
        dx_old = abs(dx)
        x = xn
    return lo, hi
