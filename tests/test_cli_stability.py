"""`nonsmooth lyapunov` and `nonsmooth orbit`: the files agree with the Python API, the figures
are made, bad input is one line with exit status 2, a failed Newton search one line with 1."""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest
import xarray as xr

import nonsmooth as ns
import nonsmooth.plot as nsplot
from nonsmooth.io import load_dataset
from cli_helpers import one_line, run_cli  # noqa: E402

PNG = b"\x89PNG"
CHAOS = ["--preset", "table3", "--set", "omega=0.92", "--periods", "200", "--transient", "50"]
SADDLE = ["--preset", "fig7", "--x0", "-1.5", "--v0", "0.25"]  # Fig. 7's unstable orbit
NO_ORBIT = ["--x0", "50", "--v0", "50"]  # Newton diverges from there


@pytest.fixture(scope="module")
def saddle():
    return ns.periodic_orbit(ns.preset("fig7"), x0=-1.5, v0=0.25)


def test_lyapunov_command_writes_the_api_result_and_a_figure(tmp_path, capsys):
    nc, png = tmp_path / "l.nc", tmp_path / "l.png"
    code, out, err = run_cli(["lyapunov", *CHAOS, "-o", str(nc), "--plot", str(png)], capsys)
    assert code == 0, err
    ds = ns.lyapunov(ns.preset("table3").replace(omega=0.92), periods=200, transient=50)
    got = load_dataset(nc)
    xr.testing.assert_equal(got, ds)  # values, dims and coordinates
    assert got.attrs["preset"] == "table3" and got.attrs["verdict"] == ds.attrs["verdict"]
    assert got.attrs["periods"] == 200 and got.attrs["method"] == "smooth"
    assert png.read_bytes()[:4] == PNG
    assert out.startswith("table3 with omega=0.92 (smooth): 200 periods after 50")
    assert f"{float(ds.exponent[0]):+.6g}" in out and f"{float(ds.exponent_sum):+.6g}" in out
    assert f"verdict: {ds.attrs['verdict']}" in out
    assert out.splitlines()[-2:] == [f"wrote {nc}", f"wrote {png}"]


def test_orbit_command_writes_the_api_result_and_a_figure(tmp_path, capsys, saddle):
    nc, png = tmp_path / "o.nc", tmp_path / "o.png"
    code, out, err = run_cli(["orbit", *SADDLE, "-o", str(nc), "--plot", str(png)], capsys)
    assert code == 0, err
    got = load_dataset(nc)
    xr.testing.assert_equal(got, saddle)  # the CLI's default method is the API's (exact)
    assert got.attrs["status"] == "converged" and got.attrs["verdict"] == "unstable"
    assert got.attrs["preset"] == "fig7"
    np.testing.assert_allclose(got.multiplier_abs, [1.774, 0.356], atol=1e-3)
    assert png.read_bytes()[:4] == PNG
    assert "period-1 orbit converged" in out
    for needle in ("-0.982138", "+0.596784", "1.77392", "0.355791", "verdict: unstable",
                   "contact fraction 0.1"):
        assert needle in out, needle


def test_orbit_on_another_model_with_complex_multipliers(capsys):
    code, out, err = run_cli(["orbit", "--model", "impact"], capsys)
    assert code == 0, err
    ds = ns.periodic_orbit(ns.model("impact").params())
    assert float(ds.multiplier_imag[0]) != 0
    mu = complex(float(ds.multiplier_real[0]), float(ds.multiplier_imag[0]))
    assert f"{mu.real:.6g}{mu.imag:+.6g}j" in out and "verdict: stable" in out


