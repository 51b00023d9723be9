"""The exact event-driven solver (integrate/exact.py) against independent references.

* scipy DOP853 (rtol = atol = 1e-12) on the same non-smooth system, restarted at every switching
  event found by terminal scipy events (max_step keeps scipy from stepping over a short
  contact, which step-end sign checks would miss);
* closed forms of free flight and of the contact phase (numpy, written independently of the
  kernel's matrix exponential);
* grazing orbits 1e-7 above and below the support;
* the smoothed switch model converging to it as eta -> 0.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from nonsmooth import Solver, preset
from nonsmooth.models.support import MODEL as SUPPORT
from nonsmooth import status as st
from nonsmooth.integrate.contract import ST_MODE
from nonsmooth.models.support.exact_kernel import advance_exact
from nonsmooth.kernels import METHOD_EXACT, advance, new_state, output_buffers

EXACT = Solver(method="exact")


def run(params, n_out, per_period=1, n_skip=0, x0=0.0, v0=0.0, mode=-1, method="exact",
        rtol=1e-8, atol=1e-10):
    solver = Solver(method=method, rtol=rtol, atol=atol)
    state = new_state(x0, v0)
    state[ST_MODE] = mode
    buf = output_buffers(n_out)
    code = advance(solver.code, params.pack(), solver.opts(), state, per_period, n_skip, n_out, *buf)
    X, V, R, M, Xmax, Xmin = buf
    return code, dict(X=X, V=V, R=R, M=M, Xmax=Xmax, Xmin=Xmin, state=state)


def reference(p, x0, v0, t_end, rtol=1e-12, atol=1e-12, max_step=0.01):
    """scipy DOP853 on eqs. 4 / 7-9 with a restart at each switch (same switching rules)."""
    w0, ws, xi, xis, F0, om = p.omega0, p.omega_s, p.xi, p.xi_s, p.F0, p.omega
    r = xis / ws ** 2

    def f_free(t, u):
        return [u[1], -w0 * w0 * u[0] - xi * u[1] + F0 * math.cos(om * t)]

    def f_contact(t, u):
        return [u[1], -w0 * w0 * u[0] - xi * u[1] + F0 * math.cos(om * t)
                - ws * ws * (u[0] - 1.0) - xis * u[1]]

    def event(fun, direction):
        fun.terminal = True
        fun.direction = direction
        return fun

    ha_up = event(lambda t, u: u[0] - 1.0, 1)             # free, X < 1: contact starts
    mhb_up = event(lambda t, u: u[0] - 1.0 + r * u[1], 1)  # free, X > 1: force positive again
    ha_down = event(lambda t, u: u[0] - 1.0, -1)          # free, X > 1: back below the support
    hb_up = event(lambda t, u: -(u[0] - 1.0) - r * u[1], 1)  # contact: force vanishes
    X, V, t = x0, v0, 0.0
    phase = "contact" if (X > 1 and ws * ws * (X - 1) + xis * V > 0) else (
        "above" if X > 1 else "below")
    n_contacts = int(phase == "contact")
    while t < t_end:
        fun, evs = {"below": (f_free, [ha_up]), "above": (f_free, [mhb_up, ha_down]),
                    "contact": (f_contact, [hb_up])}[phase]
        sol = solve_ivp(fun, (t, t_end), [X, V], method="DOP853", rtol=rtol, atol=atol,
                        events=evs, max_step=max_step)
        X, V, t = sol.y[0, -1], sol.y[1, -1], sol.t[-1]
        if sol.status == 1:
            which = [len(e) > 0 for e in sol.t_events].index(True)
            if phase == "below":
                phase = "contact" if V > 0 else "above"
            elif phase == "above":
                phase = "contact" if which == 0 else "below"
            else:
                phase = "above" if X > 1 else "below"
            n_contacts += phase == "contact"
    return X, V, n_contacts


# ---------------------------------------------------------------- scipy cross-validation
@pytest.mark.parametrize("name,changes", [("fig6a", {}), ("table2", {}), ("table3", {}),
                                         ("table4", {})])
def test_matches_scipy_dop853_with_events(name, changes):
    p = preset(name).replace(**changes)
    n = 20
    code, out = run(p, n)
    assert code == st.OK
    Xr, Vr, n_contacts = reference(p, 0.0, 0.0, n * p.period)
    assert n_contacts > 0  # the comparison crosses the switching surfaces
    assert int(np.sum((out["M"] & 8) > 0)) > 0
    scale = max(1.0, abs(Vr))
    assert abs(out["X"][-1] - Xr) <= 1e-9
    assert abs(out["V"][-1] - Vr) <= 1e-9 * scale


# ---------------------------------------------------------------- free flight closed form
def free_flight(p, x0, v0, t):
    """Independent closed form of X'' + xi X' + w0^2 X = F0 cos(om t) (complex exponentials)."""
    w0, xi, F0, om = p.omega0, p.xi, p.F0, p.omega
    H = F0 / complex(w0 * w0 - om * om, xi * om)  # particular: Re(H e^{i om t})
    lam = np.roots([1.0, xi, w0 * w0]).astype(complex)
    xp0, vp0 = H.real, (1j * om * H).real
    # homogeneous c1 e^{l1 t} + c2 e^{l2 t} with the remaining initial values
    M = np.array([[1, 1], [lam[0], lam[1]]])
    c = np.linalg.solve(M, np.array([x0 - xp0, v0 - vp0], dtype=complex))
    t = np.asarray(t)
    X = (H * np.exp(1j * om * t)).real + (c[0] * np.exp(lam[0] * t) + c[1] * np.exp(lam[1] * t)).real
    V = (1j * om * H * np.exp(1j * om * t)).real + (
        c[0] * lam[0] * np.exp(lam[0] * t) + c[1] * lam[1] * np.exp(lam[1] * t)).real
    return X, V


