"""``two_sided``: a forced oscillator between two spring-damper supports across gaps on both
sides.

Free flight  X'' + xi X' + omega0^2 X = F0 cos(omega t). The right support at X = gap_r adds
-(omega_r^2 (X - gap_r) + xi_r X') while that force pushes towards -X; the left support at
X = -gap_l is its mirror image (adds -(omega_l^2 (X + gap_l) + xi_l X') while that pushes
towards +X).

Each side is the paper's support seen in its own coordinate Y = sigma X (sigma = +1 right,
-1 left), W = sigma V, gap g: h_alpha = Y - g, h_beta = -(Y - g) - (xi/omega^2) W.

``method="smooth"``: the paper's switch model (eq. 13, bands of half-width eta) at each side.
Modes 0 free (Gamma- of both sides), 1-3 Sigma_alpha_r, Sigma_beta_r, contact_r (Gamma+ of the
right side), 4-6 the same on the left. Memory: mem[0] = entry velocity V into Sigma_alpha_r
(eq. 13a), mem[1] = which inequality of the right Gamma- union is watched in free flight
(0: h_alpha <= -eta, 1: h_beta >= eta), mem[2], mem[3] the same for the left side. The free
region is the intersection of the two sides' Gamma- (each a union: one row per side, selected
by its memory slot). The bands of the two sides never overlap (gap_r + gap_l > 2 eta).

``method="smooth_closed_form"``: the same equations solved exactly (as the support model's
method of that name): free flight, Sigma_beta and contact in closed form, Sigma_alpha by RKF45
at rtol 1e-12.

``method="exact"``: event-driven (eta = 0), modes free / contact_r / contact_l, closed form
between events. Contact starts when X reaches a gap moving outwards (a grazing touch, V = 0,
is no contact), ends when the support force vanishes; after a separation beyond the gap the
mass is free "beyond" that support (mem[1] = 1 right, mem[3] = 1 left) and contact resumes if
the force turns positive again, or that flag clears when X returns inside the gap.
"""

from __future__ import annotations

import math

import numba as nb

from ..errors import ParameterError
from .base import Method, Model, Param, _PARAM_NAMES, param_index
from .oscillator import row as _row
from .support.switch import (GAMMA_MINUS, GAMMA_PLUS, SIGMA_ALPHA, SIGMA_BETA,
                             crossed_normal, region_gap)

PARAMETERS = (
    Param("omega0", 1.0, low=0.0, low_open=True, units="rad/s",
          long_name="natural frequency sqrt(k/m)", symbol=r"$\omega_0$"),
    Param("xi", 0.05, low=0.0, units="1/s", long_name="damping c/m", symbol=r"$\xi$"),
    Param("F0", 0.3125, units="1/s^2", long_name="forcing amplitude", symbol=r"$F_0$"),
    Param("omega", 0.91, low=0.0, low_open=True, units="rad/s", long_name="forcing frequency",
          symbol=r"$\omega$"),
    Param("gap_r", 1.0, low=0.0, low_open=True, units="1",
          long_name="gap to the right support (X = gap_r)", symbol=r"$g_r$"),
    Param("omega_r", 17.32, low=0.0, units="rad/s",
          long_name="right support frequency sqrt(k_r/m)", symbol=r"$\omega_r$"),
    Param("xi_r", 0.6, low=0.0, units="1/s", long_name="right support damping c_r/m",
          symbol=r"$\xi_r$"),
    Param("gap_l", 1.0, low=0.0, low_open=True, units="1",
          long_name="gap to the left support (X = -gap_l)", symbol=r"$g_l$"),
    Param("omega_l", 17.32, low=0.0, units="rad/s",
          long_name="left support frequency sqrt(k_l/m)", symbol=r"$\omega_l$"),
    Param("xi_l", 0.6, low=0.0, units="1/s", long_name="left support damping c_l/m",
          symbol=r"$\xi_l$"),
    Param("eta", 1e-5, low=0.0, high=0.5, low_open=True, high_open=True, units="1",
          long_name="half-width of the switching bands (smooth method)", symbol=r"$\eta$"),
)

_I = param_index(PARAMETERS)
_W0, _XI, _F0 = _I["omega0"], _I["xi"], _I["F0"]
_GR, _WR, _XR = _I["gap_r"], _I["omega_r"], _I["xi_r"]
_GL, _WL, _XL = _I["gap_l"], _I["omega_l"], _I["xi_l"]
_ETA = _I["eta"]

