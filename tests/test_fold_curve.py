"""Folds continued in two parameters as one extended system (``ns.fold_curve``, issue 21
item 4): on the cusp normal form X' = a + b X - X^3 (with a decoupled, forced V' = -V +
cos t, whose multiplier is e^(-T)) the time-T map
has its folds exactly where the equilibria fold, a = -2 X^3, b = 3 X^2; the curve runs through
the cusp at (0, 0), where the two folds meet, and the cusp is located there."""

import numpy as np
import pytest
import xarray as xr

import nonsmooth as ns
from nonsmooth.errors import ParameterError

pytestmark = pytest.mark.filterwarnings("ignore::numba.NumbaExperimentalFeatureWarning")


@pytest.fixture(scope="module")
def setup():
    m = ns.model_from_equations(
        "cusp_normal_form", states=("X", "V"), parameters={"a": 0.3, "b": 1.0, "omega": 1.0},
        modes={"free": ["a + b*X - X**3", "-V + cos(omega*t)"]}, method="smooth",
        forcing_amplitude=None)
    p = m.params(a=0.3, b=1.0)
    br = ns.continuation(p, "a", x0=-0.8, bounds=(0.3, 0.5), method="smooth", step=0.02)
    return p, br


def test_the_fold_curve_of_the_cusp_normal_form_runs_through_the_cusp(setup):
    p, br = setup
    assert br.special_type.values.tolist() == [1]  # one fold, at 2 (1/3)^(3/2)
    assert float(br.special_a[0]) == pytest.approx(2 * 3 ** -1.5, abs=1e-8)
    fc = ns.fold_curve(p, "a", "b", start=br, direction="down", step=0.02,
                       bounds=(-1.0, 1.0), bounds2=(-0.5, 1.5))
    X, a, b = fc.X_section.values, fc.a.values, fc.b.values
    np.testing.assert_allclose(a, -2 * X ** 3, atol=1e-9)
    np.testing.assert_allclose(b, 3 * X ** 2, atol=1e-9)
    np.testing.assert_allclose(fc.V_section.values, 0.5, atol=1e-8)  # V = (cos t + sin t)/2
    # a multiplier 1 all along (the X direction), the other e^(-T)
    mu = np.sort(fc.multiplier_abs.values, axis=1)
    np.testing.assert_allclose(mu[:, 1], 1.0, atol=1e-7)
    np.testing.assert_allclose(mu[:, 0], np.exp(-2 * np.pi), rtol=1e-6)
    # through the cusp onto the other fold: X from -1/sqrt(3) to positive, a changes sign
    assert X[0] == pytest.approx(-3 ** -0.5, abs=1e-8) and X[-1] > 0.5 and a[-1] < -0.3
    assert fc.attrs["status"] == "left the bounds of b"
    assert fc.sizes["cusp"] == 1
    assert abs(float(fc.cusp_a[0])) < 1e-4 and abs(float(fc.cusp_b[0])) < 2e-3
    assert fc.attrs["analysis"] == "fold_curve" and "param_a" not in fc.attrs


def test_fold_curve_bad_input(setup):
    p, br = setup
    with pytest.raises(ParameterError, match="param2: must differ"):
        ns.fold_curve(p, "a", "a", start=br)
    with pytest.raises(ParameterError, match="start:"):
        ns.fold_curve(p, "a", "b", start=xr.Dataset())
    with pytest.raises(ParameterError, match="special:"):
        ns.fold_curve(p, "a", "b", start=br, special=3)
    with pytest.raises(ParameterError, match="start:"):
        ns.fold_curve(p, "b", "a", start=br)  # a branch in a, not in b
