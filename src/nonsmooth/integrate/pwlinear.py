"""Closed-form modes and rigorous event location for piecewise-linear, harmonically forced
one-degree-of-freedom oscillators (building blocks of the exact event-driven kernels).

A **mode** is the linear equation

    X'' + c X' + k X = F0 cos(omega t) + Fs sin(omega t) + b,      k > 0, c >= 0,

whose solution is particular (constant b/k + harmonic P cos + Q sin) plus homogeneous
u = (y, z) = exp(A s) u0 with A = [[0, 1], [-k, -c]]; or free flight, k = c = 0
(``KIND_FREE``), where the pair (y, z) also carries the constant force: y = y0 + z0 s + b s^2/2.
The 2x2 exponential is written in closed form for the under-, critically and over-damped cases
(``eval_state``; exp(A s) = I + A s in free flight), so one evaluation costs
one ``exp`` and two small-angle (cos, sin) pairs (Taylor polynomials, no libm call, for angles
up to 0.5 rad). The coefficients of a mode are one row of a float64 array (``mode_coeffs``);
a model is a set of such rows plus its switching rules, so the same machinery serves any
piecewise-linear 1-DOF model (support, impact with compliance, backlash, ...).

An **event functional** is an affine function of the state, g = cx X + cv V + c0. On a piece
[0, L] of a mode, g is known exactly at both ends together with g' = cx V + cv X''. Whether g
can become >= 0 inside the piece is decided *rigorously* (``classify``):

* derivative bounds: in the energy norm ||u||_W = sqrt(k y^2 + z^2) the homogeneous flow is
  non-expansive (d/dt (k y^2 + z^2) = -2 c z^2 <= 0), so |d^n g_hom/dt^n| <= D_n ||u(0)||_W
  over the whole piece with D_n the dual norm of (cx, cv) A^n; the harmonic part contributes
  omega^n R exactly (``functional_bounds``);
* exclusion: max over the piece of the cubic Hermite interpolant of (g, g') plus its error
  bound L^4 M4 / 384 is < 0, or the second-order Taylor bound from either end is < 0;
* certified single crossing: g changes sign and g' > 0 on the whole piece (min of the Hermite
  derivative minus its error bound sqrt(3) L^3 M4 / 216, here taken as L^3 M4 / 60, or a
  Taylor bound on g'); the root is then unique and is refined by a safeguarded
  third-order Newton iteration on the exact closed form (``refine_root``).

Anything else is *undecided* and the caller halves the piece. A grazing (tangential) touch
therefore cannot be missed, and two crossings close together are separated by halving until
each piece is certified (or the piece is shorter than the time tolerance).
"""

from __future__ import annotations

import math

import numba as nb

from .roots import quad_roots01
from .trig import cos_sin_small

# ---- layout of a mode-coefficient row -------------------------------------------------------
MC_K = 0       # stiffness k (> 0)
MC_C = 1       # damping c (>= 0)
MC_B = 2       # constant forcing b
MC_XS = 3      # static offset b / k
MC_P = 4       # particular solution P cos(omega t) + Q sin(omega t)
MC_Q = 5
MC_A = 6       # -c / 2 (real part of the eigenvalues)
MC_KIND = 7    # KIND_UNDER / KIND_CRIT / KIND_OVER / KIND_FREE
MC_NU = 8      # damped frequency (under) or mu = sqrt(c^2/4 - k) (over)
MC_SQK = 9     # sqrt(k)
MC_LMAX = 10   # longest piece tried in this mode
MC_G = 11      # constant acceleration of a free mode (KIND_FREE: k = c = 0), else 0
MC_FS = 12     # amplitude F_s of a forcing term F_s sin(omega t) (0: cosine forcing only)
N_MC = 13

KIND_UNDER = 0
KIND_CRIT = 1
KIND_OVER = 2
KIND_FREE = 3  # k = c = 0: free flight under a constant force b (gravity) and the forcing

# ---- bound coefficients of a functional in a mode -------------------------------------------
BD_D2 = 0  # dual norm of (cx, cv) A^2
BD_D3 = 1  # dual norm of (cx, cv) A^3
BD_D4 = 2  # dual norm of (cx, cv) A^4
BD_R = 3   # amplitude of the harmonic part of g
N_BD = 4

