"""Models written as equations (``ns.model_from_equations``): the same numbers as the same
models written by hand, closed forms derived for linear modes, any periodic forcing through
the period's local time, tangent dynamics, and one-line errors for bad equations."""

import inspect
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import nonsmooth as ns
from nonsmooth.errors import ParameterError

pytestmark = pytest.mark.filterwarnings("ignore::numba.NumbaExperimentalFeatureWarning")

FREE_DUFFING = "-xi*V - X - beta*X**3 + F0*cos(omega*t)"
SUPPORT_FORCE = "k_s*(X - gap) + c_s*V"


def one_sided_duffing():
    """The README's one-sided Duffing example (examples/one_sided_duffing.py, exact method)
    written as equations: its memory slot (free above the gap after a separation) becomes a
    third mode."""
    return ns.model_from_equations(
        "duffing_equations", states=("X", "V"),
        parameters={"xi": 0.1, "beta": 0.5, "F0": 1.0,
                    "omega": dict(default=1.2, low=0.0, low_open=True), "gap": 1.0,
                    "k_s": dict(default=20.0, low=0.0, low_open=True),
                    "c_s": dict(default=0.2, low=0.0)},
        modes={"free": ["V", FREE_DUFFING],
               "contact": ["V", f"{FREE_DUFFING} - ({SUPPORT_FORCE})"],
               "above": ["V", FREE_DUFFING]},
        guards={"free": [("gap - X", [("V > 0", "contact"), (True, "above")])],
                "contact": [(SUPPORT_FORCE, [("X > gap", "above"), (True, "free")])],
                "above": [(f"-({SUPPORT_FORCE})", "contact"), ("X - gap", "free")]},
        initial=[(f"X > gap and {SUPPORT_FORCE} > 0", "contact"), ("X > gap", "above")],
        method="exact", rtol=1e-12, atol=1e-14, contact_modes=("contact",))


def impact_oscillator():
    """Newton's impact law at X = 1, without chatter resolution (orbits with one impact per
    period only)."""
    return ns.model_from_equations(
        "impact_equations", states=("X", "V"),
        parameters={"omega0": 1.0, "xi": 0.05, "F0": 3.0, "omega": 1.5,
                    "r": dict(default=0.8, low=0.0, high=1.0)},
        modes={"free": ["V", "-omega0**2*X - xi*V + F0*cos(omega*t)"]},
        guards={"free": [ns.Guard("1 - X", "free", reset={"V": "-r*V"})]},
        method="exact", flow_is_homeomorphism=True)


def test_equations_reproduce_the_hand_written_example():
    eq = one_sided_duffing()
    hand = ns.model("examples/one_sided_duffing.py:MODEL")
    assert eq.mode_names == ("free", "contact", "above") and eq.contact_modes == 0b10
    a = ns.simulate(eq.params(), periods=20, transient=10, method="exact", samples_per_period=20)
    b = ns.simulate(hand.params(), periods=20, transient=10, method="exact",
                    samples_per_period=20)
    assert float(a.max_X) > 1.0  # contact happens
    np.testing.assert_allclose(a.X.values, b.X.values, rtol=0, atol=1e-10)
    np.testing.assert_allclose(a.V.values, b.V.values, rtol=0, atol=1e-10)
    assert float(a.max_X) == pytest.approx(float(b.max_X), abs=1e-10)


def test_linear_mode_gets_its_closed_form_and_matches_the_built_in_impact_model():
    eq = impact_oscillator()
    meth = eq.methods["exact"]
    assert meth.closed_form and meth.linear is not None
    values = dict(omega0=1.0, xi=0.05, F0=3.0, omega=1.5, r=0.8)
    a = ns.simulate(eq.params(**values), periods=30, transient=100, method="exact")
    b = ns.simulate(ns.model("impact").params(**values), periods=30, transient=100,
                    method="exact")
    np.testing.assert_allclose(a.X.values, b.X.values, rtol=0, atol=1e-9)
    np.testing.assert_allclose(a.V.values, b.V.values, rtol=0, atol=1e-9)
    assert float(a.max_X) == pytest.approx(1.0, abs=1e-12)  # the stop is reached, not passed
    # the same Floquet multipliers of the period-1 orbit (tangent dynamics with saltation)
    oa = ns.periodic_orbit(eq.params(**values), x0=0.0, v0=0.0, transient=100, method="exact")
    ob = ns.periodic_orbit(ns.model("impact").params(**values), x0=0.0, v0=0.0, transient=100,
                           method="exact")
    assert int(oa.converged) == 1 and int(ob.converged) == 1
    np.testing.assert_allclose(np.sort(oa.multiplier_abs.values),
                               np.sort(ob.multiplier_abs.values), rtol=1e-8)


