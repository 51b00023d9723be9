"""Generic hybrid kernel (``integrate.hybrid.advance_generic``) on toy models defined here."""

import math
import warnings

import numba as nb
import numpy as np
import pytest

warnings.filterwarnings("ignore", category=nb.NumbaExperimentalFeatureWarning)

from nonsmooth import status as st  # noqa: E402
from nonsmooth.integrate.contract import (  # noqa: E402
    MODEL_SIGNATURES,
    N_OPTS,
    N_STATE,
    OPT_ATOL,
    OPT_CLOSED_FORM,
    OPT_MAX_STEPS,
    OPT_N,
    OPT_NMEM,
    OPT_OMEGA,
    OPT_RTOL,
    ST_EXTRA,
    ST_H,
    ST_MODE,
    ST_V,
    ST_X,
)
from nonsmooth.integrate.hybrid import _NS, _rk_step, _rk_tangent, advance_generic  # noqa: E402
from nonsmooth._numba_cache import register_user_file  # noqa: E402
from nonsmooth.models import file_digest  # noqa: E402

# The RKF45 step with its tangent (``_rk_step_and_tangent``) takes 40-70 s to compile: it is
# cached on disk like a user's model file (stamped with the kernels' sources and this file's
# digest), compiled once before the workers start (``conftest.py``, ``precompile``).
register_user_file(__file__, f"nonsmooth_tests_hybrid_kernel_{file_digest(__file__)}")

pytestmark = pytest.mark.filterwarnings("ignore::numba.NumbaExperimentalFeatureWarning")

FIELD, JAC, GUARDS, TRANS, INIT, LIN, CURVED = MODEL_SIGNATURES

# ---- toy models; p = (w0, xi, F0, omega, r, b) ----------------------------------------------
P_W0, P_XI, P_F0, P_OM, P_R, P_B = range(6)


@nb.cfunc(FIELD, cache=False)
def osc_field(mode, t, c, s, u, p, mem, du):
    """X'' + xi X' + w0^2 X = F0 cos(omega t) + b; u[2:] decay as dz/dt = -z."""
    du[0] = u[1]
    du[1] = -p[0] * p[0] * u[0] - p[1] * u[1] + p[2] * c + p[5]
    for i in range(2, u.shape[0]):
        du[i] = -u[i]
    return 0


@nb.cfunc(JAC, cache=False)
def no_jac(mode, t, c, s, u, p, mem, J):
    return 0


@nb.cfunc(GUARDS, cache=False)
def no_guards(mode, p, mem, G):
    return 0


@nb.cfunc(GUARDS, cache=False)
def stop_guard(mode, p, mem, G):
    """g = 1 - X >= 0 (rigid stop at X = 1); columns (u..., const, cos, sin)."""
    n = G.shape[1] - 3
    for i in range(G.shape[1]):
        G[0, i] = 0.0
    G[0, 0] = -1.0
    G[0, n] = 1.0
    return 1


@nb.cfunc(TRANS, cache=False)
def impact(mode, k, t, c, s, u, p, mem):
    """Newton impact V -> -r V; counts impacts in mem[0] and stores their times in mem[1:]."""
    u[1] = -p[4] * u[1]
    i = int(mem[0])
    if i + 1 < mem.shape[0]:
        mem[i + 1] = t
    mem[0] = i + 1.0
    return 0


@nb.cfunc(TRANS, cache=False)
def stuck(mode, k, t, c, s, u, p, mem):
    """A transition that does not resolve the exit (the guard stays violated)."""
    return mode


@nb.cfunc(INIT, cache=False)
def init_free(c, s, u, p, mem):
    return 0


@nb.cfunc(LIN, cache=False)
def osc_linear(mode, p, out):
    out[0] = p[0] * p[0]
    out[1] = p[1]
    out[2] = p[5]
    out[3] = p[2]
    return 1


# a switching model: mode 0 (X <= 1, free), mode 1 (X >= 1, spring contact k_s = 4, c_s = 0.2)
@nb.cfunc(FIELD, cache=False)
def sw_field(mode, t, c, s, u, p, mem, du):
    du[0] = u[1]
    a = -p[0] * p[0] * u[0] - p[1] * u[1] + p[2] * c
    if mode == 1:
        a += -4.0 * (u[0] - 1.0) - 0.2 * u[1]
    du[1] = a
    return 0


@nb.cfunc(GUARDS, cache=False)
def sw_guards(mode, p, mem, G):
    for i in range(5):
        G[0, i] = 0.0
    if mode == 0:
        G[0, 0] = -1.0
        G[0, 2] = 1.0
    else:
        G[0, 0] = 1.0
        G[0, 2] = -1.0
    return 1


@nb.cfunc(TRANS, cache=False)
def sw_trans(mode, k, t, c, s, u, p, mem):
    mem[0] += 1.0
    return 1 - mode


@nb.cfunc(INIT, cache=False)
def sw_init(c, s, u, p, mem):
    return 1 if u[0] > 1.0 else 0


@nb.cfunc(LIN, cache=False)
def sw_linear(mode, p, out):
    if mode == 0:
        out[0] = p[0] * p[0]
        out[1] = p[1]
        out[2] = 0.0
    else:
        out[0] = p[0] * p[0] + 4.0
        out[1] = p[1] + 0.2
        out[2] = 4.0
    out[3] = p[2]
    return 1


@nb.cfunc(CURVED, cache=False)
def no_curved(mode, k, t, c, s, u, p, mem, grad):
    return math.nan


@nb.cfunc(LIN, cache=False)
def osc_linear_general(mode, p, out):
    """The same oscillator in the general form (``linmodes``): u' = A u + b + f_c cos, any n
    (u[2:] decay as dz/dt = -z)."""
    n = int(round(math.sqrt(out.shape[0] + 2.25) - 1.5))  # len(out) = n^2 + 3n
    for i in range(out.shape[0]):
        out[i] = 0.0
    out[1] = 1.0
    out[n] = -p[0] * p[0]
    out[n + 1] = -p[1]
    for i in range(2, n):
        out[i * n + i] = -1.0
    out[n * n + 1] = p[5]
    out[n * n + n + 1] = p[2]
    return 2


