"""An 8th-order Runge-Kutta step for tight tolerances: Dormand and Prince's DOP853 (the
coefficients of Hairer, Norsett and Wanner, Solving ODEs I, as scipy ships them).

At rtol 1e-12 the RKF45 takes about six times as many field evaluations as DOP853 (scipy,
the Jeffcott rotor's rub: 3,719 against 639 per period), so the generic kernel's plain runs
(no tangent columns) take this step in the modes it integrates (no closed form) when the
tolerance is below ``HI_ORDER_RTOL``: the exact methods' nonlinear modes (a rub, Stribeck slip,
a user's cubic spring), integrated at rtol 1e-12. Tangent runs keep the RKF45, whose tangent is
the derivative of its step (``hybrid._rk_tangent``).

* The step: 12 stages, the 8th-order solution propagated, the field at the step's end
  computed as the 13th (it is the next step's first, and the kernel needs it anyway).
* The error: Hairer's combination of the 5th- and 3rd-order estimates,
  err = |h| e5 / sqrt(n (e5 + 0.01 e3)) with e5, e3 the squared scaled norms; the step-size
  controller's exponent is 1/8 (``EXPO8``, for ``rkstep.control_step``).
* Events and extrema: a cubic Hermite of a step is far coarser than an 8th-order step (it
  would miss a grazing dip inside it), so every accepted step also computes its dense output
  of order 7 (three more stages, ``rk8_dense``) and the kernel treats the step as a series
  piece of a linear mode: guards as polynomials with certified exit tests, crossings by
  Newton on the polynomial, then the step retaken up to the crossing; extrema of X on it.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np
from scipy.integrate._ivp import dop853_coefficients as _dop

from .rkstep import _FM, tangent_stage
from .trig import cos_sin_small

N_STAGES8 = 12
_A8 = np.ascontiguousarray(_dop.A[:N_STAGES8, :N_STAGES8])
_B8 = np.ascontiguousarray(_dop.B)
_C8 = np.ascontiguousarray(_dop.C[:N_STAGES8])
_E5 = np.ascontiguousarray(_dop.E5[:N_STAGES8])  # (their 13th weight, on the field at the
_E3 = np.ascontiguousarray(_dop.E3[:N_STAGES8])  # step's end, is zero)
assert _dop.E5[N_STAGES8] == 0.0 and _dop.E3[N_STAGES8] == 0.0
_AX = np.ascontiguousarray(_dop.A[N_STAGES8 + 1:])  # the dense output's three extra stages
_CX = np.ascontiguousarray(_dop.C[N_STAGES8 + 1:])
_D8 = np.ascontiguousarray(_dop.D)  # F3..F6 of the interpolant from the 16 stages
EXPO8 = 1.0 / 8.0  # the error estimate is of order 7: h_new = 0.9 h err^(-1/8)

#: the plain generic kernel takes DOP853 steps (not RKF45) where rtol is below this
HI_ORDER_RTOL = 1e-10


@nb.njit(cache=True, inline="always", fastmath=_FM)
def _err2(e5, e3, h, count):
    """The squared error norm of a DOP853 step from the squared scaled norms e5, e3 of its
    5th- and 3rd-order estimates over ``count`` components (Hairer's combination); 0 when both
    are 0, NaN when they are not finite."""
    den = e5 + 0.01 * e3
    if not den > 0.0:
        return 0.0 if den == 0.0 else np.nan
    err = abs(h) * e5 / math.sqrt(den * count)
    return err * err


@nb.njit(cache=True, fastmath=_FM)
def rk8_step(field, mode, tau, C, S, h, om, n, u, k0, pp, mem, rtol, atol, us, K, u1, f1):
    """One DOP853 step of length h from (tau, u) in ``mode``; k0 = the field at the start, K
    a (13, n) work array. Writes the 8th-order solution to u1 and the field there to f1;
    returns (squared error norm, cos, sin at the end) like ``hybrid._rk_step`` (NaN when u1
    is not finite)."""
    for i in range(n):
        K[0, i] = k0[i]
    for s in range(1, N_STAGES8):
        for i in range(n):
            acc = 0.0
            for j in range(s):
                acc += _A8[s, j] * K[j, i]
            us[i] = u[i] + h * acc
        cs, sn = cos_sin_small(om * (_C8[s] * h))
        field(mode, tau + _C8[s] * h, C * cs - S * sn, S * cs + C * sn, us, pp, mem, K[s])
    cs, sn = cos_sin_small(om * h)
    C1 = C * cs - S * sn
    S1 = S * cs + C * sn
    finite = True
    for i in range(n):
        acc = 0.0
        for j in range(N_STAGES8):
            acc += _B8[j] * K[j, i]
        u1[i] = u[i] + h * acc
        if not math.isfinite(u1[i]):
            finite = False
    if not finite:
        return np.nan, C1, S1
    field(mode, tau + h, C1, S1, u1, pp, mem, f1)
    e5 = 0.0
    e3 = 0.0
    for i in range(n):
        a5 = 0.0  # (the estimates' weights on the field at the end, f1, are zero)
        a3 = 0.0
        for j in range(N_STAGES8):
            a5 += _E5[j] * K[j, i]
            a3 += _E3[j] * K[j, i]
        sc = atol + rtol * max(abs(u[i]), abs(u1[i]))
        a5 = a5 / sc
        a3 = a3 / sc
        e5 += a5 * a5
        e3 += a3 * a3
    return _err2(e5, e3, h, n), C1, S1


@nb.njit(cache=True, fastmath=_FM)
def rk8_dense(field, mode, tau, C, S, h, om, n, u, u1, f1, pp, mem, us, K, TW):
    """The dense output of the DOP853 step (tau, u) -> (tau + h, u1) just taken (K: its
    stages, f1 the field at its end): three more stages, then the interpolant of order 7 as a
    polynomial in s = t - tau written into TW like a series piece's Taylor terms
    (``linmodes.taylor_terms``): rows 0..n-1 the state (degree 7), row n the constant 1, rows
    n+1 and n+2 cos and sin of the forcing phase (their series, exact to round-off for
    om h <= THETA_POLY)."""
    for i in range(n):
        K[N_STAGES8, i] = f1[i]
    for s in range(N_STAGES8 + 1, N_STAGES8 + 4):
        for i in range(n):
            acc = 0.0
            for j in range(s):
                acc += _AX[s - N_STAGES8 - 1, j] * K[j, i]
            us[i] = u[i] + h * acc
        cs, sn = cos_sin_small(om * (_CX[s - N_STAGES8 - 1] * h))
        field(mode, tau + _CX[s - N_STAGES8 - 1] * h, C * cs - S * sn, S * cs + C * sn, us, pp,
              mem, K[s])
    nt = TW.shape[1]
    for i in range(n):
        # F0..F6 (Hairer's form: u(x) = u + x (F0 + (1 - x) (F1 + x (F2 + (1 - x) (F3 + ...))))
        # with x = s / h), expanded into powers of x, then of s
        dy = u1[i] - u[i]
        F0 = dy
        F1 = h * K[0, i] - dy
        F2 = 2.0 * dy - h * (f1[i] + K[0, i])
        c0 = c1 = c2 = c3 = c4 = c5 = c6 = c7 = 0.0
        for r in range(6, -1, -1):
            if r == 0:
                fr = F0
            elif r == 1:
                fr = F1
            elif r == 2:
                fr = F2
            else:
                acc = 0.0
                for j in range(16):
                    acc += _D8[r - 3, j] * K[j, i]
                fr = h * acc
            c0 += fr
            if (6 - r) % 2 == 0:  # times x
                c7, c6, c5, c4, c3, c2, c1, c0 = c6, c5, c4, c3, c2, c1, c0, 0.0
            else:  # times (1 - x)
                c7, c6, c5, c4, c3, c2, c1 = (c7 - c6, c6 - c5, c5 - c4, c4 - c3, c3 - c2,
                                              c2 - c1, c1 - c0)
        t = TW[i]
        ih = 1.0 / h
        t[0] = u[i] + c0
        t[1] = c1 * ih
        t[2] = c2 * (ih * ih)
        t[3] = c3 * (ih * ih * ih)
        t[4] = c4 * ((ih * ih) * (ih * ih))
        t[5] = c5 * ((ih * ih) * (ih * ih) * ih)
        t[6] = c6 * ((ih * ih) * (ih * ih) * (ih * ih))
        t[7] = c7 * ((ih * ih) * (ih * ih) * (ih * ih) * ih)
        for j in range(8, nt):
            t[j] = 0.0
    # the forcing pair: cos(om (tau + s)) = C cos(om s) - S sin(om s), and sin likewise
    TW[n, 0] = 1.0
    a = 1.0  # om^j / j!
    for j in range(nt):
        if j > 0:
            a = a * om / j
            TW[n, j] = 0.0
        r = j % 4  # cos(om s): +, 0, -, 0; sin(om s): 0, +, 0, -
        cj = a if r == 0 else (-a if r == 2 else 0.0)
        sj = a if r == 1 else (-a if r == 3 else 0.0)
        TW[n + 1, j] = C * cj - S * sj
        TW[n + 2, j] = S * cj + C * sj


@nb.njit(cache=True, fastmath=_FM)
def rk8_tangent(jacobian, mode, tau, C, S, h, om, n, u, K, pp, mem, Y, W, KY, J, us, cmi, rtol,
                atol):
    """Propagate the tangent Y (rows: u, then the continuous memory slots ``cmi``) through the
    DOP853 step just taken (its stages K, length h): the same Runge-Kutta formula applied to
    Y' = J Y with J the model's Jacobian at each stage state, the exact derivative of the
    discrete step (as ``hybrid._rk_tangent`` for the RKF45). Returns the squared norm of the
    step's error estimate on the tangent (Hairer's combination, each column scaled by
    atol + rtol max|column|); the estimate's weight on the field at the step's end is zero, so
    no Jacobian is taken there."""
    m = Y.shape[1]
    ncm = len(cmi)
    for i in range(N_STAGES8):
        for r in range(n):
            acc = 0.0
            for j in range(i):
                acc += _A8[i, j] * K[j, r]
            us[r] = u[r] + h * acc
        for q in range(ncm):
            for r in range(n):
                J[r, n + cmi[q]] = 0.0
        cs, sn = cos_sin_small(om * (_C8[i] * h))
        jacobian(mode, tau + _C8[i] * h, C * cs - S * sn, S * cs + C * sn, us, pp, mem, J)
        tangent_stage(_A8, i, h, n, J, Y, W, KY, cmi)
    e5 = 0.0
    e3 = 0.0
    for c in range(m):
        scale = 0.0
        for r in range(n):
            acc = 0.0
            for j in range(N_STAGES8):
                acc += _B8[j] * KY[j, r, c]
            Y[r, c] += h * acc
            scale = max(scale, abs(Y[r, c]))
        sc = atol + rtol * scale
        for r in range(n):
            a5 = 0.0
            a3 = 0.0
            for j in range(N_STAGES8):
                a5 += _E5[j] * KY[j, r, c]
                a3 += _E3[j] * KY[j, r, c]
            a5 = a5 / sc
            a3 = a3 / sc
            e5 += a5 * a5
            e3 += a3 * a3
    err2 = _err2(e5, e3, h, max(m * n, 1))
    return err2 if err2 == err2 else 0.0  # (a NaN estimate leaves the control to the state)