HERM_ERR = 1.0 / 384.0   # max |g - H| <= HERM_ERR L^4 max|g''''|   (cubic Hermite)
HERM_DERR = 1.0 / 60.0   # max |g' - H'| <= sqrt(3)/216 L^3 max|g''''|, with a safety factor 2


@nb.njit(cache=True)
def mode_coeffs(k, c, b, F0, om, theta, out, Fs=0.0):
    """Fill ``out`` (length N_MC) for X'' + c X' + k X = F0 cos(om t) + Fs sin(om t) + b, with
    k > 0 and c >= 0, or k = c = 0 (KIND_FREE: free flight, X = b s^2 / 2 + V0 s + X0 plus the
    harmonic part; the constant force is then carried by the homogeneous pair (y, z), see
    ``apply_propagator``).

    ``theta``: longest piece = theta / max(sqrt(k), om) (radians of the fastest oscillation).
    Returns False for an undamped mode forced (F0, Fs != 0) exactly at resonance (no bounded
    particular solution; the exact kernels return a status for it).
    """
    d = k - om * om
    den = d * d + (c * om) ** 2
    if not den > 1e-300:
        if F0 != 0.0 or Fs != 0.0:
            return False
        den = 1.0  # unforced: no particular harmonic part, nothing resonates
    free = k == 0.0
    out[MC_K] = k
    out[MC_C] = c
    out[MC_B] = b
    out[MC_XS] = 0.0 if free else b / k
    out[MC_G] = b if free else 0.0
    out[MC_FS] = Fs
    if Fs == 0.0:
        out[MC_P] = F0 * d / den
        out[MC_Q] = F0 * c * om / den
    else:  # (d P + c om Q, d Q - c om P) = (F0, Fs)
        out[MC_P] = (F0 * d - Fs * c * om) / den
        out[MC_Q] = (F0 * c * om + Fs * d) / den
    a = -0.5 * c
    out[MC_A] = a
    disc = 0.25 * c * c - k
    if free:
        out[MC_KIND] = KIND_FREE
        out[MC_NU] = 0.0
    elif disc < 0.0:
        out[MC_KIND] = KIND_UNDER
        out[MC_NU] = math.sqrt(-disc)
    elif disc > 0.0:
        out[MC_KIND] = KIND_OVER
        out[MC_NU] = math.sqrt(disc)
    else:
        out[MC_KIND] = KIND_CRIT
        out[MC_NU] = 0.0
    sqk = math.sqrt(k)
    out[MC_SQK] = sqk
    fast = max(sqk, om, 0.5 * c)
    out[MC_LMAX] = theta / fast
    return True


@nb.njit(cache=True)
def functional_bounds(mc, om, cx, cv, out):
    """Fill ``out`` (length N_BD) with the derivative-bound coefficients of g = cx X + cv V + c0
    in mode ``mc``: |g^(n)| <= D_n sqrt(k y^2 + z^2) + om^n R over any piece (see module doc).
    A free mode (KIND_FREE): g_hom'' = cx b and its higher derivatives vanish, so D_n = 0
    and |cx b| / om^2 is added to R (om^2 R then bounds g'' too)."""
    if mc[MC_KIND] == KIND_FREE:
        out[BD_D2] = 0.0
        out[BD_D3] = 0.0
        out[BD_D4] = 0.0
        out[BD_R] = (math.hypot(cx * mc[MC_P] + cv * om * mc[MC_Q],
                                cx * mc[MC_Q] - cv * om * mc[MC_P])
                     + abs(cx * mc[MC_G]) / (om * om))
        return
    k = mc[MC_K]
    c = mc[MC_C]
    w1 = cx
    w2 = cv
    for n in range(1, 5):
        w1, w2 = -k * w2, w1 - c * w2  # (w1, w2) <- (w1, w2) A
        if n == 2:
            out[BD_D2] = math.sqrt(w1 * w1 / k + w2 * w2)
        elif n == 3:
            out[BD_D3] = math.sqrt(w1 * w1 / k + w2 * w2)
    out[BD_D4] = math.sqrt(w1 * w1 / k + w2 * w2)
    P = mc[MC_P]
    Q = mc[MC_Q]
    out[BD_R] = math.hypot(cx * P + cv * om * Q, cx * Q - cv * om * P)