def test_regularised_law_with_logistic_and_softplus_matches_the_example_and_its_tangent():
    """The example's smooth method (a regularised support force): the derived Jacobian of
    logistic and softplus stays finite far from the band (a Jacobian of the same law written
    with exp overflows to inf / inf there), and the Floquet multipliers agree."""
    force = ("logistic((X - gap)/eta) * k_s*eta*softplus((k_s*(X - gap) + c_s*V)/(k_s*eta))")
    eq = ns.model_from_equations(
        "duffing_smooth_equations", states=("X", "V"),
        parameters={"xi": 0.1, "beta": 0.5, "F0": 1.0, "omega": 1.2, "gap": 1.0,
                    "k_s": 20.0, "c_s": 0.2, "eta": 1e-3},
        modes={"free": ["V", f"{FREE_DUFFING} - {force}"],
               "contact": ["V", f"{FREE_DUFFING} - {force}"]},
        guards={"free": [("gap - X", "contact")], "contact": [("X - gap", "free")]},
        initial=[("X >= gap", "contact")], method="smooth", contact_modes=("contact",))
    hand = ns.model("examples/one_sided_duffing.py:MODEL")
    a = ns.simulate(eq.params(), periods=20, transient=10, method="smooth", samples_per_period=20)
    b = ns.simulate(hand.params(), periods=20, transient=10, method="smooth",
                    samples_per_period=20)
    np.testing.assert_allclose(a.X.values, b.X.values, rtol=0, atol=1e-9)
    oa = ns.periodic_orbit(eq.params(), x0=0.1, transient=200, method="smooth")
    ob = ns.periodic_orbit(hand.params(), x0=0.1, transient=200, method="smooth")
    assert int(oa.converged) == 1 and int(ob.converged) == 1
    np.testing.assert_allclose(np.sort(oa.multiplier_abs.values),
                               np.sort(ob.multiplier_abs.values), rtol=1e-6)


def test_any_periodic_forcing_through_the_local_time():
    """Two harmonics and a constant load on a linear oscillator (no surfaces): the model reads
    cos(2 omega t) from the period's local time; scipy integrates the same equation."""
    m = ns.model_from_equations(
        "two_harmonics", states=("X", "V"),
        parameters={"xi": 0.1, "F0": 1.0, "F1": 0.5, "omega": 1.3, "b": 0.2},
        modes={"free": ["V", "-X - xi*V + F0*cos(omega*t) + F1*sin(2*omega*t) + b"]},
        method="smooth")
    assert not m.methods["smooth"].closed_form  # sin(2 omega t) is not of the closed form
    p = m.params()
    ds = ns.simulate(p, periods=5, method="smooth", samples_per_period=8, rtol=1e-11,
                     atol=1e-13)
    T = 2 * math.pi / 1.3

    def rhs(t, y):
        return [y[1], -y[0] - 0.1 * y[1] + math.cos(1.3 * t) + 0.5 * math.sin(2.6 * t) + 0.2]
    ref = solve_ivp(rhs, (0, 5 * T), [0.0, 0.0], rtol=1e-12, atol=1e-13, method="DOP853",
                    t_eval=ds.t.values)
    np.testing.assert_allclose(ds.X.values, ref.y[0], atol=1e-8)


def test_step_terms_are_not_taken_for_closed_forms_and_sign_differentiates():
    """Coulomb friction -mu sign(V) (or a Piecewise step) has zero derivatives but is not a
    constant: the mode has no closed form; its Jacobian is that of the smooth part."""
    for law in ("mu*sign(V)", "mu*Piecewise((1, V > 0), (-1, True))"):
        m = ns.model_from_equations(
            "coulomb", states=("X", "V"), parameters={"mu": 0.1, "F0": 1.0, "omega": 1.3},
            modes={"slip": ["V", f"-X - {law} + F0*cos(omega*t)"]}, method="exact")
        assert not m.methods["exact"].closed_form
        p = m.params()
        ds = ns.simulate(p, periods=2, x0=0.5, v0=0.3, method="exact", samples_per_period=4)

        def rhs(t, y):
            return [y[1], -y[0] - 0.1 * np.sign(y[1]) + math.cos(1.3 * t)]
        T = 2 * math.pi / 1.3
        ref = solve_ivp(rhs, (0, 0.25 * T), [0.5, 0.3], rtol=1e-12, atol=1e-13, method="DOP853")
        assert float(ds.X[1]) == pytest.approx(ref.y[0, -1], abs=1e-8)  # before V's sign flips


