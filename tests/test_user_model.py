"""A user's model from a script (examples/one_sided_duffing.py): the generic kernel against an
independent scipy reference, and malformed models failing at definition with one line."""

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import nonsmooth as ns
from nonsmooth.models import Method, Model

EXAMPLE = str(Path(__file__).resolve().parents[1] / "examples" / "one_sided_duffing.py")


@pytest.fixture(scope="module")
def duffing():
    return ns.model(f"{EXAMPLE}:MODEL")


def _reference(p, periods, x0=0.0, v0=0.0):
    """X(kT), V(kT), k = 0..periods, and the number of contacts: scipy DOP853 with located
    events (rtol 1e-12), the same free / contact / free-above-the-gap logic as the model."""
    xi, beta, F0, w, gap, ks, cs = (p.xi, p.beta, p.F0, p.omega, p.gap, p.k_s, p.c_s)
    T = 2 * math.pi / w

    def rhs(contact):
        def f(t, y):
            X, V = y
            a = -xi * V - X - beta * X ** 3 + F0 * math.cos(w * t)
            if contact:
                a -= ks * (X - gap) + cs * V
            return [V, a]
        return f

    def event(fn, direction):
        fn.terminal = True
        fn.direction = direction
        return fn

    reach = event(lambda t, y: y[0] - gap, 1.0)  # free below: X rises to the gap
    release = event(lambda t, y: ks * (y[0] - gap) + cs * y[1], -1.0)  # force falls to 0
    press = event(lambda t, y: ks * (y[0] - gap) + cs * y[1], 1.0)  # free above: force > 0
    below = event(lambda t, y: y[0] - gap, -1.0)  # free above: back below the gap
    mode, above, contacts = "free", False, 0
    t, y = 0.0, np.array([x0, v0])
    out = [y.copy()]
    for k in range(1, periods + 1):
        t_end = k * T
        while t < t_end:
            events = ([release] if mode == "contact" else [press, below] if above else [reach])
            sol = solve_ivp(rhs(mode == "contact"), (t, t_end), y, method="DOP853",
                            rtol=1e-12, atol=1e-14, events=events)
            if sol.status != 1:
                t, y = t_end, sol.y[:, -1]
                continue
            i = next(j for j, te in enumerate(sol.t_events) if len(te))
            t, y = sol.t_events[i][0], sol.y_events[i][0]
            if mode == "contact":
                mode, above = "free", y[0] > gap
            elif above:
                mode, above = ("contact", False) if i == 0 else ("free", False)
            else:
                mode = "contact"
            contacts += mode == "contact"
        out.append(y.copy())
    return np.array(out), contacts


def test_example_model_matches_scipy_with_events(duffing):
    p = duffing.params()
    ref, contacts = _reference(p, 10)
    assert contacts >= 5  # several contacts in 10 periods
    ds = ns.simulate(p, periods=10, samples_per_period=1, method="exact")
    got = np.stack([ds.X.values, ds.V.values], axis=1)
    np.testing.assert_allclose(got, ref, rtol=0, atol=1e-7)
    assert int(ds.regions_visited) == 0b11  # free and contact


def test_example_smooth_method_tends_to_exact(duffing):
    p = duffing.params(eta=1e-4)
    a = ns.simulate(p, periods=5, samples_per_period=1, method="smooth", rtol=1e-10,
                    atol=1e-12)
    b = ns.simulate(p, periods=5, samples_per_period=1, method="exact")
    assert np.max(np.abs(a.X.values - b.X.values)) < 1e-2


def test_example_model_runs_every_analysis(duffing):
    p = duffing.params()
    sec = ns.poincare(p, record=10, transient=100, method="exact")
    assert int(sec.period) == 1 and int(sec.contact) == 1
    bd = ns.bifurcation_diagram(p, "F0", [0.8, 1.0], transient=50, record=10, method="exact",
                                workers=1)
    assert np.all(bd.status.values == 0)


# ---- malformed models: one ParameterError at definition, naming the problem --------------------
def _one_line(exc_info):
    msg = str(exc_info.value)
    assert "\n" not in msg, msg
    return msg


def _with(duffing, method="exact", **parts):
    """The example model with some functions of ``method`` replaced (a fresh Model)."""
    m = dataclasses.replace(duffing.methods[method], **parts)
    return dataclasses.replace(duffing, name="bad", methods={method: m})


def test_wrong_state_dimension_fails_at_construction(duffing):
    with pytest.raises(ns.ParameterError) as exc:
        dataclasses.replace(duffing, state_names=("X",))
    assert "n >= 2" in _one_line(exc)


def test_missing_jacobian_fails_at_construction(duffing):
    with pytest.raises(ns.ParameterError) as exc:
        _with(duffing, jacobian=None)
    assert "jacobian is missing" in _one_line(exc)


def wrong_jacobian(mode, t, c, s, u, p, mem, J):
    J[0, 0] = 0.0
    J[0, 1] = 1.0
    J[1, 0] = -1.0  # the cubic term's -3 beta X^2 and the support are missing
    J[1, 1] = -p[0]
    return 0


