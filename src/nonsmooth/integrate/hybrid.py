"""Generic compiled kernel for hybrid (piecewise-smooth, event-driven) forced oscillators.

Implements the kernel contract of :mod:`nonsmooth.integrate.contract` for any model given as
the tuple of compiled functions
``fns = (field, jacobian, guards, transition, initial, linear, curved)``
(signatures ``contract.MODEL_SIGNATURES``); nothing here knows a particular model.

Design summary
--------------
* A mode's field is integrated with the RKF45 table of :mod:`.tableau` (local extrapolation,
  elementary controller h err^(-1/5) with ``pow_fast``, RMS error norm over the n components,
  output times hit by shortening the last step without disturbing the controller), as in
  :mod:`.rkf45`; each step holds the field of the current mode fixed. A run at rtol below
  ``rk8.HI_ORDER_RTOL`` (the exact methods' nonlinear modes at 1e-12) takes DOP853 steps
  instead (:mod:`.rk8`), its tangent columns too (``rk8_tangent``). A cubic Hermite of so
  long a step would miss a grazing dip, so each accepted DOP853 step computes its dense
  output (order 7) into the Taylor terms TW and is treated as a series piece (below): guards
  as polynomials with the certified exit test, the crossing by Newton on them, extrema of X
  (a curved guard on the dense rows of degree 7, ``pval7``); the step is then retaken
  (a true DOP853 step) up to the crossing.
* Guards are affine in (u, cos, sin): inside a mode every g_k >= 0. After an accepted step the
  exit test is g_k(end) < 0, or a negative value of g_k (on the step's cubic Hermite state
  interpolant, exact forcing) at an interior minimum of the Hermite of (g, g'). The earliest
  exit over all guards is located by the Illinois method to 1e-13 of the step, the step is
  retaken exactly up to it, and ``transition`` (reset, new mode) is applied there; no FSAL
  across a switch. A guard with g <= 0 and g' < 0 at a step start triggers its transition at
  once; more than ``ZENO_MAX`` consecutive transitions each < ``ZENO_DT`` T apart -> ZENO.
* A curved guard (a row marked by NaN in its constant column, ``models.curved_row``) is
  evaluated with its gradient by the model's ``curved`` function on the same interpolant
  (``_guard_exit``): ends that clear zero by twice the Hermite slope bound pass at once;
  otherwise the step is halved left to right until each piece's Hermite of (g, g'), less an
  error bound estimated from the true g at its midpoint, clears zero, so grazing dips are
  found; the crossing is located by Illinois on the true g (on a series piece, whose guard is a
  polynomial, by Newton: ``linmodes.poly_root``). Its gradient enters the saltation
  matrix. A mode with a curved guard is never taken in the oscillator's closed form (the
  series of ``linmodes`` evaluates curved guards on its exact polynomial). A curved *label*
  (G[k, n+1] = 1, ``models.oscillator.label_row``: the same field across it, no reset) is not
  located: the mode switches at the end of the first step that ends past it, so that the
  region at every output is the side the state is on, at no cost to the steps; a pass and
  return inside a step that the Hermite of (g, g') at its ends shows marks the mode across as
  visited. Its g and g' at a step's end are those of the next step's start (one evaluation of
  ``curved`` per label and step), and the immediate-exit test at a step's start skips labels.
* A guard with forcing terms (G[k, n+1], G[k, n+2]) is not a cubic along a step, and a step can
  be long (a stick phase has a zero error estimate, so its RKF45 steps grow to a whole output
  interval): its exit test is certified, and so is every guard on a closed-form piece (the
  exact solution is not a cubic either). A step whose Hermite of (g, g') does not clear zero by
  its error bound (derivative bounds, ``pwlinear.HERM_ERR`` / a Bernstein test of the pointwise
  bound) is scanned piece by piece (``pwlinear.classify`` on -g, halving undecided pieces), and
  a located crossing is checked to be the first. So the answer does not depend on where outputs
  are taken (issue 20).
* ``opts[OPT_CLOSED_FORM] == 1`` and n == 2: modes that ``linear`` declares
  X'' + c X' + k X = F cos(omega t) + b (k > 0), or in the general form as that oscillator,
  free flight or a drift X' = V = b0 (``_MC_DRIFT``), are propagated in closed form
  (:mod:`.pwlinear`) in pieces of at most THETA = 0.7 rad of their fastest oscillation; the
  same exit test is applied to the exact piece ends, the crossing is located by third-order
  Newton steps on the exact closed-form state, kept in the bracket (``_locate_cf``; Illinois
  after a few steps at a tangential touch), and interior extrema of X are refined by Halley's
  method on V = 0, ended by a quadratic Taylor step (exact to round-off), unless the bound of
  X'''' shows they cannot move the interval's Xmax / Xmin (``_x_extrema_exact``).
  The propagator of a full piece is computed once per mode and call.
* Work arrays are views into one workspace without reference counting (:mod:`.workspace`):
  numba would otherwise increment and decrement a reference count atomically for every array
  passed to a model function, which took most of the time of a step.
* The local time restarts at each forcing period and the step state (u, mode, h, mem) is
  all that carries over, so results are split-invariant bit for bit. It restarts at
  t0 = psi / omega, psi = ``opts[OPT_PHASE]`` the forcing phase of the section (0 by default):
  a period runs from t0 to t0 + T, the functions receive that t and (cos, sin)(omega t).

Status codes: OK, MAX_STEPS, STEP_TOO_SMALL, NON_FINITE (also for a non-finite input, a
non-positive omega, or an opts layout that does not fit ``state``), ZENO, EVENT_FAILED (a
transition or ``initial`` returned a mode outside 0..7), RESONANCE (a closed-form mode forced
exactly at its undamped resonance).
"""

from __future__ import annotations

import math
import warnings

import numba as nb
import numpy as np

# passing compiled model functions uses numba's (experimental) first-class function types
warnings.filterwarnings("ignore", category=nb.NumbaExperimentalFeatureWarning)

from .. import status as st  # noqa: E402
from .contract import (  # noqa: E402
    GENERIC_KERNEL_SIGNATURE,
    TANGENT_KERNEL_SIGNATURE,
    MAX_GUARDS,
    N_STATE,
    SECTION_K,
    OPT_ATOL,
    OPT_CLOSED_FORM,
    OPT_FRAME_PERIOD,
    OPT_MAX_STEPS,
    OPT_N,
    OPT_NMEM,
    OPT_NO_DOP853,
    OPT_NO_EXTREMA,
    OPT_PHASE,
    OPT_OMEGA,
    OPT_RTOL,
    ST_EXTRA,
    ST_H,
    ST_MODE,
    ST_V,
    ST_VA,
    ST_X,
)
from .pwlinear import (BD_D2, BD_D3, BD_D4, BD_R, EXCLUDED, HERM_ERR, MC_A,  # noqa: E402
                       MC_B, MC_K, MC_LMAX, N_BD, N_MC,
                       accel, apply_propagator, classify, energy_norm, eval_state,
                       functional_bounds, herm_clear, herm_coeffs, hom_part, jerk, mode_coeffs,
                       propagator)
from .linmodes import (N_TAYLOR, POLY_DEPTH, THETA_POLY, guard_poly, lin_matrix,  # noqa: E402
                       poly_component, poly_m4, poly_root, poly_state, poly_tangent, pval7,
                       propagate_state, pvalue, poly_x_extrema, pval, series_powers,
                       series_propagator, taylor_terms)
from .record import record_interval  # noqa: E402
from .roots import illinois_point, illinois_update, quad_roots01  # noqa: E402
from .rkstep import (_A, _B, _C, _E, _FM, _NS, _control, _cubic, _shrink,  # noqa: E402
                     control_step, shrink_step, tangent_stage,
                     _x_extrema)
from .rk8 import (EXPO8, HI_ORDER_RTOL, N_STAGES8, rk8_dense, rk8_step,  # noqa: E402
                  rk8_tangent)
from .trig import cos_sin_small  # noqa: E402
from .workspace import keep_alive, unowned, view  # noqa: E402

MAX_MODES = 8  # mode codes 0..7 (bit mask M is uint8)
THETA = 0.7  # longest closed-form piece, radians of the fastest oscillation of the mode
ZENO_MAX = 64
ZENO_DT = 1e-9
S_TOL = 1e-13  # event location tolerance, fraction of the step
_HERM_SLOPE = 4.0 / 27.0  # max |h10|, |h11| of the cubic Hermite basis on [0, 1]

# mode classes for the closed-form table
_MC_UNKNOWN = 0
_MC_CLOSED = 1
_MC_RK = 2
_MC_RESONANT = 3
_MC_POLY = 4  # a linear mode of any dimension: the series of exp(M s) (``linmodes``)
_MC_DRIFT = 5  # X' = b0, V' = 0 (A = 0): free flight without force while V = b0, else the series

# log2(m) on [0.5, 1), least-squares quartic (same as rkf45.pow_fast)
@nb.njit(cache=True, inline="always")
def _gval(G, k, n, u, C, S):
    """Guard k at state u and forcing phase (C, S)."""
    g = G[k, n] + G[k, n + 1] * C + G[k, n + 2] * S
    for i in range(n):
        g += G[k, i] * u[i]
    return g


@nb.njit(cache=True, inline="always")
def _dgval(G, k, n, du, C, S, om):
    """Time derivative of guard k along the flow du."""
    d = om * (G[k, n + 2] * C - G[k, n + 1] * S)
    for i in range(n):
        d += G[k, i] * du[i]
    return d


@nb.njit(cache=True, inline="always", fastmath=_FM)
def _stage_rotations(om, h):
    """(cos, sin) of the forcing-phase advance om c h to the RKF45 stages c = 1/4, 3/8, 1/2,
    1 and 12/13 of a step h, from two short Taylor evaluations (``cos_sin_small``)."""
    c1, s1 = cos_sin_small(om * 0.125 * h)
    c2 = c1 * c1 - s1 * s1
    s2 = 2.0 * c1 * s1
    c3 = c2 * c1 - s2 * s1
    s3 = s2 * c1 + c2 * s1
    c4 = c2 * c2 - s2 * s2
    s4 = 2.0 * c2 * s2
    c8 = c4 * c4 - s4 * s4
    s8 = 2.0 * c4 * s4
    c12, s12 = cos_sin_small(om * _C[3] * h)
    return c2, s2, c3, s3, c4, s4, c8, s8, c12, s12


@nb.njit(cache=True, inline="always", fastmath=_FM)
def _rk_step2(field, mode, tau, C, S, h, u, k0, pp, mem, rtol, atol, us, k1, k2, k3, k4, k5, u1,
              c2, s2, c3, s3, c4, s4, C1, S1, c12, s12):
    """``_rk_step`` for two states, its formulas written out with the stages in scalars (the
    fastmath contraction and reassociation may round them differently in the last bit)."""
    x, v = u[0], u[1]
    x0, v0 = k0[0], k0[1]
    us[0] = x + h * (_A[1, 0] * x0)
    us[1] = v + h * (_A[1, 0] * v0)
    field(mode, tau + _C[1] * h, C * c2 - S * s2, S * c2 + C * s2, us, pp, mem, k1)
    x1, v1 = k1[0], k1[1]
    us[0] = x + h * (_A[2, 0] * x0 + _A[2, 1] * x1)
    us[1] = v + h * (_A[2, 0] * v0 + _A[2, 1] * v1)
    field(mode, tau + _C[2] * h, C * c3 - S * s3, S * c3 + C * s3, us, pp, mem, k2)
    x2, v2 = k2[0], k2[1]
    us[0] = x + h * (_A[3, 0] * x0 + _A[3, 1] * x1 + _A[3, 2] * x2)
    us[1] = v + h * (_A[3, 0] * v0 + _A[3, 1] * v1 + _A[3, 2] * v2)
    field(mode, tau + _C[3] * h, C * c12 - S * s12, S * c12 + C * s12, us, pp, mem, k3)
    x3, v3 = k3[0], k3[1]
    us[0] = x + h * (_A[4, 0] * x0 + _A[4, 1] * x1 + _A[4, 2] * x2 + _A[4, 3] * x3)
    us[1] = v + h * (_A[4, 0] * v0 + _A[4, 1] * v1 + _A[4, 2] * v2 + _A[4, 3] * v3)
    field(mode, tau + h, C1, S1, us, pp, mem, k4)
    x4, v4 = k4[0], k4[1]
    us[0] = x + h * (_A[5, 0] * x0 + _A[5, 1] * x1 + _A[5, 2] * x2 + _A[5, 3] * x3
                     + _A[5, 4] * x4)
    us[1] = v + h * (_A[5, 0] * v0 + _A[5, 1] * v1 + _A[5, 2] * v2 + _A[5, 3] * v3
                     + _A[5, 4] * v4)
    field(mode, tau + _C[5] * h, C * c4 - S * s4, S * c4 + C * s4, us, pp, mem, k5)
    x5, v5 = k5[0], k5[1]
    X1 = x + h * (_B[0] * x0 + _B[2] * x2 + _B[3] * x3 + _B[4] * x4 + _B[5] * x5)
    eX = h * (_E[0] * x0 + _E[2] * x2 + _E[3] * x3 + _E[4] * x4 + _E[5] * x5)
    V1 = v + h * (_B[0] * v0 + _B[2] * v2 + _B[3] * v3 + _B[4] * v4 + _B[5] * v5)
    eV = h * (_E[0] * v0 + _E[2] * v2 + _E[3] * v3 + _E[4] * v4 + _E[5] * v5)
    u1[0] = X1
    u1[1] = V1
    qx = eX / (atol + rtol * max(abs(x), abs(X1)))
    qv = eV / (atol + rtol * max(abs(v), abs(V1)))
    err2 = 0.0
    err2 += qx * qx
    err2 += qv * qv
    err2 = err2 / 2
    if not (math.isfinite(X1) and math.isfinite(V1)):
        err2 = np.nan  # an overflow makes sc infinite and err2 zero: never accept it
    return err2, C1, S1


@nb.njit(cache=True, inline="always", fastmath=_FM)
def _rk_step(field, mode, tau, C, S, h, om, n, u, k0, pp, mem, rtol, atol, us, k1, k2, k3, k4,
             k5, u1):
    """One RKF45 step of length h from (tau, u) with field(mode) fixed; k0 = field at the start.
    Writes the 5th-order solution to u1; returns (squared RMS error norm, cos, sin at the end).
    The error norm is NaN when u1 is not finite."""
    c2, s2, c3, s3, c4, s4, c8, s8, c12, s12 = _stage_rotations(om, h)
    C1 = C * c8 - S * s8
    S1 = S * c8 + C * s8
    if n == 2:  # the same formulas in scalars (most models): loops of two cost more
        return _rk_step2(field, mode, tau, C, S, h, u, k0, pp, mem, rtol, atol, us, k1, k2, k3,
                         k4, k5, u1, c2, s2, c3, s3, c4, s4, C1, S1, c12, s12)
    for i in range(n):
        us[i] = u[i] + h * (_A[1, 0] * k0[i])
    field(mode, tau + _C[1] * h, C * c2 - S * s2, S * c2 + C * s2, us, pp, mem, k1)
    for i in range(n):
        us[i] = u[i] + h * (_A[2, 0] * k0[i] + _A[2, 1] * k1[i])
    field(mode, tau + _C[2] * h, C * c3 - S * s3, S * c3 + C * s3, us, pp, mem, k2)
    for i in range(n):
        us[i] = u[i] + h * (_A[3, 0] * k0[i] + _A[3, 1] * k1[i] + _A[3, 2] * k2[i])
    field(mode, tau + _C[3] * h, C * c12 - S * s12, S * c12 + C * s12, us, pp, mem, k3)
    for i in range(n):
        us[i] = u[i] + h * (_A[4, 0] * k0[i] + _A[4, 1] * k1[i] + _A[4, 2] * k2[i]
                            + _A[4, 3] * k3[i])
    field(mode, tau + h, C1, S1, us, pp, mem, k4)
    for i in range(n):
        us[i] = u[i] + h * (_A[5, 0] * k0[i] + _A[5, 1] * k1[i] + _A[5, 2] * k2[i]
                            + _A[5, 3] * k3[i] + _A[5, 4] * k4[i])
    field(mode, tau + _C[5] * h, C * c4 - S * s4, S * c4 + C * s4, us, pp, mem, k5)
    err2 = 0.0
    finite = True
    for i in range(n):
        x1 = u[i] + h * (_B[0] * k0[i] + _B[2] * k2[i] + _B[3] * k3[i] + _B[4] * k4[i]
                         + _B[5] * k5[i])
        e = h * (_E[0] * k0[i] + _E[2] * k2[i] + _E[3] * k3[i] + _E[4] * k4[i] + _E[5] * k5[i])
        u1[i] = x1
        sc = atol + rtol * max(abs(u[i]), abs(x1))
        q = e / sc
        err2 += q * q  # (not q ** 2: see tests/test_import.py, no power operator)
        if not math.isfinite(x1):
            finite = False
    err2 = err2 / n
    if not finite:
        err2 = np.nan  # an overflow makes sc infinite and err2 zero: never accept it
    return err2, C1, S1