MODE_NAMES = ("free", "Sigma_alpha_r", "Sigma_beta_r", "contact_r", "Sigma_alpha_l",
              "Sigma_beta_l", "contact_l")
FREE = 0
CONTACT_R = 3
CONTACT_L = 6
# local region codes of one side (as the support model's eq. 14)
_GM, _SA, _SB, _GP = GAMMA_MINUS, SIGMA_ALPHA, SIGMA_BETA, GAMMA_PLUS
N_MEMORY = 4
# memory slots
_VA_R, _SEL_R, _VA_L, _SEL_L = 0, 1, 2, 3


# ---- helpers --------------------------------------------------------------------------------
@nb.njit(cache=True, inline="always")
def _ratio(w, x):
    """xi/omega^2 of h_beta; 0 for a support without stiffness."""
    if w > 0.0:
        return x / (w * w)
    return 0.0


@nb.njit(cache=True, inline="always")
def _side(p, side):
    """(sigma, gap, omega^2, xi, r) of side 0 (right) or 1 (left)."""
    if side == 0:
        return 1.0, p[_GR], p[_WR] * p[_WR], p[_XR], _ratio(p[_WR], p[_XR])
    return -1.0, p[_GL], p[_WL] * p[_WL], p[_XL], _ratio(p[_WL], p[_XL])


@nb.njit(cache=True, inline="always")
def _split(mode):
    """(side, local region) of a smooth mode; the free mode is (-1, Gamma-)."""
    if mode == FREE:
        return -1, _GM
    if mode <= 3:
        return 0, mode
    return 1, mode - 3


@nb.njit(cache=True, inline="always")
def _classify(X, V, p):
    eta = p[_ETA]
    s, g, w2, x, r = _side(p, 0)
    lr = region_gap(X, V, g, eta, r)
    if lr != _GM:
        return lr
    s, g, w2, x, r = _side(p, 1)
    lr = region_gap(-X, -V, g, eta, r)
    if lr != _GM:
        return 3 + lr
    return FREE


@nb.njit(cache=True, inline="always")
def _set_selectors(X, V, p, mem):
    eta = p[_ETA]
    mem[_SEL_R] = 0.0 if X - p[_GR] <= -eta else 1.0
    mem[_SEL_L] = 0.0 if -X - p[_GL] <= -eta else 1.0


# ---- smooth (switch model at each support) --------------------------------------------------
def smooth_field(mode, t, c, s, u, p, mem, du):
    X, V = u[0], u[1]
    a = -p[_W0] * p[_W0] * X - p[_XI] * V + p[_F0] * c
    if mode != FREE:
        side, lr = _split(mode)
        sg, g, w2, x, r = _side(p, side)
        eta = p[_ETA]
        Y = sg * X
        if lr == _GP:
            a += -sg * w2 * (Y - g) - x * V
        elif lr == _SA:
            q = (Y - g + eta) / (2.0 * eta)
            va = mem[_VA_R] if side == 0 else mem[_VA_L]
            a += -x * V - sg * 0.5 * w2 * (Y - g + eta) + x * va * (1.0 - q)
        else:
            a += -sg * 0.5 * w2 * (Y - g + eta) - 0.5 * x * V
    du[0] = V
    du[1] = a
    return 0


def smooth_linear(mode, p, out):
    # the oscillator form X'' + c X' + k X = F0 cos(omega t) + b of free flight and of either
    # side's Sigma_beta and contact (eqs. 11a, 13b, 11b in the side's coordinate Y = sigma X),
    # out = (k, c, b, F0): the method smooth_closed_form; a Sigma_alpha's field uses the side's
    # entry velocity (eq. 13a): none
    w02 = p[_W0] * p[_W0]
    out[0] = w02
    out[1] = p[_XI]
    out[2] = 0.0
    if mode != FREE:
        side, lr = _split(mode)
        if lr == _SA:
            return 0
        sg, g, w2, x, r = _side(p, side)
        if lr == _GP:
            out[0] = w02 + w2
            out[1] = p[_XI] + x
            out[2] = sg * w2 * g
        else:
            out[0] = w02 + 0.5 * w2
            out[1] = p[_XI] + 0.5 * x
            out[2] = sg * 0.5 * w2 * (g - p[_ETA])
    out[3] = p[_F0]
    return 1