def test_periodic_forcing_in_t_is_the_same_at_any_section_phase():
    """A rectangular pulse in the time within the period: t is wrapped into [0, T), so a run
    started at the section phase pi/2 follows the phase-0 run."""
    m = ns.model_from_equations(
        "pulse", states=("X", "V"), parameters={"xi": 0.2, "F0": 1.0, "omega": 1.0, "c": 0.3},
        modes={"free": ["V", "-X - xi*V + F0*Piecewise((1, t < pi/omega), (0, True)) - c"]},
        method="smooth")  # a parameter may be called c (or k, s, u, p)
    kw = dict(method="smooth", rtol=1e-11, atol=1e-13)
    a = ns.simulate(m.params(), periods=6, samples_per_period=4, **kw)
    b = ns.simulate(m.params(), periods=5, samples_per_period=4, x0=float(a.X[1]),
                    v0=float(a.V[1]), section_phase=math.pi / 2, **kw)
    assert np.max(np.abs(b.X.values - a.X.values[1:1 + b.sizes["t"]])) < 1e-8


def square_wave(method="exact"):
    """A linear oscillator pushed by a square wave of period T (a parameter): +F0 while
    sin(2 pi t / T) >= 0, -F0 after; two modes whose surfaces are affine in sin, so the
    switches are located exactly and each mode is a closed-form linear mode."""
    return ns.model_from_equations(
        "square_wave", states=("X", "V"),
        parameters={"xi": 0.05, "F0": 0.4, "T": dict(default=5.0, low=0.0, low_open=True)},
        modes={"push": ["V", "-X - xi*V + F0"], "pull": ["V", "-X - xi*V - F0"]},
        guards={"push": [("sin(2*pi*t/T)", "pull")], "pull": [("-sin(2*pi*t/T)", "push")]},
        initial=[("sin(2*pi*t/T) >= 0", "push")], period="T", method=method,
        forcing_amplitude="F0")


def test_a_model_names_its_forcing_period():
    """``period="T"``: T frames time (the section at t = kT, the output interval, t in the
    functions); a square wave switched exactly at its edges matches scipy integrating each
    half period, and the stroboscopic analyses sweep T."""
    m = square_wave()
    assert m.forcing_param == "T" and not m.autonomous and m.omega is None
    assert m.methods["exact"].closed_form
    p = m.params(T=5.0)
    assert p.period == 5.0 and p.pack().size == len(m.parameters)
    ds = ns.simulate(p, periods=6, method="exact", samples_per_period=4)
    np.testing.assert_allclose(np.diff(ds.t.values), 5.0 / 4)

    def half(sign):
        return lambda t, y: [y[1], -y[0] - 0.05 * y[1] + sign * 0.4]
    y, ref = np.zeros(2), [0.0]
    for k in range(12):  # half periods: push, pull, ...
        for q in (1, 2):  # output at T/4 within each half period, and at its end
            sol = solve_ivp(half(1 if k % 2 == 0 else -1), (0, 1.25), y, rtol=1e-12,
                            atol=1e-14, method="DOP853")
            y = sol.y[:, -1]
            ref.append(y[0])
    np.testing.assert_allclose(ds.X.values, ref, atol=1e-9)
    # the same forcing period as a frequency: omega = 2 pi / T gives the same numbers
    mw = ns.model_from_equations(
        "square_wave_omega", states=("X", "V"),
        parameters={"xi": 0.05, "F0": 0.4, "omega": 2 * math.pi / 5.0},
        modes={"push": ["V", "-X - xi*V + F0"], "pull": ["V", "-X - xi*V - F0"]},
        guards={"push": [("sin(omega*t)", "pull")], "pull": [("-sin(omega*t)", "push")]},
        initial=[("sin(omega*t) >= 0", "push")], method="exact")
    dw = ns.simulate(mw.params(), periods=6, method="exact", samples_per_period=4)
    np.testing.assert_allclose(dw.X.values, ds.X.values, atol=1e-12)
    # stroboscopic analyses sweep the period: a linear system has one period-1 orbit
    bd = ns.bifurcation_diagram(p, "T", np.linspace(4.0, 6.0, 3), transient=300, record=8,
                                method="exact", sweep="up", lyapunov=False)
    assert bd.T.values.tolist() == [4.0, 5.0, 6.0]
    assert (bd.period.values == 1).all()
    po = ns.periodic_orbit(p, method="exact")
    assert int(po.converged) == 1
    # the damped linear map: both multipliers have modulus exp(-xi T / 2)
    np.testing.assert_allclose(po.multiplier_abs.values, math.exp(-0.05 * 5.0 / 2), rtol=1e-8)
    with pytest.raises(ParameterError, match="period 'P' must be a parameter"):
        ns.model_from_equations("bad", states=("X", "V"), parameters={"T": 1.0},
                                modes={"free": ["V", "-X"]}, period="P")
    with pytest.raises(ParameterError, match="not both"):
        ns.model_from_equations("bad", states=("X", "V"), parameters={"T": 1.0, "w": 1.0},
                                modes={"free": ["V", "-X"]}, period="T", omega="w")
    with pytest.raises(ParameterError, match="not both"):  # "omega" given, not the default
        ns.model_from_equations("bad", states=("X", "V"),
                                parameters={"T": 1.0, "omega": 1.0},
                                modes={"free": ["V", "-X"]}, period="T", omega="omega")