LINEAR = (osc_field, no_jac, no_guards, impact, init_free, osc_linear, no_curved)
IMPACT = (osc_field, no_jac, stop_guard, impact, init_free, osc_linear, no_curved)
SWITCH = (sw_field, no_jac, sw_guards, sw_trans, sw_init, sw_linear, no_curved)
STUCK = (osc_field, no_jac, stop_guard, stuck, init_free, osc_linear, no_curved)


# a curved guard: the phase-plane disc (X - 2)^2 + V^2 <= rho^2 (rho = p[P_R]);
# mode 0 outside it, mode 1 inside; each crossing time is stored in mem[1:], mem[0] counts
_DISC_A = 2.0


@nb.cfunc(GUARDS, cache=False)
def disc_guards(mode, p, mem, G):
    n = G.shape[1] - 3
    for i in range(G.shape[1]):
        G[0, i] = 0.0
    G[0, n] = math.nan  # curved
    return 1


@nb.cfunc(CURVED, cache=False)
def disc_curved(mode, k, t, c, s, u, p, mem, grad):
    rho = p[P_R]
    sg = 1.0 if mode == 0 else -1.0  # >= 0 outside the disc in mode 0, inside in mode 1
    dx = u[0] - _DISC_A
    grad[0] = sg * 2.0 * dx
    grad[1] = sg * 2.0 * u[1]
    for i in range(2, grad.shape[0]):
        grad[i] = 0.0
    return sg * (dx * dx + u[1] * u[1] - rho * rho)


@nb.cfunc(TRANS, cache=False)
def disc_trans(mode, k, t, c, s, u, p, mem):
    i = int(mem[0])
    if i + 1 < mem.shape[0]:
        mem[i + 1] = t
    mem[0] = i + 1.0
    return 1 - mode


DISC = (osc_field, no_jac, disc_guards, disc_trans, init_free, osc_linear, disc_curved)
LINEAR_G = (osc_field, no_jac, no_guards, impact, init_free, osc_linear_general, no_curved)
IMPACT_G = (osc_field, no_jac, stop_guard, impact, init_free, osc_linear_general, no_curved)


def make_opts(rtol=1e-10, atol=1e-12, n=2, nmem=0, closed=False, max_steps=100_000):
    o = np.zeros(N_OPTS)
    o[OPT_RTOL] = rtol
    o[OPT_ATOL] = atol
    o[OPT_MAX_STEPS] = max_steps
    o[OPT_OMEGA] = P_OM
    o[OPT_N] = n
    o[OPT_NMEM] = nmem
    o[OPT_CLOSED_FORM] = 1.0 if closed else 0.0
    return o


def make_state(X, V, extra=(), mem=(), mode=-1):
    s = np.zeros(N_STATE)
    s[ST_X] = X
    s[ST_V] = V
    s[ST_MODE] = mode
    s[ST_H] = 0.0
    s[ST_EXTRA:ST_EXTRA + len(extra)] = extra
    s[ST_EXTRA + len(extra):ST_EXTRA + len(extra) + len(mem)] = mem
    return s


def run(fns, p, opts, state, per_period=1, n_skip=0, n_out=1):
    X = np.empty(n_out)
    V = np.empty(n_out)
    R = np.empty(n_out, np.int8)
    M = np.empty(n_out, np.uint8)
    Xmax = np.empty(n_out)
    Xmin = np.empty(n_out)
    code = advance_generic(fns, np.asarray(p, float), opts, state, per_period, n_skip, n_out, X,
                           V, R, M, Xmax, Xmin)
    return code, X, V, R, M, Xmax, Xmin


def params(w0=1.3, xi=0.1, F0=0.7, om=1.0, r=0.8, b=0.0):
    return np.array([w0, xi, F0, om, r, b])


def steady(p):
    """Analytic steady state of the forced linear oscillator at t = 0 (mod T): amplitude and
    phase, X = a cos(omega t - phi)."""
    w0, xi, F0, om = p[P_W0], p[P_XI], p[P_F0], p[P_OM]
    a = F0 / math.sqrt((w0 * w0 - om * om) ** 2 + (xi * om) ** 2)
    phi = math.atan2(xi * om, w0 * w0 - om * om)
    return a * math.cos(-phi), -a * om * math.sin(-phi), a


@pytest.mark.parametrize("closed,tol", [(False, 1e-7), (True, 1e-12)])
def test_linear_oscillator_steady_state(closed, tol):
    p = params()
    X0, V0, a = steady(p)
    state = make_state(X0 + 0.3, V0 - 0.2)  # with a transient that decays (xi = 0.1)
    p2 = params(xi=0.6)  # faster decay: exp(-0.3 * 50 * 2 pi) ~ 1e-41
    X0, V0, a = steady(p2)
    code, X, V, R, M, Xmax, Xmin = run(LINEAR, p2, make_opts(closed=closed), state,
                                       per_period=4, n_skip=196, n_out=4)
    assert code == st.OK
    assert abs(X[-1] - X0) < tol and abs(V[-1] - V0) < tol
    assert np.all(R == 0) and np.all(M == 1)
    # extremes over a full period are +-a (interior extrema located)
    assert abs(Xmax.max() - a) < 100 * tol and abs(Xmin.min() + a) < 100 * tol
    # starting exactly on the orbit: the stroboscopic point is a fixed point
    state = make_state(X0, V0)
    code, X, V, *_ = run(LINEAR, p2, make_opts(closed=closed), state, n_out=50)
    assert code == st.OK
    assert np.max(np.abs(X - X0)) < tol and np.max(np.abs(V - V0)) < tol


@pytest.mark.parametrize("fns,closed", [(SWITCH, False), (SWITCH, True), (IMPACT, False),
                                        (IMPACT, True)])
