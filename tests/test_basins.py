"""Basins of attraction: fractions, known labels, linear oracle, determinism, CLI errors."""

import subprocess
import sys

import numpy as np
import pytest

import nonsmooth as ns
from nonsmooth.analysis.basins import basins
from nonsmooth.cli import main
from nonsmooth.errors import ParameterError
from nonsmooth.status import OK

GRID = (13, 13)  # on [-3, 3]^2: contains (0, 0) and the corners


def fig7(omega):
    return ns.preset("fig7").replace(omega=omega)


@pytest.fixture(scope="module")
def fig7_110():
    return basins(fig7(1.10), grid=GRID)


def settled_point(params, x0, v0, method="smooth", transient=400):
    """Section point after a long direct simulation (the oracle the labels are checked with)."""
    ds = ns.simulate(params, periods=1, transient=transient, samples_per_period=1, x0=x0, v0=v0,
                     method=method)
    return float(ds.X[0]), float(ds.V[0])


def attractor_of(ds, point, tol=1e-4):
    """Label of the attractor whose section points contain ``point`` (None if none)."""
    for k in range(ds.sizes["attractor"]):
        d = np.hypot(ds.attractor_X.values[k] - point[0], ds.attractor_V.values[k] - point[1])
        if np.nanmin(d) < tol:
            return k
    return None


def test_fractions_sum_to_one(fig7_110):
    ds = fig7_110
    total = float(ds.fraction.sum()) + float(ds.undecided_fraction)
    assert total == pytest.approx(1.0, abs=1e-12)
    n = GRID[0] * GRID[1]
    assert int(ds["count"].sum()) + int(ds.undecided_count) == n
    for k in range(ds.sizes["attractor"]):
        assert ds.fraction[k] == pytest.approx(np.count_nonzero(ds.label.values == k) / n)


def test_fig7_two_coexisting_period1_attractors_with_and_without_contact(fig7_110):
    ds = fig7_110
    assert ds.sizes["attractor"] == 2
    assert list(ds.period.values) == [1, 1]
    assert list(ds.contact.values) == [0, 1]  # canonical order: no contact first
    assert ds.max_X[0] < 1.0 <= ds.max_X[1]
    assert float(ds.undecided_fraction) == 0.0
    assert (ds.fraction > 0.1).all()


@pytest.mark.parametrize("ic", [(0.0, 0.0), (-3.0, 3.0), (3.0, -3.0), (1.5, -1.0)])
def test_known_initial_conditions_get_the_attractor_of_a_long_simulation(fig7_110, ic):
    ds = fig7_110
    expected = attractor_of(ds, settled_point(fig7(1.10), *ic))
    assert expected is not None
    assert int(ds.label.sel(x0=ic[0], v0=ic[1])) == expected


def test_origin_goes_to_the_attractor_without_contact(fig7_110):
    assert int(fig7_110.label.sel(x0=0.0, v0=0.0)) == 0


def test_early_stop_gives_the_same_labels_as_full_integration():
    p = fig7(1.18)
    fast = basins(p, grid=(12, 11))
    slow = basins(p, grid=(12, 11), early_stop=False)
    np.testing.assert_array_equal(fast.label.values, slow.label.values)
    np.testing.assert_allclose(fast.attractor_X.values, slow.attractor_X.values, atol=1e-4)
    # the lever: far fewer periods per point
    assert fast.periods_used.mean() < 0.5 * slow.periods_used.mean()
    assert (fast.capture_radius.values > 0).all()


def test_linear_case_single_attractor_at_the_analytic_fixed_point():
    p = fig7(1.10).replace(F0=0.02)
    ds = basins(p, grid=(10, 10), x=(-2, 2), v=(-2, 2))
    assert ds.sizes["attractor"] == 1
    assert int(ds.period[0]) == 1 and int(ds.contact[0]) == 0
    assert float(ds.fraction[0]) == 1.0 and float(ds.undecided_fraction) == 0.0
    w, w0, xi, F0 = p.omega, p.omega0, p.xi, p.F0
    den = (w0**2 - w**2) ** 2 + (xi * w) ** 2
    X_ss, V_ss = F0 * (w0**2 - w**2) / den, F0 * xi * w / den * w
    assert float(ds.attractor_X[0, 0]) == pytest.approx(X_ss, abs=1e-5)
    assert float(ds.attractor_V[0, 0]) == pytest.approx(V_ss, abs=1e-5)
    # the orbit sample covers one period and closes on itself
    ox = ds.orbit_X.values[0]
    assert ox[-1] == pytest.approx(ox[0], abs=1e-5)
    assert np.nanmax(ox) == pytest.approx(float(ds.max_X[0]), abs=1e-3)


def test_identical_results_with_one_and_two_workers():
    p = fig7(1.18)
    a = basins(p, grid=(11, 12), workers=1)
    b = basins(p, grid=(11, 12), workers=2)
    np.testing.assert_array_equal(a.label.values, b.label.values)
    np.testing.assert_array_equal(a.periods_used.values, b.periods_used.values)
    np.testing.assert_array_equal(a.attractor_X.values, b.attractor_X.values)
    np.testing.assert_array_equal(a.capture_radius.values, b.capture_radius.values)


def exact_works():
    p = fig7(1.10)
    from nonsmooth.kernels import Solver, advance, new_state, output_buffers
    s = Solver(method="exact")
    return advance(s.code, p.pack(), s.opts(), new_state(0.0, 0.0), 1, 0, 1,
                   *output_buffers(1)) == OK