@nb.njit(cache=True, inline="always")
def hom_part(MC, m, om, X, V, C, S):
    """Homogeneous part (y, z) of the state (X, V) at forcing phase (C, S) = (cos, sin)."""
    P = MC[m, MC_P]
    Q = MC[m, MC_Q]
    return X - MC[m, MC_XS] - P * C - Q * S, V - om * (Q * C - P * S)


@nb.njit(cache=True, inline="always")
def accel(MC, m, om, y, z, C, S):
    """X'' from the homogeneous part and the forcing phase."""
    if MC[m, MC_KIND] == KIND_FREE:  # (a branch of its own: the other kinds' arithmetic is
        return -om * om * (MC[m, MC_P] * C + MC[m, MC_Q] * S) + MC[m, MC_G]  # as it was)
    return -om * om * (MC[m, MC_P] * C + MC[m, MC_Q] * S) - MC[m, MC_K] * y - MC[m, MC_C] * z


@nb.njit(cache=True, inline="always")
def jerk(MC, m, om, F0, V, A, C, S):
    """X''' = -k V - c X'' - F0 om sin(om t) + Fs om cos(om t)."""
    if MC[m, MC_FS] != 0.0:
        return -MC[m, MC_K] * V - MC[m, MC_C] * A - F0 * om * S + MC[m, MC_FS] * om * C
    return -MC[m, MC_K] * V - MC[m, MC_C] * A - F0 * om * S


@nb.njit(cache=True, inline="always")
def propagator(MC, m, om, s):
    """(eC, eS, cw, sw) of a step s: exp(A s) = eC I + eS (A - a I) and (cos, sin)(om s)."""
    cw, sw = cos_sin_small(om * s)
    a = MC[m, MC_A]
    kind = MC[m, MC_KIND]
    if kind == KIND_UNDER:
        nu = MC[m, MC_NU]
        e = math.exp(a * s)
        cn, sn = cos_sin_small(nu * s)
        eC = e * cn
        eS = e * sn / nu
    elif kind == KIND_OVER:
        mu = MC[m, MC_NU]
        e1 = math.exp((a + mu) * s)
        eS = e1 * (-math.expm1(-2.0 * mu * s)) / (2.0 * mu)  # e^{as} sinh(mu s) / mu
        eC = e1 - mu * eS                                    # e^{as} cosh(mu s)
    elif kind == KIND_FREE:
        eC = 1.0
        eS = s
    else:
        e = math.exp(a * s)
        eC = e
        eS = e * s
    return eC, eS, cw, sw


@nb.njit(cache=True)
def propagator_table(MC, m, om, n_levels, out):
    """``out[l] = propagator(MC, m, om, MC[m, MC_LMAX] / 2**l)`` for l < n_levels: the lengths
    of the halving / doubling search, so that most pieces cost no transcendental function."""
    Lm = MC[m, MC_LMAX]
    for lev in range(n_levels):
        eC, eS, cw, sw = propagator(MC, m, om, Lm * 0.5 ** lev)
        out[lev, 0] = eC
        out[lev, 1] = eS
        out[lev, 2] = cw
        out[lev, 3] = sw


@nb.njit(cache=True, inline="always")
def _apply_free(MC, m, om, y0, z0, C0, S0, s, cw, sw):
    """``apply_propagator`` of a free mode (KIND_FREE, k = c = 0) over s: the pair (y, z)
    carries the constant force b, y = y0 + z0 s + b s^2 / 2 and z = z0 + b s."""
    C = C0 * cw - S0 * sw
    S = S0 * cw + C0 * sw
    b = MC[m, MC_G]
    y = y0 + s * (z0 + 0.5 * b * s)
    z = z0 + b * s
    P = MC[m, MC_P]
    Q = MC[m, MC_Q]
    hp = P * C + Q * S
    return hp + y, om * (Q * C - P * S) + z, b - om * om * hp, y, z, C, S