def test_free_flight_closed_form_and_steady_amplitude():
    p = preset("table3").replace(F0=0.05, omega=0.8)  # amplitude ~0.3: never reaches X = 1
    spp, n_per = 16, 40
    code, out = run(p, spp * n_per, per_period=spp, x0=0.2, v0=-0.1)
    assert code == st.OK
    t = np.arange(1, spp * n_per + 1) * p.period / spp
    Xa, Va = free_flight(p, 0.2, -0.1, t)
    assert np.max(np.abs(out["X"] - Xa)) < 1e-12
    assert np.max(np.abs(out["V"] - Va)) < 1e-12
    assert set(np.unique(out["R"])) == {0} and set(np.unique(out["M"])) == {1}
    # steady state: extremes over a period = the analytic amplitude (interior extrema found)
    amp = p.F0 / math.hypot(p.omega0 ** 2 - p.omega ** 2, p.xi * p.omega)
    code, out = run(p, 3, n_skip=400)
    assert code == st.OK
    assert np.allclose(out["Xmax"], amp, rtol=0, atol=1e-12)
    assert np.allclose(out["Xmin"], -amp, rtol=0, atol=1e-12)


def test_no_support_never_contacts():
    p = preset("table3").replace(omega_s=0.0, xi_s=0.0, F0=2.0)
    code, out = run(p, 50)
    assert code == st.OK and out["Xmax"].max() > 3.0
    assert np.all(out["M"] == 1) and np.all(out["R"] == 0)


# ---------------------------------------------------------------- grazing
def steady_start(p):
    """(X, V) at t = 0 on the free-flight steady orbit, and its amplitude."""
    H = p.F0 / complex(p.omega0 ** 2 - p.omega ** 2, p.xi * p.omega)
    return H.real, (1j * p.omega * H).real, abs(H)


@pytest.mark.parametrize("offset,contact", [(1e-7, True), (-1e-7, False)])
def test_grazing_orbit_is_decided_correctly(offset, contact):
    base = preset("table3").replace(omega=0.8)
    amp1 = base.F0 / math.hypot(base.omega0 ** 2 - base.omega ** 2, base.xi * base.omega)
    p = base.replace(F0=base.F0 * (1.0 + offset) / amp1)  # steady max X = 1 + offset
    x0, v0, amp = steady_start(p)
    assert abs(amp - (1.0 + offset)) < 1e-14
    code, out = run(p, 8, per_period=2, x0=x0, v0=v0)
    assert code == st.OK
    touched = bool(np.any(out["M"] & 8))
    assert touched == contact
    if contact:
        # first approach to the support (in the first half period): a contact of about
        # 2 sqrt(2e-7 / |X''|) s, two crossings close together
        assert out["M"][0] & 8 and out["M"][0] & 1
        assert out["Xmax"][0] > 1.0 and out["Xmax"][0] < 1.0 + offset
    else:
        assert np.allclose(out["Xmax"].max(), 1.0 + offset, rtol=0, atol=1e-13)


