"""The support model through the model interface (:mod:`nonsmooth.models.base`).

These functions describe the same model as the specialised kernels (``smooth_kernel``,
``exact_kernel``) so that the generic kernel can run it too; the tests check the two against
each other. Memory: ``mem[0]`` = Va, the entry velocity into Sigma_alpha (eq. 13a);
``mem[1]`` = which inequality of a union region holds (Gamma- is {h_alpha <= -eta} or
{h_beta >= eta}; free flight of the exact model is below X = 1 or above it after a
separation), because the guards of a mode describe an intersection of half-planes.
"""

from __future__ import annotations

import math

import numba as nb

from .parameters import IDX
from .switch import (GAMMA_MINUS, GAMMA_PLUS, SIGMA_ALPHA, SIGMA_BETA, beta_ratio,
                     crossed_normal, region)
from ..oscillator import row as _row

N_MEMORY = 2
_W0, _WS, _XI, _XIS, _F0, _ETA = (IDX[k] for k in ("omega0", "omega_s", "xi", "xi_s", "F0",
                                                   "eta"))
_FREE = 0
_CONTACT = 3


# ---- smooth (switch model, eq. 13; eq. 12 below shares its regions) ----------------------------------------------------------
def smooth_field(mode, t, c, s, u, p, mem, du):
    w02 = p[_W0] * p[_W0]
    ws2 = p[_WS] * p[_WS]
    xi, xis, eta = p[_XI], p[_XIS], p[_ETA]
    X, V = u[0], u[1]
    a = -w02 * X - xi * V + p[_F0] * c
    if mode == GAMMA_PLUS:
        a += -ws2 * (X - 1.0) - xis * V
    elif mode == SIGMA_ALPHA:
        q = (X - 1.0 + eta) / (2.0 * eta)
        a += -xis * V - 0.5 * ws2 * (X - 1.0 + eta) + xis * mem[0] * (1.0 - q)
    elif mode == SIGMA_BETA:
        a += -0.5 * ws2 * (X - 1.0 + eta) - 0.5 * xis * V
    du[0] = V
    du[1] = a
    return 0


def smooth_jacobian(mode, t, c, s, u, p, mem, J):
    w02 = p[_W0] * p[_W0]
    ws2 = p[_WS] * p[_WS]
    xi, xis, eta = p[_XI], p[_XIS], p[_ETA]
    ax, av = -w02, -xi
    if mode == GAMMA_PLUS:
        ax, av = ax - ws2, av - xis
    elif mode == SIGMA_ALPHA:
        ax, av = ax - 0.5 * ws2 - xis * mem[0] / (2.0 * eta), av - xis
        J[1, 2] = xis * (1.0 - (u[0] - 1.0 + eta) / (2.0 * eta))  # d/d mem[0] (Va, eq. 13a)
    elif mode == SIGMA_BETA:
        ax, av = ax - 0.5 * ws2, av - 0.5 * xis
    J[0, 0] = 0.0
    J[0, 1] = 1.0
    J[1, 0] = ax
    J[1, 1] = av
    return 0


@nb.njit(cache=True)
def _oscillator_row(p, share, b, out):
    """``linear``'s oscillator row (k, c, b, F0) of X'' + c X' + k X = F0 cos(omega t) + b with
    the ``share`` (0, 1/2 or 1) of the support's stiffness and damping."""
    out[0] = p[_W0] * p[_W0] + share * (p[_WS] * p[_WS])
    out[1] = p[_XI] + share * p[_XIS]
    out[2] = b
    out[3] = p[_F0]
    return 1


def smooth_linear(mode, p, out):
    # the oscillator form of Gamma- (eq. 11a), Sigma_beta (eq. 13b) and Gamma+ (eq. 11b): the
    # method smooth_closed_form; Sigma_alpha's field depends on the memory Va (eq. 13a): none
    if mode == SIGMA_ALPHA:
        return 0
    ws2 = p[_WS] * p[_WS]
    if mode == GAMMA_PLUS:
        return _oscillator_row(p, 1.0, ws2, out)
    if mode == SIGMA_BETA:
        return _oscillator_row(p, 0.5, 0.5 * ws2 * (1.0 - p[_ETA]), out)
    return _oscillator_row(p, 0.0, 0.0, out)