def test_split_invariance(fns, closed):
    p = params(w0=1.0, xi=0.05, F0=1.0, om=0.8)
    opts = make_opts(rtol=1e-8, atol=1e-10, nmem=1, closed=closed)
    s1 = make_state(0.2, 0.0, mem=(0.0,))
    one = run(fns, p, opts, s1, per_period=5, n_skip=0, n_out=50)
    s2 = make_state(0.2, 0.0, mem=(0.0,))
    a = run(fns, p, opts, s2, per_period=5, n_skip=35, n_out=0)
    b = run(fns, p, opts, s2, per_period=5, n_skip=0, n_out=15)
    assert one[0] == a[0] == b[0] == st.OK
    for k in range(1, 7):
        assert np.array_equal(one[k][35:], b[k])
    assert np.array_equal(s1, s2)
    assert s1[ST_EXTRA] >= 5  # switches (or impacts) happened and were counted
    if fns is SWITCH:
        assert np.any(one[4] == 3)  # both modes visited within some interval
    else:
        assert np.all(one[4] == 1)  # impacts keep the mode


def _scipy_impacts(p, X0, V0, t_end):
    from scipy.integrate import solve_ivp

    w0, F0, om, r = p[P_W0], p[P_F0], p[P_OM], p[P_R]
    xi = p[P_XI]

    def f(t, y):
        return [y[1], -w0 * w0 * y[0] - xi * y[1] + F0 * math.cos(om * t)]

    def ev(t, y):
        return y[0] - 1.0

    ev.terminal = True
    ev.direction = 1.0
    t0, y0 = 0.0, [X0, V0]
    times, states = [], []
    while t0 < t_end:
        sol = solve_ivp(f, (t0, t_end), y0, method="DOP853", rtol=1e-12, atol=1e-12,
                        events=ev, dense_output=True)
        if sol.status == 1:
            te = sol.t_events[0][0]
            ye = sol.y_events[0][0]
            times.append(te)
            states.append(ye.copy())
            t0, y0 = te, [1.0, -r * ye[1]]
        else:
            return times, states, sol.y[:, -1]
    return times, states, np.array(y0)


@pytest.mark.parametrize("closed", [False, True, "general"])
def test_impact_oscillator_vs_scipy(closed):
    p = params(w0=1.0, xi=0.05, F0=1.0, om=0.8, r=0.8)
    T = 2 * math.pi / p[P_OM]
    n_per = 5
    times, states, y_end = _scipy_impacts(p, 0.0, 0.0, n_per * T)
    assert len(times) >= 3
    opts = make_opts(rtol=1e-11, atol=1e-13, nmem=10, closed=bool(closed))
    fns = IMPACT_G if closed == "general" else IMPACT
    state = make_state(0.0, 0.0, mem=(0.0,) * 10)
    got = []
    for k in range(n_per):  # one period per call, impact times from the model's memory
        state[ST_EXTRA:ST_EXTRA + 10] = 0.0
        code, X, V, R, M, Xmax, Xmin = run(fns, p, opts, state)
        assert code == st.OK
        got += [k * T + state[ST_EXTRA + 1 + i] for i in range(int(state[ST_EXTRA]))]
        assert Xmax[0] <= 1.0 + 1e-9  # Hermite extrema: interpolation error ~ tolerance
    assert len(got) == len(times)
    assert np.max(np.abs(np.array(got) - np.array(times))) < 1e-7
    assert abs(state[ST_X] - y_end[0]) < 1e-7 and abs(state[ST_V] - y_end[1]) < 1e-7


def _dip_above_the_stop(closed, excess):
    """X = A cos(t - 0.15), A = 1 + excess, unforced, from t = 0 against the stop at X = 1:
    (status, time of the first impact, Xmax of the interval)."""
    A = 1.0 + excess
    p = params(w0=1.0, xi=0.0, F0=0.0, om=0.5, r=0.8)
    opts = make_opts(rtol=1e-11, atol=1e-13, nmem=3, closed=bool(closed))
    state = make_state(A * math.cos(0.15), A * math.sin(0.15), mem=(0.0,) * 3)
    code, X, V, R, M, Xmax, Xmin = run(IMPACT_G if closed == "general" else IMPACT, p, opts,
                                       state)
    assert state[ST_EXTRA] >= 1  # impacts counted
    return code, state[ST_EXTRA + 1], Xmax[0]


@pytest.mark.parametrize("closed,tol", [(False, 1e-4), (True, 1e-9), ("general", 1e-9)])
def test_dip_inside_a_closed_form_piece_is_not_missed(closed, tol):
    """X rises 1e-6 above the stop at X = 1 inside the first closed-form piece [0, 0.7]. The
    cubic Hermite of (g, g') over that piece has its minimum 0.0027 away from the true one,
    where g is positive again, so a test of g at the Hermite's minimum misses the impact; the
    certified test finds it at t = 0.15 - arccos(1 / A) (closed form; on RKF45 steps the
    crossing is located on the step's interpolant, whose error is magnified by the grazing
    slope)."""
    code, t_hit, xmax = _dip_above_the_stop(closed, 1e-6)
    assert code == st.OK
    assert abs(t_hit - (0.15 - math.acos(1.0 / (1.0 + 1e-6)))) < tol
    assert xmax <= 1.0 + 1e-9


@pytest.mark.parametrize("closed", [True, "general"])
@pytest.mark.parametrize("excess", [1e-9, 1e-12, 1e-14])
def test_a_nearly_tangential_touch_on_a_closed_form_piece_is_located(closed, excess):
    """As above, with X rising only ``excess`` above the stop: the guard's two roots lie
    2 sqrt(2 excess) apart, its slope at the first is sqrt(2 excess), so Newton's steps on the
    closed form (``hybrid._locate_cf``) converge slowly there and the location goes on by
    Illinois; the impact is still found (status OK), at 0.15 - arccos(1 / A) to the time
    that the guard's round-off allows (1e-16 / slope, and as much in the reference's arccos:
    a tenth of the bound asked); X never rises above the stop by half the excess (a missed
    impact would reach the whole of it)."""
    code, t_hit, xmax = _dip_above_the_stop(closed, excess)
    assert code == st.OK
    slope = math.sqrt(2.0 * excess)
    assert abs(t_hit - (0.15 - math.acos(1.0 / (1.0 + excess)))) < 1e-9 + 1e-15 / slope
    assert xmax < 1.0 + 0.5 * excess


