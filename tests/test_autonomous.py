"""Self-excited systems (issue 23, item 3) on Leine's belt-driven friction oscillator
(``stick_slip`` with F0 = 0) against closed forms: the Coulomb stick-slip limit cycle (its
period, amplitude and multiplier 0: sticking merges neighbouring trajectories), steady sliding
and its eigenvalues, the Hopf point of steady sliding under Stribeck friction; sections on a
surface; one-line errors for what cannot be done."""

import math

import numpy as np
import pytest

import nonsmooth as ns
from nonsmooth.errors import IntegrationError, ParameterError

pytestmark = pytest.mark.filterwarnings("ignore::numba.NumbaExperimentalFeatureWarning")

M = ns.model("stick_slip")


def coulomb_cycle(p):
    """Period and largest X of the undamped Coulomb stick-slip cycle: stick from
    X = (2 mu_k - mu_s)/omega0^2 to mu_s/omega0^2 at the belt's speed, then a harmonic arc
    about mu_k/omega0^2 of amplitude A back to the belt's speed."""
    d = (p.mu_s - p.mu_k) / p.omega0**2
    alpha = math.atan2(p.v_belt / p.omega0, d)
    period = 2 * d / p.v_belt + (math.pi + 2 * alpha) / p.omega0
    return period, p.mu_k / p.omega0**2 + math.hypot(d, p.v_belt / p.omega0)


@pytest.mark.parametrize("values", [{}, dict(omega0=1.3, v_belt=0.35, mu_s=0.8, mu_k=0.3)])
def test_coulomb_stick_slip_cycle_against_its_closed_form(values):
    p = M.params(**values)
    period, max_x = coulomb_cycle(p)
    # from X = 0, V = 1 the slip arc reaches the belt's speed (from rest it may not: without
    # damping the slip orbits inside the cycle are a centre's closed orbits)
    lc = ns.limit_cycle(p, "V", v0=1.0)  # V = 0, decreasing: once a cycle, at the largest X
    assert lc.attrs["status"] == "converged"
    assert float(lc.period) == pytest.approx(period, abs=1e-9)
    assert float(lc.X_section) == pytest.approx(max_x, abs=1e-9)
    assert float(lc.max_X) == pytest.approx(max_x, abs=1e-6)  # from the samples
    # one nontrivial multiplier (n = 2), and it is 0: the stick phase merges trajectories
    assert lc.sizes["multiplier"] == 1 and float(lc.multiplier_abs[0]) < 1e-9
    assert int(lc.stable) == 1
    assert (lc.mode.values == M.mode_names.index("stick")).any()
    sec = ns.surface_section(p, "V", crossings=6, transient=3, v0=1.0)
    assert int(sec.cycle_crossings) == 1
    assert float(sec.cycle_period) == pytest.approx(period, abs=1e-9)
    assert np.allclose(sec.return_time.values, period, atol=1e-9)
    # the other direction of the same surface: V = 0 increasing, at the smallest X of the arc
    up = ns.surface_section(p, ("V", "increasing"), crossings=3, transient=2, v0=1.0)
    assert np.allclose(up.X.values, 2 * p.mu_k / p.omega0**2 - max_x, atol=1e-9)


def test_smoothed_switch_model_cycle_approaches_the_exact_one():
    p = M.params()
    period, _ = coulomb_cycle(p)
    lc = ns.limit_cycle(p, "V", method="smooth", rtol=1e-10, atol=1e-12, v0=1.0)
    assert lc.attrs["status"] == "converged"
    assert abs(float(lc.period) - period) < 5e-3


def stribeck_slope(p):
    """d f / d V of the friction on the mass in steady sliding (V = 0, v_rel = -v_belt)."""
    return (p.mu_s - p.mu_k) / p.v_s * math.exp(-p.v_belt / p.v_s)


@pytest.mark.parametrize("xi", [0.1, 1.2])
def test_steady_sliding_and_its_eigenvalues(xi):
    p = M.params(v_s=0.5, xi=xi)
    eq = ns.equilibria(p)
    assert eq.sizes["equilibrium"] == 1
    assert M.mode_names[int(eq.mode[0])] == "slip_backward"
    mu = p.mu_k + (p.mu_s - p.mu_k) * math.exp(-p.v_belt / p.v_s)
    assert np.allclose(ns.io.components(eq).values[0], [mu / p.omega0**2, 0.0], atol=1e-12)
    c = xi - stribeck_slope(p)  # effective damping
    ref = np.roots([1.0, c, p.omega0**2])
    ev = eq.eigenvalue_real.values[0] + 1j * eq.eigenvalue_imag.values[0]
    assert np.allclose(np.sort_complex(ev), np.sort_complex(ref), atol=1e-10)
    assert int(eq.stable[0]) == (c > 0)


def test_hopf_point_of_steady_sliding():
    p = M.params(v_s=0.5)
    br = ns.equilibrium_branch(p, "xi", np.linspace(0.0, 1.0, 11))
    assert br.sizes["hopf"] == 1
    assert float(br.hopf_xi[0]) == pytest.approx(stribeck_slope(p), abs=1e-9)
    assert float(br.hopf_frequency[0]) == pytest.approx(p.omega0, abs=1e-9)
    below = br.xi.values < stribeck_slope(p)
    assert np.all(br.stable.values[below] == 0) and np.all(br.stable.values[~below] == 1)
    assert np.all(br.holds.values == 1)


