"""Continuation of periodic orbits (``analysis.continuation``), against oracles: the closed-form
grazing of the contact-free orbit, multipliers +1 / -1 at located folds / period doublings,
the unstable branch between the folds of Fig. 6a, and ``periodic_orbit`` at branch points."""

import math

import numpy as np
import pytest
from scipy.optimize import brentq

import nonsmooth as ns
from nonsmooth.analysis.continuation import (FOLD, GRAZING, PERIOD_DOUBLING, continuation)


def free_amplitude(p, omega, F0):
    """Amplitude of the contact-free period-1 orbit (the linear oscillator's)."""
    return F0 / math.sqrt((p.omega0 ** 2 - omega ** 2) ** 2 + (p.xi * omega) ** 2)


def specials(ds, typ):
    sel = ds.special_type.values == typ
    name = f"special_{ds.attrs['param']}"
    mu = ds.special_multiplier_real.values + 1j * ds.special_multiplier_imag.values
    return ds[name].values[sel], mu[sel]


@pytest.fixture(scope="module")
def fig6a_branch():
    return continuation(ns.preset("fig6a").replace(omega=0.5), "omega", bounds=(0.5, 1.6),
                        step=0.01, max_points=300)


def test_grazing_in_omega_matches_closed_form():
    p = ns.preset("table3").replace(omega=0.6)
    ds = continuation(p, "omega", bounds=(0.5, 0.9), step=0.01, max_points=60)
    w, _ = specials(ds, GRAZING)
    wg = brentq(lambda om: free_amplitude(p, om, p.F0) - 1.0, 0.6, 0.99, xtol=1e-15)
    assert len(w) >= 1 and abs(w[0] - wg) <= 1e-9


def test_grazing_in_F0_matches_closed_form():
    p = ns.preset("table3").replace(omega=0.7, F0=0.2)
    ds = continuation(p, "F0", bounds=(0.1, 0.8), step=0.02, max_points=60)
    f, _ = specials(ds, GRAZING)
    fg = math.sqrt((p.omega0 ** 2 - p.omega ** 2) ** 2 + (p.xi * p.omega) ** 2)  # A = 1
    assert len(f) >= 1 and abs(f[0] - fg) <= 1e-9


def test_fig6a_folds_and_unstable_branch(fig6a_branch):
    ds = fig6a_branch
    w, mu = specials(ds, FOLD)
    assert len(w) == 2
    assert np.all(np.abs(mu - 1.0) <= 1e-6)  # a multiplier through +1 at each fold
    w_b, w_c = sorted(w)
    # the sweep-based jump points of the same resonance curve (resonance_curve, exact):
    # omega_b in [1.05508, 1.05516], omega_c in [1.19305, 1.19313] (a sweep lingers near the
    # ghost of the fold, so its upper jump is at most a few 1e-5 late)
    assert 1.05507 <= w_b <= 1.05516 and 1.1930 <= w_c <= 1.19313
    # between the folds (after turning at omega_c, before turning at omega_b) the branch is
    # unstable: one multiplier outside the unit circle
    om = ds.omega.values
    after = ds.special_after_point.values[ds.special_type.values == FOLD]  # (omega_c, omega_b)
    middle = [i for i in range(after[0] + 1, after[1] + 1) if w_b + 1e-3 < om[i] < w_c - 1e-3]
    assert len(middle) >= 3 and all(ds.multiplier_abs.values[i, 0] > 1.0 for i in middle)
    assert all(ds.stable.values[i] == 0 for i in middle)
    # and the contact onset omega_a (grazing) below both
    g, _ = specials(ds, GRAZING)
    assert 0.94023 <= g.min() <= 0.94032


