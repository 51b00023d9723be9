"""The ``stick_slip`` model (Leine's belt-driven friction oscillator) against independent
oracles: the closed-form Coulomb stick-slip limit cycle, and scipy's DOP853 with event
location in slip."""

import math
import warnings

import numba as nb
import numpy as np
import pytest

warnings.filterwarnings("ignore", category=nb.NumbaExperimentalFeatureWarning)

from nonsmooth import kernels as K  # noqa: E402
from nonsmooth import status as st  # noqa: E402
from nonsmooth.errors import ParameterError  # noqa: E402
from nonsmooth.models.stick_slip import MODEL, SLIP_B, SLIP_F, STICK, TRANS  # noqa: E402

pytestmark = pytest.mark.filterwarnings("ignore::numba.NumbaExperimentalFeatureWarning")


def _run(params, method, x0, v0, per_period, n_periods, **solver):
    sol = K.Solver(model=MODEL, method=method, **solver)
    state = K.new_state(x0, v0)
    n = per_period * n_periods
    X, V, R, M, Xmax, Xmin = K.output_buffers(n)
    code = K.run(sol.code, sol.fns, params.pack(), sol.opts(), state, per_period, 0, n, X, V, R,
                 M, Xmax, Xmin)
    return code, X, V, R, M, Xmax, Xmin


# ---- (a) the Coulomb stick-slip limit cycle in closed form ------------------------------------
class Cycle:
    """xi = 0, F0 = 0, v_s = 0, mu_k < mu_s. Stick (V = v_belt, X'' = 0, f_req = w0^2 X) breaks
    at X_s = mu_s/w0^2 (f_req = +mu_s): the friction saturates, the mass falls behind the belt
    (v_rel < 0, friction +mu_k) and oscillates harmonically about X_c = mu_k/w0^2, starting at
    Y = X - X_c = d = (mu_s - mu_k)/w0^2 with Y' = v_belt: amplitude A = sqrt(d^2 +
    (v_belt/w0)^2), Y = A cos(w0 t - phi), tan(phi) = v_belt/(w0 d). V returns to v_belt at the
    mirror point Y = -d (w0 t = pi + 2 phi), where f_req = 2 mu_k - mu_s lies in [-mu_s, mu_s]:
    stick again, from X_e = X_c - d up to X_s, for 2 d / v_belt."""

    def __init__(self, w0, mus, muk, vb):
        self.w0, self.vb = w0, vb
        self.Xs = mus / w0**2
        self.Xc = muk / w0**2
        self.d = self.Xs - self.Xc
        self.A = math.hypot(self.d, vb / w0)
        self.phi = math.atan2(vb / w0, self.d)
        self.t_slip = (math.pi + 2.0 * self.phi) / w0
        self.t_stick = 2.0 * self.d / vb
        self.period = self.t_slip + self.t_stick
        self.Xe = self.Xc - self.d
        self.amplitude = 2.0 * self.A  # max X - min X, both reached in slip

    def X(self, t):
        """X(t) on the cycle, t = 0 in the middle of a stick phase."""
        t = t % self.period
        h = 0.5 * self.t_stick
        if t <= h:
            return self.Xe + self.vb * (t + h)
        t -= h
        if t <= self.t_slip:
            return self.Xc + self.A * math.cos(self.w0 * t - self.phi)
        return self.Xe + self.vb * (t - self.t_slip)


CYC = dict(omega0=1.3, mu_s=1.0, mu_k=0.4, v_belt=0.3)


def _cycle():
    return Cycle(CYC["omega0"], CYC["mu_s"], CYC["mu_k"], CYC["v_belt"])


def test_cycle_oracle_is_self_consistent():
    """The closed form against scipy's DOP853 (slip arc from X_s to v_rel = 0)."""
    from scipy.integrate import solve_ivp
    c = _cycle()
    w0, muk, vb = CYC["omega0"], CYC["mu_k"], CYC["v_belt"]
    ev = lambda t, u: u[1] - vb  # noqa: E731
    ev.terminal, ev.direction = True, 1
    s = solve_ivp(lambda t, u: [u[1], -w0 * w0 * u[0] + muk], (0.0, 100.0), [c.Xs, vb - 1e-12],
                  method="DOP853", rtol=1e-13, atol=1e-15, events=ev, dense_output=True)
    te = s.t_events[0][0]
    assert abs(te - c.t_slip) < 1e-9
    assert abs(s.y_events[0][0][0] - c.Xe) < 1e-9
    tt = np.linspace(0.0, te, 200001)
    x = s.sol(tt)[0]
    assert abs(x.max() - x.min() - c.amplitude) < 1e-9