def smooth_jacobian(mode, t, c, s, u, p, mem, J):
    ax = -p[_W0] * p[_W0]
    av = -p[_XI]
    if mode != FREE:
        side, lr = _split(mode)
        sg, g, w2, x, r = _side(p, side)
        eta = p[_ETA]
        if lr == _GP:
            ax, av = ax - w2, av - x
        elif lr == _SA:
            va = mem[_VA_R] if side == 0 else mem[_VA_L]
            ax, av = ax - 0.5 * w2 - sg * x * va / (2.0 * eta), av - x
            # d/d va (eq. 13a memory of this side)
            J[1, 2 + (_VA_R if side == 0 else _VA_L)] = x * (1.0 - (sg * u[0] - g + eta)
                                                              / (2.0 * eta))
        else:
            ax, av = ax - 0.5 * w2, av - 0.5 * x
    J[0, 0] = 0.0
    J[0, 1] = 1.0
    J[1, 0] = ax
    J[1, 1] = av
    return 0


@nb.njit(cache=True, inline="always")
def _srow(G, k, sg, a, b, c):
    """A row a Y + b W + c of side coordinates, written in X, V."""
    _row(G, k, sg * a, sg * b, c)


@nb.njit(cache=True, inline="always")
def _gm_row(G, k, p, side, sel):
    sg, g, w2, x, r = _side(p, side)
    eta = p[_ETA]
    if sel == 0.0:
        _srow(G, k, sg, -1.0, 0.0, g - eta)  # -eta - h_alpha >= 0
    else:
        _srow(G, k, sg, -1.0, -r, g - eta)  # h_beta - eta >= 0


def smooth_guards(mode, p, mem, G):
    eta = p[_ETA]
    if mode == FREE:
        _gm_row(G, 0, p, 0, mem[_SEL_R])
        _gm_row(G, 1, p, 1, mem[_SEL_L])
        return 2
    side, lr = _split(mode)
    sg, g, w2, x, r = _side(p, side)
    if lr == _SA:
        _srow(G, 0, sg, 1.0, 0.0, eta - g)  # h_alpha + eta
        _srow(G, 1, sg, -1.0, 0.0, g + eta)  # eta - h_alpha
        _srow(G, 2, sg, 0.0, r, 0.0)  # -h_alpha - h_beta = r W
        return 3
    if lr == _SB:
        _srow(G, 0, sg, 0.0, -r, 0.0)  # h_alpha + h_beta
        _srow(G, 1, sg, -1.0, -r, g + eta)  # h_beta + eta
        _srow(G, 2, sg, 1.0, r, eta - g)  # eta - h_beta
        return 3
    _srow(G, 0, sg, 1.0, 0.0, -g - eta)  # h_alpha - eta
    _srow(G, 1, sg, 1.0, r, -g - eta)  # -eta - h_beta
    return 2


def smooth_transition(mode, k, t, c, s, u, p, mem):
    X, V = u[0], u[1]
    eta = p[_ETA]
    side, lr = _split(mode)
    kl = k
    if mode == FREE:
        side = k
        kl = 0
    sg, g, w2, x, r = _side(p, side)
    Y = sg * X
    W = sg * V
    sel_slot = _SEL_R if side == 0 else _SEL_L
    if lr == _GM:
        # one inequality of this side's union stopped holding: stay if the other holds
        if mem[sel_slot] == 0.0 and -(Y - g) - r * W >= eta:
            mem[sel_slot] = 1.0
            return FREE
        if mem[sel_slot] == 1.0 and Y - g <= -eta:
            mem[sel_slot] = 0.0
            return FREE
    # outward normal of the crossed surface in side coordinates
    a, b = crossed_normal(lr, kl, mem[sel_slot], r)
    # a nudge above the round-off of Y near the gap, well inside the band
    d = min(1e-12 * max(1.0, g), 1e-3 * eta) / max(1e-300, math.sqrt(a * a + b * b))
    new = region_gap(Y + d * a, W + d * b, g, eta, r)
    if new == lr:
        new = region_gap(Y + 1e3 * d * a, W + 1e3 * d * b, g, eta, r)
    if new == _GM:
        _set_selectors(X, V, p, mem)
        return FREE
    if new == _SA and lr != _SA:
        mem[_VA_R if side == 0 else _VA_L] = V
    return 3 * side + new


def smooth_initial(c, s, u, p, mem):
    mem[_VA_R] = u[1]
    mem[_VA_L] = u[1]
    _set_selectors(u[0], u[1], p, mem)
    return _classify(u[0], u[1], p)