#: a Newton step on V = 0 below this fraction of the piece ends the search of an extremum of X:
#: X there is X(s) - V^2 / (2 A) (the quadratic Taylor step), whose error, about |X''' ds^3| / 6,
#: is below 1e-18 of the scale of X on pieces of at most THETA radians
_EXT_STEP = 1e-6


@nb.njit(cache=True)
def _x_extrema_exact(MC, m, om, F, y0, z0, C, S, X, V, X1, V1, h, xmax, xmin, BD):
    """Interior extrema of X on a closed-form piece of length h (F: the mode's forcing
    amplitude): first guesses from the cubic Hermite of X, then Halley's method on V(s) = 0
    with the exact state (V' = X'', V'' = X''' = ``pwlinear.jerk``), ended by a quadratic
    Taylor step once the step is below ``_EXT_STEP`` h. Candidates that cannot move xmax or
    xmin are not refined: X is within HERM_ERR h^4 max|X''''| of its Hermite on the piece
    (the bound of ``pwlinear.functional_bounds`` for g = X, into the scratch ``BD``), so
    when every candidate's Hermite value lies that far inside [xmin, xmax] (the piece's ends
    included), so does every value of X on the piece (a hop of a chattering ball lower than an
    earlier one, a slip extremum inside the interval's range)."""
    a1, a2, a3 = herm_coeffs(X, V, X1, V1, h)
    q1, q2 = quad_roots01(a1, 2.0 * a2, 3.0 * a3)
    if q1 <= 0.0 and q2 <= 0.0:
        return xmax, xmin
    functional_bounds(MC[m], om, 1.0, 0.0, BD)
    om2 = om * om
    M4 = BD[BD_D4] * energy_norm(MC, m, y0, z0) + om2 * om2 * BD[BD_R]
    err = HERM_ERR * (h * h) * (h * h) * M4
    top = max(xmax, X, X1) - err
    bot = min(xmin, X, X1) + err
    inside = True
    for q in (q1, q2):
        if q > 0.0:
            Hq = X + q * (a1 + q * (a2 + q * a3))
            inside = inside and bot <= Hq <= top
    if inside:
        return xmax, xmin
    for q in (q1, q2):
        if q > 0.0:
            s = q * h
            Xs = 0.0
            for _ in range(6):
                Xs, Vs, As, ys, zs, Cs, Ss = eval_state(MC, m, om, y0, z0, C, S, s)
                if As == 0.0:
                    break
                ds = -Vs / As
                if abs(ds) <= _EXT_STEP * h and 0.0 <= s + ds <= h:
                    Xs -= 0.5 * Vs * Vs / As  # = X + V ds + A ds^2 / 2
                    break
                den = 2.0 * As * As - Vs * jerk(MC, m, om, F, Vs, As, Cs, Ss)  # Halley
                if den > 0.0:
                    ds = -2.0 * Vs * As / den
                sn = min(h, max(0.0, s + ds))
                if abs(sn - s) <= 1e-15 * h:
                    break
                s = sn
            # any value taken on the piece is a valid bound candidate, converged or not
            xmax = max(xmax, Xs)
            xmin = min(xmin, Xs)
    return xmax, xmin


@nb.njit(cache=True, fastmath=_FM)
def _g_at(cf, s, G, k, n, q0, q1, q2, q3, C, S, om, hs, MC, mode, y0, z0):
    """Guard k at the fraction s of the current step: on the exact closed form (cf) or on the
    cubic Hermite of the state (projection coefficients q0..q3), with the exact forcing."""
    if cf:
        X, V, A, y, z, Cs, Ss = eval_state(MC, mode, om, y0, z0, C, S, s * hs)
        return G[k, 0] * X + G[k, 1] * V + G[k, 2] + G[k, 3] * Cs + G[k, 4] * Ss
    cw, sw = cos_sin_small(om * s * hs)
    Cs = C * cw - S * sw
    Ss = S * cw + C * sw
    return _cubic(q0, q1, q2, q3, s) + G[k, n] + G[k, n + 1] * Cs + G[k, n + 2] * Ss


# ---- certified exit test ----------------------------------------------------------------------
SCAN_DEPTH = 30  # halvings of a step in the certified exit test (down to 1e-9 of the step)


@nb.njit(cache=True, inline="always", fastmath=_FM)
def _g_full(cf, s, G, k, n, q0, q1, q2, q3, C, S, om, hs, MC, mode, y0, z0, F):
    """Guard k and its first two time derivatives (g, g', g'') at the fraction s of the step:
    on the exact closed form (cf; F = the mode's forcing amplitude, for the jerk) or on the
    cubic Hermite of the state (projection q0..q3), with the exact forcing terms of the guard."""
    if cf:
        X, V, A, y, z, Cs, Ss = eval_state(MC, mode, om, y0, z0, C, S, s * hs)
        Jk = jerk(MC, mode, om, F, V, A, Cs, Ss)
        g = G[k, 0] * X + G[k, 1] * V
        d = G[k, 0] * V + G[k, 1] * A
        dd = G[k, 0] * A + G[k, 1] * Jk
    else:
        cw, sw = cos_sin_small(om * s * hs)
        Cs = C * cw - S * sw
        Ss = S * cw + C * sw
        g = _cubic(q0, q1, q2, q3, s)
        d = (q1 + s * (2.0 * q2 + 3.0 * q3 * s)) / hs
        dd = (2.0 * q2 + 6.0 * q3 * s) / (hs * hs)
    a = G[k, n + 1]
    b = G[k, n + 2]
    g += G[k, n] + a * Cs + b * Ss
    d += om * (b * Cs - a * Ss)
    dd -= om * om * (a * Cs + b * Ss)
    return g, d, dd


@nb.njit(cache=True, inline="always")
def _guard_bounds(cf, G, k, n, q2, q3, om, hs, MC, mode, y0, z0, BD):
    """(M2, M3, M4): bounds of |g''|, |g'''|, |g''''| of guard k over the whole step. On a
    closed-form piece: the energy-norm bounds of the homogeneous part plus om^n times the
    harmonic amplitudes (``pwlinear.functional_bounds``: ``BD`` is the guard's row of the
    mode's table GB, ``_cf_bounds``); on an RKF45 step: the derivatives of the state's cubic
    plus om^n times the amplitude of the guard's forcing terms (``BD`` unused)."""
    om2 = om * om
    if cf:  # BD: the guard's row of GB (``_cf_bounds``: the guard's forcing included)
        En = energy_norm(MC, mode, y0, z0)
        R = BD[BD_R]
        return (BD[BD_D2] * En + om2 * R, BD[BD_D3] * En + om2 * om * R,
                BD[BD_D4] * En + om2 * om2 * R)
    Rg = math.hypot(G[k, n + 1], G[k, n + 2])
    h2 = hs * hs
    return (max(abs(2.0 * q2), abs(2.0 * q2 + 6.0 * q3)) / h2 + om2 * Rg,
            6.0 * abs(q3) / (h2 * hs) + om2 * om * Rg, om2 * om2 * Rg)


@nb.njit(cache=True, inline="always", fastmath=_FM)
def _g_dd(cf, G, k, n, u, f, C, S, om, MC, mode, F, cdd, hs):
    """g'' of guard k at a step end with state u, derivative f and forcing phase (C, S) (on an
    RKF45 step ``cdd`` is the second derivative of the state cubic's projection there, per
    fraction squared)."""
    if cf:
        dd = G[k, 0] * f[1] + G[k, 1] * jerk(MC, mode, om, F, u[1], f[1], C, S)
    else:
        dd = cdd / (hs * hs)
    return dd - om * om * (G[k, n + 1] * C + G[k, n + 2] * S)


@nb.njit(cache=True)
def _first_negative(cf, s_end, ga, da, dda, gb, db, ddb, G, k, n, q0, q1, q2, q3, C, S, om, hs,
                    MC, mode, y0, z0, F, M2, M3, M4, stack):
    """The first point found in (0, s_end] (fractions of the step) where guard k < 0, as
    (s, g(s)); (2.0, 0.0) when g >= 0 on [0, s_end] is certified. (ga, da, dda) and
    (gb, db, ddb): g, g', g'' at 0 and at s_end.

    Pieces are taken left to right; ``pwlinear.classify`` on -g with the derivative bounds
    M2..M4 excludes a piece rigorously, an undecided piece is halved (at most SCAN_DEPTH
    times; a piece still undecided then is tested at its midpoint). So a guard cannot dip below
    zero and come back inside a step unseen, however long the step: the RKF45 steps of a mode
    with a zero error estimate (a stick phase) grow to a whole output interval, and a guard
    with forcing terms can change sign twice inside one."""
    a = 0.0
    b = s_end
    depth = 0
    top = 0
    ga = max(ga, 0.0)  # round-off after the switch into this mode
    while True:
        if gb < 0.0:
            return b, gb
        L = (b - a) * hs
        if not herm_clear(ga, da, gb, db, L, M4) and classify(
                -ga, -da, -dda, -gb, -db, L, M2, M3, M4) != EXCLUDED:
            if depth < SCAN_DEPTH:
                stack[top, 0] = b
                stack[top, 1] = gb
                stack[top, 2] = db
                stack[top, 3] = ddb
                stack[top, 4] = depth + 1
                top += 1
                b = 0.5 * (a + b)
                depth += 1
                gb, db, ddb = _g_full(cf, b, G, k, n, q0, q1, q2, q3, C, S, om, hs, MC, mode, y0,
                                      z0, F)
                continue
            sm = 0.5 * (a + b)
            gm, _, _ = _g_full(cf, sm, G, k, n, q0, q1, q2, q3, C, S, om, hs, MC, mode, y0, z0,
                               F)
            if gm < 0.0:
                return sm, gm
        if top == 0:
            return 2.0, 0.0
        top -= 1
        a = b
        ga = gb
        da = db
        dda = ddb
        b = stack[top, 0]
        gb = stack[top, 1]
        db = stack[top, 2]
        ddb = stack[top, 3]
        depth = int(stack[top, 4])


#: Newton iterations of :func:`_locate_cf` before it goes on by Illinois
_CF_NEWTON = 8


@nb.njit(cache=True, fastmath=_FM)
def _locate_cf(lo, hi, glo, ghi, G, k, om, hs, MC, mode, y0, z0, C, S, F):
    """The crossing of affine guard k on a closed-form piece (n = 2; fractions of the step,
    g(lo) >= 0 > g(hi)) down to a bracket of S_TOL: third-order Newton steps (the root of the
    local quadratic g + g' d + g'' d^2 / 2, as ``pwlinear.refine_root``) on the exact closed
    form, from the secant point, kept in the bracket (the secant point when a step leaves it);
    once a step is below S_TOL / 4, the next point is taken S_TOL / 2 beyond the root estimate,
    on the far side, so that the bracket closes. A transversal crossing takes about three
    evaluations, where Illinois took eight to ten; one that Newton has not closed after
    ``_CF_NEWTON`` evaluations (a tangential touch, g' = 0 at the root) goes on by Illinois.
    F: the mode's forcing amplitude (for X''' = ``pwlinear.jerk``). Returns the final
    (lo, hi)."""
    om2 = om * om
    a0, a1, a2, a3, a4 = G[k, 0], G[k, 1], G[k, 2], G[k, 3], G[k, 4]
    s = illinois_point(lo, hi, glo, ghi)
    side = 0
    for it in range(200):
        if hi - lo <= S_TOL:
            break
        newton = it < _CF_NEWTON
        if not newton:
            s = illinois_point(lo, hi, glo, ghi)
        X, V, A, y, z, Cs, Ss = eval_state(MC, mode, om, y0, z0, C, S, s * hs)
        g = a0 * X + a1 * V + a2 + a3 * Cs + a4 * Ss
        if not newton:
            lo, hi, glo, ghi, side = illinois_update(lo, hi, glo, ghi, side, s, g)
            continue
        if g < 0.0:
            hi = s
            ghi = g
        else:
            lo = s
            glo = g
        if hi - lo <= S_TOL:
            break
        J = jerk(MC, mode, om, F, V, A, Cs, Ss)
        d = hs * (a0 * V + a1 * A + om * (a4 * Cs - a3 * Ss))
        dd = hs * hs * (a0 * A + a1 * J - om2 * (a3 * Cs + a4 * Ss))
        sn = -1.0
        if d != 0.0:
            delta = -g / d
            disc = d * d - 2.0 * g * dd
            if disc >= 0.0:
                delta = -2.0 * g / (d + math.copysign(math.sqrt(disc), d))
            if abs(delta) <= 0.25 * S_TOL:  # converged: step over the root
                delta = math.copysign(0.5 * S_TOL, delta if delta != 0.0 else -d)
            sn = s + delta
        if not (lo < sn < hi):
            sn = illinois_point(lo, hi, glo, ghi)
        s = sn
    return lo, hi


@nb.njit(cache=True, inline="always", fastmath=_FM)
def _locate(cf, lo, hi, glo, ghi, G, k, n, q0, q1, q2, q3, C, S, om, hs, MC, mode, y0, z0,
            F):
    """The crossing in the bracket [lo, hi] (fractions of the step; g(lo) >= 0 > g(hi)) down
    to S_TOL: on a closed-form piece by :func:`_locate_cf`, else by Illinois on the step's
    cubic Hermite (F: the mode's forcing amplitude); returns the final (lo, hi)."""
    if cf:
        return _locate_cf(lo, hi, glo, ghi, G, k, om, hs, MC, mode, y0, z0, C, S, F)
    side = 0
    for _ in range(200):
        if hi - lo <= S_TOL:
            break
        sm = illinois_point(lo, hi, glo, ghi)
        gm = _g_at(cf, sm, G, k, n, q0, q1, q2, q3, C, S, om, hs, MC, mode, y0, z0)
        lo, hi, glo, ghi, side = illinois_update(lo, hi, glo, ghi, side, sm, gm)
    return lo, hi


@nb.njit(cache=True, inline="always")
def frame_omega(pp, opts):
    """The frequency omega that frames time: p[opts[OPT_OMEGA]], or 2 pi / T where that slot
    holds the forcing period T (``opts[OPT_FRAME_PERIOD]``, a model's ``period``; T = 0 gives
    -1, which the kernel reports as NON_FINITE like omega <= 0)."""
    f = pp[int(opts[OPT_OMEGA])]
    if opts[OPT_FRAME_PERIOD] == 1.0:
        return 2.0 * math.pi / f if f != 0.0 else -1.0
    return f


#: the oscillator's formulas are used only where they are well conditioned (``_conditioned``);
#: elsewhere the series
OSC_COND = 1e-3