def smooth_eq12_field(mode, t, c, s, u, p, mem, du):
    # the convex combinations of eq. 12: (1 - q) f_- + q f_+ in Sigma_alpha (12a), (1 - q) f_+
    # + q f_- in Sigma_beta (12b); no memory
    w02 = p[_W0] * p[_W0]
    ws2 = p[_WS] * p[_WS]
    xi, xis, eta = p[_XI], p[_XIS], p[_ETA]
    X, V = u[0], u[1]
    a = -w02 * X - xi * V + p[_F0] * c
    support = -ws2 * (X - 1.0) - xis * V  # f_+ - f_- (second component)
    if mode == GAMMA_PLUS:
        a += support
    elif mode == SIGMA_ALPHA:
        a += (X - 1.0 + eta) / (2.0 * eta) * support
    elif mode == SIGMA_BETA:
        r = beta_ratio(p[_WS], p[_XIS])
        a += (1.0 - (-(X - 1.0) + eta - r * V) / (2.0 * eta)) * support
    du[0] = V
    du[1] = a
    return 0


def smooth_eq12_jacobian(mode, t, c, s, u, p, mem, J):
    w02 = p[_W0] * p[_W0]
    ws2 = p[_WS] * p[_WS]
    xi, xis, eta = p[_XI], p[_XIS], p[_ETA]
    X, V = u[0], u[1]
    support = -ws2 * (X - 1.0) - xis * V
    ax, av = -w02, -xi
    if mode == GAMMA_PLUS:
        ax, av = ax - ws2, av - xis
    elif mode == SIGMA_ALPHA:
        q = (X - 1.0 + eta) / (2.0 * eta)
        ax, av = ax + support / (2.0 * eta) - q * ws2, av - q * xis
    elif mode == SIGMA_BETA:
        r = beta_ratio(p[_WS], p[_XIS])
        w = 1.0 - (-(X - 1.0) + eta - r * V) / (2.0 * eta)
        ax = ax + support / (2.0 * eta) - w * ws2
        av = av + support * r / (2.0 * eta) - w * xis
    J[0, 0] = 0.0
    J[0, 1] = 1.0
    J[1, 0] = ax
    J[1, 1] = av
    return 0


def smooth_guards(mode, p, mem, G):
    # h_alpha = X - 1, h_beta = -(X - 1) - r V; every row >= 0 inside the region (eq. 14)
    r = beta_ratio(p[_WS], p[_XIS])
    eta = p[_ETA]
    if mode == GAMMA_MINUS:
        if mem[1] == 0.0:
            _row(G, 0, -1.0, 0.0, 1.0 - eta)  # -eta - h_alpha >= 0
        else:
            _row(G, 0, -1.0, -r, 1.0 - eta)  # h_beta - eta >= 0
        return 1
    if mode == SIGMA_ALPHA:
        _row(G, 0, 1.0, 0.0, eta - 1.0)  # h_alpha + eta
        _row(G, 1, -1.0, 0.0, 1.0 + eta)  # eta - h_alpha
        _row(G, 2, 0.0, r, 0.0)  # -h_alpha - h_beta = r V
        return 3
    if mode == SIGMA_BETA:
        _row(G, 0, 0.0, -r, 0.0)  # h_alpha + h_beta = -r V
        _row(G, 1, -1.0, -r, 1.0 + eta)  # h_beta + eta
        _row(G, 2, 1.0, r, eta - 1.0)  # eta - h_beta
        return 3
    _row(G, 0, 1.0, 0.0, -1.0 - eta)  # h_alpha - eta
    _row(G, 1, 1.0, r, -1.0 - eta)  # -eta - h_beta
    return 2


@nb.njit(cache=True)
def _enter(new, old, X, V, eta, mem):
    if new == SIGMA_ALPHA and old != SIGMA_ALPHA:
        mem[0] = V
    if new == GAMMA_MINUS:
        mem[1] = 0.0 if X - 1.0 <= -eta else 1.0