def test_three_dimensional_state_and_memory():
    p = params(xi=0.6)
    X0, V0, a = steady(p)
    opts = make_opts(n=3, nmem=2)
    state = make_state(X0, V0, extra=(1.0,), mem=(0.0, 0.0))
    code, X, V, *_ = run(LINEAR, p, opts, state, n_out=3)
    assert code == st.OK
    T = 2 * math.pi / p[P_OM]
    assert abs(state[ST_EXTRA] - math.exp(-3 * T)) < 1e-9 * math.exp(-3 * T) + 1e-14
    assert abs(X[-1] - X0) < 1e-7 and abs(V[-1] - V0) < 1e-7
    # impacts with n = 3: the memory slots written by transition come back in state
    p = params(w0=1.0, xi=0.05, F0=1.0, om=0.8)
    state = make_state(0.0, 0.0, extra=(1.0,), mem=(0.0, 0.0))
    code, *_ = run(IMPACT, p, opts, state, n_out=2)
    assert code == st.OK
    assert state[ST_EXTRA + 1] >= 1.0  # impact count
    assert 0.0 < state[ST_EXTRA + 2] < 2 * math.pi / 0.8  # first impact time (local)


def test_non_finite_and_zeno():
    p = params()
    code, *_ = run(LINEAR, p, make_opts(), make_state(np.nan, 0.0))
    assert code == st.NON_FINITE
    # a ball pushed onto the stop by a constant force bounces with ever shorter flights
    # (Zeno time 1 + 1.6 / 0.2 = 9 < 2 T)
    p = params(w0=0.0, xi=0.0, F0=0.0, om=1.0, r=0.8, b=1.0)
    state = make_state(0.5, 0.0, mem=(0.0,))
    code, *_ = run(IMPACT, p, make_opts(nmem=1), state, n_out=3)
    assert code == st.ZENO
    assert state[ST_EXTRA] > 64 and abs(state[ST_X] - 1.0) < 1e-9
    # a transition that leaves the guard violated: ZENO, not a hang
    p = params(w0=1.0, xi=0.0, F0=0.0, om=1.0, b=2.0)
    code, *_ = run(STUCK, p, make_opts(), make_state(0.5, 0.0))
    assert code == st.ZENO


def test_workspace_views_write_through_without_owning():
    from nonsmooth.integrate.workspace import keep_alive, unowned, view

    @nb.njit
    def fill(ws, Y):
        a = view(ws, 2, (3,))
        b = view(ws, 5, (2, 3))
        a[:] = 1.0
        b[1, 2] = 7.0
        Z = unowned(Y)
        Z[0, 1] = 5.0
        keep_alive(ws)
        return b.strides[0], b.strides[1], b[0, 0]

    ws = np.zeros(12)
    Y = np.zeros((2, 2))
    assert fill(ws, Y) == (24, 8, 0.0)
    assert ws.tolist() == [0, 0, 1, 1, 1, 0, 0, 0, 0, 0, 7, 0]
    assert Y[0, 1] == 5.0


@nb.cfunc(TRANS, cache=False)
def disc_trans_state(mode, k, t, c, s, u, p, mem):
    """As ``disc_trans``, storing (t, X, V) of each crossing."""
    i = int(mem[0])
    if 3 * i + 3 < mem.shape[0]:
        mem[3 * i + 1] = t
        mem[3 * i + 2] = u[0]
        mem[3 * i + 3] = u[1]
    mem[0] = i + 1.0
    return 1 - mode


DISC_STATE = (osc_field, no_jac, disc_guards, disc_trans_state, init_free, osc_linear,
              disc_curved)


@pytest.mark.parametrize("depth", [1e-3, 1e-6, 1e-9])
@pytest.mark.parametrize("per_period", [1, 16])
def test_curved_guard_crossing_times_and_grazing(depth, per_period):
    """X'' + X = 0 from (0, 1): the orbit X = sin t, V = cos t (radius 1) dips into the disc of
    radius rho = 1 + depth about (2, 0) around t = pi/2 (a near-grazing touch, the dip lasts
    about 2 sqrt(depth), far less than a step): it enters where sin t = (5 - rho^2) / 4 and
    leaves at pi minus that. Whatever the output sampling, both crossings are found, the state
    at each is on the curved surface to 1e-12 (located on the true g), and the crossing times
    agree with the closed form up to the integration's state error divided by the crossing
    speed (about 4 sqrt(2 depth)): |dt| sqrt(depth) < 1e-11."""
    rho = 1.0 + depth
    p = params(w0=1.0, xi=0.0, F0=0.0, om=1.0, r=rho)
    opts = make_opts(rtol=1e-12, atol=1e-14, nmem=10)
    state = make_state(0.0, 1.0, mem=(0.0,) * 10)
    code, X, *_ = run(DISC_STATE, p, opts, state, per_period=per_period, n_out=per_period)
    assert code == st.OK
    mem = state[ST_EXTRA:ST_EXTRA + 10]
    assert mem[0] == 2  # in and out
    t_in = math.asin((5.0 - rho * rho) / 4.0)
    for i, want in enumerate((t_in, math.pi - t_in)):
        t, x, v = mem[3 * i + 1:3 * i + 4]
        assert abs((x - _DISC_A) ** 2 + v * v - rho * rho) < 1e-12
        assert abs(t - want) * math.sqrt(depth) < 1e-11
    assert abs(X[-1] - math.sin(2 * math.pi)) < 1e-9