def test_branch_points_are_periodic_orbits(fig6a_branch):
    ds = fig6a_branch
    p = ns.preset("fig6a")
    upper_fold = int(ds.special_after_point.values[ds.special_type.values == FOLD][0])
    for i in (5, upper_fold + 3):  # a stable point, and one on the unstable branch
        om = float(ds.omega[i])
        orb = ns.periodic_orbit(p.replace(omega=om), x0=float(ds.X_section[i, 0]),
                                v0=float(ds.V_section[i, 0]), max_iter=3)
        assert orb.attrs["status"] == "converged" and orb.attrs["iterations"] <= 2
        assert float(orb.X_section[0]) == pytest.approx(float(ds.X_section[i, 0]), abs=1e-8)
        assert np.allclose(np.sort(orb.multiplier_abs.values),
                           np.sort(ds.multiplier_abs.values[i]), atol=1e-7)


def test_period_doubling_multiplier_is_minus_one():
    p = ns.preset("table3").replace(omega=0.6)
    ds = continuation(p, "omega", bounds=(0.5, 1.0), step=0.01, max_points=80)
    w, mu = specials(ds, PERIOD_DOUBLING)
    # just after grazing (0.83083) and at 0.96935
    assert len(w) == 2 and abs(w[1] - 0.96935) < 1e-4
    assert np.all(np.abs(mu - (-1.0)) <= 1e-6)


@pytest.mark.parametrize("kw, field", [(dict(step=0.0), "step"),
                                       (dict(bounds=(0.95, 1.0)), "bounds"),
                                       (dict(k=0), "k"),
                                       (dict(direction="sideways"), "direction")])
def test_bad_input_one_line(kw, field):
    with pytest.raises(ns.ParameterError) as e:
        continuation(ns.preset("fig7"), "omega", **kw)
    assert str(e.value).startswith(field) and "\n" not in str(e.value)


def test_bad_start_one_line():
    with pytest.raises(ns.ParameterError, match="^start: no period-1 orbit"):
        continuation(ns.preset("fig7"), "omega", x0=1e8, v0=1e8, max_points=3)


def test_branch_switching_at_period_doubling():
    """From the PD of the period-1 branch (table3, omega = 0.96935) the doubled branch starts
    next to it: genuine period-2 orbits (two distinct section points), each a fixed point of
    the 2-fold map that periodic_orbit confirms."""
    p = ns.preset("table3").replace(omega=0.6)
    ds = continuation(p, "omega", bounds=(0.5, 1.0), step=0.01, max_points=80)
    i = int(np.flatnonzero(ds.special_type.values == PERIOD_DOUBLING)[-1])
    w_pd = float(ds.special_omega[i])
    d2 = continuation(p, "omega", start=(ds, i), bounds=(0.9, 1.0), step=0.002, max_points=20)
    assert d2.attrs["k"] == 2 and d2.sizes["point"] >= 5
    assert abs(float(d2.omega[0]) - w_pd) <= 2e-4
    assert np.all(np.abs(d2.X_section.values[:, 0] - d2.X_section.values[:, 1]) > 1e-4)
    j = 3
    orb = ns.periodic_orbit(p.replace(omega=float(d2.omega[j])), k=2,
                            x0=float(d2.X_section[j, 0]), v0=float(d2.V_section[j, 0]),
                            max_iter=3)
    assert orb.attrs["status"] == "converged"
    assert float(orb.X_section[1]) == pytest.approx(float(d2.X_section[j, 1]), abs=1e-8)
    with pytest.raises(ns.ParameterError, match="^start: special point"):
        continuation(p, "omega", start=(ds, int(np.flatnonzero(ds.special_type.values
                                                                 == GRAZING)[0])))


def test_resonance_curve_all_branches():
    """resonance_curve(branches="all"): omega_a/b/c located on the continued branch agree with
    the sweep-based ones (bisection refined to 2e-6) to 1e-5 (measured: 4e-7, 3e-7, 2.3e-6;
    the sweep's omega_c comes late by the slow passage near the fold, 1.6e-7 with a transient
    of 3000), and the branch has an unstable part."""
    ds = ns.resonance_curve(ns.preset("fig6a"), np.linspace(0.5, 1.6, 111), method="exact",
                            transient=500, record=20, resolution=2e-6, branches="all")
    a = ds.attrs
    for key in ("omega_a", "omega_b", "omega_c"):
        assert abs(a[key] - a[f"{key}_continuation"]) <= 1e-5, key
    assert ds.branch_stable.values.min() == 0 and ds.branch_stable.values.max() == 1
    with pytest.raises(ns.ParameterError, match="^branches"):
        ns.resonance_curve(ns.preset("fig6a"), [0.9, 1.0], branches="some")


