"""A user model for ``nonsmooth``: a forced Duffing oscillator hitting a one-sided support.

    X'' + xi X' + X + beta X^3 = F0 cos(omega t) - f,

where the support across the gap at X = ``gap`` is a massless linear spring-damper
(stiffness ``k_s``, damping ``c_s``) that can push but never pull:

    f = k_s (X - gap) + c_s X'   while in contact (X > gap and that force > 0), else 0.

Modes: 0 ``free``, 1 ``contact``. Two methods:

* ``"exact"``: the non-smooth system, event-driven. Free flight below the gap watches
  X = gap (contact starts when the mass arrives moving in, V > 0; a grazing touch stays free);
  contact watches f = 0 (the support lets go; with damping that happens at X > gap); free
  flight above the gap after a separation watches f = 0 (contact again) and X = gap. The
  modes are nonlinear (the cubic term), so they are integrated by the RKF45 at a tight
  tolerance (``Method(rtol=1e-12, atol=1e-14)``).
* ``"smooth"``: one regularised field with a band of width ``eta``,
  f = s(z) k_s eta softplus(y) with z = (X - gap)/eta, y = (k_s (X - gap) + c_s V)/(k_s eta),
  s the logistic function; it tends to the exact force as eta -> 0. The modes only mark which
  side of the gap the mass is on (same field in both), so that orbits count as in contact.

Run it: ``python examples/one_sided_duffing.py``; use it from Python with
``nonsmooth.model("examples/one_sided_duffing.py:MODEL")`` and on the command line with
``nonsmooth simulate --model examples/one_sided_duffing.py:MODEL --method exact ...``.
"""

import math

import numba

from nonsmooth.models import Method, Model, Param, param_index

PARAMETERS = (
    Param("xi", 0.1, low=0.0, units="1/s", long_name="damping c/m", symbol=r"$\xi$"),
    Param("beta", 0.5, low=0.0, units="1/s^2", long_name="cubic stiffness (hardening)",
          symbol=r"$\beta$"),
    Param("F0", 1.0, units="1/s^2", long_name="forcing amplitude", symbol=r"$F_0$"),
    Param("omega", 1.2, low=0.0, low_open=True, units="rad/s", long_name="forcing frequency",
          symbol=r"$\omega$"),
    Param("gap", 1.0, units="1", long_name="position of the support (X = gap)", symbol=r"$g$"),
    Param("k_s", 20.0, low=0.0, low_open=True, units="1/s^2", long_name="support stiffness",
          symbol=r"$k_s$"),
    Param("c_s", 0.2, low=0.0, units="1/s", long_name="support damping", symbol=r"$c_s$"),
    Param("eta", 1e-3, low=0.0, low_open=True, units="1",
          long_name="band width of the regularised force (smooth method)", symbol=r"$\eta$"),
)

# parameter positions, derived from the names in one place
_I = param_index(PARAMETERS)
XI, BETA, F0, OMEGA, GAP, KS, CS, ETA = (_I[k] for k in (
    "xi", "beta", "F0", "omega", "gap", "k_s", "c_s", "eta"))

FREE = 0
CONTACT = 1


# ---- helpers: functions that the model functions call must be numba.njit ---------------------
@numba.njit(cache=True, inline="always")
def _row(G, k, a, b, c):
    """Guard row k: a X + b V + c >= 0 inside the mode (no forcing terms)."""
    G[k, 0] = a
    G[k, 1] = b
    G[k, 2] = c
    G[k, 3] = 0.0
    G[k, 4] = 0.0


@numba.njit(cache=True, inline="always")
def _free_accel(c, u, p):
    X, V = u[0], u[1]
    return -p[XI] * V - X - p[BETA] * X * X * X + p[F0] * c


@numba.njit(cache=True, inline="always")
def _sigmoid(z):
    if z >= 0.0:
        return 1.0 / (1.0 + math.exp(-z))
    e = math.exp(z)
    return e / (1.0 + e)


@numba.njit(cache=True, inline="always")
def _softplus(y):
    return max(y, 0.0) + math.log1p(math.exp(-abs(y)))


# ---- exact: event-driven free flight and contact ---------------------------------------------
# mem[0] = 1 in free flight above the gap (after a separation), 0 below it
def exact_field(mode, t, c, s, u, p, mem, du):
    a = _free_accel(c, u, p)
    if mode == CONTACT:
        a -= p[KS] * (u[0] - p[GAP]) + p[CS] * u[1]
    du[0] = u[1]
    du[1] = a
    return 0


def exact_jacobian(mode, t, c, s, u, p, mem, J):
    J[0, 0] = 0.0
    J[0, 1] = 1.0
    J[1, 0] = -1.0 - 3.0 * p[BETA] * u[0] * u[0]
    J[1, 1] = -p[XI]
    if mode == CONTACT:
        J[1, 0] -= p[KS]
        J[1, 1] -= p[CS]
    return 0


def exact_guards(mode, p, mem, G):
    ks, cs, gap = p[KS], p[CS], p[GAP]
    if mode == CONTACT:
        _row(G, 0, ks, cs, -ks * gap)  # support force f >= 0
        return 1
    if mem[0] == 0.0:  # free below the gap
        _row(G, 0, -1.0, 0.0, gap)  # gap - X >= 0
        return 1
    _row(G, 0, -ks, -cs, ks * gap)  # free above the gap: -f >= 0
    _row(G, 1, 1.0, 0.0, -gap)  # and X - gap >= 0
    return 2


