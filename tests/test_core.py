"""Core: tableau, integrator convergence, model against closed forms and scipy, regions."""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import nonsmooth as ns
from nonsmooth.integrate import tableau as tb
from nonsmooth.models.support.smooth_kernel import fixed_step
from nonsmooth.models.support import switch as sw
from oracles import linear_solution, steady_amplitude

FREE = ns.model("support").params(omega0=1.0, omega_s=10.0, xi=0.05, xi_s=0.3, F0=0.05, omega=0.8, eta=1e-4)


# ---------------------------------------------------------------- tableau identities
@pytest.mark.parametrize("b", [tb.RKF45_B4, tb.RKF45_B5], ids=["b4", "b5"])
def test_rkf45_order4_conditions(b):
    A, c = tb.RKF45_A, tb.RKF45_C
    np.testing.assert_allclose(A.sum(axis=1), c[:], atol=1e-15)  # row sums = nodes
    conds = [
        (b.sum(), 1.0), (b @ c, 1 / 2), (b @ c**2, 1 / 3), (b @ (A @ c[:5]), 1 / 6),
        (b @ c**3, 1 / 4), (b @ (c * (A @ c[:5])), 1 / 8), (b @ (A @ c[:5] ** 2), 1 / 12),
        (b @ (A @ (A[:5, :5] @ c[:5])), 1 / 24),
    ]
    for got, want in conds:
        assert got == pytest.approx(want, abs=1e-14)


def test_rkf45_b5_fifth_order_conditions_and_b4_not():
    A, c, b5, b4 = tb.RKF45_A, tb.RKF45_C, tb.RKF45_B5, tb.RKF45_B4
    assert b5 @ c**4 == pytest.approx(1 / 5, abs=1e-14)
    assert b5 @ (A @ c[:5] ** 3) == pytest.approx(1 / 20, abs=1e-14)
    assert b5 @ (c**2 * (A @ c[:5])) == pytest.approx(1 / 10, abs=1e-14)
    assert abs(b4 @ c**4 - 1 / 5) > 1e-4  # the embedded solution really is only order 4
    np.testing.assert_allclose(tb.RKF45_E, b5 - b4)


# ---------------------------------------------------------------- convergence order
@pytest.mark.parametrize("order", [4, 5])
def test_observed_convergence_order(order):
    p = FREE.pack()
    t_end = 10.0
    exact = linear_solution(1.0, 0.05, 0.05, 0.8, 0.0, 0.3, -0.2, t_end)
    errs = []
    for n in (40, 80, 160, 320):
        X, V = fixed_step(p, sw.GAMMA_MINUS, 0.3, -0.2, 0.0, 0, t_end, n, order)
        errs.append(math.hypot(X - exact[0], V - exact[1]))
    rates = np.log2(np.array(errs[:-1]) / np.array(errs[1:]))
    assert np.all(np.abs(rates - order) < 0.35), rates


# ---------------------------------------------------------------- adaptive accuracy
def test_free_flight_steady_state_amplitude_and_phase():
    """No contact: the settled response is A cos(omega t - phi), A = F0/sqrt(...) (<= 1e-8)."""
    p = FREE
    ds = ns.simulate(p, periods=2, transient=400, samples_per_period=64, rtol=1e-10, atol=1e-12)
    A = steady_amplitude(1.0, 0.05, 0.05, 0.8)
    phi = math.atan2(0.05 * 0.8, 1.0 - 0.8**2)
    t = ds.t.values
    X_ref = A * np.cos(0.8 * t - phi)
    V_ref = -A * 0.8 * np.sin(0.8 * t - phi)
    assert np.max(np.abs(ds.X.values - X_ref)) <= 1e-8
    assert np.max(np.abs(ds.V.values - V_ref)) <= 1e-8
    assert set(np.unique(ds.region.values)) == {sw.GAMMA_MINUS}


