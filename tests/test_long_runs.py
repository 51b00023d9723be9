"""Issue 14 items 4-6, 8 and issue 8 items 3, 8: Ctrl-C inside one trajectory and inside one
value of a sweep, progress within a run, memory check before computing, what the summaries say,
true extrema from simulate, provenance of the integrator."""

import os
import signal
import subprocess
import sys

import numpy as np
import pytest

import nonsmooth as ns
import nonsmooth.sweep as sweep
from nonsmooth.analysis.bifurcation import bifurcation_diagram
from nonsmooth.analysis.eta_study import eta_study
from nonsmooth.analysis.poincare import poincare

from cli_helpers import SAFETY_S, popen, wait_until


def _cli(*args, cwd=None, env=None):
    return subprocess.run([sys.executable, "-m", "nonsmooth.cli", *args], capture_output=True,
                          text=True, cwd=cwd, timeout=300, env=env)


@pytest.mark.parametrize("argv", [
    ["simulate", "--transient", "1000000000", "--periods", "1"],
    ["bifurcation", "--steps", "40", "--transient", "1000000000"],
])
def test_ctrl_c_stops_a_single_long_computation(argv, tmp_path):
    """Ctrl-C inside one compiled trajectory: exit 130, the one line, the old file untouched
    (how fast it stops is measured by ``benchmarks/bench_interrupt.py``)."""
    out = tmp_path / "a.nc"
    out.write_bytes(b"previous result")
    err = tmp_path / "err.txt"
    env = dict(os.environ, NONSMOOTH_PROGRESS="1")
    with open(err, "w") as fe:
        proc = popen([sys.executable, "-m", "nonsmooth.cli", *argv, "-o", str(out)],
                     stdout=subprocess.DEVNULL, stderr=fe, env=env, cwd=tmp_path)
        wait_until(proc, lambda: "% of" in err.read_text(), "a progress line")
        proc.send_signal(signal.SIGINT)
        code = proc.wait(timeout=SAFETY_S)
    text = err.read_text()
    assert code == 130, text
    assert "Traceback" not in text
    assert text.strip().splitlines()[-1].startswith("interrupted")
    assert out.read_bytes() == b"previous result"


def test_results_do_not_depend_on_the_time_slices(monkeypatch):
    p = ns.preset("table3")
    kw = dict(sweep="both", transient=200, record=30)
    vals = np.linspace(0.88, 0.93, 5)
    a = bifurcation_diagram(p, "omega", vals, **kw)
    s = ns.simulate(p.replace(omega=0.92), periods=3, transient=50)
    monkeypatch.setattr(sweep, "SLICE_SECONDS", 1e-9)  # every call one settle window / period
    b = bifurcation_diagram(p, "omega", vals, **kw)
    t = ns.simulate(p.replace(omega=0.92), periods=3, transient=50)
    np.testing.assert_array_equal(a.X.values, b.X.values)
    np.testing.assert_array_equal(a.transient_used.values, b.transient_used.values)
    np.testing.assert_array_equal(s.X.values, t.X.values)


def test_progress_is_reported_within_one_trajectory(monkeypatch):
    monkeypatch.setattr(sweep, "SLICE_SECONDS", 1e-9)
    calls = []
    ns.simulate(ns.preset("table3"), periods=2, transient=300, progress=lambda d, t: calls.append((d, t)))
    assert len(calls) > 5 and calls[-1] == (302, 302)
    assert all(0 < d <= t for d, t in calls) and calls == sorted(calls)
    calls.clear()
    poincare(ns.preset("table3"), record=10, transient=300, progress=lambda d, t: calls.append(d))
    assert len(calls) > 3
    calls.clear()
    bifurcation_diagram(ns.preset("table3"), "omega", [0.9, 0.91], sweep="up", transient=300,
                        record=5, settle=False, progress=lambda d, t: calls.append((d, t)))
    # 2 values x 305 periods, plus the estimate of the classification after the sweep (its
    # lambda1), reported done when it ends
    assert len(calls) > 3 and calls[-1][0] == calls[-1][1] > 610
    assert calls == sorted(calls) and len({t for _, t in calls}) == 1