def test_curved_guard_missed_dip_is_absent():
    """A disc the orbit does not reach (rho = 1 - 1e-6): no crossing at all."""
    p = params(w0=1.0, xi=0.0, F0=0.0, om=1.0, r=1.0 - 1e-6)
    state = make_state(0.0, 1.0, mem=(0.0,) * 3)
    code, *_ = run(DISC, p, make_opts(rtol=1e-10, atol=1e-12, nmem=3), state, n_out=5)
    assert code == st.OK and state[ST_EXTRA] == 0


def test_general_linear_modes_in_closed_form():
    """Linear modes in the general form (``linmodes``: the series of the augmented matrix
    exponential) against closed forms: the forced oscillator's steady state (as the
    oscillator's own closed form), free flight under a constant force with harmonic forcing
    (A singular: X = X0 + V0 t + b t^2 / 2 + F0 (1 - cos t)), and an extra component decaying
    as exp(-t), all to round-off; the piece count does not depend on the output sampling."""
    p = params(xi=0.6)
    X0, V0, a = steady(p)
    state = make_state(X0, V0)
    code, X, V, R, M, Xmax, Xmin = run(LINEAR_G, p, make_opts(closed=True), state, n_out=20)
    assert code == st.OK
    assert np.max(np.abs(X - X0)) < 1e-12 and np.max(np.abs(V - V0)) < 1e-12
    assert abs(Xmax.max() - a) < 1e-12 and abs(Xmin.min() + a) < 1e-12
    # free flight: w0 = xi = 0, X'' = F0 cos t + b
    F0, b, X0, V0 = 0.7, -1.0, 0.3, 2.0
    p = params(w0=0.0, xi=0.0, F0=F0, om=1.0, b=b)
    for per_period in (1, 16):
        state = make_state(X0, V0, extra=(1.0,))
        code, X, V, *_ = run(LINEAR_G, p, make_opts(closed=True, n=3), state,
                             per_period=per_period, n_out=3 * per_period)
        assert code == st.OK
        t = 2 * math.pi * np.arange(1, 4)
        want = X0 + V0 * t + 0.5 * b * t ** 2 + F0 * (1 - np.cos(t))
        got = X[per_period - 1::per_period]
        assert np.max(np.abs(got - want)) < 1e-12 * np.abs(want).max()
        assert abs(V[-1] - (V0 + b * t[-1])) < 1e-12 * abs(V0 + b * t[-1])
        assert abs(state[ST_EXTRA] - math.exp(-t[-1])) < 1e-13 * math.exp(-t[-1])


def test_series_primitives_against_exact_arithmetic():
    """``linmodes``' evaluation primitives against oracles: ``pval`` / ``pvalue`` (Horner in
    s^4 over four residues) and the bound ``poly_m4`` against the same sums in exact rational
    arithmetic, to a few ulp of the sum of the terms' magnitudes, and each coefficient alone
    exactly (random coefficients scaled as a series' hide the top orders); ``taylor_terms`` from
    ``series_powers`` (M^j / j! once per mode) summed at s against scipy's ``expm(M s) z0``,
    and ``poly_tangent`` against ``expm(A s)`` on the state rows of tangent vectors."""
    from fractions import Fraction

    import scipy.linalg

    from nonsmooth.integrate.linmodes import (N_TAYLOR, THETA_POLY, lin_matrix, poly_m4,
                                              poly_tangent, propagate_state, pval, pvalue,
                                              series_powers, series_propagator, taylor_terms)
    rng = np.random.default_rng(7)
    fact = np.array([float(math.factorial(j)) for j in range(N_TAYLOR + 1)])
    for _ in range(20):
        c = rng.normal(size=N_TAYLOR + 1) * 2.0 ** np.arange(N_TAYLOR + 1) / fact
        s = float(rng.uniform(-1.0, 1.0))
        b = float(rng.uniform(0.0, 1.0))
        cf = [Fraction(x) for x in c]
        sf, bf = Fraction(s), Fraction(b)
        val = sum(cf[j] * sf ** j for j in range(N_TAYLOR + 1))
        der = sum(j * cf[j] * sf ** (j - 1) for j in range(1, N_TAYLOR + 1))
        m4 = sum(abs(cf[j]) * j * (j - 1) * (j - 2) * (j - 3) * bf ** (j - 4)
                 for j in range(4, N_TAYLOR + 1))
        scale = float(sum(abs(cf[j]) * abs(sf) ** j for j in range(N_TAYLOR + 1)))
        dscale = float(sum(j * abs(cf[j]) * abs(sf) ** (j - 1) for j in range(1, N_TAYLOR + 1)))
        v, d = pval(c, s)
        assert abs(v - float(val)) <= 8 * 2.0 ** -52 * scale
        assert abs(d - float(der)) <= 8 * 2.0 ** -52 * dscale
        assert pvalue(c, s) == v
        assert abs(poly_m4(c, b) - float(m4)) <= 8 * 2.0 ** -52 * float(m4)
    for j in range(N_TAYLOR + 1):  # each coefficient on its own, exactly (powers of 2)
        e = np.zeros(N_TAYLOR + 1)
        e[j] = 1.0
        assert pval(e, 0.5) == (0.5 ** j, j * 0.5 ** (j - 1) if j else 0.0)
        assert poly_m4(e, 0.5) == (j * (j - 1) * (j - 2) * (j - 3) * 0.5 ** (j - 4) if j >= 4
                                   else 0.0)
    n, om = 3, 1.3
    A = rng.normal(size=(n, n))
    lin = np.concatenate([A.ravel(), rng.normal(size=3 * n)])
    m = n + 3
    PW = np.zeros((m * m, N_TAYLOR + 1))
    rho = lin_matrix(lin, n, om, PW[:, 1])
    Mx = PW[:, 1].copy()
    series_powers(m, PW)
    u = rng.normal(size=n)
    C, S = math.cos(0.4), math.sin(0.4)
    TW = np.zeros((m, N_TAYLOR + 1))
    taylor_terms(PW, n, u, C, S, TW, np.ones(m))
    # only the rows asked for are written (the constant's always), each as when all are
    for need in ([0.0, 1.0, 0.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0, 1.0, 0.0]):
        TW1 = np.full((m, N_TAYLOR + 1), np.nan)
        taylor_terms(PW, n, u, C, S, TW1, np.array(need))
        assert np.array_equal(TW1[1], TW[1]) and np.isnan(TW1[0, 1:]).all() \
            and np.isnan(TW1[2, 1:]).all() and np.array_equal(TW1[n], TW[n])
        assert np.array_equal(TW1[n + 1:], TW[n + 1:]) if need[n + 1] \
            else np.isnan(TW1[n + 1:, 1:]).all()
    z0 = np.concatenate([u, [1.0, C, S]])
    for s in (0.3 / rho, THETA_POLY / rho):  # up to a full piece
        want = scipy.linalg.expm(Mx.reshape(m, m) * s) @ z0
        got = np.array([pvalue(TW[i], s) for i in range(m)])
        assert np.max(np.abs(got - want)) < 1e-13 * np.abs(want).max()
        assert abs(got[n + 1] - math.cos(0.4 + om * s)) < 1e-14  # the forcing rows rotate
        # the end of a piece from exp(M s)'s state rows (``series_propagator``)
        E = np.zeros((n, m))
        series_propagator(PW, n, s, E)
        u1 = np.zeros(n)
        propagate_state(E, n, u, C, S, u1)
        assert np.max(np.abs(u1 - want[:n])) < 1e-13 * np.abs(want).max()
        # the tangent: exp(A s) on the state rows, memory rows left alone; from E the same
        Y = rng.normal(size=(n + 1, 2))
        want_Y = Y.copy()
        want_Y[:n] = scipy.linalg.expm(A * s) @ Y[:n]
        Y2 = Y.copy()
        poly_tangent(PW, n, s, Y, np.zeros((n, n)), np.zeros(n), False)
        assert np.max(np.abs(Y - want_Y)) < 1e-13 * np.abs(want_Y).max()
        poly_tangent(PW, n, s, Y2, E, np.zeros(n), True)
        assert np.array_equal(Y2, Y)


