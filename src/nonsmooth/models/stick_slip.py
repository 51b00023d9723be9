"""``stick_slip``: Leine's belt-driven friction oscillator (a mass on a spring, dragged by a
belt moving at ``v_belt``, with dry friction between the mass and the belt).

    X'' + xi X' + omega0^2 X = F0 cos(omega t) + f,        v_rel = V - v_belt.

Sign convention: ``f`` is the friction force on the mass. In slip it opposes the relative
velocity, f = -sign(v_rel) mu(|v_rel|), with the exponential (Stribeck) law

    mu(v) = mu_k + (mu_s - mu_k) exp(-v / v_s)

(``v_s = 0``: plain Coulomb friction, static ``mu_s``, kinetic ``mu_k``; the exponential term is
0 in slip and never divides by zero). In stick (v_rel = 0, X' = v_belt, X'' = 0) the friction
takes the value needed to hold it,

    f_req = omega0^2 X + xi v_belt - F0 cos(omega t),

and stick holds while |f_req| <= mu_s. When f_req exceeds +mu_s the friction saturates at
+mu_s, X'' = mu_s - f_req < 0, and the mass falls behind the belt (v_rel < 0: ``slip_backward``);
below -mu_s it overtakes the belt (``slip_forward``). Without damping and forcing the
stick-slip limit cycle is: stick from X = (2 mu_k - mu_s)/omega0^2 up to X_s = mu_s/omega0^2,
then backward slip, a harmonic arc about X_c = +mu_k/omega0^2 of amplitude
A = sqrt(((mu_s - mu_k)/omega0^2)^2 + (v_belt/omega0)^2), back to v_rel = 0.

Modes: 0 ``slip_forward`` (v_rel > 0, f = -mu), 1 ``slip_backward`` (v_rel < 0, f = +mu),
2 ``stick``, 3 ``transition`` (smooth method only).

``method="smooth"``: Leine's switch model (R. I. Leine, D. H. van Campen, A. de Kraker,
L. van den Steen, Nonlinear Dynamics 16 (1998) 41-54). Slip where |v_rel| > eta; in the stick
band |v_rel| <= eta the required force is taken at the actual state,
f_req = omega0^2 X + xi V - F0 cos(omega t), and the band is ``stick`` if |f_req| <= mu_s
(f = f_req: X'' = 0, V frozen) or ``transition`` if |f_req| > mu_s (f = mu_s sign(f_req),
the sign kept in ``mem[0]``). Guards (every row >= 0 inside the mode):

* slip_forward:  v_rel - eta;   slip_backward: -v_rel - eta;
* stick:         eta - v_rel, eta + v_rel, mu_s - f_req, mu_s + f_req;
* transition:    eta - v_rel, eta + v_rel, mem[0] f_req - mu_s.

``method="exact"``: the non-smooth system, event-driven. Slip guards v_rel >= 0 (forward) and
-v_rel >= 0 (backward); at v_rel = 0 the next mode follows from f_req (with V = v_belt):
stick (V reset to v_belt exactly) if |f_req| <= mu_s, else the slip direction of -sign(f_req)
(f_req > mu_s: backward). Stick has the exact field (X', V') = (v_belt, 0) and guards
mu_s - f_req (left through it -> slip_backward) and mu_s + f_req (-> slip_forward). A slip
mode entered at v_rel = 0 starts a hair (1e-14 of the velocity scale) inside it so that the
kernel never re-triggers the switch at the same instant (this is what keeps the Stribeck law,
whose slip acceleration vanishes at the breakaway point, and grazing returns free of ZENO
loops). For v_s = 0 the slip modes are linear (k = omega0^2, c = xi, b = -/+ mu_k, F = F0)
and propagated in closed form (except undamped at omega = omega0, where the kernel's closed
form has no bounded particular solution); for v_s > 0 they are integrated by DOP853 at
rtol 1e-12, atol 1e-14 (the kernel's steps below rtol 1e-10). The stick mode, a drift
X' = V = v_belt, is propagated in closed form too.

Both methods merge trajectories in stick (``flow_is_homeomorphism=False``). An orbit counts as
"sticking" when the stick mode was visited.
"""

from __future__ import annotations

import math

import numba as nb

from ..errors import ParameterError
from .base import Method, Model, Param, _PARAM_NAMES, param_index
from .oscillator import forced_row as _row