# ---- exact (eta = 0) ------------------------------------------------------------------------
@nb.njit(cache=True, inline="always")
def _has(p, side):
    if side == 0:
        return p[_WR] > 0.0 or p[_XR] > 0.0
    return p[_WL] > 0.0 or p[_XL] > 0.0


def exact_field(mode, t, c, s, u, p, mem, du):
    X, V = u[0], u[1]
    a = -p[_W0] * p[_W0] * X - p[_XI] * V + p[_F0] * c
    if mode == CONTACT_R:
        a += -p[_WR] * p[_WR] * (X - p[_GR]) - p[_XR] * V
    elif mode == CONTACT_L:
        a += -p[_WL] * p[_WL] * (X + p[_GL]) - p[_XL] * V
    du[0] = V
    du[1] = a
    return 0


def exact_jacobian(mode, t, c, s, u, p, mem, J):
    ax = -p[_W0] * p[_W0]
    av = -p[_XI]
    if mode == CONTACT_R:
        ax, av = ax - p[_WR] * p[_WR], av - p[_XR]
    elif mode == CONTACT_L:
        ax, av = ax - p[_WL] * p[_WL], av - p[_XL]
    J[0, 0] = 0.0
    J[0, 1] = 1.0
    J[1, 0] = ax
    J[1, 1] = av
    return 0


def exact_guards(mode, p, mem, G):
    if mode == CONTACT_R or mode == CONTACT_L:
        side = 0 if mode == CONTACT_R else 1
        sg, g, w2, x, r = _side(p, side)
        _srow(G, 0, sg, 1.0, r, -g)  # support force / omega^2 = -h_beta >= 0
        return 1
    for side in range(2):
        if mem[_SEL_R if side == 0 else _SEL_L] == 1.0:  # free beyond this support
            sg, g, w2, x, r = _side(p, side)
            _srow(G, 0, sg, -1.0, -r, g)  # h_beta >= 0
            _srow(G, 1, sg, 1.0, 0.0, -g)  # h_alpha >= 0
            return 2
    ng = 0
    for side in range(2):
        if _has(p, side):
            sg, g, w2, x, r = _side(p, side)
            _srow(G, ng, sg, -1.0, 0.0, g)  # -h_alpha >= 0
            ng += 1
    return ng


def exact_transition(mode, k, t, c, s, u, p, mem):
    X, V = u[0], u[1]
    if mode == CONTACT_R:
        mem[_SEL_R] = 1.0 if X > p[_GR] else 0.0
        return FREE
    if mode == CONTACT_L:
        mem[_SEL_L] = 1.0 if -X > p[_GL] else 0.0
        return FREE
    for side in range(2):
        slot = _SEL_R if side == 0 else _SEL_L
        if mem[slot] == 1.0:
            sg, g, w2, x, r = _side(p, side)
            if k == 0 and sg * X > g:  # the support force turns positive again
                return CONTACT_R if side == 0 else CONTACT_L
            mem[slot] = 0.0
            return FREE
    side = 0 if (k == 0 and _has(p, 0)) else 1
    sg = 1.0 if side == 0 else -1.0
    if sg * V > 0.0:  # reached the gap moving outwards (V = 0 is a grazing touch)
        return CONTACT_R if side == 0 else CONTACT_L
    mem[_SEL_R if side == 0 else _SEL_L] = 1.0
    return FREE


def exact_initial(c, s, u, p, mem):
    X, V = u[0], u[1]
    mode = FREE
    mem[_SEL_R] = 0.0
    mem[_SEL_L] = 0.0
    for side in range(2):
        if mode != FREE or not _has(p, side):
            continue
        sg, g, w2, x, r = _side(p, side)
        Y = sg * X
        W = sg * V
        ha = Y - g
        Fs = w2 * ha + x * W
        cont = (ha > 0.0 and Fs > 0.0) or (ha == 0.0 and W > 0.0)
        if not cont and ha > 0.0 and Fs == 0.0:
            A = sg * (-p[_W0] * p[_W0] * X - p[_XI] * V + p[_F0] * c)
            cont = w2 * W + x * A > 0.0
        if cont:
            mode = CONTACT_R if side == 0 else CONTACT_L
    if mode == FREE:
        if X > p[_GR] and _has(p, 0):
            mem[_SEL_R] = 1.0
        elif -X > p[_GL] and _has(p, 1):
            mem[_SEL_L] = 1.0
    return mode


