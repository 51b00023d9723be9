"""The built-in ``impact`` model (rigid stop at X = 1, Newton's restitution) against oracles.

(a) the period-1 single-impact orbit in closed form (free linear flight between impacts, two
    equations for the impact phase and velocity solved with scipy's fsolve): the exact method
    converges to it and stays on it;
(b) chattering (impacts accumulating in finite time) ends in sticking: status OK, never Zeno;
(c) the smooth method (a stiff contact with matched restitution) converges to the exact one as
    the contact stiffness k_c grows;
(d) r outside [0, 1]: a one-line ParameterError naming r.
"""

from __future__ import annotations

import math
import warnings

import numba as nb
import numpy as np
import pytest
from scipy.linalg import expm
from scipy.optimize import fsolve

warnings.filterwarnings("ignore", category=nb.NumbaExperimentalFeatureWarning)

from nonsmooth import status as st  # noqa: E402
from nonsmooth.errors import ParameterError  # noqa: E402
from nonsmooth.kernels import Solver, new_state, output_buffers, run  # noqa: E402
from nonsmooth.models import model  # noqa: E402
from nonsmooth.models.impact import contact_damping  # noqa: E402

pytestmark = pytest.mark.filterwarnings("ignore::numba.NumbaExperimentalFeatureWarning")

M = model("impact")
STUCK_BIT = 1 << M.mode_names.index("stuck")
# a stable period-1 orbit with one impact per forcing period
ORBIT = dict(omega0=1.0, xi=0.05, F0=3.0, omega=1.5, r=0.8)


def trajectory(solver, p, n_out, per_period=1, n_skip=0, x0=0.0, v0=0.0):
    state = new_state(x0, v0)
    buf = output_buffers(n_out)
    code = run(solver.code, solver.fns, p, solver.opts(), state, per_period, n_skip, n_out,
               *buf)
    return code, buf


class FreeFlight:
    """Closed form of X'' + xi X' + w0^2 X = F0 cos(omega t): particular part + expm."""

    def __init__(self, omega0, xi, F0, omega, **_):
        self.w = omega
        d = omega0 ** 2 - omega ** 2
        self.A, self.B = np.linalg.solve([[d, xi * omega], [-xi * omega, d]], [F0, 0.0])
        self.H = np.array([[0.0, 1.0], [-omega0 ** 2, -xi]])

    def particular(self, t):
        w, A, B = self.w, self.A, self.B
        return np.array([A * math.cos(w * t) + B * math.sin(w * t),
                         w * (-A * math.sin(w * t) + B * math.cos(w * t))])

    def flow(self, y0, t0, t1):
        yp0 = self.particular(t0)
        return self.particular(t1) + expm(self.H * (t1 - t0)) @ (np.asarray(y0) - yp0)


def period1_orbit(values):
    """(impact phase t0 in [0, T), impact velocity v > 0) of the period-1 single-impact orbit."""
    ff = FreeFlight(**values)
    r = values["r"]
    T = 2.0 * math.pi / values["omega"]

    def residual(z):
        t0, v = z
        y = ff.flow([1.0, -r * v], t0, t0 + T)
        return [y[0] - 1.0, y[1] - v]

    best = None
    for t0 in np.linspace(0.0, T, 64, endpoint=False):
        for v in (0.5, 1.0, 2.0, 4.0):
            z, info, ier, _ = fsolve(residual, [t0, v], full_output=True, xtol=1e-14)
            if ier == 1 and z[1] > 0 and max(map(abs, residual(z))) < 1e-12:
                # admissible: X < 1 strictly between the impacts
                ts = np.linspace(z[0], z[0] + T, 2001)[1:-1]
                if all(ff.flow([1.0, -r * z[1]], z[0], t)[0] < 1.0 for t in ts):
                    best = (z[0] % T, z[1])
                    break
        if best:
            break
    assert best is not None, "no admissible period-1 orbit found"
    return best, ff, T


