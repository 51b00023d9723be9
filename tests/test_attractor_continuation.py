"""Attractors followed across a parameter (``ns.attractor_continuation``, issue 21 item 3):
along the paper's Fig. 6a / 7 path in omega, two attractors coexist exactly between the two
folds that ``continuation`` finds, each keeps its label from birth to death, and the basin
shares at a value are those of ``basins`` there."""

import math

import numpy as np
import pytest
import xarray as xr

import nonsmooth as ns
from nonsmooth.errors import ParameterError

from cli_helpers import one_line, run_cli

pytestmark = pytest.mark.filterwarnings("ignore::numba.NumbaExperimentalFeatureWarning")

VALUES = np.linspace(1.0, 1.25, 11)


@pytest.fixture(scope="module")
def path():
    return ns.attractor_continuation(ns.preset("fig7"), "omega", VALUES, grid=30,
                                     method="exact")


@pytest.fixture(scope="module")
def folds():
    c = ns.continuation(ns.preset("fig6a").replace(omega=0.5), "omega", bounds=(0.5, 1.6),
                        method="exact")
    w = np.sort(c.special_omega.values[c.special_type.values == 1])  # type 1: fold
    assert w.size == 2
    return w


def test_two_attractors_exactly_between_the_folds(path, folds):
    lo, hi = folds  # omega_b ~ 1.0551, omega_c ~ 1.1930
    expected = 1 + ((VALUES > lo) & (VALUES < hi))
    assert path.n_attractors.values.tolist() == expected.tolist()
    assert path.sizes["attractor"] == 2
    # the contact orbit exists from the start and dies past the upper fold; the orbit without
    # contact is born past the lower fold and lives to the end
    contact = int(np.flatnonzero(path.contact.values[0] == 1)[0])
    other = 1 - contact
    assert math.isnan(float(path.born[contact]))
    assert float(path.died[contact]) == VALUES[np.searchsorted(VALUES, hi)]
    assert float(path.born[other]) == VALUES[np.searchsorted(VALUES, lo)]
    assert math.isnan(float(path.died[other]))
    # each label is one orbit: its largest X moves smoothly (no jump between the branches)
    for a in (contact, other):
        mx = path.max_X.values[:, a]
        assert np.nanmax(np.abs(np.diff(mx[np.isfinite(mx)]))) < 0.2
    assert (path.contact.values[:, contact][path.exists.values[:, contact] == 1] == 1).all()
    assert (path.period.values[path.exists.values == 1] == 1).all()
    np.testing.assert_allclose(path.fraction.sum("attractor") + path.undecided_fraction, 1.0)


def test_shares_are_those_of_basins_at_the_value(path):
    i = 4  # omega = 1.1: Fig. 7a
    b = ns.basins(ns.preset("fig7").replace(omega=float(VALUES[i])), grid=30, method="exact",
                  lyapunov=False)
    got = np.sort(path.fraction.values[i][path.exists.values[i] == 1])
    np.testing.assert_array_equal(got, np.sort(b.fraction.values))
    assert path.attrs["analysis"] == "attractor_continuation"
    assert "param_omega" not in path.attrs and path.omega.attrs["units"]


def test_cli_attractors(tmp_path, capsys):
    out, fig = tmp_path / "a.nc", tmp_path / "a.png"
    code, text, err = run_cli(["attractors", "--method", "exact", "--grid", "20", "--from",
                               "1.05", "--to", "1.2", "--steps", "4", "-o", str(out),
                               "--plot", str(fig)], capsys)
    assert code == 0, err
    assert "A0: period 1" in text and fig.is_file()
    with xr.open_dataset(out) as ds:
        assert ds.sizes["omega"] == 4 and ds.attrs["preset"] == "fig7"


@pytest.mark.parametrize("args, field", [
    (["--param", "nope"], "nope"),
    (["--from", "1.2", "--to", "1.1"], "from/to"),
    (["--steps", "1"], "steps"),
    (["--grid", "1"], "grid"),
    (["--match-tol", "-1"], "match_tol"),
])
def test_cli_attractors_bad_input_is_one_line(args, field, tmp_path, capsys):
    code, _, err = run_cli(["attractors", "--steps", "3", *args, "-o", str(tmp_path / "a.nc")],
                           capsys)
    assert code == 2
    one_line(err, field)


def test_bad_values():
    p = ns.preset("fig7")
    for vals, needle in (([1.1], "at least two"), ([1.1, 1.0, 1.2], "increase or decrease"),
                         ([1.0, float("nan")], "finite")):
        with pytest.raises(ParameterError, match=needle):
            ns.attractor_continuation(p, "omega", vals, grid=4)
    with pytest.raises(ParameterError, match="lyapunov"):
        ns.attractor_continuation(p, "omega", [1.0, 1.1], grid=4, lyapunov=True)
