"""``impact``: a forced oscillator hitting a rigid stop at X = 1 (Newton's restitution law).

Free flight  X'' + xi X' + omega0^2 X = F0 cos(omega t) for X < 1; at X = 1 moving in
(V- > 0) the velocity is reset to V+ = -r V-, 0 <= r <= 1.

``method="exact"``: event-driven, closed form in free flight. Modes used: ``free`` and
``stuck``. Guard in free: 1 - X >= 0. At an impact: if the mass arrives with a negligible
velocity, or the remaining chatter sequence (impact velocities r^k V, a geometric series of
flight times 2 r V / (a (1 - r)) under a constant pressing acceleration a) would accumulate
within CHATTER_T T, and the free acceleration at the stop a = -omega0^2 + F0 cos(omega t)
presses into the stop (a >= 0), the mass sticks: X = 1, V = 0 exactly, mode ``stuck``. Else
V+ = -r V- (X set to 1 exactly) and the mass stays free. With r = 0 every impact sticks if
pressing or leaves with V = 0. ``stuck``: du = 0; guard a >= 0, i.e. the row
[0, 0, -omega0^2, F0, 0]; leaving goes to free (X = 1, V = 0, accelerating away). So
chattering ends in sticking in finite time (never Zeno).

``method="smooth"``: the stop is approximated by a stiff linear spring-damper contact,
mode ``contact`` while X > 1, with force k_c (X - 1) + c V, c = 2 zeta sqrt(k_c), and zeta
chosen so that one isolated contact X'' + c X' + k_c (X - 1) = 0, entered at X = 1 and left
when X returns to X = 1, has the coefficient of restitution r:
r = exp(-zeta pi / sqrt(1 - zeta^2)), i.e. zeta = -ln r / sqrt(pi^2 + ln^2 r) (zeta = 1,
critical damping, for r = 0: the mass then never returns to X = 1 on its own and leaves only
when the forcing pulls it out). Separation is on the same surface X = 1 (both ways; the
damper may pull briefly at the end of a contact, which is what makes the restitution exactly
r). RKF45 in both modes; no memory.
"""

from __future__ import annotations

import math

import numba as nb

from .base import Method, Model, Param, _PARAM_NAMES, param_index
from .oscillator import forced_row as _row

PARAMETERS = (
    Param("omega0", 1.0, low=0.0, low_open=True, units="rad/s",
          long_name="natural frequency sqrt(k/m)", symbol=r"$\omega_0$"),
    Param("xi", 0.05, low=0.0, units="1/s", long_name="damping c/m", symbol=r"$\xi$"),
    Param("F0", 0.5, units="1/s^2", long_name="forcing amplitude", symbol=r"$F_0$"),
    Param("omega", 2.5, low=0.0, low_open=True, units="rad/s", long_name="forcing frequency",
          symbol=r"$\omega$"),
    Param("r", 0.8, low=0.0, high=1.0, units="1", long_name="coefficient of restitution",
          symbol=r"$r$"),
    Param("k_c", 1e4, low=0.0, low_open=True, units="1/s^2",
          long_name="contact stiffness of the smooth method (k_c/m)", symbol=r"$k_c$"),
)

_I = param_index(PARAMETERS)
_W0, _XI, _F0, _OM, _R, _KC = (_I[k] for k in ("omega0", "xi", "F0", "omega", "r", "k_c"))

MODE_NAMES = ("free", "contact", "stuck")
FREE = 0
CONTACT = 1
STUCK = 2

#: impact velocities below V_STICK times the velocity scale max(1, |F0|/omega0) stick
V_STICK = 1e-9
#: a chatter sequence that would accumulate within CHATTER_T forcing periods sticks at once
CHATTER_T = 1e-6


@nb.njit(cache=True, inline="always")
def _zeta(r):
    """Damping ratio of the compliant contact with coefficient of restitution r."""
    if r <= 0.0:
        return 1.0
    L = math.log(r)
    return -L / math.sqrt(math.pi * math.pi + L * L)


def contact_damping(r: float, k_c: float) -> float:
    """c = 2 zeta sqrt(k_c) of the smooth method's contact."""
    return 2.0 * float(_zeta(float(r))) * math.sqrt(k_c)


# ---- exact ----------------------------------------------------------------------------------
def exact_field(mode, t, c, s, u, p, mem, du):
    if mode == STUCK:
        du[0] = 0.0
        du[1] = 0.0
        return 0
    du[0] = u[1]
    du[1] = -p[_W0] * p[_W0] * u[0] - p[_XI] * u[1] + p[_F0] * c
    return 0


def exact_jacobian(mode, t, c, s, u, p, mem, J):
    J[0, 0] = 0.0
    if mode == STUCK:
        J[0, 1] = 0.0
        J[1, 0] = 0.0
        J[1, 1] = 0.0
        return 0
    J[0, 1] = 1.0
    J[1, 0] = -p[_W0] * p[_W0]
    J[1, 1] = -p[_XI]
    return 0


