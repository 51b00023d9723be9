"""Conformance of every built-in model and method with the model interface and the kernel
contract: one API, split invariance, statuses, the parameter layout read by name, analyses on
every model, basins' early labelling equal to full integration, one-line parameter errors."""

import math

import numpy as np
import pytest

import nonsmooth as ns
from nonsmooth import status as st
from nonsmooth.errors import ParameterError
from nonsmooth.kernels import Solver, new_state, output_buffers, run

BUILTIN = ("support", "two_sided", "impact", "stick_slip", "bouncing_ball", "impact_2dof",
           "jeffcott_rotor")

#: parameters where each model switches every period (and settles quickly)
CASES = {
    "support": dict(omega=1.1),
    "two_sided": dict(omega=1.1, F0=0.8),
    "impact": dict(xi=0.05, F0=3.0, omega=1.5),
    "stick_slip": dict(xi=0.05, F0=0.5, omega=0.8),
    "bouncing_ball": dict(A=1.3 / (4 * math.pi ** 2)),
    "impact_2dof": dict(),
    "jeffcott_rotor": dict(e=0.1, g=0.5),  # partial rub, period one
}

#: a small window of initial conditions around each model's motion, for basins
WINDOWS = {
    "support": ((-1.5, 1.5), (-1.5, 1.5)),
    "two_sided": ((-1.5, 1.5), (-1.5, 1.5)),
    "impact": ((-1.0, 0.9), (-1.0, 1.0)),
    "stick_slip": ((-1.0, 1.5), (-0.5, 0.5)),
    "bouncing_ball": ((0.0, 0.2), (-0.5, 0.5)),
    "impact_2dof": ((-1.0, 0.4), (-1.0, 1.0)),
    "jeffcott_rotor": ((-1.5, 1.5), (-1.5, 1.5)),
}


def params_of(name):
    return ns.model(name).params(**CASES[name])


def pairs():
    return [(m, meth) for m in BUILTIN for meth in ("smooth", "exact")]


def test_models_lists_the_builtins_and_model_returns_them():
    assert ns.models() == BUILTIN
    for name in BUILTIN:
        m = ns.model(name)
        assert m.name == name and m.description and m.parameters
        assert set(m.methods) == ({"smooth", "smooth_eq12", "smooth_closed_form", "exact"}
                                  if name == "support" else
                                  {"smooth", "smooth_closed_form", "exact"}
                                  if name == "two_sided" else {"smooth", "exact"})
        assert m.omega in m.param_names
        assert m.summary()["name"] == name
        for p in m.parameters:  # every parameter has a range text and units
            assert p.range_text and p.units is not None


def test_preset_keeps_returning_the_papers_sets_of_the_support_model():
    p = ns.preset("table3")
    assert p.model is ns.model("support")
    assert isinstance(p, ns.models.ModelParams) and p.omega == 0.91


def test_params_is_a_deprecated_alias_of_the_support_models_params():
    with pytest.warns(DeprecationWarning, match="model\\('support'\\).params"):
        p = ns.Params(omega0=1.0, omega_s=3.0, xi=0.05, xi_s=0.3, F0=0.1, omega=0.9)
    assert p == ns.model("support").params(omega0=1.0, omega_s=3.0, xi=0.05, xi_s=0.3, F0=0.1,
                                           omega=0.9)
    assert isinstance(p, ns.Params) and not isinstance(ns.model("impact").params(), ns.Params)
    with pytest.warns(DeprecationWarning):
        assert ns.Params.from_attrs(p.attrs()) == p
    with pytest.warns(DeprecationWarning):
        q = ns.Params.from_dimensional(m=1.0, k=1.0, c=0.05, k_s=9.0, c_s=0.3, f0=0.1, g=1.0,
                                       omega=0.9)
    assert q.omega_s == pytest.approx(3.0) and q.eta == pytest.approx(1e-5)


@pytest.mark.parametrize("name,method", pairs())
def test_split_invariance_and_status(name, method):
    p = params_of(name)
    s = Solver(model=name, method=method)
    pk, opts = p.pack(), s.opts()
    one = new_state(0.1, 0.0)
    b1 = output_buffers(10)
    assert run(s.code, s.fns, pk, opts, one, 2, 0, 10, *b1) == st.OK
    two = new_state(0.1, 0.0)
    b2 = output_buffers(4)
    assert run(s.code, s.fns, pk, opts, two, 2, 6, 0, *output_buffers(0)) == st.OK
    assert run(s.code, s.fns, pk, opts, two, 2, 0, 4, *b2) == st.OK
    for a, b in zip(b1, b2):
        np.testing.assert_array_equal(a[6:], b)
    np.testing.assert_array_equal(one, two)
    nan = new_state(float("nan"), 0.0)
    assert run(s.code, s.fns, pk, opts, nan, 1, 0, 1, *output_buffers(1)) == st.NON_FINITE


