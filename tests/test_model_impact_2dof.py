"""The built-in two-degree-of-freedom impact oscillator ``impact_2dof`` against scipy
``solve_ivp`` with events (an independent event-driven solution), and every analysis on its full
four-component state: initial conditions for every component, results naming every component,
Floquet multipliers of the 4-D map against finite differences of scipy's map, continuation
started from and carrying all components."""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import nonsmooth as ns
from nonsmooth.errors import ParameterError

pytestmark = pytest.mark.filterwarnings("ignore::numba.NumbaExperimentalFeatureWarning")

M = ns.model("impact_2dof")
P = M.params()  # F0 = 1, omega = 1, stop at delta = 0.5: one impact per period


def scipy_flow(p, u0, t1, t0=0.0):
    """u(t1) from u(t0) = u0: DOP853 at rtol 1e-12 between impacts located by events, Newton's
    law V -> -r V at X = delta (no sticking on these orbits)."""
    def rhs(t, u):
        X, V, Y, W = u
        spring = p.mu * (p.omega2**2 * (X - Y) + p.xi2 * (V - W))
        return [V, p.F0 * math.cos(p.omega * t) - p.omega1**2 * X - p.xi1 * V - spring,
                W, -p.omega2**2 * (Y - X) - p.xi2 * (W - V)]

    def hit(t, u):
        return u[0] - p.delta
    hit.terminal, hit.direction = True, 1.0
    t, u = t0, np.array(u0, float)
    impacts = 0
    while t < t1:
        sol = solve_ivp(rhs, (t, t1), u, method="DOP853", rtol=1e-12, atol=1e-13, events=hit)
        t, u = sol.t[-1], sol.y[:, -1].copy()
        if sol.status == 1:
            u[1] = -p.r * u[1]
            impacts += 1
            u[0] = p.delta  # exactly on the stop
    return u, impacts


def test_trajectory_against_scipy_with_events():
    u0 = {"X": 0.1, "V": -0.2, "Y": 0.3, "W": 0.05}
    T = 2 * math.pi / P.omega
    ds = ns.simulate(P, periods=20, u0=u0, method="exact", samples_per_period=1)
    U = ns.io.components(ds)
    assert list(U.component.values) == ["X", "V", "Y", "W"] and U.dims == ("t", "component")
    assert ds.Y.attrs["units"] == "m" and ds.W.attrs["units"] == "m/s"
    assert np.allclose(U.values[0], [0.1, -0.2, 0.3, 0.05])
    assert ds.attrs["u0"].tolist() == [0.1, -0.2, 0.3, 0.05]
    ref, impacts = scipy_flow(P, [0.1, -0.2, 0.3, 0.05], 20 * T)
    assert impacts >= 15  # it does hit the stop, about once a period
    assert np.max(np.abs(U.values[-1] - ref)) < 1e-8


def test_periodic_orbit_and_its_floquet_multipliers_against_scipy():
    po = ns.poincare(P, transient=300, record=16, method="exact")
    assert int(po.period) == 1 and int(po.contact) == 1
    last = ns.io.components(po).values[-1]
    orb = ns.periodic_orbit(P, u0=last, method="exact")
    assert orb.attrs["status"] == "converged"
    z = ns.io.components(orb, suffix="_section").values[0]
    assert z.shape == (4,) and orb.Y_section.dims == ("point",)
    T = 2 * math.pi / P.omega
    Pz, _ = scipy_flow(P, z, T)
    assert np.max(np.abs(Pz - z)) < 1e-8  # a fixed point of scipy's map too
    # the monodromy against central differences of scipy's map
    J = np.empty((4, 4))
    for j in range(4):
        h = 1e-5
        a, _ = scipy_flow(P, z + h * np.eye(4)[j], T)
        b, _ = scipy_flow(P, z - h * np.eye(4)[j], T)
        J[:, j] = (a - b) / (2 * h)
    assert np.max(np.abs(orb.monodromy.values - J)) < 1e-5
    mu_ref = np.sort(np.abs(np.linalg.eigvals(J)))[::-1]
    assert np.allclose(orb.multiplier_abs.values, mu_ref, atol=1e-5)
    assert np.allclose(ns.io.components(orb).values[0], z)


def test_poincare_section_and_orbit_name_every_component():
    po = ns.poincare(P, transient=50, record=5, method="exact", u0=[0.0, 0.0, 0.2, 0.0],
                     lyapunov=False)
    sim = ns.simulate(P, periods=int(po.transient_used) + 5, u0=[0.0, 0.0, 0.2, 0.0],
                      method="exact", samples_per_period=1)
    # the section points recorded again with every component are the same points
    U, S = ns.io.components(po), ns.io.components(sim)
    assert np.allclose(U.values, S.values[-5:], rtol=0, atol=1e-12)
    orbit = ns.io.components(po, "orbit_")
    assert orbit.dims == ("sample", "component")
    assert np.allclose(orbit.values[0], U.values[-1])