def test_slip_orbits_inside_the_cycle_are_a_centre_without_damping():
    """From rest (default parameters but a lower mu_k) the undamped Coulomb slip never reaches
    the belt's speed: a closed orbit of period 2 pi / omega0 about steady sliding, its
    nontrivial multiplier 1 (neutral)."""
    p = M.params(omega0=1.3, v_belt=0.35, mu_s=0.8, mu_k=0.3)
    lc = ns.limit_cycle(p, "V")
    assert float(lc.period) == pytest.approx(2 * math.pi / 1.3, abs=1e-9)
    assert float(lc.max_X) == pytest.approx(2 * 0.3 / 1.3**2, abs=1e-6)
    assert float(lc.multiplier_abs[0]) == pytest.approx(1.0, abs=1e-8) and int(lc.stable) == 0


def test_errors_are_one_line():
    p = M.params()
    with pytest.raises(ParameterError, match=r"limit_cycle: the system is forced \(F0 = 0.3\)"):
        ns.limit_cycle(p.replace(F0=0.3), "V")
    with pytest.raises(ParameterError, match="section: cannot read"):
        ns.limit_cycle(p, "X*(V")
    with pytest.raises(ParameterError, match="section: unknown name"):
        ns.surface_section(p, "Q - 1")
    with pytest.raises(ParameterError, match="section: direction must be one of"):
        ns.surface_section(p, ("V", "down"))
    with pytest.raises(ParameterError, match="does not depend on the state"):
        ns.surface_section(p, "v_belt")
    # a surface the orbit never reaches: a clear error after max_time, not a hang
    with pytest.raises(IntegrationError, match="no crossing: 0 of 3 crossings"):
        ns.surface_section(p, "X - 5", crossings=3, transient=0, max_time=100.0)
    lc = ns.limit_cycle(p, "X - 5", max_time=100.0)
    assert lc.attrs["status"].startswith("no crossing") and np.isnan(float(lc.period))


def test_cli_limit_cycle_and_equilibria(tmp_path, capsys):
    import xarray as xr

    from cli_helpers import one_line, run_cli
    code, out, _ = run_cli(["limit-cycle", "--v0", "1", "-o", str(tmp_path / "lc.nc")], capsys)
    period, _ = coulomb_cycle(M.params())
    assert code == 0 and f"period {period:.10g}" in out and "verdict: stable" in out
    with xr.open_dataset(tmp_path / "lc.nc") as ds:
        assert float(ds.period) == pytest.approx(period, abs=1e-9)
    code, out, _ = run_cli(["equilibria", "--set", "v_s=0.5", "--param", "xi", "--from", "0",
                            "--to", "1", "--steps", "11"], capsys)
    assert code == 0 and f"Hopf at xi = {stribeck_slope(M.params(v_s=0.5)):.10g}" in out
    code, _, err = run_cli(["limit-cycle", "--set", "F0=0.3"], capsys)
    assert code == 2
    one_line(err, "the system is forced (F0 = 0.3)")
    code, _, err = run_cli(["limit-cycle", "--section", "X - 5", "--max-time", "100"], capsys)
    assert code == 1
    one_line(err, "no crossing: 0 of 20 crossings")


def test_limit_cycle_branch_follows_the_stick_slip_cycle_along_the_belt_speed():
    p = M.params()
    vb = np.linspace(0.1, 0.4, 7)
    br = ns.limit_cycle_branch(p, "v_belt", vb, v0=1.0)
    assert br.attrs["status"] == "completed" and np.all(br.converged.values == 1)
    ref = np.array([coulomb_cycle(p.replace(v_belt=v)) for v in vb])
    assert np.allclose(br.period.values, ref[:, 0], atol=1e-9)
    assert np.allclose(br.X_section.values, ref[:, 1], atol=1e-9)
    assert np.all(br.multiplier_abs.values < 1e-9) and np.all(br.stable.values == 1)


def test_stribeck_stick_slip_cycle_coexists_with_stable_steady_sliding():
    """Just above the Hopf point (subcritical) steady sliding is stable and the stick-slip cycle
    persists: a start near steady sliding spirals in (the section's crossings converge onto
    the equilibrium, no cycle), a start far from it ends on the stick-slip cycle, which
    visits the stick mode and reaches the belt's speed."""
    p = M.params(v_s=0.5, xi=0.68)
    assert 0.68 > stribeck_slope(p)
    eq = ns.equilibria(p)
    x_eq = float(eq.X[0])
    assert int(eq.stable[0]) == 1
    near = ns.surface_section(p, "V", crossings=10, transient=400, x0=x_eq + 0.001)
    assert int(near.at_equilibrium) == 1 and int(near.cycle_crossings) == 0
    far = ns.surface_section(p, "V", crossings=10, transient=50, x0=x_eq, v0=1.0)
    assert int(far.at_equilibrium) == 0 and int(far.cycle_crossings) == 1
    lc = ns.limit_cycle(p, "V", x0=x_eq, v0=1.0)  # Stribeck slip: RKF45, not closed form
    assert lc.attrs["status"] == "converged" and int(lc.stable) == 1
    assert float(lc.period) == pytest.approx(float(far.cycle_period), abs=1e-8)
    # a stop on a crossing starts the next call on the surface: never a crossing of its own
    assert np.all(far.return_time.values > 5.0) and float(lc.period) > 5.0
    assert (lc.mode.values == M.mode_names.index("stick")).any()


