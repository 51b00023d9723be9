"""Sections at any forcing phase (issue 23, item 4): ``section_phase`` psi starts every period
at t_s = psi / omega. Oracles: the same trajectory sampled at t_s + kT by the phase-0 run (any
model and method; the specialised support kernels run phase 0, the generic kernel the shifted
run; the closed-form fold of the bouncing ball that continuation passes only off phase 0 is in
test_model_bouncing_ball.py)."""

import math
import subprocess
import sys

import numpy as np
import pytest

import nonsmooth as ns
from nonsmooth.chunks import solver_from_spec, solver_spec
from nonsmooth.errors import ParameterError
from nonsmooth.kernels import Solver

pytestmark = pytest.mark.filterwarnings("ignore::numba.NumbaExperimentalFeatureWarning")

CASES = [
    (ns.preset("table3").replace(omega=0.92), "exact", 1e-12),
    (ns.preset("table3").replace(omega=0.92), "smooth", 1e-9),  # eq. 13a memory Va as well
    (ns.model("impact").params(F0=3.0, omega=1.5), "exact", 1e-12),  # closed form, resets
    (ns.model("stick_slip").params(F0=0.5, xi=0.1), "exact", 1e-10),  # stick/slip
]


@pytest.mark.parametrize("params, method, tol", CASES,
                         ids=[f"{c[0].model.name}-{c[1]}" for c in CASES])
def test_a_shifted_section_samples_the_same_trajectory(params, method, tol):
    kw = dict(method=method, rtol=1e-11, atol=1e-13)
    a = ns.simulate(params, periods=8, samples_per_period=4, **kw)  # t = kT/4
    for q in (1, 3):  # phases pi/2 and 3 pi/2, started from the state there
        b = ns.simulate(params, periods=6, samples_per_period=4, x0=float(a.X[q]),
                        v0=float(a.V[q]), section_phase=q * math.pi / 2, **kw)
        assert b.attrs["section_phase"] == q * math.pi / 2
        np.testing.assert_allclose(b.t.values, a.t.values[q:q + b.sizes["t"]], rtol=1e-14)
        assert np.max(np.abs(b.X.values - a.X.values[q:q + b.sizes["t"]])) < tol
        assert np.max(np.abs(b.V.values - a.V.values[q:q + b.sizes["t"]])) < 10 * tol


def test_poincare_at_a_phase_reports_its_section_times():
    p = ns.preset("fig7")
    ds = ns.poincare(p, record=20, transient=300, method="exact", section_phase=math.pi)
    T = p.period
    np.testing.assert_allclose(np.diff(ds.t_section.values), T)
    assert ds.t_section.values[0] == pytest.approx(0.5 * T + 301 * T)
    zero = ns.poincare(p, record=20, transient=300, method="exact")
    assert int(ds.period) == int(zero.period) == 1  # the same attractor, another section
    assert abs(float(ds.X[0]) - float(zero.X[0])) > 1e-3


@pytest.mark.parametrize("bad", [-0.1, 2 * math.pi, math.nan, "x", True])
def test_bad_section_phase_is_one_line(bad):
    with pytest.raises(ParameterError, match="^section_phase: must satisfy") as exc:
        Solver(section_phase=bad)
    assert "\n" not in str(exc.value)


def test_section_phase_travels_with_the_solver_spec_and_the_cli(tmp_path):
    s = Solver(method="exact", section_phase=1.25)
    assert solver_from_spec(solver_spec(s)) == s
    r = subprocess.run([sys.executable, "-m", "nonsmooth.cli", "simulate", "--section-phase",
                        "7", "-o", "x.nc"], capture_output=True, text=True, timeout=300,
                       cwd=tmp_path)
    assert r.returncode == 2 and "Traceback" not in r.stderr
    assert r.stderr.strip().splitlines()[-1].startswith("error: section_phase: must satisfy")
    assert not (tmp_path / "x.nc").exists()