PARAMETERS = (
    Param("omega0", 1.0, low=0.0, low_open=True, units="rad/s",
          long_name="natural frequency sqrt(k/m)", symbol=r"$\omega_0$"),
    Param("xi", 0.0, low=0.0, units="1/s", long_name="damping c/m (multiplies X')",
          symbol=r"$\xi$"),
    Param("v_belt", 0.2, low=0.0, units="1/s", long_name="belt velocity",
          symbol=r"$v_{belt}$"),
    Param("mu_s", 1.0, low=0.0, units="1/s^2", long_name="static friction force / m",
          symbol=r"$\mu_s$"),
    Param("mu_k", 0.5, low=0.0, units="1/s^2",
          long_name="kinetic (large-slip) friction force / m, mu_k <= mu_s",
          symbol=r"$\mu_k$"),
    Param("v_s", 0.0, low=0.0, units="1/s",
          long_name="Stribeck velocity of mu_k + (mu_s - mu_k) exp(-|v_rel|/v_s) (0: Coulomb)",
          symbol=r"$v_s$"),
    Param("F0", 0.0, units="1/s^2", long_name="forcing amplitude", symbol=r"$F_0$"),
    Param("omega", 1.0, low=0.0, low_open=True, units="rad/s",
          long_name="forcing frequency (also fixes the sampling period 2 pi/omega)",
          symbol=r"$\omega$"),
    Param("eta", 1e-4, low=0.0, low_open=True, units="1/s",
          long_name="half-width of the stick band |v_rel| <= eta (smooth method)",
          symbol=r"$\eta$"),
)

_I = param_index(PARAMETERS)
_W0, _XI, _VB, _MUS, _MUK, _VS, _F0, _OM, _ETA = (_I[k] for k in (
    "omega0", "xi", "v_belt", "mu_s", "mu_k", "v_s", "F0", "omega", "eta"))

MODE_NAMES = ("slip_forward", "slip_backward", "stick", "transition")
SLIP_F = 0
SLIP_B = 1
STICK = 2
TRANS = 3
N_MEMORY = 1  # mem[0]: sign of f_req in the smooth transition mode (+1 or -1)
_EXP_CAP = 700.0  # exp argument cap (the slip field extended far past its border)


# ---- helpers (inlined into the cfuncs) --------------------------------------------------------
@nb.njit(cache=True, inline="always")
def _slip_friction(sg, vrel, p):
    """(f, df/dV) in slip direction sg (+1 forward, -1 backward), smooth in vrel across
    v_rel = 0 (the field extends past the mode's border)."""
    muk = p[_MUK]
    vs = p[_VS]
    if vs > 0.0:
        dmu = p[_MUS] - muk
        e = math.exp(min(-sg * vrel / vs, _EXP_CAP))
        return -sg * (muk + dmu * e), dmu * e / vs
    return -sg * muk, 0.0


@nb.njit(cache=True, inline="always")
def _delta(p):
    """How far inside a slip mode entered at v_rel = 0 the velocity is placed."""
    return 1e-14 * (p[_VB] + (p[_MUS] + abs(p[_F0])) / p[_W0]) + 1e-300


@nb.njit(cache=True, inline="always")
def _at_zero(X, c, u, p):
    """The exact method's mode at v_rel = 0 (sets u[1])."""
    vb = p[_VB]
    fr = p[_W0] * p[_W0] * X + p[_XI] * vb - p[_F0] * c
    if fr > p[_MUS]:
        u[1] = vb - _delta(p)
        return SLIP_B
    if fr < -p[_MUS]:
        u[1] = vb + _delta(p)
        return SLIP_F
    u[1] = vb
    return STICK


# ---- smooth (Leine's switch model) -----------------------------------------------------------
def smooth_field(mode, t, c, s, u, p, mem, du):
    X, V = u[0], u[1]
    du[0] = V
    if mode == STICK:
        du[1] = 0.0
        return 0
    a = -p[_W0] * p[_W0] * X - p[_XI] * V + p[_F0] * c
    if mode == TRANS:
        a += p[_MUS] * mem[0]
    else:
        sg = 1.0 if mode == SLIP_F else -1.0
        f, dfdv = _slip_friction(sg, V - p[_VB], p)
        a += f
    du[1] = a
    return 0


def smooth_jacobian(mode, t, c, s, u, p, mem, J):
    J[0, 0] = 0.0
    J[0, 1] = 1.0
    if mode == STICK:
        J[1, 0] = 0.0
        J[1, 1] = 0.0
        return 0
    J[1, 0] = -p[_W0] * p[_W0]
    J[1, 1] = -p[_XI]
    if mode != TRANS:
        sg = 1.0 if mode == SLIP_F else -1.0
        f, dfdv = _slip_friction(sg, u[1] - p[_VB], p)
        J[1, 1] += dfdv
    return 0


