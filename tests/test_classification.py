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