@pytest.mark.parametrize("change, needle", [
    (dict(modes={"free": ["V", "-X + foo"]}), "mode free, dV/dt: unknown name 'foo'"),
    (dict(modes={"free": ["V", "-X +* 2"]}), "mode free, dV/dt: cannot parse"),
    (dict(modes={"free": ["V"]}), "mode free: 1 expressions for 2 states"),
    (dict(guards={"free": [("1 + 0*X", "free")]}), "zero gradient"),
    (dict(guards={"free": [("1 - X", "nowhere")]}), "unknown mode 'nowhere'"),
    (dict(guards={"gone": [("1 - X", "free")]}), "guards: unknown mode 'gone'"),
    (dict(parameters={"omega": 1.0, "t": 2.0}), "'t' cannot name"),
    (dict(guards={"free": [("1 - X + Piecewise((0.5, V > 0), (0, True))", "free")]}),
     "is not smooth"),
    (dict(modes={"free": ["V", "-X + Piecewise((1, V > 0))"]}), "needs a last branch"),
    (dict(methods={"exact": dict(modes={"free": ["V", "-X"]})}, rtol=1e-9), "per method"),
    (dict(parameters={"xi": 1.0}), "forcing frequency 'omega' must be a parameter"),
])
def test_bad_equations_are_one_line_errors(change, needle):
    kw = dict(states=("X", "V"), parameters={"omega": 1.0, "xi": 0.1},
              modes={"free": ["V", "-X - xi*V + cos(omega*t)"]})
    kw.update(change)
    with pytest.raises(ParameterError) as exc:
        ns.model_from_equations("bad", **kw)
    msg = str(exc.value)
    assert msg.startswith("model bad: ") and needle in msg and "\n" not in msg


