"""`nonsmooth reproduce`: the numbers and verdicts of the report against independent oracles,
re-runs into a folder that holds a report, interruption, and the command's checks of its input.

Each test runs single cheap figures (quick mode), so the file takes a few seconds once the
kernels are compiled."""

from __future__ import annotations

import json
import re
import signal
import subprocess
import sys

import numpy as np
import pytest
import xarray as xr

import nonsmooth as ns
from nonsmooth.cli import main
from nonsmooth.reproduction import AGREES, DIFFERS, FIGURES, reproduce
from nonsmooth.reproduction.core import FigureRecord, figure
from nonsmooth.reproduction.figures.fig09_11_bifurcation import point_in_diagram

from cli_helpers import SAFETY_S, popen, wait_until  # noqa: E402


def _check(rec, start):
    (c,) = [c for c in rec.checks if c.claim.startswith(start)]
    return c


def _dense_max(p, periods, transient, **kw):
    """Oracle: the largest X sampled 50,000 times per period (within ~1e-8 of the true
    maximum; no kernel extrema involved)."""
    return float(ns.simulate(p, periods=periods, transient=transient, samples_per_period=50_000,
                             **kw).X.max())


@pytest.fixture(scope="module")
def fig345(tmp_path_factory):
    out = tmp_path_factory.mktemp("fig345")
    return out, {r.id: r for r in reproduce(out, only="fig3,fig4,fig5,fig8", quick=True)}


# -- issue 8 item 3: printed maxima are true extrema -------------------------------------------
def test_fig3_eq12_evidence_prints_true_maxima(fig345):
    out, _ = fig345
    (line,) = json.loads((out / "summary.json").read_text())["gap_evidence"]["eq12"][:1]
    m13, m12 = (float(x) for x in re.findall(r"settled orbit ([\d.]+) with eq. 13 and ([\d.]+)",
                                             line)[0])
    p = ns.preset("table1")
    assert m13 == pytest.approx(_dense_max(p, 2, 10), abs=2e-6)
    assert m12 == pytest.approx(_dense_max(p, 2, 10, method="smooth_eq12"), abs=2e-6)
    assert abs(m13 - m12) < 1e-4  # the sampled maxima differed by 4e-3


def test_fig5_max_x_is_the_true_maximum_and_the_period_is_right(fig345):
    _, recs = fig345
    row = _check(recs["fig5"], "omega_s = 31.6")
    mx = float(re.search(r"max X = ([\d.]+)", row.measured).group(1))
    transient = int(recs["fig5"].settings["transient"].split()[0])
    p = ns.preset("table2").replace(omega_s=31.6)
    assert mx == pytest.approx(_dense_max(p, 3, transient), abs=2e-6)
    assert "period 4" in row.measured  # quick mode said period 8