def test_series_root_and_extrema_against_closed_forms():
    """``poly_root`` brackets the first root of a series polynomial to its tolerance whichever
    first guess it takes (the Taylor cubic's for a root near the piece's start: a short bounce
    after an impact, from the surface or from above it; the Hermite's farther in), against the
    closed form of a ball's flight on a vibrating table (a parabola less a sinusoid, evaluated
    in 40-digit arithmetic: in doubles its cancellation alone would move a small bounce's root
    by 1e-12); ``poly_x_extrema`` finds the apex of the flight, also on a piece cut short (one
    sample interval), against its closed form."""
    import mpmath

    from nonsmooth.integrate.linmodes import (N_TAYLOR, THETA_POLY, guard_poly, lin_matrix,
                                              poly_root, poly_x_extrema, pval, series_powers,
                                              taylor_terms)
    g, A, om = 1.0, 0.033, 2.0 * math.pi
    n, m = 2, 5
    lin = np.zeros(n * n + 3 * n)
    lin[1] = 1.0  # Z' = V, V' = -g + A om^2 sin(om t)
    lin[n * n + 1] = -g
    lin[n * n + 2 * n + 1] = A * om * om
    PW = np.zeros((m * m, N_TAYLOR + 1))
    rho = lin_matrix(lin, n, om, PW[:, 1])
    series_powers(m, PW)
    hs = THETA_POLY / rho
    G = np.zeros((1, m))
    G[0, 0] = 1.0
    TW = np.zeros((m, N_TAYLOR + 1))
    cp = np.zeros(N_TAYLOR + 1)
    cv = np.zeros(N_TAYLOR + 1)
    taken = set()
    mp = mpmath.mp.clone()
    mp.dps = 40
    for z0, v0, ph in ((0.0, 1e-6, 0.3), (0.0, 1e-3, 2.5), (0.0, 0.02, 0.3), (1e-6, -1e-3, 2.5),
                       (0.0, 0.1, 2.5), (0.02, 0.3, 4.0)):
        C, S = math.cos(ph), math.sin(ph)
        mC, mS, mph = mp.cos(ph), mp.sin(ph), mp.mpf(ph)

        def z(t):  # the closed form of Z from (z0, v0) at phase ph
            t = mp.mpf(t)
            return (z0 + (v0 + A * om * mC) * t - g * t * t / 2
                    - A * (mp.sin(mph + om * t) - mS))

        def v(t):
            t = mp.mpf(t)
            return v0 + A * om * mC - g * t - A * om * mp.cos(mph + om * t)

        taylor_terms(PW, n, np.array([z0, v0]), C, S, TW, np.ones(n + 3))
        guard_poly(G, 0, n, TW, cp)
        # the first sign change of Z on a geometric grid, then the closed form's root
        ts = np.geomspace(1e-9, hs, 2001)
        neg = np.flatnonzero([z(t) < 0 for t in ts])
        assert neg.size and neg[0] > 0
        t_root = float(mp.findroot(z, (ts[neg[0] - 1], ts[neg[0]]), solver="anderson"))
        hi = min(1.0, ts[neg[0]] / hs)
        lo, hi = poly_root(cp, hs, 0.0, hi, max(z0, 0.0), pval(cp, hi * hs)[0], 1e-13)
        assert hi - lo <= 1e-13
        assert lo * hs - 1e-15 <= t_root <= hi * hs + 1e-15
        taken.add(t_root / hs < 0.25)
        # the apex of the flight up to the root (a piece cut short at the impact)
        if v0 > 0.0:
            t_apex = mp.findroot(v, (1e-12, t_root), solver="anderson")
            xmax, _ = poly_x_extrema(TW, t_root, -np.inf, np.inf, cv, rho)
            assert abs(xmax - float(z(t_apex))) <= 1e-17 + 1e-13 * abs(float(z(t_apex)))
    assert taken == {True, False}  # both first guesses were exercised


