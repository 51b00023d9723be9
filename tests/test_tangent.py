"""The tangent kernel (``integrate.hybrid.advance_tangent`` via ``nonsmooth.tangent``) against
independent oracles.

1. The monodromy of the k-period map equals central finite differences of the same kernel's
   map (``run`` on the generic kernel), for every built-in model and both methods, on orbits
   that cross every kind of switch of the model (checked with the mode bit masks).
2. Determinants (Liouville's formula and saltation determinants) with independently computed
   switching times (scipy's DOP853 with events):
   (a) support, exact: det = exp(-xi T - xi_s t_c);
   (b) impact, exact, period-1 orbit with one impact: det = exp(-xi T) r^2;
   (c) impact, smooth (no continuous memory): det = exp(-xi T - c t_c), c the contact damping.
3. Stick-slip: a period with a stick phase has a singular monodromy (rank 1; trajectories
   merge in stick), equal to finite differences.
"""

from __future__ import annotations

import math
import warnings

import numba as nb
import numpy as np
import pytest
from scipy.integrate import solve_ivp

warnings.filterwarnings("ignore", category=nb.NumbaExperimentalFeatureWarning)

import nonsmooth as ns  # noqa: E402
from nonsmooth import status as st  # noqa: E402
from nonsmooth.integrate.contract import ST_MODE  # noqa: E402
from nonsmooth.kernels import Solver, new_state, output_buffers, run  # noqa: E402
from nonsmooth.models.base import KERNEL_GENERIC  # noqa: E402
from nonsmooth.models.impact import contact_damping  # noqa: E402
from nonsmooth.tangent import TangentSetup, fd_period_map, period_map  # noqa: E402

pytestmark = pytest.mark.filterwarnings("ignore::numba.NumbaExperimentalFeatureWarning")

RTOL, ATOL = 1e-11, 1e-13


# ---- helpers ------------------------------------------------------------------------------
def make(model, method, params):
    m = ns.model(model)
    setup = TangentSetup(Solver(method=method, model=m, rtol=RTOL, atol=ATOL))
    return setup, params.pack()


def advance(setup, p, state, periods, per_period=1):
    """Advance ``state`` in place by ``periods`` outputs of T / per_period (the state carries no
    phase: a sub-period advance just moves the start point off the switching surfaces)."""
    if periods:
        code = run(KERNEL_GENERIC, setup.fns, p, setup.opts, state, per_period, periods, 0,
                   *output_buffers(0))
        assert code == st.OK


def start(setup, p, transient, sub=0, nsub=20, x0=0.0, v0=0.0):
    s = new_state(x0, v0)
    advance(setup, p, s, transient)
    advance(setup, p, s, sub, nsub)
    return s


fdmap = fd_period_map  # central differences of the kernel's own map


def rel_err(M, F):
    return float(np.max(np.abs(M - F)) / np.max(np.abs(F)))


def union(masks):
    u = 0
    for b in masks:
        u |= int(b)
    return u


def count_impacts(setup, p, state, k, n=4000):
    """Impacts of the exact impact model over k periods from ``state`` (a copy is advanced):
    velocity sign flips + -> - at the stop with a jump far larger than the smooth change of V
    over one sample interval."""
    s = state.copy()
    bufs = output_buffers(k * n)
    assert run(KERNEL_GENERIC, setup.fns, p, setup.opts, s, n, 0, k * n, *bufs) == st.OK
    X = np.concatenate([[state[0]], bufs[0]])
    V = np.concatenate([[state[1]], bufs[1]])
    dV = np.diff(V)
    smooth = 10.0 * np.median(np.abs(dV))
    return int(np.sum((V[:-1] > 0) & (V[1:] < 0) & (X[1:] > 0.99) & (np.abs(dV) > smooth)))


# ---- 1. monodromy vs finite differences ---------------------------------------------------
IMPACT_ORBIT = dict(omega0=1.0, xi=0.05, F0=3.0, omega=1.5, r=0.8)  # one impact per period

# (model, method, params, transient, sub-period steps (of T/20), k, required mode bits)
CASES = [
    ("support", "exact", ns.preset("table3").replace(omega=0.92), 50, 3, 3, {0, 3}),
    ("support", "smooth", ns.preset("table3").replace(omega=0.92), 50, 3, 3, {0, 1, 2, 3}),
    ("support", "smooth_eq12", ns.preset("table3").replace(omega=0.92), 50, 3, 3, {0, 1, 2, 3}),
    ("impact", "exact", ns.model("impact").params(**IMPACT_ORBIT), 200, 3, 3, {0}),
    # k_c = 1e3: a softer contact keeps the FD noise of the step-size controller (which the
    # tangent, the derivative of the discrete step at fixed h, does not see) well below 1e-6
    ("impact", "smooth", ns.model("impact").params(**IMPACT_ORBIT, k_c=1e3), 200, 3, 2, {0, 1}),
    ("stick_slip", "exact", ns.model("stick_slip").params(F0=0.5, xi=0.1), 50, 13, 2,
     {1, 2}),
    ("stick_slip", "smooth", ns.model("stick_slip").params(F0=0.5, xi=0.1), 50, 13, 2,
     {1, 2, 3}),
    ("two_sided", "exact", ns.model("two_sided").params(F0=1.0), 50, 3, 2, {0, 3, 6}),
    ("two_sided", "smooth", ns.model("two_sided").params(F0=1.0), 50, 3, 2, set(range(7))),
]


