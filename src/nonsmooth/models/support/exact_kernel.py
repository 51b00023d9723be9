"""The support model's specialised exact kernel: event-driven, eta = 0 (paper eqs. 4, 7-9).

Implements the kernel contract of :mod:`nonsmooth.integrate.contract` with the closed-form
modes and the rigorous event location of :mod:`nonsmooth.integrate.pwlinear`.

Model
-----
Free flight (code 0, Gamma-):  X'' + xi X' + omega0^2 X = F0 cos(omega t).
Contact     (code 3, Gamma+):  X'' + (xi + xi_s) X' + (omega0^2 + omega_s^2) X
                                   = F0 cos(omega t) + omega_s^2.
Contact is the set Gamma+ = {h_alpha > 0 and h_beta < 0} of eq. 8b, i.e. X > 1 and the support
force F_s = omega_s^2 (X - 1) + xi_s V > 0 (h_beta = -F_s / omega_s^2). Since
h_beta = -h_alpha - r V (r = xi_s / omega_s^2 >= 0), the transitions are

* contact starts when X reaches 1 moving up (h_alpha crosses 0 upwards; F_s = xi_s V > 0
  there);
* contact ends when the support force vanishes (h_beta crosses 0 upwards, eq. 9b);
* after a separation the mass is at X > 1 in free flight; if the force of a support in
  contact would become positive again before X drops below 1 (h_beta crosses 0 downwards
  with h_alpha > 0), contact resumes. This is the eta -> 0 limit of the smoothed model, whose
  regions (eq. 14) depend on the state only; the field is continuous across h_beta, so this
  crossing and the separation are transversal or tangential, never sliding.

Across h_alpha the field jumps (damping xi_s V), but X' = V > 0 on both sides whenever
h_beta < 0 there, so there is no sliding motion either: every switch is a crossing event.

Event location
--------------
Each mode segment is cut into pieces (at most ``THETA`` radians of the fastest oscillation of
the mode; halved on demand, doubled after success). On every piece the switching functionals of
the current phase and the extremum functional +-V are classified by ``pwlinear.classify``:
excluded rigorously (derivative bounds from the closed form), certified single crossing
(refined by ``pwlinear.refine_root`` until the bracket or the estimated error is below
``tol_t`` = 2e-14 max(1, T), i.e. <= 1.4e-13 s for the paper's periods), or undecided (the
piece is halved). A grazing touch therefore cannot be missed and two crossings close together
are separated. Xmax/Xmin include every interior extremum (zeros of V, located the same way,
X evaluated there from the closed form).

Cost: piece lengths are ``MC_LMAX / 2**l``, so their propagators (exp, cos, sin) are tabulated
once per call and a piece costs a few dozen flops; only pieces cut at an output time and the
root refinements (usually one or two evaluations) evaluate exp / cos / sin, with Taylor
polynomials for the small angles. About 14 pieces and 4 refinements per forcing period on the
chaotic ``table3`` case (omega = 0.92); see ``benchmarks/bench_exact.py``.

Corner cases (all end with a status, never a hang)
--------------------------------------------------
* Arrival at X = 1 with V <= 0 (a tangential, grazing touch): the support force is not
  positive, so there is no contact; the free flight continues (bit 3 of M is not set).
  Arrival with V > 0 always starts contact (for xi_s = 0, F_s = 0 at entry but grows).
* A support without stiffness and damping (omega_s = xi_s = 0) never makes contact.
* Initial mode -1: contact iff X > 1 and F_s > 0, or X = 1 and V > 0 (arriving), or X > 1,
  F_s = 0 and F_s' > 0; everything else is free flight.
* ``status.ZENO``: more than ``ZENO_MAX`` consecutive switches each less than
  ``ZENO_DT`` * T after the previous one (accumulation of ever shorter contacts, or a
  numerically degenerate corner X = 1, V = 0, X'' = 0 to round-off, where both switching
  surfaces and the first derivatives of their functionals vanish together).
* ``status.MAX_STEPS``: more than ``opts[OPT_MAX_STEPS]`` pieces per forcing period on average
  (also seen at such a degenerate corner: the derivative bounds then allow only pieces of
  about the time tolerance).
* ``status.NON_FINITE``: non-finite input state or parameters giving non-finite values.
* ``status.RESONANCE``: an undamped mode forced exactly at its resonance (xi = 0 and
  omega = omega0 in free flight; xi + xi_s = 0 and omega^2 = omega0^2 + omega_s^2 in contact):
  the secular solution is not handled, ``method="smooth"`` is.
* ``status.EVENT_FAILED``: a certified root that the refinement could not converge (not
  observed).

``opts[OPT_RTOL]``, ``opts[OPT_ATOL]`` and ``opts[OPT_VARIANT]`` are ignored: the solution
is exact to round-off and event times are located to ``tol_t`` = 2e-14 max(1, T).
``state[ST_VA]`` and ``state[ST_H]`` are not used (set to V and 0 on return).
The local time restarts at 0 at each forcing period; the piece length is reset there, so the
results do not depend on how a run is split into calls.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from ... import status as st
from ...integrate.contract import KERNEL_SIGNATURE, OPT_MAX_STEPS, ST_MODE, ST_V, ST_X
from ...integrate.pwlinear import (
    CROSSING,
    MC_C,
    MC_K,
    MC_LMAX,
    N_BD,
    N_MC,
    UNDECIDED,
    accel,
    apply_propagator,
    classify,
    deriv_bound,
    energy_norm,
    eval_state,
    functional_bounds,
    hom_part,
    mode_coeffs,
    propagator_table,
    refine_root,
)
from ...integrate.record import record_interval, store_state
from ...integrate.workspace import keep_alive, unowned
from .switch import beta_ratio

FREE = 0  # mode code of free flight (Gamma-)
CONTACT = 3  # mode code of contact (Gamma+)

THETA = 0.7  # longest piece: THETA / max(sqrt(k), omega, c/2) in each mode
ZENO_MAX = 64
ZENO_DT = 1e-9
TOL_T = 2e-14
N_LEV = 64  # piece lengths LMAX / 2**l with tabulated propagators

# internal phases
_BELOW = 0    # free flight, X <= 1: watch h_alpha up
_ABOVE = 1    # free flight, X > 1: watch -h_beta up (re-contact) and -h_alpha up (X < 1)
_CONTACT = 2  # contact: watch h_beta up (separation)

# functionals (cx, cv, c0): 0: h_alpha = X - 1, 1: -h_beta = X - 1 + r V, 2: V
_F_HA = 0
_F_MHB = 1
_F_V = 2


@nb.njit(cache=True)
def classify_initial(X, V, w0, ws, xi, xis, F0):
    """Mode code of (X, V) at t = 0 (see the module doc for the boundary cases)."""
    if not (ws > 0.0 or xis > 0.0):
        return FREE
    ha = X - 1.0
    Fs = ws * ws * ha + xis * V
    if ha > 0.0 and Fs > 0.0:
        return CONTACT
    if ha == 0.0 and V > 0.0:
        return CONTACT
    if ha > 0.0 and Fs == 0.0:
        A = -w0 * w0 * X - xi * V + F0  # same in both modes where F_s = 0
        if ws * ws * V + xis * A > 0.0:
            return CONTACT
    return FREE


@nb.njit(cache=True, inline="always")
def _tables(w0, ws, xi, xis, F0, om, r, support):
    """The per-call tables of ``advance_exact``.

    Returns (MC, FN, TB, TL, BD, sw_f, sw_s, sw_n, code): the closed-form coefficients of the
    two modes (free flight, contact), the functionals (cx, cv, c0) of ``_F_HA``, ``_F_MHB`` and
    ``_F_V``, the tabulated propagators and piece lengths per level, the derivative-bound
    coefficients per mode and functional, and the switching functionals watched in each phase
    (functional, sign, count); code is ``status.RESONANCE`` for a mode forced exactly at its
    undamped resonance (the tables are then incomplete), else ``status.OK``.
    """
    MC = np.empty((2, N_MC))
    FN = np.zeros((3, 3))
    TB = np.empty((2, N_LEV, 4))
    TL = np.empty((2, N_LEV))
    BD = np.empty((2, 3, N_BD))
    sw_f = np.empty((3, 2), np.int64)
    sw_s = np.empty((3, 2))
    sw_n = np.zeros(3, np.int64)
    if not mode_coeffs(w0 * w0, xi, 0.0, F0, om, THETA, MC[0]):
        return MC, FN, TB, TL, BD, sw_f, sw_s, sw_n, st.RESONANCE
    if not mode_coeffs(w0 * w0 + ws * ws, xi + xis, ws * ws, F0, om, THETA, MC[1]):
        if support:
            return MC, FN, TB, TL, BD, sw_f, sw_s, sw_n, st.RESONANCE
        MC[1, :] = MC[0, :]
    FN[_F_HA, 0] = 1.0
    FN[_F_HA, 2] = -1.0
    FN[_F_MHB, 0] = 1.0
    FN[_F_MHB, 1] = r
    FN[_F_MHB, 2] = -1.0
    FN[_F_V, 1] = 1.0
    for m in range(2):
        propagator_table(MC, m, om, N_LEV, TB[m])
        for lev in range(N_LEV):
            TL[m, lev] = math.ldexp(MC[m, MC_LMAX], -lev)  # (exact: L / 2^lev)
    for m in range(2):
        for f in range(3):
            functional_bounds(MC[m], om, FN[f, 0], FN[f, 1], BD[m, f])
    # switching functionals per phase: (functional, sign); count per phase
    if support:
        sw_f[_BELOW, 0] = _F_HA
        sw_s[_BELOW, 0] = 1.0
        sw_n[_BELOW] = 1
        sw_f[_ABOVE, 0] = _F_MHB
        sw_s[_ABOVE, 0] = 1.0
        sw_f[_ABOVE, 1] = _F_HA
        sw_s[_ABOVE, 1] = -1.0
        sw_n[_ABOVE] = 2
        sw_f[_CONTACT, 0] = _F_MHB
        sw_s[_CONTACT, 0] = -1.0
        sw_n[_CONTACT] = 1
    return MC, FN, TB, TL, BD, sw_f, sw_s, sw_n, st.OK


@nb.njit(cache=True, inline="always")
def _immediate_switch(FN, sw_f, sw_s, nsw, phase, X, V, A):
    """Index of the first watched functional of ``phase`` that is >= 0 and moving up at the
    piece start (an immediate switch), or -1."""
    for q in range(nsw):
        f = sw_f[phase, q]
        sg = sw_s[phase, q]
        g0 = sg * (FN[f, 0] * X + FN[f, 1] * V + FN[f, 2])
        d0 = sg * (FN[f, 0] * V + FN[f, 1] * A)
        if g0 >= 0.0 and d0 > 0.0:
            return q
    return -1


@nb.njit(cache=True, inline="always")
def _piece_end(MC, TB, TL, mi, lev, om, y, z, C, S, rem):
    """End of the next piece (tabulated length of level ``lev``, cut at ``rem``, the time
    left to the output). Returns (last, L, X1, V1, A1, y1, z1, C1, S1): whether it was cut, its
    length and the closed-form state at its end."""
    L = TL[mi, lev]
    if L >= rem:
        L = rem
        X1, V1, A1, y1, z1, C1, S1 = eval_state(MC, mi, om, y, z, C, S, L)
        return True, L, X1, V1, A1, y1, z1, C1, S1
    X1, V1, A1, y1, z1, C1, S1 = apply_propagator(
        MC, mi, om, y, z, C, S, TB[mi, lev, 0], TB[mi, lev, 1], TB[mi, lev, 2], TB[mi, lev, 3])
    return False, L, X1, V1, A1, y1, z1, C1, S1


@nb.njit(cache=True, inline="always")
def _transition(phase, f, X, V):
    """The phase after the switching functional f of ``phase`` crossed at (X, V)."""
    if phase == _BELOW:
        return _CONTACT if V > 0.0 else _ABOVE  # V <= 0: grazing touch
    if phase == _ABOVE:
        if f == _F_MHB:
            return _CONTACT if X > 1.0 else _BELOW
        return _BELOW
    return _ABOVE if X > 1.0 else _BELOW


@nb.njit(cache=True, inline="always")
def _period_reset(MC, mi, om, phase, support, X, V, C, S):
    """Phase and closed-form state (y, z, A) at the start of a forcing period (C = 1, S = 0):
    a free-flight phase is re-derived from X. Returns (phase, y, z, A)."""
    if phase != _CONTACT:
        phase = _ABOVE if (support and X > 1.0) else _BELOW
    y, z = hom_part(MC, mi, om, X, V, C, S)
    A = accel(MC, mi, om, y, z, C, S)
    return phase, y, z, A


@nb.njit(KERNEL_SIGNATURE, cache=True)
def advance_exact(p, opts, state, per_period, n_skip, n_out, X_out, V_out, R_out, M_out,
                  Xmax_out, Xmin_out):
    """Kernel contract (see ``integrate.contract``) for the exact non-smooth model."""
    w0 = p[0]
    ws = p[1]
    xi = p[2]
    xis = p[3]
    F0 = p[4]
    om = p[5]
    r = beta_ratio(ws, xis)
    support = ws > 0.0 or xis > 0.0

    X = state[ST_X]
    V = state[ST_V]
    if not (math.isfinite(X) and math.isfinite(V)):
        return st.NON_FINITE
    MCo, FNo, TBo, TLo, BDo, sw_fo, sw_so, sw_no, code = _tables(w0, ws, xi, xis, F0, om, r,
                                                                 support)
    if code != st.OK:
        return code
    # the tables without reference counting in the loop (see ``integrate.workspace``); the
    # owners are kept alive to the end
    MC, FN, TB, TL, BD = unowned(MCo), unowned(FNo), unowned(TBo), unowned(TLo), unowned(BDo)
    sw_f, sw_s, sw_n = unowned(sw_fo), unowned(sw_so), unowned(sw_no)

    T = 2.0 * math.pi / om
    dt = T / per_period
    tol_t = TOL_T * max(1.0, T)
    zeno_dt = ZENO_DT * T
    n_total = n_skip + n_out
    max_pieces = int(max(opts[OPT_MAX_STEPS], 1000.0) * (n_total / per_period + 1.0))

    mode = int(state[ST_MODE])
    if mode != FREE and mode != CONTACT:
        mode = classify_initial(X, V, w0, ws, xi, xis, F0)
    if mode == CONTACT and not support:
        mode = FREE
    if mode == CONTACT:
        phase = _CONTACT
        mi = 1
    else:
        phase = _ABOVE if (support and X > 1.0) else _BELOW
        mi = 0

    t = 0.0
    C = 1.0
    S = 0.0
    y, z = hom_part(MC, mi, om, X, V, C, S)
    A = accel(MC, mi, om, y, z, C, S)
    lev = 0
    L = 0.0
    pieces = 0
    n_tiny = 0
    t_switch = -1e300
    code = st.OK
    j = 0
    for it in range(n_total):
        j += 1
        t_end = T if j == per_period else j * dt
        xmax = X
        xmin = X
        mask = 1 << mode
        while t < t_end:
            pieces += 1
            if pieces > max_pieces:
                code = st.MAX_STEPS
                break
            nsw = sw_n[phase]
            # ---- immediate switch at the piece start (functional at 0 moving up) ----
            s_sw = -1.0
            last = False
            k_sw = _immediate_switch(FN, sw_f, sw_s, nsw, phase, X, V, A)
            if k_sw >= 0:
                s_sw = 0.0
            X1 = X
            V1 = V
            A1 = A
            y1 = y
            z1 = z
            C1 = C
            S1 = S
            if k_sw < 0:
                rem = t_end - t
                En = energy_norm(MC, mi, y, z)
                J0 = -MC[mi, MC_K] * V - MC[mi, MC_C] * A - F0 * om * S
                last, L, X1, V1, A1, y1, z1, C1, S1 = _piece_end(MC, TB, TL, mi, lev, om, y, z, C,
                                                                 S, rem)
                if not (math.isfinite(X1) and math.isfinite(V1)):
                    code = st.NON_FINITE
                    break
                undecided = False
                forced = L <= tol_t
                s_best = 2.0 * L
                for q in range(nsw):
                    f = sw_f[phase, q]
                    sg = sw_s[phase, q]
                    cx = sg * FN[f, 0]
                    cv = sg * FN[f, 1]
                    c0 = sg * FN[f, 2]
                    g0 = cx * X + cv * V + c0
                    d0 = cx * V + cv * A
                    if g0 > 0.0:
                        g0 = 0.0  # round-off after the switch that armed it (moving down)
                    g1 = cx * X1 + cv * V1 + c0
                    d1 = cx * V1 + cv * A1
                    dd0 = cx * A + cv * J0
                    M2, M3, M4 = deriv_bound(BD, mi, f, om, En)
                    cl = classify(g0, d0, dd0, g1, d1, L, M2, M3, M4)
                    if cl == UNDECIDED:
                        if forced:
                            # a piece shorter than the time tolerance: a crossing if g ends
                            # strictly positive (g1 == 0 is a touch, as with V = 0 at X = 1)
                            if g1 > 0.0 and L < s_best:
                                s_best = L
                                k_sw = q
                        else:
                            undecided = True
                    elif cl == CROSSING:
                        if undecided:
                            continue
                        sr, Xr, Vr, Ar, yr, zr, Cr, Sr, ok = refine_root(
                            MC, mi, om, F0, y, z, C, S, cx, cv, c0, g0, d0, g1, d1, L, tol_t)
                        if not ok:
                            code = st.EVENT_FAILED
                            break
                        if sr < s_best:
                            s_best = sr
                            k_sw = q
                            X1 = Xr
                            V1 = Vr
                            A1 = Ar
                            y1 = yr
                            z1 = zr
                            C1 = Cr
                            S1 = Sr
                if code != st.OK:
                    break
                # ---- extremum functional: the sign of V that is negative now ----
                sv = -1.0 if V > 0.0 else 1.0
                if V == 0.0 and A < 0.0:
                    sv = 1.0
                elif V == 0.0:
                    sv = -1.0
                if not undecided:
                    # the piece examined for extrema ends at the switch, if there is one
                    Lx = s_best if k_sw >= 0 else L
                    g0 = sv * V
                    d0 = sv * A
                    g1 = sv * V1
                    d1 = sv * A1
                    if Lx > 0.0:
                        M2, M3, M4 = deriv_bound(BD, mi, _F_V, om, En)
                        cl = classify(g0, d0, sv * J0, g1, d1, Lx, M2, M3, M4)
                        if cl == UNDECIDED:
                            if Lx > tol_t:
                                undecided = True
                        elif cl == CROSSING:
                            sr, Xr, Vr, Ar, yr, zr, Cr, Sr, ok = refine_root(
                                MC, mi, om, F0, y, z, C, S, 0.0, sv, 0.0, g0, d0, g1, d1, Lx,
                                tol_t)
                            if not ok:
                                code = st.EVENT_FAILED
                                break
                            xmax = max(xmax, Xr)
                            xmin = min(xmin, Xr)
                if undecided:
                    lev += 1
                    while lev < N_LEV - 1 and TL[mi, lev] >= L:
                        lev += 1
                    continue
            # ---- advance to the piece end or to the switch ----
            if k_sw < 0:
                t = t_end if last else t + L
                if lev > 0 and not last:
                    lev -= 1
            else:
                t = t + s_best if s_sw < 0.0 else t
            X = X1
            V = V1
            A = A1
            y = y1
            z = z1
            C = C1
            S = S1
            xmax = max(xmax, X)
            xmin = min(xmin, X)
            if k_sw >= 0:
                # ---- mode transition ----
                new_phase = _transition(phase, sw_f[phase, k_sw], X, V)
                if t - t_switch < zeno_dt:
                    n_tiny += 1
                    if n_tiny > ZENO_MAX:
                        code = st.ZENO
                        break
                else:
                    n_tiny = 0
                t_switch = t
                phase = new_phase
                mi = 1 if phase == _CONTACT else 0
                mode = CONTACT if phase == _CONTACT else FREE
                mask |= 1 << mode
                y, z = hom_part(MC, mi, om, X, V, C, S)
                A = accel(MC, mi, om, y, z, C, S)
                lev = 0
        if code != st.OK:
            break
        if j == per_period:
            j = 0
            t = 0.0
            t_switch -= T
            C = 1.0
            S = 0.0
            phase, y, z, A = _period_reset(MC, mi, om, phase, support, X, V, C, S)
            lev = 0
        record_interval(it, n_skip, X, V, mode, mask, xmax, xmin, X_out, V_out, R_out, M_out,
                        Xmax_out, Xmin_out)
    store_state(state, X, V, V, mode, 0.0)
    keep_alive(MCo)
    keep_alive(FNo)
    keep_alive(TBo)
    keep_alive(TLo)
    keep_alive(BDo)
    keep_alive(sw_fo)
    keep_alive(sw_so)
    keep_alive(sw_no)
    return code
