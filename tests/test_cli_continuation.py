"""`nonsmooth continue`: the file agrees with the Python API, the figure is made, the summary
names the special points, bad input is one line with exit status 2."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

import nonsmooth as ns
import nonsmooth.plot as nsplot
from nonsmooth.io import load_dataset
from cli_helpers import one_line, run_cli  # noqa: E402

PNG = b"\x89PNG"
FIG6A = ["--preset", "fig6a", "--set", "omega=0.5", "--param", "omega", "--bounds", "0.5", "1.6"]


@pytest.fixture(scope="module")
def branch():
    return ns.continuation(ns.preset("fig6a").replace(omega=0.5), "omega", bounds=(0.5, 1.6))


def test_continue_writes_the_api_result_and_a_figure(tmp_path, capsys, branch):
    nc, png = tmp_path / "c.nc", tmp_path / "c.png"
    code, out, err = run_cli(["continue", *FIG6A, "-o", str(nc), "--plot", str(png)], capsys)
    assert code == 0, err
    got = load_dataset(nc)
    xr.testing.assert_equal(got, branch)  # the CLI's default method is the API's (exact)
    assert got.attrs["preset"] == "fig6a" and got.attrs["param"] == "omega"
    assert got.attrs["method"] == "exact" and got.attrs["status"] == branch.attrs["status"]
    assert png.read_bytes()[:4] == PNG
    lam = branch.omega.values
    assert out.startswith(f"fig6a with omega=0.5 (exact): period-1 branch in omega, "
                          f"{lam.size} points")
    assert f"status: {branch.attrs['status']}" in out
    # the Fig. 6a resonance curve: grazing omega_a, folds omega_c and omega_b
    for needle in ("grazing (G)", "fold (F)", "0.940308", "1.193042", "1.055140"):
        assert needle in out, needle
    assert out.splitlines()[-2:] == [f"wrote {nc}", f"wrote {png}"]


def test_special_points_of_fig6a(branch):
    sp = set(zip(branch.special_type.values.tolist(), branch.special_omega.values.round(4)))
    assert {(4, 0.9403), (1, 1.193), (1, 1.0551)} <= sp
    assert branch.stable.values.min() == 0 and branch.stable.values[0] == 1


def test_a_branch_without_special_points(tmp_path, capsys):
    nc = tmp_path / "c.nc"
    code, out, err = run_cli(["continue", "--set", "omega=0.5", "--param", "omega",
                              "--bounds", "0.5", "0.8", "-o", str(nc)], capsys)
    assert code == 0, err
    assert "no special points" in out and load_dataset(nc).sizes["special"] == 0


@pytest.mark.parametrize("argv, needle", [
    (["--step", "0"], "step: must be > 0"),
    (["--step", "inf"], "step: must be finite"),
    (["--max-step", "0.001"], "max_step: must be >= step"),
    (["--bounds", "0.6", "1.6"], "bounds: 0.6 ... 1.6 exclude the start omega = 0.5"),
    (["--bounds", "1.6", "0.5"], "bounds: empty or reversed range"),
    (["--bounds", "nan", "1"], "bounds: expected numbers"),
    (["--param", "nope"], "nope: not a parameter of model 'support'"),
    (["--direction", "left"], "direction: expected 'up' or 'down'"),
    (["--k", "0"], "k: must be >= 1"),
    (["--max-points", "1"], "max_points: must be >= 2"),
    (["--model", "impact", "--param", "omega_s"], "omega_s: not a parameter"),
])
def test_bad_input_is_one_line_exit_2(argv, needle, tmp_path, capsys):
    base = ["continue", "--set", "omega=0.5", "--param", "omega"]
    code, out, err = run_cli([*base, *argv, "-o", str(tmp_path / "c.nc")], capsys)
    assert code == 2 and out == ""
    one_line(err, needle)
    assert list(tmp_path.iterdir()) == []


def test_unwritable_output_fails_before_computing(tmp_path, capsys):
    code, out, err = run_cli(["continue", *FIG6A, "-o", str(tmp_path / "no" / "c.nc")], capsys)
    assert code == 2 and out == ""
    one_line(err, "output: cannot write")
    code, out, err = run_cli(["continue", *FIG6A, "--plot", str(tmp_path / "c.xyz")], capsys)
    assert code == 2 and out == ""
    one_line(err, "plot: unknown figure format 'xyz'")


def test_plot_continuation_is_exported_and_draws_on_given_axes(branch):
    from nonsmooth.plot.common import new_figure

    assert ns.continuation is ns.analysis.continuation.continuation
    fig, (ax0, ax1) = new_figure(1, 2)
    assert nsplot.plot_continuation(branch, ax=ax0) is fig
    assert nsplot.plot_continuation(branch, var="X_section", ax=ax1) is fig
    styles = {ln.get_linestyle() for ln in ax0.get_lines()}
    assert {"-", "--"} <= styles  # stable solid, unstable dashed
    labels = [t.get_text() for t in ax0.texts]
    assert "F 1.193" in labels and "G 0.94031" in labels and "F 1.0551" in labels
    assert "nonsmooth.plot.continuation" in nsplot.plot_continuation.__module__
    assert ax0.get_xlabel() == r"$\omega$ [rad/s]"
    level = [ln for ln in ax0.get_lines() if ln.get_label() == r"support $X = 1$"]
    assert level and np.allclose(level[0].get_ydata(), 1.0)


def test_help_lists_the_options():
    from typer.testing import CliRunner

    from nonsmooth.cli import app
    res = CliRunner().invoke(app, ["continue", "--help"], env={"COLUMNS": "200"})
    assert res.exit_code == 0, res.output
    assert "<bool>" not in res.output
    for opt in ("--param", "--k", "--x0", "--v0", "--transient", "--direction", "--step",
                "--max-step", "--bounds", "--max-points", "--model", "--preset", "--set",
                "--method", "--out", "--plot"):
        assert opt in res.output, opt