# -- issue 8 item 4: Fig. 4, eta = 0.028 -------------------------------------------------------
def _turned_back_oracle(eta, periods, spp=1000):
    """Start periods of the excursions out of Gamma- (eq. 14: h_alpha > -eta and h_beta < eta)
    that return without entering Gamma+ (h_alpha >= eta and h_beta <= -eta), from densely
    sampled states (no region codes or visited masks of the kernels)."""
    p = ns.preset("fig4").replace(eta=eta)
    d = ns.simulate(p, periods=periods, samples_per_period=spp)
    ha = d.X.values - 1.0
    hb = -ha - p.xi_s / p.omega_s ** 2 * d.V.values
    out = ~((ha <= -eta) | (hb >= eta))
    plus = (ha >= eta) & (hb <= -eta)
    edges = np.flatnonzero(np.diff(out.astype(int)))
    starts, ends = edges[out[edges + 1]] + 1, edges[~out[edges + 1]] + 1
    return [int(s // spp) for s, e in zip(starts, ends) if not plus[s:e].any()], len(starts)


def test_fig4_counts_the_excursions_of_the_whole_run(fig345):
    _, recs = fig345
    rec = recs["fig4"]
    row = _check(rec, "eta = 0.028")
    back, n = _turned_back_oracle(0.028, 900)
    assert back == [4, 7, 9, 15]
    assert f"{len(back)} of {n} excursions" in row.measured
    assert "forcing periods 4, 7, 9, 15" in row.measured
    assert row.verdict == AGREES  # the paper's enlargement shows such an excursion
    assert "settled orbit (period 4" in row.measured and "enter Gamma+" in row.measured
    back, n = _turned_back_oracle(0.28, 900)
    never = _check(rec, "eta = 0.28")
    assert len(back) == n and f"{n} of {n} excursions" in never.measured
    assert never.verdict == AGREES


def test_fig4_quick_states_its_criteria_and_keeps_the_full_conclusion(fig345):
    _, recs = fig345
    rec = recs["fig4"]
    for c in rec.checks[:4]:
        assert "criterion" in c.claim
    row = _check(rec, "eta_hat")
    oracle = ns.eta_study(ns.preset("fig4"), [0.28, 0.028, 0.0028, 0.00028], record=400,
                          transient=500)
    rec_eta = float(oracle["recommended_eta"]) if "recommended_eta" in oracle \
        else oracle.attrs["recommended_eta"]
    assert rec_eta == pytest.approx(0.0028)  # the README's value (full resolution)
    assert "exact model: 0.0028 (criterion" in row.measured


def test_reproduction_netcdf_variables_are_cf_clean(fig345):
    out, _ = fig345
    for name in ("fig4", "fig5", "fig8"):
        with xr.open_dataset(out / f"{name}.nc", engine="h5netcdf") as ds:
            for k, v in ds.data_vars.items():
                assert "legend" not in v.attrs, (name, k)
                assert {"units", "flag_values", "flag_masks"} & set(v.attrs), (name, k)
    with xr.open_dataset(out / "fig4.nc", engine="h5netcdf") as ds:
        for k in ("excursions", "excursions_turned_back", "excursions_turned_back_settled"):
            assert ds[k].attrs["units"] == "1" and ds[k].attrs["long_name"]
    with xr.open_dataset(out / "fig5.nc", engine="h5netcdf") as ds:
        assert ds["seconds"].attrs["units"] == "s" and ds["omega_s"].attrs["units"] == "rad/s"
        assert ds["period"].attrs["units"] == "1"
        assert "param_omega_s" not in ds.attrs  # the swept parameter is a coordinate only


# -- issue 14 item 9: Fig. 9, coexisting attractors --------------------------------------------
def test_point_in_diagram_reports_coexisting_attractors():
    from nonsmooth.io import flag_attrs
    om = np.array([0.91, 0.92, 0.93])
    ds = xr.Dataset({"period": (("sweep", "omega"), [[3, 3, 0], [3, 0, 0]]),
                     "contact": (("sweep", "omega"), np.ones((2, 3), int))},
                    coords={"sweep": ("sweep", [0, 1], flag_attrs(["up", "down"])),
                            "omega": om})
    ds.attrs["swept_param"] = "omega"
    rec = FigureRecord("fig9", "t")
    point_in_diagram(rec, ds, "omega", 0.92, 0, "Fig. 10")
    first, second = rec.checks
    assert first.verdict == AGREES and "two attractors coexist" in first.measured
    assert "the down sweep ends on the paper's" in first.measured
    assert second.verdict == DIFFERS and "up sweep" in second.measured \
        and "period 3" in second.measured
    rec = FigureRecord("fig9", "t")
    point_in_diagram(rec, ds, "omega", 0.91, 3, "Fig. 10")
    assert [c.verdict for c in rec.checks] == [AGREES]
    ds["period"][0, 1] = -1  # up sweep not settled: no second attractor, no agreement from it
    for want, verdict in ((0, AGREES), (3, DIFFERS)):
        rec = FigureRecord("fig9", "t")
        point_in_diagram(rec, ds, "omega", 0.92, want, "Fig. 10")
        assert [c.verdict for c in rec.checks] == [verdict]
        assert "up sweep not settled" in rec.checks[0].measured


# -- issue 14 item 3: re-running figures into a folder updates the full report -----------------
def test_rerun_of_some_figures_keeps_the_others_in_the_report(tmp_path):
    reproduce(tmp_path, only="fig12b,fig12c", quick=True, command="first")
    reproduce(tmp_path, only="fig12c", quick=False, command="second")
    md = (tmp_path / "report.md").read_text()
    assert "## fig12b" in md and "## fig12c" in md
    assert "Mode: mixed: full: fig12c; quick: fig12b" in md
    assert "`first` (quick;" in md and "`second` (full;" in md
    summary = json.loads((tmp_path / "summary.json").read_text())
    runs = {f["id"]: f["run"] for f in summary["figures"]}
    assert runs["fig12b"]["command"] == "first" and runs["fig12c"]["command"] == "second"
    assert runs["fig12c"]["quick"] is False
    for png in tmp_path.glob("*.png"):  # no figure file is left out of the report
        assert f"({png.name})" in md


def test_a_summary_of_another_layout_starts_a_new_report_and_says_so(tmp_path):
    (tmp_path / "summary.json").write_text('{"meta": {}, "figures": [{"id": "fig3"}]}')
    said = []
    reproduce(tmp_path, only="fig12c", quick=True, log=said.append)
    assert any("summary.json is not a summary this version can read" in m for m in said)
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert [f["id"] for f in summary["figures"]] == ["fig12c"]


# -- issue 14 Ctrl-C: the finished figures and the report stay ---------------------------------
def test_interrupt_keeps_finished_figures_and_the_report(tmp_path, monkeypatch):
    monkeypatch.setitem(FIGURES, "figint", None)

    @figure("figint", "a figure interrupted by Ctrl-C", "nothing")
    def interrupted(ctx, rec):
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        reproduce(tmp_path, only="fig12c,figint", quick=True)
    md = (tmp_path / "report.md").read_text()
    assert "## fig12c" in md and "(fig12c.png)" in md
    assert "## figint" in md and "interrupted" in md
    assert (tmp_path / "fig12c.nc").is_file()


def test_cli_sigint_keeps_the_finished_figures(tmp_path):
    out = tmp_path / "run"
    proc = popen([sys.executable, "-m", "nonsmooth.cli", "reproduce", "--quick",
                  "--only", "fig3,fig4,fig9", "--out", str(out)],
                 stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    wait_until(proc, lambda: (out / "report.md").exists(), "the first report (fig3 done)")
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=SAFETY_S)
    assert proc.returncode == 130, err
    assert "Traceback" not in err
    md = (out / "report.md").read_text()  # written when fig3 was done, then on the interrupt
    assert "## fig3" in md and (out / "fig3.png").is_file() and (out / "fig3.nc").is_file()
    assert "(fig3.png)" in md


# -- issue 14 items 7 and 11: the command's input ----------------------------------------------
@pytest.mark.parametrize("where", ["file", "file/sub", "missing/deep/dir"])
def test_cli_out_that_cannot_be_a_folder_is_one_line_exit_2(tmp_path, capsys, where):
    (tmp_path / "file").write_text("x")
    with pytest.raises(SystemExit) as exc:
        main(["reproduce", "--quick", "--only", "fig12c", "--out", str(tmp_path / where)])
    assert exc.value.code == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and err.startswith("error: out:")
    assert not (tmp_path / "missing").exists()
    assert (tmp_path / "file").read_text() == "x"


def test_cli_workers_0_creates_the_last_level_and_quick_is_a_plain_flag(tmp_path, capsys):
    with pytest.raises(SystemExit) as exc:
        main(["reproduce", "--quick", "--workers", "0", "--only", "fig12c",
              "--out", str(tmp_path / "new")])
    assert exc.value.code in (0, None)
    assert (tmp_path / "new" / "fig12c.png").is_file()
    capsys.readouterr()
    with pytest.raises(SystemExit):
        main(["reproduce", "--help"])
    help_text = capsys.readouterr().out
    assert "--quick" in help_text and "--full" in help_text
    assert not re.search(r"--quick\s.*<bool>", help_text)