@pytest.mark.parametrize("dx", [0.05, 0.2, 0.5])
def test_limit_cycle_does_not_report_a_stable_focus_on_the_section_as_a_cycle(dx):
    """Steady sliding stable (Stribeck, above the Hopf point) and on the section V = 0: from
    starts that spiral onto it, the shooting converges onto the equilibrium, whose crossings
    return to it too, with a return time and a multiplier that depend on where Newton stopped
    (6.097 against 6.287, 0.779 against 0.794, found by an independent check). That is no
    cycle: the status says so, nothing is reported converged."""
    p = M.params(v_s=0.5, xi=0.68, v_belt=0.25)
    eq = ns.equilibria(p)
    assert int(eq.stable[0]) == 1
    lc = ns.limit_cycle(p, "V", x0=float(eq.X[0]) + dx, v0=0.0)
    assert lc.attrs["status"].startswith("equilibrium: ")
    assert lc.attrs["converged"] == 0 and lc.attrs["verdict"] == "not found"
    assert math.isnan(float(lc.period)) and int(lc.stable) == 0

def scipy_stick_slip(p, x0, v0, t_end=1000.0, window=200.0):
    """An independent event-driven solution of the unforced belt oscillator (Stribeck slip by
    scipy DOP853, each slip direction's field continued through v_rel = 0, which is located as
    an event; stick in closed form, X = X0 + v_belt t,
    until the friction needed, omega0^2 X + xi v_belt, reaches mu_s). Returns whether the mass
    stuck to the belt during the last ``window`` time units (the stick-slip cycle) and the
    final state."""
    from scipy.integrate import solve_ivp
    vb = p.v_belt

    def mu(v):
        return p.mu_k + (p.mu_s - p.mu_k) * math.exp(-v / p.v_s)

    def field(sigma):  # slip in the direction sigma = sign(v_rel), continued through 0
        def rhs(t, u):
            f = -sigma * mu(sigma * (u[1] - vb))
            return [u[1], -p.omega0**2 * u[0] - p.xi * u[1] + f]
        return rhs

    t, u, last_stick = 0.0, np.array([x0, v0], float), -math.inf
    while t < t_end:
        if abs(u[1] - vb) < 1e-12:  # at the belt's speed: stick or slip?
            f_req = p.omega0**2 * u[0] + p.xi * vb
            if abs(f_req) <= p.mu_s:
                x_end = (p.mu_s - p.xi * vb) / p.omega0**2
                dt = (x_end - u[0]) / vb
                t, u = t + dt, np.array([x_end, vb - 1e-9])  # stick, then slip backward
                last_stick = t
                continue
            u[1] = vb - 1e-9 if f_req > p.mu_s else vb + 1e-9

        def hit(t, u):
            return u[1] - vb
        # leaving backward slip (v_rel < 0) means v_rel rising through 0, and vice versa
        sigma = -1.0 if u[1] < vb else 1.0
        hit.terminal, hit.direction = True, -sigma
        sol = solve_ivp(field(sigma), (t, t_end), u, method="DOP853", rtol=1e-10, atol=1e-12,
                        events=hit)
        t, u = sol.t[-1], sol.y[:, -1].copy()
        if sol.status == 1:
            u[1] = vb
    return last_stick > t_end - window, u


def test_a_curved_section_gives_the_closed_form_cycle_and_the_same_period_and_multiplier():
    """A curved section (issue 23, item 3): the parabola X - mu_k/omega0^2 + V^2/2 = 0
    through the slip arc's centre, crossed once per turn. The Coulomb stick-slip cycle found on
    it has the closed form's period and multiplier 0 (a property of the cycle, not of the
    section), and its section point lies on the closed form's slip arc and on the surface."""
    p = M.params()
    period, max_x = coulomb_cycle(p)
    xc = p.mu_k / p.omega0**2
    amp = max_x - xc
    lc = ns.limit_cycle(p, f"X - {xc!r} + V**2/2", v0=1.0)
    assert lc.attrs["status"] == "converged" and lc.attrs["section"].endswith("decreasing")
    assert float(lc.period) == pytest.approx(period, abs=1e-9)
    assert lc.sizes["multiplier"] == 1 and float(lc.multiplier_abs[0]) < 1e-9
    X, V = float(lc.X_section), float(lc.V_section)
    assert abs(X - xc + V**2 / 2) < 1e-12
    assert math.hypot(X - xc, V / p.omega0) == pytest.approx(amp, abs=1e-9)
    assert V < 0.0  # the arc's lower half: there h decreases along the flow


def test_a_projection_onto_a_curved_section_lands_on_it_or_says_it_missed():
    """``Surface.project`` (the Newton steps of limit cycles and of continuation on a curved
    section): along X onto the circle X^2 + V^2 = 4 from (3, 0.1), the circle's point; along V
    from there, a line that misses the circle: NaN, never a point off the surface."""
    from nonsmooth.analysis.autonomous import parse_section
    p = M.params()
    circle = parse_section(p, "X**2 + V**2 - 4")
    on = circle.project(np.array([3.0, 0.1]), np.array([1.0, 0.0]), p.pack())
    assert on == pytest.approx([math.sqrt(4 - 0.01), 0.1], abs=1e-14)
    assert np.all(np.isnan(circle.project(np.array([3.0, 0.1]), np.array([0.0, 1.0]),
                                          p.pack())))


