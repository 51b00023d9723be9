"""`nonsmooth eta-study`: value parsing, outputs, and one-line errors for bad input."""

from __future__ import annotations

import math

import pytest
import xarray as xr

import nonsmooth.cli.eta_study  # noqa: F401  (registers the command, also if cli/__init__ does)
from nonsmooth.cli import main
from nonsmooth.cli.eta_study import parse_etas
from nonsmooth.errors import ParameterError


def run_cli(argv, capsys):
    with pytest.raises(SystemExit) as exc:
        main(argv)
    cap = capsys.readouterr()
    return exc.value.code, cap.out, cap.err


def test_parse_etas_accepts_lists_repeats_and_commas():
    assert parse_etas(["0.28", "0.028,0.0028", " 2.8e-4 "]) == [0.28, 0.028, 0.0028, 0.00028]
    with pytest.raises(ParameterError, match="^eta:"):
        parse_etas([])
    with pytest.raises(ParameterError, match="^eta:"):
        parse_etas(["abc"])


def test_eta_study_command_writes_dataset_and_figure(tmp_path, capsys):
    nc = tmp_path / "eta.nc"
    png = tmp_path / "eta.png"
    # space-separated list after --eta, plus a repeated --eta
    code, out, err = run_cli(["eta-study", "--preset", "fig6a", "--eta", "0.1", "0.01",
                              "--eta", "0.001", "--transient", "150", "--points", "12",
                              "--portrait-periods", "2", "--samples-per-period", "50",
                              "-o", str(nc), "--plot", str(png)], capsys)
    assert code in (0, None), err
    assert nc.is_file() and png.is_file() and png.stat().st_size > 1000
    ds = xr.open_dataset(nc, engine="h5netcdf").load()
    assert list(ds["eta"].values) == [0.1, 0.01, 0.001]
    assert ds["exact_period"] == 1 and ds["exact_reaches_gamma_plus"] == 1
    # eta = 0.1 never enters Gamma+ (cf. Fig. 4a); the small ones agree with the exact orbit
    assert list(ds["reaches_gamma_plus"].values) == [0, 1, 1]
    assert list(ds["agrees"].values) == [0, 1, 1]
    assert math.isclose(ds["recommended_eta"], 0.01)
    assert ds["distance_to_exact"].values[2] < ds["distance_to_exact"].values[1]
    assert ds.attrs["preset"] == "fig6a" and "nonsmooth_version" in ds.attrs
    assert "recommended eta: 0.01" in out


@pytest.mark.parametrize("argv,needle", [
    (["eta-study", "--preset", "fig6a", "-o", "x.nc"], "eta:"),                 # no eta at all
    (["eta-study", "--preset", "fig6a", "--eta", "0", "-o", "x.nc"], "eta:"),    # eta = 0
    (["eta-study", "--preset", "fig6a", "--eta=-0.1", "-o", "x.nc"], "eta:"),    # negative
    (["eta-study", "--preset", "fig6a", "--eta", "0.7", "-o", "x.nc"], "eta:"),  # >= 0.5
    (["eta-study", "--preset", "fig6a", "--eta", "abc", "-o", "x.nc"], "eta:"),
    (["eta-study", "--preset", "nosuch", "--eta", "0.1", "-o", "x.nc"], "preset:"),
    (["eta-study", "--preset", "fig6a", "--eta", "0.1", "--set", "xi=-1", "-o", "x.nc"], "xi:"),
])
def test_bad_input_gives_one_line_error(argv, needle, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    code, out, err = run_cli(argv, capsys)
    assert code == 2
    lines = [ln for ln in err.strip().splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("error: ") and needle in lines[0], err
    assert "Traceback" not in err
    assert not (tmp_path / "x.nc").exists()


def test_python_api_rejects_bad_eta_lists():
    from nonsmooth import preset
    from nonsmooth.analysis.eta_study import eta_study
    for bad in ([], [0.0], [-1e-3], [0.5], [float("nan")], "0.1"):
        with pytest.raises(ParameterError, match="^eta:"):
            eta_study(preset("fig6a"), bad)