@pytest.mark.parametrize("argv, field", [
    (["simulate", "--periods", "1000000000"], "periods"),
    (["poincare", "--record", "100000000000"], "record"),
    (["bifurcation", "--steps", "1000000", "--record", "1000000"], "record"),
])
def test_requests_larger_than_memory_are_refused_before_computing(argv, field, tmp_path):
    r = _cli(*argv, "-o", str(tmp_path / "a.nc"))
    assert r.returncode == 2, r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and f"{field}:" in lines[0] and "available" in lines[0]
    assert "Traceback" not in r.stderr and not (tmp_path / "a.nc").exists()


def test_simulate_reports_the_regions_the_trajectory_visited_and_true_extrema(tmp_path):
    r = _cli("simulate", "--preset", "table1", "--periods", "5", "--transient", "20",
             "-o", str(tmp_path / "t1.nc"))
    assert r.returncode == 0, r.stderr
    assert "regions visited: Gamma_minus, Sigma_alpha, Sigma_beta, Gamma_plus" in r.stdout
    ds = ns.io.load_dataset(tmp_path / "t1.nc")
    assert int(ds.regions_visited) == 0b1111
    # true extrema: never below the samples, above them between samples (interior maxima)
    assert np.all(ds.X_max.values >= ds.X.values) and np.all(ds.X_min.values <= ds.X.values)
    assert float(ds.max_X) > float(ds.X.max()) and float(ds.max_X) == float(ds.X_max.max())
    # an oracle for the maximum: a 50x finer sampling of the same run (equal to within the
    # integration tolerance) comes closer to it
    fine = ns.simulate(ns.preset("table1"), periods=5, transient=20, samples_per_period=10000)
    assert float(ds.X.max()) + 1e-4 < float(fine.X.max()) <= float(ds.max_X) + 1e-7


def test_bifurcation_summary_counts_each_point_once(tmp_path):
    r = _cli("bifurcation", "--preset", "table1", "--param", "omega_s", "--from", "38",
             "--to", "1e12", "--steps", "2", "--transient", "5", "--record", "5",
             "-o", str(tmp_path / "f.nc"))
    assert r.returncode == 0, r.stderr
    ds = ns.io.load_dataset(tmp_path / "f.nc")
    nfail = int(np.count_nonzero(ds.status.values))
    assert nfail > 0
    line = r.stdout.splitlines()[0]
    assert "over 2 sweeps x 2 values" in line and f"{nfail} failed" in line
    counts = [int(w) for w in line.split(": ")[-1].replace(",", "").split() if w.isdigit()]
    assert sum(counts) == 4


def test_integrator_text_follows_the_code():
    from nonsmooth.integrate import rkstep as rkf45
    a = ns.simulate(ns.preset("table1"), periods=1, samples_per_period=2).attrs["integrator"]
    assert "PI" not in a and "elementary" in a and f"{rkf45._SAFETY:g}" in a


def test_deprecated_keywords_still_work_with_a_warning():
    p = ns.preset("fig6a").replace(F0=0.05)
    with pytest.warns(DeprecationWarning, match="points"):
        a = poincare(p, points=5, transient=10)
    b = poincare(p, record=5, transient=10)
    np.testing.assert_array_equal(a.X.values, b.X.values)
    with pytest.raises(ns.ParameterError, match="^record:"):
        poincare(p, record=5, points=5, transient=10)
    with pytest.warns(DeprecationWarning):
        e = eta_study(p, [0.1], transient=5, points=4, portrait_periods=1, samples_per_period=4)
    assert e.sizes["n"] == 4 and e.sizes["sample"] == 4


def test_one_default_for_samples_per_period(tmp_path):
    r = _cli("simulate", "--periods", "1", "-o", str(tmp_path / "s.nc"))
    assert r.returncode == 0, r.stderr
    cli = ns.io.load_dataset(tmp_path / "s.nc")
    api = ns.simulate(ns.preset("table1"), periods=1)
    assert cli.sizes["t"] == api.sizes["t"] == 201