def exact_transition(mode, k, t, c, s, u, p, mem):
    X, V = u[0], u[1]
    if mode == CONTACT:  # the support lets go
        mem[0] = 1.0 if X > p[GAP] else 0.0
        return FREE
    if mem[0] == 0.0:  # reached X = gap: contact if moving in (else a grazing touch)
        if V > 0.0:
            return CONTACT
        mem[0] = 1.0
        return FREE
    if k == 0 and X > p[GAP]:  # above the gap the support force turned positive again
        return CONTACT
    mem[0] = 0.0  # back below the gap
    return FREE


def exact_initial(c, s, u, p, mem):
    X, V = u[0], u[1]
    f = p[KS] * (X - p[GAP]) + p[CS] * V
    mode = FREE
    if (X > p[GAP] and f > 0.0) or (X == p[GAP] and V > 0.0):
        mode = CONTACT
    mem[0] = 1.0 if (mode == FREE and X > p[GAP]) else 0.0
    return mode


# ---- smooth: one regularised field; the modes mark the side of the gap -----------------------
def smooth_field(mode, t, c, s, u, p, mem, du):
    ks, eta = p[KS], p[ETA]
    d = u[0] - p[GAP]
    y = (ks * d + p[CS] * u[1]) / (ks * eta)
    du[0] = u[1]
    du[1] = _free_accel(c, u, p) - _sigmoid(d / eta) * ks * eta * _softplus(y)
    return 0


def smooth_jacobian(mode, t, c, s, u, p, mem, J):
    ks, cs, eta = p[KS], p[CS], p[ETA]
    d = u[0] - p[GAP]
    y = (ks * d + cs * u[1]) / (ks * eta)
    sz = _sigmoid(d / eta)
    sy = _sigmoid(y)
    dfdx = sz * (1.0 - sz) * ks * _softplus(y) + sz * sy * ks
    dfdv = sz * sy * cs
    J[0, 0] = 0.0
    J[0, 1] = 1.0
    J[1, 0] = -1.0 - 3.0 * p[BETA] * u[0] * u[0] - dfdx
    J[1, 1] = -p[XI] - dfdv
    return 0


def smooth_guards(mode, p, mem, G):
    if mode == FREE:
        _row(G, 0, -1.0, 0.0, p[GAP])  # gap - X >= 0
    else:
        _row(G, 0, 1.0, 0.0, -p[GAP])  # X - gap >= 0
    return 1


def smooth_transition(mode, k, t, c, s, u, p, mem):
    return CONTACT if mode == FREE else FREE


def smooth_initial(c, s, u, p, mem):
    mem[0] = 0.0
    return CONTACT if u[0] >= p[GAP] else FREE


# ---- the model -------------------------------------------------------------------------------
MODEL = Model(
    name="one_sided_duffing",
    description="forced Duffing oscillator hitting a one-sided spring-damper support",
    parameters=PARAMETERS,
    state_names=("X", "V"),
    state_units=("1", "1/s"),
    state_long_names=("displacement X", "velocity dX/dt"),
    mode_names=("free", "contact"),
    methods={
        "exact": Method(exact_field, exact_jacobian, exact_guards, exact_transition,
                        exact_initial, modes=(FREE, CONTACT), flow_is_homeomorphism=True,
                        rtol=1e-12, atol=1e-14,
                        description="event-driven free flight and contact, DOP853 at rtol "
                                    "1e-12 (nonlinear modes)"),
        "smooth": Method(smooth_field, smooth_jacobian, smooth_guards, smooth_transition,
                         smooth_initial, modes=(FREE, CONTACT), flow_is_homeomorphism=True,
                         description="regularised support force (band eta), RKF45"),
    },
    n_memory=1,
    references=("example model of the nonsmooth README, section 'Write your own model'",),
    contact=lambda params, mask, max_X, min_X: max_X >= params.gap,
    contact_name="contact with the support (max X >= gap)",
    contact_modes=1 << CONTACT,
    contact_level=lambda params: params.gap,
    lines=lambda params, method: [(params.gap, "support (X = gap)")],
    presets={
        "soft": ({"k_s": 5.0, "c_s": 0.1}, "a soft support"),
        "stiff": ({"k_s": 500.0, "c_s": 1.0}, "a stiff support (close to an impact)"),
    },
)


if __name__ == "__main__":
    import os

    import nonsmooth as ns

    # load this file as a module (as the CLI does): its compiled functions are then cached on
    # disk (numba caches nothing defined in __main__, so a run would recompile them)
    model = ns.model(f"{os.path.abspath(__file__)}:MODEL")
    params = model.params(omega=1.2)
    ds = ns.simulate(params, periods=10, transient=20, method="exact", samples_per_period=50)
    print(f"{model.name}: {params}")
    print(f"exact, 10 periods after 20: max X = {float(ds.max_X):.6f}, "
          f"min X = {float(ds.min_X):.6f}")
    sec = ns.poincare(params, record=20, transient=200, method="exact")
    print(f"Poincare section: period {int(sec.period)}, contact {int(sec.contact)}")
