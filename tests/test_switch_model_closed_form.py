"""The ``smooth_closed_form`` method of the support and two_sided models: the switch model
(eq. 13) solved exactly, Gamma-, Sigma_beta and Gamma+ in closed form and Sigma_alpha by RKF45
at rtol 1e-12. Its oracle is the same equations integrated by the RKF45 alone at rtol 1e-12
(``smooth`` on the generic kernel), from which it must differ by that integrator's error
only, while ``smooth`` at the paper's tolerances differs by about 1e-6."""

import numpy as np
import pytest

import nonsmooth as ns
from nonsmooth import status as st
from nonsmooth.kernels import KERNEL_GENERIC, Solver, new_state, output_buffers, run

pytestmark = pytest.mark.filterwarnings("ignore::numba.NumbaExperimentalFeatureWarning")

SUPPORT = ns.model("support")


def _sections(p, method, periods, rtol=1e-8, atol=1e-10):
    s = Solver(model=p.model, method=method, rtol=rtol, atol=atol)
    buf = output_buffers(periods)
    code = KERNEL_GENERIC if method == "smooth" else s.code
    assert run(code, s.fns, p.pack(), s.opts(), new_state(0.0, 0.0), 1, 0, periods, *buf) \
        == st.OK
    return buf


@pytest.mark.parametrize("preset, kw, periods", [
    ("table3", {"omega": 1.1}, 40),  # period 1, contact every period
    ("table3", {"omega": 0.91}, 60),  # period 3
    ("table1", {}, 20),  # Fig. 3: through all four regions
    ("table2", {"omega_s": 10.0}, 30),
])
def test_closed_form_is_the_switch_models_own_solution(preset, kw, periods):
    p = SUPPORT.preset(preset).replace(**kw)
    cf = _sections(p, "smooth_closed_form", periods)
    tight = _sections(p, "smooth", periods, rtol=1e-12, atol=1e-14)
    paper = _sections(p, "smooth", periods)
    err = np.max(np.abs(cf[0] - tight[0]) + np.abs(cf[1] - tight[1]))
    rkf = np.max(np.abs(paper[0] - tight[0]) + np.abs(paper[1] - tight[1]))
    assert err < 1e-9 and rkf > 100 * err, (err, rkf)
    np.testing.assert_array_equal(cf[3], tight[3])  # the same regions visited
    assert np.count_nonzero(cf[3] & 0b1000) > periods // 3  # contact (Gamma+)


def test_floquet_multipliers_agree_with_the_tight_rkf45():
    """The tangent dynamics of the closed-form pieces (their propagators) with the saltation
    matrices and the continuous memory Va: the multipliers of the period-1 orbit at
    omega = 1.1 as those of the RKF45 at rtol 1e-12."""
    p = SUPPORT.preset("table3").replace(omega=1.1)
    a = ns.periodic_orbit(p, method="smooth_closed_form", transient=200)
    b = ns.periodic_orbit(p, method="smooth", transient=200, rtol=1e-12, atol=1e-14)
    assert a.attrs["converged"] == 1 and b.attrs["converged"] == 1
    ma = np.sort_complex(a.multiplier_real.values + 1j * a.multiplier_imag.values)
    mb = np.sort_complex(b.multiplier_real.values + 1j * b.multiplier_imag.values)
    assert np.max(np.abs(ma - mb)) < 1e-8


def test_chaotic_lambda1_agrees_with_the_paper_tolerance_method():
    """Table 3 at omega = 0.92 (chaotic): the two methods follow different trajectories of the
    same attractor; their largest Lyapunov exponents agree within their standard errors."""
    p = SUPPORT.preset("table3").replace(omega=0.92)
    a = ns.lyapunov(p, periods=3000, transient=200, method="smooth_closed_form")
    b = ns.lyapunov(p, periods=3000, transient=200, method="smooth")
    la, lb = float(a.exponent[0]), float(b.exponent[0])
    se = float(np.hypot(a.stderr[0], b.stderr[0]))
    assert la > 10 * float(a.stderr[0])  # chaotic
    assert abs(la - lb) < 4 * se, (la, lb, se)


def test_two_sided_closed_form_against_the_tight_rkf45():
    """Both supports hit every period (F0 = 0.6, omega = 1.3: period 1): each side's Sigma_alpha
    with its own entry velocity, the other regions in closed form."""
    p = ns.model("two_sided").params(F0=0.6, omega=1.3)
    cf = _sections(p, "smooth_closed_form", 40)
    tight = _sections(p, "smooth", 40, rtol=1e-12, atol=1e-14)
    paper = _sections(p, "smooth", 40)
    err = np.max(np.abs(cf[0] - tight[0]) + np.abs(cf[1] - tight[1]))
    rkf = np.max(np.abs(paper[0] - tight[0]) + np.abs(paper[1] - tight[1]))
    assert err < 1e-9 and rkf > 100 * err, (err, rkf)
    np.testing.assert_array_equal(cf[3], tight[3])
    assert np.count_nonzero(cf[3] & 0b0000010) > 25  # Sigma_alpha_r (its Va)
    assert np.count_nonzero(cf[3] & 0b0010000) > 25  # Sigma_alpha_l (its Va)