def test_period1_orbit_closed_form():
    (t0, v), ff, T = period1_orbit(ORBIT)
    r = ORBIT["r"]
    # the orbit's state at the stroboscopic section t = kT
    y_T = ff.flow([1.0, -r * v], t0, T)
    s = Solver(model=M, method="exact")
    p = M.params(**ORBIT).pack()
    # converged from rest
    code, (X, V, R, Mk, Xmax, Xmin) = trajectory(s, p, 20, n_skip=400)
    assert code == st.OK
    err_conv = max(np.max(np.abs(X - y_T[0])), np.max(np.abs(V - y_T[1])))
    assert np.max(np.abs(Xmax - 1.0)) < 1e-12  # the stop is reached, never passed
    # started on the orbit: stays on it
    code, (X, V, R, Mk, Xmax, Xmin) = trajectory(s, p, 50, x0=y_T[0], v0=y_T[1])
    assert code == st.OK
    err_on = max(np.max(np.abs(X - y_T[0])), np.max(np.abs(V - y_T[1])))
    # impact phase and velocity read from a finely sampled period: the last sample before the
    # impact and the flow from it to X = 1
    n = 4000
    code, (X, V, R, Mk, Xmax, Xmin) = trajectory(s, p, n, per_period=n, x0=y_T[0], v0=y_T[1])
    assert code == st.OK
    k = int(np.argmax(X))  # the sample closest before the impact (X decreases after it)
    tk = (k + 1) * T / n
    y = np.array([X[k], V[k]])
    tt = fsolve(lambda t: ff.flow(y, tk, tk + t[0])[0] - 1.0, [0.0], xtol=1e-15)[0]
    t_imp = (tk + tt) % T
    v_imp = ff.flow(y, tk, tk + tt)[1]
    print(f"impact phase {t0:.12f} (kernel {t_imp:.12f}), velocity {v:.12f} (kernel "
          f"{v_imp:.12f}); strobo errors: converged {err_conv:.2e}, on the orbit {err_on:.2e}")
    assert err_conv < 1e-8 and err_on < 1e-8
    assert abs(t_imp - t0) < 1e-8 and abs(v_imp - v) < 1e-8


@pytest.mark.parametrize("r, omega", [(0.5, 0.2), (0.0, 0.2), (0.7, 0.2), (0.9, 0.05),
                                      (0.99, 0.05)])
def test_chattering_ends_in_sticking(r, omega):
    # pressed onto the stop for part of each period (F0 cos > omega0^2)
    p = M.params(omega0=1.0, xi=0.05, F0=3.0, omega=omega, r=r)
    s = Solver(model=M, method="exact")
    code, (X, V, R, Mk, Xmax, Xmin) = trajectory(s, p.pack(), 80, per_period=8)
    assert code == st.OK, st.message(code)
    assert np.bitwise_or.reduce(Mk[-8:]) & STUCK_BIT  # sticks in the last period
    assert np.bitwise_or.reduce(Mk[-16:-8]) & STUCK_BIT  # and the one before
    assert np.max(Xmax) <= 1.0 + 1e-12
    assert M.is_contact(p, int(Mk[-1]), Xmax.max(), Xmin.min())
    # it also leaves the stop again (the forcing pulls it away for part of the period)
    assert np.min(Xmin[-8:]) < 0.5


def test_smooth_converges_to_exact():
    s_ex = Solver(model=M, method="exact")
    code, (Xe, Ve, *_) = trajectory(s_ex, M.params(**ORBIT).pack(), 1, n_skip=400)
    assert code == st.OK
    dist = []
    for kc in (1e3, 1e4, 1e5):
        s_sm = Solver(model=M, method="smooth", rtol=1e-10, atol=1e-12)
        code, (X, V, R, Mk, Xmax, Xmin) = trajectory(s_sm, M.params(**ORBIT, k_c=kc).pack(), 2,
                                                     n_skip=400)
        assert code == st.OK
        assert abs(X[1] - X[0]) < 1e-8  # period 1
        assert Mk[-1] & (1 << M.mode_names.index("contact"))
        dist.append(math.hypot(X[-1] - Xe[0], V[-1] - Ve[0]))
    print("distance smooth - exact for k_c = 1e3, 1e4, 1e5:", dist)
    assert dist[0] > dist[1] > dist[2]
    assert dist[2] < 0.1 * dist[0]


def test_contact_damping_matches_restitution():
    # one isolated contact X'' + c X' + k (X - 1) = 0 entered at X = 1 with V = 1 returns to
    # X = 1 after half a damped period with V = -r
    for r in (0.8, 0.3, 1.0):
        k = 1e4
        c = contact_damping(r, k)
        zeta = c / (2 * math.sqrt(k))
        wd = math.sqrt(k) * math.sqrt(1 - zeta ** 2)
        assert math.isclose(math.exp(-zeta * math.sqrt(k) * math.pi / wd), r, rel_tol=1e-12)
    assert contact_damping(0.0, 1e4) == pytest.approx(2 * 100.0)


@pytest.mark.parametrize("value", [1.5, -0.1])
def test_restitution_out_of_range(value):
    with pytest.raises(ParameterError) as e:
        M.params(r=value)
    msg = str(e.value)
    assert "\n" not in msg and msg.startswith("r:"), msg


def test_other_parameter_errors():
    for values, field in ((dict(k_c=0.0), "k_c"), (dict(omega0=-1.0), "omega0"),
                          (dict(eta=1e-5), "eta")):
        with pytest.raises(ParameterError) as e:
            M.params(**values)
        assert "\n" not in str(e.value) and str(e.value).startswith(field)