@nb.njit(cache=True, inline="always")
def apply_propagator(MC, m, om, y0, z0, C0, S0, eC, eS, cw, sw):
    """State after a step with a precomputed propagator: (X, V, A, y, z, C, S)."""
    if MC[m, MC_KIND] == KIND_FREE:  # (a branch of its own: the other kinds' arithmetic is
        return _apply_free(MC, m, om, y0, z0, C0, S0, eS, cw, sw)  # as it was)
    C = C0 * cw - S0 * sw
    S = S0 * cw + C0 * sw
    a = MC[m, MC_A]
    k = MC[m, MC_K]
    y = (eC - a * eS) * y0 + eS * z0
    z = -k * eS * y0 + (eC + a * eS) * z0
    P = MC[m, MC_P]
    Q = MC[m, MC_Q]
    hp = P * C + Q * S
    X = MC[m, MC_XS] + hp + y
    V = om * (Q * C - P * S) + z
    A = -om * om * hp - k * y - MC[m, MC_C] * z
    return X, V, A, y, z, C, S


@nb.njit(cache=True, inline="always")
def eval_state(MC, m, om, y0, z0, C0, S0, s):
    """State s after a point with homogeneous part (y0, z0) and phase (C0, S0), in mode ``m`` (row m of the mode table MC).

    Returns (X, V, A, y, z, C, S) with A = X'' and (C, S) the forcing phase at the new time.
    """
    eC, eS, cw, sw = propagator(MC, m, om, s)
    return apply_propagator(MC, m, om, y0, z0, C0, S0, eC, eS, cw, sw)


@nb.njit(cache=True, inline="always")
def energy_norm(MC, m, y, z):
    return math.sqrt(MC[m, MC_K] * y * y + z * z)


@nb.njit(cache=True, inline="always")
def deriv_bound(BD, m, f, om, En):
    """(M2, M3, M4): bounds of |g''|, |g'''|, |g''''| for functional f in mode m (table BD of
    ``functional_bounds`` rows) over a piece whose start has energy norm En."""
    om2 = om * om
    R = BD[m, f, BD_R]
    return (BD[m, f, BD_D2] * En + om2 * R, BD[m, f, BD_D3] * En + om2 * om * R,
            BD[m, f, BD_D4] * En + om2 * om2 * R)


@nb.njit(cache=True, inline="always")
def cubic_max(c0, c1, c2, c3, L):
    """Max over [0, L] of c0 + c1 s + c2 s^2 + c3 s^3."""
    best = max(c0, c0 + L * (c1 + L * (c2 + L * c3)))
    qa = 3.0 * c3
    qb = 2.0 * c2
    if qa == 0.0:
        if qb != 0.0:
            u = -c1 / qb
            if 0.0 < u < L:
                best = max(best, c0 + u * (c1 + u * (c2 + u * c3)))
        return best
    disc = qb * qb - 4.0 * qa * c1
    if disc >= 0.0:
        sq = math.sqrt(disc)
        u = (-qb - sq) / (2.0 * qa)
        if 0.0 < u < L:
            best = max(best, c0 + u * (c1 + u * (c2 + u * c3)))
        u = (-qb + sq) / (2.0 * qa)
        if 0.0 < u < L:
            best = max(best, c0 + u * (c1 + u * (c2 + u * c3)))
    return best


@nb.njit(cache=True, inline="always")
def herm_coeffs(g0, d0, g1, d1, L):
    """Cubic Hermite in u = s / L: H = g0 + a1 u + a2 u^2 + a3 u^3."""
    dg = g1 - g0
    a1 = L * d0
    a2 = 3.0 * dg - 2.0 * L * d0 - L * d1
    a3 = -2.0 * dg + L * d0 + L * d1
    return a1, a2, a3