def exact_linear(mode, p, out):
    w02 = p[_W0] * p[_W0]
    if mode == CONTACT_R:
        wr2 = p[_WR] * p[_WR]
        out[0] = w02 + wr2
        out[1] = p[_XI] + p[_XR]
        out[2] = wr2 * p[_GR]
    elif mode == CONTACT_L:
        wl2 = p[_WL] * p[_WL]
        out[0] = w02 + wl2
        out[1] = p[_XI] + p[_XL]
        out[2] = -wl2 * p[_GL]
    else:
        out[0] = w02
        out[1] = p[_XI]
        out[2] = 0.0
    out[3] = p[_F0]
    return 1


# ---- the model ------------------------------------------------------------------------------
def _check(v):
    for side in ("r", "l"):
        if v[f"omega_{side}"] == 0.0 and v[f"xi_{side}"] > 0.0:
            raise ParameterError(f"omega_{side}: must be > 0 when xi_{side} > 0 (h_beta divides "
                                 f"by omega_{side}^2); use xi_{side} = 0 for a support without "
                                 f"stiffness")
    if v["gap_r"] + v["gap_l"] <= 2.0 * v["eta"]:
        raise ParameterError(f"eta: must be < (gap_r + gap_l)/2 = "
                             f"{0.5 * (v['gap_r'] + v['gap_l']):g} so that the two supports' "
                             f"bands do not overlap, got {v['eta']:g}")


_RIGHT = 0b0001110
_LEFT = 0b1110000


def _contact(params, mask, max_X, min_X):
    return bool((mask & _RIGHT and max_X >= params.gap_r)
                or (mask & _LEFT and min_X <= -params.gap_l))


def _lines(params, method):
    lines = [(params.gap_r, "right support (X = gap_r)"),
             (-params.gap_l, "left support (X = -gap_l)")]
    if method != "exact":
        e = params.eta
        lines += [(params.gap_r - e, "band edge"), (params.gap_r + e, "band edge"),
                  (-params.gap_l - e, "band edge"), (-params.gap_l + e, "band edge")]
    return lines


_TABLE3 = dict(omega0=1.0, xi=0.05, F0=0.3125, omega=0.91, omega_r=17.32, xi_r=0.6,
               omega_l=17.32, xi_l=0.6, gap_r=1.0, gap_l=1.0)

MODEL = Model(
    name="two_sided",
    description="forced oscillator between two spring-damper supports across gaps on both "
                "sides (the paper's switch model at each support)",
    parameters=PARAMETERS,
    state_names=("X", "V"),
    state_units=("1", "1/s"),
    state_long_names=("displacement X = x/g", "velocity dX/dt"),
    mode_names=MODE_NAMES,
    methods={
        "smooth": Method(smooth_field, smooth_jacobian, smooth_guards, smooth_transition,
                         smooth_initial, modes=(0, 1, 2, 3, 4, 5, 6),
                         flow_is_homeomorphism=True, continuous_memory=(_VA_R, _VA_L),
                         evidence="smooth_closed_form",
                         description="switch model (eq. 13) at each support, RKF45 with "
                                     "located switches"),
        "smooth_closed_form": Method(
            smooth_field, smooth_jacobian, smooth_guards, smooth_transition, smooth_initial,
            smooth_linear, closed_form=True, modes=(0, 1, 2, 3, 4, 5, 6),
            flow_is_homeomorphism=True, continuous_memory=(_VA_R, _VA_L), rtol=1e-12,
            atol=1e-14, dop853=False,  # each Sigma_alpha, a thin band, in a few short steps
            description="the switch model of smooth solved exactly: free flight, Sigma_beta and "
                        "contact in closed form, Sigma_alpha (its field uses the entry "
                        "velocity) by RKF45 at rtol 1e-12"),
        "exact": Method(exact_field, exact_jacobian, exact_guards, exact_transition,
                        exact_initial, exact_linear, closed_form=True, modes=(0, 3, 6),
                        flow_is_homeomorphism=True, unused=("eta",),
                        description="closed form between located switching events"),
    },
    n_memory=N_MEMORY,
    references=("the founding paper's switch model (eqs. 4-14), applied at each of two "
                "supports",),
    check=_check,
    contact=_contact,
    contact_modes=_RIGHT | _LEFT,
    contact_name="contact with a support (a band or contact mode of a side visited and X "
                 "reached that side's gap)",
    lines=_lines,
    contact_level=lambda params: params.gap_r,  # contact onset on the right support
    presets={"table3": ({**_TABLE3, "eta": 1e-5},
                        "Table 3 supports on both sides, gaps 1, omega = 0.91")},
)
_PARAM_NAMES["two_sided"] = MODEL.param_names