@nb.njit(cache=True)
def _conditioned(k, c, b, forced, om):
    """Whether the oscillator's formulas (k > 0, c >= 0) keep the state to about
    eps / OSC_COND: False for a constant force on a weak spring, k < OSC_COND max(om^2,
    c^2 / 4) (the static offset b / k and the slow homogeneous part cancel: a loss of about
    eps |b| / k); an over-damped mode with k < OSC_COND c^2 / 4 (its slow rate
    -c / 2 + sqrt(c^2 / 4 - k) cancels); a forced mode near resonance,
    |k - om^2 + i c om| < OSC_COND max(k, om^2) (the particular harmonic and the homogeneous
    part cancel: about eps F / |k - om^2 + i c om|)."""
    om2 = om * om
    d = k - om2
    if b != 0.0 and k < OSC_COND * max(om2, 0.25 * c * c):
        return False
    if k < OSC_COND * 0.25 * c * c:
        return False
    return not (forced and d * d + (c * om) ** 2 < (OSC_COND * max(k, om2)) ** 2)


@nb.njit(cache=True)
def _oscillator(lin, om, mc):
    """A general-form ``linear`` row (n = 2) that is the oscillator X' = V,
    V' = -k X - c V + b + f_c cos(omega t) + f_s sin(omega t) with k > 0 and c >= 0, or free
    flight (k = c = 0): fill its closed-form row ``mc`` (``pwlinear.mode_coeffs``) and return
    True; False for any other form, where the oscillator's formulas are ill-conditioned
    (``_conditioned``: the series of ``linmodes``, exact to round-off, takes those) and for an
    undamped mode forced at resonance."""
    if not (lin[0] == 0.0 and lin[1] == 1.0 and lin[4] == 0.0 and lin[6] == 0.0
            and lin[8] == 0.0):
        return False
    k = -lin[2]
    c = -lin[3]
    if k == 0.0 and c == 0.0:
        return mode_coeffs(k, c, lin[5], lin[7], om, THETA, mc, lin[9])
    if not (k > 0.0 and c >= 0.0
            and _conditioned(k, c, lin[5], lin[7] != 0.0 or lin[9] != 0.0, om)):
        return False
    return mode_coeffs(k, c, lin[5], lin[7], om, THETA, mc, lin[9])


@nb.njit(cache=True)
def _as_general_row(lin):
    """The (k, c, b, F) row of the oscillator (``linear`` returned 1) rewritten in place as
    the general row of the same mode (A = [[0, 1], [-k, -c]], b = (0, b), f_c = (0, F),
    f_s = 0), for the series."""
    k, c, b, F = lin[0], lin[1], lin[2], lin[3]
    for i in range(10):
        lin[i] = 0.0
    lin[1] = 1.0
    lin[2] = -k
    lin[3] = -c
    lin[5] = b
    lin[7] = F


@nb.njit(cache=True)
def _drift(lin):
    """A general-form ``linear`` row (n = 2) that is a drift at a constant rate, X' = b0 and
    V' = 0 (A = 0, no forcing): a stick phase on a moving belt, a ball riding on its table."""
    for i in range(10):
        if i != 4 and lin[i] != 0.0:
            return False
    return True


@nb.njit(cache=True, inline="always")
def _paths(cls, ncv, v, MC, mode):
    """(cf, pm): whether the mode's pieces take the closed form or the series. A drift
    (``_MC_DRIFT``) whose state has V = b0 (kept in MC_B) moves exactly as free flight without
    force (X' = V = b0, V' = 0), so it takes that closed form; with V != b0 (X' is then not V)
    it takes the series. Curved guards keep a drift on the series."""
    if cls == _MC_DRIFT:
        d = ncv == 0 and v == MC[mode, MC_B]
        return d, not d
    return cls == _MC_CLOSED and ncv == 0, cls == _MC_POLY


@nb.njit(cache=True)
def _mode_class(linear, closed, mode, pp, lin, MC, mcs, om, MF, n, MXR, PW):
    """_MC_CLOSED / _MC_RK / _MC_RESONANT / _MC_POLY / _MC_DRIFT for ``mode``, filling the
    table row (and the forcing amplitude ``MF[mode]``, or the series' matrices M^j / j!
    ``PW[mode]`` of the augmented matrix M and its rate ``MXR[mode]``; a drift gets both) lazily."""
    if not closed:
        return _MC_RK
    if mcs[mode] == _MC_UNKNOWN:
        mcs[mode] = _MC_RK
        r = linear(mode, pp, lin)
        if r == 1 and n == 2 and lin[0] > 0.0 and lin[1] >= 0.0 and not _conditioned(
                lin[0], lin[1], lin[2], lin[3] != 0.0, om) and (
                lin[0] - om * om) ** 2 + (lin[1] * om) ** 2 > 1e-300:
            _as_general_row(lin)  # ill-conditioned (not at resonance: that stays a status)
            r = 2
        if r == 1 and n == 2 and lin[0] > 0.0 and lin[1] >= 0.0:  # (the bounds need c >= 0)
            MF[mode] = lin[3]
            if mode_coeffs(lin[0], lin[1], lin[2], lin[3], om, THETA, MC[mode]):
                mcs[mode] = _MC_CLOSED
            else:
                mcs[mode] = _MC_RESONANT
        elif r == 2 and n == 2 and _oscillator(lin, om, MC[mode]):
            MF[mode] = lin[7]
            mcs[mode] = _MC_CLOSED
        elif r == 2 and n == 2 and _drift(lin):
            MXR[mode] = lin_matrix(lin, n, om, PW[mode, :, 1])  # (the series: V != b0)
            series_powers(n + 3, PW[mode])
            mode_coeffs(0.0, 0.0, 0.0, 0.0, om, THETA, MC[mode])  # free flight, no force
            MC[mode, MC_B] = lin[4]  # the drift rate b0 (MC_B is not read by ``pwlinear``)
            MF[mode] = 0.0
            mcs[mode] = _MC_DRIFT
        elif r == 2:
            MXR[mode] = lin_matrix(lin, n, om, PW[mode, :, 1])
            series_powers(n + 3, PW[mode])
            mcs[mode] = _MC_POLY
    return int(mcs[mode])


@nb.njit(cache=True)
def _cf_bounds(MC, mode, om, G, ng, n, GB):
    """GB[k] = the derivative-bound coefficients (``pwlinear.functional_bounds``) of the guards
    of a closed-form mode (they change only with the mode or its guards), with the amplitude of
    the guard's own forcing terms added to the harmonic amplitude BD_R."""
    for k in range(ng):
        functional_bounds(MC[mode], om, G[k, 0], G[k, 1], GB[k])
        GB[k, BD_R] += math.hypot(G[k, n + 1], G[k, n + 2])


#: Guard sets per mode whose bound coefficients ``_cf_bounds_cached`` keeps (a mode re-entered
#: with one of them again, e.g. the support's free flight below and above X = 1, takes its
#: coefficients from there)
CF_SLOTS = 2


@nb.njit(cache=True, inline="always")
def _cf_bounds_cached(MC, mode, om, G, ng, n, GB, GBC, GKC, GNC):
    """:func:`_cf_bounds`, taken from the ``CF_SLOTS`` last guard sets of ``mode`` when the ng
    rows are equal to one of them (the coefficients depend on the mode's closed form, fixed in a
    call, and the rows only): GBC[mode, slot] the coefficients, GKC[mode, slot] the rows,
    GNC[mode, slot] = ng + 1 (0: empty), GNC[mode, CF_SLOTS] the slot written next."""
    m3 = n + 3
    for sl in range(CF_SLOTS):
        if GNC[mode, sl] != ng + 1:
            continue
        same = True
        for k in range(ng):
            for i in range(m3):
                if GKC[mode, sl, k, i] != G[k, i]:
                    same = False
        if same:
            for k in range(ng):
                for b in range(N_BD):
                    GB[k, b] = GBC[mode, sl, k, b]
            return
    _cf_bounds(MC, mode, om, G, ng, n, GB)
    sl = int(GNC[mode, CF_SLOTS])
    GNC[mode, CF_SLOTS] = (sl + 1) % CF_SLOTS
    GNC[mode, sl] = ng + 1
    for k in range(ng):
        for i in range(m3):
            GKC[mode, sl, k, i] = G[k, i]
        for b in range(N_BD):
            GBC[mode, sl, k, b] = GB[k, b]


@nb.njit(cache=True)
def _scan_step(cf, g0, d0, g1, d1, u, f0, u1, f1, C, S, C1, S1, G, k, n, q0, q1, q2, q3, om, hs,
               MC, mode, y0, z0, F, stack, BD):
    """Certified exit test of guard k over a whole step that the quick test passed: the first
    point found where g < 0, as (s, g(s)), or (2.0, 0.0) (``_first_negative``)."""
    M2, M3, M4 = _guard_bounds(cf, G, k, n, q2, q3, om, hs, MC, mode, y0, z0, BD)
    dd0 = _g_dd(cf, G, k, n, u, f0, C, S, om, MC, mode, F, 2.0 * q2, hs)
    dd1 = _g_dd(cf, G, k, n, u1, f1, C1, S1, om, MC, mode, F, 2.0 * q2 + 6.0 * q3, hs)
    return _first_negative(cf, 1.0, g0, d0, dd0, g1, d1, dd1, G, k, n, q0, q1, q2, q3, C, S, om,
                           hs, MC, mode, y0, z0, F, M2, M3, M4, stack)


@nb.njit(cache=True, inline="always")
def _first_crossing(cf, lo, hi, g0, d0, u, f0, C, S, G, k, n, q0, q1, q2, q3, om, hs, MC,
                    mode, y0, z0, F, stack, BD):
    """The located crossing [lo, hi] of guard k must be its first: g >= 0 on [0, lo] is
    certified, else the crossing is located again before the first negative point found.
    A transversal crossing (g(lo) >= 0, g'(lo) < 0) needs no scan of its tail: g' <=
    g'(lo) + M2 (lo - s) hs < 0 there, so g decreases to g(lo) >= 0 on
    [lo - |g'(lo)| / (M2 hs), lo] (whose halving, down to pieces short enough for
    ``classify``'s test from the end, took most of the scan). Returns the final (lo, hi).

    Inlined into the kernel: the usual case, a crossing whose whole tail [0, lo] that test
    covers, is decided here without a call; the others go on in :func:`_first_crossing_scan`,
    which starts with the same test."""
    if not lo > 0.0:
        return lo, hi
    M2 = _guard_bounds(cf, G, k, n, q2, q3, om, hs, MC, mode, y0, z0, BD)[0]
    dl = _g_full(cf, lo, G, k, n, q0, q1, q2, q3, C, S, om, hs, MC, mode, y0, z0, F)[1]
    if dl < 0.0 and M2 > 0.0 and not lo - 0.9 * (-dl / M2) / hs > 0.0:
        return lo, hi  # g >= 0 on [0, lo] (decreasing to g(lo))
    return _first_crossing_scan(cf, lo, hi, g0, d0, u, f0, C, S, G, k, n, q0, q1, q2, q3, om,
                                hs, MC, mode, y0, z0, F, stack, BD)


@nb.njit(cache=True)
def _first_crossing_scan(cf, lo, hi, g0, d0, u, f0, C, S, G, k, n, q0, q1, q2, q3, om, hs, MC,
                         mode, y0, z0, F, stack, BD):
    """:func:`_first_crossing`'s test and scan, repeated while an earlier crossing is found."""
    M2, M3, M4 = _guard_bounds(cf, G, k, n, q2, q3, om, hs, MC, mode, y0, z0, BD)
    dd0 = _g_dd(cf, G, k, n, u, f0, C, S, om, MC, mode, F, 2.0 * q2, hs)
    for _ in range(8):
        if not lo > 0.0:
            break
        gl, dl, ddl = _g_full(cf, lo, G, k, n, q0, q1, q2, q3, C, S, om, hs, MC, mode, y0, z0, F)
        s_end = lo
        if dl < 0.0 and M2 > 0.0:
            s_end = lo - 0.9 * (-dl / M2) / hs
            if not s_end > 0.0:
                break  # g >= 0 on [0, lo] (decreasing to g(lo))
            gl, dl, ddl = _g_full(cf, s_end, G, k, n, q0, q1, q2, q3, C, S, om, hs, MC, mode, y0,
                                  z0, F)
        sf, gf = _first_negative(cf, s_end, g0, d0, dd0, gl, dl, ddl, G, k, n, q0, q1, q2, q3, C,
                                 S, om, hs, MC, mode, y0, z0, F, M2, M3, M4, stack)
        if sf > 1.0:
            break
        lo, hi = _locate(cf, 0.0, sf, g0, gf, G, k, n, q0, q1, q2, q3, C, S, om, hs, MC, mode,
                         y0, z0, F)
    return lo, hi


# ---- curved guards (``contract``: NaN in a row's constant column) ------------------------------
CURVED_DEPTH = 12  # halvings of a step in the exit test of a curved guard


@nb.njit(cache=True)
def _curved_rate(curved, mode, k, tau, C, S, n, u, f, pp, mem, gr):
    """(g, dg/dt) of curved guard k at (tau, u) moving with du/dt = f; gr <- its gradient."""
    g = curved(mode, k, tau, C, S, u, pp, mem, gr)
    d = gr[n]
    for i in range(n):
        d += gr[i] * f[i]
    return g, d


@nb.njit(cache=True)
def _curved_at(curved, mode, k, tau, C, S, hs, om, n, u, f0, u1, f1, pp, mem, gr, us, s,
               pm, TW):
    """(g, dg/dt) of curved guard k at the fraction s of the step (tau, u) -> (tau + hs, u1),
    on the step's cubic Hermite state interpolant (``us`` <- that state) with exact forcing;
    on a piece of a linear mode (``pm`` 1), on its series (exact); on a DOP853 step's dense
    output (``pm`` 2), on that polynomial of degree 7 (``pval7``)."""
    th = om * (s * hs)
    if pm:
        for i in range(n):
            us[i] = pval7(TW[i], s * hs)[0] if pm == 2 else pvalue(TW[i], s * hs)
        g = curved(mode, k, tau + s * hs, C * math.cos(th) - S * math.sin(th),
                   S * math.cos(th) + C * math.sin(th), us, pp, mem, gr)
        d = gr[n]
        for i in range(n):
            d += gr[i] * (pval7(TW[i], s * hs)[1] if pm == 2 else
                          poly_component(TW, i, s * hs)[1])
        return g, d
    for i in range(n):
        du = u1[i] - u[i]
        a = hs * f0[i]
        b = 3.0 * du - 2.0 * a - hs * f1[i]
        c = -2.0 * du + a + hs * f1[i]
        us[i] = u[i] + s * (a + s * (b + s * c))
    cs = math.cos(th)
    sn = math.sin(th)
    g = curved(mode, k, tau + s * hs, C * cs - S * sn, S * cs + C * sn, us, pp, mem, gr)
    d = gr[n]
    for i in range(n):
        du = u1[i] - u[i]
        a = hs * f0[i]
        b = 3.0 * du - 2.0 * a - hs * f1[i]
        c = -2.0 * du + a + hs * f1[i]
        d += gr[i] * (a + s * (2.0 * b + 3.0 * s * c)) / hs
    return g, d


@nb.njit(cache=True)
def _immediate_exit_curved(curved, mode, tau, G, ng, n, u, f0, C, S, om, pp, mem, gr, ksec,
                           kcs):
    """``_immediate_exit`` for a mode with curved guards (row ``ksec``: a curved section,
    evaluated as ``curved``'s k = ``kcs``)."""
    for k in range(ng):
        if math.isnan(G[k, n]):
            if G[k, n + 1] == 1.0 and k != ksec:
                continue  # a label: switched at a step's end (``contract``)
            g, d = _curved_rate(curved, mode, kcs if k == ksec else k, tau, C, S, n, u, f0, pp,
                                mem, gr)
        else:
            g = _gval(G, k, n, u, C, S)
            d = _dgval(G, k, n, f0, C, S, om)
        if g <= 0.0 and d < 0.0:
            return k
    return -1