@nb.njit(cache=True, inline="always", fastmath={"contract", "reassoc"})
def herm_clear(g0, d0, g1, d1, L, M4):
    """True when g >= 0 on [0, L] is certified from its ends alone: the cubic Hermite H of
    (g, g') less its pointwise error bound M4 L^4 u^2 (1 - u)^2 / 24 (u = s / L, M4 >= |g''''|)
    is a quartic in u whose Bernstein coefficients are all >= 0."""
    b1, b2, b3 = herm_coeffs(g0, d0, g1, d1, L)
    c = M4 * (L * L) * (L * L) / 24.0
    a2 = b2 - c
    a3 = b3 + 2.0 * c
    return (g0 >= 0.0 and g1 >= 0.0 and g0 + 0.25 * b1 >= 0.0
            and g0 + 0.5 * b1 + a2 / 6.0 >= 0.0
            and g0 + 0.75 * b1 + 0.5 * a2 + 0.25 * a3 >= 0.0)


@nb.njit(cache=True, inline="always")
def herm_max(g0, d0, g1, d1, L):
    """Max over [0, L] of the cubic Hermite interpolant of (g, g') and its argmax s."""
    a1, a2, a3 = herm_coeffs(g0, d0, g1, d1, L)
    best = g0
    arg = 0.0
    if g1 > best:
        best = g1
        arg = L
    # H'(u) = a1 + 2 a2 u + 3 a3 u^2
    u1, u2 = quad_roots01(a1, 2.0 * a2, 3.0 * a3)
    for u in (u1, u2):
        if u > 0.0:
            h = g0 + u * (a1 + u * (a2 + u * a3))
            if h > best:
                best = h
                arg = u * L
    return best, arg


@nb.njit(cache=True, inline="always")
def herm_min_deriv(g0, d0, g1, d1, L):
    """Min over [0, L] of the derivative of the cubic Hermite interpolant."""
    a1, a2, a3 = herm_coeffs(g0, d0, g1, d1, L)
    m = min(d0, d1)
    if a3 > 0.0:  # H' is a convex quadratic in u: interior minimum at u = -a2 / (3 a3)
        u = -a2 / (3.0 * a3)
        if 0.0 < u < 1.0:
            m = min(m, (a1 + u * (2.0 * a2 + 3.0 * u * a3)) / L)
    return m


# classification of a piece for one functional
EXCLUDED = 0
CROSSING = 1
UNDECIDED = 2


@nb.njit(cache=True, inline="always")
def classify(g0, d0, dd0, g1, d1, L, M2, M3, M4):
    """Can g become > 0 in (0, L]? ``g0 <= 0`` is required (callers clamp round-off);
    ``dd0`` = g''(0); M2, M3, M4 bound |g''|, |g'''|, |g''''| on the piece.

    Returns EXCLUDED (g < 0 on (0, L], rigorous), CROSSING (g1 > 0 and g' > 0 on the piece:
    exactly one root), or UNDECIDED (halve the piece). A piece ending exactly at g = 0 is not
    a crossing: the next piece starts there and sees the sign of g'.
    """
    if g1 > 0.0:
        if d0 - M2 * L > 0.0:
            return CROSSING
        if herm_min_deriv(g0, d0, g1, d1, L) > HERM_DERR * M4 * L * L * L:
            return CROSSING
        return UNDECIDED
    # Taylor from the start: g(s) <= g0 + d0 s + M2 s^2 / 2 (convex bound, max at an end)
    if g0 < 0.0:
        if g0 + L * (d0 + 0.5 * M2 * L) < 0.0:
            return EXCLUDED
    elif d0 + 0.5 * M2 * L < 0.0:
        return EXCLUDED
    # third-order Taylor from the start (covers a tangential start: g0 = d0 = 0, g'' < 0)
    if g0 < 0.0:
        if cubic_max(g0, d0, 0.5 * dd0, M3 / 6.0, L) < 0.0:
            return EXCLUDED
    elif (d0 < 0.0 or (d0 == 0.0 and dd0 < 0.0)) and d0 + L * (0.5 * dd0 + L * M3 / 6.0) < 0.0:
        return EXCLUDED
    # Taylor from the end: g(s) <= g1 - d1 (L - s) + M2 (L - s)^2 / 2
    if g0 < 0.0 and g1 - L * (d1 - 0.5 * M2 * L) < 0.0:
        return EXCLUDED
    if g0 < 0.0:
        hm, _ = herm_max(g0, d0, g1, d1, L)
        if hm + HERM_ERR * M4 * L * L * L * L < 0.0:
            return EXCLUDED
    return UNDECIDED


