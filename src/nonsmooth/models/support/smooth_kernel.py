"""The support model's specialised smoothed kernel: adaptive RKF45 for the switch model.

Implements the kernel contract of :mod:`nonsmooth.integrate.contract` for eqs. 10-14.

Design choices
--------------
* The method is its coefficient table (:mod:`.tableau`): the step reads every coefficient
  from it, and one elementary step-size controller (h err^(-1/5), safety 0.9, factors in
  [0.2, 5]; it took fewer steps here than PI control) uses its order. The fifth-order solution is propagated (local extrapolation);
  the error estimate is the difference between the orders 5 and 4 solutions.
* **Switches are located, not smeared.** Each step is taken with the vector field of the
  current region held fixed (the region formulas are polynomials, so they extend smoothly past
  their borders). After a step, the exit function of that region (min/max of the indicator
  functions of eq. 14, ``switch.inside_margin``) is checked at the step end and at the
  interior extrema of h_alpha, h_beta and V on the cubic Hermite interpolant of the step
  (this catches a tangential touch of a band inside one step). If the trajectory left the
  region, the crossing is found on the interpolant (Illinois method, ~1e-12 of the step) and
  the step is retaken exactly up to it; the region switches there, and entering Sigma_alpha
  stores the entry velocity Va for eq. 13a. Cost: one extra RK step plus a few cubic
  evaluations per switch (four switches per contact), no rejected steps at switches, and
  the integrator keeps its order across every switch.
* ``F0 cos(omega t)`` is evaluated by angle addition from (cos, sin) of the step start, which
  are carried from step to step; the stage increments use a short Taylor series. This removes
  the six libm cosines per step. The local time restarts at 0 every forcing period.
* Output times are hit exactly by shortening the last step of an interval without disturbing
  the controller's step size.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from ... import status as st
from ...integrate.contract import (
    KERNEL_SIGNATURE,
    OPT_ATOL,
    OPT_MAX_STEPS,
    OPT_RTOL,
    OPT_VARIANT,
    ST_H,
    ST_MODE,
    ST_V,
    ST_VA,
    ST_X,
)
from ...integrate.record import record_interval, store_state
from ...integrate.rkstep import (
    _control,
    _shrink,
    _A,
    _B,
    _C,
    _E,
    _FM,
    RKF45_ORDER,
    _cubic,
    _x_extrema,
)
from ...integrate.roots import quad_roots01
from ...integrate.trig import cos_sin_small
from .switch import (
    GAMMA_MINUS,
    SIGMA_ALPHA,
    accel,
    beta_ratio,
    inside_margin,
    region,
)

@nb.njit(cache=True, inline="always", fastmath=_FM)
def _rk_step(mode, X0, V0, A0, Va, C, S, h, om, F0, w02, ws2, xi, xis, eta, r, tr):
    """One RKF45 step with the field of ``mode`` held fixed.

    The stages are written out (a loop over the table costs ~10 %), but every coefficient is
    read from the tableau arrays, which numba freezes as constants. The forcing at the stage
    times uses cos(omega (t + c h)) = C cos(omega c h) - S sin(omega c h), with the rotations
    for c = 1/4, 3/8, 1/2 and 1 built from z = exp(i omega h / 8) (their nodes are multiples of
    1/8) and a separate series for c = 12/13.

    Returns (X1, V1, errX, errV, C1, S1): the 5th-order solution, the error estimate, and
    (cos, sin) of omega t at the step end.
    """
    c1, s1 = cos_sin_small(om * 0.125 * h)
    c2 = c1 * c1 - s1 * s1  # 2/8
    s2 = 2.0 * c1 * s1
    c3 = c2 * c1 - s2 * s1  # 3/8
    s3 = s2 * c1 + c2 * s1
    c4 = c2 * c2 - s2 * s2  # 4/8
    s4 = 2.0 * c2 * s2
    c8 = c4 * c4 - s4 * s4  # 8/8
    s8 = 2.0 * c4 * s4
    c12, s12 = cos_sin_small(om * _C[3] * h)
    C1 = C * c8 - S * s8
    S1 = S * c8 + C * s8
    x0 = V0
    v0 = A0
    xs = X0 + h * (_A[1, 0] * x0)
    vs = V0 + h * (_A[1, 0] * v0)
    x1 = vs
    v1 = accel(mode, xs, vs, Va, F0 * (C * c2 - S * s2), w02, ws2, xi, xis, eta, r, tr)
    xs = X0 + h * (_A[2, 0] * x0 + _A[2, 1] * x1)
    vs = V0 + h * (_A[2, 0] * v0 + _A[2, 1] * v1)
    x2 = vs
    v2 = accel(mode, xs, vs, Va, F0 * (C * c3 - S * s3), w02, ws2, xi, xis, eta, r, tr)
    xs = X0 + h * (_A[3, 0] * x0 + _A[3, 1] * x1 + _A[3, 2] * x2)
    vs = V0 + h * (_A[3, 0] * v0 + _A[3, 1] * v1 + _A[3, 2] * v2)
    x3 = vs
    v3 = accel(mode, xs, vs, Va, F0 * (C * c12 - S * s12), w02, ws2, xi, xis, eta, r, tr)
    xs = X0 + h * (_A[4, 0] * x0 + _A[4, 1] * x1 + _A[4, 2] * x2 + _A[4, 3] * x3)
    vs = V0 + h * (_A[4, 0] * v0 + _A[4, 1] * v1 + _A[4, 2] * v2 + _A[4, 3] * v3)
    x4 = vs
    v4 = accel(mode, xs, vs, Va, F0 * C1, w02, ws2, xi, xis, eta, r, tr)
    xs = X0 + h * (_A[5, 0] * x0 + _A[5, 1] * x1 + _A[5, 2] * x2 + _A[5, 3] * x3 + _A[5, 4] * x4)
    vs = V0 + h * (_A[5, 0] * v0 + _A[5, 1] * v1 + _A[5, 2] * v2 + _A[5, 3] * v3 + _A[5, 4] * v4)
    x5 = vs
    v5 = accel(mode, xs, vs, Va, F0 * (C * c4 - S * s4), w02, ws2, xi, xis, eta, r, tr)
    X1 = X0 + h * (_B[0] * x0 + _B[1] * x1 + _B[2] * x2 + _B[3] * x3 + _B[4] * x4 + _B[5] * x5)
    V1 = V0 + h * (_B[0] * v0 + _B[1] * v1 + _B[2] * v2 + _B[3] * v3 + _B[4] * v4 + _B[5] * v5)
    eX = h * (_E[0] * x0 + _E[1] * x1 + _E[2] * x2 + _E[3] * x3 + _E[4] * x4 + _E[5] * x5)
    eV = h * (_E[0] * v0 + _E[1] * v1 + _E[2] * v2 + _E[3] * v3 + _E[4] * v4 + _E[5] * v5)
    return X1, V1, eX, eV, C1, S1


# the stage-angle construction above relies on these nodes
assert tuple(_C * 8) == (0.0, 2.0, 3.0, 96.0 / 13.0, 8.0, 4.0)


@nb.njit(cache=True, inline="always", fastmath=_FM)
def _error_norm(X, V, X1, V1, eX, eV, rtol, atol):
    """Squared RMS error norm of a step from (X, V) to (X1, V1) with error estimate (eX, eV);
    NaN when the step end is not finite."""
    sx = atol + rtol * max(abs(X), abs(X1))
    sv = atol + rtol * max(abs(V), abs(V1))
    qx = eX / sx
    qv = eV / sv
    err2 = 0.5 * (qx * qx + qv * qv)  # squared RMS error norm (products, not ** 2)
    if not (math.isfinite(X1) and math.isfinite(V1)):
        err2 = np.nan  # an overflow makes sx infinite and err2 zero: never accept it
    return err2


@nb.njit(cache=True, inline="always", fastmath=_FM)
def _detect_exit(mode, X, V, A, X1, V1, A1, hs, eta, r):
    """Switch detection after an accepted step of length hs in ``mode``: the exit function is
    checked at the step end and at the interior extrema of h_alpha, V and h_beta on the cubic
    Hermite interpolant of the step.

    Returns (s_ev, a1, a2, a3, b1, b2, b3): the earliest fraction of the step found outside the
    region (2.0: none), and the Hermite coefficients of X and V (see ``rkstep._cubic``).
    """
    s_ev = 2.0
    if inside_margin(mode, X1, V1, eta, r) < 0.0:
        s_ev = 1.0
    dX = X1 - X
    a1 = hs * V
    a2 = 3.0 * dX - 2.0 * hs * V - hs * V1
    a3 = -2.0 * dX + hs * V + hs * V1
    dV = V1 - V
    b1 = hs * A
    b2 = 3.0 * dV - 2.0 * hs * A - hs * A1
    b3 = -2.0 * dV + hs * A + hs * A1
    check = True
    if mode == GAMMA_MINUS:
        # leaving Gamma- needs X > 1 - eta; bound the Hermite cubic of X
        xb = max(X, X1) + (4.0 / 27.0) * hs * (abs(V) + abs(V1))
        check = xb > 1.0 - eta
    if check:
        for which in range(3):
            if which == 0:  # extrema of h_alpha = X - 1
                q1, q2 = quad_roots01(a1, 2.0 * a2, 3.0 * a3)
            elif which == 1:  # extrema of V (h_alpha + h_beta = -r V)
                q1, q2 = quad_roots01(b1, 2.0 * b2, 3.0 * b3)
            else:  # extrema of h_beta = -(X - 1) - r V
                q1, q2 = quad_roots01(-a1 - r * b1, -2.0 * (a2 + r * b2),
                                       -3.0 * (a3 + r * b3))
            for q in (q1, q2):
                if 0.0 < q < s_ev:
                    if inside_margin(mode, _cubic(X, a1, a2, a3, q),
                                     _cubic(V, b1, b2, b3, q), eta, r) < 0.0:
                        s_ev = q
    return s_ev, a1, a2, a3, b1, b2, b3


@nb.njit(cache=True, inline="always", fastmath=_FM)
def _locate_on_cubic(mode, X, V, a1, a2, a3, b1, b2, b3, s_ev, eta, r):
    """Illinois iteration on the exit function of ``mode`` along the step's Hermite cubic,
    between 0 (inside) and s_ev (outside), to 1e-13 of the step.

    Returns (hi, Xi, Vi): the fraction of the step just outside the region and the
    interpolated state there.
    """
    lo = 0.0
    glo = inside_margin(mode, X, V, eta, r)
    if glo < 0.0:
        glo = 0.0
    hi = s_ev
    ghi = inside_margin(mode, _cubic(X, a1, a2, a3, hi), _cubic(V, b1, b2, b3, hi), eta, r)
    side = 0
    for _ in range(100):
        if hi - lo <= 1e-13:
            break
        den = ghi - glo
        sm = (lo * ghi - hi * glo) / den if den != 0.0 else 0.5 * (lo + hi)
        if not (lo < sm < hi):
            sm = 0.5 * (lo + hi)
        gm = inside_margin(mode, _cubic(X, a1, a2, a3, sm), _cubic(V, b1, b2, b3, sm), eta, r)
        if gm < 0.0:
            hi = sm
            ghi = gm
            if side == -1:
                glo *= 0.5
            side = -1
        else:
            lo = sm
            glo = gm
            if side == 1:
                ghi *= 0.5
            side = 1
    Xi = _cubic(X, a1, a2, a3, hi)
    Vi = _cubic(V, b1, b2, b3, hi)
    return hi, Xi, Vi


@nb.njit(KERNEL_SIGNATURE, cache=True, fastmath=_FM)
def advance_smooth(p, opts, state, per_period, n_skip, n_out, X_out, V_out, R_out, M_out,
                   Xmax_out, Xmin_out):
    """Kernel contract (see ``integrate.contract``) for the smoothed switch model, eqs. 10-14."""
    w0 = p[0]
    ws = p[1]
    xi = p[2]
    xis = p[3]
    F0 = p[4]
    om = p[5]
    eta = p[6]
    w02 = w0 * w0
    ws2 = ws * ws
    r = beta_ratio(ws, xis)
    rtol = opts[OPT_RTOL]
    atol = opts[OPT_ATOL]
    tr = int(opts[OPT_VARIANT])

    X = state[ST_X]
    V = state[ST_V]
    Va = state[ST_VA]
    mode = int(state[ST_MODE])
    h = state[ST_H]
    if mode < 0:
        mode = region(X, V, eta, r)
        if mode == SIGMA_ALPHA:
            Va = V
    T = 2.0 * math.pi / om
    dt = T / per_period
    if not h > 0.0:
        h = min(1e-3 * T, dt)
    hmin = 1e-14 * T
    n_total = n_skip + n_out
    max_steps = int(opts[OPT_MAX_STEPS] * (n_total / per_period + 1.0))

    tau = 0.0
    C = 1.0
    S = 0.0
    A = accel(mode, X, V, Va, F0, w02, ws2, xi, xis, eta, r, tr)
    steps = 0
    code = st.OK
    rejected = False
    j = 0
    for it in range(n_total):
        j += 1
        t_end = T if j == per_period else j * dt
        xmax = X
        xmin = X
        mask = 1 << mode
        while tau < t_end:
            if steps >= max_steps:
                code = st.MAX_STEPS
                break
            steps += 1
            rem = t_end - tau
            last = h >= rem * 0.999
            hs = rem if last else h
            X1, V1, eX, eV, C1, S1 = _rk_step(mode, X, V, A, Va, C, S, hs, om, F0, w02, ws2,
                                               xi, xis, eta, r, tr)
            err2 = _error_norm(X, V, X1, V1, eX, eV, rtol, atol)
            if not err2 <= 1.0:
                h, finite = _shrink(err2, hs)
                rejected = True
                if h < hmin:
                    code = st.STEP_TOO_SMALL if finite else st.NON_FINITE
                    break
                continue
            t1 = tau + hs
            A1 = accel(mode, X1, V1, Va, F0 * C1, w02, ws2, xi, xis, eta, r, tr)

            # ---- switch detection: step end and interior extrema on the Hermite cubic ----
            s_ev, a1, a2, a3, b1, b2, b3 = _detect_exit(mode, X, V, A, X1, V1, A1, hs, eta, r)
            event = s_ev <= 1.0
            if event:
                # locate the exit on the interpolant: lo inside, hi outside
                hi, Xi, Vi = _locate_on_cubic(mode, X, V, a1, a2, a3, b1, b2, b3, s_ev, eta, r)
                if hi < 1.0:
                    hs = hi * hs
                    X1, V1, eX, eV, C1, S1 = _rk_step(mode, X, V, A, Va, C, S, hs, om, F0, w02,
                                                       ws2, xi, xis, eta, r, tr)
                    t1 = tau + hs
                    last = False
                new_mode = region(X1, V1, eta, r)
                if new_mode == mode:  # the retaken step stopped a hair before the border
                    new_mode = region(Xi, Vi, eta, r)
                if new_mode == SIGMA_ALPHA and mode != SIGMA_ALPHA:
                    Va = V1
                xmax, xmin = _x_extrema(X, V, X1, V1, hs, xmax, xmin)  # over the retaken step
                mode = new_mode
                A1 = accel(mode, X1, V1, Va, F0 * C1, w02, ws2, xi, xis, eta, r, tr)
                mask |= 1 << mode
            else:
                xmax, xmin = _x_extrema(X, V, X1, V1, hs, xmax, xmin)
                h = _control(err2, hs, h, last, rejected)
                rejected = False
            X = X1
            V = V1
            A = A1
            C = C1
            S = S1
            tau = t_end if last else t1
            xmax = max(xmax, X)
            xmin = min(xmin, X)
        if code != st.OK:
            break
        if j == per_period:
            j = 0
            tau = 0.0
            C = 1.0
            S = 0.0
            A = accel(mode, X, V, Va, F0, w02, ws2, xi, xis, eta, r, tr)
        record_interval(it, n_skip, X, V, mode, mask, xmax, xmin, X_out, V_out, R_out, M_out,
                        Xmax_out, Xmin_out)
    store_state(state, X, V, Va, mode, h)
    return code


@nb.njit(cache=True)
def fixed_step(p, mode, X0, V0, Va, transition, t_end, n_steps, order):
    """Integrate with ``n_steps`` equal RKF45 steps in a fixed region ``mode`` (no switching)
    from t = 0, propagating the order-4 (``order=4``) or order-5 solution. For convergence
    tests of the tableau; returns (X, V) at t_end."""
    w0, ws, xi, xis, F0, om, eta = p[0], p[1], p[2], p[3], p[4], p[5], p[6]
    r = beta_ratio(ws, xis)
    h = t_end / n_steps
    X = X0
    V = V0
    for n in range(n_steps):
        t = n * h
        C = math.cos(om * t)
        S = math.sin(om * t)
        A = accel(mode, X, V, Va, F0 * C, w0 * w0, ws * ws, xi, xis, eta, r, transition)
        X1, V1, eX, eV, C1, S1 = _rk_step(mode, X, V, A, Va, C, S, h, om, F0, w0 * w0, ws * ws,
                                           xi, xis, eta, r, transition)
        if order == 4:
            X1 -= eX
            V1 -= eV
        X = X1
        V = V1
    return X, V