@pytest.mark.parametrize("method, eta, tol", [("exact", 1e-4, 1e-8), ("smooth", 1e-6, 1e-3)])
def test_coulomb_stick_slip_cycle(method, eta, tol):
    """Sampling period = cycle period: the section is a fixed point; X(t), the amplitude, the
    stick and slip times match the closed form."""
    c = _cycle()
    p = MODEL.params(**CYC, omega=2.0 * math.pi / c.period, eta=eta)
    N, nper = 400, 6
    # start in the middle of a stick phase (smooth: at the band's lower edge, where the
    # cycle's stick phase lies in the switch model)
    v0 = CYC["v_belt"] - (eta if method == "smooth" else 0.0)
    code, X, V, R, M, Xmax, Xmin = _run(p, method, c.X(0.0), v0, N, nper)
    assert code == st.OK
    tt = c.period * np.arange(1, N * nper + 1) / N
    ref = np.array([c.X(t) for t in tt])
    err_x = np.abs(X - ref).max()
    err_amp = abs((Xmax.max() - Xmin.min()) - c.amplitude)
    err_sec = np.abs(X[N - 1::N] - c.X(0.0)).max()  # stroboscopic: period error * v_belt
    sticking = (R == STICK)
    # stick time from the mode record (resolution: one sample)
    t_stick = sticking[-N:].sum() * c.period / N
    print(f"{method}: max|X - X_ref| = {err_x:.2e}, amplitude error {err_amp:.2e}, "
          f"section drift {err_sec:.2e}, stick time {t_stick:.4f} vs {c.t_stick:.4f}")
    assert err_x < tol
    assert err_amp < tol
    assert err_sec < tol
    assert abs(t_stick - c.t_stick) <= 1.5 * c.period / N
    assert set(np.unique(R)) <= {SLIP_B, STICK}
    assert MODEL.is_contact(p, int(np.bitwise_or.reduce(M)), Xmax.max(), Xmin.min())
    if method == "exact":
        assert np.all(V[sticking] == CYC["v_belt"])
        assert err_x < 1e-11


def test_coulomb_cycle_reached_from_rest():
    """Any orbit that sticks once is on the cycle: from rest (X, V) = (0, 0), after the first
    stick the slip arcs have the closed-form amplitude and the stick phases their duration."""
    c = _cycle()
    N = 2000
    p = MODEL.params(**CYC, omega=2.0 * math.pi / c.period)
    code, X, V, R, M, Xmax, Xmin = _run(p, "exact", 0.0, 0.0, N, 4)
    assert code == st.OK
    last = slice(2 * N, 4 * N)
    assert abs(Xmax[last].max() - Xmin[last].min() - c.amplitude) < 1e-10
    assert abs(Xmax[last].max() - (c.Xc + c.A)) < 1e-10
    t_stick = (R[3 * N:] == STICK).sum() * c.period / N
    assert abs(t_stick - c.t_stick) <= 1.5 * c.period / N
    # the section is a fixed point once on the cycle
    assert abs(X[3 * N - 1] - X[4 * N - 1]) < 1e-10