@pytest.mark.skipif(not exact_works(), reason="exact solver not available")
def test_exact_method_finds_the_same_attractors(fig7_110):
    ex = basins(fig7(1.10), grid=GRID, method="exact")
    assert list(ex.period.values) == list(fig7_110.period.values)
    assert list(ex.contact.values) == list(fig7_110.contact.values)
    np.testing.assert_allclose(ex.attractor_X.values, fig7_110.attractor_X.values, atol=1e-3)
    assert np.mean(ex.label.values == fig7_110.label.values) >= 0.95
    assert ex.attrs["method"] == "exact"


@pytest.mark.skipif(not exact_works(), reason="exact solver not available")
def test_certified_lattice_cells_keep_labels_and_determinism():
    """Grid >= 64: the lattice-cell lever is active; labels still equal full integration and do
    not depend on the number of workers."""
    p = fig7(1.18)
    fast = basins(p, grid=64, method="exact", workers=2)
    assert fast.attrs["certified_cells"] > 0
    one = basins(p, grid=64, method="exact", workers=1)
    np.testing.assert_array_equal(fast.label.values, one.label.values)
    np.testing.assert_array_equal(fast.periods_used.values, one.periods_used.values)
    slow = basins(p, grid=64, method="exact", early_stop=False)
    np.testing.assert_array_equal(fast.label.values, slow.label.values)
    assert fast.periods_used.mean() < 0.2 * slow.periods_used.mean()
    # the same grid with the axes swapped runs with every component: balls in the whole state
    # space (here a circle sampled by a square's boundary, margin its longest image edge)
    swap = basins(p, grid=64, method="exact", axes=("V", "X"))
    np.testing.assert_array_equal(swap.label.values, fast.label.values.T)
    assert swap.attrs["certified_cells"] > 0 and (swap.capture_radius > 0).all()
    assert swap.periods_used.mean() < 0.2 * slow.periods_used.mean()


def test_the_sampled_sphere_of_a_ball_is_covered_by_its_edges():
    """The samples of S^(n-1) (the cube's boundary grid) and their neighbour edges: every
    direction lies nearer a sample than the longest edge (so the margin of a ball's image,
    its longest image edge, covers the points between the samples, to first order)."""
    from nonsmooth.analysis.basins.certify import _BALL_K, _CELL_K, sphere
    rng = np.random.default_rng(1)
    for n, k in list(_BALL_K.items()) + list(_CELL_K.items()):
        W, E = sphere(n, k)
        assert len(W) == (k + 1) ** n - (k - 1) ** n
        np.testing.assert_allclose(np.linalg.norm(W, axis=1), 1.0, rtol=1e-15)
        assert set(np.unique(E)) == set(range(len(W)))  # every sample has neighbours
        edge = np.linalg.norm(W[E[:, 0]] - W[E[:, 1]], axis=1).max()
        d = rng.normal(size=(20000, n))
        d /= np.linalg.norm(d, axis=1)[:, None]
        near = np.sqrt(np.maximum(0, 2 - 2 * (d @ W.T).max(axis=1))).max()
        assert near < 0.75 * edge, (n, k, near, edge)


@pytest.mark.parametrize("kwargs, field", [
    (dict(x=(3, -3)), "x"),
    (dict(v=(1, 1)), "v"),
    (dict(x=(float("nan"), 1)), "x min"),
    (dict(v=(0, float("inf"))), "v max"),
    (dict(grid=1), "grid"),
    (dict(grid=(5, 1)), "grid nv"),
    (dict(grid=(5, 5, 5)), "grid"),
    (dict(max_periods=0), "max_periods"),
    (dict(method="rk4"), "method"),
])
def test_bad_input_names_the_field(kwargs, field):
    with pytest.raises(ParameterError, match=f"^{field}"):
        basins(fig7(1.10), **kwargs)


def test_cli_writes_dataset_and_figures(tmp_path, capsys):
    out, png, orb = tmp_path / "b.nc", tmp_path / "b.png", tmp_path / "o.png"
    with pytest.raises(SystemExit) as exc:
        main(["basins", "--preset", "fig7", "--set", "omega=1.18", "--grid", "8", "--x", "-2", "2",
              "--v", "-2", "2", "-o", str(out), "--plot", str(png), "--orbits-plot", str(orb),
              "--workers", "1"])
    assert exc.value.code in (0, None)
    assert png.stat().st_size > 0 and orb.stat().st_size > 0
    ds = ns.io.load_dataset(out)
    assert ds.label.shape == (8, 8)
    assert ds.attrs["param_omega"] == 1.18 and ds.attrs["preset"] == "fig7"
    assert ds.attrs["analysis"] == "basins" and ds.attrs["x_min"] == -2.0
    assert "2 attractor(s)" in capsys.readouterr().out


@pytest.mark.parametrize("args, field", [
    (["--x", "3", "-3"], "x:"),
    (["--v", "1", "1"], "v:"),
    (["--grid", "1"], "grid:"),
    (["--x", "nan", "1"], "x min:"),
    (["--set", "omega=-1"], "omega:"),
])
def test_cli_bad_input_one_line_exit_2(args, field, tmp_path, capsys):
    with pytest.raises(SystemExit) as exc:
        main(["basins", "--preset", "fig7", *args, "-o", str(tmp_path / "b.nc")])
    assert exc.value.code == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and field in err and "Traceback" not in err


def test_cli_bad_input_in_a_real_process(tmp_path):
    r = subprocess.run([sys.executable, "-c", "from nonsmooth.cli import main; main()", "basins",
                        "--x", "2", "-2", "-o", str(tmp_path / "b.nc")],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 2
    assert "Traceback" not in r.stderr
    assert len(r.stderr.strip().splitlines()) == 1 and r.stderr.startswith("error: x:")