# ---- the RKF45 tangent step is the derivative of the RKF45 step -----------------------------
@nb.cfunc(FIELD, cache=False)
def coupled_field(mode, t, c, s, u, p, mem, du):
    """A nonlinear field of any dimension n that depends on the forcing phase and on memory
    slot 1 (slot 0 is a discrete flag it ignores)."""
    n = u.shape[0]
    for i in range(n):
        a = u[(i + 1) % n]
        b = u[(i + 2) % n]
        f = 0.5 * c if i == 0 else 0.4 * s
        du[i] = -0.2 * u[i] + math.sin(a) + 0.3 * mem[1] * b * b + f + 0.25 * c * u[i] * u[i]
    return 0


@nb.cfunc(JAC, cache=False)
def coupled_jacobian(mode, t, c, s, u, p, mem, J):
    """Adds into the memory column (the kernel zeroes it before each call) and writes a
    column of the discrete slot 0 that the tangent must ignore."""
    n = u.shape[0]
    for i in range(n):
        for q in range(n):
            J[i, q] = 0.0
    for i in range(n):
        a = u[(i + 1) % n]
        b = u[(i + 2) % n]
        J[i, i] += -0.2 + 0.5 * c * u[i]
        J[i, (i + 1) % n] += math.cos(a)
        J[i, (i + 2) % n] += 0.6 * mem[1] * b
        J[i, n + 1] += 0.3 * b * b  # d/d mem[1]
        J[i, n] = 123.0  # slot 0: not continuous
    return 0


@nb.njit(cache=True)
def _rk_step_and_tangent(field, jacobian, u, mem, h, om, Y):
    """One RKF45 step of ``field`` from (tau, C, S) = (0.3, cos 0.7, sin 0.7) and its tangent
    (``hybrid._rk_tangent``, memory slot 1 continuous) applied to Y (rows: u, then slot 1).
    Returns the step's end state."""
    n = u.shape[0]
    m = Y.shape[1]
    p = np.zeros(1)
    C, S = math.cos(0.7), math.sin(0.7)
    k0, k1, k2, k3, k4, k5 = (np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n),
                              np.zeros(n))
    us, u1 = np.zeros(n), np.zeros(n)
    field(0, 0.3, C, S, u, p, mem, k0)
    _rk_step(field, 0, 0.3, C, S, h, om, n, u, k0, p, mem, 1e-8, 1e-10, us, k1, k2, k3, k4, k5,
             u1)
    cmi = np.ones(1, np.int64)
    _rk_tangent(jacobian, 0, 0.3, C, S, h, om, n, u, k0, k1, k2, k3, k4, k5, p, mem, Y,
                np.zeros(n), np.zeros((_NS, n, m)), np.zeros((n, n + 2)),
                np.zeros((_NS, n, n + 2)), us, cmi, 1e-8, 1e-10)
    return u1


def precompile():
    """Compile (or load) ``_rk_step_and_tangent`` for the argument types of its tests."""
    _rk_step_and_tangent(coupled_field, coupled_jacobian, np.zeros(2), np.array([1.0, 0.8]), 0.37,
                         1.3, np.eye(3))


@pytest.mark.parametrize("n", [2, 3, 4, 5])
def test_rk_tangent_is_the_derivative_of_the_rk_step(n):
    """The tangent of an RKF45 step (the two- and four-state paths written in scalars, the
    general loop for 3 and 5 states), memory slot 1 as a continuous coordinate, equals central
    differences of the same step in u and in the slot."""
    _check_tangent_against_differences(_rk_step_and_tangent, n)


def _check_tangent_against_differences(step_and_tangent, n):
    """The tangent that ``step_and_tangent`` carries through one step of ``coupled_field`` from
    a random point (every direction: the step's whole Jacobian) against central differences
    of the same step in u and in memory slot 1."""
    rng = np.random.default_rng(n)
    u = rng.uniform(-1.0, 1.0, n)
    mem = np.array([1.0, 0.8])
    h, om = 0.37, 1.3
    Y = np.eye(n + 1)
    step_and_tangent(coupled_field, coupled_jacobian, u, mem, h, om, Y)
    eps = 1e-6
    F = np.zeros((n, n + 1))
    for j in range(n + 1):
        up, um, mp, mm = u.copy(), u.copy(), mem.copy(), mem.copy()
        if j < n:
            up[j] += eps
            um[j] -= eps
        else:
            mp[1] += eps
            mm[1] -= eps
        F[:, j] = (step_and_tangent(coupled_field, coupled_jacobian, up, mp, h, om,
                                    np.zeros((n + 1, 0)))
                   - step_and_tangent(coupled_field, coupled_jacobian, um, mm, h, om,
                                      np.zeros((n + 1, 0)))) / (2 * eps)
    assert np.max(np.abs(Y[:n] - F)) <= 1e-8 * np.max(np.abs(F))
    assert np.array_equal(Y[n], np.eye(n + 1)[n])  # the memory row is constant in a mode


