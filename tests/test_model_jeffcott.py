"""The built-in Jeffcott rotor with rub on a circular stator (``jeffcott_rotor``, a curved
switching surface X^2 + Y^2 = delta^2), against independent solutions: the closed form of
full annular rub, and scipy ``solve_ivp`` with events on the circle."""

import math
import warnings

import numba as nb
import numpy as np
import pytest

warnings.filterwarnings("ignore", category=nb.NumbaExperimentalFeatureWarning)

import nonsmooth as ns  # noqa: E402
from nonsmooth.errors import ParameterError  # noqa: E402

pytestmark = pytest.mark.filterwarnings("ignore::numba.NumbaExperimentalFeatureWarning")

ROTOR = ns.model("jeffcott_rotor")


def annular_rub(p):
    """Full annular rub X + iY = A e^{i omega t}: |A| = R > delta solves
    R |omega_n^2 - omega^2 + kappa + i (xi omega + kappa mu)| = e omega^2 with
    kappa = k_s (1 - delta / R) (bisection); returns the state (X, V, Y, W) at t = 0."""
    om, wn, xi, e, d, ks, mu = p.omega, p.omega_n, p.xi, p.e, p.delta, p.k_s, p.mu

    def f(R):
        k = ks * (1.0 - d / R)
        return R * abs(complex(wn ** 2 - om ** 2 + k, xi * om + k * mu)) - e * om ** 2

    lo, hi = d * (1 + 1e-14), 100.0 * d
    assert f(lo) < 0 < f(hi)
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if f(mid) < 0 else (lo, mid)
    R = 0.5 * (lo + hi)
    k = ks * (1.0 - d / R)
    A = e * om ** 2 / complex(wn ** 2 - om ** 2 + k, xi * om + k * mu)
    return np.array([A.real, -om * A.imag, A.imag, om * A.real]), R


def test_full_annular_rub_against_its_closed_form():
    """From 1 % off the closed-form whirl, the exact model settles on it (stroboscopic state to
    1e-9), stays in contact, and ``periodic_orbit`` finds it with multipliers inside the unit
    circle; the smooth method (eta = 1e-4, far below R - delta) agrees."""
    p = ROTOR.preset("annular_rub")
    want, R = annular_rub(p)
    assert R > p.delta
    start = dict(zip(ROTOR.state_names, want * np.array([1.01, 1.0, 1.0, 1.0])))
    for method, tol in (("exact", 1e-9), ("smooth", 1e-8)):
        ds = ns.simulate(p, periods=300, samples_per_period=1, method=method, u0=start)
        got = ns.io.components(ds).values[-1]
        assert np.max(np.abs(got - want)) < tol, (method, got, want)
    ds = ns.simulate(p, periods=2, samples_per_period=64, method="exact",
                     u0=dict(zip(ROTOR.state_names, want)))
    r = np.hypot(ds.X.values, ds.Y.values)
    assert np.all(ds.region.values == ROTOR.mode_names.index("rub"))
    assert np.max(np.abs(r - R)) < 1e-9
    orb = ns.periodic_orbit(p, method="exact", u0=dict(zip(ROTOR.state_names, want * 1.001)))
    assert orb.attrs["converged"] == 1 and int(orb.stable) == 1
    got = np.array([float(orb[f"{c}_section"][0]) for c in ROTOR.state_names])
    assert np.max(np.abs(got - want)) < 1e-9
    assert orb.multiplier_abs.values.max() < 1.0