@pytest.mark.parametrize("argv, needle", [
    (["orbit", "--k", "0"], "k: must be >= 1"),
    (["orbit", "--max-iter", "0"], "max_iter: must be >= 1"),
    (["orbit", "--tol", "0"], "tol: must be > 0"),
    (["orbit", "--set", "nope=1"], "nope: not a parameter of model 'support'"),
    (["orbit", "--model", "impact", "--method", "rk4"], "method: model 'impact' has no method"),
    (["lyapunov", "--periods", "0"], "periods: must be >= 1"),
    (["lyapunov", "--blocks", "1"], "blocks: must be >= 2"),
    (["lyapunov", "--set", "nope=1"], "nope: not a parameter of model 'support'"),
    (["lyapunov", "--model", "stick_slip", "--set", "omega_s=1"], "omega_s: not a parameter"),
    (["lyapunov", "--x0", "nan"], "x0: must be finite"),
])
def test_bad_input_is_one_line_exit_2(argv, needle, tmp_path, capsys):
    code, out, err = run_cli([*argv, "-o", str(tmp_path / "r.nc")], capsys)
    assert code == 2
    one_line(err, needle)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("command", ["lyapunov", "orbit"])
def test_unwritable_output_fails_before_computing(command, tmp_path, capsys):
    code, out, err = run_cli([command, "-o", str(tmp_path / "no" / "r.nc")], capsys)
    assert code == 2 and out == ""
    one_line(err, "output: cannot write")
    code, out, err = run_cli([command, "--plot", str(tmp_path / "r.xyz")], capsys)
    assert code == 2 and out == ""
    one_line(err, "plot: unknown figure format 'xyz'")


def test_failed_newton_search_is_one_line_exit_1(tmp_path, capsys):
    nc, png = tmp_path / "o.nc", tmp_path / "o.png"
    code, out, err = run_cli(["orbit", *NO_ORBIT, "-o", str(nc), "--plot", str(png)], capsys)
    assert code == 1 and out == ""
    status = ns.periodic_orbit(ns.preset("fig7"), x0=50, v0=50).attrs["status"]
    one_line(err, f"orbit: no period-1 orbit found from (x0, v0) = (50, 50): {status} after")
    assert list(tmp_path.iterdir()) == []  # a failed search writes nothing


def _cli(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "nonsmooth.cli", *args], capture_output=True,
                          text=True, cwd=cwd, timeout=300, env=os.environ.copy())


def test_exit_statuses_in_a_real_process(tmp_path):
    for args, code, needle in ((["orbit", *NO_ORBIT], 1, "no period-1 orbit found"),
                               (["orbit", "--k", "0"], 2, "k: must be >= 1"),
                               (["lyapunov", "--periods", "0"], 2, "periods: must be >= 1")):
        r = _cli(*args, cwd=tmp_path)
        assert r.returncode == code, (args, r.stderr)
        assert "Traceback" not in r.stdout + r.stderr and r.stdout == ""
        one_line(r.stderr, needle)


def test_plot_functions_are_exported_and_draw_on_given_axes(saddle):
    from nonsmooth.plot.common import new_figure

    lyap = ns.lyapunov(ns.preset("table3").replace(omega=0.92), periods=50, transient=0)
    fig, (ax0, ax1) = new_figure(1, 2)
    assert nsplot.plot_lyapunov(lyap, ax=ax0) is fig
    assert nsplot.plot_orbit(saddle, ax=ax1) is fig
    assert ax0.get_xscale() == "log" and len(ax0.get_lines()) >= 2
    assert "mu1 = 1.774" in ax1.texts[0].get_text()
    assert "nonsmooth.plot.stability" in nsplot.plot_orbit.__module__


@pytest.mark.parametrize("command, options", [
    ("lyapunov", ("--periods", "--transient", "--x0", "--v0", "--blocks", "--model", "--preset",
                  "--set", "--method", "--out", "--plot")),
    ("orbit", ("--k", "--x0", "--v0", "--transient", "--tol", "--max-iter", "--model",
               "--preset", "--set", "--method", "--out", "--plot")),
])
def test_help_lists_the_options(command, options):
    from typer.testing import CliRunner

    from nonsmooth.cli import app
    res = CliRunner().invoke(app, [command, "--help"], env={"COLUMNS": "200"})
    assert res.exit_code == 0, res.output
    assert "<bool>" not in res.output
    for opt in options:
        assert opt in res.output, opt