def smooth_transition(mode, k, t, c, s, u, p, mem):
    r = beta_ratio(p[_WS], p[_XIS])
    eta = p[_ETA]
    X, V = u[0], u[1]
    if mode == GAMMA_MINUS:
        # one inequality of the union stopped holding: stay if the other holds
        if mem[1] == 0.0 and -(X - 1.0) - r * V >= eta:
            mem[1] = 1.0
            return GAMMA_MINUS
        if mem[1] == 1.0 and X - 1.0 <= -eta:
            mem[1] = 0.0
            return GAMMA_MINUS
    # the region just across the crossed surface: classify a point nudged outwards
    a, b = crossed_normal(mode, k, mem[1], r)
    d = 1e-12 * max(1.0, eta) / max(1e-300, math.sqrt(a * a + b * b))
    new = region(X + d * a, V + d * b, eta, r)
    if new == mode:
        new = region(X + 1e3 * d * a, V + 1e3 * d * b, eta, r)
    _enter(new, mode, X, V, eta, mem)
    return new


def smooth_initial(c, s, u, p, mem):
    r = beta_ratio(p[_WS], p[_XIS])
    eta = p[_ETA]
    mode = region(u[0], u[1], eta, r)
    mem[0] = u[1]
    mem[1] = 0.0 if u[0] - 1.0 <= -eta else 1.0
    return mode


# ---- exact (eta = 0) ------------------------------------------------------------------------
@nb.njit(cache=True)
def _has_support(p):
    return p[_WS] > 0.0 or p[_XIS] > 0.0


def exact_field(mode, t, c, s, u, p, mem, du):
    X, V = u[0], u[1]
    a = -p[_W0] * p[_W0] * X - p[_XI] * V + p[_F0] * c
    if mode == _CONTACT:
        a += -p[_WS] * p[_WS] * (X - 1.0) - p[_XIS] * V
    du[0] = V
    du[1] = a
    return 0


def exact_jacobian(mode, t, c, s, u, p, mem, J):
    J[0, 0] = 0.0
    J[0, 1] = 1.0
    J[1, 0] = -p[_W0] * p[_W0] - (p[_WS] * p[_WS] if mode == _CONTACT else 0.0)
    J[1, 1] = -p[_XI] - (p[_XIS] if mode == _CONTACT else 0.0)
    return 0


def exact_guards(mode, p, mem, G):
    if not _has_support(p):
        return 0
    r = beta_ratio(p[_WS], p[_XIS])
    if mode == _CONTACT:
        _row(G, 0, 1.0, r, -1.0)  # support force / omega_s^2 = -h_beta >= 0
        return 1
    if mem[0] == 0.0:  # free, below the support
        _row(G, 0, -1.0, 0.0, 1.0)  # -h_alpha >= 0
        return 1
    _row(G, 0, -1.0, -r, 1.0)  # free above X = 1 after a separation: h_beta >= 0
    _row(G, 1, 1.0, 0.0, -1.0)  # and h_alpha >= 0
    return 2


def exact_transition(mode, k, t, c, s, u, p, mem):
    X, V = u[0], u[1]
    if mode == _CONTACT:
        mem[0] = 1.0 if X > 1.0 else 0.0
        return _FREE
    if mem[0] == 0.0:  # reached X = 1: contact if moving in (V <= 0 is a grazing touch)
        if V > 0.0:
            return _CONTACT
        mem[0] = 1.0
        return _FREE
    if k == 0 and X > 1.0:  # the support force turns positive again
        return _CONTACT
    mem[0] = 0.0
    return _FREE


def exact_initial(c, s, u, p, mem):
    X, V = u[0], u[1]
    mode = _FREE
    if _has_support(p):
        ha = X - 1.0
        ws2 = p[_WS] * p[_WS]
        Fs = ws2 * ha + p[_XIS] * V
        if (ha > 0.0 and Fs > 0.0) or (ha == 0.0 and V > 0.0):
            mode = _CONTACT
        elif ha > 0.0 and Fs == 0.0:
            A = -p[_W0] * p[_W0] * X - p[_XI] * V + p[_F0] * c
            if ws2 * V + p[_XIS] * A > 0.0:
                mode = _CONTACT
    mem[0] = 1.0 if (mode == _FREE and X > 1.0) else 0.0
    return mode


def exact_linear(mode, p, out):
    if mode == _CONTACT:
        return _oscillator_row(p, 1.0, p[_WS] * p[_WS], out)
    return _oscillator_row(p, 0.0, 0.0, out)