@nb.njit(cache=True, inline="always")
def _g_eval(kind, s, cp, curved, mode, k, tau, C, S, hs, om, n, u, f0, u1, f1, pp, mem, gr, us,
            pm, TW):
    """(g, dg/dt) of guard k at the fraction s of the step: kind 0, an affine guard on a
    series piece (``cp``: its polynomial in time, ``linmodes.guard_poly``); kind 1, a curved
    guard (``_curved_at``)."""
    if kind == 0:
        return pval(cp, s * hs)
    return _curved_at(curved, mode, k, tau, C, S, hs, om, n, u, f0, u1, f1, pp, mem, gr, us, s,
                      pm, TW)


@nb.njit(cache=True)
def _guard_scan(kind, cp, curved, mode, k, tau, C, S, hs, om, n, u, f0, u1, f1, pp, mem, gr,
                us, stack, ga, da, gb, db, end, s_best, pm, TW):
    """The first piece of [0, end] (fractions of the step, left to right) that holds a
    negative value of guard k (``_g_eval``; (ga, da) and (gb, db): its value and rate at 0
    and at ``end``, which the caller has): (a, b, g(b)) with g(a) >= 0 > g(b), or
    (-1, -1, 0). A piece passes when the cubic Hermite of (g, g') at its ends, less its error
    bound, stays >= 0 (``herm_clear``): the bound of g'''' is the polynomial's own (kind 0,
    rigorous) or four times the one the true g at the piece's midpoint implies (kind 1).
    Else the piece is halved (at most POLY_DEPTH / CURVED_DEPTH times); on a piece whose end
    is negative the Hermite's interior minima are tried first."""
    ga = max(ga, 0.0)  # round-off after the switch into this mode
    max_depth = POLY_DEPTH if kind == 0 else CURVED_DEPTH
    a = 0.0
    b = end
    depth = 0
    top = 0
    while True:
        if a >= s_best:
            return -1.0, -1.0, 0.0
        L = (b - a) * hs
        if gb < 0.0:
            b1, b2, b3 = herm_coeffs(ga, da, gb, db, L)
            r1, r2 = quad_roots01(b1, 2.0 * b2, 3.0 * b3)
            for q in (min(r1, r2), max(r1, r2)):
                if 0.0 < q < 1.0 and 2.0 * b2 + 6.0 * b3 * q > 0.0:  # a minimum
                    sq = a + q * (b - a)
                    gq, _ = _g_eval(kind, sq, cp, curved, mode, k, tau, C, S, hs, om, n, u, f0,
                                    u1, f1, pp, mem, gr, us, pm, TW)
                    if gq < 0.0:
                        return a, sq, gq
            return a, b, gb
        m = 0.5 * (a + b)
        gm, dm = _g_eval(kind, m, cp, curved, mode, k, tau, C, S, hs, om, n, u, f0, u1, f1, pp,
                         mem, gr, us, pm, TW)
        if kind == 0:
            M4 = poly_m4(cp, b * hs)
        else:
            b1, b2, b3 = herm_coeffs(ga, da, gb, db, L)
            e = abs(gm - (ga + 0.5 * b1 + 0.25 * b2 + 0.125 * b3))
            M4 = 4.0 * 384.0 * e / ((L * L) * (L * L)) if L > 0.0 else 0.0
        if not herm_clear(ga, da, gb, db, L, M4):
            if depth < max_depth:
                stack[top, 0] = b
                stack[top, 1] = gb
                stack[top, 2] = db
                stack[top, 4] = depth + 1
                top += 1
                b = m
                gb = gm
                db = dm
                depth += 1
                continue
            if gm < 0.0:
                return a, m, gm
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
def _guard_exit(kind, cp, curved, mode, k, tau, C, S, hs, om, n, u, f0, u1, f1, pp, mem, gr,
                us, stack, s_best, pm, TW):
    """Exit test of guard k (``_g_eval``: an affine guard on a series piece, or a curved
    guard) over the step just taken: (lo, hi) bracketing its first crossing to S_TOL of the
    step (fractions, g(lo) >= 0 > g(hi)), (2.0, 2.0) when it stays >= 0 up to ``s_best`` (an
    earlier crossing of another guard), (-1.0, -1.0) when location fails.

    A step whose ends clear zero is passed at once (kind 0: the Hermite less the polynomial's
    bound of g''''; kind 1: by twice the Hermite slope bound). Otherwise the first negative
    piece (``_guard_scan``) is bracketed, the crossing located by Illinois on the true g (kind
    0, a polynomial: by Newton, ``linmodes.poly_root``), and
    [0, lo] scanned again, so that a dip and a return before it are found too (the first
    crossing, grazing dips included; ``_first_crossing`` does this for the other guards)."""
    g0, d0 = _g_eval(kind, 0.0, cp, curved, mode, k, tau, C, S, hs, om, n, u, f0, u1, f1, pp,
                     mem, gr, us, pm, TW)
    g0 = max(g0, 0.0)  # round-off after the switch into this mode
    g1, d1 = _g_eval(kind, 1.0, cp, curved, mode, k, tau, C, S, hs, om, n, u, f0, u1, f1, pp,
                     mem, gr, us, pm, TW)
    if kind == 0:
        if herm_clear(g0, d0, g1, d1, hs, poly_m4(cp, hs)):
            return 2.0, 2.0
    else:
        sl = hs * (abs(d0) + abs(d1))
        if g1 >= 0.0 and min(g0, g1) - 2.0 * _HERM_SLOPE * sl > 1e-9 * (abs(g0) + abs(g1) + sl):
            return 2.0, 2.0
    lo, hi, ghi = _guard_scan(kind, cp, curved, mode, k, tau, C, S, hs, om, n, u, f0, u1, f1,
                              pp, mem, gr, us, stack, g0, d0, g1, d1, 1.0, s_best, pm, TW)
    if hi < 0.0:
        return 2.0, 2.0
    for _ in range(8):
        if lo >= s_best:
            return 2.0, 2.0
        glo = _g_eval(kind, lo, cp, curved, mode, k, tau, C, S, hs, om, n, u, f0, u1, f1, pp,
                      mem, gr, us, pm, TW)[0] if lo > 0.0 else g0
        if kind == 0:  # a polynomial: Newton, its derivative is free
            lo, hi = poly_root(cp, hs, lo, hi, glo, ghi, S_TOL)
        side = 0
        for _ in range(200):
            if hi - lo <= S_TOL:
                break
            sm = illinois_point(lo, hi, glo, ghi)
            gm = _g_eval(kind, sm, cp, curved, mode, k, tau, C, S, hs, om, n, u, f0, u1, f1, pp,
                         mem, gr, us, pm, TW)[0]
            lo, hi, glo, ghi, side = illinois_update(lo, hi, glo, ghi, side, sm, gm)
        if hi - lo > S_TOL:
            return -1.0, -1.0
        if not lo > 0.0:
            break
        gl, dl = _g_eval(kind, lo, cp, curved, mode, k, tau, C, S, hs, om, n, u, f0, u1, f1,
                         pp, mem, gr, us, pm, TW)
        a2, b2, g2 = _guard_scan(kind, cp, curved, mode, k, tau, C, S, hs, om, n, u, f0, u1, f1,
                                 pp, mem, gr, us, stack, g0, d0, gl, dl, lo, lo, pm, TW)
        if b2 < 0.0:
            break
        lo, hi, ghi = a2, b2, g2
    return lo, hi


@nb.njit(cache=True)
def _series_rows(G, ng, n, ncv, no_ext, need):
    """need[i] = 1 for the rows of z = (u, 1, C, S) whose Taylor terms a full series piece of
    the mode reads: X (row 0) for its extrema, unless they are not read; the components and
    forcing terms of its affine guards (the section's row too); every row when a guard is
    curved (evaluated on the whole state). The constant's row is always written."""
    for i in range(n + 3):
        need[i] = 1.0 if (ncv > 0 or (i == 0 and not no_ext) or i == n) else 0.0
    for k in range(ng):
        for i in range(n + 3):
            if G[k, i] != 0.0:
                need[i] = 1.0
    if need[n + 2] != 0.0:
        need[n + 1] = 1.0  # (the forcing pair: one flag, need[n + 1])


@nb.njit(cache=True, inline="always")
def _n_curved(G, ng, n):
    """How many of the ng guard rows are curved."""
    c = 0
    for k in range(ng):
        if math.isnan(G[k, n]):
            c += 1
    return c


@nb.njit(cache=True, inline="always")
def _exit_tested(G, ng, n, ksec):
    """Whether a step start must test any of the ng guard rows for an immediate exit
    (``_immediate_exit_curved``): every row but a curved label, which is switched at a step's
    end (``contract``)."""
    for k in range(ng):
        if not (math.isnan(G[k, n]) and G[k, n + 1] == 1.0 and k != ksec):
            return True
    return False


@nb.njit(cache=True, inline="always")
def _finite(u, n):
    """Every one of u[0:n] is finite."""
    for i in range(n):
        if not math.isfinite(u[i]):
            return False
    return True


@nb.njit(cache=True, inline="always")
def _rotate(C, S, th):
    """(cos, sin) of the forcing phase advanced by th."""
    cw = math.cos(th)
    sw = math.sin(th)
    return C * cw - S * sw, S * cw + C * sw


@nb.njit(cache=True)
def _retake(field, pm, mode, tau, C, S, hs, om, n, u, f0, pp, mem, rtol, atol, us, k1, k2, k3,
            k4, k5, u1, f1, TW, use8, K8):
    """The step retaken from (tau, u) to tau + hs, on the RKF45 (the DOP853 with ``use8``) or
    on the piece's series (``pm``): u1 and f1 at its end; returns (err2, cos, sin) there."""
    err2 = 0.0
    if pm:
        poly_state(TW, n, hs, u1)
        C1, S1 = _rotate(C, S, om * hs)
    elif use8:
        return rk8_step(field, mode, tau, C, S, hs, om, n, u, f0, pp, mem, rtol, atol, us, K8,
                        u1, f1)
    else:
        err2, C1, S1 = _rk_step(field, mode, tau, C, S, hs, om, n, u, f0, pp, mem, rtol, atol,
                                us, k1, k2, k3, k4, k5, u1)
    field(mode, tau + hs, C1, S1, u1, pp, mem, f1)
    return err2, C1, S1


@nb.njit(cache=True, inline="always")
def _deriv(cf, field, mode, tau, C, S, u, pp, mem, f, MC, om):
    """f = du/dt in ``mode`` at (tau, u); from the closed form for a closed-form mode."""
    if cf:
        y, z = hom_part(MC, mode, om, u[0], u[1], C, S)
        f[0] = u[1]
        f[1] = accel(MC, mode, om, y, z, C, S)
    else:
        field(mode, tau, C, S, u, pp, mem, f)


@nb.njit(cache=True, inline="always")
def _store(state, u, n, mem, nmem, mode, h):
    state[ST_X] = u[0]
    state[ST_V] = u[1]
    state[ST_VA] = u[1]
    state[ST_MODE] = mode
    state[ST_H] = h
    for i in range(2, n):
        state[ST_EXTRA + i - 2] = u[i]
    for i in range(nmem):
        state[ST_EXTRA + n - 2 + i] = mem[i]


@nb.njit(cache=True, inline="always")
def _immediate_exit(G, ng, n, u, f0, C, S, om):
    """Index of the first guard with g <= 0 and moving out (g' < 0) at the step start, or -1."""
    for k in range(ng):
        if _gval(G, k, n, u, C, S) <= 0.0 and _dgval(G, k, n, f0, C, S, om) < 0.0:
            return k
    return -1


@nb.njit(cache=True, inline="always")
def _section_side(G, k, H, n, u, f, C, S, om):
    """Orientation (+-1) of the section row h = H . (u, 1, C, S) written to G[k]: the side of
    the surface the state is on, or, within round-off of the surface (|h| <= 1e-9 of the
    terms' scale: a state stopped on a crossing, a reset onto it, a section point from a Newton
    step), the side it moves to (h')."""
    for i in range(n + 3):
        G[k, i] = H[i]
    h = _gval(G, k, n, u, C, S)
    scale = abs(H[n]) + abs(H[n + 1]) + abs(H[n + 2])
    for i in range(n):  # (each coefficient counts, also where its component is 0: a surface
        scale += abs(H[i]) * (1.0 + abs(u[i]))  # through the origin, V = 0, is no exception)
    sgn = 1.0
    if abs(h) <= 1e-9 * scale:
        if _dgval(G, k, n, f, C, S, om) < 0.0:
            sgn = -1.0
    elif h < 0.0:
        sgn = -1.0
    for i in range(n + 3):
        G[k, i] = sgn * H[i]
    return sgn


@nb.njit(cache=True)
def _section_side_curved(curved, mode, tau, G, k, H, n, u, f, C, S, pp, mem, gr):
    """``_section_side`` of a curved section: writes the row H (NaN in its constant column)
    to G[k] and returns the orientation sgn (+1 where h >= 0 on the state's side, or on the
    side it moves to from the surface), which the caller passes to ``curved`` as k =
    ``contract.SECTION_K`` + (sgn < 0)."""
    for i in range(n + 3):
        G[k, i] = H[i]
    h, d = _curved_rate(curved, mode, SECTION_K, tau, C, S, n, u, f, pp, mem, gr)
    scale = abs(h)
    for i in range(n):
        scale += abs(gr[i]) * (1.0 + abs(u[i]))
    if abs(h) <= 1e-9 * scale:
        return -1.0 if d < 0.0 else 1.0
    return -1.0 if h < 0.0 else 1.0


@nb.njit(cache=True, inline="always")
def _record_crossing(U_sec, T_sec, n_sec, u, n, t):
    """A crossing of the section at time t, state u, recorded where there is room
    (``advance_tangent``): returns the new count."""
    if n_sec < U_sec.shape[0]:
        for i in range(n):
            U_sec[n_sec, i] = u[i]
        T_sec[n_sec] = t
    return n_sec + 1


@nb.njit(cache=True)
def _section_hit(curved, mode, tau, G, k, H, n, u, f, C, S, om, pp, mem, gr, kc, curv):
    """A state at a switching event on the section row k (written oriented, g = sgn h, by
    ``_section_side``: g <= 1e-9 of its terms' scale) and moving across it (g' < 0): the
    section crossed at the event's instant, e.g. a section on the guard's own surface (an
    impact map). The event's state may lie past the surface by its location's error (1e-8 on
    a long RKF45 step): a section crossed earlier in the step would have been located first,
    so g < 0 is this crossing. ``curv``: a curved section, evaluated as ``curved``'s k =
    ``kc``."""
    if curv:
        g, d = _curved_rate(curved, mode, kc, tau, C, S, n, u, f, pp, mem, gr)
        scale = abs(g)
        for i in range(n):
            scale += abs(gr[i]) * (1.0 + abs(u[i]))
    else:
        g = _gval(G, k, n, u, C, S)
        d = _dgval(G, k, n, f, C, S, om)
        scale = abs(H[n]) + abs(H[n + 1]) + abs(H[n + 2])
        for i in range(n):
            scale += abs(H[i]) * (1.0 + abs(u[i]))
    return g <= 1e-9 * scale and d < 0.0


@nb.njit(cache=True, inline="always", fastmath=_FM)
def _cf_state(MC, mode, om, y0, z0, C, S, hs, u1, f1):
    """Closed-form state at hs from the homogeneous part (y0, z0) and the forcing phase (C, S):
    writes (X, V) to u1 and (V, A) to f1; returns (cos, sin) of the forcing at the end."""
    X1, V1, A1, y1, z1, C1, S1 = eval_state(MC, mode, om, y0, z0, C, S, hs)
    u1[0] = X1
    u1[1] = V1
    f1[0] = V1
    f1[1] = A1
    return C1, S1



# ---- tangent (variational) dynamics ---------------------------------------------------------
@nb.njit(cache=True, inline="always", fastmath=_FM)
def _stage_phase(i, c2, s2, c3, s3, c4, s4, c8, s8, c12, s12):
    """(cos, sin) of the forcing-phase advance to RKF45 stage i (times 0, 1/4, 3/8, 12/13, 1,
    1/2 of the step), from ``_stage_rotations``."""
    if i == 0:
        return 1.0, 0.0
    if i == 1:
        return c2, s2
    if i == 2:
        return c3, s3
    if i == 3:
        return c12, s12
    if i == 4:
        return c8, s8
    return c4, s4