@pytest.mark.parametrize("rtol", [1e-5, 1e-7, 1e-9])
def test_error_proportional_to_tolerance(rtol):
    """Global error after 5 periods of a transient stays within a modest multiple of rtol
    and shrinks with it (checked for each tolerance against the closed form)."""
    p = FREE
    ds = ns.simulate(p, periods=5, samples_per_period=8, x0=0.5, v0=0.0, rtol=rtol, atol=rtol * 1e-2)
    X_ref, V_ref = linear_solution(1.0, 0.05, 0.05, 0.8, 0.0, 0.5, 0.0, ds.t.values)
    err = np.max(np.abs(ds.X.values - X_ref))
    assert err <= 50 * rtol
    assert err >= 1e-4 * rtol  # not accidentally exact: the error really scales with rtol


def test_contact_phase_matches_closed_form():
    """Deep in Gamma+ (stiff support), the solution is the closed form of eq. 4 (contact)."""
    p = ns.model("support").params(omega0=1.0, omega_s=5.0, xi=0.05, xi_s=0.1, F0=0.3, omega=0.9, eta=1e-5)
    # start well inside contact, pushing into the support, and watch a short time window
    X0, V0 = 1.3, 0.5
    ds = ns.simulate(p, periods=1, samples_per_period=4000, x0=X0, v0=V0, rtol=1e-11, atol=1e-13)
    k = 1.0 + 25.0
    X_ref, V_ref = linear_solution(k, 0.15, 0.3, 0.9, 25.0, X0, V0, ds.t.values)
    inside = np.cumprod(ds.region.values == sw.GAMMA_PLUS).astype(bool)
    assert inside.sum() > 100  # a real stretch of contact was checked
    assert np.max(np.abs(ds.X.values[inside] - X_ref[inside])) <= 1e-8
    assert np.max(np.abs(ds.V.values[inside] - V_ref[inside])) <= 1e-7


def _scipy_switch_model(params, t_end, x0, v0, rtol=1e-12, atol=1e-12):
    """Independent reference: scipy DOP853 on eqs. 10-14, restarted at every region change
    located by scipy's own event finder (region held fixed between events)."""
    P = params
    r = P.xi_s / P.omega_s**2
    ws2, w02, eta = P.omega_s**2, P.omega0**2, P.eta

    def acc(mode, t, X, V, Va):
        return sw.accel.py_func(mode, X, V, Va, P.F0 * math.cos(P.omega * t), w02, ws2, P.xi,
                                P.xi_s, eta, r, 0)

    t, X, V = 0.0, x0, v0
    mode = sw.region.py_func(X, V, eta, r)
    Va = V
    ts, Xs = [t], [X]
    while t < t_end:
        def f(tt, y, mode=mode, Va=Va):
            return [y[1], acc(mode, tt, y[0], y[1], Va)]

        def ev(tt, y, mode=mode):
            return sw.inside_margin.py_func(mode, y[0], y[1], eta, r) + 1e-15
        ev.terminal = True
        ev.direction = -1
        sol = solve_ivp(f, (t, t_end), [X, V], method="DOP853", rtol=rtol, atol=atol,
                        events=ev, dense_output=True)
        t, (X, V) = sol.t[-1], sol.y[:, -1]
        ts.append(t)
        Xs.append(X)
        if sol.status == 1:
            # step a hair past the border and switch
            new = sw.region.py_func(X, V, eta, r)
            if new == mode:
                dt = 1e-13
                X, V = X + V * dt, V + acc(mode, t, X, V, Va) * dt
                t += dt
                new = sw.region.py_func(X, V, eta, r)
            if new == sw.SIGMA_ALPHA and mode != sw.SIGMA_ALPHA:
                Va = V
            mode = new
    return X, V


def test_smoothed_model_against_scipy_dop853():
    """Table 1 preset (eta = 7.14e-3) over 3 forcing periods from rest: our RKF45 kernel at
    rtol 1e-11 versus scipy DOP853 at rtol 1e-12 with its own event location."""
    p = ns.preset("table1")
    T = p.period
    X_ref, V_ref = _scipy_switch_model(p, 3 * T, 0.0, 0.0)
    ds = ns.simulate(p, periods=3, samples_per_period=1, rtol=1e-11, atol=1e-12)
    X, V = float(ds.X[-1]), float(ds.V[-1])
    assert abs(X - X_ref) <= 1e-8 * (1 + abs(X_ref))
    assert abs(V - V_ref) <= 1e-8 * (1 + abs(V_ref))


