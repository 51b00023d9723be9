"""The built-in ``two_sided`` model (a mass between two spring-damper supports) against oracles.

(a) with the left support far away (gap_l = 1e3) it is the paper's ``support`` model: the
    stroboscopic points and max X agree with the support model's specialised kernels;
(b) a symmetric system has a symmetric attractor: X(kT + T/2) = -X(kT);
(c) parameter errors are one line and name the field.
"""

from __future__ import annotations

import warnings

import numba as nb
import numpy as np
import pytest

warnings.filterwarnings("ignore", category=nb.NumbaExperimentalFeatureWarning)

from nonsmooth import status as st  # noqa: E402
from nonsmooth.errors import ParameterError  # noqa: E402
from nonsmooth.kernels import Solver, advance, new_state, output_buffers, run  # noqa: E402
from nonsmooth.models import model  # noqa: E402
from nonsmooth.models.support import MODEL as SUPPORT  # noqa: E402

pytestmark = pytest.mark.filterwarnings("ignore::numba.NumbaExperimentalFeatureWarning")

M = model("two_sided")
TABLE3 = dict(omega0=1.0, xi=0.05, F0=0.3125, omega_r=17.32, xi_r=0.6, omega_l=17.32, xi_l=0.6)
# table 3 at omega = 0.8 stays below the support (max X = 0.863): omega = 1.1 is a period-1
# orbit with contact (max X = 1.044)
OMEGA_A = 1.1
SOLVERS = {"exact": dict(), "smooth": dict(rtol=1e-10, atol=1e-12)}
TOL = {"exact": 1e-7, "smooth": 1e-6}


def trajectory(solver, p, n_out, per_period=1, x0=0.0, v0=0.0):
    state = new_state(x0, v0)
    buf = output_buffers(n_out)
    code = run(solver.code, solver.fns, p, solver.opts(), state, per_period, 0, n_out, *buf)
    return code, buf


@pytest.mark.parametrize("method", ["exact", "smooth"])
def test_far_left_support_is_the_support_model(method):
    n = 50
    ps = SUPPORT.params(omega0=1.0, omega_s=17.32, xi=0.05, xi_s=0.6, F0=0.3125, omega=OMEGA_A,
                eta=1e-5)
    s1 = Solver(model="support", method=method, **SOLVERS[method])
    # settle on the period-1 orbit with the support model's specialised kernel (kernels.advance
    # needs no model functions), then run both models from that point for n periods
    state = new_state(0.0, 0.0)
    buf = output_buffers(1)
    assert advance(s1.code, ps.pack(), s1.opts(), state, 1, 299, 1, *buf) == st.OK
    x0, v0 = float(buf[0][0]), float(buf[1][0])
    state = new_state(x0, v0)
    buf = output_buffers(n)
    code1 = advance(s1.code, ps.pack(), s1.opts(), state, 1, 0, n, *buf)
    X1, V1, R1, M1, Xmax1, Xmin1 = buf
    p2 = M.params(**TABLE3, omega=OMEGA_A, gap_l=1e3, eta=1e-5)
    s2 = Solver(model=M, method=method, **SOLVERS[method])
    code2, (X2, V2, R2, M2, Xmax2, Xmin2) = trajectory(s2, p2.pack(), n, x0=x0, v0=v0)
    assert code1 == st.OK and code2 == st.OK
    # a period-1 orbit with contact
    assert abs(X1[-1] - X1[0]) < 1e-8 and abs(V1[-1] - V1[0]) < 1e-8
    assert Xmax1[-1] > 1.0 and M2[-1] & 0b1110  # the right support is hit
    assert Xmin2.min() > -2.0 and not (np.bitwise_or.reduce(M2) & 0b1110000)
    print(method, "max |dX|", np.max(np.abs(X2 - X1)), "max |dV|", np.max(np.abs(V2 - V1)),
          "max |dXmax|", np.max(np.abs(Xmax2 - Xmax1)))
    tol = TOL[method]
    assert np.max(np.abs(X2 - X1)) < tol
    assert np.max(np.abs(V2 - V1)) < tol
    assert np.max(np.abs(Xmax2 - Xmax1)) < tol
    assert M.is_contact(p2, int(np.bitwise_or.reduce(M2)), Xmax2.max(), Xmin2.min())