VDP = """import nonsmooth as ns
MODEL = ns.model_from_equations(
    "van_der_pol", states=("X", "V"), parameters={"mu": 1.0},
    modes={"flow": ["V", "mu*(1 - X**2)*V - X"]}, omega=None)
"""


def test_crossings_of_a_curved_section_against_scipy_events():
    """The van der Pol oscillator's crossings of the circle X^2 + V^2 = 4 outwards: states
    and return times against scipy's DOP853 with the same surface as a located event."""
    from scipy.integrate import solve_ivp
    g = {}
    exec(VDP, g)
    p = g["MODEL"].params()
    sec = ns.surface_section(p, ("X**2 + V**2 - 4", "increasing"), x0=0.5, crossings=6,
                             transient=2)
    ev = lambda t, u: u[0]**2 + u[1]**2 - 4  # noqa: E731
    ev.direction = 1.0
    sol = solve_ivp(lambda t, u: [u[1], (1 - u[0]**2) * u[1] - u[0]], (0, 60), [0.5, 0.0],
                    method="DOP853", rtol=1e-12, atol=1e-12, events=ev)
    ref, tref = sol.y_events[0][2:8], sol.t_events[0][1:8]
    assert np.allclose(sec.X.values, ref[:, 0], atol=1e-9, rtol=0)
    assert np.allclose(sec.V.values, ref[:, 1], atol=1e-9, rtol=0)
    assert np.allclose(sec.return_time.values, np.diff(tref), atol=1e-9, rtol=0)
    # the cycle crosses the circle outwards twice per turn: a fixed point of the second return,
    # the same cycle as on V = 0 (period and multiplier belong to the cycle)
    circle = ns.limit_cycle(p, ("X**2 + V**2 - 4", "increasing"), x0=0.5, crossings=2)
    line = ns.limit_cycle(p, "V", x0=0.5)
    assert circle.attrs["status"] == line.attrs["status"] == "converged"
    assert float(circle.period) == pytest.approx(float(line.period), abs=1e-9)
    assert float(circle.multiplier_real[0]) == pytest.approx(float(line.multiplier_real[0]),
                                                              rel=1e-6)
    assert int(ns.surface_section(p, ("X**2 + V**2 - 4", "increasing"), x0=0.5, crossings=6,
                                  transient=20).cycle_crossings) == 2


def test_surface_basins_share_of_the_stick_slip_cycle_against_scipy():
    """Above the subcritical Hopf point the stable steady sliding (inside an unstable cycle)
    and the stick-slip cycle share the plane: every initial condition of a grid gets the
    attractor that an independent scipy event-driven solution reaches."""
    p = M.params(v_s=0.5, xi=0.68)
    bas = ns.surface_basins(p, "V", x=(0.6, 1.1), v=(-0.3, 0.3), grid=4, transient=500)
    assert float(bas.undecided_fraction) == 0.0 and bas.sizes["attractor"] == 2
    kinds = bas.kind.values
    cycle = int(np.flatnonzero(kinds == 1)[0])
    assert int(bas.crossings[cycle]) == 1
    agree = 0
    for j, v0 in enumerate(bas.v0.values):
        for i, x0 in enumerate(bas.x0.values):
            stuck, _ = scipy_stick_slip(p, x0, v0)
            agree += (int(bas.label[j, i]) == cycle) == stuck
    assert agree == 16
    assert 0.0 < float(bas.fraction[cycle]) < 1.0  # both attractors have a share


def test_a_reset_that_jumps_across_the_section_is_no_crossing():
    """The unforced impact oscillator from a large amplitude: while it hits the stop (X = 1,
    V -> -r V) the decreasing crossings of V = 0 are the impacts' jumps, which are not
    crossings of the flow; once the amplitude has decayed below the stop, V = 0 is crossed
    smoothly at the top of each swing, below X = 1."""
    p = ns.model("impact").params(F0=0.0, xi=0.1)
    sec = ns.surface_section(p, "V", crossings=20, transient=0, x0=-3.0)
    assert np.all(sec.X.values < 1.0 - 1e-6)
    assert np.all(np.abs(sec.V.values) < 1e-9)
    assert np.all(np.diff(sec.X.values) < 0)  # decaying swings


