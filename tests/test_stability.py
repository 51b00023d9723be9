"""``ns.lyapunov`` and ``ns.periodic_orbit`` against independent oracles: the linear free
oscillator's exponents, the time average of the divergence (Liouville), Floquet multipliers
of a stable orbit vs lambda1, the unstable saddle of Fig. 7 (multipliers vs finite
differences, quadratic Newton convergence), and bad input."""

from __future__ import annotations

import math
import time
import warnings

import numba as nb
import numpy as np
import pytest

warnings.filterwarnings("ignore", category=nb.NumbaExperimentalFeatureWarning)

import nonsmooth as ns  # noqa: E402
from nonsmooth import status as st  # noqa: E402
from nonsmooth.kernels import Solver, new_state, output_buffers, run  # noqa: E402
from nonsmooth.models.base import KERNEL_GENERIC  # noqa: E402
from nonsmooth.tangent import TangentSetup, fd_period_map  # noqa: E402

pytestmark = pytest.mark.filterwarnings("ignore::numba.NumbaExperimentalFeatureWarning")

METHODS = ["exact", "smooth"]
SADDLE = (-0.982138, 0.596784)
SADDLE_MU = (1.7739, 0.3558)
STABLE = [(0.0, 0.0, (-0.55703, 0.16048)), (-2.0, -2.0, (0.6567, 1.19366))]


fdmap = fd_period_map  # central differences of the kernel's own map


# ---- 4. contact-free orbit: the free linear oscillator ------------------------------------
@pytest.mark.parametrize("method, tol_sum", [("exact", 1e-9), ("smooth", 1e-6)])
def test_contact_free_exponents(method, tol_sum):
    params = ns.preset("table3").replace(F0=0.05)  # amplitude ~0.3: never reaches X = 1
    periods = 500
    d = ns.lyapunov(params, periods=periods, transient=100, method=method, rtol=1e-11,
                    atol=1e-13)
    sim = ns.simulate(params, periods=20, transient=100, samples_per_period=200,
                      method="exact")
    assert float(sim.X.max()) < 0.5
    xi, w0 = params.xi, params.omega0
    expo = d.exponent.values
    # the sum is the divergence -xi exactly (det of the free flow = exp(-xi t))
    assert abs(expo.sum() + xi) <= tol_sum
    # each exponent is -xi/2 up to the finite-time term of the rotation: with A = P Q P^-1
    # (Q = a rotation scaled by exp(-xi t/2)), |Phi^N v| / (exp(-xi N T/2) |v|) lies in
    # [1/kappa(P), kappa(P)], so |lambda_i + xi/2| <= log kappa(P) / (N T)
    b = math.sqrt(w0 * w0 - xi * xi / 4.0)
    P = np.array([[1.0, 0.0], [-xi / 2.0, b]])
    bound = math.log(np.linalg.cond(P)) / (periods * params.period)
    assert np.all(np.abs(expo + xi / 2.0) <= bound + tol_sum)
    # and the bound is not vacuous: it is small against xi/2
    assert bound < 1e-3 * xi


# ---- 5. sum of the exponents = time average of the divergence ------------------------------
@pytest.mark.parametrize("method", METHODS)
def test_exponent_sum_is_mean_divergence(method):
    """At table3, omega = 0.92 (chaotic) the divergence is -xi in free flight and
    -(xi + xi_s) in contact (the switches of the exact model have unit saltation determinant:
    the field is continuous at separation and the entry velocity cancels at touchdown), so
    sum(lambda) = -<xi + xi_s 1_contact>.

    The contact fraction comes from an independent trajectory: ``ns.simulate`` with the exact
    method (the specialised closed-form kernel, not the generic/tangent kernel) sampled
    uniformly in time (region 3 = contact). On a chaotic attractor two numerical trajectories
    separate within ~100 periods, so this is a comparison of two time averages over the same
    invariant measure, not over the same trajectory: its statistical error is ~5e-5 at 3000
    periods (measured), hence 10000 periods here (500 samples per period: a contact lasts
    ~0.1 s = ~7 samples, and sampling errors average out) to keep well inside 1e-4."""
    params = ns.preset("table3").replace(omega=0.92)
    periods, transient = 10000, 200
    sim = ns.simulate(params, periods=periods, transient=transient, samples_per_period=500,
                      method="exact")
    frac = float((sim.region.values[1:] == 3).mean())
    assert 0.005 < frac < 0.05
    d = ns.lyapunov(params, periods=periods, transient=transient, method=method)
    assert float(d.lambda1) > 0.01  # chaotic indeed
    want = -(params.xi + params.xi_s * frac)
    assert abs(float(d.exponent_sum) - want) <= 1e-4


# ---- 6. stable periodic orbit: lambda1 = ln|mu1| / T ---------------------------------------
@pytest.mark.parametrize("method", METHODS)
def test_lambda1_from_floquet(method):
    params = ns.preset("fig7")
    orb = ns.periodic_orbit(params, method=method, transient=300)
    assert orb.attrs["status"] == "converged" and orb.attrs["verdict"] == "stable"
    want = math.log(float(orb.multiplier_abs[0])) / params.period
    d = ns.lyapunov(params, periods=2000, transient=300, method=method)
    assert abs(float(d.lambda1) / want - 1.0) <= 1e-3