@pytest.mark.parametrize("method", ["exact", "smooth"])
def test_symmetric_system_has_symmetric_orbit(method):
    # omega = 1.1, F0 = 0.8: a stable symmetric period-1 orbit touching both supports
    p = M.params(**{**TABLE3, "F0": 0.8}, omega=1.1, gap_r=1.0, gap_l=1.0, eta=1e-5)
    s = Solver(model=M, method=method, **SOLVERS[method])
    n = 600  # 300 periods, sampled at t = kT/2
    code, (X, V, R, Mk, Xmax, Xmin) = trajectory(s, p.pack(), n, per_period=2)
    assert code == st.OK
    mask = int(np.bitwise_or.reduce(Mk[-2:]))
    assert mask & 0b0001110 and mask & 0b1110000  # both sides are hit
    assert max(Xmax[-2:]) > 1.0 and min(Xmin[-2:]) < -1.0
    assert abs(X[-1] - X[-3]) < 1e-8  # periodic
    # X(kT + T/2) = -X(kT), V likewise
    for k in (n - 2, n - 4):
        assert abs(X[k + 1] + X[k]) < 1e-6, (X[k], X[k + 1])
        assert abs(V[k + 1] + V[k]) < 1e-6
    assert abs(max(Xmax[-2:]) + min(Xmin[-2:])) < 1e-6


def test_smooth_matches_exact_asymmetric():
    # different gaps and supports on the two sides: a period-1 orbit hitting both; the switch
    # model with a thin band (eta = 1e-6) follows the exact non-smooth system
    p = M.params(**{**TABLE3, "F0": 1.2, "omega_l": 10.0, "xi_l": 0.3}, omega=1.0, gap_r=0.8,
                 gap_l=1.2, eta=1e-6)
    out = {}
    for method in ("exact", "smooth"):
        s = Solver(model=M, method=method, **SOLVERS[method])
        code, buf = trajectory(s, p.pack(), 200)
        assert code == st.OK
        out[method] = buf
    Xe, Ve, Re, Me, Xmaxe, Xmine = out["exact"]
    Xs, Vs, Rs, Ms, Xmaxs, Xmins = out["smooth"]
    assert abs(Xe[-1] - Xe[-2]) < 1e-10  # period 1
    assert Xmaxe[-1] > 0.8 and Xmine[-1] < -1.2
    assert Me[-1] == 0b1001001  # free, contact_r, contact_l
    assert Ms[-1] == 0b1111111  # every band and contact mode of the switch model
    assert np.max(np.abs(Xs - Xe)) < 1e-7 and np.max(np.abs(Vs - Ve)) < 1e-7
    assert np.max(np.abs(Xmaxs - Xmaxe)) < 1e-7 and np.max(np.abs(Xmins - Xmine)) < 1e-7


def test_exact_linear_coefficients():
    from nonsmooth.models._probe import call_linear
    fns = M.fns("exact")
    p = M.params(gap_r=0.7, gap_l=1.3, omega_r=3.0, xi_r=0.2, omega_l=5.0, xi_l=0.4)
    out = np.zeros(4)
    assert call_linear(fns, 3, p.pack(), out) == 1
    assert np.allclose(out, [1.0 + 9.0, 0.05 + 0.2, 9.0 * 0.7, 0.3125])
    assert call_linear(fns, 6, p.pack(), out) == 1
    assert np.allclose(out, [1.0 + 25.0, 0.05 + 0.4, -25.0 * 1.3, 0.3125])
    assert call_linear(fns, 0, p.pack(), out) == 1
    assert np.allclose(out, [1.0, 0.05, 0.0, 0.3125])


@pytest.mark.parametrize("values, field", [
    (dict(gap_r=-1.0), "gap_r"),
    (dict(gap_l=-0.5), "gap_l"),
    (dict(mu_s=0.3), "mu_s"),
    (dict(eta=0.7), "eta"),
    (dict(eta=0.0), "eta"),
    (dict(omega_r=0.0, xi_r=0.5), "omega_r"),
    (dict(omega_l=0.0, xi_l=0.5), "omega_l"),
    (dict(gap_r=0.1, gap_l=0.1, eta=0.2), "eta"),
])
def test_parameter_errors(values, field):
    with pytest.raises(ParameterError) as e:
        M.params(**values)
    msg = str(e.value)
    assert "\n" not in msg and msg.startswith(field), msg


def test_lines_and_contact():
    p = M.params(gap_r=0.5, gap_l=2.0)
    xs = [x for x, _ in M.plot_lines(p, "exact")]
    assert xs == [0.5, -2.0]
    assert len(M.plot_lines(p, "smooth")) == 6
    assert M.is_contact(p, 1 | 8, 0.6, 0.0)
    assert not M.is_contact(p, 1, 0.6, 0.0)
    assert M.is_contact(p, 1 | 64, 0.0, -2.1)
    assert not M.is_contact(p, 1 | 64, 0.0, -1.9)