def _wall_cycle(zeta, r):
    """The self-excited impact oscillator X'' - 2 zeta X' + X = 0 (negative damping) with a
    wall at X = 1 (V -> -r V): its limit cycle leaves the wall with V = -r v and returns to it
    with V = v after the time tau, X(t) = e^{zeta t} (cos nu t + B sin nu t). Solved from the
    closed form (bisection on v, the first return found on a fine grid and refined): (tau, the
    smallest X of the cycle, where V = 0)."""
    nu = math.sqrt(1.0 - zeta * zeta)

    def X(t, v):
        B = (-r * v - zeta) / nu
        return math.exp(zeta * t) * (math.cos(nu * t) + B * math.sin(nu * t))

    def Xd(t, v):
        B = (-r * v - zeta) / nu
        e = math.exp(zeta * t)
        return e * ((zeta + nu * B) * math.cos(nu * t) + (zeta * B - nu) * math.sin(nu * t))

    def ret(v):
        ts = np.linspace(1e-6, 4 * math.pi / nu, 40001)
        g = np.array([X(t, v) - 1.0 for t in ts])
        i = int(np.flatnonzero((g[:-1] < 0) & (g[1:] >= 0))[0])
        a, b = ts[i], ts[i + 1]
        for _ in range(200):
            m = 0.5 * (a + b)
            a, b = (m, b) if X(m, v) < 1.0 else (a, m)
        return 0.5 * (a + b)

    lo, hi = 0.05, 20.0
    f = lambda v: Xd(ret(v), v) - v  # noqa: E731
    assert f(lo) > 0 > f(hi)
    for _ in range(100):
        m = 0.5 * (lo + hi)
        lo, hi = (m, hi) if f(m) > 0 else (lo, m)
    v = 0.5 * (lo + hi)
    tau = ret(v)
    a, b = 1e-9, tau  # X' goes from -r v < 0 to v > 0: its zero is the cycle's smallest X
    for _ in range(200):
        m = 0.5 * (a + b)
        a, b = (m, b) if Xd(m, v) < 0.0 else (a, m)
    return tau, X(0.5 * (a + b), v)


def test_a_model_without_forcing_its_limit_cycle_against_the_closed_form_and_refusals(
        tmp_path, capsys):
    """A model that declares no forcing (omega=None), written as equations: a self-excited
    impact oscillator (negative damping, a wall with restitution r). Its limit cycle's period
    and its section point (V = 0, the smallest X) equal the closed form; the stroboscopic analyses refuse it in one
    line (exit 2 on the CLI)."""
    zeta, r = 0.05, 0.8
    m = ns.model_from_equations(
        "self_excited_wall", states=("X", "V"), parameters={"zeta": zeta, "r": r},
        modes={"free": ["V", "2*zeta*V - X"]},
        guards={"free": [ns.Guard("1 - X", "free", reset={"V": "-r*V"})]}, omega=None)
    assert m.autonomous and m.params().period == pytest.approx(2 * math.pi)
    tau, x_min = _wall_cycle(zeta, r)
    lc = ns.limit_cycle(m.params(), ("V", "increasing"), x0=0.5, transient=30)
    assert lc.attrs["status"] == "converged"
    assert float(lc.period) == pytest.approx(tau, abs=1e-9)
    assert float(lc.max_X) == pytest.approx(1.0, abs=1e-9)
    assert float(lc.X_section) == pytest.approx(x_min, abs=1e-9)  # on V = 0, increasing
    assert float(lc.multiplier_abs[0]) < 1.0  # a stable cycle
    for call, who in ((lambda p: ns.poincare(p, transient=10), "poincare"),
                      (lambda p: ns.periodic_orbit(p), "periodic_orbit"),
                      (lambda p: ns.bifurcation_diagram(p, "zeta", [0.05, 0.06]),
                       "bifurcation_diagram"),
                      (lambda p: ns.basins(p, grid=4), "basins")):
        with pytest.raises(ParameterError, match=f"^{who}: model self_excited_wall declares "
                                                 f"no forcing"):
            call(m.params())
    with pytest.raises(ParameterError, match="cannot use the time t"):
        ns.model_from_equations("bad", states=("X", "V"), parameters={"a": 1.0},
                                modes={"free": ["V", "-X + cos(t)"]}, omega=None)
    from cli_helpers import one_line, run_cli
    f = tmp_path / "wall.py"
    f.write_text("import nonsmooth as ns\n"
                 "MODEL = ns.model_from_equations('self_excited_wall', states=('X', 'V'),\n"
                 "    parameters={'zeta': 0.05, 'r': 0.8}, modes={'free': ['V', '2*zeta*V - X']},\n"
                 "    guards={'free': [ns.Guard('1 - X', 'free', reset={'V': '-r*V'})]},\n"
                 "    omega=None)\n")
    for cmd in ("poincare", "bifurcation", "orbit", "basins"):
        code, _, err = run_cli([cmd, "--model", f"{f}:MODEL", "--plot",
                                str(tmp_path / "x.png")], capsys)
        assert code == 2
        one_line(err, "declares no forcing (omega=None)")
    code, out, _ = run_cli(["limit-cycle", "--model", f"{f}:MODEL", "--section", "V",
                            "--direction", "increasing", "--x0", "0.5", "-o",
                            str(tmp_path / "lc.nc")], capsys)
    assert code == 0 and "period" in out


