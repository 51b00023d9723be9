"""The paper's smoothed switch model (eqs. 7, 10-14), as compiled scalar functions.

State u = (X, V) with V = X'. The forcing enters as the number ``fc = F0 cos(omega t)``
computed by the integrator, so these functions never evaluate a cosine.

Regions (eq. 14), with h_alpha = X - 1 and h_beta = -(X - 1) - (xi_s / omega_s^2) V (eq. 7):

====  =======  =====================================================================
code  region   definition
====  =======  =====================================================================
0     Gamma-   h_alpha <= -eta  or  h_beta >= eta                          (14a)
1     Sigma_a  -eta < h_alpha < eta  and  h_beta <= -h_alpha                (14c)
2     Sigma_b  h_alpha > -h_beta  and  -eta < h_beta < eta                  (14d)
3     Gamma+   h_alpha >= eta  and  h_beta <= -eta                          (14b)
====  =======  =====================================================================

The four sets partition the plane. Note h_alpha + h_beta = -(xi_s/omega_s^2) V, so the border
between Sigma_a and Sigma_b is the line V = 0 inside the band.

Transition fields. Two variants are implemented (the methods ``smooth`` and ``smooth_eq12``
of the model; the specialised kernel reads which from ``opts[OPT_VARIANT]``):

* ``TRANSITION_EQ13`` (default, the paper's eqs. 13a/13b). In Sigma_b the support force is
  interpolated *linearly in h_beta* between its values at the two band edges. In Sigma_a the
  spring force is interpolated linearly in X, and the support damping goes linearly from
  zero (at the entry velocity ``Va``, the "X_dot_a" of eq. 13a) to -xi_s V: the term
  ``-xi_s V + xi_s Va (1 - q)`` equals zero at entry. ``Va`` is a discrete memory: the velocity
  at which the trajectory entered Sigma_a (from any side); the integrator carries it.
* ``TRANSITION_EQ12`` (eqs. 12a/12b): the convex combinations (1-q) f_- + q f_+ and
  (1-q) f_+ + q f_-. They are continuous on every band edge and on the Sigma_a/Sigma_b border,
  but the support force becomes quadratic in X (q multiplies X - 1), and there is no memory.

How they differ: at the q = 1 edges both match f_+ exactly and at the outer edges of Sigma_b
both match f_-. Eq. 13a matches f_- at the entry edge of Sigma_a only when V = Va (true at the
moment of entry, not if the orbit turns back in the band), and eqs. 13a/13b disagree on the
V = 0 border between Sigma_a and Sigma_b by xi_s Va (eta - h_alpha)/(2 eta). Eq. 13 is the
default because it is what the paper integrated (its figures were computed with it).
"""

from __future__ import annotations

import math

import numba as nb

GAMMA_MINUS = 0
SIGMA_ALPHA = 1
SIGMA_BETA = 2
GAMMA_PLUS = 3

#: One word per region code, for CF ``flag_meanings`` and labels.
REGION_NAMES = ("Gamma_minus", "Sigma_alpha", "Sigma_beta", "Gamma_plus")

TRANSITION_EQ13 = 0
TRANSITION_EQ12 = 1


@nb.njit(cache=True, inline="always")
def beta_ratio(omega_s, xi_s):
    """r = xi_s / omega_s^2 in h_beta (eq. 7); 0 for a support without stiffness and damping."""
    if omega_s > 0.0:
        return xi_s / (omega_s * omega_s)
    return 0.0


@nb.njit(cache=True, inline="always")
def region_gap(X, V, gap, eta, r):
    """Region code of eq. 14 for the state (X, V) and a support at X = ``gap`` (the paper's
    1; the ``two_sided`` model applies it to each side in that side's coordinates)."""
    ha = X - gap
    hb = -ha - r * V
    if ha <= -eta or hb >= eta:
        return GAMMA_MINUS
    if ha >= eta and hb <= -eta:
        return GAMMA_PLUS
    if ha < eta and hb <= -ha:
        return SIGMA_ALPHA
    return SIGMA_BETA