def test_grazing_touch_with_zero_velocity_is_not_a_contact():
    # start exactly at the support with V = 0 and pulled away (X'' < 0): no contact
    p = preset("table3").replace(F0=0.1)
    code, out = run(p, 4, per_period=4, x0=1.0, v0=0.0)
    assert code == st.OK
    assert out["R"][0] == 0 and not out["M"][0] & 8
    # arriving with V > 0 at X = 1 is contact
    code, out = run(p, 1, per_period=64, x0=1.0, v0=0.3)
    assert code == st.OK and out["M"][0] & 8


# ---------------------------------------------------------------- contact phase closed form
def contact_phase(p, x0, v0, t):
    k = p.omega0 ** 2 + p.omega_s ** 2
    c = p.xi + p.xi_s
    H = p.F0 / complex(k - p.omega ** 2, c * p.omega)
    xs = p.omega_s ** 2 / k
    lam = np.roots([1.0, c, k]).astype(complex)
    M = np.array([[1, 1], [lam[0], lam[1]]])
    cc = np.linalg.solve(M, np.array([x0 - xs - H.real, v0 - (1j * p.omega * H).real]))
    X = xs + (H * np.exp(1j * p.omega * t)).real + (cc[0] * np.exp(lam[0] * t)
                                                    + cc[1] * np.exp(lam[1] * t)).real
    V = (1j * p.omega * H * np.exp(1j * p.omega * t)).real + (
        cc[0] * lam[0] * np.exp(lam[0] * t) + cc[1] * lam[1] * np.exp(lam[1] * t)).real
    return X, V


@pytest.mark.parametrize("name", ["table3", "table1"])
def test_contact_phase_closed_form_and_separation(name):
    p = preset(name)
    x0, v0 = 1.0 + 1e-3, 0.5  # inside Gamma+: X > 1, F_s > 0
    spp = int(p.period / (math.pi / math.hypot(p.omega0, p.omega_s) / 40))  # 40 per half-cycle
    code, out = run(p, 200, per_period=spp, x0=x0, v0=v0)
    assert code == st.OK
    assert out["R"][0] == 3
    t = np.arange(1, 201) * p.period / spp
    Xa, Va = contact_phase(p, x0, v0, t)
    Fs = p.omega_s ** 2 * (Xa - 1.0) + p.xi_s * Va
    in_contact = np.cumprod(Fs > 0).astype(bool)  # until the force first vanishes
    n = int(in_contact.sum())
    assert 3 < n < 200
    assert np.all(out["R"][:n] == 3) and out["R"][n] == 0  # separation where F_s = 0
    assert np.max(np.abs(out["X"][:n] - Xa[:n])) < 1e-12
    assert np.max(np.abs(out["V"][:n] - Va[:n])) < 1e-11 * max(1.0, np.abs(Va).max())
    # max penetration (an interior extremum) from the closed form on a fine grid
    tf = np.linspace(0.0, t[n - 1], 200001)
    assert abs(out["Xmax"][:n].max() - contact_phase(p, x0, v0, tf)[0].max()) < 1e-10


# ---------------------------------------------------------------- kernel contract
def test_split_runs_are_identical_and_contract_fields():
    p = preset("table3").replace(omega=0.92)  # chaotic: any difference would grow
    code, a = run(p, 60, per_period=3)
    assert code == st.OK
    s = new_state(0.0, 0.0)
    bufs = [output_buffers(30), output_buffers(30)]
    for b in bufs:
        assert advance(METHOD_EXACT, p.pack(), EXACT.opts(), s, 3, 0, 30, *b) == st.OK
    for i, key in enumerate(["X", "V", "R", "M", "Xmax", "Xmin"]):
        assert np.array_equal(a[key], np.concatenate([bufs[0][i], bufs[1][i]]))
    assert set(np.unique(a["R"])) <= {0, 3} and set(np.unique(a["M"])) <= {1, 8, 9}
    assert np.all(a["Xmax"] >= a["X"]) and np.all(a["Xmin"] <= a["X"])
    assert np.any(a["M"] == 9)
    # Xmax of an interval with contact exceeds 1, and the mode at its end is consistent
    assert np.all(a["Xmax"][(a["M"] & 8) > 0] > 1.0)
    assert np.all(a["X"][a["R"] == 3] > 1.0)