@nb.njit(cache=True, inline="always", fastmath=_FM)
def _jy2(JS, i, w0, w1, Y, c, ncm):
    """J Y of stage i for two states (``_rk_tangent2``): rows 0, 1 of the stage's Jacobian
    JS[i] on (w0, w1) and on the column's memory rows Y[2:, c]."""
    acc0 = 0.0
    acc0 += JS[i, 0, 0] * w0
    acc0 += JS[i, 0, 1] * w1
    acc1 = 0.0
    acc1 += JS[i, 1, 0] * w0
    acc1 += JS[i, 1, 1] * w1
    for q in range(ncm):
        yq = Y[2 + q, c]
        acc0 += JS[i, 0, 2 + q] * yq
        acc1 += JS[i, 1, 2 + q] * yq
    return acc0, acc1


@nb.njit(cache=True, inline="always", fastmath=_FM)
def _rk_tangent2(jacobian, mode, tau, C, S, h, om, u, k0, k1, k2, k3, k4, pp, mem, Y, J, JS, us,
                 cmi, rtol, atol):
    """``_rk_tangent`` for two states: the Jacobian at the six stage states first (into JS,
    stage x row x column: the state's two, then one per continuous memory slot), then each
    tangent column's stages with the same formulas in scalars, without the stage array KY
    (fastmath's reassociation may round them differently in the last bit)."""
    m = Y.shape[1]
    ncm = len(cmi)
    c2, s2, c3, s3, c4, s4, c8, s8, c12, s12 = _stage_rotations(om, h)
    for i in range(_NS):
        cw, sw = _stage_phase(i, c2, s2, c3, s3, c4, s4, c8, s8, c12, s12)
        a0, a1, a2, a3, a4 = _A[i, 0], _A[i, 1], _A[i, 2], _A[i, 3], _A[i, 4]
        for r in range(2):
            us[r] = u[r] + h * (a0 * k0[r] + a1 * k1[r] + a2 * k2[r] + a3 * k3[r] + a4 * k4[r])
        for q in range(ncm):
            J[0, 2 + cmi[q]] = 0.0
            J[1, 2 + cmi[q]] = 0.0
        jacobian(mode, tau + _C[i] * h, C * cw - S * sw, S * cw + C * sw, us, pp, mem, J)
        JS[i, 0, 0] = J[0, 0]
        JS[i, 0, 1] = J[0, 1]
        JS[i, 1, 0] = J[1, 0]
        JS[i, 1, 1] = J[1, 1]
        for q in range(ncm):
            JS[i, 0, 2 + q] = J[0, 2 + cmi[q]]
            JS[i, 1, 2 + q] = J[1, 2 + cmi[q]]
    err2 = 0.0
    for c in range(m):
        y0 = Y[0, c]
        y1 = Y[1, c]
        s0 = 0.0
        s1 = 0.0
        p0, p1 = _jy2(JS, 0, y0 + h * s0, y1 + h * s1, Y, c, ncm)
        s0 = 0.0
        s0 += _A[1, 0] * p0
        s1 = 0.0
        s1 += _A[1, 0] * p1
        q0, q1 = _jy2(JS, 1, y0 + h * s0, y1 + h * s1, Y, c, ncm)
        s0 = 0.0
        s0 += _A[2, 0] * p0
        s0 += _A[2, 1] * q0
        s1 = 0.0
        s1 += _A[2, 0] * p1
        s1 += _A[2, 1] * q1
        r0, r1 = _jy2(JS, 2, y0 + h * s0, y1 + h * s1, Y, c, ncm)
        s0 = 0.0
        s0 += _A[3, 0] * p0
        s0 += _A[3, 1] * q0
        s0 += _A[3, 2] * r0
        s1 = 0.0
        s1 += _A[3, 0] * p1
        s1 += _A[3, 1] * q1
        s1 += _A[3, 2] * r1
        t0, t1 = _jy2(JS, 3, y0 + h * s0, y1 + h * s1, Y, c, ncm)
        s0 = 0.0
        s0 += _A[4, 0] * p0
        s0 += _A[4, 1] * q0
        s0 += _A[4, 2] * r0
        s0 += _A[4, 3] * t0
        s1 = 0.0
        s1 += _A[4, 0] * p1
        s1 += _A[4, 1] * q1
        s1 += _A[4, 2] * r1
        s1 += _A[4, 3] * t1
        v0, v1 = _jy2(JS, 4, y0 + h * s0, y1 + h * s1, Y, c, ncm)
        s0 = 0.0
        s0 += _A[5, 0] * p0
        s0 += _A[5, 1] * q0
        s0 += _A[5, 2] * r0
        s0 += _A[5, 3] * t0
        s0 += _A[5, 4] * v0
        s1 = 0.0
        s1 += _A[5, 0] * p1
        s1 += _A[5, 1] * q1
        s1 += _A[5, 2] * r1
        s1 += _A[5, 3] * t1
        s1 += _A[5, 4] * v1
        z0, z1 = _jy2(JS, 5, y0 + h * s0, y1 + h * s1, Y, c, ncm)
        n0 = y0 + h * (_B[0] * p0 + _B[1] * q0 + _B[2] * r0 + _B[3] * t0 + _B[4] * v0
                       + _B[5] * z0)
        n1 = y1 + h * (_B[0] * p1 + _B[1] * q1 + _B[2] * r1 + _B[3] * t1 + _B[4] * v1
                       + _B[5] * z1)
        Y[0, c] = n0
        Y[1, c] = n1
        scale = 0.0
        scale = max(scale, abs(n0))
        scale = max(scale, abs(n1))
        sc = atol + rtol * scale
        e = h * (_E[0] * p0 + _E[2] * r0 + _E[3] * t0 + _E[4] * v0 + _E[5] * z0) / sc
        err2 += e * e
        e = h * (_E[0] * p1 + _E[2] * r1 + _E[3] * t1 + _E[4] * v1 + _E[5] * z1) / sc
        err2 += e * e
    return err2 / max(m * 2, 1)


@nb.njit(cache=True, inline="always", fastmath=_FM)
def _jy4(JS, i, w0, w1, w2, w3, Y, c, ncm):
    """J Y of stage i for four states (``_rk_tangent4``), as ``_jy2``."""
    acc0 = 0.0
    acc0 += JS[i, 0, 0] * w0
    acc0 += JS[i, 0, 1] * w1
    acc0 += JS[i, 0, 2] * w2
    acc0 += JS[i, 0, 3] * w3
    acc1 = 0.0
    acc1 += JS[i, 1, 0] * w0
    acc1 += JS[i, 1, 1] * w1
    acc1 += JS[i, 1, 2] * w2
    acc1 += JS[i, 1, 3] * w3
    acc2 = 0.0
    acc2 += JS[i, 2, 0] * w0
    acc2 += JS[i, 2, 1] * w1
    acc2 += JS[i, 2, 2] * w2
    acc2 += JS[i, 2, 3] * w3
    acc3 = 0.0
    acc3 += JS[i, 3, 0] * w0
    acc3 += JS[i, 3, 1] * w1
    acc3 += JS[i, 3, 2] * w2
    acc3 += JS[i, 3, 3] * w3
    for q in range(ncm):
        yq = Y[4 + q, c]
        acc0 += JS[i, 0, 4 + q] * yq
        acc1 += JS[i, 1, 4 + q] * yq
        acc2 += JS[i, 2, 4 + q] * yq
        acc3 += JS[i, 3, 4 + q] * yq
    return acc0, acc1, acc2, acc3


@nb.njit(cache=True, inline="always", fastmath=_FM)
def _rk_tangent4(jacobian, mode, tau, C, S, h, om, u, k0, k1, k2, k3, k4, pp, mem, Y, J, JS, us,
                 cmi, rtol, atol):
    """``_rk_tangent`` for four states (a rotor, two masses), as ``_rk_tangent2``: the Jacobian
    at the six stage states first, then each column's stages in scalars."""
    m = Y.shape[1]
    ncm = len(cmi)
    c2, s2, c3, s3, c4, s4, c8, s8, c12, s12 = _stage_rotations(om, h)
    for i in range(_NS):
        cw, sw = _stage_phase(i, c2, s2, c3, s3, c4, s4, c8, s8, c12, s12)
        a0, a1, a2, a3, a4 = _A[i, 0], _A[i, 1], _A[i, 2], _A[i, 3], _A[i, 4]
        for r in range(4):
            us[r] = u[r] + h * (a0 * k0[r] + a1 * k1[r] + a2 * k2[r] + a3 * k3[r] + a4 * k4[r])
        for q in range(ncm):
            for r in range(4):
                J[r, 4 + cmi[q]] = 0.0
        jacobian(mode, tau + _C[i] * h, C * cw - S * sw, S * cw + C * sw, us, pp, mem, J)
        for r in range(4):
            for q in range(4):
                JS[i, r, q] = J[r, q]
            for q in range(ncm):
                JS[i, r, 4 + q] = J[r, 4 + cmi[q]]
    err2 = 0.0
    for c in range(m):
        y0 = Y[0, c]
        y1 = Y[1, c]
        y2 = Y[2, c]
        y3 = Y[3, c]
        s0 = 0.0
        s1 = 0.0
        s2 = 0.0
        s3 = 0.0
        p0, p1, p2, p3 = _jy4(JS, 0, y0 + h * s0, y1 + h * s1, y2 + h * s2, y3 + h * s3, Y, c, ncm)
        s0 = 0.0
        s0 += _A[1, 0] * p0
        s1 = 0.0
        s1 += _A[1, 0] * p1
        s2 = 0.0
        s2 += _A[1, 0] * p2
        s3 = 0.0
        s3 += _A[1, 0] * p3
        q0, q1, q2, q3 = _jy4(JS, 1, y0 + h * s0, y1 + h * s1, y2 + h * s2, y3 + h * s3, Y, c, ncm)
        s0 = 0.0
        s0 += _A[2, 0] * p0
        s0 += _A[2, 1] * q0
        s1 = 0.0
        s1 += _A[2, 0] * p1
        s1 += _A[2, 1] * q1
        s2 = 0.0
        s2 += _A[2, 0] * p2
        s2 += _A[2, 1] * q2
        s3 = 0.0
        s3 += _A[2, 0] * p3
        s3 += _A[2, 1] * q3
        r0, r1, r2, r3 = _jy4(JS, 2, y0 + h * s0, y1 + h * s1, y2 + h * s2, y3 + h * s3, Y, c, ncm)
        s0 = 0.0
        s0 += _A[3, 0] * p0
        s0 += _A[3, 1] * q0
        s0 += _A[3, 2] * r0
        s1 = 0.0
        s1 += _A[3, 0] * p1
        s1 += _A[3, 1] * q1
        s1 += _A[3, 2] * r1
        s2 = 0.0
        s2 += _A[3, 0] * p2
        s2 += _A[3, 1] * q2
        s2 += _A[3, 2] * r2
        s3 = 0.0
        s3 += _A[3, 0] * p3
        s3 += _A[3, 1] * q3
        s3 += _A[3, 2] * r3
        t0, t1, t2, t3 = _jy4(JS, 3, y0 + h * s0, y1 + h * s1, y2 + h * s2, y3 + h * s3, Y, c, ncm)
        s0 = 0.0
        s0 += _A[4, 0] * p0
        s0 += _A[4, 1] * q0
        s0 += _A[4, 2] * r0
        s0 += _A[4, 3] * t0
        s1 = 0.0
        s1 += _A[4, 0] * p1
        s1 += _A[4, 1] * q1
        s1 += _A[4, 2] * r1
        s1 += _A[4, 3] * t1
        s2 = 0.0
        s2 += _A[4, 0] * p2
        s2 += _A[4, 1] * q2
        s2 += _A[4, 2] * r2
        s2 += _A[4, 3] * t2
        s3 = 0.0
        s3 += _A[4, 0] * p3
        s3 += _A[4, 1] * q3
        s3 += _A[4, 2] * r3
        s3 += _A[4, 3] * t3
        v0, v1, v2, v3 = _jy4(JS, 4, y0 + h * s0, y1 + h * s1, y2 + h * s2, y3 + h * s3, Y, c, ncm)
        s0 = 0.0
        s0 += _A[5, 0] * p0
        s0 += _A[5, 1] * q0
        s0 += _A[5, 2] * r0
        s0 += _A[5, 3] * t0
        s0 += _A[5, 4] * v0
        s1 = 0.0
        s1 += _A[5, 0] * p1
        s1 += _A[5, 1] * q1
        s1 += _A[5, 2] * r1
        s1 += _A[5, 3] * t1
        s1 += _A[5, 4] * v1
        s2 = 0.0
        s2 += _A[5, 0] * p2
        s2 += _A[5, 1] * q2
        s2 += _A[5, 2] * r2
        s2 += _A[5, 3] * t2
        s2 += _A[5, 4] * v2
        s3 = 0.0
        s3 += _A[5, 0] * p3
        s3 += _A[5, 1] * q3
        s3 += _A[5, 2] * r3
        s3 += _A[5, 3] * t3
        s3 += _A[5, 4] * v3
        z0, z1, z2, z3 = _jy4(JS, 5, y0 + h * s0, y1 + h * s1, y2 + h * s2, y3 + h * s3, Y, c, ncm)
        n0 = y0 + h * (_B[0] * p0 + _B[1] * q0 + _B[2] * r0 + _B[3] * t0 + _B[4] * v0 + _B[5] * z0)
        n1 = y1 + h * (_B[0] * p1 + _B[1] * q1 + _B[2] * r1 + _B[3] * t1 + _B[4] * v1 + _B[5] * z1)
        n2 = y2 + h * (_B[0] * p2 + _B[1] * q2 + _B[2] * r2 + _B[3] * t2 + _B[4] * v2 + _B[5] * z2)
        n3 = y3 + h * (_B[0] * p3 + _B[1] * q3 + _B[2] * r3 + _B[3] * t3 + _B[4] * v3 + _B[5] * z3)
        Y[0, c] = n0
        Y[1, c] = n1
        Y[2, c] = n2
        Y[3, c] = n3
        scale = 0.0
        scale = max(scale, abs(n0))
        scale = max(scale, abs(n1))
        scale = max(scale, abs(n2))
        scale = max(scale, abs(n3))
        sc = atol + rtol * scale
        e = h * (_E[0] * p0 + _E[2] * r0 + _E[3] * t0 + _E[4] * v0 + _E[5] * z0) / sc
        err2 += e * e
        e = h * (_E[0] * p1 + _E[2] * r1 + _E[3] * t1 + _E[4] * v1 + _E[5] * z1) / sc
        err2 += e * e
        e = h * (_E[0] * p2 + _E[2] * r2 + _E[3] * t2 + _E[4] * v2 + _E[5] * z2) / sc
        err2 += e * e
        e = h * (_E[0] * p3 + _E[2] * r3 + _E[3] * t3 + _E[4] * v3 + _E[5] * z3) / sc
        err2 += e * e
    return err2 / max(m * 4, 1)