# ---- (b) exact method against scipy in slip ----------------------------------------------------
def _scipy_slip(pr, X0, V0, t_eval):
    """DOP853 (rtol 1e-13) through slip reversals at v_rel = 0 (asserting |f_req| > mu_s there,
    i.e. no sticking). Returns X, V at t_eval and the number of reversals."""
    from scipy.integrate import solve_ivp
    w0, xi, vb, mus, muk, vs, F0, om = (pr[k] for k in ("omega0", "xi", "v_belt", "mu_s", "mu_k",
                                                         "v_s", "F0", "omega"))

    def fric(sg, vrel):
        if vs > 0:
            return -sg * (muk + (mus - muk) * math.exp(-sg * vrel / vs))
        return -sg * muk

    t_end = t_eval[-1]
    sg = 1.0 if V0 > vb else -1.0
    t, y, nrev = 0.0, [X0, V0], 0
    out = np.full((2, t_eval.size), np.nan)
    while t < t_end:
        assert nrev < 1000, "reference: too many reversals"

        def rhs(t, u, sg=sg):
            return [u[1], -w0 * w0 * u[0] - xi * u[1] + F0 * math.cos(om * t) + fric(sg, u[1] - vb)]

        def ev(t, u):
            return u[1] - vb
        ev.terminal, ev.direction = True, -sg
        s = solve_ivp(rhs, (t, t_end), y, method="DOP853", rtol=1e-13, atol=1e-15, events=ev,
                      dense_output=True)
        t_stop = s.t_events[0][0] if s.t_events[0].size else t_end
        sel = (t_eval > t) & (t_eval <= t_stop)
        if sel.any():
            out[:, sel] = s.sol(t_eval[sel])
        if not s.t_events[0].size:
            break
        t, y = t_stop, s.y_events[0][0].copy()
        y[1] = vb
        fr = w0 * w0 * y[0] + xi * vb - F0 * math.cos(om * t)
        assert abs(fr) > mus, f"the reference case must not stick (t = {t:g}, f_req = {fr:g})"
        sg = -1.0 if fr > mus else 1.0
        nrev += 1
    return out[0], out[1], nrev


SLIP_CASES = {
    # forced, belt faster than the mass ever moves: backward slip throughout
    "coulomb_pure_slip": (dict(omega0=1.0, xi=0.1, v_belt=5.0, mu_s=0.5, mu_k=0.3, v_s=0.0,
                               F0=1.0, omega=0.8), 0, 1e-8),
    # strong forcing: slip reversals at v_rel = 0 with |f_req| > mu_s, never sticking
    "coulomb_reversals": (dict(omega0=1.0, xi=0.1, v_belt=0.1, mu_s=0.3, mu_k=0.2, v_s=0.0,
                               F0=2.0, omega=0.7), 10, 1e-8),
    "stribeck_pure_slip": (dict(omega0=1.0, xi=0.1, v_belt=6.0, mu_s=0.8, mu_k=0.3, v_s=2.0,
                                F0=1.0, omega=0.8), 0, 1e-7),
    "stribeck_reversals": (dict(omega0=1.0, xi=0.1, v_belt=0.1, mu_s=0.3, mu_k=0.2, v_s=0.5,
                                F0=2.0, omega=0.7), 10, 1e-7),
}


@pytest.mark.parametrize("case", list(SLIP_CASES))
def test_exact_against_scipy_in_slip(case):
    pr, min_rev, tol = SLIP_CASES[case]
    p = MODEL.params(**pr)
    N, nper = 50, 10
    T = 2.0 * math.pi / pr["omega"]
    tt = T * np.arange(1, N * nper + 1) / N
    Xr, Vr, nrev = _scipy_slip(pr, 0.0, 0.0, tt)
    assert nrev >= min_rev
    code, X, V, R, M, Xmax, Xmin = _run(p, "exact", 0.0, 0.0, N, nper)
    assert code == st.OK
    assert not np.any(R == STICK)
    err = max(np.abs(X - Xr).max(), np.abs(V - Vr).max())
    print(f"{case}: {nrev} reversals, max error {err:.2e}")
    assert err < tol


@pytest.mark.parametrize("pr", [
    dict(xi=0.05, v_s=0.5, F0=0.3, omega=0.9),  # Stribeck, forced, sticking
    dict(xi=0.1, F0=0.6, omega=0.5),  # Coulomb, forced, sticking
    dict(xi=0.05, v_s=0.1, F0=0.8, omega=0.7, v_belt=0.1),  # both slip directions and stick
])
def test_smooth_converges_to_exact_with_sticking(pr):
    """Leine's switch model with a thin band (eta = 1e-6) follows the event-driven solution
    through forced stick-slip (measured: 1e-5 .. 1e-4 over 10 periods)."""
    out = {}
    for m in ("exact", "smooth"):
        p = MODEL.params(**pr, eta=1e-6)
        out[m] = _run(p, m, 0.3, 0.0, 200, 10, rtol=1e-10, atol=1e-12)
        assert out[m][0] == st.OK
    (_, Xe, _, Re, Me, _, _), (_, Xs, _, Rs, _, _, _) = out["exact"], out["smooth"]
    assert int(np.bitwise_or.reduce(Me)) & (1 << STICK)
    assert np.abs(Xe - Xs).max() < 1e-3
    assert abs((Re == STICK).mean() - (Rs == STICK).mean()) <= 0.01