def smooth_guards(mode, p, mem, G):
    vb, eta = p[_VB], p[_ETA]
    if mode == SLIP_F:
        _row(G, 0, 0.0, 1.0, -vb - eta, 0.0)  # v_rel - eta
        return 1
    if mode == SLIP_B:
        _row(G, 0, 0.0, -1.0, vb - eta, 0.0)  # -v_rel - eta
        return 1
    w02, xi, F0, mus = p[_W0] * p[_W0], p[_XI], p[_F0], p[_MUS]
    _row(G, 0, 0.0, -1.0, eta + vb, 0.0)  # eta - v_rel
    _row(G, 1, 0.0, 1.0, eta - vb, 0.0)  # eta + v_rel
    if mode == STICK:
        _row(G, 2, -w02, -xi, mus, F0)  # mu_s - f_req
        _row(G, 3, w02, xi, mus, -F0)  # mu_s + f_req
        return 4
    sg = mem[0]
    _row(G, 2, sg * w02, sg * xi, -mus, -sg * F0)  # sign * f_req - mu_s
    return 3


_STICK_INSET = 1e-9  # smooth stick: V frozen this fraction of eta inside the band edge


@nb.njit(cache=True, inline="always")
def _smooth_band(X, V, c, p, mem):
    """Mode in the band |v_rel| <= eta (writes the sign of f_req for the transition mode)."""
    fr = p[_W0] * p[_W0] * X + p[_XI] * V - p[_F0] * c
    if abs(fr) <= p[_MUS]:
        return STICK
    mem[0] = 1.0 if fr > 0.0 else -1.0
    return TRANS


def smooth_transition(mode, k, t, c, s, u, p, mem):
    X, V = u[0], u[1]
    if mode == SLIP_F or mode == SLIP_B:
        new = _smooth_band(X, V, c, p, mem)
        if new == STICK:
            # freeze V a fixed hair inside the band edge it crossed, not at the located
            # crossing: a value a round-off outside the band would leave stick again at once,
            # and the later exit through that edge (stick -> transition -> slip, a tangential
            # exit) would depend on the location error through a square root
            side = 1.0 if mode == SLIP_F else -1.0
            u[1] = p[_VB] + side * p[_ETA] * (1.0 - _STICK_INSET)
        return new
    if k == 0:
        return SLIP_F
    if k == 1:
        return SLIP_B
    if mode == STICK:  # |f_req| reached mu_s: f saturates with the sign of f_req
        mem[0] = 1.0 if k == 2 else -1.0
        return TRANS
    return STICK  # |f_req| fell back below mu_s


def smooth_initial(c, s, u, p, mem):
    vrel = u[1] - p[_VB]
    mem[0] = 1.0
    if vrel > p[_ETA]:
        return SLIP_F
    if vrel < -p[_ETA]:
        return SLIP_B
    return _smooth_band(u[0], u[1], c, p, mem)


# ---- exact (event-driven stick/slip) ---------------------------------------------------------
def exact_field(mode, t, c, s, u, p, mem, du):
    if mode == STICK:
        du[0] = p[_VB]
        du[1] = 0.0
        return 0
    X, V = u[0], u[1]
    sg = 1.0 if mode == SLIP_F else -1.0
    f, dfdv = _slip_friction(sg, V - p[_VB], p)
    du[0] = V
    du[1] = -p[_W0] * p[_W0] * X - p[_XI] * V + p[_F0] * c + f
    return 0


def exact_jacobian(mode, t, c, s, u, p, mem, J):
    J[0, 0] = 0.0
    if mode == STICK:
        J[0, 1] = 0.0
        J[1, 0] = 0.0
        J[1, 1] = 0.0
        return 0
    sg = 1.0 if mode == SLIP_F else -1.0
    f, dfdv = _slip_friction(sg, u[1] - p[_VB], p)
    J[0, 1] = 1.0
    J[1, 0] = -p[_W0] * p[_W0]
    J[1, 1] = -p[_XI] + dfdv
    return 0


def exact_guards(mode, p, mem, G):
    vb = p[_VB]
    if mode == SLIP_F:
        _row(G, 0, 0.0, 1.0, -vb, 0.0)  # v_rel >= 0
        return 1
    if mode == SLIP_B:
        _row(G, 0, 0.0, -1.0, vb, 0.0)  # -v_rel >= 0
        return 1
    w02, xiv, F0, mus = p[_W0] * p[_W0], p[_XI] * vb, p[_F0], p[_MUS]
    _row(G, 0, -w02, 0.0, mus - xiv, F0)  # mu_s - f_req
    _row(G, 1, w02, 0.0, mus + xiv, -F0)  # mu_s + f_req
    return 2