@nb.njit(cache=True, inline="always", fastmath=_FM)
def _rk_tangent(jacobian, mode, tau, C, S, h, om, n, u, k0, k1, k2, k3, k4, k5, pp, mem, Y, W, KY,
                J, JS, us, cmi, rtol, atol):
    """Propagate the tangent Y (rows: u, then the continuous memory slots ``cmi``) through the
    RKF45 step just taken (its stages k0..k5, length h): the same Runge-Kutta formula applied
    to the variational equation Y' = J Y with J the model's Jacobian at each stage state, i.e.
    the exact derivative of the discrete step (internal differentiation). Memory rows are
    constant within a mode; J's columns n + slot give the field's dependence on memory.
    Returns the squared RMS norm of the step's embedded error estimate on the tangent, each
    column scaled by atol + rtol max|column| (the step-size control takes it with the state's).
    Two and four states: ``_rk_tangent2``, ``_rk_tangent4``."""
    if n == 2:
        return _rk_tangent2(jacobian, mode, tau, C, S, h, om, u, k0, k1, k2, k3, k4, pp, mem, Y,
                            J, JS, us, cmi, rtol, atol)
    if n == 4:
        return _rk_tangent4(jacobian, mode, tau, C, S, h, om, u, k0, k1, k2, k3, k4, pp, mem, Y,
                            J, JS, us, cmi, rtol, atol)
    m = Y.shape[1]
    ncm = len(cmi)
    # forcing phase at the stage times 0, 1/4, 3/8, 12/13, 1, 1/2 of the step
    c2, s2, c3, s3, c4, s4, c8, s8, c12, s12 = _stage_rotations(om, h)
    for i in range(_NS):
        cw, sw = _stage_phase(i, c2, s2, c3, s3, c4, s4, c8, s8, c12, s12)
        a0, a1, a2, a3, a4 = _A[i, 0], _A[i, 1], _A[i, 2], _A[i, 3], _A[i, 4]
        for r in range(n):  # the stage state (_A is strictly lower triangular)
            us[r] = u[r] + h * (a0 * k0[r] + a1 * k1[r] + a2 * k2[r] + a3 * k3[r] + a4 * k4[r])
        for q in range(ncm):
            for r in range(n):
                J[r, n + cmi[q]] = 0.0
        jacobian(mode, tau + _C[i] * h, C * cw - S * sw, S * cw + C * sw, us, pp, mem, J)
        tangent_stage(_A, i, h, n, J, Y, W, KY, cmi)
    b0, b1, b2, b3, b4, b5 = _B[0], _B[1], _B[2], _B[3], _B[4], _B[5]
    err2 = 0.0
    for c in range(m):
        scale = 0.0
        for r in range(n):
            Y[r, c] += h * (b0 * KY[0, r, c] + b1 * KY[1, r, c] + b2 * KY[2, r, c]
                            + b3 * KY[3, r, c] + b4 * KY[4, r, c] + b5 * KY[5, r, c])
            scale = max(scale, abs(Y[r, c]))
        sc = atol + rtol * scale
        for r in range(n):
            e = h * (_E[0] * KY[0, r, c] + _E[2] * KY[2, r, c] + _E[3] * KY[3, r, c]
                     + _E[4] * KY[4, r, c] + _E[5] * KY[5, r, c]) / sc
            err2 += e * e
    return err2 / max(m * n, 1)


@nb.njit(cache=True, inline="always", fastmath=_FM)
def _cf_tangent(MC, mode, om, h, Y, PT):
    """Y <- Phi(h) Y for a closed-form mode: Phi = exp(A h), A = [[0, 1], [-k, -c]] (the
    mode's homogeneous propagator, from the table PT for a full piece); memory rows are
    unchanged."""
    if h == MC[mode, MC_LMAX] and PT[mode, 4] == 1.0:
        eC = PT[mode, 0]
        eS = PT[mode, 1]
    else:
        eC, eS, cw, sw = propagator(MC, mode, om, h)
    a = MC[mode, MC_A]
    k = MC[mode, MC_K]
    p00 = eC - a * eS
    p11 = eC + a * eS
    p10 = -k * eS
    for c in range(Y.shape[1]):
        y0 = Y[0, c]
        y1 = Y[1, c]
        Y[0, c] = p00 * y0 + eS * y1
        Y[1, c] = p10 * y0 + p11 * y1


@nb.njit(cache=True, inline="always")
def _saltation(transition, mode, k, tau, C, S, om, n, ue, me, fm, gk, gdot, new_mode, up, mp,
               fp, pp, Y, cmi, uc, mc, ua, ma, chained, tw_last):
    """Y <- the tangent just after the transition (mode, guard k) -> new_mode at (tau, ue, me).

    For a column w = (w_u, w_m) the perturbed trajectory meets the surface g_k = 0 a time
    tau_w = -(grad g_k . w_u) / g' later (g' = d g_k / dt along the old field fm), at the state
    ue + w_u + fm tau_w; the transition R (reset and memory writes) maps that point, and the
    result is carried back by -tau_w along the new field fp:

        w_u+ = D R (w_u + fm tau_w, w_m, tau_w) - fp tau_w,   w_m+ = D R_mem (...)

    which is the saltation matrix I + (fp - fm) grad^T / g' for a switch without reset, and
    the reset's Jacobian with its correction for an impact. D R along that direction (which
    lies in the surface) is a central difference of the model's ``transition`` (exact for the
    affine resets of the built-in models); a one-sided difference is used where the other side
    leaves for another mode (up, mp: the state and memory after the actual transition).

    A transition with g' >= 0 is not a transversal crossing but a round-off exit (e.g. a frozen
    state a hair outside its band, found at a step end): its time is set by the step grid,
    not by the state, so tau_w = 0 there; except when it is ``chained`` to a transition at the
    same instant (a tangential exit through a surface the state sits on, e.g. a frozen stick
    velocity on its band edge leaving the band as soon as the friction saturates): every
    nearby trajectory then leaves at once too, so its time shift is that of the transition
    before (``tw_last``, per column, updated here). Returns False if the new tangent is not finite (a
    grazing touch, g' -> 0-, makes the saltation unbounded)."""
    ncm = len(cmi)
    scale = 1.0
    for i in range(n):
        scale = max(scale, abs(ue[i]))
    for c in range(Y.shape[1]):
        tw = 0.0
        for i in range(n):
            tw += gk[i] * Y[i, c]
        gn = 0.0
        if chained:
            for i in range(n):
                gn += abs(gk[i] * fm[i])
        if chained and not gdot < -1e-6 * gn:
            tw = tw_last[c]
        else:
            tw = -tw / gdot if gdot < 0.0 else 0.0
        tw_last[c] = tw
        dn = abs(tw) * om
        for i in range(n):
            dn = max(dn, abs(Y[i, c] + fm[i] * tw))
        for q in range(ncm):
            dn = max(dn, abs(Y[n + q, c]))
        if dn == 0.0:
            continue
        eps = 1e-7 * scale / dn
        ok_side = 0
        cw = math.cos(om * eps * tw)  # the phase's rotation by om e tw, e = +-eps (cos is
        sp = math.sin(om * eps * tw)  # even and sin odd, bit for bit)
        for side in (1.0, -1.0):
            e = side * eps
            for i in range(n):
                uc[i] = ue[i] + e * (Y[i, c] + fm[i] * tw)
            for i in range(len(me)):
                mc[i] = me[i]
            for q in range(ncm):
                mc[cmi[q]] += e * Y[n + q, c]
            sw = side * sp
            got = transition(mode, k, tau + e * tw, C * cw - S * sw, S * cw + C * sw, uc, pp, mc)
            if side > 0.0:
                for i in range(n):
                    ua[i] = uc[i]
                for q in range(ncm):
                    ma[q] = mc[cmi[q]]
                if got == new_mode:
                    ok_side += 1
            elif got == new_mode:
                ok_side += 2
        # derivative of R along the direction: central, else one-sided against the actual R
        for i in range(n):
            if ok_side == 3 or ok_side == 0:
                d = (ua[i] - uc[i]) / (2.0 * eps)
            elif ok_side == 1:
                d = (ua[i] - up[i]) / eps
            else:
                d = (up[i] - uc[i]) / eps
            Y[i, c] = d - fp[i] * tw
        for q in range(ncm):
            if ok_side == 3 or ok_side == 0:
                d = (ma[q] - mc[cmi[q]]) / (2.0 * eps)
            elif ok_side == 1:
                d = (ma[q] - mp[cmi[q]]) / eps
            else:
                d = (mp[cmi[q]] - mc[cmi[q]]) / eps
            Y[n + q, c] = d
    for c in range(Y.shape[1]):
        for i in range(Y.shape[0]):
            if not math.isfinite(Y[i, c]):
                return False
    return True


@nb.njit(cache=True, fastmath=_FM)
def _qr_logs(Y, out, row):
    """Modified Gram-Schmidt (twice) of the columns of Y in place; log of the norms -> out[row]
    when row >= 0 (Benettin's re-orthonormalisation)."""
    N, m = Y.shape
    for c in range(m):
        for _ in range(2):
            for q in range(c):
                d = 0.0
                for i in range(N):
                    d += Y[i, q] * Y[i, c]
                for i in range(N):
                    Y[i, c] -= d * Y[i, q]
        nr = 0.0
        for i in range(N):
            nr += Y[i, c] * Y[i, c]
        nr = math.sqrt(nr)
        if row >= 0:
            out[row, c] = math.log(nr) if nr > 0.0 else -np.inf
        if nr > 0.0:
            for i in range(N):
                Y[i, c] /= nr