@pytest.mark.parametrize("model, method, params, transient, sub, k, need", CASES,
                         ids=[f"{c[0]}-{c[1]}" for c in CASES])
def test_monodromy_matches_finite_differences(model, method, params, transient, sub, k, need):
    setup, p = make(model, method, params)
    s0 = start(setup, p, transient, sub)
    s1, M, code, bufs = period_map(setup, p, s0, k)
    assert code == st.OK
    visited = union(bufs[3])
    assert all(visited & (1 << b) for b in need), (bin(visited), need)
    if model == "impact" and method == "exact":
        # impacts (resets inside mode free) happen: counted independently, and each one
        # multiplies the determinant by r^2
        hits = count_impacts(setup, p, s0, k)
        assert hits >= 1
        want = math.exp(-params.xi * k * params.period) * params.r ** (2 * hits)
        assert abs(np.linalg.det(M) / want - 1.0) <= 1e-8
    F = fdmap(setup, p, s0, k)
    assert rel_err(M, F) <= 1e-6


def test_impact_exact_sticking_annihilates():
    """Impact, exact, chatter that ends in sticking every period: the stuck phase forgets the
    state (released at a time fixed by the forcing), so the monodromy vanishes, as do the
    finite differences."""
    setup, p = make("impact", "exact",
                    ns.model("impact").params(omega0=1.0, xi=0.05, F0=3.0, omega=0.2, r=0.5))
    s0 = start(setup, p, 20, sub=5, nsub=10)
    assert int(s0[ST_MODE]) == 0  # free at the start
    s1, M, code, bufs = period_map(setup, p, s0, 1)
    assert code == st.OK and union(bufs[3]) & (1 << 2)  # stuck visited
    F = fdmap(setup, p, s0, 1)
    assert np.max(np.abs(F)) < 1e-8
    assert np.max(np.abs(M)) < 1e-8


# ---- 2. determinants: Liouville and saltation ---------------------------------------------
def support_contact_time(params, X0, V0, in_contact, T):
    """Time in contact of the exact support model over [0, T] from (X0, V0), scipy DOP853:
    contact starts at X = 1 moving in, ends where the support force omega_s^2 (X - 1) + xi_s V
    vanishes; free beyond X = 1 after a separation, contact resumes if that force turns
    positive again, and free-below resumes at X = 1 moving out."""
    w0, ws, xi, xis, F0, om = (params.omega0, params.omega_s, params.xi, params.xi_s,
                               params.F0, params.omega)

    def rhs(contact):
        def f(t, y):
            a = -w0 * w0 * y[0] - xi * y[1] + F0 * math.cos(om * t)
            if contact:
                a -= ws * ws * (y[0] - 1.0) + xis * y[1]
            return [y[1], a]
        return f

    def ev_x(t, y):
        return y[0] - 1.0

    def ev_force(t, y):
        return ws * ws * (y[0] - 1.0) + xis * y[1]

    t, y, tc = 0.0, np.array([X0, V0]), 0.0
    mode = "contact" if in_contact else ("beyond" if X0 > 1.0 else "free")
    for _ in range(1000):
        if mode == "contact":
            ev_force.terminal, ev_force.direction = True, -1
            evs = [ev_force]
        elif mode == "free":
            ev_x.terminal, ev_x.direction = True, 1
            evs = [ev_x]
        else:
            ev_x.terminal, ev_x.direction = True, -1
            ev_force.terminal, ev_force.direction = True, 1
            evs = [ev_x, ev_force]
        sol = solve_ivp(rhs(mode == "contact"), (t, T), y, method="DOP853", rtol=1e-12,
                        atol=1e-14, events=evs)
        t1, y1 = sol.t[-1], sol.y[:, -1]
        if mode == "contact":
            tc += t1 - t
        if sol.status == 0:
            return tc
        t, y = t1, y1
        hit = [i for i, e in enumerate(sol.t_events) if len(e)][0]
        if mode == "contact":
            mode = "beyond" if y[0] > 1.0 else "free"
        elif mode == "free":
            mode = "contact"
        else:
            mode = "free" if hit == 0 else "contact"
    raise AssertionError("too many events")