def _scipy_rotor(p, u0, periods):
    """scipy DOP853 (rtol 1e-12) with terminal events on X^2 + Y^2 = delta^2, restarted in
    the other mode at each crossing: the state at every period boundary."""
    from scipy.integrate import solve_ivp

    om, wn, xi, e, d, ks, mu = p.omega, p.omega_n, p.xi, p.e, p.delta, p.k_s, p.mu

    def f(t, y, rub):
        X, V, Y, W = y
        ax = e * om ** 2 * math.cos(om * t) - wn ** 2 * X - xi * V
        ay = e * om ** 2 * math.sin(om * t) - wn ** 2 * Y - xi * W
        if rub:
            k = ks * (1.0 - d / math.hypot(X, Y))
            ax -= k * (X - mu * Y)
            ay -= k * (mu * X + Y)
        return [V, ax, W, ay]

    def circle(t, y, rub):
        return y[0] ** 2 + y[2] ** 2 - d ** 2

    circle.terminal = True
    T = 2 * math.pi / om
    y = np.array(u0, float)
    t = 0.0
    rub = y[0] ** 2 + y[2] ** 2 > d ** 2
    out = []
    for k in range(1, periods + 1):
        while True:
            circle.direction = -1.0 if rub else 1.0
            sol = solve_ivp(f, (t, k * T), y, method="DOP853", rtol=1e-12, atol=1e-14,
                            events=circle, args=(rub,))
            y, t = sol.y[:, -1], sol.t[-1]
            if sol.status == 1:
                rub = not rub
                continue
            break
        out.append(y.copy())
    return np.array(out)


def test_intermittent_rub_against_scipy_with_events():
    """At resonance the whirl crosses the clearance circle twice per turn while it builds up
    (from rest): every state component at each period boundary agrees with scipy."""
    p = ROTOR.preset("intermittent")
    ds = ns.simulate(p, periods=12, samples_per_period=1, method="exact")
    ours = ns.io.components(ds).values[1:]
    ref = _scipy_rotor(p, [0.0, 0.0, 0.0, 0.0], 12)
    assert np.max(np.abs(ours - ref)) < 1e-7
    assert np.any(ds.visited.values & 0b10)  # rubbing happened
    assert not np.all(ds.visited.values == 0b10)  # and free flight


def _disc_field(mode, t, c, s, u, p, mem, du):
    """A forced undamped oscillator (the hand-written models of the refusal tests)."""
    du[0] = u[1]
    du[1] = -u[0] + p[0] * c
    return 0


def _disc_jacobian(mode, t, c, s, u, p, mem, J):
    J[0, 0] = 0.0
    J[0, 1] = 1.0
    J[1, 0] = -1.0
    J[1, 1] = 0.0
    return 0


def test_a_wrong_curved_guard_or_linear_mode_is_one_line():
    from nonsmooth.models import Method, Model, Param
    from nonsmooth.models.oscillator import curved_row

    field, jacobian = _disc_field, _disc_jacobian

    def guards(mode, p, mem, G):
        curved_row(G, 0)
        return 1

    def transition(mode, k, t, c, s, u, p, mem):
        u[1] = -u[1]
        return 0

    def initial(c, s, u, p, mem):
        return 0

    def curved(mode, k, t, c, s, u, p, mem, grad):
        grad[0] = -u[0]  # wrong: d/dX (1 - X^2 - V^2) = -2 X
        grad[1] = -2.0 * u[1]
        grad[2] = 0.0
        return 1.0 - u[0] * u[0] - u[1] * u[1]

    def linear(mode, p, out):  # wrong: declares X'' = -2 X + F0 cos
        for i in range(10):
            out[i] = 0.0
        out[1] = 1.0
        out[2] = -2.0
        out[2 * 2 + 2 + 1] = p[0]
        return 2

    params = (Param("F0", 0.5), Param("omega", 1.0, low=0.0, low_open=True))
    for kw, needle in (
            (dict(curved=curved), "curved: the gradient of surface 0 in mode free disagrees"),
            (dict(), "guards marks surface 0 of mode free curved, but the method has no "
                     "curved function"),
            (dict(linear=linear, closed_form=True),
             "linear: mode free is not the linear mode it declares: dV/dt = ")):
        m = Model("disc", "a disc", params, ("X", "V"), ("free",),
                  {"exact": Method(field, jacobian, guards, transition, initial, **kw)})
        with pytest.raises(ParameterError) as exc:
            m.fns("exact")
        assert needle in str(exc.value) and "\n" not in str(exc.value)