def test_wrong_jacobian_is_caught_by_the_sample_check(duffing):
    with pytest.raises(ns.ParameterError) as exc:
        _with(duffing, jacobian=wrong_jacobian).fns("exact")
    msg = _one_line(exc)
    assert "exact.jacobian disagrees with the field" in msg and "J[1,0]" in msg


@pytest.mark.parametrize("slots, words", [((0, 0), "names a slot twice"),
                                           ((1,), "names slots outside 0..0")])
def test_continuous_memory_names_each_slot_once_and_inside(duffing, slots, words):
    """A repeated slot would give the tangent kernel more memory columns than slots."""
    with pytest.raises(ns.ParameterError) as exc:
        _with(duffing, continuous_memory=slots).fns("exact")
    assert f"exact.continuous_memory {slots} {words}" in _one_line(exc)


def _python_only(x):  # not numba.njit: numba cannot call it from a compiled function
    return {"a": x}["a"]


def uncompilable_field(mode, t, c, s, u, p, mem, du):
    du[0] = u[1]
    du[1] = _python_only(u[0])
    return 0


def test_function_numba_cannot_compile(duffing):
    with pytest.raises(ns.ParameterError) as exc:
        _with(duffing, field=uncompilable_field).fns("exact")
    msg = _one_line(exc)
    assert "exact.field (uncompilable_field) does not compile with numba" in msg


BAD_TRANSITION = '''
import dataclasses
import nonsmooth as ns

ex = ns.model({example!r})


def transition_to_nowhere(mode, k, t, c, s, u, p, mem):
    return 7


MODEL = dataclasses.replace(ex, name="nowhere", methods={{
    "exact": dataclasses.replace(ex.methods["exact"], transition=transition_to_nowhere)}})
'''


def test_transition_to_unknown_mode_fails_when_the_script_loads(tmp_path):
    script = tmp_path / "nowhere.py"
    script.write_text(BAD_TRANSITION.format(example=f"{EXAMPLE}:MODEL"))
    with pytest.raises(ns.ParameterError) as exc:
        ns.model(f"{script}:MODEL")
    msg = _one_line(exc)
    assert "exact.transition" in msg and "unknown mode 7" in msg


def test_unknown_mode_in_modes_fails_at_construction(duffing):
    with pytest.raises(ns.ParameterError) as exc:
        _with(duffing, modes=(0, 2))
    assert "mode 2 is not one of the 2 modes" in _one_line(exc)


def test_a_user_model_is_a_model():
    m = ns.model(f"{EXAMPLE}:MODEL")
    assert isinstance(m, Model) and isinstance(m.methods["exact"], Method)
    assert m is ns.model(EXAMPLE)  # NAME defaults to MODEL; loaded once
    assert m.source.endswith("one_sided_duffing.py:MODEL")


def test_a_copied_folder_with_its_numba_cache_loads(tmp_path):
    """numba's in-tree cache (``__pycache__`` beside the file, where NUMBA_CACHE_DIR is unset)
    names the module it was compiled for, and user models were loaded under a name made of
    their path: a folder copied with its cache failed with "No module named
    nonsmooth_user_model_<old path>". A user file's numba functions are now cached under a
    name made of its contents, in the package's cache. Fresh processes, as a user copying a
    project would run them."""
    import os
    import shutil
    import subprocess
    import sys

    from nonsmooth._numba_cache import cache_base
    a, b = tmp_path / "a", tmp_path / "b"
    a.mkdir()
    shutil.copy(EXAMPLE, a / "one_sided_duffing.py")
    # NUMBA_CACHE_DIR unset (numba's own choice would be __pycache__ beside the file); the
    # package's cache then lies in XDG_CACHE_HOME/nonsmooth/numba: this run's, for speed
    xdg = tmp_path / "xdg"
    (xdg / "nonsmooth").mkdir(parents=True)
    (xdg / "nonsmooth" / "numba").symlink_to(cache_base(), target_is_directory=True)
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    env["XDG_CACHE_HOME"] = str(xdg)
    code = ("import nonsmooth as ns; m = ns.model({!r}); "
            "print(repr(float(ns.simulate(m.params(), periods=3, method='exact').X[-1])))")
    outs = []
    for folder in (a, b):
        if folder is b:
            shutil.copytree(a, b)  # with whatever cache lies beside the file
        r = subprocess.run([sys.executable, "-c", code.format(
            f"{folder / 'one_sided_duffing.py'}:MODEL")], env=env, capture_output=True,
            text=True)
        assert r.returncode == 0, r.stderr.strip().splitlines()[-1]
        outs.append(r.stdout.strip())
    assert outs[0] == outs[1] and float(outs[0]) == float(outs[0])
    assert not list(tmp_path.rglob("one_sided_duffing*.nbi"))  # none beside the file
    assert list((cache_base() / "user").glob("nonsmooth_user_model_one_sided_duffing_py_*/"
                                             "one_sided_duffing*.nbi"))