def test_support_exact_liouville():
    params = ns.preset("table3").replace(omega=0.92)
    setup, p = make("support", "exact", params)
    T = params.period
    checked = 0
    s0 = start(setup, p, 50)
    for _ in range(6):  # several different periods of the chaotic orbit
        s1, M, code, bufs = period_map(setup, p, s0, 1)
        assert code == st.OK
        mode0 = int(s0[ST_MODE])
        if union(bufs[3]) & (1 << 3) and (mode0 == 3 or s0[0] < 1.0):
            tc = support_contact_time(params, s0[0], s0[1], mode0 == 3, T)
            assert tc > 0.0
            want = math.exp(-params.xi * T - params.xi_s * tc)
            assert abs(np.linalg.det(M) / want - 1.0) <= 1e-7
            checked += 1
        s0 = s1
    assert checked >= 3


def test_impact_exact_saltation_determinant():
    params = ns.model("impact").params(**IMPACT_ORBIT)
    orb = ns.periodic_orbit(params, method="exact", transient=200)
    assert orb.attrs["status"] == "converged"
    M = orb["monodromy"].values
    T = params.period
    want = math.exp(-params.xi * T) * params.r ** 2
    assert abs(np.linalg.det(M) / want - 1.0) <= 1e-9
    # the orbit has exactly one impact per period (independent count)
    setup, p = make("impact", "exact", params)
    s0 = setup.state_of(np.array([float(orb["X_section"][0]), float(orb["V_section"][0])]),
                        new_state(0.0, 0.0))
    assert count_impacts(setup, p, s0, 1) == 1
    # and the same from the tangent kernel at the solver tolerances of this file
    _, M2, code, _ = period_map(setup, p, s0, 1)
    assert code == st.OK
    assert abs(np.linalg.det(M2) / want - 1.0) <= 1e-9


def impact_contact_time(params, X0, V0, in_contact, T):
    """Time with X > 1 of the smooth impact model over [0, T] (scipy DOP853, events X = 1)."""
    w0, xi, F0, om, kc = params.omega0, params.xi, params.F0, params.omega, params.k_c
    c = contact_damping(params.r, kc)

    def rhs(contact):
        def f(t, y):
            a = -w0 * w0 * y[0] - xi * y[1] + F0 * math.cos(om * t)
            if contact:
                a -= kc * (y[0] - 1.0) + c * y[1]
            return [y[1], a]
        return f

    def ev(t, y):
        return y[0] - 1.0

    ev.terminal = True
    t, y, tc, contact = 0.0, np.array([X0, V0]), 0.0, in_contact
    for _ in range(1000):
        ev.direction = -1 if contact else 1
        sol = solve_ivp(rhs(contact), (t, T), y, method="DOP853", rtol=1e-12, atol=1e-14,
                        events=ev)
        if contact:
            tc += sol.t[-1] - t
        if sol.status == 0:
            return tc
        t, y = sol.t[-1], sol.y[:, -1]
        contact = not contact
    raise AssertionError("too many events")


def test_impact_smooth_liouville():
    """Smooth impact model (no continuous memory; switches without reset, continuous field):
    det = exp(-int trace J dt) = exp(-xi T - c t_c). The tangent is the derivative of the
    discrete RK map, so agreement is to the integration tolerance, not to round-off."""
    params = ns.model("impact").params(**IMPACT_ORBIT, k_c=1e3)
    setup, p = make("impact", "smooth", params)
    T = params.period
    c = contact_damping(params.r, params.k_c)
    s0 = start(setup, p, 200, sub=3)
    assert int(s0[ST_MODE]) == 0
    checked = 0
    for _ in range(4):
        s1, M, code, bufs = period_map(setup, p, s0, 1)
        assert code == st.OK
        tc = impact_contact_time(params, s0[0], s0[1], int(s0[ST_MODE]) == 1, T)
        assert (tc > 0.0) == (union(bufs[3]) == 0b11)
        want = math.exp(-params.xi * T - c * tc)
        assert abs(np.linalg.det(M) / want - 1.0) <= 1e-6
        checked += tc > 0.0
        s0 = s1
    assert checked >= 2


# ---- 3. stick-slip: sticking merges trajectories ------------------------------------------
@pytest.mark.parametrize("method", ["exact", "smooth"])
def test_stick_slip_stick_period_is_singular(method):
    params = ns.model("stick_slip").params(F0=0.5, xi=0.1)
    setup, p = make("stick_slip", method, params)
    s0 = start(setup, p, 50, sub=13)
    assert int(s0[ST_MODE]) in (0, 1)  # slipping at the start (not on a band edge)
    s1, M, code, bufs = period_map(setup, p, s0, 1)
    assert code == st.OK and union(bufs[3]) & (1 << 2)  # a stick phase in the period
    n = setup.n
    Mu = M[:n, :n]
    sv = np.linalg.svd(Mu, compute_uv=False)
    assert abs(np.linalg.det(Mu)) <= 1e-12 * sv[0] ** 2
    assert sv[1] <= 1e-12 * sv[0] and sv[0] > 1e-3  # rank 1
    F = fdmap(setup, p, s0, 1)
    assert rel_err(M, F) <= 1e-6