def test_a_model_file_of_equations_runs_from_the_cli(tmp_path):
    import subprocess
    import sys
    f = tmp_path / "impact_eq.py"
    f.write_text(
        "import nonsmooth as ns\n"
        "MODEL = ns.model_from_equations('impact_eq', states=('X', 'V'),\n"
        "    parameters={'xi': 0.05, 'F0': 3.0, 'omega': 1.5, 'r': 0.8},\n"
        "    modes={'free': ['V', '-X - xi*V + F0*cos(omega*t)']},\n"
        "    guards={'free': [ns.Guard('1 - X', 'free', reset={'V': '-r*V'})]})\n")
    r = subprocess.run([sys.executable, "-m", "nonsmooth.cli", "poincare", "--model",
                        f"{f}:MODEL", "--method", "exact", "--record", "20", "--transient",
                        "100", "-o", str(tmp_path / "p.nc")], capture_output=True, text=True,
                       timeout=300)
    assert r.returncode == 0, r.stderr
    ds = ns.io.load_dataset(tmp_path / "p.nc")
    assert int(ds.period) == 1 and ds.attrs["model"] == "impact_eq"
    # its description says that it declares no contact (a newcomer read "contact: contact")
    r = subprocess.run([sys.executable, "-m", "nonsmooth.cli", "models", f"{f}:MODEL"],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0 and "contact: not defined (no contact_modes" in r.stdout


def test_a_forcing_frequency_or_period_given_as_a_plain_number_must_be_positive():
    """A plain number's range is any finite value, but omega <= 0 (or T <= 0) frames no time:
    one line naming it. (A newcomer's omega=0 reached the kernel, which ended the run as
    'non-finite state'.)"""
    by_period = ns.model_from_equations(
        "plain_T", states=("X", "V"), parameters={"T": 5.0, "F0": 0.4},
        modes={"free": ["V", "-X - 0.05*V + F0*cos(2*pi*t/T)"]}, period="T", method="exact",
        compile_now=False)
    for bad in (0.0, -1.5):
        with pytest.raises(ParameterError, match=r"^omega: the forcing frequency must be > 0, "
                                                 r"got " + f"{bad:g}$"):
            impact_oscillator().params(omega=bad)
        with pytest.raises(ParameterError, match=r"^T: the forcing period must be > 0"):
            by_period.params(T=bad)
    assert impact_oscillator().params(omega=0.5).omega == 0.5
    assert by_period.params(T=2.0).T == 2.0


def test_default_ranges_of_a_period_model_are_periods(tmp_path, capsys):
    """The default sweeps of a model with a forcing period are the frequency defaults as
    periods: parameter_map's x axis and the CLI's --from/--to (bifurcation: omega 0.8 ... 1.0,
    so T = 2 pi / 1.0 ... 2 pi / 0.8)."""
    from cli_helpers import run_cli
    from nonsmooth.io import load_dataset
    m = square_wave()
    assert m.forcing_range(0.8, 1.0) == pytest.approx((2 * math.pi, 2.5 * math.pi))
    assert ns.model("support").forcing_range(0.8, 1.0) == (0.8, 1.0)
    d = ns.parameter_map(m.params(), y=("F0", 0.1, 0.4, 1), transient=5, record=2,
                         method="exact", lyapunov=False)
    np.testing.assert_allclose(d["T"].values[[0, -1]], [2 * math.pi, 2.5 * math.pi])
    path = tmp_path / "sq.py"
    path.write_text("import nonsmooth as ns\n\n\n" + inspect.getsource(square_wave)
                    + "\nMODEL = square_wave()\n")
    nc = tmp_path / "b.nc"
    code, out, err = run_cli(["bifurcation", "--model", f"{path}:MODEL", "--steps", "3",
                              "--record", "2", "--transient", "5", "-o", str(nc)], capsys)
    assert code == 0, err
    np.testing.assert_allclose(load_dataset(nc)["T"].values[[0, -1]],
                               [2 * math.pi, 2.5 * math.pi])


def test_a_self_excited_cycle_is_the_same_with_a_period_parameter():
    """A van der Pol oscillator (no forcing amplitude) declared with a period parameter: its
    limit cycle and the orbit sampled over one turn are those of the same model declared with
    omega (the sampling sets the frame slot to the sample interval: a period, not 2 pi / it)."""
    kw = dict(states=("X", "V"), modes={"free": ["V", "mu*(1 - X**2)*V - X"]},
              method="smooth")
    mt = ns.model_from_equations("vdp_T", parameters={"mu": 1.0, "T": 3.0}, period="T",
                                 forcing_amplitude=None, **kw)
    mw = ns.model_from_equations("vdp_w", parameters={"mu": 1.0, "omega": 2 * math.pi / 3.0},
                                 **kw)
    a = ns.limit_cycle(mt.params(), "V", x0=1.0, method="smooth")
    b = ns.limit_cycle(mw.params(), "V", x0=1.0, method="smooth")
    assert float(a.period) == pytest.approx(float(b.period), rel=1e-9)
    assert float(a.max_X) == pytest.approx(float(b.max_X), abs=1e-8)
    assert float(a.max_X) == pytest.approx(2.0086, abs=1e-3)  # van der Pol, mu = 1


def test_a_resonance_over_a_period_names_its_points_by_the_period():
    """Swept over a period T, the resonance curve's contact and jump points are T_a, T_b,
    T_c (the omega_* names stay, with the same values); the figure labels them so."""
    from nonsmooth.analysis.resonance import jump_names

    m = ns.model_from_equations(
        "impact_period", states=("X", "V"),
        parameters={"xi": 0.05, "F0": 0.5, "r": dict(default=0.8, low=0.0, high=1.0),
                    "T": dict(default=5.0, low=0.0, low_open=True)},
        modes={"free": ["V", "-X - xi*V + F0*cos(2*pi*t/T)"]},
        guards={"free": [ns.Guard("1 - X", "free", reset={"V": "-r*V"})]}, method="exact",
        period="T", forcing_amplitude="F0", contact_level=lambda p: 1.0)
    res = ns.resonance_curve(m.params(), np.linspace(4.0, 9.0, 26), method="exact",
                             transient=100, record=10)
    assert jump_names(res) == ("T_a", "T_b", "T_c")
    assert 4.0 < res.attrs["T_a"] == res.attrs["omega_a"] < 9.0
    np.testing.assert_array_equal(res.attrs["T_c_bracket"], res.attrs["omega_c_bracket"])
    fig = ns.plot.plot_resonance(res)
    texts = [t.get_text() for t in fig.axes[0].texts]
    assert any(t.startswith("$T_a = ") for t in texts) and not any("omega" in t for t in texts)
    assert jump_names(ns.resonance_curve(ns.preset("fig6a"), np.linspace(0.9, 1.0, 3),
                                         transient=20, record=5)) == \
        ("omega_a", "omega_b", "omega_c")


def test_a_derivation_is_read_back_and_a_changed_model_derived_again(tmp_path, monkeypatch):
    """A model built again (a command, a worker process) reads its derivation back instead of
    running SymPy, and is the same model; another default, or equations that fail their
    sample check, are derived again (a failed model is never stored)."""
    from nonsmooth import _numba_cache
    from nonsmooth.models import equations as eq
    monkeypatch.setattr(_numba_cache, "cache_base", lambda: tmp_path / "numba")
    derived = []
    real = eq._derive
    monkeypatch.setattr(eq, "_derive", lambda *a: derived.append(a[3]) or real(*a))
    kw = dict(states=("X", "V"), parameters={"xi": 0.05, "F0": 3.0, "omega": 1.5, "r": 0.8},
              modes={"free": ["V", "-X - xi*V + F0*cos(omega*t)"]},
              guards={"free": [ns.Guard("1 - X", "free", reset={"V": "-r*V"})]},
              admissible="X <= 1")
    a = ns.model_from_equations("probe", **kw)
    b = ns.model_from_equations("probe", **kw)
    assert derived == ["exact"]
    ma, mb = a.method("exact"), b.method("exact")
    for field in ("closed_form", "rtol", "atol", "modes", "description", "admissible_text",
                  "flow_is_homeomorphism"):
        assert getattr(ma, field) == getattr(mb, field), field
    assert ma.closed_form and (ma.curved is None) == (mb.curved is None)
    p = b.params()
    assert mb.admissible([0.5, 0.0], p) and not mb.admissible([1.5, 0.0], p)
    runs = [ns.simulate(m.params(), periods=5, method="exact").X.values for m in (a, b)]
    np.testing.assert_array_equal(runs[0], runs[1])
    ns.model_from_equations("probe", **{**kw, "parameters": {**kw["parameters"], "r": 0.7}})
    assert derived == ["exact", "exact"]
    broken = {**kw, "modes": {"free": ["V", "-X + log(X - 2)"]}}  # NaN at the sample point
    for _ in range(2):
        with pytest.raises(ParameterError, match="model broken: "):
            ns.model_from_equations("broken", **broken)
    assert derived[2:] == ["exact", "exact"]
    assert not list((tmp_path / "equations").glob("broken_*.json"))


def _oscillator_closed_form(k, c, b, Fc, Fs, om, X0, V0, t):
    """X'' + c X' + k X = Fc cos(om t) + Fs sin(om t) + b from (X0, V0), independently of the
    kernel: the particular harmonic by harmonic balance, the static part b / k (or, k = c = 0,
    the parabola b t^2 / 2), the homogeneous part by scipy's matrix exponential."""
    from scipy.linalg import expm
    d = k - om * om
    den = d * d + (c * om) ** 2
    P = (Fc * d - Fs * c * om) / den
    Q = (Fc * c * om + Fs * d) / den
    xs = b / k if k else 0.0
    y0 = np.array([X0 - xs - P, V0 - om * Q])
    A = np.array([[0.0, 1.0], [-k, -c]])
    X, V = [], []
    for s in t:
        y = expm(A * s) @ y0
        if not k:  # free flight: the constant force is not in the homogeneous part
            y += [0.5 * b * s * s, b * s]
        X.append(xs + P * math.cos(om * s) + Q * math.sin(om * s) + y[0])
        V.append(om * (Q * math.cos(om * s) - P * math.sin(om * s)) + y[1])
    return np.array(X), np.array(V)


@pytest.mark.parametrize("k, c, b, Fc, Fs", [(2.0, 0.1, 0.3, 0.0, 0.7),  # forced in sin
                                             (0.5, 3.0, -0.2, 0.4, -0.6),  # over-damped
                                             (0.0, 0.0, -1.0, 0.3, 0.8)])  # free flight
def test_a_general_linear_row_of_the_oscillators_form_takes_its_closed_form(k, c, b, Fc, Fs):
    """A mode written as equations that is the oscillator forced in sin (which the (k, c, b, F)
    row cannot state), or free flight under a constant force (k = c = 0), is propagated by
    the oscillator's formulas (``hybrid._oscillator``), with a surface that it reaches only
    at the end: the state against the closed form to 1e-12 (the parabola's growth scaled)."""
    om = 1.3
    m = ns.model_from_equations(
        "general_row", states=("X", "V"),
        parameters={"k": k, "c": c, "b": b, "Fc": Fc, "Fs": Fs, "omega": om},
        modes={"free": ["V", "-k*X - c*V + b + Fc*cos(omega*t) + Fs*sin(omega*t)"]},
        guards={"free": [("X + 1000", "free")]}, method="exact")
    assert m.methods["exact"].closed_form
    ds = ns.simulate(m.params(), periods=6, method="exact", x0=0.2, v0=-0.4,
                     samples_per_period=5)
    X, V = _oscillator_closed_form(k, c, b, Fc, Fs, om, 0.2, -0.4, ds.t.values)
    scale = 1.0 + np.abs(X)
    assert np.max(np.abs(ds.X.values - X) / scale) < 1e-12
    assert np.max(np.abs(ds.V.values - V) / scale) < 1e-12


def test_free_flight_does_not_miss_a_brief_visit_past_a_surface():
    """Free flight from X = 0 with V = 1 under g = 1 tops out at X = 1/2 at t = 1; a surface
    at h = 1/2 - 1e-6 is passed and recrossed within 2.8e-3 of the apex, inside one closed-form
    piece (0.7 / omega = 7 long). The certified exit test of the free mode (its bound
    |g''| <= g) finds it: the reset V -> -V there sends the mass back down at once."""
    h = 0.5 - 1e-6
    m = ns.model_from_equations(
        "brief_visit", states=("X", "V"), parameters={"g": 1.0, "h": h, "omega": 0.1},
        modes={"up": ["V", "-g"]}, guards={"up": [("h - X", [(True, "up", {"V": "-V"})])]},
        method="exact")
    ds = ns.simulate(m.params(), periods=1, method="exact", x0=0.0, v0=1.0,
                     samples_per_period=40)
    t = ds.t.values
    v1 = math.sqrt(2e-6)  # the speed at h
    t1 = 1.0 - v1
    after = t > t1
    expect = h - v1 * (t[after] - t1) - 0.5 * (t[after] - t1) ** 2
    np.testing.assert_allclose(ds.X.values[after], expect, rtol=0, atol=1e-9 * (1 + t[-1] ** 2))


@pytest.mark.parametrize("forcing", ["sin", "cos"])
@pytest.mark.parametrize("k, b", [(1e-8, -0.1), (1.3 ** 2 * (1 + 1e-7), 0.0)])
def test_an_ill_conditioned_row_keeps_the_series(k, b, forcing):
    """A weak spring with a constant force (b / k = 1e7) and a mode near resonance: the
    oscillator's formulas would cancel large terms (X to 1e-7 and 4e-9 only), so these rows
    go to the series (``hybrid._conditioned``), exact to round-off, whether the mode is a
    general row (forced in sin) or the oscillator's (k, c, b, F) row (forced in cos): X
    against the closed form in 40 digits (mpmath) to 1e-12. (Found by a review of 6fd7526.)"""
    import mpmath as mp
    om, F0 = 1.3, 0.3
    m = ns.model_from_equations(
        "ill_conditioned_row", states=("X", "V"), parameters={"k": k, "b": b, "F0": F0,
                                                              "omega": om},
        modes={"m": ["V", f"-k*X + b + F0*{forcing}(omega*t)"]}, method="exact")
    ds = ns.simulate(m.params(), periods=2, method="exact", x0=0.0, v0=0.5,
                     samples_per_period=50)
    with mp.workdps(40):
        K, B, F, W = mp.mpf(k), mp.mpf(b), mp.mpf(F0), mp.mpf(om)
        s, amp = mp.sqrt(K), F / (K - W * W)  # the particular amp sin (or cos) of omega t
        harm = mp.sin if forcing == "sin" else mp.cos
        c1 = -B / K - (amp if forcing == "cos" else 0)
        c2 = (mp.mpf(0.5) - (amp * W if forcing == "sin" else 0)) / s
        ref = [float(B / K + amp * harm(W * t) + c1 * mp.cos(s * t) + c2 * mp.sin(s * t))
               for t in ds.t.values]
    assert np.max(np.abs(ds.X.values - np.array(ref))) < 1e-12


@pytest.mark.parametrize("v0", [0.05, 0.2])
def test_a_drift_mode_takes_its_closed_form_and_does_not_miss_a_brief_dip(v0):
    """A drift X' = w, V' = 0 (the stick phase of a mass on a belt) against a surface that
    moves, g = c + a cos(omega t) - X: with c chosen so that g dips 1e-6 below zero for some
    5e-3 near t = pi + asin(w / a), inside one piece (0.7 long), the reset X -> 0 must happen
    at the first root of c + a cos(omega t) - w t, and again at the next. From V = w the drift
    moves as force-free flight (``hybrid._MC_DRIFT``: the closed form); from V != w (X' is
    then not V) it takes the series: both give the root-found solution to 1e-11."""
    from scipy.optimize import brentq
    a, w = 0.3, 0.05
    tm = math.pi + math.asin(w / a)
    c = -(a * math.cos(tm) - w * tm) - 1e-6
    m = ns.model_from_equations(
        "drift_dip", states=("X", "V"), parameters={"c": c, "a": a, "w": w, "omega": 1.0},
        modes={"glide": ["w", "0"]},
        guards={"glide": [("c + a*cos(omega*t) - X", [(True, "glide", {"X": "0"})])]},
        method="exact")
    ds = ns.simulate(m.params(), periods=2, method="exact", x0=0.0, v0=v0,
                     samples_per_period=400)
    g = lambda t, t0: c + a * math.cos(t) - w * (t - t0)  # noqa: E731
    t1 = brentq(g, tm - 0.01, tm, args=(0.0,), xtol=1e-15)
    grid = np.linspace(t1 + 1e-3, 4 * math.pi, 4000)  # the next root: the first sign change
    i = np.flatnonzero(np.array([g(s, t1) for s in grid]) < 0)[0]
    t2 = brentq(g, grid[i - 1], grid[i], args=(t1,), xtol=1e-15)
    t = ds.t.values
    expect = np.where(t < t1, w * t, np.where(t < t2, w * (t - t1), w * (t - t2)))
    assert t2 < t[-1] and np.max(np.abs(ds.X.values - expect)) < 1e-11
    assert np.all(ds.V.values == v0)


def test_a_method_knows_the_parameters_it_does_not_read(tmp_path):
    """``Method.unused`` of a model written as equations: the parameters none of the method's
    expressions reads (the forcing frequency always counts as read), the same when the
    derivation comes from the cache; a figure's title leaves them out."""
    import matplotlib
    matplotlib.use("Agg")
    from nonsmooth.plot.common import param_title

    def build():
        return ns.model_from_equations(
            "unused_probe", states=("X", "V"),
            parameters={"F0": 0.5, "omega": 1.3, "k_c": 100.0, "r": 0.8, "spare": 2.0},
            methods={
                "exact": dict(modes={"free": ["V", "F0*cos(omega*t) - X - 0.1*V"]},
                              guards={"free": [ns.Guard("1 - X", "free", {"V": "-r*V"})]}),
                "smooth": dict(modes={"free": ["V", "F0*cos(omega*t) - X - 0.1*V"],
                                      "contact": ["V", "F0*cos(omega*t) - X - 0.1*V "
                                                  "- k_c*(X - 1)"]},
                               guards={"free": [("1 - X", "contact")],
                                       "contact": [("X - 1", "free")]})})
    for m in (build(), build()):  # (the second from the derivation's cache)
        assert m.methods["exact"].unused == ("k_c", "spare")
        assert m.methods["smooth"].unused == ("r", "spare")
    ds = ns.simulate(m.params(), periods=2, method="exact")
    assert param_title(ds) == "F0=0.5, omega=1.3, r=0.8"