def test_lyapunov_spectrum_has_four_exponents_equal_to_the_floquet_logs():
    po = ns.poincare(P, transient=300, record=8, method="exact", lyapunov=False)
    last = ns.io.components(po).values[-1]
    orb = ns.periodic_orbit(P, u0=last, method="exact")
    ly = ns.lyapunov(P, periods=400, transient=100, u0=last, method="exact")
    T = 2 * math.pi / P.omega
    assert ly.sizes["i"] == 4
    # on a stable periodic orbit the exponents are ln|mu| / T of the Floquet multipliers
    ref = np.sort(np.log(orb.multiplier_abs.values) / T)[::-1]
    assert np.allclose(ly.exponent.values, ref, atol=5e-3)


def test_continuation_starts_from_and_carries_every_component():
    po = ns.poincare(P, transient=300, record=4, method="exact", lyapunov=False)
    last = ns.io.components(po).values[-1]
    br = ns.continuation(P, "omega", u0=last, bounds=(0.98, 1.02), step=0.01, method="exact")
    sec = ns.io.components(br, suffix="_section")
    assert sec.dims == ("point", "j", "component") and sec.sizes["component"] == 4
    assert np.allclose(sec.values[0, 0], last, atol=1e-8)
    T = 2 * math.pi / br.omega.values[-1]
    Pz, _ = scipy_flow(P.replace(omega=float(br.omega.values[-1])), sec.values[-1, 0], T)
    assert np.max(np.abs(Pz - sec.values[-1, 0])) < 1e-8


def test_smooth_stop_converges_to_the_impact_law_as_one_over_sqrt_k_c():
    """The compliant stop's contact lasts ~ pi / sqrt(k_c): the settled orbit's error decays as
    k_c^(-1/2), on every component."""
    ex = ns.simulate(P, periods=10, transient=200, method="exact", samples_per_period=20)
    errs = []
    for k_c in (1e4, 1e6, 1e8):
        sm = ns.simulate(P.replace(k_c=k_c), periods=10, transient=200, method="smooth",
                         samples_per_period=20)
        assert float(sm.max_X) > P.delta  # it penetrates the compliant stop, a little
        errs.append(float(np.max(np.abs(ns.io.components(sm).values
                                        - ns.io.components(ex).values))))
    slopes = np.diff(np.log10(errs)) / 2.0
    assert np.all(np.abs(slopes + 0.5) < 0.1), (errs, slopes)
    assert errs[-1] < 5e-3


@pytest.mark.parametrize("u0, message", [
    ([0.0, 0.0, 0.0], "u0: expected 4 numbers (X, V, Y, W), got 3"),
    ({"Z": 1.0}, "u0: unknown component 'Z' (model 'impact_2dof' has X, V, Y, W)"),
    ([0.0, 0.0, math.nan, 0.0], "u0[Y]: must be finite"),
    ("Y=1,W", "u0: expected NAME=VALUE pairs"),
])
def test_bad_initial_states_are_one_line_errors(u0, message):
    with pytest.raises(ParameterError, match=message.replace("(", r"\(").replace(")", r"\)")
                       .replace("[", r"\[").replace("]", r"\]")):
        ns.simulate(P, periods=1, u0=u0, method="exact")


def test_u0_and_x0_together_are_refused():
    with pytest.raises(ParameterError, match="u0: give the initial state either as u0 or as"):
        ns.periodic_orbit(P, x0=0.1, u0={"Y": 0.2})


def test_cli_starts_from_u0_shows_the_named_components_and_refuses_unknown_ones(tmp_path,
                                                                                 capsys):
    import xarray as xr

    from cli_helpers import one_line, run_cli
    out, fig = tmp_path / "s.nc", tmp_path / "s.png"
    code, stdout, _ = run_cli(["simulate", "-m", "impact_2dof", "--method", "exact", "--u0",
                               "X=0.1,Y=0.3", "--show", "X,Y", "--periods", "2", "-o", str(out),
                               "--plot", str(fig)], capsys)
    assert code == 0 and fig.stat().st_size > 0
    with xr.open_dataset(out) as ds:
        assert ns.io.components(ds).values[0].tolist() == [0.1, 0.0, 0.3, 0.0]
    orb = tmp_path / "o.png"
    code, stdout, _ = run_cli(["orbit", "-m", "impact_2dof", "--transient", "300", "--show",
                               "Y,W", "--plot", str(orb)], capsys)
    assert code == 0 and "Y(jT)" in stdout and "W(jT)" in stdout and orb.stat().st_size > 0
    for argv, needle in ((["simulate", "-m", "impact_2dof", "--show", "X,Q"],
                          "show: unknown component 'Q'"),
                         (["orbit", "-m", "impact_2dof", "--show", "X,Q"],
                          "show: unknown component 'Q'"),
                         (["poincare", "-m", "impact_2dof", "--show", "X"],
                          "show: expected two state components"),
                         (["simulate", "-m", "impact_2dof", "--u0", "Q=1"],
                          "u0: unknown component 'Q'")):
        code, _, err = run_cli(argv + ["--plot", str(tmp_path / "x.png")], capsys)
        assert code == 2
        one_line(err, needle)


