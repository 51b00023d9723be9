"""Basins (issues 8 and 14): confirmed periodic attractors, chaotic attractors as labels, CF
result files, slices (progress, Ctrl-C), size and budget checks."""

import signal
import subprocess
import sys
import warnings

import numpy as np
import pytest

import nonsmooth as ns
from nonsmooth.analysis import basins as basins_module
from nonsmooth.analysis.basins import basins
from nonsmooth.analysis.basins.attractors import _polish
from nonsmooth.cli import main
from nonsmooth.errors import ParameterError

from cli_helpers import SAFETY_S, popen, wait_until  # noqa: E402

FIG4 = dict(x=(-4, 2), v=(-30, 30), grid=20, method="exact", max_periods=800)


@pytest.fixture(scope="module")
def fig4():
    return basins(ns.preset("fig4"), **FIG4)


def section(x0, v0, record, transient=0):
    """Section points of a long exact run (the oracle)."""
    ds = ns.poincare(ns.preset("fig4"), record=record, transient=transient, x0=x0, v0=v0,
                     method="exact")
    return ds.X.values, ds.V.values


def smallest_period(X, V, tol, max_period=16):
    for q in range(1, max_period + 1):
        if np.abs(X[q:] - X[:-q]).max() <= tol and np.abs(V[q:] - V[:-q]).max() <= tol:
            return q
    return 0


# -- issue 8 item 1: every periodic attractor is one; the chaotic basin is one label ----------
def test_fig4_periodic_attractors_are_periodic_in_a_long_run(fig4):
    ds = fig4
    tol = ds.attrs["section_tol"]
    periodic = np.flatnonzero(ds.kind.values == 0)
    assert periodic.size >= 1
    for k in periodic:
        q = int(ds.period[k])
        X, V = section(float(ds.attractor_X[k, 0]), float(ds.attractor_V[k, 0]), record=3000)
        assert smallest_period(X, V, tol) == q, f"attractor {k} of period {q} is not periodic"
        # and it stays on the reported section points
        AX = ds.attractor_X.values[k, :q]
        assert np.abs(X[q - 1::q] - AX[0]).max() <= tol