def test_two_parameter_grazing_curve_matches_closed_form():
    """The grazing curve of the contact-free orbit in (omega, F0): F0 = sqrt((omega0^2 -
    omega^2)^2 + (xi omega)^2) at each located point (the linear amplitude equals the gap)."""
    from nonsmooth.analysis.continuation import two_parameter_curve
    p = ns.preset("table3").replace(omega=0.6, F0=0.3)
    ds = two_parameter_curve(p, "omega", "F0", [0.2, 0.3], special="grazing",
                             bounds=(0.5, 0.95))
    w = ds.omega.values[:, 0]
    F0 = np.sqrt((p.omega0 ** 2 - w ** 2) ** 2 + (p.xi * w) ** 2)
    assert np.all(np.abs(F0 - ds.F0.values) <= 1e-9)
    with pytest.raises(ns.ParameterError, match="^special"):
        two_parameter_curve(p, "omega", "F0", [0.2], special="cusp")


def test_cli_two_parameter(tmp_path):
    from typer.testing import CliRunner
    from nonsmooth.cli import app
    out = tmp_path / "two.nc"
    res = CliRunner().invoke(app, ["continue", "--preset", "table3", "--set", "omega=0.6",
                                   "--param", "omega", "--bounds", "0.5", "0.95",
                                   "--two-param", "F0", "--values", "0.2", "0.3", "2",
                                   "--special", "grazing", "-o", str(out)])
    assert res.exit_code == 0, res.output
    import xarray as xr
    with xr.open_dataset(out) as ds:
        assert ds.sizes["F0"] == 2 and np.all(np.isfinite(ds.omega.values[:, 0]))


def test_stable_parts_agree_with_a_sweep(fig6a_branch):
    """Stable points of the branch (below omega_a, on the contact branch, above omega_c) are the
    attractors a sweep settles on: max X from bifurcation_diagram at the same omega."""
    br = fig6a_branch
    idx = [3, 25, len(br.omega) - 4]
    assert all(int(br.stable[i]) == 1 for i in idx)
    for i in idx:
        om = float(br.omega[i])
        sw = ns.bifurcation_diagram(ns.preset("fig6a"), "omega", [om, om + 1e-9], sweep="fresh",
                                    method="exact", transient=2000, record=5,
                                    x0=float(br.X_section[i, 0]) + 1e-3,
                                    v0=float(br.V_section[i, 0]), lyapunov=False)
        assert float(sw.max_X[0, 0]) == pytest.approx(float(br.max_X[i]), abs=1e-6)


def test_the_corrector_does_not_jump_to_another_branch():
    """Forced Stribeck stick-slip in F0: a corrector that wandered 0.77 in F0 from a step of
    0.045 landed on another branch (the point after F0 = 0.105 was at 0.871); now each point
    lies within three steps (at most 3 x max_step = 0.6) of its prediction, so the branch is
    a connected curve: no two neighbours farther apart than that."""
    p = ns.model("stick_slip").preset("stribeck")
    br = continuation(p, "F0", transient=200, method="exact", bounds=(0.0, 1.0), step=0.02,
                      max_points=40)
    y = np.c_[br.X_section.values[:, 0], br.V_section.values[:, 0], br.F0.values]
    assert np.all(np.linalg.norm(np.diff(y, axis=0), axis=1) <= 0.6)
    assert np.all(np.abs(np.diff(br.F0.values)) <= 0.2 + 1e-12)
    assert br.sizes["point"] >= 20 and float(br.F0[-1]) > 1.0
