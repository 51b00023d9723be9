"""Classification with evidence: lambda1 with its error in poincare, bifurcation_diagram and
basins, and the verdicts periodic / quasi-periodic / chaotic / not settled
(``analysis.stability.classify``)."""

import math

import numpy as np
import pytest

import nonsmooth as ns
from nonsmooth.analysis.stability import (CHAOTIC, NOT_SETTLED, PERIODIC, QUASI_PERIODIC,
                                          classify)


def test_classify_rules():
    assert classify(-0.02, 0.001, period=3) == PERIODIC
    assert classify(0.05, 0.005, period=0) == CHAOTIC
    assert classify(0.001, 0.002, period=0) == QUASI_PERIODIC
    assert classify(-0.05, 0.001, period=0) == NOT_SETTLED  # no period found, yet contracting
    assert classify(-0.05, 0.001, period=None) == PERIODIC  # no period looked for


def test_poincare_chaotic_has_positive_lambda1_beyond_error():
    ds = ns.poincare(ns.preset("table3").replace(omega=0.92), transient=300, record=300,
                     method="exact")
    assert int(ds.period) == 0
    assert float(ds.lambda1) > 5 * float(ds.lambda1_stderr) > 0
    assert int(ds.motion) == CHAOTIC
    assert ds.motion.attrs["flag_meanings"].split()[CHAOTIC] == "chaotic"


def test_bifurcation_periodic_points_match_floquet():
    """On period-1 points lambda1 from the sweep equals ln|mu_1| / T of the orbit that
    periodic_orbit finds from the sweep's section point."""
    params = ns.preset("fig7")
    b = ns.bifurcation_diagram(params, "omega", [1.08, 1.1, 1.12], sweep="up", method="exact",
                               transient=300, record=200)
    assert np.all(b.period.values == 1) and np.all(b.motion.values == PERIODIC)
    for j, om in enumerate(b.omega.values):
        p = params.replace(omega=float(om))
        orb = ns.periodic_orbit(p, x0=float(b.X[0, j, -1]), v0=float(b.V[0, j, -1]))
        assert orb.attrs["status"] == "converged"
        lam = math.log(float(orb.multiplier_abs[0])) / p.period
        assert float(b.lambda1[0, j]) == pytest.approx(lam, rel=2e-3)


def test_basins_attractor_lambda1_equals_floquet():
    params = ns.preset("fig7")
    ds = ns.basins(params, grid=24, method="exact")
    assert ds.sizes["attractor"] == 2
    for a in range(2):
        orb = ns.periodic_orbit(params, x0=float(ds.attractor_X[a, 0]),
                                v0=float(ds.attractor_V[a, 0]))
        lam = math.log(float(orb.multiplier_abs[0])) / params.period
        # 400 periods of one tangent vector; a complex pair makes the per-period growth oscillate
        assert float(ds.lambda1[a]) == pytest.approx(lam, rel=3e-3)
        assert float(ds.lambda1[a]) < 0


def test_lyapunov_off_keeps_the_old_variables():
    ds = ns.poincare(ns.preset("fig7"), transient=50, record=20, method="exact",
                     lyapunov=False)
    assert "lambda1" not in ds and int(ds.period) == 1


def test_periodic_points_get_the_floquet_lambda1_without_error_bars():
    """A periodic point of a sweep reports ln|mu_1| / (p T) of its orbit (one tangent pass over
    p periods), stderr 0, the same number as the orbit Newton's shooting finds."""
    params = ns.preset("fig7")
    b = ns.bifurcation_diagram(params, "omega", [1.1, 1.11], sweep="up", method="exact",
                               transient=300, record=50)
    assert int(b.period[0, 0]) == 1 and float(b.lambda1_stderr[0, 0]) == 0.0
    p = params.replace(omega=1.1)
    orb = ns.periodic_orbit(p, x0=float(b.X[0, 0, -1]), v0=float(b.V[0, 0, -1]))
    lam = math.log(float(orb.multiplier_abs[0])) / p.period
    assert float(b.lambda1[0, 0]) == pytest.approx(lam, rel=1e-5)
    sec = ns.poincare(p, transient=300, record=50, method="exact")
    assert int(sec.period) == 1 and float(sec.lambda1_stderr) == 0.0
    assert float(sec.lambda1) == pytest.approx(lam, rel=1e-5)