def test_rk8_dense_output_is_scipys_dop853_interpolant():
    """The DOP853 step of the generic kernel (``integrate.rk8``, the plain runs at rtol below
    1e-10) and its dense output written as a polynomial piece: the step's end and the
    interpolant at interior points against scipy's own DOP853 step and dense output (the same
    method: to round-off), the forcing rows against cos and sin."""
    from scipy.integrate import DOP853

    from nonsmooth.integrate import rk8
    from nonsmooth.integrate.linmodes import N_TAYLOR, pval7

    om, tau, h = 1.3, 0.4 / 1.3, 0.2
    C, S = math.cos(om * tau), math.sin(om * tau)

    def field(mode, t, c, s, u, p, mem, du):
        du[0] = u[1]
        du[1] = -u[0] - 0.3 * u[0] ** 3 + 0.5 * c
        return 0

    u = np.array([0.3, -0.2])
    k0, u1, f1, us = np.zeros(2), np.zeros(2), np.zeros(2), np.zeros(2)
    field(0, tau, C, S, u, None, None, k0)
    K = np.zeros((16, 2))
    TW = np.zeros((5, N_TAYLOR + 1))
    err2, C1, S1 = rk8.rk8_step.py_func(field, 0, tau, C, S, h, om, 2, u, k0, None, None, 1e-6,
                                        1e-8, us, K, u1, f1)
    rk8.rk8_dense.py_func(field, 0, tau, C, S, h, om, 2, u, u1, f1, None, None, us, K, TW)
    ref = DOP853(lambda t, y: np.array([y[1], -y[0] - 0.3 * y[0] ** 3 + 0.5 * math.cos(om * t)]),
                 tau, u, tau + 10, first_step=h, max_step=h, rtol=1e-3, atol=1e-3)
    ref.step()
    assert abs(ref.t - (tau + h)) < 1e-15 and np.abs(ref.y - u1).max() < 1e-15
    assert abs(C1 - math.cos(om * (tau + h))) < 1e-15 and abs(S1 - math.sin(om * (tau + h))) < 1e-15
    dense = ref.dense_output()
    for x in (0.0, 0.3, 0.5, 0.77, 1.0):
        s = x * h
        got = np.array([np.polyval(TW[i][::-1], s) for i in range(5)])
        assert np.abs(got[:2] - dense(tau + s)).max() < 1e-15
        assert got[2] == 1.0
        assert abs(got[3] - math.cos(om * (tau + s))) < 1e-15
        assert abs(got[4] - math.sin(om * (tau + s))) < 1e-15
        for i in range(2):  # the kernel's degree-7 evaluation of these rows, and its derivative
            v, d = pval7(TW[i], s)
            assert abs(v - got[i]) < 1e-15
            assert abs(d - np.polyval(np.polyder(TW[i][:8][::-1]), s)) < 1e-14


def _rk8_step_and_tangent(field, jacobian, u, mem, h, om, Y):
    """``_rk_step_and_tangent`` for the DOP853 step (``rk8.rk8_step``, ``rk8.rk8_tangent``)."""
    from nonsmooth.integrate import rk8

    n = u.shape[0]
    m = Y.shape[1]
    p = np.zeros(1)
    C, S = math.cos(0.7), math.sin(0.7)
    k0, us, u1, f1 = np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n)
    K = np.zeros((16, n))
    field(0, 0.3, C, S, u, p, mem, k0)
    rk8.rk8_step(field, 0, 0.3, C, S, h, om, n, u, k0, p, mem, 1e-8, 1e-10, us, K, u1, f1)
    rk8.rk8_tangent(jacobian, 0, 0.3, C, S, h, om, n, u, K, p, mem, Y, np.zeros(n),
                    np.zeros((rk8.N_STAGES8, n, m)), np.zeros((n, n + 2)), us,
                    np.ones(1, np.int64), 1e-8, 1e-10)
    return u1


@pytest.mark.parametrize("n", [2, 4])
def test_rk8_tangent_is_the_derivative_of_the_rk8_step(n):
    """The tangent of a DOP853 step (the runs at rtol below 1e-10), memory slot 1 as a
    continuous coordinate, equals central differences of the same step in u and in the
    slot."""
    _check_tangent_against_differences(_rk8_step_and_tangent, n)


def test_cached_guard_bounds_equal_the_computed_ones():
    """``hybrid._cf_bounds_cached`` (a closed-form mode re-entered with a guard set it had:
    the support's free flight below and above X = 1) gives the coefficients that
    ``_cf_bounds`` computes, for every set of a sequence that revisits, changes and evicts
    sets, and only the sets it was given."""
    from nonsmooth.integrate.contract import MAX_GUARDS
    from nonsmooth.integrate.hybrid import (CF_SLOTS, MAX_MODES, _cf_bounds, _cf_bounds_cached)
    from nonsmooth.integrate.pwlinear import N_BD, N_MC, mode_coeffs

    n, om = 2, 0.9
    MC = np.zeros((MAX_MODES, N_MC))
    assert mode_coeffs(1.0, 0.1, 0.0, 0.5, om, 0.7, MC[0])
    assert mode_coeffs(5.0, 0.3, 4.0, 0.5, om, 0.7, MC[1])
    rows = {"below": [[-1.0, 0.0, 1.0, 0.0, 0.0]], "above": [[-1.0, -0.07, 1.0, 0.0, 0.0]],
            "forced": [[1.0, 0.2, -1.0, 0.3, -0.4]], "two": [[1.0, 0.0, -1.0, 0, 0],
                                                         [0.0, 1.0, 0.5, 0, 0]]}
    GBC = np.zeros((MAX_MODES, CF_SLOTS, MAX_GUARDS, N_BD))
    GKC = np.zeros((MAX_MODES, CF_SLOTS, MAX_GUARDS, n + 3))
    GNC = np.zeros((MAX_MODES, CF_SLOTS + 1))
    seq = [(0, "below"), (1, "forced"), (0, "above"), (0, "below"), (0, "above"), (1, "two"),
           (0, "forced"), (0, "below"), (0, "above"), (1, "forced"), (1, "two"), (0, "below")]
    for mode, key in seq:
        G = np.zeros((MAX_GUARDS, n + 3))
        ng = len(rows[key])
        G[:ng] = rows[key]
        want = np.full((MAX_GUARDS, N_BD), -1.0)
        got = np.full((MAX_GUARDS, N_BD), -1.0)
        _cf_bounds(MC, mode, om, G, ng, n, want)
        _cf_bounds_cached(MC, mode, om, G, ng, n, got, GBC, GKC, GNC)
        assert np.array_equal(got, want), (mode, key)
        assert np.all(got[ng:] == -1.0)  # rows beyond ng untouched