def test_table1_visits_all_four_regions_in_order():
    """Fig. 3: Gamma- -> Sigma_alpha -> Gamma+ -> Sigma_beta -> Gamma- in every cycle."""
    ds = ns.simulate(ns.preset("table1"), periods=2, transient=30, samples_per_period=40000)
    R = ds.region.values
    runs = R[np.r_[True, R[1:] != R[:-1]]]  # consecutive distinct regions
    assert set(runs) == {0, 1, 2, 3}
    seq = "".join(map(str, runs))
    # every transition follows the cyclic order 0 -> 1 -> 3 -> 2 -> 0
    nxt = {"0": "1", "1": "3", "3": "2", "2": "0"}
    assert all(nxt[a] == b for a, b in zip(seq, seq[1:])), seq


def test_visited_mask_records_thin_bands_between_samples():
    ds = ns.simulate(ns.preset("table1"), periods=3, transient=30, samples_per_period=50)
    mask = np.bitwise_or.reduce(ds.visited.values.astype(int))
    assert mask == 0b1111


# ---------------------------------------------------------------- model continuity
def _acc(mode, X, V, Va, p, tr=0):
    r = sw.beta_ratio(p.omega_s, p.xi_s)
    return sw.accel(mode, X, V, Va, 0.1, p.omega0**2, p.omega_s**2, p.xi, p.xi_s, p.eta, r, tr)


@pytest.mark.parametrize("tr", [0, 1], ids=["eq13", "eq12"])
def test_rhs_continuous_on_band_edges(tr):
    p = ns.preset("table3")
    eta, r = p.eta, p.xi_s / p.omega_s**2
    rng = np.random.default_rng(1)
    for V in rng.uniform(-2, 2, 5):
        # Sigma_alpha / Gamma+ border (h_alpha = +eta), any entry velocity
        X = 1 + eta
        assert _acc(1, X, V, 0.7, p, tr) == pytest.approx(_acc(3, X, V, 0.7, p, tr), abs=1e-9)
        # Sigma_alpha entry edge (h_alpha = -eta) at the entry velocity
        X = 1 - eta
        assert _acc(1, X, V, V, p, tr) == pytest.approx(_acc(0, X, V, V, p, tr), abs=1e-9)
        # Sigma_beta edges: h_beta = -eta (from Gamma+) and h_beta = +eta (to Gamma-)
        for hb, other in ((-eta, 3), (eta, 0)):
            X = 1 - hb - r * V
            assert _acc(2, X, V, 0.0, p, tr) == pytest.approx(_acc(other, X, V, 0.0, p, tr), abs=1e-9)


def test_eq12_continuous_on_sigma_border_eq13_is_not():
    """On the Sigma_alpha/Sigma_beta border (V = 0 inside the band) eq. 12 is continuous;
    eq. 13 jumps by xi_s Va (eta - h_alpha)/(2 eta), as documented in models.switch."""
    p = ns.preset("table3")
    X = 1 + 0.3 * p.eta
    assert _acc(1, X, 0.0, 0.4, p, 1) == pytest.approx(_acc(2, X, 0.0, 0.4, p, 1), abs=1e-9)
    jump = _acc(1, X, 0.0, 0.4, p, 0) - _acc(2, X, 0.0, 0.4, p, 0)
    assert jump == pytest.approx(p.xi_s * 0.4 * (p.eta - 0.3 * p.eta) / (2 * p.eta), rel=1e-9)


def test_regions_partition_the_plane():
    p = ns.preset("table1")
    r = p.xi_s / p.omega_s**2
    rng = np.random.default_rng(0)
    for X, V in zip(rng.uniform(1 - 3 * p.eta, 1 + 3 * p.eta, 4000), rng.uniform(-0.1, 0.1, 4000)):
        code = sw.region(X, V, p.eta, r)
        margins = [sw.inside_margin(m, X, V, p.eta, r) for m in range(4)]
        assert margins[code] >= 0.0
        ha, hb = X - 1, -(X - 1) - r * V
        inside = [ha <= -p.eta or hb >= p.eta, -p.eta < ha < p.eta and hb <= -ha,
                  ha > -hb and -p.eta < hb < p.eta, ha >= p.eta and hb <= -p.eta]
        # eq. 14: exactly the sets; Sigma sets only outside Gamma-/Gamma+
        assert inside[code]