def exact_transition(mode, k, t, c, s, u, p, mem):
    if mode == STICK:
        # f_req left [-mu_s, mu_s]: the friction saturates and the mass slips the other way
        if k == 0:
            u[1] = p[_VB] - _delta(p)
            return SLIP_B
        u[1] = p[_VB] + _delta(p)
        return SLIP_F
    return _at_zero(u[0], c, u, p)


def exact_initial(c, s, u, p, mem):
    mem[0] = 0.0
    vrel = u[1] - p[_VB]
    if vrel > 0.0:
        return SLIP_F
    if vrel < 0.0:
        return SLIP_B
    fr = p[_W0] * p[_W0] * u[0] + p[_XI] * p[_VB] - p[_F0] * c
    if fr > p[_MUS]:
        return SLIP_B
    if fr < -p[_MUS]:
        return SLIP_F
    return STICK


def exact_linear(mode, p, out):
    if mode == STICK:  # X' = v_belt, V' = 0: the general linear form (A = 0, b = (v_belt, 0))
        for i in range(10):
            out[i] = 0.0
        out[4] = p[_VB]
        return 2
    if p[_VS] > 0.0:
        return 0
    k = p[_W0] * p[_W0]
    d = k - p[_OM] * p[_OM]
    if p[_F0] != 0.0 and not d * d + (p[_XI] * p[_OM]) ** 2 > 1e-300:
        # undamped and forced at omega = omega0: no bounded closed form (secular growth);
        # integrate this mode by the tight-tolerance RKF45 instead
        return 0
    out[0] = k
    out[1] = p[_XI]
    out[2] = -p[_MUK] if mode == SLIP_F else p[_MUK]
    out[3] = p[_F0]
    return 1


# ---- the model -------------------------------------------------------------------------------
def _check(v):
    if v["mu_k"] > v["mu_s"]:
        raise ParameterError(f"mu_k: must satisfy 0 <= mu_k <= mu_s = {v['mu_s']:g} (kinetic "
                             f"friction cannot exceed static), got {v['mu_k']:g}")


_DEFAULTS = dict(omega0=1.0, xi=0.0, v_belt=0.2, mu_s=1.0, mu_k=0.5, v_s=0.0, F0=0.0,
                 omega=1.0)

_COMMON = dict(
    state_names=("X", "V"),
    state_units=("1", "1/s"),
    state_long_names=("displacement X", "velocity dX/dt"),
    mode_names=MODE_NAMES,
)

MODEL = Model(
    name="stick_slip",
    description="belt-driven friction oscillator (Leine's stick-slip system): Coulomb or "
                "exponential Stribeck friction, switch model or event-driven stick/slip",
    parameters=PARAMETERS,
    methods={
        "smooth": Method(smooth_field, smooth_jacobian, smooth_guards, smooth_transition,
                         smooth_initial, modes=(SLIP_F, SLIP_B, STICK, TRANS),
                         flow_is_homeomorphism=False,
                         description="Leine's switch model (stick band |v_rel| <= eta), RKF45 "
                                     "with located switches"),
        "exact": Method(exact_field, exact_jacobian, exact_guards, exact_transition,
                        exact_initial, exact_linear, closed_form=True,
                        modes=(SLIP_F, SLIP_B, STICK), flow_is_homeomorphism=False,
                        rtol=1e-12, atol=1e-14, unused=("eta",),
                        description="event-driven stick/slip: closed form in stick and "
                                    "Coulomb slip, DOP853 (rtol 1e-12) in Stribeck slip"),
    },
    n_memory=N_MEMORY,
    references=("R. I. Leine, D. H. van Campen, A. de Kraker, L. van den Steen, Stick-slip "
                "vibrations induced by alternate friction models, Nonlinear Dynamics 16 (1998) "
                "41-54 (switch model)",),
    check=_check,
    contact_modes=1 << STICK,
    contact_name="sticking (the stick mode visited)",
    presets={
        "coulomb": ({**_DEFAULTS, "eta": 1e-4},
                    "unforced, undamped Coulomb stick-slip limit cycle (closed form known)"),
        "stribeck": ({**_DEFAULTS, "xi": 0.05, "v_s": 0.5, "F0": 0.1, "omega": 0.9,
                      "eta": 1e-4},
                     "damped, weakly forced oscillator with exponential Stribeck friction"),
    },
    **_COMMON,
)
_PARAM_NAMES["stick_slip"] = MODEL.param_names