def test_surface_bifurcation_diagram_follows_the_stick_slip_cycle(tmp_path, capsys):
    """Along the belt speed, the crossings of V = 0 (decreasing) after a transient are those of
    the Coulomb stick-slip cycle (its closed form, as ``limit_cycle_branch``): one crossing per
    turn at the cycle's section point, the cycle's period; the CLI writes the diagram."""
    p = M.params()
    vb = np.linspace(0.1, 0.4, 4)
    ds = ns.surface_bifurcation_diagram(p, "v_belt", vb, crossings=6, transient=20, v0=1.0)
    ref = np.array([coulomb_cycle(p.replace(v_belt=v)) for v in vb])
    assert np.all(ds.status.values == 0) and np.all(ds.cycle_crossings.values == 1)
    assert np.max(np.abs(ds.X.values - ref[:, 1:2])) < 1e-9
    assert np.allclose(ds.cycle_period.values, ref[:, 0], atol=1e-9)
    from cli_helpers import run_cli
    fig = tmp_path / "sb.png"
    code, out, _ = run_cli(["surface-bifurcation", "--param", "v_belt", "--from", "0.1",
                            "--to", "0.4", "--steps", "4", "--v0", "1", "--crossings", "6",
                            "--transient", "20", "--plot", str(fig)], capsys)
    assert code == 0 and "4 cycles (1 crossing(s) per turn: 4)" in out
    assert fig.stat().st_size > 0


FOLD_MODEL = """import nonsmooth as ns
MODEL = ns.model_from_equations(
    "fold_of_cycles", states=("X", "Y"), parameters={"mu": -0.5},
    modes={"flow": ["X*(mu + 2*(X**2 + Y**2) - (X**2 + Y**2)**2) - Y",
                    "Y*(mu + 2*(X**2 + Y**2) - (X**2 + Y**2)**2) + X"]}, omega=None)
"""


def test_limit_cycles_continued_through_their_fold_against_the_closed_form(tmp_path, capsys):
    """r' = r (mu + 2 r^2 - r^4), theta' = 1: cycles where mu = s^2 - 2 s (s = r^2), the outer
    one stable, the inner one unstable, meeting in a fold at mu = -1, r = 1; every period 2 pi,
    the multiplier exp(2 pi 4 s (1 - s)). Pseudo-arclength continuation of the cycles on
    Y = 0 (increasing) goes round the fold from the stable onto the unstable branch and
    locates it; a cycle started on the section is no immediate crossing of it."""
    f = tmp_path / "fold.py"
    f.write_text(FOLD_MODEL)
    ns_ = {}
    exec(FOLD_MODEL, ns_)
    p = ns_["MODEL"].params()
    lc = ns.limit_cycle(p, ("Y", "increasing"), x0=1.5)
    assert lc.attrs["status"] == "converged"
    assert float(lc.period) == pytest.approx(2 * math.pi, abs=1e-9)  # (was 2e-19: the start)
    s0 = 1 + math.sqrt(0.5)
    assert float(lc.X_section) == pytest.approx(math.sqrt(s0), abs=1e-9)
    br = ns.continuation(p, "mu", section=("Y", "increasing"), x0=1.5, direction="down",
                         step=0.05, bounds=(-1.5, -0.05))
    assert br.attrs["status"] == "left the bounds" and br.attrs["section"] == "Y = 0, increasing"
    mu, X = br.mu.values, br.X_section.values[:, 0]
    s = X**2
    assert np.allclose(mu, s**2 - 2 * s, atol=1e-9, rtol=0)
    assert np.allclose(br.period.values, 2 * math.pi, atol=1e-9, rtol=0)
    mult = br.multiplier_real.values[:, 0]
    assert np.allclose(mult, np.exp(8 * math.pi * s * (1 - s)), rtol=1e-6, atol=1e-12)
    assert np.array_equal(br.stable.values == 1, X > 1)
    assert (X > 1.2).any() and (X < 0.5).any()  # both sides of the fold
    assert list(br.special_type.values) == [1]  # one fold
    assert float(br.special_mu[0]) == pytest.approx(-1.0, abs=1e-8)
    assert float(br.special_X_section[0]) == pytest.approx(1.0, abs=1e-4)
    assert float(br.special_multiplier_real[0]) == pytest.approx(1.0, abs=1e-4)
    # the same cycles on Y = 0 counted both ways: two crossings per turn (k = 2)
    both = ns.continuation(p, "mu", section=("Y", "both"), k=2, x0=1.5, direction="down",
                           step=0.05, bounds=(-1.5, -0.5))
    assert np.allclose(both.period.values, 2 * math.pi, atol=1e-9, rtol=0)
    assert list(both.special_type.values) == [1]
    assert float(both.special_mu[0]) == pytest.approx(-1.0, abs=1e-8)
    from cli_helpers import one_line, run_cli
    code, out, _ = run_cli(["continue", "--model", f"{f}:MODEL", "--param", "mu", "--section",
                            "Y", "--crossing", "increasing", "--x0", "1.5", "--direction",
                            "down", "--step", "0.05", "--bounds", "-1.5", "-0.05", "-o",
                            str(tmp_path / "br.nc")], capsys)
    assert code == 0 and "limit-cycle branch on Y = 0, increasing" in out
    assert "fold (F)" in out and "-1.000000" in out
    code, _, err = run_cli(["continue", "--model", f"{f}:MODEL", "--param", "mu", "--section",
                            "Y - mu", "--x0", "1.5"], capsys)
    assert code == 2
    one_line(err, "names the continued parameter mu")