def test_a_start_beyond_the_stop_or_below_the_table_is_refused(capsys):
    """The exact methods admit only states on the free side of their rigid obstacle (the
    smooth ones, whose obstacle is compliant, admit any)."""
    from cli_helpers import one_line, run_cli
    with pytest.raises(ParameterError, match=r"u0: the start \(X=0.7, V=0, Y=0, W=0\) is "
                                             r"outside what impact_2dof \(exact\) admits: "
                                             r"X <= delta"):
        ns.simulate(P, periods=1, x0=0.7, method="exact")
    ball = ns.model("bouncing_ball").preset("period_one")
    for call in (lambda: ns.periodic_orbit(ball, x0=-0.1, method="exact"),
                 lambda: ns.bifurcation_diagram(ball, "A", [0.03, 0.04], x0=-0.1,
                                                method="exact")):
        with pytest.raises(ParameterError, match=r"admits: Z >= 0"):
            call()
    assert ns.simulate(ball, periods=1, x0=-0.01, method="smooth").sizes["t"] > 0
    code, _, err = run_cli(["simulate", "-m", "impact_2dof", "--method", "exact", "--x0", "0.7",
                            "--plot", "/tmp/never.png"], capsys)
    assert code == 2
    one_line(err, "outside what impact_2dof (exact) admits: X <= delta")


def test_x_and_v_quantities_carry_the_models_units():
    po = ns.poincare(P, transient=20, record=4, method="exact", lyapunov=False)
    for name in ("X", "max_X", "min_X", "orbit_X", "Y", "orbit_Y"):
        assert po[name].attrs["units"] == "m", name
    for name in ("V", "orbit_V", "W"):
        assert po[name].attrs["units"] == "m/s", name
    bif = ns.bifurcation_diagram(P, "omega", [0.9, 1.0], transient=20, record=4,
                                 method="exact", lyapunov=False)
    assert bif.X.attrs["units"] == "m" and bif.max_X.attrs["units"] == "m"
    assert ns.preset("table3").model.state_units == ("1", "1/s")  # the paper's, unchanged


def test_basins_on_any_two_components_against_single_runs(tmp_path, capsys):
    """Basins on the grid (X, Y) with V = W = 0 (the exact method merges trajectories in
    sticking: no certificate, every point runs until its section repeats): each grid point's
    label is the attractor that ``poincare`` reaches from the same full start, and the axes
    are named in the result."""
    ds = ns.basins(P, x=(-0.6, 0.4), v=(-0.8, 0.8), grid=3, method="exact", axes=("X", "Y"),
                   max_periods=2000)
    assert ds.attrs["axes"] == "X Y" and ds.v0.attrs["long_name"] == "initial Y"
    assert ds.attrs["certified_cells"] == 0 and float(ds.undecided_fraction) == 0.0
    for i, x in enumerate(ds.x0.values):
        for j, y in enumerate(ds.v0.values):
            po = ns.poincare(P, transient=600, record=4, method="exact", u0=[x, 0.0, y, 0.0],
                             lyapunov=False)
            k = int(ds.label[i, j])
            pts = np.stack([ds.attractor_X[k].values, ds.attractor_V[k].values], axis=1)
            last = np.array([float(po.X[-1]), float(po.V[-1])])
            assert np.nanmin(np.abs(pts - last).max(axis=1)) < 1e-6
    from cli_helpers import one_line, run_cli
    out = tmp_path / "b.nc"
    code, stdout, _ = run_cli(["basins", "-m", "impact_2dof", "--method", "exact", "--axes",
                               "X,Y", "--u0", "W=0.1", "--x", "-0.6", "0.4", "--v", "-0.8",
                               "0.8", "--grid", "2", "-o", str(out)], capsys)
    assert code == 0 and "attractor" in stdout
    code, _, err = run_cli(["basins", "-m", "impact_2dof", "--axes", "X,Q", "-o",
                            str(tmp_path / "c.nc")], capsys)
    assert code == 2
    one_line(err, "axes: unknown component 'Q'")


def test_basins_certify_balls_in_the_four_dimensional_state_space():
    """The smooth method's flow is a homeomorphism: on a grid of 64 x 64 points in (X, Y) the
    capture balls and lattice cells are certified in the whole state space (X, V, Y, W). Far
    from the stop (delta = 5) the model is linear with one attractor, the forced response, so
    every label is known; nearly every point is decided at once instead of running ~130
    periods until its section repeats. A 16 x 16 grid certifies nothing (it would not pay)."""
    p = ns.model("impact_2dof").params(delta=5.0, k_c=100.0)
    ds = ns.basins(p, x=(-1, 1), v=(-1, 1), grid=64, method="smooth", axes=("X", "Y"),
                   lyapunov=False)
    assert ds.sizes["attractor"] == 1 and (ds.label.values == 0).all()
    assert float(ds.capture_radius[0, 0]) > 0.5
    assert ds.attrs["certified_cells"] == ds.attrs["lattice_cells"] == 16
    assert ds.periods_used.mean() < 2.0 and ds.attrs["certification_periods"] > 0
    small = ns.basins(p, x=(-1, 1), v=(-1, 1), grid=16, method="smooth", axes=("X", "Y"),
                      lyapunov=False)
    assert small.attrs["certification_periods"] == 0 and small.periods_used.mean() > 50