@nb.njit(cache=True, fastmath=_FM)
def _advance(fns, p, opts, state, per_period, n_skip, n_out, X_out, V_out, R_out, M_out,
             Xmax_out, Xmin_out, Y, L_out, cmi, qr, U_out, H, SEC, U_sec, T_sec):
    field, jacobian, guards, transition, initial, linear, curved = fns
    tan = Y.shape[1] > 0
    # a section surface h = H . (u, 1, cos, sin) = 0 (``advance_tangent``): an extra guard row
    # whose crossings are recorded, never a transition (its sign flips at each crossing)
    has_sec = H.shape[0] > 0
    csec = has_sec and math.isnan(H[int(opts[OPT_N])])  # a curved section (SECTION_K)
    n = int(opts[OPT_N])
    nmem = int(opts[OPT_NMEM])
    if n < 2 or nmem < 0 or n - 2 + nmem > N_STATE - ST_EXTRA:
        return st.NON_FINITE
    # every work array is a view into one workspace, without reference counting (see
    # ``workspace``). numba frees ``ws`` after its last use on each path, so the rule is: a
    # path that reads a view after ``ws`` was made ends with ``keep_alive(ws)`` (the main loop's
    # end, the early returns after ``_store``); a return before any later read needs nothing
    nt = n if tan else 0  # tangent work arrays are empty without a tangent
    mt = Y.shape[1]
    nme = max(nmem, 1)
    nj = n + nmem if tan else 0
    nlin = max(4, n * n + 3 * n)  # a ``linear`` row: (k, c, b, F), or (A, b, f_c, f_s)
    m3 = n + 3
    sizes = (len(p), 26 * n, nme, MAX_GUARDS * (n + 3), MAX_MODES * (N_MC + 7), nlin,
             N_BD * (1 + MAX_GUARDS), (SCAN_DEPTH + 1) * 5, N_STAGES8 * nt * mt, 6 * nt + nt * nj,
             _NS * nt * nj if nt == 2 or nt == 4 else 0,
             2 * nme if tan else 0, len(cmi), mt, n + 1,
             MAX_MODES + (N_TAYLOR + 1) * (m3 + 1) + n * n + n
             + MAX_MODES * (n * m3 + 1) + 2 * m3
             + MAX_MODES * (CF_SLOTS * MAX_GUARDS * (N_BD + m3) + CF_SLOTS + 1)
             + 2 * MAX_GUARDS)
    total = 0
    for z in sizes:
        total += z
    npw = MAX_MODES * (N_TAYLOR + 1) * m3 * m3  # the series' matrices: filled before use
    ws = np.empty(total + npw)
    ws[:total] = 0.0
    o = 0
    pp = view(ws, o, (len(p),))
    o += len(p)
    rows = view(ws, o, (10, n))  # the rows of a view are views too
    u, u1, f0, f1, us = rows[0], rows[1], rows[2], rows[3], rows[4]
    k1, k2, k3, k4, k5 = rows[5], rows[6], rows[7], rows[8], rows[9]
    o += 10 * n
    K8 = view(ws, o, (16, n))  # DOP853: 12 stages, the field at the end, 3 dense stages
    o += 16 * n
    mem = view(ws, o, (nme,))
    o += nme
    G = view(ws, o, (MAX_GUARDS, n + 3))
    o += MAX_GUARDS * (n + 3)
    MC = view(ws, o, (MAX_MODES, N_MC))
    o += MAX_MODES * N_MC
    MF = view(ws, o, (MAX_MODES,))
    o += MAX_MODES
    PT = view(ws, o, (MAX_MODES, 5))  # propagator of a full piece per mode (5: computed)
    o += MAX_MODES * 5
    mcs = view(ws, o, (MAX_MODES,))  # class of each mode (_MC_*), 0 = not known yet
    o += MAX_MODES
    lin = view(ws, o, (nlin,))
    o += nlin
    BD = view(ws, o, (N_BD,))
    o += N_BD
    GB = view(ws, o, (MAX_GUARDS, N_BD))  # bound coefficients of the guards of a closed form
    o += MAX_GUARDS * N_BD
    stack = view(ws, o, (SCAN_DEPTH + 1, 5))
    o += (SCAN_DEPTH + 1) * 5
    KY = view(ws, o, (N_STAGES8, nt, mt))  # the tangent's stages (RKF45: the first 6)
    o += N_STAGES8 * nt * mt
    rows = view(ws, o, (6, nt))
    W, ue, fm, gk, uc, ua = rows[0], rows[1], rows[2], rows[3], rows[4], rows[5]
    J = view(ws, o + 6 * nt, (nt, nj))
    o += 6 * nt + nt * nj
    njs = nt if nt == 2 or nt == 4 else 0
    JS = view(ws, o, (_NS, njs, nj))  # the Jacobian at the stages of a 2- or 4-state tangent step
    o += _NS * njs * nj
    nmt = nme if tan else 0
    me = view(ws, o, (nmt,))
    mc = view(ws, o + nmt, (nmt,))
    o += 2 * nmt
    ma = view(ws, o, (len(cmi),))
    o += len(cmi)
    tw_last = view(ws, o, (mt,))
    o += mt
    gr = view(ws, o, (n + 1,))  # gradient of a curved guard
    o += n + 1
    MXR = view(ws, o, (MAX_MODES,))  # rate rho of each _MC_POLY mode (piece: THETA_POLY / rho)
    o += MAX_MODES
    TW = view(ws, o, (m3, N_TAYLOR + 1))  # the Taylor terms of the current piece (a row each)
    o += (N_TAYLOR + 1) * m3
    cp = view(ws, o, (N_TAYLOR + 1,))  # a guard as a polynomial on the piece
    o += N_TAYLOR + 1
    PE = view(ws, o, (n, n))  # exp(A h) of a series piece, for the tangent
    pt = view(ws, o + n * n, (n,))
    o += n * n + n
    PF = view(ws, o, (MAX_MODES, n, m3))  # exp(M L) of a full series piece, state rows
    o += MAX_MODES * n * m3
    PFR = view(ws, o, (MAX_MODES,))  # 1: PF[mode] computed
    o += MAX_MODES
    need = view(ws, o, (m3,))  # the rows of the Taylor terms a full series piece needs
    ALL = view(ws, o + m3, (m3,))  # every row (a piece cut short, retaken, the last)
    o += 2 * m3
    # the bound coefficients of the last guard sets of each closed-form mode
    GBC = view(ws, o, (MAX_MODES, CF_SLOTS, MAX_GUARDS, N_BD))
    o += MAX_MODES * CF_SLOTS * MAX_GUARDS * N_BD
    GKC = view(ws, o, (MAX_MODES, CF_SLOTS, MAX_GUARDS, m3))
    o += MAX_MODES * CF_SLOTS * MAX_GUARDS * m3
    GNC = view(ws, o, (MAX_MODES, CF_SLOTS + 1))
    o += MAX_MODES * (CF_SLOTS + 1)
    # each affine guard's g and g' at the step's end, which are those at the next step's start
    # while ``gv`` (an accepted step without a switch in a mode whose guards are all affine and
    # not a series piece's: the state, its derivative and the phase are copied from the end);
    # in a mode with curved guards, a curved label's g and g' at the step's end, the next
    # step's start while ``lv`` and that start is the time they were taken at (``t_lv``)
    gc = view(ws, o, (MAX_GUARDS,))
    dc = view(ws, o + MAX_GUARDS, (MAX_GUARDS,))
    PW = view(ws, total, (MAX_MODES, m3 * m3, N_TAYLOR + 1))  # M^j / j! of each _MC_POLY mode
    if o + 2 * MAX_GUARDS != total:  # the views above and ``sizes`` must agree (views are not
        return st.NON_FINITE  # bounds-checked); a mismatch is a bug of this function (tests)
    pp[:] = p
    ALL[:] = 1.0
    Y = unowned(Y)  # owned by the caller for the whole call
    L_out = unowned(L_out)
    cmi = unowned(cmi)
    om = frame_omega(pp, opts)
    if not (om > 0.0 and math.isfinite(om)):
        return st.NON_FINITE
    rtol = opts[OPT_RTOL]
    atol = opts[OPT_ATOL]
    closed = opts[OPT_CLOSED_FORM] == 1.0
    # a tight tolerance integrates by DOP853 (``rk8``), its tangent too, unless the method says
    use8 = rtol < HI_ORDER_RTOL and opts[OPT_NO_DOP853] != 1.0
    no_ext = opts.shape[0] > OPT_NO_EXTREMA and opts[OPT_NO_EXTREMA] == 1.0
    om4 = (om * om) * (om * om)
    for q in range(len(cmi)):
        if cmi[q] < 0 or cmi[q] >= nmem:
            return st.NON_FINITE

    u[0] = state[ST_X]
    u[1] = state[ST_V]
    for i in range(2, n):
        u[i] = state[ST_EXTRA + i - 2]
    for i in range(nmem):
        mem[i] = state[ST_EXTRA + n - 2 + i]
    mode = int(state[ST_MODE])
    h = state[ST_H]
    if not _finite(u, n):
        return st.NON_FINITE

    T = 2.0 * math.pi / om
    dt = T / per_period
    if not h > 0.0:
        h = min(1e-3 * T, dt)
    hmin = 1e-14 * T
    zeno_dt = ZENO_DT * T
    n_total = n_skip + n_out
    max_steps = int(opts[OPT_MAX_STEPS] * (n_total / per_period + 1.0))

    # the section's forcing phase: every period starts at t0 = psi / omega (0: the default,
    # bit for bit the arithmetic without a phase)
    psi = opts[OPT_PHASE]
    t0 = psi / om
    C0 = math.cos(psi) if psi != 0.0 else 1.0
    S0 = math.sin(psi) if psi != 0.0 else 0.0
    code = st.OK
    if mode < 0:
        mode = initial(C0, S0, u, pp, mem)
    if mode < 0 or mode >= MAX_MODES:
        _store(state, u, n, mem, nmem, mode, h)
        keep_alive(ws)
        return st.EVENT_FAILED
    ng = min(max(guards(mode, pp, mem, G), 0), MAX_GUARDS)
    ncv = _n_curved(G, ng, n)
    sgn = 1.0  # orientation of the section row: g = sgn h >= 0 on the side the state is on
    ksec = -1
    n_sec = 0
    t_done = 0.0  # time of the periods this call has completed
    if has_sec:
        if ng >= MAX_GUARDS:
            _store(state, u, n, mem, nmem, mode, h)
            keep_alive(ws)
            return st.EVENT_FAILED
        field(mode, t0, C0, S0, u, pp, mem, f0)  # (f0 is computed again below)
        if csec:
            sgn = _section_side_curved(curved, mode, t0, G, ng, H, n, u, f0, C0, S0, pp, mem,
                                       gr)
            ncv += 1
        else:
            sgn = _section_side(G, ng, H, n, u, f0, C0, S0, om)
        ksec = ng
        ng += 1
    imm = _exit_tested(G, ng, n, ksec)
    cls = _mode_class(linear, closed, mode, pp, lin, MC, mcs, om, MF, n, MXR, PW)
    if cls == _MC_RESONANT:
        _store(state, u, n, mem, nmem, mode, h)
        keep_alive(ws)
        return st.RESONANCE
    cf, pm = _paths(cls, ncv, u[1], MC, mode)
    if pm:
        _series_rows(G, ng, n, ncv, no_ext, need)
    if cf:
        _cf_bounds(MC, mode, om, G, ng, n, GB)

    tau = t0
    C = C0
    S = S0
    _deriv(cf, field, mode, tau, C, S, u, pp, mem, f0, MC, om)
    steps = 0
    rejected = False
    n_tiny = 0
    t_switch = -1e300
    gv = False
    lv = False
    t_lv = 0.0
    tw_all = True
    j = 0
    for it in range(n_total):
        j += 1
        t_end = t0 + (T if j == per_period else j * dt)
        xmax = u[0]
        xmin = u[0]
        mask = 1 << mode
        while tau < t_end:
            # ---- immediate exit at the step start: g <= 0 and moving out ----
            if gv:
                k_tr = -1
                for k in range(ng):
                    if gc[k] <= 0.0 and dc[k] < 0.0:
                        k_tr = k
                        break
            elif ncv == 0:
                k_tr = _immediate_exit(G, ng, n, u, f0, C, S, om)
            elif not imm:
                k_tr = -1  # (curved labels only)
            else:
                k_tr = _immediate_exit_curved(curved, mode, tau, G, ng, n, u, f0, C, S, om, pp,
                                              mem, gr, ksec, SECTION_K + (sgn < 0.0))
            if k_tr < 0:
                if steps >= max_steps:
                    code = st.MAX_STEPS
                    break
                steps += 1
                rem = t_end - tau
                y0 = 0.0
                z0 = 0.0
                err2 = 0.0
                pd = False  # a DOP853 step with its dense output in TW
                if cf:
                    Lm = MC[mode, MC_LMAX]
                    last = Lm >= rem
                    hs = rem if last else Lm
                    y0, z0 = hom_part(MC, mode, om, u[0], u[1], C, S)
                    if last:
                        X1, V1, A1, y1, z1, C1, S1 = eval_state(MC, mode, om, y0, z0, C, S, hs)
                    else:  # a full piece: its propagator is the same every time
                        if PT[mode, 4] == 0.0:
                            PT[mode, 0], PT[mode, 1], PT[mode, 2], PT[mode, 3] = propagator(
                                MC, mode, om, hs)
                            PT[mode, 4] = 1.0
                        X1, V1, A1, y1, z1, C1, S1 = apply_propagator(
                            MC, mode, om, y0, z0, C, S, PT[mode, 0], PT[mode, 1], PT[mode, 2],
                            PT[mode, 3])
                    if not (math.isfinite(X1) and math.isfinite(V1)):
                        code = st.NON_FINITE
                        break
                    u1[0] = X1
                    u1[1] = V1
                    f1[0] = V1
                    f1[1] = A1
                elif pm:  # a linear mode of any dimension: the series of exp(M s)
                    Lm = THETA_POLY / MXR[mode]
                    last = Lm >= rem
                    hs = rem if last else Lm
                    tw_all = last
                    taylor_terms(PW[mode], n, u, C, S, TW, ALL if last else need)
                    if last:
                        poly_state(TW, n, hs, u1)
                    else:  # a full piece: its end from exp(M L), the same every time
                        if PFR[mode] == 0.0:
                            series_propagator(PW[mode], n, Lm, PF[mode])
                            PFR[mode] = 1.0
                        propagate_state(PF[mode], n, u, C, S, u1)
                    C1, S1 = _rotate(C, S, om * hs)
                    if not _finite(u1, n):
                        code = st.NON_FINITE
                        break
                    field(mode, tau + hs, C1, S1, u1, pp, mem, f1)
                else:
                    last = h >= rem * 0.999
                    hs = rem if last else h
                    if use8 and om * hs > THETA_POLY:  # (its forcing's series on the piece)
                        hs = THETA_POLY / om
                        last = False
                    if use8:  # (f1 too)
                        err2, C1, S1 = rk8_step(field, mode, tau, C, S, hs, om, n, u, f0, pp,
                                                mem, rtol, atol, us, K8, u1, f1)
                    else:
                        err2, C1, S1 = _rk_step(field, mode, tau, C, S, hs, om, n, u, f0, pp,
                                                mem, rtol, atol, us, k1, k2, k3, k4, k5, u1)
                    if not err2 <= 1.0:
                        h, finite = shrink_step(err2, hs, EXPO8) if use8 else _shrink(err2, hs)
                        rejected = True
                        if h < hmin:
                            code = st.STEP_TOO_SMALL if finite else st.NON_FINITE
                            break
                        continue
                    if use8:  # its dense output: the step is a polynomial piece for the
                        rk8_dense(field, mode, tau, C, S, hs, om, n, u, u1, f1, pp, mem, us, K8,
                                  TW)  # guards and extrema, as a series piece
                        pd = True
                    else:
                        field(mode, tau + hs, C1, S1, u1, pp, mem, f1)

                # ---- exit test for every guard; earliest crossing located by Illinois ----
                s_best = 2.0
                s_lo = 0.0  # the located crossing lies in [s_lo, s_best] (fractions)
                En = -1.0  # energy norm of a closed-form piece, when needed
                dip_k = -1  # a label passed and re-crossed inside the step (its fraction)
                dip_s = 2.0
                for k in range(ng):
                    curv = ncv > 0 and math.isnan(G[k, n])
                    if curv and G[k, n + 1] == 1.0 and k != ksec:
                        # a label (``contract``): the mode switches at the step's end if it
                        # ends past it; a pass and return inside the step that the Hermite of
                        # (g, g') at the step's ends shows is only a visit of the mode across
                        # (the visited mask), not a switch
                        # (the start's g and g': the last step's end, kept while ``lv``)
                        g0 = gc[k]
                        d0 = dc[k]
                        g1, d1 = _curved_rate(curved, mode, k, tau + hs, C1, S1, n, u1, f1, pp,
                                              mem, gr)
                        gc[k] = g1
                        dc[k] = d1
                        if g1 < 0.0:
                            if 1.0 < s_best:
                                s_best = 1.0
                                s_lo = 1.0
                                k_tr = k
                        else:
                            if not (lv and tau == t_lv):
                                g0, d0 = _curved_rate(curved, mode, k, tau, C, S, n, u, f0, pp,
                                                      mem, gr)
                            b1, b2, b3 = herm_coeffs(max(g0, 0.0), d0, g1, d1, hs)
                            r1, r2 = quad_roots01(b1, 2.0 * b2, 3.0 * b3)
                            for q in (r1, r2):
                                if 0.0 < q < min(dip_s, 1.0) and 2.0 * b2 + 6.0 * b3 * q > 0.0 \
                                        and max(g0, 0.0) + q * (b1 + q * (b2 + q * b3)) < 0.0:
                                    dip_s = q
                                    dip_k = k
                        continue
                    if pm or pd or curv:  # a polynomial guard (a series piece, a DOP853
                        if not curv:  # step's dense output), or a curved one
                            guard_poly(G, k, n, TW, cp)
                        kc = SECTION_K + (sgn < 0.0) if k == ksec else k  # (curved section)
                        lo, hi = _guard_exit(1 if curv else 0, cp, curved, mode, kc, tau, C, S,
                                             hs, om, n, u, f0, u1, f1, pp, mem, gr, us, stack,
                                             s_best, 2 if pd else (1 if pm else 0), TW)
                        if hi < 0.0:
                            code = st.EVENT_FAILED
                            break
                        if hi < s_best:
                            s_best = hi
                            s_lo = lo
                            k_tr = k
                        continue
                    if gv:
                        g0 = gc[k]
                        d0 = dc[k]
                    else:
                        g0 = _gval(G, k, n, u, C, S)
                        d0 = _dgval(G, k, n, f0, C, S, om)
                    if g0 < 0.0:
                        g0 = 0.0  # round-off after the switch into this mode (d0 >= 0 here)
                    g1 = _gval(G, k, n, u1, C1, S1)
                    d1 = _dgval(G, k, n, f1, C1, S1, om)
                    gc[k] = g1
                    dc[k] = d1
                    hi = 2.0
                    ghi = 0.0
                    if g1 < 0.0:
                        hi = 1.0
                        ghi = g1
                    # certified where g along the step is not a cubic: on a closed-form piece,
                    # and for guards with forcing terms. Otherwise g on the step's interpolant
                    # is the Hermite of (g, g'), and a Hermite that stays clear of zero by the
                    # bound of its derivative basis functions (4/27) has no negative minimum
                    # (on a closed-form piece: less the Hermite's error bound, also certified)
                    cert = cf or G[k, n + 1] != 0.0 or G[k, n + 2] != 0.0
                    M4 = 0.0  # bound of |g''''| over a closed-form piece
                    if hi > 1.0 and (cf or not cert):
                        sl = hs * (abs(d0) + abs(d1))
                        err = 0.0
                        if cf:  # the guard's bound coefficients are those of the mode entry
                            if En < 0.0:
                                En = energy_norm(MC, mode, y0, z0)
                            M4 = GB[k, BD_D4] * En + om4 * GB[k, BD_R]
                            err = HERM_ERR * M4 * ((hs * hs) * (hs * hs))
                        if min(g0, g1) - _HERM_SLOPE * sl - err > 1e-9 * (abs(g0) + abs(g1)
                                                                          + sl):
                            continue
                    q0 = 0.0
                    q1 = 0.0
                    q2 = 0.0
                    q3 = 0.0
                    if not cf:  # projection of the state's cubic Hermite on the guard (after
                        for i in range(n):  # the test above, which most steps pass)
                            du = u1[i] - u[i]
                            q0 += G[k, i] * u[i]
                            q1 += G[k, i] * (hs * f0[i])
                            q2 += G[k, i] * (3.0 * du - 2.0 * hs * f0[i] - hs * f1[i])
                            q3 += G[k, i] * (-2.0 * du + hs * f0[i] + hs * f1[i])
                    b1, b2, b3 = herm_coeffs(g0, d0, g1, d1, hs)
                    r1, r2 = quad_roots01(b1, 2.0 * b2, 3.0 * b3)
                    for q in (r1, r2):
                        if 0.0 < q < hi and 2.0 * b2 + 6.0 * b3 * q > 0.0:  # a minimum
                            gq = _g_at(cf, q, G, k, n, q0, q1, q2, q3, C, S, om, hs, MC, mode,
                                       y0, z0)
                            if gq < 0.0:
                                hi = q
                                ghi = gq
                    # certified: the Hermite of (g, g') is within HERM_ERR M4 hs^4 of g and a
                    # step it does not clear is scanned (``_scan_step``)
                    if cert and hi > 1.0:
                        hm = min(g0, g1)
                        for q in (r1, r2):
                            if 0.0 < q < 1.0:
                                hm = min(hm, g0 + q * (b1 + q * (b2 + q * b3)))
                        if not cf:  # (on a closed-form piece M4 is known from above)
                            M4 = _guard_bounds(cf, G, k, n, q2, q3, om, hs, MC, mode, y0, z0,
                                               BD)[2]
                        if not (hm > HERM_ERR * M4 * ((hs * hs) * (hs * hs))
                                or herm_clear(g0, d0, g1, d1, hs, M4)):
                            hi, ghi = _scan_step(cf, g0, d0, g1, d1, u, f0, u1, f1, C, S, C1, S1,
                                                 G, k, n, q0, q1, q2, q3, om, hs, MC, mode, y0,
                                                 z0, MF[mode], stack, GB[k])
                    if hi > 1.0:
                        continue
                    if hi > s_best:
                        gb = _g_at(cf, s_best, G, k, n, q0, q1, q2, q3, C, S, om, hs, MC, mode,
                                   y0, z0)
                        if gb >= 0.0:
                            continue
                        hi = s_best
                        ghi = gb
                    lo, hi = _locate(cf, 0.0, hi, g0, ghi, G, k, n, q0, q1, q2, q3, C, S, om,
                                     hs, MC, mode, y0, z0, MF[mode])
                    if cert and lo > 0.0:  # the first crossing, not a later one
                        lo, hi = _first_crossing(cf, lo, hi, g0, d0, u, f0, C, S, G, k, n, q0,
                                                 q1, q2, q3, om, hs, MC, mode, y0, z0, MF[mode],
                                                 stack, GB[k])
                    if hi - lo > S_TOL:
                        code = st.EVENT_FAILED
                        break
                    if hi < s_best:
                        s_best = hi
                        s_lo = lo
                        k_tr = k
                if code != st.OK:
                    break
                if dip_k >= 0 and dip_s < s_best:  # the mode across the label: visited
                    for i in range(n):
                        us[i] = u1[i]  # (a label resets nothing: a copy for the call)
                    Cd, Sd = _rotate(C, S, om * (dip_s * hs))
                    dm = transition(mode, dip_k, tau + dip_s * hs, Cd, Sd, us, pp, mem)
                    if 0 <= dm < MAX_MODES:
                        mask |= 1 << dm

                if k_tr >= 0:
                    if s_best < 1.0:  # retake the step exactly up to the crossing
                        hs = s_best * hs
                        last = False
                        if cf:
                            C1, S1 = _cf_state(MC, mode, om, y0, z0, C, S, hs, u1, f1)
                        else:
                            if pm and not tw_all:  # (the rows a full piece did not need)
                                taylor_terms(PW[mode], n, u, C, S, TW, ALL)
                                tw_all = True
                            err2, C1, S1 = _retake(field, pm, mode, tau, C, S, hs, om, n, u, f0,
                                                   pp, mem, rtol, atol, us, k1, k2, k3, k4, k5,
                                                   u1, f1, TW, use8, K8)
                            if ncv > 0 and math.isnan(G[k_tr, n]):
                                # a curved guard: Newton on the true g of the retaken step's
                                # end (the interpolant is a cubic, the step 5th order), kept
                                # within the located bracket (and 1e-4 of the step around
                                # it) and only while |g| decreases
                                hs_full = hs / s_best
                                t_lo = max(s_lo - 1e-4, 0.0) * hs_full
                                t_hi = min(s_best + 1e-4, 1.0) * hs_full
                                kc = SECTION_K + (sgn < 0.0) if k_tr == ksec else k_tr
                                gn, dn = _curved_rate(curved, mode, kc, tau + hs, C1, S1, n,
                                                      u1, f1, pp, mem, gr)
                                for _ in range(4):
                                    if not dn < 0.0:
                                        break
                                    dh = -gn / dn
                                    if not (abs(dh) > 1e-15 * hs and t_lo < hs + dh < t_hi):
                                        break
                                    h_old = hs
                                    hs += dh
                                    err2, C1, S1 = _retake(field, pm, mode, tau, C, S, hs, om, n,
                                                           u, f0, pp, mem, rtol, atol, us, k1,
                                                           k2, k3, k4, k5, u1, f1, TW, use8, K8)
                                    g2, d2 = _curved_rate(curved, mode, kc, tau + hs, C1, S1,
                                                          n, u1, f1, pp, mem, gr)
                                    if not abs(g2) < abs(gn):  # no better: back, and stop
                                        hs = h_old
                                        err2, C1, S1 = _retake(field, pm, mode, tau, C, S, hs,
                                                               om, n, u, f0, pp, mem, rtol,
                                                               atol, us, k1, k2, k3, k4, k5,
                                                               u1, f1, TW, use8, K8)
                                        break
                                    gn, dn = g2, d2
                        if not math.isfinite(u1[0]):
                            code = st.NON_FINITE
                            break
                errY2 = 0.0
                if tan:
                    if cf:
                        if cls != _MC_DRIFT:  # (a drift's propagator is the identity)
                            _cf_tangent(MC, mode, om, hs, Y, PT)
                    elif pm:
                        if PFR[mode] == 1.0 and hs == THETA_POLY / MXR[mode]:  # a full piece
                            poly_tangent(PW[mode], n, hs, Y, PF[mode], pt, True)
                        else:
                            poly_tangent(PW[mode], n, hs, Y, PE, pt, False)
                    elif use8:
                        errY2 = rk8_tangent(jacobian, mode, tau, C, S, hs, om, n, u, K8, pp, mem,
                                            Y, W, KY, J, us, cmi, rtol, atol)
                    else:
                        errY2 = _rk_tangent(jacobian, mode, tau, C, S, hs, om, n, u, f0, k1, k2,
                                            k3, k4, k5, pp, mem, Y, W, KY, J, JS, us, cmi,
                                            rtol, atol)
                # (a label's switch at the step's end leaves the step whole: it is controlled)
                lab_end = k_tr >= 0 and ncv > 0 and math.isnan(G[k_tr, n]) \
                    and G[k_tr, n + 1] == 1.0 and k_tr != ksec
                if (k_tr < 0 or lab_end) and not cf and not pm:
                    # step-size control after an accepted step without a switch; with tangent
                    # vectors, also by their error (at rest the state's estimate is 0, and a
                    # step of a whole period would give the tangent of the RK polynomial)
                    if use8:
                        h = control_step(max(err2, errY2), hs, h, last, rejected, EXPO8)
                    else:
                        h = _control(max(err2, errY2), hs, h, last, rejected)
                    rejected = False
                if no_ext:
                    pass  # (OPT_NO_EXTREMA: the outputs are not read)
                elif cf:
                    xmax, xmin = _x_extrema_exact(MC, mode, om, MF[mode], y0, z0, C, S, u[0],
                                                  u[1], u1[0], u1[1], hs, xmax, xmin, BD)
                elif pm:
                    xmax, xmin = poly_x_extrema(TW, hs, xmax, xmin, cp, MXR[mode])
                elif pd:  # the DOP853 step's dense output, sampled as a series piece
                    xmax, xmin = poly_x_extrema(TW, hs, xmax, xmin, cp, THETA_POLY / hs)
                else:
                    xmax, xmin = _x_extrema(u[0], f0[0], u1[0], f1[0], hs, xmax, xmin)
                for i in range(n):
                    u[i] = u1[i]
                    f0[i] = f1[i]
                C = C1
                S = S1
                gv = k_tr < 0 and not pm and not pd and ncv == 0
                # (a visit across a label called ``transition``, which may write mem)
                lv = k_tr < 0 and ncv > 0 and not (dip_k >= 0 and dip_s < s_best)
                t_lv = tau + hs
                tau = t_end if last else tau + hs
                xmax = max(xmax, u[0])
                xmin = min(xmin, u[0])
            if k_tr >= 0:
                gv = False  # a reset, or the section row flips
                lv = False
            if k_tr >= 0 and k_tr == ksec:
                # ---- a crossing of the section surface: record it, flip the row ----
                if SEC[0] == 0.0 or SEC[0] == -sgn:
                    n_sec = _record_crossing(U_sec, T_sec, n_sec, u, n, t_done + (tau - t0))
                sgn = -sgn
                for i in range(n + 3):
                    G[ksec, i] = -G[ksec, i]
                if cf:
                    _cf_bounds(MC, mode, om, G, ng, n, GB)
                if SEC[1] > 0.0 and n_sec >= SEC[1]:
                    SEC[3] = t_done + (tau - t0)
                    break
                continue
            if k_tr >= 0:
                # ---- transition through guard k_tr at (tau, u) ----
                gdot = 0.0
                old_mode = mode
                label = ncv > 0 and math.isnan(G[k_tr, n]) and G[k_tr, n + 1] == 1.0
                if has_sec and _section_hit(curved, mode, tau, G, ksec, H, n, u, f0, C, S, om,
                                            pp, mem, gr, SECTION_K + (sgn < 0.0), csec):
                    # the section's surface reached at this switching event (a section on the
                    # guard's own surface: an impact map): a crossing, with the state before
                    # the transition, which the reset would otherwise hide; a stop there is
                    # made before the transition (the next run takes it at its start)
                    if SEC[0] == 0.0 or SEC[0] == -sgn:
                        n_sec = _record_crossing(U_sec, T_sec, n_sec, u, n,
                                                 t_done + (tau - t0))
                        if SEC[1] > 0.0 and n_sec >= SEC[1]:
                            SEC[3] = t_done + (tau - t0)
                            break
                if tan and not label:
                    for i in range(n):
                        ue[i] = u[i]
                        fm[i] = f0[i]
                        gk[i] = G[k_tr, i]
                    for i in range(len(mem)):
                        me[i] = mem[i]
                    if math.isnan(G[k_tr, n]):
                        gdot = _curved_rate(curved, mode, k_tr, tau, C, S, n, u, f0, pp, mem,
                                            gr)[1]
                        for i in range(n):
                            gk[i] = gr[i]
                    else:
                        gdot = _dgval(G, k_tr, n, f0, C, S, om)
                new_mode = transition(mode, k_tr, tau, C, S, u, pp, mem)
                if tau - t_switch < zeno_dt:
                    n_tiny += 1
                    if n_tiny > ZENO_MAX:
                        code = st.ZENO
                        break
                else:
                    n_tiny = 0
                t_switch = tau
                if new_mode < 0 or new_mode >= MAX_MODES:
                    code = st.EVENT_FAILED
                    break
                mode = new_mode
                mask |= 1 << mode
                ng = min(max(guards(mode, pp, mem, G), 0), MAX_GUARDS)
                ncv = _n_curved(G, ng, n)
                if has_sec:
                    if ng >= MAX_GUARDS:
                        code = st.EVENT_FAILED
                        break
                    ksec = ng
                    ng += 1
                    if csec:
                        ncv += 1
                imm = _exit_tested(G, ng, n, ksec)
                cls = int(mcs[mode])  # (known after the mode's first visit)
                if cls == _MC_UNKNOWN:
                    cls = _mode_class(linear, closed, mode, pp, lin, MC, mcs, om, MF, n, MXR,
                                      PW)
                if cls == _MC_RESONANT:
                    code = st.RESONANCE
                    break
                cf, pm = _paths(cls, ncv, u[1], MC, mode)
                _deriv(cf, field, mode, tau, C, S, u, pp, mem, f0, MC, om)
                if csec:  # the side after the reset: a jump across the surface is no
                    sgn = _section_side_curved(curved, mode, tau, G, ksec, H, n, u, f0, C, S,
                                               pp, mem, gr)  # crossing
                elif has_sec:
                    sgn = _section_side(G, ksec, H, n, u, f0, C, S, om)
                if pm:  # (the section's row written)
                    _series_rows(G, ng, n, ncv, no_ext, need)
                if cf:
                    _cf_bounds_cached(MC, mode, om, G, ng, n, GB, GBC, GKC, GNC)
                if tan and not label and not _saltation(
                        transition, old_mode, k_tr, tau, C, S, om, n, ue, me, fm, gk, gdot,
                        mode, u, mem, f0, pp, Y, cmi, uc, mc, ua, ma, n_tiny > 0, tw_last):
                    code = st.GRAZING
                    break
                if not _finite(u, n):
                    code = st.NON_FINITE
                    break
                xmax = max(xmax, u[0])
                xmin = min(xmin, u[0])
        if code != st.OK:
            break
        if has_sec and SEC[1] > 0.0 and n_sec >= SEC[1]:
            break  # stopped on the section (the outputs of this interval are not written)
        if j == per_period:
            j = 0
            gv = False  # the phase restarts at (C0, S0), f0 is computed again
            lv = False
            t_done += T
            tau = t0
            t_switch -= T
            C = C0
            S = S0
            rejected = False
            _deriv(cf, field, mode, tau, C, S, u, pp, mem, f0, MC, om)
            if tan and qr == 1:
                _qr_logs(Y, L_out, it - n_skip)
        record_interval(it, n_skip, u[0], u[1], mode, mask, xmax, xmin, X_out, V_out, R_out,
                        M_out, Xmax_out, Xmin_out)
        if U_out.shape[0] > 0 and it >= n_skip:
            for i in range(n):
                U_out[it - n_skip, i] = u[i]
    if has_sec:
        SEC[2] = n_sec
        if not (SEC[1] > 0.0 and n_sec >= SEC[1]):
            SEC[3] = t_done + (tau - t0)
    _store(state, u, n, mem, nmem, mode, h)
    keep_alive(ws)  # the views above are not used after this
    return code