def test_cycles_continued_on_a_curved_section_through_their_fold_against_the_closed_form():
    """The fold-of-cycles system's branch, continued on the parabola Y = X^2 / 5 (curved: the
    section point's coordinate is measured on its tangent line, moved back onto it along the
    normal): every point on the closed form's cycles, the fold at mu = -1."""
    ns_ = {}
    exec(FOLD_MODEL, ns_)
    p = ns_["MODEL"].params()
    br = ns.continuation(p, "mu", section=("Y - X**2/5", "increasing"), x0=1.5,
                         direction="down", step=0.05, bounds=(-1.5, -0.05))
    assert br.attrs["status"] == "left the bounds"
    X, Y = br.X_section.values[:, 0], br.V_section.values[:, 0]
    assert np.abs(Y - X**2 / 5).max() < 1e-12
    s = X**2 + Y**2
    assert np.allclose(br.mu.values, s**2 - 2 * s, atol=1e-9, rtol=0)
    assert np.allclose(br.period.values, 2 * math.pi, atol=1e-9, rtol=0)
    assert np.allclose(br.multiplier_real.values[:, 0], np.exp(8 * math.pi * s * (1 - s)),
                       rtol=1e-6, atol=1e-12)
    assert (s > 1.4).any() and (s < 0.3).any()  # both sides of the fold
    assert list(br.special_type.values) == [1]
    assert float(br.special_mu[0]) == pytest.approx(-1.0, abs=1e-8)


def test_stick_slip_cycle_continued_in_the_belt_speed_against_its_closed_form():
    """The Coulomb stick-slip cycle (sticking: a saltation at each switch, multiplier 0)
    followed by pseudo-arclength continuation in the belt speed (F0 = 0: the section names the
    self-excited case of a model with forcing): every point is the closed form's cycle."""
    p = M.params()
    br = ns.continuation(p, "v_belt", section="V", v0=1.0, step=0.05, bounds=(0.1, 0.4))
    assert br.attrs["status"] == "left the bounds" and br.sizes["point"] >= 4
    ref = np.array([coulomb_cycle(p.replace(v_belt=v)) for v in br.v_belt.values])
    assert np.allclose(br.period.values, ref[:, 0], atol=1e-9, rtol=0)
    assert np.allclose(br.X_section.values[:, 0], ref[:, 1], atol=1e-9, rtol=0)
    assert np.all(br.multiplier_abs.values < 1e-9) and np.all(br.stable.values == 1)
    assert np.all(br.contact_fraction.values > 0)  # every cycle sticks
    assert br.v_belt.values[-1] > 0.4 and np.all(np.diff(br.v_belt.values) > 0)  # "up"
    # at the lower limit of a parameter's range (xi = 0): a one-sided dF/dlam
    up = ns.continuation(p, "xi", section="V", v0=1.0, step=0.02, bounds=(0.0, 0.05))
    assert up.sizes["point"] >= 2 and float(up.xi[0]) == 0.0
    assert float(up.period[0]) == pytest.approx(coulomb_cycle(p)[0], abs=1e-9)
    for kw, field in ((dict(start=(up, 0)), "start"), (dict(section_phase=1.0),
                                                       "section_phase")):
        with pytest.raises(ParameterError, match=f"^{field}: "):
            ns.continuation(p, "v_belt", section="V", v0=1.0, **kw)
    with pytest.raises(ParameterError, match="^param: F0 is the forcing's"):
        ns.continuation(p, "F0", section="V", v0=1.0)


def test_fold_of_cycles_followed_in_two_parameters_against_the_closed_form():
    """r' = r (mu + nu r^2 - r^4): cycles where s^2 - nu s - mu = 0 (s = r^2), a fold of
    cycles at mu = -nu^2/4 (s = nu/2). ``two_parameter_curve`` locates it on the cycle branch
    at each nu."""
    m = ns.model_from_equations(
        "fold_of_cycles_2", states=("X", "Y"), parameters={"mu": -0.5, "nu": 2.0},
        modes={"flow": ["X*(mu + nu*(X**2 + Y**2) - (X**2 + Y**2)**2) - Y",
                        "Y*(mu + nu*(X**2 + Y**2) - (X**2 + Y**2)**2) + X"]}, omega=None)
    nus = np.array([1.6, 2.0, 2.4])
    curve = ns.two_parameter_curve(m.params(), "mu", "nu", nus, section=("Y", "increasing"),
                                   x0=2.0, direction="down", step=0.05, bounds=(-2.0, -0.1))
    assert curve.attrs["section"] == "Y = 0, increasing"
    assert np.allclose(curve.mu.values[:, 0], -nus**2 / 4, atol=1e-8, rtol=0)
    assert np.all(np.isnan(curve.mu.values[:, 1:]))  # one fold per branch
    assert np.allclose(curve.multiplier_real.values[:, 0], 1.0, atol=1e-4)