@nb.njit(cache=True, inline="always")
def herm_root(g0, d0, g1, d1, L):
    """Root in (0, L) of the cubic Hermite interpolant (g0 < 0 <= g1): a few Newton steps on
    the cubic from the secant point, kept inside the interval (a cheap first guess)."""
    a1, a2, a3 = herm_coeffs(g0, d0, g1, d1, L)
    u = -g0 / (g1 - g0)
    for _ in range(4):
        h = g0 + u * (a1 + u * (a2 + u * a3))
        dh = a1 + u * (2.0 * a2 + 3.0 * u * a3)
        if dh <= 0.0:
            break
        un = u - h / dh
        if not (0.0 < un < 1.0):
            break
        u = un
    return u * L


@nb.njit(cache=True)
def refine_root(MC, m, om, F0, y0, z0, C0, S0, cx, cv, c0, g0, d0, g1, d1, L, tol):
    """Root of g = cx X + cv V + c0 in [0, L] where g(0) = g0 <= 0 <= g(L) = g1 and g' > 0.

    Third-order Newton (root of the local quadratic g + g' d + g'' d^2 / 2) on the exact
    closed form, safeguarded by the bracket (bisection when a step leaves it). Once the
    estimated error of the corrected point, (|g3| + sqrt(k) |g2| + k |g1|) |d|^3 / (6 g1)
    with g_n the n-th derivative, is below ``tol``, the state is carried there by its Taylor
    series to third order (exact to round-off for such a small step): a transversal root
    usually costs one or two evaluations. Returns (s, X, V, A, y, z, C, S, ok).
    """
    lo = 0.0
    hi = L
    s = herm_root(g0, d0, g1, d1, L)
    k = MC[m, MC_K]
    c = MC[m, MC_C]
    sqk = MC[m, MC_SQK]
    X = V = A = y = z = C = S = 0.0
    ok = False
    for _ in range(100):
        X, V, A, y, z, C, S = eval_state(MC, m, om, y0, z0, C0, S0, s)
        J = -k * V - c * A - F0 * om * S
        J2 = -k * A - c * J - F0 * om * om * C
        g = cx * X + cv * V + c0
        d = cx * V + cv * A
        dd = cx * A + cv * J
        d3 = cx * J + cv * J2
        if g < 0.0:
            lo = s
        else:
            hi = s
        delta = 0.0
        if d > 0.0:
            delta = -g / d
            disc = d * d - 2.0 * g * dd
            if disc >= 0.0:
                delta = -2.0 * g / (d + math.sqrt(disc))
            ad = abs(delta)
            err = (abs(d3) + sqk * abs(dd) + k * abs(d)) * ad * ad * ad / (6.0 * d)
            sn = s + delta
            if err <= 0.25 * tol and ad <= 0.1 * L and lo - tol <= sn <= hi + tol:
                # Taylor transport of the state by delta
                h2 = 0.5 * delta * delta
                h3 = h2 * delta / 3.0
                X = X + V * delta + A * h2 + J * h3
                V = V + A * delta + J * h2 + J2 * h3
                cw, sw = cos_sin_small(om * delta)
                C, S = C * cw - S * sw, S * cw + C * sw
                y, z = hom_part(MC, m, om, X, V, C, S)
                A = accel(MC, m, om, y, z, C, S)
                s = sn
                ok = True
                break
        if hi - lo <= tol:
            ok = True
            break
        sn = s + delta
        if not (lo < sn < hi) or d <= 0.0:
            sn = 0.5 * (lo + hi)
        s = sn
    return s, X, V, A, y, z, C, S, ok


__all__ = ["mode_coeffs", "functional_bounds", "eval_state", "hom_part", "accel", "jerk",
           "classify", "cubic_max", "refine_root", "herm_max", "herm_min_deriv", "herm_root", "energy_norm",
           "deriv_bound", "cos_sin_small", "propagator", "propagator_table",
           "apply_propagator", "EXCLUDED", "CROSSING", "UNDECIDED", "N_MC", "N_BD"]