# ---- robustness: sticking with Stribeck, equal coefficients, v_belt = 0, forcing --------------
@pytest.mark.parametrize("method", ["exact", "smooth"])
@pytest.mark.parametrize("pr", [
    dict(xi=0.05, v_s=0.5, F0=0.3, omega=0.9),  # Stribeck: zero slip acceleration at breakaway
    dict(),  # the defaults (undamped, omega = omega0: no closed form, RK)
    dict(mu_k=1.0),  # mu_k = mu_s
    dict(v_belt=0.0, F0=1.5, omega=0.5),  # belt at rest: stick = rest
    dict(mu_k=0.0, F0=0.2, omega=1.7),
])
def test_sticking_runs_without_zeno(method, pr):
    p = MODEL.params(**pr, eta=1e-5)
    code, X, V, R, M, Xmax, Xmin = _run(p, method, 0.3, 0.0, 100, 20)
    assert code == st.OK, st.message(code)
    assert np.all(np.isfinite(X))
    mask = int(np.bitwise_or.reduce(M))
    assert mask & (1 << STICK)
    if method == "exact":
        assert not mask & (1 << TRANS)
        assert np.all(V[R == STICK] == p.v_belt)


def test_smooth_stick_band_and_transition():
    """In the smooth method's stick mode the velocity is frozen inside the band."""
    p = MODEL.params(xi=0.05, F0=0.3, omega=0.9, eta=1e-3)
    code, X, V, R, M, Xmax, Xmin = _run(p, "smooth", 0.3, 0.0, 100, 10)
    assert code == st.OK
    s = R == STICK
    assert s.any()
    assert np.all(np.abs(V[s] - p.v_belt) <= p.eta * (1 + 1e-9))
    f = R == SLIP_F
    b = R == SLIP_B
    assert np.all(V[f] - p.v_belt >= p.eta * (1 - 1e-9))
    assert np.all(V[b] - p.v_belt <= -p.eta * (1 - 1e-9))


# ---- (c) bad input -------------------------------------------------------------------------------
@pytest.mark.parametrize("bad, field", [
    (dict(mu_k=1.5), "mu_k"),
    (dict(mu_s=0.2), "mu_k"),  # default mu_k = 0.5 > mu_s
    (dict(v_belt=-0.1), "v_belt"),
    (dict(omega0=0.0), "omega0"),
    (dict(eta=0.0), "eta"),
    (dict(v_s=-1.0), "v_s"),
    (dict(omega=-1.0), "omega"),
])
def test_bad_parameters(bad, field):
    with pytest.raises(ParameterError) as e:
        MODEL.params(**bad)
    msg = str(e.value)
    assert msg.startswith(f"{field}:")
    assert "\n" not in msg
    assert "<=" in msg or "<" in msg


def test_model_definition():
    assert MODEL.mode_names == ("slip_forward", "slip_backward", "stick", "transition")
    assert MODEL.param_names == ("omega0", "xi", "v_belt", "mu_s", "mu_k", "v_s", "F0", "omega",
                                 "eta")
    p = MODEL.params()
    assert (p.omega0, p.xi, p.v_belt, p.mu_s, p.mu_k, p.v_s, p.F0, p.omega, p.eta) == (
        1.0, 0.0, 0.2, 1.0, 0.5, 0.0, 0.0, 1.0, 1e-4)
    for m in ("smooth", "exact"):
        assert not MODEL.method(m).flow_is_homeomorphism
        MODEL.fns(m)  # compiles and passes the definition checks
    assert MODEL.contact_modes == 1 << STICK
    assert not MODEL.is_contact(p, 1 << SLIP_B, 1.0, -1.0)
    for name in MODEL.presets:
        MODEL.preset(name)