def test_smooth_modes_are_labels_switched_at_step_ends():
    """The smooth method's modes only name the side of the circle (one field, no reset):
    label surfaces, whose crossing the kernel does not locate (``contract``). The trajectory
    is then bit for bit that of the same field written as one mode, and at every output (a
    step's end) the mode is the side of the circle the state is on."""
    from nonsmooth.models import jeffcott_rotor as J
    one = ns.model_from_equations(
        "jeffcott_one_mode", states=("X", "V", "Y", "W"),
        parameters={q.name: q for q in J.PARAMETERS}, forcing_amplitude="e",
        methods={"smooth": dict(modes={"free": [
            "V", f"{J.FREE_X} - {J.SMOOTH_PRESS}*(X - mu*Y)",
            "W", f"{J.FREE_Y} - {J.SMOOTH_PRESS}*(mu*X + Y)"]})})
    p = ROTOR.preset("partial_rub")
    ds = ns.simulate(p, periods=30, samples_per_period=16, method="smooth")
    ref = ns.simulate(one.params(**{q: getattr(p, q) for q in ROTOR.param_names}), periods=30,
                      samples_per_period=16, method="smooth")
    U = ns.io.components(ds).values
    assert np.array_equal(U, ns.io.components(ref).values)
    r = np.hypot(U[:, 0], U[:, 2])
    rub = ds.region.values == ROTOR.mode_names.index("rub")
    assert rub.any() and (~rub).any()
    assert np.array_equal(rub[1:], r[1:] > p.delta)  # (the start: classified by initial)


def test_a_surface_is_no_label_where_the_mode_across_watches_another():
    """Two modes of one field, switched across a curved surface without a reset, but the mode
    across also watches a wall: the surface is located as any curved guard (a label's switch at
    a step's end would leave the wall unwatched over the rest of that step), so the wall stops
    the mass whatever the output sampling."""
    m = ns.model_from_equations(
        "label_and_wall", states=("X", "V"), parameters={"k": 1.0},
        modes={"a": ["exp(V)*k", "0"], "b": ["exp(V)*k", "0"], "c": ["0", "0"]},
        guards={"a": [("-X - X**3", "b")], "b": [("X + X**3", "a"), ("0.5 - X", "c")]},
        initial=[("X < 0", "a")], omega=None)
    for spp in (1, 4):
        ds = ns.simulate(m.params(), periods=2, samples_per_period=spp, x0=-3.0,
                         method="exact")
        assert float(ds.X[-1]) == pytest.approx(0.5, abs=1e-12)
        assert int(ds.region[-1]) == m.mode_names.index("c")


def test_a_label_surface_between_different_fields_is_one_line():
    from nonsmooth.models import Method, Model, Param
    from nonsmooth.models.oscillator import label_row

    def field(mode, t, c, s, u, p, mem, du):
        du[0] = u[1]
        du[1] = -u[0] - mode * u[1] + p[0] * c  # mode 1 is damped: another field
        return 0

    def jacobian(mode, t, c, s, u, p, mem, J):
        J[0, 0] = 0.0
        J[0, 1] = 1.0
        J[1, 0] = -1.0
        J[1, 1] = -1.0 * mode
        return 0

    def guards(mode, p, mem, G):
        label_row(G, 0)
        return 1

    def transition(mode, k, t, c, s, u, p, mem):
        return 1 - mode

    def initial(c, s, u, p, mem):
        return 0

    def curved(mode, k, t, c, s, u, p, mem, grad):
        sg = 1.0 - 2.0 * mode
        grad[0] = -2.0 * sg * u[0]
        grad[1] = -2.0 * sg * u[1]
        grad[2] = 0.0
        return sg * (1.0 - u[0] * u[0] - u[1] * u[1])

    params = (Param("F0", 0.5), Param("omega", 1.0, low=0.0, low_open=True))
    m = Model("disc_label", "a disc", params, ("X", "V"), ("inside", "outside"),
              {"smooth": Method(field, jacobian, guards, transition, initial, curved=curved)})
    with pytest.raises(ParameterError) as exc:
        m.fns("smooth")
    assert "smooth.guards marks surface 0 of mode inside a label, but the mode it enters " \
           "(outside) has another field" in str(exc.value) and "\n" not in str(exc.value)


    def guards_wall(mode, p, mem, G):  # the label, and a wall X <= 2 beside it
        label_row(G, 0)
        for i in range(5):
            G[1, i] = 0.0
        G[1, 0] = -1.0
        G[1, 2] = 2.0
        return 2

    m = Model("disc_label_wall", "a disc", params, ("X", "V"), ("inside", "outside"),
              {"smooth": Method(_disc_field, _disc_jacobian, guards_wall, transition, initial,
                                curved=curved)})
    with pytest.raises(ParameterError) as exc:
        m.fns("smooth")
    assert "a label must be the only surface of both modes it separates" in str(exc.value)
    assert "\n" not in str(exc.value)