@nb.njit(GENERIC_KERNEL_SIGNATURE, cache=True, fastmath=_FM)
def advance_generic(fns, p, opts, state, per_period, n_skip, n_out, X_out, V_out, R_out, M_out,
                    Xmax_out, Xmin_out):
    """Kernel contract (see ``integrate.contract``) for a hybrid model given by ``fns``. It
    calls ``_advance`` with exactly ``advance_tangent``'s argument types (``qr`` an int64, not
    the literal 0), so numba compiles that body once for both kernels, not twice."""
    return _advance(fns, p, opts, state, per_period, n_skip, n_out, X_out, V_out, R_out, M_out,
                    Xmax_out, Xmin_out, np.zeros((0, 0)), np.zeros((0, 0)),
                    np.zeros(0, np.int64), np.int64(0), np.zeros((0, 0)), np.zeros(0),
                    np.zeros(4), np.zeros((0, 0)), np.zeros(0))


@nb.njit(TANGENT_KERNEL_SIGNATURE, cache=True, fastmath=_FM)
def advance_tangent(fns, p, opts, state, per_period, n_skip, n_out, X_out, V_out, R_out, M_out,
                    Xmax_out, Xmin_out, Y, L_out, cmi, qr, U_out, H, SEC, U_sec, T_sec):
    """``advance_generic`` that also carries tangent vectors (the columns of Y) along the
    trajectory: the variational equation of each mode (``_rk_tangent`` / ``_cf_tangent``) and
    the saltation matrix of every transition (``_saltation``). Rows of Y: the state u (n), then
    the continuous memory slots ``cmi`` (e.g. the eq. 13a entry velocity). With ``qr`` = 1 the
    columns are re-orthonormalised at every forcing-period end (Benettin) and the logs of the
    norms of the recorded periods go to ``L_out[period - n_skip]`` (per_period must be 1);
    with ``qr`` = 0, Y is left as the product (the monodromy of the stroboscopic map when
    Y starts as the identity). ``U_out`` (n_out x n, or 0 x 0 for none) receives every
    component of the state u at each output; Y with no columns carries nothing (the plain
    kernel, with all components recorded).

    A section surface ``H`` (n + 3: h = H . (u, 1, cos omega t, sin omega t); empty: none):
    its crossings are located like a guard's and recorded, in the direction ``SEC[0]`` (-1: h
    decreasing, +1: increasing, 0: both), as U_sec[i] (the state) and T_sec[i] (the time since
    the call began), at most len(T_sec) of them; ``SEC[2]`` returns their number. With
    ``SEC[1]`` = m > 0 the call stops at the m-th recorded crossing (mid-period: for an
    autonomous system, whose field does not depend on t), Y and ``state`` then hold the
    crossing, and ``SEC[3]`` the time since the call began (else the time integrated). A state
    on the surface at the start (within 1e-9 of its scale: a stop on a crossing) is not a
    crossing: the side it moves to counts; a reset that jumps across the surface is not one
    either (the side is taken again after every transition). A switching event on the
    surface, moving across it (a section on a guard's own surface: an impact map), is a
    crossing, recorded with the state before the transition; a stop there comes before the
    transition, which the next call takes at its start (the map from one event's state to
    the next's). A curved surface: ``H[n]`` NaN,
    h and its gradient from ``curved(mode, contract.SECTION_K, ...)`` of ``fns`` (a curved
    guard row)."""
    if Y.shape[0] != int(opts[OPT_N]) + len(cmi) or (qr == 1 and (
            per_period != 1 or L_out.shape[0] < n_out or L_out.shape[1] < Y.shape[1])) or (
            U_out.shape[0] > 0 and (U_out.shape[0] < n_out or U_out.shape[1] < int(opts[OPT_N]))) or (
            H.shape[0] > 0 and (H.shape[0] != int(opts[OPT_N]) + 3 or SEC.shape[0] < 4
                                or U_sec.shape[0] != T_sec.shape[0] or (
                                    U_sec.shape[0] > 0 and U_sec.shape[1] < int(opts[OPT_N])))):
        return st.NON_FINITE
    return _advance(fns, p, opts, state, per_period, n_skip, n_out, X_out, V_out, R_out, M_out,
                    Xmax_out, Xmin_out, Y, L_out, cmi, qr, U_out, H, SEC, U_sec, T_sec)