def exact_guards(mode, p, mem, G):
    if mode == STUCK:
        _row(G, 0, 0.0, 0.0, -p[_W0] * p[_W0], p[_F0])  # free acceleration at the stop >= 0
        return 1
    _row(G, 0, -1.0, 0.0, 1.0, 0.0)  # 1 - X >= 0
    return 1


def exact_transition(mode, k, t, c, s, u, p, mem):
    if mode == STUCK:
        u[0] = 1.0
        u[1] = 0.0
        return FREE
    w0 = p[_W0]
    r = p[_R]
    vin = u[1]
    u[0] = 1.0
    a = -w0 * w0 + p[_F0] * c  # free acceleration at X = 1, V = 0
    if a >= 0.0:
        vstick = V_STICK * max(1.0, abs(p[_F0]) / w0)
        T = 2.0 * math.pi / p[_OM]
        stick = r * vin <= vstick
        if not stick and r < 1.0 and a > 0.0:
            stick = 2.0 * r * vin / (a * (1.0 - r)) <= CHATTER_T * T
        if stick:
            u[1] = 0.0
            return STUCK
    if vin > 0.0:
        u[1] = -r * vin
    return FREE


def exact_initial(c, s, u, p, mem):
    X, V = u[0], u[1]
    if X >= 1.0 and V == 0.0 and -p[_W0] * p[_W0] + p[_F0] * c >= 0.0:
        u[0] = 1.0
        return STUCK
    return FREE


def exact_linear(mode, p, out):
    if mode == STUCK:
        return 0
    out[0] = p[_W0] * p[_W0]
    out[1] = p[_XI]
    out[2] = 0.0
    out[3] = p[_F0]
    return 1


# ---- smooth (compliant contact) --------------------------------------------------------------
def smooth_field(mode, t, c, s, u, p, mem, du):
    X, V = u[0], u[1]
    a = -p[_W0] * p[_W0] * X - p[_XI] * V + p[_F0] * c
    if mode == CONTACT:
        kc = p[_KC]
        a += -kc * (X - 1.0) - 2.0 * _zeta(p[_R]) * math.sqrt(kc) * V
    du[0] = V
    du[1] = a
    return 0


def smooth_jacobian(mode, t, c, s, u, p, mem, J):
    ax = -p[_W0] * p[_W0]
    av = -p[_XI]
    if mode == CONTACT:
        kc = p[_KC]
        ax -= kc
        av -= 2.0 * _zeta(p[_R]) * math.sqrt(kc)
    J[0, 0] = 0.0
    J[0, 1] = 1.0
    J[1, 0] = ax
    J[1, 1] = av
    return 0


def smooth_guards(mode, p, mem, G):
    if mode == CONTACT:
        _row(G, 0, 1.0, 0.0, -1.0, 0.0)  # X - 1 >= 0
    else:
        _row(G, 0, -1.0, 0.0, 1.0, 0.0)  # 1 - X >= 0
    return 1


def smooth_transition(mode, k, t, c, s, u, p, mem):
    if mode == CONTACT:
        return FREE
    return CONTACT


def smooth_initial(c, s, u, p, mem):
    X, V = u[0], u[1]
    if X > 1.0 or (X == 1.0 and V > 0.0):
        return CONTACT
    return FREE


def _contact(params, mask, max_X, min_X):
    return max_X >= 1.0 - 1e-9


def _lines(params, method):
    return [(1.0, "stop")]


MODEL = Model(
    name="impact",
    description="forced oscillator hitting a rigid stop at X = 1 (Newton's restitution "
                "V+ = -r V-); smooth method: a stiff spring-damper contact with the same "
                "restitution",
    parameters=PARAMETERS,
    state_names=("X", "V"),
    state_units=("1", "1/s"),
    state_long_names=("displacement X = x/g", "velocity dX/dt"),
    mode_names=MODE_NAMES,
    methods={
        "smooth": Method(smooth_field, smooth_jacobian, smooth_guards, smooth_transition,
                         smooth_initial, modes=(FREE, CONTACT), flow_is_homeomorphism=True,
                         description="compliant contact (k_c, damping matched to r), RKF45 "
                                     "with located switches"),
        "exact": Method(exact_field, exact_jacobian, exact_guards, exact_transition,
                        exact_initial, exact_linear, closed_form=True, modes=(FREE, STUCK),
                        flow_is_homeomorphism=False, unused=("k_c",),
                        description="closed form between located impacts; chatter ends in "
                                    "sticking"),
    },
    references=("impact oscillator with Newton's restitution law",),
    contact=_contact,
    contact_modes=0b110,
    contact_name="the orbit reaches the stop (max X >= 1 - 1e-9)",
    lines=_lines,
    contact_level=lambda params: 1.0,
)
_PARAM_NAMES["impact"] = MODEL.param_names
