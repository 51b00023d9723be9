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
    with pytest.raises(ParameterError, match="section: .* is not affine in the state"):
        ns.limit_cycle(p, "X*V")
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
    lc = ns.limit_cycle(p, "V", x0=x_eq, v0=1.0)
    assert lc.attrs["status"] == "converged" and int(lc.stable) == 1
    assert float(lc.period) == pytest.approx(float(far.cycle_period), abs=1e-8)
    assert (lc.mode.values == M.mode_names.index("stick")).any()