@nb.njit(cache=True, inline="always")
def region(X, V, eta, r):
    """Region code of eq. 14 for the state (X, V)."""
    return region_gap(X, V, 1.0, eta, r)


@nb.njit(cache=True, inline="always")
def crossed_normal(mode, k, sel, r):
    """(a, b): the outward normal, in (X, V), of the surface k of region ``mode`` whose guards
    are the switch model's (generic description of eq. 14: Gamma- watches one inequality, the
    one ``sel`` names (0: h_alpha <= -eta, 1: h_beta >= eta); Sigma_alpha: h_alpha + eta,
    eta - h_alpha, r V; Sigma_beta: -r V, h_beta + eta, eta - h_beta; Gamma+: h_alpha - eta,
    -eta - h_beta). A point nudged along it is in the region across the surface."""
    a = 0.0
    b = 0.0
    if mode == GAMMA_MINUS:
        a = 1.0
        b = 0.0 if sel == 0.0 else r
    elif mode == SIGMA_ALPHA:
        if k == 0:
            a = -1.0
        elif k == 1:
            a = 1.0
        else:
            b = -r
    elif mode == SIGMA_BETA:
        if k == 0:
            b = r
        elif k == 1:
            a = 1.0
            b = r
        else:
            a = -1.0
            b = -r
    elif k == 0:
        a = -1.0
    else:
        a = -1.0
        b = -r
    return a, b


@nb.njit(cache=True, inline="always")
def inside_margin(mode, X, V, eta, r):
    """A continuous function that is >= 0 inside region ``mode`` and < 0 outside.

    Used to locate the exit from a region (min/max of the indicator functions of eq. 14).
    """
    ha = X - 1.0
    hb = -ha - r * V
    if mode == GAMMA_MINUS:
        return max(-eta - ha, hb - eta)
    if mode == GAMMA_PLUS:
        return min(ha - eta, -eta - hb)
    if mode == SIGMA_ALPHA:
        return min(min(ha + eta, eta - ha), -ha - hb)
    return min(min(ha + hb, hb + eta), eta - hb)


@nb.njit(cache=True, inline="always")
def accel(mode, X, V, Va, fc, w02, ws2, xi, xis, eta, r, transition):
    """Second component of f_-, f_alpha, f_beta, f_+ (eqs. 11a, 13a / 12a, 13b / 12b, 11b).

    ``fc`` is F0 cos(omega t); ``w02`` = omega0^2, ``ws2`` = omega_s^2.
    """
    base = -w02 * X - xi * V + fc
    if mode == GAMMA_MINUS:
        return base
    if mode == GAMMA_PLUS:
        return base - ws2 * (X - 1.0) - xis * V
    if mode == SIGMA_ALPHA:
        if transition == TRANSITION_EQ13:
            q = (X - 1.0 + eta) / (2.0 * eta)
            return base - xis * V - 0.5 * ws2 * (X - 1.0 + eta) + xis * Va * (1.0 - q)
        q = (X - 1.0 + eta) / (2.0 * eta)
        return base + q * (-ws2 * (X - 1.0) - xis * V)
    # SIGMA_BETA
    if transition == TRANSITION_EQ13:
        return base - 0.5 * ws2 * (X - 1.0 + eta) - 0.5 * xis * V
    q = (-(X - 1.0) + eta - r * V) / (2.0 * eta)
    return base + (1.0 - q) * (-ws2 * (X - 1.0) - xis * V)


@nb.njit(cache=True)
def rhs(t, X, V, Va, p, transition):
    """Full right-hand side f(u, t) of eq. 10 at the region of (X, V); returns (X', V')."""
    w0, ws, xi, xis, F0, om, eta = p[0], p[1], p[2], p[3], p[4], p[5], p[6]
    r = beta_ratio(ws, xis)
    mode = region(X, V, eta, r)
    fc = F0 * math.cos(om * t)
    return V, accel(mode, X, V, Va, fc, w0 * w0, ws * ws, xi, xis, eta, r, transition)