def test_impacts_on_a_circle_floquet_multipliers_equal_finite_differences():
    """A mass in a circular clearance (centre (-2, 0), radius 3: the wall it hits is near
    X = 1) with Newton's law on the normal velocity, written as equations (a curved guard and a
    reset). On the X axis its period-1 orbit is the 1-DOF impact oscillator's (the built-in
    ``impact`` model: same section point, same multipliers in (X, V)); the saltation matrix
    at an impact on the circle uses the surface's gradient, whose direction turns with Y, so
    the wall's curvature kicks a transverse perturbation and makes the orbit unstable in Y,
    where the free flow alone would damp it. The monodromy equals central differences of the
    kernel's own period map."""
    impact = "(1 + r)*((X - c0)*V + Y*W)/((X - c0)**2 + Y**2)"
    m = ns.model_from_equations(
        "circle_impact", states=("X", "V", "Y", "W"),
        parameters={"xi": 0.05, "F0": 3.0, "omega": 1.5, "delta": 3.0, "c0": -2.0, "r": 0.8},
        modes={"free": ["V", "-X - xi*V + F0*cos(omega*t)", "W", "-1.2*Y - xi*W"]},
        guards={"free": [ns.Guard("delta**2 - (X - c0)**2 - Y**2", "free",
                                  reset={"V": f"V - {impact}*(X - c0)",
                                         "W": f"W - {impact}*Y"})]},
        admissible="(X - c0)**2 + Y**2 <= delta**2")
    p = m.params()
    po = ns.poincare(p, transient=300, record=8, method="exact", lyapunov=False,
                     u0=[0.0, 0.0, 0.0, 0.0])
    assert int(po.period) == 1
    orb = ns.periodic_orbit(p, u0=ns.io.components(po).values[-1], method="exact")
    assert orb.attrs["status"] == "converged"
    z = ns.io.components(orb, suffix="_section").values[0]
    line = ns.model("impact").params(omega0=1.0, xi=0.05, F0=3.0, omega=1.5, r=0.8)
    ref = ns.periodic_orbit(line, x0=float(z[0]), v0=float(z[1]), method="exact")
    assert abs(float(ref.X_section[0]) - z[0]) < 1e-9 and abs(float(ref.V_section[0]) - z[1]) < 1e-9

    def period_map(u):
        ds = ns.simulate(p, periods=1, samples_per_period=1, method="exact", u0=list(u))
        return ns.io.components(ds).values[-1]

    J = np.empty((4, 4))
    for j in range(4):
        h = 1e-6
        J[:, j] = (period_map(z + h * np.eye(4)[j]) - period_map(z - h * np.eye(4)[j])) / (2 * h)
    M = orb.monodromy.values
    assert np.max(np.abs(M - J)) < 1e-6 * np.abs(J).max()
    mu_x = np.sort(np.abs(np.linalg.eigvals(M[:2, :2])))
    assert np.allclose(mu_x, np.sort(ref.multiplier_abs.values), rtol=0, atol=1e-8)
    # the free flow alone has transverse multipliers of modulus exp(-xi T / 2) < 1
    assert np.abs(np.linalg.eigvals(M[2:, 2:])).max() > 1.5  # the wall's curvature