def test_fig4_chaotic_basin_is_one_chaotic_label(fig4):
    ds = fig4
    kinds = list(ds.kind.values)
    assert kinds.count(1) == 1  # one chaotic attractor, period 0, after the periodic ones
    c = kinds.index(1)
    assert int(ds.period[c]) == 0 and ds.kind.attrs["flag_meanings"] == "periodic chaotic"
    assert float(ds.undecided_fraction) == 0.0
    assert float(ds.fraction.sum()) == pytest.approx(1.0, abs=1e-12)
    assert float(ds.fraction[c]) > 0.3
    # oracle: trajectories from points of the chaotic basin (among them those once labelled
    # period 8 and 16) stay aperiodic, on the reported cloud
    idx = np.argwhere(ds.label.values == c)
    tol = ds.attrs["section_tol"]
    for i, j in idx[:: max(1, len(idx) // 4)]:
        X, V = section(float(ds.x0[i]), float(ds.v0[j]), record=400, transient=800)
        assert smallest_period(X, V, 10 * tol) == 0
    X, V = section(float(ds.attractor_X[c, 0]), float(ds.attractor_V[c, 0]), record=400)
    assert smallest_period(X, V, 10 * tol) == 0
    assert np.nanmax(ds.attractor_X.values[c]) <= float(ds.max_X[c])


def test_fig4_early_labels_equal_full_integration(fig4):
    slow = basins(ns.preset("fig4"), **FIG4, early_stop=False)
    np.testing.assert_array_equal(fig4.label.values, slow.label.values)
    np.testing.assert_array_equal(fig4.kind.values, slow.kind.values)


def test_polish_rejects_a_candidate_that_drifts_away():
    """A section point of the chaotic attractor passed off as a period-1 candidate is not
    confirmed; a point of the period-3 orbit is."""
    from nonsmooth.kernels import Solver
    p = ns.preset("fig4")
    solver = Solver(method="exact")
    X, V = section(-1.0, 5.0, record=20, transient=800)
    assert _polish(solver, p.pack(), np.array([[X[-1], V[-1]]]), 3e-4) is None


# -- issue 8 item 7: CF result files ------------------------------------------------------------
def test_dataset_is_cf_flagged_with_valid_units(fig4, tmp_path):
    import cf_xarray  # noqa: F401
    ds = ns.io.load_dataset(ns.io.save_dataset(fig4, tmp_path / "b.nc"))
    assert ds.attrs["Conventions"].startswith("CF-")
    lab = ds.label
    assert lab.cf.is_flag_variable
    assert lab.attrs["flag_meanings"].split()[0] == "undecided"
    assert len(lab.attrs["flag_meanings"].split()) == ds.sizes["attractor"] + 1
    assert "chaotic" in lab.attrs["flag_meanings"] and "period_3" in lab.attrs["flag_meanings"]
    np.testing.assert_array_equal((lab.cf == "undecided").values, lab.values == -1)
    assert ds.status.cf.is_flag_variable and (ds.status.values == 0).all()
    assert ds.kind.cf.is_flag_variable and ds.contact.cf.is_flag_variable
    for name, var in ds.variables.items():
        if "units" in var.attrs:
            assert var.attrs["units"] in ("1", "1/s", "s"), name
    assert "forcing periods" in ds.orbit_t.attrs["long_name"]
    assert ds.attractor_X.dims == ("attractor", "n") and "t_section" in ds.coords
    for name in ("undecided_fraction", "undecided_count", "failed_count"):
        assert name in ds.data_vars and name not in ds.attrs


# -- issue 14 items 4 and 5: slices (progress, Ctrl-C) change nothing ---------------------------
def test_tiny_slices_give_identical_results_and_report_progress(monkeypatch):
    p = ns.preset("fig7").replace(omega=1.18)
    ref = basins(p, grid=(12, 11))
    calls = []
    monkeypatch.setattr(ns.sweep, "SLICE_SECONDS", 1e-9)
    sliced = basins(p, grid=(12, 11), progress=lambda d, t: calls.append((d, t)))
    for v in ("label", "periods_used", "attractor_X", "attractor_V", "capture_radius"):
        np.testing.assert_array_equal(ref[v].values, sliced[v].values)
    assert ref.attrs["certification_periods"] == sliced.attrs["certification_periods"]
    assert len(calls) > 20  # one report per slice, not per round
    done = [d for d, _ in calls]
    assert done == sorted(done) and calls[-1] == (132, 132)


def test_cli_sigint_stops_a_long_basins_run(tmp_path):
    """Every trajectory of the first round runs 10^7 periods before its periodicity is tested:
    one compiled call per round ignored SIGINT for minutes. Now the run stops, exit 130, and
    the old file is untouched (how fast: ``benchmarks/bench_interrupt.py``)."""
    cmd = [sys.executable, "-m", "nonsmooth.cli", "basins", "--preset", "fig7", "--method",
           "exact"]
    out = tmp_path / "a.nc"
    out.write_text("old result")
    proc = popen(cmd + ["--grid", "300", "--transient", "10000000", "--max-periods",
                        "10000000", "-o", str(out)],
                 stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    # computing: the chunk store exists once the first round has started
    wait_until(proc, lambda: (tmp_path / "a.nc.chunks" / "manifest.json").exists(),
               "the chunk store")
    proc.send_signal(signal.SIGINT)
    try:
        _, err = proc.communicate(timeout=SAFETY_S)
    finally:
        proc.kill()
    assert proc.returncode == 130, err
    assert "Traceback" not in err
    assert err.strip().splitlines()[-1].startswith("interrupted")
    assert out.read_text() == "old result"


# -- issue 14 items 6, 7, 11: checks before the wait -----------------------------------------
def test_grid_larger_than_memory_is_refused_in_one_line(capsys, tmp_path):
    with pytest.raises(ParameterError, match="^grid: .*GiB"):
        basins(ns.preset("fig7"), grid=100000)
    with pytest.raises(SystemExit) as exc:
        main(["basins", "--grid", "100000", "-o", str(tmp_path / "a.nc")])
    assert exc.value.code == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and err.startswith("error: grid:") and "smaller" in err


def test_cli_unknown_orbits_plot_format_fails_before_computing(tmp_path, capsys):
    out = tmp_path / "b.nc"
    with pytest.raises(SystemExit) as exc:
        main(["basins", "--grid", "4", "-o", str(out), "--orbits-plot", str(tmp_path / "o.xyz")])
    assert exc.value.code == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "orbits-plot" in err and "xyz" in err
    assert not out.exists()


def test_too_small_budget_warns_and_the_cli_says_it(tmp_path, capsys):
    with pytest.warns(UserWarning, match="max_periods=5.*raise max_periods"):
        ds = basins(ns.preset("fig7"), grid=4, max_periods=5)
    assert ds.sizes["attractor"] == 0 and float(ds.undecided_fraction) == 1.0
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        basins(ns.preset("fig7"), grid=4)  # enough budget: no warning
    with pytest.raises(SystemExit) as exc:
        main(["basins", "--grid", "4", "--max-periods", "5", "-o", str(tmp_path / "b.nc")])
    assert exc.value.code in (0, None)
    assert "raise max_periods" in capsys.readouterr().out


# -- the certificates stand on one model property ---------------------------------------------
def test_without_the_homeomorphism_property_no_certificate_is_used(monkeypatch):
    p = ns.preset("fig7").replace(omega=1.18)
    slow = basins(p, grid=(6, 5), early_stop=False)
    monkeypatch.setattr(basins_module, "MAP_IS_HOMEOMORPHISM", False)
    ds = basins(p, grid=(6, 5))
    np.testing.assert_array_equal(ds.label.values, slow.label.values)
    np.testing.assert_array_equal(ds.periods_used.values, slow.periods_used.values)
    assert (ds.capture_radius.fillna(0).values == 0).all()


def test_attractors_that_share_their_x_and_v_are_told_apart_by_the_other_components():
    """Issue 23, item 2: a forced oscillator (X, V) beside a damped double well Z'' = -0.5 Z'
    + Z - Z^3 that X and V do not see: two attractors with the same (X, V) section points,
    Z = +1 and Z = -1. ``basins`` on (Z, W) finds both, and labels each start by the well
    an independent solution of the double well (scipy) ends in (a grid without the saddle
    Z = W = 0, where a start would stay)."""
    from scipy.integrate import solve_ivp
    m = ns.model_from_equations(
        "oscillator_and_double_well", states=("X", "V", "Z", "W"),
        parameters={"F0": 0.5, "omega": 1.0},
        modes={"free": ["V", "-0.2*V - X + F0*cos(omega*t)", "W", "-0.5*W + Z - Z**3"]},
        method="smooth", closed_form=False)
    ds = ns.basins(m.params(), axes=("Z", "W"), x=(-1.5, 1.5), v=(-1.5, 1.5), grid=4,
                   max_periods=400)
    assert ds.sizes["attractor"] == 2 and float(ds.undecided_fraction) == 0.0
    zs = [float(ds.attractor_Z[k, 0]) for k in range(2)]  # each attractor's Z on the section
    assert sorted(np.round(zs, 6)) == [-1.0, 1.0]
    assert np.allclose(ds.attractor_X[0].values, ds.attractor_X[1].values, atol=1e-6)
    for i, z0 in enumerate(ds.x0.values):
        for j, w0 in enumerate(ds.v0.values):
            sol = solve_ivp(lambda t, y: [y[1], -0.5 * y[1] + y[0] - y[0]**3], (0, 200),
                            [z0, w0], rtol=1e-10, atol=1e-12)
            assert zs[int(ds.label[i, j])] == pytest.approx(np.sign(sol.y[0, -1]), abs=1e-6)