def test_solver_method_exact_dispatch_and_direct_call_agree():
    p = preset("fig6a")
    code, a = run(p, 5)
    s = new_state(0.0, 0.0)
    b = output_buffers(5)
    assert advance_exact(p.pack(), EXACT.opts(), s, 1, 0, 5, *b) == code == st.OK
    assert np.array_equal(a["X"], b[0])


def test_status_codes_for_bad_input():
    p = preset("table3")
    code, _ = run(p, 2, x0=float("nan"))
    assert code == st.NON_FINITE
    # undamped free flight forced exactly at resonance: no bounded closed form, its own status
    q = SUPPORT.params(omega0=1.0, omega_s=10.0, xi=0.0, xi_s=0.3, F0=0.1, omega=1.0)
    code, _ = run(q, 2)
    assert code == st.RESONANCE


def test_initial_mode_classification():
    p = preset("table3")
    for x0, v0, mode in [(1.01, 0.1, 3), (1.01, -10.0, 0), (0.99, 1.0, 0), (1.0, 0.5, 3),
                         (1.0, -0.5, 0), (1.0, 0.0, 0)]:
        code, out = run(p, 1, per_period=10 ** 6, x0=x0, v0=v0)
        assert code == st.OK
        assert out["M"][0] & (1 << mode), (x0, v0, mode)


# ---------------------------------------------------------------- eta -> 0
def settled_point(p, method):
    code, out = run(p, 2, n_skip=300, method=method, rtol=1e-11, atol=1e-13)
    assert code == st.OK
    return np.array([out["X"][-1], out["V"][-1]]), out


def test_smoothed_model_converges_to_exact_as_eta_shrinks():
    p = preset("fig6a")
    ref, out = settled_point(p, "exact")
    assert np.all(out["M"] == 9)  # periodic orbit with contact
    etas = [1e-1, 1e-2, 1e-3, 1e-4, 1e-5]
    dist = []
    for eta in etas:
        pt, _ = settled_point(p.replace(eta=eta), "smooth")
        dist.append(float(np.hypot(*(pt - ref))))
    orders = np.diff(-np.log10(dist))  # per decade of eta
    print("\neta:", etas, "\ndistance smoothed-exact:", ["%.3e" % d for d in dist],
          "\nobserved order:", np.round(orders, 3))
    assert all(a > b for a, b in zip(dist, dist[1:]))  # monotone
    assert dist[-1] < 1e-8
    assert np.all(orders[1:] > 1.8)  # second order in eta for the eq. 13 transition


@pytest.mark.parametrize("xi,xi_s", [(2.0, 6.0),                        # critical free, over contact
                                     (2.0, 2.0 * math.sqrt(10.0) - 2.0),  # critical contact
                                     (3.0, 0.5)])                        # overdamped free flight
def test_critically_and_overdamped_modes_match_scipy(xi, xi_s):
    p = SUPPORT.params(omega0=1.0, omega_s=3.0, xi=xi, xi_s=xi_s, F0=5.0, omega=1.0)
    code, out = run(p, 10)
    assert code == st.OK
    Xr, Vr, n_contacts = reference(p, 0.0, 0.0, 10 * p.period)
    assert n_contacts >= 5 and np.all(out["M"][1:] & 8)
    assert abs(out["X"][-1] - Xr) <= 1e-9 and abs(out["V"][-1] - Vr) <= 1e-9


@pytest.mark.parametrize("F0", [1.0, 1.0 + 1e-12, 1.0 - 1e-12])
@pytest.mark.parametrize("xi_s", [0.6, 0.0])
def test_degenerate_corner_starts_end_with_a_status(F0, xi_s):
    # X = 1, V = 0 with X'' = 0 (or 1e-12) at t = 0: both switching surfaces and the field's
    # first derivatives vanish together. Must end quickly with a status, never hang.
    import time
    p = SUPPORT.params(omega0=1.0, omega_s=17.32, xi=0.0, xi_s=xi_s, F0=F0, omega=0.92)
    t0 = time.perf_counter()
    code, out = run(p, 4, per_period=4, x0=1.0, v0=0.0)
    assert time.perf_counter() - t0 < 5.0
    assert code in (st.OK, st.ZENO, st.MAX_STEPS)
    if code == st.OK:
        assert np.all(np.isfinite(out["X"]))