def test_stribeck_cycle_branch_turns_at_its_sliding_bifurcation_against_scipy():
    """v_s = 0.5, xi = 0.68 along the belt speed: the stable stick-slip cycle's stick phase
    shrinks to nothing and the branch turns back onto the unstable slip cycle born at the
    subcritical Hopf point of steady sliding (a sliding bifurcation: a non-smooth fold, the
    multiplier jumps from 0 to about 1.08). Checked against scipy's DOP853 on the slip field:
    at the located corner the slip cycle closes and just touches the belt's speed; the points
    after it are closed slip orbits that never reach it; the branch ends on steady sliding at
    the Hopf point xi = (mu_s - mu_k)/v_s exp(-v_belt/v_s), period 2 pi / omega0."""
    from scipy.integrate import solve_ivp
    from scipy.optimize import minimize_scalar
    p = M.params(v_s=0.5, xi=0.68)
    x_eq = float(ns.equilibria(p).X[0])
    br = ns.continuation(p, "v_belt", section="V", x0=x_eq, v0=1.0, step=0.01,
                         bounds=(0.1, 0.5))
    assert br.attrs["status"].startswith("the cycle shrinks onto an equilibrium")
    fold = np.flatnonzero(br.special_type.values == 1)
    assert len(fold) == 1 and int(br.special_jump[fold[0]]) == 1
    after = int(br.special_after_point[fold[0]])
    mu = br.multiplier_abs.values[:, 0]
    assert np.all(mu[:after + 1] < 1e-9) and np.all(br.contact_fraction[:after - 1] > 0)
    assert np.all(mu[after + 1:] > 1.0) and np.all(br.contact_fraction[after + 1:] == 0)
    lam = br.v_belt.values
    assert np.all(np.diff(lam[:after + 1]) > 0) and np.all(np.diff(lam[after + 1:]) < 0)

    def slip_orbit(v_belt, x):
        """The slip field (v_rel < 0 throughout) from (x, 0) to its next V = 0, decreasing:
        (the return X, the largest V on the way)."""
        q = p.replace(v_belt=v_belt)

        def rhs(t, u):
            return [u[1], -q.omega0**2 * u[0] - q.xi * u[1] + q.mu_k
                    + (q.mu_s - q.mu_k) * math.exp((u[1] - v_belt) / q.v_s)]

        def back(t, u):
            return u[1]
        back.terminal, back.direction = True, -1
        a = solve_ivp(rhs, (0.0, 1.0), [x, 0.0], method="DOP853", rtol=1e-12, atol=1e-13)
        b = solve_ivp(rhs, (1.0, 20.0), a.y[:, -1], method="DOP853", rtol=1e-12, atol=1e-13,
                      events=back, dense_output=True)
        ts = np.linspace(1.0, b.t[-1], 4001)
        i = int(np.argmax(b.sol(ts)[1]))
        top = minimize_scalar(lambda t: -b.sol(t)[1], bounds=(ts[max(i - 1, 0)],
                              ts[min(i + 1, 4000)]), method="bounded",
                              options=dict(xatol=1e-12))
        return float(b.y_events[0][0][0]), float(b.sol(top.x)[1])

    x_ret, v_top = slip_orbit(float(br.special_v_belt[fold[0]]),
                              float(br.special_X_section[fold[0]]))
    assert x_ret == pytest.approx(float(br.special_X_section[fold[0]]), abs=1e-9)
    assert v_top == pytest.approx(float(br.special_v_belt[fold[0]]), abs=1e-8)  # touches
    for i in (after + 2, len(lam) - 2):
        x_ret, v_top = slip_orbit(lam[i], float(br.X_section[i, 0]))
        assert x_ret == pytest.approx(float(br.X_section[i, 0]), abs=1e-9)
        assert v_top < lam[i] - 1e-4
    hopf = math.log((p.mu_s - p.mu_k) / (p.v_s * p.xi)) * p.v_s  # stribeck_slope = xi
    assert abs(lam[-1] - hopf) < 1e-4 and abs(float(br.period[-1]) - 2 * math.pi) < 1e-3


def test_an_isola_of_cycles_is_followed_once_round_and_closes_against_the_closed_form():
    """r' = r g, theta' = 1 with g = 1/4 - mu^2 - (s - 1)^2 (s = r^2): cycles on the circle
    mu^2 + (s - 1)^2 = 1/4 (an isola: a closed branch with folds at mu = +-1/2, s = 1), period
    2 pi, multiplier exp(-8 pi s (s - 1)). Continuation goes once round it, locates both folds
    and stops where the branch comes back to its first point (status "closed loop")."""
    m = ns.model_from_equations(
        "isola_of_cycles", states=("X", "Y"), parameters={"mu": 0.0},
        modes={"flow": ["X*(0.25 - mu**2 - (X**2 + Y**2 - 1)**2) - Y",
                        "Y*(0.25 - mu**2 - (X**2 + Y**2 - 1)**2) + X"]}, omega=None)
    br = ns.continuation(m.params(), "mu", section=("Y", "increasing"), x0=1.2, step=0.05,
                         bounds=(-1.0, 1.0), max_points=400)
    assert br.attrs["status"].startswith("closed loop")
    mu, s = br.mu.values, br.X_section.values[:, 0] ** 2
    assert np.allclose(mu**2 + (s - 1) ** 2, 0.25, atol=1e-9, rtol=0)
    assert np.allclose(br.period.values, 2 * math.pi, atol=1e-9, rtol=0)
    assert np.allclose(br.multiplier_real.values[:, 0], np.exp(-8 * math.pi * s * (s - 1)),
                       rtol=1e-6, atol=1e-12)
    # once round: both halves, every angle of the circle visited, none twice
    ang = np.unwrap(np.arctan2(mu, s - 1))
    assert 2 * math.pi - 0.5 < abs(ang[-1] - ang[0]) < 2 * math.pi + 0.5
    assert list(br.special_type.values) == [1, 1]
    assert np.allclose(np.sort(br.special_mu.values), [-0.5, 0.5], atol=1e-8)