def test_benettin_stops_at_its_error_target_and_short_records_run_whole(monkeypatch):
    from nonsmooth.analysis import stability
    from nonsmooth.kernels import Solver, new_state
    p = ns.preset("fig4")
    solver = Solver(method="exact", model=p.model)
    P = p.pack()[None, :]
    sec = ns.poincare(p, transient=300, record=20, method="exact", lyapunov=False)
    S = new_state(float(sec.X[-1]), float(sec.V[-1]))[None, :]
    lam, err, _ = stability.lambda1_points(P, solver, S, 30000)
    assert 0 < err[0] <= stability.REL_STDERR * lam[0]  # ended at the target ...
    monkeypatch.setattr(stability, "REL_STDERR", 0.0)
    lam_all, err_all, _ = stability.lambda1_points(P, solver, S, 30000)
    assert err_all[0] < err[0]  # ... long before the 30000 periods
    assert abs(lam[0] - lam_all[0]) <= 3 * err[0]
    # a record within the first stage runs whole: the target changes nothing
    short = stability.lambda1_points(P, solver, S, 400)
    monkeypatch.setattr(stability, "REL_STDERR", 1.0)
    assert np.array_equal(short[0], stability.lambda1_points(P, solver, S, 400)[0])


def test_evidence_runs_skip_the_extrema_and_keep_the_trajectory(monkeypatch):
    """The lambda1 evidence's tangent runs leave out the interior extrema of X
    (``OPT_NO_EXTREMA``, a third of their time): the same lambda1 to the last bit, on a
    chaotic and a periodic point, through Benettin and through one monodromy pass."""
    from nonsmooth.analysis import stability
    from nonsmooth.kernels import Solver, new_state
    P = np.array([ns.preset("fig4").pack(), ns.preset("table3").replace(omega=0.86).pack()])
    solver = Solver(method="exact", model=ns.preset("fig4").model)
    S = np.array([new_state(0.1, 0.0), new_state(0.1, 0.0)])
    quiet = (stability.lambda1_points(P, solver, S, 300)[0],
             stability.floquet_lambda1_points(P[1:], solver, S[1:], [3])[0])
    monkeypatch.setattr(stability, "quiet_opts", lambda setup: setup.opts.copy())
    full = (stability.lambda1_points(P, solver, S, 300)[0],
            stability.floquet_lambda1_points(P[1:], solver, S[1:], [3])[0])
    assert np.all(np.isfinite(quiet[0])) and quiet[0][0] > 0 > quiet[0][1]
    assert np.array_equal(quiet[0], full[0]) and np.array_equal(quiet[1], full[1])


def test_smooth_sweep_evidence_is_the_closed_form_tangent_of_the_same_equations():
    """support's ``smooth`` names ``smooth_closed_form`` (the same switch model solved
    exactly) for its lambda1 evidence: a periodic point without contact gets the linear
    oscillator's -xi / 2 to rounding (the RKF45 tangent at 1e-8 was 1.5e-7 off), and a
    period-3 contact orbit the Floquet lambda1 of the orbit converged by Newton's shooting
    at rtol 1e-12 (the RKF45: 1.6e-7)."""
    params = ns.preset("table3")
    b = ns.bifurcation_diagram(params, "omega", [0.82, 0.86], sweep="up")
    assert b.lambda1.attrs["tangent_method"] == "smooth_closed_form"
    assert b.attrs["method"] == "smooth"
    assert int(b.period[0, 0]) == 1 and int(b.contact[0, 0]) == 0
    assert float(b.lambda1[0, 0]) == pytest.approx(-params.xi / 2, rel=1e-12)
    k = int(b.period[0, 1])
    assert k == 3
    p = params.replace(omega=0.86)
    orb = ns.periodic_orbit(p, k=k, x0=float(b.X[0, 1, -1]), v0=float(b.V[0, 1, -1]),
                            method="smooth_closed_form", rtol=1e-12, atol=1e-14)
    assert orb.attrs["status"] == "converged"
    lam = math.log(float(orb.multiplier_abs[0])) / (k * p.period)
    assert float(b.lambda1[0, 1]) == pytest.approx(lam, rel=2e-8)


def test_an_evidence_method_must_solve_the_same_equations():
    from dataclasses import replace

    from nonsmooth.errors import ParameterError
    m = ns.model("support")
    methods = dict(m.methods)
    methods["smooth_eq12"] = replace(methods["smooth_eq12"], evidence="smooth_closed_form")
    with pytest.raises(ParameterError) as exc:
        replace(m, name="support_variant", methods=methods)
    msg = str(exc.value)
    assert "\n" not in msg and "smooth_eq12" in msg and "evidence" in msg
    assert ns.model("two_sided").method("smooth").evidence == "smooth_closed_form"
