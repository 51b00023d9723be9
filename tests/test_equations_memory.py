"""Memory slots of models written as equations (``memory=``): the paper's switch model written
as equations (examples/switch_model_equations.py: the entry velocity Va, a continuous slot,
and the flag of Gamma-'s union) against the built-in ``support`` model's own interface
functions on the same generic kernel, and one-line errors for memory misused."""

import numpy as np
import pytest

import nonsmooth as ns
from nonsmooth import status as st
from nonsmooth.errors import ParameterError
from nonsmooth.kernels import KERNEL_GENERIC, Solver, new_state, output_buffers, run

pytestmark = pytest.mark.filterwarnings("ignore::numba.NumbaExperimentalFeatureWarning")

EXAMPLE = "examples/switch_model_equations.py:MODEL"


def _pair(**kw):
    """The built-in support model's parameters (table 3 with ``kw``) and the same values for
    the equations' model."""
    sup = ns.model("support")
    pa = sup.preset("table3").replace(**kw)
    return pa, ns.model(EXAMPLE).params(**{k: float(getattr(pa, k)) for k in sup.param_names})


def _sections(p, code, periods):
    s = Solver(model=p.model, method="smooth")
    buf = output_buffers(periods)
    assert run(s.code if code is None else code, s.fns, p.pack(), s.opts(), new_state(0.0, 0.0),
               1, 0, periods, *buf) == st.OK
    return buf


def test_memory_slots_are_continuous_where_a_field_uses_them():
    m = ns.model(EXAMPLE)
    assert m.n_memory == 2
    assert m.methods["smooth"].continuous_memory == (0,)  # Va; the flag ``side`` is not
    assert not m.methods["smooth"].closed_form


def test_a_slot_set_from_the_state_and_read_by_a_reset_is_carried_by_the_tangent():
    """No field uses Vm, but it takes the velocity at one event and a later reset reads it:
    its variation must enter the saltation there, so it is continuous memory. The tangent's
    map over three periods equals central differences of the period map (a flag there gave
    0.120 for 0.244)."""
    from nonsmooth.tangent import TangentSetup, period_map
    F = "-X - 0.1*V + F0*cos(omega*t)"
    m = ns.model_from_equations(
        "memory_reset_read", states=("X", "V"), parameters={"F0": 2.0, "omega": 1.3},
        memory={"Vm": "0"}, modes={"left": ["V", F], "right": ["V", F]},
        guards={"left": [("-X", "right", {"Vm": "V"})],
                "right": [("1 - X", "right", {"V": "-0.5*V - 0.3*Vm"}), ("X", "left")]},
        method="smooth", closed_form=False)
    assert m.methods["smooth"].continuous_memory == (0,)
    p = m.params()
    s = Solver(model=m, method="smooth", rtol=1e-12, atol=1e-14)
    st0 = new_state(0.2, 0.0)
    assert run(s.code, s.fns, p.pack(), s.opts(), st0, 1, 0, 30, *output_buffers(30)) == st.OK
    setup = TangentSetup(s)
    P = p.pack()
    _, Y, code, _ = period_map(setup, P, st0, 3)
    assert code == st.OK
    z0 = setup.z_of(st0)
    FD = np.zeros((setup.N, setup.N))
    for j in range(setup.N):
        out = []
        for sg in (1.0, -1.0):
            z = z0.copy()
            z[j] += sg * 1e-6
            out.append(setup.z_of(period_map(setup, P, setup.state_of(z, st0), 3)[0]))
        FD[:, j] = (out[0] - out[1]) / 2e-6
    assert np.max(np.abs(Y - FD)) < 1e-6 * (1.0 + np.max(np.abs(FD)))