# ---- 7. Fig. 7: the saddle and the two attractors ------------------------------------------
def _setup(params, method):
    solver = Solver(method=method, model=params.model, rtol=1e-11, atol=1e-13)
    return TangentSetup(solver), params.pack()


def _check_multipliers_fd(params, method, orb):
    setup, p = _setup(params, method)
    s = new_state(float(orb.X_section[0]), float(orb.V_section[0]))
    run(KERNEL_GENERIC, setup.fns, p, setup.opts, s, 1, 0, 0, *output_buffers(0))  # classify
    F = fdmap(setup, p, s, 1)
    n = setup.n
    assert np.all(F[:n, n:] == 0.0)  # the memory is not read on these orbits: z = u
    ev = np.linalg.eigvals(F[:n, :n])
    ev = ev[np.argsort(-np.abs(ev))]
    mu = orb.multiplier_real.values + 1j * orb.multiplier_imag.values
    assert len(mu) == n
    assert np.max(np.abs(mu - ev)) <= 1e-6


@pytest.mark.parametrize("method", METHODS)
def test_fig7_saddle(method):
    params = ns.preset("fig7")
    orb = ns.periodic_orbit(params, method=method, x0=-1.5, v0=0.25)
    assert orb.attrs["status"] == "converged"
    tol = 1e-6 if method == "exact" else 2e-5
    assert abs(float(orb.X_section[0]) - SADDLE[0]) <= tol
    assert abs(float(orb.V_section[0]) - SADDLE[1]) <= tol
    mu = orb.multiplier_abs.values
    assert np.all(orb.multiplier_imag.values == 0.0)
    assert np.allclose(mu, SADDLE_MU, atol=2e-4)
    assert mu[0] > 1.0 > mu[1]
    assert orb.attrs["verdict"] == "unstable" and int(orb.stable) == 0
    _check_multipliers_fd(params, method, orb)
    # quadratic convergence: from 1e-2 away, a handful of Newton steps
    z = np.array([float(orb.X_section[0]), float(orb.V_section[0])])
    near = ns.periodic_orbit(params, method=method, x0=z[0] + 0.008, v0=z[1] - 0.006)
    assert near.attrs["status"] == "converged" and near.attrs["iterations"] <= 6
    assert abs(float(near.X_section[0]) - z[0]) <= 1e-8
    assert abs(float(near.V_section[0]) - z[1]) <= 1e-8


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("x0, v0, point", STABLE)
def test_fig7_attractors(method, x0, v0, point):
    params = ns.preset("fig7")
    orb = ns.periodic_orbit(params, method=method, x0=x0, v0=v0, transient=300)
    assert orb.attrs["status"] == "converged" and orb.attrs["verdict"] == "stable"
    assert abs(float(orb.X_section[0]) - point[0]) <= 2e-5
    assert abs(float(orb.V_section[0]) - point[1]) <= 2e-5
    assert np.all(orb.multiplier_abs.values < 1.0)
    _check_multipliers_fd(params, method, orb)


# ---- 8. bad input --------------------------------------------------------------------------
@pytest.mark.parametrize("call, field", [
    (lambda P: ns.periodic_orbit(P, k=0), "k"),
    (lambda P: ns.periodic_orbit(P, tol=0.0), "tol"),
    (lambda P: ns.periodic_orbit(P, tol=-1e-10), "tol"),
    (lambda P: ns.lyapunov(P, periods=0), "periods"),
])
def test_bad_input(call, field):
    with pytest.raises(ns.ParameterError) as e:
        call(ns.preset("fig7"))
    msg = str(e.value)
    assert "\n" not in msg and msg.startswith(field + ":")


@pytest.mark.parametrize("method", METHODS)
def test_far_start_fails_gracefully(method):
    t = time.perf_counter()
    orb = ns.periodic_orbit(ns.preset("fig7"), method=method, x0=1e8, v0=0.0)
    assert time.perf_counter() - t < 5.0
    assert orb.attrs["status"] != "converged"
    assert orb.attrs["verdict"] == "not found"


def test_multipliers_of_a_state_at_rest_smoothed_method():
    """Unforced (F0 = 0), the rest state is the orbit: its multipliers are those of the linear
    free oscillator, |mu| = exp(-xi T / 2). The RKF45's error estimate of a state at rest is 0;
    the steps must still be short enough for the tangent (they were a whole period, and the
    smoothed method gave |mu| = 4.25, an unstable rest state)."""
    p = ns.preset("table3").replace(F0=0.0)
    for method in ("smooth", "exact"):
        o = ns.periodic_orbit(p, method=method)
        assert o.attrs["status"] == "converged"
        np.testing.assert_allclose(o.multiplier_abs.values, math.exp(-p.xi * p.period / 2),
                                   rtol=1e-7)