@pytest.mark.parametrize("name", BUILTIN)
def test_parameters_are_read_by_name(name):
    """Permuting nothing but the *values* of two parameters changes the result the way the
    names say: the kernel reads omega where the model's index says omega is."""
    m = ns.model(name)
    p = params_of(name)
    s = Solver(model=name, method="exact")
    pk = p.pack()
    assert pk[m.index[m.omega]] == getattr(p, m.omega)
    a = new_state(0.1, 0.0)
    run(s.code, s.fns, pk, s.opts(), a, 1, 0, 0, *output_buffers(0))
    # the forcing period frames the output: one period at omega, two at omega/2 differ
    q = p.replace(**{m.omega: getattr(p, m.omega) / 2})
    assert q.period == pytest.approx(2 * p.period)


@pytest.mark.parametrize("name,method", pairs())
def test_every_analysis_runs_on_every_model(name, method):
    p = params_of(name)
    ds = ns.simulate(p, periods=2, transient=5, method=method, samples_per_period=20)
    assert ds.attrs["model"] == name and ds.attrs["method"] == method
    assert ds.region.attrs["flag_meanings"].split() == list(ns.model(name).mode_names)
    sec = ns.poincare(p, record=8, transient=30, method=method)
    assert int(sec.period) >= -1
    w = ns.model(name).omega
    bif = ns.bifurcation_diagram(p, w, [getattr(p, w), 1.02 * getattr(p, w)], transient=20,
                                 record=5, method=method)
    assert bif.sizes[w] == 2


@pytest.mark.parametrize("name,method", pairs())
def test_basins_early_labelling_equals_full_integration(name, method):
    p = params_of(name)
    x, v = WINDOWS[name]
    fast = ns.basins(p, x=x, v=v, grid=(5, 4), method=method, max_periods=400)
    slow = ns.basins(p, x=x, v=v, grid=(5, 4), method=method, max_periods=400,
                     early_stop=False)
    np.testing.assert_array_equal(fast.label.values, slow.label.values)
    assert float(fast.undecided_fraction) < 0.5


def test_the_homeomorphism_property_is_declared_per_method():
    assert ns.model("support").method("smooth").flow_is_homeomorphism
    assert not ns.model("impact").method("exact").flow_is_homeomorphism
    assert not ns.model("stick_slip").method("exact").flow_is_homeomorphism


@pytest.mark.parametrize("name,values,field", [
    ("impact", dict(r=1.5), "r"),
    ("stick_slip", dict(mu_k=2.0, mu_s=1.0), "mu_k"),
    ("stick_slip", dict(v_belt=-1.0), "v_belt"),
    ("two_sided", dict(gap_r=-1.0), "gap_r"),
    ("support", dict(mu_s=1.0), "mu_s"),
    ("stick_slip", dict(omega_s=1.0), "omega_s"),
])
def test_bad_parameters_give_one_line_naming_the_field(name, values, field):
    with pytest.raises(ParameterError) as exc:
        ns.model(name).params(**values)
    msg = str(exc.value)
    assert msg.startswith(f"{field}:") and "\n" not in msg


def test_unknown_model_is_one_line():
    with pytest.raises(ParameterError, match="^model: unknown model 'nosuch'"):
        ns.model("nosuch")


def test_generic_kernel_reproduces_the_specialised_support_kernels():
    """The support model written through the interface (models/support/generic.py) and run
    by the generic kernel agrees with the specialised kernels: an independent implementation
    of the same model."""
    p = ns.preset("table3").replace(omega=1.1)  # period 1 with contact every period
    for method, tol in (("smooth", 1e-7), ("smooth_eq12", 1e-7), ("exact", 1e-9)):
        s = Solver(model="support", method=method, rtol=1e-10, atol=1e-12)
        out = {}
        for code in (s.code, 2):
            state = new_state(0.0, 0.0)
            buf = output_buffers(20)
            assert run(code, s.fns, p.pack(), s.opts(), state, 1, 100, 20, *buf) == st.OK
            out[code] = buf
        a, b = out[s.code], out[2]
        assert np.max(np.abs(a[0] - b[0])) < tol and np.max(np.abs(a[1] - b[1])) < tol
        np.testing.assert_array_equal(a[3], b[3])  # the same regions visited
        assert np.all(a[3] & 0b1000)  # contact (Gamma+) in every period
        assert math.isclose(a[4].max(), b[4].max(), abs_tol=tol)


def test_layering_kernels_and_analyses_never_import_a_particular_model():
    """integrate/ and analysis/ (and sweep, simulate) import the model interface only; a new
    model is one new module (the import-linter contract of the architecture review)."""
    import pathlib
    import re
    root = pathlib.Path(ns.__file__).parent
    files = [*(root / "integrate").glob("*.py"), *(root / "analysis").rglob("*.py"),
             root / "sweep.py", root / "simulate.py"]
    names = "|".join(ns.models())
    pattern = re.compile(rf"(from|import)\s+\S*models\.({names}|switch)\b|from \.+models import ({names})")
    offenders = [f"{f.relative_to(root)}: {m.group(0)}" for f in files
                 for m in pattern.finditer(f.read_text())]
    assert offenders == []