@pytest.mark.parametrize("omega", [1.1, 0.91])
def test_switch_model_as_equations_reproduces_the_built_in_model(omega):
    """Same RKF45 steps, guards and transitions as models/support/generic.py on the generic
    kernel: stroboscopic points to round-off over 60 periods from rest (period 1 and period
    3: the orbit runs through Gamma+ and Sigma_alpha, where Va enters the field), the same
    regions visited."""
    pa, pb = _pair(omega=omega)
    a = _sections(pa, KERNEL_GENERIC, 60)
    b = _sections(pb, None, 60)
    assert np.max(np.abs(a[0] - b[0])) < 1e-11 and np.max(np.abs(a[1] - b[1])) < 1e-11
    np.testing.assert_array_equal(a[3], b[3])
    assert np.count_nonzero(a[3] & 0b1000) > 30  # contact (Gamma+)
    assert np.count_nonzero(a[3] & 0b0010) > 15  # and Sigma_alpha (Va in the field)


def test_the_tangent_carries_the_continuous_memory():
    """Floquet multipliers of the period-1 orbit at omega = 1.1: eq. 13a's term xi_s Va (1 - q)
    makes them depend on Va, whose Jacobian column and reset (Va = V on entry) the tangent
    carries; the built-in model gives the same to 1e-10."""
    pa, pb = _pair(omega=1.1)
    oa = ns.periodic_orbit(pa, method="smooth", transient=200)
    ob = ns.periodic_orbit(pb, method="smooth", transient=200)
    assert oa.attrs["converged"] == 1 and ob.attrs["converged"] == 1
    ma = np.sort_complex(oa.multiplier_real.values + 1j * oa.multiplier_imag.values)
    mb = np.sort_complex(ob.multiplier_real.values + 1j * ob.multiplier_imag.values)
    assert ma.shape == mb.shape == (2,)
    assert np.max(np.abs(ma - mb)) < 1e-10


MODEL = dict(states=("X", "V"), parameters={"k": 1.0, "c": 0.1, "F0": 1.0, "omega": 1.2},
             method="exact")


def _model(**kw):
    spec = dict(MODEL, modes={"free": ["V", "-k*X - c*V + F0*cos(omega*t) + Xa"]},
                guards={"free": [("1 - X", "free", {"V": "-0.8*V"})]})
    spec.update(kw)
    return ns.model_from_equations("memory_errors", **spec)


@pytest.mark.parametrize("kw, match", [
    (dict(memory={"Xa": 0}, guards={"free": [("1 + Xa - X", "free")]}),
     r"^model memory_errors: mode free, surface 0: the surface varies with the memory slot "
     r"'Xa', which the tangent dynamics carry"),
    (dict(memory={"Xa": 0}, guards={"free": [("1 - X", "free", {"Xb": "V"})]}),
     r"^model memory_errors: mode free, surface 0: reset of 'Xb', which is neither a state "
     r"nor a memory slot$"),
    (dict(memory={"Xa": 0}, initial=[("X > 0", "free", {"Xc": "1"})]),
     r"^model memory_errors: initial, entry 0: 'Xc' is not a memory slot \(memory: Xa\)$"),
    (dict(memory={"X": 0}), r"^model memory_errors: state, parameter and memory names must "
                            r"all differ$"),
    (dict(memory={"Xa": 0}, n_memory=1), r"^model memory_errors: give memory=\{\.\.\.\} or "
                                         r"n_memory, not both$"),
    (dict(), r"^model memory_errors: mode free, dV/dt: unknown name 'Xa'"),
    (dict(memory={"Xa": 0, "Xs": "X"}, guards={"free": [("1.5 + Xs - X", "free")]}),
     r"^model memory_errors: mode free, surface 0: the surface varies with the memory slot "
     r"'Xs', which the tangent dynamics carry"),
    (dict(memory={"Xa": 0}, admissible="X <= Xa"),
     r"^model memory_errors: admissible: a condition on the state and the parameters, "
     r"without t or memory$"),
    (dict(memory={"Xa": "Xb", "Xb": 0}),
     r"^model memory_errors: memory Xa: a start value is an expression of the state, the "
     r"parameters and t, not of memory$"),
    (dict(memory={1: 0}), r"^model memory_errors: memory: a dict \{name: value at a fresh "
                          r"start\} or a sequence of names$"),
])
def test_memory_misused_is_one_line(kw, match):
    with pytest.raises(ParameterError, match=match) as err:
        _model(**kw)
    assert "\n" not in str(err.value)
